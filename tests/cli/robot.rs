//! Issue 27 through a real pseudo-terminal to `scorpion sim --pty`
//! standing for the robot, the tools using nothing but the line: a ROM
//! that differs in one byte of its jump table refused before anything is
//! written, and read whole into a profile the sim runs; a backup, a
//! hostile change, a restore, RAM compared; a one-byte change uploaded as
//! one range, and the upload undone.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

use isa::objfmt::{HookKind, HookRecord, Hooks};
use linker::{Format, Image, LoadArea};

use crate::{scorpion, scorpion_with_input, transcript};

/// `scorpion sim --pty ARGS`, stopped when dropped.
pub(crate) struct Sim {
    pub(crate) child: Child,
    pub(crate) path: String,
}

impl Sim {
    pub(crate) fn start(dir: &std::path::Path, args: &[&str]) -> Sim {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(["sim", "--pty"])
            .args(args)
            .current_dir(dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("the scorpion binary runs");
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout is piped"));
        let mut path = String::new();
        stdout
            .read_line(&mut path)
            .expect("the first line is the pseudo-terminal's path");
        Sim {
            child,
            path: path.trim().to_owned(),
        }
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// examples/patrol (an OS with both hooks) copied into `dir` and uploaded
/// to a fresh pty robot: the project's directory and the robot.
pub(crate) fn patrol_on_a_pty_robot(dir: &std::path::Path) -> (std::path::PathBuf, Sim) {
    let project = dir.join("patrol");
    crate::copy_dir(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/patrol"),
        &project,
    );
    let sim = Sim::start(dir, &[]);
    let output = scorpion(&project, &["upload", "--port", &sim.path, "--no-dry-run"]);
    assert!(output.status.success(), "{}", transcript(&output));
    (project, sim)
}

/// An extension of `len` bytes at $0400 (`JMP chain`, a handler that falls
/// through, filler), with the byte at `changed` (if any) altered.
fn extension_elf(len: usize, changed: Option<usize>) -> Vec<u8> {
    extension_at(0x0400, len, changed)
}

/// `scorpion ARGS LINE` in `dir`, which must exit 0: what it printed.
fn run_ok(dir: &Path, line: &[&str], args: &[&str]) -> String {
    let mut all = args.to_vec();
    all.extend(line);
    let output = scorpion(dir, &all);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{args:?}: {text}");
    text
}

/// [`extension_elf`] at `base` instead of $0400.
pub(crate) fn extension_at(base: u16, len: usize, changed: Option<usize>) -> Vec<u8> {
    let mut bytes: Vec<u8> = (0..len).map(|i| (i * 37 + 11) as u8).collect();
    if let Some(at) = changed {
        bytes[at] ^= 0x5A;
    }
    extension_of(base, bytes)
}

/// `bytes` at `base` as [`extension_at`] lays them out: its first six
/// bytes become the chain slot's `JMP` and the handler's.
pub(crate) fn extension_of(base: u16, mut bytes: Vec<u8>) -> Vec<u8> {
    let [low, high] = base.to_le_bytes();
    bytes[..6].copy_from_slice(&[0x4C, 0x00, 0x00, 0x4C, low, high]);
    let image = Image {
        entry: u32::from(base) + 3,
        flags: 0,
        areas: vec![LoadArea {
            load: u32::from(base),
            run: u32::from(base),
            bytes,
        }],
        sections: vec![],
        symbols: vec![],
        hooks: Hooks {
            records: vec![HookRecord {
                kind: HookKind::Unknown,
                handler: base + 3,
                chain: Some(base + 1),
            }],
        },
        lines: isa::objfmt::SrcMap::default(),
    };
    Format::Elf.write(&image).expect("an ELF image")
}

/// The reference ROM with PENDING's operand (`$FF2E`, a jump-table byte
/// the ROM never calls through itself) changed, as a ROM profile file.
pub(crate) fn changed_rom() -> (Vec<u8>, u8, u8) {
    let mut rom = Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("parses");
    let area = rom
        .areas
        .iter_mut()
        .find(|area| area.load <= 0xFF2E && 0xFF2E < area.end())
        .expect("the ROM loads $FF2E");
    let at = (0xFF2E - area.load) as usize;
    let before = area.bytes[at];
    area.bytes[at] = before ^ 0x10;
    (
        Format::Elf.write(&rom).expect("an ELF image"),
        before,
        before ^ 0x10,
    )
}

#[test]
fn a_rom_differing_in_one_jump_table_byte_is_refused_and_read_into_a_profile() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (rom, expected, found) = changed_rom();
    std::fs::write(dir.path().join("changed.elf"), rom).expect("write the ROM");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(600, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--rom", "changed.elf", "--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];

    let mut args = vec!["upload", "ext.elf", "--no-dry-run"];
    args.extend(line);
    let output = scorpion(dir.path(), &args);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    let wanted = format!("$FF2E: expected ${expected:02X}, found ${found:02X}");
    assert!(text.contains(&wanted), "{text}");
    assert!(text.contains("uploader::wrong_rom"), "{text}");
    // Nothing was written: the hook and the image's memory are as at power-up.
    let mut args = vec!["read", "$0200", "3"];
    args.extend(line);
    let output = scorpion(dir.path(), &args);
    assert!(
        String::from_utf8_lossy(&output.stdout).starts_with("0200: 4C 21 FF"),
        "{}",
        transcript(&output)
    );

    // The whole ROM, read over the line into a profile the sim runs.
    let mut args = vec!["rom", "read", "-o", "read.elf"];
    args.extend(line);
    let output = scorpion(dir.path(), &args);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(text.contains("1 byte differs from"), "{text}");
    let read = Image::parse(
        "read.elf",
        &std::fs::read(dir.path().join("read.elf")).expect("the profile"),
    )
    .expect("an image");
    let changed = Image::parse(
        "changed.elf",
        &std::fs::read(dir.path().join("changed.elf")).expect("the ROM"),
    )
    .expect("an image");
    for address in 0xF000..=0xFFFFu32 {
        assert_eq!(
            read.byte_at(address),
            changed.byte_at(address),
            "${address:04X}"
        );
    }
    assert_eq!(read.symbol("GETCH"), changed.symbol("GETCH"));
    let output = scorpion_with_input(
        Some(dir.path()),
        &["sim", "--rom", "read.elf"],
        "/7RFF2D03\n",
    );
    let text = transcript(&output);
    assert!(
        text.contains(&format!("R4C{found:02X}")),
        "the sim runs the profile: {text}"
    );
}

#[test]
fn backup_a_hostile_change_restore_and_the_ram_compares() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(600, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let run = |args: &[&str]| run_ok(dir.path(), &line, args);
    run(&["upload", "ext.elf", "--no-dry-run"]);
    run(&["backup", "-o", "before.bak"]);
    // Hostile: code and zero page overwritten, the hook pointed at them.
    run(&[
        "ask",
        "/9W04100000",
        "/9W0500DEAD",
        "/9W00F0BEEF",
        "/9W02010005",
    ]);
    run(&["backup", "-o", "hostile.bak"]);
    let text = run(&["restore", "before.bak"]);
    assert!(text.contains("verified"), "{text}");
    run(&["backup", "-o", "after.bak"]);
    let read = |name: &str| std::fs::read(dir.path().join(name)).expect("a backup");
    assert_ne!(read("hostile.bak"), read("before.bak"), "the change took");
    assert_eq!(
        read("after.bak"),
        read("before.bak"),
        "RAM, table and hooks"
    );
}

#[test]
fn a_one_byte_change_goes_as_one_range_and_undo_puts_it_back() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(2048, None)).expect("the image");
    std::fs::write(dir.path().join("ext2.elf"), extension_elf(2048, Some(1000)))
        .expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let run = |args: &[&str]| run_ok(dir.path(), &line, args);
    run(&["upload", "ext.elf", "--no-dry-run"]);
    run(&["read", "$0400", "2048", "-o", "first.bin"]);
    let text = run(&["upload", "ext2.elf", "--no-dry-run", "--replace"]);
    // The changed byte's fine range (odd, at most 39 bytes), and the
    // table entry (15 bytes: its id).
    let written = text
        .split(" bytes written in 2 ranges")
        .next()
        .and_then(|head| head.rsplit(' ').next())
        .and_then(|count| count.parse::<usize>().ok())
        .unwrap_or_else(|| panic!("{text}"));
    assert!((16..=15 + 39).contains(&written), "{text}");
    run(&["read", "$0400", "2048", "-o", "second.bin"]);
    let first = std::fs::read(dir.path().join("first.bin")).expect("a dump");
    let second = std::fs::read(dir.path().join("second.bin")).expect("a dump");
    let differ: Vec<usize> = (0..2048).filter(|&i| first[i] != second[i]).collect();
    assert_eq!(differ, vec![1000]);

