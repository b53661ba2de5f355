//! Value parsers shared by the subcommands.

/// Parses an address or count written as `0x1234`, `$1234` or decimal, into
/// 0..=`max`.
fn parse_number(text: &str, max: u64) -> Result<u64, String> {
    let trimmed = text.trim();
    let (digits, radix) = if let Some(hex) = trimmed
        .strip_prefix("0x")
        .or_else(|| trimmed.strip_prefix("0X"))
        .or_else(|| trimmed.strip_prefix('$'))
    {
        (hex, 16)
    } else {
        (trimmed, 10)
    };
    let digits = digits.replace('_', "");
    if digits.is_empty() {
        return Err(format!(
            "`{text}` is not a number (write 0x1234, $1234 or 4660)"
        ));
    }
    let value = u64::from_str_radix(&digits, radix)
        .map_err(|_| format!("`{text}` is not a number (write 0x1234, $1234 or 4660)"))?;
    if value > max {
        return Err(format!("{text} is out of range (0 to {max}, ${max:X})"));
    }
    Ok(value)
}

/// A 16-bit address: `0x1234`, `$1234` or `4660`.
pub(crate) fn address(text: &str) -> Result<u16, String> {
    parse_number(text, 0xFFFF).map(|value| value as u16)
}

/// A byte count that fits in the 64 KiB address space: `0x100`, `$100` or `256`.
pub(crate) fn length(text: &str) -> Result<u32, String> {
    parse_number(text, 0x1_0000).map(|value| value as u32)
}

/// A `-D` symbol definition: `NAME` (value 1) or `NAME=VALUE`, the value
/// as `42`, `$2A`, `0x2A` or `%101010`, optionally negative, within 32 bits.
pub(crate) fn define(text: &str) -> Result<(String, i64), String> {
    let (name, value) = text.split_once('=').unwrap_or((text, "1"));
    let valid = name
        .bytes()
        .next()
        .is_some_and(|b| b.is_ascii_alphabetic() || b == b'_')
        && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
    if !valid {
        return Err(format!(
            "`{name}` is not a symbol name (letters, digits and `_`)"
        ));
    }
    let value = value.trim();
    let (negative, digits) = value
        .strip_prefix('-')
        .map_or((false, value), |rest| (true, rest));
    let (digits, radix) = if let Some(hex) = digits
        .strip_prefix('$')
        .or_else(|| digits.strip_prefix("0x"))
        .or_else(|| digits.strip_prefix("0X"))
    {
        (hex, 16)
    } else if let Some(binary) = digits.strip_prefix('%') {
        (binary, 2)
    } else {
        (digits, 10)
    };
    let number = match u128::from_str_radix(digits, radix) {
        Ok(n) if n <= u128::from(u32::MAX) => n as i64,
        Ok(_) => {
            return Err(format!(
                "`{value}` is out of range: a define is a 32-bit value (at most $FFFFFFFF)"
            ));
        }
        Err(_) => {
            return Err(format!(
                "`{value}` is not a number (write 42, $2A, 0x2A or %101010)"
            ));
        }
    };
    Ok((name.to_owned(), if negative { -number } else { number }))
}

/// `-t SYSTEM`: one of ca65's target systems. Its symbols and character
/// set are taken whatever its CPU; instructions of another CPU (a
/// 65C02's `stz`) are refused where a source uses them, so a source that
/// says `.setcpu "6502"` builds for `apple2enh` as with ca65.
pub(crate) fn system(text: &str) -> Result<&'static assembler::systems::System, String> {
    assembler::systems::find(text).ok_or_else(|| {
        let names: Vec<&str> = assembler::systems::SYSTEMS.iter().map(|s| s.name).collect();
        format!("no system `{text}` (ca65's: {})", names.join(", "))
    })
}

/// `--feature NAME`: a ca65 feature.
pub(crate) fn feature(text: &str) -> Result<String, String> {
    match assembler::Features::default().set(text, true) {
        Ok(()) => Ok(text.to_ascii_lowercase()),
        Err(assembler::FeatureError::Unknown) => Err(format!(
            "no feature `{text}`; ca65's: {}",
            assembler::CA65_FEATURES.join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defines_in_every_spelling() {
        assert_eq!(define("DEBUG"), Ok(("DEBUG".into(), 1)));
        assert_eq!(define("_x1=7"), Ok(("_x1".into(), 7)));
        assert_eq!(define("X=$2A"), Ok(("X".into(), 42)));
        assert_eq!(define("X=0x2a"), Ok(("X".into(), 42)));
        assert_eq!(define("X=%101"), Ok(("X".into(), 5)));
        assert_eq!(define("X=-3"), Ok(("X".into(), -3)));
        assert_eq!(define("X=-0x10"), Ok(("X".into(), -16)));
        assert_eq!(define("X=$FFFFFFFF"), Ok(("X".into(), 0xFFFF_FFFF)));
        assert!(define("X=$100000000").is_err());
        assert!(define("X=--1").is_err(), "one sign only");
        assert!(define("1X=2").unwrap_err().contains("not a symbol name"));
        assert!(define("9X").is_err());
        assert!(define("=1").is_err());
        assert!(define("X=zz").unwrap_err().contains("not a number"));
        assert!(define("X=").is_err());
    }

    #[test]
    fn addresses_in_three_spellings() {
        assert_eq!(address("0x1234"), Ok(0x1234));
        assert_eq!(address("$FFFF"), Ok(0xFFFF));
        assert_eq!(address("$ff"), Ok(0xFF));
        assert_eq!(address("4660"), Ok(0x1234));
        assert_eq!(address("0"), Ok(0));
        assert!(address("65536").unwrap_err().contains("out of range"));
        assert!(address("$").unwrap_err().contains("not a number"));
        assert!(address("12ab").unwrap_err().contains("not a number"));
        assert!(address("-1").is_err());
        assert_eq!(length("0x10000"), Ok(0x10000));
    }
}
