//! Issue 27 on the virtual Scorpion, through nothing but the line: a ROM
//! that is not the profile's is refused before anything is written (one
//! byte of its jump table, read; one byte elsewhere, by the checksum the
//! loader computes on the robot); a one-byte change to an installed
//! extension is written as one short range; a backup survives a hostile
//! change and a restore puts RAM back as it was, hooks last; an upload
//! keeps what it overwrote, and restoring that undoes it.

mod common;

use common::{Kept, assert_done, extension, one_byte_changed, options, robot, target};
use romlib::VirtualScorpion;
use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use uploader::transport::VirtualTransport;
use uploader::{
    Backup, Error, FINE, LoaderChoice, NoProgress, UploadOptions, backup, restore, upload,
    upload_keeping,
};

/// The reference ROM with the byte at `address` changed.
fn robot_with_rom_byte(address: u16, delta: u8) -> (VirtualTransport, u8, u8) {
    let mut rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("parses");
    let area = rom
        .areas
        .iter_mut()
        .find(|area| area.load <= u32::from(address) && u64::from(address) < area.end())
        .expect("the ROM loads it");
    let at = (u32::from(address) - area.load) as usize;
    let before = area.bytes[at];
    area.bytes[at] = before.wrapping_add(delta);
    let robot = VirtualScorpion::with_rom("changed.elf", &rom).expect("a ROM");
    (
        VirtualTransport::new(robot),
        before,
        before.wrapping_add(delta),
    )
}

/// User zero page, the hooks, user RAM and the table, as the robot has them.
fn user_memory(robot: &VirtualScorpion) -> Vec<u8> {
    let memory = robot.robot().board().memory();
    [
        0x0030..0x0100,
        0x0200..0x0206,
        0x0400..0x0F40,
        0x0F80..0x1000,
    ]
    .into_iter()
    .flat_map(|range| memory[range].to_vec())
    .collect()
}

/// The same without where the RAM loader runs (the top of user RAM and of
/// user zero page): its scratch, which an upload does not keep.
fn user_memory_but_the_loaders(robot: &VirtualScorpion) -> Vec<u8> {
    let memory = robot.robot().board().memory();
    [
        0x0030..0x00F8,
        0x0200..0x0206,
        0x0400..0x0E00,
        0x0F80..0x1000,
    ]
    .into_iter()
    .flat_map(|range| memory[range].to_vec())
    .collect()
}

/// Where two memory dumps first differ, for a short failure message.
fn first_difference(a: &[u8], b: &[u8]) -> Option<usize> {
    (0..a.len().max(b.len())).find(|&i| a.get(i) != b.get(i))
}

#[test]
fn a_rom_differing_in_one_jump_table_byte_is_refused_before_any_write() {
    // PENDING's operand: the ROM itself never calls through it.
    let image = extension(2048, 3);
    for path in [LoaderChoice::Never, LoaderChoice::Always] {
        let (transport, expected, found) = robot_with_rom_byte(0xFF2E, 0x10);
        // Through the loader, the jump table is read at the fast rate: only
        // `rate` (at the top of user RAM, no call but CMD_DONE) went in
        // before, and it is unhooked again.
        let memory = match path {
            LoaderChoice::Always => user_memory_but_the_loaders,
            _ => user_memory,
        };
        let untouched = memory(transport.robot());
        let mut client = uploader::client(transport, &UploadOptions::default().profile);
        let error = upload(&mut client, &image, &options(path), &mut NoProgress)
            .expect_err("a ROM that is not the profile's");
        match &error {
            Error::WrongRom {
                differences,
                whole_sum: None,
                ..
            } => assert_eq!(differences, &vec![(0xFF2E, expected, found)], "{path:?}"),
            other => panic!("{path:?}: {other:?}"),
        }
        assert!(error.to_string().contains("$FF2E"), "{error}");
        let robot = client.into_transport().into_robot();
        assert_eq!(
            first_difference(&memory(&robot), &untouched),
            None,
            "nothing written ({path:?})"
        );
    }
}

