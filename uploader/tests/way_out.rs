//! Where an upload chains the image: to what the hook (or the chain slot
//! of an earlier copy) leads to, unless that is no way for a command to go
//! (a hook or chain slot damaged by hand into the ROM's zero page, the
//! middle of the ROM, memory holding a `BRK`). Then the image falls
//! through to the ROM's target, and says so (hostile15 F1, F2). A way out
//! into an owner's code that gets somewhere is kept.

mod common;

use common::{extension_at, robot};
use isa::objfmt::HookKind;
use romlib::protocol::Command;
use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use uploader::transport::VirtualTransport;
use uploader::{Client, UploadOptions, upload};
use uploader::{Event, Phase, Progress};

/// The ways out dropped, as the progress heard them, and where each was
/// read where that was not the hook itself.
#[derive(Default)]
struct Heard(Vec<u16>, Vec<Option<u16>>);

impl Progress for Heard {
    fn phase(&mut self, _phase: Phase, _total: usize) {}
    fn advanced(&mut self, _done: usize) {}
    fn event(&mut self, event: &Event) {
        if let Event::WayOutDropped { from, slot, .. } = event {
            self.0.push(*from);
            self.1.push(*slot);
        }
    }
}

fn word(client: &mut Client<VirtualTransport>, at: u16) -> u16 {
    let memory = client.transport().robot().robot().board().memory();
    u16::from_le_bytes([memory[usize::from(at)], memory[usize::from(at) + 1]])
}

fn poke(client: &mut Client<VirtualTransport>, at: u16, bytes: &[u8]) {
    let board = client.transport().robot_mut().robot_mut().board_mut();
    board.load(at, bytes).expect("RAM");
}

/// A command nobody handles goes down the chain and the robot still
/// answers after it (a jam would leave it silent).
fn answers_after_an_unknown_command(client: &mut Client<VirtualTransport>) {
    let unknown = Command::parse(b"/1Z").expect("a command");
    let _ = client.listen(&unknown);
    client.probe().expect("the robot answers");
}

#[test]
fn a_hook_damaged_by_hand_is_no_way_out_for_a_new_image() {
    let options = UploadOptions::default();
    let image = extension_at(0x0400);
    // The ROM's zero page, the middle of the ROM, a KIM-bus page of zeros
    // (a BRK), a loop in user RAM.
    for (target, code) in [
        (0x0021u16, &[][..]),
        (0xF800, &[][..]),
        (0x2121, &[][..]),
        (0x0700, &[0xEA, 0x4C, 0x01, 0x07][..]),
        (0x0700, &[0x20, 0x00, 0x07][..]),
    ] {
        let mut client = uploader::client(robot(), &options.profile);
        poke(&mut client, 0x0700, code);
        poke(&mut client, HOOK_UNKNOWN + 1, &target.to_le_bytes());
        let mut heard = Heard::default();
        let report = upload(&mut client, &image, &options, &mut heard).expect("uploaded");
        assert_eq!(word(&mut client, 0x0401), BAD_COMMAND, "${target:04X}");
        assert_eq!(report.dropped, [(HookKind::Unknown, target)]);
        assert_eq!(heard.0, [target], "said as it happens");
        assert_eq!(word(&mut client, HOOK_UNKNOWN + 1), 0x0403);
        answers_after_an_unknown_command(&mut client);
    }
    // An owner's code that gets to the ROM's target is a way out: by a
    // JMP after a delay of 512 instructions, or by the jump-table idiom
    // (the target less one pushed, then RTS).
    for code in [
        &[0xA2, 0x00, 0xCA, 0xD0, 0xFD, 0x4C, 0x21, 0xFF][..],
        &[0xA9, 0xFF, 0x48, 0xA9, 0x20, 0x48, 0x60][..],
        // A call to a subroutine in RAM that returns, and one into the ROM.
        &[0x20, 0x08, 0x07, 0x4C, 0x21, 0xFF, 0xEA, 0xEA, 0xE8, 0x60][..],
        &[0x20, 0x00, 0xFF, 0x4C, 0x21, 0xFF][..],
    ] {
        let mut client = uploader::client(robot(), &options.profile);
        poke(&mut client, 0x0700, code);
        poke(&mut client, HOOK_UNKNOWN + 1, &[0x00, 0x07]);
        let report =
            upload(&mut client, &image, &options, &mut Heard::default()).expect("uploaded");
        assert_eq!(word(&mut client, 0x0401), 0x0700, "kept: {code:02X?}");
        assert!(report.dropped.is_empty(), "{code:02X?}");
    }
}

