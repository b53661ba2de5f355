//! What a robot holds, saved and put back: user RAM, the user zero page,
//! the table of installed extensions and the hooks ([`Backup`]), in a
//! checksummed file format; and what an upload overwrote, kept through a
//! [`Keep`] so that the upload can be undone (a restore of it).
//!
//! # The file format
//!
//! ```text
//! SCORPION-BACKUP 2\n                       magic line (ASCII)
//! 'A' address:u16 length:u16 bytes...       memory (repeated)
//! 'H' kind:u8 target:u16                    a hook's target (0 HOOK_UNKNOWN, 1 HOOK_LOOP)
//! 'W' address:u16 length:u16 sum:u32        a witness: the robot's sum (`robot_sum`) of
//!                                           memory a hook's way runs, not held by the file
//! 'T' address:u16 length:u16 sum:u32        a table entry an upload the file undoes wrote,
//!                                           witnessed as written (an undo file's)
//! 'w', 't' address:u16 length:u16 sum:u16   the same, kept from a version 1 file: the
//!                                           narrow Fletcher-16 (`fletcher16`)
//! 'R' address:u16 length:u16 bytes...       the robot's ROM there (its jump table, vectors)
//! 'E' fnv1a32:u32                           end: FNV-1a 32 of every byte before 'E'
//! ```
//!
//! Numbers are little-endian. A file that does not end in a matching `E`
//! record is refused whole: nothing of a damaged backup is written.
//!
//! Version 1 (`SCORPION-BACKUP 1`, before hostile30) held its `W` and `T`
//! sums as the narrow Fletcher-16 (both sums mod 256), which some changes
//! of two bytes pass. Such a file is still read (its witnesses as narrow
//! ones, checked as they were); every file written is version 2.

use isa::objfmt::HookKind;

use crate::client::Client;
use crate::fingerprint;
use crate::hooks::{read_hooks, switch_hooks};
use crate::image::{Area, RomProfile, UploadImage};
use crate::loader::loader_plan;
use crate::progress::Progress;
use crate::transport::Transport;
use crate::upload::{LoaderChoice, UploadOptions, UploadReport, upload};
use crate::{Error, Result};

/// The first line of a backup file.
pub const MAGIC: &[u8] = b"SCORPION-BACKUP 2\n";

/// The first line of a version 1 file (narrow witnesses), still read.
pub const MAGIC_1: &[u8] = b"SCORPION-BACKUP 1\n";

/// What a robot held: memory and hook targets.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Backup {
    /// Memory, by address.
    pub areas: Vec<Area>,
    /// Each hook's target.
    pub hooks: Vec<(HookKind, u16)>,
    /// What the code a hook goes back to summed when the file was written,
    /// where the file does not hold that code itself (an upload's undo
    /// file keeps only what the upload overwrote): a restore compares each
    /// with the robot's memory before any hook moves, so that no hook is
    /// pointed at code that is not there (another robot, a restore since).
    pub witnesses: Vec<Witness>,
    /// The table entries the uploads an undo file undoes wrote, each
    /// witnessed as written: the extensions the undo takes out. Checked
    /// with the [`Backup::witnesses`]; every other entry the robot lists
    /// must hold what the file puts back (a later upload wrote it
    /// otherwise: recheck18 F1). An older file keeps its entry's witness
    /// among the witnesses.
    pub written_entries: Vec<Witness>,
    /// The bytes of the robot's ROM where an image's calls land (its jump
    /// table and vectors) when the file was written: a restore onto a robot
    /// whose ROM differs there is refused.
    pub rom: Vec<Area>,
}

/// The checksum of `len` bytes from `address`, as the robot held them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Witness {
    /// The first address.
    pub address: u16,
    /// How many bytes.
    pub len: u16,
    /// Their checksum.
    pub sum: Checksum,
}

/// What a [`Witness`] holds of the bytes it covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Checksum {
    /// The robot's sum ([`crate::robot_sum`]): over at most
    /// [`crate::sums::EXACT`] bytes, as every witness written is, no
    /// change of one or two bytes passes it.
    Wide(u32),
    /// A version 1 file's Fletcher-16 ([`crate::fletcher16`], both sums
    /// mod 256), which some changes of two bytes pass (hostile30 F4).
    Narrow(u16),
}

impl Checksum {
    /// The checksum a witness of `bytes` holds now.
    #[must_use]
    pub fn of(bytes: &[u8]) -> Checksum {
        Checksum::Wide(crate::robot_sum(bytes))
    }

    /// `bytes`' checksum of the same kind as this one.
    #[must_use]
    pub fn of_like(self, bytes: &[u8]) -> Checksum {
        match self {
            Checksum::Wide(_) => Checksum::of(bytes),
            Checksum::Narrow(_) => Checksum::Narrow(crate::fletcher16(bytes)),
        }
    }

    /// Whether `bytes` sum to this.
    #[must_use]
    pub fn matches(self, bytes: &[u8]) -> bool {
        self.of_like(bytes) == self
    }
}

impl std::fmt::Display for Checksum {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Checksum::Wide(sum) => write!(f, "${sum:08X}"),
            Checksum::Narrow(sum) => write!(f, "${sum:04X} (a version 1 file's Fletcher-16)"),
        }
    }
}

/// Where an upload keeps what it is about to overwrite.
pub trait Keep {
    /// Whether to keep anything (reading it costs line time).
    fn wanted(&self) -> bool {
        true
    }

    /// Called before the upload writes the image's bytes, with what the
    /// robot held there, its hooks and its table as the upload found them.
    fn keep(&mut self, overwritten: &Backup);

    /// Called once the upload has finished, verified, with what
    /// [`Keep::keep`] received and a witness of the image's entry in the
    /// table: what an undo checks first, so that it is applied to the robot
    /// the upload went to and nowhere else. By default, kept again.
    fn finished(&mut self, kept: &Backup) {
        self.keep(kept);
    }

    /// Called in place of [`Keep::finished`] when the upload left the
    /// robot as it found it (the same image, installed as it was, the
    /// hooks where they were: read back to be sure), but for the RAM
    /// loader, which `kept` holds what it went over of: what an earlier
    /// upload of it kept, with `own` ([`Backup::going_further_back`]),
    /// undoes this one too and goes further back, unless it holds bytes
    /// where `loader_went_over` (the loader's code written this time over
    /// other bytes, which an older file would put back as they were before
    /// it, losing these); then `kept` is this upload's undo, as a change's.
    /// `own` is `kept` without the table and the memory of the other
    /// extensions installed, which the upload left as found and an older
    /// file must not take as this upload found them (recheck17 F2). By
    /// default, [`Keep::finished`].
    fn finished_unchanged(&mut self, kept: &Backup, own: &Backup, loader_went_over: &[Area]) {
        let _ = (own, loader_went_over);
        self.finished(kept);
    }

    /// Why what [`Keep::keep`] was handed could not be kept (a directory
    /// that takes no file, a full disk), if it could not: the upload then
    /// stops before it writes anything more ([`Error::UndoNotKept`];
    /// hostile20 F1: the robot was changed with no record of what it
    /// held). By default, nothing failed.
    fn failed(&self) -> Option<String> {
        None
    }
}

/// Stops an upload whose keeper could not keep what it was handed.
///
/// # Errors
/// [`Error::UndoNotKept`].
pub(crate) fn kept_or_stop(keep: &dyn Keep) -> Result<()> {
    match keep.failed() {
        Some(why) => Err(Error::UndoNotKept { why }),
        None => Ok(()),
    }
}

/// Keeps nothing (reads nothing).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoKeep;

impl Keep for NoKeep {
    fn wanted(&self) -> bool {
        false
    }

    fn keep(&mut self, _overwritten: &Backup) {}

    fn finished(&mut self, _kept: &Backup) {}
}

/// FNV-1a, 32 bits.
fn fnv1a32(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811C_9DC5, |hash, &byte| {
        (hash ^ u32::from(byte)).wrapping_mul(0x0100_0193)
    })
}

fn kind_code(kind: HookKind) -> u8 {
    match kind {
        HookKind::Unknown => 0,
        HookKind::Loop => 1,
    }
}

impl Backup {
    /// Whether any of the file's checks is a version 1 file's narrow
    /// Fletcher-16 ([`Checksum::Narrow`]), which some changes of two
    /// bytes pass.
    #[must_use]
    pub fn narrow_checks(&self) -> bool {
        (self.witnesses.iter())
            .chain(&self.written_entries)
            .any(|witness| matches!(witness.sum, Checksum::Narrow(_)))
    }

