//! Builds the reference ROM from `rom/` with our own assembler and linker
//! (target `scorpion-rom`), and generates from the one linked image:
//! - `scorpion-rom.elf` and `scorpion-rom.bin`, embedded by `romlib`;
//! - `symbols.rs`: every exported ABI name as a Rust constant;
//! - `scorpion.inc`: the same names for assembler sources, plus the hook
//!   macros of `rom/hooks.inc`;
//! - `hardware.inc`, which the ROM's sources include: the I/O page's names,
//!   written from the `platform` crate.
//!
//! Each exported name's description is the comment on the source line that
//! defines it, so the ROM source is the one place it is written; a name
//! without one fails the build.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Layout symbols (`__DATA_LOAD__`) and hook declarations are not ABI.
fn is_abi_name(name: &str) -> bool {
    !name.starts_with("__")
}

/// Whether an exported name is a size (`RXBUF_SIZE`) rather than an
/// address.
fn is_size(name: &str) -> bool {
    name.ends_with("_SIZE")
}

/// The text after `;` on the line that defines `name`, without a leading
/// `$FFxx` address (the jump table repeats its addresses in comments).
fn descriptions(rom_dir: &Path) -> BTreeMap<String, String> {
    let mut found = BTreeMap::new();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(rom_dir)
        .expect("the rom directory is readable")
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .filter(|path| {
            path.extension()
                .is_some_and(|ext| ext == "s" || ext == "inc")
        })
        .collect();
    entries.sort();
    for path in entries {
        let text = std::fs::read_to_string(&path).expect("ROM sources are UTF-8 text");
        for line in text.lines() {
            let Some((code, comment)) = line.split_once(';') else {
                continue;
            };
            let name: String = code
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let rest = code[name.len()..].trim_start();
            if name.is_empty() || !(rest.starts_with('=') || rest.starts_with(':')) {
                continue;
            }
            let mut comment = comment.trim();
            if let Some(after) = comment.strip_prefix('$') {
                if after.len() > 4 && after[..4].chars().all(|c| c.is_ascii_hexdigit()) {
                    comment = after[4..].trim_start();
                }
            }
            found.entry(name).or_insert_with(|| comment.to_owned());
        }
    }
    found
}

/// FNV-1a, to name the ROM build in `scorpion.inc`.
fn fnv1a(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811C_9DC5_u32, |hash, &byte| {
        (hash ^ u32::from(byte)).wrapping_mul(0x0100_0193)
    })
}

