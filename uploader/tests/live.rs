//! Memory the robot writes while it runs, beside the code the host reads:
//! a counter in the program's `.data` right after its code, which its
//! `HOOK_LOOP` handler bumps on every pass of the control loop (hostile16
//! F4). Following the chain read it with the code around it, and a backup
//! reads all user RAM: both failed as "memory in use" on every try, so
//! `debug --port` could not attach and `scorpion backup` could not save.
//! An upload of another extension in front of it read the counter too, as
//! a witness of the code the undo goes back to, and failed likewise. A
//! plain read of the counter is still told it changes.

mod common;

use common::{Kept, extension_at, robot};
use isa::objfmt::{HookKind, HookRecord};
use romlib::protocol::Command;
use std::time::Duration;
use uploader::stub::{Reply, RobotDebug};
use uploader::transport::VirtualTransport;
use uploader::{Area, Client, NoProgress, RomProfile, UploadImage, UploadOptions, upload};

/// Where the loop handler counts.
const COUNT: u16 = 0x041E;

/// `/1W` answers `W` and the count; the loop handler counts its passes,
/// the count the first byte after the code (as ca65's `.data` after
/// `.code` puts it):
///
/// ```text
/// $0400  CMP #'W'       ; HOOK_UNKNOWN's handler
/// $0402  BNE $0415
/// $0404  LDA #'W'
/// $0406  JSR PUTCH
/// $0409  LDA $041E
/// $040C  JSR PUTHEX
/// $040F  JSR PUTEOL
/// $0412  JMP CMD_DONE
/// $0415  JMP chain      ; its slot $0416
/// $0418  INC $041E      ; HOOK_LOOP's handler
/// $041B  JMP chain      ; its slot $041C
/// $041E  .byte 0
/// ```
fn counting() -> UploadImage {
    let bytes = vec![
        0xC9, b'W', 0xD0, 0x11, 0xA9, b'W', 0x20, 0x00, 0xFF, 0xAD, 0x1E, 0x04, 0x20, 0x03, 0xFF,
        0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF, 0x4C, 0x21, 0xFF, 0xEE, 0x1E, 0x04, 0x4C, 0x24, 0xFF,
        0x00,
    ];
    let mut image = UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes,
        }],
        vec![
            HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0400,
                chain: Some(0x0416),
            },
            HookRecord {
                kind: HookKind::Loop,
                handler: 0x0418,
                chain: Some(0x041C),
            },
        ],
    )
    .expect("an image");
    image.set_code(vec![0x0400..=0x041D]);
    image
}

/// A robot running [`counting`], uploaded as `scorpion upload` does.
fn counting_robot() -> Client<VirtualTransport> {
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &counting(), &options, &mut NoProgress).expect("uploaded");
    let ask = Command::parse(b"/1W").expect("a command");
    let first = client.ask(&ask).expect("answers");
    let second = client.ask(&ask).expect("answers");
    assert_ne!(first, second, "the count goes on while the robot runs");
    client
}

/// The extension at $0700 uploaded in front of what `client`'s robot
/// runs: its undo file.
fn in_front_kept(client: &mut Client<VirtualTransport>) -> uploader::Backup {
    let mut kept = Kept::default();
    uploader::upload_keeping(
        client,
        &extension_at(0x0700),
        &UploadOptions::default(),
        &mut NoProgress,
        &mut kept,
    )
    .expect("uploaded in front of it");
    kept.0.expect("an undo file")
}

#[test]
fn a_counter_is_told_as_changing_to_a_plain_read_and_read_live() {
    let mut client = counting_robot();
    let error = client
        .read_memory(0x0415, 16)
        .expect_err("a plain read of a counter");
    assert!(
        matches!(&error, uploader::Error::MemoryChanging { changed, .. } if changed == &[COUNT]),
        "{error:?}"
    );
    let read = client.read_live(0x0415, 16).expect("read live");
    assert_eq!(read.changing, [COUNT]);
    assert_eq!(read.bytes[..9], counting().areas()[0].bytes[0x15..0x1E]);
}

