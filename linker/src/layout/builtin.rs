//! The built-in targets. The Scorpion ones read their bounds from the ROM's
//! symbols; see the table in [`crate::layout`].

use std::collections::HashMap;

use super::{Area, Layout, Segment, SegmentKind};
use crate::error::Error;

/// Names `--target` accepts besides a `.toml` file.
pub const BUILTIN_TARGETS: [&str; 4] = ["flat", "scorpion-ext", "scorpion-os", "scorpion-rom"];

/// The board's KIM-bus space and ROM (`platform::map`).
const KIM_START: u64 = platform::map::KIM_START as u64;
const KIM_END: u64 = platform::map::KIM_END as u64;
const ROM_START: u64 = platform::map::ROM_START as u64;
const ROM_SIZE: u64 = platform::map::ROM_SIZE as u64;
const ROM_FILL: u8 = platform::map::ROM_FILL;
/// The ROM's own RAM starts after the stack page (ARCHITECTURE.md): the
/// `scorpion-rom` target's choice, which the ROM's hooks at `$0200` follow.
const ROM_RAM_START: u64 = 0x0200;
/// Where the ROM target puts the optional service jump table (the
/// reference ROM's `JUMPTABLE` segment), and the CPU's vectors.
const JUMPTABLE_START: u64 = 0xFF00;
const VECTORS_START: u64 = isa::vectors::NMI as u64;

/// Absolute symbols the Scorpion layouts read their bounds from: the ROM's
/// exports (from `--just-symbols`) or, when linking the ROM itself, its own.
#[derive(Debug, Clone, Default)]
pub struct RomSymbols {
    values: HashMap<String, i64>,
}

impl RomSymbols {
    /// Adds a symbol; the first definition of a name wins.
    pub fn insert(&mut self, name: &str, value: i64) {
        self.values.entry(name.to_owned()).or_insert(value);
    }

    /// A symbol's value.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<i64> {
        self.values.get(name).copied()
    }

    /// Every symbol and its value.
    pub fn iter(&self) -> impl Iterator<Item = (&str, i64)> {
        self.values
            .iter()
            .map(|(name, value)| (name.as_str(), *value))
    }

    fn require<const N: usize>(&self, target: &str, names: [&str; N]) -> Result<[u64; N], Error> {
        let missing: Vec<&str> = names
            .iter()
            .copied()
            .filter(|name| self.get(name).is_none())
            .collect();
        if !missing.is_empty() {
            let help = if target == "scorpion-rom" {
                "export them from the ROM's sources (`.exportzp USER_ZP_START`, `.export USER_RAM_START`): the ROM's own zero page and RAM end where the user's begin".to_owned()
            } else {
                "pass the ROM's linked ELF image with `--just-symbols ROM.elf`; the layout takes the user zero page and RAM bounds (USER_ZP_START/USER_ZP_END, USER_RAM_START/USER_RAM_END) from it".to_owned()
            };
            return Err(Error::MissingRomSymbols {
                target: target.to_owned(),
                missing: missing.join(", "),
                help,
            });
        }
        let mut values = [0u64; N];
        for (value, name) in values.iter_mut().zip(names) {
            let raw = self.get(name).unwrap_or_default();
            *value = u64::try_from(raw)
                .ok()
                .filter(|value| *value <= 0xFFFF)
                .ok_or_else(|| Error::LayoutInvalid {
                    path: target.to_owned(),
                    reason: format!("the ROM's {name} = {raw} is not an address"),
                })?;
        }
        Ok(values)
    }
}

/// A built-in segment: takes the ca65 segment of its name and the sections
/// llvm-mos's compiler and assembler name for the same purpose, so their
/// objects link with the built-in targets too.
fn segment(name: &str, load: &str, kind: SegmentKind) -> Segment {
    let mut segment = Segment::new(name, load, kind);
    let llvm_mos: &[&str] = match name {
        "CODE" => &[".text", ".text.*"],
        "RODATA" => &[".rodata", ".rodata.*"],
        "DATA" => &[".data", ".data.*"],
        "BSS" => &[".bss", ".bss.*", ".noinit", ".noinit.*"],
        "ZEROPAGE" => &[".zp", ".zp.*", ".zeropage", ".zeropage.*"],
        _ => &[],
    };
    segment
        .sections
        .extend(llvm_mos.iter().map(|pattern| (*pattern).to_owned()));
    segment
}

fn area(name: &str, start: u64, end_inclusive: u64, output: bool) -> Area {
    Area {
        name: name.to_owned(),
        start,
        size: end_inclusive + 1 - start,
        fill: false,
        fill_value: 0,
        output,
        define: false,
        file: None,
        exprs: None,
    }
}

fn inclusive(target: &str, what: &str, start: u64, end: u64) -> Result<(), Error> {
    if end < start {
        return Err(Error::LayoutInvalid {
            path: target.to_owned(),
            reason: format!("the ROM's {what} range ${start:04X}-${end:04X} is empty"),
        });
    }
    Ok(())
}

