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

/// fresh7's F2, hostile9's F10: a robot that answers nothing at all was
/// told as "no installed extension answered it".
#[test]
fn ask_of_a_robot_that_answers_nothing_says_so() {
    use serialport::SerialPort;
    let (_master, slave) = serialport::TTYPort::pair().expect("a pseudo-terminal pair");
    let path = slave.name().expect("the slave's path");
    let text = ask(&["--port", &path, "--timeout", "100", "/1Q"]);
    assert!(text.starts_with("exit: 1"), "{text}");
    assert!(
        text.contains("`/1Q`: no answer within 100 ms, and no answer to a read of HOOK_UNKNOWN either: the robot answers nothing"),
        "{text}"
    );
}

/// fresh11 F5: `--timeout 0` was taken (and then no extension "answered"
/// in no time); a wait of at least 1 ms is asked for.
#[test]
fn a_timeout_of_zero_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = scorpion(
        dir.path(),
        &["ask", "--port", "emu", "--timeout", "0", "/1X"],
    );
    assert_eq!(output.status.code(), Some(2), "{}", transcript(&output));
    assert!(
        transcript(&output).contains("--timeout"),
        "{}",
        transcript(&output)
    );
}
