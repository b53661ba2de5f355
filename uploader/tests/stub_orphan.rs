//! What a killed debug session leaves, and where the stub goes (issue 27,
//! the hostile tester's F1 to F5 of the `orphan` round): an upload, a
//! restore or an undo finding a stub a killed session left hooked refuses
//! before anything is written (chaining to it made a loop); the stub goes
//! where no installed extension and no RAM loader lies; a breakpoint a
//! killed session left on a chain slot's `JMP` is taken out with the
//! robot's bytes, not the image's. A hook whose chain comes back into
//! what an upload or a session writes (hostile10's F2 to F4) is refused
//! before anything is written.

mod common;

use common::stub::handler;
use isa::objfmt::{HookKind, HookRecord};
use romlib::protocol::{Answer, Command, Extension};
use romlib::symbols::{HOOK_UNKNOWN, USER_RAM_END};
use std::time::Duration;
use uploader::stub::{Reply, RobotDebug};
use uploader::transport::VirtualTransport;
use uploader::{
    Area, Client, Error, LoaderChoice, NoProgress, RomProfile, UploadImage, UploadOptions,
};

const WAIT: Duration = Duration::from_secs(1);

/// `LDA $0480` in the handler, where the breakpoints go.
const AT: u16 = 0x040C;

fn options() -> UploadOptions {
    UploadOptions {
        loader: LoaderChoice::Never,
        ..UploadOptions::default()
    }
}

/// An extension at `base` whose `/1<letter>` answers `<letter>`; anything
/// else falls through its chain slot (`base + 20`).
fn answering(base: u16, letter: u8) -> UploadImage {
    let bytes = vec![
        0xE0, 0x01, // CPX #1
        0xD0, 0x0F, // BNE chain
        0xC9, letter, // CMP #letter
        0xD0, 0x0B, // BNE chain
        0xA9, letter, // LDA #letter
        0x20, 0x00, 0xFF, // JSR PUTCH
        0x20, 0x09, 0xFF, // JSR PUTEOL
        0x4C, 0x1E, 0xFF, // JMP CMD_DONE
        0x4C, 0x21, 0xFF, // chain: JMP BAD_COMMAND
    ];
    UploadImage::new(
        vec![Area {
            address: base,
            bytes,
        }],
        vec![HookRecord {
            kind: HookKind::Unknown,
            handler: base,
            chain: Some(base + 20),
        }],
    )
    .expect("an image")
}

/// `images` uploaded in turn onto a fresh virtual robot, each verified.
fn uploaded(images: &[&UploadImage]) -> Client<VirtualTransport> {
    let profile = RomProfile::reference();
    let mut client = uploader::client(common::robot(), &profile);
    for image in images {
        uploader::upload(&mut client, image, &options(), &mut NoProgress).expect("uploaded");
    }
    client
}

fn attach(client: Client<VirtualTransport>, image: &UploadImage) -> RobotDebug<VirtualTransport> {
    RobotDebug::attach(client, &RomProfile::reference(), image.clone()).expect("attaches")
}

/// A session with a breakpoint at [`AT`], its process killed while the
/// robot runs.
fn killed_session(image: &UploadImage) -> Client<VirtualTransport> {
    let client = uploaded(&[image]);
    let mut first = attach(client, image);
    first.set_breakpoint(AT, &[]).expect("set");
    first.abandon()
}

/// What an upload or a restore writes: the hooks, the table of
/// installed extensions, user RAM (the ROM's own workspace changes as it
/// answers).
fn written(client: &mut Client<VirtualTransport>) -> Vec<u8> {
    let memory = memory(client);
    let profile = RomProfile::reference();
    let hook = usize::from(HOOK_UNKNOWN);
    let mut kept = memory[hook..hook + 6].to_vec();
    if let Some((table, capacity)) = profile.table {
        let table = usize::from(table);
        kept.extend_from_slice(
            &memory[table..table + capacity * (1 + romlib::installed::ENTRY_LEN)],
        );
    }
    kept.extend_from_slice(&memory[0x0400..=usize::from(USER_RAM_END)]);
    kept
}

fn memory(client: &mut Client<VirtualTransport>) -> Vec<u8> {
    client
        .transport()
        .robot_mut()
        .robot()
        .board()
        .memory()
        .to_vec()
}

