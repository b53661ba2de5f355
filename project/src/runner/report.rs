//! What a run of a project's tests tells its caller: each test's
//! [`Outcome`] as it comes (through [`Progress`], whose methods all do
//! nothing unless a front end overrides them), and the [`Report`] at the
//! end.

use std::path::PathBuf;
use std::time::Duration;

use romlib::VirtualScorpion;

use super::build::Built;
use super::review::Decision;

/// How a test passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Passed {
    /// It held.
    Ok,
    /// A new or changed snapshot, taken as it is now.
    Accepted,
    /// A stale snapshot, deleted.
    Deleted,
    /// Not checked: what it checks is what tests the filter left out
    /// would have run (a cycle budget of a routine no selected test
    /// called). Counted as filtered out, neither passed nor failed.
    NotRun,
}

impl Passed {
    /// The word a test line ends with: `ok`, `accepted`, `deleted`.
    pub fn word(self) -> &'static str {
        match self {
            Passed::Ok => "ok",
            Passed::Accepted => "accepted",
            Passed::Deleted => "deleted",
            Passed::NotRun => "not run (the tests that would run it are filtered out)",
        }
    }
}

/// Why a test failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    /// What to show, a line each, indented as under a test line.
    pub text: String,
    /// A changed snapshot's diff (`-` accepted, `+` now).
    pub diff: Option<String>,
    /// Where the snapshot's new text was left for review (`NAME.snap.new`).
    pub pending: Option<PathBuf>,
}

impl Failure {
    /// A failure said by `text` alone.
    pub fn text(text: impl Into<String>) -> Failure {
        Failure {
            text: text.into(),
            diff: None,
            pending: None,
        }
    }
}

/// How a test ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// It passed.
    Passed(Passed),
    /// It failed.
    Failed(Failure),
}

impl Outcome {
    /// Whether it failed.
    pub fn failed(&self) -> bool {
        matches!(self, Outcome::Failed(_))
    }
}

/// One test's name and outcome.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TestResult {
    /// The test's name (`probe/listing`, `transcript tests/probe.expect`,
    /// `call tests/io.calls:3 double`...), what `NAME` filters on.
    pub name: String,
    /// How it ended.
    pub outcome: Outcome,
}

/// A workspace member's counts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemberReport {
    /// The member's name in the workspace.
    pub name: String,
    /// Its tests that passed.
    pub passed: usize,
    /// Its tests that failed.
    pub failed: usize,
}

/// What a run found, all told.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Report {
    /// Every test that ran, in the order they ran.
    pub tests: Vec<TestResult>,
    /// Tests that passed.
    pub passed: usize,
    /// Tests that failed.
    pub failed: usize,
    /// Tests the filter did not select.
    pub filtered_out: usize,
    /// A workspace's members, in order (empty for a project).
    pub members: Vec<MemberReport>,
    /// Robot time the transcripts on the virtual Scorpion stood for.
    pub robot_time: Duration,
    /// Wall time they took (robots set up and images loaded included).
    pub wall_time: Duration,
    /// With a port: the wall time the transcripts took on the robot there
    /// (the two above are the rehearsal's).
    pub port_time: Option<Duration>,
    /// The images uploaded to a robot on a real port, which stay there.
    pub left_installed: Vec<String>,
    /// Whether every upload to that robot changed nothing on it, so the
    /// project's undo file is still the one an earlier run kept.
    pub kept_older_undo: bool,
    /// What `--replace` took out on that robot, as the uploads said:
    /// `extension 8C8390 ($0400-$044F)`, for the image that took its place.
    pub replaced: Vec<(String, String)>,
    /// Ways out the robot's chains held that were no way for a command to
    /// go (`HOOK_UNKNOWN led to $0021`), for the image that falls through
    /// to the ROM instead.
    pub dropped: Vec<(String, String)>,
    /// Extensions a reset freed while an image went in (`extension
    /// 8C8390 ($0400-$044F)`), for that image: no longer installed.
    pub reset_freed: Vec<(String, String)>,
}

impl Report {
    /// Whether every test passed.
    pub fn success(&self) -> bool {
        self.failed == 0
    }

    /// The test named `name`, if it ran.
    pub fn test(&self, name: &str) -> Option<&TestResult> {
        self.tests.iter().find(|test| test.name == name)
    }
}

/// What a snapshot review asks about one snapshot.
#[derive(Debug, Clone, Copy)]
pub struct Question<'a> {
    /// The test's name (`probe/listing`, `stale tests/snapshots/...`).
    pub name: &'a str,
    /// What differs: the diff or the new text, indented.
    pub why: &'a str,
    /// What accepting does: `accept` or `delete it`.
    pub accept: &'a str,
}

/// Told of a run as it goes. Every method does nothing unless overridden;
/// the run's order: for each project (a workspace's members each between
/// [`member_started`](Progress::member_started) and
/// [`member_finished`](Progress::member_finished)), the images' builds and
/// their warnings, then each test between
/// [`test_started`](Progress::test_started) and
/// [`test_finished`](Progress::test_finished).
pub trait Progress {
    /// A workspace's member's tests begin.
    fn member_started(&mut self, _name: &str) {}

    /// A workspace's member's tests ended with these counts.
    fn member_finished(&mut self, _member: &MemberReport) {}

    /// An image was built: its linked image, symbols and listing (what a
    /// profiler or a coverage map names addresses with).
    fn image_built(&mut self, _built: &Built) {}

    /// A warning of the assembler or linker building `_image`.
    fn build_warning(&mut self, _image: &str, _warning: &miette::Report) {}

    /// The test `_name` begins.
    fn test_started(&mut self, _name: &str) {}

    /// The test `_name` ended.
    fn test_finished(&mut self, _name: &str, _outcome: &Outcome) {}

    /// A card of a fresh virtual robot went to `_start`-`_end` of its KIM
    /// bus.
    fn card_mapped(&mut self, _card: &str, _start: u16, _end: u16) {}

    /// The test `_test` has a fresh virtual robot, images loaded, about to
    /// run: where an observer (a profiler, a coverage map) is attached.
    fn robot_ready(&mut self, _test: &str, _robot: &mut VirtualScorpion) {}

    /// The test `_test` is done with its virtual robot: where what an
    /// observer gathered is read back.
    fn robot_done(&mut self, _test: &str, _robot: &mut VirtualScorpion) {}

    /// The project's runs on the virtual Scorpion are done (its
    /// transcripts and routine calls; with a port, the rehearsal, before
    /// anything is sent to the robot): the observer's own checks over
    /// what they ran (the project's cycle budgets), each a test's name
    /// and outcome, recorded as the project's tests (a failure, in a
    /// rehearsal, keeps the robot untouched). `_filtered`: a filter left
    /// some tests out. None unless overridden.
    fn virtual_runs_done(&mut self, _filtered: bool) -> Vec<(String, Outcome)> {
        Vec::new()
    }

    /// A card or the world script `_script` printed `_line`.
    fn script_printed(&mut self, _script: &str, _line: &str) {}

    /// In [`Mode::Review`](super::Mode::Review): what to do with a new,
    /// changed or stale snapshot. Skipped (left pending) unless overridden.
    ///
    /// # Errors
    /// Whatever stops the run (the answer could not be read).
    fn review(&mut self, _question: &Question<'_>) -> miette::Result<Decision> {
        Ok(Decision::Skip)
    }
}

/// A [`Progress`] that is told nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {}
