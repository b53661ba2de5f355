//! The runner as a library, with no CLI process: a new project made in a
//! temporary directory, its snapshots and transcripts run by
//! `run_tests`, the report checked (counts, a planted change failing with
//! its diff, its transcript mismatch and a pending `.snap.new`), the
//! events a progress recorder receives in order, and the decisions about
//! one pending snapshot at a time.

use std::path::Path;

use romlib::VirtualScorpion;
use scorpion_project::runner::{
    self, Decision, Mode, Options, Outcome, Passed, Progress, Question, SNAPSHOT_KINDS,
};
use scorpion_project::template::{self, Kind};
use scorpion_project::{Environment, Found, Project};

/// What a run told its progress, in order.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Event {
    Started(String),
    Finished(String, bool),
    RobotReady(String),
    RobotDone(String),
    Review(String),
    CardMapped(String, u16, u16),
    ScriptPrinted(String, String),
}

/// Records every event; answers reviews with `answer`.
#[derive(Default)]
struct Recorder {
    events: Vec<Event>,
    answer: Option<Decision>,
}

impl Progress for Recorder {
    fn test_started(&mut self, name: &str) {
        self.events.push(Event::Started(name.to_owned()));
    }
    fn test_finished(&mut self, name: &str, outcome: &Outcome) {
        self.events
            .push(Event::Finished(name.to_owned(), !outcome.failed()));
    }
    fn robot_ready(&mut self, test: &str, _robot: &mut VirtualScorpion) {
        self.events.push(Event::RobotReady(test.to_owned()));
    }
    fn robot_done(&mut self, test: &str, _robot: &mut VirtualScorpion) {
        self.events.push(Event::RobotDone(test.to_owned()));
    }
    fn card_mapped(&mut self, card: &str, start: u16, end: u16) {
        self.events
            .push(Event::CardMapped(card.to_owned(), start, end));
    }
    fn script_printed(&mut self, script: &str, line: &str) {
        self.events
            .push(Event::ScriptPrinted(script.to_owned(), line.to_owned()));
    }
    fn review(&mut self, question: &Question<'_>) -> miette::Result<Decision> {
        self.events.push(Event::Review(question.name.to_owned()));
        Ok(self.answer.unwrap_or(Decision::Skip))
    }
}

/// A project's tests run with `options` (no user file, no environment).
fn run(project: &Project, options: Options, recorder: &mut Recorder) -> runner::Report {
    let found = Found::Project(project.clone());
    runner::run_tests(&found, &options, recorder).expect("the run itself ends")
}

fn options() -> Options {
    Options {
        environment: Environment::default(),
        ..Options::default()
    }
}

fn new_project(dir: &Path) -> Project {
    template::create(&dir.join("probe"), "probe", Kind::Extension).expect("a new project")
}

/// The tests a new project has, in the order they run: its image's
/// snapshots, then its transcript.
fn expected_names() -> Vec<String> {
    let mut names: Vec<String> = SNAPSHOT_KINDS
        .iter()
        .map(|kind| format!("probe/{kind}"))
        .collect();
    names.push("transcript tests/probe.expect".to_owned());
    names
}

#[test]
fn a_new_project_passes_and_the_progress_hears_each_test_in_order() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = new_project(dir.path());
    let mut recorder = Recorder::default();
    let report = run(&project, options(), &mut recorder);

    let names = expected_names();
    assert_eq!(report.passed, names.len(), "{report:#?}");
    assert_eq!(report.failed, 0, "{report:#?}");
    assert_eq!(report.filtered_out, 0);
    assert!(report.success());
    let ran: Vec<&str> = report.tests.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(ran, names);
    assert!(report.robot_time > std::time::Duration::ZERO);

    let transcript = names.last().expect("a transcript").clone();
    let mut expected = Vec::new();
    for name in &names {
        expected.push(Event::Started(name.clone()));
        if *name == transcript {
            expected.push(Event::RobotReady(name.clone()));
            expected.push(Event::RobotDone(name.clone()));
        }
        expected.push(Event::Finished(name.clone(), true));
    }
    assert_eq!(recorder.events, expected);
}

