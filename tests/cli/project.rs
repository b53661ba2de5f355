//! A project's loop as a user runs it: `scorpion new`, `scorpion test`, a
//! change to the source that alters the bytes failing with a diff,
//! `scorpion test --accept`, passing again; `scorpion build` in the
//! project; errors in `Scorpion.toml` at their line; the examples'
//! projects passing their own tests.

use std::path::Path;

use crate::{scorpion, transcript};

fn stdout(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[test]
fn new_test_change_fail_accept_pass() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "probe"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("probe");
    for file in [
        "Scorpion.toml",
        "src/probe.s",
        "tests/probe.expect",
        ".gitignore",
        "README.md",
    ] {
        assert!(project.join(file).is_file(), "{file}");
    }

    let first = scorpion(&project, &["test"]);
    assert_eq!(first.status.code(), Some(0), "{}", transcript(&first));
    insta::assert_snapshot!("project_passes_at_once", stdout(&first));

    // From a subdirectory too, as cargo finds its manifest.
    let below = scorpion(&project.join("src"), &["test"]);
    assert_eq!(below.status.code(), Some(0), "{}", transcript(&below));

    let source = project.join("src/probe.s");
    let text = std::fs::read_to_string(&source).expect("the source");
    std::fs::write(&source, text.replace("VERSION = $01", "VERSION = $02")).expect("edit");
    let changed = scorpion(&project, &["test"]);
    assert_eq!(changed.status.code(), Some(1), "{}", transcript(&changed));
    insta::assert_snapshot!("project_change_fails_with_a_diff", stdout(&changed));
    // README shows this failure, for a project named myext.
    let shown = crate::readme_block("A transcript that fails says", "text");
    assert!(
        stdout(&changed).contains(&shown.replace("myext", "probe")),
        "README.md's failing transcript is stale:\n{shown}"
    );

    // The transcript says V01: accepting the snapshots leaves it failing,
    // until it says what the robot now answers.
    let accepted = scorpion(&project, &["test", "--accept"]);
    assert!(
        stdout(&accepted).contains("test probe/bytes ... accepted"),
        "{}",
        transcript(&accepted)
    );
    let transcript_file = project.join("tests/probe.expect");
    let text = std::fs::read_to_string(&transcript_file).expect("the transcript");
    std::fs::write(&transcript_file, text.replace("V01", "V02")).expect("edit");
    let again = scorpion(&project, &["test"]);
    assert_eq!(again.status.code(), Some(0), "{}", transcript(&again));
    assert!(
        stdout(&again).ends_with("5 passed, 0 failed\n"),
        "{}",
        transcript(&again)
    );

    // A snapshot no image makes any more fails, and --accept deletes it.
    let stale = project.join("tests/snapshots/gone__bytes.snap");
    std::fs::write(
        &stale,
        "---\nsource: Scorpion.toml\nexpression: gone/bytes\n---\n",
    )
    .expect("write");
    let failed = scorpion(&project, &["test"]);
    assert_eq!(failed.status.code(), Some(1), "{}", transcript(&failed));
    assert!(stdout(&failed).contains("test stale tests/snapshots/gone__bytes.snap ... FAILED"));
    let cleaned = scorpion(&project, &["test", "--accept"]);
    assert_eq!(cleaned.status.code(), Some(0), "{}", transcript(&cleaned));
    assert!(!stale.exists());

    let built = scorpion(&project, &["build"]);
    assert_eq!(built.status.code(), Some(0), "{}", transcript(&built));
    assert!(project.join("target/scorpion/probe.elf").is_file());
}

#[test]
fn an_operating_system_project_passes_at_once() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "os", "--os"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let tested = scorpion(&dir.path().join("os"), &["test"]);
    assert_eq!(tested.status.code(), Some(0), "{}", transcript(&tested));
}