/// `/1<letter>`'s answer, if one came.
fn ask(client: &mut Client<VirtualTransport>, letter: u8) -> Option<Answer> {
    let command = Command::Extension(Extension::new(vec![letter]).expect("a command"));
    client.listen(&command).expect("the line works")
}

fn refused_naming_the_stub(result: uploader::Result<impl std::fmt::Debug>, stub: u16) {
    match result {
        Err(error @ Error::DebugStubHooked { .. }) => {
            let Error::DebugStubHooked { stub: found, .. } = &error else {
                unreachable!()
            };
            assert_eq!(*found, stub, "{error}");
            let said = error.to_string();
            assert!(
                said.contains("debug stub") && said.contains("HOOK_UNKNOWN"),
                "{said}"
            );
            let help = miette::Diagnostic::help(&error).map(|h| h.to_string());
            assert!(
                help.as_deref()
                    .is_some_and(|h| h.contains("scorpion debug --port")),
                "{help:?}"
            );
        }
        other => panic!("not refused: {other:?}"),
    }
}

#[test]
fn an_upload_of_the_same_image_over_a_stub_left_hooked_is_refused_with_nothing_written() {
    let image = handler();
    let stub = {
        let client = uploaded(&[&image]);
        attach(client, &image).stub().address
    };
    let mut client = killed_session(&image);
    let before = written(&mut client);
    let result = uploader::upload(&mut client, &image, &options(), &mut NoProgress);
    refused_naming_the_stub(result, stub);
    assert!(written(&mut client) == before, "something was written");
    // What the refusal says to run cleans it up; then the upload works,
    // and an unknown command falls through to the ROM (no loop).
    let debug = attach(client, &image);
    assert_eq!(debug.recovery().removed, [AT]);
    let mut client = debug.detach().expect("detached");
    uploader::upload(&mut client, &image, &options(), &mut NoProgress).expect("uploaded");
    let fresh = ask(&mut uploaded(&[&image]), b'Z');
    assert_eq!(
        ask(&mut client, b'Z'),
        fresh,
        "`/1Z` as on a robot never debugged"
    );
    assert_eq!(ask(&mut client, b'Q'), Some(Answer::Text("Q42".into())));
}

#[test]
fn an_upload_of_another_image_over_a_stub_left_hooked_is_refused() {
    let image = handler();
    let mut client = killed_session(&image);
    let before = written(&mut client);
    let other = answering(0x0600, b'U');
    let result = uploader::upload(&mut client, &other, &options(), &mut NoProgress);
    assert!(
        matches!(result, Err(Error::DebugStubHooked { .. })),
        "{result:?}"
    );
    assert!(written(&mut client) == before, "something was written");
}

#[test]
fn a_restore_over_a_stub_left_hooked_is_refused() {
    let image = handler();
    let profile = RomProfile::reference();
    let mut client = uploaded(&[&image]);
    let saved = uploader::backup(&mut client, &profile).expect("a backup");
    let mut first = attach(client, &image);
    first.set_breakpoint(AT, &[]).expect("set");
    let mut client = first.abandon();
    let before = written(&mut client);
    let result = uploader::restore(&mut client, &saved, &options(), &mut NoProgress);
    assert!(
        matches!(result, Err(Error::DebugStubHooked { .. })),
        "{result:?}"
    );
    assert!(written(&mut client) == before, "something was written");
}

/// fresh19 F11: the undo of the upload a killed session debugged was
/// refused as "a later upload was chained ahead", with advice that could
/// not help; the stub is named, as an upload and a restore name it.
#[test]
fn an_undo_over_a_stub_left_hooked_names_the_stub() {
    let image = handler();
    let mut client = uploaded(&[]);
    let mut kept = common::Kept::default();
    uploader::upload_keeping(&mut client, &image, &options(), &mut NoProgress, &mut kept)
        .expect("uploaded");
    let mut first = attach(client, &image);
    first.set_breakpoint(AT, &[]).expect("set");
    let mut client = first.abandon();
    let before = written(&mut client);
    let undo = UploadOptions {
        undo: true,
        ..options()
    };
    let result = uploader::restore(&mut client, &kept.0.expect("kept"), &undo, &mut NoProgress);
    assert!(
        matches!(result, Err(Error::DebugStubHooked { .. })),
        "{result:?}"
    );
    assert!(written(&mut client) == before, "something was written");
}

