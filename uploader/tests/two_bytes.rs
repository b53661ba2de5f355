//! hostile30 F1-F3: the robot's sums were Fletcher-16 with both sums mod
//! 256, under which two bytes changed by `+d` and `-d`, `k` apart, with
//! `d * k` a multiple of 256 (bit 7 of two bytes two apart, `$40` moved
//! four bytes, `+1`/`-1` 256 apart) sum as they did. An upload took such
//! memory for held and said "verified" with the robot running other code;
//! a table of `.word $8000` went in with 102 bytes still zero; an undo kept
//! an owner's `80 00 80` as zeros and wrote zeros back; a restore left
//! such an edit in place. Both sums are 16 bits now (`uploader::robot_sum`):
//! each case here ends with the robot holding what it must.

mod common;

use common::{Kept, robot};
use uploader::{
    Area, NoProgress, UploadImage, UploadOptions, backup, restore, upload, upload_keeping,
};

/// The changes of two bytes the narrow sums could not see: `(first
/// offset, change there, distance, change there)`.
fn unseen_by_narrow_sums() -> Vec<(usize, u8, usize, u8)> {
    let mut edits = vec![
        (40, 0x80, 2, 0x80),   // bit 7 of two bytes two apart
        (300, 0x80, 4, 0x80),  // four apart
        (611, 0xC0, 4, 0x40),  // $40 moved four bytes
        (16, 0x01, 256, 0xFF), // +1, -1 256 apart
    ];
    // +d, -d with d * k = 256, for every power of two.
    for shift in 0..8 {
        let d = 1u8 << shift;
        edits.push((700 + shift * 3, d, 256 >> shift, d.wrapping_neg()));
    }
    edits
}

/// The bytes at `range` of the virtual robot.
fn held(
    client: &mut uploader::Client<uploader::transport::VirtualTransport>,
    range: std::ops::Range<usize>,
) -> Vec<u8> {
    client.transport().robot().robot().board().memory()[range].to_vec()
}

/// Writes `bytes` at `at` by hand (the robot's owner at its monitor).
fn by_hand(
    client: &mut uploader::Client<uploader::transport::VirtualTransport>,
    at: usize,
    bytes: &[u8],
) {
    (client.transport().robot_mut().robot_mut().board_mut())
        .load(at as u16, bytes)
        .expect("RAM");
}

/// Changes `memory` at `at` by `first` and `distance` later by `second`,
/// and checks the narrow sums of the 257 bytes around them miss it.
fn edited(memory: &[u8], (at, first, distance, second): (usize, u8, usize, u8)) -> Vec<u8> {
    let mut out = memory.to_vec();
    out[at] = out[at].wrapping_add(first);
    out[at + distance] = out[at + distance].wrapping_add(second);
    let span = at..(at + 257).min(memory.len());
    if distance < span.len() {
        assert_eq!(
            uploader::fletcher16(&out[span.clone()]),
            uploader::fletcher16(&memory[span.clone()]),
            "the narrow sums' blind spot at {at}"
        );
    }
    assert_ne!(
        uploader::robot_sum(&out[span.clone()]),
        uploader::robot_sum(&memory[span]),
        "the robot's sums see it"
    );
    out
}

/// F1 (C1, C2): an installed extension edited by hand in two bytes is
/// written again by the next upload of it, whatever the distance and the
/// change, and so is an image that differs from what the robot holds by
/// two swapped constants.
#[test]
fn an_upload_writes_two_bytes_the_narrow_sums_took_for_held() {
    let options = UploadOptions::default();
    let image = common::extension_big();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &image, &options, &mut NoProgress).expect("installed");
    let area = &image.areas()[0];
    let range = usize::from(area.address)..usize::from(area.address) + area.bytes.len();
    // As installed: its chain slot holds the hook's earlier target.
    let installed = held(&mut client, range.clone());
    assert_eq!(installed[3..], area.bytes[3..]);
    for edit in unseen_by_narrow_sums() {
        let changed = edited(&installed, edit);
        by_hand(&mut client, range.start, &changed);
        let report = upload(&mut client, &image, &options, &mut NoProgress)
            .unwrap_or_else(|error| panic!("{edit:?}: {error}"));
        assert!(report.written_bytes() >= 2, "{edit:?}: {report:?}");
        assert!(
            held(&mut client, range.clone()) == installed,
            "{edit:?}: the robot does not hold the image"
        );
    }
}

/// F1 (C3): a table of `.word $8000` uploaded onto zeroed RAM (a first
/// upload) is written whole: a range with an even count of `$80`s on
/// places of one parity summed as zeros do.
#[test]
fn a_table_of_words_goes_in_whole_over_zeros() {
    let mut bytes = vec![0x60]; // RTS
    for _ in 0..400 {
        bytes.extend([0x00, 0x80]);
    }
    let image = UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes: bytes.clone(),
        }],
        vec![],
    )
    .expect("an image");
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &image, &options, &mut NoProgress).expect("uploaded");
    let wrong = held(&mut client, 0x0400..0x0400 + bytes.len())
        .iter()
        .zip(&bytes)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(wrong, 0, "{wrong} bytes not written");
}

