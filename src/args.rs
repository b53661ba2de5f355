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

#[cfg(test)]
mod tests {
    use super::*;

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