#[test]
fn a_rom_differing_past_its_jump_table_is_refused_by_its_checksum() {
    // A byte of the ROM's free space, which no jump-table read covers.
    let image = extension(2048, 4);
    let (transport, _, _) = robot_with_rom_byte(0xF900, 0x01);
    let mut client = uploader::client(transport, &UploadOptions::default().profile);
    let error = upload(
        &mut client,
        &image,
        &options(LoaderChoice::Always),
        &mut NoProgress,
    )
    .expect_err("a ROM that is not the profile's");
    assert!(
        matches!(
            &error,
            Error::WrongRom { differences, whole_sum: Some(((address, len), expected, found)), .. }
                if differences.is_empty() && expected != found
                    && (u32::from(*address)..u32::from(*address) + *len as u32).contains(&0xF900)
                    && *len <= uploader::EXACT
        ),
        "{error:?}"
    );
    assert!(
        error.to_string().contains("$F900-$F9FF"),
        "the range is named: {error}"
    );
    let robot = client.into_transport().into_robot();
    let memory = robot.robot().board().memory();
    assert_eq!(
        target(memory, HOOK_UNKNOWN),
        (0x4C, BAD_COMMAND),
        "the loader is out"
    );
    assert!(
        memory[0x0400..0x0C00].iter().all(|&b| b == 0),
        "no byte of the image written"
    );
}

#[test]
fn a_one_byte_change_is_written_as_one_range_and_verified() {
    // Small images too (fresh7's F1: the table entry, which an edit always
    // changes, counted as half of an image of one or two 256-byte ranges,
    // and the whole image was written).
    for (len, offset) in [(2048, 1000), (426, 300), (200, 100)] {
        one_byte_change_of(len, offset);
    }
}

fn one_byte_change_of(len: usize, offset: usize) {
    let image = extension(len, 5);
    let options = UploadOptions {
        loader: LoaderChoice::Always,
        replace: true,
        ..UploadOptions::default()
    };
    let mut client = uploader::client(robot(), &options.profile);
    let first = upload(&mut client, &image, &options, &mut NoProgress).expect("the first upload");
    assert_eq!(first.written_bytes(), len + 15);

    let new = one_byte_changed(&image, offset);
    let report = upload(&mut client, &new, &options, &mut NoProgress).expect("the change");
    let address = 0x0400 + offset as u16;
    let code: Vec<&(u16, usize)> = report
        .written
        .iter()
        .filter(|(at, _)| *at < 0x0F00)
        .collect();
    assert_eq!(code.len(), 1, "one range of code: {:?}", report.written);
    let (at, len) = *code[0];
    assert!(
        at <= address && usize::from(address - at) < len,
        "{:?}",
        report.written
    );
    // A fine range: about FINE bytes.
    assert!(len <= FINE, "{:?}", report.written);
    // The table entry (its id changed) is the only other range.
    assert_eq!(report.written.len(), 2, "{:?}", report.written);
    assert_done(client.into_transport(), &new, "the one-byte change");

    // The same image again: nothing differs, nothing is written.
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &new, &options, &mut NoProgress).expect("the upload");
    let again = upload(&mut client, &new, &options, &mut NoProgress).expect("again");
    assert!(again.written.is_empty(), "{:?}", again.written);
}

#[test]
fn backup_a_hostile_change_and_restore_give_back_the_ram() {
    let image = extension(1024, 7);
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &image, &options, &mut NoProgress).expect("an extension installed");
    let saved = backup(&mut client, &options.profile).expect("a backup");
    let file = saved.encode();
    let before = user_memory(client.transport().robot());

    // Hostile: every byte of user RAM and zero page changed, the hook
    // pointed into the middle of the garbage.
    let robot = client.transport().robot_mut().robot_mut().board_mut();
    robot.load(0x0400, &[0xA5; 0x0B40]).expect("RAM");
    robot.load(0x0030, &[0x5A; 0xD0]).expect("RAM");
    robot.load(0x0201, &[0x00, 0x08]).expect("RAM");

    let saved = Backup::decode("saved", &file).expect("the file reads back");
    restore(&mut client, &saved, &options, &mut NoProgress).expect("the restore");
    assert_eq!(
        first_difference(&user_memory(client.transport().robot()), &before),
        None
    );
    assert_done(client.into_transport(), &image, "restored");
}

