//! Raw binary and the three record formats (uploader.md section 3 gives
//! the record layouts).

use core::fmt::Write as _;

use crate::error::Error;
use crate::image::{Image, LoadArea};

/// Data bytes per Intel HEX and S-record record (what most programmers use).
const RECORD_BYTES: usize = 16;
/// The KIM-1 tape format's maximum record length.
const KIM_RECORD_BYTES: usize = 24;

/// The loaded areas' bytes back to back, in output order (ld65's `bin`).
/// A link's own output ([`crate::Linked::write`]) also leaves out the BSS
/// segments inside written areas, as ld65 does; an image read back from
/// ELF no longer knows which area a segment was in, and keeps every byte.
#[must_use]
pub fn write_bin(image: &Image) -> Vec<u8> {
    let mut out = Vec::new();
    for area in &image.areas {
        append_without(&mut out, area, &[]);
    }
    out
}

/// Appends `area`'s bytes to `out` but those whose load address lies in
/// one of `holes` (`start..end`).
pub(crate) fn append_without(out: &mut Vec<u8>, area: &LoadArea, holes: &[(u64, u64)]) {
    let start = u64::from(area.load);
    out.extend(area.bytes.iter().enumerate().filter_map(|(index, byte)| {
        let address = start + index as u64;
        let inside = holes
            .iter()
            .any(|(from, to)| (*from..*to).contains(&address));
        (!inside).then_some(*byte)
    }));
}

/// Each area cut into records of at most `max` bytes that do not cross a
/// `boundary`-aligned address: (address, bytes).
fn records(image: &Image, max: usize, boundary: u64) -> Vec<(u64, &[u8])> {
    let mut out = Vec::new();
    for area in &image.areas {
        let mut address = u64::from(area.load);
        let mut rest = area.bytes.as_slice();
        while !rest.is_empty() {
            let to_boundary = (boundary - address % boundary) as usize;
            let take = rest.len().min(max).min(to_boundary);
            out.push((address, &rest[..take]));
            rest = &rest[take..];
            address += take as u64;
        }
    }
    out
}

fn hex_bytes(line: &mut String, bytes: &[u8]) {
    for byte in bytes {
        let _ = write!(line, "{byte:02X}");
    }
}

/// Intel HEX: `:LLAAAATT...CC`, an `04` record whenever the upper 16
/// address bits change, `:00000001FF` at the end.
#[must_use]
pub fn write_ihex(image: &Image) -> Vec<u8> {
    fn record(out: &mut String, address: u16, kind: u8, data: &[u8]) {
        let mut sum = data.len() as u8;
        sum = sum
            .wrapping_add((address >> 8) as u8)
            .wrapping_add(address as u8)
            .wrapping_add(kind);
        for byte in data {
            sum = sum.wrapping_add(*byte);
        }
        let _ = write!(out, ":{:02X}{address:04X}{kind:02X}", data.len());
        hex_bytes(out, data);
        let _ = writeln!(out, "{:02X}", sum.wrapping_neg());
    }
    let mut out = String::new();
    let mut upper = 0u64;
    for (address, data) in records(image, RECORD_BYTES, 0x1_0000) {
        if address >> 16 != upper {
            upper = address >> 16;
            record(&mut out, 0, 0x04, &(upper as u16).to_be_bytes());
        }
        record(&mut out, address as u16, 0x00, data);
    }
    record(&mut out, 0, 0x01, &[]);
    out.into_bytes()
}

/// Motorola S-records with the narrowest address width that holds the
/// image: `S1`/`S9` up to $FFFF, `S2`/`S8` up to $FFFFFF, else `S3`/`S7`.
#[must_use]
pub fn write_srec(image: &Image) -> Vec<u8> {
    fn record(out: &mut String, kind: u8, address: u64, address_len: usize, data: &[u8]) {
        let count = (address_len + data.len() + 1) as u8;
        let address_bytes = &address.to_be_bytes()[8 - address_len..];
        let mut sum = count;
        for byte in address_bytes.iter().chain(data) {
            sum = sum.wrapping_add(*byte);
        }
        let _ = write!(out, "S{kind}{count:02X}");
        hex_bytes(out, address_bytes);
        hex_bytes(out, data);
        let _ = writeln!(out, "{:02X}", !sum);
    }
    let top = image
        .areas
        .iter()
        .map(|area| area.end().saturating_sub(1))
        .chain([u64::from(image.entry)])
        .max()
        .unwrap_or(0);
    let (data_kind, end_kind, address_len) = match top {
        0..=0xFFFF => (1, 9, 2),
        0x1_0000..=0xFF_FFFF => (2, 8, 3),
        _ => (3, 7, 4),
    };
    let mut out = String::new();
    record(&mut out, 0, 0, 2, b"scorpion");
    let data = records(image, RECORD_BYTES, 1 << 32);
    for (address, bytes) in &data {
        record(&mut out, data_kind, *address, address_len, bytes);
    }
    match data.len() {
        count @ 0..=0xFFFF => record(&mut out, 5, count as u64, 2, &[]),
        count => record(&mut out, 6, count as u64, 3, &[]),
    }
    record(&mut out, end_kind, u64::from(image.entry), address_len, &[]);
    out.into_bytes()
}

