//! `scorpion test`: a project's tests. For every image, snapshots of the
//! assembled output (listing, map, symbols, bytes: nothing of the machine,
//! no times); then every transcript (`tests/*.expect`) on the virtual
//! Scorpion with the images loaded as an upload leaves them and the
//! project's cards and surroundings; with `--port`, the transcripts on a
//! real robot after uploading the images, and no snapshots.
//!
//! A snapshot that fails leaves its new text beside the accepted one
//! (`NAME.snap.new`, as insta's assertions do), for `--review`, `--accept`,
//! `--reject` or `cargo insta review`. `scorpion test NAME` runs the tests
//! whose name contains NAME, as `cargo test NAME` does.
//!
//! The library's runner ([`scorpion_project::runner`]) runs them; this
//! prints each test's line as it comes and asks `--review`'s questions.

use std::io::{BufRead as _, Read as _, Write as _};
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};
use scorpion_project::runner::{self, Decision, MemberReport, Mode, Outcome, Progress, Question};
use scorpion_project::{Environment, Found, undo};

/// The longest answer `--review` reads from a line.
const ANSWER_MAX: u64 = 256;

/// Run the project's tests: snapshots of the assembled output and
/// transcripts on the virtual Scorpion.
///
/// Prints a line per test and `N passed, N failed`; exits 1 if any failed.
/// A new or changed snapshot fails with its diff, its new text left beside
/// the accepted one as `NAME.snap.new` (what `cargo insta review` shows
/// too), until `--accept` or `--review` takes it.

#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// Only the tests whose name contains NAME: an image's (`probe`), one
    /// snapshot (`probe/listing`), one file's (`probe.expect`,
    /// `tests/io.calls`).
    #[arg(value_name = "NAME")]
    filter: Option<String>,
    /// Take the new and changed snapshots (of the tests NAME selects) as
    /// they are now, and delete the stale ones.
    #[arg(long, conflicts_with_all = ["reject", "review", "port"])]
    accept: bool,
    /// Leave the accepted snapshots as they are and delete the pending
    /// `.snap.new` files (of the tests NAME selects).
    #[arg(long, conflicts_with_all = ["review", "port"])]
    reject: bool,
    /// Ask about each new, changed or stale snapshot, one at a time: `a`
    /// accepts it, `r` rejects it (deletes the pending file), `s` skips it
    /// (leaves it pending).
    #[arg(long, conflicts_with = "port")]
    review: bool,
    /// Rehearse the transcripts on the virtual Scorpion (with the
    /// project's cards and world), then, if they pass, upload the images
    /// to the robot on PORT and run them there (no snapshots). Without a
    /// value: SCORPION_PORT, else the per-user file's, else the project's
    /// [robot] port.
    #[arg(
        long,
        value_name = "PORT",
        num_args = 0..=1,
        default_missing_value = crate::cmd::ports::CONFIGURED,
        value_parser = crate::cmd::ports::port_value
    )]
    port: Option<String>,
    /// With --port: replace what the robot has installed where the images
    /// go (an earlier build of them, most often), as `scorpion upload
    /// --replace` does; without it such an upload fails the test.
    #[arg(long, requires = "port")]
    replace: bool,
    /// Also print the robot time the transcripts stood for and the wall
    /// time they took (left out otherwise: the output stays the same from
    /// run to run).
    #[arg(long)]
    timing: bool,
    /// Count which lines of the project's own sources the transcripts and
    /// `.calls` tests ran, and each conditional branch taken and not
    /// taken: the lines never run are named, and
    /// `target/scorpion/coverage/` gets `lcov.info` (LCOV) and
    /// `index.html`.
    #[arg(long, conflicts_with = "port")]
    coverage: bool,
    /// Draw each transcript's robot in its room (the project's world
    /// file, docs/WORLD.md) as sim's --path does, one picture per
    /// transcript beside FILE: `--path out/run.svg` draws
    /// `tests/patrol.expect` to `out/run-patrol.svg`.
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    path: Option<std::path::PathBuf>,
}

impl Args {
    fn mode(&self) -> Mode {
        if self.accept {
            Mode::Accept
        } else if self.reject {
            Mode::Reject
        } else if self.review {
            Mode::Review
        } else {
            Mode::Fail
        }
    }
}

/// Prints the run as it comes: a line per test on stdout, what the
/// virtual robot's scripts print and where its cards went on stderr.
struct Printer {
    out: std::io::StdoutLock<'static>,
    /// The profiler on every test's robot, for `--coverage` and the
    /// project's `[budgets]`.
    watch: Option<crate::cmd::profile::Watch>,
    /// Budgets are checked (some project has them).
    budgets: bool,
    /// `--coverage`: each project's report written when its tests end.
    coverage: bool,
    /// The first coverage report that could not be written.
    failed_write: Option<miette::Report>,
}