    /// The file's bytes.
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        for area in &self.areas {
            out.push(b'A');
            out.extend_from_slice(&area.address.to_le_bytes());
            out.extend_from_slice(&(area.bytes.len() as u16).to_le_bytes());
            out.extend_from_slice(&area.bytes);
        }
        for &(kind, target) in &self.hooks {
            out.push(b'H');
            out.push(kind_code(kind));
            out.extend_from_slice(&target.to_le_bytes());
        }
        let witnesses = self.witnesses.iter().map(|witness| (b'W', witness));
        let entries = self.written_entries.iter().map(|witness| (b'T', witness));
        for (record, witness) in witnesses.chain(entries) {
            let narrow = matches!(witness.sum, Checksum::Narrow(_));
            out.push(if narrow {
                record.to_ascii_lowercase()
            } else {
                record
            });
            out.extend_from_slice(&witness.address.to_le_bytes());
            out.extend_from_slice(&witness.len.to_le_bytes());
            match witness.sum {
                Checksum::Wide(sum) => out.extend_from_slice(&sum.to_le_bytes()),
                Checksum::Narrow(sum) => out.extend_from_slice(&sum.to_le_bytes()),
            }
        }
        for area in &self.rom {
            out.push(b'R');
            out.extend_from_slice(&area.address.to_le_bytes());
            out.extend_from_slice(&(area.bytes.len() as u16).to_le_bytes());
            out.extend_from_slice(&area.bytes);
        }
        let sum = fnv1a32(&out);
        out.push(b'E');
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Reads a backup file (`name` for messages).
    ///
    /// # Errors
    /// [`Error::BadBackup`] saying where and what is wrong.
    pub fn decode(name: &str, bytes: &[u8]) -> Result<Backup> {
        let bad = |at: usize, reason: &str| Error::BadBackup {
            name: name.to_owned(),
            offset: at,
            reason: reason.to_owned(),
        };
        let version_1 = bytes.starts_with(MAGIC_1);
        if !bytes.starts_with(MAGIC) && !version_1 {
            return Err(bad(
                0,
                "it does not start with `SCORPION-BACKUP 2` (or an older `SCORPION-BACKUP 1`)",
            ));
        }
        let mut at = MAGIC.len();
        let mut backup = Backup::default();
        // Where each hook's and each memory record started: a second
        // record for the same hook or bytes would make a restore's result
        // depend on the order it is read in.
        let mut hooks_at: Vec<(HookKind, usize)> = Vec::new();
        let mut areas_at: Vec<(u32, u32, usize)> = Vec::new();
        let take = |at: &mut usize, len: usize| -> Result<&[u8]> {
            let slice = bytes.get(*at..*at + len).ok_or_else(|| {
                bad(
                    *at,
                    &format!(
                        "it ends in the middle of a record: expected {len} more bytes, found {}",
                        bytes.len().saturating_sub(*at)
                    ),
                )
            })?;
            *at += len;
            Ok(slice)
        };
        loop {
            let start = at;
            let tag = take(&mut at, 1)?[0];
            match tag {
                b'A' => {
                    let head = take(&mut at, 4)?;
                    let address = u16::from_le_bytes([head[0], head[1]]);
                    let len = usize::from(u16::from_le_bytes([head[2], head[3]]));
                    let end = u32::from(address) + len as u32;
                    if end > 0x1_0000 {
                        return Err(bad(start, "a memory record runs past $FFFF"));
                    }
                    // hostile21 F9: said to overlap what it lay inside.
                    if len == 0 {
                        return Err(bad(
                            start,
                            &format!(
                                "a memory record of 0 bytes (at ${address:04X}): no backup writes one"
                            ),
                        ));
                    }
                    if let Some(&(_, _, first)) = areas_at
                        .iter()
                        .find(|&&(from, to, _)| u32::from(address) < to && from < end)
                    {
                        return Err(bad(
                            start,
                            &format!(
                                "a memory record (${address:04X}, {len} bytes) overlaps the one at byte {first}"
                            ),
                        ));
                    }
                    areas_at.push((u32::from(address), end, start));
                    let data = take(&mut at, len)?.to_vec();
                    backup.areas.push(Area {
                        address,
                        bytes: data,
                    });
                }
                b'H' => {
                    let record = take(&mut at, 3)?;
                    let kind = match record[0] {
                        0 => HookKind::Unknown,
                        1 => HookKind::Loop,
                        found => {
                            return Err(bad(
                                start + 1,
                                &format!("an unknown hook: expected 0 or 1, found {found}"),
                            ));
                        }
                    };
                    if let Some(&(_, first)) = hooks_at.iter().find(|(k, _)| *k == kind) {
                        return Err(bad(
                            start,
                            &format!(
                                "a second record for {} (the first is at byte {first})",
                                kind.rom_symbol()
                            ),
                        ));
                    }
                    hooks_at.push((kind, start));
                    backup
                        .hooks
                        .push((kind, u16::from_le_bytes([record[1], record[2]])));
                }
                kind @ (b'W' | b'T' | b'w' | b't') => {
                    // A version 1 file's `W` and `T` are narrow, as its
                    // copies' `w` and `t` are in version 2.
                    let narrow = version_1 || kind.is_ascii_lowercase();
                    if version_1 && kind.is_ascii_lowercase() {
                        return Err(bad(
                            start,
                            &format!(
                                "an unknown record `{}` (version 1 files have none)",
                                char::from(kind)
                            ),
                        ));
                    }
                    let kind = kind.to_ascii_uppercase();
                    let record = take(&mut at, if narrow { 6 } else { 8 })?;
                    let word = |i: usize| u16::from_le_bytes([record[i], record[i + 1]]);
                    let (address, len) = (word(0), word(2));
                    if u32::from(address) + u32::from(len) > 0x1_0000 {
                        return Err(bad(start, "a witness runs past $FFFF"));
                    }
                    let sum = if narrow {
                        Checksum::Narrow(word(4))
                    } else {
                        Checksum::Wide(u32::from_le_bytes([
                            record[4], record[5], record[6], record[7],
                        ]))
                    };
                    // Every witness written is at most `EXACT` bytes,
                    // over which its sums see any change of one or two.
                    if !narrow && usize::from(len) > crate::sums::EXACT {
                        return Err(bad(
                            start,
                            &format!(
                                "a witness of {len} bytes (at ${address:04X}): a version 2 file's are at most {}",
                                crate::sums::EXACT
                            ),
                        ));
                    }
                    let witness = Witness { address, len, sum };
                    // hostile19 F2: each is read from the robot before
                    // anything else is checked; one a table could not
                    // hold, or a copy, is refused here.
                    let entry = romlib::installed::ENTRY_LEN;
                    let whole = usize::from(len) % entry == 0
                        && (entry..=romlib::installed::ENTRIES * entry).contains(&usize::from(len));
                    if kind == b'T' && !whole {
                        return Err(bad(
                            start,
                            &format!(
                                "a table entry record of {len} bytes (entries are {entry} bytes each)"
                            ),
                        ));
                    }
                    let records = if kind == b'W' {
                        &mut backup.witnesses
                    } else {
                        &mut backup.written_entries
                    };
                    // Nothing to check, or checked already.
                    if len > 0 && !records.contains(&witness) {
                        records.push(witness);
                    }
                }
                b'R' => {
                    let head = take(&mut at, 4)?;
                    let address = u16::from_le_bytes([head[0], head[1]]);
                    let len = usize::from(u16::from_le_bytes([head[2], head[3]]));
                    if u32::from(address) + len as u32 > 0x1_0000 {
                        return Err(bad(start, "a ROM record runs past $FFFF"));
                    }
                    let data = take(&mut at, len)?.to_vec();
                    backup.rom.push(Area {
                        address,
                        bytes: data,
                    });
                }
                b'E' => {
                    let sum = take(&mut at, 4)?;
                    let sum = u32::from_le_bytes([sum[0], sum[1], sum[2], sum[3]]);
                    let computed = fnv1a32(&bytes[..start]);
                    if sum != computed {
                        return Err(bad(
                            start,
                            &format!(
                                "its checksum does not match: the end record holds ${sum:08X}, the bytes before it sum to ${computed:08X} (the file is damaged)"
                            ),
                        ));
                    }
                    if at != bytes.len() {
                        return Err(bad(at, "bytes follow the end record"));
                    }
                    return Ok(backup);
                }
                other => {
                    return Err(bad(
                        start,
                        &format!(
                            "an unknown record: expected A, H, W, T, w, t, R or E, found ${other:02X}"
                        ),
                    ));
                }
            }
        }
    }

    /// Bytes of memory held.
    #[must_use]
    pub fn len(&self) -> usize {
        self.areas.iter().map(|area| area.bytes.len()).sum()
    }

    /// Whether it holds no memory.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.areas.is_empty()
    }
}

/// What [`crate::backup`] saves of a robot with `profile`: the user zero
/// page, user RAM and the table of installed extensions (flags and
/// entries), as address ranges.
#[must_use]
pub fn backup_ranges(profile: &RomProfile) -> Vec<(u16, usize)> {
    let mut ranges = Vec::new();
    if let Some(zp) = &profile.user_zero_page {
        ranges.push((
            u16::from(*zp.start()),
            usize::from(*zp.end() - *zp.start()) + 1,
        ));
    }
    ranges.push((
        *profile.user_ram.start(),
        usize::from(*profile.user_ram.end() - *profile.user_ram.start()) + 1,
    ));
    if let Some(range) = table_range(profile) {
        ranges.push(range);
    }
    ranges
}

/// The table of installed extensions (flags and entries), if the ROM
/// keeps one.
pub(crate) fn table_range(profile: &RomProfile) -> Option<(u16, usize)> {
    profile
        .table
        .map(|(at, entries)| (at, entries * (1 + romlib::installed::ENTRY_LEN)))
}

/// Reads what `profile`'s robot holds ([`backup_ranges`] and the hooks),
/// every span read until two answers agree.
///
/// # Errors
/// A line error, [`Error::Unreadable`], [`Error::NotAHook`].
pub fn backup<T: Transport>(client: &mut Client<T>, profile: &RomProfile) -> Result<Backup> {
    Ok(backup_live(client, profile)?.backup)
}

/// What [`backup_live`] read, and what a person should know of it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Saved {
    /// What the robot held.
    pub backup: Backup,
    /// The addresses whose bytes kept changing while they were read (a
    /// counter the robot's control loop keeps, hostile16 F4): the backup
    /// holds the last value read there, a moment of a running program, as
    /// any backup of a running machine does.
    pub changing: Vec<u16>,
    /// Hooks whose way is already no way for a command to go (it loops,
    /// stops the CPU, strays): a restore of the file will refuse them, as
    /// it refuses now (recheck16 F4).
    pub broken: Vec<BrokenHook>,
    /// Installed extensions with memory outside what a backup saves (an
    /// operating system in KIM-bus RAM): the file only witnesses it, and
    /// a restore after it has gone is refused (fresh17 F4).
    pub outside: Vec<romlib::installed::Installed>,
    /// What is wrong with the robot's table of installed extensions, where
    /// it does not decode (changed by hand): a restore of the file refuses
    /// it before anything moves (hostile19 F4).
    pub damaged_table: Option<String>,
    /// Where the robot's hooks and its table disagree, as the file holds
    /// them: a restore puts back an extension its hooks do not lead to as
    /// it is (listed, never run), and refuses the others (`refused`).
    pub disagreements: Vec<crate::held_way::Disagreement>,
    /// Why a restore of the file will be refused before it writes
    /// anything, if it will: the robot's own state, changed by hand.
    pub refused: Option<String>,
}

/// A hook whose way is no way for a command to go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BrokenHook {
    /// The hook.
    pub hook: HookKind,
    /// Where it goes.
    pub target: u16,
    /// What is wrong with the way.
    pub why: &'static str,
    /// The way, `$0800 -> $0800`.
    pub path: String,
}

/// [`backup`], with what a person should know of it ([`Saved`]).
///
/// # Errors
/// As [`backup`].
pub fn backup_live<T: Transport>(client: &mut Client<T>, profile: &RomProfile) -> Result<Saved> {
    let hooks = read_hooks(client, profile)?;
    // Restored, a stub a session left hooked would be back with no host.
    crate::stub::left::refuse_hooked(client, profile, &hooks, &|_| false)?;
    let mut areas = Vec::new();
    let mut changing = Vec::new();
    for (address, len) in backup_ranges(profile) {
        let read = client.read_live(address, len)?;
        changing.extend(read.changing);
        areas.push(Area {
            address,
            bytes: read.bytes,
        });
    }
    // The robot's own ROM, not the profile's: a restore compares with it.
    let mut rom = Vec::new();
    for range in &profile.jump_table {
        let len = usize::from(range.end() - range.start()) + 1;
        rom.push(Area {
            address: *range.start(),
            bytes: client.read_memory(*range.start(), len)?,
        });
    }
    let mut backup = Backup {
        areas,
        hooks,
        rom,
        ..Backup::default()
    };
    let seen = crate::held_way::over_robot(client, profile, &backup)?;
    // hostile28 F3: every byte of code the ways run outside what the file
    // holds, each arm of a branch too, not only the steps' first bytes.
    let everyone = backup_table(profile, &seen);
    let laid = crate::way_checked::laid(&backup);
    let code = crate::way_checked::code_of(client, profile, (&backup.hooks, &everyone), &laid)?;
    let ranges = witness_ranges_over(profile, &backup, &seen, &code);
    backup.witnesses = read_witnesses(client, &ranges)?;
    // Code that changed while it was read is witnessed by nothing: its
    // restore refuses it, said now as it will say it.
    let unwitnessed = crate::way_checked::owner_in_front(&everyone, &code)
        .or_else(|| crate::way_checked::computed_outside(profile, &backup, &code))
        .map(|error| error.to_string())
        .or_else(|| {
            crate::way_checked::first_unchecked(profile, &backup, &code, &|_| false)
                .map(|(way, at)| crate::way_checked::unchecked_error(way, at, false).to_string())
        });
    let mut broken = Vec::new();
    let saved = |address: u16| backup.byte_at(u32::from(address)).is_some();
    let outside: Vec<romlib::installed::Installed> = backup_table(profile, &backup)
        .into_iter()
        .filter(|entry| {
            entry
                .extents
                .iter()
                .any(|extent| !saved(*extent.start()) || !saved(*extent.end()))
        })
        .collect();
    let into_ram = crate::chain::into_ram(profile, &backup.hooks);
    if !into_ram.is_empty() {
        // The table as this backup read it, not read again.
        let everyone = backup_table(profile, &backup);
        for (hook, target) in into_ram {
            if let Some((why, path)) =
                crate::chain::broken_way(client, profile, &everyone, (hook, target))?
            {
                broken.push(BrokenHook {
                    hook,
                    target,
                    why,
                    path: path.to_string(),
                });
            }
        }
    }
    let damaged_table = damaged_table(profile, &backup);
    let disagreements = crate::held_way::disagreements(profile, &backup);
    // fresh25 F2: what a restore of the file will refuse, said now as the
    // restore will say it (not what the robot-side check would do after).
    let refused = check_file(profile, &memory_profile(profile), &backup, false)
        .err()
        .map(|error| error.to_string())
        .or(unwitnessed);
    Ok(Saved {
        backup,
        changing,
        broken,
        outside,
        damaged_table,
        disagreements,
        refused,
    })
}