#[test]
fn the_stub_goes_beside_an_installed_extension_not_over_it() {
    // An extension at the very top of user RAM, where the stub went.
    let top = answering(USER_RAM_END - 21, b'U');
    let image = handler();
    let client = uploaded(&[&top, &image]);
    let mut debug = attach(client, &image);
    let stub = debug.stub().clone();
    let end = u32::from(stub.address) + stub.bytes.len() as u32;
    assert!(
        end <= u32::from(USER_RAM_END - 21),
        "the stub at ${:04X}-${end:04X} meets the extension at ${:04X}",
        stub.address,
        USER_RAM_END - 21
    );
    // The installed extension still answers, through the stub's chain.
    assert_eq!(
        debug.command(b"/1U", WAIT).expect("sent"),
        Reply::Answer(b"U\r".to_vec())
    );
    debug.detach().expect("detached");
}

#[test]
fn the_stub_goes_beside_the_ram_loader_not_over_it() {
    let image = handler();
    let client = uploaded(&[&image]);
    let debug = attach(client, &image);
    let stub = debug.stub().clone();
    let loader = uploader::loader_plan(
        &RomProfile::reference(),
        &image,
        (9600, uploader::FAST_BAUD),
    )
    .expect("links")
    .expect("room for the loader");
    let (start, end) = (
        u32::from(loader.code.address),
        u32::from(loader.code.address) + loader.code.bytes.len() as u32,
    );
    let stub_end = u32::from(stub.address) + stub.bytes.len() as u32;
    assert!(
        stub_end <= start || end <= u32::from(stub.address),
        "the stub at ${:04X} meets the loader at ${start:04X}-${end:04X}",
        stub.address
    );
    let zero_page = u16::from(stub.zero_page);
    let loader_zp = u16::from(*loader.zero_page.start())..=u16::from(*loader.zero_page.end());
    assert!(
        !loader_zp.contains(&zero_page) && !loader_zp.contains(&(zero_page + 1)),
        "the stub's zero page ${zero_page:02X} meets the loader's {loader_zp:?}"
    );
}

#[test]
fn a_session_killed_with_a_breakpoint_on_a_chain_slot_jmp_is_cleaned_up_with_the_robots_bytes() {
    // The handler chained to an installed extension: its chain slot holds
    // that extension's handler, the image's placeholder does not.
    let other = answering(0x0600, b'U');
    let image = handler();
    let client = uploaded(&[&other, &image]);
    let chained = {
        let mut client = client;
        let held = memory(&mut client)[0x0400..0x0403].to_vec();
        assert_eq!(held, [0x4C, 0x00, 0x06], "the chain slot as uploaded");
        client
    };
    let mut first = attach(chained, &image);
    first.set_breakpoint(0x0400, &[]).expect("set");
    let client = first.abandon();
    let mut second = attach(client, &image);
    assert_eq!(second.recovery().removed, [0x0400]);
    assert_eq!(second.read(0x0400, 3).expect("read"), [0x4C, 0x00, 0x06]);
    assert_eq!(second.compare_with_image().expect("read"), None);
    assert_eq!(
        second.command(b"/1U", WAIT).expect("sent"),
        Reply::Answer(b"U\r".to_vec())
    );
    let mut client = second.detach().expect("detached");
    let hook = usize::from(HOOK_UNKNOWN);
    assert_eq!(memory(&mut client)[hook..hook + 3], [0x4C, 0x03, 0x04]);
}

