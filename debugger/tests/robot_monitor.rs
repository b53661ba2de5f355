//! The monitor's language on a robot through the debug stub
//! (`debugger::robot`), over the virtual Scorpion's line: what a robot
//! cannot do is refused with the reason, and `display` expressions are
//! read with `/7R` while it runs and from the stub at a stop.

use isa::objfmt::{HookKind, HookRecord};
use romlib::VirtualScorpion;
use uploader::stub::RobotDebug;
use uploader::transport::VirtualTransport;
use uploader::{Area, RomProfile, UploadImage};

use debugger::monitor::{Failure, Reply};
use debugger::robot::RobotMonitor;

/// `/1Q` answers `Q` and the byte at $0480 (as in uploader/tests/stub.rs).
fn handler() -> Vec<u8> {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0xA9, b'Q', 0x20, 0x00, 0xFF, 0xAD, 0x80, 0x04,
        0x20, 0x03, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ];
    bytes.resize(0x81, 0xEA);
    bytes[0x80] = 0x42;
    bytes
}

fn attached() -> (RobotMonitor, RobotDebug<VirtualTransport>) {
    let bytes = handler();
    let mut robot = VirtualScorpion::new();
    robot
        .robot_mut()
        .board_mut()
        .load(0x0400, &bytes)
        .expect("RAM");
    robot
        .install_hook(HookKind::Unknown, 0x0403, None)
        .expect("a JMP");
    let symbols = debugger::Symbols::new(&robot, &[]);
    let image = UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes,
        }],
        vec![HookRecord {
            kind: HookKind::Unknown,
            handler: 0x0403,
            chain: Some(0x0401),
        }],
    )
    .expect("an image");
    let profile = RomProfile::reference();
    let client = uploader::client(VirtualTransport::new(robot), &profile);
    let debug = RobotDebug::attach(client, &profile, image).expect("attaches");
    (RobotMonitor::new(symbols, Vec::new()), debug)
}

fn text(m: &mut RobotMonitor, d: &mut RobotDebug<VirtualTransport>, line: &str) -> String {
    match m.command(d, line) {
        Ok(Reply::Text(text)) => text,
        other => panic!("`{line}`: {other:?}"),
    }
}

fn refusal(m: &mut RobotMonitor, d: &mut RobotDebug<VirtualTransport>, line: &str) -> String {
    match m.command(d, line) {
        Err(Failure::Usage(why)) => why,
        other => panic!("`{line}` was not refused: {other:?}"),
    }
}

#[test]
fn what_a_robot_cannot_do_is_refused_with_the_reason() {
    let (mut m, mut d) = attached();
    for (line, reason) in [
        ("watch $0480", "no data breakpoints"),
        ("back", "can be neither copied nor re-run"),
        ("reverse-continue", "can be neither copied nor re-run"),
        ("who-wrote $0480", "can be neither copied nor re-run"),
        ("break $FF00", "the ROM cannot be patched"),
        ("break $040C if A == 1", "always stops"),
        ("regs", "needs a stop"),
        ("set A 1", "needs a stop"),
        ("print A", "registers are known only at a stop"),
        // fresh11 F7: said as a reason, not "refused on the robot: not on
        // the robot".
        ("finish", "which cannot be patched"),
    ] {
        let why = refusal(&mut m, &mut d, line);
        assert!(why.contains(reason), "`{line}`: {why}");
    }
    // fresh19 F6: `next` while it runs is refused as `next`.
    for (line, said) in [("next", "next is refused"), ("step", "step is refused")] {
        let why = format!("{:?}", m.command(&mut d, line).expect_err("refused"));
        assert!(why.contains(said), "`{line}`: {why}");
    }
    // At a stop, commands down the line wait for `continue`.
    text(&mut m, &mut d, "break $040C");
    assert!(text(&mut m, &mut d, "/1Q").contains("stopped: breakpoint 1, $040C"));
    let why = refusal(&mut m, &mut d, "/1X");
    assert!(why.contains("continue"), "{why}");
}

