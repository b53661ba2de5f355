//! Issue 23, item 15: every file a user names is read through one bounded
//! reader. `/dev/zero`, a FIFO with no writer or a file over its limit,
//! named as a source, an `.include`/`.incbin`, a card, a world, a ROM
//! profile, a transcript, a `.calls` file, a layout, an object or an
//! image, gets a clear error naming the file and what it is, instead of
//! memory growing to the limit, a "cannot find" or a reader blocked for
//! ever. Every run here is under a memory limit and a time limit, so the
//! old behaviour fails the test instead of the machine.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::{build_example, transcript};

/// Address space for a run: far more than any of these commands needs,
/// far less than reading `/dev/zero` to the end takes.
const MEMORY_KIB: u64 = 1 << 20;

/// Wall-clock time for a run: a blocked reader is killed at this.
const TIME_LIMIT: Duration = Duration::from_secs(30);

/// Runs `scorpion ARGS` in `dir` under [`MEMORY_KIB`] of address space,
/// stdin empty; kills it at [`TIME_LIMIT`] and fails, naming the args.
fn bounded(dir: &Path, args: &[&str]) -> Output {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_scorpion"))
        .args(args)
        .current_dir(dir)
        .env_remove("RUST_BACKTRACE")
        .env("NO_COLOR", "1")
        .env("COLUMNS", "200")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    let started = Instant::now();
    loop {
        if child
            .try_wait()
            .expect("the child can be waited for")
            .is_some()
        {
            return child.wait_with_output().expect("its output");
        }
        if started.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let output = child.wait_with_output().expect("its output");
            panic!(
                "`scorpion {}` hung ({TIME_LIMIT:?}):\n{}",
                args.join(" "),
                transcript(&output)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Asserts that the run failed cleanly (exit 1, no panic, no abort) and
/// said each of `said`.
fn refused(output: &Output, said: &[&str]) {
    let text = flat(output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(!text.contains("panicked"), "{text}");
    for words in said {
        assert!(text.contains(words), "`{words}` missing from:\n{text}");
    }
}

/// The run's transcript with every run of blanks one space: a message may
/// be wrapped anywhere.
fn flat(output: &Output) -> String {
    transcript(output)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// Makes a FIFO at `path` (no writer ever opens it).
fn fifo(path: &Path) {
    let made = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo {}", path.display());
}

#[test]
fn dev_zero_as_a_source_is_refused_as_a_device() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    refused(
        &bounded(dir.path(), &["asm", "/dev/zero", "-o", "zero.o"]),
        &["/dev/zero: a character device, not a regular file"],
    );
}

#[test]
fn a_source_over_sixteen_mib_is_refused_naming_the_limit() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // Sparse: no disk is used for the zeros.
    let file = std::fs::File::create(dir.path().join("huge.s")).expect("created");
    file.set_len(17 << 20).expect("grown");
    refused(
        &bounded(dir.path(), &["asm", "huge.s", "-o", "huge.o"]),
        &["huge.s: 17 MiB, over the 16 MiB limit for a source or .incbin file"],
    );
}

#[test]
fn include_and_incbin_of_dev_zero_say_what_it_is_not_cannot_find() {
    for directive in [".include", ".incbin"] {
        let dir = tempfile::tempdir().expect("a temporary directory");
        std::fs::write(
            dir.path().join("main.s"),
            format!("        {directive} \"/dev/zero\"\n"),
        )
        .expect("written");
        let output = bounded(dir.path(), &["asm", "main.s", "-o", "main.o"]);
        refused(&output, &["/dev/zero", "a character device"]);
        assert!(
            !transcript(&output).contains("cannot find"),
            "{directive}: {}",
            transcript(&output)
        );
    }
}

#[test]
fn incbin_of_a_fifo_does_not_block() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    fifo(&dir.path().join("pipe.bin"));
    std::fs::write(dir.path().join("main.s"), "        .incbin \"pipe.bin\"\n").expect("written");
    refused(
        &bounded(dir.path(), &["asm", "main.s", "-o", "main.o"]),
        &["pipe.bin: a FIFO (named pipe), not a regular file"],
    );
}

#[test]
fn a_card_a_world_and_a_rom_profile_that_are_not_files_are_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    fifo(&dir.path().join("world.rhai"));
    refused(
        &bounded(dir.path(), &["sim", "--card", "/dev/zero@9000"]),
        &["/dev/zero: a character device"],
    );
    refused(
        &bounded(dir.path(), &["sim", "--world", "world.rhai"]),
        &["world.rhai: a FIFO (named pipe)"],
    );
    refused(
        &bounded(dir.path(), &["sim", "--rom", "/dev/zero"]),
        &["/dev/zero: a character device"],
    );
}

#[test]
fn objects_images_and_layouts_that_are_not_files_are_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    fifo(&dir.path().join("pipe.o"));
    fifo(&dir.path().join("layout.toml"));
    build_example(dir.path(), "rangefinder/rangefinder.s", "ok.elf", &[]);
    let runs: [&[&str]; 6] = [
        &["link", "pipe.o", "-o", "out.elf"],
        &["link", "ok.elf", "--target", "layout.toml", "-o", "out.elf"],
        &["disasm", "/dev/zero"],
        &["emu", "run", "/dev/zero"],
        &["sim", "--image", "pipe.o"],
        &["upload", "ok.elf", "--port", "emu", "--expect", "/dev/zero"],
    ];
    for args in runs {
        let output = bounded(dir.path(), args);
        let text = flat(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {text}");
        assert!(
            text.contains("a FIFO (named pipe), not a regular file")
                || text.contains("a character device, not a regular file"),
            "{args:?}: {text}"
        );
    }
}

#[test]
fn a_projects_transcript_and_calls_that_are_not_files_are_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = bounded(dir.path(), &["new", "hostile"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("hostile");
    fifo(&project.join("tests/flood.expect"));
    let output = bounded(&project, &["test"]);
    let text = flat(&output);
    assert!(
        text.contains("tests/flood.expect: a FIFO (named pipe), not a regular file"),
        "{text}"
    );
    std::fs::remove_file(project.join("tests/flood.expect")).expect("removed");
    std::os::unix::fs::symlink("/dev/zero", project.join("tests/zero.calls")).expect("linked");
    let output = bounded(&project, &["test"]);
    let text = flat(&output);
    assert!(
        text.contains("tests/zero.calls: a character device, not a regular file"),
        "{text}"
    );
}

/// Issue 27: a backup to restore, an undo file and a `rom read --base`
/// profile that are a FIFO or `/dev/zero` are refused before the robot
/// is reached (the old `std::fs::read` blocked on the FIFO and read
/// `/dev/zero` until memory ran out).
#[test]
fn backups_undo_files_and_base_profiles_that_are_not_files_are_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    fifo(&dir.path().join("pipe.bak"));
    let line = ["--port", "emu"];
    for (args, said) in [
        (
            vec!["restore", "pipe.bak"],
            "pipe.bak: a FIFO (named pipe), not a regular file",
        ),
        (
            vec!["restore", "/dev/zero"],
            "/dev/zero: a character device, not a regular file",
        ),
        (
            vec!["upload", "--undo", "--undo-file", "pipe.bak"],
            "pipe.bak: a FIFO (named pipe), not a regular file",
        ),
        (
            vec!["rom", "read", "-o", "rom.elf", "--base", "/dev/zero"],
            "/dev/zero: a character device, not a regular file",
        ),
    ] {
        let mut all = args.clone();
        all.extend(line);
        refused(&bounded(dir.path(), &all), &[said]);
    }
}

/// Issue 28's hostile tester: a world file that is not UTF-8 is named as
/// the world file (not "the script"); a `script` it names that is missing
/// is said at the `script` key of the world file, file:line:col.
#[test]
fn a_world_file_and_the_script_it_names_are_said_for_what_they_are() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("latin1.toml"), b"# caf\xE9\nwalls = []\n")
        .expect("a world file");
    let output = bounded(dir.path(), &["sim", "--world", "latin1.toml"]);
    refused(
        &output,
        &["cannot read the world file latin1.toml", "not UTF-8 text"],
    );
    assert!(!transcript(&output).contains("the script"));

    std::fs::write(
        dir.path().join("room.toml"),
        "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\nscript = \"gone.rhai\"\n[robot]\nx = 100\ny = 100\n",
    )
    .expect("a world file");
    refused(
        &bounded(dir.path(), &["sim", "--world", "room.toml"]),
        &[
            "room.toml:2:10: cannot read the world script: gone.rhai: no such file",
            "script = \"gone.rhai\"",
        ],
    );
}

/// The hostile tester's panic: miette's renderer cannot pad past column
/// 65535, so an error far along a long line (a generated source, a world
/// file of 100,000 corners) crashed every command. Narrated instead, with
/// its place.
#[test]
fn an_error_past_column_65535_is_said_not_a_panic() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let source = format!("; a long line\n{}lda #$1FFFF\n", " ".repeat(70_000));
    std::fs::write(dir.path().join("long.s"), source).expect("the source");
    let output = bounded(dir.path(), &["asm", "long.s", "-o", "long.o"]);
    refused(&output, &["long.s", "$1FFFF"]);
    let world = format!("[robot]\nx = {}\"10\"\n", " ".repeat(70_000));
    std::fs::write(dir.path().join("long.toml"), world).expect("the world");
    let output = bounded(dir.path(), &["sim", "--world", "long.toml"]);
    refused(&output, &["long.toml"]);
}
