//! Where a restore's hooks lead. A file made by hand (its checksum made
//! again) whose hook's way loops or stops the CPU had it hooked, exit 0
//! (hostile10 F10); an undo of an upload that a later one was chained
//! ahead of unhooked that later one too, and the later one's undo then
//! hooked code the first undo had taken away (fresh10 F20, hostile11 F2).

mod common;

use common::{Kept, extension, extension_at, robot};
use isa::objfmt::HookKind;
use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use uploader::{Error, NoProgress, UploadOptions, backup, restore, upload, upload_keeping};

fn hook(client: &mut uploader::Client<uploader::transport::VirtualTransport>) -> u16 {
    let memory = client.transport().robot().robot().board().memory();
    let at = usize::from(HOOK_UNKNOWN);
    u16::from_le_bytes([memory[at + 1], memory[at + 2]])
}

#[test]
fn a_file_whose_hook_loops_or_stops_the_cpu_is_not_hooked() {
    let image = extension(512, 3);
    let options = UploadOptions::default();
    for (code, at, slot, why) in [
        // JMP to itself.
        (vec![0x4C, 0x00, 0x06], 0x0600, None, "comes back"),
        // BCC to itself, run on the host.
        (vec![0x90, 0xFE], 0x0600, None, "comes back"),
        // NOP NOP JAM.
        (vec![0xEA, 0xEA, 0x02], 0x0600, None, "stops the CPU"),
        // hostile15 F3: one instruction before the JMP hid where it goes:
        // a loop, the ROM's zero page, the middle of the ROM.
        (vec![0xEA, 0x4C, 0x01, 0x06], 0x0600, None, "comes back"),
        (
            vec![0xEA, 0x4C, 0x21, 0x00],
            0x0600,
            None,
            "where no extension's code is",
        ),
        (
            vec![0xEA, 0x4C, 0x00, 0xF8],
            0x0600,
            None,
            "where no extension's code is",
        ),
        // hostile15 F9: a loop whose X counts round (the same registers
        // again after 256 passes), and a bare RTS.
        (
            vec![0xEA, 0xE8, 0x4C, 0x01, 0x06],
            0x0600,
            None,
            "comes back",
        ),
        (vec![0x60], 0x0600, None, "returns where nothing called it"),
        // hostile16 F1: a call to itself, for ever.
        (vec![0xEA, 0x20, 0x00, 0x06], 0x0600, None, "comes back"),
        (vec![0x20, 0x00, 0x06], 0x0600, None, "comes back"),
        // A call into the ROM's zero page; one to a subroutine that jumps
        // back to the start.
        (
            vec![0x20, 0x21, 0x00],
            0x0600,
            None,
            "where no extension's code is",
        ),
        (
            vec![0x20, 0x06, 0x06, 0x4C, 0x00, 0x06, 0x4C, 0x00, 0x06],
            0x0600,
            None,
            "comes back",
        ),
        // A loop that counts but never gets out: the same registers
        // again, nothing written between.
        (
            vec![0xA2, 0xF0, 0xE8, 0xD0, 0xFD, 0x90, 0xF9],
            0x0600,
            None,
            "comes back",
        ),
        // The extension's handler (JMP $0400, its chain slot), whose slot
        // the file points back at the handler: a loop through the table.
        (vec![], 0x0403, Some(0x0403), "comes back"),
        // hostile11 F7: the slot sent into the ROM's own RAM (its command
        // buffer), to a ROM subroutine, to the ROM's reset.
        (vec![], 0x0403, Some(0x0300), "where no extension's code is"),
        (
            vec![],
            0x0403,
            Some(romlib::symbols::PUTCH),
            "where no extension's code is",
        ),
        (vec![], 0x0403, Some(0xFF27), "where no extension's code is"),
    ] {
        let mut client = uploader::client(robot(), &options.profile);
        upload(&mut client, &image, &options, &mut NoProgress).expect("an extension installed");
        let mut file = backup(&mut client, &options.profile).expect("a backup");
        let mut put = |address: u16, bytes: &[u8]| {
            for area in &mut file.areas {
                let start = usize::from(address).wrapping_sub(usize::from(area.address));
                if start + bytes.len() <= area.bytes.len() {
                    area.bytes[start..start + bytes.len()].copy_from_slice(bytes);
                    return;
                }
            }
            panic!("${address:04X} is not in the backup");
        };
        put(0x0600, &code);
        if let Some(slot) = slot {
            put(0x0401, &slot.to_le_bytes());
        }
        // The table lists nothing: a hook past what it lists is refused
        // before the way is followed (hostile22 F9), which this is about.
        put(0x0F80, &[0]);
        // Nor the entry's bytes: the way into a freed entry's memory is
        // refused before too (hostile25 F6).
        put(0x0F88, &[0; romlib::installed::ENTRY_LEN]);
        file.hooks = vec![
            (HookKind::Unknown, at),
            (HookKind::Loop, romlib::symbols::ROM_LOOP),
        ];
        file.witnesses.clear();
        let error =
            restore(&mut client, &file, &options, &mut NoProgress).expect_err("the way is refused");
        let said = error.to_string();
        assert!(
            matches!(error, Error::RestoreChainBroken { .. }) && said.contains(why),
            "{code:02X?} {slot:04X?}: {said}"
        );
        assert_eq!(hook(&mut client), BAD_COMMAND, "left at the ROM's target");
        assert!(client.probe().is_ok(), "the robot answers");
    }
}