#[test]
fn an_upload_keeps_what_it_overwrote_and_restoring_that_undoes_it() {
    let first = extension(1024, 8);
    let options = UploadOptions {
        replace: true,
        ..UploadOptions::default()
    };
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &first, &options, &mut NoProgress).expect("the first upload");
    let before = user_memory(client.transport().robot());

    let second = one_byte_changed(&first, 700);
    let mut kept = Kept::default();
    upload_keeping(&mut client, &second, &options, &mut NoProgress, &mut kept)
        .expect("the second upload");
    assert!(user_memory(client.transport().robot()) != before);
    let kept = kept.0.expect("kept");
    restore(&mut client, &kept, &options, &mut NoProgress).expect("the undo");
    // The loader's zero page included, which it wrote as it ran.
    assert_eq!(
        first_difference(&user_memory(client.transport().robot()), &before),
        None
    );
    assert_done(client.into_transport(), &first, "undone");
}

/// hostile7's F1: the first upload to a robot writes the RAM loader at
/// the top of user RAM, over whatever the owner had there; its undo put
/// back the extension's place, not the loader's.
#[test]
fn an_undo_puts_back_what_the_ram_loader_overwrote() {
    let image = extension(1024, 8);
    let options = UploadOptions::default();
    let mut transport = robot();
    let board = transport.robot_mut().robot_mut().board_mut();
    let pattern = |len: usize, seed: usize| -> Vec<u8> {
        (0..len).map(|i| ((i * 7 + seed) % 251) as u8 | 1).collect()
    };
    board.load(0x0400, &pattern(0x0B40, 3)).expect("RAM");
    board.load(0x0030, &pattern(0xD0, 5)).expect("RAM");
    let before = user_memory(transport.robot());
    let mut client = uploader::client(transport, &options.profile);
    let mut kept = Kept::default();
    let report = upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut kept)
        .expect("the upload");
    let loader = report.loader.expect("through the RAM loader");
    let memory = client.transport().robot().robot().board().memory();
    let place = usize::from(loader.address)..usize::from(loader.address) + loader.len;
    assert!(
        memory[place.clone()] != before[place.start - 0x0400 + 0xD6..][..place.len()],
        "the loader was written over the pattern"
    );
    let kept = kept.0.expect("kept");
    restore(&mut client, &kept, &options, &mut NoProgress).expect("the undo");
    let after = user_memory(client.transport().robot());
    if let Some(at) = first_difference(&after, &before) {
        panic!(
            "differs at offset {at} of the dump: {:02X?} was {:02X?}",
            &after[at..(at + 8).min(after.len())],
            &before[at..(at + 8).min(before.len())]
        );
    }
}

