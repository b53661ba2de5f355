//! Issue 27, point 4, through a real pseudo-terminal to `scorpion sim
//! --pty` standing for the robot, the tools using nothing but the line:
//! `scorpion debug --port` attaches its stub beside an uploaded handler, a
//! breakpoint inside the handler is hit by its command, the registers
//! read, a byte of memory changed, a step, continue and the command
//! answered with the changed byte, the breakpoint removed, and the code
//! (read with `scorpion read`) compared with the image.

use isa::objfmt::{HookKind, HookRecord, Hooks};
use linker::{Format, Image, ImageSymbol, LoadArea};

use crate::robot::Sim;
use crate::{scorpion, scorpion_with_input, transcript};

/// The handler's bytes at $0400: `/1Q` answers `Q` and the byte at
/// `value` ($0480) in hex.
///
/// ```text
/// $0400  JMP chain      ; the chain slot, $0401
/// $0403  handler: CMP #'Q'
/// $0405  BNE $0400
/// $0407  LDA #'Q'
/// $0409  JSR PUTCH
/// $040C  show: LDA value
/// $040F  JSR PUTHEX
/// $0412  JSR PUTEOL
/// $0415  JMP CMD_DONE
/// $0480  value: .byte $42
/// ```
pub(crate) fn handler_bytes() -> Vec<u8> {
    let mut bytes = vec![
        0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0, 0xF9, 0xA9, b'Q', 0x20, 0x00, 0xFF, 0xAD, 0x80, 0x04,
        0x20, 0x03, 0xFF, 0x20, 0x09, 0xFF, 0x4C, 0x1E, 0xFF,
    ];
    bytes.resize(0x81, 0xEA);
    bytes[0x80] = 0x42;
    bytes
}

/// The handler as a linked image, with its names (constants: the image
/// has no sections, so the monitor shows addresses bare).
fn handler_elf() -> Vec<u8> {
    let symbol = |name: &str, value: u32| ImageSymbol {
        name: name.to_owned(),
        value,
        size: 0,
        global: true,
        section: None,
    };
    let image = Image {
        entry: 0x0403,
        flags: 0,
        areas: vec![LoadArea {
            load: 0x0400,
            run: 0x0400,
            bytes: handler_bytes(),
        }],
        sections: vec![],
        symbols: vec![
            symbol("handler", 0x0403),
            symbol("show", 0x040C),
            symbol("value", 0x0480),
        ],
        hooks: Hooks {
            records: vec![HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0403,
                chain: Some(0x0401),
            }],
        },
        lines: isa::objfmt::SrcMap::default(),
    };
    Format::Elf.write(&image).expect("an ELF image")
}

const SESSION: &str = "\
break show
/1Q
regs
print A
mem value 1
poke value $99
step
continue
break handler
delete 1
/1Q
continue
delete 2
/1Q
quit
";