#[test]
fn errors_in_the_project_file_name_its_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("Scorpion.toml"),
        "[project]\nname = \"bad\"\n\n[[image]]\nname = \"bad\"\nsourcse = [\"bad.s\"]\n",
    )
    .expect("write the project");
    let output = scorpion(dir.path(), &["test"]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let text = transcript(&output).replace(dir.path().to_str().expect("UTF-8"), "[TMP]");
    insta::assert_snapshot!(text);
}

#[test]
fn outside_a_project_test_says_what_it_looked_for() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let output = scorpion(dir.path(), &["test"]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    assert!(
        String::from_utf8_lossy(&output.stderr).contains("no Scorpion.toml in"),
        "{}",
        transcript(&output)
    );
}

#[test]
fn the_examples_are_a_workspace_whose_members_pass_their_tests() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let suite = scorpion(&examples, &["test"]);
    assert_eq!(suite.status.code(), Some(0), "{}", transcript(&suite));
    insta::assert_snapshot!("examples_workspace_test", stdout(&suite));
    // Each member is a project of its own as well.
    let alone = scorpion(&examples.join("adc"), &["test"]);
    assert_eq!(alone.status.code(), Some(0), "{}", transcript(&alone));
    assert!(stdout(&alone).ends_with("5 passed, 0 failed\n"));
}

/// A workspace of two fresh projects: `build` and `test` run both; a
/// failing member fails the run and the others still run; `upload` and
/// `test --port` say to go into a member.
#[test]
fn a_workspace_builds_and_tests_its_members() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for name in ["one", "two"] {
        let made = scorpion(dir.path(), &["new", name]);
        assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    }
    let file = dir.path().join("Scorpion.toml");
    std::fs::write(&file, "[workspace]\nmembers = [\"one\", \"two\"]\n").expect("write");
    let built = scorpion(dir.path(), &["build"]);
    assert_eq!(built.status.code(), Some(0), "{}", transcript(&built));
    assert!(dir.path().join("two/target/scorpion/two.elf").is_file());
    let tested = scorpion(dir.path(), &["test"]);
    assert_eq!(tested.status.code(), Some(0), "{}", transcript(&tested));
    let text = stdout(&tested);
    assert!(
        text.contains("== one\n") && text.contains("two: 5 passed, 0 failed\n"),
        "{text}"
    );
    assert!(text.ends_with("10 passed, 0 failed\n"), "{text}");

    // The first member's transcript now expects another answer.
    std::fs::write(dir.path().join("one/tests/one.expect"), "/1V => V09\n").expect("write");
    let failing = scorpion(dir.path(), &["test"]);
    assert_eq!(failing.status.code(), Some(1), "{}", transcript(&failing));
    let text = stdout(&failing);
    assert!(text.contains("one: 4 passed, 1 failed\n"), "{text}");
    assert!(text.contains("two: 5 passed, 0 failed\n"), "{text}");
    assert!(text.ends_with("9 passed, 1 failed\n"), "{text}");

    for args in [&["upload", "--port", "emu"][..], &["test", "--port", "emu"]] {
        let refused = scorpion(dir.path(), args);
        assert_eq!(refused.status.code(), Some(1), "{}", transcript(&refused));
        assert!(
            transcript(&refused).contains("workspace"),
            "{args:?}: {}",
            transcript(&refused)
        );
    }
}

#[test]
fn workspace_errors_name_the_file_and_the_member() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let file = dir.path().join("Scorpion.toml");
    std::fs::write(&file, "[workspace]\nmembers = [\"gone\"]\n").expect("write");
    let missing = scorpion(dir.path(), &["test"]);
    assert_eq!(missing.status.code(), Some(1), "{}", transcript(&missing));
    assert!(
        transcript(&missing).contains("member `gone` has no Scorpion.toml"),
        "{}",
        transcript(&missing)
    );
    std::fs::write(&file, "[workspace]\nmembers = [\"a\"]\nname = \"x\"\n").expect("write");
    let extra = scorpion(dir.path(), &["test"]);
    assert_eq!(extra.status.code(), Some(1), "{}", transcript(&extra));
    assert!(
        transcript(&extra).contains("Scorpion.toml:3:1"),
        "{}",
        transcript(&extra)
    );
}