/// fresh13 F1: the same image uploaded again changes nothing, and says
/// so (read back on the robot), so that the undo kept by the upload that
/// put it there, with what the RAM loader went over since, still puts the
/// robot back as it was before both; an upload that changes anything (a
/// byte of the image, a byte of it changed by hand since) does not say
/// so. A small image (its first upload through the ROM's commands, the
/// next through the loader), a bigger one, and the ROM's commands alone.
#[test]
fn the_same_image_uploaded_again_changes_nothing_and_the_first_undo_still_applies() {
    let cases = [
        (extension(24, 3), LoaderChoice::Auto),
        (extension(1024, 8), LoaderChoice::Auto),
        (extension(1024, 8), LoaderChoice::Never),
    ];
    for (image, loader) in cases {
        let case = format!("{} bytes, {loader:?}", image.len());
        let options = UploadOptions {
            replace: true,
            ..options(loader)
        };
        let (transport, before) = patterned_robot();
        let mut client = uploader::client(transport, &options.profile);
        let upload_again = |client: &mut uploader::Client<VirtualTransport>, image| {
            let mut kept = Kept::default();
            let report = upload_keeping(client, image, &options, &mut NoProgress, &mut kept)
                .expect("the upload");
            assert_eq!(report.unchanged, kept.1, "{case}: told as reported");
            (report.unchanged, kept.0.expect("kept"))
        };
        let (unchanged, mut undo) = upload_again(&mut client, &image);
        assert!(!unchanged, "{case}: the first upload changed the robot");
        for _ in 0..2 {
            let (unchanged, kept) = upload_again(&mut client, &image);
            assert!(unchanged, "{case}: the same image again");
            undo = undo.going_further_back(&kept);
        }
        restore(&mut client, &undo, &options, &mut NoProgress).expect("the first undo");
        let after = user_memory(client.transport().robot());
        assert_eq!(first_difference(&after, &before), None, "{case}");

        // Installed again, then changed: by the image, by hand.
        let (unchanged, _) = upload_again(&mut client, &image);
        assert!(!unchanged, "{case}: put back in");
        let changed = one_byte_changed(&image, image.len() / 2);
        let (unchanged, _) = upload_again(&mut client, &changed);
        assert!(!unchanged, "{case}: one byte of the image changed");
        let (unchanged, _) = upload_again(&mut client, &image);
        assert!(!unchanged, "{case}: and back");
        let address = image.areas()[0].address + 10;
        let byte = image.byte(address).expect("loaded");
        let board = client.transport().robot_mut().robot_mut().board_mut();
        board.load(address, &[byte ^ 0x40]).expect("RAM");
        let (unchanged, _) = upload_again(&mut client, &image);
        assert!(!unchanged, "{case}: a byte of it changed by hand");
        let (unchanged, _) = upload_again(&mut client, &image);
        assert!(unchanged, "{case}: the same image again, at the end");
    }
}

/// hostile9's F1: 256 bytes of one even byte ($EA, a NOP sled; $20,
/// spaces) sum as zeros do, and were kept as zeros without a read: the
/// undo wrote zeros over them.
#[test]
fn an_undo_puts_back_a_run_of_one_even_byte() {
    for fill in [0xEA, 0x20] {
        let image = extension(1024, 8);
        let options = UploadOptions::default();
        let mut transport = robot();
        let board = transport.robot_mut().robot_mut().board_mut();
        board.load(0x0400, &[fill; 0x0B40]).expect("RAM");
        let before = user_memory(transport.robot());
        let mut client = uploader::client(transport, &options.profile);
        let mut kept = Kept::default();
        upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut kept)
            .expect("the upload");
        let kept = kept.0.expect("kept");
        restore(&mut client, &kept, &options, &mut NoProgress).expect("the undo");
        let after = user_memory(client.transport().robot());
        assert_eq!(
            first_difference(&after, &before),
            None,
            "${fill:02X} put back"
        );
    }
}

/// A robot whose user RAM and user zero page hold a pattern with no zero
/// in it (what an owner's RAM may hold: zeros hide nothing), and its user
/// memory as it is.
fn patterned_robot() -> (VirtualTransport, Vec<u8>) {
    let pattern: Vec<u8> = (0..0x0B40u32).map(|i| (i * 13 % 251) as u8 | 1).collect();
    let mut transport = robot();
    let board = transport.robot_mut().robot_mut().board_mut();
    board.load(0x0400, &pattern).expect("RAM");
    board.load(0x0030, &pattern[..0xD0]).expect("RAM");
    let before = user_memory(transport.robot());
    (transport, before)
}

/// hostile9's F6: an upload killed while the RAM loader went in left its
/// code over the owner's RAM and no undo file (it was written once the
/// image's sums were in). At every point the line dies, what was kept
/// (if anything was written) puts the robot back byte for byte.
#[test]
fn an_upload_cut_anywhere_leaves_an_undo_that_puts_everything_back() {
    cut_anywhere_then_undo(
        &patterned_robot,
        &extension(1024, 8),
        &UploadOptions::default(),
        (40..2600).step_by(120),
    );
}

