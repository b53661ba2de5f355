//! The ld65 differential test: the same sources assembled and linked by
//! ca65 + ld65 (Debian's cc65) and by our assembler + linker with the
//! `flat` target (what `scorpion build --target flat --start ADDR --format
//! bin` runs, objects in memory) must give the same binary, byte for byte.
//!
//! Inputs: every case the assembler's own tests assemble
//! (`assembler/tests/cases/*/ok_*.s`, the one hand-written corpus; the
//! cases ca65 + ld65 build otherwise are listed in [`KNOWN_DIFFERENCES`]
//! with the reason) and seeded
//! random programs from `asm_gen` covering every documented opcode and
//! addressing mode, labels, cheap locals, unnamed labels, macros,
//! expressions and data directives. A failure names the seed (or file) and
//! the first differing address, and keeps the sources in a temporary
//! directory for `ca65 -l`.

#[path = "asm_gen/mod.rs"]
mod asm_gen;
#[path = "ld65_diff/mod.rs"]
mod ld65_diff;

use std::path::Path;
use std::process::Command;

use ld65_diff::{files_of, report, toolchain};
use scorpion_tests::tools;

/// Both toolchains on one program linked for the flat layout at [`START`]
/// with the main area's fill value `fill`.
fn compare(
    what: &str,
    files: &[(String, Vec<u8>)],
    mains: &[String],
    tools: (&Path, &Path),
    fill: u8,
) -> Result<(), String> {
    ld65_diff::compare(what, files, mains, &ld65_config(START, fill), tools, None)
}

/// Where the flat image starts.
const START: u16 = 0x0800;

/// The ld65 config equivalent to our `flat` target, with `fill` as the
/// main area's `fillval` (what `.res` and `.align` without a value get).
fn ld65_config(start: u16, fill: u8) -> String {
    format!(
        "MEMORY {{
    ZP:   start = $0000, size = $0100, type = rw;
    MAIN: start = ${start:04X}, size = ${:04X}, file = %O, fillval = ${fill:02X};
}}
SEGMENTS {{
    ZEROPAGE: load = ZP,   type = zp;
    CODE:     load = MAIN, type = ro;
    RODATA:   load = MAIN, type = ro;
    DATA:     load = MAIN, type = rw;
    BSS:      load = MAIN, type = bss;
}}
",
        0x1_0000 - u32::from(start)
    )
}

/// A generated program's files, every one of them assembled.
fn generated(program: &[(String, String)]) -> (Vec<(String, Vec<u8>)>, Vec<String>) {
    let files = program
        .iter()
        .map(|(name, text)| (name.clone(), text.clone().into_bytes()))
        .collect();
    let mains = program.iter().map(|(name, _)| name.clone()).collect();
    (files, mains)
}

/// Cases where ca65 + ld65 do not build the same bytes, and why. Each must
/// still differ: a case that comes to match fails the test until it is
/// taken off this list.
const KNOWN_DIFFERENCES: [(&str, &str); 7] = [
    (
        "include/ok_include.s",
        "includes `builtin.inc`, a built-in include only our assembler has",
    ),
    (
        "instructions/ok_undocumented_names.s",
        "`lxa` and `sbx`, the NMOS manuals' names, which ca65 2.19 does not know",
    ),
    (
        "linkage/ok_forceimport.s",
        "imports a symbol no other object defines (asm_multi/forceimport links it)",
    ),
    (
        "relocations/ok_relocations.s",
        "relocations ca65 refuses as range errors at assembly time",
    ),
    (
        "segments/ok_segments.s",
        "custom segments that the flat ld65 config has no area for",
    ),
    (
        "warnings/ok_warnings.s",
        "ld65 fails on the `.assert` warnings this case exists to raise",
    ),
    (
        "zeropage/ok_forward.s",
        "imports a symbol no other object defines",
    ),
];

/// A case's directory: every file's name and bytes.
type CaseFiles = ld65_diff::Files;

/// The assembler's `ok_*.s` cases, each with the other files of its
/// directory (includes, binaries).
fn cases() -> Vec<(String, CaseFiles)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assembler/tests/cases");
    let mut found = Vec::new();
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .expect("the assembler's cases")
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|path| path.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        let files = files_of(&dir);
        for (name, _) in &files {
            if name.starts_with("ok_") && name.ends_with(".s") {
                let dir_name = dir.file_name().expect("a name").to_string_lossy();
                found.push((format!("{dir_name}/{name}"), files.clone()));
            }
        }
    }
    found
}

