//! `scorpion profile` on the examples' projects: the tables name their
//! routines and commands, and the folded stacks and the flame graph hold
//! them (checked for content, not only for existence).

use std::path::Path;

use crate::{copy_dir, lines_with, scorpion, transcript};

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// Profiles `examples/NAME` into `out`: the report, the folded stacks,
/// the SVG.
fn profile(name: &str, out: &Path) -> (String, String, String) {
    let folded = out.join(format!("{name}.folded"));
    let svg = out.join(format!("{name}.svg"));
    let output = scorpion(
        &example(name),
        &[
            "profile",
            "--folded",
            folded.to_str().expect("UTF-8"),
            "--flamegraph",
            svg.to_str().expect("UTF-8"),
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    (
        String::from_utf8_lossy(&output.stdout).into_owned(),
        std::fs::read_to_string(&folded).expect("the folded stacks"),
        std::fs::read_to_string(&svg).expect("the flame graph"),
    )
}

#[test]
fn the_adc_extension_profiled_by_routine_command_and_line() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let (report, folded, svg) = profile("adc", out.path());
    // Its transcript sends /2A three times (two channels, one refused)
    // and the ROM's /1X once.
    let row = |key: &str| {
        report
            .lines()
            .find(|line| line.starts_with(key))
            .unwrap_or_else(|| panic!("no `{key}` row in:\n{report}"))
            .to_owned()
    };
    let a = row("/2A ");
    let fields: Vec<&str> = a.split_whitespace().collect();
    assert_eq!(fields[1], "3", "three /2A runs: {a}");
    assert!(a.contains("adc.expect:"), "the worst run's line: {a}");
    assert!(row("/1X ").split_whitespace().nth(1) == Some("1"));
    assert!(
        report.contains("one character at 9600 baud: 1041 cycles"),
        "{report}"
    );
    // The ROM's services the handler calls are routines; IRQ a root.
    for routine in ["PUTCH", "PUTHEX", "IRQ", "main"] {
        assert!(
            report.lines().any(|l| l.starts_with(routine)),
            "no {routine} in:\n{report}"
        );
    }
    // The busy wait on the card's status (`@wait: bit ADC_STATUS`, 15
    // laps a conversion) is the hottest line of adc.s.
    let hot = report
        .lines()
        .find(|line| line.starts_with("adc.s:"))
        .unwrap_or_else(|| panic!("no adc.s line in:\n{report}"));
    assert!(hot.starts_with("adc.s:43 "), "{hot}");
    let runs: u64 = hot
        .split_whitespace()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .expect("runs");
    assert_eq!(runs % 2, 0, "two conversions, the same laps each: {hot}");
    // The stacks: a command's frame under the loop, its calls under it.
    assert!(
        folded.lines().any(|l| l.starts_with("main;/2A0;PUTHEX")),
        "{folded}"
    );
    assert!(folded.lines().any(|l| l.starts_with("IRQ")), "{folded}");
    let total: u64 = folded
        .lines()
        .map(|l| {
            l.rsplit(' ')
                .next()
                .and_then(|n| n.parse::<u64>().ok())
                .expect("a count")
        })
        .sum();
    assert!(
        report.starts_with(&format!("{total} cycles of robot time profiled")),
        "{report}"
    );
    assert!(svg.starts_with("<?xml") && svg.contains("<svg"), "an SVG");
    assert!(
        svg.contains("/2A0") && svg.contains("PUTHEX"),
        "the flame graph names the stacks"
    );
}

#[test]
fn the_patrol_operating_system_profiled() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let (report, folded, svg) = profile("patrol", out.path());
    assert!(report.contains("/2A "), "{report}");
    assert!(folded.contains("main;/2A1"), "{folded}");
    assert!(svg.contains("<svg"));
}

