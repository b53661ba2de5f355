//! [`run_tests`]: a project's (or a workspace's members') tests. For every
//! image, snapshots of the assembled output (listing, map, symbols, bytes:
//! nothing of the machine, no times); then every transcript
//! (`tests/*.expect`) on the virtual Scorpion with the images loaded as an
//! upload leaves them and the project's cards and surroundings, and every
//! routine call (`tests/*.calls`); with a port, the transcripts on a real
//! robot after a rehearsal on the virtual one and an upload of the images,
//! and no snapshots.
//!
//! A snapshot that fails leaves its new text beside the accepted one
//! (`NAME.snap.new`, as insta's assertions do) unless the [`Mode`] says
//! otherwise. A filter runs the tests whose name contains it, as `cargo
//! test NAME` does.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use cards::RoomView;
use romlib::VirtualScorpion;
use uploader::transport::{Exchanged, Observed, SerialTransport, VirtualTransport};
use uploader::{Client, ClientConfig, Expectations, Mismatch, RomProfile, Transport, UploadImage};

use crate::undo::{self, UndoFile};

use super::build::{Built, SNAPSHOT_KINDS, build};
use super::calls;
use super::error::{Error, FrontEnd, PathWithoutRoom, Result, WorkspacePort};
use super::report::{Failure, MemberReport, Outcome, Passed, Progress, Question, Report};
use super::review::{self, Decision, Mode};
use super::rig::{EMU, Rig, Scripts, is_world_file, rom, virtual_robot};
use super::room_lines::RoomLine;
use super::snapshot::{self, Compared};
use super::transcript::{self, Clock, Step};
use crate::{Environment, FILE, Flags, Found, Project, Resolved, Sourced};

/// What to run, and how.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Only the tests whose name contains this: an image's (`probe`), one
    /// snapshot (`probe/listing`), one file's (`probe.expect`,
    /// `tests/io.calls`). Empty: all.
    pub filter: Option<String>,
    /// What to do with snapshots that differ.
    pub mode: Mode,
    /// Run the transcripts on the robot on this port (after a rehearsal on
    /// the virtual one, and an upload of the images) instead of the
    /// snapshots: `Some("")` for the port the configuration names.
    pub port: Option<String>,
    /// With a port: replace what the robot has installed where the images
    /// go (an earlier build of the same images, most often), as `scorpion
    /// upload --replace` does, instead of refusing the upload.
    pub replace: bool,
    /// The environment the configuration is resolved with (the line's
    /// rate, the port, the per-user file).
    pub environment: Environment,
    /// Draw each transcript's robot in its room (a world file) to a
    /// picture named after this one and the transcript ([`path_picture`]).
    pub path: Option<PathBuf>,
}

/// Where `--path FILE.svg` puts the picture of the transcript at
/// `transcript`: beside FILE, its stem, a dash, the transcript's stem
/// (`--path out/run.svg` and `tests/patrol.expect`: `out/run-patrol.svg`).
#[must_use]
pub fn path_picture(path: &Path, transcript: &Path) -> PathBuf {
    let stem = |p: &Path| {
        p.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let extension = path
        .extension()
        .map_or_else(|| "svg".to_owned(), |e| e.to_string_lossy().into_owned());
    path.with_file_name(format!("{}-{}.{extension}", stem(path), stem(transcript)))
}

/// Runs the tests of `found` (a project, or every member of a workspace),
/// telling `progress` of each as it goes.
///
/// # Errors
/// What stops the run: a configuration that does not resolve, a snapshot
/// that cannot be written, a robot that cannot be reached. A test that
/// fails is in the report, not an error.
pub fn run_tests(found: &Found, options: &Options, progress: &mut dyn Progress) -> Result<Report> {
    let progress = RefCell::new(progress);
    let mut run = Run {
        report: Report::default(),
        filter: options.filter.clone().filter(|f| !f.is_empty()),
        options,
        progress: &progress,
        started: None,
    };
    if options.path.is_some() {
        rooms_to_draw(found, run.filter.as_deref())?;
    }
    match found {
        Found::Project(project) => run.project(project)?,
        Found::Workspace(workspace) => {
            if options.port.is_some() {
                return Err(Error::WorkspacePort(Box::new(WorkspacePort {
                    root: workspace.root.clone(),
                })));
            }
            // One run for every member: what is set up once (the scripting
            // engine's library, the ROM's symbols) serves all.
            for (name, project) in workspace.projects()? {
                progress.borrow_mut().member_started(&name);
                let (passed, failed) = (run.report.passed, run.report.failed);
                if let Err(error) = run.project(&project) {
                    run.record(
                        &format!("project {name}"),
                        Outcome::Failed(Failure::text(rendered(error))),
                    );
                }
                let member = MemberReport {
                    name,
                    passed: run.report.passed - passed,
                    failed: run.report.failed - failed,
                };
                progress.borrow_mut().member_finished(&member);
                run.report.members.push(member);
            }
        }
    }
    Ok(run.report)
}

/// For `--path`: every project whose transcripts the run selects has a
/// room to draw them in (a world file), checked before anything is built
/// so that the flag is refused once, not by a failure of every
/// transcript.
fn rooms_to_draw(found: &Found, filter: Option<&str>) -> Result<()> {
    let members;
    let projects: Vec<&Project> = match found {
        Found::Project(project) => vec![project],
        Found::Workspace(workspace) => {
            members = workspace.projects()?;
            members.iter().map(|(_, project)| project).collect()
        }
    };
    for project in projects {
        let world = project.file.robot.world.as_deref();
        if world.is_some_and(|w| is_world_file(Path::new(w))) {
            continue;
        }
        let selected = project.transcripts().iter().any(|path| {
            let name = format!("transcript {}", relative(project, path));
            filter.is_none_or(|filter| name.contains(filter))
        });
        if selected {
            return Err(Error::PathWithoutRoom(Box::new(PathWithoutRoom {
                file: project.shown().to_owned(),
                world: world.map(str::to_owned),
            })));
        }
    }
    Ok(())
}

/// The progress, shared between the run and the lines it opens (a line
/// tells what the scripts print as it runs; the run, between exchanges,
/// what passed).
type Shared<'r, 'p> = &'r RefCell<&'p mut dyn Progress>;

/// A run under way.
struct Run<'r, 'p, 'o> {
    report: Report,
    /// The filter, if not empty.
    filter: Option<String>,
    options: &'o Options,
    progress: Shared<'r, 'p>,
    /// The test [`Progress::test_started`] was told of last.
    started: Option<String>,
}

