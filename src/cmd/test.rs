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

use std::fmt::Write as _;
use std::io::{BufRead as _, Read as _, Write as _};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};
use uploader::transport::VirtualTransport;
use uploader::{Client, ClientConfig, NoProgress, RomProfile, Transport, UploadImage};

use crate::cmd::ports;
use crate::project::build::{Built, SNAPSHOT_KINDS, build};
use crate::project::config::Found;
use crate::project::snapshot::{self, Outcome};
use crate::project::transcript::{self, Clock};
use crate::project::{FILE, Project};

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
    #[arg(long, value_name = "PORT", num_args = 0..=1, default_missing_value = "")]
    port: Option<String>,
    /// Also print the robot time the transcripts stood for and the wall
    /// time they took (left out otherwise: the output stays the same from
    /// run to run).
    #[arg(long)]
    timing: bool,
}

/// What to do with a snapshot that differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Fail, leaving the new text pending.
    Fail,
    /// Take it.
    Accept,
    /// Fail, deleting the pending text.
    Reject,
    /// Ask.
    Review,
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

/// An answer to `--review`'s question.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Decision {
    Accept,
    Reject,
    Skip,
}

/// The results, printed as they come.
struct Tally {
    passed: usize,
    failed: usize,
    /// Tests NAME did not select.
    filtered_out: usize,
    /// `scorpion test NAME`'s NAME.
    filter: Option<String>,
    /// Robot time the virtual transcripts took, all told.
    robot_time: std::time::Duration,
    /// Wall time they took (robots set up and images loaded included).
    wall_time: std::time::Duration,
    out: std::io::StdoutLock<'static>,
}

impl Tally {
    fn record(&mut self, name: &str, result: Result<&str, String>) {
        match result {
            Ok(how) => {
                self.passed += 1;
                let _ = writeln!(self.out, "test {name} ... {how}");
            }
            Err(why) => {
                self.failed += 1;
                let _ = writeln!(self.out, "test {name} ... FAILED\n{why}");
            }
        }
    }

    /// Whether the test `name` runs; counted as filtered out if not.
    fn selects(&mut self, name: &str) -> bool {
        let selected = self
            .filter
            .as_deref()
            .is_none_or(|filter| name.contains(filter));
        if !selected {
            self.filtered_out += 1;
        }
        selected
    }

