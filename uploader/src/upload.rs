//! The upload: connect, read the hooks, put every loaded byte into the
//! robot verified (through the ROM's commands or the RAM loader), then
//! install the image's hooks.
//!
//! Safety rules, in order of importance:
//! - A hook is switched only after every byte of the image (or of a loader
//!   stage) verified, by one `/9W` of its operand, then read back.
//! - When anything suspicious happened (a lost, late or garbled answer, a
//!   byte that read back wrong), a read-only pass over every byte follows
//!   (see `body`).
//! - A chain slot receives the hook's target as it was before the upload
//!   (or after a reset, the ROM's), so an extension falls through to what
//!   was there; a hook found pointing anywhere else is not chained to.

use std::time::Duration;

use isa::objfmt::HookKind;
use romlib::protocol::{Command, Extension};

use crate::backup::{Backup, EarlyWitnesses, Keep, NoKeep};
use crate::body::{Body, Limits, RunEnd, Writer};
use crate::chain;
use crate::client::{Client, ClientConfig, spans};
use crate::delta;
use crate::fingerprint;
use crate::hooks::{
    Wanted, read_hook, read_hooks, read_word, settle_hooks, switch_hook, write_word_verified,
};
use crate::image::{Area, RomProfile, UploadImage};
use crate::loader::{FAST_BAUD, Loader, loader_estimate, rom_only_estimate};
use crate::progress::{Event, Phase, Progress};
use crate::session::{Session, recoverable};
use crate::sums::robot_sum;
use crate::table;
use crate::transport::{Transport, char_time};
use crate::{Error, Result};
use romlib::protocol::Answer;

/// Whether the RAM loader carries the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoaderChoice {
    /// When the estimate says it is faster, or the robot may hold the
    /// image already (its sums spare the writes), and it can go in beside
    /// the extensions installed ([`UploadReport::without_loader`] says why
    /// not).
    #[default]
    Auto,
    /// Never: the ROM's `/9W` for every byte.
    Never,
    /// Always, or fail saying why not.
    Always,
}

/// How an upload behaves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UploadOptions {
    /// Where the ROM keeps its hooks and what may be written.
    pub profile: RomProfile,
    /// The most times one byte is written before the upload fails.
    pub max_writes: u32,
    /// The most read-only verification passes after faults.
    pub max_passes: u32,
    /// Consecutive lost or garbled answers tolerated.
    pub max_lost: u32,
    /// Whether the RAM loader carries the body.
    pub loader: LoaderChoice,
    /// The rate the loader switches the line to for the transfer; `None`
    /// keeps the rate the upload connected at.
    pub fast_baud: Option<u32>,
    /// Take an installed extension that overlaps the image out of its
    /// chains (and out of the table) instead of refusing the upload.
    pub replace: bool,
    /// Through the loader, write only the ranges whose checksum on the
    /// robot differs from the image's (see `delta`); `false` writes every
    /// byte.
    pub delta: bool,
    /// Restore a backup onto a robot whose ROM differs from the one it
    /// was taken from or from the profile (its code's calls into the ROM
    /// may land elsewhere): [`crate::restore`] tells what it overrides,
    /// and an upload with it compares nothing of the ROM.
    pub force_rom: bool,
    /// [`crate::restore`] of a file whose restore stopped half way (the
    /// caller knows it started one): a witness whose memory holds what
    /// the file itself puts there passes, since that restore wrote it.
    pub resume: bool,
    /// [`crate::restore`] of an upload's undo file: refused while a
    /// hook leads first to code the file does not put back (a later
    /// upload chained ahead of the one undone, which the undo would
    /// unhook too).
    pub undo: bool,
    /// [`crate::restore`] of the undo file of an upload that did not
    /// finish (killed, a dead line): its records of the table entries the
    /// upload wrote are not checked as witnesses (it may have stopped
    /// before or while it wrote them), only used to tell its extension
    /// from others (hostile20 F4: its own undo was refused for good).
    pub interrupted: bool,
    /// Images uploaded before, as linked (a caller's record of them):
    /// where the robot's table lists one of them in the image's place
    /// (an earlier version `--replace` takes out), every range in which
    /// it differs from the image is written, whatever the robot's sums
    /// say (hostile31 F1: an edit that only moves bytes about balances
    /// the sums). It can only add writes.
    pub previous: Vec<UploadImage>,
}

impl Default for UploadOptions {
    fn default() -> Self {
        UploadOptions {
            profile: RomProfile::default(),
            max_writes: 8,
            max_passes: 6,
            max_lost: 200,
            loader: LoaderChoice::Auto,
            fast_baud: Some(FAST_BAUD),
            replace: false,
            delta: true,
            force_rom: false,
            resume: false,
            undo: false,
            interrupted: false,
            previous: Vec::new(),
        }
    }
}

impl UploadOptions {
    pub(crate) fn limits(&self) -> Limits {
        Limits {
            max_writes: self.max_writes,
            max_passes: self.max_passes,
            max_lost: self.max_lost,
        }
    }
}

/// A hook the upload switched: the same record the virtual robot's
/// loader gives (`previous` is the extension's fallthrough, in its chain
/// slot).
pub use romlib::InstalledHook;

/// What the RAM loader did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoaderReport {
    /// Where it ran.
    pub address: u16,
    /// Its size in bytes (both parts).
    pub len: usize,
    /// The rate the body travelled at.
    pub baud: u32,
    /// Times it was found gone (a reset) and restored.
    pub recoveries: u32,
}

/// What an upload did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UploadReport {
    /// Bytes loaded and verified.
    pub bytes: usize,
    /// Time on the transport's clock (emulated seconds on the virtual
    /// Scorpion) from the first probe to the last hook verified.
    pub device_time: Duration,
    /// Characters sent to the robot.
    pub chars_sent: usize,
    /// Characters received from it.
    pub chars_received: usize,
    /// Bytes written again after reading back wrong.
    pub rewrites: usize,
    /// Answers lost, late or garbled.
    pub lost_answers: usize,
    /// Read-only verification passes run after faults.
    pub final_passes: u32,
    /// The hooks switched.
    pub hooks: Vec<InstalledHook>,
    /// The RAM loader, if it carried the body.
    pub loader: Option<LoaderReport>,
    /// The ranges written (address, length), the table entry's included:
    /// with a delta upload, only those the robot did not hold.
    pub written: Vec<(u16, usize)>,
    /// Why `--loader auto` could not use the RAM loader, where it could
    /// not (not where the ROM's commands were estimated faster): every
    /// byte went through the ROM's commands, none compared with the
    /// robot's by checksums.
    pub without_loader: Option<String>,
    /// Whether the upload left the robot as it found it: the same image,
    /// installed as it was, the hooks where they were (read back to be
    /// sure; only decided when the upload kept what it overwrote).
    pub unchanged: bool,
    /// The installed extensions `--replace` took out: they overlapped the
    /// image, and no longer answer.
    pub replaced: Vec<romlib::installed::Installed>,
    /// Ways out the robot's chains held that were no way for a command
    /// to go (each hook and where it led): the image falls through to the
    /// ROM's target instead.
    pub dropped: Vec<(HookKind, u16)>,
    /// Hooks whose chain had an earlier copy of the image behind another
    /// extension: the image went back there, the chain slot of the
    /// extension in front (given) pointing at it again, not to the head
    /// of the chain.
    pub relinked: Vec<(HookKind, u16)>,
    /// Installed extensions a reset (`/1R`) freed while the upload ran
    /// (their entries' flags cleared): their code is still in RAM, but no
    /// hook leads to it, and the table no longer names it.
    pub reset_freed: Vec<romlib::installed::Installed>,
    /// The ids of the extensions the robot's table listed when the upload
    /// read it (an earlier copy of the image included; `None`: the ROM
    /// keeps no table): see [`UploadReport::gone`].
    pub listed: Option<Vec<u32>>,
}

