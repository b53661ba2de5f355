//! The assembler benchmark: a generated program of 200,000 lines (every
//! documented addressing mode, labels, cheap locals, unnamed labels,
//! expressions, a macro, data) in `.org $1000` chunks under 64 KiB,
//! assembled and linked into one binary by
//!
//! - ca65 + ld65 (Debian's cc65; a memory area of `size = $1000000`),
//! - 64tass (Debian's; the same program in its syntax, `--flat`),
//! - us: `assembler::assemble` reading the file from disk, `linker::link`
//!   with a custom layout whose area is large enough, the binary written to
//!   disk (what `scorpion build` does, minus process start-up),
//!
//! in the same run, printing each wall time (median of several runs), lines
//! per second and our ratios, checking that the three binaries are
//! identical, and timing us at 25k, 50k, 100k and 200k lines to show that
//! the time per line stays flat (linear time).
//!
//! Run: `cargo bench -p scorpion-tests --bench asm_200k`
//! (`ASM_BENCH_RUNS=N` sets the repetitions, ca65 taking seconds per run;
//! `ASM_BENCH_OURS_ONLY=1` skips the peers; `ASM_BENCH_KEEP=1` keeps the
//! generated sources and prints where).

#[path = "../tests/asm_gen/mod.rs"]
mod asm_gen;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

const LAYOUT: &str = r#"
name = "benchmark: one big area, as ld65 with size = $1000000"

[[area]]
name = "MAIN"
start = "$1000"
size = "$1000000"

[[segment]]
name = "CODE"
load = "MAIN"
kind = "rw"
"#;

