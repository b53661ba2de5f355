//! `--path FILE.svg` on `test` and `debug` (issue 28, 2), as on `sim`:
//! the robot's path in its room (a world file) drawn when the run ends,
//! one picture per transcript for `test`.

use std::path::Path;

use crate::{copy_dir, scorpion, scorpion_with_input, transcript};

/// The example room, copied into `dir`.
fn room(dir: &Path) {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/room/room.toml");
    std::fs::copy(example, dir.join("room.toml")).expect("the example room");
}

/// A new project `probe` in `dir` whose robot is in the example room
/// (`[robot] world`).
fn project_in_room(dir: &Path) -> std::path::PathBuf {
    assert!(scorpion(dir, &["new", "probe"]).status.success());
    let project = dir.join("probe");
    room(&project);
    let file = project.join("Scorpion.toml");
    let text = std::fs::read_to_string(&file).expect("the project file");
    std::fs::write(
        &file,
        text.replace("cards = []", "cards = []\nworld = \"room.toml\""),
    )
    .expect("the world in the project");
    project
}

#[test]
fn debug_draws_the_path_of_its_session() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    room(dir.path());
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--world", "room.toml", "--path", "path.svg"],
        "/8C+500100\n/8D+500100\ncontinue 600000\nquit\n",
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let picture = std::fs::read_to_string(dir.path().join("path.svg")).expect("the picture");
    assert!(picture.starts_with("<svg "), "{picture}");
    assert!(picture.contains(">/8C+500100 at "), "{picture}");
    assert!(picture.contains("<polyline"), "the trail: {picture}");
    // The robot drawn is the one the session ran, 11 cm on from where it
    // started (x=100, the picture's y flipped): not the robot first built
    // to check the set-up, which never moved.
    let robot = picture
        .split(r#"<g class="robot"><circle cx=""#)
        .nth(1)
        .and_then(|rest| rest.split('"').next())
        .expect("the robot drawn");
    let x: f64 = robot.parse().expect("a number");
    assert!((x - 111.0).abs() < 1.0, "the robot at x={x}: {picture}");
}

