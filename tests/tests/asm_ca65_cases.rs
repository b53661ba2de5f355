//! Small programs where ca65 + ld65 and our toolchain once disagreed (a
//! silent difference: both build, other bytes) or where we refused what
//! ca65 builds (issue 24). One case per directory in `asm_ca65_cases/`:
//! `main.s` (assembled; other files are what it includes), and beside it
//! in `main.s`'s own comments what ca65 2.19 + ld65 make of it:
//!
//! - `; bytes: 30 01 EA 60` the image, linked at $0800 with the flat
//!   configuration of `asm_differential.rs` (or `layout.cfg` of the case);
//! - `; system: apple2enh` assembled by both with `-t SYSTEM`;
//! - `; out: at 2003` a line `.out` prints;
//! - `; warns: asm::zp-forward` a warning we must give (with its place);
//! - `; cc65-include: yes` includes from cc65's `asminc`, found as ca65
//!   finds them without `-I` (`assembler::cc65_include_dirs`; needs
//!   cc65 installed, as the record check does).
//!
//! Our side needs no outside tool: the recorded bytes are the expectation.
//! With ca65 and ld65 installed (always under `CI=true`) the same bytes
//! and `.out` lines are checked against them, so the record cannot drift
//! from ca65's answer.

#[path = "ld65_diff/mod.rs"]
mod ld65_diff;

use std::path::{Path, PathBuf};
use std::process::Command;

use scorpion_tests::tools;

/// The flat layout at $0800 (as `asm_differential.rs`'s, fill value 0).
const FLAT_CFG: &str = "MEMORY {
    ZP:   start = $0000, size = $0100, type = rw;
    MAIN: start = $0800, size = $F800, file = %O;
}
SEGMENTS {
    ZEROPAGE: load = ZP,   type = zp;
    CODE:     load = MAIN, type = ro;
    RODATA:   load = MAIN, type = ro;
    DATA:     load = MAIN, type = rw;
    BSS:      load = MAIN, type = bss;
}
";

/// One case: its files and what ca65 + ld65 make of it.
struct Case {
    name: String,
    files: ld65_diff::Files,
    cfg: String,
    bytes: Vec<u8>,
    system: ld65_diff::System,
    out: Vec<String>,
    warns: Vec<String>,
    cc65_include: bool,
}

/// The values of the `; KEY: value` comment lines of `text`.
fn field<'t>(text: &'t str, key: &str) -> Vec<&'t str> {
    let prefix = format!("; {key}:");
    text.lines()
        .filter_map(|line| line.strip_prefix(prefix.as_str()))
        .map(str::trim)
        .collect()
}

fn cases() -> Vec<Case> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/asm_ca65_cases");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("the cases")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.is_dir())
        .collect();
    dirs.sort();
    dirs.iter()
        .map(|dir| {
            let name = dir
                .file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            let files = ld65_diff::files_of(dir);
            let main = files
                .iter()
                .find(|(file, _)| file == "main.s")
                .map(|(_, text)| String::from_utf8_lossy(text).into_owned())
                .unwrap_or_else(|| panic!("{name} has no main.s"));
            let cfg = files
                .iter()
                .find(|(file, _)| file == "layout.cfg")
                .map_or_else(
                    || FLAT_CFG.to_owned(),
                    |(_, text)| String::from_utf8_lossy(text).into_owned(),
                );
            let bytes = field(&main, "bytes")
                .iter()
                .flat_map(|line| line.split_whitespace())
                .map(|byte| {
                    u8::from_str_radix(byte, 16)
                        .unwrap_or_else(|_| panic!("{name}: `{byte}` in `; bytes:`"))
                })
                .collect();
            let system = field(&main, "system").first().map(|system| {
                assembler::systems::find(system)
                    .unwrap_or_else(|| panic!("{name}: no system `{system}`"))
            });
            let owned = |key| field(&main, key).into_iter().map(str::to_owned).collect();
            Case {
                cc65_include: !field(&main, "cc65-include").is_empty(),
                out: owned("out"),
                warns: owned("warns"),
                name,
                files,
                cfg,
                bytes,
                system,
            }
        })
        .collect()
}

/// What a toolchain made of a case: the image, the warnings and the
/// `.out` lines.
type Made = (Vec<u8>, Vec<String>, Vec<String>);