impl UploadReport {
    /// How many bytes [`UploadReport::written`] holds.
    #[must_use]
    pub fn written_bytes(&self) -> usize {
        self.written.iter().map(|range| range.1).sum()
    }

    /// Of `earlier`, the ids of extensions an uploader put in before this
    /// upload, those no longer installed: not in the table when this
    /// upload read it (a reset before: recheck23 F1), or freed by a reset
    /// while it ran.
    #[must_use]
    pub fn gone(&self, earlier: &[u32]) -> Vec<u32> {
        earlier
            .iter()
            .copied()
            .filter(|id| {
                self.listed
                    .as_ref()
                    .is_some_and(|listed| !listed.contains(id))
                    || self.reset_freed.iter().any(|entry| entry.id == *id)
            })
            .collect()
    }
}

/// Reads the hooks (the first question of an upload), and returns them
/// with the rate the robot answered at. If the robot does not answer at
/// the host's rate but the host can try the loader's fast rate, an upload
/// interrupted there may have left it so: `/1F` (which a loader still
/// hooked obeys, and anything else drops) asks it back. A robot that stays
/// at the fast rate (a `/1R` there unhooked the loader) is read there: only
/// the loader can bring it back.
pub(crate) fn connect<T: Transport>(
    client: &mut Client<T>,
    options: &UploadOptions,
) -> Result<(Vec<(HookKind, u16)>, u32)> {
    let base = client.transport().baud();
    let error = match read_hooks(client, &options.profile) {
        Err(error @ (Error::NoAnswer { .. } | Error::WrongBaud { .. })) => error,
        other => return other.map(|hooks| (hooks, base)),
    };
    let Some(fast) = options.fast_baud.filter(|&fast| fast != base) else {
        return Err(error);
    };
    if client.transport().set_baud(fast).is_err() {
        return Err(error);
    }
    client.transport().clear_input()?;
    if client.probe().is_err() {
        client.transport().set_baud(base)?;
        client.transport().clear_input()?;
        return Err(error);
    }
    client.send(&Command::Extension(Extension::new(b"F".as_slice())?))?;
    let until = client.transport().now() + char_time(3, fast) + Duration::from_millis(2);
    client.wait_until(until)?;
    client.transport().set_baud(base)?;
    client.transport().clear_input()?;
    if client.probe().is_ok() {
        return read_hooks(client, &options.profile).map(|hooks| (hooks, base));
    }
    client.transport().set_baud(fast)?;
    client.transport().clear_input()?;
    match read_hooks(client, &options.profile) {
        Ok(hooks) => Ok((hooks, fast)),
        Err(_) => {
            client.transport().set_baud(base)?;
            Err(error)
        }
    }
}

/// Whether the loader carries this upload, and where it goes; else why
/// not, where `auto` considered it (said in the report: then every byte
/// goes through the ROM's commands, none compared by checksums).
fn choose_loader<T: Transport>(
    client: &mut Client<T>,
    options: &UploadOptions,
    image: &UploadImage,
    initial: &[(HookKind, u16)],
    (baud, fast): (u32, u32),
    with_sums: bool,
    plan: Option<&table::Plan>,
) -> Result<(Option<Loader>, Option<String>)> {
    if options.loader == LoaderChoice::Never {
        return Ok((None, None));
    }
    let profile = &options.profile;
    let refuse = |reason: String| {
        if options.loader == LoaderChoice::Always {
            Err(Error::LoaderUnavailable { reason })
        } else {
            Ok((None, Some(reason)))
        }
    };
    let Some(loader) = Loader::place(profile, image, (baud, fast))? else {
        return refuse(
            "the image leaves no room for it in user RAM or user zero page, or the ROM lacks GETCH, CHKCH or CMD_DONE".into(),
        );
    };
    // An extension already hooked lives somewhere in RAM: the table says
    // where, or nothing does and the loader could land on it.
    let others = plan.map_or(&[][..], |plan| plan.others.as_slice());
    if let Some(reason) = crate::beside::refusal(client, profile, initial, others, &loader)? {
        return refuse(reason);
    }
    // A robot that may hold the image already: its sums spare the writes.
    let held_maybe = with_sums && options.delta && plan.is_some_and(|plan| plan.held_maybe);
    if options.loader == LoaderChoice::Auto && !held_maybe {
        // What goes in: `sums` only when it is wanted.
        let len = if with_sums {
            loader.len()
        } else {
            usize::from(loader.sums - loader.address())
        };
        let with = loader_estimate(image.len(), len, baud, fast);
        if with >= rom_only_estimate(image.len(), baud) {
            // The faster way chosen: nothing the user need be told.
            return Ok((None, None));
        }
    }
    Ok((Some(loader), None))
}

/// Uploads `image` through `client`: body, verification, then hooks.
///
/// # Errors
/// Any [`Error`]; on every error path, no hook points at code that did not
/// verify (hooks are the last thing written, each part of the loader
/// verified before it is hooked).
pub fn upload<T: Transport>(
    client: &mut Client<T>,
    image: &UploadImage,
    options: &UploadOptions,
    progress: &mut dyn Progress,
) -> Result<UploadReport> {
    upload_keeping(client, image, options, progress, &mut NoKeep)
}

