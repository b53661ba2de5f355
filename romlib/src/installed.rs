//! The table of installed extensions (`EXTTAB`): what every loader reads
//! before it writes anything, and writes, verified, before it switches a
//! hook. The ROM owns the table's RAM and frees every entry at power-up
//! and on `/1R` (when the hooks go back to the ROM too).
//!
//! The table is `EXTTAB_ENTRIES` flags bytes, one per entry, then the
//! entries' `EXTTAB_ENTRY_LEN` (15) bytes each: a loader reads the flags
//! in one question and then only the entries in use.
//!
//! A flags byte: bit 7 in use (clear: the entry is free, whatever its
//! bytes hold; a reset clears only the flags), bit 6 another extent of the
//! entry before, bit 0 takes `HOOK_UNKNOWN`, bit 1 takes `HOOK_LOOP`.
//!
//! | entry bytes | what |
//! |---|---|
//! | 0-2 | the image's id (24 bits of a hash of its bytes), little-endian |
//! | 3-4, 5-6 | the extent: first and last address (inclusive), little-endian |
//! | 7-8, 9-10 | `HOOK_UNKNOWN`'s handler and chain slot (0: none) |
//! | 11-12, 13-14 | `HOOK_LOOP`'s handler and chain slot (0: none) |
//!
//! An image whose memory is in several places (an operating system's code
//! on the KIM bus, its variables in user RAM) takes one entry per extent;
//! the first carries the hooks, the others have bit 6 set.

use std::ops::RangeInclusive;

use isa::objfmt::{HookKind, HookRecord};

use crate::symbols::{EXTTAB, EXTTAB_ENTRIES, EXTTAB_ENTRY_LEN};

/// The table's address.
pub const TABLE: u16 = EXTTAB;
/// Entries in the table.
pub const ENTRIES: usize = EXTTAB_ENTRIES as usize;
/// Bytes per entry, its flags byte not counted.
pub const ENTRY_LEN: usize = EXTTAB_ENTRY_LEN as usize;
/// The table's size in bytes: the flags, then the entries.
pub const TABLE_LEN: usize = ENTRIES * (1 + ENTRY_LEN);

const USED: u8 = 0x80;
const MORE: u8 = 0x40;
const TAKES_UNKNOWN: u8 = 0x01;
const TAKES_LOOP: u8 = 0x02;

/// Where a table of `entries` entries at `table` keeps an entry's flags
/// byte and its bytes.
#[must_use]
pub fn flags_address(table: u16, slot: usize) -> u16 {
    table + slot as u16
}

/// Whether a flags byte marks its entry in use.
#[must_use]
pub fn in_use(flags: u8) -> bool {
    flags & USED != 0
}

/// Where entry `slot`'s bytes start, in a table of `entries` entries.
#[must_use]
pub fn entry_address(table: u16, entries: usize, slot: usize) -> u16 {
    table + (entries + slot * ENTRY_LEN) as u16
}

/// A hook an installed extension took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TakenHook {
    /// Which hook.
    pub kind: HookKind,
    /// Where the hook (or the chain slot before it) jumps to.
    pub handler: u16,
    /// The `JMP` operand holding the next target in the chain, if any.
    pub chain: Option<u16>,
}

/// One installed image: its id, the memory it owns, the hooks it took.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Installed {
    /// 24 bits of a hash of the image's bytes.
    pub id: u32,
    /// The memory it owns, loaded or reserved.
    pub extents: Vec<RangeInclusive<u16>>,
    /// The hooks it took.
    pub hooks: Vec<TakenHook>,
    /// The first table entry it occupies.
    pub slot: usize,
}

/// A table that does not decode: an entry that continues nothing, an
/// extent that ends before it starts, or a hook's handler or chain slot
/// outside the entry's own memory.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the table of installed extensions is damaged at the entry whose flags are at ${address:04X}: {reason}"
)]
pub struct DamagedTable {
    /// The entry's address.
    pub address: u16,
    /// What is wrong.
    pub reason: String,
}