/// hostile8 F4: `HOOK_UNKNOWN` pointed by hand into a left stub's code,
/// not at its handler, was not taken for the stub: an upload chained to
/// it (the next unknown command ran the stub from the middle). Now the
/// upload refuses it, and the session the refusal names takes it out and
/// gives the hook back to what the stub chains to.
#[test]
fn a_hook_pointed_inside_a_stub_left_hooked_is_that_stub() {
    let image = handler();
    let stub = {
        let client = uploaded(&[&image]);
        attach(client, &image).stub().clone()
    };
    for target in [stub.handler + 1, stub.address, stub.code_end - 8] {
        let mut client = killed_session(&image);
        client
            .transport()
            .robot_mut()
            .robot_mut()
            .board_mut()
            .load(HOOK_UNKNOWN + 1, &target.to_le_bytes())
            .expect("RAM");
        let before = written(&mut client);
        let result = uploader::upload(&mut client, &image, &options(), &mut NoProgress);
        refused_naming_the_stub(result, stub.address);
        assert!(
            written(&mut client) == before,
            "${target:04X}: something was written"
        );
        let debug = attach(client, &image);
        let recovery = debug.recovery().clone();
        assert!(recovery.hooked, "${target:04X}: {recovery:?}");
        assert_eq!(recovery.hooked_inside, Some(target));
        assert_eq!(recovery.removed, [AT]);
        assert!(
            recovery.describe().contains(&format!("${target:04X}")),
            "{}",
            recovery.describe()
        );
        let mut client = debug.detach().expect("detached");
        let hook = usize::from(HOOK_UNKNOWN);
        assert_eq!(
            memory(&mut client)[hook..hook + 3],
            [0x4C, 0x03, 0x04],
            "${target:04X}: the hook back at the image's handler"
        );
        uploader::upload(&mut client, &image, &options(), &mut NoProgress).expect("uploaded");
        assert_eq!(ask(&mut client, b'Q'), Some(Answer::Text("Q42".into())));
        let fresh = ask(&mut uploaded(&[&image]), b'Z');
        assert_eq!(ask(&mut client, b'Z'), fresh, "${target:04X}: `/1Z`");
    }
}

/// hostile10 F11: the hook at the left stub's own `JMP PREV` (its code's
/// last instruction) or in its data, where a few bytes cannot tell a
/// stub: the clean-up attach refused ("leads into where the stub goes"),
/// and the killed session's breakpoint stayed in the code. The code where
/// this image's stub goes is taken as its stub, hooked.
#[test]
fn a_hook_at_a_left_stubs_last_jump_or_its_data_is_that_stub() {
    let image = handler();
    let stub = {
        let client = uploaded(&[&image]);
        attach(client, &image).stub().clone()
    };
    let data = stub.code_end + 4;
    assert!(stub.contains(data));
    for target in [stub.code_end - 3, data] {
        let mut client = killed_session(&image);
        client
            .transport()
            .robot_mut()
            .robot_mut()
            .board_mut()
            .load(HOOK_UNKNOWN + 1, &target.to_le_bytes())
            .expect("RAM");
        let debug = attach(client, &image);
        let recovery = debug.recovery().clone();
        assert!(recovery.hooked, "${target:04X}: {recovery:?}");
        assert_eq!(recovery.hooked_inside, Some(target));
        assert_eq!(recovery.removed, [AT]);
        let mut client = debug.detach().expect("detached");
        let hook = usize::from(HOOK_UNKNOWN);
        assert_eq!(
            memory(&mut client)[hook..hook + 3],
            [0x4C, 0x03, 0x04],
            "${target:04X}: the hook back at the image's handler"
        );
        assert_eq!(ask(&mut client, b'Q'), Some(Answer::Text("Q42".into())));
    }
}

/// Puts `bytes` into the robot's RAM at `at` as an owner (or a glitch)
/// would, and points `HOOK_UNKNOWN` at `target`.
fn by_hand(client: &mut Client<VirtualTransport>, at: u16, bytes: &[u8], target: u16) {
    let board = client.transport().robot_mut().robot_mut().board_mut();
    board.load(at, bytes).expect("RAM");
    board
        .load(HOOK_UNKNOWN + 1, &target.to_le_bytes())
        .expect("RAM");
}

/// hostile10 F3: `HOOK_UNKNOWN` into the middle of the image's place
/// (code nobody's table names) was taken for an earlier copy of the image
/// and its "chain slot" read: the hook went to $0000 and the image chained
/// there. Now the hook goes back to the ROM's target, and so does the chain.
#[test]
fn a_hook_into_the_middle_of_the_upload_goes_back_to_the_rom() {
    let image = answering(0x0400, b'U');
    let mut client = uploaded(&[]);
    // `JMP BAD_COMMAND` at $0410, hooked.
    by_hand(&mut client, 0x0410, &[0x4C, 0x21, 0xFF], 0x0410);
    uploader::upload(&mut client, &image, &options(), &mut NoProgress).expect("uploaded");
    let memory = memory(&mut client);
    assert_eq!(memory[0x0413..0x0416], [0x4C, 0x21, 0xFF], "the chain slot");
    assert_eq!(ask(&mut client, b'U'), Some(Answer::Text("U".into())));
    let fresh = ask(&mut uploaded(&[&image]), b'Z');
    assert_eq!(
        ask(&mut client, b'Z'),
        fresh,
        "`/1Z` falls through to the ROM"
    );
}