impl Run<'_, '_, '_> {
    /// Records how the test `name` ended.
    fn record(&mut self, name: &str, outcome: Outcome) {
        let progress = self.progress;
        let mut progress = progress.borrow_mut();
        if self.started.take().as_deref() != Some(name) {
            progress.test_started(name);
        }
        match &outcome {
            Outcome::Failed(_) => self.report.failed += 1,
            Outcome::Passed(Passed::NotRun) => self.report.filtered_out += 1,
            Outcome::Passed(_) => self.report.passed += 1,
        }
        progress.test_finished(name, &outcome);
        self.report.tests.push(super::report::TestResult {
            name: name.to_owned(),
            outcome,
        });
    }

    /// [`Run::record`] of a pass or a failure's text.
    fn record_result(&mut self, name: &str, result: Result<Passed, String>) {
        let outcome = match result {
            Ok(passed) => Outcome::Passed(passed),
            Err(why) => Outcome::Failed(Failure::text(why)),
        };
        self.record(name, outcome);
    }

    /// Whether the test `name` runs; counted as filtered out if not.
    fn selects(&mut self, name: &str) -> bool {
        let selected = self
            .filter
            .as_deref()
            .is_none_or(|filter| name.contains(filter));
        if !selected {
            self.report.filtered_out += 1;
        }
        selected
    }

    /// Tells the progress that the test `name` begins.
    fn start(&mut self, name: &str) {
        self.progress.borrow_mut().test_started(name);
        self.started = Some(name.to_owned());
    }

    /// One project's tests.
    fn project(&mut self, project: &Project) -> Result<()> {
        // Failures of this project only (a workspace runs several).
        let failed_before = self.report.failed;
        let mut built = Vec::new();
        for spec in &project.file.images {
            match build(project, spec) {
                Ok(image) => {
                    for warning in &image.warnings {
                        self.progress
                            .borrow_mut()
                            .build_warning(&image.name, warning);
                    }
                    self.progress.borrow_mut().image_built(&image);
                    built.push(image);
                }
                Err(error) => {
                    self.record_result(&format!("build {}", spec.name), Err(rendered(error)))
                }
            }
        }
        match &self.options.port {
            Some(port) => {
                let (setup, resolved) = Setup::of(project, Some(port), &self.options.environment)?;
                let sourced = resolved.port()?.clone();
                let port = sourced.value.clone();
                if self.report.failed == failed_before {
                    // The rehearsal: every transcript on the virtual robot
                    // with the project's cards and world first; the robot
                    // is touched only if they all pass.
                    self.virtual_transcripts(project, &setup, &built)?;
                    self.virtual_checks();
                }
                if self.report.failed == failed_before {
                    self.robot_transcripts(project, &setup, &built, &sourced)?;
                } else {
                    self.record_result(
                        &format!("upload to {port}"),
                        Err("  the rehearsal on the virtual Scorpion failed; nothing was sent to the robot".to_owned()),
                    );
                }
            }
            None => {
                let mode = self.options.mode;
                for image in &built {
                    self.check_snapshots(project, image, mode)?;
                }
                if built.len() == project.file.images.len() {
                    self.stale_snapshots(project, mode)?;
                }
                if self.report.failed == failed_before || built.len() == project.file.images.len() {
                    let (setup, _) = Setup::of(project, None, &self.options.environment)?;
                    self.virtual_transcripts(project, &setup, &built)?;
                    self.routine_calls(project, &setup, &built)?;
                    self.virtual_checks();
                }
            }
        }
        Ok(())
    }

    /// The observer's checks over the project's virtual runs
    /// ([`Progress::virtual_runs_done`]), recorded as tests.
    fn virtual_checks(&mut self) {
        let filtered = self.filter.is_some();
        let checks = self.progress.borrow_mut().virtual_runs_done(filtered);
        for (name, outcome) in checks {
            self.record(&name, outcome);
        }
    }

    /// What [`Progress::review`] decides about the snapshot `name`.
    fn ask(&mut self, name: &str, why: &str, accept: &str) -> Result<Decision> {
        self.progress
            .borrow_mut()
            .review(&Question { name, why, accept })
            .map_err(|error| Error::Review(FrontEnd(error)))
    }

    fn check_snapshots(&mut self, project: &Project, built: &Built, mode: Mode) -> Result<()> {
        for (kind, content) in built.snapshots() {
            let name = format!("{}/{kind}", built.name);
            if !self.selects(&name) {
                continue;
            }
            self.start(&name);
            let path = project.snapshot_path(&built.name, kind);
            let pending = snapshot::pending_path(&path);
            let compared = snapshot::compare(&path, &content);
            if compared == Compared::Same {
                // A pending text from an earlier failure is out of date.
                review::remove(&pending)?;
                self.record_result(&name, Ok(Passed::Ok));
                continue;
            }
            let shown = relative(project, &path);
            let (why, diff) = match &compared {
                Compared::New => (
                    format!("  no snapshot {shown} yet:\n{}", indent(&content)),
                    None,
                ),
                Compared::Changed(diff) => (
                    format!("  {shown} differs (- snapshot, + now):\n{}", indent(diff)),
                    Some(diff.clone()),
                ),
                Compared::Same => (String::new(), None),
            };
            let decision = match mode {
                Mode::Accept => Decision::Accept,
                Mode::Reject => Decision::Reject,
                Mode::Fail => Decision::Skip,
                Mode::Review => self.ask(&name, &why, "accept")?,
            };
            let rendered = snapshot::render(FILE, &name, &content);
            review::decide(decision, &path, &rendered)?;
            // The review showed the diff already.
            let why = if mode == Mode::Review {
                String::new()
            } else {
                why
            };
            let outcome = match decision {
                Decision::Accept => Outcome::Passed(Passed::Accepted),
                Decision::Reject => Outcome::Failed(Failure {
                    text: format!("{why}  rejected: the snapshot stays as it was\n"),
                    diff,
                    pending: None,
                }),
                Decision::Skip => {
                    let shown = relative(project, &pending);
                    Outcome::Failed(Failure {
                        text: format!(
                            "{why}  the new one is in {shown}: `scorpion test {name} --accept` takes it, `scorpion test --review` (or `cargo insta review`) asks\n"
                        ),
                        diff,
                        pending: Some(pending),
                    })
                }
            };
            self.record(&name, outcome);
        }
        Ok(())
    }

    /// Snapshot files no image and kind of the project makes (an image
    /// renamed or removed): a failure, or deleted with [`Mode::Accept`]
    /// (pending ones with [`Mode::Reject`] too).
    fn stale_snapshots(&mut self, project: &Project, mode: Mode) -> Result<()> {
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
            if !self.selects(&name) {
                continue;
            }
            let pending = path.extension().is_some_and(|ext| ext == "new");
            let why = format!("  no image of {FILE} makes {shown}\n");
            let decision = match mode {
                Mode::Accept => Decision::Accept,
                Mode::Reject if pending => Decision::Accept,
                Mode::Reject | Mode::Fail => Decision::Skip,
                Mode::Review if pending => Decision::Skip,
                Mode::Review => {
                    self.start(&name);
                    self.ask(&name, &why, "delete it")?
                }
            };
            match decision {
                Decision::Accept => {
                    review::remove(&path)?;
                    self.record_result(&name, Ok(Passed::Deleted));
                }
                // A pending text nothing makes is left for whoever made it.
                Decision::Reject | Decision::Skip if pending => {}
                Decision::Reject | Decision::Skip => self.record_result(
                    &name,
                    Err(format!(
                        "{why}  `scorpion test --accept` deletes it, `scorpion test --review` asks\n"
                    )),
                ),
            }
        }
        Ok(())
    }

    /// A fresh robot of `setup` with the images loaded as an upload
    /// leaves them, ready for the test `name`.
    fn robot(
        &mut self,
        setup: &Setup,
        built: &[Built],
        name: &str,
    ) -> Result<(VirtualScorpion, Scripts)> {
        let progress = self.progress;
        let mut progress = progress.borrow_mut();
        let (mut robot, scripts) = virtual_robot(
            setup.baud,
            setup.rom.as_ref(),
            &setup.rig,
            &mut |card, start, end| {
                progress.card_mapped(card, start, end);
            },
        )?;
        for image in built {
            robot
                .load_image(&image.linked.image)
                .map_err(|source| Error::Load {
                    image: image.name.clone(),
                    source,
                })?;
        }
        progress.robot_ready(name, &mut robot);
        Ok((robot, scripts))
    }

    /// Every `tests/*.calls` file: each call on a fresh virtual Scorpion.
    fn routine_calls(&mut self, project: &Project, setup: &Setup, built: &[Built]) -> Result<()> {
        let mut symbols = HashMap::new();
        for image in built {
            for symbol in &image.linked.image.symbols {
                if let Ok(value) = u16::try_from(symbol.value) {
                    symbols.entry(symbol.name.clone()).or_insert(value);
                }
            }
        }
        for path in project.test_files("calls") {
            let shown = relative(project, &path);
            let text = hostfs::read_text(&path, hostfs::TEXT).map_err(|source| Error::Read {
                shown: shown.clone(),
                path: path.clone(),
                source,
            })?;
            let calls = match calls::parse(&text, &symbols) {
                Ok(calls) => calls,
                Err(why) => {
                    let name = format!("calls {shown}");
                    if self.selects(&name) {
                        self.record_result(&name, Err(format!("  {shown}: {why}")));
                    }
                    continue;
                }
            };
            for call in calls {
                let name = format!("call {shown}:{} {}", call.line, call.routine);
                if !self.selects(&name) {
                    continue;
                }
                self.start(&name);
                let result = match self.robot(setup, built, &name) {
                    Ok((mut robot, scripts)) => {
                        let result = calls::run(&call, &mut robot);
                        let mut progress = self.progress.borrow_mut();
                        show(&scripts, &mut **progress);
                        progress.robot_done(&name, &mut robot);
                        result
                    }
                    Err(error) => Err(rendered(error)),
                };
                self.record_result(
                    &name,
                    result
                        .map(|()| Passed::Ok)
                        .map_err(|why| format!("  {why}")),
                );
            }
        }
        Ok(())
    }

    /// Every transcript on a fresh virtual Scorpion with the images loaded.
    fn virtual_transcripts(
        &mut self,
        project: &Project,
        setup: &Setup,
        built: &[Built],
    ) -> Result<()> {
        let mut robot_time = Duration::ZERO;
        let started = Instant::now();
        for path in project.transcripts() {
            let name = format!("transcript {}", relative(project, &path));
            if !self.selects(&name) {
                continue;
            }
            self.start(&name);
            let result = match self.robot(setup, built, &name) {
                Ok((robot, scripts)) => {
                    let room = setup.rig.room.get().map(|view| InRoom {
                        view,
                        opened: robot.cycles(),
                    });
                    let line = Showing::new(
                        VirtualTransport::new(robot),
                        Tell {
                            scripts,
                            progress: self.progress,
                        },
                    );
                    let mut client = client(line);
                    let mut commands = Vec::new();
                    let result = run_transcript(
                        project,
                        &path,
                        &mut client,
                        Clock::Robot,
                        room.as_ref(),
                        &mut commands,
                    );
                    robot_time += client.transport().now();
                    done(client.transport(), &name);
                    match (&self.options.path, &room) {
                        (Some(picture), Some(room)) => {
                            let file = path_picture(picture, &path);
                            // A PNG that cannot be made is a picture not written.
                            let picture = room.view.picture_for(&file, &commands).map_err(|e| {
                                Error::Write {
                                    path: file.clone(),
                                    source: std::io::Error::other(e.to_string()),
                                }
                            })?;
                            // Whole or not at all: through a file renamed over it.
                            hostfs::write(&file, &picture).map_err(|error| Error::Write {
                                path: file.clone(),
                                source: match error {
                                    hostfs::Error::Write { cause, .. } => cause,
                                    other => std::io::Error::other(other.to_string()),
                                },
                            })?;
                            result
                        }
                        // Refused before the run ([`rooms_to_draw`]).
                        (Some(_), None) => Err(indent(
                            "--path draws the robot in its room, and the robot has none: \
                             give the project a world file (`world = \"room.toml\"` under \
                             [robot] in Scorpion.toml; docs/WORLD.md)",
                        )),
                        _ => result,
                    }
                }
                Err(error) => Err(indent(&rendered(error))),
            };
            self.record_result(&name, result.map(|()| Passed::Ok));
        }
        self.report.robot_time += robot_time;
        self.report.wall_time += started.elapsed();
        Ok(())
    }

    /// Uploads the images to the robot on `port`, then runs the
    /// transcripts.
    fn robot_transcripts(
        &mut self,
        project: &Project,
        setup: &Setup,
        built: &[Built],
        sourced: &Sourced<String>,
    ) -> Result<()> {
        let port = sourced.value.as_str();
        // On `emu` the robot is the virtual one with the project's parts; a
        // real robot has its own cards, and is opened without them.
        let progress = self.progress;
        let transport: Box<dyn Transport + '_> = if port == EMU {
            let (robot, scripts) = {
                let mut progress = progress.borrow_mut();
                virtual_robot(setup.baud, None, &setup.rig, &mut |card, start, end| {
                    progress.card_mapped(card, start, end);
                })?
            };
            Box::new(Showing::new(
                VirtualTransport::new(robot),
                Tell { scripts, progress },
            ))
        } else {
            // A port that came from a file or the environment is named
            // with where it came from, as every other command names it.
            let opened = SerialTransport::open(port, setup.baud);
            // A bare `--port` before a filter takes the filter as the
            // port (fresh21 F1): one that is no device is named as the
            // flag's.
            let device = crate::device_like(port);
            Box::new(opened.map_err(|source| match &sourced.origin {
                crate::resolve::Origin::Flag(_) if device => Error::Upload(source),
                crate::resolve::Origin::Flag(_) => Error::PortTaken {
                    port: port.to_owned(),
                    source: Box::new(source),
                },
                origin => Error::PortOpen {
                    port: port.to_owned(),
                    origin: origin.clone(),
                    source: Box::new(source),
                },
            })?)
        };
        let mut client = client(transport);
        let options = uploader::UploadOptions {
            replace: self.options.replace,
            ..uploader::UploadOptions::default()
        };
        // A real robot's uploads keep what they overwrote, as `scorpion
        // upload`'s do, in the project's undo file (fresh10 F22: none was
        // kept); `emu` is a fresh virtual Scorpion with nothing to undo.
        let mut undo = (port != EMU).then(|| UndoFile::new(undo::in_project(&project.root)));
        // The ids of the images this run left on the robot, for what a
        // reset during a later one freed.
        let mut uploaded_here: Vec<(u32, String)> = Vec::new();
        // recheck24: all or none, as `scorpion upload` (a full table took
        // the first images, then refused the next). Said as the upload of
        // the image in the way (fresh25 F5).
        if port != EMU && built.len() > 1 {
            let images = built
                .iter()
                .map(|built| {
                    Ok((
                        built.name.as_str(),
                        UploadImage::try_from(&built.linked.image)?,
                    ))
                })
                .collect::<Result<Vec<_>>>()?;
            let named: Vec<(&str, &UploadImage)> =
                images.iter().map(|(name, image)| (*name, image)).collect();
            if let Err(source) = uploader::refuse_what_cannot_go_in(
                &mut client,
                &options.profile,
                &named,
                options.replace,
            ) {
                let image = match &source {
                    uploader::Error::ImageInTheWay { image, .. } => image.clone(),
                    // recheck26 N6: the project's images together (a
                    // table too full for them all).
                    _ => built
                        .iter()
                        .map(|built| built.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                };
                let name = format!("upload {image}");
                self.start(&name);
                let silent = silent_note(&source, sourced);
                let mut why = indent(&rendered(Error::UploadImage {
                    image,
                    source: Box::new(source),
                }));
                why.push_str(&silent);
                self.record_result(&name, Err(why));
                return Ok(());
            }
        }
        for image in built {
            let name = format!("upload {}", image.name);
            self.start(&name);
            if let Some(why) = undo.as_ref().and_then(|undo| undo_refused(&undo.path)) {
                self.record_result(&name, Err(why));
                return Ok(());
            }
            let upload = UploadImage::try_from(&image.linked.image)?;
            let mut seen = HooksSeen::default();
            let uploaded = match undo.as_mut() {
                Some(undo) => {
                    uploader::upload_keeping(&mut client, &upload, &options, &mut seen, undo)
                }
                None => uploader::upload(&mut client, &upload, &options, &mut seen),
            };
            // fresh14 F5: the hint only where something installed is in
            // the way, not after every failure (a robot that is not there).
            let in_the_way = matches!(
                uploaded,
                Err(uploader::Error::Robot(_) | uploader::Error::HookInUse { .. })
            );
            // recheck23 F2: a silent robot on a port a file or the
            // environment named: where it came from.
            if let Ok(report) = &uploaded {
                for &(kind, from) in &report.dropped {
                    self.report.dropped.push((
                        image.name.clone(),
                        format!("{} led to ${from:04X}", kind.rom_symbol()),
                    ));
                }
                for old in &report.replaced {
                    self.report
                        .replaced
                        .push((image.name.clone(), old.describe()));
                }
                // hostile21 F12: what a reset freed is named as the
                // project's image it is, and no longer said to be left
                // installed.
                for old in &report.reset_freed {
                    let ours = uploaded_here.iter().find(|(id, _)| *id == old.id);
                    let named = match ours {
                        Some((_, name)) => format!("{name} ({})", old.describe()),
                        None => old.describe(),
                    };
                    if let Some((_, name)) = ours {
                        self.report.left_installed.retain(|left| left != name);
                    }
                    self.report.reset_freed.push((image.name.clone(), named));
                }
                // hostile22 F6: a reset frees every entry: this run's
                // earlier images too, whether or not the upload could name
                // them (one early in it found the table empty), as
                // `scorpion upload` tells them.
                let ids: Vec<u32> = uploaded_here.iter().map(|(id, _)| *id).collect();
                let gone = report.gone(&ids);
                for (_, name) in uploaded_here.iter().filter(|(id, _)| gone.contains(id)) {
                    if self.report.left_installed.contains(name) {
                        self.report.left_installed.retain(|left| left != name);
                        self.report
                            .reset_freed
                            .push((image.name.clone(), name.clone()));
                    }
                }
                // Where a hook moved and nothing freed was named, what it
                // led to (hostile25 F8: said beside the image it was).
                if report.reset_freed.is_empty() && gone.is_empty() {
                    for &(hook, before, after) in &seen.changed {
                        self.report.reset_freed.push((
                            image.name.clone(),
                            format!(
                                "what {hook} led to (${before:04X}; it leads to ${after:04X} now)"
                            ),
                        ));
                    }
                }
            }
            let silent = uploaded
                .as_ref()
                .err()
                .map(|error| silent_note(error, sourced))
                .unwrap_or_default();
            let uploaded = uploaded.map_err(|source| Error::UploadImage {
                image: image.name.clone(),
                source: Box::new(source),
            });
            if let Err(error) = uploaded {
                // A failed upload is a failed test, said like the others;
                // the transcripts would only test what the robot had.
                let mut why = indent(&rendered(error));
                if let Some(undo) = undo.as_ref().filter(|undo| undo.uploading()) {
                    why.push_str(&format!(
                        "    (what the robot held before it is kept in {} (marked {}): `scorpion upload --undo` puts it back)\n",
                        undo.path.display(),
                        undo::UPLOADING
                    ));
                }
                why.push_str(&silent);
                if !self.options.replace && in_the_way {
                    why.push_str(
                        "    (`scorpion test --port --replace` replaces what the robot has there)\n",
                    );
                }
                self.record_result(&name, Err(why));
                return Ok(());
            }
            if let Some(undo) = &undo {
                undo.finished_upload();
                if let Some(error) = &undo.failed {
                    self.record_result(
                        &name,
                        Err(indent(&format!(
                            "uploaded, but its undo file {} could not be written: {error}\n",
                            undo.path.display()
                        ))),
                    );
                    return Ok(());
                }
            }
            self.record_result(&name, Ok(Passed::Ok));
            if port != EMU {
                let first = self.report.left_installed.is_empty();
                let kept_older = undo.as_ref().is_some_and(|undo| undo.kept_older);
                self.report.kept_older_undo = kept_older && (first || self.report.kept_older_undo);
                self.report.left_installed.push(image.name.clone());
                uploaded_here.push((upload.id(), image.name.clone()));
            }
        }
        let clock = if port == EMU {
            Clock::Robot
        } else {
            Clock::Line
        };
        let started = Instant::now();
        for path in project.transcripts() {
            let name = format!("transcript {}", relative(project, &path));
            if !self.selects(&name) {
                continue;
            }
            self.start(&name);
            // The robot on a port is seen through its line alone: the
            // room lines were checked in the rehearsal, and are refused here.
            let result = run_transcript(project, &path, &mut client, clock, None, &mut Vec::new());
            // fresh13 F3: the rehearsal had the project's cards; a robot
            // that answers otherwise may lack one.
            let result = result.map_err(|why| match cards_hint(setup, port) {
                Some(hint) => format!("{why}{hint}"),
                None => why,
            });
            self.record_result(&name, result.map(|()| Passed::Ok));
        }
        *self.report.port_time.get_or_insert_default() += started.elapsed();
        Ok(())
    }
}