#[test]
fn a_transcript_line_can_bound_the_answers_robot_time() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "timed"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("timed");
    let file = project.join("tests/timed.expect");
    // /1V and V01 are 3 + 4 characters at 9600 baud: about 7.3 ms of line.
    std::fs::write(&file, "/1V => V01 within 10ms\n").expect("write");
    let fast = scorpion(&project, &["test"]);
    assert_eq!(fast.status.code(), Some(0), "{}", transcript(&fast));
    std::fs::write(&file, "/1V => V01 within 2ms\n").expect("write");
    let slow = scorpion(&project, &["test"]);
    assert_eq!(slow.status.code(), Some(1), "{}", transcript(&slow));
    let text = stdout(&slow);
    assert!(
        text.contains("expected `an answer within 2000 us`"),
        "{text}"
    );
    std::fs::write(&file, "/1V => V01 within soon\n").expect("write");
    let bad = scorpion(&project, &["test"]);
    assert!(
        stdout(&bad).contains("is not a time"),
        "{}",
        transcript(&bad)
    );
}

#[test]
fn the_readmes_project_section_runs_as_written() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = crate::path_with_scorpion();
    let script = crate::readme_block("## A project", "sh");
    let output = std::process::Command::new("sh")
        .arg("-e")
        .arg("-c")
        .arg(format!("exec 2>&1\n{script}"))
        .current_dir(dir.path())
        .env("PATH", &path)
        .env("NO_COLOR", "1")
        .env_remove("SCORPION_PORT")
        .env_remove("SCORPION_BAUD")
        .output()
        .expect("sh runs");
    assert!(output.status.success(), "{}", transcript(&output));
    assert_eq!(
        String::from_utf8_lossy(&output.stdout),
        crate::readme_block("## A project", "text"),
        "README.md's project section is stale"
    );
}

/// `scorpion test --port` uploads and runs the transcripts only; the port
/// comes from the user's file when the project does not name one, and
/// `SCORPION_PORT` overrides both.
#[test]
fn test_on_a_robot_takes_the_port_from_the_user_or_the_environment() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "robo"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("robo");
    let config = dir.path().join("config");
    std::fs::create_dir_all(config.join("scorpion")).expect("mkdir");
    let run = |extra: &[(&str, &str)]| {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_scorpion"));
        command
            .args(["test", "--port"])
            .current_dir(&project)
            .env("NO_COLOR", "1")
            .env("XDG_CONFIG_HOME", &config)
            .env_remove("SCORPION_PORT");
        for (key, value) in extra {
            command.env(key, value);
        }
        command.output().expect("runs")
    };
    let none = run(&[]);
    assert_eq!(none.status.code(), Some(1), "{}", transcript(&none));
    assert!(String::from_utf8_lossy(&none.stderr).contains("no port for the robot"));

    std::fs::write(
        config.join("scorpion/config.toml"),
        "[robot]\nport = \"emu\"\n",
    )
    .expect("write");
    let mine = run(&[]);
    assert_eq!(mine.status.code(), Some(0), "{}", transcript(&mine));
    let text = stdout(&mine);
    assert!(text.contains("test upload robo ... ok"), "{text}");
    assert!(!text.contains("listing"), "no snapshots on a robot: {text}");

    std::fs::write(
        config.join("scorpion/config.toml"),
        "[robot]\nport = \"/dev/null/none\"\n",
    )
    .expect("write");
    let env = run(&[("SCORPION_PORT", "emu")]);
    assert_eq!(env.status.code(), Some(0), "{}", transcript(&env));

    std::fs::write(config.join("scorpion/config.toml"), "[robot]\nprot = 1\n").expect("write");
    let broken = run(&[]);
    assert_eq!(broken.status.code(), Some(1), "{}", transcript(&broken));
    assert!(
        String::from_utf8_lossy(&broken.stderr).contains("config.toml:2:1"),
        "{}",
        transcript(&broken)
    );
}