    let text = run(&["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    run(&["read", "$0400", "2048", "-o", "undone.bin"]);
    assert_eq!(
        std::fs::read(dir.path().join("undone.bin")).expect("a dump"),
        first
    );
}

#[test]
fn the_readme_section_runs_as_written_against_the_pty_robot() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(700, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let path = crate::path_with_scorpion();
    let mut printed = String::new();
    let script = crate::readme_block("## Back up, restore, undo, and the right ROM", "sh");
    for line in script.lines() {
        let output = Command::new("sh")
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
        "it is the built-in reference ROM, byte for byte",
        "uploaded and verified 700 bytes",
        "verified 700 bytes (none of them written: the robot held them all)",
        "restored scorpion-last-upload.undo",
        "restored robot.bak",
    ] {
        assert!(printed.contains(expected), "{expected}:\n{printed}");
    }
    // The robot holds what it held before the upload.
    let output = scorpion(
        dir.path(),
        &[
            "backup",
            "--port",
            &sim.path,
            "--baud",
            "19200",
            "-o",
            "after.bak",
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        std::fs::read(dir.path().join("after.bak")).expect("a backup"),
        std::fs::read(dir.path().join("robot.bak")).expect("a backup"),
    );
    // fresh10 F3: restored again onto a robot that holds it, the bytes
    // written are said as the RAM loader's, not as changes found.
    let output = scorpion(
        dir.path(),
        &[
            "restore",
            "robot.bak",
            "--port",
            &sim.path,
            "--baud",
            "19200",
        ],
    );
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(
        said.contains("written, all where the RAM loader ran, put back after it"),
        "{said}"
    );
}

/// `scorpion ARGS` in `dir`, killed after `seconds` (exit status 124):
/// for what used to hang.
fn scorpion_within(dir: &std::path::Path, seconds: u32, args: &[&str]) -> std::process::Output {
    Command::new("timeout")
        .arg(seconds.to_string())
        .arg(env!("CARGO_BIN_EXE_scorpion"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .env("COLUMNS", "100")
        .output()
        .expect("timeout runs")
}

/// What the robot holds (RAM, table, hooks), as `scorpion backup` saves it.
fn robot_state(dir: &std::path::Path, line: &[&str], name: &str) -> Vec<u8> {
    let mut args = vec!["backup", "-o", name];
    args.extend(line);
    let output = scorpion(dir, &args);
    assert!(output.status.success(), "{}", transcript(&output));
    std::fs::read(dir.join(name)).expect("a backup")
}

/// Hostile F4: an undo file kept on one robot, where the hook went back
/// into an earlier copy of the image, undone on another robot whose RAM
/// does not hold that copy: refused, naming the memory and its sums,
/// before any hook moved.
#[test]
fn undo_on_another_robot_is_refused_before_any_hook_moves() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(2048, None)).expect("the image");
    std::fs::write(dir.path().join("ext2.elf"), extension_elf(2048, Some(1000)))
        .expect("the image");
    let first = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", first.path.as_str(), "--baud", "19200"];
    for args in [
        vec!["upload", "ext.elf", "--no-dry-run"],
        vec!["upload", "ext2.elf", "--no-dry-run", "--replace"],
    ] {
        let mut args = args;
        args.extend(line);
        let output = scorpion(dir.path(), &args);
        assert!(output.status.success(), "{}", transcript(&output));
    }
    drop(first);

    let other = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", other.path.as_str(), "--baud", "19200"];
    let before = robot_state(dir.path(), &line, "before.bak");
    let mut args = vec!["upload", "--undo"];
    args.extend(line);
    let output = scorpion_within(dir.path(), 120, &args);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("uploader::witness_differs"), "{text}");
    assert!(text.contains("$0400-"), "{text}");
    assert_eq!(robot_state(dir.path(), &line, "after.bak"), before);
}

/// Hostile F5: an output that is a FIFO is refused before the line is
/// used, not blocked on (each run is killed after 60 s on the old code).
#[test]
fn outputs_to_a_fifo_are_refused_before_the_robot_is_touched() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(600, None)).expect("the image");
    let made = Command::new("mkfifo")
        .arg(dir.path().join("pipe"))
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let before = robot_state(dir.path(), &line, "before.bak");
    for args in [
        vec!["upload", "ext.elf", "--no-dry-run", "--undo-file", "pipe"],
        vec!["backup", "-o", "pipe"],
        vec!["rom", "read", "-o", "pipe"],
        vec!["read", "$0400", "16", "-o", "pipe"],
    ] {
        let mut all = args.clone();
        all.extend(line);
        let output = scorpion_within(dir.path(), 60, &all);
        let text = transcript(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {text}");
        assert!(
            text.contains("pipe: a FIFO (named pipe)"),
            "{args:?}: {text}"
        );
    }
    assert_eq!(robot_state(dir.path(), &line, "after.bak"), before);
}

/// Hostile F6: `--replace --loader always` where the loader cannot be
/// used (code no table entry names is hooked in front of the replaced
/// extension: the loader could land on it) is refused before the
/// replaced extension leaves its chain.
#[test]
fn a_loader_refusal_comes_before_a_replace_changes_anything() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("a.elf"), extension_at(0x0400, 600, None)).expect("A");
    std::fs::write(
        dir.path().join("a2.elf"),
        extension_at(0x0400, 600, Some(300)),
    )
    .expect("A changed");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let mut args = vec!["upload", "a.elf", "--no-dry-run"];
    args.extend(line);
    let output = scorpion(dir.path(), &args);
    assert!(output.status.success(), "{}", transcript(&output));
    // Code put in by hand at $0900, `JMP $0403` (A's handler), hooked in
    // front of A: no entry of the table names it.
    for write in ["/9W09004C03", "/7W090204", "/9W02010009"] {
        let mut args = vec!["ask", write, "--allow-silence"];
        args.extend(line);
        let output = scorpion(dir.path(), &args);
        assert!(output.status.success(), "{}", transcript(&output));
    }
    let before = robot_state(dir.path(), &line, "before.bak");
    let mut args = vec![
        "upload",
        "a2.elf",
        "--no-dry-run",
        "--replace",
        "--loader",
        "always",
    ];
    args.extend(line);
    let output = scorpion(dir.path(), &args);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("nothing was changed"), "{text}");
    assert_eq!(robot_state(dir.path(), &line, "after.bak"), before);
}