/// [`upload`], keeping what it overwrites: before the image's bytes are
/// written, `keep` receives what the robot held there (through the loader
/// with [`UploadOptions::delta`], only the ranges that differ), the table
/// of installed extensions and the hooks as the upload found them.
/// Restoring that ([`crate::restore`]) undoes the upload.
///
/// # Errors
/// As [`upload`].
pub fn upload_keeping<T: Transport>(
    client: &mut Client<T>,
    image: &UploadImage,
    options: &UploadOptions,
    progress: &mut dyn Progress,
    keep: &mut dyn Keep,
) -> Result<UploadReport> {
    options.profile.check(image)?;
    let start = client.transport().now();
    let stats_before = client.stats();
    progress.phase(Phase::Connect, image.len());
    let profile = &options.profile;
    let limits = options.limits();

    // The hooks as they are now; disarm any that points into memory this
    // upload will overwrite, since the old code there is about to change.
    // Where this upload's loader goes: a failed upload of the same image
    // may have left it hooked.
    let base = client.transport().baud();
    let rates = (base, options.fast_baud.unwrap_or(base));
    let leftover = Loader::place(profile, image, rates)?;
    let (mut hooks_now, found_at) = connect(client, options)?;
    // A debug stub a killed session left hooked is no extension to chain
    // to: refused before anything is written.
    let known = |target: u16| {
        image.hooks().iter().any(|record| record.handler == target)
            || leftover
                .as_ref()
                .is_some_and(|loader| [loader.sums, loader.frames, loader.rate].contains(&target))
    };
    crate::stub::left::refuse_hooked(client, profile, &hooks_now, &known)?;
    // The right ROM, or no write. Through the loader the jump table is
    // read once the line runs at the fast rate, before `frames` (which
    // calls GETCH and CHKCH) is hooked: only `rate`, which calls nothing
    // but CMD_DONE (its entry read before `rate` is hooked) and obeys
    // nothing but `/1F`, runs before. A write before the loader (a hook
    // disarmed or an extension replaced points hooks back at the ROM's
    // entries; a table entry freed) reads those entries first, at the base
    // rate. Through the ROM's commands (`Auto` finding the loader does not
    // pay), the table is compared while the image goes in, before anything
    // is hooked; `--loader never` compares it first of all.
    // `force_rom` (a forced restore, whose caller has compared and told)
    // skips every comparison.
    let rom_checked = options.loader == LoaderChoice::Never || options.force_rom;
    if rom_checked && !options.force_rom {
        fingerprint::check_jump_table(client, profile)?;
    }
    let mut entries_checked = rom_checked;
    // A refusal comes before anything changes: `prepare` may unhook an
    // extension it replaces, and `choose_loader` decides only after.
    if options.loader == LoaderChoice::Always
        && let Err(error) = crate::always::check(
            client,
            profile,
            image,
            &hooks_now,
            options.replace,
            leftover.as_ref(),
        )
    {
        return Err(reset_or(client, profile, &hooks_now, error));
    }
    if options.replace && !entries_checked {
        fingerprint::check_reset_entries(client, profile)?;
        entries_checked = true;
    }
    // What is installed: an overlap is refused (or, with `replace`, the old
    // extension leaves its chains first, which changes the hooks).
    // Before `prepare` unhooks anything, the undo file holds the hooks and
    // the table as found and a witness of the code each hook leads to
    // (only that: nothing of the image is written before the file is kept
    // again, whole, in `before_write`), then each chain slot re-pointed.
    let mut witnesses = EarlyWitnesses::default();
    let mut slots: Vec<Area> = Vec::new();
    let mut before_unhook = |client: &mut Client<T>, found: &[Area], slot: Option<Area>| {
        if !keep.wanted() {
            return Ok(());
        }
        slots.extend(slot);
        keep_early(
            client,
            (profile, image),
            &as_found(profile, found.to_vec(), &hooks_now),
            (&[], &slots),
            (&mut witnesses, keep),
        )
    };
    let mut plan = table::prepare(
        client,
        profile,
        image,
        options.replace,
        (options.max_writes, &hooks_now),
        &mut before_unhook,
    )?;
    // hostile21 F10: a reset between the read of the hooks and that of the
    // table: the table is empty, the hooks as read lead into code it no
    // longer lists (the image then chained to it, and the upload ended
    // "verified" with it hooked). Where the table lists nothing and a hook
    // is not at the ROM's target, the hooks are read again (nothing has
    // been written yet); what a reset moved is taken as it is now.
    if plan.as_ref().is_some_and(table::Plan::lists_nothing)
        && hooks_now
            .iter()
            .any(|&(kind, target)| profile.reset_target(kind) != Some(target))
    {
        let again = read_hooks(client, profile)?;
        for (&(kind, before), &(_, after)) in hooks_now.iter().zip(&again) {
            if before != after {
                progress.event(&Event::HookChanged {
                    kind,
                    before,
                    after,
                });
            }
        }
        if let Some(plan) = plan.as_mut() {
            plan.hooks.clone_from(&again);
        }
        hooks_now = again;
    }
    // What an undo puts back: the hooks and the table as found (the table
    // as `prepare` read it, flags and the entries in use: no more reads).
    let mut kept = keep.wanted().then(|| {
        let found = plan
            .as_ref()
            .map_or_else(Vec::new, |plan| plan.found.clone());
        as_found(profile, found, &hooks_now)
    });
    // Chain slots of other extensions `prepare` re-pointed, as they were.
    let unlinked = plan
        .as_ref()
        .map_or_else(Vec::new, |plan| plan.unlinked.clone());
    if let Some(plan) = plan.as_ref() {
        hooks_now.clone_from(&plan.hooks);
    } else if options.replace {
        hooks_now = read_hooks(client, profile)?;
    }
    // Kept again before each change the upload makes before its bytes go
    // out: a hook disarmed, a table entry freed.
    let mut before_change = |client: &mut Client<T>, image: &UploadImage| match kept.as_ref() {
        Some(kept) => keep_early(
            client,
            (profile, image),
            kept,
            (&[], &unlinked),
            (&mut witnesses, keep),
        ),
        None => Ok(()),
    };
    let others = plan.as_ref().map_or(&[][..], |plan| plan.others.as_slice());
    let mut initial = Vec::new();
    let mut dropped = Vec::new();
    let initial_read = hooks_now.clone();
    for (kind, mut target) in hooks_now {
        let address = profile.hook_address(kind);
        let loader = leftover
            .as_ref()
            .filter(|loader| loader.left_hooked(kind, target, others));
        if image.contains(target) || loader.is_some() {
            // An earlier copy of this image, probably: the hook goes back
            // to where that fell through (its chain slot), so the chain
            // behind it survives; else to the ROM's target. (The loader
            // falls through to nothing: it is only ever hooked in place of
            // the ROM's own target.)
            // Only a hook at the image's handler is such a copy's: one
            // into the middle of the image is into code this upload
            // overwrites, whose chain slot, if any, is not there.
            let slot = match loader {
                Some(_) => None,
                None => image
                    .hooks()
                    .iter()
                    .find(|record| record.kind == kind && record.handler == target)
                    .and_then(|record| record.chain),
            };
            let fallthrough = match slot {
                Some(slot) => read_word(client, slot)?.filter(|&to| {
                    !image.contains(to)
                        && (others.iter().any(|other| other.contains(to))
                            || leftover.as_ref().is_none_or(|l| !l.contains(to)))
                }),
                None => None,
            };
            // Nor is a way out one that comes back into the image, or one
            // that is no way at all (hostile14 F7: a slot damaged by hand
            // to $0021, the ROM's zero page, re-chained and hooked there;
            // hostile15 F2: to code that stops the CPU): the ROM's target
            // then.
            let fallthrough = match fallthrough {
                Some(to) => match chain::judge_way(client, profile, others, (kind, to), &|at| {
                    image.contains(at)
                })? {
                    chain::Way::Fine => Some(to),
                    chain::Way::ComesBack(_) => None,
                    chain::Way::Broken(why, path) => {
                        drop_way(progress, &mut dropped, (kind, to, slot), why, &path);
                        None
                    }
                },
                None => None,
            };
            let Some(to) = fallthrough.or(profile.reset_target(kind)) else {
                return Err(Error::HookInUse {
                    hook: kind.rom_symbol(),
                    target,
                });
            };
            check_entries_once(client, profile, &mut entries_checked)?;
            before_change(client, image)?;
            switch_hook(client, address, to, options.max_writes)?;
            progress.event(&Event::HookDisarmed {
                kind,
                from: target,
                to,
            });
            target = to;
        } else {
            let takes = image.hooks().iter().any(|record| record.kind == kind);
            match chain::judge_way(client, profile, others, (kind, target), &|at| {
                image.contains(at)
            })? {
                chain::Way::Fine => {}
                // Chaining the image to it would make a loop.
                chain::Way::ComesBack(path) => {
                    let error = Error::ChainComesBack {
                        hook: kind.rom_symbol(),
                        path: path.to_string(),
                    };
                    return Err(reset_or(client, profile, &initial_read, error));
                }
                // hostile15 F2: a hook damaged by hand (into the ROM's zero
                // page, the middle of the ROM, code that stops the CPU) is
                // no way out for the image: it falls through to the ROM.
                // A hook the image does not take is left as it is.
                chain::Way::Broken(why, path) => {
                    if let Some(to) = profile.reset_target(kind).filter(|_| takes) {
                        drop_way(progress, &mut dropped, (kind, target, None), why, &path);
                        target = to;
                    }
                }
            }
        }
        initial.push((kind, target));
    }
    let before = |kind: HookKind| target_before(&initial, kind);

    // Chain slots get the hooks' current targets before the body goes out,
    // so they are verified with it; an earlier copy that goes back where it
    // was in a chain, where it fell through to.
    let relinks = plan
        .as_ref()
        .map_or_else(Vec::new, |plan| plan.relink.clone());
    let mut relinked: Vec<table::Relink> = Vec::new();
    let mut image = image.clone();
    for record in image.hooks().to_vec() {
        if let Some(slot) = record.chain {
            let onward = relinks
                .iter()
                .find(|relink| relink.kind == record.kind)
                .map_or_else(|| before(record.kind), |relink| relink.onward);
            let [low, high] = onward.to_le_bytes();
            image.set_byte(slot, low);
            image.set_byte(slot + 1, high);
        }
    }
    // The image's entry in the table goes in with the body, verified with
    // it; its flags, which make it count, once body and entry are in.
    let bytes = image.len();
    if let Some(plan) = plan.as_mut() {
        if plan.frees_first() {
            check_entries_once(client, profile, &mut entries_checked)?;
            before_change(client, &image)?;
        }
        plan.free_first(client, options.max_writes)?;
        image.push_area(plan.entry_area());
        // The record of the entry, with the sum of its bytes as this
        // upload writes them, kept from here on, before the entry goes
        // out: the undo of an upload killed after it tells the entry as
        // this upload's (hostile20 F4). An undo finds that sum only on the
        // robot the upload went to, and only until another upload or a
        // restore has changed the table (an undo file applied to another
        // robot is refused, `--port emu`'s fresh one included).
        if let Some(kept) = kept.as_mut() {
            kept.written_entries = vec![entry_witness(&plan.entry_area())];
        }
    }
    // What was kept, once kept.
    let mut kept_file: Option<Backup> = None;

    // The bytes of the earlier version the table lists where the image
    // goes, as uploaded (hostile31 F1).
    let previous: Vec<Area> = options
        .previous
        .iter()
        .filter(|earlier| {
            plan.as_ref()
                .is_some_and(|plan| plan.replaced.iter().any(|gone| gone.id == earlier.id()))
        })
        .flat_map(|earlier| earlier.areas().to_vec())
        .collect();
    let with_sums = wants_sums(&image, keep.wanted())
        || (options.delta && plan.as_ref().is_some_and(|plan| plan.held_maybe));
    let (loader, without_loader) = choose_loader(
        client,
        options,
        &image,
        &initial,
        rates,
        with_sums,
        plan.as_ref(),
    )?;
    if loader.is_none() && found_at != base {
        return Err(Error::LeftAtFastRate {
            port: client.transport().name(),
            found: found_at,
            base,
        });
    }
    let mut session = None;
    let (mut rewrites, mut passes) = (0, 0);
    let mut written = Vec::new();
    let mut hooks;
    if let Some(loader) = loader {
        let mut running = Session::new(
            loader,
            profile,
            before(HookKind::Unknown),
            (base, options.fast_baud),
            limits,
            with_sums,
            (!rom_checked).then(|| profile.clone()),
        );
        // A robot whose table lists nothing has had no upload of ours
        // since it was powered (or none that finished): reading for a
        // loader left in RAM would cost a question for nothing.
        running.maybe_resident = plan.as_ref().is_none_or(|plan| {
            plan.found
                .first()
                .is_none_or(|flags| flags.bytes.iter().any(|&flag| flag != 0))
        });
        // An undo puts back what the loader overwrites too, and can from
        // before the loader is first written.
        running.keep_under = kept.is_some();
        let mut before_write = |client: &mut Client<T>, under: &[Area]| -> Result<()> {
            match kept.as_ref() {
                Some(kept) => keep_early(
                    client,
                    (profile, &image),
                    kept,
                    (under, &unlinked),
                    (&mut witnesses, keep),
                ),
                None => Ok(()),
            }
        };
        let result = running
            .install(client, progress, &mut before_write)
            .and_then(|()| {
                if let Some(kept) = kept.as_mut() {
                    kept.areas.extend(running.take_under());
                }
                if !running.has_sums() {
                    // A small image: written whole, read back byte by byte.
                    kept_file = keep_old(client, profile, kept.take(), (&image, &unlinked), keep)?;
                    written = whole(&image);
                    let mut body = Body::new(&image, Writer::Frames);
                    body.plan_writes(client.transport().baud(), progress);
                    running.transfer(client, &mut body, progress)?;
                    (rewrites, passes) = (body.rewrites, body.passes());
                    return Ok(());
                }
                // The whole ROM is summed on the robot while the image's
                // sums are on their way: all before anything of the image
                // is written. Not when the loader was found in RAM,
                // verified: this robot has stayed powered since an upload
                // put it there, which summed its ROM (the jump table is
                // read each time).
                let rom = if running.wrote_loader() && !options.force_rom {
                    fingerprint::whole_rom(profile)
                } else {
                    Vec::new()
                };
                let mut first: Vec<(u16, usize)> = rom.iter().map(|(range, _)| *range).collect();
                let table = running
                    .take_rom_check()
                    .map(|profile| (fingerprint::table_sums(&profile), profile));
                if let Some((sums, _)) = &table {
                    first.extend(sums.iter().map(|(range, _)| *range));
                }
                // A reset while the sums are asked unhooks the loader: it
                // is restored and they are asked again.
                let mut tries = 0;
                let summed = loop {
                    let asked = if options.delta {
                        delta::differing_and(client, &first, &image)
                    } else if kept.is_some() {
                        delta::all_and(client, &first, &image)
                    } else {
                        crate::sums::robot_sums(client, &first).map(|found| delta::Summed {
                            held: image.areas().iter().map(|area| (area.clone(), 0)).collect(),
                            known: first.iter().copied().zip(found.iter().copied()).collect(),
                            first: found,
                        })
                    };
                    match asked {
                        Ok(asked) => break asked,
                        Err(error) if recoverable(&error) && tries < 3 => {
                            tries += 1;
                            running.recover(client, progress).map_err(|_| error)?;
                        }
                        Err(error) => return Err(error),
                    }
                };
                let delta::Summed {
                    held: todo,
                    first: found,
                    known,
                } = summed;
                let (whole, rest) = found.split_at(rom.len().min(found.len()));
                fingerprint::check_whole(client, profile, &rom, whole)?;
                let mut found = rest.iter().copied();
                if let Some((sums, profile)) = table {
                    let differ = sums.iter().any(|(_, sum)| found.next() != Some(*sum));
                    if differ {
                        // What differs, read until two answers agree (a
                        // sum that noise changed passes here).
                        fingerprint::check_jump_table(client, &profile)?;
                    }
                }
                let todo = delta::with_known_changes(todo, &known, &image, &previous);
                kept_file = keep_summed(
                    client,
                    profile,
                    kept.take(),
                    (&todo, &known),
                    (&image, &unlinked),
                    keep,
                )?;
                let todo = delta::merged(&todo);
                written = todo.iter().map(|a| (a.address, a.bytes.len())).collect();
                (rewrites, passes) =
                    write_ranges(client, &mut running, &image, todo, options, progress)?;
                Ok(())
            })
            .and_then(|()| write_flags(client, plan.as_mut(), options))
            .and_then(|()| {
                // `/1F` through the loader, its last job; then the hooks
                // (the loader's replaced by the image's, or back to its
                // target before). A reset meanwhile, or a `/1F` that did
                // not arrive, is found and the end taken again.
                let mut attempts = 0;
                loop {
                    let ours = Some(running.handler());
                    let end = running
                        .back_to_base(client, attempts > 0, progress)
                        .and_then(|()| {
                            install_hooks(
                                client,
                                &image,
                                options,
                                (&initial, &relinks, &mut relinked),
                                ours,
                                progress,
                            )
                        });
                    match end {
                        Err(error) if recoverable(&error) && attempts < 3 => {
                            attempts += 1;
                            running.find(client).map_err(|_| error)?;
                        }
                        other => return other,
                    }
                }
            });
        match result {
            Ok(installed) => hooks = installed,
            Err(error) => {
                // Where the line still works, the loader goes (best effort:
                // the error that stopped the upload is the one to report).
                // On a dead line the robot may be left at the fast rate with
                // the (verified) loader hooked, which the next upload's
                // `connect` undoes; the host goes back to the rate it was
                // given either way.
                if line_works(&error) {
                    let _ = running.remove(client, progress);
                }
                let _ = client.transport().set_baud(base);
                return Err(error);
            }
        }
        session = Some(running);
    } else {
        kept_file = keep_old(client, profile, kept.take(), (&image, &unlinked), keep)?;
        written = whole(&image);
        let body;
        // The jump table is compared while the image goes in (the return
        // wire idles under the `/9W`s), before anything is hooked.
        let check = (!rom_checked).then_some(profile);
        (body, hooks) = rom_path(
            client,
            &image,
            options,
            (&initial, &relinks, &mut relinked),
            plan.as_mut(),
            check,
            progress,
        )?;
        (rewrites, passes) = (body.rewrites, body.passes());
    }
    // Through the loader, a reset is found and recovered from while the
    // body goes in; one after its last check clears the entry's flags, and
    // then the ROM's own path goes over the whole image again.
    if session.is_some() && !still_installed(client, plan.as_mut())? {
        unhook(client, &hooks, options)?;
        if let Some(plan) = plan.as_mut() {
            plan.forget_flags();
        }
        let body;
        (body, hooks) = rom_path(
            client,
            &image,
            options,
            (&initial, &relinks, &mut relinked),
            plan.as_mut(),
            None,
            progress,
        )?;
        rewrites += body.rewrites;
        passes += body.passes();
        written = whole(&image);
    }

    let mut unchanged = false;
    if let Some(kept) = kept_file {
        let owns = |address: u16| session.as_ref().is_some_and(|s| s.owns(address));
        // A chain slot taken past an earlier copy and pointed at it again
        // is as it was.
        let unlinked = unlinked
            .iter()
            .any(|slot| !relinked.iter().any(|relink| relink.slot == slot.address));
        let again = plan.as_ref().is_some_and(|plan| plan.reused);
        unchanged = crate::unchanged::left_as_found(
            client,
            profile,
            (&kept, &image),
            (unlinked, again),
            &owns,
        );
        if unchanged {
            let others = plan.as_ref().map_or(&[][..], |plan| &plan.others[..]);
            let own = crate::unchanged::own_memory(&kept, profile, others);
            let code_byte = |address: u16| session.as_ref().and_then(|s| s.code_byte(address));
            let over = crate::unchanged::loader_went_over(&own, &code_byte);
            keep.finished_unchanged(&kept, &own, &over);
        } else {
            keep.finished(&kept);
        }
    }
    let stats = client.stats();
    let listed = plan.as_ref().map(|plan| {
        let mut listed: Vec<u32> = plan
            .others
            .iter()
            .chain(&plan.replaced)
            .map(|entry| entry.id)
            .collect();
        if plan.reused {
            listed.push(image.id());
        }
        listed
    });
    let (replaced, reset_freed) =
        plan.map_or_else(Default::default, |plan| (plan.replaced, plan.freed));
    Ok(UploadReport {
        bytes,
        device_time: client.transport().now().saturating_sub(start),
        chars_sent: stats.sent - stats_before.sent,
        chars_received: stats.received - stats_before.received,
        rewrites,
        lost_answers: stats.lost - stats_before.lost,
        final_passes: passes,
        hooks,
        loader: session.map(|session| {
            let (address, len) = session.placement();
            LoaderReport {
                address,
                len,
                baud: session.rate(),
                recoveries: session.recoveries,
            }
        }),
        written,
        without_loader,
        unchanged,
        replaced,
        dropped,
        relinked: relinked
            .iter()
            .map(|relink| (relink.kind, relink.slot))
            .collect(),
        reset_freed,
        listed,
    })
}

