//! `scorpion profile`: where the cycles go when the project's tests run.
//! Every transcript and `.calls` test runs as `scorpion test` runs it (the
//! library's runner: each on a fresh virtual Scorpion with the project's
//! images, cards, surroundings and ROM) with the profiler set on its
//! robot; the counts of all of them together are printed as tables,
//! dearest first (routines, robot commands beside a character's time on
//! the line, hot source lines), and written as folded stacks and an SVG
//! flame graph into `target/scorpion/`.
//!
//! A command of its own rather than `--profile` on `test`: its output is
//! the report (the tests' verdict is `scorpion test`'s), with options of
//! its own. [`Watch`] is the observer both use: `scorpion test
//! --coverage` and the project's `[budgets]` set it on the test runner.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};
use romlib::VirtualScorpion;
use scorpion_profile::lines::LineTable;
use scorpion_profile::{Profile, Profiler, Recorder, report};
use scorpion_project::runner::{self, Built, Failure, Mode, Outcome, Passed, Progress};
use scorpion_project::{Environment, Found};

/// Profile the project's tests on the virtual Scorpion: cycles per
/// routine, robot command and source line, and a flame graph.
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
    /// Also write the stacks as a speedscope file (JSON, its "sampled"
    /// profile; open it at https://www.speedscope.app).
    #[arg(long, value_name = "FILE")]
    speedscope: Option<PathBuf>,
}

/// One project's counts.
pub(crate) struct Member {
    /// Its directory.
    pub(crate) root: PathBuf,
    /// Its images as built for the tests.
    pub(crate) images: Vec<linker::Image>,
    /// Every test's counts together.
    pub(crate) profile: Profile,
    /// Tests profiled.
    pub(crate) tests: usize,
    /// Its project file's `[budgets]`.
    pub(crate) budgets: Vec<scorpion_profile::budget::Budget>,
}

impl Member {
    fn new(project: &scorpion_project::Project) -> Member {
        Member {
            root: project.root.clone(),
            images: Vec::new(),
            profile: Profile::default(),
            tests: 0,
            budgets: project
                .file
                .budgets
                .iter()
                .map(|(key, cycles)| scorpion_profile::budget::Budget::new(key, *cycles))
                .collect(),
        }
    }

    /// `scorpion test`'s tests of its budgets (`budget KEY`), over what
    /// its tests ran; `filtered`: a filter left some tests out, so a
    /// budget nothing ran is not run rather than failed. None if it has
    /// no budget, or no test ran and none was filtered out.
    pub(crate) fn budget_tests(&self, filtered: bool) -> Vec<(String, Outcome)> {
        use scorpion_profile::budget::Subject;
        if self.budgets.is_empty() || (self.tests == 0 && !filtered) {
            return Vec::new();
        }
        let (overruns, unused) = scorpion_profile::budget::check(&self.profile, &self.budgets);
        let mut tests = Vec::new();
        for budget in &self.budgets {
            let key = match &budget.subject {
                Subject::Command(key) | Subject::Routine(key) => key,
            };
            let outcome = if let Some(overrun) = overruns.iter().find(|o| &o.budget == budget) {
                Outcome::Failed(Failure::text(format!("  {overrun}")))
            } else if !unused.iter().any(|u| &u.budget == budget) {
                Outcome::Passed(Passed::Ok)
            } else if filtered {
                Outcome::Passed(Passed::NotRun)
            } else {
                Outcome::Failed(Failure::text(format!(
                    "  no command or routine the tests ran is named `{key}` (a command is `/2A`: its count and letter; a routine, a JSR target's label or a .calls test's routine)"
                )))
            };
            tests.push((format!("budget {key}"), outcome));
        }
        tests
    }

