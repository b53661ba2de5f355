//! Issue 27's second round of a new user's findings, on `scorpion sim
//! --pty` standing for the robot: an undo after the extension has run
//! (its variables changed) and the refusal of one whose code was
//! tampered with; an undo file applied to another robot; `restore
//! --force` onto a robot with another ROM; a second identical upload with
//! another extension installed; an undo file in a missing directory.

use crate::robot::{Sim, changed_rom, extension_at};
use crate::{scorpion, transcript};

/// A handler whose `/1Q` counts its calls in a BSS byte and answers `Q`,
/// the count and `version`; 600 bytes of table between, so that a
/// change of `version` and a byte of the table are 32-byte ranges apart.
fn counter_source(version: u8) -> String {
    format!(
        "        .include \"scorpion.inc\"
        .code
        SCORPION_UNKNOWN_HANDLER
        cmp #'Q'
        bne not_mine
        inc count
        lda #'Q'
        jsr PUTCH
        lda count
        jsr PUTHEX
        lda version
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
table:  .res 600, $EA
version: .byte ${version:02X}
        .bss
count:  .res 1
"
    )
}

/// `scorpion ARGS` on the line `line`: the output, and whether it exited 0.
fn on(dir: &std::path::Path, line: &[&str], args: &[&str]) -> (bool, String) {
    let mut all = args.to_vec();
    all.extend(line);
    let output = scorpion(dir, &all);
    (output.status.success(), transcript(&output))
}

/// Uploads a friend's extension (100 bytes at `at`, `friend.elf` beside
/// `project`) to the robot on `line`, from the project.
fn upload_friend(project: &std::path::Path, line: &[&str], at: u16) {
    let friend = project
        .parent()
        .expect("beside the project")
        .join("friend.elf");
    std::fs::write(friend, extension_at(at, 100, None)).expect("the image");
    ok(project, line, &["upload", "../friend.elf", "--no-dry-run"]);
}

/// `on` that must succeed.
fn ok(dir: &std::path::Path, line: &[&str], args: &[&str]) -> String {
    let (success, text) = on(dir, line, args);
    assert!(success, "{args:?}: {text}");
    text
}

