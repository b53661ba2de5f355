//! `scorpion disasm`: disassemble a linked image, an object or a raw binary.
//!
//! An ELF file is read as what it is: a linked image (`scorpion build`'s
//! default output) by its placed segments at their run addresses, with its
//! symbols (and the built-in ROM's, for ROM and hook addresses) as labels;
//! an object by its sections from offset 0, with its symbols as labels and
//! each relocation beside the instruction it patches. Anything else is raw
//! bytes at `--base`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use goblin::elf::Elf;
use miette::{Context, IntoDiagnostic};

use crate::args;

/// Disassemble a linked image, an ELF object or a raw binary.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "An ELF image or object is recognised by its header: code is \
disassembled at its addresses with the symbols as labels, data shown as .byte rows. \
Any other file is raw bytes at --base."
)]
pub(crate) struct Args {
    /// The file: an image or object from `scorpion build`/`asm`, or raw bytes.
    file: PathBuf,
    /// Address of a raw file's first byte (default $0000; not for ELF files).
    #[arg(long, value_parser = args::address)]
    base: Option<u16>,
    /// Address to start disassembling at (default: the first byte).
    #[arg(long, value_parser = args::address)]
    start: Option<u16>,
    /// Number of bytes to disassemble (default: to the end).
    #[arg(long, value_parser = args::length)]
    length: Option<u32>,
}

/// One stretch of bytes to show, with its labels and notes by address.
struct Block {
    title: String,
    address: u16,
    bytes: Vec<u8>,
    code: bool,
    labels: BTreeMap<u16, Vec<String>>,
    /// Relocations of an object: offset -> text.
    notes: BTreeMap<u16, String>,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let bytes = hostfs::read(&args.file, hostfs::BINARY)
        .wrap_err_with(|| format!("cannot read {}", args.file.display()))?;
    let name = args.file.display().to_string();
    let is_elf = bytes.starts_with(b"\x7fELF");
    let (header, blocks, operand_labels) = if is_elf {
        if args.base.is_some() {
            miette::bail!(
                "{name} is an ELF file: its addresses come from the file, so --base does not apply"
            );
        }
        elf_blocks(&name, &bytes)?
    } else {
        let base = args.base.unwrap_or(0);
        let block = Block {
            title: String::new(),
            address: base,
            bytes,
            code: true,
            labels: BTreeMap::new(),
            notes: BTreeMap::new(),
        };
        (None, vec![block], BTreeMap::new())
    };
    let window = window(args, &name, &blocks)?;
    let mut out = String::new();
    if let Some(header) = header {
        let _ = writeln!(out, "; {header}");
    }
    let label = |address: u16| operand_labels.get(&address).map(String::as_str);
    for block in &blocks {
        let lines = render(block, window, &label);
        if lines.is_empty() {
            continue;
        }
        if !block.title.is_empty() {
            let _ = writeln!(out, "; {}", block.title);
        }
        out.push_str(&lines);
    }
    std::io::stdout()
        .lock()
        .write_all(out.as_bytes())
        .into_diagnostic()?;
    Ok(ExitCode::SUCCESS)
}

/// The address range `--start`/`--length` ask for, checked against the
/// file's addresses.
fn window(args: &Args, name: &str, blocks: &[Block]) -> miette::Result<(u32, u32)> {
    let first = blocks
        .iter()
        .map(|b| u32::from(b.address))
        .min()
        .unwrap_or(0);
    let start = args.start.map_or(first, u32::from);
    let inside = blocks.iter().any(|b| {
        let from = u32::from(b.address);
        start >= from && start <= from + b.bytes.len() as u32
    });
    if !inside {
        let extents: Vec<String> = blocks
            .iter()
            .map(|b| {
                let end = u32::from(b.address) + (b.bytes.len() as u32).saturating_sub(1);
                format!("${:04X}-${end:04X}", b.address)
            })
            .collect();
        miette::bail!(
            "--start ${start:04X} is outside {name} ({})",
            extents.join(", ")
        );
    }
    let end = args
        .length
        .map_or(u32::MAX, |length| start.saturating_add(length));
    Ok((start, end))
}