/// Says that the way out `from` of `kind` is no way (`why`, the way
/// followed), and keeps it for the report.
fn drop_way(
    progress: &mut dyn Progress,
    dropped: &mut Vec<(HookKind, u16)>,
    (kind, from, slot): (HookKind, u16, Option<u16>),
    why: &'static str,
    path: &chain::Path,
) {
    progress.event(&Event::WayOutDropped {
        kind,
        from,
        slot,
        why,
        path: path.to_string(),
    });
    dropped.push((kind, from));
}

/// Compares the robot's jump-table entries of the hooks' reset targets
/// with the profile's, unless that was done.
fn check_entries_once<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    checked: &mut bool,
) -> Result<()> {
    if !*checked {
        fingerprint::check_reset_entries(client, profile)?;
        *checked = true;
    }
    Ok(())
}

/// Every area of `image` as (address, length).
fn whole(image: &UploadImage) -> Vec<(u16, usize)> {
    image
        .areas()
        .iter()
        .map(|area| (area.address, area.bytes.len()))
        .collect()
}

/// Reads what `image` will overwrite (two answers agreeing for each span)
/// and hands it, with the hooks and table read at the start, to `keep`;
/// returns what it handed.
fn keep_old<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    kept: Option<Backup>,
    (image, unlinked): (&UploadImage, &[Area]),
    keep: &mut dyn Keep,
) -> Result<Option<Backup>> {
    let Some(mut kept) = kept else {
        return Ok(None);
    };
    let first = kept.areas.len();
    for area in image.areas() {
        // The table entry: the whole table is kept already.
        if covered(&kept, area) {
            continue;
        }
        // What the undo puts back: a counter the old code keeps there
        // (hostile16 F4) as it was at one moment.
        let bytes = client.read_live(area.address, area.bytes.len())?.bytes;
        kept.areas.push(Area {
            address: area.address,
            bytes,
        });
    }
    keep_oldest(&mut kept.areas, first);
    overlay(&mut kept.areas, unlinked);
    let ranges = crate::backup::kept_witness_ranges_on(client, profile, &kept, image)?;
    kept.witnesses = crate::backup::read_witnesses(client, &ranges)?;
    keep.keep(&kept);
    crate::backup::kept_or_stop(keep)?;
    Ok(Some(kept))
}

