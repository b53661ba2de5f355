//! The corpus of real code: Debian's `cc65` package, which CI installs
//! (`.ci/install-test-tools`); nothing of it is in this repository.
//!
//! - **C samples** (`samples/`, `samples/geos/`, `samples/tutorial/`):
//!   compiled by cc65 at two optimisation levels (GEOS resources through
//!   grc65 and sp65 first, as the samples' own build does); each output,
//!   and each assembly file the build makes or ships, assembled by ca65
//!   and by us and linked with a stub of its imports (read from ca65's
//!   object by od65) by ld65 and by our linker reading the same
//!   configuration: the same bytes.
//! - **asminc**: every include file, included alone, accepted by us
//!   wherever ca65 accepts it.
//! - **cfg**: every ld65 configuration, read by our linker as
//!   `--target FILE.cfg` does and used to link a program made for it
//!   (every segment, every import, every symbol the configuration defines
//!   used): every output file the same as ld65's.
//!
//! Each test prints its row of the table in the assembler's README (kind,
//! count, identical) and fails on any program outside the listed
//! deliberate differences.

#[path = "ld65_diff/mod.rs"]
mod ld65_diff;

use std::path::{Path, PathBuf};
use std::process::Command;

use ld65_diff::{Files, compare, od65, report, stub, toolchain};
use scorpion_tests::tools;

/// The package's shared directory (`/usr/share/cc65`), from cl65.
fn share(test: &str) -> Option<PathBuf> {
    let cl65 = tools::require("cl65", test)?;
    let output = Command::new(cl65)
        .arg("--print-target-path")
        .output()
        .expect("cl65 runs");
    let target = PathBuf::from(String::from_utf8_lossy(&output.stdout).trim());
    Some(
        target
            .parent()
            .expect("the target path's parent")
            .to_owned(),
    )
}

/// Prints a row of the corpus table, past the harness's capture.
fn row(kind: &str, count: usize, identical: usize, deliberate: &[(&str, &str)]) {
    use std::io::Write as _;
    let mut line = format!("CORPUS {kind}: {count} programs, {identical} identical");
    for (name, why) in deliberate {
        line.push_str(&format!("\n  not built: {name}: {why}"));
    }
    line.push('\n');
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}

/// The files of `dir` with extension `ext`, sorted.
fn files_with(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == ext))
        .collect();
    found.sort();
    found
}

fn name_of(path: &Path) -> String {
    path.file_name()
        .expect("a file name")
        .to_string_lossy()
        .into_owned()
}

/// An ld65 configuration that places `segments` (ca65's names, from the
/// program and its stub) at $0800, zero-page ones in $00-$FF.
fn program_config(segments: &[(String, bool)]) -> String {
    let mut text = String::from(
        "MEMORY {\n    ZP:   start = $0000, size = $0100, type = rw, file = \"\";\n    MAIN: start = $0800, size = $F800, file = %O;\n}\nSEGMENTS {\n",
    );
    let mut seen = Vec::new();
    for (name, zp) in segments {
        if seen.contains(name) {
            continue;
        }
        seen.push(name.clone());
        let (load, kind) = match (name.as_str(), zp) {
            (_, true) | ("ZEROPAGE" | "EXTZP", _) => ("ZP", "zp"),
            ("BSS", _) => ("MAIN", "bss"),
            _ => ("MAIN", "ro"),
        };
        text.push_str(&format!("    {name}: load = {load}, type = {kind};\n"));
    }
    text.push_str("}\n");
    text
}

/// One assembly program (`main`, with the other `files` it includes) with
/// a stub of its imports, through both toolchains.
fn assembly_program(
    what: &str,
    files: &Files,
    main: &str,
    tools: (&Path, &Path),
    od65_path: &Path,
) -> Result<(), String> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).expect("write a source");
    }
    let object = ld65_diff::ca65(dir.path(), tools.0, main, None)
        .map_err(|message| format!("{what}: {message}"))?;
    let imports = od65(od65_path, &object, "--dump-imports");
    let mut segments = od65(od65_path, &object, "--dump-segments");
    segments.extend([("ZEROPAGE".to_owned(), true), ("CODE".to_owned(), false)]);
    let mut all = files.clone();
    all.push(("stub.s".to_owned(), stub(&imports).into_bytes()));
    let mains = [main.to_owned(), "stub.s".to_owned()];
    compare(what, &all, &mains, &program_config(&segments), tools, None)
}