#[test]
fn the_assemblers_cases_match_ld65() {
    let Some((ca65, ld65)) = toolchain("the_assemblers_cases_match_ld65") else {
        return;
    };
    let tools = (ca65.as_path(), ld65.as_path());
    let cases = cases();
    assert!(cases.len() >= 20, "only {} cases found", cases.len());
    let total = cases.len();
    let mut failures = Vec::new();
    for (what, files) in cases {
        let main = what.rsplit('/').next().unwrap_or(&what).to_string();
        let known = KNOWN_DIFFERENCES.iter().find(|(case, _)| *case == what);
        // Twice: reserved bytes (`.res`, `.align` without a value) take the
        // area's fill value in both toolchains, zero by default.
        let mut differs = false;
        for fill in [0x00, 0xFF] {
            let label = format!("{what} (fill ${fill:02X})");
            match compare(&label, &files, std::slice::from_ref(&main), tools, fill) {
                Err(failure) if known.is_none() => failures.push(failure),
                Err(_) => differs = true,
                Ok(()) => {}
            }
        }
        if let Some((_, reason)) = known
            && !differs
        {
            failures.push(format!(
                "{what} now matches ca65 + ld65; take it off KNOWN_DIFFERENCES (it was: {reason})"
            ));
        }
    }
    report(failures, 2 * total);
}

/// Every program in `tests/<under>/*/`: its name, its files and the
/// sources to assemble (every `.s`).
fn programs_in(under: &str) -> Vec<(String, CaseFiles, Vec<String>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(under);
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .expect("the programs")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.is_dir())
        .collect();
    dirs.sort();
    assert!(!dirs.is_empty(), "no programs in {}", root.display());
    dirs.iter()
        .map(|dir| {
            let files = files_of(dir);
            let mains = files
                .iter()
                .map(|(name, _)| name.clone())
                .filter(|name| name.ends_with(".s"))
                .collect();
            let name = dir
                .file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            (name, files, mains)
        })
        .collect()
}

/// Programs of several files (`asm_multi/*/`, all linked together): what
/// one file cannot show alone, imports among them.
#[test]
fn programs_of_several_files_match_ld65() {
    let Some((ca65, ld65)) = toolchain("programs_of_several_files_match_ld65") else {
        return;
    };
    let programs = programs_in("asm_multi");
    let failures: Vec<String> = programs
        .iter()
        .filter_map(|(what, files, mains)| {
            compare(what, files, mains, (ca65.as_path(), ld65.as_path()), 0).err()
        })
        .collect();
    report(failures, programs.len());
}

/// Programs with their own ld65 configuration (`asm_cfg/*/layout.cfg`):
/// what the flat layout cannot show, such as the linker's tables of
/// constructors.
#[test]
fn programs_with_their_own_configuration_match_ld65() {
    let Some((ca65, ld65)) = toolchain("programs_with_their_own_configuration_match_ld65") else {
        return;
    };
    let programs = programs_in("asm_cfg");
    let failures: Vec<String> = programs
        .iter()
        .filter_map(|(what, files, mains)| {
            let cfg = files
                .iter()
                .find(|(name, _)| name == "layout.cfg")
                .map(|(_, text)| String::from_utf8_lossy(text).into_owned())
                .expect("the configuration");
            let tools = (ca65.as_path(), ld65.as_path());
            ld65_diff::compare(what, files, mains, &cfg, tools, None).err()
        })
        .collect();
    report(failures, programs.len());
}

/// C programs of ours (`cc65/*.c` and the two Scorpion extensions in
/// `c_extension/*/range_sum.c`), compiled by cc65 at three
/// optimisation levels; each output (with `.autoimport`, `.case`,
/// `.macpack longbranch`, `.proc name: near`...) assembled by ca65 and by
/// us and linked with a stub of the runtime names it calls: the same
/// binary.
#[test]
fn c_programs_compiled_by_cc65_match_ld65() {
    let test = "c_programs_compiled_by_cc65_match_ld65";
    let Some((ca65, ld65)) = toolchain(test) else {
        return;
    };
    let (Some(cc65), Some(od65)) = (tools::require("cc65", test), tools::require("od65", test))
    else {
        return;
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cc65");
    let mut programs: Vec<_> = std::fs::read_dir(&dir)
        .expect("the C programs")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "c"))
        .collect();
    programs.sort();
    // The Scorpion extension written in C (`c_extension.rs` runs it).
    for kind in ["static", "stack"] {
        programs.push(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/c_extension")
                .join(kind)
                .join("range_sum.c"),
        );
    }
    assert!(programs.len() >= 2, "{programs:?}");
    let mut failures = Vec::new();
    let mut total = 0;
    for program in &programs {
        for level in ["", "-O", "-Oirs"] {
            let out = tempfile::tempdir().expect("a temporary directory");
            let assembly = out.path().join("program.s");
            let mut command = Command::new(&cc65);
            if !level.is_empty() {
                command.arg(level);
            }
            let compiled = command
                .arg(program)
                .arg("-o")
                .arg(&assembly)
                .output()
                .expect("cc65 runs");
            assert!(
                compiled.status.success(),
                "cc65 {level} {}: {}",
                program.display(),
                String::from_utf8_lossy(&compiled.stderr)
            );
            // A stub of the runtime names it calls, read from ca65's
            // object of it.
            let object = ld65_diff::ca65(out.path(), &ca65, "program.s", None)
                .unwrap_or_else(|message| panic!("{}: {message}", program.display()));
            let stub = ld65_diff::stub(&ld65_diff::od65(&od65, &object, "--dump-imports"));
            let files = vec![
                (
                    "program.s".to_owned(),
                    std::fs::read(&assembly).expect("cc65's output"),
                ),
                ("runtime_stub.s".to_owned(), stub.into_bytes()),
            ];
            let mains = ["program.s".to_owned(), "runtime_stub.s".to_owned()];
            let name = program
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            total += 1;
            if let Err(failure) = compare(
                &format!("{name} (cc65 {level})"),
                &files,
                &mains,
                (ca65.as_path(), ld65.as_path()),
                0,
            ) {
                failures.push(failure);
            }
        }
    }
    report(failures, total);
}