#[test]
fn an_undo_of_an_upload_a_later_one_chained_ahead_of_is_refused() {
    let (options, _, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    let (first, second) = (extension_at(0x0500), extension_at(0x0800));
    let mut kept_first = Kept::default();
    upload_keeping(
        &mut client,
        &first,
        &options,
        &mut NoProgress,
        &mut kept_first,
    )
    .expect("the first");
    let mut kept_second = Kept::default();
    upload_keeping(
        &mut client,
        &second,
        &options,
        &mut NoProgress,
        &mut kept_second,
    )
    .expect("the second");
    let (kept_first, kept_second) = (kept_first.0.expect("kept"), kept_second.0.expect("kept"));
    let before = held(&mut client);
    let error = restore(&mut client, &kept_first, &undo, &mut NoProgress)
        .expect_err("the later upload is ahead of it");
    assert!(
        matches!(
            error,
            Error::UndoNotLast {
                current: 0x0803,
                ..
            }
        ),
        "{error}"
    );
    assert!(error.to_string().contains("$0803 (extension "), "{error}");
    assert!(held(&mut client) == before, "nothing written");
    // In the order they were made, both undo.
    restore(&mut client, &kept_second, &undo, &mut NoProgress).expect("the later one");
    assert_eq!(hook(&mut client), 0x0503);
    restore(&mut client, &kept_first, &undo, &mut NoProgress).expect("then the first");
    assert_eq!(hook(&mut client), BAD_COMMAND);
    // A backup restores the robot whole: what is hooked now goes.
    let mut client = uploader::client(robot(), &options.profile);
    let empty = backup(&mut client, &options.profile).expect("a backup");
    upload(&mut client, &first, &options, &mut NoProgress).expect("installed");
    restore(&mut client, &empty, &options, &mut NoProgress).expect("a backup is not an undo");
    assert_eq!(hook(&mut client), BAD_COMMAND);
}

/// recheck18 F1: an extension, a second in front of it, then an edit of
/// the first (its data; the handler where it was) with `--replace`. The
/// undo of the second found HOOK_UNKNOWN leading where it led before the
/// second and passed its check for later uploads; it put the table back
/// as the second found it, listing the old image over the edit. The undo
/// compares the table's entries with the file's: the later one is named,
/// nothing is written, and the undos in the right order go through.
#[test]
fn an_undo_refuses_to_put_back_an_entry_a_later_upload_wrote() {
    let (options, replace, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    let first = extension_at(0x0500);
    let in_front = extension_at(0x0800);
    let mut bytes = first.areas()[0].bytes.clone();
    bytes[40] = 0x07;
    let edited = uploader::UploadImage::new(
        vec![uploader::Area {
            address: 0x0500,
            bytes,
        }],
        first.hooks().to_vec(),
    )
    .expect("an image");
    let mut kept = [Kept::default(), Kept::default(), Kept::default()];
    for ((image, options), kept) in [
        (&first, &options),
        (&in_front, &options),
        (&edited, &replace),
    ]
    .into_iter()
    .zip(&mut kept)
    {
        upload_keeping(&mut client, image, options, &mut NoProgress, kept).expect("uploaded");
    }
    let [_, kept_in_front, kept_edit] = kept.map(|kept| kept.0.expect("kept"));
    let before = held(&mut client);
    let error = restore(&mut client, &kept_in_front, &undo, &mut NoProgress)
        .expect_err("the edit wrote the table after it");
    assert!(
        matches!(error, Error::UndoEntryChanged { id, .. } if id == edited.id()),
        "{error}"
    );
    assert!(held(&mut client) == before, "nothing written");
    restore(&mut client, &kept_edit, &undo, &mut NoProgress).expect("the edit first");
    let installed = uploader::read_installed(&mut client, &options.profile).expect("the table");
    let ids: Vec<u32> = installed.iter().map(|entry| entry.id).collect();
    assert!(
        ids.contains(&first.id()) && ids.contains(&in_front.id()),
        "{ids:06X?}"
    );
    restore(&mut client, &kept_in_front, &undo, &mut NoProgress).expect("then the one in front");
    let installed = uploader::read_installed(&mut client, &options.profile).expect("the table");
    let ids: Vec<u32> = installed.iter().map(|entry| entry.id).collect();
    assert_eq!(ids, [first.id()]);
    assert_eq!(hook(&mut client), 0x0503);
}

/// recheck16 F4: a backup of a robot whose hook was already broken (sent
/// by hand into a loop) said only "saved", and the user learnt of it at
/// the restore that refused it. The backup names the way, as the restore
/// refuses it.
#[test]
fn a_backup_of_a_robot_whose_hook_is_broken_says_so() {
    let (options, mut client) = one_installed();
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    assert_eq!(saved.broken, [], "an extension's working chain");
    {
        let board = client.transport().robot_mut().robot_mut().board_mut();
        board.load(0x0800, &[0x4C, 0x00, 0x08]).expect("RAM");
        board
            .load(HOOK_UNKNOWN + 1, &0x0800u16.to_le_bytes())
            .expect("RAM");
    }
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    assert_eq!(saved.broken.len(), 1, "{:?}", saved.broken);
    let broken = &saved.broken[0];
    assert_eq!((broken.hook, broken.target), (HookKind::Unknown, 0x0800));
    assert!(broken.why.contains("comes back"), "{}", broken.why);
    assert_eq!(broken.path, "$0800 -> $0800");
    let error = restore(&mut client, &saved.backup, &options, &mut NoProgress)
        .expect_err("the way is refused at the restore, as the backup said");
    // The table lists the extension the hook no longer reaches: refused
    // before a byte is written (hostile22 F9).
    assert!(
        matches!(error, Error::BackupRefused { ref reason } if reason.contains("$0800")),
        "{error}"
    );
}

/// fresh17 F6: the undo of an upload that replaced an extension (an edit
/// away from the handler, the usual one) was refused as "a later upload
/// was chained ahead" where the hook led to the new image's handler at
/// another place than the old one's, whose bytes the upload did not
/// rewrite, so the file did not hold them (the old code moved a
/// replacement behind another extension to the head). The file witnesses
/// the table entry the upload wrote: that names the image it undoes.
#[test]
fn the_undo_of_a_replacement_whose_handler_did_not_change_goes_through() {
    let (options, replace, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    // 512 bytes at $0400: its chain slot's JMP first, two handlers (`JMP
    // $0400`) at $0480 and $0490, far from the slot and from the edit;
    // the first image hooks the one, the edit the other.
    let mut bytes = extension(512, 3).areas()[0].bytes.clone();
    bytes[0x80..0x83].copy_from_slice(&[0x4C, 0x00, 0x04]);
    bytes[0x90..0x93].copy_from_slice(&[0x4C, 0x00, 0x04]);
    let hooked_at = |handler: u16, bytes: Vec<u8>| {
        uploader::UploadImage::new(
            vec![uploader::Area {
                address: 0x0400,
                bytes,
            }],
            vec![isa::objfmt::HookRecord {
                kind: HookKind::Unknown,
                handler,
                chain: Some(0x0401),
            }],
        )
        .expect("an image")
    };
    let first = hooked_at(0x0480, bytes.clone());
    upload(&mut client, &first, &options, &mut NoProgress).expect("the first");
    bytes[300] ^= 0x5A;
    let edited = hooked_at(0x0490, bytes);
    let mut kept = Kept::default();
    upload_keeping(&mut client, &edited, &replace, &mut NoProgress, &mut kept).expect("replaced");
    assert_eq!(hook(&mut client), 0x0490, "the edit hooked");
    restore(&mut client, &kept.0.expect("kept"), &undo, &mut NoProgress).expect("undone");
    assert_eq!(hook(&mut client), 0x0480, "the hook as it was");
    let memory = client.transport().robot().robot().board().memory();
    assert_eq!(
        memory[0x0400 + 300],
        first.areas()[0].bytes[300],
        "the first's byte back"
    );
}

/// fresh17 F4: a backup of a robot with an operating system in KIM-bus
/// RAM said nothing of it; a restore after the OS had gone was refused
/// (its code only witnessed). The backup says so as it saves.
#[test]
fn a_backup_names_the_extensions_it_does_not_save() {
    let (options, mut client) = one_installed();
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    assert_eq!(saved.outside, [], "user RAM is saved");
    upload(
        &mut client,
        &extension_at(0x1000),
        &options,
        &mut NoProgress,
    )
    .expect("on the KIM bus");
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    let outside: Vec<_> = saved
        .outside
        .iter()
        .map(|entry| entry.extents.clone())
        .collect();
    assert_eq!(outside, [vec![0x1000..=0x103F]]);
}

/// A robot with the extension at $0400 uploaded, and the options used.
fn one_installed() -> (
    UploadOptions,
    uploader::Client<uploader::transport::VirtualTransport>,
) {
    installed_at(0x0400)
}

/// The robot with one extension at `base` installed, and the options.
fn installed_at(
    base: u16,
) -> (
    UploadOptions,
    uploader::Client<uploader::transport::VirtualTransport>,
) {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &extension_at(base), &options, &mut NoProgress).expect("installed");
    (options, client)
}

/// recheck17 F3: a file whose HOOK_UNKNOWN way loops (a chain slot sent
/// to itself by hand before the backup) and whose HOOK_LOOP is fine: the
/// restore left both at the ROM's targets, and the loop handler of the
/// robot's operating system stopped running without a word. The broken
/// one stays at the ROM's target, said; the other is restored.
#[test]
fn a_broken_hook_in_a_file_does_not_take_the_other_down() {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    // $0600  JMP chain      ; HOOK_LOOP's handler, its slot $0601
    let os = uploader::UploadImage::new(
        vec![uploader::Area {
            address: 0x0600,
            bytes: vec![0x4C, 0x24, 0xFF],
        }],
        vec![isa::objfmt::HookRecord {
            kind: HookKind::Loop,
            handler: 0x0600,
            chain: Some(0x0601),
        }],
    )
    .expect("an image");
    upload(&mut client, &os, &options, &mut NoProgress).expect("the loop handler");
    let mut file = backup(&mut client, &options.profile).expect("a backup");
    for area in &mut file.areas {
        if (u32::from(area.address)..area.end()).contains(&0x0700) {
            let at = usize::from(0x0700 - area.address);
            area.bytes[at..at + 3].copy_from_slice(&[0x4C, 0x00, 0x07]);
        }
    }
    file.hooks = vec![(HookKind::Unknown, 0x0700), (HookKind::Loop, 0x0600)];
    file.witnesses.clear();
    let error = restore(&mut client, &file, &options, &mut NoProgress).expect_err("refused");
    assert!(matches!(error, Error::RestoreChainBroken { .. }), "{error}");
    assert_eq!(hook(&mut client), BAD_COMMAND, "the broken one at the ROM");
    let memory = client.transport().robot().robot().board().memory();
    let at = usize::from(romlib::symbols::HOOK_LOOP) + 1;
    assert_eq!(memory[at..at + 2], [0x00, 0x06], "the loop handler hooked");
}

/// The default upload options, with `--replace`, and an undo's.
fn plain_replace_undo() -> (UploadOptions, UploadOptions, UploadOptions) {
    let options = UploadOptions::default();
    let replace = UploadOptions {
        replace: true,
        ..options.clone()
    };
    let undo = UploadOptions {
        undo: true,
        ..options.clone()
    };
    (options, replace, undo)
}

/// The hooks, and user RAM with the table.
fn held(client: &mut uploader::Client<uploader::transport::VirtualTransport>) -> Vec<u8> {
    let memory = client.transport().robot().robot().board().memory();
    [&memory[0x0200..0x0206], &memory[0x0400..0x1000]].concat()
}

/// hostile19 F1: an undo file that takes out an extension (it holds the
/// sum of the entry its upload wrote) without the table's flags there
/// went through, "verified", and left the table listing an entry of
/// zeros. Such a file is refused before anything is written.
#[test]
fn an_undo_file_that_does_not_free_the_entry_it_takes_out_is_refused() {
    let (options, _, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    let mut kept = Kept::default();
    let image = extension_at(0x0700);
    upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut kept).expect("uploaded");
    let mut file = kept.0.expect("kept");
    let (table, entries) = options.profile.table.expect("a table");
    file.areas = without(&file.areas, table..=table + entries as u16 - 1);
    let before = held(&mut client);
    let error = restore(&mut client, &file, &undo, &mut NoProgress).expect_err("refused");
    assert!(
        error
            .to_string()
            .contains("does not put back the table there"),
        "{error}"
    );
    assert!(held(&mut client) == before, "nothing written");
}

/// hostile19 F2: a witness in the I/O page (a read of the serial chip's
/// data register eats a received byte), or a table entry record off the
/// table's entries, was read from the robot before anything else was
/// checked. Both are refused before the line is used.
#[test]
fn witnesses_outside_memory_an_extension_may_hold_are_refused_unread() {
    let (options, _, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0700),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("uploaded");
    let file = kept.0.expect("kept");
    let (table, _) = options.profile.table.expect("a table");
    let io = uploader::Witness {
        address: 0xC010,
        len: 4,
        sum: uploader::Checksum::Wide(0),
    };
    let off_entries = uploader::Witness {
        address: table,
        len: romlib::installed::ENTRY_LEN as u16,
        sum: uploader::Checksum::Wide(0),
    };
    for (witnesses, entries, what) in [
        (vec![io], vec![], "outside the memory"),
        (vec![], vec![off_entries], "not on the table's entries"),
    ] {
        let mut file = file.clone();
        file.witnesses.extend(witnesses);
        file.written_entries.extend(entries);
        let sent = client.stats().sent;
        let error = restore(&mut client, &file, &undo, &mut NoProgress).expect_err("refused");
        assert!(error.to_string().contains(what), "{error}");
        assert_eq!(client.stats().sent, sent, "the line is not used: {error}");
    }
}

/// `areas` without the bytes in `gone`.
fn without(areas: &[uploader::Area], gone: std::ops::RangeInclusive<u16>) -> Vec<uploader::Area> {
    let mut kept: Vec<uploader::Area> = Vec::new();
    for area in areas {
        for (offset, &byte) in area.bytes.iter().enumerate() {
            let address = area.address.wrapping_add(offset as u16);
            if gone.contains(&address) {
                continue;
            }
            match kept.last_mut() {
                Some(last)
                    if u32::from(last.address) + last.bytes.len() as u32 == u32::from(address) =>
                {
                    last.bytes.push(byte);
                }
                _ => kept.push(uploader::Area {
                    address,
                    bytes: vec![byte],
                }),
            }
        }
    }
    kept
}

/// hostile19 F4: a backup of a robot whose table was damaged by hand said
/// only "saved"; its restore moved the hooks to the ROM and then failed,
/// every time. The backup says so, and the restore refuses it before
/// anything moves.
#[test]
fn a_backup_of_a_damaged_table_says_so_and_its_restore_moves_nothing() {
    let (options, mut client) = one_installed();
    let (table, _) = options.profile.table.expect("a table");
    // The MORE bit on an entry that continues none.
    by_hand(&mut client, table + 2, &[0xC0]);
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    let damaged = saved.damaged_table.expect("said");
    assert!(damaged.contains("continues no entry"), "{damaged}");
    let before = held(&mut client);
    let error =
        restore(&mut client, &saved.backup, &options, &mut NoProgress).expect_err("refused");
    assert!(error.to_string().contains("does not decode"), "{error}");
    assert!(held(&mut client) == before, "nothing moved");
}

/// A keeper that cannot keep anything (a full disk).
struct CannotKeep;

impl uploader::Keep for CannotKeep {
    fn keep(&mut self, _overwritten: &uploader::Backup) {}

    fn failed(&self) -> Option<String> {
        Some("No space left on device".to_owned())
    }
}

/// hostile20 F1: an upload whose undo file could not be written (a full
/// disk, a directory that takes no file) warned and changed the robot all
/// the same, exit 0, with no record of what it held. It stops before it
/// writes anything, by either path, a `--replace` too.
#[test]
fn an_upload_that_cannot_keep_its_undo_writes_nothing() {
    for loader in [
        uploader::LoaderChoice::Never,
        uploader::LoaderChoice::Always,
    ] {
        let (options, mut client) = one_installed();
        let options = UploadOptions { loader, ..options };
        let replace = UploadOptions {
            replace: true,
            ..options.clone()
        };
        let mut edited = extension_at(0x0400).areas()[0].bytes.clone();
        edited[40] = 0x07;
        let edited = uploader::UploadImage::new(
            vec![uploader::Area {
                address: 0x0400,
                bytes: edited,
            }],
            extension_at(0x0400).hooks().to_vec(),
        )
        .expect("an image");
        for (image, options) in [(extension_at(0x0800), &options), (edited, &replace)] {
            let before = held(&mut client);
            let error = upload_keeping(
                &mut client,
                &image,
                options,
                &mut NoProgress,
                &mut CannotKeep,
            )
            .expect_err("stopped");
            assert!(
                matches!(error, Error::UndoNotKept { .. }),
                "{loader:?}: {error}"
            );
            assert!(held(&mut client) == before, "{loader:?}: nothing written");
        }
    }
}

/// hostile20 F4: an upload killed after its table entry went in (a
/// `--replace`, or a new extension in front) left its undo file without
/// the record of that entry, and its own undo was refused for good as "a
/// later upload wrote it". The record is kept before the entry goes out,
/// and the undo of an upload that did not finish takes it as its own:
/// wherever the line dies, the undo puts the robot back as it was.
#[test]
fn the_undo_of_an_upload_cut_anywhere_puts_the_robot_back() {
    let (options, _, undo) = plain_replace_undo();
    let undo = UploadOptions {
        interrupted: true,
        ..undo
    };
    let in_front = extension_at(0x0800);
    let sent = {
        let (_, mut client) = one_installed();
        let before = client.stats().sent;
        upload(&mut client, &in_front, &options, &mut NoProgress).expect("uploaded");
        client.stats().sent - before
    };
    let mut cut = 0;
    for at in (0..sent).step_by(common::fault_step(37)) {
        let (_, client) = one_installed();
        let mut transport = client.into_transport();
        let before = held_of(&mut transport);
        let config = uploader::transport::FaultConfig {
            stall_after: Some(at),
            ..uploader::transport::FaultConfig::none(3)
        };
        let faulty = uploader::transport::FaultyTransport::new(transport, config);
        let mut client = uploader::client(faulty, &options.profile);
        let mut kept = Kept::default();
        let result = upload_keeping(&mut client, &in_front, &options, &mut NoProgress, &mut kept);
        let mut transport = client.into_transport().into_inner();
        let Some(file) = kept.0.filter(|_| result.is_err()) else {
            continue;
        };
        cut += 1;
        let mut client = uploader::client(transport, &options.profile);
        restore(&mut client, &file, &undo, &mut NoProgress)
            .unwrap_or_else(|error| panic!("cut after {at} of {sent}: {error}"));
        transport = client.into_transport();
        assert!(
            held_of(&mut transport) == before,
            "cut after {at}: not as before"
        );
    }
    assert!(cut > 3, "{cut} cuts");
}

/// [`held`] of the robot behind `transport`.
fn held_of(transport: &mut uploader::transport::VirtualTransport) -> Vec<u8> {
    let memory = transport.robot().robot().board().memory();
    [&memory[0x0200..0x0206], &memory[0x0400..0x1000]].concat()
}

/// hostile21 F5: the eighth extension, on the KIM bus's RAM at $1000,
/// takes the table's last entry ($0FF1-$0FFF): its undo file holds one
/// record from there on, across two writable ranges that meet, and its
/// undo was refused ("outside the memory an upload may write"). It goes
/// through.
#[test]
fn the_undo_of_an_extension_after_the_tables_last_entry_goes_through() {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    for base in (0..7).map(|n| 0x0400 + n * 0x80) {
        upload(&mut client, &extension_at(base), &options, &mut NoProgress).expect("installed");
    }
    let before = backup(&mut client, &options.profile).expect("a backup");
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x1000),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("the eighth");
    // As a project's run keeps it (its images' undos merged): the table's
    // entry and the memory after it in one record.
    let kept = kept.0.expect("kept");
    let mut run = kept.clone();
    run.areas.clear();
    let file = run.going_further_back(&kept);
    assert!(
        file.areas
            .iter()
            .any(|area| area.address <= 0x0FFF && area.end() > 0x1000),
        "{:?}",
        file.areas
            .iter()
            .map(|area| (area.address, area.bytes.len()))
            .collect::<Vec<_>>()
    );
    // The table's last entry and the memory after it: one span, in two
    // writable ranges.
    let held = |address: u32| file.byte_at(address).is_some();
    assert!(held(0x0FFF) && held(0x1000), "{:?}", file.areas);
    let undo = UploadOptions {
        undo: true,
        ..UploadOptions::default()
    };
    restore(&mut client, &file, &undo, &mut NoProgress).expect("undone");
    let after = backup(&mut client, &options.profile).expect("a backup");
    assert_eq!(before.hooks, after.hooks);
    assert_eq!(before.areas, after.areas);
}

/// hostile21 F6, F8: a backup whose hook records were taken out was
/// restored "verified" with the hooks left at the ROM and every extension
/// unhooked; one with a record of "the ROM" at the serial chip's register
/// had it read (eating a received byte) and blamed on the ROM. Both are
/// refused before a byte is sent.
#[test]
fn a_backup_without_its_hooks_or_with_rom_records_off_the_rom_sends_nothing() {
    let (options, mut client) = one_installed();
    let saved = backup(&mut client, &options.profile).expect("a backup");
    let mut no_hooks = saved.clone();
    no_hooks.hooks.clear();
    let mut off_rom = saved.clone();
    off_rom.rom.push(uploader::Area {
        address: 0xC010,
        bytes: vec![0],
    });
    // hostile22 F2: memory outside what an upload may write, said as the
    // file's (it was an image's "link with --target").
    let mut io = saved.clone();
    io.areas.push(uploader::Area {
        address: 0xC000,
        bytes: vec![0; 4],
    });
    for (name, file, why) in [
        ("no hooks", no_hooks, "gives HOOK_UNKNOWN no target"),
        ("off the ROM", off_rom, "is not in the ROM"),
        (
            "the I/O page",
            io,
            "the file's memory records: $C000-$C003 is outside",
        ),
    ] {
        let sent = client.stats().sent;
        let result = restore(&mut client, &file, &options, &mut NoProgress);
        match result {
            Err(Error::BackupRefused { reason }) => {
                assert!(reason.contains(why), "{name}: {reason}")
            }
            other => panic!("{name}: {other:?}"),
        }
        assert_eq!(client.stats().sent, sent, "{name}: something was sent");
        assert_eq!(hook(&mut client), 0x0403, "{name}");
    }
    restore(&mut client, &saved, &options, &mut NoProgress).expect("the backup itself");
}

/// hostile22 F9: a file (made by hand) whose hook goes to a copy of a
/// handler in the RAM loader's place, which no entry of its table lists,
/// while the table lists the extension the hook went to: restored, exit
/// 0, the listed extension unhooked. Refused before a byte is sent.
#[test]
fn a_backup_hooking_code_its_table_does_not_list_writes_nothing() {
    let (options, mut client) = one_installed();
    let saved = backup(&mut client, &options.profile).expect("a backup");
    let mut crafted = saved.clone();
    let copy = extension_at(0x0E8C);
    let bytes = &copy.areas()[0].bytes;
    for area in &mut crafted.areas {
        for (offset, &byte) in bytes.iter().enumerate() {
            let at = 0x0E8C + offset as u32;
            if let Some(index) = at.checked_sub(u32::from(area.address))
                && (index as usize) < area.bytes.len()
            {
                area.bytes[index as usize] = byte;
            }
        }
    }
    assert_eq!(crafted.byte_at(0x0E8F), Some(0x4C), "the copy is held");
    for hook in &mut crafted.hooks {
        if hook.0 == HookKind::Unknown {
            hook.1 = 0x0E8F;
        }
    }
    // Its way ($0E8F -> $0E8C -> $0000) leads nowhere: no owner's handler
    // in front of the extension (fresh28 F1), told once the way is
    // followed, before anything is written.
    let before = held(&mut client);
    match restore(&mut client, &crafted, &options, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            assert!(
                reason.contains("code no extension its table lists"),
                "{reason}"
            );
            assert!(reason.ends_with("nothing was written"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    assert_eq!(hook(&mut client), 0x0403);
}

/// hostile22 F10 (hostile21 F7): a file that points HOOK_LOOP at the
/// extension's HOOK_UNKNOWN handler was refused once its memory was
/// written, the hooks then left at the ROM. Its own table says whose
/// handler that is: refused before a byte is sent.
#[test]
fn a_backup_pointing_a_hook_at_the_other_hooks_handler_sends_nothing() {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    // $0400 JMP slot / $0403 handler: JMP $0400; $0406 JMP slot / $0409
    // handler: JMP $0406.
    let mut bytes = vec![
        0x4C, 0x00, 0x00, 0x4C, 0x00, 0x04, 0x4C, 0x00, 0x00, 0x4C, 0x06, 0x04,
    ];
    bytes.resize(32, 0xEA);
    let image = uploader::UploadImage::new(
        vec![uploader::Area {
            address: 0x0400,
            bytes,
        }],
        vec![
            isa::objfmt::HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0403,
                chain: Some(0x0401),
            },
            isa::objfmt::HookRecord {
                kind: HookKind::Loop,
                handler: 0x0409,
                chain: Some(0x0407),
            },
        ],
    )
    .expect("an image");
    upload(&mut client, &image, &options, &mut NoProgress).expect("installed");
    let mut crafted = backup(&mut client, &options.profile).expect("a backup");
    for hook in &mut crafted.hooks {
        if hook.0 == HookKind::Loop {
            hook.1 = 0x0403;
        }
    }
    let sent = client.stats().sent;
    match restore(&mut client, &crafted, &options, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            assert!(
                reason.contains("the HOOK_UNKNOWN handler of extension"),
                "{reason}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(client.stats().sent, sent, "something was sent");
}

/// Extensions on HOOK_UNKNOWN at `bases`, each uploaded in front of the
/// ones before (`[0x0500, 0x0800]`: HOOK_UNKNOWN -> $0803 -> $0503 -> the
/// ROM), the robot, and a backup of it.
fn in_a_chain(
    bases: &[u16],
) -> (
    UploadOptions,
    uploader::Client<uploader::transport::VirtualTransport>,
    uploader::Backup,
) {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    for &at in bases {
        upload(&mut client, &extension_at(at), &options, &mut NoProgress).expect("installed");
    }
    let saved = backup(&mut client, &options.profile).expect("a backup");
    (options, client, saved)
}

/// Puts `bytes` into the robot's memory at `at` as an owner would, by
/// hand.
fn by_hand(
    client: &mut uploader::Client<uploader::transport::VirtualTransport>,
    at: u16,
    bytes: &[u8],
) {
    client
        .transport()
        .robot_mut()
        .robot_mut()
        .board_mut()
        .load(at, bytes)
        .expect("RAM");
}

/// Sets the byte at `at` in the file (the file holds it).
fn set(file: &mut uploader::Backup, at: u16, byte: u8) {
    let area = file
        .areas
        .iter_mut()
        .find(|area| at >= area.address && usize::from(at - area.address) < area.bytes.len())
        .expect("held");
    area.bytes[usize::from(at - area.address)] = byte;
}

/// Records what a restore says as it goes.
#[derive(Default)]
struct Said(Vec<uploader::Event>);

impl uploader::Progress for Said {
    fn event(&mut self, event: &uploader::Event) {
        self.0.push(event.clone());
    }
}

fn not_hooked(said: &Said) -> Vec<String> {
    said.0
        .iter()
        .filter_map(|event| match event {
            uploader::Event::RestoredNotHooked { found } => Some(found.describe()),
            _ => None,
        })
        .collect()
}

/// hostile22 F4: a file whose table frees the extension at $0500 while
/// the one at $0800 still chains to it was restored, exit 0, with
/// HOOK_UNKNOWN running through memory the table calls free (the next
/// upload may go there). Refused before a byte is sent; `backup` of a
/// robot in that state says so.
#[test]
fn a_backup_whose_hooks_run_through_a_freed_entry_sends_nothing() {
    let (options, mut client, mut crafted) = in_a_chain(&[0x0500, 0x0800]);
    let table = romlib::installed::TABLE;
    assert_eq!(
        crafted.byte_at(u32::from(table)).map(|f| f & 0x80),
        Some(0x80)
    );
    set(&mut crafted, table, 0);
    let sent = client.stats().sent;
    match restore(&mut client, &crafted, &options, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            assert!(
                reason.contains("HOOK_UNKNOWN runs through extension")
                    && reason.contains("($0500-$053F)")
                    && reason.contains("$0803 -> $0503")
                    && reason.contains("an entry the table has freed")
                    && reason.contains("nothing was written"),
                "{reason}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(client.stats().sent, sent, "something was sent");
    // The robot put in that state by hand: its backup tells it.
    by_hand(&mut client, table, &[0]);
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    let told: Vec<String> = saved.disagreements.iter().map(|d| d.describe()).collect();
    assert_eq!(
        told,
        ["HOOK_UNKNOWN runs through extension 000000 ($0500-$053F) ($0803 -> $0503), an entry the table has freed".replace("000000", &format!("{:06X}", extension_at(0x0500).id()))],
    );
}

/// recheck22 F6, hSkip: a file whose HOOK_UNKNOWN is at the ROM's target
/// while its table lists both extensions on it, or whose front extension
/// chains past the other to the ROM, was restored "verified" without a
/// word of the extensions it leaves listed and never run. It is restored
/// as it holds them (a robot is left so by an extension that takes the
/// hook whole, and a backup of it must come back), and said.
#[test]
fn a_backup_whose_hooks_skip_a_listed_extension_says_so() {
    let (options, mut client, saved) = in_a_chain(&[0x0500, 0x0800]);
    let mut at_rom = saved.clone();
    for hook in &mut at_rom.hooks {
        if hook.0 == HookKind::Unknown {
            hook.1 = BAD_COMMAND;
        }
    }
    let mut said = Said::default();
    restore(&mut client, &at_rom, &options, &mut said).expect("restored as it is");
    assert_eq!(hook(&mut client), BAD_COMMAND);
    let told = not_hooked(&said);
    assert_eq!(told.len(), 2, "{told:?}");
    assert!(
        told.iter()
            .all(|line| line.contains("but HOOK_UNKNOWN does not lead to it")),
        "{told:?}"
    );
    // The front one chains past the other, to the ROM.
    let mut skip = saved.clone();
    let [low, high] = BAD_COMMAND.to_le_bytes();
    set(&mut skip, 0x0801, low);
    set(&mut skip, 0x0802, high);
    let mut said = Said::default();
    restore(&mut client, &skip, &options, &mut said).expect("restored as it is");
    assert_eq!(hook(&mut client), 0x0803);
    let told = not_hooked(&said);
    assert_eq!(told.len(), 1, "{told:?}");
    assert!(
        told[0].contains("($0500-$053F) on HOOK_UNKNOWN")
            && told[0].ends_with(&format!("($0803 -> ${BAD_COMMAND:04X})")),
        "{told:?}"
    );
    // A backup of the robot now says it too, and a whole one says nothing.
    let now = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    assert_eq!(now.disagreements.len(), 1, "{:?}", now.disagreements);
    let mut said = Said::default();
    restore(&mut client, &saved, &options, &mut said).expect("restored");
    assert!(not_hooked(&said).is_empty(), "{:?}", said.0);
    assert_eq!(hook(&mut client), 0x0803);
}

/// fresh25 F3: an undo that puts back a hook past an extension the table
/// still lists (B in front of A, the hook sent to A by hand, then B
/// hooked again by an upload, then that upload undone) said nothing; a
/// restore of a backup of the same state said it. The undo file does not
/// hold the chain slots: told from the robot once the undo is done.
#[test]
fn an_undo_that_leaves_a_listed_extension_unhooked_says_so() {
    let (options, _, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    for at in [0x0500, 0x0800] {
        upload(&mut client, &extension_at(at), &options, &mut NoProgress).expect("installed");
    }
    by_hand(&mut client, HOOK_UNKNOWN + 1, &0x0503u16.to_le_bytes());
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0800),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("hooked again");
    assert_eq!(hook(&mut client), 0x0803);
    let mut said = Said::default();
    restore(&mut client, &kept.0.expect("kept"), &undo, &mut said).expect("undone");
    assert_eq!(hook(&mut client), 0x0503);
    let told = not_hooked(&said);
    assert_eq!(told.len(), 1, "{told:?}");
    assert!(
        told[0].contains("($0800-$083F) on HOOK_UNKNOWN")
            && told[0].ends_with(&format!("($0503 -> ${BAD_COMMAND:04X})")),
        "{told:?}"
    );
}

/// fresh25 F2: `backup` of a robot whose HOOK_UNKNOWN an owner pointed
/// at zeros said a restore would leave the hook at the ROM's target; the
/// restore refused the file as made by hand. `backup` now says the
/// restore's own refusal, and the restore gives it.
#[test]
fn a_backup_says_the_refusal_its_restore_will_give() {
    let (options, mut client) = one_installed();
    by_hand(&mut client, HOOK_UNKNOWN + 1, &0x0700u16.to_le_bytes());
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    let said = saved.refused.clone().expect("a restore of it is refused");
    assert!(said.contains("$0700, which holds $00"), "{said}");
    match restore(&mut client, &saved.backup, &options, &mut NoProgress) {
        Err(error @ Error::BackupRefused { .. }) => assert_eq!(error.to_string(), said),
        other => panic!("{other:?}"),
    }
    // A robot as an upload leaves it: nothing to say.
    let (options, mut client) = one_installed();
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    assert_eq!(saved.refused, None);
}

/// Refused, and the robot's memory as it was.
fn refused_untouched(
    client: &mut uploader::Client<uploader::transport::VirtualTransport>,
    file: &uploader::Backup,
    options: &UploadOptions,
    wanted: &[&str],
) {
    let before = held(client);
    match restore(client, file, options, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            for part in wanted {
                assert!(reason.contains(part), "{part:?}: {reason}");
            }
            assert!(reason.ends_with("nothing was written"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(client) == before, "the robot's memory changed");
}

/// hostile25 F1, F2, F5, F6: files whose ways the restore found wrong only
/// after writing, or not at all (exit 0): the table frees every entry the
/// hook runs through; the middle extension's entry points elsewhere, so
/// the way runs through unlisted code before the last one; a chain slot
/// sent back to the front (a loop); the front one's flags left out of the
/// file, which then leaves the robot's (cleared by a reset). Each is
/// refused before a byte is written.
#[test]
fn a_backup_whose_ways_run_wrong_is_refused_before_writing() {
    let table = romlib::installed::TABLE;
    let entries = romlib::installed::ENTRIES as u16;
    let entry_len = romlib::installed::ENTRY_LEN as u16;
    // F6: nothing listed, the hook into the freed entries' code.
    let (options, mut client, saved) = in_a_chain(&[0x0500, 0x0800, 0x0A00]);
    let mut freed = saved.clone();
    for slot in 0..3 {
        set(&mut freed, table + slot, 0);
    }
    refused_untouched(
        &mut client,
        &freed,
        &options,
        &["runs through extension", "($0A00-$0A3F) ($0A03)", "freed"],
    );
    // F2: the middle one's entry says $0C00 (handler and chain slot moved
    // with it): its code at $0800 is no entry's, and $0500 is behind it.
    let mut elsewhere = saved.clone();
    let middle = table + entries + entry_len;
    for (offset, byte) in [(4, 0x0C), (6, 0x0C), (8, 0x0C), (10, 0x0C)] {
        set(&mut elsewhere, middle + offset, byte);
    }
    refused_untouched(
        &mut client,
        &elsewhere,
        &options,
        &[
            "code no entry of the table lists ($0A03 -> $0803)",
            "before extension",
            "($0500-$053F)",
        ],
    );
    // F5: the last one's chain slot sent back to the front.
    let mut loops = saved.clone();
    set(&mut loops, 0x0501, 0x03);
    set(&mut loops, 0x0502, 0x0A);
    refused_untouched(
        &mut client,
        &loops,
        &options,
        &["comes back to where it has been ($0A03 -> $0803 -> $0503 -> $0A03)"],
    );
    // F5b: the middle one's chain slot sent into the middle of the last
    // one's code (its `BNE`), not its handler: told only after writing.
    let mut strays = saved.clone();
    set(&mut strays, 0x0801, 0x05);
    set(&mut strays, 0x0802, 0x05);
    refused_untouched(
        &mut client,
        &strays,
        &options,
        &[
            "runs into extension",
            "($0500-$053F) ($0A03 -> $0803 -> $0505) but not to its handler",
            "the middle of its code",
        ],
    );
    // F1: the front one's flags not in the file; the robot reset.
    let mut part = saved.clone();
    part.areas = without(&part.areas, table + 2..=table + 2);
    let reset = romlib::protocol::Command::parse(b"/1R").expect("a command");
    let _ = client.listen(&reset).expect("the line works");
    refused_untouched(
        &mut client,
        &part,
        &options,
        &[
            "on the robot as the file would leave it",
            "($0A00-$0A3F) ($0A03), an entry the table has freed",
        ],
    );
    // The file whole goes through.
    restore(&mut client, &saved, &options, &mut NoProgress).expect("restored");
    assert_eq!(hook(&mut client), 0x0A03);
}

/// hostile25 F4: on a robot whose HOOK_UNKNOWN runs through code no entry
/// lists (the front extension's flags cleared by hand), `--replace` of
/// the one behind it freed that one's entry, then refused as a loop
/// ("nothing was written"), and the undo of it was refused. The way into
/// the image through the unlisted code is refused before anything moves.
#[test]
fn a_replacement_reached_through_unlisted_code_moves_nothing() {
    let (options, mut client, _) = in_a_chain(&[0x0500, 0x0800, 0x0A00]);
    let table = romlib::installed::TABLE;
    by_hand(&mut client, table + 2, &[0]);
    let before = held(&mut client);
    let options = UploadOptions {
        replace: true,
        ..options
    };
    let edit = common::one_byte_changed(&extension_at(0x0800), 40);
    let mut kept = Kept::default();
    match upload_keeping(&mut client, &edit, &options, &mut NoProgress, &mut kept) {
        Err(Error::UnlistedWayIn { path, .. }) => assert_eq!(path, "$0A03 -> $0A00 -> $0803"),
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "the robot changed");
}

/// recheck25 R1: the same robot and a project whose last image replaces
/// the extension behind the unlisted code: the first images went in,
/// then the last was refused. The check of the project's images before
/// any is sent refuses it; without the unlisted code it passes.
#[test]
fn a_project_replacing_behind_unlisted_code_is_refused_before_any_image() {
    let (options, mut client, _) = in_a_chain(&[0x0500, 0x0800, 0x0A00]);
    let first = extension_at(0x0C00);
    let last = common::one_byte_changed(&extension_at(0x0800), 40);
    let images = [("m0", &first), ("m2", &last)];
    uploader::refuse_what_cannot_go_in(&mut client, &options.profile, &images, true)
        .expect("a replacement the chain re-points");
    by_hand(&mut client, romlib::installed::TABLE + 2, &[0]);
    match uploader::refuse_what_cannot_go_in(&mut client, &options.profile, &images, true) {
        Err(Error::UnlistedWayIn { path, .. }) => assert_eq!(path, "$0A03 -> $0A00 -> $0803"),
        other => panic!("{other:?}"),
    }
    // recheck26 N3: without `--replace`, the one behind freed too: the
    // last image goes where the table says is free, and the way runs
    // into it all the same.
    by_hand(&mut client, romlib::installed::TABLE + 1, &[0]);
    let last = extension_at(0x0800);
    let images = [("m0", &first), ("m2", &last)];
    match uploader::refuse_what_cannot_go_in(&mut client, &options.profile, &images, false) {
        Err(Error::UnlistedWayIn { path, .. }) => assert_eq!(path, "$0A03 -> $0A00 -> $0803"),
        other => panic!("{other:?}"),
    }
    // recheck27: the last image where the hook itself goes (code no entry
    // lists): the first chains to it as it goes in. Alone, it is fine.
    let last = extension_at(0x0A00);
    match uploader::refuse_what_cannot_go_in(
        &mut client,
        &options.profile,
        &[("m0", &first), ("m2", &last)],
        false,
    ) {
        Err(Error::UnlistedWayIn { path, .. }) => assert_eq!(path, "$0A03"),
        other => panic!("{other:?}"),
    }
    uploader::refuse_what_cannot_go_in(&mut client, &options.profile, &[("m2", &last)], false)
        .expect("alone, the upload points the hook past it");
}

/// recheck25 R5: a file without one entry's bytes (its flags kept) was
/// refused as a table "damaged on the robot when it was saved", read as
/// zeros. The robot's copy of the entry is what the restore leaves: it is
/// looked at there, and the restore goes through.
#[test]
fn a_backup_without_an_entrys_bytes_is_judged_over_the_robots_copy() {
    let (options, mut client, saved) = in_a_chain(&[0x0500, 0x0800]);
    let (table, entries) = options.profile.table.expect("a table");
    let entry = romlib::installed::entry_address(table, entries, 1);
    let mut cut = saved.clone();
    cut.areas = without(
        &cut.areas,
        entry..=entry + romlib::installed::ENTRY_LEN as u16 - 1,
    );
    let reset = romlib::protocol::Command::parse(b"/1R").expect("a command");
    let _ = client.listen(&reset).expect("the line works");
    restore(&mut client, &cut, &options, &mut NoProgress).expect("restored");
    assert_eq!(hook(&mut client), 0x0803);
    let listed = uploader::read_installed(&mut client, &options.profile).expect("the table");
    assert_eq!(listed.len(), 2, "{listed:?}");
}

/// recheck25 R6: an upload in front of code no entry lists (the front
/// extension's flags cleared by hand) went through, and its undo was
/// refused as a file made by hand. The undo puts back what its upload
/// found.
#[test]
fn the_undo_of_an_upload_in_front_of_unlisted_code_goes_through() {
    let (options, mut client, _) = in_a_chain(&[0x0500, 0x0800, 0x0A00]);
    let (_, _, undo) = plain_replace_undo();
    by_hand(&mut client, romlib::installed::TABLE + 2, &[0]);
    let before = held(&mut client);
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0C00),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("in front");
    assert_eq!(hook(&mut client), 0x0C03);
    restore(&mut client, &kept.0.expect("kept"), &undo, &mut NoProgress).expect("undone");
    assert_eq!(hook(&mut client), 0x0A03);
    assert!(held(&mut client) == before, "the robot as it was");
}

/// hostile26 F1: a backup whose way goes on, past the first step, into
/// memory the file neither holds nor witnesses (the extension behind's
/// code cut out of it) was restored, exit 0, the table listing code that
/// was not there. Each step is checked as the first is.
#[test]
fn a_backup_whose_way_goes_on_into_memory_it_does_not_hold_is_refused() {
    let (options, mut client, saved) = in_a_chain(&[0x0500, 0x0800]);
    let mut cut = saved.clone();
    cut.areas = without(&cut.areas, 0x0500..=0x053F);
    let before = held(&mut client);
    match restore(&mut client, &cut, &options, &mut NoProgress) {
        Err(Error::UnwitnessedStep { target, path, .. }) => {
            assert_eq!((target, path.as_str()), (0x0503, "$0803 -> $0503"));
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
}

/// hostile26 F2: an extension whose chain slot an owner sent on into code
/// on the KIM bus no entry lists: `backup` kept no witness of it, and a
/// restore after that code changed said "verified". The backup witnesses
/// it, and the restore refuses the change.
#[test]
fn a_backup_witnesses_the_code_its_ways_reach_outside_what_it_saves() {
    let (options, mut client) = installed_at(0x0500);
    let owners = [
        0x4C,
        BAD_COMMAND.to_le_bytes()[0],
        BAD_COMMAND.to_le_bytes()[1],
    ];
    let board = client.transport().robot_mut().robot_mut().board_mut();
    board.load(0x1000, &owners).expect("KIM-bus RAM");
    board.load(0x0501, &[0x00, 0x10]).expect("RAM");
    let saved = backup(&mut client, &options.profile).expect("a backup");
    assert!(
        saved
            .witnesses
            .iter()
            .any(|witness| witness.address <= 0x1000 && 0x1000 < witness.address + witness.len),
        "{:?}",
        saved.witnesses
    );
    let board = client.transport().robot_mut().robot_mut().board_mut();
    board
        .load(0x1000, &[0x02, 0x02, 0x02])
        .expect("KIM-bus RAM");
    match restore(&mut client, &saved, &options, &mut NoProgress) {
        Err(Error::WitnessDiffers { .. }) => {}
        other => panic!("{other:?}"),
    }
}

/// hostile26 F1b: an undo file made by hand (b's code and the whole table
/// put in it, HOOK_UNKNOWN at b, its witnesses dropped) whose way goes on
/// from b's chain slot into a, which it neither holds nor witnesses, on a
/// robot reset since (its table lists nothing) and a's code changed: the
/// undo went through, exit 0, the table listing code nothing checked. A
/// later step must lie in an extension the robot still lists.
#[test]
fn an_undo_whose_way_goes_on_into_code_nothing_checks_is_refused() {
    let (options, mut client, _) = in_a_chain(&[0x0500]);
    let (_, _, undo) = plain_replace_undo();
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0800),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("in front");
    let mut file = kept.0.expect("kept");
    let (table, entries) = options.profile.table.expect("a table");
    let end = romlib::installed::entry_address(table, entries, entries - 1)
        + romlib::installed::ENTRY_LEN as u16;
    let memory = client.transport().robot().robot().board().memory();
    let area = |at: u16, end: u16| uploader::Area {
        address: at,
        bytes: memory[usize::from(at)..usize::from(end)].to_vec(),
    };
    file.areas = vec![area(0x0800, 0x0840), area(table, end)];
    file.witnesses.clear();
    file.written_entries.clear();
    for hook in &mut file.hooks {
        if hook.0 == HookKind::Unknown {
            hook.1 = 0x0803;
        }
    }
    let reset = romlib::protocol::Command::parse(b"/1R").expect("a command");
    let _ = client.listen(&reset).expect("the line works");
    by_hand(&mut client, 0x0504, b"Z");
    let before = held(&mut client);
    match restore(&mut client, &file, &undo, &mut NoProgress) {
        Err(Error::UndoStepUnlisted { target, path, .. }) => {
            assert_eq!((target, path.as_str()), (0x0503, "$0803 -> $0503"));
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
}

/// N1: the owner's code on the KIM bus that a chain slot leads to goes on,
/// by its `JMP`, to more of it: `backup` witnessed the first 16 bytes
/// only, and a restore after the code further on changed said "verified".
/// Each step is witnessed, and a file without the later witness is
/// refused.
#[test]
fn a_backup_witnesses_every_step_of_code_outside_what_it_saves() {
    let (options, mut client) = installed_at(0x0500);
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    by_hand(&mut client, 0x1000, &[0x4C, 0x00, 0x20]);
    by_hand(&mut client, 0x2000, &[0x4C, lo, hi]);
    by_hand(&mut client, 0x0501, &[0x00, 0x10]);
    let saved = backup(&mut client, &options.profile).expect("a backup");
    let witnessed = |at: u16| {
        saved
            .witnesses
            .iter()
            .any(|witness| witness.address <= at && at < witness.address + witness.len)
    };
    assert!(
        witnessed(0x1000) && witnessed(0x2000),
        "{:?}",
        saved.witnesses
    );
    // The file without the later witness: nothing checks $2000.
    let mut cut = saved.clone();
    cut.witnesses
        .retain(|witness| !(witness.address <= 0x2000 && 0x2000 < witness.address + witness.len));
    let before = held(&mut client);
    match restore(&mut client, &cut, &options, &mut NoProgress) {
        Err(Error::UnwitnessedStep { target, path, .. }) => {
            assert_eq!((target, path.as_str()), (0x2000, "$0503 -> $1000 -> $2000"));
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    // The code further on changed: the restore is refused.
    by_hand(&mut client, 0x2000, &[0x02, 0x02, 0x02]);
    match restore(&mut client, &saved, &options, &mut NoProgress) {
        Err(Error::WitnessDiffers { .. }) => {}
        other => panic!("{other:?}"),
    }
}

/// hostile28 F4: b's undo file with a's entry cut out, on a robot reset
/// since (its flags cleared) whose stale copy of that entry was zeroed:
/// the undo wrote a's flag, then refused the table as damaged, and every
/// command after that failed. Refused before the flags go in.
#[test]
fn an_undo_whose_table_would_not_decode_over_the_robots_writes_nothing() {
    let (options, mut client, _) = in_a_chain(&[0x0500]);
    let (_, _, undo) = plain_replace_undo();
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0800),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("in front");
    let mut file = kept.0.expect("kept");
    let (table, entries) = options.profile.table.expect("a table");
    let entry = romlib::installed::entry_address(table, entries, 0);
    let len = romlib::installed::ENTRY_LEN as u16;
    file.areas = without(&file.areas, entry..=entry + len - 1);
    let reset = romlib::protocol::Command::parse(b"/1R").expect("a command");
    let _ = client.listen(&reset).expect("the line works");
    by_hand(&mut client, entry, &vec![0; usize::from(len)]);
    let before = held(&mut client);
    match restore(&mut client, &file, &undo, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            assert!(reason.contains("would not decode"), "{reason}");
            assert!(reason.ends_with("nothing was written"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    uploader::read_installed(&mut client, &options.profile).expect("the table decodes");
}

/// The robot of hostile28 F3: the extension at $0500 on HOOK_UNKNOWN, its
/// chain slot by hand into code on the KIM bus that does something before
/// each `JMP`: $1000 `NOP` x14, `JMP $2000` (its high byte at $1010, past
/// a 16-byte window); $2000 `LDA $0F00`, `BNE $2008`, `JMP $3000`;
/// $2008 `JMP $3100`; $3000 and $3100 `INC $0F01`, `JMP BAD_COMMAND`. The
/// host run takes one arm of the branch ($0F00 holds 0: $3000).
fn kim_code_before_each_jmp() -> (
    UploadOptions,
    uploader::Client<uploader::transport::VirtualTransport>,
    uploader::Backup,
) {
    let (options, mut client) = installed_at(0x0500);
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    let mut first = vec![0xEA; 14];
    first.extend([0x4C, 0x00, 0x20]);
    by_hand(&mut client, 0x1000, &first);
    by_hand(
        &mut client,
        0x2000,
        &[
            0xAD, 0x00, 0x0F, 0xD0, 0x03, 0x4C, 0x00, 0x30, 0x4C, 0x00, 0x31,
        ],
    );
    by_hand(&mut client, 0x3000, &[0xEE, 0x01, 0x0F, 0x4C, lo, hi]);
    by_hand(&mut client, 0x3100, &[0xEE, 0x01, 0x0F, 0x4C, lo, hi]);
    by_hand(&mut client, 0x0501, &[0x00, 0x10]);
    let saved = backup(&mut client, &options.profile).expect("a backup");
    (options, client, saved)
}

/// hostile28 F3 (a), (b): `backup` witnessed 16 bytes at each step, and
/// followed a step only when it began with a `JMP`: the `JMP`'s high byte
/// past the window, and every step after it, changed with the restore
/// saying "verified". Now every byte of code the way runs is witnessed,
/// both arms of a branch too, and a change anywhere in it is refused
/// before anything is written.
#[test]
fn a_backup_witnesses_every_byte_of_code_its_ways_run() {
    let (options, mut client, saved) = kim_code_before_each_jmp();
    let code = (0x1000..=0x1010)
        .chain(0x2000..=0x200A)
        .chain(0x3000..=0x3005)
        .chain(0x3100..=0x3105);
    let unwitnessed: Vec<u16> = code.filter(|&at| !saved.witnessed(at)).collect();
    assert!(
        unwitnessed.is_empty(),
        "{unwitnessed:04X?} of {:?}",
        saved.witnesses
    );
    for (at, byte) in [
        (0x1010, 0x21),
        (0x2006, 0x01),
        (0x3002, 0x05),
        (0x3101, 0x14),
    ] {
        let before = client.transport().robot().robot().board().memory()[usize::from(at)];
        by_hand(&mut client, at, &[byte]);
        let held_before = held(&mut client);
        match restore(&mut client, &saved, &options, &mut NoProgress) {
            Err(Error::WitnessDiffers { address, len, .. }) => {
                assert!(
                    address <= at && at < address + len,
                    "${at:04X}: ${address:04X}+{len}"
                );
            }
            other => panic!("${at:04X} changed: {other:?}"),
        }
        assert!(
            held(&mut client) == held_before,
            "nothing written (${at:04X})"
        );
        by_hand(&mut client, at, &[before]);
    }
    restore(&mut client, &saved, &options, &mut NoProgress).expect("unchanged, restored");
}

/// hostile30 F4: witnesses were Fletcher-16 mod 256, blind to bit 7 of
/// two bytes two apart: two `NOP`s of the owner's KIM-bus code turned
/// into `ROR A` passed, and the restore said "verified". Each witness is
/// the robot's wide sum over at most `EXACT` bytes now: refused, nothing
/// written.
#[test]
fn a_witness_sees_two_bytes_changed_that_summed_alike_mod_256() {
    let (options, mut client, saved) = kim_code_before_each_jmp();
    assert!(
        saved
            .witnesses
            .iter()
            .all(|witness| usize::from(witness.len) <= uploader::EXACT
                && matches!(witness.sum, uploader::Checksum::Wide(_))),
        "{:?}",
        saved.witnesses
    );
    let memory = client.transport().robot().robot().board().memory().to_vec();
    let changed = [0x6A, 0xEA, 0x6A];
    assert_eq!(
        uploader::fletcher16(&changed),
        uploader::fletcher16(&memory[0x1002..0x1005]),
        "the narrow sums' blind spot"
    );
    by_hand(&mut client, 0x1002, &changed);
    let held_before = held(&mut client);
    match restore(&mut client, &saved, &options, &mut NoProgress) {
        Err(Error::WitnessDiffers { address, len, .. }) => {
            assert!(
                address <= 0x1002 && 0x1004 < address + len,
                "${address:04X}+{len}"
            );
        }
        other => panic!("two bytes changed: {other:?}"),
    }
    assert!(held(&mut client) == held_before, "nothing written");
}

/// hostile28 F3 (c): a file whose witness of a step was cut to the step's
/// opcode byte (or dropped) checks nothing of the rest of the code the
/// way runs: refused, the byte named, nothing written.
#[test]
fn a_file_that_witnesses_part_of_the_code_a_way_runs_is_refused() {
    let (options, mut client, saved) = kim_code_before_each_jmp();
    let covering = |file: &uploader::Backup, at: u16| {
        file.witnesses
            .iter()
            .position(|w| w.address <= at && at < w.address + w.len)
            .expect("witnessed")
    };
    // The witness of $3100 (the arm not run) dropped.
    let mut dropped = saved.clone();
    let i = covering(&dropped, 0x3100);
    let cut = dropped.witnesses.remove(i);
    // Only what lies outside $3100-$3105 is witnessed again.
    for (start, end) in [(cut.address, 0x30FF), (0x3106, cut.address + cut.len - 1)] {
        if start <= end {
            let bytes = &client.transport().robot().robot().board().memory()
                [usize::from(start)..=usize::from(end)];
            dropped.witnesses.push(uploader::Witness {
                address: start,
                len: end - start + 1,
                sum: uploader::Checksum::of(bytes),
            });
        }
    }
    let before = held(&mut client);
    match restore(&mut client, &dropped, &options, &mut NoProgress) {
        Err(error @ Error::UnwitnessedStep { target: 0x3100, .. }) => {
            let text = error.to_string();
            assert!(text.contains("runs the code at $3100"), "{text}");
            assert!(text.ends_with("nothing was written"), "{text}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    // The witness of $1000 cut before the `JMP`'s high byte.
    let mut short = saved.clone();
    let i = covering(&short, 0x1000);
    let memory = client.transport().robot().robot().board().memory().to_vec();
    let first = short.witnesses[i];
    assert_eq!(first.address, 0x1000, "{:?}", short.witnesses);
    short.witnesses[i] = uploader::Witness {
        address: 0x1000,
        len: 16,
        sum: uploader::Checksum::of(&memory[0x1000..0x1010]),
    };
    if first.len > 17 {
        short.witnesses.push(uploader::Witness {
            address: 0x1011,
            len: first.len - 17,
            sum: uploader::Checksum::of(&memory[0x1011..usize::from(first.address + first.len)]),
        });
    }
    match restore(&mut client, &short, &options, &mut NoProgress) {
        Err(Error::UnwitnessedStep {
            target: 0x1010,
            path,
            ..
        }) => {
            assert!(path.starts_with("$0503 -> $1000"), "{path}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
}

/// a at $0500 installed, then b at $0800 in front of it with its undo
/// kept: the robot, and b's undo file.
fn b_in_front_of_a_kept() -> (
    UploadOptions,
    uploader::Client<uploader::transport::VirtualTransport>,
    uploader::Backup,
) {
    let (options, mut client, _) = in_a_chain(&[0x0500]);
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0800),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("in front");
    (options, client, kept.0.expect("kept"))
}

/// hostile28 F5: b's undo file with a record of code added by hand at
/// $0900 (`JMP` a's handler) and HOOK_UNKNOWN pointed at it: restored,
/// exit 0, the hook running memory the table calls free. An upload's
/// undo puts back code no entry lists only where the robot runs it.
#[test]
fn an_undo_that_puts_in_code_no_entry_lists_and_nothing_runs_is_refused() {
    let (_, mut client, mut file) = b_in_front_of_a_kept();
    let (_, _, undo) = plain_replace_undo();
    file.areas.push(uploader::Area {
        address: 0x0900,
        bytes: vec![0x4C, 0x03, 0x05],
    });
    for (kind, target) in &mut file.hooks {
        if *kind == HookKind::Unknown {
            *target = 0x0900;
        }
    }
    let before = held(&mut client);
    match restore(&mut client, &file, &undo, &mut NoProgress) {
        Err(error @ Error::UndoAddsCode { target: 0x0900, .. }) => {
            assert!(
                error.to_string().ends_with("nothing was written"),
                "{error}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    assert_eq!(hook(&mut client), 0x0803, "b still hooked");
}

/// hostile28 F6, F7: after `/1R` (the table's flags cleared, memory
/// kept), b's undo marked a in use again from what memory held: a's
/// code past the 16 bytes the file witnesses changed by hand, or its
/// entry's id, and the undo said "verified". Refused, nothing written;
/// with the robot as the upload left it, the undo goes through.
#[test]
fn an_undo_after_a_reset_lists_nothing_it_does_not_check() {
    let (_, mut client, file) = b_in_front_of_a_kept();
    let (options, _, undo) = plain_replace_undo();
    let (table, entries) = options.profile.table.expect("a table");
    let reset = romlib::protocol::Command::parse(b"/1R").expect("a command");
    let _ = client.listen(&reset).expect("the line works");
    // a's tail, past what the file witnesses, now runs $0900.
    by_hand(&mut client, 0x0530, &[0x4C, 0x00, 0x09]);
    let a_entry = romlib::installed::entry_address(table, entries, 0);
    by_hand(&mut client, a_entry + 1, &[0x56, 0x34, 0x12]);
    let before = held(&mut client);
    match restore(&mut client, &file, &undo, &mut NoProgress) {
        Err(error @ Error::UndoRelistsUnchecked { .. }) => {
            let text = error.to_string();
            assert!(text.contains("no longer lists"), "{text}");
            assert!(text.ends_with("nothing was written"), "{text}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    // Not reset: the same undo goes through.
    let (_, mut client, file) = b_in_front_of_a_kept();
    restore(&mut client, &file, &undo, &mut NoProgress).expect("undone");
    assert_eq!(hook(&mut client), 0x0503, "a hooked again");
}

/// A counter the way's own code keeps in line, after a branch always
/// taken ($1000 `INC $1007`, `LDA #1`, `BNE $1008`; $1007 the counter;
/// $1008 `JMP BAD_COMMAND`): reached as code on the branch's other arm,
/// it is data the code writes, which changes as it runs. Not witnessed,
/// not refused: the backup restores with the counter moved on.
#[test]
fn data_the_ways_code_writes_is_not_taken_for_code() {
    let (options, mut client) = installed_at(0x0500);
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    by_hand(
        &mut client,
        0x1000,
        &[0xEE, 0x07, 0x10, 0xA9, 0x01, 0xD0, 0x01, 0x00, 0x4C, lo, hi],
    );
    by_hand(&mut client, 0x0501, &[0x00, 0x10]);
    let saved = backup(&mut client, &options.profile).expect("a backup");
    assert!(!saved.witnessed(0x1007), "{:?}", saved.witnesses);
    for at in (0x1000..=0x1006).chain(0x1008..=0x100A) {
        assert!(saved.witnessed(at), "${at:04X}: {:?}", saved.witnesses);
    }
    by_hand(&mut client, 0x1007, &[0x2A]);
    restore(&mut client, &saved, &options, &mut NoProgress).expect("restored");
}

/// fresh28 F1: an owner's handler in front of an uploaded extension
/// (HOOK_UNKNOWN by hand at $0900: `NOP`, `JMP` the extension's handler).
/// Its backup was refused ("code no extension its table lists") on the
/// robot it was taken from. It is restored as it was; one whose code goes
/// elsewhere is still refused, nothing written.
#[test]
fn an_owners_handler_in_front_of_an_extension_is_restored_as_it_was() {
    let (options, mut client) = installed_at(0x0500);
    by_hand(&mut client, 0x0900, &[0xEA, 0x4C, 0x03, 0x05]);
    by_hand(&mut client, HOOK_UNKNOWN + 1, &[0x00, 0x09]);
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    assert_eq!(saved.refused, None, "{:?}", saved.refused);
    let file = saved.backup;
    by_hand(&mut client, HOOK_UNKNOWN + 1, &[0x03, 0x05]);
    by_hand(&mut client, 0x0900, &[0; 4]);
    restore(&mut client, &file, &options, &mut NoProgress).expect("restored");
    assert_eq!(
        hook(&mut client),
        0x0900,
        "the owner's handler in front again"
    );
    // The owner's code changed in the file to go past the extension.
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    let mut past = file.clone();
    set(&mut past, 0x0902, lo);
    set(&mut past, 0x0903, hi);
    let before = held(&mut client);
    match restore(&mut client, &past, &options, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            assert!(reason.contains("does not go on into them"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
    // hostile30 F8: into the extension elsewhere than its handler (its
    // chain slot's `JMP` at $0500, which goes on to the ROM): refused, the
    // way into it named.
    let mut middle = file.clone();
    set(&mut middle, 0x0902, 0x00);
    set(&mut middle, 0x0903, 0x05);
    match restore(&mut client, &middle, &options, &mut NoProgress) {
        Err(Error::BackupRefused { reason }) => {
            assert!(
                reason.contains("at $0500, not at its HOOK_UNKNOWN handler $0503"),
                "{reason}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
}

/// fresh29 F1: an owner's HOOK_LOOP handler at $0600 (`INC $0700`, `JMP`
/// the ROM's loop), then an upload on HOOK_UNKNOWN with its undo kept;
/// the owner changes his handler by hand (`INC $0702`). The undo was
/// refused ("the upload ... is no longer on the robot"), though it leaves
/// HOOK_LOOP as it is. It goes through, the owner's change kept; a change
/// to the code the undo hooks anew is still refused.
#[test]
fn an_undo_leaves_an_owners_change_on_a_hook_it_does_not_move() {
    let options = UploadOptions::default();
    let (_, _, undo) = plain_replace_undo();
    let mut client = uploader::client(robot(), &options.profile);
    let [lo, hi] = romlib::symbols::ROM_LOOP.to_le_bytes();
    by_hand(&mut client, 0x0600, &[0xEE, 0x00, 0x07, 0x4C, lo, hi]);
    by_hand(&mut client, romlib::symbols::HOOK_LOOP + 1, &[0x00, 0x06]);
    let mut kept = Kept::default();
    upload_keeping(
        &mut client,
        &extension_at(0x0800),
        &options,
        &mut NoProgress,
        &mut kept,
    )
    .expect("installed");
    let file = kept.0.expect("kept");
    assert!(file.witnessed(0x0600), "{:?}", file.witnesses);
    by_hand(&mut client, 0x0601, &[0x02]);
    restore(&mut client, &file, &undo, &mut NoProgress).expect("undone");
    let memory = client.transport().robot().robot().board().memory();
    assert_eq!(memory[0x0601], 0x02, "the owner's change kept");
    let at = usize::from(romlib::symbols::HOOK_LOOP) + 1;
    assert_eq!(memory[at..at + 2], [0x00, 0x06], "HOOK_LOOP as it was");
    assert_eq!(hook(&mut client), BAD_COMMAND, "the upload undone");
}

/// hostile29 F3: a loop handler that calls one subroutine twice ($0900
/// `JSR $0A00`, `JSR $0A00`, `JMP` the ROM's loop; $0A00 `INC $0F20`,
/// `RTS`), or recurses five deep and returns, was taken for "a loop the
/// robot would run for ever": a backup warned, and its restore left
/// HOOK_LOOP at the ROM. Both are restored as they were; a file whose
/// subroutine calls itself for ever leaves HOOK_LOOP at the ROM.
#[test]
fn a_subroutine_called_twice_or_a_recursion_that_ends_is_no_loop() {
    let [lo, hi] = romlib::symbols::ROM_LOOP.to_le_bytes();
    let twice = [0x20, 0x00, 0x0A, 0x20, 0x00, 0x0A, 0x4C, lo, hi];
    let sub = [0xEE, 0x20, 0x0F, 0x60];
    // $0900: LDA #5; STA $0F21; JSR $0A00; JMP the ROM's loop. $0A00:
    // DEC $0F21; BEQ +3; JSR $0A00; RTS.
    let five = [0xA9, 0x05, 0x8D, 0x21, 0x0F, 0x20, 0x00, 0x0A, 0x4C, lo, hi];
    let recursion = [0xCE, 0x21, 0x0F, 0xF0, 0x03, 0x20, 0x00, 0x0A, 0x60];
    let loop_at = usize::from(romlib::symbols::HOOK_LOOP) + 1;
    for (name, handler, sub) in [
        ("twice", &twice[..], &sub[..]),
        ("recursion", &five[..], &recursion[..]),
    ] {
        let options = UploadOptions::default();
        let mut client = uploader::client(robot(), &options.profile);
        by_hand(&mut client, 0x0900, handler);
        by_hand(&mut client, 0x0A00, sub);
        by_hand(&mut client, romlib::symbols::HOOK_LOOP + 1, &[0x00, 0x09]);
        let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
        assert!(saved.broken.is_empty(), "{name}: {:?}", saved.broken);
        restore(&mut client, &saved.backup, &options, &mut NoProgress)
            .unwrap_or_else(|error| panic!("{name}: {error}"));
        let memory = client.transport().robot().robot().board().memory();
        assert_eq!(
            memory[loop_at..loop_at + 2],
            [0x00, 0x09],
            "{name}: HOOK_LOOP as it was"
        );
        if name == "twice" {
            // The subroutine made to call itself for ever, in the file.
            let mut file = saved.backup.clone();
            for (i, byte) in [0x20u8, 0x00, 0x0A].into_iter().enumerate() {
                set(&mut file, 0x0A00 + i as u16, byte);
            }
            match restore(&mut client, &file, &options, &mut NoProgress) {
                Err(Error::RestoreChainBroken { .. }) => {}
                other => panic!("for ever: {other:?}"),
            }
            let memory = client.transport().robot().robot().board().memory();
            let rom = romlib::symbols::ROM_LOOP.to_le_bytes();
            assert_eq!(
                memory[loop_at..loop_at + 2],
                rom,
                "HOOK_LOOP left at the ROM"
            );
        }
    }
}

/// hostile29 F1: code on the KIM bus that a chain slot leads to and that
/// jumps through a pointer it sets (`LDA #0`, `STA $0F10`, `LDA #>target`,
/// `STA $0F11`, `JMP ($0F10)`): `backup` witnessed the one target it saw,
/// and a jump table's other handlers changed unseen, restored with exit
/// 0. Refused before anything is written, and said by `backup`; the same
/// code in user RAM, which the file restores whole, goes through.
#[test]
fn a_way_that_jumps_where_its_data_says_outside_the_file_is_refused() {
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    for (code_at, refused) in [(0x1000u16, true), (0x0900, false)] {
        let target = code_at + 0x20;
        let [t_lo, t_hi] = target.to_le_bytes();
        let (options, mut client) = installed_at(0x0500);
        by_hand(
            &mut client,
            code_at,
            &[
                0xA9, t_lo, 0x8D, 0x10, 0x0F, 0xA9, t_hi, 0x8D, 0x11, 0x0F, 0x6C, 0x10, 0x0F,
            ],
        );
        by_hand(&mut client, target, &[0x4C, lo, hi]);
        let [c_lo, c_hi] = code_at.to_le_bytes();
        by_hand(&mut client, 0x0501, &[c_lo, c_hi]);
        let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
        let before = held(&mut client);
        let result = restore(&mut client, &saved.backup, &options, &mut NoProgress);
        if refused {
            let said = saved.refused.unwrap_or_default();
            assert!(said.contains("jumps where its data says"), "{said}");
            match result {
                Err(Error::ComputedWayOutside { at, .. }) => assert_eq!(at, code_at + 10),
                other => panic!("{other:?}"),
            }
            assert!(held(&mut client) == before, "nothing written");
        } else {
            assert_eq!(saved.refused, None);
            result.expect("restored");
        }
    }
}

/// hostile30 F5: code on the KIM bus that bumps the operand of its own
/// `JMP` ($1000 `INC $1004`, `JMP $2000`: the jump goes elsewhere every
/// pass) was taken for a fixed jump; its restore went through unchecked.
/// It jumps where its data says: refused, and `backup` says so.
#[test]
fn code_that_changes_its_own_jump_is_a_jump_where_its_data_says() {
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    let (options, mut client) = installed_at(0x0500);
    by_hand(&mut client, 0x1000, &[0xEE, 0x04, 0x10, 0x4C, 0x00, 0x20]);
    by_hand(&mut client, 0x2000, &[0x4C, lo, hi]);
    by_hand(&mut client, 0x0501, &[0x00, 0x10]);
    let saved = uploader::backup_live(&mut client, &options.profile).expect("a backup");
    let said = saved.refused.clone().unwrap_or_default();
    assert!(said.contains("jumps where its data says"), "{said}");
    let before = held(&mut client);
    match restore(&mut client, &saved.backup, &options, &mut NoProgress) {
        Err(Error::ComputedWayOutside { .. }) => {}
        other => panic!("{other:?}"),
    }
    assert!(held(&mut client) == before, "nothing written");
}