/// hostile10 F4: `HOOK_UNKNOWN` at an owner's `JMP` back into an earlier
/// copy of the image: chained to it, the image jumped to itself for ever
/// at the next unknown command (exit 0). Refused, nothing written.
#[test]
fn an_upload_whose_chain_comes_back_into_the_image_is_refused() {
    let image = answering(0x0400, b'U');
    let mut client = uploaded(&[&image]);
    by_hand(&mut client, 0x0600, &[0x4C, 0x00, 0x04], 0x0600);
    let before = written(&mut client);
    let result = uploader::upload(&mut client, &image, &options(), &mut NoProgress);
    match &result {
        Err(error @ Error::ChainComesBack { path, .. }) => {
            assert_eq!(path, "$0600 -> $0400", "{error}");
            assert!(error.to_string().contains("HOOK_UNKNOWN"), "{error}");
        }
        other => panic!("not refused: {other:?}"),
    }
    assert!(written(&mut client) == before, "something was written");
    // The robot as it was: `/1U` still answers through the owner's JMP.
    assert_eq!(ask(&mut client, b'U'), Some(Answer::Text("U".into())));
}

/// hostile10 F4, the stub's way: `HOOK_UNKNOWN` at the last instruction of
/// a stub a killed session left (`JMP PREV`, to the image's handler) was
/// neither taken for the stub nor followed: the image chained to it.
#[test]
fn an_upload_whose_chain_is_a_left_stubs_jmp_is_refused() {
    let image = handler();
    let client = uploaded(&[&image]);
    let debug = attach(client, &image);
    let stub = debug.stub().clone();
    let mut client = debug.abandon();
    by_hand(&mut client, stub.code_end - 3, &[], stub.code_end - 3);
    let before = written(&mut client);
    let result = uploader::upload(&mut client, &image, &options(), &mut NoProgress);
    assert!(
        matches!(
            result,
            Err(Error::ChainComesBack { .. } | Error::DebugStubHooked { .. })
        ),
        "{result:?}"
    );
    assert!(written(&mut client) == before, "something was written");
}

/// hostile10 F2: an owner's `JMP` into a stub an earlier session left in
/// RAM (unhooked), hooked: the next session wrote its stub there and
/// chained it to that `JMP`, a loop (the robot dead until reset). Attach
/// refuses before it writes anything; the upload too, through the old
/// stub's chain.
#[test]
fn an_attach_whose_chain_comes_back_into_the_stubs_place_is_refused() {
    let image = handler();
    let looped = || {
        let client = uploaded(&[&image]);
        let debug = attach(client, &image);
        let stub = debug.stub().clone();
        let mut client = debug.detach().expect("detached");
        let [low, high] = stub.handler.to_le_bytes();
        by_hand(&mut client, 0x0600, &[0x4C, low, high], 0x0600);
        assert_eq!(ask(&mut client, b'Q'), Some(Answer::Text("Q42".into())));
        (client, stub)
    };
    let (client, stub) = looped();
    let result = RobotDebug::attach(client, &RomProfile::reference(), image.clone());
    let Err(uploader::stub::StubError::Refused { reason, .. }) = result else {
        panic!(
            "not refused: {:?}",
            result.map(|debug| debug.stub().clone())
        );
    };
    assert!(
        reason.contains(&format!("$0600 -> ${:04X}", stub.handler)),
        "{reason}"
    );
    let (mut client, _) = looped();
    let before = written(&mut client);
    let result = uploader::upload(&mut client, &image, &options(), &mut NoProgress);
    match &result {
        Err(Error::ChainComesBack { path, .. }) => {
            assert_eq!(path, &format!("$0600 -> ${:04X} -> $0403", stub.handler));
        }
        other => panic!("not refused: {other:?}"),
    }
    assert!(written(&mut client) == before, "something was written");
}

