//! One source file per case, expected output beside it as an insta
//! snapshot (`snapshots/cases__<feature>__<name>.snap`):
//!
//! - `cases/<feature>/ok_*.s` must assemble; the snapshot holds the
//!   listing, the object read back with goblin (sections with their bytes,
//!   relocations, symbols, the source map) and any warnings;
//! - `cases/<feature>/err_*.s` must fail; the snapshot holds every
//!   diagnostic as miette renders it (file:line:col, the marked source line,
//!   backtraces).
//!
//! Sources are served from memory: every file of the case's directory is
//! loaded into a `MemorySource`, and `builtin.inc` is registered as a
//! built-in include, as the CLI registers `scorpion.inc`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use assembler::{MemorySource, Options};
use goblin::elf::Elf;
use isa::objfmt::{SRCMAP_SECTION, SrcMap};

const BUILTIN: &str = "; a built-in include, found with no path\nBUILTIN_VALUE = $42\n.macro builtin_macro\n        lda #BUILTIN_VALUE\n.endmacro\n";

use scorpion_tests::render;

/// A readable dump of an object, read back with goblin.
fn dump(object: &[u8]) -> String {
    let elf = Elf::parse(object).expect("goblin reads our object");
    let mut out = String::new();
    let _ = writeln!(
        out,
        "e_machine {} e_flags {:#x} type {}",
        elf.header.e_machine, elf.header.e_flags, elf.header.e_type
    );
    let name = |index: usize| -> String {
        elf.section_headers
            .get(index)
            .and_then(|sh| elf.shdr_strtab.get_at(sh.sh_name))
            .unwrap_or("?")
            .to_string()
    };
    for (index, sh) in elf.section_headers.iter().enumerate().skip(1) {
        let section = name(index);
        if section.starts_with(".symtab")
            || section.starts_with(".strtab")
            || section.starts_with(".shstrtab")
        {
            continue;
        }
        let _ = writeln!(
            out,
            "section [{index}] {section} type {} flags {:#x} size {} align {}",
            sh.sh_type, sh.sh_flags, sh.sh_size, sh.sh_addralign
        );
        if section.starts_with(".rela") || section.starts_with(".scorpion") {
            continue;
        }
        if sh.sh_type == goblin::elf::section_header::SHT_PROGBITS {
            let start = sh.sh_offset as usize;
            let bytes = &object[start..start + sh.sh_size as usize];
            for (row, chunk) in bytes.chunks(16).enumerate() {
                let hex: Vec<String> = chunk.iter().map(|b| format!("{b:02X}")).collect();
                let _ = writeln!(out, "  {:04X}: {}", row * 16, hex.join(" "));
            }
        }
    }
    for (section, relocs) in &elf.shdr_relocs {
        let target = elf.section_headers[*section].sh_info as usize;
        for reloc in relocs.iter() {
            let symbol = elf.syms.get(reloc.r_sym);
            let symbol_name = symbol
                .map(|s| {
                    if s.st_type() == goblin::elf::sym::STT_SECTION {
                        name(s.st_shndx)
                    } else {
                        elf.strtab.get_at(s.st_name).unwrap_or("?").to_string()
                    }
                })
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "reloc {}+{:04X} {} {} {:+}",
                name(target),
                reloc.r_offset,
                isa::elf::relocation_name(reloc.r_type).unwrap_or("?"),
                symbol_name,
                reloc.r_addend.unwrap_or(0)
            );
        }
    }
    for sym in elf.syms.iter().skip(1) {
        if sym.st_type() == goblin::elf::sym::STT_SECTION
            || sym.st_type() == goblin::elf::sym::STT_FILE
        {
            continue;
        }
        let section = match sym.st_shndx {
            0 => "UND".to_string(),
            0xFFF1 => "ABS".to_string(),
            index => name(index),
        };
        let bind = if sym.st_bind() == goblin::elf::sym::STB_GLOBAL {
            "global"
        } else {
            "local"
        };
        let zp = if sym.st_other & isa::elf::STO_MOS_ZEROPAGE != 0 {
            " zp"
        } else {
            ""
        };
        let _ = writeln!(
            out,
            "symbol {} = {:#06X} {section} {bind}{zp}",
            elf.strtab.get_at(sym.st_name).unwrap_or("?"),
            sym.st_value
        );
    }
    if let Some((index, sh)) = elf
        .section_headers
        .iter()
        .enumerate()
        .find(|(i, _)| name(*i) == SRCMAP_SECTION)
    {
        let _ = index;
        let start = sh.sh_offset as usize;
        let map = SrcMap::decode(&object[start..start + sh.sh_size as usize])
            .expect("the source map decodes");
        for entry in &map.entries {
            let _ = writeln!(
                out,
                "srcmap {}+{:04X} {}:{}:{}",
                name(entry.section as usize),
                entry.offset,
                map.file_name(entry.loc).unwrap_or("?"),
                entry.loc.line,
                entry.loc.column
            );
        }
        for symbol in &map.symbols {
            let sym = elf
                .syms
                .get(symbol.symbol as usize)
                .expect("a symbol index");
            let _ = write!(
                out,
                "srcmap symbol {} {}:{}:{}",
                elf.strtab.get_at(sym.st_name).unwrap_or("?"),
                map.file_name(symbol.loc).unwrap_or("?"),
                symbol.loc.line,
                symbol.loc.column
            );
            if let Some(call) = symbol.expanded_at {
                let _ = write!(
                    out,
                    " from the macro call at {}:{}:{}",
                    map.file_name(call).unwrap_or("?"),
                    call.line,
                    call.column
                );
            }
            out.push('\n');
        }
    }
    if let Some((_, sh)) = elf
        .section_headers
        .iter()
        .enumerate()
        .find(|(i, _)| name(*i) == isa::objfmt::ASSERT_SECTION)
    {
        let start = sh.sh_offset as usize;
        let asserts =
            isa::objfmt::Assertion::decode_all(&object[start..start + sh.sh_size as usize])
                .expect("the assertions decode");
        for assertion in asserts {
            let _ = writeln!(
                out,
                "assert {:?} {}:{}:{} {:?} {:?}",
                assertion.action,
                assertion.file,
                assertion.line,
                assertion.column,
                assertion.message,
                assertion.expr.ops
            );
        }
    }
    if let Some((_, sh)) = elf
        .section_headers
        .iter()
        .enumerate()
        .find(|(i, _)| name(*i) == isa::objfmt::EXPRS_SECTION)
    {
        let start = sh.sh_offset as usize;
        let fields =
            isa::objfmt::ExprField::decode_all(&object[start..start + sh.sh_size as usize])
                .expect("the fields decode");
        for field in fields {
            let _ = writeln!(
                out,
                "field {}+{:04X} {:?} {:?}",
                name(field.section as usize),
                field.offset,
                field.kind,
                field.expr.ops
            );
        }
    }
    if let Some((_, sh)) = elf
        .section_headers
        .iter()
        .enumerate()
        .find(|(i, _)| name(*i) == isa::objfmt::CONDES_SECTION)
    {
        let start = sh.sh_offset as usize;
        let entries =
            isa::objfmt::CondesEntry::decode_all(&object[start..start + sh.sh_size as usize])
                .expect("the table entries decode");
        for entry in entries {
            let _ = writeln!(
                out,
                "condes type {} priority {} symbol #{}",
                entry.kind, entry.priority, entry.symbol
            );
        }
    }
    if let Some((_, sh)) = elf
        .section_headers
        .iter()
        .enumerate()
        .find(|(i, _)| name(*i) == isa::objfmt::FILL_SECTION)
    {
        let start = sh.sh_offset as usize;
        let runs = isa::objfmt::FillRun::decode_all(&object[start..start + sh.sh_size as usize])
            .expect("the fill runs decode");
        for run in runs {
            let _ = writeln!(
                out,
                "fill {}+{:04X} {} bytes",
                name(run.section as usize),
                run.offset,
                run.length
            );
        }
    }
    out
}