/// How many bytes at a hook's target are witnessed when no entry of the
/// table says how far its extension reaches.
const WITNESS_WINDOW: u16 = 16;

/// The memory whose sums witness `backup`'s hooks: for each hook that a
/// restore points into RAM, the extents of the installed extension (in
/// the backup's own table) that holds its target, or the first
/// [`WITNESS_WINDOW`] bytes at the target where no entry holds it; less
/// what the backup holds itself (a restore writes and verifies that).
#[cfg(test)]
pub(crate) fn witness_ranges(profile: &RomProfile, backup: &Backup) -> Vec<(u16, usize)> {
    witness_ranges_over(profile, backup, backup, &[])
}

/// [`witness_ranges`], the ways followed through `seen` (the backup over
/// the robot's bytes, [`crate::held_way::over_robot`]): the code a way
/// reaches outside the backup, and where its `JMP` goes on (N1); and every
/// byte of `code` (hostile28 F3).
fn witness_ranges_over(
    profile: &RomProfile,
    backup: &Backup,
    seen: &Backup,
    code: &[crate::way_checked::WayCode],
) -> Vec<(u16, usize)> {
    let mut marked = vec![false; 0x1_0000];
    for at in code.iter().flat_map(|way| way.code.iter()) {
        if profile.writable.iter().any(|range| range.contains(at)) {
            marked[usize::from(*at)] = true;
        }
    }
    // Every step of a way into memory the backup does not hold: a
    // restore checks the code there is what it was (hostile26 F2). Where
    // the code the way runs is known byte by byte, that is all: a window
    // past it takes in data the code writes (a counter in line), which a
    // restore would find changed.
    let run = |at: u16| code.iter().any(|way| way.code.contains(&at));
    let listed = backup_table(profile, seen);
    let in_listed = |at: u16| listed.iter().any(|entry| entry.contains(at));
    for (_, way) in crate::held_way::steps(profile, seen) {
        let at = way[way.len() - 1];
        let writable = profile.writable.iter().any(|range| range.contains(&at));
        if writable && (in_listed(at) || !run(at)) {
            mark_window(&mut marked, profile, (at, WITNESS_WINDOW), None);
        }
    }
    for (target, extents) in hooked_extents(profile, backup) {
        if extents.is_empty() {
            if !run(target) {
                mark_window(&mut marked, profile, (target, WITNESS_WINDOW), None);
            }
        } else {
            for extent in extents {
                marked[usize::from(*extent.start())..=usize::from(*extent.end())].fill(true);
            }
        }
    }
    unmarked_but_held(marked, backup)
}

/// The memory whose sums witness the hooks of what an upload of `image`
/// keeps (`kept`): only what is known to be code, never RAM the code
/// writes, which changes as soon as an extension runs. Of the extension
/// a kept hook goes back to, that is the bytes `image` loads there (the
/// robot holds them already, verified by their sums, or the file does),
/// and the first [`WITNESS_WINDOW`] bytes at the target (its handler's
/// entry); less the image's own RAM it does not load (its BSS and zero
/// page) and what the file holds.
pub(crate) fn kept_witness_ranges(
    profile: &RomProfile,
    kept: &Backup,
    image: &UploadImage,
    window: &dyn Fn(u16) -> u16,
) -> Vec<(u16, usize)> {
    let mut marked = vec![false; 0x1_0000];
    for (target, extents) in hooked_extents(profile, kept) {
        let home = extents.iter().find(|extent| extent.contains(&target));
        mark_window(&mut marked, profile, (target, window(target)), home);
        for extent in &extents {
            for address in extent.clone() {
                if image.contains(address) {
                    marked[usize::from(address)] = true;
                }
            }
        }
    }
    for extent in image.extents() {
        for address in extent.clone() {
            if !image.contains(address) {
                marked[usize::from(address)] = false;
            }
        }
    }
    unmarked_but_held(marked, kept)
}

/// [`kept_witness_ranges`], each hook's window as [`handler_windows`]
/// finds it on the robot.
///
/// # Errors
/// The line's errors.
pub(crate) fn kept_witness_ranges_on<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    kept: &Backup,
    image: &UploadImage,
) -> Result<Vec<(u16, usize)>> {
    let windows = handler_windows(client, profile, kept, image)?;
    let window = |target: u16| {
        windows
            .iter()
            .find(|(at, _)| *at == target)
            .map_or(WITNESS_WINDOW, |&(_, len)| len)
    };
    Ok(kept_witness_ranges(profile, kept, image, &window))
}

/// How many bytes at each hook of `kept` that goes into RAM the undo file
/// witnesses: the handler's instructions up to its first that does not go
/// on to the next (a `JMP`, `RTS`, `RTI`, `BRK`), at most
/// [`WITNESS_WINDOW`]. What follows may be the extension's data, which
/// its program writes (hostile17 F3: a counter's slow byte, witnessed,
/// changed before the undo, which was then refused for good); so may a
/// byte that changes as it is read, where the window stops short of it.
/// Read from the robot as it is now.
///
/// # Errors
/// The line's errors.
fn handler_windows<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    kept: &Backup,
    image: &UploadImage,
) -> Result<Vec<(u16, u16)>> {
    let mut windows = Vec::new();
    for (target, _) in hooked_extents(profile, kept) {
        let len = usize::from(WITNESS_WINDOW).min(0x1_0000 - usize::from(target));
        // An earlier copy of the image, uploaded again: its handler is
        // decoded from the image, not read (a read costs line time, and
        // the one-byte change its second).
        let loaded: Option<Vec<u8>> = (0..len)
            .map(|i| image.byte(target.wrapping_add(i as u16)))
            .collect();
        let read = match loaded {
            Some(bytes) => crate::LiveRead {
                bytes,
                changing: Vec::new(),
            },
            None => client.read_live(target, len)?,
        };
        let mut end = 0;
        while end < len {
            let op = isa::opcode(read.bytes[end]);
            end += usize::from(op.len());
            let goes_on = !matches!(
                op.mnemonic,
                isa::Mnemonic::Jmp | isa::Mnemonic::Rts | isa::Mnemonic::Rti | isa::Mnemonic::Brk
            ) && op.kind != isa::OpcodeKind::Jam;
            if !goes_on {
                break;
            }
        }
        let end = read
            .changing
            .iter()
            .map(|&at| usize::from(at.wrapping_sub(target)))
            .filter(|&offset| offset > 0)
            .fold(end.min(len), usize::min);
        windows.push((target, end.max(1) as u16));
    }
    Ok(windows)
}

/// How many bytes at a hook's target an undo file kept before the image's
/// bytes go out witnesses: the handler's first instruction, at least.
/// Until the file is kept again, whole, nothing of the code the hooks go
/// back to has changed, and the file holds the table entries that say
/// whose code it is; each byte read at the base rate costs robot time
/// (the one-byte change's second).
const EARLY_WITNESS_WINDOW: u16 = 4;

/// The first [`EARLY_WITNESS_WINDOW`] bytes at each hook of `backup` that
/// a restore points into RAM (within the extension that holds it), less
/// what the backup holds: what an undo file kept before any byte of the
/// image is written needs.
pub(crate) fn hook_windows(profile: &RomProfile, backup: &Backup) -> Vec<(u16, usize)> {
    let mut marked = vec![false; 0x1_0000];
    for (target, extents) in hooked_extents(profile, backup) {
        let home = extents.iter().find(|extent| extent.contains(&target));
        mark_window(&mut marked, profile, (target, EARLY_WITNESS_WINDOW), home);
    }
    unmarked_but_held(marked, backup)
}

/// Witnesses of [`hook_windows`], each range read once however often an
/// upload keeps its undo file again before its next change.
#[derive(Debug, Default)]
pub(crate) struct EarlyWitnesses(Vec<((u16, usize), Vec<Witness>)>);

impl EarlyWitnesses {
    /// Hands `keep` what an upload changed so far (`backup`: the hooks and
    /// the table as found, the chain slots re-pointed, what the loader
    /// overwrote), with the witnesses of its hooks' windows: called before
    /// each change made before the image's bytes go out (hostile10 F5).
    ///
    /// A window that holds what `image` loads there (an edited extension
    /// uploaded again over itself, the usual case) is read once, as the
    /// bytes an upload expects are (`Client::read_expecting`).
    pub(crate) fn keep<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        (profile, image): (&RomProfile, &UploadImage),
        mut backup: Backup,
        keep: &mut dyn Keep,
    ) -> Result<()> {
        let slots = image.chain_slot_bytes();
        let mut witnesses = Vec::new();
        for window in hook_windows(profile, &backup) {
            let (address, len) = window;
            let known = self.0.iter().find(|(read, _)| *read == window);
            match known {
                Some((_, read)) => witnesses.extend(read.iter().copied()),
                None => {
                    let expected: Vec<Option<u8>> = (0..len)
                        .map(|i| address.wrapping_add(i as u16))
                        .map(|at| image.byte(at).filter(|_| !slots.contains(&at)))
                        .collect();
                    let read =
                        witnesses_of(address, &client.read_live_expecting(address, &expected)?);
                    witnesses.extend(read.iter().copied());
                    self.0.push((window, read));
                }
            }
        }
        backup.witnesses = witnesses;
        keep.keep(&backup);
        kept_or_stop(keep)
    }
}

/// Each hook of `backup` that a restore points into RAM: its target and
/// the extents of the installed extension (in the backup's own table)
/// that holds it (none where no entry does).
fn hooked_extents(
    profile: &RomProfile,
    backup: &Backup,
) -> Vec<(u16, Vec<std::ops::RangeInclusive<u16>>)> {
    let installed = backup_table(profile, backup);
    backup
        .hooks
        .iter()
        .filter(|&&(kind, target)| {
            profile.reset_target(kind) != Some(target) && !in_rom(profile, target)
        })
        .map(|&(_, target)| {
            let extents = installed
                .iter()
                .filter(|entry| entry.contains(target))
                .flat_map(|entry| entry.extents.iter().cloned())
                .collect();
            (target, extents)
        })
        .collect()
}

/// Marks the first [`WITNESS_WINDOW`] bytes at `target`, within the
/// writable range that holds it and within `home` (its extension's
/// extent) where known.
fn mark_window(
    marked: &mut [bool],
    profile: &RomProfile,
    (target, window): (u16, u16),
    home: Option<&std::ops::RangeInclusive<u16>>,
) {
    let end = profile
        .writable
        .iter()
        .find(|range| range.contains(&target))
        .map_or(target, |range| *range.end());
    let end = end.min(target.saturating_add(window - 1));
    let end = home.map_or(end, |home| end.min(*home.end()));
    marked[usize::from(target)..=usize::from(end)].fill(true);
}

/// The marked addresses as runs, less what `backup` holds itself: each
/// read once, its witnesses of at most `sums::EXACT` bytes
/// ([`witnesses_of`]; or the sums' ranges that tile it, `sums::tiled`).
fn unmarked_but_held(mut marked: Vec<bool>, backup: &Backup) -> Vec<(u16, usize)> {
    for area in &backup.areas {
        let start = usize::from(area.address);
        marked[start..start + area.bytes.len()].fill(false);
    }
    let mut ranges: Vec<(u16, usize)> = Vec::new();
    for (address, &wanted) in marked.iter().enumerate() {
        if !wanted {
            continue;
        }
        match ranges.last_mut() {
            Some((start, len)) if usize::from(*start) + *len == address => *len += 1,
            _ => ranges.push((address as u16, 1)),
        }
    }
    ranges
}

