//! Issue 22: one resolved configuration for every command, and the
//! virtual robot's parts (cards, world) used wherever it runs and never in
//! the way of a real port. A matrix: each command that takes a port, a
//! card, an include or a define, against each source that may carry it
//! (flag, environment, per-user file, project); the robot on a port is a
//! `scorpion sim --pty` started with the example's card, standing for the
//! real one. Every run gets its own per-user directory and no
//! `SCORPION_*` variable but those the case sets.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use crate::transcript;

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples")
}

/// Where a setting comes from, in a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    Flag,
    Env,
    UserFile,
    Project,
}

const PORT_SOURCES: [Source; 4] = [Source::Flag, Source::Env, Source::UserFile, Source::Project];

/// A copy of examples/adc (its Scorpion.toml, source, card, transcript)
/// in a temporary directory, with its own per-user directory beside it.
struct Adc {
    dir: tempfile::TempDir,
}

impl Adc {
    fn new() -> Adc {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let project = dir.path().join("adc");
        std::fs::create_dir_all(project.join("tests/snapshots")).expect("mkdir");
        for file in ["Scorpion.toml", "adc.s", "adc.rhai", "adc.expect"] {
            std::fs::copy(examples().join("adc").join(file), project.join(file)).expect("copy");
        }
        std::fs::create_dir_all(dir.path().join("xdg/scorpion")).expect("mkdir");
        Adc { dir }
    }

    fn project(&self) -> PathBuf {
        self.dir.path().join("adc")
    }

    fn xdg(&self) -> PathBuf {
        self.dir.path().join("xdg")
    }

    /// Puts `port` where `source` says (the project's file, the per-user
    /// file, or nowhere for a flag or the environment) and returns the
    /// extra arguments and variables the run needs.
    fn port_from(&self, source: Source, port: &str) -> (Vec<String>, Vec<(String, String)>) {
        let user = self.xdg().join("scorpion/config.toml");
        let _ = std::fs::remove_file(&user);
        let toml = self.project().join("Scorpion.toml");
        let original =
            std::fs::read_to_string(examples().join("adc/Scorpion.toml")).expect("the project");
        std::fs::write(&toml, &original).expect("write");
        match source {
            Source::Flag => (vec!["--port".into(), port.into()], vec![]),
            Source::Env => (vec![], vec![("SCORPION_PORT".into(), port.into())]),
            Source::UserFile => {
                std::fs::write(&user, format!("[robot]\nport = \"{port}\"\n")).expect("write");
                (vec![], vec![])
            }
            Source::Project => {
                std::fs::write(
                    &toml,
                    original.replace("[robot]\n", &format!("[robot]\nport = \"{port}\"\n")),
                )
                .expect("write");
                (vec![], vec![])
            }
        }
    }

    /// Runs `scorpion ARGS` in `dir` with this case's environment.
    fn run(&self, dir: &Path, args: &[&str], env: &[(String, String)]) -> Output {
        let mut command = Command::new(env!("CARGO_BIN_EXE_scorpion"));
        command
            .args(args)
            .current_dir(dir)
            .env_remove("RUST_BACKTRACE")
            .env_remove("SCORPION_PORT")
            .env_remove("SCORPION_BAUD")
            .env("XDG_CONFIG_HOME", self.xdg())
            .env("NO_COLOR", "1")
            .env("COLUMNS", "100");
        for (name, value) in env {
            command.env(name, value);
        }
        command.output().expect("the scorpion binary runs")
    }
}

/// A `scorpion sim --pty` (with `args`), killed when dropped.
struct Pty {
    child: std::process::Child,
    path: String,
}

impl Pty {
    fn start(args: &[&str]) -> Pty {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .arg("sim")
            .arg("--pty")
            .args(args)
            .current_dir(std::env::temp_dir())
            .env(
                "XDG_CONFIG_HOME",
                std::env::temp_dir().join("no-scorpion-user"),
            )
            .env_remove("SCORPION_PORT")
            .env_remove("SCORPION_BAUD")
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("the scorpion binary runs");
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout is piped"));
        let mut path = String::new();
        stdout
            .read_line(&mut path)
            .expect("the first line is the path");
        let path = path.trim().to_owned();
        assert!(path.starts_with("/dev/"), "{path}");
        Pty { child, path }
    }