#[test]
fn a_backup_of_a_robot_counting_is_saved_and_says_where() {
    let mut client = counting_robot();
    let uploader::Saved {
        backup: saved,
        changing,
        ..
    } = uploader::backup_live(&mut client, &RomProfile::reference())
        .expect("a backup of a running robot");
    assert_eq!(changing, [COUNT]);
    // Restored over a robot whose code was damaged, it is put back and
    // verified, and the robot counts again.
    client
        .transport()
        .robot_mut()
        .robot_mut()
        .board_mut()
        .load(0x0418, &[0xEA, 0xEA, 0xEA])
        .expect("RAM");
    uploader::restore(
        &mut client,
        &saved,
        &UploadOptions::default(),
        &mut NoProgress,
    )
    .expect("restored, verified");
    let memory = client.transport().robot().robot().board().memory();
    assert_eq!(memory[0x0418..0x041B], [0xEE, 0x1E, 0x04]);
    client.read_live(COUNT, 1).expect("read live");
    assert!(client.read_memory(COUNT, 1).is_err(), "it counts again");
}

#[test]
fn a_session_attaches_beside_a_counter_after_the_code() {
    let client = counting_robot();
    let profile = RomProfile::reference();
    let mut debug = RobotDebug::attach(client, &profile, counting()).expect("attaches");
    // fresh17 F8: a write of the running counter takes, and is said to
    // be changing since, not refused as memory that is no RAM.
    assert_eq!(
        debug
            .write_as_program_live(COUNT, &[0x80])
            .expect("written"),
        [COUNT]
    );
    assert_eq!(
        debug
            .write_as_program_live(0x0600, &[1, 2])
            .expect("written"),
        [],
        "RAM that holds still"
    );
    debug
        .set_breakpoint(0x0418, &[0x0400, 0x0418])
        .expect("a breakpoint in the loop handler");
    let before = debug.read(COUNT, 1).expect("read through the stub")[0];
    debug.resume().expect("continue");
    match debug.wait_event(Duration::from_secs(1)).expect("a stop") {
        Reply::Stopped(registers) => assert_eq!(registers.pc, 0x0418),
        other => panic!("no stop at the loop handler: {other:?}"),
    }
    assert_eq!(
        debug.read(COUNT, 1).expect("read")[0],
        before.wrapping_add(1)
    );
    debug.remove_breakpoint(0x0418).expect("removed");
    debug.resume().expect("continue");
    assert_eq!(debug.compare_with_image().expect("read"), None);
    debug.detach().expect("detaches");
}

#[test]
fn another_extension_goes_in_front_of_a_counting_one_and_comes_out() {
    let mut client = counting_robot();
    let options = UploadOptions::default();
    let undo = in_front_kept(&mut client);
    // No witness covers the counter: a restore would find it changed.
    assert!(
        undo.witnesses
            .iter()
            .all(|w| !(w.address..w.address + w.len).contains(&COUNT)),
        "{:?}",
        undo.witnesses
    );
    assert!(!undo.witnesses.is_empty(), "the code the hooks go back to");
    uploader::restore(&mut client, &undo, &options, &mut NoProgress).expect("undone");
    let memory = client.transport().robot().robot().board().memory();
    let hook = usize::from(romlib::symbols::HOOK_UNKNOWN) + 1;
    assert_eq!(memory[hook..hook + 2], [0x00, 0x04], "HOOK_UNKNOWN back");
}