/// The witnesses of `ranges`, from bytes read until two answers agree.
pub(crate) fn read_witnesses<T: Transport>(
    client: &mut Client<T>,
    ranges: &[(u16, usize)],
) -> Result<Vec<Witness>> {
    let mut witnesses = Vec::new();
    for &(address, len) in ranges {
        witnesses.extend(witnesses_of(address, &client.read_live(address, len)?));
    }
    Ok(witnesses)
}

/// The witnesses of what `read` found from `address`: one for each run
/// of bytes that held still while they were read. A byte the robot kept
/// changing (a counter in an extension's data, which its control loop
/// bumps: hostile16 F4) is no witness of anything: a restore would find
/// it changed again.
pub(crate) fn witnesses_of(address: u16, read: &crate::LiveRead) -> Vec<Witness> {
    let mut witnesses = Vec::new();
    let mut start = 0;
    for end in read
        .changing
        .iter()
        .map(|&at| usize::from(at.wrapping_sub(address)))
        .chain([read.bytes.len()])
    {
        // Short enough for their sums to see any change of one or two
        // bytes (hostile30 F4).
        for (at, len) in crate::sums::pieces(end.saturating_sub(start), crate::sums::EXACT) {
            let from = start + at;
            witnesses.push(Witness {
                address: address.wrapping_add(from as u16),
                len: len as u16,
                sum: Checksum::of(&read.bytes[from..from + len]),
            });
        }
        start = end + 1;
    }
    witnesses
}

/// The profile's ROM bytes of its jump table and vectors (the upload that
/// keeps them has compared them with the robot's).
pub(crate) fn profile_rom(profile: &RomProfile) -> Vec<Area> {
    let Some(rom) = &profile.rom else {
        return Vec::new();
    };
    profile
        .jump_table
        .iter()
        .filter_map(|range| {
            let start = usize::from(range.start().checked_sub(rom.address)?);
            let end = usize::from(range.end().checked_sub(rom.address)?) + 1;
            Some(Area {
                address: *range.start(),
                bytes: rom.bytes.get(start..end)?.to_vec(),
            })
        })
        .collect()
}

pub(crate) fn in_rom(profile: &RomProfile, target: u16) -> bool {
    profile.rom.as_ref().is_some_and(|rom| {
        u32::from(target) >= u32::from(rom.address) && u32::from(target) < rom.end()
    })
}

/// What is wrong with the backup's copy of the table, where it does not
/// decode.
fn damaged_table(profile: &RomProfile, backup: &Backup) -> Option<String> {
    decoded_table(profile, backup)?.err()
}

/// The backup's copy of the table, decoded (`None` for a ROM without a
/// table; bytes the file does not hold are taken as zeros).
fn decoded_table(
    profile: &RomProfile,
    backup: &Backup,
) -> Option<std::result::Result<Vec<romlib::installed::Installed>, String>> {
    let (at, entries) = profile.table?;
    let len = entries * (1 + romlib::installed::ENTRY_LEN);
    // recheck25 R5: an entry in use that the file does not hold whole is
    // not the file's to judge (read as zeros, it was called damaged on
    // the robot): the robot's copy is looked at where the file holds
    // part of the table ([`refuse_ways_over_robot`]).
    let cut = (0..entries).any(|slot| {
        let flags = backup.byte_at(u32::from(romlib::installed::flags_address(at, slot)));
        let entry = romlib::installed::entry_address(at, entries, slot);
        flags.is_some_and(romlib::installed::in_use)
            && (0..romlib::installed::ENTRY_LEN)
                .any(|i| backup.byte_at(u32::from(entry) + i as u32).is_none())
    });
    if cut {
        return None;
    }
    let held: Vec<u8> = (0..len)
        .map(|i| backup.byte_at(u32::from(at) + i as u32).unwrap_or(0))
        .collect();
    Some(romlib::installed::decode_table(at, entries, &held).map_err(|damaged| damaged.to_string()))
}

/// hostile21 F6: a file whose table lists an extension on a hook, and
/// which gives that hook no target, was restored "verified" with the hook
/// left at the ROM and the extension unhooked. Refused before anything is
/// written (only where the file holds the entry's flags: an undo file holds
/// what its upload changed).
fn check_hooks_given(profile: &RomProfile, backup: &Backup) -> Result<()> {
    let Some((table, _)) = profile.table else {
        return Ok(());
    };
    for entry in backup_table(profile, backup) {
        let flags = romlib::installed::flags_address(table, entry.slot);
        if backup.byte_at(u32::from(flags)).is_none() {
            continue;
        }
        for hook in &entry.hooks {
            if !backup.hooks.iter().any(|(kind, _)| *kind == hook.kind) {
                return Err(Error::BackupRefused {
                    reason: format!(
                        "the file's table lists {} on {} (its handler at ${:04X}), but the file gives {} no target: it would be left at the ROM's and the extension unhooked; nothing was written",
                        entry.describe(),
                        hook.kind.rom_symbol(),
                        hook.handler,
                        hook.kind.rom_symbol()
                    ),
                });
            }
        }
    }
    Ok(())
}

/// hostile22 F9, F10: where the file holds the table's flags whole, a hook
/// into RAM must go to the handler, for that hook, of an extension the
/// table lists, if it lists any on that hook: a hook to the other hook's
/// handler (the memory was written, then the restore refused) or to code
/// no entry names (the RAM loader's place, which the next upload writes
/// over) is refused before a byte is written.
fn check_hook_owners(profile: &RomProfile, backup: &Backup) -> Result<()> {
    let Some((table, entries)) = profile.table else {
        return Ok(());
    };
    let whole = (0..entries).all(|slot| {
        backup
            .byte_at(u32::from(romlib::installed::flags_address(table, slot)))
            .is_some()
    });
    if !whole {
        return Ok(());
    }
    let listed = backup_table(profile, backup);
    for &(kind, target) in &backup.hooks {
        if profile.reset_target(kind) == Some(target) || in_rom(profile, target) {
            continue;
        }
        let on_this = || {
            listed
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .filter(|hook| hook.kind == kind)
        };
        if on_this().count() == 0 || on_this().any(|hook| hook.handler == target) {
            continue;
        }
        let other = listed.iter().find_map(|entry| {
            (entry.hooks.iter())
                .find(|hook| hook.kind != kind && hook.handler == target)
                .map(|hook| (entry, hook.kind))
        });
        // Code no entry lists: an owner's handler in front of the
        // extensions, told once the robot is there to follow its way
        // (fresh28 F1, `way_checked::owner_in_front`).
        let Some((entry, its)) = other else {
            continue;
        };
        let what = format!("the {} handler of {}", its.rom_symbol(), entry.describe());
        return Err(Error::BackupRefused {
            reason: format!(
                "the file points {} at ${target:04X}, {what}, while its table lists extensions on {}: they would be reached through that code, if at all (the table's chain slots do not lead to them); nothing was written",
                kind.rom_symbol(),
                kind.rom_symbol()
            ),
        });
    }
    Ok(())
}

/// The extensions the backup's copy of the table lists (none where it
/// holds no table, or one that does not decode: the hooks' targets are
/// then witnessed by their first bytes).
pub(crate) fn backup_table(
    profile: &RomProfile,
    backup: &Backup,
) -> Vec<romlib::installed::Installed> {
    decoded_table(profile, backup)
        .and_then(std::result::Result::ok)
        .unwrap_or_default()
}

impl Backup {
    /// What an undo of an upload and of one after it that changed nothing
    /// on the robot ([`Keep::finished_unchanged`]) puts back: this, the
    /// earlier upload's undo, with every byte `later` holds and this does
    /// not (the RAM loader may have gone over memory the earlier upload
    /// did not touch: as `later` found it, it is as it was before both).
    /// The hooks, the witnesses and the ROM are this one's; the table
    /// entries written are both's (a project's second image is taken out
    /// too).
    #[must_use]
    pub fn going_further_back(mut self, later: &Backup) -> Backup {
        for entry in &later.written_entries {
            // An entry the later upload wrote again (a `--replace` at the
            // same slot) is as it wrote it.
            let end = u32::from(entry.address) + u32::from(entry.len);
            self.written_entries.retain(|earlier| {
                u32::from(earlier.address) + u32::from(earlier.len) <= u32::from(entry.address)
                    || u32::from(earlier.address) >= end
            });
            self.written_entries.push(*entry);
        }
        let mut added: Vec<Area> = Vec::new();
        for area in &later.areas {
            for (offset, &byte) in area.bytes.iter().enumerate() {
                let address = area.address.wrapping_add(offset as u16);
                if self.byte_at(u32::from(address)).is_none() {
                    crate::delta::push(&mut added, address, &[byte]);
                }
            }
        }
        self.areas.extend(added);
        self.areas.sort_by_key(|area| area.address);
        self
    }

    /// Whether a witness of the file covers `address`.
    #[must_use]
    pub fn witnessed(&self, address: u16) -> bool {
        self.witnesses.iter().any(|witness| {
            u32::from(witness.address) <= u32::from(address)
                && u32::from(address) < u32::from(witness.address) + u32::from(witness.len)
        })
    }

    /// The byte the backup holds at `address`, if it holds one.
    #[must_use]
    pub fn byte_at(&self, address: u32) -> Option<u8> {
        self.areas.iter().find_map(|area| {
            let offset = address.checked_sub(u32::from(area.address))?;
            area.bytes.get(offset as usize).copied()
        })
    }
}

/// Refuses a restore onto a robot whose ROM differs from the one the
/// backup was taken from (the RAM it holds calls into that ROM), unless
/// `force_rom` (then returns the refusal it overrode).
fn check_backup_rom<T: Transport>(
    client: &mut Client<T>,
    backup: &Backup,
    force_rom: bool,
) -> Result<Option<Error>> {
    let mut overridden = None;
    {
        let mut differences = Vec::new();
        for area in &backup.rom {
            let found = client.read_memory(area.address, area.bytes.len())?;
            differences.extend(
                area.bytes
                    .iter()
                    .zip(&found)
                    .enumerate()
                    .filter(|(_, (wanted, found))| wanted != found)
                    .map(|(i, (&wanted, &found))| (area.address + i as u16, wanted, found)),
            );
        }
        if !differences.is_empty() {
            let error = Error::BackupRomDiffers { differences };
            if !force_rom {
                return Err(error);
            }
            overridden = Some(error);
        }
    }
    Ok(overridden)
}

/// Whether `address` is in `range` (an address and a length: the table's,
/// as [`table_range`] gives it).
pub(crate) fn within(range: Option<(u16, usize)>, address: u16) -> bool {
    range.is_some_and(|(at, len)| {
        usize::from(address) >= usize::from(at) && usize::from(address) < usize::from(at) + len
    })
}