#[test]
fn a_workspace_is_profiled_member_by_member() {
    let output = scorpion(&example(""), &["profile"]);
    assert!(!output.status.success());
    assert!(
        String::from_utf8_lossy(&output.stderr).contains("members run on robots of their own"),
        "{}",
        transcript(&output)
    );
}

/// The 1-based numbers of the lines of `text` that contain `what`.
fn stdout(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// A new project's transcript sends only `/1V`: its handler's two
/// `bne not_mine` are never taken and its chain `JMP` (the built-in
/// `SCORPION_CHAIN_UNKNOWN`, counted at the line that uses it) never
/// runs, and coverage says so, line by line, in the summary, the LCOV
/// file and the HTML page. Two more transcript lines (a `/2V0` and a
/// `/1W`, neither the extension's) take both and run it, and coverage is
/// whole.
#[test]
fn a_branch_never_taken_is_named_until_a_transcript_takes_it() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (project, source) = crate::new_project(dir.path());
    let branches = lines_with(&source, "bne not_mine");
    assert_eq!(branches.len(), 2, "{source}");

    let first = scorpion(&project, &["test", "--coverage"]);
    assert!(first.status.success(), "{}", transcript(&first));
    let text = stdout(&first);
    for line in &branches {
        assert!(
            text.contains(&format!("  branch never taken: src/myext.s:{line}\n")),
            "{text}"
        );
    }
    let chain = lines_with(&source, "SCORPION_CHAIN_UNKNOWN");
    assert_eq!(chain.len(), 1, "{source}");
    assert!(
        text.contains(&format!("  never run: src/myext.s:{}\n", chain[0])),
        "/1V never goes down the chain: {text}"
    );
    assert_eq!(
        text.matches("never run:").count(),
        1,
        "/1V runs every other line: {text}"
    );
    assert!(text.contains("branches (50.0%)"), "{text}");
    let lcov = std::fs::read_to_string(project.join("target/scorpion/coverage/lcov.info"))
        .expect("lcov.info");
    let sf = project.join("src/myext.s");
    assert!(lcov.contains(&format!("SF:{}\n", sf.display())), "{lcov}");
    for line in &branches {
        assert!(
            lcov.contains(&format!("BRDA:{line},0,0,0\n")),
            "never taken: {lcov}"
        );
        assert!(
            lcov.contains(&format!("BRDA:{line},0,1,1\n")),
            "not taken once: {lcov}"
        );
        assert!(lcov.contains(&format!("DA:{line},1\n")), "{lcov}");
    }
    assert!(
        lcov.contains("BRF:4\nBRH:2\n") && lcov.ends_with("end_of_record\n"),
        "{lcov}"
    );
    let html = std::fs::read_to_string(project.join("target/scorpion/coverage/index.html"))
        .expect("index.html");
    assert!(
        html.contains("never taken") && html.contains("cmp #'V'"),
        "the page shows the source and the branch: {html}"
    );

    // genhtml, the LCOV tool, reads the file.
    if let Some(genhtml) = scorpion_tests::tools::require(
        "genhtml",
        "a_branch_never_taken_is_named_until_a_transcript_takes_it",
    ) {
        let out = dir.path().join("genhtml");
        let read = std::process::Command::new(genhtml)
            .args(["--branch-coverage", "--output-directory"])
            .arg(&out)
            .arg(project.join("target/scorpion/coverage/lcov.info"))
            .output()
            .expect("genhtml runs");
        assert!(read.status.success(), "{}", transcript(&read));
        assert!(out.join("index.html").is_file());
    }

    let expect = project.join("tests/myext.expect");
    let mut transcript_text = std::fs::read_to_string(&expect).expect("the transcript");
    transcript_text.push_str("/2V0 => nothing           # not /1V: on down the chain\n");
    transcript_text.push_str("/1W => nothing            # not V either\n");
    std::fs::write(&expect, transcript_text).expect("write");
    let second = scorpion(&project, &["test", "--coverage"]);
    assert!(second.status.success(), "{}", transcript(&second));
    let text = stdout(&second);
    assert!(
        text.contains("lines (100.0%), 4 of 4 branches (100.0%)"),
        "{text}"
    );
    assert!(!text.contains("branch never taken"), "{text}");
    assert!(!text.contains("never run"), "{text}");
}