#[test]
fn upload_in_a_project_builds_and_rehearses_with_its_cards() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "up"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("up");
    let output = scorpion(
        &project,
        &["upload", "--port", "emu", "--expect", "tests/up.expect"],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = stdout(&output);
    assert!(text.contains("rehearsed on the virtual Scorpion"), "{text}");
    assert!(text.contains("< V01"), "{text}");
    assert!(project.join("target/scorpion/up.elf").is_file());
}

#[test]
fn a_project_can_name_its_rom_profile() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "withrom"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("withrom");
    std::fs::write(project.join("rom.elf"), romlib::ROM_ELF).expect("write the profile");
    let file = project.join("Scorpion.toml");
    let text = std::fs::read_to_string(&file).expect("the project");
    std::fs::write(&file, format!("{text}rom = \"rom.elf\"\n")).expect("edit");
    let tested = scorpion(&project, &["test"]);
    assert_eq!(tested.status.code(), Some(0), "{}", transcript(&tested));
    std::fs::write(&file, format!("{text}rom = \"missing.elf\"\n")).expect("edit");
    let missing = scorpion(&project, &["test"]);
    assert_eq!(missing.status.code(), Some(1), "{}", transcript(&missing));
    assert!(
        transcript(&missing).contains("missing.elf"),
        "{}",
        transcript(&missing)
    );
}

#[test]
fn routine_calls_check_registers_memory_and_cycles() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "calls"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("calls");
    let source = project.join("src/calls.s");
    let mut text = std::fs::read_to_string(&source).expect("the source");
    text.push_str(
        "\n; Routines for tests/calls.calls.\ndouble: asl a\n        rts\nclear:  lda #0\n        sta buffer\n        sta buffer+1\n        rts\n        .bss\nbuffer: .res 2\n",
    );
    std::fs::write(&source, text).expect("edit");
    std::fs::write(
        project.join("tests/calls.calls"),
        "# routine-level tests\ncall double A=$21 => A=$42 C=0 within 20 cycles\ncall clear buffer=FF FF => buffer=00 00\n",
    )
    .expect("write");
    let passed = scorpion(&project, &["test", "--accept"]);
    assert_eq!(passed.status.code(), Some(0), "{}", transcript(&passed));
    let text = stdout(&passed);
    assert!(
        text.contains("test call tests/calls.calls:2 double ... ok"),
        "{text}"
    );
    assert!(
        text.contains("test call tests/calls.calls:3 clear ... ok"),
        "{text}"
    );

    std::fs::write(
        project.join("tests/calls.calls"),
        "call double A=$81 => A=$02 C=0\n",
    )
    .expect("write");
    let failed = scorpion(&project, &["test"]);
    assert_eq!(failed.status.code(), Some(1), "{}", transcript(&failed));
    let text = stdout(&failed);
    assert!(text.contains("C=$01, expected $00"), "{text}");
    std::fs::write(project.join("tests/calls.calls"), "call nowhere => A=0\n").expect("write");
    let unknown = scorpion(&project, &["test"]);
    assert!(
        stdout(&unknown).contains("line 1: `nowhere` is neither an address nor a symbol"),
        "{}",
        transcript(&unknown)
    );
    std::fs::write(
        project.join("tests/calls.calls"),
        "call double A=$01 => A=$02 within 5 cycles\n",
    )
    .expect("write");
    let slow = scorpion(&project, &["test"]);
    assert!(
        stdout(&slow).contains("did not return within 5 cycles"),
        "{}",
        transcript(&slow)
    );
    // A hook handler ends in the ROM (`jmp CMD_DONE`): the failure says
    // why it never comes back.
    std::fs::write(
        project.join("tests/calls.calls"),
        "call handler A=$56 X=$01 => A=$56\n",
    )
    .expect("write");
    let handler = scorpion(&project, &["test"]);
    assert!(
        stdout(&handler).contains("it is in the ROM, and a routine that ends by jumping there"),
        "{}",
        transcript(&handler)
    );
}