const LD65_CONFIG: &str = "MEMORY { MAIN: start = $1000, size = $1000000, file = %O; }
SEGMENTS { CODE: load = MAIN, type = rw; }
";

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn run(command: &mut Command, what: &str) {
    let output = command
        .output()
        .unwrap_or_else(|error| panic!("{what} does not start: {error}"));
    assert!(
        output.status.success(),
        "{what} failed:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Our whole pipeline from source file to binary file.
fn ours(source: &Path, out: &Path, target: &linker::Target) -> Vec<u8> {
    let assembly =
        assembler::assemble(&assembler::FsSource, source, &assembler::Options::default())
            .unwrap_or_else(|error| {
                let first: Vec<String> = error
                    .diagnostics()
                    .iter()
                    .take(5)
                    .map(assembler::Diagnostic::summary)
                    .collect();
                panic!(
                    "our assembler rejected the benchmark: {error}\n{}",
                    first.join("\n")
                )
            });
    let name = source.display().to_string();
    let linked = linker::link(
        &[linker::Input {
            name: &name,
            bytes: &assembly.object,
        }],
        &linker::LinkOptions {
            target,
            just_symbols: &[],
            sources: &linker::NoSources,
        },
    )
    .unwrap_or_else(|error| panic!("our linker failed: {error:?}"));
    let binary = linker::Format::Bin
        .write(&linked.image)
        .unwrap_or_else(|error| panic!("cannot write the binary: {error:?}"));
    std::fs::write(out, &binary).expect("write our binary");
    binary
}

fn time_ours(
    source: &Path,
    out: &Path,
    target: &linker::Target,
    runs: usize,
) -> (Duration, Vec<u8>) {
    let mut binary = ours(source, out, target); // warm-up
    let times = (0..runs)
        .map(|_| {
            let start = Instant::now();
            binary = ours(source, out, target);
            start.elapsed()
        })
        .collect();
    (median(times), binary)
}

fn seconds(duration: Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

#[allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
fn main() {
    let runs: usize = std::env::var("ASM_BENCH_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5)
        .max(1);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let layout =
        linker::Layout::from_toml("benchmark.toml", LAYOUT).expect("the benchmark layout parses");
    let target = linker::Target::Custom(layout);

    let program = asm_gen::generate(2024, 200_000, asm_gen::Flavor::Benchmark);
    let (_, ca65_text) = &program.files[0];
    let source = dir.path().join("bench.s");
    std::fs::write(&source, ca65_text).expect("write the ca65 source");
    std::fs::write(dir.path().join("bench.asm"), &program.tass).expect("write the 64tass source");
    std::fs::write(dir.path().join("bench.cfg"), LD65_CONFIG).expect("write the ld65 config");
    println!(
        "asm_200k: {} lines ({} KiB of source), {} runs each, median wall time",
        program.lines,
        ca65_text.len() / 1024,
        runs
    );

    let (our_time, our_binary) = time_ours(&source, &dir.path().join("ours.bin"), &target, runs);
    let lines_per_second = |time: Duration| program.lines as f64 / time.as_secs_f64();
    println!(
        "  scorpion (assemble + link): {:>9}  {:>10.0} lines/s  {} bytes",
        seconds(our_time),
        lines_per_second(our_time),
        our_binary.len()
    );

    // Where our time goes.
    let assemble_only = median(
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                let assembly = assembler::assemble(
                    &assembler::FsSource,
                    &source,
                    &assembler::Options::default(),
                );
                assert!(assembly.is_ok(), "the benchmark assembles");
                start.elapsed()
            })
            .collect(),
    );
    println!(
        "    of which assembling:       {:>9}  {:>10.0} lines/s",
        seconds(assemble_only),
        lines_per_second(assemble_only)
    );

    let peers = std::env::var_os("ASM_BENCH_OURS_ONLY").is_none();
    let ca65 = peers
        .then(|| scorpion_tests::tools::require("ca65", "asm_200k"))
        .flatten();
    let ld65 = peers
        .then(|| scorpion_tests::tools::require("ld65", "asm_200k"))
        .flatten();
    let tass = peers
        .then(|| scorpion_tests::tools::require("64tass", "asm_200k"))
        .flatten();

    if let (Some(ca65), Some(ld65)) = (&ca65, &ld65) {
        let cc65_runs = runs.min(3);
        let times: Vec<Duration> = (0..cc65_runs)
            .map(|_| {
                let start = Instant::now();
                run(
                    Command::new(ca65)
                        .current_dir(dir.path())
                        .args(["bench.s", "-o", "bench.o"]),
                    "ca65",
                );
                run(
                    Command::new(ld65).current_dir(dir.path()).args([
                        "-C",
                        "bench.cfg",
                        "-o",
                        "ld65.bin",
                        "bench.o",
                    ]),
                    "ld65",
                );
                start.elapsed()
            })
            .collect();
        let time = median(times);
        let binary = std::fs::read(dir.path().join("ld65.bin")).expect("ld65 wrote its output");
        println!(
            "  ca65 + ld65:                {:>9}  {:>10.0} lines/s  {} bytes  -> scorpion is {:.1}x faster",
            seconds(time),
            lines_per_second(time),
            binary.len(),
            time.as_secs_f64() / our_time.as_secs_f64()
        );
        assert!(binary == our_binary, "ld65's binary differs from ours");
    }
    if let Some(tass) = &tass {
        let times: Vec<Duration> = (0..runs)
            .map(|_| {
                let start = Instant::now();
                run(
                    Command::new(tass).current_dir(dir.path()).args([
                        "-q",
                        "--flat",
                        "-o",
                        "64tass.bin",
                        "bench.asm",
                    ]),
                    "64tass",
                );
                start.elapsed()
            })
            .collect();
        let time = median(times);
        let binary = std::fs::read(dir.path().join("64tass.bin")).expect("64tass wrote its output");
        println!(
            "  64tass:                     {:>9}  {:>10.0} lines/s  {} bytes  -> scorpion is {:.2}x faster",
            seconds(time),
            lines_per_second(time),
            binary.len(),
            time.as_secs_f64() / our_time.as_secs_f64()
        );
        assert!(binary == our_binary, "64tass's binary differs from ours");
    }
    if ca65.is_some() && ld65.is_some() && tass.is_some() {
        println!("  the three binaries are identical");
    }

    println!("linearity (scorpion, same generator, median of {runs}):");
    let mut per_line = Vec::new();
    for lines in [25_000, 50_000, 100_000, 200_000] {
        let program = asm_gen::generate(2024, lines, asm_gen::Flavor::Benchmark);
        let path = dir.path().join(format!("lines{lines}.s"));
        std::fs::write(&path, &program.files[0].1).expect("write a source");
        let (time, _) = time_ours(&path, &dir.path().join("lines.bin"), &target, runs);
        let nanos = time.as_secs_f64() * 1e9 / program.lines as f64;
        per_line.push(nanos);
        println!(
            "  {:>7} lines: {:>9}  {:>6.0} ns/line",
            program.lines,
            seconds(time),
            nanos
        );
    }
    let spread = per_line.iter().copied().fold(f64::MIN, f64::max)
        / per_line.iter().copied().fold(f64::MAX, f64::min);
    println!(
        "  time per line varies by {spread:.2}x from 25k to 200k lines (1.00 = perfectly linear)"
    );
    if std::env::var_os("ASM_BENCH_KEEP").is_some() {
        println!("sources kept in {}", dir.keep().display());
    }
}