fn hex(value: u32) -> String {
    if value < 0x100 {
        format!("${value:02X}")
    } else {
        format!("${value:04X}")
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets it"));
    let rom_dir = manifest.join("rom");
    #[allow(clippy::print_stdout, reason = "build-script directives go to stdout")]
    {
        println!("cargo:rerun-if-changed=rom");
    }

    // The I/O page's names come from the platform crate, as the emulator's
    // wiring does; the sources include the generated file.
    std::fs::write(out.join("hardware.inc"), platform::hardware_inc())
        .expect("OUT_DIR is writable");
    let main_file = rom_dir.join("scorpion.s");
    let options = assembler::Options {
        include_dirs: vec![out.clone()],
        ..assembler::Options::default()
    };
    let assembly = match assembler::assemble(&assembler::FsSource, &main_file, &options) {
        Ok(assembly) => assembly,
        Err(error) => {
            let details: Vec<String> = error
                .diagnostics()
                .iter()
                .map(|diagnostic| format!("{diagnostic:?}"))
                .collect();
            panic!("the ROM does not assemble: {error}\n{}", details.join("\n"));
        }
    };
    let target = linker::Target::builtin("scorpion-rom", None).expect("a built-in target");
    let linked = linker::link(
        &[linker::Input {
            name: "scorpion.s",
            bytes: &assembly.object,
        }],
        &linker::LinkOptions {
            target: &target,
            just_symbols: &[],
            sources: &linker::NoSources,
        },
    )
    .unwrap_or_else(|error| panic!("the ROM does not link: {error:?}"));
    let elf = linker::Format::Elf
        .write(&linked.image)
        .unwrap_or_else(|error| panic!("cannot write the ROM's ELF: {error:?}"));
    let bin = linker::Format::Bin
        .write(&linked.image)
        .unwrap_or_else(|error| panic!("cannot write the ROM image: {error:?}"));
    assert_eq!(bin.len(), 0x1000, "the ROM image must fill $F000-$FFFF");

    let docs = descriptions(&rom_dir);
    let mut symbols: Vec<(&str, u32, &str)> = Vec::new();
    for symbol in linked.image.symbols.iter().filter(|s| s.global) {
        if !is_abi_name(&symbol.name) {
            continue;
        }
        let doc = docs.get(&symbol.name).unwrap_or_else(|| {
            panic!(
                "the ROM exports {} but no source line defining it has a comment to document it",
                symbol.name
            )
        });
        symbols.push((&symbol.name, symbol.value, doc));
    }
    symbols.sort_by(|a, b| a.0.cmp(b.0));

    let mut rust =
        String::from("// Generated by romlib's build.rs from the linked ROM. Do not edit.\n\n");
    for (name, value, doc) in &symbols {
        writeln!(rust, "/// `{name}` = `{}`: {doc}", hex(*value)).expect("writing to a String");
        writeln!(rust, "pub const {name}: u16 = 0x{value:04X};").expect("writing to a String");
    }
    rust.push_str(
        "\n/// Every name the ROM exports, sorted by name.\npub const ALL: &[Symbol] = &[\n",
    );
    for (name, value, doc) in &symbols {
        writeln!(
            rust,
            "    Symbol {{ name: \"{name}\", value: 0x{value:04X}, doc: {doc:?} }},"
        )
        .expect("writing to a String");
    }
    rust.push_str("];\n");

    let mut inc = format!(
        "; scorpion.inc: the Scorpion reference ROM's exported names, for\n\
         ; extensions and operating systems (`.include \"scorpion.inc\"`).\n\
         ;\n\
         ; Generated by romlib from the linked ROM (image FNV-1a {:08X}).\n\
         ; Do not edit: change the ROM source instead.\n",
        fnv1a(&bin)
    );
    // Sizes (`RXBUF_SIZE`) are no addresses: they get a group of their own.
    type Member = fn(&str, u32) -> bool;
    let groups: [(&str, Member); 4] = [
        ("zero page and RAM the ROM owns or leaves free", |n, v| {
            v < 0x1000 && !is_size(n)
        }),
        ("services (the jump table at fixed addresses)", |n, v| {
            v >= 0xF000 && !is_size(n)
        }),
        ("other", |n, v| (0x1000..0xF000).contains(&v) && !is_size(n)),
        ("sizes", |n, _| is_size(n)),
    ];
    for (title, member) in groups {
        let names: Vec<_> = symbols.iter().filter(|s| member(s.0, s.1)).collect();
        if names.is_empty() {
            continue;
        }
        write!(inc, "\n; ---- {title} ----\n").expect("writing to a String");
        let mut by_value = names.clone();
        by_value.sort_by_key(|s| (s.1, s.0));
        for (name, value, doc) in by_value {
            writeln!(inc, "{name:<15} = {:<6} ; {doc}", hex(*value)).expect("writing to a String");
        }
    }
    inc.push('\n');
    inc.push_str(
        &std::fs::read_to_string(rom_dir.join("hooks.inc")).expect("rom/hooks.inc is readable"),
    );

    std::fs::write(out.join("scorpion-rom.elf"), &elf).expect("OUT_DIR is writable");
    std::fs::write(out.join("scorpion-rom.bin"), &bin).expect("OUT_DIR is writable");
    std::fs::write(out.join("symbols.rs"), rust).expect("OUT_DIR is writable");
    std::fs::write(out.join("scorpion.inc"), inc).expect("OUT_DIR is writable");
}