fn source_for(path: &Path) -> (MemorySource, String) {
    let dir = path.parent().expect("a case directory");
    let mut source = MemorySource::new();
    for entry in std::fs::read_dir(dir).expect("the case directory is readable") {
        let file = entry.expect("a directory entry").path();
        if file.is_file() {
            let name = file
                .file_name()
                .expect("a file name")
                .to_string_lossy()
                .into_owned();
            source.insert(name, std::fs::read(&file).expect("a case file"));
        }
    }
    let name = path
        .file_name()
        .expect("a file name")
        .to_string_lossy()
        .into_owned();
    (source, name)
}

/// The options for the case at `path`: the cases in `zeropage/` are of
/// `Options::forward_zero_page` (zero page wherever the final value fits,
/// settled by the layout passes); the ld65 differential test assembles
/// them with the default, ca65's choice.
fn options(path: &Path) -> Options {
    let forward_zero_page = path
        .parent()
        .and_then(Path::file_name)
        .is_some_and(|dir| dir == "zeropage");
    Options {
        forward_zero_page,
        listing: true,
        builtin_includes: BTreeMap::from([(
            "builtin.inc".to_string(),
            BUILTIN.as_bytes().to_vec(),
        )]),
        ..Options::default()
    }
}

#[test]
fn cases() {
    insta::glob!("cases/**/*.s", |path| {
        let (source, name) = source_for(path);
        let result = assembler::assemble(&source, Path::new(&name), &options(path));
        let mut snapshot = String::new();
        if name.starts_with("ok_") {
            let assembly = match result {
                Ok(assembly) => assembly,
                Err(error) => panic!("{name} should assemble:\n{}", render(&error)),
            };
            snapshot.push_str(assembly.listing.as_deref().unwrap_or(""));
            snapshot.push_str("\n--- object\n");
            snapshot.push_str(&dump(&assembly.object));
            for message in &assembly.messages {
                let _ = writeln!(snapshot, "--- .out: {message}");
            }
            for warning in &assembly.warnings {
                snapshot.push_str("\n--- warning\n");
                snapshot.push_str(&render(warning));
            }
        } else if name.starts_with("err_") {
            let error = match result {
                Ok(_) => panic!("{name} should fail to assemble"),
                Err(error) => error,
            };
            assert!(
                !error.diagnostics().is_empty(),
                "{name}: an error with diagnostics"
            );
            for diagnostic in error.diagnostics() {
                let location = diagnostic
                    .location()
                    .map(ToString::to_string)
                    .unwrap_or_default();
                let _ = writeln!(snapshot, "--- {} {location}", diagnostic.code());
                snapshot.push_str(&render(diagnostic));
            }
        } else {
            return;
        }
        insta::with_settings!({ omit_expression => true, prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(snapshot);
        });
    });
}