/// `1 entry`, `3 entries`, as messages count a table's entries.
#[must_use]
pub fn entries_text(count: usize) -> String {
    if count == 1 {
        "1 entry".to_owned()
    } else {
        format!("{count} entries")
    }
}

/// `$0400-$0452`, as messages write an extent.
#[must_use]
pub fn extent_text(extent: &RangeInclusive<u16>) -> String {
    format!("${:04X}-${:04X}", extent.start(), extent.end())
}

/// 24 bits of FNV-1a over `bytes`: tells two images apart in a listing.
#[must_use]
pub fn image_id(bytes: impl IntoIterator<Item = u8>) -> u32 {
    let mut hash: u32 = 0x811C_9DC5;
    for byte in bytes {
        hash ^= u32::from(byte);
        hash = hash.wrapping_mul(0x0100_0193);
    }
    hash & 0x00FF_FFFF
}

impl Installed {
    /// `extension 8C8390 ($0400-$044F)`, as messages name an installed
    /// image: its id and its memory.
    #[must_use]
    pub fn describe(&self) -> String {
        let extents: Vec<String> = self.extents.iter().map(extent_text).collect();
        format!("extension {:06X} ({})", self.id, extents.join(", "))
    }

    /// An image about to be installed: its id, its memory, and the hooks
    /// its records take (its slot is set where it goes).
    #[must_use]
    pub fn new(id: u32, extents: Vec<RangeInclusive<u16>>, records: &[HookRecord]) -> Installed {
        Installed {
            id,
            extents,
            hooks: records
                .iter()
                .map(|record| TakenHook {
                    kind: record.kind,
                    handler: record.handler,
                    chain: record.chain,
                })
                .collect(),
            slot: 0,
        }
    }

    /// Whether `address` is in memory it owns.
    #[must_use]
    pub fn contains(&self, address: u16) -> bool {
        self.extents.iter().any(|extent| extent.contains(&address))
    }

    /// Table entries needed.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.extents.len().max(1)
    }

    /// The flags bytes of its entries, one per extent.
    #[must_use]
    pub fn flags(&self) -> Vec<u8> {
        (0..self.entries())
            .map(|index| {
                if index > 0 {
                    return USED | MORE;
                }
                self.hooks.iter().fold(USED, |flags, hook| {
                    flags
                        | match hook.kind {
                            HookKind::Unknown => TAKES_UNKNOWN,
                            HookKind::Loop => TAKES_LOOP,
                        }
                })
            })
            .collect()
    }

    /// Its entries' bytes, `ENTRY_LEN` per extent (the flags apart).
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.entries() * ENTRY_LEN);
        for (index, extent) in self.extents.iter().enumerate() {
            let mut entry = [0u8; ENTRY_LEN];
            entry[0..3].copy_from_slice(&self.id.to_le_bytes()[..3]);
            entry[3..5].copy_from_slice(&extent.start().to_le_bytes());
            entry[5..7].copy_from_slice(&extent.end().to_le_bytes());
            if index == 0 {
                for hook in &self.hooks {
                    let at = match hook.kind {
                        HookKind::Unknown => 7,
                        HookKind::Loop => 11,
                    };
                    entry[at..at + 2].copy_from_slice(&hook.handler.to_le_bytes());
                    entry[at + 2..at + 4].copy_from_slice(&hook.chain.unwrap_or(0).to_le_bytes());
                }
            }
            out.extend_from_slice(&entry);
        }
        out
    }

    /// The refusal of an image with memory `extents`, where one of them
    /// meets one of this extension's ([`crate::Error::Overlap`], naming
    /// both); `None` where none does.
    #[must_use]
    pub fn overlap(&self, extents: &[RangeInclusive<u16>]) -> Option<crate::Error> {
        extents.iter().find_map(|new| {
            let owned = self
                .extents
                .iter()
                .find(|owned| owned.start() <= new.end() && new.start() <= owned.end())?;
            Some(crate::Error::Overlap {
                new: extent_text(new),
                old: extent_text(owned),
                id: self.id,
            })
        })
    }
}