/// hostile10's F5: `upload --replace` took the installed extension out of
/// its chain and freed its entry before any undo file existed; killed
/// there, the extension was gone and nothing could bring it back. Cut
/// anywhere, what was kept puts the robot back as it was, the replaced
/// extension hooked and listed.
#[test]
fn a_replace_cut_anywhere_leaves_an_undo_that_puts_the_old_extension_back() {
    let old = extension(1024, 8);
    replaced_cut_anywhere_then_undo(&old, &one_byte_changed(&old, 1000));
}

/// fresh14 F3: a `--replace --full` cut while the RAM loader an earlier
/// upload left in RAM was hooked: the undo was refused ("an upload after
/// the one it undoes was chained ahead"), for a hook at the loader, which
/// the file did not hold. Cut anywhere, undone.
#[test]
fn a_full_replace_cut_anywhere_leaves_an_undo_that_puts_the_old_extension_back() {
    let old = extension(1024, 8);
    let new = one_byte_changed(&old, 1000);
    let options = UploadOptions {
        replace: true,
        delta: false,
        ..UploadOptions::default()
    };
    let installed = || {
        let (transport, _) = patterned_robot();
        let (result, transport) = common::run(transport, &old, &options);
        result.expect("the first upload");
        let before = user_memory(transport.robot());
        (transport, before)
    };
    cut_anywhere_then_undo(
        &installed,
        &new,
        &options,
        (10..2000).step_by(common::fault_step(15)),
    );
}

/// The same image again (its hook disarmed first, the RAM loader found
/// where the first upload left it and hooked): cut anywhere, undone.
#[test]
fn the_same_upload_again_cut_anywhere_leaves_an_undo_that_puts_it_back() {
    let old = extension(1024, 8);
    replaced_cut_anywhere_then_undo(&old, &old);
}

/// Uploads `old` to a patterned robot, then `new` over it with `replace`
/// ([`cut_anywhere_then_undo`]).
fn replaced_cut_anywhere_then_undo(old: &uploader::UploadImage, new: &uploader::UploadImage) {
    let options = UploadOptions {
        replace: true,
        ..UploadOptions::default()
    };
    let installed = || {
        let (transport, _) = patterned_robot();
        let (result, transport) = common::run(transport, old, &options);
        result.expect("the first upload");
        let before = user_memory(transport.robot());
        (transport, before)
    };
    cut_anywhere_then_undo(
        &installed,
        new,
        &options,
        (20..1400).step_by(common::fault_step(40)),
    );
}

/// Uploads `image` with `options` to the robot `robot` makes (with its
/// user memory as it is), the line cut after each of `cuts` host
/// characters; whatever was kept must put the robot back as it was, and
/// where nothing was kept nothing may have changed.
fn cut_anywhere_then_undo(
    robot: &dyn Fn() -> (VirtualTransport, Vec<u8>),
    image: &uploader::UploadImage,
    options: &UploadOptions,
    cuts: impl Iterator<Item = usize>,
) {
    use uploader::transport::{FaultConfig, FaultyTransport};
    let mut tried = 0;
    for at in cuts {
        let (transport, before) = robot();
        let config = FaultConfig {
            stall_after: Some(at),
            stall_for: None,
            ..FaultConfig::none(5)
        };
        let mut client =
            uploader::client(FaultyTransport::new(transport, config), &options.profile);
        let mut kept = Kept::default();
        let result = upload_keeping(&mut client, image, options, &mut NoProgress, &mut kept);
        let transport = client.into_transport().into_inner();
        if result.is_ok() {
            break;
        }
        tried += 1;
        let changed = user_memory(transport.robot()) != before;
        let Some(kept) = kept.0 else {
            assert!(
                !changed,
                "cut after {at}: the robot changed and nothing kept"
            );
            continue;
        };
        let mut client = uploader::client(transport, &options.profile);
        // As `upload --undo` gives it: the file of an upload that did not
        // finish.
        let undo = UploadOptions {
            interrupted: true,
            ..options.clone()
        };
        restore(&mut client, &kept, &undo, &mut NoProgress)
            .unwrap_or_else(|error| panic!("cut after {at}: the undo: {error}"));
        let after = user_memory(client.transport().robot());
        assert_eq!(
            first_difference(&after, &before),
            None,
            "cut after {at} host characters"
        );
    }
    assert!(tried > 5, "cut {tried} times");
}

