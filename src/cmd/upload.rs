//! `scorpion upload`: rehearse an image on the virtual Scorpion, put it
//! into a robot, verify every byte, then switch its hooks.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use miette::Context;
use romlib::protocol::{Answer, Command};
use uploader::transport::VirtualTransport;
use uploader::{
    Client, ClientConfig, Event, Expectations, LoaderChoice, NoProgress, Phase, Progress,
    RomProfile, Transport, UploadImage, UploadOptions, UploadReport,
};

use crate::cmd::ports;
use scorpion_project::runner::transcript::{self, Clock, TranscriptFailed};
use scorpion_project::undo::{
    FurtherBack, UNDOING, UNDONE, UPLOADING, UndoFile, Unfinished, marked,
};

/// Upload a linked image (`scorpion link` or `scorpion build` output) into
/// the robot with its own RAM-write commands: every byte verified with
/// `/7R` reads while the writes go out, what differs rewritten, hooks
/// switched only after the whole body verified.
///
/// First the same upload is rehearsed on the virtual Scorpion in this
/// process and, with --expect, the image is put through its paces there:
/// any difference stops before the robot is touched. Larger images go
/// through a RAM loader (a small 6502 program the uploader installs in two
/// parts, each verified before it is hooked, and removes afterwards) that
/// carries about one byte per character instead of the ROM's two per
/// eleven, at 19200 baud when the line allows.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The linked ELF image; none: the images of the project
    /// (`Scorpion.toml` here or above), built first.
    image: Option<PathBuf>,
    #[command(flatten)]
    line: ports::Line,
    /// Commands and the answers they must produce (`/1Q => QHELLO`, one a
    /// line, `#` comments): checked on the rehearsal (a virtual Scorpion
    /// with this image alone; never sent to a real robot), and with
    /// `--port emu` again after the upload.
    #[arg(long, value_name = "FILE")]
    expect: Option<PathBuf>,
    /// Skip the rehearsal on the virtual Scorpion.
    #[arg(long)]
    no_dry_run: bool,
    /// Replace an installed extension the image overlaps: it is taken out
    /// of its hooks' chains (verified) before the image is written. Without
    /// it such an upload is refused; `scorpion installed` lists what is there.
    #[arg(long)]
    replace: bool,
    /// The RAM loader: `auto` uses it when it is faster, or the robot may
    /// hold the image already (compared by checksums), and it can go in
    /// beside what is installed; the upload says why where it does not.
    #[arg(long, value_enum, default_value_t = Loader::Auto)]
    loader: Loader,
    /// The rate the loader switches the line to for the transfer; 0 keeps
    /// --baud (for a line whose far end cannot follow).
    #[arg(long, default_value_t = uploader::FAST_BAUD, value_name = "BAUD", value_parser = fast_baud)]
    fast_baud: u32,
    /// Characters sent ahead of an answer not yet received; 0 waits for
    /// each answer. By default the reference ROM's receive buffer, less one
    /// command.
    #[arg(long)]
    window: Option<usize>,
    /// Write every byte. By default an upload through the RAM loader
    /// compares checksums computed on the robot and writes only the ranges
    /// that differ.
    #[arg(long)]
    full: bool,
    /// Undo the last upload: put back what it overwrote (its undo file),
    /// verified, hooks last, instead of uploading.
    #[arg(long, conflicts_with_all = ["image", "full", "replace"])]
    undo: bool,
    /// Where an upload keeps what it overwrites and `--undo` finds it
    /// [default: target/scorpion/last-upload.undo in a project, else
    /// scorpion-last-upload.undo here]. Not on `--port emu`, whose robot
    /// lasts one command.
    #[arg(long, value_name = "FILE")]
    undo_file: Option<PathBuf>,
}

/// What an upload interrupted left: whether `kept` says its undo file
/// (`undo`) was written.
fn upload_interrupted(undo: &Path, kept: &std::sync::atomic::AtomicBool) -> String {
    // The mark, not only the flag: a project's later image interrupted
    // before it kept anything has the flag of the one before (fresh21 F4).
    if kept.load(std::sync::atomic::Ordering::Relaxed) && marked(undo, UPLOADING).exists() {
        format!(
            "interrupted: the upload did not finish; nothing that did not verify is hooked\n  `scorpion upload --undo` puts back what the robot held before it (kept in {}); then upload again",
            undo.display()
        )
    } else {
        "interrupted before anything of the image was written; nothing that did not verify is hooked".to_owned()
    }
}

