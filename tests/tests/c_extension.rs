//! A Scorpion extension written in C: cc65 compiles the arithmetic, our
//! assembler assembles its output and the handler around it, our linker
//! links both against the reference ROM, and the virtual Scorpion answers
//! the new command with what the C function computed. Two ways:
//! `static/`, a function with static locals (`cc65 -Cl`) that needs no C
//! runtime, and `stack/`, one with parameters and locals on cc65's C
//! stack, linked with the part of the C runtime we wrote for it
//! (`stack/runtime.s`), at every optimisation level.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use romlib::VirtualScorpion;
use romlib::protocol::Command as RobotCommand;
use scorpion_tests::tools;

/// Compiles `dir/range_sum.c` with `cc65_args`, assembles it with the
/// other sources of `dir` and the shared `answer.s`, links for `scorpion-ext` against the reference
/// ROM, and asks the virtual Scorpion `/1K`: its answer.
fn build_and_ask(cc65: &Path, dir: &str, cc65_args: &[&str]) -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/c_extension")
        .join(dir);
    let out = tempfile::tempdir().expect("a temporary directory");
    let compiled = out.path().join("range_sum.s");
    let status = Command::new(cc65)
        .args(cc65_args)
        .arg(dir.join("range_sum.c"))
        .arg("-o")
        .arg(&compiled)
        .output()
        .expect("cc65 runs");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );

    let mut files = assembler::MemorySource::new();
    let mut names = vec!["range_sum.s".to_owned()];
    files.insert(
        "range_sum.s",
        std::fs::read(&compiled).expect("cc65's output"),
    );
    let shared = dir
        .parent()
        .expect("the extensions' directory")
        .join("answer.s");
    let own = std::fs::read_dir(&dir)
        .expect("the extension's sources")
        .map(|entry| entry.expect("an entry").path());
    for path in own.chain([shared]) {
        if path.extension().is_some_and(|e| e == "s") {
            let name = path
                .file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            files.insert(name.as_str(), std::fs::read(&path).expect("a source"));
            names.push(name);
        }
    }
    names.sort();
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let objects: Vec<(String, Vec<u8>)> = names
        .iter()
        .map(|name| {
            let assembly = assembler::assemble(&files, Path::new(name), &options)
                .unwrap_or_else(|error| panic!("{name}: {error:?}"));
            (name.clone(), assembly.object)
        })
        .collect();
    let inputs: Vec<linker::Input<'_>> = objects
        .iter()
        .map(|(name, bytes)| linker::Input { name, bytes })
        .collect();
    let rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("the ROM's ELF");
    let target = linker::Target::builtin("scorpion-ext", None).expect("a built-in target");
    let linked = linker::link(
        &inputs,
        &linker::LinkOptions {
            target: &target,
            just_symbols: &[linker::SymbolFile {
                name: "scorpion-rom.elf",
                image: &rom,
            }],
            sources: &linker::NoSources,
        },
    )
    .unwrap_or_else(|error| panic!("{error:?}"));

    let mut robot = VirtualScorpion::new();
    robot
        .load_image(&linked.image)
        .expect("the extension loads");
    let command: RobotCommand = "/1K".parse().expect("a command");
    let answer = robot.ask_extension(&command).expect("an answer");
    let known: RobotCommand = "/1X".parse().expect("a command");
    assert!(robot.exchange(&known).expect("the ROM answers").is_some());
    text_of(&answer.encode())
}

#[test]
fn an_extension_written_in_c_answers_on_the_virtual_scorpion() {
    let test = "an_extension_written_in_c_answers_on_the_virtual_scorpion";
    let Some(cc65) = tools::require("cc65", test) else {
        return;
    };
    // $10 + $20 + $30 + $FF, summed by the C function.
    assert_eq!(build_and_ask(&cc65, "static", &["-O", "-Cl"]), "K015F");
}

#[test]
fn a_stack_using_extension_in_c_runs_on_our_runtime_at_every_level() {
    let test = "a_stack_using_extension_in_c_runs_on_our_runtime_at_every_level";
    let Some(cc65) = tools::require("cc65", test) else {
        return;
    };
    for level in [&[][..], &["-O"], &["-Oirs"], &["-Os"]] {
        assert_eq!(
            build_and_ask(&cc65, "stack", level),
            "K015F",
            "cc65 {level:?}"
        );
    }
}

/// An answer's text without its carriage return.
fn text_of(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes.strip_suffix(b"\r").unwrap_or(bytes)).into_owned()
}