#[test]
fn a_breakpoint_in_a_handler_on_the_pty_robot_and_the_code_compared_after() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), handler_elf()).expect("the image");
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", &sim.path, "--no-dry-run"],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        SESSION,
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    let in_order = [
        "breakpoint 1: $040C",
        "stopped: breakpoint 1, $040C",
        // At the stop: A holds the letter, X the count (docs/PROTOCOL.md).
        "PC=$040C A=$51 X=$01",
        "$51",
        "$0480: 42",
        "$0480: 99 (read back)",
        // One instruction, LDA value: A holds the changed byte.
        "stopped: $040F",
        "A=$99",
        "answer: Q99",
        // `handler`'s CMP and BNE go to a trampoline, the branch relocated.
        "breakpoint 2: $0403",
        "deleted breakpoint 1",
        "stopped: breakpoint 2, $0403",
        "answer: Q99",
        "deleted breakpoint 2",
        "answer: Q99",
        "detached",
    ];
    let mut from = 0;
    for expected in in_order {
        let at = printed[from..]
            .find(expected)
            .unwrap_or_else(|| panic!("`{expected}` after byte {from}:\n{printed}"));
        from += at + expected.len();
    }
    // The last /1Q ran through without a stop.
    assert_eq!(
        printed.matches("stopped: breakpoint").count(),
        2,
        "{printed}"
    );
    // The code is the image's again, but for the byte changed; the hook
    // is the handler's again.
    let output = scorpion(
        dir.path(),
        &[
            "read",
            "$0400",
            "129",
            "-o",
            "after.bin",
            "--port",
            &sim.path,
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    let mut expected = handler_bytes();
    expected[0x80] = 0x99;
    assert_eq!(
        std::fs::read(dir.path().join("after.bin")).expect("a dump"),
        expected
    );
    let output = scorpion(
        dir.path(),
        &["read", "$0200", "3", "-o", "hook.bin", "--port", &sim.path],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        std::fs::read(dir.path().join("hook.bin")).expect("a dump"),
        [0x4C, 0x03, 0x04]
    );
}

#[test]
fn the_readme_section_runs_as_written_against_the_pty_robot() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // The README's source, built by its own first command.
    std::fs::write(
        dir.path().join("ext.s"),
        crate::readme_block("## Debug on the robot", "asm"),
    )
    .expect("the source");
    let sim = Sim::start(dir.path(), &[]);
    let path = crate::path_with_scorpion();
    let mut printed = String::new();
    let script = crate::readme_block("## Debug on the robot", "sh");
    for line in script.lines() {
        let output = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("{line} 2>&1"))
            .current_dir(dir.path())
            .env("PATH", &path)
            .env("PORT", &sim.path)
            .env("NO_COLOR", "1")
            .output()
            .expect("sh runs");
        assert!(
            output.status.success(),
            "`{line}`:\n{}",
            transcript(&output)
        );
        printed.push_str(&String::from_utf8_lossy(&output.stdout));
    }
    for expected in [
        "stopped: breakpoint 1, $0409 (show)",
        "$0418: 99 (read back)",
        "A=$99",
        "answer: Q99",
        "deleted breakpoint 1",
        "detached",
        // fresh14 F8: what stays in RAM, said as the session starts.
        "in memory after the session, unhooked; no undo puts back what was there",
        // fresh28 F3: and the loader's zero page.
        "its state in user zero page $F8-$FF), stay in memory",
        "(and user zero page $F6-$F7)",
    ] {
        assert!(printed.contains(expected), "{expected}:\n{printed}");
    }
}

/// The hostile tester's F1 and M1: a breakpoint inside an instruction of a
/// built image was patched (the robot reset), and one address took two
/// breakpoints. Both refused, the robot's code left as uploaded.
#[test]
fn a_breakpoint_inside_an_instruction_or_twice_at_one_place_is_refused() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let output = scorpion(
        dir.path(),
        &[
            "read",
            "$0400",
            "25",
            "-o",
            "before.bin",
            "--port",
            &sim.path,
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    // `show` (LDA value) is at $0409: $040A is its operand.
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        "break $040A\nbreak show\nbreak show\n/1Q\ncontinue\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    assert!(
        printed.contains("a breakpoint at $040A is refused on the robot: no instruction"),
        "{printed}"
    );
    assert!(
        printed.contains("a breakpoint at $0409 is refused on the robot: one is there already"),
        "{printed}"
    );
    assert!(printed.contains("answer: Q42"), "{printed}");
    let output = scorpion(
        dir.path(),
        &[
            "read",
            "$0400",
            "25",
            "-o",
            "after.bin",
            "--port",
            &sim.path,
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        std::fs::read(dir.path().join("after.bin")).expect("a dump"),
        std::fs::read(dir.path().join("before.bin")).expect("a dump")
    );
}

/// The hostile tester's F2: a signal (Ctrl-C sent to a piped monitor, a
/// closed terminal, `kill`) while the robot was stopped at a breakpoint
/// ended the process there, the robot stuck in the stub for good. Now it
/// ends the session: the breakpoints taken out, the hook given back. Not
/// at the next line read (fresh10 F7: with the pipe left open, or nobody
/// at the terminal, that never came and the robot stayed stopped): at once.
#[test]
fn a_signal_at_a_stop_gives_the_robot_back() {
    use std::process::Command;
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let (mut child, stdin, mut stdout, mut seen) = stopped_at_show(dir.path(), &sim);
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(killed.success());
    // The session ends with no line more (the pipe stays open) and gives
    // the robot back; one that waited would be killed after 30 s, and say
    // nothing of it.
    let pid = child.id().to_string();
    let (done, waited) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        if waited
            .recv_timeout(std::time::Duration::from_secs(30))
            .is_err()
        {
            let _ = Command::new("kill").args(["-KILL", &pid]).status();
        }
    });
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut stdout, &mut rest);
    let status = child.wait().expect("it ends");
    let _ = done.send(());
    watchdog.join().expect("the watchdog");
    drop(stdin);
    seen.push_str(&rest);
    assert!(seen.contains("detached"), "{seen}");
    // hostile15 F8: said, and not a success (a script reads the status).
    assert!(seen.contains("interrupted (signal 15)"), "{seen}");
    assert_eq!(status.code(), Some(143), "{seen}");
    // The robot goes on: its code is the image's again and /1Q answers.
    let output = scorpion(
        dir.path(),
        &["read", "$0409", "3", "-o", "show.bin", "--port", &sim.path],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        std::fs::read(dir.path().join("show.bin")).expect("a dump"),
        [0xAD, 0x18, 0x04]
    );
    let output = scorpion(dir.path(), &["ask", "/1Q", "--port", &sim.path]);
    assert!(
        String::from_utf8_lossy(&output.stdout).contains("Q42"),
        "{}",
        transcript(&output)
    );
}