/// Areas from `first` on (read as the upload goes) lose the bytes an area
/// before them holds (the table as read before anything was written, which
/// a replace has changed since): each address kept once, as it was first
/// (hostile10 F9: a new entry longer than the one it replaced overlapped
/// it, and the undo file was refused whole).
fn keep_oldest(areas: &mut Vec<Area>, first: usize) {
    let (older, newer) = areas.split_at(first);
    let held = |address: u16| {
        older
            .iter()
            .any(|area| area.address <= address && u32::from(address) < area.end())
    };
    let mut runs: Vec<Area> = Vec::new();
    for area in newer {
        let mut run: Option<Area> = None;
        for (i, &byte) in area.bytes.iter().enumerate() {
            let address = area.address.wrapping_add(i as u16);
            if held(address) {
                runs.extend(run.take());
                continue;
            }
            match &mut run {
                Some(run) => run.bytes.push(byte),
                None => {
                    run = Some(Area {
                        address,
                        bytes: vec![byte],
                    });
                }
            }
        }
        runs.extend(run);
    }
    areas.truncate(first);
    areas.extend(runs);
}

/// What an undo of an upload starts from: the table (`found`) and the
/// hooks as the upload found them, with the ROM's bytes it was checked
/// against.
fn as_found(profile: &RomProfile, found: Vec<Area>, hooks: &[(HookKind, u16)]) -> Backup {
    Backup {
        areas: found,
        hooks: hooks.to_vec(),
        rom: crate::backup::profile_rom(profile),
        ..Backup::default()
    }
}