/// hostile15 F1: with two extensions chained (the hook to the second, its
/// slot to the first), the first's slot damaged by hand, the first
/// uploaded again: it is taken out of the chain by pointing the second's
/// slot where the first fell through. That was the damaged way, hooked.
/// Now the ROM's target is passed on, and the first goes back behind the
/// second falling through to it.
#[test]
fn a_damaged_way_out_is_not_passed_on_to_the_extension_before() {
    let options = UploadOptions::default();
    let (first, second) = (extension_at(0x0400), extension_at(0x0500));
    for damage in [0x0150u16, 0xC010, 0xF800] {
        let mut client = uploader::client(robot(), &options.profile);
        for image in [&first, &second] {
            upload(&mut client, image, &options, &mut Heard::default()).expect("installed");
        }
        assert_eq!(
            word(&mut client, 0x0501),
            0x0403,
            "the second falls to the first"
        );
        poke(&mut client, 0x0401, &damage.to_le_bytes());
        upload(&mut client, &first, &options, &mut Heard::default()).expect("again");
        // hostile14 F6b: the first goes back where it was, behind the
        // second, and falls through to the ROM, not to the damage.
        assert_eq!(word(&mut client, HOOK_UNKNOWN + 1), 0x0503);
        assert_eq!(
            word(&mut client, 0x0501),
            0x0403,
            "the second falls to the first"
        );
        assert_eq!(
            word(&mut client, 0x0401),
            BAD_COMMAND,
            "the first falls to the ROM, not to ${damage:04X}"
        );
        answers_after_an_unknown_command(&mut client);
    }
}

/// hostile15 F7: a way out damaged into the middle of another installed
/// extension (past its handler) was kept, and that extension's command then
/// answered wrong. No chain goes into an extension but at its handler.
#[test]
fn a_way_out_into_the_middle_of_another_extension_is_dropped() {
    let options = UploadOptions::default();
    let (first, second) = (extension_at(0x0400), extension_at(0x0500));
    let mut client = uploader::client(robot(), &options.profile);
    for image in [&second, &first] {
        upload(&mut client, image, &options, &mut Heard::default()).expect("installed");
    }
    assert_eq!(
        word(&mut client, 0x0401),
        0x0503,
        "the first falls to the second"
    );
    poke(&mut client, 0x0401, &0x0505u16.to_le_bytes());
    let mut heard = Heard::default();
    upload(&mut client, &first, &options, &mut heard).expect("again");
    assert_eq!(heard.0, [0x0505]);
    assert_eq!(word(&mut client, 0x0401), BAD_COMMAND);
    answers_after_an_unknown_command(&mut client);
}

/// recheck27 P2: HOOK_UNKNOWN pointed by hand at code in the place the
/// upload takes, whose chain slot (as the image has it) holds zeros: the
/// warning said "HOOK_UNKNOWN led to $0000". It says where $0000 was read.
#[test]
fn a_way_out_read_from_the_uploads_own_place_says_where_it_was_read() {
    let options = UploadOptions::default();
    let image = extension_at(0x0400);
    let mut client = uploader::client(robot(), &options.profile);
    let [lo, hi] = BAD_COMMAND.to_le_bytes();
    poke(&mut client, 0x0403, &[0x4C, lo, hi]);
    poke(&mut client, HOOK_UNKNOWN + 1, &0x0403u16.to_le_bytes());
    let mut heard = Heard::default();
    upload(&mut client, &image, &options, &mut heard).expect("uploaded");
    assert_eq!((heard.0, heard.1), (vec![0x0000], vec![Some(0x0401)]));
    assert_eq!(word(&mut client, 0x0401), BAD_COMMAND);
    assert_eq!(word(&mut client, HOOK_UNKNOWN + 1), 0x0403);
}
