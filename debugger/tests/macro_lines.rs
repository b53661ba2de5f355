//! The line a user sees for code a macro made: a built-in macro's code
//! (from an include the toolchain serves, not a file of theirs) is shown
//! at their line that called it, a breakpoint on that line stops at the
//! macro's first byte and `next` runs the call as one line; a macro of
//! their own shows its own lines inside.

use std::collections::BTreeMap;

use debugger::{Breakpoint, Debugger, Why};
use romlib::VirtualScorpion;

/// A built-in include (as `scorpion.inc` is one) with a macro of three
/// instructions.
const BUILT_IN: &str = ".macro THREE\n        nop\n        nop\n        nop\n.endmacro\n";

/// `/1Q` runs the built-in `THREE`, then the user's own `MINE`.
const SOURCE: &str = "        .include \"scorpion.inc\"
        .include \"three.inc\"
.macro MINE
        inx
        inx
.endmacro
        .code
        SCORPION_UNKNOWN_HANDLER
        cmp #'Q'
        bne not_mine
        THREE
        MINE
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

/// The 1-based line of `SOURCE` that is `text`, trimmed.
fn line(text: &str) -> u32 {
    let index = SOURCE
        .lines()
        .position(|l| l.trim() == text)
        .expect("the line");
    u32::try_from(index + 1).expect("small")
}

/// A debugger on the handler, its source `q.s` written in `dir` (the
/// user's file there; `three.inc` and `scorpion.inc` only built in).
fn debugger(dir: &std::path::Path) -> Debugger {
    std::fs::write(dir.join("q.s"), SOURCE).expect("write");
    let files = assembler::MemorySource::new().with("q.s", SOURCE);
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([
            (
                "scorpion.inc".to_owned(),
                romlib::SCORPION_INC.as_bytes().to_vec(),
            ),
            ("three.inc".to_owned(), BUILT_IN.as_bytes().to_vec()),
        ]),
        ..assembler::Options::default()
    };
    let assembly = assembler::assemble(&files, std::path::Path::new("q.s"), &options)
        .expect("the handler assembles");
    let image =
        romlib::link_against_rom("q.s", &assembly.object, "scorpion-ext").expect("it links");
    let loaded = image.clone();
    let make = Box::new(move || {
        let mut robot = VirtualScorpion::new();
        robot.load_image(&loaded)?;
        Ok(robot)
    });
    let mut d = Debugger::new(make, &[image]).expect("the robot builds");
    d.set_source_root(dir.to_path_buf());
    d
}

#[test]
fn a_built_in_macros_call_is_one_line_and_a_users_macro_its_own() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut d = debugger(dir.path());
    let three = line("THREE");
    let start = d
        .address_of_line("q.s", three)
        .expect("a line that calls a macro has its code");
    let id = d.add_breakpoint(Breakpoint::At(start));
    d.send(b"/1Q");
    let hit = d.run(200_000).expect("runs");
    assert!(
        matches!(hit.why, Why::Breakpoint { id: at, .. } if at == id),
        "{hit:?}"
    );
    assert_eq!(d.cpu().pc, start);
    assert_eq!(d.source_of(start), Some(("q.s".to_owned(), three)));
    assert_eq!(
        d.disassemble(start, 3)
            .iter()
            .map(|l| l.source.clone())
            .collect::<Vec<_>>(),
        vec![Some(("q.s".to_owned(), three)); 3],
        "each NOP of the built-in macro at the user's line"
    );
    let next = d.next_line(100_000).expect("steps");
    assert_eq!(next.why, Why::Stepped);
    assert_eq!(next.instructions, 3, "the three NOPs: one line");
    assert_eq!(
        d.source_of(d.cpu().pc),
        Some(("q.s".to_owned(), line(".macro MINE") + 1)),
        "the user's own macro: its first INX's own line"
    );
    let next = d.next_line(100_000).expect("steps");
    assert_eq!(next.instructions, 1, "one INX a line in the user's macro");
    assert_eq!(
        d.source_of(d.cpu().pc),
        Some(("q.s".to_owned(), line(".macro MINE") + 2))
    );
    let next = d.next_line(100_000).expect("steps");
    assert_eq!(
        d.source_of(d.cpu().pc),
        Some(("q.s".to_owned(), line("jmp CMD_DONE"))),
        "{next:?}"
    );
}

/// Where the user's file is not there to open (an image debugged away
/// from its sources), nothing is the user's: the macro's own line shows.
#[test]
fn without_the_users_file_the_macros_own_line_shows() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut d = debugger(dir.path());
    let start = d.address_of_line("q.s", line("THREE")).expect("code");
    d.set_source_root(dir.path().join("elsewhere"));
    assert_eq!(d.source_of(start), Some(("three.inc".to_owned(), 2)));
}