#[test]
fn displays_are_read_while_it_runs_and_at_a_stop() {
    let (mut m, mut d) = attached();
    // fresh13 F2: its value at once, read with /7R while the robot runs;
    // a register's is said to wait for a stop.
    text(&mut m, &mut d, "poke $0480 $5A");
    assert_eq!(
        text(&mut m, &mut d, "display [$0480]"),
        "display 1: [$0480] = $5A\n"
    );
    assert_eq!(
        text(&mut m, &mut d, "display A"),
        "display 2: A = (the robot is running: registers are known only at a stop)\n"
    );
    // fresh14 F4: said as the virtual monitor says it.
    assert_eq!(text(&mut m, &mut d, "undisplay 2"), "display 2 removed\n");
    // Running: read with /7R after the command's answer.
    let shown = text(&mut m, &mut d, "/1Q");
    assert!(shown.contains("answer: Q5A\n1: [$0480] = $5A"), "{shown}");
    text(&mut m, &mut d, "poke $0480 $17");
    text(&mut m, &mut d, "break $040F");
    // At the stop: read through the stub, beside the registers.
    let shown = text(&mut m, &mut d, "/1Q");
    assert!(shown.contains("A=$17"), "{shown}");
    assert!(shown.contains("1: [$0480] = $17"), "{shown}");
    let shown = text(&mut m, &mut d, "print A + [$0480]");
    assert_eq!(shown, "$2E\n");
    let shown = text(&mut m, &mut d, "continue");
    assert!(shown.contains("answer: Q17"), "{shown}");
    // As many as the virtual robot's monitor shows, each read at every
    // command: no more.
    for _ in 1..64 {
        text(&mut m, &mut d, "display [$0481]");
    }
    let why = refusal(&mut m, &mut d, "display [$0482]");
    assert!(why.contains("at most 64 expressions"), "{why}");
}

/// The hostile tester's F5: `next` over `JSR PUTEOL` ends the answer
/// before the stop; the stop after it is shown with it, and the monitor
/// knows the robot is stopped.
#[test]
fn a_step_whose_stop_comes_after_the_answer_shows_both() {
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $0412");
    let shown = text(&mut m, &mut d, "/1Q");
    assert!(shown.contains("stopped: breakpoint 1, $0412"), "{shown}");
    // fresh11 F7: `nexti`, as the docs' table names it, is `next`.
    let shown = text(&mut m, &mut d, "nexti");
    assert!(shown.contains("answer: Q42\nstopped: $0415"), "{shown}");
    assert!(text(&mut m, &mut d, "regs").contains("PC=$0415"));
}

/// G2: a command another program sends down the line hits a breakpoint
/// while the monitor idles; the front end's `notice` before the next
/// command sees the stop.
#[test]
fn a_stop_while_idle_is_noticed() {
    use uploader::Transport as _;
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $040C");
    d.client().transport().send(b"/1Q").expect("sent");
    let noticed = m
        .notice(&mut d, std::time::Duration::from_secs(1))
        .expect("the line")
        .expect("a stop");
    assert!(
        noticed.contains("(a stop no command waited for) stopped: breakpoint 1, $040C"),
        "{noticed}"
    );
    assert!(text(&mut m, &mut d, "regs").contains("PC=$040C"));
}

/// fresh10 F13: Enter on an empty line repeats the last step, as in the
/// virtual monitor; after any other command it does nothing.
#[test]
fn an_empty_line_repeats_the_last_step() {
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $040C");
    assert!(text(&mut m, &mut d, "/1Q").contains("stopped: breakpoint 1, $040C"));
    assert!(text(&mut m, &mut d, "step").contains("stopped: $040F"));
    let again = text(&mut m, &mut d, "");
    assert!(
        again.contains("answer: Q42") || again.contains("stopped"),
        "{again}"
    );
    assert!(text(&mut m, &mut d, "info").contains("breakpoint 1"));
    assert_eq!(text(&mut m, &mut d, ""), "");
}