/// hostile9's F7: an undo cut half way (killed, a dead line) could not be
/// finished: the table it had put back no longer held the upload's entry,
/// and the undo file was refused as "no longer on the robot". Cut
/// anywhere, the same undo again finishes the job.
#[test]
fn an_undo_cut_anywhere_can_be_run_again_to_the_end() {
    use uploader::transport::{FaultConfig, FaultyTransport};
    let image = extension(1024, 8);
    let options = UploadOptions::default();
    let mut cut = 0;
    for at in (40..3000).step_by(150) {
        let (transport, before) = patterned_robot();
        let mut client = uploader::client(transport, &options.profile);
        let mut kept = Kept::default();
        upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut kept)
            .expect("the upload");
        let kept = kept.0.expect("kept");
        let config = FaultConfig {
            stall_after: Some(at),
            stall_for: None,
            ..FaultConfig::none(5)
        };
        let mut client = uploader::client(
            FaultyTransport::new(client.into_transport(), config),
            &options.profile,
        );
        let first = restore(&mut client, &kept, &options, &mut NoProgress);
        let mut client = uploader::client(client.into_transport().into_inner(), &options.profile);
        if first.is_err() {
            cut += 1;
            let resume = UploadOptions {
                resume: true,
                ..UploadOptions::default()
            };
            restore(&mut client, &kept, &resume, &mut NoProgress)
                .unwrap_or_else(|error| panic!("cut after {at}: again: {error}"));
        }
        let after = user_memory(client.transport().robot());
        assert_eq!(first_difference(&after, &before), None, "cut after {at}");
        if first.is_ok() {
            break;
        }
    }
    assert!(cut > 5, "cut {cut} times");
}

/// hostile9's F4: a loader an earlier upload left in RAM, one byte of its
/// place changed since (by hand, a glitch): the next upload's verification
/// wrote the loader's byte over it without keeping it, and the undo left
/// the loader's byte there.
#[test]
fn an_undo_puts_back_a_byte_changed_in_a_loader_left_in_ram() {
    let image = extension(1024, 8);
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    let first = uploader::upload(&mut client, &image, &options, &mut NoProgress).expect("first");
    let loader = first.loader.expect("through the RAM loader");
    // One byte in each of the loader's last two parts (the first, `rate`,
    // changed makes the loader be written whole, kept as ever).
    let places = [loader.address + 40, loader.address + loader.len as u16 - 12];
    let board = client.transport().robot_mut().robot_mut().board_mut();
    for at in places {
        let byte = board.memory()[usize::from(at)];
        board.load(at, &[byte ^ 0x5A]).expect("RAM");
    }
    let before = user_memory(client.transport().robot());
    let mut kept = Kept::default();
    upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut kept)
        .expect("the upload again");
    let memory = client.transport().robot().robot().board().memory();
    for at in places {
        assert_ne!(
            memory[usize::from(at)],
            before[usize::from(at) - 0x0400 + 0xD6],
            "${at:04X}: the loader's byte is back"
        );
    }
    let kept = kept.0.expect("kept");
    restore(&mut client, &kept, &options, &mut NoProgress).expect("the undo");
    let after = user_memory(client.transport().robot());
    assert_eq!(first_difference(&after, &before), None, "all put back");
}