/// Decodes a table of `flags.len()` entries: `entry(slot)` gives the
/// bytes of an entry in use (a loader reads only those).
///
/// # Errors
/// [`DamagedTable`] for an entry that cannot be what a loader wrote.
pub fn decode<'a>(
    table: u16,
    flags: &[u8],
    entry: impl Fn(usize) -> &'a [u8],
) -> Result<Vec<Installed>, DamagedTable> {
    let mut installed: Vec<Installed> = Vec::new();
    for (slot, &flags) in flags.iter().enumerate() {
        if !in_use(flags) {
            continue;
        }
        let address = flags_address(table, slot);
        let damaged = |reason: &str| DamagedTable {
            address,
            reason: reason.to_owned(),
        };
        let bytes = entry(slot);
        if bytes.len() < ENTRY_LEN {
            return Err(damaged("its entry was not read whole"));
        }
        let word = |at: usize| u16::from_le_bytes([bytes[at], bytes[at + 1]]);
        let id = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], 0]);
        let (first, last) = (word(3), word(5));
        if last < first {
            return Err(damaged("its extent ends before it starts"));
        }
        if flags & MORE != 0 {
            let Some(owner) = installed
                .last_mut()
                .filter(|owner| owner.id == id && owner.slot + owner.extents.len() == slot)
            else {
                return Err(damaged("it continues no entry of the same image"));
            };
            owner.extents.push(first..=last);
            continue;
        }
        // hostile25 F2: zeroed by hand, flags kept: no loader writes an
        // entry of nothing (a chain then ran through memory it seemed to
        // list at $0000).
        if bytes[..ENTRY_LEN].iter().all(|&byte| byte == 0) {
            return Err(damaged("it is marked in use and holds nothing (all zeros)"));
        }
        let mut hooks = Vec::new();
        for (flag, kind, at) in [
            (TAKES_UNKNOWN, HookKind::Unknown, 7),
            (TAKES_LOOP, HookKind::Loop, 11),
        ] {
            if flags & flag != 0 {
                let chain = word(at + 2);
                hooks.push(TakenHook {
                    kind,
                    handler: word(at),
                    chain: (chain != 0).then_some(chain),
                });
            }
        }
        installed.push(Installed {
            id,
            extents: vec![first..=last],
            hooks,
            slot,
        });
    }
    // A handler or a chain slot outside the image's own memory is no
    // upload's: an upload that chained through it would jump to whatever
    // two bytes lie there (hostile10 F12: the ROM, the table, an I/O
    // register).
    for one in &installed {
        let within = |at: u16| one.extents.iter().any(|extent| extent.contains(&at));
        let astray = one.hooks.iter().find(|hook| {
            !within(hook.handler)
                || hook
                    .chain
                    .is_some_and(|slot| !within(slot) || !within(slot.wrapping_add(1)))
        });
        if let Some(hook) = astray {
            return Err(DamagedTable {
                address: flags_address(table, one.slot),
                reason: format!(
                    "its {} handler (${:04X}) or chain slot ({}) lies outside its own memory",
                    hook.kind.rom_symbol(),
                    hook.handler,
                    hook.chain
                        .map_or_else(|| "none".to_owned(), |slot| format!("${slot:04X}"))
                ),
            });
        }
    }
    // No loader lists two extensions in one place (an overlap is refused,
    // or the old one taken out first): two entries that claim the same
    // memory were written by hand (hostile21 F14: one extension listed
    // twice, restored, and a hook then ran through memory no entry held).
    for (index, one) in installed.iter().enumerate() {
        if let Some(other) = installed[index + 1..]
            .iter()
            .find(|other| other.overlap(&one.extents).is_some())
        {
            return Err(DamagedTable {
                address: flags_address(table, other.slot),
                reason: format!(
                    "it claims memory the entry at slot {} claims too ({})",
                    one.slot,
                    one.describe()
                ),
            });
        }
    }
    Ok(installed)
}