/// The hostile tester's finding: a step back undrew the trail (the
/// picture was of the robot the session held at its end, a copy from
/// before), though the picture is of the whole run. Forward 2 s (the robot
/// meets the post at x=125 and bumps), back, on a little, quit: the trail
/// still reaches the post, and the bump is drawn, as without the step
/// back.
#[test]
fn debug_draws_the_whole_run_past_a_step_back() {
    let ends = |session: &str| {
        let dir = tempfile::tempdir().expect("a temporary directory");
        room(dir.path());
        let output = scorpion_with_input(
            Some(dir.path()),
            &["debug", "--world", "room.toml", "--path", "path.svg"],
            session,
        );
        assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
        let picture = std::fs::read_to_string(dir.path().join("path.svg")).expect("the picture");
        let trail = picture
            .split(r#"<polyline class="trail" points=""#)
            .nth(1)
            .and_then(|rest| rest.split('"').next())
            .expect("the trail");
        let last = trail.split(' ').next_back().expect("a point").to_owned();
        (last, picture.matches(r#"<g class="bump">"#).count())
    };
    let forward = ends("/4C+40\n/4D+40\ncontinue 2000000\nquit\n");
    let back = ends("/4C+40\n/4D+40\ncontinue 2000000\nback 500000\ncontinue 100000\nquit\n");
    assert!(forward.0.starts_with("125."), "forward: {forward:?}");
    assert_eq!(forward.1, 1, "one bump forward");
    assert_eq!(back, forward, "a step back undraws nothing");
}

#[test]
fn debug_path_needs_a_room() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let output = scorpion_with_input(Some(dir.path()), &["debug", "--path", "path.svg"], "quit\n");
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    assert!(
        transcript(&output).contains("--path draws the robot in its room"),
        "{}",
        transcript(&output)
    );
}

#[test]
fn test_draws_one_picture_per_transcript() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = project_in_room(dir.path());
    std::fs::write(
        project.join("tests/drive.expect"),
        "/8C+500100\n/8D+500100\nwait 600ms\npose => x=111cm y=100cm within 1cm\n",
    )
    .expect("the transcript");
    let output = scorpion(&project, &["test", "--path", "out/run.svg"]);
    // The directory is the user's to make.
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    std::fs::create_dir(project.join("out")).expect("out/");
    let output = scorpion(&project, &["test", "--path", "out/run.svg"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    for stem in ["probe", "drive"] {
        let picture = std::fs::read_to_string(project.join(format!("out/run-{stem}.svg")))
            .expect("a picture per transcript");
        assert!(picture.starts_with("<svg "), "{picture}");
    }
    let drive = std::fs::read_to_string(project.join("out/run-drive.svg")).expect("drive");
    assert!(drive.contains(">/8D+500100 at "), "{drive}");
}

/// examples/linefollow: the line-follower operating system follows the
/// curved tape of its room.toml to its end, its transcript asserting the
/// pose there; its path drawn. Moved 20 cm along the line, the pose its
/// transcript requires fails.
#[test]
fn the_line_follower_follows_its_curved_line_to_the_end() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/linefollow");
    let project = dir.path().join("linefollow");
    copy_dir(&example, &project);
    let output = scorpion(&project, &["test", "--path", "path.svg"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let picture =
        std::fs::read_to_string(project.join("path-follow.svg")).expect("the follower's path");
    assert!(picture.contains(">/2L1 at "), "{picture}");

    let expect = project.join("tests/follow.expect");
    let text = std::fs::read_to_string(&expect).expect("the transcript");
    assert!(text.contains("x=230cm y=170cm"), "{text}");
    std::fs::write(&expect, text.replace("x=230cm y=170cm", "x=230cm y=190cm"))
        .expect("a wrong pose");
    let output = scorpion(&project, &["test", "follow"]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    assert!(
        transcript(&output).contains("tests/follow.expect:6: `pose` answered `x=229.5cm y=171.5cm"),
        "{}",
        transcript(&output)
    );
}

/// A picture into a directory that does not exist is refused before the
/// run, by each command that draws one, not after it with the verdict
/// lost (a new user's finding).
#[test]
fn a_path_into_a_missing_directory_is_refused_before_the_run() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = project_in_room(dir.path());
    for args in [
        &["test", "--path", "out/run.svg"][..],
        &["sim", "--path", "out/run.svg"][..],
        &["debug", "--path", "out/run.svg"][..],
    ] {
        let output = scorpion_with_input(Some(&project), args, "quit\n");
        let said = transcript(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {said}");
        assert!(
            said.contains("the directory out does not exist"),
            "{args:?}: {said}"
        );
        assert!(
            !said.contains("... ok"),
            "refused before any test ran: {said}"
        );
    }
    // A FIFO would block the picture's write for ever (a hostile tester's).
    let fifo = project.join("pipe.svg");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let output = scorpion_with_input(Some(&project), &["sim", "--path", "pipe.svg"], "");
    let said = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{said}");
    assert!(said.contains("not a regular file"), "{said}");
}

/// `--path FILE.png` (issue 28, 2): the same picture as the SVG of the
/// same transcript (`test` runs in robot time: both runs are the same),
/// rasterized at its size; the robot's outline drawn in the trail's blue
/// where the SVG puts the robot at the end.
#[test]
fn a_png_path_is_the_svg_rasterized() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = project_in_room(dir.path());
    std::fs::write(
        project.join("tests/drive.expect"),
        "/8C+500100\n/8D+500100\nwait 600ms\npose => x=111cm y=100cm within 1cm\n",
    )
    .expect("the transcript");
    for picture in ["path.svg", "path.png"] {
        let output = scorpion(&project, &["test", "drive", "--path", picture]);
        assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    }
    let svg = std::fs::read_to_string(project.join("path-drive.svg")).expect("the SVG");
    let attribute = |from: &str, name: &str| -> f64 {
        let start = from.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
        from[start..start + from[start..].find('"').expect("a quote")]
            .parse()
            .expect("a number")
    };
    let view_box: Vec<f64> = {
        let start = svg.find("viewBox=\"").expect("a viewBox") + 9;
        svg[start..start + svg[start..].find('"').expect("a quote")]
            .split(' ')
            .map(|n| n.parse().expect("a number"))
            .collect()
    };
    let robot = &svg[svg.find(r#"<g class="robot">"#).expect("the robot")..];
    let (cx, cy, r) = (
        attribute(robot, "cx"),
        attribute(robot, "cy"),
        attribute(robot, "r"),
    );
    assert!(cx > 105.0, "the robot moved east: {robot}");

    let png = resvg::tiny_skia::Pixmap::load_png(project.join("path-drive.png")).expect("a PNG");
    assert_eq!(
        (png.width(), png.height()),
        (
            (view_box[2] * 3.0).ceil() as u32,
            (view_box[3] * 3.0).ceil() as u32
        ),
        "3 pixels a centimetre, as the SVG's size says"
    );
    let blue = |x: f64, y: f64| {
        let (px, py) = (
            ((x - view_box[0]) * 3.0) as i64,
            ((y - view_box[1]) * 3.0) as i64,
        );
        (-2..=2).any(|dx| {
            (-2..=2).any(|dy| {
                let (Ok(x), Ok(y)) = (u32::try_from(px + dx), u32::try_from(py + dy)) else {
                    return false;
                };
                png.pixel(x, y)
                    .is_some_and(|p| (p.red(), p.green(), p.blue()) == (0, 102, 204))
            })
        })
    };
    // The outline's east and west edges, not its middle.
    assert!(
        blue(cx + r, cy) && blue(cx - r, cy),
        "the robot's outline at ({cx}, {cy})"
    );
    assert!(
        !blue(cx, cy + r / 2.0),
        "inside the outline the floor shows"
    );
    let background = png.pixel(0, 0).expect("a corner");
    assert_eq!(
        (background.red(), background.green(), background.blue()),
        (0xfa, 0xfa, 0xfa),
        "the picture's floor"
    );
}

/// `test --path` in a project whose robot has no room is refused before
/// any test runs, naming what `test` reads (the project's `[robot]
/// world`), not a `--world` it does not take; it failed every transcript
/// (issue 28's fourth pass).
#[test]
fn test_path_without_a_room_is_refused_up_front() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    assert!(scorpion(dir.path(), &["new", "probe"]).status.success());
    let project = dir.path().join("probe");
    let output = scorpion(&project, &["test", "--path", "run.svg"]);
    let said = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{said}");
    assert!(
        said.contains("--path draws each transcript's robot in its room"),
        "{said}"
    );
    assert!(
        said.contains(r#"`world = "room.toml"` under [robot]"#),
        "{said}"
    );
    assert!(!said.contains("--world"), "test takes no --world: {said}");
    assert!(
        !said.contains("... "),
        "refused before any test ran: {said}"
    );
    // Filtered to no transcript, there is nothing to draw: the snapshots run.
    let output = scorpion(&project, &["test", "probe/", "--path", "run.svg"]);
    let said = transcript(&output);
    assert!(!said.contains("--path draws"), "{said}");
    assert!(said.contains("test probe/listing ... "), "{said}");
}

/// `--path` names a picture: `.svg` or `.png`, any case; anything else
/// (which got an SVG under its name) is refused before the run, by each
/// command that draws one.
#[test]
fn a_path_that_is_not_a_picture_is_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = project_in_room(dir.path());
    for path in ["run.jpg", "run.txt", "run", "run.svg.bak"] {
        for command in ["test", "sim", "debug"] {
            let output = scorpion_with_input(Some(&project), &[command, "--path", path], "quit\n");
            let said = transcript(&output);
            assert_eq!(output.status.code(), Some(1), "{command} {path}: {said}");
            assert!(
                said.contains(&format!("--path {path}: a picture is .svg or .png")),
                "{command} {path}: {said}"
            );
            assert!(!said.contains("... "), "refused before the run: {said}");
            assert!(
                !project.join(path).exists(),
                "{command} {path}: nothing written"
            );
        }
    }
    let output = scorpion(&project, &["test", "probe.expect", "--path", "RUN.SVG"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let picture = std::fs::read_to_string(project.join("RUN-probe.SVG")).expect("drawn");
    assert!(picture.starts_with("<svg "), "{picture}");
}

/// A picture whose write fails half way (here the file size limit of
/// `ulimit -f`, with SIGXFSZ ignored so that the write returns an error)
/// leaves the file as it was, not half a picture, and no temporary file
/// beside it.
#[test]
fn a_failed_write_of_the_path_leaves_the_file_as_it_was() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    room(dir.path());
    let args = ["sim", "--world", "room.toml", "--path", "path.png"];
    let output = scorpion_with_input(Some(dir.path()), &args, "");
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let whole = std::fs::metadata(dir.path().join("path.png"))
        .expect("drawn")
        .len();
    assert!(
        whole > 4096,
        "a picture larger than the limit: {whole} bytes"
    );

    let old = "the last run's picture";
    std::fs::write(dir.path().join("path.png"), old).expect("the old picture");
    let output = std::process::Command::new("sh")
        .arg("-c")
        // 2 blocks: 1 KiB or 2, whichever sh counts in.
        .arg(r#"ulimit -f 2 && trap "" XFSZ && exec "$0" "$@" < /dev/null"#)
        .arg(env!("CARGO_BIN_EXE_scorpion"))
        .args(args)
        .current_dir(dir.path())
        .env("NO_COLOR", "1")
        .output()
        .expect("sh runs");
    let said = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{said}");
    assert!(said.contains("cannot write the path to path.png"), "{said}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("path.png")).expect("the picture"),
        old,
        "the file as it was: {said}"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("the directory")
        .map(|entry| entry.expect("an entry").file_name())
        .collect();
    assert_eq!(left.len(), 2, "room.toml and path.png alone: {left:?}");
}
