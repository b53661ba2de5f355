//! What the debuggers put on the robot's line: the monitor's `/...` and
//! `send` lines, and under `scorpion dap` `launch`'s `commands` and a
//! debug-console line starting with `/` (`evaluate`). Each is one command
//! as the ROM reads it (docs/PROTOCOL.md, section 1: `/`, a count N of 1
//! to 9, then N characters), so the longest is 11 characters; and
//! `launch` sends no more in all than a serial port holds ([`HOLDS`]). Sent as it came, 100 kB of
//! "command" queued about 48 bytes of memory a byte and minutes of line
//! time ahead of everything after it.

use romlib::protocol::{Command, EXTENSION_MAX_LEN};

/// The longest command: `/`, the count, and the most characters a count
/// says.
pub const MAX_COMMAND: usize = 2 + EXTENSION_MAX_LEN;

/// The most bytes a serial port holds on their way out: Linux's serial
/// driver's transmit buffer (`UART_XMIT_SIZE`, a page), the bound the
/// simulator's host line keeps too.
pub const HOLDS: usize = 4096;

/// `text` as a command to send, or why it is not one.
///
/// # Errors
/// Why it is not one command as the ROM reads it.
pub fn command(text: &str) -> Result<Command, String> {
    if text.len() > MAX_COMMAND {
        let shown: String = text.chars().take(MAX_COMMAND).collect();
        return Err(format!(
            "`{shown}...` is {} bytes: a command is `/`, a count 1-9 and that many characters, {MAX_COMMAND} at most (docs/PROTOCOL.md)",
            text.len()
        ));
    }
    Command::parse(text.as_bytes()).map_err(|error| error.to_string())
}

/// Checks `launch`'s `commands`: each a command, and no more in all than a
/// serial port holds.
///
/// # Errors
/// A list longer than [`HOLDS`], or the first that is not a command.
pub fn commands(texts: &[String]) -> Result<(), String> {
    let total: usize = texts.iter().map(String::len).sum();
    if total > HOLDS {
        return Err(format!(
            "`commands` holds {total} bytes: at most {} go down the line at once (what a serial port holds); send the rest from the debug console",
            HOLDS
        ));
    }
    texts.iter().try_for_each(|text| command(text).map(drop))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_command_of_at_most_eleven_characters() {
        assert!(command("/9W04001234").is_ok());
        assert!(command("/2A1").is_ok());
        let long = format!("/1E{}", "x".repeat(100_000));
        let said = command(&long).expect_err("too long");
        assert!(said.contains("100003 bytes"), "{said}");
        assert!(said.len() < 200, "the text is not echoed whole: {said}");
        assert!(command("/3A1").is_err(), "the count says 3, 2 follow");
        assert!(command("/1E/1B").is_err(), "two commands");
    }

    #[test]
    fn launch_sends_no_more_than_a_port_holds() {
        let few = vec!["/1E".to_owned(); 10];
        assert_eq!(commands(&few), Ok(()));
        assert!(commands(&["/1E".to_owned(), "hello".to_owned()]).is_err());
        let many = vec!["/1E".to_owned(); 2000];
        assert!(commands(&many).is_err());
    }
}