/// F2: an owner's bytes in free RAM that the narrow sums took for zeros
/// are kept by the upload that overwrites them, and its undo puts them
/// back.
#[test]
fn an_undo_puts_back_an_owners_bytes_that_summed_as_zeros() {
    let owners: [(usize, &[u8]); 4] = [
        (0x0603, &[0x80, 0x00, 0x80]),
        (0x0658, &[0x40, 0x00, 0x00, 0x00, 0xC0]),
        (0x0700, &[0x01, 0xFE, 0x01]),
        (0x07A0, &[0x80, 0x00, 0x80]),
    ];
    for options in [
        UploadOptions::default(),
        UploadOptions {
            delta: false,
            ..UploadOptions::default()
        },
    ] {
        let mut client = uploader::client(robot(), &options.profile);
        for (at, bytes) in owners {
            by_hand(&mut client, at, bytes);
        }
        // The hooks, and user RAM with the table (the ROM's own RAM
        // between them changes with every command).
        let mine = |client: &mut uploader::Client<uploader::transport::VirtualTransport>| {
            [held(client, 0x0200..0x0206), held(client, 0x0400..0x1000)].concat()
        };
        let before = mine(&mut client);
        let mut kept = Kept::default();
        let image = common::extension_big();
        upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut kept)
            .expect("uploaded");
        let file = kept.0.expect("kept");
        for (at, bytes) in owners {
            let in_file: Vec<Option<u8>> = (0..bytes.len())
                .map(|i| file.byte_at((at + i) as u32))
                .collect();
            let wanted: Vec<Option<u8>> = bytes.iter().copied().map(Some).collect();
            assert_eq!(in_file, wanted, "${at:04X} kept (delta: {})", options.delta);
        }
        let undo = UploadOptions {
            undo: true,
            ..options.clone()
        };
        restore(&mut client, &file, &undo, &mut NoProgress).expect("undone");
        let after = mine(&mut client);
        let differs: Vec<(usize, u8, u8)> = (0..before.len())
            .filter(|&i| before[i] != after[i])
            .map(|i| {
                (
                    if i < 6 { 0x0200 + i } else { 0x0400 + i - 6 },
                    before[i],
                    after[i],
                )
            })
            .collect();
        assert!(
            differs.is_empty(),
            "not as before the upload (delta: {}): {differs:04X?}",
            options.delta
        );
    }
}

/// F3: a backup restored over a robot whose extension was edited in two
/// bytes since puts those bytes back.
#[test]
fn a_restore_puts_back_two_bytes_the_narrow_sums_took_for_held() {
    let options = UploadOptions::default();
    let image = common::extension_big();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &image, &options, &mut NoProgress).expect("installed");
    let saved = backup(&mut client, &options.profile).expect("a backup");
    let before = held(&mut client, 0x0400..0x1000);
    let area = &image.areas()[0];
    for edit in unseen_by_narrow_sums() {
        by_hand(
            &mut client,
            usize::from(area.address),
            &edited(&area.bytes, edit),
        );
        restore(&mut client, &saved, &options, &mut NoProgress)
            .unwrap_or_else(|error| panic!("{edit:?}: {error}"));
        assert!(
            held(&mut client, 0x0400..0x1000) == before,
            "{edit:?}: not as the backup"
        );
    }
}

/// hostile31 F1: an edit that only moves bytes about (two instructions
/// whose bytes add up alike swapped) balances both of the robot's sums:
/// the `--replace` upload of it took the old bytes for held. Given the
/// earlier version as it was uploaded (`UploadOptions::previous`, which
/// `scorpion upload` keeps beside its undo file), the ranges where the
/// two differ are written whatever the sums say.
#[test]
fn an_edit_that_balances_the_sums_is_written_where_the_earlier_version_is_known() {
    let v1 = common::extension_big();
    let mut areas = v1.areas().to_vec();
    areas[0].bytes[300..304].copy_from_slice(&[0xA9, 0x10, 0x69, 0x50]);
    let v1 = UploadImage::new(areas.clone(), v1.hooks().to_vec()).expect("v1");
    areas[0].bytes[300..304].copy_from_slice(&[0x69, 0x50, 0xA9, 0x10]);
    let v2 = UploadImage::new(areas, v1.hooks().to_vec()).expect("v2");
    assert_eq!(
        uploader::robot_sum(&v1.areas()[0].bytes),
        uploader::robot_sum(&v2.areas()[0].bytes),
        "the sums balance"
    );
    let at = 0x0400 + 300;
    for (previous, written) in [(vec![], false), (vec![v1.clone()], true)] {
        let options = UploadOptions::default();
        let mut client = uploader::client(robot(), &options.profile);
        upload(&mut client, &v1, &options, &mut NoProgress).expect("v1 installed");
        let replace = UploadOptions {
            replace: true,
            previous,
            ..UploadOptions::default()
        };
        let report = upload(&mut client, &v2, &replace, &mut NoProgress).expect("v2 uploaded");
        // The range the edit lies in (whole: the sums took it for held)
        // and the table entry, not the chain slot's range (the upload
        // fills the slot; the earlier version had it as linked).
        assert!(
            !report
                .written
                .iter()
                .any(|&(start, len)| start <= 0x0401 && 0x0401 < usize::from(start) + len),
            "{:?}",
            report.written
        );
        let wanted = &v2.areas()[0].bytes[300..304];
        assert_eq!(
            held(&mut client, at..at + 4) == wanted,
            written,
            "the earlier version given: {written}"
        );
    }
}