    /// The robot with the ADC card, as the real one would have it.
    fn with_adc_card() -> Pty {
        let card = examples().join("adc/adc.rhai");
        Pty::start(&["--card", card.to_str().expect("UTF-8")])
    }
}

impl Drop for Pty {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Issue 22's first reproduction, README's card block: the rehearsal with
/// the card passes, and the upload to the robot goes ahead (it failed
/// "--card and --world do not apply to the robot", exit 1).
#[test]
fn upload_with_a_card_rehearses_it_then_uploads_to_the_real_port() {
    let adc = Adc::new();
    let robot = Pty::with_adc_card();
    let built = adc.run(&adc.project(), &["build"], &[]);
    assert!(built.status.success(), "{}", transcript(&built));
    let card = examples().join("adc/adc.rhai");
    let expect = examples().join("adc/adc.expect");
    let output = adc.run(
        &adc.project(),
        &[
            "upload",
            "target/scorpion/adc.elf",
            "--port",
            &robot.path,
            "--card",
            card.to_str().expect("UTF-8"),
            "--expect",
            expect.to_str().expect("UTF-8"),
        ],
        &[],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let text = stdout(&output);
    assert!(text.contains("4 expectations met"), "{text}");
    assert!(text.contains("uploaded and verified"), "{text}");
    // It is in the robot: the card's channel 1 answers through it.
    let asked = adc.run(&adc.project(), &["ask", "--port", &robot.path, "/2A1"], &[]);
    assert_eq!(stdout(&asked), "A57\n", "{}", transcript(&asked));
}

/// fresh6's F2: `ask` of an extension's command that nobody answered
/// printed nothing and exited 0. It fails now, saying whether any
/// extension is installed at all; `--allow-silence` accepts an
/// extension's instruction.
#[test]
fn ask_fails_when_no_answer_came_and_says_why() {
    let adc = Adc::new();
    let robot = Pty::with_adc_card();
    let ask = |args: &[&str]| {
        let mut all = vec!["ask", "--port", &robot.path];
        all.extend_from_slice(args);
        adc.run(&adc.project(), &all, &[])
    };
    let fresh = ask(&["/2A1"]);
    assert_eq!(fresh.status.code(), Some(1), "{}", transcript(&fresh));
    let text = transcript(&fresh);
    assert!(
        text.contains("`/2A1`: no answer within 500 ms: no extension is installed"),
        "{text}"
    );
    let built = adc.run(&adc.project(), &["build"], &[]);
    assert!(built.status.success(), "{}", transcript(&built));
    let uploaded = adc.run(
        &adc.project(),
        &["upload", "target/scorpion/adc.elf", "--port", &robot.path],
        &[],
    );
    assert!(uploaded.status.success(), "{}", transcript(&uploaded));
    // The first answers; the second is nobody's: the third is not sent.
    let asked = ask(&["/2A1", "/1Q", "/1X"]);
    assert_eq!(asked.status.code(), Some(1), "{}", transcript(&asked));
    assert_eq!(String::from_utf8_lossy(&asked.stdout), "A57\n");
    let text = transcript(&asked);
    assert!(
        text.contains("`/1Q`: no answer within 500 ms: no installed extension answered it"),
        "{text}"
    );
    let allowed = ask(&["--allow-silence", "--timeout", "100", "/1Q", "/1X"]);
    assert_eq!(allowed.status.code(), Some(0), "{}", transcript(&allowed));
    assert!(
        String::from_utf8_lossy(&allowed.stdout).starts_with('X'),
        "{}",
        transcript(&allowed)
    );
}

/// The matrix for the port: `upload`, `ask`, `installed`, `read` and
/// `test --port` find the robot from each source (only `test --port`
/// did, and `upload`, `ask`, `installed` said `--port` was required).
#[test]
fn every_command_that_talks_to_a_robot_takes_the_port_from_each_source() {
    let adc = Adc::new();
    let project = adc.project();
    for source in PORT_SOURCES {
        // A robot of its own for each source: every upload finds it empty.
        let robot = Pty::with_adc_card();
        let (flags, env) = adc.port_from(source, &robot.path);
        let flags: Vec<&str> = flags.iter().map(String::as_str).collect();
        let with = |args: &[&str]| -> Vec<String> {
            args.iter()
                .chain(flags.iter())
                .map(|s| (*s).to_owned())
                .collect()
        };
        let run = |args: Vec<String>| {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let output = adc.run(&project, &args, &env);
            assert_eq!(
                output.status.code(),
                Some(0),
                "{source:?} {args:?}\n{}",
                transcript(&output)
            );
            stdout(&output)
        };
        // The project's images uploaded, its card rehearsing them.
        let uploaded = run(with(&["upload"]));
        assert!(
            uploaded.contains("uploaded and verified"),
            "{source:?}: {uploaded}"
        );
        let asked = run(with(&["ask", "/2A1"]));
        assert_eq!(asked, "A57\n", "{source:?}");
        let installed = run(with(&["installed"]));
        assert!(
            installed.contains("HOOK_UNKNOWN -> $0400"),
            "{source:?}: {installed}"
        );
        let read = run(with(&["read", "$0400", "4"]));
        assert!(read.starts_with("0400:"), "{source:?}: {read}");
        // `test --port` with no value takes the configured port (on a
        // robot of its own: its upload finds the robot empty).
        let robot = Pty::with_adc_card();
        let (_, env) = adc.port_from(source, &robot.path);
        let mut test = vec!["test".to_owned(), "--port".to_owned()];
        if source == Source::Flag {
            test.push(robot.path.clone());
        }
        let args: Vec<&str> = test.iter().map(String::as_str).collect();
        let output = adc.run(&project, &args, &env);
        assert_eq!(
            output.status.code(),
            Some(0),
            "{source:?}\n{}",
            transcript(&output)
        );
        let tested = stdout(&output);
        assert!(tested.ends_with(" 0 failed\n"), "{source:?}: {tested}");
    }
}

/// `scorpion config` names each source, with the file's line.
#[test]
fn config_says_where_each_setting_came_from() {
    let adc = Adc::new();
    let project = adc.project();
    let cases = [
        (Source::Flag, "flag --port"),
        (Source::Env, "environment SCORPION_PORT"),
        (Source::UserFile, "user file "),
        (Source::Project, "project Scorpion.toml:12"),
    ];
    for (source, said) in cases {
        let (flags, env) = adc.port_from(source, "/dev/ttyS9");
        let mut args = vec!["config"];
        args.extend(flags.iter().map(String::as_str));
        let output = adc.run(&project, &args, &env);
        assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
        let text = stdout(&output);
        let line = text
            .lines()
            .find(|l| l.starts_with("port "))
            .expect("a port line");
        assert!(line.contains("/dev/ttyS9"), "{source:?}: {line}");
        assert!(line.contains(said), "{source:?}: {line}");
        if source == Source::UserFile {
            assert!(line.ends_with("config.toml:2)"), "{line}");
        }
        let cards_line = if source == Source::Project { 13 } else { 12 };
        assert!(
            text.contains(&format!(
                "cards      adc.rhai  (project Scorpion.toml:{cards_line})"
            )),
            "{text}"
        );
    }
    // Each source over the next: the flag over the environment over the
    // per-user file over the project.
    adc.port_from(Source::Project, "/dev/from-project");
    std::fs::write(
        adc.xdg().join("scorpion/config.toml"),
        "[robot]\nport = \"/dev/from-user\"\nbaud = 4800\n",
    )
    .expect("write");
    let env = [("SCORPION_PORT".to_owned(), "/dev/from-env".to_owned())];
    let shown = |args: &[&str], env: &[(String, String)]| stdout(&adc.run(&project, args, env));
    assert!(shown(&["config", "--port", "/dev/from-flag"], &env).contains("/dev/from-flag  (flag"));
    assert!(shown(&["config"], &env).contains("/dev/from-env  (environment"));
    let user = shown(&["config"], &[]);
    assert!(user.contains("/dev/from-user  (user file"), "{user}");
    assert!(user.contains("baud       4800  (user file"), "{user}");
}

/// A bad SCORPION_BAUD is refused, naming the variable.
#[test]
fn a_variable_that_is_not_a_rate_is_refused_by_name() {
    let adc = Adc::new();
    let output = adc.run(
        &adc.project(),
        &["config"],
        &[("SCORPION_BAUD".to_owned(), "fast".to_owned())],
    );
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    assert!(
        String::from_utf8_lossy(&output.stderr).contains("SCORPION_BAUD=fast is not a baud rate"),
        "{}",
        transcript(&output)
    );
}

/// A `SCORPION_*` variable that is not text (a byte past UTF-8) is
/// refused, naming it; it was taken as unset, so the port from the
/// per-user file or the project was used without a word.
#[cfg(unix)]
#[test]
fn a_variable_that_is_not_text_is_refused_by_name() {
    use std::os::unix::ffi::OsStrExt as _;
    let adc = Adc::new();
    for (name, command) in [
        ("SCORPION_PORT", &["config"][..]),
        ("SCORPION_PORT", &["ask", "/1E"][..]),
        ("SCORPION_BAUD", &["config"][..]),
    ] {
        let output = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .args(command)
            .current_dir(adc.project())
            .env_remove("RUST_BACKTRACE")
            .env_remove("SCORPION_PORT")
            .env_remove("SCORPION_BAUD")
            .env("XDG_CONFIG_HOME", adc.xdg())
            .env("NO_COLOR", "1")
            .env(name, std::ffi::OsStr::from_bytes(b"/dev/tty\xFF"))
            .output()
            .expect("the scorpion binary runs");
        assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
        assert!(
            String::from_utf8_lossy(&output.stderr)
                .contains(&format!("{name}=/dev/tty\u{FFFD} is not text (UTF-8)")),
            "{name} {command:?}: {}",
            transcript(&output)
        );
    }
}

/// The matrix for cards: each command that runs the virtual robot takes
/// them from the project, or from `--card` instead. `ask --port emu` and
/// `upload --port emu` loaded neither the project's images nor its cards.
#[test]
fn every_command_that_runs_the_virtual_robot_takes_the_cards_from_each_source() {
    let adc = Adc::new();
    let project = adc.project();
    let card = examples().join("adc/adc.rhai");
    let card = card.to_str().expect("UTF-8");
    let expect = examples().join("adc/adc.expect");
    let expect = expect.to_str().expect("UTF-8");
    let bare = "[project]\nname = \"adc\"\n\n[[image]]\nname = \"adc\"\nsources = [\"adc.s\"]\n\n[tests]\ntranscripts = [\"adc.expect\"]\n";
    for source in [Source::Project, Source::Flag] {
        let mut flags: Vec<&str> = Vec::new();
        if source == Source::Flag {
            std::fs::write(project.join("Scorpion.toml"), bare).expect("write");
            flags = vec!["--card", card];
        }
        let run = |args: &[&str], input: &str| {
            let mut all: Vec<&str> = args.to_vec();
            all.extend(&flags);
            let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
                .args(&all)
                .current_dir(&project)
                .env("XDG_CONFIG_HOME", adc.xdg())
                .env_remove("SCORPION_PORT")
                .env_remove("SCORPION_BAUD")
                .env("NO_COLOR", "1")
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("runs");
            use std::io::Write as _;
            let _ = child
                .stdin
                .take()
                .expect("piped")
                .write_all(input.as_bytes());
            let output = child.wait_with_output().expect("ends");
            assert_eq!(
                output.status.code(),
                Some(0),
                "{source:?} {all:?}\n{}",
                transcript(&output)
            );
            stdout(&output)
        };
        assert_eq!(
            run(&["ask", "--port", "emu", "/2A1"], ""),
            "A57\n",
            "{source:?}"
        );
        assert_eq!(run(&["sim"], "/2A1\n"), "A57\n", "{source:?}");
        let uploaded = run(&["upload", "--port", "emu", "--expect", expect], "");
        assert!(uploaded.contains("< A57"), "{source:?}: {uploaded}");
        let debugged = run(&["debug"], "/2A1\ncontinue 100000\n");
        assert!(debugged.contains("< A57"), "{source:?}: {debugged}");
        if source == Source::Project {
            let tested = run(&["test", "--accept"], "");
            assert!(
                tested.contains("transcript adc.expect ... ok"),
                "{source:?}: {tested}"
            );
        }
    }
}

/// `scorpion test --port` rehearses with the project's cards first: a
/// transcript the virtual robot fails stops before the robot is touched.
#[test]
fn test_on_a_port_rehearses_with_the_projects_cards_first() {
    let adc = Adc::new();
    let project = adc.project();
    // The robot on the port has no card: only the rehearsal can pass.
    let robot = Pty::start(&[]);
    let output = adc.run(&project, &["test", "--port", &robot.path], &[]);
    let text = stdout(&output);
    assert!(
        text.starts_with("test transcript adc.expect ... ok\ntest upload adc ... ok\n"),
        "{}",
        transcript(&output)
    );
    // Now the project's transcript is wrong: the rehearsal fails, and the
    // robot is left alone.
    let transcript_file = project.join("adc.expect");
    let wrong = std::fs::read_to_string(&transcript_file)
        .expect("read")
        .replace("A57", "A58");
    std::fs::write(&transcript_file, wrong).expect("write");
    let robot = Pty::start(&[]);
    let output = adc.run(&project, &["test", "--port", &robot.path], &[]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let text = stdout(&output);
    assert!(text.contains("nothing was sent to the robot"), "{text}");
    assert!(!text.contains("test upload adc"), "{text}");
    let installed = adc.run(&project, &["installed", "--port", &robot.path], &[]);
    assert_eq!(stdout(&installed).lines().next(), Some("nothing installed"));
}

/// The matrix for includes and defines: `scorpion build` in a project
/// honours `-D` and `-I` on top of the images' own (they were ignored),
/// and refuses the output's flags, saying why.
#[test]
fn build_in_a_project_honours_defines_and_includes_and_refuses_outputs() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let root = dir.path();
    std::fs::create_dir_all(root.join("inc")).expect("mkdir");
    std::fs::create_dir_all(root.join("extra")).expect("mkdir");
    std::fs::write(root.join("inc/value.inc"), "VALUE = $11\n").expect("write");
    std::fs::write(root.join("extra/other.inc"), "OTHER = $22\n").expect("write");
    std::fs::write(
        root.join("v.s"),
        ".include \"value.inc\"\n.ifdef WITH_OTHER\n.include \"other.inc\"\n.byte OTHER\n.endif\n.byte VALUE, LEVEL\n",
    )
    .expect("write");
    std::fs::write(
        root.join("Scorpion.toml"),
        "[project]\nname = \"v\"\n\n[[image]]\nname = \"v\"\nsources = [\"v.s\"]\ninclude = [\"inc\"]\ndefines = { LEVEL = 1 }\n",
    )
    .expect("write");
    let adc = Adc::new();
    let listing = |args: &[&str]| {
        let output = adc.run(root, args, &[]);
        assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
        std::fs::read_to_string(root.join("target/scorpion/v.lst")).expect("the listing")
    };
    // From the project alone: VALUE from its include directory, LEVEL its
    // define.
    let plain = listing(&["build"]);
    assert!(plain.contains("11 01"), "{plain}");
    assert!(!plain.contains("other.inc\n"), "{plain}");
    // -D replaces the project's LEVEL and adds WITH_OTHER; -I finds
    // other.inc.
    let more = listing(&["build", "-D", "WITH_OTHER", "-D", "LEVEL=2", "-I", "extra"]);
    assert!(more.contains("11 02"), "{more}");
    assert!(more.contains("OTHER = $22"), "{more}");
    for flags in [
        &["-o", "x.elf"][..],
        &["--format", "bin"],
        &["--target", "flat"],
        &["-l", "v.lst"],
    ] {
        let mut args = vec!["build"];
        args.extend(flags);
        let output = adc.run(root, &args, &[]);
        assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains(&format!("{} cannot apply to a project's build", flags[0])),
            "{}",
            transcript(&output)
        );
    }
}

/// The world from the project or from `--world`, each setting by itself:
/// `--world` keeps the project's cards (it replaced them all in `sim`,
/// and `ask --port emu` took neither from the project).
#[test]
fn the_world_comes_from_the_project_or_the_flag_and_keeps_the_projects_cards() {
    let adc = Adc::new();
    let project = adc.project();
    std::fs::write(
        project.join("wall.rhai"),
        "// Against a wall from power-up.\nfn init() { bumpers(0x04); }\n",
    )
    .expect("write the world");
    let toml = project.join("Scorpion.toml");
    let original = std::fs::read_to_string(&toml).expect("the project");
    std::fs::write(
        &toml,
        original.replace("[robot]\n", "[robot]\nworld = \"wall.rhai\"\n"),
    )
    .expect("write");
    let asked = adc.run(&project, &["ask", "--port", "emu", "/1B", "/2A1"], &[]);
    assert_eq!(stdout(&asked), "B04\nA57\n", "{}", transcript(&asked));
    let shown = stdout(&adc.run(&project, &["config"], &[]));
    assert!(
        shown.contains("world      wall.rhai  (project Scorpion.toml:12)"),
        "{shown}"
    );

    std::fs::write(&toml, &original).expect("write");
    for command in [&["ask", "--port", "emu", "/1B", "/2A1"][..], &["sim"]] {
        let mut args = command.to_vec();
        args.extend(["--world", "wall.rhai"]);
        let output = crate::scorpion_with_input(Some(&project), &args, "/1B\n/2A1\n");
        assert_eq!(
            stdout(&output),
            "B04\nA57\n",
            "{args:?}\n{}",
            transcript(&output)
        );
    }
}

/// A `[robot] rom` that cannot be read is named as the ROM profile, with
/// the project file's key, by every command that reads it (found by a
/// new user: `test`, `build` and `read --port emu` said only
/// "nosuch.elf: no such file").
#[test]
fn a_missing_rom_profile_is_named_by_every_command() {
    let adc = Adc::new();
    let toml = adc.project().join("Scorpion.toml");
    let original = std::fs::read_to_string(&toml).expect("the project");
    std::fs::write(
        &toml,
        original.replace("[robot]\n", "[robot]\nrom = \"nosuch.elf\"\n"),
    )
    .expect("write");
    let runs: [&[&str]; 5] = [
        &["test"],
        &["build"],
        &["sim"],
        &["ask", "--port", "emu", "/1X"],
        &["read", "--port", "emu", "0x0400", "1"],
    ];
    for args in runs {
        let output = adc.run(&adc.project(), args, &[]);
        // `test` reports on stdout, as a test's failure; the others on stderr.
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(!output.status.success(), "{args:?} exits 0:\n{said}");
        assert!(
            said.contains("ROM profile") && said.contains("nosuch.elf"),
            "{args:?} does not name the ROM profile:\n{said}"
        );
    }
}

/// A port that does not open says where it was configured (a stale one in
/// the per-user file, the environment or the project), and a define out of
/// 32 bits says it is out of range, not that it is no number.
#[test]
fn a_port_that_does_not_open_names_its_source_and_a_big_define_its_range() {
    let adc = Adc::new();
    let project = adc.project();
    for (source, origin) in [
        (Source::UserFile, "user file"),
        (Source::Env, "environment SCORPION_PORT"),
        (Source::Project, "project"),
    ] {
        let (_, env) = adc.port_from(source, "/dev/no-such-scorpion-port");
        // fresh19 F7: `test --port` said only "does not exist"; a bare
        // `--port` (the configured one) was `test`'s and `debug`'s alone.
        for args in [
            &["ask", "/1X"][..],
            &["test", "--port"],
            &["installed", "--port"],
            &["ask", "--port", "--", "/1X"],
        ] {
            let output = adc.run(&project, args, &env);
            assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(
                stderr.contains("/dev/no-such-scorpion-port is from the ")
                    && stderr.contains(origin)
                    && stderr.contains("does not exist"),
                "{source:?} {args:?}: {stderr}"
            );
        }
    }
    // fresh21 F1: a bare `--port` before the arguments takes the first as
    // the port; the error says so, and how to write it.
    let output = adc.run(&project, &["ask", "--port", "/1X", "/1V"], &[]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--port took `/1X` as the robot's serial port")
            && stderr.contains("(or before `--`)"),
        "{stderr}"
    );
    // recheck22 F2: where clap then misses an argument, and in `test`.
    for (args, code) in [
        (&["read", "--port", "$0200", "6"][..], 2),
        (&["test", "--port", "adc"], 1),
    ] {
        let output = adc.run(&project, args, &[]);
        assert_eq!(output.status.code(), Some(code), "{}", transcript(&output));
        let said = transcript(&output);
        assert!(said.contains("--port took `"), "{args:?}: {said}");
    }
    // hostile21 F13: an empty value (a script's unset variable) is refused,
    // not taken for the configured port.
    let output = adc.run(&project, &["ask", "--port", "", "/1X"], &[]);
    assert_eq!(output.status.code(), Some(2), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("an empty port"), "{stderr}");
    let output = adc.run(&project, &["build", "-D", "BIG=99999999999"], &[]);
    assert_eq!(output.status.code(), Some(2), "{}", transcript(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("`99999999999` is out of range"), "{stderr}");
}

/// The loop of a user with a robot: `test --port`, change the source,
/// `test --port` again. The robot holds the earlier build where the new
/// one goes: without `--replace` that is a failed test said like the
/// others (with the summary and exit 1), with it the new build replaces
/// the old and the transcripts pass.
#[test]
fn test_on_a_port_replaces_an_earlier_build_only_when_asked() {
    let adc = Adc::new();
    let project = adc.project();
    let robot = Pty::with_adc_card();
    let (_, env) = adc.port_from(Source::Env, &robot.path);
    let first = adc.run(&project, &["test", "--port"], &env);
    assert_eq!(first.status.code(), Some(0), "{}", transcript(&first));
    let source = project.join("adc.s");
    let text = std::fs::read_to_string(&source).expect("the source");
    std::fs::write(&source, format!("{text}\n        .byte $5A ; a change\n")).expect("write");
    let refused = adc.run(&project, &["test", "--port"], &env);
    assert_eq!(refused.status.code(), Some(1), "{}", transcript(&refused));
    let out = stdout(&refused);
    assert!(out.contains("test upload adc ... FAILED"), "{out}");
    assert!(out.contains("--replace"), "{out}");
    assert!(out.ends_with(" 1 failed\n"), "{out}");
    let replaced = adc.run(&project, &["test", "--port", "--replace"], &env);
    assert_eq!(replaced.status.code(), Some(0), "{}", transcript(&replaced));
    let out = stdout(&replaced);
    assert!(out.contains("test upload adc ... ok"), "{out}");
    // fresh14 F2: the earlier build taken out is named.
    assert!(
        out.contains("took out extension ")
            && out.contains(" ($0400-$044F) for adc: it overlapped"),
        "{out}"
    );
    assert!(out.ends_with(" 0 failed\n"), "{out}");
}

/// In a workspace's root, `sim` and `debug` run a robot with no image, and
/// say why, rather than seem to have lost the members' extensions (a new
/// user's finding: `/1V` got no answer and nothing was said).
#[test]
fn sim_and_debug_in_a_workspace_say_the_robot_has_no_image() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("Scorpion.toml"),
        "[workspace]\nmembers = [\"a\"]\n",
    )
    .expect("the workspace");
    assert!(crate::scorpion(dir.path(), &["new", "a"]).status.success());
    for args in [&["sim"][..], &["debug"][..]] {
        let output = crate::scorpion_with_input(Some(dir.path()), args, "quit\n");
        let said = crate::transcript(&output);
        assert!(
            said.contains("is a workspace of a: the virtual Scorpion runs with no image"),
            "{args:?}: {said}"
        );
    }
}