    /// Writes `target/scorpion/coverage/lcov.info` and `index.html` and
    /// tells the totals and what never ran.
    pub(crate) fn write_coverage(
        &self,
        name: &str,
        out: &mut dyn std::io::Write,
    ) -> miette::Result<()> {
        let coverage =
            scorpion_profile::coverage::Coverage::new(&self.profile, &self.lines(), &|file| {
                self.is_users(file)
            });
        let (lines, _) = coverage.line_counts();
        if lines == 0 {
            // An lcov.info without a record is one genhtml and lcov reject,
            // and 0 of 0 lines is no percentage.
            let _ = writeln!(
                out,
                "coverage: nothing to cover (no code line of the project's sources ran or was built); no report written"
            );
            return Ok(());
        }
        let dir = self.root.join("target/scorpion/coverage");
        let lcov = dir.join("lcov.info");
        let html = dir.join("index.html");
        let root = &self.root;
        write(
            &lcov,
            coverage
                .lcov(name, &|file| root.join(file).display().to_string())
                .as_bytes(),
        )?;
        write(
            &html,
            coverage
                .html(&format!("{name}: coverage of the tests"), &|file| {
                    read_source(root, file)
                })
                .as_bytes(),
        )?;
        let (lines, lines_hit) = coverage.line_counts();
        let (branches, branches_hit) = coverage.branch_counts();
        use scorpion_profile::coverage::percent;
        let _ = writeln!(
            out,
            "coverage: {lines_hit} of {lines} lines ({}), {branches_hit} of {branches} branches ({}): {}, {}",
            percent(lines_hit, lines),
            percent(branches_hit, branches),
            shown(root, &lcov),
            shown(root, &html)
        );
        let never: Vec<String> = coverage
            .never_run()
            .iter()
            .map(|(file, line)| format!("{file}:{line}"))
            .collect();
        if !never.is_empty() {
            let _ = writeln!(out, "  never run: {}", never.join(", "));
        }
        for missed in coverage.missed_branches() {
            let how = if missed.never_taken {
                "never taken"
            } else {
                "always taken"
            };
            let _ = writeln!(out, "  branch {how}: {}:{}", missed.file, missed.line);
        }
        Ok(())
    }

    /// Whether `file` (as its build named it) is one of the project's own
    /// sources, which the user can open: its lines are shown, and a
    /// built-in macro's code counts at the line of it that called the
    /// macro (`isa::objfmt::user_place`, as the debuggers show it).
    pub(crate) fn is_users(&self, file: &str) -> bool {
        hostfs::is_users_source(&self.root, file)
    }

    /// The line tables of its images, its own sources read.
    pub(crate) fn lines(&self) -> LineTable {
        let images: Vec<&linker::Image> = self.images.iter().collect();
        LineTable::new(&images, &|file| read_source(&self.root, file))
    }
}

/// The observer set on the test runner: a profiler on every test's
/// virtual robot, its counts gathered per project.
pub(crate) struct Watch {
    /// Counts by address and branch only (coverage), or everything.
    coverage_only: bool,
    /// The projects, the one running last.
    pub(crate) members: Vec<Member>,
    /// A workspace's members, by name.
    roots: Vec<(String, scorpion_project::Project)>,
    recorder: Option<Recorder>,
}

impl Watch {
    /// A watch of the tests of `found`.
    pub(crate) fn new(found: &Found, coverage_only: bool) -> miette::Result<Watch> {
        let (members, roots) = match found {
            Found::Project(project) => (vec![Member::new(project)], Vec::new()),
            Found::Workspace(workspace) => (Vec::new(), workspace.projects()?),
        };
        Ok(Watch {
            coverage_only,
            members,
            roots,
            recorder: None,
        })
    }

    /// The robot of a test: the profiler set on it.
    pub(crate) fn robot_ready(&mut self, robot: &mut VirtualScorpion) {
        let profiler = Profiler::for_robot(robot);
        let profiler = if self.coverage_only {
            profiler.coverage_only()
        } else {
            profiler
        };
        self.recorder = Some(Recorder::attach_profiler(robot, profiler));
    }

    /// The test `test` is done: its counts added to its project's.
    pub(crate) fn robot_done(&mut self, test: &str, robot: &mut VirtualScorpion) {
        let Some(recorder) = self.recorder.take() else {
            return;
        };
        let mut profile = recorder.finish(robot);
        let Some(member) = self.members.last_mut() else {
            return;
        };
        if let Some(shown) = test.strip_prefix("transcript ") {
            if let Some(expectations) = hostfs::read_text(member.root.join(shown), hostfs::TEXT)
                .ok()
                .and_then(|text| uploader::Expectations::parse(&text).ok())
            {
                name_origins(&mut profile, &expectations, shown);
            }
        } else if let Some(call) = test.strip_prefix("call ") {
            let origin = call.split(' ').next().unwrap_or(call);
            for run in &mut profile.commands {
                run.origin = Some(origin.to_owned());
            }
        }
        member.profile.merge(&profile);
        member.tests += 1;
    }

    /// A workspace's member begins.
    pub(crate) fn member_started(&mut self, name: &str) {
        if let Some((_, project)) = self.roots.iter().find(|(member, _)| member == name) {
            let member = Member::new(project);
            self.members.push(member);
        }
    }

    /// The project's budgets checked over what its tests ran.
    pub(crate) fn budget_tests(&self, filtered: bool) -> Vec<(String, Outcome)> {
        self.members
            .last()
            .map(|member| member.budget_tests(filtered))
            .unwrap_or_default()
    }

    /// Whether any project watched has budgets.
    pub(crate) fn needed(found: &Found) -> miette::Result<bool> {
        Ok(match found {
            Found::Project(project) => !project.file.budgets.is_empty(),
            Found::Workspace(workspace) => workspace
                .projects()?
                .iter()
                .any(|(_, project)| !project.file.budgets.is_empty()),
        })
    }