/// fresh10 F4b: in the template's handler only `jsr PUTCH` took a
/// breakpoint (every instruction starts a source line, and each line was
/// taken for a jump target), so no step could leave it. A `JSR` may cover
/// an instruction nothing jumps to: from `jsr PUTCH` the steps go line by
/// line to the answer, and `lda #VERSION` takes a breakpoint too; the
/// branches and what they go to are still refused.
#[test]
fn the_new_templates_handler_steps_line_by_line_on_the_robot() {
    use std::collections::BTreeMap;
    let dir = tempfile::tempdir().expect("a temporary directory");
    let root = dir.path().join("new");
    scorpion_project::template::create(&root, "new", scorpion_project::template::Kind::Extension)
        .expect("the template");
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let source = std::fs::read(root.join("src/new.s")).expect("its source");
    let source = assembler::MemorySource::new().with("new.s", source);
    let assembly = assembler::assemble(&source, std::path::Path::new("new.s"), &options)
        .expect("the template assembles");
    let linked = romlib::link_against_rom("new.s", &assembly.object, "scorpion-ext")
        .expect("the template links");
    let mut robot = VirtualScorpion::new();
    robot.load_image(&linked).expect("loads");
    let symbols = debugger::Symbols::new(&robot, std::slice::from_ref(&linked));
    let image = UploadImage::try_from(&linked).expect("an image");
    let profile = RomProfile::reference();
    let client = uploader::client(VirtualTransport::new(robot), &profile);
    let mut d = RobotDebug::attach(client, &profile, image).expect("attaches");
    let images = vec![linked];
    if let Some(starts) = debugger::robot::instruction_starts(&images) {
        d.set_instruction_starts(starts);
    }
    let mut m = RobotMonitor::new(symbols, images);

    // fresh10 F4, fresh14 F7: the handler's first line, `cpx #1` and its
    // `bne`, takes a breakpoint (the branch relocated in the trampoline),
    // and steps line by line from there.
    text(&mut m, &mut d, "break handler");
    assert!(text(&mut m, &mut d, "/1V").contains("stopped: breakpoint 1, $0400"));
    for to in ["$0402", "$0404", "$0406", "$0408"] {
        let shown = text(&mut m, &mut d, "step");
        assert!(shown.contains(&format!("stopped: {to}")), "{to}: {shown}");
    }
    assert!(text(&mut m, &mut d, "continue").contains("V01"));
    // Another command goes down the chain, past the relocated branch.
    assert!(text(&mut m, &mut d, "/1W").contains("stopped: breakpoint 1, $0400"));
    let shown = text(&mut m, &mut d, "continue");
    assert!(!shown.contains("V01"), "{shown}");
    assert!(!shown.contains("stopped"), "{shown}");
    text(&mut m, &mut d, "delete 1");
    text(&mut m, &mut d, "break handler+8");
    assert!(text(&mut m, &mut d, "/1V").contains("stopped: breakpoint 2, $0408"));
    let shown = text(&mut m, &mut d, "step");
    assert!(
        shown.contains("stopped: $040B"),
        "jsr PUTCH stepped over: {shown}"
    );
    let shown = text(&mut m, &mut d, "step");
    assert!(shown.contains("stopped: $040D"), "lda #VERSION: {shown}");
    assert!(text(&mut m, &mut d, "regs").contains("A=$01"));
    let shown = text(&mut m, &mut d, "next");
    assert!(shown.contains("stopped: $0410"), "jsr PUTHEX: {shown}");
    let shown = text(&mut m, &mut d, "continue");
    assert!(shown.contains("V01"), "{shown}");
    // A breakpoint on the two-byte `lda #VERSION` itself.
    text(&mut m, &mut d, "delete 2");
    text(&mut m, &mut d, "break handler+$B");
    assert!(text(&mut m, &mut d, "/1V").contains("stopped: breakpoint 3, $040B"));
    assert!(text(&mut m, &mut d, "continue").contains("V01"));
}

