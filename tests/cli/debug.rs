//! `scorpion debug` driven by scripted sessions, as a user at its prompt
//! would: the session files sit beside this one (`debug/*.txt`), their
//! transcripts in snapshots.

use std::path::Path;
use std::process::Output;

use crate::{scorpion, scorpion_with_input, transcript};

fn session(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/cli/debug/{name}"));
    std::fs::read_to_string(path).expect("the session file")
}

/// The ADC example with its card: break at the handler's label, send its
/// command, step, see the registers, step back three instructions and see
/// the earlier registers again, read the card's registers, stop at the read
/// of its data register, find who wrote its control register, go back to
/// the breakpoint, and continue to the answer.
#[test]
fn a_session_on_the_adc_example_with_its_card() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = scorpion_with_input(Some(&adc), &["debug"], &session("adc_session.txt"));
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    // The registers before the three instructions, and after going back.
    let regs: Vec<&str> = text.lines().filter(|l| l.starts_with("PC=")).collect();
    assert_eq!(
        regs[0], regs[2],
        "back 3 gives the registers three instructions earlier"
    );
    assert_ne!(regs[0], regs[1]);
    assert!(text.contains("< A57\\r"), "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn mistakes_are_said_and_the_session_goes_on() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = scorpion_with_input(
        Some(&adc),
        &["debug"],
        "frobnicate\nbreak nowhere\nbreak read_chanel\nback 999999\nwatch $20..$10\nmem\ndelete 7\nregs\n",
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    insta::assert_snapshot!(text);
}

/// A handler that jams the CPU: the session says so and fails.
#[test]
fn a_robot_that_breaks_fails_the_session() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("jam.s"),
        "        .include \"scorpion.inc\"\n        SCORPION_UNKNOWN_HANDLER\nhandler: .byte $02\n",
    )
    .expect("write");
    let built = scorpion(
        dir.path(),
        &[
            "build",
            "jam.s",
            "-o",
            "jam.elf",
            "--target",
            "scorpion-ext",
        ],
    );
    assert_eq!(built.status.code(), Some(0), "{}", transcript(&built));
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--image", "jam.elf"],
        "/1Z\ncontinue\nregs\n",
    );
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(text.contains("error: ") && text.contains("$0400"), "{text}");
}

/// `scorpion new`'s project: `break src/myext.s:26`, the line that
/// calls the built-in `SCORPION_CHAIN_UNKNOWN`, stops at the macro's
/// `JMP` when a command no extension knows goes down the chain; the stop,
/// `bt` and `list` show that line of the user's source, not
/// `scorpion.inc`'s (the old monitor refused the breakpoint: "no code
/// came from src/myext.s:26").
#[test]
fn a_line_that_calls_a_built_in_macro_takes_a_breakpoint() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (project, text) = crate::new_project(dir.path());
    let chain = crate::lines_with(&text, "SCORPION_CHAIN_UNKNOWN")[0];
    let output = scorpion_with_input(
        Some(&project),
        &["debug"],
        &format!("break src/myext.s:{chain}\n/1W\ncontinue\nbt\nlist\nquit\n"),
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let shown = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        shown.contains("breakpoint 1: $") && shown.contains("breakpoint 1 ($"),
        "set and hit: {shown}"
    );
    let line = format!("src/myext.s:{chain}");
    assert!(
        shown.contains(&format!("  {line}:         SCORPION_CHAIN_UNKNOWN\n")),
        "the stop shows the user's line: {shown}"
    );
    assert!(
        shown.contains("#0 ") && shown.contains(&format!("  {line}: SCORPION_CHAIN_UNKNOWN")),
        "bt: {shown}"
    );
    assert!(
        shown.contains(&format!("> {line}   ")),
        "list marks the user's line: {shown}"
    );
    assert!(!shown.contains("scorpion.inc"), "{shown}");
}

#[test]
fn the_readmes_debugging_section_runs_as_written() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let script = crate::readme_block("## Debug on the virtual Scorpion", "sh");
    let output = std::process::Command::new("sh")
        .arg("-e")
        .arg("-c")
        .arg(format!("exec 2>&1\n{script}"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("PATH", crate::path_with_scorpion())
        .env("TMPDIR", tmp.path())
        .env("NO_COLOR", "1")
        .output()
        .expect("sh runs");
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        String::from_utf8_lossy(&output.stdout),
        crate::readme_block("## Debug on the virtual Scorpion", "text"),
        "README.md's debugging section is stale"
    );
}