/// The cycles of a built-in macro's code (`SCORPION_CHAIN_UNKNOWN`'s
/// `JMP`, written in `scorpion.inc`) are the user's line that called it
/// in the profile's hot lines, as in the coverage and the debuggers (the
/// old report said `scorpion.inc:80`, a file the user cannot open).
#[test]
fn a_built_in_macros_cycles_are_the_calling_lines() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (project, source) = crate::new_project(dir.path());
    let chain = lines_with(&source, "SCORPION_CHAIN_UNKNOWN");
    assert_eq!(chain.len(), 1, "{source}");
    let expect = project.join("tests/myext.expect");
    let mut transcript_text = std::fs::read_to_string(&expect).expect("the transcript");
    transcript_text.push_str("/1W => nothing            # down the chain\n");
    std::fs::write(&expect, transcript_text).expect("write");
    let output = scorpion(&project, &["profile", "--limit", "100"]);
    assert!(output.status.success(), "{}", transcript(&output));
    let text = stdout(&output);
    let row = text
        .lines()
        .find(|l| l.starts_with(&format!("src/myext.s:{} ", chain[0])))
        .unwrap_or_else(|| panic!("no row for the chain's line: {text}"));
    let runs: Vec<&str> = row.split_whitespace().collect();
    assert_eq!(runs[1], "1", "one /1W ran the JMP once (3 cycles): {row}");
    assert_eq!(runs[2], "3", "{row}");
    assert!(!text.contains("scorpion.inc"), "{text}");
}

/// The examples' projects covered: each one's LCOV names its source with
/// lines run, and its HTML page shows the source.
#[test]
fn the_examples_projects_covered() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, source) in [
        ("adc", "adc.s"),
        ("patrol", "patrol.s"),
        ("checksum", "checksum.s"),
    ] {
        let project = dir.path().join(name);
        copy_dir(&example(name), &project);
        let output = scorpion(&project, &["test", "--coverage"]);
        assert!(output.status.success(), "{}", transcript(&output));
        assert!(
            stdout(&output).contains("coverage: "),
            "{}",
            transcript(&output)
        );
        let lcov = std::fs::read_to_string(project.join("target/scorpion/coverage/lcov.info"))
            .expect("lcov.info");
        assert!(
            lcov.contains(&format!("SF:{}\n", project.join(source).display())),
            "{lcov}"
        );
        let hit: usize = lcov
            .lines()
            .find_map(|l| l.strip_prefix("LH:"))
            .and_then(|n| n.parse().ok())
            .expect("LH");
        assert!(hit > 0, "{name}: no line run:\n{lcov}");
        let html = std::fs::read_to_string(project.join("target/scorpion/coverage/index.html"))
            .expect("index.html");
        assert!(
            html.contains(source) && html.contains("class=\"run\""),
            "{name}"
        );
    }
}

/// A budget in the project file fails the test run when a command goes
/// over it, naming the transcript line and the stack; a generous one
/// passes.
#[test]
fn a_command_over_its_budget_fails_the_tests() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = dir.path().join("adc");
    copy_dir(&example("adc"), &project);
    let file = project.join("Scorpion.toml");
    let original = std::fs::read_to_string(&file).expect("the project file");
    std::fs::write(
        &file,
        format!("{original}\n[budgets]\n\"/2A\" = 100\nPUTHEX = 100000\n"),
    )
    .expect("write");
    let over = scorpion(&project, &["test"]);
    assert!(!over.status.success(), "{}", transcript(&over));
    let text = stdout(&over);
    assert!(text.contains("test budget /2A ... FAILED"), "{text}");
    assert!(
        text.contains("over its budget of 100 at adc.expect:"),
        "{text}"
    );
    assert!(text.contains("(stack: main;/2A"), "{text}");
    assert!(text.contains("test budget PUTHEX ... ok"), "{text}");

    std::fs::write(&file, format!("{original}\n[budgets]\n\"/2A\" = 100000\n")).expect("write");
    let within = scorpion(&project, &["test"]);
    assert!(within.status.success(), "{}", transcript(&within));
    assert!(stdout(&within).contains("test budget /2A ... ok"));
}

