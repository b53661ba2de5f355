//! The table of the ROM's commands: for each (count, letter) pair the
//! reference ROM dispatches on, its form as docs/PROTOCOL.md writes it, and
//! whether and how it answers. The host protocol's checks
//! ([`Command::is_question`](super::Command::is_question),
//! [`Command::answer_len`](super::Command::answer_len), which pairs are free
//! for extensions) read this table, and tests hold it equal to the ROM's
//! dispatch table and to docs/PROTOCOL.md's command tables.

/// What a command sends back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Reply {
    /// An instruction: nothing.
    Nothing,
    /// A question whose answer is always this many characters, carriage
    /// return included.
    Fixed(usize),
    /// `/7Raaaa##`: `R`, two hex digits per byte read, carriage return.
    PerByte,
    /// `/1S`: as long as the last scan left the buffer.
    Variable,
}

/// One command of the reference ROM.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CommandSpec {
    /// The count after the slash: how many characters follow it.
    pub count: u8,
    /// The first character after the count.
    pub letter: u8,
    /// The form as docs/PROTOCOL.md writes it (`/8Cdff####`): `h` a hex
    /// digit, `#` a decimal digit, `d` a direction, `f` a speed digit, `a`
    /// an address digit.
    pub form: &'static str,
    /// What it answers.
    pub reply: Reply,
    /// What it does, in a few words.
    pub summary: &'static str,
}

impl CommandSpec {
    /// Whether the ROM answers it.
    #[must_use]
    pub const fn is_question(&self) -> bool {
        !matches!(self.reply, Reply::Nothing)
    }
}

const fn instruction(form: &'static str, summary: &'static str) -> CommandSpec {
    spec(form, Reply::Nothing, summary)
}

const fn question(form: &'static str, reply: Reply, summary: &'static str) -> CommandSpec {
    spec(form, reply, summary)
}

const fn spec(form: &'static str, reply: Reply, summary: &'static str) -> CommandSpec {
    let bytes = form.as_bytes();
    CommandSpec {
        count: bytes[1] - b'0',
        letter: bytes[2],
        form,
        reply,
        summary,
    }
}

/// `P`, `Bhh E# G# T# Ms####s#### Yhh Xhh C#### D####`, carriage return.
const EVERYTHING_LEN: usize = 1 + 3 + 2 + 2 + 2 + 11 + 3 + 3 + 5 + 5 + 1;

/// Every command the reference ROM dispatches on, in the order of its
/// dispatch table (`commands` in rom/loop.s).
pub const COMMANDS: [CommandSpec; 25] = [
    instruction("/1R", "reset to the power-up state"),
    question("/1B", Reply::Fixed(4), "the bumper microswitches"),
    question("/1S", Reply::Variable, "the scanner buffer"),
    question("/1E", Reply::Fixed(3), "the eyes"),
    question("/1G", Reply::Fixed(3), "the tracker lamps"),
    question(
        "/1T",
        Reply::Fixed(3),
        "the ground-tracker phototransistors",
    ),
    question("/1M", Reply::Fixed(12), "steps moved since the last /1M"),
    question("/1X", Reply::Fixed(4), "the busy byte"),
    question("/1C", Reply::Fixed(6), "steps still to go, left motor"),
    question("/1D", Reply::Fixed(6), "steps still to go, right motor"),
    question(
        "/1P",
        Reply::Fixed(EVERYTHING_LEN),
        "almost everything at once",
    ),
    instruction("/2E#", "set the eyes"),
    instruction("/2G#", "tracker lamps on or off"),
    instruction("/3Yhh", "set the Master I/O byte"),
    instruction("/3Zhh", "set the obey mask"),
    instruction("/3Khh", "speaker tone"),
    instruction("/3H##", "horizontal scan"),
    instruction("/3V##", "vertical scan"),
    instruction("/4Cdff", "left motor, continuous"),
    instruction("/4Ddff", "right motor, continuous"),
    question("/7Raaaa##", Reply::PerByte, "read memory"),
    instruction("/7Waaaahh", "write one byte"),
    instruction("/8Cdff####", "move the left motor"),
    instruction("/8Ddff####", "move the right motor"),
    instruction("/9Waaaahhhh", "write two bytes at once"),
];

/// The ROM's command with this count and letter, if it has one.
#[must_use]
pub fn find(count: usize, letter: u8) -> Option<&'static CommandSpec> {
    COMMANDS
        .iter()
        .find(|spec| usize::from(spec.count) == count && spec.letter == letter)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::Command;

    /// The form with every field filled in: a command the ROM accepts.
    fn sample(form: &str) -> String {
        form.chars()
            .enumerate()
            .map(|(at, c)| match c {
                'd' if at > 2 => '+',
                'h' | 'a' | 'f' | '#' if at > 2 => '1',
                other => other,
            })
            .collect()
    }

    #[test]
    fn every_form_parses_to_a_command_that_points_back_at_its_entry() {
        for spec in &COMMANDS {
            let text = sample(spec.form);
            let command = Command::parse(text.as_bytes())
                .unwrap_or_else(|error| panic!("{}: {text}: {error}", spec.form));
            assert_eq!(command.spec(), Some(spec), "{text}");
            assert_eq!(command.to_string(), text, "{} round-trips", spec.form);
            assert_eq!(command.is_question(), spec.is_question(), "{text}");
            assert_eq!(
                spec.form.len() - 2,
                usize::from(spec.count),
                "{}: the count is the characters after it",
                spec.form
            );
            match spec.reply {
                Reply::Fixed(len) => assert_eq!(command.answer_len(), Some(len)),
                Reply::PerByte => assert_eq!(command.answer_len(), Some(2 + 2 * 11)),
                Reply::Variable | Reply::Nothing => assert_eq!(command.answer_len(), None),
            }
        }
    }

    #[test]
    fn no_pair_is_listed_twice_and_the_rest_are_extensions() {
        for (index, spec) in COMMANDS.iter().enumerate() {
            assert!(
                COMMANDS[index + 1..]
                    .iter()
                    .all(|other| (other.count, other.letter) != (spec.count, spec.letter)),
                "{} twice",
                spec.form
            );
        }
        for count in 1..=9u8 {
            for letter in b'A'..=b'Z' {
                let text = format!(
                    "/{count}{}{}",
                    char::from(letter),
                    "Q".repeat(usize::from(count) - 1)
                );
                let listed = find(usize::from(count), letter).is_some();
                match Command::parse(text.as_bytes()) {
                    Ok(Command::Extension(_)) => assert!(!listed, "{text} is the ROM's"),
                    Ok(_) => assert!(listed, "{text} parsed as a ROM command"),
                    Err(_) => assert!(listed, "{text} is free for extensions, yet refused"),
                }
            }
        }
    }
}