impl Printer {
    /// Writes the coverage of the project whose tests ran last.
    fn write_coverage(&mut self, name: &str) {
        let Some(member) = self.watch.as_ref().and_then(|w| w.members.last()) else {
            return;
        };
        let name = if name.is_empty() {
            member.root.display().to_string()
        } else {
            name.to_owned()
        };
        if let Err(error) = member.write_coverage(&name, &mut self.out) {
            self.failed_write.get_or_insert(error);
        }
    }
}

impl Progress for Printer {
    fn image_built(&mut self, built: &runner::Built) {
        if let Some(watch) = &mut self.watch {
            watch.image_built(built);
        }
    }

    fn robot_ready(&mut self, _test: &str, robot: &mut romlib::VirtualScorpion) {
        if let Some(watch) = &mut self.watch {
            watch.robot_ready(robot);
        }
    }

    fn robot_done(&mut self, test: &str, robot: &mut romlib::VirtualScorpion) {
        if let Some(watch) = &mut self.watch {
            watch.robot_done(test, robot);
        }
    }

    fn member_started(&mut self, name: &str) {
        let _ = writeln!(self.out, "== {name}");
        if let Some(watch) = &mut self.watch {
            watch.member_started(name);
        }
    }

    fn virtual_runs_done(&mut self, filtered: bool) -> Vec<(String, Outcome)> {
        match &self.watch {
            Some(watch) if self.budgets => watch.budget_tests(filtered),
            _ => Vec::new(),
        }
    }

    fn member_finished(&mut self, member: &MemberReport) {
        // A member's coverage before its summary, not after every
        // member's.
        if self.coverage {
            self.write_coverage(&member.name);
        }
        let _ = writeln!(
            self.out,
            "{}: {} passed, {} failed",
            member.name, member.passed, member.failed
        );
    }

    fn build_warning(&mut self, _image: &str, warning: &miette::Report) {
        // "Warning: " as miette heads a related warning: the
        // problem matcher reads a warning's severity there.
        let _ = writeln!(std::io::stderr(), "Warning: {warning:?}");
    }

    fn test_finished(&mut self, name: &str, outcome: &Outcome) {
        match outcome {
            Outcome::Passed(how) => {
                let _ = writeln!(self.out, "test {name} ... {}", how.word());
            }
            Outcome::Failed(failure) => {
                let _ = writeln!(self.out, "test {name} ... FAILED\n{}", failure.text);
            }
        }
    }

    fn card_mapped(&mut self, card: &str, start: u16, end: u16) {
        crate::cmd::rig::say_mapped(card, start, end);
    }

    fn script_printed(&mut self, script: &str, line: &str) {
        let _ = writeln!(std::io::stderr(), "{script}: {line}");
    }

    /// Asks what to do with the snapshot, after its diff. The end of the
    /// input skips the rest.
    fn review(&mut self, question: &Question<'_>) -> miette::Result<Decision> {
        let _ = write!(self.out, "review {}\n{}", question.name, question.why);
        loop {
            let _ = write!(
                self.out,
                "  a {}, r reject, s skip (leave it pending)? ",
                question.accept
            );
            let _ = self.out.flush();
            let mut line = String::new();
            let mut input = std::io::stdin().lock();
            // An answer is a word: a longer line is read no further than
            // this (and the rest of it skipped), whatever is piped in.
            let read = (&mut input)
                .take(ANSWER_MAX)
                .read_line(&mut line)
                .into_diagnostic()
                .wrap_err("cannot read the answer")?;
            if read as u64 == ANSWER_MAX && !line.ends_with('\n') {
                input
                    .skip_until(b'\n')
                    .into_diagnostic()
                    .wrap_err("cannot read the answer")?;
                line.clear();
                line.push('?');
            }
            if read == 0 {
                let _ = writeln!(self.out);
                return Ok(Decision::Skip);
            }
            match line.trim().to_ascii_lowercase().as_str() {
                "a" | "accept" => return Ok(Decision::Accept),
                "r" | "reject" => return Ok(Decision::Reject),
                "s" | "skip" | "" => return Ok(Decision::Skip),
                _ => {}
            }
        }
    }
}