/// Hostile F7: reading memory the robot writes while it runs (its zero
/// page and receive buffer) is not blamed on the line.
#[test]
fn reading_ram_in_use_says_the_bytes_changed_and_where() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let output = scorpion_within(
        dir.path(),
        300,
        &[
            "read", "$0000", "512", "--port", &sim.path, "--baud", "19200",
        ],
    );
    let text = transcript(&output);
    // hostile16 F4: read as one moment's value, the bytes that changed
    // named (the receive ring's head and tail), not refused.
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(
        text.contains("note: the robot wrote $0000, $0001")
            && text.contains("while it was read, as it runs: one moment's value"),
        "{text}"
    );
    assert!(text.contains("\n0000: "), "{text}");
    assert!(!text.contains("uploader::unreadable"), "{text}");
}

/// Hostile F8: a backup taken from a robot with another ROM is refused
/// on this one, saying what differs, and restored with `--force`.
#[test]
fn a_backup_from_another_rom_is_refused_unless_forced() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (rom, theirs, ours) = changed_rom();
    std::fs::write(dir.path().join("changed.elf"), rom).expect("write the ROM");
    let changed = Sim::start(dir.path(), &["--rom", "changed.elf", "--baud", "19200"]);
    robot_state(
        dir.path(),
        &["--port", changed.path.as_str(), "--baud", "19200"],
        "theirs.bak",
    );
    drop(changed);
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let mut args = vec!["restore", "theirs.bak"];
    args.extend(line);
    let output = scorpion(dir.path(), &args);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("uploader::backup_rom_differs"), "{text}");
    // The backup holds the changed ROM's byte; the robot the reference's.
    assert!(
        text.contains(&format!("$FF2E: expected ${ours:02X}, found ${theirs:02X}")),
        "{text}"
    );
    args.push("--force");
    let output = scorpion(dir.path(), &args);
    assert!(output.status.success(), "{}", transcript(&output));
}

