//! The VS Code extension in editors/vscode/ (issue 25, point 3) checked
//! through the node scripts kept beside it in editors/vscode/test/: its
//! grammar tokenizing the examples (vscode-textmate), a DAP session started
//! as its debugger contribution says (VS Code's own DAP test client; every
//! request issue 25 asks of an assembly debugger), its
//! problem matcher over a real `scorpion build` error, and its packaging
//! with vsce. The scripts need `npm ci` in editors/vscode (as
//! `.ci/install-test-tools` does); without it they skip here and fail in CI.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

/// How long one script may run (a DAP session on a loaded machine).
const PATIENCE: Duration = Duration::from_secs(240);

fn extension() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("editors/vscode")
}

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples")
}

/// The packages the scripts `require`, as package.json lists them.
const PACKAGES: [&str; 5] = [
    "vscode-textmate",
    "vscode-oniguruma",
    "@vscode/debugadapter-testsupport",
    "@vscode/vsce",
    "yauzl",
];

fn node(test: &str) -> Option<PathBuf> {
    scorpion_tests::tools::require_npm_packages(&extension(), &PACKAGES, test)
}

/// Runs `node SCRIPT ARGS` in the extension's directory, killed after
/// `PATIENCE` so that a script waiting forever fails the test instead.
fn run_script(node: &Path, script: &str, args: &[&str]) -> Output {
    let scratch = tempfile::tempdir().expect("a scratch directory");
    let (stdout, stderr) = (scratch.path().join("out"), scratch.path().join("err"));
    let mut child = Command::new(node)
        .arg(format!("test/{script}"))
        .args(args)
        .current_dir(extension())
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&stdout).expect("stdout file"))
        .stderr(std::fs::File::create(&stderr).expect("stderr file"))
        .spawn()
        .expect("node runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("node is waited for") {
            break status;
        }
        if start.elapsed() > PATIENCE {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "test/{script} ran longer than {PATIENCE:?}; its output:\n{}\n{}",
                std::fs::read_to_string(&stdout).unwrap_or_default(),
                std::fs::read_to_string(&stderr).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Output {
        status,
        stdout: std::fs::read(&stdout).expect("stdout"),
        stderr: std::fs::read(&stderr).expect("stderr"),
    }
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).expect("the file reads");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{} is not JSON: {e}", path.display()))
}

#[test]
fn the_manifest_grammar_and_examples_are_json_and_point_at_each_other() {
    let manifest = json(&extension().join("package.json"));
    assert_eq!(manifest["name"], "scorpion");
    let contributes = &manifest["contributes"];
    let language = &contributes["languages"][0];
    assert_eq!(language["id"], "ca65");
    assert_eq!(language["extensions"], serde_json::json!([".s", ".inc"]));
    let configuration =
        json(&extension().join(language["configuration"].as_str().expect("a path")));
    assert_eq!(configuration["comments"]["lineComment"], ";");
    let grammar_entry = &contributes["grammars"][0];
    let grammar = json(&extension().join(grammar_entry["path"].as_str().expect("a path")));
    assert_eq!(grammar["scopeName"], grammar_entry["scopeName"]);
    // The launch attribute that debugs a real robot (docs/DEBUGGING.md).
    let launch = &contributes["debuggers"][0]["configurationAttributes"]["launch"];
    assert_eq!(launch["properties"]["port"]["type"], "string", "{launch}");
    for example in ["launch.json", "tasks.json"] {
        json(&extension().join("examples").join(example));
    }
    // The tasks use the matcher the manifest contributes.
    let tasks = json(&extension().join("examples/tasks.json"));
    let matcher = format!(
        "${}",
        contributes["problemMatchers"][0]["name"]
            .as_str()
            .expect("a name")
    );
    let tasks = tasks["tasks"].as_array().expect("tasks");
    assert_eq!(tasks.len(), 3, "build, test, upload");
    for task in tasks {
        assert_eq!(task["problemMatcher"], matcher.as_str(), "{task}");
    }
}