fn render<'a>(
    block: &Block,
    (start, end): (u32, u32),
    label: &dyn Fn(u16) -> Option<&'a str>,
) -> String {
    let mut out = String::new();
    let address = u32::from(block.address);
    let from = start.saturating_sub(address) as usize;
    let Some(bytes) = block.bytes.get(from.min(block.bytes.len())..) else {
        return out;
    };
    let first = block.address.wrapping_add(from as u16);
    let take = end.saturating_sub(u32::from(first)).min(bytes.len() as u32) as usize;
    let bytes = &bytes[..take];
    let emit_labels = |out: &mut String, at: u16| {
        for name in block.labels.get(&at).into_iter().flatten() {
            let _ = writeln!(out, "{name}:");
        }
    };
    if block.code {
        for line in isa::Disassembler::new(bytes, first) {
            emit_labels(&mut out, line.address);
            // The closure shortens the labels' lifetime to the line's.
            #[allow(clippy::redundant_closure, reason = "a lifetime coercion")]
            let shown = line.display_with(|address| label(address));
            let _ = write!(out, "{shown}");
            let covered = line.address..line.address.wrapping_add(line.bytes.len() as u16);
            let notes: Vec<&str> = block
                .notes
                .range(covered)
                .map(|(_, note)| note.as_str())
                .collect();
            if !notes.is_empty() {
                let _ = write!(out, "  ; {}", notes.join(", "));
            }
            out.push('\n');
        }
    } else {
        // Data: eight bytes a row, a new row at each label.
        let mut row: Vec<String> = Vec::new();
        let mut row_start = first;
        for (index, byte) in bytes.iter().enumerate() {
            let at = first.wrapping_add(index as u16);
            if block.labels.contains_key(&at) || row.len() == 8 {
                flush_row(&mut out, row_start, &mut row);
                emit_labels(&mut out, at);
                row_start = at;
            }
            row.push(format!("${byte:02X}"));
        }
        flush_row(&mut out, row_start, &mut row);
    }
    out
}

fn flush_row(out: &mut String, address: u16, row: &mut Vec<String>) {
    if !row.is_empty() {
        let _ = writeln!(out, "{address:04X}  .byte {}", row.join(","));
        row.clear();
    }
}

type Parsed = (Option<String>, Vec<Block>, BTreeMap<u16, String>);

fn elf_blocks(name: &str, bytes: &[u8]) -> miette::Result<Parsed> {
    let elf = Elf::parse(bytes)
        .map_err(|error| miette::miette!("{name} is not a readable ELF file: {error}"))?;
    if elf.header.e_type == goblin::elf::header::ET_REL {
        return Ok(object_blocks(name, bytes, &elf));
    }
    let image = linker::Image::parse(name, bytes)?;
    let mut labels: BTreeMap<u16, Vec<String>> = BTreeMap::new();
    let mut operand_labels: BTreeMap<u16, String> = BTreeMap::new();
    // Globals first, so an operand is named by the exported name.
    let mut symbols: Vec<&linker::ImageSymbol> = image
        .symbols
        .iter()
        .filter(|s| s.section.is_some())
        .collect();
    symbols.sort_by_key(|s| (!s.global, s.value, s.name.clone()));
    for symbol in symbols {
        let Ok(address) = u16::try_from(symbol.value) else {
            continue;
        };
        labels.entry(address).or_default().push(symbol.name.clone());
        operand_labels
            .entry(address)
            .or_insert_with(|| symbol.name.clone());
    }
    // The built-in ROM's names for its own addresses and its RAM (the
    // hooks, the command buffer): never for the user's RAM or zero page.
    for rom in romlib::symbols::ALL {
        let owned = (0x0200..0x0400).contains(&rom.value) || rom.value >= platform::map::ROM_START;
        if owned {
            operand_labels
                .entry(rom.value)
                .or_insert_with(|| rom.name.to_string());
        }
    }
    let mut blocks = Vec::new();
    for section in &image.sections {
        let Ok(address) = u16::try_from(section.run) else {
            continue;
        };
        let contents: Option<Vec<u8>> = (0..section.size)
            .map(|offset| image.run_byte(section.run + offset))
            .collect();
        let Some(contents) = contents.filter(|c| !c.is_empty()) else {
            continue;
        };
        let end = u32::from(address) + section.size - 1;
        let last = u16::try_from(end).unwrap_or(u16::MAX);
        blocks.push(Block {
            title: format!("{} ${address:04X}-${end:04X}", section.name),
            address,
            bytes: contents,
            code: section.exec,
            // The labels inside the section.
            labels: labels
                .range(address..=last)
                .map(|(at, names)| (*at, names.clone()))
                .collect(),
            notes: BTreeMap::new(),
        });
    }
    let header = format!("{name}: linked image, entry ${:04X}", image.entry);
    Ok((Some(header), blocks, operand_labels))
}