    /// Asks what to do with the snapshot `name`, after its diff (`why`).
    /// The end of the input skips the rest.
    fn ask(&mut self, name: &str, why: &str, accept: &str) -> miette::Result<Decision> {
        let _ = write!(self.out, "review {name}\n{why}");
        loop {
            let _ = write!(
                self.out,
                "  a {accept}, r reject, s skip (leave it pending)? "
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

/// Deletes `path` if it is there.
fn remove(path: &Path) -> miette::Result<()> {
    match std::fs::remove_file(path) {
        Err(error) if error.kind() != std::io::ErrorKind::NotFound => Err(error)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot delete {}", path.display())),
        _ => Ok(()),
    }
}

fn write_file(path: &Path, text: &str) -> miette::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).into_diagnostic()?;
    }
    std::fs::write(path, text)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", path.display()))
}

fn check_snapshots(
    project: &Project,
    built: &Built,
    mode: Mode,
    tally: &mut Tally,
) -> miette::Result<()> {
    for (kind, content) in built.snapshots() {
        let name = format!("{}/{kind}", built.name);
        if !tally.selects(&name) {
            continue;
        }
        let path = project.snapshot_path(&built.name, kind);
        let pending = snapshot::pending_path(&path);
        let outcome = snapshot::compare(&path, &content);
        if outcome == Outcome::Same {
            // A pending text from an earlier failure is out of date.
            remove(&pending)?;
            tally.record(&name, Ok("ok"));
            continue;
        }
        let shown = relative(project, &path);
        let why = match &outcome {
            Outcome::New => format!("  no snapshot {shown} yet:\n{}", indent(&content)),
            Outcome::Changed(diff) => {
                format!("  {shown} differs (- snapshot, + now):\n{}", indent(diff))
            }
            Outcome::Same => String::new(),
        };
        let decision = match mode {
            Mode::Accept => Decision::Accept,
            Mode::Reject => Decision::Reject,
            Mode::Fail => Decision::Skip,
            Mode::Review => tally.ask(&name, &why, "accept")?,
        };
        let rendered = snapshot::render(FILE, &name, &content);
        // The review showed the diff already.
        let why = if mode == Mode::Review {
            String::new()
        } else {
            why
        };
        match decision {
            Decision::Accept => {
                write_file(&path, &rendered)?;
                remove(&pending)?;
                tally.record(&name, Ok("accepted"));
            }
            Decision::Reject => {
                remove(&pending)?;
                tally.record(
                    &name,
                    Err(format!("{why}  rejected: the snapshot stays as it was\n")),
                );
            }
            Decision::Skip => {
                write_file(&pending, &rendered)?;
                let pending = relative(project, &pending);
                let why = format!(
                    "{why}  the new one is in {pending}: `scorpion test {name} --accept` takes it, `scorpion test --review` (or `cargo insta review`) asks\n"
                );
                tally.record(&name, Err(why));
            }
        }
    }
    Ok(())
}

/// Snapshot files no image and kind of the project makes (an image renamed
/// or removed): a failure, or deleted with `--accept` (pending ones with
/// `--reject` too).
fn stale_snapshots(project: &Project, mode: Mode, tally: &mut Tally) -> miette::Result<()> {
    let dir = project.root.join("tests").join("snapshots");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Ok(());
    };
    let wanted: Vec<PathBuf> = project
        .file
        .images
        .iter()
        .flat_map(|image| SNAPSHOT_KINDS.map(|kind| project.snapshot_path(&image.name, kind)))
        .collect();
    let mut stale: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .filter(|path| {
            let accepted = snapshot::accepted_path(path).unwrap_or_default();
            let snap = path.extension().is_some_and(|ext| ext == "snap");
            let pending = path.extension().is_some_and(|ext| ext == "new")
                && accepted.extension().is_some_and(|ext| ext == "snap");
            (snap && !wanted.contains(path)) || (pending && !wanted.contains(&accepted))
        })
        .collect();
    stale.sort();
    for path in stale {
        let shown = relative(project, &path);
        let name = format!("stale {shown}");
        if !tally.selects(&name) {
            continue;
        }
        let pending = path.extension().is_some_and(|ext| ext == "new");
        let why = format!("  no image of {FILE} makes {shown}\n");
        let decision = match mode {
            Mode::Accept => Decision::Accept,
            Mode::Reject if pending => Decision::Accept,
            Mode::Reject | Mode::Fail => Decision::Skip,
            Mode::Review if pending => Decision::Skip,
            Mode::Review => tally.ask(&name, &why, "delete it")?,
        };
        match decision {
            Decision::Accept => {
                remove(&path)?;
                tally.record(&name, Ok("deleted"));
            }
            // A pending text nothing makes is left for whoever made it.
            Decision::Reject | Decision::Skip if pending => {}
            Decision::Reject | Decision::Skip => tally.record(
                &name,
                Err(format!(
                    "{why}  `scorpion test --accept` deletes it, `scorpion test --review` asks\n"
                )),
            ),
        }
    }
    Ok(())
}

fn indent(text: &str) -> String {
    text.lines().fold(String::new(), |mut out, line| {
        let _ = writeln!(out, "    {line}");
        out
    })
}

fn relative(project: &Project, path: &Path) -> String {
    path.strip_prefix(&project.root)
        .unwrap_or(path)
        .display()
        .to_string()
}

/// Runs the transcript at `path` on `client`: every line that differs is
/// a line of the failure.
fn run_transcript<T: Transport>(
    project: &Project,
    path: &Path,
    client: &mut Client<T>,
    clock: Clock,
) -> Result<(), String> {
    let shown = relative(project, path);
    let expectations = transcript::read(path, &shown).map_err(|e| indent(&format!("{e:?}")))?;
    let checked = expectations
        .check_all(client)
        .map_err(|e| indent(&format!("{:?}", miette::Report::new(e))))?;
    if checked.mismatches.is_empty() {
        Ok(())
    } else {
        Err(transcript::describe(&shown, &checked.mismatches, clock)
            .lines()
            .fold(String::new(), |mut out, line| {
                let _ = writeln!(out, "  {line}");
                out
            }))
    }
}

fn client<T: Transport>(transport: T) -> Client<T> {
    Client::new(
        transport,
        ClientConfig {
            window: RomProfile::reference().window(),
            ..ClientConfig::default()
        },
    )
}

/// What every virtual robot of a run is made of, read once: the line's
/// rate, the project's ROM profile, its cards and surroundings.
struct Setup {
    baud: u32,
    rom: Option<(String, linker::Image)>,
    rig: crate::cmd::rig::Rig,
}