/// A pty robot at 19200 baud with two extensions uploaded in `dir`, one
/// after the other: `first.elf` (200 bytes at $0C00), then `ext.elf`
/// (`len` bytes at $0400), which chains to the first.
fn two_installed(dir: &std::path::Path, len: usize) -> Sim {
    let first = extension_at(0x0C00, 200, None);
    std::fs::write(dir.join("first.elf"), first).expect("the image");
    std::fs::write(dir.join("ext.elf"), extension_at(0x0400, len, None)).expect("the image");
    let sim = Sim::start(dir, &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(dir, &line, &["upload", "first.elf", "--no-dry-run"]);
    ok(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
    sim
}

/// F4': the undo file's witness covered the extension's BSS, so an undo
/// was refused once the new image had run. It covers code alone now: the
/// undo works after `/1Q` changed the count, and the robot answers as
/// with the first image; a byte of the code changed on the robot is still
/// refused.
#[test]
fn undo_works_after_the_extension_ran_and_refuses_tampered_code() {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (name, version) in [("a", 0xA1), ("b", 0xB2)] {
        std::fs::write(
            dir.path().join(format!("{name}.s")),
            counter_source(version),
        )
        .expect("the source");
        let built = scorpion(
            dir.path(),
            &["build", &format!("{name}.s"), "-o", &format!("{name}.elf")],
        );
        assert!(built.status.success(), "{}", transcript(&built));
    }
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let d = dir.path();
    ok(d, &line, &["upload", "a.elf", "--no-dry-run"]);
    ok(d, &line, &["upload", "b.elf", "--no-dry-run", "--replace"]);
    let text = ok(d, &line, &["ask", "/1Q", "/1Q"]);
    assert!(text.contains("Q02B2"), "B answers and counted: {text}");
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    let text = ok(d, &line, &["ask", "/1Q"]);
    assert!(text.contains("A1"), "A answers again: {text}");

    // Again, and a byte of the code both images load (the table, far from
    // `version`) changed on the robot before the undo.
    ok(d, &line, &["upload", "b.elf", "--no-dry-run", "--replace"]);
    ok(d, &line, &["ask", "/1Q"]);
    let installed = ok(d, &line, &["read", "$0440", "2"]);
    assert!(installed.contains("0440: EA EA"), "{installed}");
    ok(d, &line, &["ask", "/9W04401111"]);
    let (success, text) = on(d, &line, &["upload", "--undo"]);
    assert!(!success, "{text}");
    assert!(text.contains("uploader::witness_differs"), "{text}");
}

/// M5: an undo file kept on the pty robot, applied to `--port emu` (a
/// fresh virtual Scorpion): refused, the upload's table entry not there.
#[test]
fn an_undo_file_from_one_robot_is_refused_on_another() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_at(0x0400, 600, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(dir.path(), &line, &["upload", "ext.elf", "--no-dry-run"]);
    let (success, text) = on(dir.path(), &["--port", "emu"], &["upload", "--undo"]);
    assert!(!success, "{text}");
    assert!(text.contains("uploader::witness_differs"), "{text}");
    assert!(text.contains("$0F88-"), "the table entry: {text}");
    // F4 (round 3): said as what it is, an undo file whose upload is not
    // there, the range named as the table's entry.
    assert!(
        text.contains(
            "the robot is not as the upload the undo file scorpion-last-upload.undo undoes left it"
        ),
        "{text}"
    );
    assert!(text.contains("installed-extension table's entry"), "{text}");
    assert!(!text.contains("the backup was written"), "{text}");
    // On its own robot it works.
    let text = ok(dir.path(), &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
}

/// F4 (issue 27, round 3): after a successful undo the undo file is
/// marked used (kept as `.undone`): a second undo says the upload is
/// already undone, and touches nothing.
#[test]
fn a_second_undo_says_already_undone() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_at(0x0400, 300, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let d = dir.path();
    ok(d, &line, &["upload", "ext.elf", "--no-dry-run"]);
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    assert!(!d.join("scorpion-last-upload.undo").exists());
    assert!(d.join("scorpion-last-upload.undo.undone").is_file());
    let (success, text) = on(d, &line, &["upload", "--undo"]);
    assert!(!success, "{text}");
    assert!(text.contains("already undone"), "{text}");
    assert!(!text.contains("witness_differs"), "{text}");
}

/// F6': `restore --force` onto a robot whose ROM differs from the profile
/// (and from the backup's) goes through, saying what it overrides.
#[test]
fn restore_force_onto_another_rom_goes_through_and_says_what_it_overrides() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (rom, reference, changed) = changed_rom();
    std::fs::write(dir.path().join("changed.elf"), rom).expect("write the ROM");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(dir.path(), &line, &["backup", "-o", "reference.bak"]);
    drop(sim);
    let sim = Sim::start(dir.path(), &["--rom", "changed.elf", "--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let (success, text) = on(dir.path(), &line, &["restore", "reference.bak"]);
    assert!(!success, "{text}");
    // F5 (round 3): the refusal the README documents, its help naming
    // `restore --force`; not the upload's, about linking an image.
    assert!(text.contains("uploader::backup_rom_differs"), "{text}");
    assert!(!text.contains("uploader::wrong_rom"), "{text}");
    assert!(text.contains("restore FILE --force"), "{text}");
    let text = ok(dir.path(), &line, &["restore", "reference.bak", "--force"]);
    assert!(text.contains("restored reference.bak"), "{text}");
    let wrong = format!("$FF2E: expected ${reference:02X}, found ${changed:02X}");
    assert!(
        text.contains("warning: --force overrides: the robot's ROM is not"),
        "{text}"
    );
    assert!(text.matches(&wrong).count() >= 2, "both checks: {text}");
}

/// F5': with another extension installed, a second identical upload is
/// compared by checksums under `--loader auto` and writes nothing.
#[test]
fn a_second_identical_upload_beside_another_extension_writes_nothing() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let sim = two_installed(dir.path(), 700);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let d = dir.path();
    let text = ok(d, &line, &["upload", "ext.elf", "--no-dry-run"]);
    assert!(
        text.contains("(none of them written: the robot held them all)"),
        "{text}"
    );
    assert!(!text.contains("uploaded and verified"), "{text}");
    assert!(text.contains("through the RAM loader"), "{text}");
    // Both still installed, chained.
    let text = ok(d, &line, &["installed"]);
    assert!(
        text.contains("-> $0C03") || text.contains("$0C03"),
        "{text}"
    );
    assert!(text.contains("$0403"), "{text}");
}

/// F7': `--undo-file` in a directory that does not exist is refused,
/// naming it, before the robot is touched; nothing is made.
#[test]
fn an_undo_file_in_a_missing_directory_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_at(0x0400, 300, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let (success, text) = on(
        dir.path(),
        &line,
        &[
            "upload",
            "ext.elf",
            "--no-dry-run",
            "--undo-file",
            "nowhere/x.undo",
        ],
    );
    assert!(!success, "{text}");
    assert!(
        text.contains("the directory nowhere does not exist"),
        "{text}"
    );
    assert!(!dir.path().join("nowhere").exists());
    let text = ok(dir.path(), &line, &["read", "$0200", "3"]);
    assert!(text.contains("0200: 4C 21 FF"), "untouched: {text}");
}

/// F7 (issue 27, round 3): the README's loader paragraph names the size
/// `upload` prints on a serial port (where it keeps an undo file, so the
/// checksum part goes in), not only the demo's on `--port emu`.
#[test]
fn the_readme_names_the_loader_size_a_serial_upload_prints() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_at(0x0400, 700, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let text = ok(dir.path(), &line, &["upload", "ext.elf", "--no-dry-run"]);
    let loader = text
        .split("through the RAM loader (")
        .nth(1)
        .and_then(|rest| rest.split(')').next())
        .unwrap_or_else(|| panic!("no loader in: {text}"));
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    assert!(
        readme.contains(&format!("`through the RAM loader ({loader})`")),
        "README.md does not say `through the RAM loader ({loader})`"
    );
}

/// F6 (issue 27, round 6): an undo file crafted with a valid checksum
/// whose hook points into RAM it neither restores nor witnesses ($0900,
/// beside the extension) is refused by `upload --undo` and by `restore`,
/// naming the hook, its target and why, before anything is written; the
/// upload's own undo file still undoes it.
#[test]
fn an_undo_file_whose_hook_goes_to_memory_it_neither_holds_nor_witnesses_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), extension_at(0x0400, 300, None)).expect("the image");
    let sim = Sim::start(dir.path(), &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let d = dir.path();
    ok(d, &line, &["upload", "ext.elf", "--no-dry-run"]);
    let kept = std::fs::read(d.join("scorpion-last-upload.undo")).expect("the undo file");
    let mut crafted = uploader::Backup::decode("kept", &kept).expect("it reads");
    assert!(
        crafted.hooks.iter().all(|&(_, target)| target >= 0xF000),
        "the upload found the hooks at the ROM: {:?}",
        crafted.hooks
    );
    for hook in &mut crafted.hooks {
        if hook.0 == isa::objfmt::HookKind::Unknown {
            hook.1 = 0x0900;
        }
    }
    assert!(
        crafted.byte_at(0x0900).is_none()
            && crafted
                .witnesses
                .iter()
                .all(|w| !(w.address..w.address.saturating_add(w.len)).contains(&0x0900)),
        "the crafted file neither holds nor witnesses $0900"
    );
    std::fs::write(d.join("crafted.undo"), crafted.encode()).expect("the crafted file");
    let before = ok(d, &line, &["read", "$0200", "6"]);
    assert!(before.contains("0200: 4C 03 04"), "{before}");
    for args in [
        vec!["upload", "--undo", "--undo-file", "crafted.undo"],
        vec!["restore", "crafted.undo"],
    ] {
        let (success, text) = on(d, &line, &args);
        assert!(!success, "{args:?}: {text}");
        assert!(text.contains("uploader::unwitnessed_hook"), "{text}");
        assert!(text.contains("HOOK_UNKNOWN at $0900"), "{text}");
        assert!(text.contains("not in the ROM's code"), "{text}");
        assert!(text.contains("not restored by this file"), "{text}");
        assert!(text.contains("not witnessed"), "{text}");
        assert_eq!(ok(d, &line, &["read", "$0200", "6"]), before, "{args:?}");
    }
    assert!(d.join("crafted.undo").is_file(), "not marked used");
    // A hook into the middle of the ROM: refused as a file made by hand,
    // not with the help of an image ("link extensions with --target").
    for hook in &mut crafted.hooks {
        if hook.0 == isa::objfmt::HookKind::Unknown {
            hook.1 = 0xFF00;
        }
    }
    std::fs::write(d.join("rom.undo"), crafted.encode()).expect("the crafted file");
    for args in [
        vec!["upload", "--undo", "--undo-file", "rom.undo"],
        vec!["restore", "rom.undo"],
    ] {
        let (success, text) = on(d, &line, &args);
        assert!(!success, "{args:?}: {text}");
        assert!(text.contains("uploader::backup_refused"), "{text}");
        assert!(text.contains("inside the ROM"), "{text}");
        assert!(!text.contains("--target"), "{text}");
        assert_eq!(ok(d, &line, &["read", "$0200", "6"]), before, "{args:?}");
    }
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    let text = ok(d, &line, &["read", "$0200", "3"]);
    assert!(text.contains("0200: 4C 21 FF"), "undone: {text}");
}

/// F6's other side: with two extensions chained, the undo of the second
/// goes back to the first's handler, which the undo file witnesses
/// (not holds): it is taken, and the hook goes back there.
#[test]
fn the_undo_of_a_chained_extension_goes_back_to_the_first() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let sim = two_installed(dir.path(), 300);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let d = dir.path();
    let kept = std::fs::read(d.join("scorpion-last-upload.undo")).expect("the undo file");
    let kept = uploader::Backup::decode("kept", &kept).expect("it reads");
    assert!(
        kept.hooks
            .contains(&(isa::objfmt::HookKind::Unknown, 0x0C03)),
        "{:?}",
        kept.hooks
    );
    assert!(
        kept.byte_at(0x0C03).is_none(),
        "witnessed, not held: {kept:?}"
    );
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    let text = ok(d, &line, &["read", "$0200", "3"]);
    assert!(text.contains("0200: 4C 03 0C"), "back to the first: {text}");
}

