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
//! in the same run, in interleaved rounds (so that other load on the
//! machine falls on all three alike), printing each wall time (median and
//! best of the rounds), lines per second and our ratios, checking that the
//! three binaries are identical, and timing us at 25k, 50k, 100k and 200k
//! lines to show that the time per line stays flat (linear time).
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

/// Our best time over `runs` (after a warm-up): the least disturbed by
/// other load, for the linearity table.
fn time_ours(source: &Path, out: &Path, target: &linker::Target, runs: usize) -> Duration {
    ours(source, out, target);
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            ours(source, out, target);
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
}

fn seconds(duration: Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

#[allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
fn main() {
    let runs: usize = std::env::var("ASM_BENCH_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(9)
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
    let cc65_runs = runs.min(3);
    println!(
        "asm_200k: {} lines ({} KiB of source); rounds of scorpion, 64tass and ca65+ld65 interleaved \
         ({runs} rounds, ca65 in the first {cc65_runs}) so that load on the machine hits all alike",
        program.lines,
        ca65_text.len() / 1024,
    );

    // Warm-up (file cache, page faults) for every tool.
    let mut our_binary = ours(&source, &dir.path().join("ours.bin"), &target);
    let tass_command = |tass: &Path| {
        let mut command = Command::new(tass);
        command
            .current_dir(dir.path())
            .args(["-q", "--flat", "-o", "64tass.bin", "bench.asm"]);
        command
    };
    if let Some(tass) = &tass {
        run(&mut tass_command(tass), "64tass");
    }
    let (mut our_times, mut tass_times, mut cc65_times) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..runs {
        let start = Instant::now();
        our_binary = ours(&source, &dir.path().join("ours.bin"), &target);
        our_times.push(start.elapsed());
        if let Some(tass) = &tass {
            let start = Instant::now();
            run(&mut tass_command(tass), "64tass");
            tass_times.push(start.elapsed());
        }
        if let (Some(ca65), Some(ld65)) = (&ca65, &ld65)
            && round < cc65_runs
        {
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
            cc65_times.push(start.elapsed());
        }
    }
    let lines_per_second = |time: Duration| program.lines as f64 / time.as_secs_f64();
    let best = |times: &[Duration]| times.iter().copied().min().unwrap_or_default();
    let (our_median, our_best) = (median(our_times.clone()), best(&our_times));
    println!("                              median     lines/s      best   output");
    println!(
        "  scorpion (assemble + link): {:>9}  {:>10.0}  {:>9}  {} bytes",
        seconds(our_median),
        lines_per_second(our_median),
        seconds(our_best),
        our_binary.len()
    );
    let compare = |name: &str, times: &[Duration], binary: &[u8]| {
        let (time, fastest) = (median(times.to_vec()), best(times));
        println!(
            "  {name:<27} {:>9}  {:>10.0}  {:>9}  {} bytes  -> scorpion is {:.2}x faster (median), {:.2}x (best)",
            seconds(time),
            lines_per_second(time),
            seconds(fastest),
            binary.len(),
            time.as_secs_f64() / our_median.as_secs_f64(),
            fastest.as_secs_f64() / our_best.as_secs_f64()
        );
    };
    if !cc65_times.is_empty() {
        let binary = std::fs::read(dir.path().join("ld65.bin")).expect("ld65 wrote its output");
        compare("ca65 + ld65:", &cc65_times, &binary);
        assert!(binary == our_binary, "ld65's binary differs from ours");
    }
    if !tass_times.is_empty() {
        let binary = std::fs::read(dir.path().join("64tass.bin")).expect("64tass wrote its output");
        compare("64tass:", &tass_times, &binary);
        assert!(binary == our_binary, "64tass's binary differs from ours");
    }
    if !cc65_times.is_empty() && !tass_times.is_empty() {
        println!("  the three binaries are identical");
    }

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
        "  scorpion's assembling alone: {:>9}  {:>10.0} lines/s (median)",
        seconds(assemble_only),
        lines_per_second(assemble_only)
    );

    println!("linearity (scorpion, same generator, best of {runs}):");
    let mut per_line = Vec::new();
    for lines in [25_000, 50_000, 100_000, 200_000] {
        let program = asm_gen::generate(2024, lines, asm_gen::Flavor::Benchmark);
        let path = dir.path().join(format!("lines{lines}.s"));
        std::fs::write(&path, &program.files[0].1).expect("write a source");
        let time = time_ours(&path, &dir.path().join("lines.bin"), &target, runs);
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
