//! `--card FILE[@ADDR]` and `--world FILE` as a user gives them: the
//! examples' cards answering through their extensions in `scorpion sim`
//! and `scorpion ask --port emu`, and scripts that loop, do not parse or do
//! not fit stopping the run with a located error and a non-zero exit.

use std::path::Path;

use crate::{build_example, readme_block, scorpion, transcript};

fn example(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(path)
        .display()
        .to_string()
}

/// `scorpion sim ARGS` in `dir` with `input` on stdin; the exit code and
/// the transcript with the paths made stable.
fn sim_in(dir: &Path, args: &[&str], input: &str) -> (i32, String) {
    let mut all = vec!["sim"];
    all.extend(args);
    let output = crate::scorpion_with_input(Some(dir), &all, input);
    let text = transcript(&output)
        .replace(&example(""), "[EXAMPLES]/")
        .replace(dir.to_str().expect("UTF-8"), "[TMP]");
    (output.status.code().unwrap_or(-1), text)
}

#[test]
fn the_rangefinder_card_script_gives_real_distances_in_sim() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    build_example(
        dir.path(),
        "rangefinder/rangefinder.s",
        "rangefinder.elf",
        &["--target", "scorpion-ext"],
    );
    let card = example("rangefinder/rangefinder.rhai");
    let (code, text) = sim_in(
        dir.path(),
        &["--image", "rangefinder.elf", "--card", &card],
        "/1U\n/1U\n",
    );
    assert_eq!(code, 0, "{text}");
    insta::assert_snapshot!(text);
    // Without its card the extension reads plain RAM: 0 cm.
    let (_, text) = sim_in(dir.path(), &["--image", "rangefinder.elf"], "/1U\n");
    assert!(text.contains("U0000"), "{text}");
}

#[test]
fn ask_on_the_virtual_scorpion_takes_cards_too() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    build_example(
        dir.path(),
        "adc/adc.s",
        "adc.elf",
        &["--target", "scorpion-ext"],
    );
    let card = format!("{}@A000", example("adc/adc.rhai"));
    // The extension reads $9000; the card moved to $A000 is not there, and
    // the extension says so rather than wait for it.
    let output = scorpion(
        dir.path(),
        &[
            "ask", "--port", "emu", "--image", "adc.elf", "--card", &card, "/2A0", "/1X",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    assert_eq!(String::from_utf8_lossy(&output.stdout), "A--\nX00\n");
    let card = example("adc/adc.rhai");
    let output = scorpion(
        dir.path(),
        &[
            "ask", "--port", "emu", "--image", "adc.elf", "--card", &card, "/2A0", "/2A1",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    assert_eq!(String::from_utf8_lossy(&output.stdout), "AC0\nA57\n");
}

/// fresh11 F10: an extension for a card, on a robot without the card,
/// answers "nothing" within a few milliseconds and the robot goes on. What
/// the card's status register reads without the card: RAM on the virtual
/// robot (as it was left), the floating bus or pull-ups on a real one.
#[test]
fn the_card_examples_answer_on_a_robot_without_their_card() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    build_example(
        dir.path(),
        "adc/adc.s",
        "adc.elf",
        &["--target", "scorpion-ext"],
    );
    build_example(
        dir.path(),
        "rangefinder/rangefinder.s",
        "rangefinder.elf",
        &["--target", "scorpion-ext"],
    );
    // ADC STATUS at $9001: as left (0), the bus floating ($90), pull-ups.
    let (code, text) = sim_in(
        dir.path(),
        &["--image", "adc.elf"],
        "/2A0\n/9W90009090\n/2A1\n/9W9000FFFF\n/2A7\n/1X\n",
    );
    assert_eq!(code, 0, "{text}");
    assert_eq!(text.matches("A--\n").count(), 3, "{text}");
    assert!(text.contains("X00"), "{text}");
    // The rangefinder's STATUS at $8001 floating with bit 7 set: "no echo".
    let (code, text) = sim_in(
        dir.path(),
        &["--image", "rangefinder.elf"],
        "/9W80008080\n/1U\n/1X\n",
    );
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("U----\n"), "{text}");
    assert!(text.contains("X00"), "{text}");
}

#[test]
fn a_card_script_that_loops_stops_the_sim_with_its_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    build_example(
        dir.path(),
        "rangefinder/rangefinder.s",
        "rangefinder.elf",
        &["--target", "scorpion-ext"],
    );
    std::fs::write(
        dir.path().join("stuck.rhai"),
        "const SIZE = 4;\nconst BASE = 0x8000;\n\n// Waits for an echo that the script itself would have to make.\nfn write(reg, value, now) {\n    while get(1) != 0 { }\n}\nfn init() { set(1, 0x80); }\n",
    )
    .expect("write the script");
    let (code, text) = sim_in(
        dir.path(),
        &["--image", "rangefinder.elf", "--card", "stuck.rhai"],
        "/1U\n",
    );
    assert_eq!(code, 1, "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn a_card_script_with_a_syntax_error_is_refused_with_its_place() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("typo.rhai"),
        "const SIZE = 4;\nconst BASE = 0x8000;\nfn read(reg, now) {\n    if reg == 1 { 0x80 } els { 0 }\n}\n",
    )
    .expect("write the script");
    let (code, text) = sim_in(dir.path(), &["--card", "typo.rhai"], "/1X\n");
    assert_eq!(code, 1, "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn cards_must_fit_the_kim_bus_and_not_each_other() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // Named relative to the run, so that no path of the machine changes
    // where miette wraps the message.
    std::fs::copy(example("adc/adc.rhai"), dir.path().join("adc.rhai")).expect("copy the card");
    let (code, text) = sim_in(dir.path(), &["--card", "adc.rhai@0400"], "");
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("is not inside the KIM bus"), "{text}");
    let (code, text) = sim_in(
        dir.path(),
        &["--card", "adc.rhai", "--card", "adc.rhai"],
        "",
    );
    assert_eq!(code, 1, "{text}");
    insta::assert_snapshot!(text);
}