/// fresh10 F6: an upload interrupted (Ctrl-C) said nothing of what it
/// left, and the next upload replaced its undo file, the only record of
/// what the robot held before it. Now the interruption says so, the next
/// upload is refused until `upload --undo` (which puts the robot back),
/// and after that uploads go on.
#[test]
fn an_interrupted_upload_says_so_and_its_undo_file_is_not_replaced() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let dir = dir.path();
    std::fs::write(dir.join("ext.elf"), extension_at(0x0400, 2048, None)).expect("the image");
    let sim = Sim::start(dir, &[]);
    let line = ["--port", sim.path.as_str()];
    ok(dir, &line, &["read", "$0400", "2048", "-o", "before.bin"]);
    let undo = dir.join("scorpion-last-upload.undo");
    let output = interrupted(
        dir,
        &["upload", "ext.elf", "--no-dry-run", "--port", &sim.path],
        &|| {
            let waited = std::time::Instant::now();
            while !undo.exists() && waited.elapsed() < std::time::Duration::from_secs(30) {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            assert!(undo.exists(), "no undo file within 30 s");
            std::thread::sleep(std::time::Duration::from_millis(300));
        },
    );
    let said = transcript(&output);
    assert_eq!(output.status.code(), Some(130), "{said}");
    assert!(
        said.contains("interrupted: the upload did not finish")
            && said.contains("scorpion upload --undo"),
        "{said}"
    );
    let (success, said) = on(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
    assert!(!success, "{said}");
    assert!(said.contains("the last upload did not finish"), "{said}");
    ok(dir, &line, &["upload", "--undo"]);
    ok(dir, &line, &["read", "$0400", "2048", "-o", "after.bin"]);
    assert!(
        std::fs::read(dir.join("after.bin")).expect("a dump")
            == std::fs::read(dir.join("before.bin")).expect("a dump"),
        "the undo put the robot's RAM back"
    );
    ok(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
}

/// fresh10 F10: an upload while an undo was half done replaced that
/// undo's file, and the next `--undo` took the new file for the one half
/// done. The upload is refused until the undo is finished.
#[test]
fn an_upload_while_an_undo_is_half_done_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let dir = dir.path();
    std::fs::write(dir.join("ext.elf"), extension_at(0x0400, 200, None)).expect("the image");
    let sim = Sim::start(dir, &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
    // What an undo killed after its checks leaves beside its file.
    std::fs::write(dir.join("scorpion-last-upload.undo.undoing"), b"").expect("the mark");
    let (success, said) = on(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
    assert!(!success, "{said}");
    assert!(
        said.contains("started and did not finish") && said.contains("scorpion upload --undo"),
        "{said}"
    );
    let said = ok(dir, &line, &["upload", "--undo"]);
    assert!(said.contains("restored"), "{said}");
    ok(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
}

/// hostile10 F9: the undo file of a `--replace` by an image whose memory
/// takes zero page (its table entry longer than the one it replaced) held
/// the entry twice, and `upload --undo` refused the file whole.
#[test]
fn the_undo_of_a_replace_by_an_image_with_zero_page_works() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let dir = dir.path();
    let handler = |zero_page: bool| {
        format!(
            "        .include \"scorpion.inc\"
{}        .code
        SCORPION_UNKNOWN_HANDLER
        cmp #'V'
        bne not_mine
        lda #'V'
        jsr PUTCH
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
",
            if zero_page {
                "        .zeropage\nzp:     .res 2\n"
            } else {
                ""
            }
        )
    };
    for (name, zero_page) in [("plain", false), ("zp", true)] {
        std::fs::write(dir.join(format!("{name}.s")), handler(zero_page)).expect("a source");
        let output = scorpion(
            dir,
            &["build", &format!("{name}.s"), "-o", &format!("{name}.elf")],
        );
        assert!(output.status.success(), "{}", transcript(&output));
    }
    let sim = Sim::start(dir, &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(dir, &line, &["upload", "plain.elf", "--no-dry-run"]);
    let before = ok(dir, &line, &["installed"]);
    ok(
        dir,
        &line,
        &["upload", "zp.elf", "--no-dry-run", "--replace"],
    );
    ok(dir, &line, &["upload", "--undo"]);
    assert_eq!(ok(dir, &line, &["installed"]), before);
}

/// fresh10 F19: a restore interrupted (Ctrl-C) said nothing. It says what
/// it left and how to finish; the restore run again does.
#[test]
fn an_interrupted_restore_says_so_and_runs_again() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let dir = dir.path();
    std::fs::write(dir.join("ext.elf"), extension_at(0x0400, 2048, None)).expect("the image");
    let sim = Sim::start(dir, &[]);
    let line = ["--port", sim.path.as_str()];
    ok(dir, &line, &["backup", "-o", "robot.bak"]);
    ok(dir, &line, &["upload", "ext.elf", "--no-dry-run"]);
    let output = interrupted(dir, &["restore", "robot.bak", "--port", &sim.path], &|| {
        std::thread::sleep(std::time::Duration::from_secs(2))
    });
    let said = transcript(&output);
    assert_eq!(output.status.code(), Some(130), "{said}");
    assert!(
        said.contains("interrupted: the restore did not finish")
            && said.contains("scorpion restore robot.bak"),
        "{said}"
    );
    ok(dir, &line, &["restore", "robot.bak"]);
    ok(dir, &line, &["backup", "-o", "after.bak"]);
    assert!(
        std::fs::read(dir.join("after.bak")).expect("a backup")
            == std::fs::read(dir.join("robot.bak")).expect("a backup"),
        "the robot as backed up"
    );
}

/// `scorpion ARGS` in `dir`, sent a Ctrl-C (SIGINT) once `when` returns;
/// what it printed and its status.
fn interrupted(dir: &std::path::Path, args: &[&str], when: &dyn Fn()) -> std::process::Output {
    use std::process::{Command, Stdio};
    let child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("scorpion runs");
    when();
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(killed.success());
    child.wait_with_output().expect("it ends")
}

/// fresh10 F20: the undo of an older upload (its own undo file) also
/// unhooked a later upload chained ahead of it, exit 0; and the undo of
/// the later one then hooked code the first undo had taken away, and the
/// robot hung at its next command (hostile11 F2). The older undo is
/// refused now, naming the later extension, and nothing is written; in
/// the order they were made, both undo.
#[test]
fn the_undo_of_an_upload_a_later_one_chained_ahead_of_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    std::fs::write(d.join("first.elf"), extension_at(0x0C00, 200, None)).expect("the image");
    std::fs::write(d.join("ext.elf"), extension_at(0x0400, 300, None)).expect("the image");
    let sim = Sim::start(d, &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(
        d,
        &line,
        &[
            "upload",
            "first.elf",
            "--no-dry-run",
            "--undo-file",
            "u1.undo",
        ],
    );
    ok(
        d,
        &line,
        &[
            "upload",
            "ext.elf",
            "--no-dry-run",
            "--undo-file",
            "u2.undo",
        ],
    );
    let hooks = ok(d, &line, &["read", "$0200", "3"]);
    let (refused, said) = on(d, &line, &["upload", "--undo", "--undo-file", "u1.undo"]);
    assert!(!refused, "{said}");
    assert!(
        said.contains("uploader::undo_not_last")
            && said.contains("HOOK_UNKNOWN leads first to $0403 (extension ")
            && said.contains("nothing was written"),
        "{said}"
    );
    assert_eq!(ok(d, &line, &["read", "$0200", "3"]), hooks, "unchanged");
    assert!(d.join("u1.undo").exists(), "the file is kept for later");
    ok(d, &line, &["upload", "--undo", "--undo-file", "u2.undo"]);
    let text = ok(d, &line, &["read", "$0200", "3"]);
    assert!(text.contains("0200: 4C 03 0C"), "back to the first: {text}");
    ok(d, &line, &["upload", "--undo", "--undo-file", "u1.undo"]);
    let text = ok(d, &line, &["read", "$0200", "3"]);
    assert!(text.contains("0200: 4C 21 FF"), "back to the ROM: {text}");
}

/// fresh11 F6: an OS whose `HOOK_LOOP` handler never goes on to the
/// ROM's loop silenced the robot once hooked; the upload blamed the cable
/// (on the rehearsal too, where there is none), and did not say that its
/// undo file was left marked. Both name the handler now, and the upload
/// on the robot says where what it overwrote is kept.
#[test]
fn a_loop_handler_that_never_goes_on_is_named_and_the_undo_file_told() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    std::fs::write(
        d.join("hog.s"),
        ".include \"scorpion.inc\"\n.data\npasses: .byte 0\n.code\nSCORPION_LOOP_HANDLER\ntick:\n        inc passes\n        jmp tick\n",
    )
    .expect("the source");
    let built = scorpion(
        d,
        &["build", "hog.s", "-o", "hog.elf", "--target", "scorpion-os"],
    );
    assert!(built.status.success(), "{}", transcript(&built));
    let sim = Sim::start(d, &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let (done, said) = on(d, &line, &["upload", "hog.elf"]);
    assert!(!done, "{said}");
    assert!(
        said.contains("rehearsal") && said.contains("uploader::loop_handler_silent"),
        "{said}"
    );
    let (done, said) = on(d, &line, &["upload", "hog.elf", "--no-dry-run"]);
    assert!(!done, "{said}");
    assert!(
        said.contains("uploader::loop_handler_silent")
            && said.contains("scorpion-last-upload.undo (marked .uploading)")
            && said.contains("`scorpion upload --undo` puts it back"),
        "{said}"
    );
}

/// fresh11 F8: `scorpion test --port` on a project with room lines
/// (examples/linefollow) said the robot had no room because the project
/// had no world file, which it has. On a port the room cannot be seen,
/// and the message says that, and that the rehearsal checked them.
#[test]
fn room_lines_on_a_port_are_refused_for_what_they_are() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = dir.path().join("linefollow");
    crate::copy_dir(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/linefollow"),
        &project,
    );
    let sim = Sim::start(dir.path(), &[]);
    let (passed, said) = on(&project, &["--port", sim.path.as_str()], &["test"]);
    assert!(!passed, "{said}");
    assert!(
        said.contains("seen through its line alone")
            && said.contains("no line of this transcript was sent"),
        "{said}"
    );
    assert!(!said.contains("world = "), "{said}");
}

/// fresh10 F22: `scorpion test --port` uploaded to the robot and kept no
/// undo file (README: every upload keeps what it overwrote). It keeps the
/// project's, and `upload --undo` puts the robot back.
#[test]
fn test_on_a_port_keeps_the_projects_undo_file() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, _) = crate::new_project(dir.path());
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    let before = ok(&project, &line, &["read", "$0200", "3"]);
    let tested = ok(&project, &line, &["test", "--timing"]);
    assert!(tested.contains("upload myext ... ok"), "{tested}");
    // The rehearsal's figures are said to be its, beside the robot's.
    assert!(tested.contains("transcripts rehearsed: "), "{tested}");
    assert!(tested.contains("; on the robot: "), "{tested}");
    // fresh13 F1: what stays on the robot is said, and how to take it out.
    assert!(
        tested.contains("left installed on the robot: myext; `scorpion upload --undo`"),
        "{tested}"
    );
    let undo = project.join("target/scorpion/last-upload.undo");
    assert!(undo.is_file(), "{tested}");
    assert!(
        !project
            .join("target/scorpion/last-upload.undo.uploading")
            .exists(),
        "finished"
    );
    assert_ne!(ok(&project, &line, &["read", "$0200", "3"]), before);
    // fresh13 F1: tested again, unchanged: the undo file still goes back
    // to the robot as it was before the first run, and says so.
    let again = ok(&project, &line, &["test"]);
    assert!(
        again.contains("puts back what it held before the last upload that changed it (this run changed nothing on it"),
        "{again}"
    );
    let uploaded = ok(&project, &line, &["upload"]);
    assert!(
        uploaded.contains("the robot held this image already, installed as it is now"),
        "{uploaded}"
    );
    let undone = ok(&project, &line, &["upload", "--undo"]);
    assert!(undone.contains("restored"), "{undone}");
    assert_eq!(ok(&project, &line, &["read", "$0200", "3"]), before);
}