/// What a run interrupted by a signal left: an upload to a robot that did
/// not finish (its undo file still marked), or nothing half done.
fn test_interrupted(undo_files: &[std::path::PathBuf]) -> String {
    match undo_files
        .iter()
        .find(|path| undo::marked(path, undo::UPLOADING).exists())
    {
        Some(path) => format!(
            "interrupted: an upload to the robot did not finish; nothing that did not verify is hooked\n  `scorpion upload --undo` puts back what the robot held before it (kept in {}); then test again",
            path.display()
        ),
        None => {
            "interrupted: no upload was under way; what is installed on a robot stays installed"
                .to_owned()
        }
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let found = Found::here()?;
    if let Some(path) = &args.path {
        crate::cmd::rig::check_path(path)?;
    }
    let started = std::time::Instant::now();
    let filter = args.filter.clone().filter(|f| !f.is_empty());
    let options = runner::Options {
        filter: filter.clone(),
        mode: args.mode(),
        // The runner takes an empty port for the configured one.
        port: args.port.as_ref().map(|port| {
            crate::cmd::ports::given_port(Some(port))
                .cloned()
                .unwrap_or_default()
        }),
        replace: args.replace,
        environment: Environment::from_process()?,
        path: args.path.clone(),
    };
    // Budgets need the whole profiler; coverage alone, the counts. With
    // a port, the rehearsal on the virtual Scorpion checks them, before
    // anything is sent to the robot.
    let budgets = crate::cmd::profile::Watch::needed(&found)?;
    let watch = if args.coverage || budgets {
        Some(crate::cmd::profile::Watch::new(&found, !budgets)?)
    } else {
        None
    };
    let mut printer = Printer {
        out: std::io::stdout().lock(),
        watch,
        budgets,
        coverage: args.coverage,
        failed_write: None,
    };
    // hostile15 F4: a run on a port killed during an upload said nothing
    // of what it left; it says what `scorpion upload` says.
    let undo_files: Vec<std::path::PathBuf> = match &found {
        Found::Project(project) => vec![undo::in_project(&project.root)],
        Found::Workspace(workspace) => workspace
            .member_names()
            .iter()
            .map(|member| undo::in_project(&workspace.root.join(member)))
            .collect(),
    };
    crate::cmd::say_when_interrupted(move || test_interrupted(&undo_files))?;
    let report = runner::run_tests(&found, &options, &mut printer)?;
    if let (true, Found::Project(project)) = (args.coverage, &found) {
        printer.write_coverage(&project.file.project.name);
    }
    if let Some(error) = printer.failed_write.take() {
        return Err(error);
    }
    let out = &mut printer.out;
    if args.timing {
        // With a port the virtual Scorpion's figures are the rehearsal's:
        // said so, beside the robot's own (fresh11's nit: they were given
        // as the transcripts' own).
        let (virtual_run, port) = match report.port_time {
            Some(port) => (
                "transcripts rehearsed",
                format!(
                    "; on the robot: {:.6} s (its line's time)",
                    port.as_secs_f64()
                ),
            ),
            None => ("transcripts", String::new()),
        };
        let _ = writeln!(
            out,
            "{virtual_run}: {:.6} s of robot time in {:.6} s{port} (all tests: {:.6} s)",
            report.robot_time.as_secs_f64(),
            report.wall_time.as_secs_f64(),
            started.elapsed().as_secs_f64()
        );
    }
    // fresh13 F1: the images stay on the robot, and nothing said so. A run
    // whose uploads changed nothing keeps the undo file it found; one that
    // changed an image keeps what that upload overwrote.
    for (image, way) in &report.dropped {
        let _ = writeln!(
            out,
            "warning: {way}, which is no way for a command to go (damaged by hand?): {image} falls through to the ROM's target instead"
        );
    }
    // fresh14 F2: what `--replace` took out is named.
    for (image, old) in &report.replaced {
        let _ = writeln!(
            out,
            "took out {old} for {image}: it overlapped the image (--replace), and no longer answers"
        );
    }
    for (image, old) in &report.reset_freed {
        let _ = writeln!(
            out,
            "warning: the robot reset while {image} went in (a /1R frees every entry): {old} is no longer installed (its code stays in RAM, unhooked); upload it again to answer its commands"
        );
    }
    if !report.left_installed.is_empty() {
        let _ = writeln!(
            out,
            "left installed on the robot: {}; `scorpion upload --undo` puts back what it held before {}",
            report.left_installed.join(", "),
            if report.kept_older_undo {
                "the last upload that changed it (this run changed nothing on it; each `--undo` goes back one upload)"
            } else {
                "this run's uploads (each `--undo` goes back one upload: again, to before the one before)"
            }
        );
    }
    if let Some(filter) = &filter {
        if report.passed + report.failed == 0 {
            miette::bail!(
                help = "NAME is part of a test's name: an image's (`myext`), a snapshot's (`myext/listing`), a file's (`myext.expect`); `scorpion test` lists them all",
                "no test's name contains `{filter}`"
            );
        }
        let _ = writeln!(
            out,
            "{} passed, {} failed, {} filtered out",
            report.passed, report.failed, report.filtered_out
        );
    } else {
        let _ = writeln!(out, "{} passed, {} failed", report.passed, report.failed);
    }
    Ok(if report.success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