/// recheck23 F2: a silent robot on a port a file or the environment
/// named: where it came from (a line of a test's failure).
fn silent_note(error: &uploader::Error, sourced: &Sourced<String>) -> String {
    match (error, &sourced.origin) {
        (uploader::Error::NoAnswer { .. }, origin)
            if !matches!(origin, crate::resolve::Origin::Flag(_)) =>
        {
            format!("    (the port {} is from the {origin})\n", sourced.value)
        }
        _ => String::new(),
    }
}

/// `error` as the front end's miette handler renders it, for a test's
/// failure.
fn rendered(error: Error) -> String {
    format!("{:?}", miette::Report::new(error))
}

fn indent(text: &str) -> String {
    text.lines().fold(String::new(), |mut out, line| {
        let _ = writeln!(out, "    {line}");
        out
    })
}

/// `path` as shown to the user: relative to the project's root.
fn relative(project: &Project, path: &Path) -> String {
    path.strip_prefix(&project.root)
        .unwrap_or(path)
        .display()
        .to_string()
}

/// The room a transcript's robot is in, and the robot time (cycles) its
/// line was opened at: the line's clock counts from it, the room's from 0.
struct InRoom {
    view: RoomView,
    opened: u64,
}

/// Lets robot time pass on `client`'s line for `time`, dropping what the
/// robot says meanwhile.
fn wait<T: Transport>(client: &mut Client<T>, time: Duration) -> uploader::Result<()> {
    let line = client.transport();
    let until = line.now() + time;
    let mut dropped = Vec::new();
    loop {
        let now = line.now();
        if now >= until {
            return Ok(());
        }
        dropped.clear();
        line.receive(&mut dropped, until - now)?;
    }
}

