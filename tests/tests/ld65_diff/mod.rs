//! Both toolchains on one program: ca65 + ld65 (Debian's cc65) and our
//! assembler + linker, each reading the same ld65 configuration (ours
//! through `--target FILE.cfg`'s reader), every output file compared byte
//! for byte. Shared by the differential tests (`asm_differential.rs`,
//! `cc65_corpus.rs`).

#![allow(dead_code, reason = "each test file uses part of it")]

use std::path::{Path, PathBuf};
use std::process::Command;

use scorpion_tests::tools;

/// The name both toolchains give the main output; other files are named
/// from it (`%O.1`).
pub(crate) const OUTPUT: &str = "out.bin";

/// A program's files: name and bytes.
pub(crate) type Files = Vec<(String, Vec<u8>)>;

/// ca65 and ld65, or `None` after saying why `test` skips.
pub(crate) fn toolchain(test: &str) -> Option<(PathBuf, PathBuf)> {
    let ca65 = tools::require("ca65", test)?;
    let ld65 = tools::require("ld65", test)?;
    Some((ca65, ld65))
}

/// A target system (`-t`) for both assemblers, or none.
pub(crate) type System = Option<&'static assembler::systems::System>;

/// ca65 on `name` in `dir` (for `system`): the object's path, or what
/// ca65 said.
pub(crate) fn ca65(dir: &Path, ca65: &Path, name: &str, system: System) -> Result<PathBuf, String> {
    let object = format!("{name}.o");
    let output = Command::new(ca65)
        .current_dir(dir)
        .args(system.iter().flat_map(|s| ["-t", s.name]))
        .args([name, "-o", object.as_str()])
        .output()
        .expect("ca65 runs");
    if !output.status.success() {
        return Err(format!(
            "ca65 rejected {name}: {}",
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    Ok(dir.join(object))
}

/// Every file of `dir` (not its subdirectories): name and bytes, by name.
pub(crate) fn files_of(dir: &Path) -> Files {
    let mut files: Files = std::fs::read_dir(dir)
        .expect("a directory")
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|path| path.is_file())
        .map(|path| {
            let name = path
                .file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            (name, std::fs::read(&path).expect("a file"))
        })
        .collect();
    files.sort();
    files
}

/// ca65 + ld65 on `files` (written to `dir`, `mains` assembled) with the
/// configuration `cfg`: every output file by name, or their complaint.
pub(crate) fn reference(
    dir: &Path,
    files: &[(String, Vec<u8>)],
    mains: &[String],
    cfg: &str,
    (ca65_path, ld65): (&Path, &Path),
    system: System,
) -> Result<Files, String> {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).expect("write a source");
    }
    let mut objects = Vec::new();
    for name in mains {
        objects.push(ca65(dir, ca65_path, name, system)?);
    }
    let out = dir.join("ld65");
    std::fs::create_dir_all(&out).expect("an output directory");
    std::fs::write(dir.join("layout.cfg"), cfg).expect("write the configuration");
    let output = Command::new(ld65)
        .current_dir(&out)
        .args(["-C", "../layout.cfg", "-o", OUTPUT])
        .args(&objects)
        .output()
        .expect("ld65 runs");
    if !output.status.success() {
        return Err(format!(
            "ld65 failed: {}",
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    let written = files_of(&out);
    Ok(written)
}

/// Our assembler and linker, in memory, with the configuration `cfg`:
/// every output file by name (the image as raw bytes, and the other files
/// the configuration names), or our errors.
pub(crate) fn ours(
    files: &[(String, Vec<u8>)],
    mains: &[String],
    cfg: &str,
    system: System,
) -> Result<Files, String> {
    let mut source = assembler::MemorySource::new();
    for (name, text) in files {
        source.insert(name.as_str(), text.as_slice());
    }
    let options = assembler::Options {
        system,
        ..assembler::Options::default()
    };
    let mut objects = Vec::new();
    for name in mains {
        let assembly =
            assembler::assemble(&source, Path::new(name), &options).map_err(|error| {
                let details: Vec<String> = error
                    .diagnostics()
                    .iter()
                    .map(assembler::Diagnostic::summary)
                    .collect();
                format!("we rejected {name}: {error}\n{}", details.join("\n"))
            })?;
        objects.push((name.clone(), assembly.object));
    }
    let inputs: Vec<linker::Input<'_>> = objects
        .iter()
        .map(|(name, bytes)| linker::Input { name, bytes })
        .collect();
    let layout = linker::Layout::from_ld65("layout.cfg", cfg, None)
        .map_err(|error| format!("our reading of the configuration failed: {error:?}"))?;
    let target = linker::Target::Custom(layout);
    let linked = linker::link(
        &inputs,
        &linker::LinkOptions {
            target: &target,
            just_symbols: &[],
            sources: &linker::NoSources,
        },
    )
    .map_err(|error| format!("our link failed: {error:?}"))?;
    let mut written = Vec::new();
    // ld65 writes the main file when an area names it, even an empty one.
    if linked
        .layout
        .areas
        .iter()
        .any(|area| area.output && area.file.is_none())
    {
        let bytes = linked
            .write(linker::Format::Bin)
            .map_err(|error| format!("cannot write the binary: {error:?}"))?;
        written.push((OUTPUT.to_owned(), bytes));
    }
    for file in &linked.other_files {
        written.push((file.path(OUTPUT), file.bytes()));
    }
    written.sort();
    Ok(written)
}

/// Both toolchains on one program; the differences, if any, with the
/// sources kept for `ca65 -l`.
pub(crate) fn compare(
    what: &str,
    files: &[(String, Vec<u8>)],
    mains: &[String],
    cfg: &str,
    tools: (&Path, &Path),
    system: System,
) -> Result<(), String> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let expected = match reference(dir.path(), files, mains, cfg, tools, system) {
        Ok(outputs) => outputs,
        Err(message) => {
            let kept = dir.keep();
            return Err(format!(
                "{what}: the reference toolchain failed (sources kept in {}):\n{message}",
                kept.display()
            ));
        }
    };
    let actual = match ours(files, mains, cfg, system) {
        Ok(outputs) => outputs,
        Err(message) => {
            let kept = dir.keep();
            return Err(format!(
                "{what}: {message}\n(sources kept in {})",
                kept.display()
            ));
        }
    };
    let names =
        |outputs: &Files| -> Vec<String> { outputs.iter().map(|(n, _)| n.clone()).collect() };
    if names(&expected) != names(&actual) {
        let kept = dir.keep();
        return Err(format!(
            "{what}: ld65 wrote {:?}, we wrote {:?} (sources kept in {})",
            names(&expected),
            names(&actual),
            kept.display()
        ));
    }
    for ((name, expected), (_, actual)) in expected.iter().zip(&actual) {
        if expected != actual {
            let first = expected
                .iter()
                .zip(actual)
                .position(|(a, b)| a != b)
                .unwrap_or(expected.len().min(actual.len()));
            let show = |bytes: &[u8]| -> String {
                bytes
                    .iter()
                    .skip(first.saturating_sub(4))
                    .take(12)
                    .map(|b| format!("{b:02X}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            let kept = dir.keep();
            return Err(format!(
                "{what}: {name} differs at offset {first:#06X} (ld65 {} bytes, ours {} bytes)\n  ld65: {}\n  ours: {}\nsources kept in {}",
                expected.len(),
                actual.len(),
                show(expected),
                show(actual),
                kept.display()
            ));
        }
    }
    Ok(())
}

/// Panics with every failure.
pub(crate) fn report(failures: Vec<String>, total: usize) {
    assert!(
        failures.is_empty(),
        "{} of {total} programs differ:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

/// od65's list of `what` (`--dump-imports`, `--dump-segments`) in
/// `object`: each entry's name and whether its address size is zero page.
pub(crate) fn od65(od65: &Path, object: &Path, what: &str) -> Vec<(String, bool)> {
    let output = Command::new(od65)
        .arg(what)
        .arg(object)
        .output()
        .expect("od65 runs");
    assert!(output.status.success(), "od65 {what} {}", object.display());
    let text = String::from_utf8_lossy(&output.stdout);
    let mut found = Vec::new();
    let mut zp = false;
    for line in text.lines().map(str::trim) {
        if let Some(size) = line.strip_prefix("Address size:") {
            zp = size.contains("zeropage");
        }
        if let Some(name) = line.strip_prefix("Name:") {
            let name = name.trim().trim_matches('"').to_owned();
            // A name imported at two places is listed twice.
            if !found.iter().any(|(n, _)| *n == name) {
                found.push((name, zp));
            }
            zp = false;
        }
    }
    found
}

/// A stub for `imports`: zero-page cells, bare `RTS` labels, and for
/// the names a linker configuration would define constants like the ones
/// it would give (a `_START__` below its `_LAST__`, small `_SIZE__`s),
/// all exported.
pub(crate) fn stub(imports: &[(String, bool)]) -> String {
    let mut text = String::from("; The imports of a corpus program.\n");
    let (zp, abs): (Vec<_>, Vec<_>) = imports.iter().partition(|(_, zp)| *zp);
    text.push_str("        .zeropage\n");
    for (name, _) in &zp {
        text.push_str(&format!("        .exportzp {name}\n{name}: .res 2\n"));
    }
    text.push_str("        .code\n");
    for (index, (name, _)) in abs.iter().enumerate() {
        if name.starts_with("__") && name.ends_with("__") && name != "__STARTUP__" {
            let value = if name.ends_with("_SIZE__") {
                0x10 + index
            } else if name.ends_with("_LAST__") {
                0x1800 + 0x10 * index
            } else {
                0x1000 + index
            };
            text.push_str(&format!("        .export {name}\n{name} = ${value:04X}\n"));
        } else {
            text.push_str(&format!("        .export {name}\n{name}: rts\n"));
        }
    }
    text
}