/// Refuses a restore onto a robot whose memory under a hook's target (the
/// table's entry of the hooked extension, or its code) no longer sums as
/// it did when the backup was written (nor, with `resume`, holds what the
/// backup itself puts there: a restore of it that stopped half way).
fn check_witnesses<T: Transport>(
    client: &mut Client<T>,
    backup: &Backup,
    profile: &RomProfile,
    (resume, interrupted, undo): (bool, bool, bool),
) -> Result<()> {
    let table = table_range(profile);
    // Read only where an undo's witness differs.
    let mut unchanged: Option<crate::way_checked::Unchanged> = None;
    // An older file witnessed its entry among the code's witnesses.
    let code = (backup.witnesses.iter()).map(|witness| (witness, !within(table, witness.address)));
    let entries = (backup.written_entries.iter())
        .filter(|_| !interrupted)
        .map(|entry| (entry, false));
    for (witness, code) in code.chain(entries) {
        let bytes = client.read_memory(witness.address, usize::from(witness.len))?;
        // The code a hook goes back to as the robot will hold it once the
        // file is written: a file that undoes two uploads holds bytes the
        // later one rewrote under the earlier one's witness, as they were
        // (fresh19 F10: a project run whose second image replaced the
        // handler an earlier upload's file witnessed could not be undone).
        // An entry is the robot's as the upload wrote it.
        let after: Vec<u8> = (0..u32::from(witness.len))
            .zip(&bytes)
            .map(|(i, &now)| {
                let held = backup.byte_at(u32::from(witness.address) + i);
                held.filter(|_| code).unwrap_or(now)
            })
            .collect();
        let found = witness.sum.of_like(&after);
        // What the file itself puts there, where its restore stopped half
        // way (killed, a dead line) and wrote it already: finishing it is
        // what the file is for. Only then: a fresh robot's zeros may be
        // what the file holds too.
        let resumed = || {
            let held: Option<Vec<u8>> = (0..u32::from(witness.len))
                .map(|i| backup.byte_at(u32::from(witness.address) + i))
                .collect();
            held.as_ref() == Some(&bytes)
        };
        if found != witness.sum && !(resume && resumed()) {
            // fresh29 F1: an owner's code on a hook the undo leaves as it
            // is, changed by hand since: the undo does not run it anew.
            if undo && code {
                let known = match unchanged.take() {
                    Some(known) => known,
                    None => crate::way_checked::Unchanged::read(client, profile, backup)?,
                };
                let left = known.only_on_unchanged(witness);
                unchanged = Some(known);
                if left {
                    continue;
                }
            }
            let in_table = within(table, witness.address);
            return Err(Error::WitnessDiffers {
                what: if in_table {
                    "the installed-extension table's entry a hook goes back to"
                } else {
                    "the code a hook goes back to"
                },
                address: witness.address,
                len: witness.len,
                expected: witness.sum,
                found,
            });
        }
    }
    Ok(())
}

/// Puts `backup` back into the robot, verified, hooks last: first every
/// hook goes to the ROM's own target (verified), so nothing runs the RAM
/// while it changes; then the memory, through the RAM loader where it
/// pays (only the ranges whose checksum differs), and where the loader
/// itself ran, with the ROM's commands; then each hook to its target in
/// the backup, verified. A reset or a lost byte on the way leaves every
/// hook at the ROM's target or at verified code.
///
/// Before any hook moves, the robot's ROM is compared with the profile's
/// ([`Error::WrongRom`]) and with the one the backup was taken from
/// ([`Error::BackupRomDiffers`]), and each [`Witness`] with the robot's
/// memory ([`Error::WitnessDiffers`]). With `options.force_rom` a ROM that
/// differs is not refused: each refusal overridden is told to `progress`
/// ([`crate::Event::RomCheckOverridden`]), and the memory then goes in
/// through the ROM's own commands alone (the RAM loader calls the ROM
/// through the jump table that differs), unchecked against the ROM.
///
/// # Errors
/// [`Error::WrongRom`], [`Error::BackupRomDiffers`],
/// [`Error::WitnessDiffers`], [`Error::BackupRefused`] for memory an upload may
/// not write, [`Error::UnwitnessedHook`] for a hook into RAM the file
/// neither holds nor witnesses (before the line is used), and every error
/// an upload has.
pub fn restore<T: Transport>(
    client: &mut Client<T>,
    backup: &Backup,
    options: &UploadOptions,
    progress: &mut dyn Progress,
) -> Result<Vec<UploadReport>> {
    let profile = &options.profile;
    // Everything the file asks is checked before the robot is touched: a
    // file refused half way must not have moved a hook first.
    let memory = memory_options(options);
    let whole = check_file(profile, &memory.profile, backup, options.undo)?;
    // A restore or upload that died at the loader's fast rate may have
    // left the robot there: `connect` finds it and asks it back.
    let (hooks, _) = crate::upload::connect(client, options)?;
    // A debug stub a killed session left hooked: its breakpoints are not
    // the backup's to take out. Said first (fresh19 F11: an undo called it
    // a later upload chained ahead).
    crate::stub::left::refuse_hooked(client, profile, &hooks, &|_| false)?;
    if options.undo {
        // Read once for both looks.
        let undone = crate::undo::undone_extensions(client, backup, profile)?;
        crate::undo::refuse_later_uploads(client, backup, profile, (&hooks, &undone.0))?;
        crate::undo::refuse_later_entries(backup, (profile, options.resume), &undone)?;
    }
    // The ROM the backup was taken from first: a robot with another ROM
    // is told as that (`restore --force` overrides it), not as a ROM the
    // profile's image was linked against.
    let mut overridden = Vec::new();
    overridden.extend(check_backup_rom(client, backup, options.force_rom)?);
    match fingerprint::check_jump_table(client, profile) {
        Err(error @ Error::WrongRom { .. }) if options.force_rom => overridden.push(error),
        other => other?,
    }
    check_witnesses(
        client,
        backup,
        profile,
        (options.resume, options.interrupted, options.undo),
    )?;
    // The ways as the restore would leave them, followed past what the
    // file holds over the robot's bytes (the witnesses checked above).
    let seen = crate::held_way::over_robot(client, profile, backup)?;
    // hostile28 F4: a file holding part of the table (an undo file with an
    // entry cut out) over what a reset left of the robot's: the table it
    // would leave does not decode. Told before the flags go in.
    if let Some(damaged) = damaged_table(profile, &seen) {
        return Err(Error::BackupRefused {
            reason: format!(
                "the table of installed extensions, the file's over the robot's, would not decode ({damaged}): the file does not hold the entries its flags mark in use; nothing was written"
            ),
        });
    }
    if seen != *backup {
        refuse_ways(
            profile,
            &seen,
            "on the robot as the file would leave it",
            options.undo,
        )?;
    }
    let undo = options.undo || !backup.written_entries.is_empty();
    if undo {
        check_steps_on_robot(client, profile, backup, &seen)?;
    } else {
        check_steps_over(profile, backup, &seen)?;
    }
    crate::way_checked::check_restore(client, profile, (backup, &seen), undo)?;
    if undo && !options.resume && !options.interrupted {
        crate::relisted::check(client, profile, (backup, &seen))?;
    }
    for error in &overridden {
        progress.event(&crate::progress::Event::RomCheckOverridden {
            refusal: error.to_string(),
        });
    }
    let mut memory = memory;
    if !overridden.is_empty() {
        memory.loader = LoaderChoice::Never;
    }
    progress.event(&crate::progress::Event::RestoreStarted);
    let to_rom: Vec<(HookKind, u16)> = HookKind::ALL
        .into_iter()
        .filter_map(|kind| profile.reset_target(kind).map(|to| (kind, to)))
        .collect();
    switch_hooks(client, profile, &to_rom, options.max_writes)?;
    let mut reports = Vec::new();
    // The table is read again where the file writes memory.
    let table = whole.as_ref().map(|_| (&memory, table_range(profile)));
    if let Some(whole) = whole {
        let (through_loader, after) = split_for_loader(&memory, &whole, client.transport().baud())?;
        if let Some(image) = through_loader {
            reports.push(upload(client, &image, &memory, progress)?);
        }
        if let Some(image) = after {
            let rom = UploadOptions {
                loader: LoaderChoice::Never,
                ..memory.clone()
            };
            reports.push(upload(client, &image, &rom, progress)?);
        }
    }
    if let Some(table) = table {
        table_again(client, backup, table, progress)?;
    }
    // recheck17 F3: a hook whose way is broken stays at the ROM's target;
    // the others, whose ways are fine, are restored all the same.
    let refused = crate::chain::check_restored(client, profile, &backup.hooks)?;
    let fine: Vec<(HookKind, u16)> = backup
        .hooks
        .iter()
        .copied()
        .filter(|(kind, _)| !refused.iter().any(|(broken, _)| broken == kind))
        .collect();
    // And once the hooks are in: a reset as they went in put them back at
    // the ROM's targets and cleared the table again (the code they reach
    // is in place: a reset keeps user RAM). Both are read again, and
    // written again where a reset undid them (hostile20 F5: the hooks
    // were left at the ROM after "verified").
    let mut rounds = 0;
    let unreached = loop {
        switch_hooks(client, profile, &fine, options.max_writes)?;
        if let Some(table) = table {
            table_again(client, backup, table, progress)?;
        }
        // What the robot lists and its hooks do not lead to, as
        // `installed` shows it (fresh25 F3: an undo file does not hold
        // the chain slots to tell it before). Read before the hooks are
        // read back: a reset while it is read is found by that.
        let unreached = crate::held_way::unreached(client, profile)?;
        let now = read_hooks(client, profile)?;
        let lost = fine.iter().find(|hook| !now.contains(hook));
        rounds += 1;
        match lost {
            None => break unreached,
            Some(&(kind, target)) if rounds == 3 => {
                let operand = profile.hook_address(kind) + 1;
                let found = now
                    .iter()
                    .find(|(this, _)| *this == kind)
                    .map_or(0, |h| h.1);
                return Err(Error::VerifyFailed {
                    address: operand,
                    expected: target.to_le_bytes()[0],
                    found: found.to_le_bytes()[0],
                    attempts: rounds,
                });
            }
            Some(_) => {}
        }
    };
    if let Some((_, error)) = refused.into_iter().next() {
        return Err(error);
    }
    for found in unreached {
        progress.event(&crate::progress::Event::RestoredNotHooked { found });
    }
    Ok(reports)
}

/// hostile19 F5: a reset (`/1R`) while the memory went in clears the
/// table (and the hooks, which are still at the ROM's targets then): the
/// table is read again before any hook moves, and what the file holds of
/// it written again, with the ROM's commands, where a reset cleared it.
/// Without it the hooks went to code the table no longer listed, and the
/// undo said "verified".
fn table_again<T: Transport>(
    client: &mut Client<T>,
    backup: &Backup,
    (memory, table): (&UploadOptions, Option<(u16, usize)>),
    progress: &mut dyn Progress,
) -> Result<()> {
    let Some((at, len)) = table else {
        return Ok(());
    };
    let held: Vec<Option<u8>> = (0..len)
        .map(|i| backup.byte_at(u32::from(at) + i as u32))
        .collect();
    if held.iter().all(Option::is_none) {
        return Ok(());
    }
    if client
        .read_expecting(at, &held)?
        .iter()
        .zip(&held)
        .all(|(now, held)| held.is_none_or(|held| held == *now))
    {
        return Ok(());
    }
    let mut areas: Vec<Area> = Vec::new();
    for (i, byte) in held.iter().enumerate() {
        if let Some(byte) = byte {
            crate::delta::push(&mut areas, at + i as u16, &[*byte]);
        }
    }
    let rom = UploadOptions {
        loader: LoaderChoice::Never,
        ..memory.clone()
    };
    upload(
        client,
        &UploadImage::new(areas, Vec::new())?,
        &rom,
        progress,
    )?;
    Ok(())
}