/// On the robot too, the line that calls the built-in
/// `SCORPION_CHAIN_UNKNOWN` takes a breakpoint at the macro's `JMP` (the
/// old monitor refused it: "no code came from ext.s:15"), hit by a
/// command the handler passes down the chain, which then goes on down it.
#[test]
fn a_line_that_calls_a_built_in_macro_takes_a_breakpoint_on_the_robot() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let source = std::fs::read_to_string(dir.path().join("ext.s")).expect("the source");
    let chain = source
        .lines()
        .position(|l| l.trim() == "SCORPION_CHAIN_UNKNOWN")
        .expect("the chain line")
        + 1;
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "ext.elf"],
        &format!("break ext.s:{chain}\n/1Z\ncontinue\n/1Q\nquit\n"),
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    let mut from = 0;
    for expected in [
        "breakpoint 1: $",
        "(not_mine)",
        "stopped: breakpoint 1, $",
        "answer: Q42",
        "detached",
    ] {
        let at = printed[from..]
            .find(expected)
            .unwrap_or_else(|| panic!("`{expected}` after byte {from}:\n{printed}"));
        from += at + expected.len();
    }
}

/// The README's handler built from its source and uploaded to a pty
/// robot: the directory holding `ext.s` and `ext.elf`, and the robot.
pub(crate) fn readme_handler_on_a_pty_robot() -> (tempfile::TempDir, Sim) {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("ext.s"),
        crate::readme_block("## Debug on the robot", "asm"),
    )
    .expect("the source");
    let built = scorpion(dir.path(), &["build", "ext.s", "-o", "ext.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", &sim.path, "--no-dry-run"],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    (dir, sim)
}

/// fresh10 F23: a command whose answer takes longer than the monitor
/// waits (`/1J` here, about 3 s) answered after the next was sent, and
/// that answer was shown as the next one's, without a word. The monitor
/// now says the answer may be the earlier command's.
#[test]
fn an_answer_after_a_slow_command_is_said_to_be_maybe_its() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("slow.s"),
        "        .include \"scorpion.inc\"
        .code
        SCORPION_UNKNOWN_HANDLER
        cmp #'J'
        bne not_mine
        lda #12
        sta count
outer:  ldx #0
middle: ldy #0
inner:  dey
        bne inner
        dex
        bne middle
        dec count
        bne outer
        lda #'J'
        jsr PUTCH
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
        .bss
count:  .res 1
",
    )
    .expect("the source");
    let built = scorpion(dir.path(), &["build", "slow.s", "-o", "slow.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(
        dir.path(),
        &["upload", "slow.elf", "--port", &sim.path, "--no-dry-run"],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "slow.elf"],
        "/1J\n/1X\nquit\n",
    );
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(said.contains("running (nothing came back"), "{said}");
    assert!(said.contains("this may be the answer of /1J"), "{said}");
}