impl Setup {
    /// The virtual robot the one resolution gives `project` (its cards,
    /// world and ROM profile; the rate from the environment, the per-user
    /// file or the project), and the port, if `port` asks for one
    /// (`Some("")`: the configured one).
    fn of(project: &Project, port: Option<&str>) -> miette::Result<(Setup, Option<String>)> {
        let flags = scorpion_project::Flags {
            port: port.filter(|p| !p.is_empty()).map(str::to_owned),
            ..scorpion_project::Flags::default()
        };
        let resolved = crate::cmd::config::resolve_in(&flags, &project.root)?;
        let port = match port {
            Some(_) => Some(resolved.port()?.value.clone()),
            None => None,
        };
        Ok((
            Setup {
                baud: resolved.baud.value,
                rom: crate::cmd::config::rom(&resolved)?,
                rig: crate::cmd::config::rig(&resolved),
            },
            port,
        ))
    }

    /// A fresh robot with the images loaded as an upload leaves them.
    /// What its scripts print is shown as it runs and when the
    /// [`ports::Shown`] is dropped.
    fn robot(&self, built: &[Built]) -> miette::Result<(romlib::VirtualScorpion, ports::Shown)> {
        let (mut robot, shown) = ports::virtual_robot(self.baud, self.rom.as_ref(), &self.rig)?;
        for image in built {
            robot
                .load_image(&image.linked.image)
                .wrap_err_with(|| format!("cannot load {}", image.name))?;
        }
        Ok((robot, shown))
    }
}

/// Every `tests/*.calls` file: each call on a fresh virtual Scorpion.
fn routine_calls(
    project: &Project,
    setup: &Setup,
    built: &[Built],
    tally: &mut Tally,
) -> miette::Result<()> {
    let mut symbols = std::collections::HashMap::new();
    for image in built {
        for symbol in &image.linked.image.symbols {
            if let Ok(value) = u16::try_from(symbol.value) {
                symbols.entry(symbol.name.clone()).or_insert(value);
            }
        }
    }
    for path in project.test_files("calls") {
        let shown = relative(project, &path);
        let text = hostfs::read_text(&path, hostfs::TEXT)
            .wrap_err_with(|| format!("cannot read {shown}"))?;
        let calls = match crate::project::calls::parse(&text, &symbols) {
            Ok(calls) => calls,
            Err(why) => {
                let name = format!("calls {shown}");
                if tally.selects(&name) {
                    tally.record(&name, Err(format!("  {shown}: {why}")));
                }
                continue;
            }
        };
        for call in calls {
            let name = format!("call {shown}:{} {}", call.line, call.routine);
            if !tally.selects(&name) {
                continue;
            }
            let result = setup
                .robot(built)
                .map_err(|e| format!("{e:?}"))
                .and_then(|(mut robot, _shown)| crate::project::calls::run(&call, &mut robot));
            tally.record(
                &name,
                result.map(|()| "ok").map_err(|why| format!("  {why}")),
            );
        }
    }
    Ok(())
}

/// Every transcript on a fresh virtual Scorpion with the images loaded.
fn virtual_transcripts(
    project: &Project,
    setup: &Setup,
    built: &[Built],
    tally: &mut Tally,
) -> miette::Result<()> {
    let mut robot_time = std::time::Duration::ZERO;
    let started = std::time::Instant::now();
    for path in project.transcripts() {
        let name = format!("transcript {}", relative(project, &path));
        if !tally.selects(&name) {
            continue;
        }
        let result = match setup.robot(built) {
            Ok((robot, shown)) => {
                let mut client = client(ports::Showing::new(VirtualTransport::new(robot), shown));
                let result = run_transcript(project, &path, &mut client, Clock::Robot);
                robot_time += client.transport().now();
                result
            }
            Err(error) => Err(indent(&format!("{error:?}"))),
        };
        tally.record(&name, result.map(|()| "ok"));
    }
    tally.robot_time += robot_time;
    tally.wall_time += started.elapsed();
    Ok(())
}