/// Hostile minor findings: a missing undo file and a damaged one are told
/// apart; `rom read --base` refuses an extension's image.
#[test]
fn undo_file_errors_say_what_is_wrong_and_rom_read_refuses_an_extension_base() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(600, None)).expect("the image");
    std::fs::write(
        dir.path().join("damaged.undo"),
        b"SCORPION-BACKUP 1\nA\x00\x04",
    )
    .expect("a damaged undo file");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let run = |args: &[&str]| {
        let mut all = args.to_vec();
        all.extend(["--port", sim.path.as_str(), "--baud", "19200"]);
        let output = scorpion(dir.path(), &all);
        assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
        transcript(&output)
    };
    let text = run(&["upload", "--undo", "--undo-file", "missing.undo"]);
    assert!(text.contains("missing.undo does not exist"), "{text}");
    let text = run(&["upload", "--undo", "--undo-file", "damaged.undo"]);
    assert!(!text.contains("nothing to undo"), "{text}");
    assert!(text.contains("(at byte 19)"), "{text}");
    let text = run(&["rom", "read", "--base", "ext.elf", "-o", "rom.elf"]);
    assert!(text.contains("is not a ROM profile"), "{text}");
    assert!(text.contains("$0400-$0657"), "{text}");
    assert!(!dir.path().join("rom.elf").exists());
}