/// Hands `keep` what an upload has changed so far, before its next change
/// and before any byte of the image goes out: `kept` (the hooks and the
/// table as found) with what the loader overwrote (`under`) and the chain
/// slots `prepare` re-pointed (`unlinked`). Its witnesses are of the
/// hooks' windows only: the code they lead to is all as it was.
fn keep_early<T: Transport>(
    client: &mut Client<T>,
    context: (&RomProfile, &UploadImage),
    kept: &Backup,
    (under, unlinked): (&[Area], &[Area]),
    (witnesses, keep): (&mut EarlyWitnesses, &mut dyn Keep),
) -> Result<()> {
    let mut early = kept.clone();
    early.areas.extend_from_slice(under);
    overlay(&mut early.areas, unlinked);
    witnesses.keep(client, context, early, keep)
}

/// Whether `kept` holds all of `area` in one of its areas already.
fn covered(kept: &Backup, area: &Area) -> bool {
    kept.areas
        .iter()
        .any(|old| old.address <= area.address && area.end() <= old.end())
}

/// Puts the chain slots `prepare` re-pointed into what is kept, as they
/// were before: over the bytes read since where an area read holds them
/// (an extension replaced in place of the one before it), else as areas
/// of their own.
fn overlay(areas: &mut Vec<Area>, unlinked: &[Area]) {
    for slot in unlinked {
        let mut alone = Vec::new();
        for (offset, &byte) in slot.bytes.iter().enumerate() {
            let address = slot.address.wrapping_add(offset as u16);
            let holder = areas
                .iter_mut()
                .find(|area| area.address <= address && usize::from(address) < area.end() as usize);
            match holder {
                Some(area) => area.bytes[usize::from(address - area.address)] = byte,
                None => alone.push((address, byte)),
            }
        }
        for (address, byte) in alone {
            match areas.last_mut() {
                Some(last) if last.end() == u32::from(address) => last.bytes.push(byte),
                _ => areas.push(Area {
                    address,
                    bytes: vec![byte],
                }),
            }
        }
    }
}

/// The record of the table entry an upload writes.
fn entry_witness(entry: &Area) -> crate::backup::Witness {
    crate::backup::Witness {
        address: entry.address,
        len: entry.bytes.len() as u16,
        sum: crate::backup::Checksum::of(&entry.bytes),
    }
}

/// Hands `keep` what the ranges of `held` hold on the robot now (the
/// ranges about to be written, each with the robot's sum of it), with the
/// hooks and table read at the start. A range whose sum is that of zeros
/// (RAM nothing was loaded into, on the virtual robot) is zeros, known
/// without a read: over at most `sums::EXACT` bytes nothing else sums to
/// nothing. Any other is read once at the loader's rate and checked
/// against its sum (read again, up to four times, if noise changed an
/// answer).
fn keep_summed<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    kept: Option<Backup>,
    (held, known): (&[delta::Held], &[(crate::sums::Range, u32)]),
    (image, unlinked): (&UploadImage, &[Area]),
    keep: &mut dyn Keep,
) -> Result<Option<Backup>> {
    let Some(mut kept) = kept else {
        return Ok(None);
    };
    let first = kept.areas.len();
    for (area, sum) in held {
        let len = area.bytes.len();
        if covered(&kept, area) {
            continue;
        }
        let bytes = if crate::sums::sums_as_zeros(*sum, len) {
            vec![0; len]
        } else {
            read_summed(client, area.address, len, *sum)?
        };
        kept.areas.push(Area {
            address: area.address,
            bytes,
        });
    }
    keep_oldest(&mut kept.areas, first);
    overlay(&mut kept.areas, unlinked);
    // The code the kept hooks go back to, summed on the robot (the loader's
    // `sums` is hooked here): an undo checks it is still there. Nothing is
    // written yet, so a range the sums asked already tile is put together
    // from their answers; only the rest is asked.
    // Each witness of at most `sums::EXACT` bytes (hostile30 F4): the
    // ranges the sums asked where they tile it, pieces of the rest asked.
    let ranges: Vec<(crate::sums::Range, Option<u32>)> =
        crate::backup::kept_witness_ranges_on(client, profile, &kept, image)?
            .into_iter()
            .flat_map(|range| crate::sums::tiled(known, range))
            .collect();
    let unknown: Vec<crate::sums::Range> = ranges
        .iter()
        .filter(|(_, sum)| sum.is_none())
        .map(|(range, _)| *range)
        .collect();
    let mut asked = crate::sums::robot_sums(client, &unknown)?.into_iter();
    kept.witnesses = ranges
        .into_iter()
        .map(|((address, len), sum)| crate::backup::Witness {
            address,
            len: len as u16,
            sum: crate::backup::Checksum::Wide(sum.or_else(|| asked.next()).unwrap_or(0)),
        })
        .collect();
    keep.keep(&kept);
    crate::backup::kept_or_stop(keep)?;
    Ok(Some(kept))
}