/// README's profiling section, run as written: every line its output
/// block shows comes out, and the flame graph and the coverage report are
/// there with what they show.
#[test]
fn the_readmes_profiling_section_runs_as_written() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let heading = "## Where the cycles go";
    let script = crate::readme_block(heading, "sh");
    let output = std::process::Command::new("sh")
        .arg("-e")
        .arg("-c")
        .arg(format!("exec 2>&1\n{script}"))
        .current_dir(dir.path())
        .env("PATH", crate::path_with_scorpion())
        .env("NO_COLOR", "1")
        .env_remove("SCORPION_PORT")
        .env_remove("SCORPION_BAUD")
        .output()
        .expect("sh runs");
    assert!(output.status.success(), "{}", transcript(&output));
    let text = stdout(&output);
    for line in crate::readme_block(heading, "text").lines() {
        assert!(
            text.contains(line),
            "README.md's profiling section is stale: `{line}` is not in\n{text}"
        );
    }
    let project = dir.path().join("myext");
    let svg = std::fs::read_to_string(project.join("target/scorpion/flamegraph.svg"))
        .expect("the flame graph");
    assert!(
        svg.contains("<svg") && svg.contains("/1V"),
        "the command's box"
    );
    let folded = std::fs::read_to_string(project.join("target/scorpion/profile.folded"))
        .expect("the folded stacks");
    assert!(
        folded.lines().any(|l| l.starts_with("main;/1V;PUTHEX")),
        "{folded}"
    );
    let lcov = std::fs::read_to_string(project.join("target/scorpion/coverage/lcov.info"))
        .expect("lcov.info");
    assert!(lcov.contains("myext.s") && lcov.contains("BRDA:"), "{lcov}");
    let html = std::fs::read_to_string(project.join("target/scorpion/coverage/index.html"))
        .expect("index.html");
    assert!(html.contains("jsr PUTCH"), "the page shows the source");
}

/// `--folded F --flamegraph F`: the SVG would overwrite the folded stacks
/// silently; the same path twice is refused, before anything runs.
#[test]
fn the_same_file_for_folded_stacks_and_flame_graph_is_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let same = dir.path().join("out");
    let same = same.to_str().expect("UTF-8");
    let output = scorpion(
        &example("adc"),
        &["profile", "--folded", same, "--flamegraph", same],
    );
    assert!(!output.status.success(), "{}", transcript(&output));
    let said = transcript(&output);
    assert!(said.contains("name the same file"), "{said}");
    assert!(!dir.path().join("out").exists(), "nothing written");
}

/// Coverage of a project with no code line: no lcov.info without records
/// (genhtml rejects it) and no "0 of 0 lines (100%)".
#[test]
fn coverage_of_a_project_with_no_code_says_there_is_nothing_to_cover() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = dir.path().join("empty");
    std::fs::create_dir_all(project.join("src")).expect("src");
    std::fs::create_dir_all(project.join("tests")).expect("tests");
    std::fs::write(
        project.join("Scorpion.toml"),
        "[project]\nname = \"empty\"\n\n[[image]]\nname = \"empty\"\nsources = [\"src/main.s\"]\n",
    )
    .expect("write");
    std::fs::write(project.join("src/main.s"), "; nothing\n").expect("write");
    std::fs::write(project.join("tests/t.expect"), "/1X => X00\n").expect("write");
    let output = scorpion(&project, &["test", "--coverage"]);
    let said = transcript(&output);
    assert!(said.contains("nothing to cover"), "{said}");
    assert!(!said.contains("0 of 0 lines"), "{said}");
    assert!(
        !project.join("target/scorpion/coverage/lcov.info").exists(),
        "no lcov.info without records"
    );
}