/// fresh11's nit: at a stop P shows B and the unused bit as the stub's
/// `PHP` pushed them ($30); `set P $01` showed $21, `set P $31` too. They
/// are no flags: `set` leaves them as the stop showed them.
#[test]
fn set_p_keeps_b_as_the_stop_showed_it() {
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $040C");
    assert!(text(&mut m, &mut d, "/1Q").contains("stopped: breakpoint 1, $040C"));
    let p = |text: &str| text.split("P=").nth(1).map(|p| p[..3].to_owned());
    let shown = p(&text(&mut m, &mut d, "regs")).expect("P");
    assert_eq!(&shown[..2], "$3", "B and the unused bit at a stop: {shown}");
    assert_eq!(
        p(&text(&mut m, &mut d, "set P $01")).as_deref(),
        Some("$31")
    );
    assert_eq!(p(&text(&mut m, &mut d, "regs")).as_deref(), Some("$31"));
    assert_eq!(p(&text(&mut m, &mut d, "set C 0")).as_deref(), Some("$30"));
    assert!(text(&mut m, &mut d, "continue").contains("Q42"));
}

/// hostile10 F8: a stop whose frame was lost on the line (here read and
/// thrown away, as a dropped byte garbles it) left the monitor taking the
/// robot for running: `regs`, `step` and `continue` were refused. Before a
/// command that needs a stop the monitor asks the stub, tells the stop,
/// and runs the command.
#[test]
fn a_stop_whose_frame_was_lost_is_found_before_a_command_that_needs_one() {
    use uploader::Transport as _;
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $040C");
    d.client().transport().send(b"/1Q").expect("sent");
    let mut lost = Vec::new();
    while d
        .client()
        .transport()
        .receive(&mut lost, std::time::Duration::from_millis(300))
        .expect("the line")
        > 0
    {}
    assert!(
        lost.contains(&0xF0),
        "the stop frame came and was lost: {lost:02X?}"
    );
    let shown = text(&mut m, &mut d, "regs");
    assert!(
        shown.contains("(a stop no command waited for) stopped: breakpoint 1, $040C"),
        "{shown}"
    );
    assert!(shown.contains("PC=$040C"), "{shown}");
    // The `Q` went with the lost frame; the rest of the answer comes.
    let shown = text(&mut m, &mut d, "continue");
    assert!(shown.contains("answer: 42"), "{shown}");
}

/// hostile14 F3: while the robot runs, an expression that reads no
/// register (`$A`, a character) is evaluated; one that reads a register is
/// refused. F4: a display of many neighbouring bytes is read in spans, not
/// one `/7R` a byte (18 s for a thousand bytes, at every command).
#[test]
fn expressions_read_what_they_need_while_the_robot_runs() {
    let (mut m, mut d) = attached();
    assert_eq!(text(&mut m, &mut d, "print $A"), "$0A\n");
    assert_eq!(text(&mut m, &mut d, "print 'X' + 1"), "$59\n");
    assert!(refusal(&mut m, &mut d, "print X + 1").contains("registers are known only at a stop"));
    let sum: Vec<String> = (0..200).map(|i| format!("[${:04X}]", 0x0400 + i)).collect();
    let sent = d.client().stats().sent;
    let shown = text(&mut m, &mut d, &format!("display {}", sum.join("+")));
    let cost = d.client().stats().sent - sent;
    assert!(shown.starts_with("display 1: "), "{shown}");
    // A question (`/7Raaaann`) per 99 bytes, not per byte (9 characters
    // each: 1800 for the 200).
    assert!(
        cost < 60,
        "{cost} characters sent for 200 neighbouring bytes"
    );
}

/// hostile14 F8: a display of memory the robot changes as it runs (the
/// head of the ROM's receive ring here, which every question moves) hid
/// the answer of every command after it behind "the bytes changed between
/// reads". hostile16 F4: and it showed no value, though watching a value
/// change is what a display is for. It is shown as one moment's value,
/// said to change, and the answer with it; so are `print` and `mem`.
#[test]
fn a_display_of_changing_memory_does_not_hide_the_answer() {
    let (mut m, mut d) = attached();
    let head = romlib::symbols::find("RXHEAD")
        .expect("the ROM's RXHEAD")
        .value;
    let changing = |shown: &str, before: &str| {
        let value = shown
            .split_once(before)
            .map(|(_, after)| after)
            .unwrap_or_else(|| panic!("no {before:?} in {shown}"));
        assert!(
            value.starts_with('$')
                && value[3..].starts_with(&format!(
                    " (changing: the robot wrote ${head:04X} while it was read"
                )),
            "{shown}"
        );
    };
    let shown = text(&mut m, &mut d, &format!("display [${head:04X}]"));
    changing(&shown, &format!("display 1: [${head:04X}] = "));
    let shown = text(&mut m, &mut d, "/1Q");
    assert!(shown.contains("answer: Q42"), "{shown}");
    changing(&shown, &format!("1: [${head:04X}] = "));
    let shown = text(&mut m, &mut d, &format!("print [${head:04X}]"));
    changing(&shown, "");
    let shown = text(&mut m, &mut d, &format!("mem ${head:04X} 2"));
    assert!(
        shown.contains(&format!("\n(changing: the robot wrote ${head:04X}")),
        "{shown}"
    );
}