/// fresh13 F3: examples/adc tested on a robot without its card: the
/// transcript fails there (`A--`), and the failure says the rehearsal had
/// the project's card, which the robot may lack.
#[test]
fn a_transcript_failing_on_a_port_names_the_cards_the_rehearsal_had() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = dir.path().join("adc");
    crate::copy_dir(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc"),
        &project,
    );
    // Started outside the project: a robot without the card.
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(&project, &["test", "--port", &sim.path]);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("answered `A--`, expected `AC0`"), "{text}");
    assert!(
        text.contains("(the rehearsal passed with the project's cards on the KIM bus: adc.rhai;"),
        "{text}"
    );
}

/// hostile14 F1: data written by hand where the first upload's RAM loader
/// had run; the same upload again (its loader written over the data) kept
/// the first upload's undo file, whose bytes there were from before it:
/// the undo wrote them over the data, which was gone for good. Where the
/// loader went over bytes the older file holds, the upload keeps its own.
#[test]
fn a_no_change_upload_whose_loader_went_over_data_keeps_an_undo_that_puts_it_back() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    std::fs::write(
        d.join("ext.elf"),
        crate::robot::extension_at(0x0400, 600, None),
    )
    .expect("the image");
    let sim = Sim::start(d, &[]);
    let line = ["--port", sim.path.as_str()];
    ok(
        d,
        &line,
        &["upload", "ext.elf", "--no-dry-run", "--loader", "always"],
    );
    let installed = ok(d, &line, &["installed"]);
    let loader = installed
        .split("RAM loader ($")
        .nth(1)
        .and_then(|rest| rest.get(..4))
        .map(str::to_owned);
    // Where the loader ran: the top of user RAM ($0E7F on the reference
    // ROM), whatever `installed` says of it.
    let at = loader.unwrap_or_else(|| "0E7F".to_owned());
    ok(
        d,
        &line,
        &["ask", &format!("/9W{at}A1A2"), "--allow-silence"],
    );
    let data = ok(d, &line, &["read", &format!("${at}"), "2"]);
    assert!(data.contains("A1 A2"), "{data}");
    let again = ok(
        d,
        &line,
        &["upload", "ext.elf", "--no-dry-run", "--loader", "always"],
    );
    assert!(
        !again.contains("the robot held this image already"),
        "{again}"
    );
    let undone = ok(d, &line, &["upload", "--undo"]);
    assert!(undone.contains("restored"), "{undone}");
    assert_eq!(
        ok(d, &line, &["read", &format!("${at}"), "2"]),
        data,
        "the data put back"
    );
}