/// What a restore checks of a file before the line is used: its memory
/// records, hooks, witnesses and table, each as something `backup` or an
/// upload could have written, and its hooks followed through its own
/// memory ([`crate::held_way`]). Returns the memory as one image (none
/// where the file holds none). `memory` is the profile the memory is
/// written with ([`memory_options`]). An upload's undo file (`undo`)
/// puts back the robot as its upload found it: a way through code no
/// entry lists that the upload chained in front of (an owner's, hooked
/// by hand, or a freed entry's) is not refused there (recheck25 R6: the
/// upload went through, and its undo was refused as made by hand); the
/// witnesses still check that code is what it was.
fn check_file(
    profile: &RomProfile,
    memory: &RomProfile,
    backup: &Backup,
    undo: bool,
) -> Result<Option<UploadImage>> {
    let whole = if backup.areas.is_empty() {
        None
    } else {
        let whole = UploadImage::new(backup.areas.clone(), Vec::new())?;
        // hostile22 F2: said as a file's, not an image's ("link with
        // --target").
        memory.check(&whole).map_err(|error| match error {
            Error::BadImage { reason } => Error::BackupRefused {
                reason: format!("the file's memory records: {reason}; nothing was written"),
            },
            error => error,
        })?;
        Some(whole)
    };
    check_hook_targets(backup, memory, table_range(profile))?;
    // An undo file (given to `restore` too) witnesses the code its hooks
    // go back to; what lies behind that, its upload did not change.
    if !undo && backup.written_entries.is_empty() {
        check_steps(profile, backup)?;
    }
    check_records(backup, memory, profile.table)?;
    check_hooks_given(profile, backup)?;
    if let Some(damaged) = damaged_table(profile, backup) {
        // hostile19 F4: the hooks went to the ROM first, and every restore
        // of it failed after.
        return Err(Error::BackupRefused {
            reason: format!(
                "the file's table of installed extensions does not decode ({damaged}): it was damaged on the robot when it was saved; nothing was written"
            ),
        });
    }
    refuse_held_stub(backup, profile)?;
    // After the stub's own refusal: a stub is code no entry lists too.
    if !undo {
        check_hook_owners(profile, backup)?;
    }
    refuse_ways(profile, backup, "in the file", undo)?;
    Ok(whole)
}

/// Refuses the ways through `seen` (a file, or a file over what the robot
/// holds) that a restore must not hook ([`crate::held_way`]); `place`
/// says whose memory it was; `undo`, as [`check_file`] takes it.
fn refuse_ways(profile: &RomProfile, seen: &Backup, place: &str, undo: bool) -> Result<()> {
    let refused = crate::held_way::disagreements(profile, seen)
        .into_iter()
        .filter(|found| !(undo && found.made_by_hand_before()))
        .find_map(|found| found.refusal().map(|why| (found, why)));
    match refused {
        Some((found, why)) => Err(Error::BackupRefused {
            reason: format!(
                "{place}, {}: restored, {why}; nothing was written",
                found.describe()
            ),
        }),
        None => Ok(()),
    }
}

/// The options a restore writes memory with: the table is written as
/// memory, flags and all, while no hook points into RAM (no table
/// bookkeeping of the upload's own).
fn memory_options(options: &UploadOptions) -> UploadOptions {
    UploadOptions {
        profile: memory_profile(&options.profile),
        ..options.clone()
    }
}

/// [`memory_options`]'s profile.
fn memory_profile(profile: &RomProfile) -> RomProfile {
    let mut memory = profile.clone();
    memory.table = None;
    if let Some((address, len)) = table_range(profile) {
        memory.writable.push(address..=address + (len as u16 - 1));
    }
    memory
}

/// A hook may go back to the ROM (its reset target, or anywhere in the
/// ROM's bytes) or into memory an upload may write; never into the I/O
/// page, the stack or the ROM's own RAM, where no code of an extension
/// can be (a hook there stops the robot at its next command). A hook into
/// RAM must go where the file restores memory or holds a witness
/// ([`Error::UnwitnessedHook`]), so that the code it reaches is checked.
fn check_hook_targets(
    backup: &Backup,
    profile: &crate::image::RomProfile,
    table: Option<(u16, usize)>,
) -> Result<()> {
    for &(kind, target) in &backup.hooks {
        let to_rom = profile.reset_target(kind) == Some(target);
        if !to_rom && in_rom(profile, target) {
            // A backup or an undo file only ever holds the ROM's own
            // target: anywhere else in the ROM is its data or the middle
            // of its code (hostile8's F1: a vector, a JMP's operand).
            return Err(Error::BackupRefused {
                reason: format!(
                    "the backup points {} at ${target:04X}, inside the ROM but not where the ROM points it ({}): no extension's code is there; nothing was written",
                    kind.rom_symbol(),
                    profile
                        .reset_target(kind)
                        .map_or_else(|| "nowhere".to_owned(), |to| format!("${to:04X}"))
                ),
            });
        }
        let to_ram = profile.writable.iter().any(|range| range.contains(&target));
        if !to_rom && !to_ram {
            return Err(Error::BackupRefused {
                reason: format!(
                    "the backup points {} at ${target:04X}, which is neither the ROM nor memory an extension may hold; nothing was written",
                    kind.rom_symbol()
                ),
            });
        }
        // A file written by `backup` holds the RAM a hook goes to, and an
        // upload's undo file holds or witnesses it (`kept_witness_ranges`
        // marks the target first): a hook into RAM that neither covers was
        // made by something else, and nothing would be checked there
        // before the robot jumps in.
        if !to_rom && within(table, target) {
            // Witnessed or held, the table is data (hostile10 F14).
            return Err(Error::BackupRefused {
                reason: format!(
                    "the backup points {} at ${target:04X}, in the table of installed extensions: no handler starts there; nothing was written",
                    kind.rom_symbol()
                ),
            });
        }
        let held = backup.byte_at(u32::from(target)).is_some();
        let witnessed = backup.witnesses.iter().any(|witness| {
            u32::from(witness.address) <= u32::from(target)
                && u32::from(target) < u32::from(witness.address) + u32::from(witness.len)
        });
        if !to_rom && !held && !witnessed {
            return Err(Error::UnwitnessedHook {
                hook: kind.rom_symbol(),
                target,
            });
        }
        if !to_rom && !witnessed {
            check_held_entry(backup, kind, target)?;
        }
    }
    Ok(())
}

/// hostile26 F1: each step of a backup's ways into RAM (past the first,
/// which [`check_hook_targets`] checks) lies in memory the file holds or
/// witnesses, as `backup` writes it: else the code a restore hooks there
/// is not checked. (An undo file witnesses the code its hooks go back to;
/// what lies behind that, [`check_steps_on_robot`] checks.)
fn check_steps(profile: &RomProfile, backup: &Backup) -> Result<()> {
    check_steps_over(profile, backup, backup)
}

/// [`check_steps`], the ways followed through `seen` (the file over the
/// robot's bytes): a step on from code the file only witnesses (N1).
fn check_steps_over(profile: &RomProfile, backup: &Backup, seen: &Backup) -> Result<()> {
    match unchecked_steps(profile, backup, seen).into_iter().next() {
        Some((kind, way)) => Err(Error::UnwitnessedStep {
            hook: kind.rom_symbol(),
            target: way[way.len() - 1],
            path: crate::held_way::path_text(&way),
        }),
        None => Ok(()),
    }
}

/// hostile26 F1b: an undo file's ways past the first step into memory it
/// neither holds nor witnesses lie in an extension the robot's table lists
/// now, or on a way the robot's hooks run now: code its upload did not
/// change, which the robot runs already. A file changed by hand (or a
/// robot reset since, its table cleared, its hooks at the ROM) hooked
/// code nothing checked, exit 0.
///
/// # Errors
/// [`Error::UndoStepUnlisted`]; the line's errors.
fn check_steps_on_robot<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    backup: &Backup,
    seen: &Backup,
) -> Result<()> {
    let listed = crate::table::read_installed(client, profile)?;
    let unchecked: Vec<(HookKind, Vec<u16>)> = unchecked_steps(profile, backup, seen)
        .into_iter()
        .filter(|(_, way)| {
            !listed
                .iter()
                .any(|entry| entry.contains(way[way.len() - 1]))
        })
        .collect();
    if unchecked.is_empty() {
        return Ok(());
    }
    // Code no entry lists that the robot's ways run through now (recheck25
    // R6: an upload chained in front of it, its undo puts that way back).
    let now = Backup {
        hooks: read_hooks(client, profile)?,
        ..Backup::default()
    };
    let now = crate::held_way::over_robot(client, profile, &now)?;
    let run_now: Vec<u16> = crate::held_way::steps(profile, &now)
        .into_iter()
        .map(|(_, way)| way[way.len() - 1])
        .collect();
    match unchecked
        .into_iter()
        .find(|(_, way)| !run_now.contains(&way[way.len() - 1]))
    {
        Some((kind, way)) => Err(Error::UndoStepUnlisted {
            hook: kind.rom_symbol(),
            target: way[way.len() - 1],
            path: crate::held_way::path_text(&way),
        }),
        None => Ok(()),
    }
}

/// The steps of the file's ways into RAM (followed through `seen`), past
/// the first, that land in memory it neither holds nor witnesses: each
/// with the way there.
fn unchecked_steps(
    profile: &RomProfile,
    backup: &Backup,
    seen: &Backup,
) -> Vec<(HookKind, Vec<u16>)> {
    crate::held_way::steps(profile, seen)
        .into_iter()
        .filter(|(_, way)| {
            let at = way[way.len() - 1];
            let writable = profile.writable.iter().any(|range| range.contains(&at));
            let held = backup.byte_at(u32::from(at)).is_some();
            let witnessed = backup.witnessed(at);
            // The first step is `check_hook_targets`'s.
            way.len() > 1 && writable && !held && !witnessed
        })
        .collect()
}

/// Each witness lies in memory an upload may write (the table included),
/// and each table entry record on whole entries of the table: anything
/// else is no file an upload or `backup` wrote, and would be read from
/// the robot (the I/O page, where a read of the serial chip's data
/// register eats a received byte) before the rest is checked (hostile19
/// F2).
fn check_records(backup: &Backup, memory: &RomProfile, table: Option<(u16, usize)>) -> Result<()> {
    let writable = |witness: &Witness| {
        let last = u32::from(witness.address) + u32::from(witness.len) - 1;
        u16::try_from(last).is_ok_and(|last| memory.writable_span(witness.address, last))
    };
    if let Some(witness) = backup.witnesses.iter().find(|witness| !writable(witness)) {
        return Err(Error::BackupRefused {
            reason: format!(
                "the file witnesses {} bytes at ${:04X}, outside the memory an extension may hold: no upload or backup wrote that; nothing was written",
                witness.len, witness.address
            ),
        });
    }
    // hostile21 F8: ROM records are read from the robot to compare; one
    // outside the ROM would read the I/O page (a read of the serial chip's
    // data register eats a received byte) and blame the ROM.
    let start = memory
        .rom
        .as_ref()
        .map_or(platform::map::ROM_START, |rom| rom.address);
    let in_the_rom =
        |area: &Area| area.address >= start && !area.bytes.is_empty() && area.end() <= 0x1_0000;
    if let Some(area) = backup.rom.iter().find(|area| !in_the_rom(area)) {
        return Err(Error::BackupRefused {
            reason: format!(
                "the file's record of the robot's ROM ({} bytes at ${:04X}) is not in the ROM: no backup wrote that; nothing was written",
                area.bytes.len(),
                area.address
            ),
        });
    }
    let on_entries = |witness: &Witness| {
        table.is_some_and(|(at, entries)| {
            let first = u32::from(romlib::installed::entry_address(at, entries, 0));
            let end = first + (entries * romlib::installed::ENTRY_LEN) as u32;
            let address = u32::from(witness.address);
            address >= first
                && (address - first) % romlib::installed::ENTRY_LEN as u32 == 0
                && address + u32::from(witness.len) <= end
        })
    };
    if let Some(entry) = backup
        .written_entries
        .iter()
        .find(|entry| !on_entries(entry))
    {
        return Err(Error::BackupRefused {
            reason: format!(
                "the file's record of a table entry an upload wrote ({} bytes at ${:04X}) is not on the table's entries: no upload wrote that; nothing was written",
                entry.len, entry.address
            ),
        });
    }
    Ok(())
}