/// Issue 22: cards and surroundings are the virtual Scorpion's, and never
/// stop work on a real port (the robot has its own): given as flags to a
/// command that talks to a real robot only, they are noted, not refused.
#[test]
fn cards_and_surroundings_never_stop_work_on_a_real_port() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let card = example("adc/adc.rhai");
    let output = scorpion(
        dir.path(),
        &["ask", "--port", "/dev/null", "--card", &card, "/1X"],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !stderr.contains("do not apply to the robot"),
        "{}",
        transcript(&output)
    );
    assert!(
        stderr.contains("note: --card belongs to the virtual Scorpion"),
        "{}",
        transcript(&output)
    );
}

#[test]
fn the_world_script_sets_the_bumpers_in_sim() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("wall.rhai"),
        "// Against a wall from power-up; the robot is moved away after 2 s.\nfn init() { bumpers(0x04); wake_at(ms(2000)); }\nfn wake(now) { bumpers(0); }\n",
    )
    .expect("write the script");
    let (code, text) = sim_in(dir.path(), &["--world", "wall.rhai"], "/1B\n");
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("B04"), "{text}");
}

#[test]
fn the_readmes_own_card_section_runs_as_written() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::os::unix::fs::symlink(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples"),
        dir.path().join("examples"),
    )
    .expect("link the examples");
    let path = crate::path_with_scorpion();
    let mut printed = String::new();
    for line in readme_block("## Your own card", "sh").lines() {
        let output = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("{line} 2>&1"))
            .current_dir(dir.path())
            .env("PATH", &path)
            .env("NO_COLOR", "1")
            .output()
            .expect("sh runs");
        assert!(
            output.status.success(),
            "`{line}`:\n{}",
            transcript(&output)
        );
        printed.push_str(&String::from_utf8_lossy(&output.stdout));
    }
    assert_eq!(
        printed,
        readme_block("## Your own card", "text"),
        "README.md's card section is stale"
    );
}

#[test]
fn the_readmes_room_section_runs_as_written() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::os::unix::fs::symlink(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples"),
        dir.path().join("examples"),
    )
    .expect("link the examples");
    let path = crate::path_with_scorpion();
    let mut printed = String::new();
    for line in readme_block("## Your robot in a room", "sh").lines() {
        let output = std::process::Command::new("sh")
            .arg("-c")
            .arg(line)
            .current_dir(dir.path())
            .env("PATH", &path)
            .env("NO_COLOR", "1")
            .output()
            .expect("sh runs");
        assert!(
            output.status.success(),
            "`{line}`:\n{}",
            transcript(&output)
        );
        printed.push_str(&String::from_utf8_lossy(&output.stdout));
    }
    assert_eq!(
        printed,
        readme_block("## Your robot in a room", "text"),
        "README.md's room section is stale"
    );
    let picture = std::fs::read_to_string(dir.path().join("path.svg")).expect("the picture");
    assert!(picture.starts_with("<svg "), "{picture}");
    assert!(picture.contains(">bump 10 at "), "{picture}");
    assert!(picture.contains(">/4C+40 at "), "{picture}");
}

#[test]
fn path_needs_a_room() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (code, text) = sim_in(dir.path(), &["--path", "path.svg"], "/1B\n");
    assert_eq!(code, 1, "{text}");
    assert!(
        text.contains("--path draws the robot in its room"),
        "{text}"
    );
    assert!(!dir.path().join("path.svg").exists());
}

