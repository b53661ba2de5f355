//! Changing the robot from the monitor: `set REG VALUE` (registers and
//! flags) and `mem ADDR BYTE...`/`poke` (RAM), values as expressions. Each
//! change is a host action the debugger records, so that a step back and
//! forward again sees it at the same instruction.

use crate::{Debugger, Register};

use super::{Failure, address, expression, registers, usage};

const SET_USAGE: &str = "set A|X|Y|S|P|PC|C|Z|I|D|V|N [=] VALUE (memory: mem ADDR BYTE...)";

/// `set A $05`, `set A=$05`, `set C 1`, `set PC label`.
pub(super) fn set(d: &mut Debugger, text: &str) -> Result<String, Failure> {
    let name: String = text
        .chars()
        .take_while(char::is_ascii_alphanumeric)
        .collect();
    let register = Register::named(&name).ok_or_else(|| usage(SET_USAGE))?;
    let value_text = text[name.len()..].trim_start();
    let value_text = value_text.strip_prefix('=').unwrap_or(value_text).trim();
    if value_text.is_empty() {
        return Err(usage(SET_USAGE));
    }
    let value = expression(d, value_text, 0)?
        .eval(d)
        .map_err(|error| Failure::Usage(error.to_string()))?;
    d.set_register(register, value)?;
    Ok(format!(
        "{register} = {}\n  {}\n",
        crate::expr::show(value),
        registers(d)
    ))
}

/// `mem ADDR BYTE BYTE...` and `poke ADDR BYTE...`: each byte an
/// expression (`$2F`, `47`, `'A'`, `<label`).
pub(super) fn poke(d: &mut Debugger, at: &str, words: &[&str]) -> Result<String, Failure> {
    let start = address(d, at)?;
    let words = match words {
        ["=", rest @ ..] => rest,
        other => other,
    };
    let mut bytes = Vec::with_capacity(words.len());
    for word in words {
        let value = expression(d, word, 0)?
            .eval(d)
            .map_err(|error| Failure::Usage(error.to_string()))?;
        let byte = u8::try_from(value).map_err(|_| {
            usage(&format!(
                "`{word}` is {value}: a byte is 0 to 255 ($00-$FF)"
            ))
        })?;
        bytes.push(byte);
    }
    d.poke(start, &bytes)?;
    Ok(format!(
        "wrote {} byte{} at ${start:04X}\n{}",
        bytes.len(),
        if bytes.len() == 1 { "" } else { "s" },
        super::memory(d, start, u64::try_from(bytes.len()).unwrap_or(16))
    ))
}