#[test]
fn sim_in_a_project_takes_overrides_part_by_part() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "over"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("over");
    std::fs::write(project.join("wall.rhai"), "fn init() { bumpers(0x04); }\n").expect("write");
    // --world replaces the surroundings only: the project's image is there.
    let output = crate::scorpion_with_input(
        Some(&project),
        &["sim", "--world", "wall.rhai"],
        "/1V\n/1B\n",
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    assert_eq!(stdout(&output), "V01\nB04\n", "{}", transcript(&output));
    // --image replaces the images: /1V is nobody's then.
    let other = scorpion(&project, &["build"]);
    assert_eq!(other.status.code(), Some(0), "{}", transcript(&other));
    std::fs::copy(
        project.join("target/scorpion/over.elf"),
        project.join("copy.elf"),
    )
    .expect("copy");
    let output =
        crate::scorpion_with_input(Some(&project), &["sim", "--image", "copy.elf"], "/1V\n");
    assert_eq!(stdout(&output), "V01\n", "{}", transcript(&output));
    assert!(!String::from_utf8_lossy(&output.stderr).contains("from Scorpion.toml"));
}

/// An image whose target is an ld65 configuration: a ca65 project's own
/// `.cfg` builds the image, and a mistake in it is named at its line.
#[test]
fn an_image_links_with_its_ld65_configuration() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("Scorpion.toml"),
        "[project]\nname = \"cfg\"\n\n[[image]]\nname = \"os\"\nsources = [\"os.s\"]\ntarget = \"os.cfg\"\n",
    )
    .expect("write the project");
    std::fs::write(
        dir.path().join("os.s"),
        "        .code\nstart:  jmp start\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("os.cfg"),
        "MEMORY { KIM: start = $2000, size = $1000; }\nSEGMENTS { CODE: load = KIM, type = ro; }\n",
    )
    .expect("write");
    let built = scorpion(dir.path(), &["build"]);
    assert_eq!(built.status.code(), Some(0), "{}", transcript(&built));
    let image = std::fs::read(dir.path().join("target/scorpion/os.elf")).expect("the image");
    let image = linker::Image::parse("os.elf", &image).expect("an image");
    assert_eq!(image.areas[0].load, 0x2000);
    assert_eq!(image.areas[0].bytes, [0x4C, 0x00, 0x20]);
    std::fs::write(
        dir.path().join("os.cfg"),
        "MEMORY { KIM: start = $2000, size = $1000; }\nSEGMENTS { CODE: load = KIM, typ = ro; }\n",
    )
    .expect("write");
    let broken = scorpion(dir.path(), &["build"]);
    assert_eq!(broken.status.code(), Some(1), "{}", transcript(&broken));
    assert!(
        transcript(&broken).contains("os.cfg:2:"),
        "{}",
        transcript(&broken)
    );
}

/// An upload's rehearsal says every expectation line the image does not
/// meet, each at its `file:line`, and touches nothing.
#[test]
fn a_failing_rehearsal_names_every_line_that_differs() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "twice"]);
    assert_eq!(made.status.code(), Some(0), "{}", transcript(&made));
    let project = dir.path().join("twice");
    std::fs::write(
        project.join("wrong.expect"),
        "# two lines wrong\n/1V => V02\n/1X => X00\n/1V => V03\n",
    )
    .expect("write");
    let output = scorpion(
        &project,
        &["upload", "--port", "emu", "--expect", "wrong.expect"],
    );
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let text = transcript(&output);
    assert!(text.contains("wrong.expect: 2 of 3 lines"), "{text}");
    assert!(
        text.contains(
            "wrong.expect:2: `/1V` answered `V01`, expected `V02` (at 0.000 ms of robot time"
        ),
        "{text}"
    );
    assert!(
        text.contains("wrong.expect:4: `/1V` answered `V01`, expected `V03` (at "),
        "{text}"
    );
    assert!(!text.contains("uploaded and verified"), "{text}");
}