/// Uploads the images to the robot on `port`, then runs the transcripts.
fn robot_transcripts(
    project: &Project,
    setup: &Setup,
    built: &[Built],
    port: &str,
    tally: &mut Tally,
) -> miette::Result<()> {
    // On `emu` the robot is the virtual one with the project's parts; a
    // real robot has its own cards, and is opened without them.
    let transport = ports::open(port, setup.baud, &setup.rig)?;
    let mut client = client(transport);
    for image in built {
        let upload = UploadImage::try_from(&image.linked.image)?;
        uploader::upload(
            &mut client,
            &upload,
            &uploader::UploadOptions::default(),
            &mut NoProgress,
        )
        .wrap_err_with(|| format!("cannot upload {}", image.name))?;
        tally.record(&format!("upload {}", image.name), Ok("ok"));
    }
    let clock = if port == ports::EMU {
        Clock::Robot
    } else {
        Clock::Line
    };
    for path in project.transcripts() {
        let name = format!("transcript {}", relative(project, &path));
        if !tally.selects(&name) {
            continue;
        }
        let result = run_transcript(project, &path, &mut client, clock);
        tally.record(&name, result.map(|()| "ok"));
    }
    Ok(())
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let found = Found::here()?;
    let started = std::time::Instant::now();
    let mut tally = Tally {
        passed: 0,
        failed: 0,
        filtered_out: 0,
        filter: args.filter.clone().filter(|f| !f.is_empty()),
        robot_time: std::time::Duration::ZERO,
        wall_time: std::time::Duration::ZERO,
        out: std::io::stdout().lock(),
    };
    match found {
        Found::Project(project) => test_project(&project, args, &mut tally)?,
        Found::Workspace(workspace) => {
            if args.port.is_some() {
                miette::bail!(
                    help = "a workspace's members may not fit on one robot together: run `scorpion test --port` in each member's directory",
                    "--port tests one project on the robot, and {FILE} here is a workspace"
                );
            }
            // One process for every member: what is set up once (the
            // scripting engine's library, the ROM's symbols) serves all.
            for (name, project) in workspace.projects()? {
                let _ = writeln!(tally.out, "== {name}");
                let (passed, failed) = (tally.passed, tally.failed);
                if let Err(error) = test_project(&project, args, &mut tally) {
                    tally.record(&format!("project {name}"), Err(format!("{error:?}")));
                }
                let _ = writeln!(
                    tally.out,
                    "{name}: {} passed, {} failed",
                    tally.passed - passed,
                    tally.failed - failed
                );
            }
        }
    }
    if args.timing {
        let _ = writeln!(
            tally.out,
            "transcripts: {:.6} s of robot time in {:.6} s (all tests: {:.6} s)",
            tally.robot_time.as_secs_f64(),
            tally.wall_time.as_secs_f64(),
            started.elapsed().as_secs_f64()
        );
    }
    if let Some(filter) = &tally.filter {
        if tally.passed + tally.failed == 0 {
            miette::bail!(
                help = "NAME is part of a test's name: an image's (`myext`), a snapshot's (`myext/listing`), a file's (`myext.expect`); `scorpion test` lists them all",
                "no test's name contains `{filter}`"
            );
        }
        let _ = writeln!(
            tally.out,
            "{} passed, {} failed, {} filtered out",
            tally.passed, tally.failed, tally.filtered_out
        );
    } else {
        let _ = writeln!(
            tally.out,
            "{} passed, {} failed",
            tally.passed, tally.failed
        );
    }
    Ok(if tally.failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// One project's tests, recorded in `tally`.
fn test_project(project: &Project, args: &Args, tally: &mut Tally) -> miette::Result<()> {
    // Failures of this project only (a workspace runs several).
    let failed_before = tally.failed;
    let mut built = Vec::new();
    for spec in &project.file.images {
        match build(project, spec) {
            Ok(image) => {
                for warning in &image.warnings {
                    let _ = writeln!(std::io::stderr(), "{warning:?}");
                }
                built.push(image);
            }
            Err(error) => tally.record(&format!("build {}", spec.name), Err(format!("{error:?}"))),
        }
    }
    match &args.port {
        Some(port) => {
            let (setup, port) = Setup::of(project, Some(port))?;
            let port = port.unwrap_or_default();
            if tally.failed == failed_before {
                // The rehearsal: every transcript on the virtual robot with
                // the project's cards and world first; the robot is
                // touched only if they all pass.
                virtual_transcripts(project, &setup, &built, tally)?;
            }
            if tally.failed == failed_before {
                robot_transcripts(project, &setup, &built, &port, tally)?;
            } else {
                tally.record(
                    &format!("upload to {port}"),
                    Err("  the rehearsal on the virtual Scorpion failed; nothing was sent to the robot".to_owned()),
                );
            }
        }
        None => {
            for image in &built {
                check_snapshots(project, image, args.mode(), tally)?;
            }
            if built.len() == project.file.images.len() {
                stale_snapshots(project, args.mode(), tally)?;
            }
            if tally.failed == failed_before || built.len() == project.file.images.len() {
                let (setup, _) = Setup::of(project, None)?;
                virtual_transcripts(project, &setup, &built, tally)?;
                routine_calls(project, &setup, &built, tally)?;
            }
        }
    }
    Ok(())
}