/// Samples not built, and why: each must still be refused as said.
const SAMPLES_NOT_BUILT: [(&str, &str); 2] = [
    (
        "samples/supervisionhello.c",
        "compiled for the Watara Supervision's 65SC02; the Scorpion's CPU is an NMOS 6502 and we refuse `.setcpu \"65SC02\"`",
    ),
    (
        "geos/geosconio.c",
        "cc65 2.19 itself rejects it (`mouse_init` is no longer declared)",
    ),
];

/// The cc65 target each sample is written for.
fn sample_target(dir: &str, name: &str) -> &'static str {
    match (dir, name) {
        ("geos", _) => "geos-cbm",
        (_, "atari2600hello.c") => "atari2600",
        (_, "supervisionhello.c") => "supervision",
        _ => "c64",
    }
}

#[test]
fn cc65_samples_build_as_ca65_and_ld65_build_them() {
    let test = "cc65_samples_build_as_ca65_and_ld65_build_them";
    let Some(share) = share(test) else { return };
    let Some((ca65, ld65)) = toolchain(test) else {
        return;
    };
    let (Some(cc65), Some(od65), Some(grc65), Some(sp65)) = (
        tools::require("cc65", test),
        tools::require("od65", test),
        tools::require("grc65", test),
        tools::require("sp65", test),
    ) else {
        return;
    };
    let tools = (ca65.as_path(), ld65.as_path());
    let mut failures = Vec::new();
    let mut total = 0;
    for dir_name in ["samples", "geos", "tutorial"] {
        let source_dir = match dir_name {
            "samples" => share.join("samples"),
            other => share.join("samples").join(other),
        };
        // The sample directory's files, and what its build makes first:
        // GEOS resources (grc65: a header and an assembly file each) and
        // the bitmap (sp65).
        let work = tempfile::tempdir().expect("a temporary directory");
        for entry in std::fs::read_dir(&source_dir).expect("the samples") {
            let path = entry.expect("an entry").path();
            if path.is_file() {
                std::fs::copy(&path, work.path().join(name_of(&path))).expect("copy a sample");
            }
        }
        for resource in files_with(work.path(), "grc") {
            let status = Command::new(&grc65)
                .current_dir(work.path())
                .arg(name_of(&resource))
                .status()
                .expect("grc65 runs");
            assert!(status.success(), "grc65 {}", resource.display());
        }
        if work.path().join("logo.pcx").exists() {
            let status = Command::new(&sp65)
                .current_dir(work.path())
                .args([
                    "-r",
                    "logo.pcx",
                    "-c",
                    "geos-bitmap",
                    "-w",
                    "bitmap.c,ident=bitmap",
                ])
                .status()
                .expect("sp65 runs");
            assert!(status.success(), "sp65 on logo.pcx");
        }
        let mut files: Files = Vec::new();
        for entry in std::fs::read_dir(work.path()).expect("the work directory") {
            let path = entry.expect("an entry").path();
            files.push((name_of(&path), std::fs::read(&path).expect("a file")));
        }
        files.sort();
        // Assembly files shipped or made by the build, on their own.
        for source in files_with(work.path(), "s") {
            let name = name_of(&source);
            total += 1;
            let what = format!("{dir_name}/{name}");
            if let Err(failure) = assembly_program(&what, &files, &name, tools, &od65) {
                failures.push(failure);
            }
        }
        // The C programs, compiled at two levels.
        for program in files_with(&source_dir, "c") {
            let name = name_of(&program);
            let what = format!("{dir_name}/{name}");
            let refused = SAMPLES_NOT_BUILT.iter().find(|(n, _)| *n == what);
            for level in ["-O", "-Oirs"] {
                let assembly = format!("{}{level}.s", name.trim_end_matches(".c"));
                let compiled = Command::new(&cc65)
                    .current_dir(work.path())
                    .args([
                        "-t",
                        sample_target(dir_name, &name),
                        level,
                        &name,
                        "-o",
                        &assembly,
                    ])
                    .output()
                    .expect("cc65 runs");
                if !compiled.status.success() {
                    assert!(
                        refused.is_some(),
                        "cc65 {level} {what} failed: {}",
                        String::from_utf8_lossy(&compiled.stderr)
                    );
                    continue;
                }
                let mut program_files = files.clone();
                program_files.push((
                    assembly.clone(),
                    std::fs::read(work.path().join(&assembly)).expect("cc65's output"),
                ));
                let label = format!("{what} (cc65 {level})");
                let result = assembly_program(&label, &program_files, &assembly, tools, &od65);
                match (result, refused) {
                    (Ok(()), Some((_, why))) => failures.push(format!(
                        "{label} now builds identically; take it off SAMPLES_NOT_BUILT (it was: {why})"
                    )),
                    (Err(failure), None) => {
                        total += 1;
                        failures.push(failure);
                    }
                    (Ok(()), None) => total += 1,
                    (Err(failure), Some((_, why))) => {
                        if !failure.contains("65SC02") {
                            failures.push(format!("{label} fails otherwise than listed ({why}):\n{failure}"));
                        }
                    }
                }
            }
        }
    }
    row(
        "cc65 samples (C at -O and -Oirs, and their assembly)",
        total,
        total - failures.len(),
        &SAMPLES_NOT_BUILT,
    );
    report(failures, total);
}