/// fresh10 F21: a breakpoint in code the control loop runs (examples/
/// patrol's `HOOK_LOOP` handler: `rom` is its `JMP` on to the ROM's loop,
/// run on every pass) was hit before the patch was read back; the stop
/// frames were taken for line noise, the breakpoint forgotten, and `quit`
/// left the robot stopped in the stub. Now the stop is told, `continue`
/// stops there again, and `quit` gives the robot back with the code as
/// the image has it.
#[test]
fn a_breakpoint_in_the_control_loops_handler_stops_there_and_quit_lets_go() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, sim) = crate::robot::patrol_on_a_pty_robot(dir.path());
    let output = scorpion_with_input(
        Some(&project),
        &["debug", "--port", &sim.path],
        "break rom\ninfo\ncontinue\nregs\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    let mut from = 0;
    for expected in [
        "breakpoint 1: $",
        "(rom)",
        "(a stop no command waited for) stopped: breakpoint 1, $",
        // fresh11 F7: the stop names its source line.
        " at patrol.s:",
        "breakpoint 1: $",
        "stopped: breakpoint 1, $",
        "PC=$",
        "detached",
    ] {
        let at = printed[from..]
            .find(expected)
            .unwrap_or_else(|| panic!("`{expected}` after byte {from}:\n{printed}"));
        from += at + expected.len();
    }
    // The robot runs and answers, the JMP at `rom` is the image's again.
    let output = scorpion(&project, &["installed", "--port", &sim.path]);
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(
        said.contains("HOOK_LOOP: $1000 (") && !said.contains("debug stub"),
        "{said}"
    );
    let output = scorpion(&project, &["read", "--port", &sim.path, "$104E", "3"]);
    assert!(
        transcript(&output).contains("4C 24 FF"),
        "{}",
        transcript(&output)
    );
}

/// fresh10 F16: a session that cannot give the robot back at `quit` (the
/// robot went astray, or here its line is gone) said what an upload
/// says, "stalled mid-upload ... safe to retry". It says now that the
/// session could not give the robot back, and what to do about it.
#[test]
fn a_quit_that_cannot_give_the_robot_back_says_so() {
    use std::io::Write as _;
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let (child, mut stdin, _stdout, seen) = stopped_at_show(dir.path(), &sim);
    drop(sim);
    stdin.write_all(b"quit\n").expect("quit");
    drop(stdin);
    let output = child.wait_with_output().expect("it ends");
    let said = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{seen}{said}");
    assert!(
        said.contains("could not give the robot back") && said.contains("reset it"),
        "{said}"
    );
    assert!(
        !said.contains("mid-upload") && !said.contains("safe to retry"),
        "{said}"
    );
}

/// `scorpion debug --port` on `sim` with `dir`'s `ext.elf`, its input
/// and output piped, stopped at `show` by `/1Q`: the process, its input,
/// its output, and what it printed up to the registers.
fn stopped_at_show(
    dir: &std::path::Path,
    sim: &Sim,
) -> (
    std::process::Child,
    std::process::ChildStdin,
    std::io::BufReader<std::process::ChildStdout>,
    String,
) {
    use std::io::{BufRead as _, BufReader, Write as _};
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
        .args(["debug", "--port", &sim.path, "--image", "ext.elf"])
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("scorpion runs");
    let mut stdin = child.stdin.take().expect("its input");
    stdin.write_all(b"break show\n/1Q\n").expect("the lines");
    let mut stdout = BufReader::new(child.stdout.take().expect("its output"));
    let mut seen = String::new();
    while !seen.contains("PC=") {
        let mut line = String::new();
        let read = stdout.read_line(&mut line).expect("a line");
        assert!(read > 0, "ended before the stop:\n{seen}");
        seen.push_str(&line);
    }
    (child, stdin, stdout, seen)
}