/// fresh15 F4: a refused breakpoint's hint named a place a breakpoint was
/// already at (refused in turn), and a breakpoint set twice got a hint.
#[test]
fn a_refused_breakpoints_hint_skips_the_breakpoints_set() {
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $0409");
    let twice = refusal(&mut m, &mut d, "break $0409");
    assert!(twice.contains("one is there already"), "{twice}");
    assert!(!twice.contains("nearest"), "{twice}");
    // LDA #'Q' and the JSR after it overlap the breakpoint on the JSR.
    let overlap = refusal(&mut m, &mut d, "break $0407");
    assert!(
        overlap.contains("overlap the breakpoint at $0409"),
        "{overlap}"
    );
    assert!(overlap.contains("(`break $040C`)"), "{overlap}");
    text(&mut m, &mut d, "break $040C");
}

/// fresh15 F7: at a stop, `mem $9000 3` read the ADC card's result (a
/// real bus read on the robot), which cleared its status, and the handler
/// then answered "no card". Reads of the I/O page and of the KIM bus
/// outside the image are refused, saying why; RAM and the ROM are read.
#[test]
fn reads_that_would_change_a_cards_registers_are_refused() {
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $040C");
    assert!(text(&mut m, &mut d, "/1Q").contains("stopped: breakpoint 1"));
    for line in ["mem $9000 3", "print [$9002]", "mem $C000", "mem $0FFF 2"] {
        let why = refusal(&mut m, &mut d, line);
        assert!(
            why.contains("reading a register there can change it"),
            "`{line}`: {why}"
        );
    }
    // A display is kept, its value the reason.
    let shown = text(&mut m, &mut d, "display [$C001]");
    assert!(
        shown.contains("reading a register there can change it"),
        "{shown}"
    );
    assert!(text(&mut m, &mut d, "mem $0480 1").contains("$0480: 42"));
    assert!(text(&mut m, &mut d, "mem $FF00 1").contains("$FF00: "));
}

/// fresh15 F6: on a noisy line one of the monitor's own `/7R` reads,
/// garbled, went down `HOOK_UNKNOWN` and stopped at the user's breakpoint
/// on its handler (A='R', X=7), shown as a stop like any other. It is
/// said to be the monitor's own.
#[test]
fn a_stop_from_a_garbled_read_of_the_monitors_own_says_so() {
    let (mut m, mut d) = attached();
    text(&mut m, &mut d, "break $0403");
    // A `/7R` whose digits noise turned into letters: malformed, so the
    // ROM passes it to HOOK_UNKNOWN.
    uploader::Transport::send(d.client().transport(), b"/7RZZZZ04").expect("sent");
    let said = m
        .notice(&mut d, std::time::Duration::from_secs(1))
        .expect("the line")
        .expect("the stop");
    assert!(said.contains("stopped: breakpoint 1, $0403"), "{said}");
    assert!(
        said.contains("note: A='R' X=7 is the monitor's own /7R (a read of memory), garbled"),
        "{said}"
    );
    // A stop by a command of the user's says nothing of the kind.
    text(&mut m, &mut d, "continue");
    let said = text(&mut m, &mut d, "/1Q");
    assert!(said.contains("stopped: breakpoint 1"), "{said}");
    assert!(!said.contains("the monitor's own"), "{said}");
}