/// fresh14 F5: `test --port` on a robot that answers nothing ended with
/// "`scorpion test --port --replace` replaces what the robot has there":
/// nothing was in the way. The hint comes only where something is.
#[test]
fn test_on_a_port_that_answers_nothing_gives_no_replace_hint() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, _) = crate::new_project(dir.path());
    let sim = Sim::start(dir.path(), &[]);
    // The port is there; the robot behind it stands still.
    let pid = nix::unistd::Pid::from_raw(i32::try_from(sim.child.id()).expect("a pid"));
    nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGSTOP).expect("stopped");
    let output = scorpion(&project, &["test", "--port", &sim.path]);
    let _ = nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGCONT);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("upload myext ... FAILED"), "{text}");
    assert!(!text.contains("--replace"), "{text}");
}

/// hostile15 F4: `test --port` killed during its upload ended without a
/// word of what it left (`scorpion upload` says it). It says the same now,
/// and the undo puts the robot back.
#[test]
fn a_test_on_a_port_interrupted_during_its_upload_says_so() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, _) = crate::new_project(dir.path());
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    let before = ok(&project, &line, &["read", "$0200", "3"]);
    let marked = project.join("target/scorpion/last-upload.undo.uploading");
    let output = interrupted(&project, &["test", "--port", &sim.path], &|| {
        let waited = std::time::Instant::now();
        while !marked.exists() && waited.elapsed() < std::time::Duration::from_secs(60) {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(marked.exists(), "no upload under way within 60 s");
    });
    let said = transcript(&output);
    assert_eq!(output.status.code(), Some(130), "{said}");
    assert!(
        said.contains("interrupted: an upload to the robot did not finish")
            && said.contains("`scorpion upload --undo` puts back what the robot held before it"),
        "{said}"
    );
    ok(&project, &line, &["upload", "--undo"]);
    assert_eq!(ok(&project, &line, &["read", "$0200", "3"]), before);
}

/// hostile14 F6b: a project of two images, tested on a port twice: each
/// run's upload of the first image took it from behind the second to the
/// head of the chain, and the second's put it behind again, so no second
/// run was ever "unchanged", and `upload --undo` went back one run only
/// (both images stayed installed). Now the first goes back where it was,
/// the second run changes nothing, and the undo empties the robot.
#[test]
fn a_two_image_project_tested_twice_is_undone_to_the_robot_before() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = two_image_project(dir.path(), 'U');
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    let before = ok(&project, &line, &["read", "$0200", "3"]);
    let first = ok(&project, &line, &["test"]);
    assert!(
        first.contains("left installed on the robot: myext, second"),
        "{first}"
    );
    let again = ok(&project, &line, &["test"]);
    assert!(
        again.contains("puts back what it held before the last upload that changed it (this run changed nothing on it"),
        "{again}"
    );
    let listed = ok(&project, &line, &["installed"]);
    // fresh19 F12: in the project that built them, named.
    assert!(
        listed.contains(" (myext): $") && listed.contains(" (second): $"),
        "{listed}"
    );
    assert!(listed.contains(" second) -> $"), "the chain too: {listed}");
    second_answers(&project, 'Q');
    let edited = ok(&project, &line, &["installed"]);
    assert!(
        edited
            .contains(" (where the project's second goes, but not it as its sources build now): $"),
        "{edited}"
    );
    second_answers(&project, 'U');
    let undone = ok(&project, &line, &["upload", "--undo"]);
    assert!(undone.contains("restored"), "{undone}");
    assert_eq!(
        ok(&project, &line, &["read", "$0200", "3"]),
        before,
        "{listed}"
    );
    let listed = ok(&project, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
}