#[test]
fn trace_writes_every_instruction_run_to_a_file() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let dir = tempfile::tempdir().expect("a temporary directory");
    let file = dir.path().join("trace.txt");
    let script = format!(
        "break read_channel\n/2A1\ncontinue\ntrace {}\nstep 3\ntrace off\nstep 2\n",
        file.display()
    );
    let output = scorpion_with_input(Some(&adc), &["debug"], &script);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let trace = std::fs::read_to_string(&file).expect("the trace");
    let lines: Vec<&str> = trace.lines().collect();
    assert_eq!(lines.len(), 3, "{trace}");
    assert!(
        lines[0].contains("0400") && lines[0].contains("CPX"),
        "{trace}"
    );
}

#[test]
fn breaks_at_a_source_line_and_lists_the_source_there() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = scorpion_with_input(
        Some(&adc),
        &["debug"],
        "break adc.s:44\n/2A1\ncontinue\nlist\nbreak adc.s:2\n",
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        text.contains("breakpoint 1: $0420 (read_channel+$20)"),
        "{text}"
    );
    assert!(text.contains("  adc.s:44:         bvs @result"), "{text}");
    assert!(text.contains("> adc.s:44           bvs @result"), "{text}");
    assert!(text.contains("error: no code came from adc.s:2"), "{text}");
}