/// `len` bytes from `address`, read once and checked against `sum` (the
/// robot's), again while they do not agree; then read until two answers
/// agree.
fn read_summed<T: Transport>(
    client: &mut Client<T>,
    address: u16,
    len: usize,
    sum: u32,
) -> Result<Vec<u8>> {
    for _ in 0..4 {
        let mut bytes = Vec::with_capacity(len);
        for span in spans(address, len) {
            match client.ask(&Command::ReadMemory(span)) {
                Ok(Answer::Memory(data)) if data.len() == usize::from(span.count()) => {
                    bytes.extend(data);
                }
                Ok(_)
                | Err(Error::Protocol(_) | Error::NoAnswer { .. } | Error::WrongBaud { .. }) => {
                    break;
                }
                Err(error) => return Err(error),
            }
        }
        if bytes.len() == len && robot_sum(&bytes) == sum {
            return Ok(bytes);
        }
    }
    client.read_memory(address, len)
}

/// Whether the loader's `sums` goes in: it costs about three characters
/// a byte of it at the fast rate (written, read back), and pays for
/// itself in an image large enough that its sums spare the return wire
/// the `/7R` answers, or that the robot may hold already, and in an upload
/// that keeps what it overwrites (a range of zeros is known by its sum).
fn wants_sums(image: &UploadImage, keeping: bool) -> bool {
    keeping || image.len() >= SUMS_PAY
}

/// The image size from which the loader's `sums` pays for itself.
const SUMS_PAY: usize = 256;

/// Writes `todo` through the loader, verified by the robot's sums; with a
/// delta upload, a
/// transfer that met faults (a write whose address noise changed may have
/// landed on a range the sums passed) is followed by the sums again, and
/// whatever differs now is written again.
fn write_ranges<T: Transport>(
    client: &mut Client<T>,
    running: &mut Session,
    image: &UploadImage,
    mut todo: Vec<Area>,
    options: &UploadOptions,
    progress: &mut dyn Progress,
) -> Result<(usize, u32)> {
    let (mut rewrites, mut passes) = (0, 0);
    for _ in 0..=options.max_passes {
        if todo.is_empty() {
            return Ok((rewrites, passes));
        }
        let done = running.transfer_summed(client, &todo, progress)?;
        rewrites += done.rewrites;
        passes += done.passes;
        if !options.delta || done.passes == 0 {
            return Ok((rewrites, passes));
        }
        let mut tries = 0;
        todo = loop {
            match delta::differing(client, image) {
                Ok(todo) => break todo,
                Err(error) if recoverable(&error) && tries < 3 => {
                    tries += 1;
                    running.recover(client, progress).map_err(|_| error)?;
                }
                Err(error) => return Err(error),
            }
        };
    }
    Err(Error::LoaderUnavailable {
        reason: format!(
            "ranges kept differing after {} rounds of writes and sums",
            options.max_passes
        ),
    })
}

/// The body (the table entry with it) through the ROM's `/9W` with `/7R`
/// verification (and, with `check`, the jump table compared on the way),
/// the entry's flags, then the hooks. A reset clears the
/// flags: found set after the hooks, no reset undid the body since its
/// last check; found cleared, the hooks go back and the whole image goes
/// over again (three times at most).
fn rom_path<T: Transport>(
    client: &mut Client<T>,
    image: &UploadImage,
    options: &UploadOptions,
    (initial, relinks, relinked): (
        &[(HookKind, u16)],
        &[table::Relink],
        &mut Vec<table::Relink>,
    ),
    mut plan: Option<&mut table::Plan>,
    mut check: Option<&RomProfile>,
    progress: &mut dyn Progress,
) -> Result<(Body, Vec<InstalledHook>)> {
    for _ in 0..3 {
        let mut body = Body::new(image, Writer::Rom);
        body.plan_writes(client.transport().baud(), progress);
        if let Some(profile) = check {
            body.add_checks(fingerprint::table_checks(profile));
        }
        while body.run(client, options.limits(), progress)? != RunEnd::Done {}
        if let Some(profile) = check.take()
            && !body.checks_passed()
        {
            // Read until two answers agree: what differs, or noise.
            fingerprint::check_jump_table(client, profile)?;
        }
        write_flags(client, plan.as_deref_mut(), options)?;
        let hooks = install_hooks(
            client,
            image,
            options,
            (initial, relinks, relinked),
            None,
            progress,
        )?;
        if still_installed(client, plan.as_deref_mut())? {
            return Ok((body, hooks));
        }
        unhook(client, &hooks, options)?;
        if let Some(plan) = plan.as_deref_mut() {
            plan.forget_flags();
        }
    }
    Err(reset_error(initial))
}

/// Whether the image's entry is still flagged in the table, and the other
/// extensions' entries as the upload found them (a ROM without a table
/// cannot tell: yes).
fn still_installed<T: Transport>(
    client: &mut Client<T>,
    plan: Option<&mut table::Plan>,
) -> Result<bool> {
    match plan {
        Some(plan) => plan.still_there(client),
        None => Ok(true),
    }
}

/// Points every hook the upload switched back at its target from before
/// (a reset made that the ROM's own), verified.
fn unhook<T: Transport>(
    client: &mut Client<T>,
    hooks: &[InstalledHook],
    options: &UploadOptions,
) -> Result<()> {
    for hook in hooks {
        let address = options.profile.hook_address(hook.kind);
        let to = options
            .profile
            .reset_target(hook.kind)
            .unwrap_or(hook.previous);
        switch_hook(client, address, to, options.max_writes)?;
    }
    Ok(())
}

/// `error`, a refusal found from the hooks as first read, unless a reset
/// since moved them (recheck21 F1: `/1R` as an upload began left chain
/// slots in RAM leading "back into the image", and the refusal blamed a
/// loop): then the reset, said as one. Nothing was written either way.
fn reset_or<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    read: &[(HookKind, u16)],
    error: Error,
) -> Error {
    let Ok(now) = read_hooks(client, profile) else {
        return error;
    };
    read.iter()
        .zip(&now)
        .find(|((_, before), (_, after))| before != after)
        .map_or(error, |(&(kind, before), &(_, after))| Error::RobotReset {
            hook: kind.rom_symbol(),
            before,
            after,
        })
}

/// The robot reset while the image went in, more often than retried.
fn reset_error(initial: &[(HookKind, u16)]) -> Error {
    let (kind, before) = initial.first().copied().unwrap_or((HookKind::Unknown, 0));
    Error::RobotReset {
        hook: kind.rom_symbol(),
        before,
        after: before,
    }
}