#[test]
fn asminc_files_are_accepted_where_ca65_accepts_them() {
    let test = "asminc_files_are_accepted_where_ca65_accepts_them";
    let Some(share) = share(test) else { return };
    let Some(ca65) = tools::require("ca65", test) else {
        return;
    };
    let asminc = share.join("asminc");
    let includes: Vec<PathBuf> = std::fs::read_dir(&asminc)
        .expect("asminc")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.is_file())
        .collect();
    assert!(includes.len() >= 50, "{} files in asminc", includes.len());
    let mut source = assembler::MemorySource::new();
    for path in &includes {
        source.insert(
            format!("asminc/{}", name_of(path)).as_str(),
            std::fs::read(path).expect("an include").as_slice(),
        );
    }
    let options = assembler::Options {
        include_dirs: vec![PathBuf::from("asminc")],
        ..assembler::Options::default()
    };
    let (mut failures, mut accepted_by_ca65, mut total) = (Vec::new(), 0, 0);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut sorted = includes.clone();
    sorted.sort();
    for path in &sorted {
        let name = name_of(path);
        total += 1;
        let text = format!(".include \"{name}\"\n");
        std::fs::write(dir.path().join("main.s"), &text).expect("write");
        let theirs = Command::new(&ca65)
            .current_dir(dir.path())
            .arg("-I")
            .arg(&asminc)
            .args(["main.s", "-o", "main.o"])
            .output()
            .expect("ca65 runs");
        let mut source = source.clone();
        source.insert("main.s", text.as_bytes());
        let ours = assembler::assemble(&source, Path::new("main.s"), &options);
        if theirs.status.success() {
            accepted_by_ca65 += 1;
            if let Err(error) = ours {
                let details: Vec<String> = error
                    .diagnostics()
                    .iter()
                    .map(assembler::Diagnostic::summary)
                    .collect();
                failures.push(format!(
                    "{name}: ca65 accepts it, we do not:\n{}",
                    details.join("\n")
                ));
            }
        } else if ours.is_ok() {
            // Not a failure of ours, but worth knowing: say it.
            tools::skipped(
                test,
                &format!("{name}: ca65 rejects it alone and we accept it"),
            );
        }
    }
    row(
        "asminc (each file included alone)",
        accepted_by_ca65,
        accepted_by_ca65 - failures.len(),
        &[],
    );
    report(failures, total);
}

/// A program using each macro file of `asminc/` (`*.mac`), included as a
/// ca65 project includes it: what including alone cannot show.
const MACRO_USES: [(&str, &str); 7] = [
    ("apple2.mac", "scrcode \"Hello, World! @[]abc\", 65, 'x'\n"),
    ("atari.mac", "scrcode \"Hello, World! @[]abc\", 65, 'x'\n"),
    (
        "cbm.mac",
        "scrcode \"Hello, World! @[]abc\", 65, 'x'\n        .byte scrbyte('a')\n",
    ),
    (
        "cpu.mac",
        ".byte <CPU_6502X, <CPU_65C02, >CPU_4510\n.if .cpu .bitand CPU_ISET_6502\n        nop\n.endif\n",
    ),
    (
        "generic.mac",
        "add #1\n        sub $10\n        add $1234, x\nback:   bge back\n        blt back\n        bgt back\n        ble back\n        bnz back\n        bze back\n",
    ),
    (
        "longbranch.mac",
        "back:   jeq back\n        jne fwd\n        jcc back\n        .res 200\n        jcs back\nfwd:    jmi fwd\n        jpl back\n        jvc back\n        jvs back\n",
    ),
    ("module.mac", "module_header _drv\n        .byte 1\n"),
];

