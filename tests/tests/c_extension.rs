//! A Scorpion extension written in C: cc65 compiles the arithmetic, our
//! assembler assembles its output and the handler around it, our linker
//! links both against the reference ROM, and the virtual Scorpion answers
//! the new command with what the C function computed.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use romlib::VirtualScorpion;
use romlib::protocol::Command as RobotCommand;
use scorpion_tests::tools;

#[test]
fn an_extension_written_in_c_answers_on_the_virtual_scorpion() {
    let Some(cc65) = tools::require(
        "cc65",
        "an_extension_written_in_c_answers_on_the_virtual_scorpion",
    ) else {
        return;
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/c_extension");
    let out = tempfile::tempdir().expect("a temporary directory");
    let compiled = out.path().join("range_sum.s");
    let status = Command::new(cc65)
        .args(["-O", "-Cl"])
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
    files.insert(
        "range_sum.s",
        std::fs::read(&compiled).expect("cc65's output"),
    );
    files.insert(
        "handler.s",
        std::fs::read(dir.join("handler.s")).expect("the handler"),
    );
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let objects: Vec<(String, Vec<u8>)> = ["handler.s", "range_sum.s"]
        .iter()
        .map(|name| {
            let assembly = assembler::assemble(&files, Path::new(name), &options)
                .unwrap_or_else(|error| panic!("{name}: {error:?}"));
            ((*name).to_owned(), assembly.object)
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
    // $10 + $20 + $30 + $FF, summed by the C function.
    assert_eq!(text_of(&answer.encode()), "K015F");
    let known: RobotCommand = "/1X".parse().expect("a command");
    assert!(robot.exchange(&known).expect("the ROM answers").is_some());
}

/// An answer's text without its carriage return.
fn text_of(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes.strip_suffix(b"\r").unwrap_or(bytes)).into_owned()
}