/// Sets the image's entry's flags in the table of installed extensions,
/// verified (a ROM without a table: nothing).
fn write_flags<T: Transport>(
    client: &mut Client<T>,
    plan: Option<&mut table::Plan>,
    options: &UploadOptions,
) -> Result<()> {
    match plan {
        Some(plan) => plan.write_flags(client, options.max_writes),
        None => Ok(()),
    }
}

/// Whether the robot still answers after `error`: worth asking it to take
/// the loader out.
pub(crate) fn line_works(error: &Error) -> bool {
    !recoverable(error)
        && !matches!(
            error,
            Error::RobotJammed { .. }
                | Error::Io { .. }
                | Error::Port { .. }
                | Error::PortBusy { .. }
                | Error::PortNotFound { .. }
                | Error::BaudChange { .. }
        )
}

/// A hook's target when the upload began (after any disarming).
fn target_before(initial: &[(HookKind, u16)], kind: HookKind) -> u16 {
    initial
        .iter()
        .find(|(k, _)| *k == kind)
        .map_or(0, |&(_, target)| target)
}

/// Points the image's hooks at its handlers, the last thing an upload
/// does: each chain slot holds what the hook pointed at before (or, after
/// a reset, the ROM's target), each hook is switched by one `/9W`; `ours`
/// is the RAM loader's handler, if it holds `HOOK_UNKNOWN`, which goes
/// back to its target before the upload unless the image takes it. Then
/// both hooks are read back whole, and whatever noise changed is put
/// right, the hooks the image does not take included.
///
/// An earlier copy of the image that was behind another extension in a
/// chain (`relinks`) goes back there instead, the chain slot in front
/// pointed at it again, while the hook is as the upload found it (a reset
/// since: to the head, as any image); those are added to `relinked`.
fn install_hooks<T: Transport>(
    client: &mut Client<T>,
    image: &UploadImage,
    options: &UploadOptions,
    (initial, relinks, relinked): (
        &[(HookKind, u16)],
        &[table::Relink],
        &mut Vec<table::Relink>,
    ),
    ours: Option<u16>,
    progress: &mut dyn Progress,
) -> Result<Vec<InstalledHook>> {
    let profile = &options.profile;
    progress.phase(Phase::Hooks, image.hooks().len());
    let mut hooks = Vec::new();
    relinked.clear();
    for record in image.hooks() {
        let address = profile.hook_address(record.kind);
        let before = target_before(initial, record.kind);
        let relink = relinks.iter().find(|relink| relink.kind == record.kind);
        // What the image's chain slot was written with.
        let slot_holds = relink.map_or(before, |relink| relink.onward);
        let reset = profile.reset_target(record.kind);
        // The loader, if the image replaces it here.
        let ours = ours.filter(|_| record.kind == HookKind::Unknown);
        let mut known = vec![before];
        known.extend(reset);
        known.extend(ours);
        // When the hook started at the ROM's own target, nothing it can
        // have turned into since (a reset: the same target; the loader; a
        // write gone astray) is anything to chain to: no need to look.
        let current = if reset == Some(before) {
            before
        } else {
            read_hook(client, record.kind, address, &known)?
        };
        // Only while the extension in front is still installed: a reset
        // since cleared the table, and an image behind code no entry
        // names could not be uploaded again (the chain would lead back
        // into it past what no table says).
        if let Some(relink) = relink
            && (current == before || Some(current) == ours)
            && in_front_installed(client, profile, relink)?
        {
            // Where it was: the slot in front points at it again, the
            // image verified.
            write_word_verified(
                client,
                relink.slot,
                record.handler.to_le_bytes(),
                options.max_writes,
            )?;
            relinked.push(*relink);
            hooks.push(InstalledHook {
                kind: record.kind,
                handler: record.handler,
                previous: relink.onward,
                chain: record.chain,
            });
            continue;
        }
        let fallthrough = if current == before || Some(current) == ours {
            before
        } else if image.contains(current) {
            return Err(Error::RobotReset {
                hook: record.kind.rom_symbol(),
                before,
                after: current,
            });
        } else {
            progress.event(&Event::HookChanged {
                kind: record.kind,
                before,
                after: current,
            });
            // After a reset the ROM's own target; anything else is not
            // something this upload verified, so not something to chain to.
            if Some(current) == reset {
                current
            } else {
                before
            }
        };
        if fallthrough != slot_holds
            && let Some(slot) = record.chain
        {
            write_word_verified(client, slot, fallthrough.to_le_bytes(), options.max_writes)?;
        }
        hooks.push(InstalledHook {
            kind: record.kind,
            handler: record.handler,
            previous: fallthrough,
            chain: record.chain,
        });
    }
    let mut wanted = Vec::new();
    for kind in HookKind::ALL {
        let address = profile.hook_address(kind);
        let reset = profile.reset_target(kind);
        let loader_leaves = kind == HookKind::Unknown && ours.is_some();
        wanted.push(match hooks.iter().find(|hook| hook.kind == kind) {
            // Back where it was: the hook as found (the loader leaves it).
            Some(_) if relinked.iter().any(|relink| relink.kind == kind) => Wanted {
                address,
                target: target_before(initial, kind),
                also: if loader_leaves { None } else { reset },
                write: loader_leaves,
            },
            Some(hook) => Wanted {
                address,
                target: hook.handler,
                also: None,
                write: true,
            },
            // The loader leaves.
            None if kind == HookKind::Unknown && ours.is_some() => Wanted {
                address,
                target: target_before(initial, kind),
                also: None,
                write: true,
            },
            // Only checked: as it was, or the ROM's own after a reset.
            None => Wanted {
                address,
                target: target_before(initial, kind),
                also: reset,
                write: false,
            },
        });
    }
    if let Err(error) = settle_hooks(client, &wanted, options.max_writes) {
        // fresh11 F6: an OS's loop handler that never goes on to the
        // ROM's loop silences the robot the moment it is hooked; the
        // line's own help would blame the cable.
        let looping = hooks.iter().find(|hook| hook.kind == HookKind::Loop);
        return Err(match (error, looping) {
            (
                cause @ (Error::NoAnswer { .. } | Error::Stalled { .. } | Error::Unreadable { .. }),
                Some(hook),
            ) => Error::LoopHandlerSilent {
                handler: hook.handler,
                cause: Box::new(cause),
            },
            (error, _) => error,
        });
    }
    if ours.is_some() {
        progress.event(&Event::LoaderRemoved);
    }
    for installed in &hooks {
        progress.event(&Event::HookInstalled {
            kind: installed.kind,
            handler: installed.handler,
            previous: installed.previous,
        });
    }
    Ok(hooks)
}

/// Whether the table still names the extension whose chain slot `relink`
/// goes back behind.
fn in_front_installed<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    relink: &table::Relink,
) -> Result<bool> {
    Ok(crate::table::read_installed(client, profile)?
        .iter()
        .flat_map(|other| other.hooks.iter())
        .any(|hook| hook.kind == relink.kind && hook.chain == Some(relink.slot)))
}

/// A client paced for `profile`'s receive buffer.
pub fn client<T: Transport>(transport: T, profile: &RomProfile) -> Client<T> {
    Client::new(
        transport,
        ClientConfig {
            window: profile.window(),
            ..ClientConfig::default()
        },
    )
}