#[test]
fn asminc_macro_files_expand_as_ca65_expands_them() {
    let test = "asminc_macro_files_expand_as_ca65_expands_them";
    let Some(share) = share(test) else { return };
    let Some((ca65, ld65)) = toolchain(test) else {
        return;
    };
    let asminc = share.join("asminc");
    let shipped: Vec<String> = files_with(&asminc, "mac")
        .iter()
        .map(|p| name_of(p))
        .collect();
    let covered: Vec<String> = MACRO_USES
        .iter()
        .map(|(name, _)| (*name).to_owned())
        .collect();
    assert_eq!(
        shipped, covered,
        "every macro file of the package is used here"
    );
    let cfg = "MEMORY { ZP: start = $0000, size = $0100, type = rw, file = \"\"; MAIN: start = $0800, size = $7800, file = %O; }\nSEGMENTS { ZEROPAGE: load = ZP, type = zp, optional = yes; CODE: load = MAIN, type = ro; RODATA: load = MAIN, type = ro, optional = yes; HEADER: load = MAIN, type = ro, optional = yes; }\n";
    let mut failures = Vec::new();
    for (name, uses) in MACRO_USES {
        let mut files: Files = vec![(
            "program.s".to_owned(),
            format!("        .include \"{name}\"\n        .code\n        {uses}").into_bytes(),
        )];
        for path in files_with(&asminc, "mac")
            .iter()
            .chain(&files_with(&asminc, "inc"))
        {
            files.push((name_of(path), std::fs::read(path).expect("an include")));
        }
        if let Err(failure) = compare(
            name,
            &files,
            &["program.s".to_owned()],
            cfg,
            (ca65.as_path(), ld65.as_path()),
            None,
        ) {
            failures.push(failure);
        }
    }
    row(
        "asminc macro files (each used by a program)",
        MACRO_USES.len(),
        MACRO_USES.len() - failures.len(),
        &[],
    );
    report(failures, MACRO_USES.len());
}

/// The words after `key =` in an item's attributes (`type`, `define`).
fn attribute<'a>(item: &'a str, key: &str) -> Option<&'a str> {
    let mut rest = item;
    while let Some(at) = rest.find(key) {
        let before = rest[..at].chars().next_back();
        let after = rest[at + key.len()..].trim_start();
        if before.is_none_or(|c| !c.is_alphanumeric() && c != '_')
            && let Some(value) = after.strip_prefix('=')
        {
            let value = value.trim_start();
            let end = value
                .find(|c: char| c == ',' || c == ';' || c.is_whitespace())
                .unwrap_or(value.len());
            return Some(&value[..end]);
        }
        rest = &rest[at + key.len()..];
    }
    None
}