/// hostile11 F3: another program reading the robot's port (a terminal
/// left open, a modem manager's probe) took the bytes a poll announced,
/// and every command then waited in `read` for ever. Reads return now
/// when nothing is there: the command ends, one way or the other.
#[test]
fn a_second_reader_on_the_port_does_not_hang_a_command() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let sim = Sim::start(dir.path(), &[]);
    let mut thief = std::process::Command::new("cat")
        .arg(&sim.path)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("cat runs");
    let asked = std::process::Command::new("timeout")
        .args([
            "60",
            env!("CARGO_BIN_EXE_scorpion"),
            "ask",
            "--port",
            &sim.path,
        ])
        .args(["/1P", "/1X", "/1P", "/1X", "/1P", "/1X"])
        .output()
        .expect("timeout runs");
    let _ = thief.kill();
    let _ = thief.wait();
    assert_ne!(asked.status.code(), Some(124), "{}", transcript(&asked));
}

/// fresh10 F11: `--expect` on a port is checked on a rehearsal with the
/// image alone; where the image chains to another extension on the robot,
/// the upload says the expectations were met without it. And with
/// `--no-dry-run` they would be checked nowhere: refused.
#[test]
fn expectations_on_a_port_say_what_the_rehearsal_lacked() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("a.elf"), extension_at(0x0400, 64, None)).expect("an image");
    std::fs::write(dir.path().join("b.elf"), extension_at(0x0600, 64, None)).expect("an image");
    std::fs::write(dir.path().join("ok.expect"), "/1X => X00\n").expect("expectations");
    let sim = Sim::start(dir.path(), &[]);
    let port = sim.path.as_str();
    let output = scorpion(
        dir.path(),
        &["upload", "a.elf", "--no-dry-run", "--port", port],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion(
        dir.path(),
        &["upload", "b.elf", "--expect", "ok.expect", "--port", port],
    );
    let text = transcript(&output);
    assert!(output.status.success(), "{text}");
    assert!(
        text.contains("note: on the robot HOOK_UNKNOWN falls through to $0403, another extension the rehearsal did not have"),
        "{text}"
    );
    let output = scorpion(
        dir.path(),
        &[
            "upload",
            "b.elf",
            "--expect",
            "ok.expect",
            "--no-dry-run",
            "--replace",
            "--port",
            port,
        ],
    );
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(
        text.contains("--expect is checked on the rehearsal, which --no-dry-run skips"),
        "{text}"
    );
}

