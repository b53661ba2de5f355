//! Properties of random programs: every section's bytes land at its
//! address, every relocation holds its target, nothing overlaps, alignment
//! holds, and the ELF image reads back unchanged.

use isa::elf::R_MOS_ADDR16;
use isa::objfmt::{ObjectBuilder, SymbolDef};
use linker::{Format, Image, MemorySources, SymbolFile, Target};
use proptest::prelude::*;

use crate::support::{fake_rom, link_with};

const SEGMENTS: [&str; 5] = ["CODE", "RODATA", "DATA", "BSS", "ZEROPAGE"];

#[derive(Debug, Clone)]
struct Section {
    segment: usize,
    bytes: Vec<u8>,
    align: u64,
    /// Offsets of 16-bit relocations and the label (object, section) each targets.
    relocs: Vec<(u32, prop::sample::Index)>,
}

fn section() -> impl Strategy<Value = Section> {
    (0..SEGMENTS.len(), 0..5u32).prop_flat_map(|(segment, align_log)| {
        let max = if SEGMENTS[segment] == "ZEROPAGE" {
            12
        } else {
            120
        };
        (
            proptest::collection::vec(any::<u8>(), 0..max),
            proptest::collection::vec((any::<u32>(), any::<prop::sample::Index>()), 0..6),
        )
            .prop_map(move |(bytes, relocs)| Section {
                segment,
                bytes,
                align: 1 << align_log,
                relocs,
            })
    })
}

fn program() -> impl Strategy<Value = Vec<Vec<Section>>> {
    proptest::collection::vec(proptest::collection::vec(section(), 0..4), 1..4)
}

/// A label at the start of every section: `o{object}s{section}`.
fn label(object: usize, section: usize) -> String {
    format!("o{object}s{section}")
}

fn has_bytes(section: &Section) -> bool {
    SEGMENTS[section.segment] != "BSS" && SEGMENTS[section.segment] != "ZEROPAGE"
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_programs_link_consistently(program in program()) {
        let labels: Vec<(usize, usize)> = program
            .iter()
            .enumerate()
            .flat_map(|(o, sections)| (0..sections.len()).map(move |s| (o, s)))
            .collect();
        let mut objects = Vec::new();
        for (o, sections) in program.iter().enumerate() {
            let mut obj = ObjectBuilder::new();
            let mut ids = Vec::new();
            for (s, section) in sections.iter().enumerate() {
                let name = SEGMENTS[section.segment];
                let id = match name {
                    "BSS" => obj.bss(name, section.bytes.len() as u32),
                    "ZEROPAGE" => obj.zeropage(name, section.bytes.len() as u32),
                    _ => obj.data(name, &section.bytes),
                };
                obj.align(id, section.align);
                obj.global(&label(o, s), SymbolDef::Section(id, 0));
                ids.push(id);
            }
            for (s, section) in sections.iter().enumerate() {
                if !has_bytes(section) || section.bytes.len() < 2 {
                    continue;
                }
                for (at, target) in &section.relocs {
                    let (to, ts) = labels[target.index(labels.len())];
                    let symbol = obj.import(&label(to, ts), false);
                    let offset = at % (section.bytes.len() as u32 - 1);
                    obj.reloc(ids[s], offset, R_MOS_ADDR16, symbol, 0);
                }
            }
            objects.push((format!("p{o}.o"), obj.build()));
        }
        let named: Vec<(&str, Vec<u8>)> =
            objects.iter().map(|(n, b)| (n.as_str(), b.clone())).collect();
        let rom = fake_rom(&[]);
        let files = [SymbolFile { name: "rom.elf", image: &rom }];
        let linked = match link_with(&named, &Target::ScorpionExt, &files, &MemorySources::default()) {
            Ok(linked) => linked,
            Err(linker::Error::Failed { errors, .. }) => {
                // Only a too-big random program may fail, and it says so.
                for error in &errors {
                    prop_assert!(
                        matches!(error, linker::Error::Overflow { .. } | linker::Error::ZeroPagePlacement { .. }),
                        "{error:?}"
                    );
                }
                return Ok(());
            }
            Err(other) => return Err(TestCaseError::fail(format!("{other:?}"))),
        };
        let image = &linked.image;

        // Section addresses, from their labels.
        let mut placed = Vec::new();
        for (o, sections) in program.iter().enumerate() {
            for (s, section) in sections.iter().enumerate() {
                let start = image.symbol(&label(o, s)).expect("every label is in the image");
                prop_assert_eq!(u64::from(start) % section.align, 0, "alignment of {}", label(o, s));
                placed.push((start, section));
            }
        }
        // Nothing overlaps.
        let mut ranges: Vec<(u32, u32)> = placed
            .iter()
            .filter(|(_, section)| !section.bytes.is_empty())
            .map(|(start, section)| (*start, start + section.bytes.len() as u32))
            .collect();
        ranges.sort_unstable();
        for pair in ranges.windows(2) {
            prop_assert!(pair[0].1 <= pair[1].0, "overlap: {:?}", pair);
        }
        // Bytes land where their labels say, relocated words hold their targets.
        for (o, sections) in program.iter().enumerate() {
            for (s, section) in sections.iter().enumerate() {
                let start = image.symbol(&label(o, s)).expect("label");
                if !has_bytes(section) {
                    prop_assert!(start < 0x100 || SEGMENTS[section.segment] == "BSS");
                    continue;
                }
                let mut patched = vec![false; section.bytes.len()];
                if section.bytes.len() >= 2 {
                        for (at, _) in &section.relocs {
                        let offset = (at % (section.bytes.len() as u32 - 1)) as usize;
                        patched[offset] = true;
                        patched[offset + 1] = true;
                    }
                }
                for (i, byte) in section.bytes.iter().enumerate() {
                    if !patched[i] {
                        prop_assert_eq!(image.byte_at(start + i as u32), Some(*byte));
                    }
                }
                // The last relocation written at an offset wins; check those.
                let mut last = std::collections::BTreeMap::new();
                if section.bytes.len() >= 2 {
                    for (at, target) in &section.relocs {
                        let offset = at % (section.bytes.len() as u32 - 1);
                        last.insert(offset, labels[target.index(labels.len())]);
                    }
                }
                for (offset, (to, ts)) in last {
                    let overwritten = last_overlaps(section, offset);
                    if overwritten {
                        continue;
                    }
                    let value = image.symbol(&label(to, ts)).expect("target");
                    let lo = image.byte_at(start + offset).expect("loaded");
                    let hi = image.byte_at(start + offset + 1).expect("loaded");
                    prop_assert_eq!(u16::from_le_bytes([lo, hi]), value as u16);
                }
            }
        }
        // The ELF image reads back unchanged.
        let read = Image::parse("p.elf", &Format::Elf.write(image).expect("writes")).expect("reads");
        prop_assert_eq!(&read, image);
    }
}

/// Whether another relocation at `offset ± 1` also writes one of this
/// relocation's bytes (then the order of application decides).
fn last_overlaps(section: &Section, offset: u32) -> bool {
    let len = section.bytes.len() as u32 - 1;
    section
        .relocs
        .iter()
        .map(|(at, _)| at % len)
        .any(|other| other + 1 == offset || offset + 1 == other)
}