/// The items (`name: attributes`) of every `block { ... }` of `cfg`.
fn items(cfg: &str, block: &str) -> Vec<(String, String)> {
    let text: String = cfg
        .lines()
        .map(|line| line.split('#').next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let mut found = Vec::new();
    let mut rest = text.as_str();
    while let Some(at) = rest.find(block) {
        let after = &rest[at + block.len()..];
        let Some(open) = after.find('{') else { break };
        if !after[..open].trim().is_empty() {
            rest = after;
            continue;
        }
        let close = after.find('}').expect("a closed block");
        for item in after[open + 1..close].split(';') {
            if let Some((name, attrs)) = item.split_once(':') {
                found.push((name.trim().to_owned(), attrs.to_owned()));
            }
        }
        rest = &after[close..];
    }
    found
}

/// A program for configuration `cfg`: two bytes in every segment (reserved
/// space in BSS and zero-page ones), the configuration's imports exported,
/// and in `CODE` a word for every symbol the configuration defines.
fn program_for(cfg: &str) -> String {
    let mut text = String::new();
    let mut words = Vec::new();
    for (name, attrs) in items(cfg, "MEMORY") {
        if attribute(&attrs, "define") == Some("yes") {
            words.extend(["START", "SIZE", "LAST"].map(|s| format!("__{name}_{s}__")));
        }
    }
    for (index, (name, attrs)) in items(cfg, "SEGMENTS").into_iter().enumerate() {
        text.push_str(&format!(".segment \"{name}\"\n"));
        match attribute(&attrs, "type") {
            Some("zp") => text.push_str(".res 2\n"),
            Some("bss") => text.push_str(".res 3\n"),
            _ => text.push_str(&format!(".byte {}, {}\n", index, index + 100)),
        }
        if attribute(&attrs, "define") == Some("yes") {
            words.extend(["LOAD", "RUN", "SIZE"].map(|s| format!("__{name}_{s}__")));
        }
    }
    for (name, attrs) in items(cfg, "SYMBOLS") {
        if attribute(&attrs, "type") == Some("import") {
            text.push_str(&format!(".export {name}\n{name} = $1234\n"));
        } else if name == "__OVERLAYSIZE__" {
            // Overlays are empty until the program sizes them, as a GEOS
            // program's resources do.
            text.push_str(&format!(".export {name}\n{name} = $1000\n"));
        } else {
            words.push(name);
        }
    }
    // The start and initialisation routines an executable format names
    // (`runad = start`, `initad = AREA: routine`).
    for (_, attrs) in items(cfg, "FORMATS") {
        for option in attrs.split(',') {
            let Some((key, value)) = option.split_once('=') else {
                continue;
            };
            if !matches!(key.trim(), "runad" | "initad") {
                continue;
            }
            let routine = value.rsplit(':').next().unwrap_or(value).trim();
            if !text.contains(&format!(".export {routine}\n")) {
                text.push_str(&format!(
                    ".segment \"CODE\"\n.export {routine}\n{routine}: rts\n"
                ));
            }
        }
    }
    for (_, attrs) in items(cfg, "FEATURES") {
        for key in ["label", "count"] {
            if let Some(name) = attribute(&attrs, key) {
                words.push(name.to_owned());
            }
        }
    }
    if !words.is_empty() && items(cfg, "SEGMENTS").iter().any(|(n, _)| n == "CODE") {
        text.push_str(".segment \"CODE\"\n");
        for word in &words {
            text.push_str(&format!(".import {word}\n.word {word}\n"));
        }
    }
    text
}

/// Configurations not linked, and why: each must still be refused.
const CONFIGS_NOT_LINKED: [(&str, &str); 2] = [
    (
        "lunix.cfg",
        "writes o65, a relocatable format for LUnix's loader; we write absolute images (bin, atari) and refuse `format = o65` by name",
    ),
    (
        "module.cfg",
        "writes o65 (cc65's loadable drivers); refused by name, as lunix.cfg",
    ),
];

#[test]
fn ld65_configurations_link_as_ld65_links() {
    let test = "ld65_configurations_link_as_ld65_links";
    let Some(share) = share(test) else { return };
    let Some((ca65, ld65)) = toolchain(test) else {
        return;
    };
    let tools = (ca65.as_path(), ld65.as_path());
    let configs = files_with(&share.join("cfg"), "cfg");
    assert!(configs.len() >= 60, "{} configurations", configs.len());
    let (mut failures, mut total) = (Vec::new(), 0);
    for path in &configs {
        let name = name_of(path);
        let cfg = std::fs::read_to_string(path).expect("a configuration");
        let program = program_for(&cfg);
        let files = vec![("program.s".to_owned(), program.into_bytes())];
        let mains = ["program.s".to_owned()];
        if let Some((_, why)) = CONFIGS_NOT_LINKED.iter().find(|(n, _)| *n == name) {
            // Still refused, by name.
            match ld65_diff::ours(&files, &mains, &cfg, None) {
                Err(error) if error.contains("the o65 format is not supported") => {}
                other => failures.push(format!(
                    "{name} is no longer refused as listed ({why}): {:?}",
                    other.map(|files| files.len())
                )),
            }
            continue;
        }
        total += 1;
        if let Err(failure) = compare(&name, &files, &mains, &cfg, tools, None) {
            failures.push(failure);
        }
    }
    row(
        "ld65 configurations (cfg/, each linking a program made for it)",
        total,
        total - failures.len(),
        &CONFIGS_NOT_LINKED,
    );
    report(failures, total);
}