/// hostile31 F3: a version 1 file (an earlier scorpion's) checks the code
/// it only witnesses with both sums mod 256, which some changes of two
/// bytes pass; `restore` and `upload --undo` say so whenever they use one.
#[test]
fn a_version_1_file_is_read_with_a_warning_about_its_checks() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // HOOK_UNKNOWN at the ROM's target; a witness of $1000-$100F.
    let mut body = b"SCORPION-BACKUP 1\n".to_vec();
    body.extend_from_slice(&[b'H', 0, 0x21, 0xFF]);
    body.extend_from_slice(&[b'W', 0x00, 0x10, 0x10, 0x00, 0x00, 0x00]);
    // The end record: FNV-1a 32 of every byte before it.
    let sum = body.iter().fold(0x811C_9DC5_u32, |hash, &byte| {
        (hash ^ u32::from(byte)).wrapping_mul(0x0100_0193)
    });
    body.push(b'E');
    body.extend_from_slice(&sum.to_le_bytes());
    std::fs::write(dir.path().join("old.bak"), &body).expect("the file");
    std::fs::write(dir.path().join("old.undo"), &body).expect("the file");
    for args in [
        vec!["restore", "old.bak", "--port", "emu"],
        vec![
            "upload",
            "--undo",
            "--undo-file",
            "old.undo",
            "--port",
            "emu",
        ],
    ] {
        let output = scorpion(dir.path(), &args);
        let text = transcript(&output);
        assert!(
            text.contains("old.") && text.contains("was written by an earlier scorpion"),
            "{args:?}: {text}"
        );
        assert!(text.contains("take a new backup"), "{args:?}: {text}");
    }
}

/// hostile31 F1: an edit that only moves bytes about (two instructions
/// whose bytes add up alike swapped) balances the robot's sums, and the
/// `--replace` upload of it left the old bytes, "verified". `upload`
/// keeps each image it put in beside its undo file, and the next upload
/// writes where the earlier version differs, whatever the sums say.
#[test]
fn an_edit_that_balances_the_sums_is_written_by_the_next_upload() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut bytes: Vec<u8> = (0..600).map(|i| (i * 37 + 11) as u8).collect();
    bytes[300..304].copy_from_slice(&[0xA9, 0x10, 0x69, 0x50]);
    std::fs::write(
        dir.path().join("v1.elf"),
        extension_of(0x0400, bytes.clone()),
    )
    .expect("v1");
    bytes[300..304].copy_from_slice(&[0x69, 0x50, 0xA9, 0x10]);
    std::fs::write(dir.path().join("v2.elf"), extension_of(0x0400, bytes)).expect("v2");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let run = |args: &[&str]| run_ok(dir.path(), &line, args);
    run(&["upload", "v1.elf", "--no-dry-run"]);
    assert!(
        dir.path().join("scorpion-last-upload.undo.images").is_dir(),
        "the image kept beside the undo file"
    );
    run(&["upload", "v2.elf", "--no-dry-run", "--replace"]);
    let text = run(&["ask", "/7R052C04"]);
    assert!(text.contains("R6950A910"), "v2's bytes at $052C: {text}");
}
