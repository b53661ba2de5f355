//! `scorpion sim`: commands on stdin, answers on stdout; a pseudo-terminal
//! served at the line's pace; loaded images; bad options.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::{build_example, scorpion, transcript};

/// Runs `scorpion sim ARGS` with `input` on stdin.
fn sim(args: &[&str], input: &str) -> std::process::Output {
    let mut all = vec!["sim"];
    all.extend(args);
    crate::scorpion_with_input(None, &all, input)
}

/// `scorpion sim` with `images` (in `dir`) and `input`; its output, and
/// the transcript with `dir` as `[TMP]`.
fn sim_images(
    dir: &std::path::Path,
    images: &[&str],
    input: &str,
) -> (std::process::Output, String) {
    let paths: Vec<String> = images
        .iter()
        .map(|image| dir.join(image).display().to_string())
        .collect();
    let mut args = Vec::new();
    for path in &paths {
        args.extend(["--image", path.as_str()]);
    }
    let output = sim(&args, input);
    let text = transcript(&output).replace(dir.to_str().expect("UTF-8"), "[TMP]");
    (output, text)
}

#[test]
fn sim_answers_commands_from_stdin() {
    let output = sim(&[], "/1P\n/2E3\n/2G1\n/1E\n/1G\n/7RF00004\n/1Q\n/1X\n");
    insta::assert_snapshot!(transcript(&output));
}

#[test]
fn sim_closes_bumpers_at_power_up() {
    let output = sim(&["--bumpers", "05"], "/1B\n/1P\n");
    insta::assert_snapshot!(transcript(&output));
}

#[test]
fn sim_runs_at_another_baud_rate() {
    let output = sim(&["--baud", "19200"], "/1X\n");
    insta::assert_snapshot!(transcript(&output));
}

#[test]
fn sim_refuses_a_rate_the_6551_lacks() {
    let output = sim(&["--baud", "1000"], "");
    insta::assert_snapshot!(transcript(&output));
}

#[test]
fn sim_loads_images_and_chains_their_hooks() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let layout = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/checksum/checksum.toml")
        .display()
        .to_string();
    build_example(dir.path(), "rangefinder/rangefinder.s", "first.elf", &[]);
    build_example(
        dir.path(),
        "checksum/checksum.s",
        "second.elf",
        &["--target", &layout],
    );
    let (_, text) = sim_images(
        dir.path(),
        &["first.elf", "second.elf"],
        "/7R020102\n/9KF0000010\n/1U\n",
    );
    insta::assert_snapshot!(text);
}

#[test]
fn sim_reports_an_image_that_is_not_one() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("junk.elf"), b"not an ELF").expect("written");
    let output = scorpion(dir.path(), &["sim", "--image", "junk.elf"]);
    insta::assert_snapshot!(transcript(&output));
}

/// A child process killed when dropped, so a failing test leaves no
/// simulator behind.
struct Child(std::process::Child);

