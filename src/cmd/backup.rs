//! `scorpion backup` and `scorpion restore`: what a robot holds (user RAM,
//! the user zero page, the table of installed extensions, the hooks) saved
//! to a checksummed file, verified, and written back verified, hooks last.
//! The file format is `uploader`'s (`uploader::Backup`); every upload
//! keeps one of what it overwrote, which `scorpion upload --undo` restores.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use uploader::{Backup, UploadOptions};

use crate::cmd::ports;

/// Save what the robot holds (user RAM, user zero page, the table of
/// installed extensions, the hooks) to a file, every span read until two
/// answers agree.
#[derive(Debug, clap::Args)]
pub(crate) struct BackupArgs {
    #[command(flatten)]
    line: ports::Line,
    /// The backup file to write.
    #[arg(short, long)]
    output: PathBuf,
}

/// Put a backup (`scorpion backup`'s, or an upload's undo file) back into
/// the robot, verified: the hooks to the ROM first, the memory (only the
/// ranges that differ, through the RAM loader), the hooks last.
#[derive(Debug, clap::Args)]
pub(crate) struct RestoreArgs {
    #[command(flatten)]
    line: ports::Line,
    /// The backup file.
    file: PathBuf,
    /// Restore onto a robot whose ROM differs from the one the backup was
    /// taken from, or from the ROM profile (the project's, else the
    /// reference ROM): its code's calls into the ROM may land elsewhere.
    /// Each check overridden is printed as a warning, and the memory goes
    /// in through the ROM's own commands (the RAM loader would call the
    /// ROM that differs).
    #[arg(long)]
    force: bool,
}

pub(crate) fn run_backup(args: &BackupArgs) -> miette::Result<ExitCode> {
    // A FIFO or a device is refused before the line is used.
    hostfs::check_writable(&args.output)?;
    let (mut client, profile) = ports::probed(&args.line)?;
    let uploader::Saved {
        backup,
        changing,
        broken,
        outside,
        damaged_table: _,
        disagreements,
        refused,
    } = uploader::backup_live(&mut client, &profile)?;
    hostfs::write(&args.output, &backup.encode())?;
    print(&format!(
        "saved {} bytes and {} hooks to {}",
        backup.len(),
        backup.hooks.len(),
        args.output.display()
    ));
    if !changing.is_empty() {
        // hostile16 F4: a counter the robot's control loop keeps is read
        // as it was at one moment, and said, not refused.
        print(&format!(
            "note: {} changed while {} read ({}): the robot's program writes {} as it runs, and the file holds the last value read",
            if changing.len() == 1 {
                "1 byte"
            } else {
                "bytes"
            },
            if changing.len() == 1 {
                "it was"
            } else {
                "they were"
            },
            uploader::addresses_text(&changing),
            if changing.len() == 1 { "it" } else { "them" },
        ));
    }
    if let Some(refused) = &refused {
        // fresh25 F2: said as the restore will refuse it, in place of
        // the looks below that would say otherwise; not blamed on a hand
        // change (hostile29 F4: code that changed while it was read).
        let reason = refused.trim_end_matches("; nothing was written");
        print(&format!(
            "warning: a restore of this file will be refused, writing nothing: {reason}"
        ));
    }
    // A table that does not decode (hostile19 F4) is one of the restore's
    // refusals, said above.
    let broken: Vec<_> = broken.into_iter().filter(|_| refused.is_none()).collect();
    for entry in &outside {
        // fresh17 F4: said now, not first at a restore that refuses it.
        print(&format!(
            "note: {} has memory outside what a backup saves (user RAM and the user zero page): the file checks it is still there at a restore, and cannot bring it back once it is gone (upload it again then)",
            entry.describe()
        ));
    }
    // fresh29 F2: code no entry lists that a hook's way runs outside what
    // the file saves (an owner's, on the KIM bus) is only witnessed: said
    // now, not first at a restore that refuses it.
    let owners: Vec<String> = backup
        .witnesses
        .iter()
        .filter(|witness| !outside.iter().any(|entry| entry.contains(witness.address)))
        .map(|witness| {
            let last = u32::from(witness.address) + u32::from(witness.len) - 1;
            if witness.len == 1 {
                format!("${:04X}", witness.address)
            } else {
                format!("${:04X}-${last:04X}", witness.address)
            }
        })
        .collect();
    if !owners.is_empty() && refused.is_none() {
        print(&format!(
            "note: the hooks' ways run code no entry lists outside what a backup saves ({}): the file checks at a restore, by its checksums, that it is still there, and cannot bring it back, so a change there (by hand too) refuses the restore",
            owners.join(", ")
        ));
    }
    for found in &disagreements {
        // Said now, not first at the restore (hostile22 F4, hSkip); one
        // the restore refuses is said above.
        match found {
            uploader::Disagreement::NotHooked { .. } => print(&format!(
                "warning: {}: a restore of this file puts it back so, listed and never run (upload it again to hook it)",
                found.describe()
            )),
            // fresh28 F1: an owner's handler in front of the extensions.
            uploader::Disagreement::Unlisted { first: true, .. } if refused.is_none() => {
                print(&format!(
                    "note: {}: a handler of your own in front of them, which a restore of this file puts back so (an upload over that code is refused while a hook runs it)",
                    found.describe()
                ));
            }
            _ => {}
        }
    }
    for hook in &broken {
        // recheck16 F4: said now, not first at the restore that refuses it.
        print(&format!(
            "warning: {} leads {}, and that way {}: a restore of this file leaves {} at the ROM's target (upload the extension again to hook it)",
            hook.hook.rom_symbol(),
            hook.path,
            hook.why,
            hook.hook.rom_symbol()
        ));
    }
    Ok(ExitCode::SUCCESS)
}