/// fresh10 F6: an upload cut while its RAM loader was hooked left
/// `HOOK_UNKNOWN` at an address nothing named (`installed` showed it bare).
/// `loader_left_at` tells it for the loader; nothing else is taken for it.
#[test]
fn the_ram_loader_an_upload_cut_left_hooked_is_told() {
    use uploader::transport::{FaultConfig, FaultyTransport};
    let image = extension(1024, 8);
    // The line kept at its rate, as on a pseudo-terminal: a robot left at
    // the fast rate is found there first (`installed` probes it).
    let options = UploadOptions {
        fast_baud: None,
        ..UploadOptions::default()
    };
    let mut told = 0;
    for at in (200..2600).step_by(200) {
        let config = FaultConfig {
            stall_after: Some(at),
            stall_for: None,
            ..FaultConfig::none(3)
        };
        let mut client = uploader::client(FaultyTransport::new(robot(), config), &options.profile);
        if uploader::upload(&mut client, &image, &options, &mut NoProgress).is_ok() {
            break;
        }
        let transport = client.into_transport().into_inner();
        let memory = transport.robot().robot().board().memory();
        let hook = usize::from(romlib::symbols::HOOK_UNKNOWN);
        let target = u16::from_le_bytes([memory[hook + 1], memory[hook + 2]]);
        let mut client = uploader::client(transport, &options.profile);
        let left = uploader::loader_left_at(&mut client, &options.profile, target).expect("read");
        let rom = options.profile.reset_target(isa::objfmt::HookKind::Unknown);
        if Some(target) == rom || target == 0x0400 {
            assert_eq!(left, None, "cut after {at}: ${target:04X} is no loader");
        } else {
            assert!(left.is_some(), "cut after {at}: ${target:04X} not told");
            told += 1;
        }
    }
    assert!(told > 2, "told {told} times");
}

/// fresh11 F6: an OS whose `HOOK_LOOP` handler never goes on to the
/// ROM's loop (`tick: INC passes / JMP tick`, `SCORPION_CHAIN_LOOP`
/// forgotten) silences the robot the moment it is hooked. The upload
/// said what a dead cable says; it names the handler now.
#[test]
fn a_loop_handler_that_never_goes_on_is_named_when_the_robot_goes_silent() {
    use isa::objfmt::{HookKind, HookRecord};
    let image = uploader::UploadImage::new(
        vec![uploader::Area {
            address: 0x0400,
            bytes: vec![0xEE, 0x80, 0x04, 0x4C, 0x00, 0x04, 0x4C, 0x24, 0xFF],
        }],
        vec![HookRecord {
            kind: HookKind::Loop,
            handler: 0x0400,
            chain: Some(0x0407),
        }],
    )
    .expect("an image");
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    let error = upload(&mut client, &image, &options, &mut NoProgress).expect_err("silent");
    assert!(
        matches!(
            error,
            Error::LoopHandlerSilent {
                handler: 0x0400,
                ..
            }
        ),
        "{error}"
    );
    assert!(
        error
            .to_string()
            .contains("HOOK_LOOP was pointed at the image's handler ($0400)")
    );
}

/// The virtual robot's line, dead for good once the host has sent
/// `until` (the robot keeps running; nothing more reaches either end).
struct DeadAfter {
    inner: VirtualTransport,
    until: Vec<u8>,
    sent: Vec<u8>,
    dead: bool,
}

impl uploader::transport::Transport for DeadAfter {
    fn send(&mut self, bytes: &[u8]) -> uploader::Result<()> {
        if self.dead {
            return Ok(());
        }
        self.sent.extend_from_slice(bytes);
        self.dead = self.sent.windows(self.until.len()).any(|w| w == self.until);
        self.inner.send(bytes)
    }
    fn receive(
        &mut self,
        into: &mut Vec<u8>,
        timeout: std::time::Duration,
    ) -> uploader::Result<usize> {
        let mut heard = Vec::new();
        let n = self.inner.receive(&mut heard, timeout)?;
        if self.dead {
            return Ok(0);
        }
        into.extend_from_slice(&heard);
        Ok(n)
    }
    fn baud(&self) -> u32 {
        self.inner.baud()
    }
    fn set_baud(&mut self, baud: u32) -> uploader::Result<()> {
        self.inner.set_baud(baud)
    }
    fn now(&self) -> std::time::Duration {
        self.inner.now()
    }
    fn clear_input(&mut self) -> uploader::Result<()> {
        self.inner.clear_input()
    }
    fn name(&self) -> String {
        self.inner.name()
    }
}

