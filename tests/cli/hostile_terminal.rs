//! What a hostile tester found where the CLI meets its terminal: a huge
//! answer piped into `scorpion test --review`, and a stderr closed before
//! an error is written. Each ends cleanly: bounded memory, exit 1, never a
//! panic (exit 101) or an abort (134).

use std::io::Write as _;
use std::process::{Command, Stdio};

use crate::scorpion;

/// Address space for the review run: far less than the piped line.
const MEMORY_KIB: u64 = 700_000;

/// A line this long, without a newline, then `s` to skip.
const LINE: usize = 800 << 20;

#[test]
fn a_huge_answer_to_review_is_read_no_further_than_an_answer() {
    let dir = tempfile::tempdir().expect("a directory");
    assert!(scorpion(dir.path(), &["new", "big"]).status.success());
    let project = dir.path().join("big");
    assert!(scorpion(&project, &["test", "--accept"]).status.success());
    let source = project.join("src/big.s");
    let text = std::fs::read_to_string(&source).expect("the source");
    let planted = text.replacen("lda #VERSION", "lda #VERSION + 1", 1);
    assert_ne!(planted, text, "the planted change");
    std::fs::write(&source, planted).expect("write");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_scorpion"))
        .args(["test", "--review"])
        .current_dir(&project)
        .env_remove("RUST_BACKTRACE")
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("scorpion runs");
    let mut stdin = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || {
        let chunk = vec![b'a'; 1 << 20];
        for _ in 0..LINE / chunk.len() {
            if stdin.write_all(&chunk).is_err() {
                return;
            }
        }
        let _ = stdin.write_all(b"\ns\ns\ns\ns\ns\n");
    });
    let output = child.wait_with_output().expect("it ends");
    let _ = writer.join();
    let stderr = String::from_utf8_lossy(&output.stderr);
    // Skipped snapshots still fail the run: exit 1, not an abort.
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("memory allocation"), "{stderr}");
}

#[test]
fn an_error_written_to_a_closed_stderr_is_no_panic() {
    let dir = tempfile::tempdir().expect("a directory");
    let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
        .args(["build", "nosuch.s", "-o", "x.elf"])
        .current_dir(dir.path())
        .env_remove("RUST_BACKTRACE")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("scorpion runs");
    // The reader goes away before anything is written: the pipe is closed.
    drop(child.stderr.take());
    let status = child.wait().expect("it ends");
    assert_eq!(status.code(), Some(1), "{status}");
}