/// Refuses an upload that would replace the undo file of one that did not
/// finish (marked [`UPLOADING`]): that file keeps what the robot held
/// before it, which nothing else does.
fn refuse_unfinished(undo: &Path) -> miette::Result<()> {
    match scorpion_project::undo::unfinished(undo) {
        None => Ok(()),
        // fresh10 F10: a new undo file would take that undo's place, and
        // the mark would then be taken for this one's.
        Some(what @ Unfinished::Undo) => Err(miette::miette!(
            code = "upload::undo_unfinished",
            help = "`scorpion upload --undo` finishes it (the robot as it was before the upload it undoes), then upload again",
            "{}; nothing was sent",
            what.said(undo)
        )),
        Some(what @ Unfinished::Upload) => Err(miette::miette!(
            code = "upload::unfinished",
            help = format!(
                "`scorpion upload --undo` puts the robot back as it was before that upload, then upload again; or keep this upload's undo elsewhere (`--undo-file`); deleting {} gives that undo up",
                marked(undo, UPLOADING).display()
            ),
            "{}, and this upload's undo file would replace it; nothing was sent",
            what.said(undo)
        )),
    }
}

impl Args {
    /// The undo file: `--undo-file`, the project's, or one here.
    fn undo_path(&self) -> PathBuf {
        if let Some(path) = &self.undo_file {
            return path.clone();
        }
        match scorpion_project::Project::here() {
            Ok(project) => scorpion_project::undo::in_project(&project.root),
            Err(_) => PathBuf::from("scorpion-last-upload.undo"),
        }
    }
}

/// `--loader`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Loader {
    /// When it is faster or the robot may hold the image, and it can go in
    /// beside what is installed.
    Auto,
    /// Never: the ROM's `/9W` for every byte.
    Never,
    /// Always, or fail saying why not.
    Always,
}

impl Args {
    fn options(&self) -> UploadOptions {
        UploadOptions {
            loader: match self.loader {
                Loader::Auto => LoaderChoice::Auto,
                Loader::Never => LoaderChoice::Never,
                Loader::Always => LoaderChoice::Always,
            },
            fast_baud: (self.fast_baud != 0).then_some(self.fast_baud),
            replace: self.replace,
            delta: !self.full,
            ..UploadOptions::default()
        }
    }

    fn client<T: Transport>(&self, transport: T, profile: &RomProfile) -> Client<T> {
        Client::new(
            transport,
            ClientConfig {
                window: self.window.unwrap_or_else(|| profile.window()),
                ..ClientConfig::default()
            },
        )
    }
}

/// A progress bar on stderr (hidden when stderr is not a terminal), with
/// bytes/s and ETA.
struct Bar {
    bar: ProgressBar,
    /// The warnings said: one the upload meets again (a hook found changed
    /// on each of its tries) is said once (recheck21).
    said: Vec<String>,
}

impl Bar {
    fn new() -> Bar {
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{msg:>10} [{bar:32}] {bytes}/{total_bytes} {bytes_per_sec} ETA {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        Bar {
            bar,
            said: Vec::new(),
        }
    }

    fn say(&self, line: &str) {
        self.bar
            .suspend(|| crate::cmd::say_err(&format!("{line}\n")));
    }
}

impl Progress for Bar {
    fn phase(&mut self, phase: Phase, total: usize) {
        let name = match phase {
            Phase::Connect => "connecting",
            Phase::Loader => "loader",
            Phase::Write => "writing",
            Phase::FinalVerify => "verifying",
            Phase::Hooks => "hooking",
        };
        self.bar.set_message(name);
        self.bar.set_length(total as u64);
        self.bar.set_position(0);
    }

    fn advanced(&mut self, done: usize) {
        self.bar.set_position(done as u64);
    }