/// hostile10 F1: a backup taken with a killed session's stub hooked held
/// it, and restoring the file brought the stub back hooked with no host
/// (and its breakpoint's `JSR`), exit 0. The backup is refused; a file
/// that holds a stub hooked (taken before this, or crafted) is refused by
/// the restore, with nothing written.
#[test]
fn a_backup_with_a_stub_hooked_is_refused_and_so_is_restoring_one() {
    let image = handler();
    let profile = RomProfile::reference();
    let mut client = killed_session(&image);
    let result = uploader::backup(&mut client, &profile);
    assert!(
        matches!(result, Err(Error::DebugStubHooked { .. })),
        "{:?}",
        result.map(|_| "a backup")
    );
    // A file as a backup taken then held it: the stub in RAM (a session
    // detached leaves it there, unhooked), the hook pointed at it.
    let client = uploaded(&[&image]);
    let debug = attach(client, &image);
    let stub = debug.stub().clone();
    let mut client = debug.detach().expect("detached");
    let mut saved = uploader::backup(&mut client, &profile).expect("a backup");
    for hook in &mut saved.hooks {
        if hook.0 == HookKind::Unknown {
            hook.1 = stub.handler;
        }
    }
    let before = written(&mut client);
    match uploader::restore(&mut client, &saved, &options(), &mut NoProgress) {
        Err(error @ Error::BackupHoldsDebugStub { .. }) => {
            let said = error.to_string();
            assert!(
                said.contains(&format!("${:04X}", stub.address)) && said.contains("HOOK_UNKNOWN"),
                "{said}"
            );
        }
        other => panic!("not refused: {other:?}"),
    }
    assert!(written(&mut client) == before, "something was written");
}

/// fresh10 F14: after a `/1R` (the table cleared, the hooks back at the
/// ROM, RAM kept) the image's code was still in RAM: attach took it,
/// hooked the stub ahead of the ROM, and breakpoints were set that no
/// command could reach. Refused, saying the image is not installed.
#[test]
fn an_image_in_ram_but_not_installed_is_refused() {
    let image = handler();
    let mut client = uploaded(&[&image]);
    let command = Command::parse(b"/1R").expect("a command");
    let _ = client.listen(&command).expect("the line works");
    let result = RobotDebug::attach(client, &RomProfile::reference(), image.clone());
    let Err(uploader::stub::StubError::Refused { reason, .. }) = result else {
        panic!(
            "not refused: {:?}",
            result.map(|debug| debug.stub().clone())
        );
    };
    assert!(
        reason.contains("not installed") && reason.contains("$0403"),
        "{reason}"
    );
}

/// hostile10 F7: only a `JMP` at the hook's target was followed: a `NOP`
/// before it, a `JMP (ind)` or a branch made the loop again (exit 0).
/// The code at the target is run on the host over the robot's memory to
/// where it goes; an owner's handler that falls to the ROM still chains.
#[test]
fn code_that_comes_back_into_the_image_any_way_is_refused() {
    let image = answering(0x0400, b'U');
    for (what, code) in [
        ("NOP; JMP $0400", &[0xEA, 0x4C, 0x00, 0x04][..]),
        (
            "JMP ($0608)",
            &[0x6C, 0x08, 0x06, 0xEA, 0xEA, 0xEA, 0xEA, 0xEA, 0x00, 0x04][..],
        ),
        (
            "CLC; BCC +1; .byte $50; NOP; JMP $0400",
            &[0x18, 0x90, 0x01, 0x50, 0xEA, 0x4C, 0x00, 0x04][..],
        ),
    ] {
        let mut client = uploaded(&[&image]);
        by_hand(&mut client, 0x0600, code, 0x0600);
        let before = written(&mut client);
        let result = uploader::upload(&mut client, &image, &options(), &mut NoProgress);
        assert!(
            matches!(result, Err(Error::ChainComesBack { .. })),
            "{what}: {result:?}"
        );
        assert!(
            written(&mut client) == before,
            "{what}: something was written"
        );
    }
    // CMP #'W'; BNE +3; JMP CMD_DONE; JMP BAD_COMMAND: to the ROM.
    let mut client = uploaded(&[]);
    by_hand(
        &mut client,
        0x0600,
        &[0xC9, b'W', 0xD0, 0x03, 0x4C, 0x1E, 0xFF, 0x4C, 0x21, 0xFF],
        0x0600,
    );
    uploader::upload(&mut client, &image, &options(), &mut NoProgress).expect("uploaded");
    assert_eq!(memory(&mut client)[0x0413..0x0416], [0x4C, 0x00, 0x06]);
    assert_eq!(ask(&mut client, b'U'), Some(Answer::Text("U".into())));
}