/// fresh14 F3: a replace killed once it had hooked the RAM loader an
/// earlier upload left in RAM (so its undo file does not hold the
/// loader): the undo was refused, as if a later upload were chained
/// ahead, and every way out with it. The loader is the upload's own.
#[test]
fn an_undo_takes_out_the_ram_loader_a_killed_upload_left_hooked() {
    let old = extension(1024, 8);
    let new = one_byte_changed(&old, 1000);
    let options = UploadOptions {
        replace: true,
        delta: false,
        ..UploadOptions::default()
    };
    let (transport, _) = patterned_robot();
    let (result, transport) = common::run(transport, &old, &options);
    result.expect("the first upload");
    let before = user_memory(transport.robot());
    let plan = uploader::loader_plan(&options.profile, &new, (9600, uploader::FAST_BAUD))
        .expect("links")
        .expect("room");
    // Killed as the loader found in RAM is hooked whole (`sums`, once
    // `frames` and `sums` read back as linked).
    let [low, high] = plan.sums_handler.to_le_bytes();
    let until = format!("/9W{:04X}{low:02X}{high:02X}", HOOK_UNKNOWN + 1).into_bytes();
    let cut = DeadAfter {
        inner: transport,
        until,
        sent: Vec::new(),
        dead: false,
    };
    let mut client = uploader::client(cut, &options.profile);
    let mut kept = Kept::default();
    let result = upload_keeping(&mut client, &new, &options, &mut NoProgress, &mut kept);
    assert!(result.is_err(), "the line died");
    let transport = client.into_transport().inner;
    let memory = transport.robot().robot().board().memory();
    let hook = usize::from(HOOK_UNKNOWN);
    let target = u16::from_le_bytes([memory[hook + 1], memory[hook + 2]]);
    assert!(
        [plan.frames_handler, plan.sums_handler].contains(&target),
        "the loader hooked: ${target:04X}"
    );
    let mut client = uploader::client(transport, &options.profile);
    let undo = UploadOptions {
        undo: true,
        interrupted: true,
        ..options
    };
    restore(&mut client, &kept.0.expect("kept"), &undo, &mut NoProgress).expect("the undo");
    let after = user_memory(client.transport().robot());
    assert_eq!(
        first_difference(&after, &before),
        None,
        "the old extension back"
    );
}

/// hostile14 F7: the chain slot of an installed extension damaged by hand
/// to point into the ROM's zero page ($0021): the same upload again hooked
/// the ROM's target meanwhile and then wrote $0021 back into the slot, so
/// the next unknown command went there. A way out where no extension's
/// code can be is not kept: the image falls through to the ROM.
#[test]
fn a_chain_slot_damaged_into_the_roms_zero_page_is_not_kept() {
    let image = extension(64, 8);
    let options = UploadOptions::default();
    let (result, mut transport) = common::run(robot(), &image, &options);
    result.expect("the first upload");
    let slot = image.hooks()[0].chain.expect("a chain slot");
    let board = transport.robot_mut().robot_mut().board_mut();
    board.load(slot, &[0x21, 0x00]).expect("RAM");
    let (result, transport) = common::run(transport, &image, &options);
    result.expect("the same upload again");
    let memory = transport.robot().robot().board().memory();
    let at = usize::from(slot);
    let to = u16::from_le_bytes([memory[at], memory[at + 1]]);
    assert_eq!(to, BAD_COMMAND, "the slot falls through to the ROM");
}