/// fresh17 F1: the same image uploaded again after its program counted
/// was a change (the count put back to what the image loads), so a new
/// undo file was kept, and after `test --port` twice the undo went back
/// one run only. Its data is the program's to change: the upload that
/// puts it back as built changes nothing that is installed, and the
/// older undo file is kept.
#[test]
fn the_same_image_again_after_it_counted_changes_nothing_installed() {
    let mut client = counting_robot();
    assert_ne!(
        client.read_live(COUNT, 1).expect("read").bytes,
        [0],
        "it counted"
    );
    let mut kept = Kept::default();
    let report = uploader::upload_keeping(
        &mut client,
        &counting(),
        &UploadOptions::default(),
        &mut NoProgress,
        &mut kept,
    )
    .expect("uploaded again");
    assert!(report.unchanged, "{report:?}");
    assert!(kept.1, "the older undo file kept");
    // Its code changed is a change.
    let mut areas = counting().areas().to_vec();
    areas[0].bytes[5] = b'w';
    let mut edited = UploadImage::new(areas, counting().hooks().to_vec()).expect("an image");
    edited.set_code(vec![0x0400..=0x041D]);
    let replace = UploadOptions {
        replace: true,
        ..UploadOptions::default()
    };
    let mut kept = Kept::default();
    let report =
        uploader::upload_keeping(&mut client, &edited, &replace, &mut NoProgress, &mut kept)
            .expect("uploaded");
    assert!(!report.unchanged && !kept.1, "{report:?}");
}

/// hostile17 F1: on a noisy line, a byte of static code that noise hit a
/// few times in one read was named as changing, and its value taken from
/// one (garbled) answer. Memory in use differs nearly every time it is
/// read twice; a byte noise hits now and then does not.
#[test]
fn noise_does_not_pass_static_memory_off_as_changing() {
    use uploader::transport::{FaultConfig, FaultyTransport};
    let code: Vec<u8> = (0..=255u8).map(|i| i.wrapping_mul(97)).collect();
    for seed in 0..100 {
        let mut robot = robot();
        robot
            .robot_mut()
            .robot_mut()
            .board_mut()
            .load(0x0600, &code)
            .expect("RAM");
        let faulty = FaultyTransport::new(robot, FaultConfig::noise(seed, 0.0, 0.01, 0.0));
        let mut client = uploader::client(faulty, &RomProfile::reference());
        match client.read_live(0x0600, code.len()) {
            Ok(read) => {
                assert_eq!(read.changing, [], "seed {seed}");
                assert_eq!(read.bytes, code, "seed {seed}");
            }
            // Too noisy to read is said as such, never as memory in use.
            Err(error) => assert!(
                matches!(error, uploader::Error::Unreadable { .. }),
                "seed {seed}: {error}"
            ),
        }
    }
}

/// hostile17 F4: a counter kept in the code section (data among code, as
/// hand-written 6502 often has) failed the attach's compare of the code
/// as "memory in use". Bytes the running program keeps changing are its
/// data, not code to compare.
#[test]
fn a_session_attaches_to_an_image_with_a_counter_in_its_code() {
    let client = counting_robot();
    let mut image = counting();
    image.set_code(vec![0x0400..=COUNT]);
    let profile = RomProfile::reference();
    let debug = RobotDebug::attach(client, &profile, image).expect("attaches");
    debug.detach().expect("detaches");
}

/// An extension whose handler jumps over a 16-bit counter its loop
/// handler keeps.
fn counting_16() -> UploadImage {
    // $0600  JMP $0605      ; HOOK_UNKNOWN's handler
    // $0603  .word 0        ; the counter
    // $0605  JMP chain      ; its slot $0606
    // $0608  INC $0603      ; HOOK_LOOP's handler
    // $060B  BNE $0610
    // $060D  INC $0604
    // $0610  JMP chain      ; its slot $0611
    let bytes = vec![
        0x4C, 0x05, 0x06, 0x00, 0x00, 0x4C, 0x21, 0xFF, 0xEE, 0x03, 0x06, 0xD0, 0x03, 0xEE, 0x04,
        0x06, 0x4C, 0x24, 0xFF,
    ];
    UploadImage::new(
        vec![Area {
            address: 0x0600,
            bytes,
        }],
        vec![
            HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0600,
                chain: Some(0x0606),
            },
            HookRecord {
                kind: HookKind::Loop,
                handler: 0x0608,
                chain: Some(0x0611),
            },
        ],
    )
    .expect("an image")
}

/// Runs the robot until the slow byte of [`counting_16`]'s counter has
/// moved from what it was.
fn until_the_slow_byte_moved(client: &mut Client<VirtualTransport>) {
    let high = |client: &mut Client<VirtualTransport>| {
        client.transport().robot().robot().board().memory()[0x0604]
    };
    let before = high(client);
    for _ in 0..200 {
        if high(client) != before {
            return;
        }
        client.probe().expect("the robot answers");
    }
    panic!("the slow byte never moved");
}

