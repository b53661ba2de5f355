//! `scorpion emu run`: the bundled sieve, every stop reason, the trace, the
//! JSON report and bad input. Wall-time fields are masked in snapshots.

use std::path::Path;

use crate::{scorpion, transcript};

/// The transcript with the wall-clock figures replaced (they vary per run).
fn masked(output: &std::process::Output) -> String {
    transcript(output)
        .lines()
        .map(|line| {
            if line.starts_with("seconds: ") {
                "seconds: [wall]".to_string()
            } else if line.starts_with("emulated MHz: ") {
                "emulated MHz: [wall]".to_string()
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

const SIEVE: &[u8] = include_bytes!("../../emulator/programs/sieve.bin");

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).expect("write the test image");
}

#[test]
fn runs_the_bundled_sieve_to_its_trap() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write(dir.path(), "sieve.bin", SIEVE);
    let args = [
        "emu",
        "run",
        "sieve.bin",
        "--load",
        "0x0400",
        "--start",
        "$0400",
        "--until-trap",
    ];
    let output = scorpion(dir.path(), &args);
    assert_eq!(output.status.code(), Some(0));
    insta::assert_snapshot!("emu_sieve", masked(&output));
}

#[test]
fn json_report_has_the_documented_keys_as_numbers() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write(dir.path(), "sieve.bin", SIEVE);
    let output = scorpion(
        dir.path(),
        &[
            "emu",
            "run",
            "sieve.bin",
            "--load",
            "1024",
            "--start",
            "1024",
            "--until-trap",
            "--json",
        ],
    );
    assert_eq!(output.status.code(), Some(0));
    let text = String::from_utf8(output.stdout).expect("utf-8");
    assert_eq!(text.lines().count(), 1, "one JSON object on one line");
    let mut value: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let object = value.as_object_mut().expect("an object");
    let keys: Vec<&str> = object.keys().map(String::as_str).collect();
    let mut expected = vec![
        "stop",
        "pc",
        "a",
        "x",
        "y",
        "sp",
        "p",
        "instructions",
        "cycles",
        "seconds",
    ];
    expected.sort_unstable();
    assert_eq!(keys, expected);
    assert_eq!(object["stop"], "trap");
    for key in ["pc", "a", "x", "y", "sp", "p", "instructions", "cycles"] {
        assert!(object[key].is_u64(), "{key} is a whole number");
    }
    assert!(object["seconds"].is_f64() || object["seconds"].is_u64());
    // 1028 primes below 8192, in X (low) and Y (high).
    assert_eq!(
        (object["x"].as_u64(), object["y"].as_u64()),
        (Some(4), Some(4))
    );
    object.insert("seconds".into(), "[wall]".into());
    insta::assert_snapshot!("emu_sieve_json", value.to_string());
}

/// LDA #$42, then a JAM opcode, at $FFF0, with the reset vector there.
fn jam_image() -> Vec<u8> {
    let mut image = vec![0xA9, 0x42, 0x02];
    image.resize(12, 0xEA);
    image.extend_from_slice(&[0xF0, 0xFF, 0x00, 0x00]);
    image
}

#[test]
fn a_jam_is_a_fault_reported_where_it_happened() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write(dir.path(), "jam.bin", &jam_image());
    // No --start: the reset vector at $FFFC says $FFF0.
    let output = scorpion(dir.path(), &["emu", "run", "jam.bin", "--load", "$FFF0"]);
    assert_eq!(output.status.code(), Some(1));
    insta::assert_snapshot!("emu_jam", masked(&output));
    let json = scorpion(
        dir.path(),
        &["emu", "run", "jam.bin", "--load", "$FFF0", "--json"],
    );
    assert_eq!(json.status.code(), Some(1));
    let value: serde_json::Value = serde_json::from_slice(&json.stdout).expect("valid JSON");
    assert_eq!(value["stop"], "jam");
    assert_eq!(value["pc"], 0xFFF2);
    assert_eq!(value["a"], 0x42);
}