    fn event(&mut self, event: &Event) {
        // Line faults are routine and the summary counts them; changes to
        // the robot's hooks and rate deserve a line of their own.
        let line = match event {
            Event::HookChanged {
                kind,
                before,
                after,
            } => {
                format!(
                    "warning: {} changed from ${before:04X} to ${after:04X} during the upload (a reset? A /1R frees every installed extension: what it led to is no longer installed; `scorpion installed` lists what is)",
                    kind.rom_symbol()
                )
            }
            Event::HookDisarmed { kind, from, to } => format!(
                "{} pointed into the upload (${from:04X}); pointed it at ${to:04X} while the upload runs (it is hooked to the image again at the end)",
                kind.rom_symbol()
            ),
            Event::WayOutDropped {
                kind,
                from,
                slot: None,
                why,
                path,
            } => format!(
                "warning: {} led to ${from:04X}, which {why} ({path}): the image falls through to the ROM's target instead",
                kind.rom_symbol()
            ),
            // recheck27 P2: said as the hook's own way, "HOOK_UNKNOWN led
            // to $0000" where it led into the upload.
            Event::WayOutDropped {
                kind,
                from,
                slot: Some(slot),
                why,
                path,
            } => format!(
                "warning: {} led into the upload, and the chain slot there (${slot:04X}) to ${from:04X}, which {why} ({path}): the image falls through to the ROM's target instead",
                kind.rom_symbol()
            ),
            Event::LoaderRestored { baud, .. } => format!(
                "warning: the RAM loader was lost (a reset?); restored, robot found at {baud} baud"
            ),
            _ => return,
        };
        if !self.said.contains(&line) {
            self.say(&line);
            self.said.push(line);
        }
    }
}

/// The linked image, and what the uploader sends of it.
fn read_image(path: &PathBuf) -> miette::Result<(linker::Image, UploadImage)> {
    let name = path.display().to_string();
    let bytes =
        hostfs::read(path, hostfs::BINARY).wrap_err_with(|| format!("cannot read {name}"))?;
    let linked = linker::Image::parse(&name, &bytes)?;
    let image = UploadImage::try_from(&linked)?;
    Ok((linked, image))
}

fn read_expectations(path: &Path) -> miette::Result<(String, Expectations)> {
    let shown = path.display().to_string();
    let expectations = transcript::read_commands(path, &shown)?;
    Ok((shown, expectations))
}

/// Checks every line of `expectations` on `client`: the transcript, or
/// every line that differs, each at its `file:line` on stderr, then the
/// error.
fn check_expectations<T: Transport>(
    (shown, expectations): &(String, Expectations),
    client: &mut Client<T>,
    help: &str,
) -> miette::Result<Vec<(Command, Option<Answer>)>> {
    let checked = expectations.check_all(client)?;
    match TranscriptFailed::of(shown, expectations, &checked.mismatches, help) {
        Some(failed) => {
            crate::cmd::say_err(&transcript::describe(
                shown,
                &checked.mismatches,
                Clock::Robot,
            ));
            Err(failed.into())
        }
        None => Ok(checked.transcript),
    }
}

/// `> command` and `< answer` lines.
fn transcript(lines: &[(Command, Option<Answer>)]) -> String {
    let mut text = String::new();
    for (command, answer) in lines {
        let _ = writeln!(text, "  > {command}");
        if let Some(answer) = answer {
            let _ = writeln!(text, "  < {}", uploader::answer_text(answer));
        }
    }
    text
}

/// How the upload went, for people.
fn summary(report: &UploadReport, image: &UploadImage, emulated: bool) -> String {
    let seconds = report
        .device_time
        .max(Duration::from_millis(1))
        .as_secs_f64();
    let written = report.written_bytes();
    // fresh28 F4: "uploaded" where the robot held every byte already.
    let (what, held) = if written == 0 && report.bytes > 0 {
        (
            "verified",
            " (none of them written: the robot held them all)",
        )
    } else {
        ("uploaded and verified", "")
    };
    let mut text = format!(
        "{what} {} bytes{held} in {seconds:.2} s{} ({:.0} bytes/s)",
        report.bytes,
        if emulated { " of robot time" } else { "" },
        report.bytes as f64 / seconds
    );
    if let Some(loader) = &report.loader {
        let _ = write!(
            text,
            ", through the RAM loader (${:04X}, {} bytes) at {} baud",
            loader.address, loader.len, loader.baud
        );
    } else if report.without_loader.is_none() {
        // Chosen (`--loader auto`: faster for an image this small) or
        // asked for (`--loader never`): said, so no one looks for it.
        text.push_str(", with the ROM's own commands (/9W, /7R)");
    }
    if 0 < written && written < report.bytes {
        let _ = write!(
            text,
            "\n  {written} bytes written in {} range{}: the robot held the rest (checksums computed on it)",
            report.written.len(),
            if report.written.len() == 1 { "" } else { "s" }
        );
    }
    if let Some(reason) = &report.without_loader {
        let _ = write!(
            text,
            "\n  every byte written with the ROM's commands, none compared by checksums: the RAM loader was not used ({reason})"
        );
    }
    for area in image.areas() {
        let _ = write!(text, "\n  ${:04X}-${:04X}", area.address, area.end() - 1);
    }
    for old in &report.replaced {
        let _ = write!(
            text,
            "\n  took out {}: it overlapped the image (--replace), and no longer answers",
            old.describe()
        );
    }
    for old in &report.reset_freed {
        let _ = write!(
            text,
            "\n  warning: the robot reset during the upload (a /1R frees every entry): {} is no longer installed (its code stays in RAM, unhooked); upload it again to answer its commands",
            old.describe()
        );
    }
    if report.rewrites > 0 || report.lost_answers > 0 {
        let _ = write!(
            text,
            "\n  line faults: {} bytes rewritten, {} answers lost, {} extra verification passes",
            report.rewrites, report.lost_answers, report.final_passes
        );
    }
    for hook in &report.hooks {
        // hostile14 F6b: left where it was in the chain.
        let (way, place) = match report.relinked.iter().find(|(kind, _)| *kind == hook.kind) {
            Some((_, slot)) => (
                " ... ->",
                format!(
                    "where it was in the chain, behind the extension whose chain slot is at ${slot:04X}; "
                ),
            ),
            None => ("", String::new()),
        };
        let _ = write!(
            text,
            "\n  {} ->{way} ${:04X} ({place}falls through to ${:04X})",
            hook.kind.rom_symbol(),
            hook.handler,
            hook.previous
        );
    }
    text
}

/// A note for each hook the image falls through to another extension
/// on: the rehearsal's robot had this image alone, so the expectations
/// were met without the extensions chained behind it on the robot
/// (fresh10 F11: `/1W => nothing` passed, and the robot answered `W99`).
fn others_not_rehearsed(
    report: &uploader::UploadReport,
    profile: &uploader::RomProfile,
    earlier: &[Loaded],
) -> String {
    let mut text = String::new();
    for hook in &report.hooks {
        // The project's images before this one were rehearsed with it.
        let rehearsed = earlier.iter().any(|loaded| {
            loaded
                .image
                .hooks()
                .iter()
                .any(|record| record.kind == hook.kind && record.handler == hook.previous)
        });
        if !rehearsed && profile.reset_target(hook.kind) != Some(hook.previous) {
            let _ = writeln!(
                text,
                "note: on the robot {} falls through to ${:04X}, another extension the rehearsal did not have: the expectations were met without it",
                hook.kind.rom_symbol(),
                hook.previous
            );
        }
    }
    text
}

/// `, with first.elf before it`: the images a rehearsal had before the
/// one it reports on, if any.
fn with_earlier(earlier: &[Loaded]) -> String {
    if earlier.is_empty() {
        return String::new();
    }
    let names: Vec<&str> = earlier.iter().map(|loaded| loaded.name.as_str()).collect();
    format!(", with {} before it, as on the robot", names.join(" and "))
}

/// `--fast-baud`: 0, or a rate the robot's 6551 runs at (hostile10 F15:
/// `--fast-baud 1` was taken, and the upload said "at 19200 baud").
fn fast_baud(text: &str) -> Result<u32, String> {
    let rate: u32 = text
        .parse()
        .map_err(|_| format!("`{text}` is no baud rate"))?;
    if rate == 0 || platform::acia::baud_code(rate).is_some() {
        Ok(rate)
    } else {
        Err(format!(
            "the robot's 6551 does not run at {rate} baud: give 0 (keep --baud) or one of its rates ({})",
            platform::acia::rates_text()
        ))
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    // One resolution for the line and the virtual robot: the port and
    // rate from the flags, the environment, the per-user file or the
    // project; the project's cards, world and ROM profile rehearse the
    // upload (and are the robot on `--port emu`), unless flags name others.
    let resolved = args.line.resolve()?;
    resolved.port()?;
    if args.undo {
        let path = args.undo_path();
        let backup = read_undo(&path)?;
        let transport = ports::open_resolved(&resolved, &[])?;
        let rom = crate::cmd::config::rom(&resolved)?;
        let profile = crate::cmd::config::profile(rom.as_ref())?;
        // `--loader never` (the help of a noisy line's failure) holds
        // for the undo too.
        let loader = args.options().loader;
        // Written once the undo's checks pass: an undo stopped after it
        // (killed, a dead line) is finished by the next `--undo`.
        let started = marked(&path, UNDOING);
        crate::cmd::say_when_interrupted(|| {
            "interrupted: the undo did not finish; nothing that did not verify is hooked\n  `scorpion upload --undo` finishes it".to_owned()
        })?;
        let code = crate::cmd::backup::restore_into(
            transport,
            profile,
            &backup,
            &path,
            // hostile20 F4: an upload killed after its entry went in.
            (false, loader, marked(&path, UPLOADING).exists()),
            Some(&started),
        )
        .map_err(|report| ports::traced_report(undo_refused(report, &path), &resolved))?;
        undone(&path)?;
        return Ok(code);
    }
    // The undo file is written during the upload: a FIFO or a device there
    // would block it half way, so it is refused before the robot is touched.
    if !resolved.is_emulated() {
        undo_file_writable(&args.undo_path(), args.undo_file.is_none())?;
        refuse_unfinished(&args.undo_path())?;
    }
    match &args.image {
        Some(path) => upload_all(
            args,
            &resolved,
            &[Loaded::read(path)?],
            &mut UndoFile::new(args.undo_path()),
        ),
        None => {
            let Some(project) = &resolved.project else {
                // None here, or a workspace: the error says which.
                scorpion_project::Project::here()?;
                miette::bail!("no project here");
            };
            // One keeper for all the images: the undo file puts back what
            // the robot held before the first (hostile14 F6).
            let mut undo = UndoFile::new(args.undo_path());
            let mut images = Vec::new();
            for spec in &project.file.images {
                let (_, path) = scorpion_project::runner::build::build_to_target(project, spec)?;
                images.push(Loaded::read(&path)?);
            }
            // fresh19 F9: each image is rehearsed with those before it,
            // as the robot will hold them, and `--expect` is checked once
            // the last is in (a transcript may use them all).
            upload_all(args, &resolved, &images, &mut undo)
        }
    }
}

/// After a successful undo of the file at `path` (by `upload --undo`, or
/// `restore` of an upload's undo file: recheck20 F3): marked used, and
/// the file of the upload before takes its place.
pub(crate) fn undone(path: &Path) -> miette::Result<()> {
    // Marked used: a second undo says "already undone" rather than
    // comparing the robot with an upload no longer on it. Kept (as
    // `.undone`), not deleted: what was undone stays on disk.
    let used = marked(path, UNDONE);
    if let Err(error) = std::fs::rename(path, &used) {
        miette::bail!(
            "undone, but cannot mark the undo file {} used (as {}): {error}",
            path.display(),
            used.display()
        );
    }
    // An upload that did not finish is undone too.
    let _ = std::fs::remove_file(marked(path, UPLOADING));
    match scorpion_project::undo::further_back(path) {
        Some(FurtherBack::Unfinished) => print(&format!(
            "{} now holds the undo of the upload before that one (the one undone did not finish): `scorpion upload --undo` again puts back what the robot held before it\n",
            path.display()
        )),
        Some(FurtherBack::Earlier(more)) => print(&format!(
            "{} now holds the undo of the upload before that one: `scorpion upload --undo` again puts back what the robot held before it ({})\n",
            path.display(),
            match more {
                0 => "the last undo file kept".to_owned(),
                1 => "1 more kept before it".to_owned(),
                n => format!("{n} more kept before it"),
            }
        )),
        None => {}
    }
    Ok(())
}

/// The undo file, read: a missing one is "nothing to undo"; a damaged
/// one or something that is not a file says what is wrong with it.
fn read_undo(path: &Path) -> miette::Result<uploader::Backup> {
    let used = marked(path, UNDONE);
    match hostfs::check(path, hostfs::BACKUP) {
        Err(error) if error.is_not_found() && used.is_file() => Err(miette::miette!(
            code = "upload::already_undone",
            help = format!(
                "a successful undo keeps its undo file as {}, and the undo file of the upload before takes its place: none is left (an upload keeps its own and the {} before it, {}.1 to {}.{}). `scorpion restore` of a backup goes further back",
                used.display(),
                scorpion_project::undo::EARLIER,
                path.display(),
                path.display(),
                scorpion_project::undo::EARLIER
            ),
            "nothing to undo: the last upload kept in {} is already undone",
            path.display()
        )),
        Err(error) if error.is_not_found() => Err(miette::miette!(
            help = "`scorpion upload` keeps what it overwrites there; give `--undo-file` if it kept it elsewhere",
            "nothing to undo: {} does not exist (no upload has kept what it overwrote there)",
            path.display()
        )),
        _ => crate::cmd::backup::read_backup(path)
            .wrap_err_with(|| format!("cannot undo from {}", path.display())),
    }
}

/// An undo refused because the robot no longer holds what the undo file's
/// upload put there, said as such: that upload is no longer on the robot.
fn undo_refused(report: miette::Report, path: &Path) -> miette::Report {
    match report.downcast_ref::<uploader::Error>() {
        Some(uploader::Error::WitnessDiffers {
            what,
            address,
            len,
            expected,
            found,
            ..
        }) => miette::miette!(
            code = "uploader::witness_differs",
            help = "another upload replaced it, it was undone already (by a restore or an undo with another undo file), or that memory was changed by hand since (put it back as it was, and undo again); nothing was changed: otherwise upload the image you want instead of undoing",
            "the robot is not as the upload the undo file {} undoes left it: ${address:04X}-${:04X}, {what}, is not what it was when the undo file was written (its checksum was {expected}, the robot's is {found})",
            path.display(),
            u32::from(*address) + u32::from(*len) - 1
        ),
        _ => report,
    }
}

/// The undo file can be written: no FIFO, device or directory at its
/// path, and its directory there. A missing directory is refused, naming
/// it, as for every other output; only the default one in a project
/// (`target/scorpion`, the tool's own, like a build's) is made.
fn undo_file_writable(path: &Path, default: bool) -> miette::Result<()> {
    if default && let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .map_err(|error| miette::miette!("cannot make {}: {error}", parent.display()))?;
    }
    hostfs::check_writable(path)
        .map_err(miette::Report::from)
        .wrap_err("--undo-file: the upload keeps what it overwrites there")
}

/// A linked image read for an upload: its name as shown, the image as
/// linked (its labels name a handler that hangs) and as the uploader
/// takes it.
struct Loaded {
    name: String,
    linked: linker::Image,
    image: UploadImage,
}

impl Loaded {
    fn read(path: &PathBuf) -> miette::Result<Loaded> {
        let (linked, image) = read_image(path)?;
        Ok(Loaded {
            name: scorpion_project::shown(path),
            linked,
            image,
        })
    }
}

/// Uploads `images` one after the other (a project's, or the one named),
/// each with one keeper. All are rehearsed first on one virtual Scorpion,
/// and the expectations checked there once the last is in: nothing is
/// sent to the robot unless every image and the file pass (hostile21 F4:
/// a project's first images went to the robot before a later one's
/// rehearsal failed, and the error said nothing was sent).
fn upload_all(
    args: &Args,
    resolved: &scorpion_project::Resolved,
    images: &[Loaded],
    undo: &mut UndoFile,
) -> miette::Result<ExitCode> {
    let expectations = args.expect.as_deref().map(read_expectations).transpose()?;
    let rom = crate::cmd::config::rom(resolved)?;
    let emulated = resolved.is_emulated();
    let options = UploadOptions {
        profile: crate::cmd::config::profile(rom.as_ref())?,
        // hostile31 F1: the earlier versions this project uploaded.
        previous: if emulated {
            Vec::new()
        } else {
            crate::cmd::uploaded::read(&undo.path)
        },
        ..args.options()
    };
    for loaded in images {
        options.profile.check(&loaded.image)?;
    }
    // fresh10 F11: the pair uploaded with a zero exit and nothing checked.
    if args.no_dry_run && expectations.is_some() && !emulated {
        return Err(miette::miette!(
            help = "drop --no-dry-run to check them on the rehearsal, or drop --expect; nothing was sent to the robot",
            "--expect is checked on the rehearsal, which --no-dry-run skips (expectations are never sent to a real robot)"
        ));
    }
    // The rehearsal: the same uploads into a virtual Scorpion, then the
    // expectations, before the robot is touched. (Into `emu` without
    // expectations it would be the upload itself over again.)
    if !args.no_dry_run && (!emulated || expectations.is_some()) {
        rehearse(args, resolved, images, &options, expectations.as_ref())?;
    }
    if !emulated && images.len() > 1 {
        refuse_overlaps(args, resolved, images, &options)?;
    }
    // The earlier images said to be freed, so each is said once.
    let mut said_gone: Vec<&str> = Vec::new();
    for (index, loaded) in images.iter().enumerate() {
        let last = index + 1 == images.len();
        let expect = expectations.as_ref().filter(|_| last);
        let gone = upload_file(
            args,
            resolved,
            (&images[..index], loaded),
            undo,
            (&options, expect, expectations.is_some()),
        )
        .map_err(|report| {
            // recheck23 F4: refused as a reset: the earlier ones went too.
            let reset = report.chain().any(|cause| {
                matches!(
                    cause.downcast_ref::<uploader::Error>(),
                    Some(uploader::Error::RobotReset { .. })
                )
            });
            let names: Vec<&str> = images[..index]
                .iter()
                .map(|earlier| earlier.name.as_str())
                .collect();
            if reset && !names.is_empty() {
                // recheck24 F2: "X uploaded before it ... is no longer".
                report.wrap_err(format!(
                    "the robot reset while {} went in: {} uploaded before it by this command {} no longer installed (a /1R frees every installed extension)",
                    loaded.name,
                    names.join(", "),
                    if names.len() == 1 { "is" } else { "are" }
                ))
            } else {
                report
            }
        })?;
        // hostile22 F5: a reset frees every entry, this command's earlier
        // images' too ([`uploader::UploadReport::gone`]); recheck24 F1:
        // each said once (one reset, not one per image after).
        let names: Vec<&str> = images[..index]
            .iter()
            .filter(|earlier| gone.contains(&earlier.image.id()))
            .map(|earlier| earlier.name.as_str())
            .filter(|name| !said_gone.contains(name))
            .collect();
        said_gone.extend(names.iter().copied());
        if !names.is_empty() {
            print(&format!(
                "warning: the robot reset while {} went in (a /1R frees every installed extension): {} uploaded before it by this command {} no longer installed; `scorpion upload` again puts {} back\n",
                loaded.name,
                names.join(", "),
                if names.len() == 1 { "is" } else { "are" },
                if names.len() == 1 { "it" } else { "them" },
            ));
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Refuses a project's images before any is sent where one overlaps an
/// extension the robot's table lists (other than an earlier copy of
/// itself) or an image before it, or where the table has too few free
/// entries for them all: its upload would be refused after the ones
/// before it went in (hostile22 F7, recheck23 F3, F5). The rehearsal
/// cannot know the robot's, and `--no-dry-run` skips it.
fn refuse_overlaps(
    args: &Args,
    resolved: &scorpion_project::Resolved,
    images: &[Loaded],
    options: &UploadOptions,
) -> miette::Result<()> {
    let transport = ports::open_resolved(resolved, &[])?;
    let mut client = args.client(transport, &options.profile);
    client
        .probe()
        .map_err(|error| ports::traced(error, resolved))?;
    let named: Vec<(&str, &UploadImage)> = images
        .iter()
        .map(|loaded| (loaded.name.as_str(), &loaded.image))
        .collect();
    uploader::refuse_what_cannot_go_in(&mut client, &options.profile, &named, options.replace)
        .map_err(|error| ports::traced(error, resolved))?;
    Ok(())
}

/// Uploads `images` into one fresh virtual Scorpion with the resolved
/// cards and surroundings, one after the other as the robot will hold
/// them, a line for each; then checks `expectations` there.
fn rehearse(
    args: &Args,
    resolved: &scorpion_project::Resolved,
    images: &[Loaded],
    options: &UploadOptions,
    expectations: Option<&(String, Expectations)>,
) -> miette::Result<()> {
    let rom = crate::cmd::config::rom(resolved)?;
    let rig = crate::cmd::config::rig(resolved);
    let (mut robot, shown) = ports::virtual_robot(resolved.baud.value, rom.as_ref(), &rig)?;
    // A handler that hangs in the rehearsal is named by its label.
    for loaded in images {
        robot.add_labels(&loaded.linked);
    }
    let transport = ports::Showing::new(VirtualTransport::new(robot), shown);
    let mut client = args.client(transport, &options.profile);
    let mut out = String::new();
    for (index, loaded) in images.iter().enumerate() {
        let report = uploader::upload(&mut client, &loaded.image, options, &mut NoProgress)
            .wrap_err_with(|| match index {
                0 if images.len() == 1 => {
                    "the rehearsal on the virtual Scorpion failed; nothing was sent to the robot"
                        .to_owned()
                }
                _ => format!(
                    "the rehearsal on the virtual Scorpion failed (uploading {}{}); nothing was sent to the robot",
                    loaded.name,
                    with_earlier(&images[..index])
                ),
            })?;
        let _ = write!(
            out,
            "rehearsed on the virtual Scorpion{}: {} bytes verified in {:.2} s of robot time",
            with_earlier(&images[..index]),
            report.bytes,
            report.device_time.as_secs_f64()
        );
        match expectations {
            Some(expectations) if index + 1 < images.len() => {
                let _ = writeln!(
                    out,
                    "; {} is checked once the project's last image is in",
                    expectations.0
                );
            }
            _ => out.push('\n'),
        }
    }
    if let Some(expectations) = expectations {
        let others = resolved
            .project
            .as_ref()
            .is_some_and(|project| project.file.images.len() > 1);
        let alone = if images.len() == 1 && others {
            // fresh21 F5: a project's transcript may need its other images.
            " (the rehearsal had this image alone: in a project, `scorpion upload --expect FILE` with no image named rehearses all its images together)"
        } else {
            ""
        };
        let lines = check_expectations(
            expectations,
            &mut client,
            &format!(
                "the image does not behave on the virtual Scorpion as the expectations say{alone}; nothing was sent to the robot"
            ),
        )?;
        out.pop();
        let _ = writeln!(
            out,
            ", {} expectation{} met",
            lines.len(),
            if lines.len() == 1 { "" } else { "s" },
        );
        // On `emu` the transcript follows the upload itself.
        if !resolved.is_emulated() {
            out.push_str(&transcript(&lines));
        }
    }
    print(&out);
    Ok(())
}

/// Uploads `loaded` to the robot `resolved` names, after `earlier` (on
/// `emu`, a fresh virtual Scorpion, which holds them already); `expect`,
/// on `emu`, is checked after it (`--expect` was given: `expected`).
/// The ids of the earlier images no longer installed once it went in
/// ([`uploader::UploadReport::gone`]).
fn upload_file(
    args: &Args,
    resolved: &scorpion_project::Resolved,
    (earlier, loaded): (&[Loaded], &Loaded),
    undo: &mut UndoFile,
    (options, expect, expected): (&UploadOptions, Option<&(String, Expectations)>, bool),
) -> miette::Result<Vec<u32>> {
    let image = &loaded.image;
    let profile = &options.profile;
    let emulated = resolved.is_emulated();
    let mut out = String::new();

    // The robot itself: on `emu`, a fresh virtual Scorpion with the same
    // parts; on a port, the robot, which has its own.
    let held: Vec<(String, linker::Image)> = earlier
        .iter()
        .map(|loaded| (loaded.name.clone(), loaded.linked.clone()))
        .collect();
    let transport = ports::open_resolved(resolved, if emulated { &held } else { &[] })?;
    let mut client = args.client(transport, profile);
    let mut bar = Bar::new();
    // `emu` is a fresh virtual Scorpion for each command: nothing of it
    // outlives this one for an undo to put back.
    let result = if emulated {
        uploader::upload(&mut client, image, options, &mut bar)
    } else {
        let (path, kept) = (undo.path.clone(), std::sync::Arc::clone(&undo.kept));
        crate::cmd::say_when_interrupted(move || upload_interrupted(&path, &kept))?;
        uploader::upload_keeping(&mut client, image, options, &mut bar, undo)
    };
    bar.bar.finish_and_clear();
    let report = match result {
        Ok(report) => report,
        // fresh11 F6: a line that failed half way left the undo file
        // marked, and nothing said so.
        Err(error) if !emulated && undo.uploading() => {
            return Err(miette::Report::new(error).wrap_err(format!(
                "the upload did not finish; nothing that did not verify is hooked; what the robot held before it is kept in {} (marked {UPLOADING}): `scorpion upload --undo` puts it back",
                undo.path.display()
            )));
        }
        Err(error) => return Err(ports::traced(error, resolved)),
    };
    if !emulated {
        // Finished: the next upload may replace the undo file.
        undo.finished_upload();
        crate::cmd::uploaded::record(&undo.path, image);
    }
    let undo_failed = undo.failed.take();
    if let Some(error) = &undo_failed {
        bar.say(&format!(
            "warning: cannot write the undo file {}: {error}",
            undo.path.display()
        ));
    }
    if let Some(error) = undo.history_failed.take() {
        // hostile20 F2: the file lost is the one before, not this one.
        bar.say(&format!(
            "warning: the undo file of the upload before could not be kept as {} ({error}): `scorpion upload --undo` goes back to before this upload only",
            scorpion_project::undo::earlier(&undo.path, 1).display()
        ));
    }
    out.push_str(&summary(&report, image, emulated));
    out.push('\n');
    if !emulated && undo_failed.is_none() && !report.replaced.is_empty() {
        let _ = writeln!(
            out,
            "  `scorpion upload --undo` puts back what the robot held before, {} included",
            if report.replaced.len() == 1 {
                "the extension taken out"
            } else {
                "the extensions taken out"
            }
        );
    }
    if let Some(why) = &undo.older_damaged {
        let _ = writeln!(
            out,
            "warning: the robot held this image already, but the undo file found ({}) was damaged ({why}): it is replaced by this upload's, which puts back the robot as this upload found it",
            undo.path.display()
        );
    }
    if undo.kept_older {
        let _ = writeln!(
            out,
            "the robot held this image already, installed as it is now: {} still undoes the last upload that changed the robot",
            undo.path.display()
        );
        // fresh17 F1: what was written then is the image's data (a
        // counter its program keeps), put back as built. Only where the
        // robot's bytes were compared (fresh30 F1, hostile29 F8: `--full`
        // or no loader writes every byte, changed or not).
        let compared = options.delta && report.loader.is_some() && report.without_loader.is_none();
        let written = report.written_bytes();
        let data = image.code().is_some_and(|code| {
            image.areas().iter().any(|area| {
                (u32::from(area.address)..area.end())
                    .any(|at| !code.iter().any(|range| range.contains(&(at as u16))))
            })
        });
        if compared && 0 < written {
            out.push_str("  (its data, which its program had changed, is put back as built)\n");
        } else if !compared && data {
            out.push_str("  (every byte written again, its data as built)\n");
        }
    }
    if !emulated && expected {
        out.push_str(&others_not_rehearsed(&report, profile, earlier));
    }
    if emulated && let Some(expectations) = expect {
        let lines = check_expectations(
            expectations,
            &mut client,
            "the image is installed on the virtual Scorpion and answers otherwise than the expectations say",
        )?;
        let _ = write!(
            out,
            "the virtual Scorpion answers, after the upload:\n{}",
            transcript(&lines)
        );
    }
    print(&out);
    let earlier: Vec<u32> = earlier.iter().map(|loaded| loaded.image.id()).collect();
    Ok(report.gone(&earlier))
}

fn print(text: &str) {
    crate::cmd::say_out(text);
}