pub(crate) fn run_restore(args: &RestoreArgs) -> miette::Result<ExitCode> {
    let backup = read_backup(&args.file)?;
    let resolved = args.line.resolve()?;
    let transport = ports::open_resolved(&resolved, &[])?;
    let rom = crate::cmd::config::rom(&resolved)?;
    let profile = crate::cmd::config::profile(rom.as_ref())?;
    let file = args.file.display().to_string();
    crate::cmd::say_when_interrupted(move || {
        format!(
            "interrupted: the restore did not finish; nothing that did not verify is hooked\n  `scorpion restore {file}` again puts the rest back"
        )
    })?;
    let code = restore_into(
        transport,
        profile,
        &backup,
        &args.file,
        (args.force, uploader::LoaderChoice::Auto, false),
        None,
    )
    .map_err(|report| ports::traced_report(report, &resolved))?;
    // recheck20 F3: an upload's undo file restored is an undo done: the
    // file of the upload before takes its place, as after `upload --undo`.
    if code == ExitCode::SUCCESS && !backup.written_entries.is_empty() {
        crate::cmd::upload::undone(&args.file)?;
    }
    Ok(code)
}

/// Restores `backup` (from `file`) through `transport` into a robot with
/// `profile`'s ROM, and says so.
pub(crate) fn restore_into(
    transport: Box<dyn uploader::Transport>,
    profile: uploader::RomProfile,
    backup: &Backup,
    file: &Path,
    (force_rom, loader, interrupted): (bool, uploader::LoaderChoice, bool),
    started: Option<&Path>,
) -> miette::Result<ExitCode> {
    // A restore of this file started before and stopped half way (the
    // file `started` names is there): it may be finished.
    let resume = started.is_some_and(Path::exists);
    let options = UploadOptions {
        profile,
        force_rom,
        loader,
        resume,
        // hostile19 F7: an undo file given to `restore` is checked as an
        // undo (only an upload's file records the entries it wrote).
        undo: started.is_some() || !backup.written_entries.is_empty(),
        interrupted,
        ..UploadOptions::default()
    };
    if resume {
        print(&format!(
            "finishing the restore of {} that stopped half way",
            file.display()
        ));
    }
    let mut client = uploader::client(transport, &options.profile);
    let mut told = Overrides { started };
    let reports = uploader::restore(&mut client, backup, &options, &mut told)?;
    if let Some(started) = started {
        let _ = std::fs::remove_file(started);
    }
    let written: usize = reports
        .iter()
        .flat_map(|report| report.written.iter().map(|range| range.1))
        .sum();
    // Through the RAM loader, what it ran over goes back after it, with
    // the ROM's commands: written whatever the robot held (fresh10 F3:
    // an unchanged robot read as "188 written").
    let after_loader: usize = match reports.as_slice() {
        [_, after] => after.written_bytes(),
        _ => 0,
    };
    let written = match after_loader {
        0 => format!("{written} written"),
        all if all == written => {
            format!("{written} written, all where the RAM loader ran, put back after it")
        }
        some => {
            format!("{written} written, {some} of them where the RAM loader ran, put back after it")
        }
    };
    print(&format!(
        "restored {} ({} bytes checked, {written}, {} hooks), verified",
        file.display(),
        backup.len(),
        backup.hooks.len()
    ));
    Ok(ExitCode::SUCCESS)
}

/// Says, as it happens, each ROM check `--force` overrode; marks the
/// restore started (`started`) once its checks passed.
struct Overrides<'a> {
    started: Option<&'a Path>,
}

impl uploader::Progress for Overrides<'_> {
    fn event(&mut self, event: &uploader::Event) {
        match event {
            uploader::Event::RomCheckOverridden { refusal } => {
                crate::cmd::say_err(&format!("warning: --force overrides: {refusal}\n"));
            }
            uploader::Event::RestoredNotHooked { found } => {
                crate::cmd::say_err(&format!(
                    "warning: restored, {}: it is listed and never runs, as the file had it (upload it again to hook it)\n",
                    found.describe()
                ));
            }
            uploader::Event::RestoreStarted => {
                if let Some(started) = self.started {
                    // Best effort: without it a stopped undo is refused
                    // again, as before, with nothing changed by the refusal.
                    let _ = std::fs::write(started, b"");
                }
            }
            _ => {}
        }
    }
}

/// Reads (through the bounded reader: a FIFO or `/dev/zero` is refused,
/// not waited on) and checks a backup file.
pub(crate) fn read_backup(path: &Path) -> miette::Result<Backup> {
    let bytes = hostfs::read(path, hostfs::BACKUP)?;
    let backup = Backup::decode(&path.display().to_string(), &bytes)?;
    // hostile31 F3: a version 1 file's checks are the narrow sums, which
    // some changes of two bytes pass: said each time it is used.
    if backup.narrow_checks() {
        crate::cmd::say_err(&format!(
            "warning: {} was written by an earlier scorpion: its checks of the code it only witnesses (both sums mod 256) miss some changes of two bytes, so a change by hand there may pass; take a new backup (or upload again) once this one is restored\n",
            path.display()
        ));
    }
    Ok(backup)
}

fn print(text: &str) {
    crate::cmd::say_out(&format!("{text}\n"));
}
