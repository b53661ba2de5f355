//! `scorpion upload`: into the in-process virtual Scorpion (`--port emu`)
//! with expectations checked after; end to end through a real
//! pseudo-terminal to `scorpion sim --pty`, rehearsal first; a rehearsal
//! that fails touching nothing; and images it must refuse.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

use isa::objfmt::{HookKind, HookRecord, Hooks};
use linker::{Format, Image, LoadArea};

use crate::read::{PtyRobot, memory};
use crate::{build_example, scorpion, transcript};

/// An extension image of `len` bytes at $0400 that is real code: `$0400:
/// JMP chain` (the chain slot, $0401, is its operand), `$0403: JMP $0400`
/// (the handler owns nothing and falls through), then filler.
fn extension_elf(len: usize) -> Vec<u8> {
    let mut bytes: Vec<u8> = (0..len).map(|i| (i * 31 + 7) as u8).collect();
    bytes[..6].copy_from_slice(&[0x4C, 0x00, 0x00, 0x4C, 0x00, 0x04]);
    let image = Image {
        entry: 0x0403,
        flags: 0,
        areas: vec![LoadArea {
            load: 0x0400,
            run: 0x0400,
            bytes,
        }],
        sections: vec![],
        symbols: vec![],
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

/// `scorpion sim --pty`, stopped when dropped.
pub(crate) struct Sim {
    child: Child,
    pub(crate) path: String,
}

impl Sim {
    pub(crate) fn start() -> Sim {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(["sim", "--pty"])
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

/// The checksum example, built by `scorpion build` into `dir`.
fn checksum_example(dir: &std::path::Path) -> String {
    let layout = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/checksum/checksum.toml")
        .display()
        .to_string();
    build_example(
        dir,
        "checksum/checksum.s",
        "checksum.elf",
        &["--target", &layout],
    );
    "checksum.elf".into()
}

#[test]
fn uploads_into_the_virtual_scorpion_and_checks_expectations() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(2048)).expect("write the image");
    std::fs::write(
        dir.path().join("ext.expect"),
        "# the extension passes unknown commands on; the ROM still answers\n\
         /1Q\n/1X => X00\n/7R020003 => R4C0304\n/7R040103 => R21FF4C\n",
    )
    .expect("write the expectations");
    let output = scorpion(
        dir.path(),
        &[
            "upload",
            "ext.elf",
            "--port",
            "emu",
            "--expect",
            "ext.expect",
        ],
    );
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    // Robot time on the virtual Scorpion is exact, so the figures are too.
    insta::assert_snapshot!("upload_emu_loader", text);

    let output = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", "emu", "--loader", "never"],
    );
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    insta::assert_snapshot!("upload_emu_rom_only", text);
}

#[test]
fn end_to_end_through_a_pseudo_terminal_to_scorpion_sim() {
    let sim = Sim::start();
    let dir = tempfile::tempdir().expect("temporary directory");
    let checksum = checksum_example(dir.path());
    std::fs::write(
        dir.path().join("checksum.expect"),
        "/9W10000102\n/9K10000002 => K0003\n",
    )
    .expect("write the expectations");
    // A larger extension first, through the RAM loader (at 9600: a
    // pseudo-terminal has no line rate to raise), then the checksum
    // example chained behind it, rehearsed with its expectations.
    std::fs::write(dir.path().join("ext.elf"), extension_elf(1200)).expect("write the image");
    let output = scorpion(dir.path(), &["upload", "ext.elf", "--port", &sim.path]);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(
        text.contains("rehearsed on the virtual Scorpion: 1200 bytes verified"),
        "{text}"
    );
    assert!(
        text.contains("through the RAM loader") && text.contains("at 9600 baud"),
        "{text}"
    );
    let output = scorpion(
        dir.path(),
        &[
            "upload",
            &checksum,
            "--port",
            &sim.path,
            "--expect",
            "checksum.expect",
        ],
    );
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(text.contains("2 expectations met"), "{text}");
    assert!(text.contains("< K0003"), "{text}");
    assert!(text.contains("(falls through to $0403)"), "{text}");

    // The robot behind the pseudo-terminal answers the new command, and
    // the chain runs through both extensions to the ROM.
    let output = scorpion(
        dir.path(),
        &[
            "ask",
            "--port",
            &sim.path,
            "--allow-silence",
            "/9W20001020",
            "/9K20000002",
            "/1Q",
            "/1X",
        ],
    );
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(text.contains("K0030\nX00\n"), "{text}");
    let output = scorpion(
        dir.path(),
        &[
            "read", "--port", &sim.path, "$0400", "1200", "-o", "dump.bin",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let mut expected: Vec<u8> = (0..1200).map(|i| (i * 31 + 7) as u8).collect();
    expected[..6].copy_from_slice(&[0x4C, 0x21, 0xFF, 0x4C, 0x00, 0x04]);
    assert_eq!(
        std::fs::read(dir.path().join("dump.bin")).expect("the dump"),
        expected,
        "the extension, its chain slot holding BAD_COMMAND"
    );
}

#[test]
fn a_failed_rehearsal_touches_nothing() {
    let robot = PtyRobot::spawn(memory());
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(300)).expect("write the image");
    std::fs::write(
        dir.path().join("wrong.expect"),
        "/7R040301 => R00   # it is a JMP\n",
    )
    .expect("write the expectations");
    let output = scorpion(
        dir.path(),
        &[
            "upload",
            "ext.elf",
            "--port",
            &robot.path,
            "--expect",
            "wrong.expect",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    insta::assert_snapshot!(
        "upload_rehearsal_failed",
        transcript(&output).replace(&robot.path, "[PTY]")
    );
    assert_eq!(
        *robot.memory.lock().expect("the robot's memory"),
        memory(),
        "the robot was not touched"
    );

    let output = scorpion(
        dir.path(),
        &[
            "upload",
            "ext.elf",
            "--port",
            "emu",
            "--expect",
            "missing.expect",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    assert!(transcript(&output).contains("missing.expect"));
    std::fs::write(dir.path().join("bad.expect"), "/1X => B00\n").expect("write");
    let output = scorpion(
        dir.path(),
        &[
            "upload",
            "ext.elf",
            "--port",
            "emu",
            "--expect",
            "bad.expect",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    // Named at its file:line.
    assert!(
        transcript(&output).contains("bad.expect:1: "),
        "{}",
        transcript(&output)
    );
}

#[test]
fn uploads_to_a_robot_with_another_rom_through_a_pseudo_terminal() {
    // The double's hooks point at $F123 and $F045, not the reference ROM's
    // targets. Its ROM's bytes are the reference ROM's (issue 27: a jump
    // table that differs is refused, tested in robot.rs), where those are
    // the middle of the ROM: no way for a command to go (hostile15 F2).
    // The image falls through to the ROM's target instead and says so;
    // HOOK_LOOP, which it does not take, is left alone. (The double runs
    // no code: the ROM's commands carry the image.)
    let mut memory = memory();
    memory[usize::from(platform::map::ROM_START)..].copy_from_slice(romlib::ROM);
    let robot = PtyRobot::spawn(memory);
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(600)).expect("write the image");
    let output = scorpion(
        dir.path(),
        &[
            "upload",
            "ext.elf",
            "--port",
            &robot.path,
            "--no-dry-run",
            "--loader",
            "never",
        ],
    );
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(text.contains("uploaded and verified 600 bytes"), "{text}");
    assert!(!text.contains("rehearsed"), "{text}");
    assert!(
        text.contains(
            "warning: HOOK_UNKNOWN led to $F123, which leads where no extension's code is"
        ),
        "{text}"
    );
    assert!(!text.contains("HOOK_LOOP led"), "{text}");
    let memory = robot.memory.lock().expect("the robot's memory");
    assert_eq!(
        &memory[0x0400..0x0406],
        &[0x4C, 0x21, 0xFF, 0x4C, 0x00, 0x04]
    );
    assert_eq!(&memory[0x0200..0x0203], &[0x4C, 0x03, 0x04]);
    assert_eq!(
        &memory[0x0203..0x0206],
        &[0x4C, 0x45, 0xF0],
        "HOOK_LOOP untouched"
    );
}

#[test]
fn refuses_what_it_cannot_upload_safely() {
    let robot = PtyRobot::spawn(memory());
    let dir = tempfile::tempdir().expect("temporary directory");
    let image = Image {
        entry: 0x0100,
        flags: 0,
        areas: vec![LoadArea {
            load: 0x0100,
            run: 0x0100,
            bytes: vec![0xEA; 16],
        }],
        sections: vec![],
        symbols: vec![],
        hooks: Hooks::default(),
        lines: isa::objfmt::SrcMap::default(),
    };
    std::fs::write(
        dir.path().join("stack.elf"),
        Format::Elf.write(&image).expect("an ELF image"),
    )
    .expect("write the image");
    let output = scorpion(dir.path(), &["upload", "stack.elf", "--port", &robot.path]);
    assert_eq!(output.status.code(), Some(1));
    insta::assert_snapshot!("upload_outside_user_memory", transcript(&output));
    assert_eq!(
        robot.memory.lock().expect("the robot's memory")[0x0100..0x0110],
        memory()[0x0100..0x0110],
        "nothing was written"
    );

    std::fs::write(dir.path().join("junk.elf"), b"not an image").expect("write");
    let output = scorpion(dir.path(), &["upload", "junk.elf", "--port", &robot.path]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        transcript(&output).contains("junk.elf"),
        "{}",
        transcript(&output)
    );
    std::fs::write(dir.path().join("ext.elf"), extension_elf(100)).expect("write the image");
    let output = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", "emu", "--baud", "12345"],
    );
    assert_eq!(output.status.code(), Some(1));
    assert!(
        transcript(&output)
            .contains("baud = \"12345\" (flag --baud) is not a rate the robot's 6551 runs at"),
        "{}",
        transcript(&output)
    );
}

#[test]
fn the_readme_main_job_prints_what_the_readme_says() {
    // demo/main-job.sh, step by step, with this build's binary.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().expect("temporary directory");
    let build = scorpion(
        dir.path(),
        &[
            "build",
            &root
                .join("examples/checksum/checksum.s")
                .display()
                .to_string(),
            "--target",
            &root
                .join("examples/checksum/checksum.toml")
                .display()
                .to_string(),
            "-o",
            "checksum.elf",
        ],
    );
    assert_eq!(build.status.code(), Some(0), "{}", transcript(&build));
    let upload = scorpion(
        dir.path(),
        &[
            "upload",
            "checksum.elf",
            "--port",
            "emu",
            "--expect",
            &root.join("demo/checksum.expect").display().to_string(),
        ],
    );
    assert_eq!(upload.status.code(), Some(0), "{}", transcript(&upload));
    let printed = format!(
        "== build examples/checksum (a /9K command: the sum of a memory range)\n{}{}\n\
         == rehearse, upload, verify, ask (demo/checksum.expect)\n{}",
        String::from_utf8_lossy(&build.stdout),
        String::from_utf8_lossy(&build.stderr),
        String::from_utf8_lossy(&upload.stdout),
    );
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let block = readme
        .split("bash demo/main-job.sh\n```\n\n```text\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("the README shows the main job's output");
    assert_eq!(block, printed, "README.md's main-job output is stale");
    let script = std::fs::read_to_string(root.join("demo/main-job.sh")).expect("demo/main-job.sh");
    for step in [
        "examples/checksum/checksum.s",
        "--port emu --expect",
        "demo/checksum.expect",
    ] {
        assert!(script.contains(step), "demo/main-job.sh lost `{step}`");
    }
    // A first run builds for minutes: the build runs on its own, before
    // the first step, with cargo's progress shown (not `--quiet`), from
    // the versions the tests ran with.
    let build = script
        .find("cargo build --release --locked")
        .expect("demo/main-job.sh builds the binary on its own first");
    let first_step = script.find("scorpion build").expect("the first step");
    assert!(build < first_step, "the build comes before the first step");
    let build_line = script[build..].lines().next().unwrap_or_default();
    assert!(
        !build_line.contains("--quiet"),
        "the build shows its progress"
    );
}

/// Issue 11's second reproduction, through a real pseudo-terminal: a
/// second extension at `$0400` onto a robot that has the first is refused
/// with nothing sent but questions; `scorpion installed` shows what is
/// there; `--replace` takes the first out of the chain and puts the second
/// in, and the robot answers the new command and no longer the old one.
#[test]
fn an_overlapping_upload_is_refused_and_replace_swaps_the_extension() {
    let dir = tempfile::tempdir().expect("temporary directory");
    build_example(dir.path(), "rangefinder/rangefinder.s", "first.elf", &[]);
    build_example(dir.path(), "checksum/checksum.s", "second.elf", &[]);
    let sim = Sim::start();
    let port = sim.path.as_str();
    let first = scorpion(dir.path(), &["upload", "first.elf", "--port", port]);
    assert_eq!(first.status.code(), Some(0), "{}", transcript(&first));
    let second = scorpion(dir.path(), &["upload", "second.elf", "--port", port]);
    let text = transcript(&second);
    assert_eq!(second.status.code(), Some(1), "{text}");
    assert!(
        text.contains("romlib::overlap") && text.contains("--replace"),
        "{text}"
    );
    let listed = scorpion(dir.path(), &["installed", "--port", port]);
    let text = transcript(&listed);
    assert_eq!(listed.status.code(), Some(0), "{text}");
    assert!(
        text.contains("HOOK_UNKNOWN: $0400 (") && text.contains(") -> $FF21"),
        "{text}"
    );
    let first_id = text
        .split("extension ")
        .nth(1)
        .and_then(|rest| rest.split(':').next())
        .expect("the first's id")
        .to_owned();
    let replaced = scorpion(
        dir.path(),
        &["upload", "second.elf", "--port", port, "--replace"],
    );
    let said = transcript(&replaced);
    assert_eq!(replaced.status.code(), Some(0), "{said}");
    // fresh14 F2: the one taken out is named, and the way back.
    assert!(
        said.contains(&format!("took out extension {first_id} ($0400-$"))
            && said.contains("no longer answers")
            && said.contains("`scorpion upload --undo` puts back what the robot held before, the extension taken out"),
        "{said}"
    );
    let asked = scorpion(dir.path(), &["ask", "--port", port, "/9KF0000002", "/1U"]);
    let text = transcript(&asked);
    assert!(text.contains("K"), "the new command answers: {text}");
    assert!(!text.contains("U0"), "the replaced command is gone: {text}");
    let listed = scorpion(dir.path(), &["installed", "--port", port]);
    let text = transcript(&listed);
    assert_eq!(text.matches("extension ").count(), 1, "{text}");
}

/// hostile10 F15: `--fast-baud 1` was taken (and the upload said "at
/// 19200 baud"): a rate the robot's 6551 lacks is refused before anything.
#[test]
fn a_fast_rate_the_robots_acia_lacks_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_elf(100)).expect("write the image");
    for rate in ["1", "300000"] {
        let output = scorpion(
            dir.path(),
            &["upload", "ext.elf", "--port", "emu", "--fast-baud", rate],
        );
        assert_eq!(output.status.code(), Some(2), "{}", transcript(&output));
        assert!(
            transcript(&output).contains(&format!("does not run at {rate} baud")),
            "{}",
            transcript(&output)
        );
    }
    let output = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", "emu", "--fast-baud", "0"],
    );
    assert!(output.status.success(), "{}", transcript(&output));
}
