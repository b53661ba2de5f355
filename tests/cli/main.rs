//! The `scorpion` binary run as a process: arguments in, output and exit
//! status out, snapshotted with insta. One module per subcommand.

mod ask;
mod asm;
mod build;
mod cards;
mod disasm;
mod emu;
mod link;
mod project;
mod read;
mod search_order;
mod sim;
mod terminal;
mod upload;

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