#[test]
fn random_programs_match_ld65() {
    let Some((ca65, ld65)) = toolchain("random_programs_match_ld65") else {
        return;
    };
    // Many small programs (each feature in many contexts) and a few big ones.
    let seeds = 1..=100u64;
    let total = seeds.clone().count();
    let mut failures = Vec::new();
    let mut covered = std::collections::BTreeSet::new();
    for seed in seeds {
        let lines = match seed % 10 {
            0 => 3000,
            5 => 1000,
            _ => 300,
        };
        let program = asm_gen::generate(seed, lines, asm_gen::Flavor::Differential);
        covered.extend(program.covered.iter().copied());
        let (files, mains) = generated(&program.files);
        if let Err(failure) = compare(
            &format!("seed {seed} ({lines} lines)"),
            &files,
            &mains,
            (&ca65, &ld65),
            0,
        ) {
            failures.push(failure);
        }
    }
    report(failures, total);
    assert_eq!(
        covered.len(),
        asm_gen::documented_count(),
        "the random programs use every documented opcode in every mode"
    );
}

#[test]
fn benchmark_flavour_matches_ld65() {
    let Some((ca65, ld65)) = toolchain("benchmark_flavour_matches_ld65") else {
        return;
    };
    // The benchmark's program shape (`.org` chunks), small: one chunk at
    // $1000 linked at START gives the same bytes.
    let program = asm_gen::generate(7, 2000, asm_gen::Flavor::Benchmark);
    let (files, mains) = generated(&program.files);
    if let Err(failure) = compare("benchmark flavour", &files, &mains, (&ca65, &ld65), 0) {
        report(vec![failure], 1);
    }
}

/// ca65's target systems (`-t`): every byte a source can hold in a string
/// and in a character constant, and the symbols each system defines,
/// assembled by `ca65 -t SYSTEM` and by ours with the same system.
#[test]
fn target_systems_translate_and_define_as_ca65s() {
    let Some((ca65, ld65)) = toolchain("target_systems_translate_and_define_as_ca65s") else {
        return;
    };
    let mut source: Vec<u8> = b"        .byte \"".to_vec();
    // Every byte but the string's quote, the line ends and a NUL.
    source.extend((1..=0xFEu8).filter(|b| !matches!(b, b'"' | b'\n' | b'\r')));
    source.extend(b"\"\n        lda #'A'\n        .byte 'z', '_', .strat(\"Hi\", 1)\n");
    let probes = [
        "__CBM__",
        "__C64__",
        "__ATARI__",
        "__APPLE2__",
        "__GEOS__",
        "__C16__",
    ];
    for (bit, name) in probes.iter().enumerate() {
        source.extend(format!(".ifdef {name}\n        .byte {}\n.endif\n", 0x80 | bit).bytes());
    }
    let cfg = ld65_config(START, 0);
    let systems: Vec<_> = assembler::systems::SYSTEMS
        .iter()
        .filter(|s| s.other_cpu.is_none())
        .collect();
    let files = vec![("chars.s".to_owned(), source)];
    let mains = ["chars.s".to_owned()];
    let failures: Vec<String> = systems
        .iter()
        .filter_map(|system| {
            let what = format!("-t {}", system.name);
            let tools = (ca65.as_path(), ld65.as_path());
            ld65_diff::compare(&what, &files, &mains, &cfg, tools, Some(system)).err()
        })
        .collect();
    report(failures, systems.len());
}