/// Decodes a whole table as it stands in memory (`TABLE_LEN` bytes for the
/// reference ROM's).
///
/// # Errors
/// As [`decode`].
pub fn decode_table(
    table: u16,
    entries: usize,
    bytes: &[u8],
) -> Result<Vec<Installed>, DamagedTable> {
    let flags = bytes.get(..entries).unwrap_or_default();
    decode(table, flags, |slot| {
        let start = entries + slot * ENTRY_LEN;
        bytes.get(start..start + ENTRY_LEN).unwrap_or_default()
    })
}

/// The memory a linked image owns: where its bytes are stored, and where
/// each of its segments runs (BSS and zero page included, which an upload
/// does not write but the image uses), merged where they touch.
#[must_use]
pub fn image_extents(image: &linker::Image) -> Vec<RangeInclusive<u16>> {
    let loaded = image
        .areas
        .iter()
        .map(|area| (u64::from(area.load), area.bytes.len() as u64));
    let running = image
        .sections
        .iter()
        .map(|section| (u64::from(section.run), u64::from(section.size)));
    merge(loaded.chain(running))
}

/// `(start, length)` pairs as sorted, merged inclusive ranges (clipped to
/// 16 bits; empty ones dropped).
#[must_use]
pub fn merge(ranges: impl IntoIterator<Item = (u64, u64)>) -> Vec<RangeInclusive<u16>> {
    let mut spans: Vec<(u64, u64)> = ranges
        .into_iter()
        .filter(|&(start, len)| len > 0 && start <= 0xFFFF)
        .map(|(start, len)| (start, (start + len - 1).min(0xFFFF)))
        .collect();
    spans.sort_unstable();
    let mut merged: Vec<(u64, u64)> = Vec::new();
    for (start, end) in spans {
        match merged.last_mut() {
            Some(last) if start <= last.1 + 1 => last.1 = last.1.max(end),
            _ => merged.push((start, end)),
        }
    }
    merged
        .into_iter()
        .map(|(start, end)| start as u16..=end as u16)
        .collect()
}