#[test]
fn the_grammar_scopes_mnemonics_directives_and_comments_of_the_examples() {
    let test = "the_grammar_scopes_mnemonics_directives_and_comments_of_the_examples";
    let Some(node) = node(test) else { return };
    let mut sources: Vec<String> = std::fs::read_dir(examples())
        .expect("examples/")
        .filter_map(Result::ok)
        .filter(|entry| entry.path().is_dir())
        .flat_map(|dir| {
            std::fs::read_dir(dir.path())
                .expect("an example")
                .filter_map(Result::ok)
        })
        .map(|entry| entry.path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "s"))
        .map(|path| path.display().to_string())
        .collect();
    sources.sort();
    assert!(sources.len() >= 4, "the examples' sources: {sources:?}");
    let args: Vec<&str> = sources.iter().map(String::as_str).collect();
    let output = run_script(&node, "grammar.js", &args);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for source in &sources {
        let name = Path::new(source)
            .file_name()
            .expect("a name")
            .to_string_lossy();
        assert!(
            stdout.contains(&format!("{name}: ")),
            "{name} tokenized: {stdout}"
        );
    }
}

#[test]
fn a_dap_session_through_the_extensions_debugger_contribution() {
    let test = "a_dap_session_through_the_extensions_debugger_contribution";
    let Some(node) = node(test) else { return };
    let adc = examples().join("adc");
    let output = run_script(
        &node,
        "dap.js",
        &[env!("CARGO_BIN_EXE_scorpion"), adc.to_str().expect("UTF-8")],
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for step in [
        "dap: initialized",
        "dap: launched",
        "dap: stopped on entry",
        "dap: hit adc.s:",
        "dap: registers: ",
        "dap: stepped to adc.s:",
        "dap: loadedSources: adc.s",
        "dap: disassemble: 0x",
        "dap: setVariable A = $32",
        "dap: writeMemory and readMemory",
        "dap: data breakpoint: wrote $82 to $9000",
        "dap: function breakpoint at PUTHEX",
        "dap: conditional breakpoint at adc.s:",
        "dap: log point and instruction breakpoint at 0x",
        "dap: exception: BRK at $",
        "dap: restarted",
        "dap: continued",
        "dap: disconnected",
    ] {
        assert!(stdout.contains(step), "{step:?} in {stdout}");
    }
}

#[test]
fn the_problem_matcher_finds_a_build_errors_file_line_column_and_message() {
    let test = "the_problem_matcher_finds_a_build_errors_file_line_column_and_message";
    let Some(node) = node(test) else { return };
    // The planted error: `sec` misspelt in a copy of the ADC project.
    let dir = tempfile::tempdir().expect("a scratch directory");
    let project = dir.path().join("adc");
    std::fs::create_dir(&project).expect("the project's directory");
    std::fs::copy(
        examples().join("scorpion.inc"),
        dir.path().join("scorpion.inc"),
    )
    .expect("scorpion.inc");
    for entry in std::fs::read_dir(examples().join("adc")).expect("examples/adc") {
        let path = entry.expect("an entry").path();
        if path.is_file() {
            std::fs::copy(&path, project.join(path.file_name().expect("a name"))).expect("a copy");
        }
    }
    let source = std::fs::read_to_string(project.join("adc.s")).expect("adc.s");
    let line = source
        .lines()
        .position(|l| l.trim() == "sec")
        .expect("adc.s has a `sec`")
        + 1;
    let planted: Vec<String> = source
        .lines()
        .map(|l| {
            if l.trim() == "sec" {
                l.replace("sec", "sex")
            } else {
                l.to_owned()
            }
        })
        .collect();
    std::fs::write(project.join("adc.s"), planted.join("\n") + "\n").expect("the bug planted");

    let built = super::scorpion(&project, &["build"]);
    assert!(!built.status.success(), "{}", super::transcript(&built));
    let printed = project.join("build-output.txt");
    let mut text = built.stdout.clone();
    text.extend(&built.stderr);
    std::fs::write(&printed, &text).expect("the output saved");

    let output = run_script(&node, "matcher.js", &[printed.to_str().expect("UTF-8")]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let problems: Value = serde_json::from_slice(&output.stdout).expect("the problems as JSON");
    let problems = problems.as_array().expect("a list");
    assert_eq!(
        problems.len(),
        1,
        "one located error, not the summary: {problems:?}\n{}",
        String::from_utf8_lossy(&text)
    );
    let problem = &problems[0];
    assert_eq!(problem["file"], "adc.s", "{problem}");
    assert_eq!(problem["line"], line, "{problem}");
    let column = planted[line - 1].find("sex").expect("the planted line") + 1;
    assert_eq!(problem["column"], column, "{problem}");
    assert_eq!(problem["severity"], "error", "{problem}");
    assert_eq!(
        problem["message"], "`sex` is not an instruction, directive or macro",
        "{problem}"
    );
}

#[test]
fn the_extension_packages_into_a_vsix_with_its_files() {
    let test = "the_extension_packages_into_a_vsix_with_its_files";
    let Some(node) = node(test) else { return };
    let dir = tempfile::tempdir().expect("a scratch directory");
    let vsix = dir.path().join("scorpion.vsix");
    let output = run_script(&node, "package.js", &[vsix.to_str().expect("UTF-8")]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(vsix.is_file(), "the .vsix was written");
    for entry in [
        "extension/package.json",
        "extension/syntaxes/ca65.tmLanguage.json",
        "extension/language-configuration.json",
        "extension.vsixmanifest",
    ] {
        assert!(stdout.lines().any(|l| l == entry), "{entry} in {stdout}");
    }
}

/// A Lua value as docs/DEBUGGING.md's Neovim block writes them: a quoted
/// string, a boolean, or a list of strings `{ 'a', 'b' }`.
fn lua_value(text: &str) -> Value {
    let text = text.trim();
    let unquote = |s: &str| s.trim().trim_matches('\'').trim_matches('"').to_owned();
    match text {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        list if list.starts_with('{') => Value::Array(
            list.trim_start_matches('{')
                .trim_end_matches('}')
                .split(',')
                .filter(|item| !item.trim().is_empty())
                .map(|item| Value::String(unquote(item)))
                .collect(),
        ),
        quoted => Value::String(unquote(quoted)),
    }
}

#[test]
fn a_dap_session_through_the_neovim_adapter_definition_in_debugging_md() {
    let test = "a_dap_session_through_the_neovim_adapter_definition_in_debugging_md";
    let Some(node) = node(test) else { return };
    let docs =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/DEBUGGING.md"))
            .expect("docs/DEBUGGING.md");
    let section = &docs[docs.find("### Neovim").expect("the Neovim section")..];
    let start = section.find("```lua\n").expect("its Lua block") + "```lua\n".len();
    let block = &section[start..start + section[start..].find("```").expect("the block's end")];

    // `dap.adapters.scorpion = { type = 'executable', command = ..., args = { ... } }`
    let adapter = block
        .lines()
        .find(|l| l.contains("dap.adapters.scorpion"))
        .expect("the adapter definition");
    let field = |name: &str| {
        let at = adapter.find(&format!("{name} = ")).expect(name) + name.len() + 3;
        let rest = &adapter[at..];
        let end = if rest.starts_with('{') {
            rest.find('}').expect("a list's end") + 1
        } else {
            rest.find(',').expect("a field's end")
        };
        lua_value(&rest[..end])
    };
    assert_eq!(field("command"), "scorpion", "{adapter}");
    // The configuration: one `key = value,` a line, comments dropped.
    let mut launch = serde_json::Map::new();
    let configuration = &block[block.find("dap.configurations").expect("a configuration")..];
    for line in configuration.lines().skip(2) {
        let code = line.split("--").next().unwrap_or_default().trim();
        let Some((key, value)) = code.split_once(" = ") else {
            continue;
        };
        launch.insert(
            key.trim().to_owned(),
            lua_value(value.trim_end_matches(',')),
        );
    }
    assert_eq!(launch["type"], "scorpion", "{launch:?}");
    let definition = serde_json::json!({"args": field("args"), "launch": launch});
    let dir = tempfile::tempdir().expect("a scratch directory");
    let file = dir.path().join("neovim.json");
    std::fs::write(&file, definition.to_string()).expect("the definition written");

    let adc = examples().join("adc");
    let output = run_script(
        &node,
        "dap.js",
        &[
            env!("CARGO_BIN_EXE_scorpion"),
            adc.to_str().expect("UTF-8"),
            file.to_str().expect("UTF-8"),
        ],
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{definition}\n{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for step in [
        "dap: hit adc.s:",
        "dap: registers: ",
        "dap: stepped to adc.s:",
        "dap: disconnected",
    ] {
        assert!(stdout.contains(step), "{step:?} in {stdout}");
    }
}

/// docs/DEBUGGING.md's bug hunt in VS Code terms, run as the guide writes
/// it: the planted bug (`bcc @carried` turned into `bcs @carried` in a copy
/// of the checksum example) hunted through the extension's debugger
/// contribution with VS Code's DAP test client, the same steps as the
/// monitor's hunt; its transcript (each step with the DAP requests it
/// made) is the guide's.
#[test]
fn the_debugging_guides_bug_hunt_runs_in_vs_code_as_written() {
    let test = "the_debugging_guides_bug_hunt_runs_in_vs_code_as_written";
    let Some(node) = node(test) else { return };
    let dir = tempfile::tempdir().expect("a scratch directory");
    let project = dir.path().join("checksum-bug");
    std::fs::create_dir(&project).expect("the project's directory");
    std::fs::copy(
        examples().join("scorpion.inc"),
        dir.path().join("scorpion.inc"),
    )
    .expect("scorpion.inc");
    for entry in std::fs::read_dir(examples().join("checksum")).expect("examples/checksum") {
        let path = entry.expect("an entry").path();
        if path.is_file() {
            std::fs::copy(&path, project.join(path.file_name().expect("a name"))).expect("a copy");
        }
    }
    let source = std::fs::read_to_string(project.join("checksum.s")).expect("checksum.s");
    let planted = source.replace("bcc @carried", "bcs @carried");
    assert_ne!(planted, source, "the bug is planted");
    std::fs::write(project.join("checksum.s"), planted).expect("the bug planted");

    let output = run_script(
        &node,
        "hunt.js",
        &[
            env!("CARGO_BIN_EXE_scorpion"),
            project.to_str().expect("UTF-8"),
        ],
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let guide =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/DEBUGGING.md"))
            .expect("docs/DEBUGGING.md");
    let section = &guide[guide.find("## A bug hunt in VS Code").expect("the section")..];
    let start = section.find("```text\n").expect("its transcript") + "```text\n".len();
    let block = &section[start..start + section[start..].find("```").expect("the block's end")];
    assert_eq!(
        stdout, block,
        "docs/DEBUGGING.md's VS Code bug hunt is stale"
    );
}

/// Runs the `$scorpion` matcher (test/matcher.js) over what `output`
/// printed; the problems it finds.
fn problems(node: &Path, dir: &Path, output: &Output) -> Vec<Value> {
    let printed = dir.join("printed.txt");
    let mut text = output.stdout.clone();
    text.extend(&output.stderr);
    std::fs::write(&printed, &text).expect("the output saved");
    let matched = run_script(node, "matcher.js", &[printed.to_str().expect("UTF-8")]);
    assert!(
        matched.status.success(),
        "{}",
        String::from_utf8_lossy(&matched.stderr)
    );
    let found: Value = serde_json::from_slice(&matched.stdout).expect("the problems as JSON");
    found.as_array().expect("a list").clone()
}

/// Issue 25's leftover: the matcher missed warnings (`⚠`, on their own or
/// beside errors) and messages miette wrapped over two lines (a long
/// message's place was no longer right under its first line). Over real
/// output of `scorpion asm` (warnings and an error; warnings alone) and
/// `scorpion build` (a project file's long message), each is found at its
/// place with its severity, code and whole message.
#[test]
fn the_problem_matcher_finds_warnings_and_long_messages() {
    let test = "the_problem_matcher_finds_warnings_and_long_messages";
    let Some(node) = node(test) else { return };
    let dir = tempfile::tempdir().expect("a scratch directory");
    std::fs::write(
        dir.path().join("mixed.s"),
        "        jmp ($02FF)\n        .warning \"check this\"\n        lda #300\n",
    )
    .expect("mixed.s");
    std::fs::write(dir.path().join("warned.s"), "        jmp ($02FF)\n").expect("warned.s");
    let mixed = super::scorpion(dir.path(), &["asm", "mixed.s", "-o", "mixed.o"]);
    assert!(!mixed.status.success(), "{}", super::transcript(&mixed));
    let found = problems(&node, dir.path(), &mixed);
    let summary: Vec<(String, u64, String)> = found
        .iter()
        .map(|p| {
            (
                p["severity"].as_str().unwrap_or_default().to_owned(),
                p["line"].as_u64().unwrap_or_default(),
                p["code"].as_str().unwrap_or_default().to_owned(),
            )
        })
        .collect();
    assert_eq!(
        summary,
        [
            ("warning".to_owned(), 1, "asm::jmp-page-wrap".to_owned()),
            ("warning".to_owned(), 2, "asm::user-warning".to_owned()),
            ("error".to_owned(), 3, "asm::range".to_owned()),
        ],
        "{found:?}\n{}",
        super::transcript(&mixed)
    );
    assert_eq!(found[1]["message"], "check this");

    let warned = super::scorpion(dir.path(), &["asm", "warned.s", "-o", "warned.o"]);
    assert!(warned.status.success(), "{}", super::transcript(&warned));
    let found = problems(&node, dir.path(), &warned);
    assert_eq!(found.len(), 1, "{found:?}\n{}", super::transcript(&warned));
    assert_eq!(found[0]["severity"], "warning", "{found:?}");
    assert_eq!(found[0]["file"], "warned.s", "{found:?}");
    assert_eq!(
        (found[0]["line"].clone(), found[0]["column"].clone()),
        (1.into(), 13.into())
    );

    // A message longer than a line: miette wrapped it at 80 columns.
    let project = dir.path().join("bad");
    std::fs::create_dir(&project).expect("the project");
    std::fs::write(
        project.join("Scorpion.toml"),
        "[project]\nname = \"bad\"\n\n[[image]]\nname = \"bad\"\nsourcse = [\"bad.s\"]\n",
    )
    .expect("Scorpion.toml");
    let built = super::scorpion(&project, &["build"]);
    assert!(!built.status.success(), "{}", super::transcript(&built));
    let found = problems(&node, &project, &built);
    assert_eq!(found.len(), 1, "{found:?}\n{}", super::transcript(&built));
    let message = found[0]["message"].as_str().unwrap_or_default();
    assert!(
        message.contains("unknown field `sourcse`") && message.ends_with("`defines`"),
        "the whole message: {found:?}"
    );
    assert_eq!(
        (found[0]["line"].clone(), found[0]["column"].clone()),
        (6.into(), 1.into())
    );
}

/// Issue 25's leftover: the README's first launch configuration ("create a
/// launch.json file" gives it) had a `commands` entry the extension does
/// not generate. It is the extension's `initialConfigurations` now.
#[test]
fn the_readmes_first_launch_configuration_is_the_one_generated() {
    let readme = std::fs::read_to_string(extension().join("README.md")).expect("README.md");
    let section = &readme[readme
        .find("## Debugging: launch.json")
        .expect("the section")..];
    let start = section.find("```json\n").expect("its block") + "```json\n".len();
    let block = &section[start..start + section[start..].find("```").expect("the block's end")];
    let shown: Value = serde_json::from_str(block).expect("the block is JSON");
    let manifest = json(&extension().join("package.json"));
    let generated = &manifest["contributes"]["debuggers"][0]["initialConfigurations"];
    assert_eq!(&shown["configurations"], generated, "{block}");
}
