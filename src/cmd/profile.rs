//! `scorpion profile`: where the cycles go when the project's tests run.
//! Every transcript and `.calls` test runs on a fresh virtual Scorpion
//! (the project's images, cards, surroundings and ROM, as `scorpion test`
//! runs them) under the profiler; the counts of all of them together are
//! printed as tables, dearest first (routines, robot commands beside a
//! character's time on the line, hot source lines), and written as folded
//! stacks and an SVG flame graph into `target/scorpion/`.
//!
//! A command of its own rather than `--profile` on `test`: its output is
//! the report (the tests' pass or fail is `scorpion test`'s), and it has
//! options of its own.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};
use scorpion_profile::lines::LineTable;
use scorpion_profile::{Profile, Recorder, report};
use uploader::transport::VirtualTransport;
use uploader::{Client, ClientConfig, Expectations, RomProfile};

use crate::cmd::ports;
use crate::project::Project;
use crate::project::build::{Built, build};
use crate::project::config::Found;
use crate::project::transcript;

/// Profile the project's tests on the virtual Scorpion: cycles per
/// routine, per robot command and per source line, and a flame graph.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// Only the tests whose name contains NAME (`myext.expect`,
    /// `tests/io.calls`).
    #[arg(value_name = "NAME")]
    filter: Option<String>,
    /// Rows of each table (routines, hot lines).
    #[arg(long, value_name = "N", default_value_t = 15)]
    limit: usize,
    /// Where to write the folded stacks (default
    /// `target/scorpion/profile.folded`).
    #[arg(long, value_name = "FILE")]
    folded: Option<PathBuf>,
    /// Where to write the SVG flame graph (default
    /// `target/scorpion/flamegraph.svg`).
    #[arg(long, value_name = "FILE")]
    flamegraph: Option<PathBuf>,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let project = match Found::here()? {
        Found::Project(project) => project,
        Found::Workspace(_) => miette::bail!(
            help = "run `scorpion profile` in a member's directory",
            "a workspace's members run on robots of their own: profile one project at a time"
        ),
    };
    let mut built = Vec::new();
    for spec in &project.file.images {
        built.push(build(&project, spec)?);
    }
    let run = profile_tests(&project, &built, args.filter.as_deref())?;
    let mut out = std::io::stdout().lock();
    for line in &run.notes {
        let _ = writeln!(out, "{line}");
    }
    let profile = &run.profile;
    let images: Vec<&linker::Image> = built.iter().map(|b| &b.linked.image).collect();
    let lines = LineTable::new(&images, &|file| read_source(&project.root, file));
    let _ = writeln!(
        out,
        "{} cycles of robot time profiled ({} tests)\n",
        profile.total, run.tests
    );
    let _ = writeln!(out, "{}", report::routines_table(profile, args.limit));
    let _ = writeln!(out, "{}", report::commands_table(profile, run.baud));
    let _ = writeln!(
        out,
        "{}",
        report::hot_lines_table(profile, &lines, args.limit)
    );
    let target = project.root.join("target/scorpion");
    let folded = args
        .folded
        .clone()
        .unwrap_or_else(|| target.join("profile.folded"));
    let svg = args
        .flamegraph
        .clone()
        .unwrap_or_else(|| target.join("flamegraph.svg"));
    write(&folded, profile.folded().as_bytes())?;
    let title = format!("{}: cycles by stack", project.file.project.name);
    write(&svg, &scorpion_profile::flame::svg(profile, &title)?)?;
    let _ = writeln!(
        out,
        "folded stacks: {}\nflame graph: {}",
        shown(&project, &folded),
        shown(&project, &svg)
    );
    Ok(ExitCode::SUCCESS)
}

/// What the profiled tests gave.
pub(crate) struct Profiled {
    /// Every test's counts together.
    pub(crate) profile: Profile,
    /// The line's rate (for a character's time).
    pub(crate) baud: u32,
    /// Tests run.
    pub(crate) tests: usize,
    /// A line per test that did not pass (the profile has it anyway).
    pub(crate) notes: Vec<String>,
}

/// Every transcript and `.calls` test NAME selects, each on a fresh
/// virtual robot under the profiler.
pub(crate) fn profile_tests(
    project: &Project,
    built: &[Built],
    filter: Option<&str>,
) -> miette::Result<Profiled> {
    let flags = scorpion_project::Flags::default();
    let resolved = crate::cmd::config::resolve_in(&flags, &project.root)?;
    let baud = resolved.baud.value;
    let rom = crate::cmd::config::rom(&resolved)?;
    let rig = crate::cmd::config::rig(&resolved);
    let robot = || -> miette::Result<romlib::VirtualScorpion> {
        let (mut robot, _shown) = ports::virtual_robot(baud, rom.as_ref(), &rig)?;
        for image in built {
            robot
                .load_image(&image.linked.image)
                .wrap_err_with(|| format!("cannot load {}", image.name))?;
        }
        Ok(robot)
    };
    let selects = |name: &str| filter.is_none_or(|f| name.contains(f));
    let mut profiled = Profiled {
        profile: Profile::default(),
        baud,
        tests: 0,
        notes: Vec::new(),
    };
    for path in project.transcripts() {
        let shown = shown(project, &path);
        if !selects(&shown) {
            continue;
        }
        let expectations = transcript::read(&path, &shown)?;
        let mut robot = robot()?;
        let recorder = Recorder::attach(&mut robot);
        let mut client = Client::new(
            VirtualTransport::new(robot),
            ClientConfig {
                window: RomProfile::reference().window(),
                ..ClientConfig::default()
            },
        );
        match expectations.check_all(&mut client) {
            Ok(checked) if checked.mismatches.is_empty() => {}
            Ok(checked) => profiled.notes.push(format!(
                "transcript {shown}: {} lines answered otherwise (see `scorpion test`)",
                checked.mismatches.len()
            )),
            Err(error) => profiled
                .notes
                .push(format!("transcript {shown}: stopped early: {error}")),
        }
        let mut profile = recorder.finish(client.transport().robot_mut());
        name_origins(&mut profile, &expectations, &shown);
        profiled.profile.merge(&profile);
        profiled.tests += 1;
    }
    Ok(profiled)
}

/// Gives each command its transcript line: commands arrive in the
/// transcript's order, each the next line that sends it.
pub(crate) fn name_origins(profile: &mut Profile, expectations: &Expectations, shown: &str) {
    let mut next = 0;
    for run in &mut profile.commands {
        let found = expectations.lines[next..]
            .iter()
            .position(|line| line.command.encode() == run.text.as_bytes());
        if let Some(offset) = found {
            let line = &expectations.lines[next + offset];
            run.origin = Some(format!("{shown}:{}", line.line));
            next += offset + 1;
        }
    }
}

/// A source file of the project, by the name its build gave the
/// assembler; `None` for what is not the project's (built-in includes).
pub(crate) fn read_source(root: &Path, file: &str) -> Option<String> {
    let path = root.join(file);
    if !path.starts_with(root) {
        return None;
    }
    hostfs::read_text(&path, hostfs::TEXT).ok()
}

fn shown(project: &Project, path: &Path) -> String {
    path.strip_prefix(&project.root)
        .unwrap_or(path)
        .display()
        .to_string()
}

fn write(path: &Path, bytes: &[u8]) -> miette::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot create {}", dir.display()))?;
    }
    std::fs::write(path, bytes)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", path.display()))
}