#[test]
fn a_planted_change_fails_with_its_diff_its_mismatch_and_a_pending_snapshot() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = new_project(dir.path());
    let source = project.root.join("src").join("probe.s");
    let text = std::fs::read_to_string(&source).expect("the new source");
    assert!(text.contains("VERSION = $01"), "{text}");
    std::fs::write(&source, text.replace("VERSION = $01", "VERSION = $02"))
        .expect("the planted change");

    let mut recorder = Recorder::default();
    let report = run(&project, options(), &mut recorder);
    assert!(!report.success());
    assert_eq!(report.passed + report.failed, expected_names().len());

    // The bytes hold the version: a diff from the old byte to the new,
    // and the new text pending beside the accepted one.
    let bytes = report.test("probe/bytes").expect("the bytes' snapshot ran");
    let Outcome::Failed(failure) = &bytes.outcome else {
        panic!("the changed bytes passed: {bytes:#?}");
    };
    let diff = failure.diff.as_deref().expect("a changed snapshot's diff");
    assert!(
        diff.lines()
            .any(|l| l.starts_with("- ") && l.contains(" 01")),
        "{diff}"
    );
    assert!(
        diff.lines()
            .any(|l| l.starts_with("+ ") && l.contains(" 02")),
        "{diff}"
    );
    let pending = failure.pending.as_deref().expect("a pending snapshot");
    assert_eq!(
        pending,
        project
            .snapshot_path("probe", "bytes")
            .with_extension("snap.new")
    );
    let written = std::fs::read_to_string(pending).expect("the pending file was written");
    assert!(written.starts_with("---\nsource: Scorpion.toml\nexpression: probe/bytes\n---\n"));

    // The transcript says the line, the command, both answers.
    let transcript = report
        .test("transcript tests/probe.expect")
        .expect("the transcript ran");
    let Outcome::Failed(failure) = &transcript.outcome else {
        panic!("the transcript passed: {transcript:#?}");
    };
    let line = std::fs::read_to_string(project.root.join("tests").join("probe.expect"))
        .expect("the transcript")
        .lines()
        .position(|l| l.starts_with("/1V"))
        .expect("a /1V line")
        + 1;
    assert!(
        failure.text.contains(&format!(
            "tests/probe.expect:{line}: `/1V` answered `V02`, expected `V01`"
        )),
        "{}",
        failure.text
    );

    // Every failure the report holds was told to the progress, as failed.
    for test in &report.tests {
        assert!(
            recorder
                .events
                .contains(&Event::Finished(test.name.clone(), !test.outcome.failed())),
            "{}",
            test.name
        );
    }
}

#[test]
fn one_pending_snapshot_at_a_time_is_accepted_rejected_or_reviewed() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = new_project(dir.path());
    let source = project.root.join("src").join("probe.s");
    let text = std::fs::read_to_string(&source).expect("the new source");
    std::fs::write(&source, text.replace("VERSION = $01", "VERSION = $02"))
        .expect("the planted change");
    let report = run(&project, options(), &mut Recorder::default());
    let failed_snapshots: Vec<String> = report
        .tests
        .iter()
        .filter(|t| t.outcome.failed() && t.name.starts_with("probe/"))
        .map(|t| t.name.clone())
        .collect();
    let pending = runner::review::pending(&project);
    assert_eq!(pending.len(), failed_snapshots.len(), "{pending:#?}");

    // Accept the bytes' alone: its test passes, the others still fail.
    let bytes = project.snapshot_path("probe", "bytes");
    let one = pending
        .iter()
        .find(|p| p.accepted == bytes)
        .expect("the bytes are pending");
    assert!(one.diff().expect("readable").is_some());
    one.accept().expect("accepted");
    assert!(!one.pending.exists());
    let again = run(
        &project,
        Options {
            filter: Some("probe/".to_owned()),
            ..options()
        },
        &mut Recorder::default(),
    );
    assert_eq!(
        again.test("probe/bytes").map(|t| &t.outcome),
        Some(&Outcome::Passed(Passed::Ok))
    );
    assert_eq!(again.failed, failed_snapshots.len() - 1);

    // Reject the listing's: the pending file goes, the accepted stays.
    let listing = project.snapshot_path("probe", "listing");
    let accepted_text = std::fs::read_to_string(&listing).expect("accepted listing");
    let pending = runner::review::pending(&project);
    let one = pending
        .iter()
        .find(|p| p.accepted == listing)
        .expect("the listing is pending");
    one.reject().expect("rejected");
    assert!(!one.pending.exists());
    assert_eq!(
        std::fs::read_to_string(&listing).expect("accepted listing"),
        accepted_text
    );

    // A review answered `accept` takes what is left, each asked once.
    let mut reviewer = Recorder {
        answer: Some(Decision::Accept),
        ..Recorder::default()
    };
    let reviewed = run(
        &project,
        Options {
            filter: Some("probe/".to_owned()),
            mode: Mode::Review,
            ..options()
        },
        &mut reviewer,
    );
    assert_eq!(reviewed.failed, 0, "{reviewed:#?}");
    let asked: Vec<&Event> = reviewer
        .events
        .iter()
        .filter(|e| matches!(e, Event::Review(_)))
        .collect();
    assert_eq!(asked.len(), failed_snapshots.len() - 1, "{asked:?}");
    assert!(runner::review::pending(&project).is_empty());
}

