//! The `scorpion` binary run as a process: arguments in, output and exit
//! status out, snapshotted with insta. One module per subcommand.

mod ask;
mod asm;
mod build;
mod cards;
mod config;
mod dap;
mod dap_requests;
mod debug;
mod debug_pty;
mod disasm;
mod emu;
mod hostile_files;
mod hostile_terminal;
mod journeys;
mod layouts;
mod link;
mod profile;
mod project;
mod read;
mod robot;
mod robot_dap;
mod robot_debug;
mod robot_left_stub;
mod robot_live;
mod robot_recovery;
mod robot_undo;
mod room_path;
mod search_order;
mod sim;
mod sim_line;
mod terminal;
mod upload;
mod view;
mod view_browser;
mod vscode;

use std::process::{Command, Output};

/// Runs `scorpion` with `args` in `dir` and returns its output.
pub(crate) fn scorpion(dir: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scorpion"))
        .args(args)
        .current_dir(dir)
        .env_remove("RUST_BACKTRACE")
        .env("NO_COLOR", "1")
        .env("COLUMNS", "100")
        .output()
        .expect("the scorpion binary runs")
}

/// Builds `examples/<source>` into `dir/<output>` with `scorpion build`,
/// with `extra` arguments (`--target ...`); panics, showing why, if it fails.
pub(crate) fn build_example(dir: &std::path::Path, source: &str, output: &str, extra: &[&str]) {
    let source = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(source);
    let mut args = vec!["build", source.to_str().expect("UTF-8"), "-o", output];
    args.extend(extra);
    let built = scorpion(dir, &args);
    assert!(built.status.success(), "{}", transcript(&built));
}

/// `scorpion new myext` in `dir`: the project's directory and its
/// `src/myext.s`.
pub(crate) fn new_project(dir: &std::path::Path) -> (std::path::PathBuf, String) {
    let made = scorpion(dir, &["new", "myext"]);
    assert!(made.status.success(), "{}", transcript(&made));
    let project = dir.join("myext");
    let source = std::fs::read_to_string(project.join("src/myext.s")).expect("the source");
    (project, source)
}

/// The numbers (from 1) of the lines of `text` that contain `what`.
pub(crate) fn lines_with(text: &str, what: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, line)| line.contains(what))
        .map(|(index, _)| index + 1)
        .collect()
}

/// Copies the directory `from` into `to`, without its `target/` (an
/// example, so that a test writes into a temporary directory, not the
/// repository).
pub(crate) fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).expect("a directory");
    for entry in std::fs::read_dir(from).expect("the example").flatten() {
        let target = to.join(entry.file_name());
        if entry.file_type().expect("a type").is_dir() {
            if entry.file_name() != "target" {
                copy_dir(&entry.path(), &target);
            }
        } else {
            std::fs::copy(entry.path(), &target).expect("a copy");
        }
    }
}

/// Exit code, stdout and stderr as one text, for snapshots.
pub(crate) fn transcript(output: &Output) -> String {
    format!(
        "exit: {}\n--- stdout\n{}--- stderr\n{}",
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// The fenced block of `kind` that follows `heading` in README.md.
pub(crate) fn readme_block(heading: &str, kind: &str) -> String {
    let readme =
        std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md"))
            .expect("README.md");
    let section = &readme[readme.find(heading).expect("the section")..];
    let fence = format!("```{kind}\n");
    let start = section.find(&fence).expect("the block") + fence.len();
    let end = start + section[start..].find("```").expect("the block's end");
    section[start..end].to_string()
}

/// Runs `scorpion ARGS` (in `dir`, else the package's directory) with
/// `input` on stdin. A command that exits before reading its input (a sim
/// that refuses its images) is not an error here.
pub(crate) fn scorpion_with_input(
    dir: Option<&std::path::Path>,
    args: &[&str],
    input: &str,
) -> Output {
    use std::io::Write as _;
    use std::process::Stdio;
    let mut command = Command::new(env!("CARGO_BIN_EXE_scorpion"));
    if let Some(dir) = dir {
        command.current_dir(dir);
    }
    let mut child = command
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .env("NO_COLOR", "1")
        .env("COLUMNS", "100")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the scorpion binary runs");
    let written = child
        .stdin
        .take()
        .expect("stdin is piped")
        .write_all(input.as_bytes());
    if let Err(error) = written {
        assert_eq!(
            error.kind(),
            std::io::ErrorKind::BrokenPipe,
            "the input is written"
        );
    }
    child
        .wait_with_output()
        .expect("scorpion ends at the end of its input")
}

/// `PATH` with the `scorpion` binary's directory first: how a README's
/// commands find it.
pub(crate) fn path_with_scorpion() -> String {
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_scorpion"))
        .parent()
        .expect("the binary's directory")
        .to_path_buf();
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}