/// Runs the transcript at `path` on `client`: every line that differs is
/// a line of the failure. With a `room`, its room lines are checked and
/// each command is added to `commands` with its robot time (for the
/// picture of the path).
/// Why an upload may not write the project's undo file at `path` now
/// (an unfinished upload or undo keeps what the robot held), with its
/// directory made.
fn undo_refused(path: &Path) -> Option<String> {
    if let Some(what) = undo::unfinished(path) {
        return Some(indent(&format!(
            "{}: `scorpion upload --undo` first; nothing was sent\n",
            what.said(path)
        )));
    }
    let parent = path.parent()?;
    std::fs::create_dir_all(parent)
        .err()
        .map(|error| indent(&format!("cannot make {}: {error}\n", parent.display())))
}

fn run_transcript<T: Transport>(
    project: &Project,
    path: &Path,
    client: &mut Client<T>,
    clock: Clock,
    room: Option<&InRoom>,
    commands: &mut Vec<(u64, String)>,
) -> Result<(), String> {
    let shown = relative(project, path);
    let transcript = transcript::read(path, &shown).map_err(|e| indent(&rendered(e)))?;
    let failed = |e: uploader::Error| indent(&format!("{:?}", miette::Report::new(e)));
    let mismatches = match room {
        None => {
            if let Some(line) = transcript.first_room_line() {
                let refused = match clock {
                    Clock::Line => transcript::no_room_on_port(&shown, line),
                    Clock::Robot => transcript::no_room(&shown, line),
                };
                return Err(indent(&rendered(refused)));
            }
            transcript
                .expectations()
                .check_all(client)
                .map_err(failed)?
                .mismatches
        }
        Some(room) => {
            let started = client.transport().now();
            let mut mismatches = Vec::new();
            let mut bumps_seen = 0;
            for step in &transcript.steps {
                let now = client.transport().now();
                let at = now.saturating_sub(started);
                match step {
                    Step::Command(expectation) => {
                        let sent = u64::try_from(now.as_micros()).unwrap_or(u64::MAX);
                        commands.push((
                            room.opened.saturating_add(sent),
                            expectation.command.to_string(),
                        ));
                        let one = Expectations {
                            lines: vec![expectation.clone()],
                        };
                        let checked = one.check_all(client).map_err(failed)?;
                        mismatches.extend(checked.mismatches.into_iter().map(|mut m| {
                            m.at += at;
                            m
                        }));
                    }
                    Step::Room(_, RoomLine::Wait(time)) => {
                        wait(client, *time).map_err(failed)?;
                    }
                    Step::Room(line, RoomLine::Pose(check)) => {
                        if let Some(found) = check.check(&room.view) {
                            mismatches.push(Mismatch {
                                line: *line,
                                command: "pose".into(),
                                expected: check.expected(),
                                found,
                                at,
                            });
                        }
                    }
                    Step::Room(line, RoomLine::Bumped(check)) => {
                        let bumps = room.view.trail().bumps;
                        let since = &bumps[bumps_seen.min(bumps.len())..];
                        bumps_seen = bumps.len();
                        if let Some(found) = check.check(since) {
                            mismatches.push(Mismatch {
                                line: *line,
                                command: "bumped".into(),
                                expected: check.expected(),
                                found,
                                at,
                            });
                        }
                    }
                }
            }
            mismatches
        }
    };
    if mismatches.is_empty() {
        Ok(())
    } else {
        Err(transcript::describe(&shown, &mismatches, clock)
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

/// For a transcript that failed on a robot on a port: the cards the
/// rehearsal had on its KIM bus, which the robot may lack.
fn cards_hint(setup: &Setup, port: &str) -> Option<String> {
    if port == EMU || setup.rig.cards.is_empty() {
        return None;
    }
    let cards: Vec<String> = setup
        .rig
        .cards
        .iter()
        .map(|card| card.path.display().to_string())
        .collect();
    Some(format!(
        "    (the rehearsal passed with the project's cards on the KIM bus: {}; does the robot have them, at the same addresses?)\n",
        cards.join(", ")
    ))
}

/// What every virtual robot of a run is made of, read once: the line's
/// rate, the project's ROM profile, its cards and surroundings.
struct Setup {
    baud: u32,
    rom: Option<(String, linker::Image)>,
    rig: Rig,
}

impl Setup {
    /// The virtual robot the one resolution gives `project` (its cards,
    /// world and ROM profile; the rate from the environment, the per-user
    /// file or the project), and that resolution, whose port is `port`
    /// where one is given (`Some("")`: the configured one).
    fn of(
        project: &Project,
        port: Option<&str>,
        environment: &Environment,
    ) -> Result<(Setup, Resolved)> {
        let flags = Flags {
            port: port.filter(|p| !p.is_empty()).map(str::to_owned),
            ..Flags::default()
        };
        let resolved = Resolved::resolve(&flags, environment, &project.root)?;
        let setup = Setup {
            baud: resolved.baud.value,
            rom: rom(&resolved)?,
            rig: Rig::of(&resolved),
        };
        Ok((setup, resolved))
    }
}

/// The hooks an upload found changed under it (a reset), from its
/// progress: said with what the reset freed.
#[derive(Default)]
struct HooksSeen {
    /// Each hook (its name), where it led, and where it leads now.
    changed: Vec<(&'static str, u16, u16)>,
}

impl uploader::Progress for HooksSeen {
    fn event(&mut self, event: &uploader::Event) {
        if let uploader::Event::HookChanged {
            kind,
            before,
            after,
        } = event
            && !self
                .changed
                .iter()
                .any(|(k, b, _)| *k == kind.rom_symbol() && b == before)
        {
            self.changed.push((kind.rom_symbol(), *before, *after));
        }
    }
}

/// Tells `progress` what the scripts printed since the last look.
fn show(scripts: &Scripts, progress: &mut dyn Progress) {
    for (name, printed) in scripts {
        for line in printed.take() {
            progress.script_printed(name, &line);
        }
    }
}

/// What a virtual robot's scripts print, told to the progress after
/// every exchange on its line and when dropped.
struct Tell<'r, 'p> {
    scripts: Scripts,
    progress: Shared<'r, 'p>,
}

impl Tell<'_, '_> {
    fn show(&self) {
        show(&self.scripts, &mut **self.progress.borrow_mut());
    }
}

impl Exchanged for Tell<'_, '_> {
    fn exchanged(&mut self) {
        self.show();
    }
}

impl Drop for Tell<'_, '_> {
    fn drop(&mut self) {
        self.show();
    }
}

/// A line to the virtual robot that tells what its scripts print.
type Showing<'r, 'p, T> = Observed<T, Tell<'r, 'p>>;

/// The test `name` is done with the robot on `line`.
fn done(line: &mut Showing<'_, '_, VirtualTransport>, name: &str) {
    let (inner, tell) = line.parts_mut();
    tell.show();
    tell.progress
        .borrow_mut()
        .robot_done(name, inner.robot_mut());
}
