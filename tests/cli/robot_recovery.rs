//! The hostile tester's findings on `scorpion debug --port` (issue 27,
//! point 4), on a `scorpion sim --pty` robot: a session killed with
//! `kill -9` at a stop or while the robot runs is cleaned up by the next
//! one (the robot answering, its code the image's); a robot holding
//! another build is refused before anything is written; a step over
//! `JSR PUTEOL`, whose stop comes after the answer, is seen, and `quit`
//! leaves the robot running.

use std::io::{BufRead as _, BufReader, Write as _};
use std::process::{Command, Stdio};

use crate::robot::Sim;
use crate::robot_debug::readme_handler_on_a_pty_robot;
use crate::{scorpion, scorpion_with_input, transcript};

/// The README handler's bytes from `show` ($0409) to `value` ($0418),
/// as `scorpion read` dumps them.
fn code(dir: &std::path::Path, sim: &Sim) -> Vec<u8> {
    let output = scorpion(
        dir,
        &["read", "$0400", "25", "-o", "code.bin", "--port", &sim.path],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    std::fs::read(dir.join("code.bin")).expect("a dump")
}

/// `/1Q` answered `Q42`: the robot runs its control loop.
fn answers(dir: &std::path::Path, sim: &Sim) {
    let output = scorpion(dir, &["ask", "/1Q", "--port", &sim.path]);
    assert!(
        String::from_utf8_lossy(&output.stdout).contains("Q42"),
        "{}",
        transcript(&output)
    );
}

/// A monitor fed `lines`, killed with SIGKILL once its output holds
/// `until`: what it printed.
pub(crate) fn killed_monitor(dir: &std::path::Path, sim: &Sim, lines: &str, until: &str) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
        .args(["debug", "--port", &sim.path, "--image", "ext.elf"])
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("scorpion runs");
    let mut stdin = child.stdin.take().expect("its input");
    stdin.write_all(lines.as_bytes()).expect("the lines");
    let mut stdout = BufReader::new(child.stdout.take().expect("its output"));
    let mut seen = String::new();
    while !seen.contains(until) {
        let mut line = String::new();
        let read = stdout.read_line(&mut line).expect("a line");
        assert!(read > 0, "ended before `{until}`:\n{seen}");
        seen.push_str(&line);
    }
    child.kill().expect("killed");
    child.wait().expect("it ends");
    seen
}

#[test]
fn a_monitor_killed_at_a_stop_is_cleaned_up_by_the_next_session() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let before = code(dir.path(), &sim);
    killed_monitor(dir.path(), &sim, "break show\n/1Q\n", "PC=");
    // Another command meets the stopped robot: it says so, and what to
    // run, rather than blaming the baud rate.
    let other = scorpion_with_input(Some(dir.path()), &["installed", "--port", &sim.path], "");
    let said = transcript(&other);
    assert!(!other.status.success(), "{said}");
    assert!(
        said.contains("stopped in the debug stub") && said.contains("scorpion debug --port"),
        "{said}"
    );
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "regs\ncontinue\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    for expected in [
        "an earlier session did not detach",
        "stopped in its stub at $0409",
        "breakpoints at $0409 were taken out",
        "PC=$0409",
        "answer: 42",
        "detached",
    ] {
        assert!(printed.contains(expected), "{expected}:\n{printed}");
    }
    assert_eq!(code(dir.path(), &sim), before);
    answers(dir.path(), &sim);
}

#[test]
fn a_monitor_killed_while_the_robot_runs_is_cleaned_up_by_the_next_session() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let before = code(dir.path(), &sim);
    killed_monitor(dir.path(), &sim, "break show\n", "breakpoint 1:");
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "/1Q\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    for expected in [
        "still hooked",
        "breakpoints at $0409 were taken out",
        "answer: Q42",
    ] {
        assert!(printed.contains(expected), "{expected}:\n{printed}");
    }
    assert_eq!(code(dir.path(), &sim), before);
    answers(dir.path(), &sim);
}

#[test]
fn a_robot_holding_another_build_is_refused_before_anything_is_written() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    // The same handler with one NOP more at its top: every byte after it
    // moves.
    let source = std::fs::read_to_string(dir.path().join("ext.s")).expect("the source");
    let other = source.replacen("        cmp #'Q'", "        nop\n        cmp #'Q'", 1);
    assert_ne!(other, source);
    std::fs::write(dir.path().join("other.s"), other).expect("the source");
    let built = scorpion(dir.path(), &["build", "other.s", "-o", "other.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let before = code(dir.path(), &sim);
    let hooks = scorpion(
        dir.path(),
        &["read", "$0200", "6", "-o", "hooks.bin", "--port", &sim.path],
    );
    assert!(hooks.status.success(), "{}", transcript(&hooks));
    let hooks = std::fs::read(dir.path().join("hooks.bin")).expect("a dump");
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "other.elf"],
        "break show\nquit\n",
    );
    let printed = transcript(&output);
    assert!(!output.status.success(), "{printed}");
    let said = printed.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        said.contains("the robot does not hold the image: $0400 holds C9 51"),
        "{printed}"
    );
    assert!(said.contains("the image has EA C9 51"), "{printed}");
    assert_eq!(code(dir.path(), &sim), before);
    let output = scorpion(
        dir.path(),
        &["read", "$0200", "6", "-o", "hooks.bin", "--port", &sim.path],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        std::fs::read(dir.path().join("hooks.bin")).expect("a dump"),
        hooks
    );
    answers(dir.path(), &sim);
}