/// recheck17 F2: A, then B in front of it, then A again unchanged (its
/// undo file goes further back, to before A). After the undo of B and then
/// of A, the robot listed nothing, but B's chain slot and its table entry
/// were back in freed memory: the unchanged upload had added to A's older
/// file what it found there, B's bytes. Now both undos leave the robot as
/// it was before A, byte for byte.
#[test]
fn undos_out_of_order_after_an_unchanged_upload_leave_the_robot_as_before() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    let sim = a_and_b(d);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    ok(d, &line, &["backup", "-o", "before.bak"]);
    let a = ["a.elf", "--no-dry-run", "--undo-file", "a.undo"];
    ok(d, &line, &[&["upload"][..], &a].concat());
    ok(
        d,
        &line,
        &["upload", "b.elf", "--no-dry-run", "--undo-file", "b.undo"],
    );
    let again = ok(d, &line, &[&["upload"][..], &a].concat());
    assert!(again.contains("held this image already"), "{again}");
    ok(d, &line, &["upload", "--undo", "--undo-file", "b.undo"]);
    ok(d, &line, &["upload", "--undo", "--undo-file", "a.undo"]);
    ok(d, &line, &["backup", "-o", "after.bak"]);
    let read = |name: &str| {
        let bytes = std::fs::read(d.join(name)).expect("the backup");
        uploader::Backup::decode(name, &bytes).expect("it reads")
    };
    let (before, after) = (read("before.bak"), read("after.bak"));
    assert_eq!(before.hooks, after.hooks);
    for area in &before.areas {
        for (offset, &byte) in area.bytes.iter().enumerate() {
            let address = u32::from(area.address) + offset as u32;
            assert_eq!(
                after.byte_at(address),
                Some(byte),
                "${address:04X} is not as it was before A"
            );
        }
    }
}

/// fresh19 F1: an upload replaced the undo file of the upload before it
/// (a `test --port` run's, not yet used), and only the last upload could
/// be undone. Each upload keeps the one before one back: `--undo` goes
/// back one upload at a time, to the robot as it was before both.
#[test]
fn each_undo_goes_back_one_upload() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    std::fs::write(d.join("first.elf"), extension_at(0x0C00, 200, None)).expect("the image");
    let sim = Sim::start(d, &["--baud", "19200"]);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let before = ok(d, &line, &["read", "$0200", "3"]);
    drop(sim);
    let sim = two_installed(d, 300);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    assert!(ok(d, &line, &["read", "$0200", "3"]).contains("4C 03 04"));
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(
        text.contains("now holds the undo of the upload before that one"),
        "{text}"
    );
    assert!(ok(d, &line, &["read", "$0200", "3"]).contains("4C 03 0C"));
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    assert_eq!(ok(d, &line, &["read", "$0200", "3"]), before);
    let listed = ok(d, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
    let (success, text) = on(d, &line, &["upload", "--undo"]);
    assert!(!success && text.contains("already undone"), "{text}");
}

/// `scorpion new myext` in `dir` with a second image at $0C00 whose
/// handler answers `/1U` with `answer`.
fn two_image_project(dir: &std::path::Path, answer: char) -> std::path::PathBuf {
    let (project, _) = crate::new_project(dir);
    let layout =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/checksum/checksum.toml");
    std::fs::copy(layout, project.join("src/second.toml")).expect("the layout");
    second_answers(&project, answer);
    let manifest = std::fs::read_to_string(project.join("Scorpion.toml")).expect("the manifest");
    let manifest = manifest.replace(
        "[robot]",
        "[[image]]\nname = \"second\"\nsources = [\"src/second.s\"]\ntarget = \"src/second.toml\"\n\n[robot]",
    );
    std::fs::write(project.join("Scorpion.toml"), manifest).expect("the manifest");
    project
}

/// Writes the second image's source, answering `/1U` with `answer`.
fn second_answers(project: &std::path::Path, answer: char) {
    std::fs::write(
        project.join("src/second.s"),
        format!("        .include \"scorpion.inc\"\n        .code\n        SCORPION_UNKNOWN_HANDLER\n        cmp #'U'\n        bne other\n        lda #'{answer}'\n        jsr PUTCH\n        jsr PUTEOL\n        jmp CMD_DONE\nother:  SCORPION_CHAIN_UNKNOWN\n"),
    )
    .expect("the second source");
}

/// fresh19 F10: a project tested on a port, another extension uploaded in
/// front, then the second image edited and tested again with `--replace`:
/// the undo was refused at once (`witness_differs`), the other upload's
/// file witnessing the second image's handler as it was. The witness is
/// checked against what the robot holds once the file is written.
#[test]
fn the_undo_of_a_run_that_replaced_an_image_another_upload_witnessed_goes_through() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = two_image_project(dir.path(), 'U');
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    let before = ok(&project, &line, &["read", "$0200", "3"]);
    ok(&project, &line, &["test"]);
    upload_friend(&project, &line, 0x0800);
    second_answers(&project, 'V');
    let run = ok(&project, &line, &["test", "--replace"]);
    assert!(ok(&project, &line, &["ask", "/1U"]).contains('V'), "{run}");
    // recheck20 F1: one upload back at a time: the run, then the other
    // extension, then the first run.
    let undone = ok(&project, &line, &["upload", "--undo"]);
    assert!(undone.contains("restored"), "{undone}");
    assert!(ok(&project, &line, &["ask", "/1U"]).contains('U'));
    let listed = ok(&project, &line, &["installed"]);
    assert!(
        listed.contains("$0800-"),
        "the other extension stays: {listed}"
    );
    let undone = ok(&project, &line, &["upload", "--undo"]);
    assert!(undone.contains("restored"), "{undone}");
    let listed = ok(&project, &line, &["installed"]);
    assert!(!listed.contains("$0800-"), "{listed}");
    let undone = ok(&project, &line, &["upload", "--undo"]);
    assert!(undone.contains("restored"), "{undone}");
    assert_eq!(ok(&project, &line, &["read", "$0200", "3"]), before);
    let listed = ok(&project, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
}

/// hostile19 F7: `scorpion restore` of an upload's undo file (its help
/// allows one) skipped the undo's checks: with a later upload in front,
/// it went through and the table listed what was no longer there. An
/// undo file is checked as an undo whichever command is given it.
#[test]
fn restore_of_an_undo_file_is_checked_as_an_undo() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    let sim = a_and_b(d);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let a = ["upload", "a.elf", "--no-dry-run", "--undo-file", "a.undo"];
    ok(d, &line, &a);
    ok(d, &line, &["upload", "b.elf", "--no-dry-run"]);
    let before = ok(d, &line, &["installed"]);
    let (success, text) = on(d, &line, &["restore", "a.undo"]);
    assert!(!success, "{text}");
    assert!(text.contains("undo_not_last"), "{text}");
    assert_eq!(ok(d, &line, &["installed"]), before, "nothing written");
}