/// Runs `scorpion debug` in `dir` on `input` as [`scorpion_with_input`]
/// does, but under a memory limit (1 GB of address space, through the
/// shell's `ulimit`) and a time limit: a command that allocates gigabytes
/// or runs for ever fails the test instead of the machine.
fn debug_bounded(
    dir: &Path,
    args: &[&str],
    input: impl AsRef<[u8]>,
    limit: std::time::Duration,
) -> Output {
    use std::io::Write as _;
    use std::process::{Command, Stdio};
    let mut child = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1000000 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_scorpion"))
        .args(args)
        .current_dir(dir)
        .env_remove("RUST_BACKTRACE")
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let input = input.as_ref().to_vec();
    // Written on a thread of its own: a monitor stuck in a command stops
    // reading, and the write must not stall the clock below.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let start = std::time::Instant::now();
    while child.try_wait().expect("the child's status").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let output = child.wait_with_output().expect("the killed child");
            panic!(
                "`scorpion {}` still runs after {limit:?}:\n{}",
                args.join(" "),
                transcript(&output)
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = writer.join();
    child.wait_with_output().expect("the child's output")
}

/// Issue 23, item 11: counts and lengths beyond what the address space
/// holds or what a session can wait for are refused, each saying its bound;
/// at the old code they panicked (`mem 0 18446744073709551615`), allocated
/// gigabytes (`mem 0 4294967296`, `dis 0 100000000`) or ran for hours
/// (`step 4294967296`). A dump across $FFFF goes on at $0000, not at
/// `10000:`. A listing at the last line a u32 holds panicked (overflow).
/// The robot is where it was after all of them.
#[test]
fn counts_beyond_their_bounds_are_refused_and_the_session_goes_on() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let script = session("hostile_counts.txt");
    let output = debug_bounded(
        &adc,
        &["debug"],
        format!("regs\n{script}"),
        std::time::Duration::from_secs(60),
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    let replies: Vec<&str> = text.split("(scorpion) ").skip(1).collect();
    for (command, reply) in script.lines().zip(&replies[1..]) {
        let reply = reply.strip_prefix(command).unwrap_or(reply);
        let expected = match command {
            "mem $FFF8 24" => "\n$FFF8: FF FF 3B F6 00 F0 3C F6 ",
            "regs" => "\nPC=",
            "list adc.s:4294967295" => "adc.s has no line 4294967295",
            _ if command.contains(" -") => " is a number of ",
            _ if command.ends_with(" 0") => " is at least 1, not 0",
            _ => " is at most ",
        };
        assert!(reply.contains(expected), "{command}: {reply}");
    }
    assert!(text.contains("\n$0000: 00 00"), "{text}");
    assert!(!text.contains("\n$10000:"), "{text}");
    let regs: Vec<&str> = text.lines().filter(|l| l.starts_with("PC=")).collect();
    assert_eq!(regs.len(), 2, "{text}");
    assert_eq!(regs[0], regs[1], "nothing ran: {text}");
}

/// Issue 23, item 11: a trace whose writes fail says so, naming the file,
/// and the session fails; at the old code `continue` went on for ever
/// (the tracer stops the run at its failed write, and the run started
/// again) and `trace off` said nothing.
#[test]
fn a_trace_that_cannot_be_written_says_so() {
    if !Path::new("/dev/full").exists() {
        scorpion_tests::tools::skipped(
            "a_trace_that_cannot_be_written_says_so",
            "no /dev/full here",
        );
        return;
    }
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    for script in [
        "trace /dev/full\ncontinue\nregs\n",
        "trace /dev/full\nstep 3\ntrace off\nregs\n",
        "trace /dev/full\nstep 3\n",
    ] {
        let output = debug_bounded(&adc, &["debug"], script, std::time::Duration::from_secs(60));
        assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        assert!(
            text.contains("error: cannot write the trace to /dev/full: No space left on device"),
            "{script}: {text}"
        );
    }
}

/// `who-wrote` and `back` say what is true of the session: the image's
/// install (and the ROM's power-up) ran before it began, so nothing in the
/// session wrote the handler's code and nothing ran before its first
/// instruction. The old monitor said "since power-up" for both.
#[test]
fn who_wrote_and_back_speak_of_the_session() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = scorpion_with_input(
        Some(&adc),
        &["debug"],
        "who-wrote read_channel\nback 1\nstep 2\nback 3\n",
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(!text.contains("power-up\n"), "{text}");
    assert!(
        text.contains("no instruction has written $") && text.contains("since the session began"),
        "{text}"
    );
    assert!(
        text.contains("cannot go back 1 instructions: only 0 have run since the session began"),
        "{text}"
    );
    assert!(
        text.contains("cannot go back 3 instructions: only 2 have run since the session began"),
        "{text}"
    );
}

/// A trace's failed write is said by the command whose run wrote it: the
/// old monitor buffered a `step`'s lines, so `/dev/full` failed only at
/// the next command that flushed (`trace off`, or the session's end).
#[test]
fn a_trace_write_that_fails_is_said_by_the_command_that_ran() {
    if !Path::new("/dev/full").exists() {
        scorpion_tests::tools::skipped(
            "a_trace_write_that_fails_is_said_by_the_command_that_ran",
            "no /dev/full here",
        );
        return;
    }
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = debug_bounded(
        &adc,
        &["debug"],
        "trace /dev/full\nstep 3\nregs\ntrace off\n",
        std::time::Duration::from_secs(60),
    );
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    let replies: Vec<&str> = text.split("(scorpion) ").skip(1).collect();
    let reply = |command: &str| {
        replies
            .iter()
            .find(|r| r.starts_with(&format!("{command}\n")))
            .copied()
            .unwrap_or_else(|| panic!("no reply to {command}: {text}"))
    };
    let failed = "error: cannot write the trace to /dev/full: No space left on device";
    assert!(reply("step 3").contains(failed), "{text}");
    assert!(!reply("trace off").contains("error"), "{text}");
}

/// The monitor sends only what the ROM reads as one command (11
/// characters at most, docs/PROTOCOL.md): a 100 kB line starting with `/`
/// was queued whole, minutes of line time ahead of everything after it
/// (the hostile sweep after issue 23). Refused, saying why; the session
/// goes on and the next command is answered.
#[test]
fn the_monitor_sends_only_commands_the_rom_can_read() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let long = format!("/2A1{}", "1".repeat(100_000));
    let output = scorpion_with_input(
        Some(&adc),
        &["debug"],
        &format!("{long}\nsend /1E/1B\n/2A1\ncontinue 200000\n"),
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        text.contains(
            "is 100004 bytes: a command is `/`, a count 1-9 and that many characters, 11 at most"
        ),
        "{}",
        &text[text.len().saturating_sub(2000)..]
    );
    assert!(
        text.contains("expected exactly 1 characters after `/1`"),
        "{text:.2000}"
    );
    assert!(
        !text.contains("sent /2A11111"),
        "the long line was not sent"
    );
    assert!(text.contains("sent /2A1\n"), "{text:.2000}");
    assert!(
        text.contains("< A57\\r"),
        "only /2A1 was on the line: {text:.3000}"
    );
}