    /// An image was built for the tests.
    pub(crate) fn image_built(&mut self, built: &Built) {
        if let Some(member) = self.members.last_mut() {
            member.images.push(built.linked.image.clone());
        }
    }
}

/// The test runner with a [`Watch`], telling nothing else.
struct Quiet<'w> {
    watch: &'w mut Watch,
}

impl Progress for Quiet<'_> {
    fn member_started(&mut self, name: &str) {
        self.watch.member_started(name);
    }

    fn image_built(&mut self, built: &Built) {
        self.watch.image_built(built);
    }

    fn robot_ready(&mut self, _test: &str, robot: &mut VirtualScorpion) {
        self.watch.robot_ready(robot);
    }

    fn robot_done(&mut self, test: &str, robot: &mut VirtualScorpion) {
        self.watch.robot_done(test, robot);
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let named = [
        ("--folded", &args.folded),
        ("--flamegraph", &args.flamegraph),
        ("--speedscope", &args.speedscope),
    ];
    for (index, (first, one)) in named.iter().enumerate() {
        for (second, other) in &named[index + 1..] {
            let (Some(one), Some(other)) = (one, other) else {
                continue;
            };
            // One would overwrite the other: refuse before running anything.
            if std::path::absolute(one).ok() == std::path::absolute(other).ok() {
                miette::bail!(
                    help = format!("give {first} and {second} different files"),
                    "{first} and {second} name the same file, {}: one would overwrite the other",
                    one.display()
                );
            }
        }
    }
    let found = Found::here()?;
    let Found::Project(project) = &found else {
        miette::bail!(
            help = "run `scorpion profile` in a member's directory",
            "a workspace's members run on robots of their own: profile one project at a time"
        );
    };
    let mut watch = Watch::new(&found, false)?;
    let options = runner::Options {
        filter: args.filter.clone().filter(|f| !f.is_empty()),
        mode: Mode::Fail,
        port: None,
        replace: false,
        environment: Environment::from_process()?,
        path: None,
    };
    let report = runner::run_tests(&found, &options, &mut Quiet { watch: &mut watch })?;
    let mut out = std::io::stdout().lock();
    for test in report.tests.iter().filter(|test| test.outcome.failed()) {
        let _ = writeln!(
            out,
            "test {} failed (see `scorpion test`); profiled as it ran",
            test.name
        );
    }
    let Some(member) = watch.members.first() else {
        return Ok(ExitCode::SUCCESS);
    };
    let profile = &member.profile;
    if member.tests == 0 {
        miette::bail!(
            help = "`scorpion profile` runs the transcripts (tests/*.expect) and routine-level tests (tests/*.calls)",
            "no transcript or routine-level test to profile"
        );
    }
    let baud = crate::cmd::config::resolve_in(&scorpion_project::Flags::default(), &project.root)?
        .baud
        .value;
    let lines = member.lines();
    let _ = writeln!(
        out,
        "{} cycles of robot time profiled ({} tests)\n",
        profile.total, member.tests
    );
    let _ = writeln!(out, "{}", report::routines_table(profile, args.limit));
    let _ = writeln!(out, "{}", report::commands_table(profile, baud));
    let _ = writeln!(
        out,
        "{}",
        report::hot_lines_table(profile, &lines, &|file| member.is_users(file), args.limit)
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
        shown(&project.root, &folded),
        shown(&project.root, &svg)
    );
    if let Some(path) = &args.speedscope {
        let json = scorpion_profile::speedscope::json(profile, &title)
            .into_diagnostic()
            .wrap_err("cannot write the speedscope file")?;
        write(path, json.as_bytes())?;
        let _ = writeln!(out, "speedscope: {}", shown(&project.root, path));
    }
    Ok(ExitCode::SUCCESS)
}

/// Gives each command its transcript line: commands arrive in the
/// transcript's order, each the next line that sends it.
pub(crate) fn name_origins(
    profile: &mut Profile,
    expectations: &uploader::Expectations,
    shown: &str,
) {
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
    if !path.starts_with(root) || root.as_os_str().is_empty() {
        return None;
    }
    hostfs::read_text(&path, hostfs::TEXT).ok()
}

/// `path` as the user sees it: relative to the project when inside it.
pub(crate) fn shown(root: &Path, path: &Path) -> String {
    path.strip_prefix(root)
        .unwrap_or(path)
        .display()
        .to_string()
}

/// Writes `bytes` to `path`, making its directory.
pub(crate) fn write(path: &Path, bytes: &[u8]) -> miette::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot create {}", dir.display()))?;
    }
    std::fs::write(path, bytes)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", path.display()))
}