/// MOS Technology / KIM-1 paper tape: `;LLAAAA` data `CCCC` (16-bit sum of
/// the length, address and data bytes), then `;00NNNNCCCC` with the record
/// count. Lines end in CR LF; the NULs and XOFF of real paper tape are not
/// written (the KIM-1 loader skips to each `;`).
///
/// # Errors
/// [`Error::Format`] when an area lies above $FFFF.
pub fn write_kim(image: &Image) -> Result<Vec<u8>, Error> {
    if let Some(area) = image.areas.iter().find(|area| area.end() > 0x1_0000) {
        return Err(Error::Format {
            format: "kim".into(),
            reason: format!(
                "the area at ${:X} ends past $FFFF; KIM-1 tape has 16-bit addresses",
                area.load
            ),
        });
    }
    let mut out = String::new();
    let data = records(image, KIM_RECORD_BYTES, 0x1_0000);
    for (address, bytes) in &data {
        let address = *address as u16;
        let mut sum = bytes.len() as u16 + (address >> 8) + (address & 0xFF);
        for byte in *bytes {
            sum = sum.wrapping_add(u16::from(*byte));
        }
        let _ = write!(out, ";{:02X}{address:04X}", bytes.len());
        hex_bytes(&mut out, bytes);
        let _ = write!(out, "{sum:04X}\r\n");
    }
    let count = data.len() as u16;
    let sum = (count >> 8) + (count & 0xFF);
    let _ = write!(out, ";00{count:04X}{sum:04X}\r\n");
    Ok(out.into_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::LoadArea;

    fn image(load: u32, bytes: Vec<u8>) -> Image {
        Image {
            entry: load,
            areas: vec![LoadArea {
                load,
                run: load,
                bytes,
            }],
            ..Image::default()
        }
    }

    #[test]
    fn kim_checksum_matches_the_published_example() {
        // uploader.md: `;180000FFEEDD...8899` ends `0AFC`.
        let bytes = vec![
            0xFF, 0xEE, 0xDD, 0xCC, 0xBB, 0xAA, 0x00, 0x99, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33,
            0x22, 0x11, 0x00, 0xFF, 0xEE, 0xDD, 0xCC, 0xBB, 0xAA, 0x99,
        ];
        let text = String::from_utf8(write_kim(&image(0, bytes)).unwrap()).unwrap();
        let first = text.lines().next().unwrap();
        assert!(first.starts_with(";180000FFEEDD"), "{first}");
        assert_eq!(text.lines().nth(1), Some(";0000010001"));
    }

    #[test]
    fn ihex_and_srec_records() {
        let img = image(0x1000, vec![0xA9, 0x01, 0x60]);
        let hex = String::from_utf8(write_ihex(&img)).unwrap();
        assert_eq!(hex, ":03100000A90160E3\n:00000001FF\n");
        let srec = String::from_utf8(write_srec(&img)).unwrap();
        let lines: Vec<&str> = srec.lines().collect();
        assert_eq!(lines[1], "S1061000A90160DF");
        assert_eq!(lines[2], "S5030001FB");
        assert_eq!(lines[3], "S9031000EC");
    }

    #[test]
    fn wide_addresses_pick_wider_records() {
        let img = image(0x1_FFF8, vec![0x55; 16]);
        let hex = String::from_utf8(write_ihex(&img)).unwrap();
        assert!(hex.starts_with(":020000040001F9\n:08FFF800"), "{hex}");
        assert!(hex.contains(":020000040002F8\n:08000000"), "{hex}");
        let srec = String::from_utf8(write_srec(&img)).unwrap();
        assert!(srec.lines().nth(1).unwrap().starts_with("S2"));
        assert!(write_kim(&img).is_err());
    }
}
