//! `scorpion ask`: raw and decoded answers from the virtual Scorpion,
//! instructions, extension commands, bad commands and ports.

use crate::{scorpion, transcript};

fn ask(args: &[&str]) -> String {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut all = vec!["ask"];
    all.extend_from_slice(args);
    transcript(&scorpion(dir.path(), &all))
}

#[test]
fn ask_prints_each_answer_on_a_line() {
    insta::assert_snapshot!(ask(&[
        "--port",
        "emu",
        "/1P",
        "/2E3",
        "/1E",
        "/3H02",
        "/1X",
        "/7RF00008"
    ]));
}

#[test]
fn ask_decodes_every_answer_form() {
    insta::assert_snapshot!(ask(&[
        "--port",
        "emu",
        "--decode",
        "--allow-silence",
        "/2E1",
        "/2G1",
        "/4C+20",
        "/1P",
        "/1B",
        "/1S",
        "/1E",
        "/1G",
        "/1T",
        "/1M",
        "/1X",
        "/1C",
        "/1D",
        "/7R020006",
        "/1Q"
    ]));
}

#[test]
fn ask_rejects_what_is_not_a_command() {
    insta::assert_snapshot!(ask(&["--port", "emu", "/1P", "/8C+5"]));
}

#[test]
fn ask_needs_the_virtual_robot_for_images() {
    insta::assert_snapshot!(ask(&[
        "--port",
        "/dev/null-scorpion",
        "--image",
        "x.elf",
        "/1P"
    ]));
}

#[test]
fn ask_reports_a_missing_port() {
    insta::assert_snapshot!(ask(&["--port", "/dev/no-such-scorpion", "/1P"]));
}

#[test]
fn ask_fails_when_an_extensions_command_gets_no_answer() {
    insta::assert_snapshot!(ask(&["--port", "emu", "/1X", "/1Q", "/1P"]));
}