#[test]
fn the_cycle_limit_stops_runaway_programs() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // $0400: NOP; JMP $0400 (a loop, but not a trap).
    write(dir.path(), "loop.bin", &[0xEA, 0x4C, 0x00, 0x04]);
    let base = [
        "emu", "run", "loop.bin", "--load", "0x400", "--start", "0x400",
    ];
    let limited = scorpion(
        dir.path(),
        &[&base[..], &["--max-cycles", "1_000"]].concat(),
    );
    assert_eq!(limited.status.code(), Some(0), "the limit is the asked end");
    insta::assert_snapshot!("emu_cycle_limit", masked(&limited));
    let missed = scorpion(
        dir.path(),
        &[&base[..], &["--max-cycles", "1000", "--until-trap"]].concat(),
    );
    assert_eq!(
        missed.status.code(),
        Some(3),
        "--until-trap, but no trap came"
    );
    let json = scorpion(
        dir.path(),
        &[&base[..], &["--max-cycles", "1000", "--json"]].concat(),
    );
    let value: serde_json::Value = serde_json::from_slice(&json.stdout).expect("valid JSON");
    assert_eq!(value["stop"], "cycle_limit");
    let cycles = value["cycles"].as_u64().expect("a number");
    assert!(
        (1_007..1_007 + 5).contains(&cycles),
        "{cycles}: limit + reset, within one instruction"
    );
}

#[test]
fn trace_writes_one_line_per_instruction() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // LDX #2; loop: DEX; BNE loop; JMP *
    write(
        dir.path(),
        "count.bin",
        &[0xA2, 0x02, 0xCA, 0xD0, 0xFD, 0x4C, 0x05, 0x02],
    );
    let output = scorpion(
        dir.path(),
        &[
            "emu",
            "run",
            "count.bin",
            "--load",
            "0x200",
            "--start",
            "0x200",
            "--until-trap",
            "--trace",
            "count.trace",
        ],
    );
    assert_eq!(output.status.code(), Some(0));
    let trace = std::fs::read_to_string(dir.path().join("count.trace")).expect("the trace file");
    insta::assert_snapshot!("emu_trace", trace);
    insta::assert_snapshot!("emu_trace_stdout", masked(&output));
}

#[test]
fn bad_input_gets_a_clear_error() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let missing = scorpion(dir.path(), &["emu", "run", "nope.bin"]);
    assert_eq!(missing.status.code(), Some(1));
    insta::assert_snapshot!("emu_missing_file", transcript(&missing));
    write(dir.path(), "two.bin", &[1, 2]);
    let too_high = scorpion(dir.path(), &["emu", "run", "two.bin", "--load", "$FFFF"]);
    assert_eq!(too_high.status.code(), Some(1));
    insta::assert_snapshot!("emu_image_too_large", transcript(&too_high));
    let bad_address = scorpion(
        dir.path(),
        &["emu", "run", "two.bin", "--start", "0x1_0000"],
    );
    assert_eq!(bad_address.status.code(), Some(2));
    insta::assert_snapshot!("emu_bad_start", transcript(&bad_address));
    let bad_cycles = scorpion(
        dir.path(),
        &["emu", "run", "two.bin", "--max-cycles", "lots"],
    );
    assert_eq!(bad_cycles.status.code(), Some(2));
    insta::assert_snapshot!("emu_bad_cycles", transcript(&bad_cycles));
}

/// fresh11 F11: `emu run` of a linked image (an ELF) ran its header as
/// code; it is refused, saying what runs one.
#[test]
fn emu_run_refuses_an_elf_file() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("image.elf"), b"\x7fELF\x01\x01\x01\0rest").expect("write");
    let output = scorpion(dir.path(), &["emu", "run", "image.elf"]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    assert!(
        transcript(&output).contains("image.elf is an ELF file")
            && transcript(&output).contains("scorpion debug --image"),
        "{}",
        transcript(&output)
    );
}