/// A file taken while a debug session was attached (or had died) holds
/// its stub hooked (hostile10's F1): restored, the stub would be back with
/// no host, its breakpoints' `JSR`s live in the code.
fn refuse_held_stub(backup: &Backup, profile: &RomProfile) -> Result<()> {
    for &(kind, target) in &backup.hooks {
        if kind != HookKind::Unknown || profile.reset_target(kind) == Some(target) {
            continue;
        }
        let held = |at: u16| backup.byte_at(u32::from(at));
        if let Some(stub) = crate::stub::left::held_at_target(profile, target, &held) {
            return Err(Error::BackupHoldsDebugStub {
                hook: kind.rom_symbol(),
                stub: stub.address,
                end: stub.end,
            });
        }
    }
    Ok(())
}

/// A hook into RAM the file itself restores must find there what starts
/// an extension's handler (hostile8's F2, F3: a crafted file's hook into
/// zeros, the table, or the last byte of what it holds; the table is
/// refused before, with witnessed targets): a whole documented
/// instruction other than `BRK`, every byte of it held by the file.
fn check_held_entry(backup: &Backup, kind: HookKind, target: u16) -> Result<()> {
    let refuse = |why: String| {
        Err(Error::BackupRefused {
            reason: format!(
                "the backup points {} at ${target:04X}, {why}: no handler starts there; nothing was written",
                kind.rom_symbol()
            ),
        })
    };
    let first = backup.byte_at(u32::from(target)).unwrap_or(0);
    let opcode = isa::opcode(first);
    if !opcode.is_documented() || opcode.mnemonic == isa::Mnemonic::Brk {
        return refuse(format!(
            "which holds ${first:02X} (not an instruction a handler starts with)"
        ));
    }
    let whole =
        (0..u32::from(opcode.len())).all(|i| backup.byte_at(u32::from(target) + i).is_some());
    if !whole {
        return refuse(format!(
            "where the file holds only part of the {}-byte instruction",
            opcode.len()
        ));
    }
    Ok(())
}

/// Where the loader would run for a restore of `whole` (a hole at the top
/// of user RAM and user zero page), and `whole` split into what goes
/// through it and what goes in after it, with the ROM's commands. No
/// loader (a profile without one, `--loader never`): all of it after.
fn split_for_loader(
    options: &UploadOptions,
    whole: &UploadImage,
    baud: u32,
) -> Result<(Option<UploadImage>, Option<UploadImage>)> {
    let profile = &options.profile;
    let rates = (baud, options.fast_baud.unwrap_or(baud));
    let ram_end = *profile.user_ram.end();
    let hole = ram_end.saturating_sub(LOADER_HOLE - 1)..=ram_end;
    let zp_hole = profile
        .user_zero_page
        .as_ref()
        .map(|zp| u16::from(zp.end().saturating_sub(7))..=u16::from(*zp.end()));
    let holed = cut(
        whole,
        &[Some(hole), zp_hole.clone()]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>(),
    );
    let plan = match (&holed, options.loader) {
        (_, LoaderChoice::Never) | (None, _) => None,
        (Some(holed), _) => loader_plan(profile, holed, rates)?,
    };
    let Some(plan) = plan else {
        return Ok((None, Some(whole.clone())));
    };
    let code = plan.code.address..=(plan.code.end() - 1) as u16;
    let zp = u16::from(*plan.zero_page.start())..=u16::from(*plan.zero_page.end());
    // The loader runs only where the file puts back every byte it
    // overwrites, code and zero page: else a restore (an undo, which holds
    // only what its upload wrote) would leave it there, over the owner's
    // RAM or an installed extension nobody then puts back.
    if !code
        .clone()
        .chain(zp.clone())
        .all(|address| whole.contains(address))
    {
        return Ok((None, Some(whole.clone())));
    }
    let before = cut(whole, &[code.clone(), zp.clone()]);
    let after = keep_only(whole, &[code, zp]);
    Ok((before, after))
}

/// How much of user RAM's top a restore leaves to the loader at first.
const LOADER_HOLE: u16 = 0x100;

/// `image` without the bytes in `holes`; `None` if nothing is left.
fn cut(image: &UploadImage, holes: &[std::ops::RangeInclusive<u16>]) -> Option<UploadImage> {
    select(image, |address| {
        !holes.iter().any(|hole| hole.contains(&address))
    })
}

/// `image`'s bytes in `ranges` alone; `None` if there are none.
fn keep_only(image: &UploadImage, ranges: &[std::ops::RangeInclusive<u16>]) -> Option<UploadImage> {
    select(image, |address| {
        ranges.iter().any(|range| range.contains(&address))
    })
}