/// hostile17 F3: an extension whose handler jumps over a 16-bit counter
/// its loop handler keeps: the undo file of an upload in front of it
/// witnessed the handler's first 16 bytes, the counter's slow byte among
/// them, and once that byte moved the undo was refused for good ("not
/// what it was ... another upload replaced it"). The window ends at the
/// handler's first `JMP`.
#[test]
fn an_undo_in_front_of_a_counter_after_a_handlers_jump_goes_through() {
    let counting = counting_16();
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &counting, &options, &mut NoProgress).expect("installed");
    let undo_file = in_front_kept(&mut client);
    until_the_slow_byte_moved(&mut client);
    let undo = UploadOptions {
        undo: true,
        ..options
    };
    uploader::restore(&mut client, &undo_file, &undo, &mut NoProgress).expect("undone");
    let memory = client.transport().robot().robot().board().memory();
    let hook = usize::from(romlib::symbols::HOOK_UNKNOWN) + 1;
    assert_eq!(memory[hook..hook + 2], [0x00, 0x06], "HOOK_UNKNOWN back");
}

/// recheck18 F3: a 16-bit counter in the code section. Its fast byte was
/// taken as data (it changes as it is read), but its slow byte, which had
/// moved and held still while it was read, failed the compare as "the
/// robot does not hold the image". The bytes right after a changing one
/// are its counter's.
#[test]
fn a_session_attaches_beside_a_sixteen_bit_counter_in_its_code() {
    let mut image = counting_16();
    image.set_code(vec![0x0600..=0x0612]);
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &image, &options, &mut NoProgress).expect("installed");
    until_the_slow_byte_moved(&mut client);
    let profile = RomProfile::reference();
    let mut debug = RobotDebug::attach(client, &profile, image).expect("attaches");
    assert_eq!(debug.compare_with_image().expect("compares"), None);
    debug.detach().expect("detaches");
}

/// hostile19 F3: an image that differs from the robot's only right after
/// a counter among the code was attached without a word, its byte there
/// taken as the counter's; a breakpoint set there and removed then put
/// the image's byte back over the robot's instruction, and the installed
/// extension broke. The bytes after a counter are taken as the robot
/// holds them, and attach says it did not compare them.
#[test]
fn bytes_after_a_counter_among_the_code_are_the_robots() {
    let mut image = counting_16();
    image.set_code(vec![0x0600..=0x0612]);
    let options = UploadOptions::default();
    let mut client = uploader::client(robot(), &options.profile);
    upload(&mut client, &image, &options, &mut NoProgress).expect("installed");
    let mut bytes = image.areas()[0].bytes.clone();
    bytes[5] = 0x6C;
    let mut wrong = UploadImage::new(
        vec![Area {
            address: 0x0600,
            bytes,
        }],
        image.hooks().to_vec(),
    )
    .expect("an image");
    wrong.set_code(vec![0x0600..=0x0612]);
    let profile = RomProfile::reference();
    let mut debug = RobotDebug::attach(client, &profile, wrong).expect("attaches");
    let note = debug.recovery().data_note().expect("a note");
    // The counter's high byte at $0604 may move during the read too.
    assert!(
        note.contains("note: $0603 among") || note.contains("note: $0603, $0604 among"),
        "{note}"
    );
    assert!(note.contains("$0605 after it differ"), "{note}");
    assert_eq!(debug.image().byte(0x0605), Some(0x4C), "the robot's byte");
    let entries = [0x0600, 0x0605, 0x0608, 0x0610];
    debug.set_breakpoint(0x0605, &entries).expect("set");
    debug.remove_breakpoint(0x0605).expect("removed");
    assert_eq!(debug.compare_with_image().expect("compares"), None);
    let mut client = debug.detach().expect("detaches");
    let memory = client.transport().robot().robot().board().memory();
    assert_eq!(memory[0x0605], 0x4C, "the robot's JMP as it was");
}