/// fresh14 F9: `debug --port` on a robot that never had the image said
/// "the image is in RAM but not installed". The code is compared first:
/// the first byte that differs is named, with the image's and the robot's.
#[test]
fn debug_on_a_robot_without_the_image_names_the_bytes_that_differ() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, _) = crate::new_project(dir.path());
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(&project, &["debug", "--port", &sim.path]);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(!text.contains("in RAM but not installed"), "{text}");
    assert!(text.contains("not_the_image"), "{text}");
}

/// fresh14 F7: in examples/adc, a step from `sta ADC_CONTROL` (a store to
/// the card's register, which the host cannot do for the robot) was
/// refused for good, since `ldx #0` after it is followed by the wait
/// loop's line. The robot now runs it alone in a trampoline of the stub:
/// the card starts, the steps go on through the loop, and the channel is
/// answered.
#[test]
fn a_step_over_a_store_to_the_cards_register_runs_on_the_robot() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = dir.path().join("adc");
    crate::copy_dir(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc"),
        &project,
    );
    let sim = Sim::start(&project, &["--card", "adc.rhai"]);
    let uploaded = scorpion(&project, &["upload", "--port", &sim.path, "--no-dry-run"]);
    assert!(uploaded.status.success(), "{}", transcript(&uploaded));
    let source = std::fs::read_to_string(project.join("adc.s")).expect("the source");
    let line_of = |text: &str| {
        1 + source
            .lines()
            .position(|l| l.trim_start().starts_with(text))
            .unwrap_or_else(|| panic!("`{text}` in adc.s"))
    };
    let (start, store, count) = (
        line_of("ora #$80"),
        line_of("sta ADC_CONTROL"),
        line_of("ldx #0"),
    );
    let output = scorpion_with_input(
        Some(&project),
        &["debug", "--port", &sim.path],
        &format!("break adc.s:{start}\n/2A1\nstep\nstep\nstep\nstep\ncontinue\nquit\n"),
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    assert!(!printed.contains("refused"), "{printed}");
    let mut from = 0;
    for expected in [
        format!("at adc.s:{start}"),
        format!("at adc.s:{store}"),
        format!("at adc.s:{count}"),
        format!("at adc.s:{}", count + 1),
        "P=$72".into(),
        "answer: A".into(),
        "detached".into(),
    ] {
        let at = printed[from..]
            .find(&expected)
            .unwrap_or_else(|| panic!("`{expected}` after byte {from}:\n{printed}"));
        from += at + expected.len();
    }
    assert!(
        !printed.contains("answer: A--"),
        "the card answered: {printed}"
    );
}

/// fresh21 F2: `scorpion debug --port ... | head -2`: once `head` quit,
/// the session's next line failed to print, and the process ended there
/// with the stub still hooked (every upload then refused). Whatever ends
/// the session, its output gone included, the robot is given back.
#[test]
fn a_session_whose_output_is_gone_gives_the_robot_back() {
    use std::process::{Command, Stdio};
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let hooked = scorpion(dir.path(), &["read", "--port", &sim.path, "$0200", "3"]);
    let before = String::from_utf8_lossy(&hooked.stdout).into_owned();
    for closed in ["stdout", "stderr"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(["debug", "--port", &sim.path, "--image", "ext.elf"])
            .current_dir(dir.path())
            .env("NO_COLOR", "1")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("scorpion runs");
        // The reader of one of them quits at once, as `head -0` would.
        let (out, err) = (child.stdout.take(), child.stderr.take());
        let kept = if closed == "stdout" {
            drop(out);
            err.map(|err| std::thread::spawn(move || std::io::read_to_string(err)))
        } else {
            drop(err);
            out.map(|out| std::thread::spawn(move || std::io::read_to_string(out)))
        };
        let status = child.wait().expect("it ends");
        let said = kept
            .map(|reader| reader.join().expect("read").unwrap_or_default())
            .unwrap_or_default();
        assert!(!said.contains("panicked"), "{closed}: {said}");
        let after = scorpion(dir.path(), &["read", "--port", &sim.path, "$0200", "3"]);
        assert_eq!(
            String::from_utf8_lossy(&after.stdout),
            before,
            "{closed} closed ({status}): the stub is left hooked\n{said}"
        );
    }
}