/// The help for an unknown Scorpion.toml key lists every table, `[budgets]`
/// among them.
#[test]
fn the_project_files_key_list_names_budgets() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("Scorpion.toml"),
        "[project]\nname = \"k\"\nbudget = 3\n",
    )
    .expect("write");
    let output = scorpion(dir.path(), &["test"]);
    assert!(!output.status.success(), "{}", transcript(&output));
    let said = transcript(&output);
    assert!(said.contains("[robot]"), "the key list is shown: {said}");
    assert!(said.contains("[budgets]"), "{said}");
}

/// `--speedscope FILE`: speedscope's "sampled" JSON, read back with
/// serde: its weights add up to the cycles the report says it profiled,
/// and its frames name the command and the routines.
#[test]
fn the_speedscope_file_holds_the_profiles_cycles() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let file = dir.path().join("adc.speedscope.json");
    let output = scorpion(
        &example("adc"),
        &[
            "profile",
            "--folded",
            dir.path().join("f").to_str().expect("UTF-8"),
            "--flamegraph",
            dir.path().join("s.svg").to_str().expect("UTF-8"),
            "--speedscope",
            file.to_str().expect("UTF-8"),
        ],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    let report = stdout(&output);
    let total: u64 = report
        .split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .expect("N cycles of robot time profiled");
    let text = std::fs::read_to_string(&file).expect("the speedscope file");
    let read: scorpion_profile::speedscope::File =
        serde_json::from_str(&text).expect("speedscope's schema");
    let sampled = &read.profiles[0];
    assert_eq!(sampled.kind, "sampled");
    assert_eq!(sampled.weights.iter().sum::<u64>(), total);
    let names: Vec<&str> = read.shared.frames.iter().map(|f| f.name.as_str()).collect();
    for name in ["main", "/2A0", "PUTHEX", "IRQ"] {
        assert!(names.contains(&name), "{names:?}");
    }
}

/// The adc example copied into `dir/name` with `budgets` as its project
/// file's `[budgets]` table.
fn adc_with_budgets(dir: &Path, name: &str, budgets: &str) -> std::path::PathBuf {
    let project = dir.join(name);
    copy_dir(&example("adc"), &project);
    let file = project.join("Scorpion.toml");
    let original = std::fs::read_to_string(&file).expect("the project file");
    let renamed = original.replace(
        "name = \"adc\"\n\n[[image]]",
        &format!("name = \"{name}\"\n\n[[image]]"),
    );
    std::fs::write(&file, format!("{renamed}\n[budgets]\n{budgets}\n")).expect("write");
    project
}

/// `scorpion test --port` rehearses the transcripts on the virtual
/// Scorpion: a command over its budget there fails the rehearsal, and
/// nothing is sent to the robot (issue 26 F4).
#[test]
fn a_budget_fails_the_rehearsal_of_test_port() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = adc_with_budgets(dir.path(), "adc", "\"/2A\" = 100");
    let output = scorpion(&project, &["test", "--port", "emu"]);
    assert!(!output.status.success(), "{}", transcript(&output));
    let text = stdout(&output);
    assert!(text.contains("test budget /2A ... FAILED"), "{text}");
    assert!(
        text.contains("over its budget of 100 at adc.expect:"),
        "{text}"
    );
    assert!(
        text.contains("nothing was sent to the robot"),
        "the upload is not attempted: {text}"
    );
}