fn select(image: &UploadImage, wanted: impl Fn(u16) -> bool) -> Option<UploadImage> {
    let mut areas: Vec<Area> = Vec::new();
    for area in image.areas() {
        for (i, &byte) in area.bytes.iter().enumerate() {
            let address = area.address + i as u16;
            if !wanted(address) {
                continue;
            }
            match areas.last_mut() {
                Some(last) if last.end() == u32::from(address) => last.bytes.push(byte),
                _ => areas.push(Area {
                    address,
                    bytes: vec![byte],
                }),
            }
        }
    }
    UploadImage::new(areas, Vec::new()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Backup {
        Backup {
            areas: vec![
                Area {
                    address: 0x0030,
                    bytes: vec![1, 2, 3],
                },
                Area {
                    address: 0x0400,
                    bytes: (0..=255).collect(),
                },
            ],
            hooks: vec![(HookKind::Unknown, 0xFF21), (HookKind::Loop, 0x0456)],
            witnesses: vec![
                Witness {
                    address: 0x0800,
                    len: 0x40,
                    sum: Checksum::Wide(0x1234_5678),
                },
                // Kept from a version 1 file.
                Witness {
                    address: 0x0900,
                    len: 0x40,
                    sum: Checksum::Narrow(0x1234),
                },
            ],
            written_entries: vec![Witness {
                address: 0x0F90,
                len: romlib::installed::ENTRY_LEN as u16,
                sum: Checksum::Wide(0x5678_9ABC),
            }],
            rom: vec![Area {
                address: 0xFFFA,
                bytes: vec![1, 2, 3, 4, 5, 6],
            }],
        }
    }

    #[test]
    fn a_backup_round_trips() {
        let bytes = sample().encode();
        assert!(bytes.starts_with(MAGIC));
        assert_eq!(Backup::decode("b", &bytes).expect("decodes"), sample());
    }

    #[test]
    fn any_damaged_byte_is_refused() {
        let bytes = sample().encode();
        for at in 0..bytes.len() {
            let mut damaged = bytes.clone();
            damaged[at] ^= 0x01;
            assert!(
                Backup::decode("b", &damaged).is_err(),
                "byte {at} flipped was taken"
            );
        }
        assert!(Backup::decode("b", &bytes[..bytes.len() - 1]).is_err());
    }

    /// hostile30: a version 1 file (narrow sums in its `W` and `T`) is
    /// still read, its witnesses narrow; written again, they are kept as
    /// `w` and `t` records and read back the same. A `w` in a version 1
    /// file is refused at its place.
    #[test]
    fn a_version_1_file_is_read_with_its_narrow_sums() {
        let entry = romlib::installed::ENTRY_LEN as u8;
        let mut body = MAGIC_1.to_vec();
        body.extend_from_slice(&[b'H', 0, 0x00, 0x08]);
        body.extend_from_slice(&[b'W', 0x00, 0x08, 0x10, 0, 0x34, 0x12]);
        body.extend_from_slice(&[b'T', 0x90, 0x0F, entry, 0, 0x78, 0x56]);
        let backup = Backup::decode("old.bak", &with_end(body.clone())).expect("decodes");
        assert!(backup.narrow_checks());
        let mut wide = sample();
        wide.witnesses
            .retain(|w| matches!(w.sum, Checksum::Wide(_)));
        assert!(!wide.narrow_checks());
        assert_eq!(backup.witnesses[0].sum, Checksum::Narrow(0x1234));
        assert_eq!(backup.written_entries[0].sum, Checksum::Narrow(0x5678));
        let again = backup.encode();
        assert!(again.starts_with(MAGIC));
        assert!(again.windows(2).any(|w| w == [b'w', 0x00]), "kept narrow");
        assert_eq!(
            Backup::decode("again.bak", &again).expect("decodes"),
            backup
        );
        let narrow = |bytes: &[u8]| Checksum::Narrow(crate::fletcher16(bytes));
        assert!(narrow(&[1, 2, 3]).matches(&[1, 2, 3]));
        assert!(!narrow(&[1, 2, 3]).matches(&[1, 2, 4]));
        // Version 1 had no narrow copies to tell apart.
        let at = body.len();
        body.extend_from_slice(&[b'w', 0x00, 0x08, 0x10, 0, 0x34, 0x12]);
        let error = Backup::decode("mixed.bak", &with_end(body)).expect_err("refused");
        assert!(
            matches!(&error, Error::BadBackup { offset, .. } if *offset == at),
            "{error:?}"
        );
    }

    /// A backup file with `backup`'s records and a good end record.
    fn with_end(mut body: Vec<u8>) -> Vec<u8> {
        let sum = fnv1a32(&body);
        body.push(b'E');
        body.extend_from_slice(&sum.to_le_bytes());
        body
    }

    #[test]
    fn a_second_record_for_one_hook_is_refused_at_its_place() {
        let mut body = MAGIC.to_vec();
        body.extend_from_slice(&[b'H', 0, 0x21, 0xFF]);
        let second = body.len();
        body.extend_from_slice(&[b'H', 0, 0x00, 0x04]);
        let error = Backup::decode("twice.bak", &with_end(body)).expect_err("refused");
        let text = error.to_string();
        assert!(
            matches!(&error, Error::BadBackup { offset, .. } if *offset == second),
            "{error:?}"
        );
        assert!(text.contains("HOOK_UNKNOWN"), "{text}");
        assert!(text.contains(&format!("byte {}", MAGIC.len())), "{text}");
    }

    /// hostile19 F2: a table entry record no table could hold is refused
    /// at its place; a copy of a record is one record (3000 copies were
    /// each read from the robot).
    #[test]
    fn table_entry_records_are_whole_entries_and_copies_are_one() {
        let entry = romlib::installed::ENTRY_LEN as u8;
        let mut body = MAGIC.to_vec();
        let record = |kind: u8, len: u8| [kind, 0x90, 0x0F, len, 0, 0x34, 0x12, 0, 0];
        for _ in 0..3 {
            body.extend_from_slice(&record(b'T', entry));
            body.extend_from_slice(&record(b'W', 4));
        }
        body.extend_from_slice(&record(b'W', 0));
        let backup = Backup::decode("copies.bak", &with_end(body.clone())).expect("decodes");
        // Longer than its sums see whole: no file writes one.
        let mut long = MAGIC.to_vec();
        long.extend_from_slice(&[b'W', 0x00, 0x08, 0x01, 0x01, 0, 0, 0, 0]);
        let error = Backup::decode("long.bak", &with_end(long)).expect_err("refused");
        assert!(error.to_string().contains("257 bytes"), "{error}");
        assert_eq!(
            (backup.written_entries.len(), backup.witnesses.len()),
            (1, 1)
        );
        let odd = body.len();
        body.extend_from_slice(&record(b'T', entry - 1));
        let error = Backup::decode("odd.bak", &with_end(body)).expect_err("refused");
        assert!(
            matches!(&error, Error::BadBackup { offset, .. } if *offset == odd),
            "{error:?}"
        );
    }

    #[test]
    fn overlapping_memory_records_are_refused_at_their_place() {
        let mut body = MAGIC.to_vec();
        body.extend_from_slice(&[b'A', 0x00, 0x04, 4, 0, 1, 2, 3, 4]);
        let second = body.len();
        body.extend_from_slice(&[b'A', 0x02, 0x04, 1, 0, 9]);
        let error = Backup::decode("overlap.bak", &with_end(body)).expect_err("refused");
        assert!(
            matches!(&error, Error::BadBackup { offset, .. } if *offset == second),
            "{error:?}"
        );
        assert!(error.to_string().contains("$0402"), "{error}");
        // hostile21 F9: an empty record inside another is said to be empty.
        let mut body = MAGIC.to_vec();
        body.extend_from_slice(&[b'A', 0x00, 0x04, 4, 0, 1, 2, 3, 4]);
        body.extend_from_slice(&[b'A', 0x02, 0x04, 0, 0]);
        let error = Backup::decode("empty.bak", &with_end(body)).expect_err("refused");
        assert!(error.to_string().contains("0 bytes (at $0402)"), "{error}");
    }

    #[test]
    fn a_truncated_or_damaged_file_says_where_and_what_was_expected() {
        let bytes = sample().encode();
        let cut = &bytes[..MAGIC.len() + 3];
        let text = Backup::decode("cut.bak", cut)
            .expect_err("refused")
            .to_string();
        assert!(
            text.contains(&format!("at byte {}", MAGIC.len() + 1)),
            "{text}"
        );
        assert!(text.contains("expected 4 more bytes, found 2"), "{text}");

        let mut damaged = bytes.clone();
        let last = damaged.len() - 1;
        damaged[last] ^= 0x40;
        let text = Backup::decode("damaged.bak", &damaged)
            .expect_err("refused")
            .to_string();
        assert!(
            text.contains(&format!("at byte {}", bytes.len() - 5)),
            "{text}"
        );
        assert!(text.contains("the end record holds $"), "{text}");
    }

    /// A hook into the I/O page, the ROM's zero page or the stack is
    /// refused (`restore` asks this before it opens the line); RAM an
    /// extension may hold and the ROM's own target are not.
    #[test]
    fn a_hook_into_the_io_page_or_the_roms_ram_is_refused_before_the_line_is_used() {
        let profile = RomProfile::reference();
        let options = UploadOptions {
            profile: profile.clone(),
            ..UploadOptions::default()
        };
        for target in [0xC000, 0x0000, 0x01FD] {
            let backup = Backup {
                areas: Vec::new(),
                hooks: vec![(HookKind::Unknown, target)],
                ..Backup::default()
            };
            let said = check_hook_targets(&backup, &memory_options(&options).profile, None)
                .expect_err("refused")
                .to_string();
            assert!(said.contains(&format!("${target:04X}")), "{said}");
        }
        let ram = Backup {
            areas: vec![Area {
                address: 0x0400,
                bytes: vec![0xEA; 4],
            }],
            hooks: vec![
                (HookKind::Unknown, 0x0400),
                (
                    HookKind::Loop,
                    profile.reset_target(HookKind::Loop).expect("known"),
                ),
            ],
            ..Backup::default()
        };
        assert!(check_hook_targets(&ram, &profile, table_range(&profile)).is_ok());
    }

    /// F6 (issue 27, round 6): a hook into RAM the file neither restores
    /// nor witnesses is refused, naming the hook and its target; one the
    /// file holds a byte at, or a witness covers, is taken.
    #[test]
    fn a_hook_into_ram_the_file_neither_holds_nor_witnesses_is_refused() {
        let profile = RomProfile::reference();
        let bare = Backup {
            hooks: vec![(HookKind::Loop, 0x0700)],
            witnesses: vec![Witness {
                address: 0x0701,
                len: 0x10,
                sum: Checksum::Wide(0),
            }],
            ..Backup::default()
        };
        let error =
            check_hook_targets(&bare, &profile, table_range(&profile)).expect_err("refused");
        assert!(
            matches!(
                error,
                Error::UnwitnessedHook {
                    hook: "HOOK_LOOP",
                    target: 0x0700
                }
            ),
            "{error:?}"
        );
        let said = error.to_string();
        for part in [
            "HOOK_LOOP at $0700",
            "not in the ROM's code",
            "not restored by this file",
            "not witnessed",
        ] {
            assert!(said.contains(part), "{part}: {said}");
        }
        let witnessed = Backup {
            witnesses: vec![Witness {
                address: 0x06F8,
                len: 0x09,
                sum: Checksum::Wide(0),
            }],
            ..bare.clone()
        };
        assert!(check_hook_targets(&witnessed, &profile, table_range(&profile)).is_ok());
        let held = Backup {
            areas: vec![Area {
                address: 0x0700,
                bytes: vec![0x60],
            }],
            ..bare
        };
        assert!(check_hook_targets(&held, &profile, table_range(&profile)).is_ok());
    }

    /// hostile8's F1-F3: crafted files (a valid checksum) whose hook goes
    /// into the ROM's data, the middle of its code, zeros, the table of
    /// installed extensions, or the last byte of what the file holds were
    /// restored, exit 0, and the robot jammed at its next command.
    #[test]
    fn a_hook_at_no_handler_is_refused_before_the_line_is_used() {
        let profile = RomProfile::reference();
        let table = table_range(&profile);
        let (table_at, _) = table.expect("the reference ROM has a table");
        // As `restore` asks it: the table writable, with the memory.
        let options = UploadOptions {
            profile: profile.clone(),
            ..UploadOptions::default()
        };
        let profile = memory_options(&options).profile;
        let file = |hook: u16, areas: Vec<Area>| Backup {
            areas,
            hooks: vec![(HookKind::Unknown, hook)],
            ..Backup::default()
        };
        let handler = vec![0x4C, 0x21, 0xFF, 0xC9, b'Q', 0xD0];
        let cases = [
            (file(0xFF01, Vec::new()), "inside the ROM"),
            (file(0xFFFC, Vec::new()), "inside the ROM"),
            (
                file(
                    0x0030,
                    vec![Area {
                        address: 0x0030,
                        bytes: vec![0; 16],
                    }],
                ),
                "holds $00",
            ),
            (
                file(
                    table_at + 8,
                    vec![Area {
                        address: table_at,
                        bytes: vec![0x20; 64],
                    }],
                ),
                "in the table",
            ),
            // hostile10 F14: witnessed (an undo file's witness of the
            // entry), the table is no handler either.
            (
                Backup {
                    witnesses: vec![Witness {
                        address: table_at + 8,
                        len: 15,
                        sum: Checksum::Wide(0),
                    }],
                    ..file(table_at + 8, Vec::new())
                },
                "in the table",
            ),
            (
                file(
                    0x0405,
                    vec![Area {
                        address: 0x0400,
                        bytes: handler.clone(),
                    }],
                ),
                "only part of the 2-byte instruction",
            ),
        ];
        for (backup, why) in cases {
            let hook = backup.hooks[0].1;
            let said = check_hook_targets(&backup, &profile, table)
                .expect_err("refused")
                .to_string();
            assert!(
                said.contains(why) && said.contains(&format!("${hook:04X}")),
                "{said}"
            );
        }
        let good = file(
            0x0403,
            vec![Area {
                address: 0x0400,
                bytes: handler,
            }],
        );
        assert!(check_hook_targets(&good, &profile, table).is_ok());
    }

    /// The handler of the extension the witness tests keep at $0400.
    const HANDLER: isa::objfmt::HookRecord = isa::objfmt::HookRecord {
        kind: HookKind::Unknown,
        handler: 0x0403,
        chain: Some(0x0401),
    };

    /// A file's areas: the table of installed extensions naming one at
    /// `extent` (its handler [`HANDLER`]), and $0420-$043F of its code.
    fn table_naming(profile: &RomProfile, extent: std::ops::RangeInclusive<u16>) -> Vec<Area> {
        let (table, entries) = profile.table.expect("the reference ROM keeps a table");
        let installed = romlib::installed::Installed::new(1, vec![extent], &[HANDLER]);
        let mut flags = vec![0u8; entries];
        flags[..installed.entries()].copy_from_slice(&installed.flags());
        vec![
            Area {
                address: table,
                bytes: flags,
            },
            Area {
                address: romlib::installed::entry_address(table, entries, 0),
                bytes: installed.encode(),
            },
            Area {
                address: 0x0420,
                bytes: vec![0; 0x20],
            },
        ]
    }

    /// An undo file whose hook goes back into an extension it holds only a
    /// part of: the rest of that extension (as the kept table names it)
    /// is witnessed; a hook at the ROM's target needs no witness.
    #[test]
    fn witnesses_cover_the_hooked_extension_less_what_the_backup_holds() {
        let profile = RomProfile::reference();
        let rom_target = profile.reset_target(HookKind::Loop).expect("known");
        let backup = Backup {
            areas: table_naming(&profile, 0x0400..=0x0BFF),
            hooks: vec![(HookKind::Unknown, 0x0403), (HookKind::Loop, rom_target)],
            ..Backup::default()
        };
        assert_eq!(
            witness_ranges(&profile, &backup),
            vec![(0x0400, 0x20), (0x0440, 0x0C00 - 0x0440)]
        );
        // No table entry names it: its first bytes.
        let bare = Backup {
            hooks: vec![(HookKind::Unknown, 0x0700)],
            ..Backup::default()
        };
        assert_eq!(
            witness_ranges(&profile, &bare),
            vec![(0x0700, usize::from(WITNESS_WINDOW))]
        );
    }

    /// What an upload keeps witnesses only code: of the extension the
    /// kept hook goes back to (its table extent $0400-$050F, BSS and all),
    /// the bytes the new image loads, less what the file holds; never the
    /// new image's BSS ($0500-$050F), which its code writes.
    #[test]
    fn an_uploads_witnesses_cover_the_code_it_loads_not_its_bss() {
        let profile = RomProfile::reference();
        let kept = Backup {
            areas: table_naming(&profile, 0x0400..=0x050F),
            hooks: vec![(HookKind::Unknown, 0x0403)],
            ..Backup::default()
        };
        let linked = linker::Image {
            entry: 0x0403,
            flags: 0,
            areas: vec![linker::LoadArea {
                load: 0x0400,
                run: 0x0400,
                bytes: vec![0xEA; 0x100],
            }],
            sections: vec![linker::ImageSection {
                name: "BSS".into(),
                run: 0x0500,
                load: 0x0500,
                size: 0x10,
                kind: linker::layout::SegmentKind::Bss,
                exec: false,
            }],
            symbols: Vec::new(),
            hooks: isa::objfmt::Hooks {
                records: vec![HANDLER],
            },
            lines: isa::objfmt::SrcMap::default(),
        };
        let image = UploadImage::try_from(&linked).expect("an image");
        assert_eq!(image.extents(), &[0x0400..=0x050F]);
        assert_eq!(
            kept_witness_ranges(&profile, &kept, &image, &|_| WITNESS_WINDOW),
            vec![(0x0400, 0x20), (0x0440, 0xC0)]
        );
        // The whole extent, BSS included, by the rule for a full backup.
        assert_eq!(
            witness_ranges(&profile, &kept),
            vec![(0x0400, 0x20), (0x0440, 0xD0)]
        );
    }

    #[test]
    fn the_reference_backup_covers_zero_page_ram_and_the_table() {
        let ranges = backup_ranges(&RomProfile::reference());
        assert_eq!(
            ranges,
            vec![(0x0030, 0xD0), (0x0400, 0x0B40), (0x0F80, 0x80)]
        );
    }
}