#[test]
fn a_step_over_puteol_sees_the_stop_after_the_answer_and_quit_lets_it_go() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let before = code(dir.path(), &sim);
    // $040F is `JSR PUTEOL`, $0412 `JMP CMD_DONE`.
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "break $040F\n/1Q\nnext\nregs\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    for expected in ["answer: Q42", "stopped: $0412", "PC=$0412", "detached"] {
        assert!(printed.contains(expected), "{expected}:\n{printed}");
    }
    assert!(!printed.contains("error"), "{printed}");
    assert_eq!(code(dir.path(), &sim), before);
    answers(dir.path(), &sim);
}

/// A new user's F1 (issue 27): after the README's own session, whose
/// `poke value $99` changes a byte of `.data`, a second session attaches
/// (the robot's code is the image's; its data is the program's own), and
/// sees the poked byte.
#[test]
fn after_the_readme_session_a_second_attach_works() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let before = code(dir.path(), &sim);
    let first = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "break show\n/1Q\nregs\npoke value $99\nstep\ncontinue\ndelete 1\n/1Q\n",
    );
    assert!(first.status.success(), "{}", transcript(&first));
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "/1Q\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    for expected in ["answer: Q99", "detached"] {
        assert!(printed.contains(expected), "{expected}:\n{printed}");
    }
    assert!(!printed.contains("does not hold the image"), "{printed}");
    // The code as uploaded; only `value` ($0418) changed.
    let after = code(dir.path(), &sim);
    assert_eq!(after[..0x18], before[..0x18]);
    assert_eq!((before[0x18], after[0x18]), (0x42, 0x99));
}

/// The other half of F1: a byte of the image's code changed on the robot
/// (`cmp #'Q'` made `cmp #'R'` at a stop) is still refused.
#[test]
fn a_changed_code_byte_is_still_refused() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let first = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "break show\n/1Q\npoke $0401 $52\ncontinue\ndelete 1\nquit\n",
    );
    assert!(first.status.success(), "{}", transcript(&first));
    let changed = code(dir.path(), &sim);
    assert_eq!(changed[1], 0x52, "{}", transcript(&first));
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "break show\nquit\n",
    );
    let printed = transcript(&output);
    assert!(!output.status.success(), "{printed}");
    let said = printed.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        said.contains("the robot does not hold the image: $0401 holds 52"),
        "{printed}"
    );
    assert!(said.contains("the image has 51"), "{printed}");
    assert_eq!(code(dir.path(), &sim), changed);
}

/// The hooks' six bytes, as `scorpion read` dumps them.
fn hooks(dir: &std::path::Path, sim: &Sim) -> Vec<u8> {
    let output = scorpion(
        dir,
        &["read", "$0200", "6", "-o", "hooks.bin", "--port", &sim.path],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    std::fs::read(dir.join("hooks.bin")).expect("a dump")
}

/// The `orphan` round's F1 (issue 27): a monitor killed while the robot
/// runs leaves its stub hooked and a breakpoint in the code; an upload of
/// the same image chained the image to the stub, which chains to the
/// image (`/1Z` looped), and said nothing. Now it is refused, naming the
/// stub and what takes it out, with nothing written; after that
/// (`debug --port`, `quit`) the upload goes in and `/1Z` is answered.
#[test]
fn an_upload_over_a_killed_monitors_stub_is_refused_until_debug_cleans_up() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    killed_monitor(dir.path(), &sim, "break show\n", "breakpoint 1:");
    let (code_left, hooks_left) = (code(dir.path(), &sim), hooks(dir.path(), &sim));
    let upload = ["upload", "ext.elf", "--port", &sim.path, "--no-dry-run"];
    let output = scorpion(dir.path(), &upload);
    let printed = transcript(&output);
    assert!(!output.status.success(), "{printed}");
    let said = printed.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        said.contains("HOOK_UNKNOWN") && said.contains("leads to a debug stub"),
        "{printed}"
    );
    assert!(said.contains("scorpion debug --port"), "{printed}");
    assert_eq!(code(dir.path(), &sim), code_left);
    assert_eq!(hooks(dir.path(), &sim), hooks_left);
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "quit\n",
    );
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion(dir.path(), &upload);
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion(
        dir.path(),
        &["ask", "/1Z", "--allow-silence", "--port", &sim.path],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    answers(dir.path(), &sim);
}
