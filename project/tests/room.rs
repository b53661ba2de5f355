//! Transcripts about the robot in its room (issue 28, 2): a project with
//! a world file drives its robot with ROM commands, lets robot time pass
//! (`wait`), and asserts the pose and the bumps; a wrong pose fails at its
//! `file:line`; room lines in a project without a room are refused at
//! theirs; `--path` draws one picture per transcript.

use std::path::Path;

use scorpion_project::runner::{self, Options, Outcome, path_picture};
use scorpion_project::template::{self, Kind};
use scorpion_project::{Environment, Found, Project};

/// A room of 3 by 2 metres, a post 20 cm round 60 cm east of the robot,
/// which stands at (100, 100) facing east.
const ROOM: &str = r#"
walls = [[0, 0], [300, 0], [300, 200], [0, 200]]

[[obstacle]]
circle = { x = 160, y = 100, radius = 20 }

[robot]
x = 100
y = 100
heading = 0
"#;

/// A new project, its own transcript left out, with `transcript` as
/// `tests/drive.expect`, and the room as its world if `room`.
fn project(dir: &Path, transcript: &str, room: bool) -> Project {
    let project =
        template::create(&dir.join("probe"), "probe", Kind::Extension).expect("a new project");
    let root = &project.root;
    std::fs::remove_file(root.join("tests/probe.expect")).expect("the template's transcript");
    std::fs::write(root.join("tests/drive.expect"), transcript).expect("the transcript");
    if room {
        std::fs::write(root.join("room.toml"), ROOM).expect("the world file");
        let file = root.join("Scorpion.toml");
        let text = std::fs::read_to_string(&file).expect("the project file");
        std::fs::write(
            &file,
            text.replace("cards = []", "cards = []\nworld = \"room.toml\""),
        )
        .expect("the world in the project");
    }
    Project::load(root).expect("the project")
}

fn run(project: &Project, options: Options) -> runner::Report {
    let found = Found::Project(project.clone());
    runner::run_tests(&found, &options, &mut runner::NoProgress).expect("the run itself ends")
}

fn options() -> Options {
    Options {
        environment: Environment::default(),
        ..Options::default()
    }
}

/// The transcript's failure text, if it failed.
fn failure(report: &runner::Report) -> Option<String> {
    let test = report
        .test("transcript tests/drive.expect")
        .expect("the transcript ran");
    match &test.outcome {
        Outcome::Failed(failure) => Some(failure.text.clone()),
        Outcome::Passed(_) => None,
    }
}

/// The transcript of docs/WORLD.md ("In a transcript"), run as written:
/// both wheels 200 steps forward at speed 50 (250 steps a second,
/// 0.8 s), 22 cm east, 3 cm short of the post; then 50 more, into it.
fn drive() -> String {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/WORLD.md"))
            .expect("docs/WORLD.md");
    let section = &doc[doc.find("## In a transcript").expect("the section")..];
    let start = section.find("```text\n").expect("a text block") + "```text\n".len();
    let end = start + section[start..].find("```").expect("its end");
    section[start..end].to_owned()
}

#[test]
fn a_transcript_drives_the_robot_and_asserts_its_pose_and_its_bumps() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let report = run(&project(dir.path(), &drive(), true), options());
    assert_eq!(failure(&report), None, "{report:#?}");
}

#[test]
fn a_wrong_pose_and_a_bump_that_did_not_happen_fail_at_their_lines() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let text = "/8C+500200\n/8D+500200\nwait 1000ms\n\
                pose => x=140cm y=100cm within 1cm\nbumped => $10\n";
    let report = run(&project(dir.path(), text, true), options());
    let message = failure(&report).expect("the transcript fails");
    // As docs/WORLD.md shows it.
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/WORLD.md"))
            .expect("docs/WORLD.md");
    let shown = doc
        .lines()
        .find(|line| line.starts_with("tests/drive.expect:4: `pose` answered"))
        .expect("the failure in the doc");
    assert!(message.contains(shown), "{message}\n---\n{shown}");
    assert!(
        message.contains(
            "tests/drive.expect:5: `bumped` answered `no change of the bumpers`, expected `bumpers $10 closed`"
        ),
        "{message}"
    );
}

#[test]
fn room_lines_without_a_room_are_refused_at_their_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let text = "/1X => X00\npose => x=1cm y=2cm within 1cm\n";
    let report = run(&project(dir.path(), text, false), options());
    let message = failure(&report).expect("the transcript fails");
    assert!(
        message.contains("tests/drive.expect:2: the robot has no room to check this line in"),
        "{message}"
    );
}

#[test]
fn a_mistake_in_a_pose_line_is_said_at_its_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let text = "/1X => X00\npose => x=1m y=2cm within 1cm\n";
    let report = run(&project(dir.path(), text, true), options());
    let message = failure(&report).expect("the transcript fails");
    assert!(
        message.contains("tests/drive.expect:2: `x=1m`: x is a number in cm"),
        "{message}"
    );
}

#[test]
fn path_draws_one_picture_per_transcript() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = project(dir.path(), &drive(), true);
    let picture = dir.path().join("out.svg");
    let report = run(
        &project,
        Options {
            path: Some(picture.clone()),
            ..options()
        },
    );
    assert_eq!(failure(&report), None, "{report:#?}");
    let file = path_picture(&picture, Path::new("tests/drive.expect"));
    assert_eq!(file, dir.path().join("out-drive.svg"));
    let svg = std::fs::read_to_string(&file).expect("the picture was written");
    assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"), "{svg}");
    assert!(
        svg.contains("/8C+500200"),
        "the commands along the trail: {svg}"
    );
}