/// An object's sections from offset 0, its relocations beside them.
fn object_blocks(name: &str, bytes: &[u8], elf: &Elf<'_>) -> Parsed {
    use goblin::elf::section_header::{SHF_ALLOC, SHF_EXECINSTR, SHT_PROGBITS};
    let section_name = |index: usize| {
        elf.section_headers
            .get(index)
            .and_then(|sh| elf.shdr_strtab.get_at(sh.sh_name))
            .unwrap_or("?")
    };
    let symbol_name = |index: usize| {
        elf.syms.get(index).map_or_else(String::new, |sym| {
            if sym.st_type() == goblin::elf::sym::STT_SECTION {
                section_name(sym.st_shndx).to_string()
            } else {
                elf.strtab.get_at(sym.st_name).unwrap_or("?").to_string()
            }
        })
    };
    let mut blocks = Vec::new();
    for (index, sh) in elf.section_headers.iter().enumerate() {
        if sh.sh_type != SHT_PROGBITS || sh.sh_flags & u64::from(SHF_ALLOC) == 0 {
            continue;
        }
        let range = sh.file_range().unwrap_or(0..0);
        let Some(contents) = bytes.get(range).filter(|c| !c.is_empty()) else {
            continue;
        };
        let mut labels: BTreeMap<u16, Vec<String>> = BTreeMap::new();
        for sym in elf.syms.iter() {
            let kind = sym.st_type();
            if sym.st_shndx == index
                && kind != goblin::elf::sym::STT_SECTION
                && kind != goblin::elf::sym::STT_FILE
                && let Ok(offset) = u16::try_from(sym.st_value)
            {
                let text = elf.strtab.get_at(sym.st_name).unwrap_or("?").to_string();
                labels.entry(offset).or_default().push(text);
            }
        }
        let mut notes = BTreeMap::new();
        for (target, relocs) in &elf.shdr_relocs {
            if elf.section_headers[*target].sh_info as usize != index {
                continue;
            }
            for reloc in relocs.iter() {
                let Ok(offset) = u16::try_from(reloc.r_offset) else {
                    continue;
                };
                let kind = isa::elf::relocation_name(reloc.r_type).unwrap_or("R_MOS_?");
                let addend = reloc.r_addend.unwrap_or(0);
                let symbol = symbol_name(reloc.r_sym);
                let text = match addend {
                    0 => format!("{kind} {symbol}"),
                    _ => format!("{kind} {symbol}{addend:+}"),
                };
                notes.insert(offset, text);
            }
        }
        let code = sh.sh_flags & u64::from(SHF_EXECINSTR) != 0;
        blocks.push(Block {
            title: format!(
                "section {} ({} bytes, offsets from 0)",
                section_name(index),
                contents.len()
            ),
            address: 0,
            bytes: contents.to_vec(),
            code,
            labels,
            notes,
        });
    }
    let header = format!("{name}: relocatable object; operands patched by a relocation are marked");
    (Some(header), blocks, BTreeMap::new())
}