/// recheck20 F3: `scorpion restore` of the last upload's undo file undid
/// it but left the file in place, and every later `upload --undo` was
/// refused (that upload no longer on the robot). It is an undo done: the
/// file of the upload before takes its place.
#[test]
fn restore_of_the_undo_file_steps_the_undo_back_too() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    let sim = two_installed(d, 300);
    let line = ["--port", sim.path.as_str(), "--baud", "19200"];
    let text = ok(d, &line, &["restore", "scorpion-last-upload.undo"]);
    assert!(
        text.contains("now holds the undo of the upload before that one"),
        "{text}"
    );
    assert!(ok(d, &line, &["read", "$0200", "3"]).contains("4C 03 0C"));
    let text = ok(d, &line, &["upload", "--undo"]);
    assert!(text.contains("restored"), "{text}");
    let listed = ok(d, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
}

/// A pty robot at 19200 baud, with `a.elf` (200 bytes at $0C00) and
/// `b.elf` (300 bytes at $0400) written in `dir`, not uploaded.
fn a_and_b(dir: &std::path::Path) -> Sim {
    std::fs::write(dir.join("a.elf"), extension_at(0x0C00, 200, None)).expect("the image");
    std::fs::write(dir.join("b.elf"), extension_at(0x0400, 300, None)).expect("the image");
    Sim::start(dir, &["--baud", "19200"])
}

/// fresh19 F9: `scorpion upload --expect` in a project of two images
/// rehearsed each image alone, so a transcript that used both failed on
/// the second's command (with `/1W` "no answer"). Each image is rehearsed
/// with those before it, and the transcript checked once both are in: on
/// `emu` and on a port alike.
#[test]
fn upload_expect_in_a_two_image_project_rehearses_them_together() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = two_image_project(dir.path(), 'U');
    std::fs::write(
        project.join("tests/both.expect"),
        "/1V => V01\n/1U => U\n/1X => X00\n",
    )
    .expect("the transcript");
    let sim = Sim::start(dir.path(), &[]);
    // hostile21 F4: a transcript that fails (here on the last image's
    // command) sends nothing, the first image included.
    std::fs::write(project.join("tests/bad.expect"), "/1V => V01\n/1U => UX\n")
        .expect("the transcript");
    let line = ["--port", sim.path.as_str()];
    let before = ok(&project, &line, &["read", "$0200", "3"]);
    let (success, text) = on(&project, &line, &["upload", "--expect", "tests/bad.expect"]);
    assert!(!success, "{text}");
    assert!(text.contains("nothing was sent to the robot"), "{text}");
    assert!(!text.contains("uploaded and verified"), "{text}");
    assert_eq!(ok(&project, &line, &["read", "$0200", "3"]), before);
    let listed = ok(&project, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
    // fresh21 F5: one image named is rehearsed alone, and the help says so.
    let (success, text) = on(
        &project,
        &line,
        &[
            "upload",
            "target/scorpion/myext.elf",
            "--expect",
            "tests/both.expect",
        ],
    );
    assert!(!success, "{text}");
    assert!(
        text.contains("the rehearsal had this image alone"),
        "{text}"
    );
    for port in ["emu", sim.path.as_str()] {
        let text = ok(
            &project,
            &["--port", port],
            &["upload", "--expect", "tests/both.expect"],
        );
        assert!(
            text.contains("tests/both.expect is checked once the project's last image is in"),
            "{port}: {text}"
        );
        assert!(
            text.contains("with target/scorpion/myext.elf before it, as on the robot")
                && text.contains("3 expectations met"),
            "{port}: {text}"
        );
        assert!(
            !text.contains("the rehearsal did not have")
                // The first image, in the table the second read: not lost.
                && !text.contains("no longer installed"),
            "{port}: {text}"
        );
    }
    // The transcript fails where the project's images answer otherwise.
    second_answers(&project, 'Q');
    let (success, text) = on(
        &project,
        &["--port", sim.path.as_str()],
        &["upload", "--expect", "tests/both.expect", "--replace"],
    );
    assert!(!success, "{text}");
    assert!(text.contains("nothing was sent to the robot"), "{text}");
}

/// fresh21 F4: a project's upload whose second image is refused (it
/// overlaps an older build of itself, no `--replace`) after the first
/// changed nothing said "the upload did not finish ... `scorpion upload
/// --undo` puts it back", and that undo took out an upload from before
/// the run. Nothing of the refused image was kept or written: the refusal
/// says only what is in the way, by `upload` and by `test --port` alike.
#[test]
fn a_later_image_refused_before_it_kept_anything_gives_no_undo_advice() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = two_image_project(dir.path(), 'U');
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    ok(&project, &line, &["test"]);
    second_answers(&project, 'Q');
    let before = ok(&project, &line, &["installed"]);
    for args in [&["upload"][..], &["test"]] {
        let (success, text) = on(&project, &line, args);
        assert!(!success, "{args:?}: {text}");
        assert!(text.contains("overlaps"), "{args:?}: {text}");
        assert!(!text.contains("did not finish"), "{args:?}: {text}");
        assert!(!text.contains("puts it back"), "{args:?}: {text}");
        assert_eq!(ok(&project, &line, &["installed"]), before, "{args:?}");
    }
}

/// fresh21 F6: a project whose `[robot] rom` names a profile not made yet
/// (a fresh clone: the README's `rom read -o` then `rom = ...`) refused
/// `rom read -o` itself, the command that makes it, with a code and no
/// help. It reads the robot (a note says the profile is missing), and
/// every command that then meets a missing profile says how to make one.
#[test]
fn rom_read_makes_the_profile_a_project_names_before_it_exists() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, _) = crate::new_project(dir.path());
    let toml = project.join("Scorpion.toml");
    let manifest = std::fs::read_to_string(&toml).expect("the manifest");
    std::fs::write(
        &toml,
        manifest.replace("[robot]\n", "[robot]\nrom = \"robot-rom.elf\"\n"),
    )
    .expect("the manifest");
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    let (success, text) = on(&project, &line, &["installed"]);
    assert!(!success, "{text}");
    assert!(
        text.contains("scorpion::project::rom_unreadable") && text.contains("rom read -o FILE"),
        "{text}"
    );
    let text = ok(&project, &line, &["rom", "read", "-o", "robot-rom.elf"]);
    assert!(
        text.contains("robot-rom.elf") && text.contains("note:"),
        "{text}"
    );
    assert!(project.join("robot-rom.elf").is_file());
    let text = ok(&project, &line, &["installed"]);
    assert!(text.contains("nothing installed"), "{text}");
}

