//! Which lines of data in code are code lines: an instruction written as
//! bytes that the code runs into is one (the chain `JMP` of
//! `SCORPION_CHAIN_UNKNOWN`, a `BIT` that skips the next instruction);
//! a table after an always-taken branch, a string after a `JSR` that
//! reads it, and a table only loaded from are not. A built-in macro's
//! code counts at the user's line that called it.

mod common;

use romlib::VirtualScorpion;
use scorpion_profile::Recorder;
use scorpion_profile::coverage::Coverage;
use scorpion_profile::lines::LineTable;

const SOURCE: &str = "        .include \"scorpion.inc\"
        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'Q'
        bne not_mine
        lda #1
        .byte $2C
        lda #2
        jsr print
        .byte \"HI\", 0
        clc
        bcc done
        .byte 1, 2, 3
done:   lda table
        jmp CMD_DONE
print:  rts
table:  .byte $60, $EA
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

fn table() -> LineTable {
    let image = common::extension(SOURCE);
    LineTable::new(&[&image], &|file| match file {
        "q.s" => Some(SOURCE.to_owned()),
        "scorpion.inc" => Some(romlib::SCORPION_INC.to_owned()),
        _ => None,
    })
}

/// The line of `file` whose text (trimmed) is `text`, from 1.
fn line_of(file_text: &str, text: &str) -> u32 {
    let index = file_text
        .lines()
        .position(|line| line.trim() == text)
        .unwrap_or_else(|| panic!("no line {text:?}"));
    u32::try_from(index + 1).expect("small")
}

fn is_code_line(table: &LineTable, file: &str, line: u32) -> bool {
    table.lines.iter().any(|l| l.file == file && l.line == line)
}

#[test]
fn the_chain_jmp_written_as_a_byte_is_a_code_line() {
    let table = table();
    let line = line_of(romlib::SCORPION_INC, ".byte $4C");
    let chain = table
        .lines
        .iter()
        .find(|l| l.file == "scorpion.inc" && l.line == line)
        .expect("the chain JMP's line is a code line");
    assert_eq!(chain.starts.len(), 1, "{chain:?}");
    let (file, at) = table.place_of(chain.starts[0] + 1).expect("placed");
    assert_eq!(file, "scorpion.inc");
    assert_ne!(
        at, line,
        "its operand is the next line, inside the same JMP"
    );
    assert!(
        !is_code_line(&table, "scorpion.inc", at),
        "the operand's line starts no instruction"
    );
}

#[test]
fn a_bit_that_skips_an_instruction_is_code_data_around_it_is_not() {
    let table = table();
    assert!(is_code_line(&table, "q.s", line_of(SOURCE, ".byte $2C")));
    for data in [".byte \"HI\", 0", ".byte 1, 2, 3", "table:  .byte $60, $EA"] {
        assert!(
            !is_code_line(&table, "q.s", line_of(SOURCE, data)),
            "{data} is data"
        );
    }
}

/// `/1Q` answers `Q`; anything else goes down the chain.
const HANDLER: &str = "        .include \"scorpion.inc\"
        .code
        SCORPION_UNKNOWN_HANDLER
        cmp #'Q'
        bne not_mine
        jsr PUTCH
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

/// The coverage of the handler's own file after `commands`.
fn covered(commands: &[&[u8]]) -> Coverage {
    let image = common::extension(HANDLER);
    let mut robot = VirtualScorpion::new();
    robot.load_image(&image).expect("the image loads");
    let recorder = Recorder::attach(&mut robot);
    for command in commands {
        // BAD_COMMAND, at the end of the chain, answers nothing.
        let answer = robot.transact(command, 1_000_000);
        assert!(answer.is_ok() || command != b"/1Q", "{answer:?}");
    }
    let profile = recorder.finish(&mut robot);
    let table = LineTable::new(&[&image], &|file| {
        (file == "q.s").then(|| HANDLER.to_owned())
    });
    Coverage::new(&profile, &table, &|file| file == "q.s")
}

#[test]
fn the_chain_macro_counts_at_the_users_line_run_or_not() {
    let call = line_of(HANDLER, "SCORPION_CHAIN_UNKNOWN");
    let hits = |coverage: &Coverage| {
        let file = &coverage.files[0];
        assert_eq!(coverage.files.len(), 1, "only q.s is kept");
        file.lines
            .iter()
            .find(|l| l.line == call)
            .map(|l| l.hits)
            .expect("the macro's line is a code line of q.s")
    };
    let only_mine = covered(&[b"/1Q"]);
    assert_eq!(hits(&only_mine), 0, "no command went down the chain");
    let (lines, run) = only_mine.line_counts();
    assert_eq!(run + 1, lines, "all but the chain line ran");
    let chained = covered(&[b"/1Q", b"/1Z"]);
    assert_eq!(hits(&chained), 1, "/1Z went down the chain once");
    let (lines, run) = chained.line_counts();
    assert_eq!(run, lines);
}