impl Drop for Child {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn sim_serves_a_pseudo_terminal_at_the_baud_rate() {
    let mut child = Child(
        Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(["sim", "--pty"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("the scorpion binary runs"),
    );
    let mut stdout = BufReader::new(child.0.stdout.take().expect("stdout is piped"));
    let mut path = String::new();
    stdout
        .read_line(&mut path)
        .expect("the first line is the path");
    let path = path.trim();
    assert!(path.starts_with("/dev/"), "{path}");
    let mut port = serialport::new(path, 9600)
        .timeout(Duration::from_millis(50))
        .open()
        .expect("the pseudo-terminal opens");
    let started = Instant::now();
    port.write_all(b"/2E3/1E/1P").expect("commands are written");
    let mut answer = Vec::new();
    let mut buffer = [0u8; 64];
    while answer.iter().filter(|&&b| b == b'\r').count() < 2
        && started.elapsed() < Duration::from_secs(5)
    {
        if let Ok(count) = port.read(&mut buffer) {
            answer.extend_from_slice(&buffer[..count]);
        }
    }
    let elapsed = started.elapsed();
    assert_eq!(
        String::from_utf8_lossy(&answer),
        "E3\rPB00E3G0T0M+0000+0000Y00X82C0000D0000\r"
    );
    // 10 characters out and 41 back take 53 ms on a 9600-baud line: the
    // simulator keeps the line's pace rather than answering at once.
    assert!(elapsed >= Duration::from_millis(50), "{elapsed:?}");
}

/// The hostile tester's finding: `sim --pty` runs until interrupted, and
/// an interrupt killed it before `--path` was drawn, so it never was.
/// SIGINT ends the session and the picture shows the trail the robot
/// drove, commanded through the pseudo-terminal.
#[test]
fn an_interrupted_pty_session_draws_its_path() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let world = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/room/room.toml");
    let picture = dir.path().join("pty.svg");
    let mut child = Child(
        Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(["sim", "--pty", "--world"])
            .arg(&world)
            .arg("--path")
            .arg(&picture)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("the scorpion binary runs"),
    );
    let mut stdout = BufReader::new(child.0.stdout.take().expect("stdout is piped"));
    let mut path = String::new();
    stdout
        .read_line(&mut path)
        .expect("the first line is the path");
    let mut port = serialport::new(path.trim(), 9600)
        .timeout(Duration::from_millis(50))
        .open()
        .expect("the pseudo-terminal opens");
    port.write_all(b"/4C+40/4D+40")
        .expect("commands are written");
    std::thread::sleep(Duration::from_millis(1500));
    let interrupted = Command::new("kill")
        .args(["-INT", &child.0.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(interrupted.success());
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.0.try_wait().expect("waited for") {
            break status;
        }
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "sim did not stop"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status:?}");
    let svg = std::fs::read_to_string(&picture).expect("the picture drawn");
    let points = svg
        .split(r#"<polyline class="trail" points=""#)
        .nth(1)
        .and_then(|rest| rest.split('"').next())
        .expect("a trail");
    assert!(
        points.split_whitespace().count() >= 2,
        "the robot drove, and its trail is drawn: {points}"
    );
}

/// Issue 11's first reproduction: two extensions built with the defaults
/// both sit at `$0400`. The second is refused before a byte of it is
/// loaded, naming both extents, and the sim exits non-zero instead of
/// chaining the hook to itself.
#[test]
fn sim_refuses_an_image_that_overlaps_an_installed_one() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    build_example(dir.path(), "rangefinder/rangefinder.s", "first.elf", &[]);
    build_example(dir.path(), "checksum/checksum.s", "second.elf", &[]);
    let (output, text) = sim_images(dir.path(), &["first.elf", "second.elf"], "/1X\n");
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(
        !text.contains("(was $0400)"),
        "the chain points at itself: {text}"
    );
    insta::assert_snapshot!(text);
}

/// Issue 11's third reproduction: a handler that never returns. `sim`
/// used to exit 0 with the answers missing; it exits 1 naming the PC and
/// the label, and `upload --port emu --expect` stops in its rehearsal the
/// same way instead of blaming the line.
#[test]
fn a_handler_that_never_returns_is_reported_where_it_hangs() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("hang.s"),
        ".include \"scorpion.inc\"\nSCORPION_UNKNOWN_HANDLER\n        cmp #'Q'\n        bne pass\nhang:   jmp hang\npass:   SCORPION_CHAIN_UNKNOWN\n",
    )
    .expect("write the source");
    let built = scorpion(dir.path(), &["build", "hang.s", "-o", "hang.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let (output, text) = sim_images(dir.path(), &["hang.elf"], "/1X\n/1Q\n/1X\n");
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("X00"), "the answer before the hang: {text}");
    insta::assert_snapshot!(text);
    std::fs::write(dir.path().join("hang.expect"), "/1X => X00\n/1Q\n").expect("write");
    let upload = scorpion(
        dir.path(),
        &[
            "upload",
            "hang.elf",
            "--port",
            "emu",
            "--expect",
            "hang.expect",
        ],
    );
    let text = transcript(&upload);
    assert_eq!(upload.status.code(), Some(1), "{text}");
    assert!(
        text.contains("romlib::stuck") && text.contains("$0404 (hang)"),
        "{text}"
    );
}

/// Issue 11's INJECT reproduction: with patrol cruising (it feeds the ROM
/// its motor commands through INJECT), the host's `/1P` right behind
/// `/2A1` used to be cut by the injected text and never answered.
#[test]
fn a_host_question_behind_an_injecting_os_is_answered() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    build_example(
        dir.path(),
        "patrol/patrol.s",
        "patrol.elf",
        &["--target", "scorpion-os"],
    );
    for _ in 0..3 {
        let (output, text) = sim_images(dir.path(), &["patrol.elf"], "/2A1\n/1P\n");
        assert_eq!(output.status.code(), Some(0), "{text}");
        assert!(
            String::from_utf8_lossy(&output.stdout).starts_with("PB00"),
            "{text}"
        );
    }
}