#[test]
fn the_examples_readme_shows_the_same_card_commands() {
    let examples =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/README.md"))
            .expect("examples/README.md");
    let section = &examples[examples.find("## Your own card").expect("the section")..];
    let start = section.find("```sh\n").expect("the block") + 6;
    let end = start + section[start..].find("```").expect("its end");
    assert_eq!(&section[start..end], readme_block("## Your own card", "sh"));
}

#[test]
fn what_a_card_script_prints_shows_on_stderr_in_sim() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("chatty.rhai"),
        "const SIZE = 1;\nconst BASE = 0x9000;\nfn write(reg, value, now) { print(`written ${value} at ${now}`); }\n",
    )
    .expect("write the script");
    let (code, text) = sim_in(dir.path(), &["--card", "chatty.rhai"], "/7W900042\n/1X\n");
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("chatty.rhai: written 66 at "), "{text}");
}

#[test]
fn what_the_scripts_print_shows_on_stderr_in_ask_and_read() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("talk.rhai"),
        "fn init() { print(\"hello\"); wake_at(ms(1)); }\nfn wake(now) { print(`awake at ${now}`); }\n",
    )
    .expect("write the world");
    std::fs::write(
        dir.path().join("chatty.rhai"),
        "const SIZE = 1;\nconst BASE = 0x9000;\nfn read(reg, now) { print(`read at ${now}`); 0x42 }\nfn write(reg, value, now) { print(`written ${value} at ${now}`); }\n",
    )
    .expect("write the card");
    // `ask` runs the virtual robot itself.
    let output = scorpion(
        dir.path(),
        &[
            "ask",
            "--port",
            "emu",
            "--world",
            "talk.rhai",
            "--card",
            "chatty.rhai",
            "/7W900042",
            "/1X",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("talk.rhai: hello\n"), "{stderr}");
    assert!(stderr.contains("talk.rhai: awake at "), "{stderr}");
    assert!(stderr.contains("chatty.rhai: written 66 at "), "{stderr}");
    // `read` opens it as a line, as upload, installed and test do.
    let output = scorpion(
        dir.path(),
        &[
            "read",
            "--port",
            "emu",
            "--card",
            "chatty.rhai",
            "0x9000",
            "1",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("chatty.rhai: read at "), "{stderr}");
}

#[test]
fn a_world_or_card_fault_in_ask_is_shown_at_its_place() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("spin.rhai"),
        "fn init() { wake_at(0); }\nfn wake(now) { wake_at(now); }\n",
    )
    .expect("write the world");
    let output = scorpion(
        dir.path(),
        &["ask", "--port", "emu", "--world", "spin.rhai", "/1U"],
    );
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("the surroundings failed"), "{stderr}");
    assert!(stderr.contains("spin.rhai:2:16"), "{stderr}");
    // The snippet and the help, not only the one-line message.
    assert!(
        stderr.contains(" 2 │ fn wake(now) { wake_at(now); }"),
        "{stderr}"
    );
    assert!(stderr.contains("help: robot time stands still"), "{stderr}");

    std::fs::write(
        dir.path().join("broken.rhai"),
        "const SIZE = 1;\nconst BASE = 0x9000;\nfn write(reg, value, now) {\n    throw `no register ${reg}`;\n}\n",
    )
    .expect("write the card");
    let output = scorpion(
        dir.path(),
        &["ask", "--port", "emu", "--card", "broken.rhai", "/7W900042"],
    );
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("the card at $9000 failed"), "{stderr}");
    assert!(stderr.contains("broken.rhai:4:5"), "{stderr}");
    assert!(
        stderr.contains(" 4 │     throw `no register ${reg}`;"),
        "{stderr}"
    );
}

/// hostile13 F1: a card script that failed while `scorpion test` ran a
/// transcript (`read` returning a string): the transcript failed with
/// `AFF`, not a word of the script. Its place and fault are said.
#[test]
fn a_card_script_failing_in_a_transcript_is_named_by_scorpion_test() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = dir.path().join("adc");
    crate::copy_dir(Path::new(&example("adc")), &project);
    let script = project.join("adc.rhai");
    let text = std::fs::read_to_string(&script).expect("the card");
    let broken = text.replace(
        "    irq(false);\n    this.result\n}",
        "    irq(false);\n    \"str\"\n}",
    );
    assert_ne!(broken, text, "the card's read changed");
    std::fs::write(&script, broken).expect("written");
    let output = scorpion(&project, &["test"]);
    let printed = transcript(&output);
    assert_eq!(output.status.code(), Some(1), "{printed}");
    assert!(
        printed.contains("(the card at $9000 failed: adc.rhai:")
            && printed.contains("`read` returned a string for register 2, not a byte)"),
        "{printed}"
    );
}