/// A routine that only a `.calls` test runs is a routine of the profile
/// (a root: nothing of the robot's called it), so its budget is checked
/// (issue 26 F5): `double` is `ASL A` (2) and `RTS` (6).
#[test]
fn a_routine_run_only_by_a_calls_test_is_budgeted() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let made = scorpion(dir.path(), &["new", "calls"]);
    assert!(made.status.success(), "{}", transcript(&made));
    let project = dir.path().join("calls");
    let source = project.join("src/calls.s");
    let mut text = std::fs::read_to_string(&source).expect("the source");
    text.push_str("\ndouble: asl a\n        rts\n");
    std::fs::write(&source, text).expect("edit");
    std::fs::write(
        project.join("tests/calls.calls"),
        "call double A=$21 => A=$42\n",
    )
    .expect("write");
    let file = project.join("Scorpion.toml");
    let original = std::fs::read_to_string(&file).expect("the project file");
    std::fs::write(&file, format!("{original}\n[budgets]\ndouble = 7\n")).expect("write");
    let over = scorpion(&project, &["test", "--accept"]);
    assert!(!over.status.success(), "{}", transcript(&over));
    let said = stdout(&over);
    assert!(said.contains("test budget double ... FAILED"), "{said}");
    assert!(
        said.contains("routine double took 8 cycles, over its budget of 7"),
        "{said}"
    );
    assert!(said.contains("(stack: double)"), "a root: {said}");

    std::fs::write(&file, format!("{original}\n[budgets]\ndouble = 8\n")).expect("write");
    let within = scorpion(&project, &["test"]);
    assert!(within.status.success(), "{}", transcript(&within));
    assert!(stdout(&within).contains("test budget double ... ok"));
}

/// `scorpion test NAME` runs some tests only: a budget on what only the
/// others run says so and does not fail (issue 26 F6); unfiltered, the
/// same budget on nothing the tests run fails.
#[test]
fn a_filter_leaves_the_budgets_of_what_it_left_out_unchecked() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let project = adc_with_budgets(dir.path(), "adc", "\"/2A\" = 100000\nnowhere = 10");
    let filtered = scorpion(&project, &["test", "adc/listing"]);
    let said = stdout(&filtered);
    assert!(filtered.status.success(), "{}", transcript(&filtered));
    assert!(
        said.contains("test budget /2A ... not run (the tests that would run it are filtered out)"),
        "{said}"
    );
    assert!(said.contains("test budget nowhere ... not run"), "{said}");
    assert!(said.contains("1 passed, 0 failed, "), "{said}");

    let all = scorpion(&project, &["test"]);
    let said = stdout(&all);
    assert!(!all.status.success(), "{}", transcript(&all));
    assert!(said.contains("test budget /2A ... ok"), "{said}");
    assert!(said.contains("test budget nowhere ... FAILED"), "{said}");
}

/// In a workspace, each member's budgets and coverage come with its own
/// tests, before its summary line, not after every member's (issue 26
/// F7).
#[test]
fn a_workspaces_members_report_in_order() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for name in ["one", "two"] {
        adc_with_budgets(dir.path(), name, "\"/2A\" = 100000");
    }
    std::fs::write(
        dir.path().join("Scorpion.toml"),
        "[workspace]\nmembers = [\"one\", \"two\"]\n",
    )
    .expect("write");
    let output = scorpion(dir.path(), &["test", "--coverage"]);
    assert!(output.status.success(), "{}", transcript(&output));
    let said = stdout(&output);
    let at = |what: &str, from: usize| {
        said[from..]
            .find(what)
            .map(|i| i + from)
            .unwrap_or_else(|| panic!("no `{what}` after {from} in:\n{said}"))
    };
    let one = at("== one", 0);
    let one_budget = at("test budget /2A ... ok", one);
    let one_coverage = at("coverage: ", one_budget);
    let one_done = at("one: ", one_coverage);
    let two = at("== two", one_done);
    let two_budget = at("test budget /2A ... ok", two);
    let two_coverage = at("coverage: ", two_budget);
    at("two: ", two_coverage);
}