/// A built-in include's text is listed by default; with
/// `list_builtin_includes` off the listing keeps the `.include` line and the
/// including file's own lines (a macro of the include expanded there too),
/// and an include of the user's own stays listed.
#[test]
fn a_builtin_include_can_be_left_out_of_the_listing() {
    let mut source = MemorySource::new();
    source.insert(
        "main.s".to_string(),
        b".include \"builtin.inc\"\n.include \"own.inc\"\n        builtin_macro\n        nop\n"
            .to_vec(),
    );
    source.insert("own.inc".to_string(), b"OWN_VALUE = 7\n".to_vec());
    let listing = |list_builtin_includes| {
        let options = Options {
            list_builtin_includes,
            ..options(Path::new("main.s"))
        };
        assembler::assemble(&source, Path::new("main.s"), &options)
            .expect("it assembles")
            .listing
            .expect("a listing")
    };
    let full = listing(true);
    assert!(full.contains("BUILTIN_VALUE = $42"), "{full}");
    let own = listing(false);
    assert!(!own.contains("BUILTIN_VALUE = $42"), "{own}");
    assert!(!own.contains("a built-in include"), "{own}");
    for kept in [
        ".include \"builtin.inc\"",
        "OWN_VALUE = 7",
        "builtin_macro",
        "lda #BUILTIN_VALUE",
        "nop",
    ] {
        assert!(own.contains(kept), "{kept} is listed:\n{own}");
    }
}