/// The fenced block of `kind` that follows `heading` in docs/DEBUGGING.md.
fn guide_block(heading: &str, kind: &str) -> String {
    let guide =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/DEBUGGING.md"))
            .expect("docs/DEBUGGING.md");
    let section = &guide[guide.find(heading).expect("the section")..];
    let fence = format!("```{kind}\n");
    let start = section.find(&fence).expect("the block") + fence.len();
    let end = start + section[start..].find("```").expect("the block's end");
    section[start..end].to_string()
}

/// The planted-bug hunt of docs/DEBUGGING.md, run as written: its output
/// is the guide's.
#[test]
fn the_debugging_guides_bug_hunt_runs_as_written() {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let heading = "## A bug hunt in the monitor";
    let script = guide_block(heading, "sh");
    let output = std::process::Command::new("sh")
        .arg("-e")
        .arg("-c")
        .arg(format!("exec 2>&1\n{script}"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("PATH", crate::path_with_scorpion())
        .env("TMPDIR", tmp.path())
        .env("NO_COLOR", "1")
        .output()
        .expect("sh runs");
    assert!(output.status.success(), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("< K0203\\r") && text.contains("< K0003\\r"),
        "{text}"
    );
    assert_eq!(
        text,
        guide_block(heading, "text"),
        "docs/DEBUGGING.md's bug hunt is stale"
    );
}

/// New commands at the prompt from a script: a conditional breakpoint, a
/// hit count, a log point, set, mem writes, print, display, bt, until,
/// and their mistakes (a condition that does not parse, with its column;
/// a count of 2^64; a register's value out of range; ROM written).
#[test]
fn conditions_counts_logs_sets_and_their_mistakes() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = scorpion_with_input(Some(&adc), &["debug"], &session("new_commands.txt"));
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    insta::assert_snapshot!(text);
}

/// Found by a fresh-eyes tester of the new monitor: a line that is not
/// UTF-8 ended the whole session (exit 1, the robot lost), a long flat
/// expression (`1+1+...`, 100,000 terms) overflowed the stack, and
/// `display` took any number of expressions. Each is refused alone now;
/// the session goes on and ends well.
#[test]
fn a_bad_line_a_long_expression_and_many_displays_are_refused_alone() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let mut input = b"print 1\nprint \xff\xfe A\nprint 2\n".to_vec();
    input.extend(format!("print {}1\n", "1+".repeat(5_000)).bytes());
    input.extend("display A\n".repeat(70).bytes());
    input.extend(b"print 3\nquit\n");
    let output = debug_bounded(&adc, &["debug"], input, std::time::Duration::from_secs(60));
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        text.contains("error: that line is not UTF-8 text; it was skipped"),
        "{text:.3000}"
    );
    assert!(text.contains("print 2\n2 = $02"), "{text:.3000}");
    assert!(text.contains("at most 1000 operators"), "{text:.3000}");
    assert!(text.contains("display 64: A = "), "{text:.3000}");
    assert!(!text.contains("display 65:"), "{text:.3000}");
    assert!(
        text.contains("at most 64 expressions are displayed at once"),
        "{text:.3000}"
    );
    assert!(text.contains("print 3\n3 = $03"), "{text:.3000}");
}

/// Issue 25's leftovers: `mem ADDR $10` (a length written in hex, as
/// addresses are) was refused as "not a number"; a length is any
/// expression now, within the same bounds.
#[test]
fn a_memory_length_may_be_written_in_hex() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let output = scorpion_with_input(
        Some(&adc),
        &["debug"],
        "mem $0300 $10\nmem $0300 %11\nmem $0300 16\nmem $0300 $10001\n",
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("$0300:")).collect();
    assert_eq!(rows.len(), 3, "{text}");
    assert_eq!(rows[0], rows[2], "$10 is 16 bytes: {text}");
    assert_eq!(
        rows[1].split_whitespace().count(),
        1 + 3 + 1,
        "%11 is 3 bytes (and their text): {text}"
    );
    assert!(text.contains("is at most 65536 bytes"), "{text}");
}