#[test]
fn with_a_port_the_images_are_uploaded_and_the_transcripts_run_there() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = new_project(dir.path());
    let mut recorder = Recorder::default();
    let report = run(
        &project,
        Options {
            port: Some(runner::EMU.to_owned()),
            ..options()
        },
        &mut recorder,
    );
    let ran: Vec<&str> = report.tests.iter().map(|t| t.name.as_str()).collect();
    // The rehearsal on the virtual robot, the upload, the transcript on
    // the robot the port names; no snapshots.
    assert_eq!(
        ran,
        [
            "transcript tests/probe.expect",
            "upload probe",
            "transcript tests/probe.expect"
        ]
    );
    assert!(report.success(), "{report:#?}");
}

#[test]
fn a_projects_card_is_on_each_transcripts_robot_and_what_it_prints_is_told() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = new_project(dir.path());
    let card = "cards/hello.rhai";
    let path = project.root.join(card);
    std::fs::create_dir_all(path.parent().expect("a directory")).expect("cards/");
    std::fs::write(
        &path,
        "const SIZE = 2;\nconst BASE = 0x9100;\nfn init() { print(\"hello from the card\"); }\n",
    )
    .expect("the card");
    let file = project.root.join("Scorpion.toml");
    let text = std::fs::read_to_string(&file).expect("the project file");
    assert!(text.contains("cards = []"), "{text}");
    std::fs::write(
        &file,
        text.replace("cards = []", &format!("cards = [\"{card}\"]")),
    )
    .expect("the card in the project");
    let project = Project::load(&project.root).expect("the project with its card");

    let mut recorder = Recorder::default();
    let report = run(&project, options(), &mut recorder);
    assert!(report.success(), "{report:#?}");

    // The transcript's events, from its start to its end: the card mapped
    // on its fresh robot before the robot is ready, what the card printed
    // while it ran, the robot done before the test is.
    let transcript = "transcript tests/probe.expect".to_owned();
    let events = &recorder.events;
    let from = events
        .iter()
        .position(|e| *e == Event::Started(transcript.clone()))
        .expect("the transcript started");
    let to = events
        .iter()
        .position(|e| *e == Event::Finished(transcript.clone(), true))
        .expect("the transcript passed");
    let during = &events[from..=to];
    let at = |wanted: &Event| {
        during
            .iter()
            .position(|e| e == wanted)
            .unwrap_or_else(|| panic!("{wanted:?} not in {during:#?}"))
    };
    let mapped = at(&Event::CardMapped(card.to_owned(), 0x9100, 0x9101));
    let ready = at(&Event::RobotReady(transcript.clone()));
    let printed = at(&Event::ScriptPrinted(
        card.to_owned(),
        "hello from the card".to_owned(),
    ));
    let done = at(&Event::RobotDone(transcript.clone()));
    assert!(
        mapped < ready && ready < printed && printed < done,
        "{during:#?}"
    );
    // Snapshots run no robot.
    assert_eq!(
        events
            .iter()
            .filter(|e| matches!(e, Event::CardMapped(..)))
            .count(),
        1,
        "{events:#?}"
    );
}

#[test]
fn each_routine_call_has_its_own_robot_and_its_failure_says_what_differs() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = new_project(dir.path());
    let source = project.root.join("src").join("probe.s");
    let mut text = std::fs::read_to_string(&source).expect("the new source");
    text.push_str("\ndouble: asl a\n        rts\n");
    std::fs::write(&source, text).expect("a routine");
    std::fs::write(
        project.root.join("tests").join("probe.calls"),
        "call double A=$21 => A=$42 C=0\ncall double A=$81 => A=$02 C=0\n",
    )
    .expect("the calls");

    let mut recorder = Recorder::default();
    let only_calls = Options {
        filter: Some("call ".to_owned()),
        ..options()
    };
    let report = run(&project, only_calls, &mut recorder);
    let first = "call tests/probe.calls:1 double".to_owned();
    let second = "call tests/probe.calls:2 double".to_owned();
    let ran: Vec<&str> = report.tests.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(ran, [first.as_str(), second.as_str()]);
    assert_eq!(
        report.test(&first).map(|t| &t.outcome),
        Some(&Outcome::Passed(Passed::Ok))
    );
    let Some(Outcome::Failed(failure)) = report.test(&second).map(|t| &t.outcome) else {
        panic!("$81 doubled leaves the carry set: {report:#?}");
    };
    assert!(
        failure.text.contains("C=$01, expected $00"),
        "{}",
        failure.text
    );
    // The snapshots and the transcript are filtered out, not run.
    assert_eq!(report.filtered_out, expected_names().len());

    let mut expected = Vec::new();
    for (name, passed) in [(&first, true), (&second, false)] {
        expected.push(Event::Started(name.clone()));
        expected.push(Event::RobotReady(name.clone()));
        expected.push(Event::RobotDone(name.clone()));
        expected.push(Event::Finished(name.clone(), passed));
    }
    assert_eq!(recorder.events, expected);
}