/// `flat`: see the module docs for the equivalent ld65 config.
pub(crate) fn flat(start: u64) -> Layout {
    Layout {
        name: "flat".into(),
        areas: vec![
            area("ZP", 0, 0xFF, false),
            area("MAIN", start, 0xFFFF, true),
        ],
        segments: vec![
            segment("ZEROPAGE", "ZP", SegmentKind::ZeroPage),
            segment("CODE", "MAIN", SegmentKind::ReadOnly),
            segment("RODATA", "MAIN", SegmentKind::ReadOnly),
            segment("DATA", "MAIN", SegmentKind::ReadWrite),
            segment("BSS", "MAIN", SegmentKind::Bss),
        ],
        ld65_alignment: true,
        config: super::Config::default(),
    }
}

/// The user's zero page and RAM as the ROM exports them (inclusive
/// bounds: `[zp_start, zp_end, ram_start, ram_end]`), checked to be
/// ranges: what the extension and OS layouts are built from.
fn user_space(rom: &RomSymbols, target: &str) -> Result<[u64; 4], Error> {
    let bounds = rom.require(
        target,
        [
            "USER_ZP_START",
            "USER_ZP_END",
            "USER_RAM_START",
            "USER_RAM_END",
        ],
    )?;
    let [zp_start, zp_end, ram_start, ram_end] = bounds;
    inclusive(target, "user zero page", zp_start, zp_end)?;
    inclusive(target, "user RAM", ram_start, ram_end)?;
    Ok(bounds)
}

/// `scorpion-ext`: everything in the user's zero page and RAM.
pub(crate) fn scorpion_ext(rom: &RomSymbols) -> Result<Layout, Error> {
    let target = "scorpion-ext";
    let [zp_start, zp_end, ram_start, ram_end] = user_space(rom, target)?;
    Ok(Layout {
        name: target.into(),
        areas: vec![
            area("ZP", zp_start, zp_end, false),
            area("RAM", ram_start, ram_end, true),
        ],
        segments: vec![
            segment("ZEROPAGE", "ZP", SegmentKind::ZeroPage),
            segment("CODE", "RAM", SegmentKind::ReadOnly),
            segment("RODATA", "RAM", SegmentKind::ReadOnly),
            segment("DATA", "RAM", SegmentKind::ReadWrite),
            segment("BSS", "RAM", SegmentKind::Bss),
        ],
        ld65_alignment: false,
        config: super::Config::default(),
    })
}

/// `scorpion-os`: code and data in KIM-bus RAM, BSS in user RAM.
pub(crate) fn scorpion_os(rom: &RomSymbols) -> Result<Layout, Error> {
    let target = "scorpion-os";
    let [zp_start, zp_end, ram_start, ram_end] = user_space(rom, target)?;
    Ok(Layout {
        name: target.into(),
        areas: vec![
            area("ZP", zp_start, zp_end, false),
            area("KIM", KIM_START, KIM_END, true),
            area("URAM", ram_start, ram_end, false),
        ],
        segments: vec![
            segment("ZEROPAGE", "ZP", SegmentKind::ZeroPage),
            segment("CODE", "KIM", SegmentKind::ReadOnly),
            segment("RODATA", "KIM", SegmentKind::ReadOnly),
            segment("DATA", "KIM", SegmentKind::ReadWrite),
            segment("BSS", "URAM", SegmentKind::Bss),
        ],
        ld65_alignment: false,
        config: super::Config::default(),
    })
}

/// `scorpion-rom`: the ROM image, its zero page and RAM below the user's.
pub(crate) fn scorpion_rom(rom: &RomSymbols) -> Result<Layout, Error> {
    let target = "scorpion-rom";
    let [zp_user, ram_user] = rom.require(target, ["USER_ZP_START", "USER_RAM_START"])?;
    if zp_user == 0 || ram_user <= ROM_RAM_START {
        return Err(Error::LayoutInvalid {
            path: target.into(),
            reason: format!(
                "USER_ZP_START = ${zp_user:02X} and USER_RAM_START = ${ram_user:04X} leave the ROM no zero page or RAM (its RAM starts at ${ROM_RAM_START:04X})"
            ),
        });
    }
    let mut rom_area = area("ROM", ROM_START, ROM_START + ROM_SIZE - 1, true);
    rom_area.fill = true;
    rom_area.fill_value = ROM_FILL;
    let mut data = segment("DATA", "ROM", SegmentKind::ReadWrite);
    data.run = Some("RAM".into());
    data.define = true;
    let mut jumptable = segment("JUMPTABLE", "ROM", SegmentKind::ReadOnly);
    jumptable.start = Some(JUMPTABLE_START);
    let mut vectors = segment("VECTORS", "ROM", SegmentKind::ReadOnly);
    vectors.start = Some(VECTORS_START);
    vectors.optional = false;
    Ok(Layout {
        name: target.into(),
        areas: vec![
            area("ZP", 0, zp_user - 1, false),
            area("RAM", ROM_RAM_START, ram_user - 1, false),
            rom_area,
        ],
        segments: vec![
            segment("ZEROPAGE", "ZP", SegmentKind::ZeroPage),
            segment("CODE", "ROM", SegmentKind::ReadOnly),
            segment("RODATA", "ROM", SegmentKind::ReadOnly),
            data,
            segment("BSS", "RAM", SegmentKind::Bss),
            jumptable,
            vectors,
        ],
        ld65_alignment: false,
        config: super::Config::default(),
    })
}
