//! The runner's errors say what miette's `wrap_err` said before them: the
//! runner's message, the lower error as the cause, and the lower error's
//! code, help and snippets; so the CLI, which renders them, prints the
//! same bytes. Each case builds the same failure twice, once as the
//! runner's variant and once as the `wrap_err` the runner used to return.

use miette::{Diagnostic, IntoDiagnostic, WrapErr};
use scorpion_project::runner;

/// What a renderer shows of `diagnostic`: message, code, help, the causes'
/// messages, how many labels, whether it has source code.
fn shown(
    diagnostic: &dyn Diagnostic,
) -> (
    String,
    Option<String>,
    Option<String>,
    Vec<String>,
    usize,
    bool,
) {
    let mut causes = Vec::new();
    let mut cause = diagnostic.source();
    while let Some(error) = cause {
        causes.push(error.to_string());
        cause = error.source();
    }
    (
        diagnostic.to_string(),
        diagnostic.code().map(|c| c.to_string()),
        diagnostic.help().map(|h| h.to_string()),
        causes,
        diagnostic.labels().map_or(0, Iterator::count),
        diagnostic.source_code().is_some(),
    )
}

fn unreadable(dir: &std::path::Path) -> hostfs::Error {
    hostfs::read_text(dir.join("gone.expect"), hostfs::TEXT).expect_err("no such file")
}

#[test]
fn a_file_that_cannot_be_read_is_said_as_wrap_err_said_it() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let typed = runner::Error::Read {
        shown: "tests/gone.expect".to_owned(),
        path: dir.path().join("gone.expect"),
        source: unreadable(dir.path()),
    };
    let wrapped = Err::<(), _>(unreadable(dir.path()))
        .wrap_err("cannot read tests/gone.expect")
        .expect_err("an error");
    assert_eq!(shown(&typed), shown(wrapped.as_ref()));
}

#[test]
fn a_snapshot_that_cannot_be_deleted_is_said_as_wrap_err_said_it() {
    let io = || std::io::Error::new(std::io::ErrorKind::PermissionDenied, "permission denied");
    let typed = runner::Error::Delete {
        path: "tests/snapshots/probe__listing.snap.new".into(),
        source: io(),
    };
    let wrapped = Err::<(), _>(io())
        .into_diagnostic()
        .wrap_err("cannot delete tests/snapshots/probe__listing.snap.new")
        .expect_err("an error");
    assert_eq!(shown(&typed), shown(wrapped.as_ref()));
}

#[test]
fn a_bad_transcript_line_is_said_as_before() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("bad.expect");
    std::fs::write(&path, "/1V => V01\n=> V01\n").expect("write");
    let typed =
        runner::transcript::read_commands(&path, "tests/bad.expect").expect_err("a bad line");
    let runner::Error::BadTranscript(bad) = &typed else {
        panic!("{typed:?}");
    };
    assert_eq!((bad.shown.as_str(), bad.line), ("tests/bad.expect", 2));
    let before = miette::miette!(
        code = "uploader::bad_expectations",
        help = "each line is `COMMAND` or `COMMAND => ANSWER`; `#` starts a comment",
        "tests/bad.expect:{}: {}",
        bad.line,
        bad.reason
    );
    assert_eq!(shown(&typed), shown(before.as_ref()));
}