/// fresh21 F7: a port the environment (or a file) names, whose device
/// answers nothing (a stale setting: the number now another terminal's),
/// timed out with the cable's help alone; a port that does not exist
/// named where it came from. A silent one does too.
#[test]
fn a_configured_port_that_answers_nothing_names_where_it_came_from() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, _) = crate::new_project(dir.path());
    let sim = Sim::start(dir.path(), &[]);
    let pid = nix::unistd::Pid::from_raw(i32::try_from(sim.child.id()).expect("a pid"));
    nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGSTOP).expect("stopped");
    // recheck22 F1: `ask` and `debug --port` too.
    for args in [
        &["installed"][..],
        &["upload", "--no-dry-run"],
        &["ask", "/1X"],
        &["ask", "/1H"],
        &["debug", "--port"],
        &["test", "--port"],
    ] {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(args)
            .current_dir(&project)
            .env("SCORPION_PORT", &sim.path)
            .env("NO_COLOR", "1")
            .output()
            .expect("scorpion runs");
        let text = transcript(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {text}");
        assert!(
            text.contains(&format!(
                "the port {} is from the environment SCORPION_PORT",
                sim.path
            )) && text.contains("no answer"),
            "{args:?}: {text}"
        );
    }
    let _ = nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGCONT);
}

/// hostile22 F7, recheck22 F5: a project's later image that overlaps an
/// extension on the robot (a friend's, where it goes) was refused after
/// the images before it went in, and nothing said they had. It is found
/// from the robot's table before any image is sent.
#[test]
fn a_project_image_in_the_way_of_an_installed_extension_sends_nothing() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = two_image_project(dir.path(), 'U');
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    upload_friend(&project, &line, 0x0C00);
    let before = ok(&project, &line, &["installed"]);
    let (success, text) = on(&project, &line, &["upload"]);
    assert!(!success, "{text}");
    assert!(
        text.contains("nothing was sent to the robot") && text.contains("overlaps"),
        "{text}"
    );
    assert!(!text.contains("uploaded and verified"), "{text}");
    // fresh25 F5: the help fits a project (no `--target`), and `test
    // --port` names the image in the way and gives it too.
    assert!(
        text.contains("`--replace` takes out") && !text.contains("--target"),
        "{text}"
    );
    assert_eq!(ok(&project, &line, &["installed"]), before);
    let (success, tested) = on(&project, &line, &["test"]);
    assert!(!success, "{tested}");
    assert!(
        tested.contains("test upload second ... FAILED")
            && tested.contains("`--replace` takes out"),
        "{tested}"
    );
    assert_eq!(ok(&project, &line, &["installed"]), before);
}

/// recheck23 F3, F5: the check before a project's images are sent missed
/// two ways a later one is refused after the first went in: the table
/// too full for them all, and images that overlap each other (with
/// `--no-dry-run`, which skips the rehearsal that finds it).
#[test]
fn a_project_that_cannot_go_in_whole_sends_nothing() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let project = two_image_project(dir.path(), 'U');
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    // Seven of the eight entries taken.
    for n in 0..7u16 {
        let base = 0x1000 + n * 0x100;
        let name = format!("friend{n}.elf");
        std::fs::write(dir.path().join(&name), extension_at(base, 40, None)).expect("the image");
        ok(
            &project,
            &line,
            &["upload", &format!("../{name}"), "--no-dry-run"],
        );
    }
    let before = ok(&project, &line, &["installed"]);
    let (success, text) = on(&project, &line, &["upload", "--no-dry-run"]);
    assert!(!success, "{text}");
    assert!(
        text.contains("need 2 entries") && text.contains("which has 1 free"),
        "{text}"
    );
    assert!(!text.contains("uploaded and verified"), "{text}");
    assert_eq!(ok(&project, &line, &["installed"]), before);
    // recheck24: `test --port` took what fitted, then refused the next
    // with a `--replace` hint that could not help. All or none too.
    let (success, tested) = on(&project, &line, &["test"]);
    assert!(!success, "{tested}");
    assert!(
        tested.contains("need 2 entries") && tested.contains("which has 1 free"),
        "{tested}"
    );
    assert!(
        !tested.contains("left installed") && !tested.contains("--replace replaces"),
        "{tested}"
    );
    assert_eq!(ok(&project, &line, &["installed"]), before);
    // fresh25 F1: `--replace` frees nothing here: refused alike, where it
    // took the first image, then refused the second.
    for command in [
        &["upload", "--replace", "--no-dry-run"][..],
        &["test", "--replace"],
    ] {
        let (success, text) = on(&project, &line, command);
        assert!(!success, "{text}");
        assert!(
            text.contains("need 2 entries") && text.contains("which has 1 free"),
            "{text}"
        );
        assert_eq!(ok(&project, &line, &["installed"]), before);
    }
    // The second image moved onto the first.
    let layout = project.join("src/second.toml");
    let text = std::fs::read_to_string(&layout).expect("the layout");
    std::fs::write(&layout, text.replace("\"$0C00\"", "\"$0400\"")).expect("the layout");
    let sim = Sim::start(dir.path(), &[]);
    let line = ["--port", sim.path.as_str()];
    let (success, text) = on(&project, &line, &["upload", "--no-dry-run"]);
    assert!(!success, "{text}");
    assert!(
        text.contains("or an image before it: nothing was sent to the robot"),
        "{text}"
    );
    let listed = ok(&project, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
    let (success, tested) = on(&project, &line, &["test"]);
    assert!(!success, "{tested}");
    assert!(
        tested.contains("cannot load second") && tested.contains("nothing was sent to the robot"),
        "{tested}"
    );
    let listed = ok(&project, &line, &["installed"]);
    assert!(listed.contains("nothing installed"), "{listed}");
}

/// fresh25 F2, F7: `backup` of a robot whose HOOK_UNKNOWN an owner
/// pointed at zeros said a restore would leave the hook at the ROM; the
/// restore refused the file as made by hand. `backup` says the refusal
/// the restore gives; `installed` counts the table's free entries.
#[test]
fn backup_says_the_refusal_its_restore_will_give() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    std::fs::write(d.join("ext.elf"), extension_at(0x0400, 40, None)).expect("the image");
    let sim = Sim::start(d, &[]);
    let line = ["--port", sim.path.as_str()];
    ok(d, &line, &["upload", "ext.elf", "--no-dry-run"]);
    let listed = ok(d, &line, &["installed"]);
    assert!(
        listed.contains("1 of the table's 8 entries in use, 7 free"),
        "{listed}"
    );
    ok(d, &line, &["ask", "--allow-silence", "/9W02010007"]);
    let saved = ok(d, &line, &["backup", "-o", "odd.bak"]);
    let said = "the backup points HOOK_UNKNOWN at $0700, which holds $00";
    assert!(
        saved.contains(&format!(
            "warning: a restore of this file will be refused, writing nothing: {said}"
        )),
        "{saved}"
    );
    assert!(!saved.contains("leaves HOOK_UNKNOWN at the ROM"), "{saved}");
    let (success, text) = on(d, &line, &["restore", "odd.bak"]);
    assert!(!success && text.contains(said), "{text}");
}