/// Our assembler and linker on the case.
fn ours(case: &Case) -> Result<Made, String> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, text) in &case.files {
        std::fs::write(dir.path().join(name), text).expect("write a case file");
    }
    let options = assembler::Options {
        system: case.system,
        system_include_dirs: if case.cc65_include {
            assembler::cc65_include_dirs()
        } else {
            Vec::new()
        },
        ..assembler::Options::default()
    };
    let main = dir.path().join("main.s");
    let assembly = assembler::assemble(&assembler::FsSource, &main, &options).map_err(|error| {
        let details: Vec<String> = error
            .diagnostics()
            .iter()
            .map(assembler::Diagnostic::summary)
            .collect();
        format!("we rejected it: {error}\n{}", details.join("\n"))
    })?;
    let layout = linker::Layout::from_ld65("layout.cfg", &case.cfg, None)
        .map_err(|error| format!("our reading of the configuration failed: {error:?}"))?;
    let target = linker::Target::Custom(layout);
    let inputs = [linker::Input {
        name: "main.s",
        bytes: &assembly.object,
    }];
    let linked = linker::link(
        &inputs,
        &linker::LinkOptions {
            target: &target,
            just_symbols: &[],
            sources: &linker::NoSources,
        },
    )
    .map_err(|error| format!("our link failed: {error:?}"))?;
    let image = linked
        .write(linker::Format::Bin)
        .map_err(|error| format!("cannot write the binary: {error:?}"))?;
    let warnings = assembly
        .warnings
        .iter()
        .map(|w| format!("{} {}", w.code(), w.summary()))
        .collect();
    Ok((image, warnings, assembly.messages))
}

/// Each case's image as ld65 writes it, and every `.out` line and warning
/// it names, from our assembler and linker.
#[test]
fn we_build_what_ca65_and_ld65_build() {
    let test = "we_build_what_ca65_and_ld65_build";
    let cases = cases();
    assert!(cases.len() >= 3, "only {} cases", cases.len());
    let mut failures = Vec::new();
    for case in &cases {
        if case.cc65_include && tools::require("ca65", test).is_none() {
            continue;
        }
        match ours(case) {
            Err(message) => failures.push(format!("{}: {message}", case.name)),
            Ok((image, warnings, messages)) => {
                if image != case.bytes {
                    failures.push(format!(
                        "{}: ca65 + ld65 {:02X?}\n  ours {image:02X?}",
                        case.name, case.bytes
                    ));
                }
                for code in &case.warns {
                    if !warnings.iter().any(|w| w.starts_with(&format!("{code} "))) {
                        failures.push(format!(
                            "{}: no `{code}` warning among {warnings:?}",
                            case.name
                        ));
                    }
                }
                if messages != case.out {
                    failures.push(format!(
                        "{}: `.out` printed {messages:?}, ca65 {:?}",
                        case.name, case.out
                    ));
                }
            }
        }
    }
    ld65_diff::report(failures, cases.len());
}

/// The recorded bytes and `.out` lines are ca65 + ld65's.
#[test]
fn the_records_are_ca65_and_ld65s() {
    let Some((ca65, ld65)) = ld65_diff::toolchain("the_records_are_ca65_and_ld65s") else {
        return;
    };
    let cases = cases();
    let mut failures = Vec::new();
    for case in &cases {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let mains = ["main.s".to_owned()];
        let tools = (ca65.as_path(), ld65.as_path());
        match ld65_diff::reference(
            dir.path(),
            &case.files,
            &mains,
            &case.cfg,
            tools,
            case.system,
        ) {
            Err(message) => failures.push(format!("{}: {message}", case.name)),
            Ok(outputs) => {
                let image = outputs
                    .iter()
                    .find(|(name, _)| name == ld65_diff::OUTPUT)
                    .map(|(_, bytes)| bytes.clone())
                    .unwrap_or_default();
                if image != case.bytes {
                    failures.push(format!(
                        "{}: recorded {:02X?}, ca65 + ld65 {image:02X?}",
                        case.name, case.bytes
                    ));
                }
            }
        }
        let printed = Command::new(&ca65)
            .current_dir(dir.path())
            .args(case.system.iter().flat_map(|s| ["-t", s.name]))
            .args(["main.s", "-o", "out.o"])
            .output()
            .expect("ca65 runs");
        let lines: Vec<String> = String::from_utf8_lossy(&printed.stdout)
            .lines()
            .map(str::to_owned)
            .collect();
        if lines != case.out {
            failures.push(format!(
                "{}: recorded `.out` {:?}, ca65 {lines:?}",
                case.name, case.out
            ));
        }
    }
    ld65_diff::report(failures, cases.len());
}