/// The first run of `needed` free entries in a table of `capacity`
/// entries, given what is installed.
#[must_use]
pub fn free_slot(installed: &[Installed], needed: usize, capacity: usize) -> Option<usize> {
    let mut used = vec![false; capacity];
    for image in installed {
        for slot in image.slot..image.slot + image.entries() {
            if let Some(u) = used.get_mut(slot) {
                *u = true;
            }
        }
    }
    (0..=capacity.checked_sub(needed)?)
        .find(|&start| used[start..start + needed].iter().all(|u| !u))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Installed {
        Installed {
            id: 0x00AB_CDEF,
            extents: vec![0x1000..=0x10FF, 0x0400..=0x041F],
            hooks: vec![
                TakenHook {
                    kind: HookKind::Unknown,
                    handler: 0x1003,
                    chain: Some(0x1001),
                },
                TakenHook {
                    kind: HookKind::Loop,
                    handler: 0x1010,
                    chain: None,
                },
            ],
            slot: 1,
        }
    }

    /// `image` placed in an empty table as a loader leaves it.
    fn table_with(image: &Installed) -> Vec<u8> {
        let mut table = vec![0u8; TABLE_LEN];
        for (index, flags) in image.flags().into_iter().enumerate() {
            table[image.slot + index] = flags;
        }
        let start = ENTRIES + image.slot * ENTRY_LEN;
        let bytes = image.encode();
        table[start..start + bytes.len()].copy_from_slice(&bytes);
        table
    }

    #[test]
    fn entries_round_trip_at_their_slot() {
        let image = sample();
        let table = table_with(&image);
        assert_eq!(
            decode_table(TABLE, ENTRIES, &table).unwrap(),
            vec![image.clone()]
        );
        assert_eq!(free_slot(std::slice::from_ref(&image), 1, ENTRIES), Some(0));
        assert_eq!(free_slot(&[image], 2, ENTRIES), Some(3));
        assert_eq!(free_slot(&[], ENTRIES + 1, ENTRIES), None);
        assert_eq!(
            merge([(0x0400, 0x10), (0x0410, 4), (0x00F0, 6), (0x1000, 0)]),
            vec![0x00F0..=0x00F5, 0x0400..=0x0413]
        );
        assert_eq!(entry_address(TABLE, ENTRIES, 1), TABLE + 8 + 15);
    }

    #[test]
    fn damaged_tables_are_refused() {
        let mut table = vec![0u8; TABLE_LEN];
        table[ENTRIES + 5] = 1;
        assert_eq!(
            decode_table(TABLE, ENTRIES, &table).unwrap(),
            vec![],
            "stale bytes of a free entry"
        );
        // hostile25 F2: an entry in use zeroed by hand.
        let mut table = vec![0u8; TABLE_LEN];
        table[3] = 0x81;
        let error = decode_table(TABLE, ENTRIES, &table).unwrap_err();
        assert!(error.reason.contains("holds nothing"), "{error}");
        let mut table = table_with(&sample());
        table[ENTRIES + 2 * ENTRY_LEN] ^= 1;
        let error = decode_table(TABLE, ENTRIES, &table).unwrap_err();
        assert!(error.reason.contains("continues"), "{error}");
        let mut table = table_with(&sample());
        table[ENTRIES + ENTRY_LEN + 6] = 0x0F;
        let error = decode_table(TABLE, ENTRIES, &table).unwrap_err();
        assert!(error.reason.contains("ends before"), "{error}");
        // hostile10 F12: a chain slot (or a handler) pointed by hand out
        // of the image's memory: the ROM, the table, an I/O register.
        for slot in [0xFF00u16, 0x0F88, 0xC010, 0x10FF] {
            let mut image = sample();
            image.hooks[0].chain = Some(slot);
            let error = decode_table(TABLE, ENTRIES, &table_with(&image)).unwrap_err();
            assert!(error.reason.contains("outside its own memory"), "{error}");
        }
        let mut image = sample();
        image.hooks[1].handler = 0x2000;
        let error = decode_table(TABLE, ENTRIES, &table_with(&image)).unwrap_err();
        assert!(error.reason.contains("HOOK_LOOP"), "{error}");
        // hostile21 F14: one extension listed twice (a copy at slot 4).
        let image = sample();
        let mut table = table_with(&image);
        let again = Installed { slot: 4, ..image };
        let copy = table_with(&again);
        table[4..6].copy_from_slice(&copy[4..6]);
        let start = ENTRIES + 4 * ENTRY_LEN;
        table[start..start + 2 * ENTRY_LEN].copy_from_slice(&copy[start..start + 2 * ENTRY_LEN]);
        let error = decode_table(TABLE, ENTRIES, &table).unwrap_err();
        assert!(error.reason.contains("slot 1 claims too"), "{error}");
    }

    #[test]
    fn overlaps_are_inclusive() {
        let image = sample();
        let error = image.overlap(&[0x0300..=0x0400]).expect("meets $0400");
        assert!(
            matches!(&error, crate::Error::Overlap { new, old, id: 0x00AB_CDEF }
                if new == "$0300-$0400" && old == "$0400-$041F"),
            "{error}"
        );
        assert!(image.overlap(&[0x0420..=0x0FFF, 0x10FF..=0x1200]).is_some());
        assert!(image.overlap(&[0x0420..=0x0FFF, 0x1100..=0x1200]).is_none());
    }
}
