//! The assembler benchmark: a generated program of 200,000 lines (every
//! documented addressing mode, labels, cheap locals, unnamed labels,
//! expressions, a macro, data) in `.org $1000` chunks under 64 KiB,
//! assembled and linked into one binary by
//!
//! - ca65 + ld65 (Debian's cc65; a memory area of `size = $1000000`),
//! - 64tass (Debian's; the same program in its syntax, `--flat`),
//! - us: `assembler::assemble` reading the file from disk, `linker::link`
//!   with a custom layout whose area is large enough, the binary written to
//!   disk (what `scorpion build` does),
//!
//! in the same run, in interleaved rounds (so that other load on the
//! machine falls on all three alike), printing each wall time (median and
//! best of the rounds), lines per second and our ratios, and checking that
//! the three binaries are identical.
//!
//! Every tool runs as a fresh process, ours included: this binary starts
//! itself again for each measurement and the child times its own work
//! (process start-up excluded, page faults included). Timing ours in one
//! long-lived process instead flatters small programs, whose memory the
//! allocator hands back warm, against large ones, which get fresh pages
//! from the kernel every time.
//!
//! Then the linearity table: the same generator at 12,500 to 1,600,000
//! lines, our time split into assembling, linking and writing, 64tass
//! (and ca65 + ld65 up to 100,000 lines) beside it, and for each the
//! exponent of a least-squares fit of log(time) against log(lines): 1.00
//! is linear, 2.00 quadratic. The last line names the part that grows.
//!
//! Last, the error case: a file defining 20,000 symbols that uses 300
//! names it never defines (each error with its "did you mean"), assembled
//! by ca65 and by us, each failing, each a fresh process; the ratio of
//! the medians (issue 24: ours must stay within twice ca65's time).
//!
//! Run: `cargo bench -p scorpion-tests --bench asm_200k`
//! (`ASM_BENCH_RUNS=N` sets the rounds, default 9; `ASM_BENCH_MAX_LINES=N`
//! caps the linearity sizes, default 1,600,000; `ASM_BENCH_OURS_ONLY=1`
//! skips the peers; `ASM_BENCH_KEEP=1` keeps the generated sources and
//! prints where; `ASM_BENCH_ERRORS_ONLY=1` runs only the error case).

#[path = "../tests/asm_gen/mod.rs"]
mod asm_gen;

use std::path::{Path, PathBuf};
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

/// Set in the child: `SOURCE` and `OUTPUT` paths, tab-separated.
const CHILD_VAR: &str = "ASM_BENCH_CHILD";

/// Set in the error case's child: the failing source's path.
const ERRORS_CHILD_VAR: &str = "ASM_BENCH_ERRORS_CHILD";

/// The error case: symbols defined, and names used but never defined.
const ERROR_CASE: (usize, usize) = (20_000, 300);

/// The linearity sizes (capped by `ASM_BENCH_MAX_LINES`).
const SIZES: [usize; 8] = [
    12_500, 25_000, 50_000, 100_000, 200_000, 400_000, 800_000, 1_600_000,
];

/// ca65 is quadratic: beyond this it would take minutes per run.
const CA65_MAX_LINES: usize = 100_000;

/// One of our runs, timed in a fresh process.
#[derive(Debug, Clone, Copy, Default)]
struct OurRun {
    assemble: Duration,
    link: Duration,
    write: Duration,
    /// Peak resident memory of the child, when the system says.
    peak_kib: Option<u64>,
}

impl OurRun {
    fn total(&self) -> Duration {
        self.assemble + self.link + self.write
    }
}

/// Our whole pipeline from source file to binary file, in phases.
fn ours(source: &Path, out: &Path) -> (Vec<u8>, [Duration; 3]) {
    let layout =
        linker::Layout::from_toml("benchmark.toml", LAYOUT).expect("the benchmark layout parses");
    let target = linker::Target::Custom(layout);
    let start = Instant::now();
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
    let assembled = Instant::now();
    let name = source.display().to_string();
    let linked = linker::link(
        &[linker::Input {
            name: &name,
            bytes: &assembly.object,
        }],
        &linker::LinkOptions {
            target: &target,
            just_symbols: &[],
            sources: &linker::NoSources,
        },
    )
    .unwrap_or_else(|error| panic!("our linker failed: {error:?}"));
    let link_done = Instant::now();
    let binary = linker::Format::Bin
        .write(&linked.image)
        .unwrap_or_else(|error| panic!("cannot write the binary: {error:?}"));
    std::fs::write(out, &binary).expect("write our binary");
    let written = Instant::now();
    (
        binary,
        [
            assembled - start,
            link_done - assembled,
            written - link_done,
        ],
    )
}

/// The child's side: one timed run, the phases in nanoseconds on stdout.
#[allow(clippy::print_stdout, reason = "the child reports to its parent")]
fn child(spec: &str) {
    let (source, out) = spec
        .split_once('\t')
        .expect("ASM_BENCH_CHILD is `SOURCE<tab>OUTPUT`");
    let (_, phases) = ours(Path::new(source), Path::new(out));
    // The high-water mark of resident memory, from Linux's status file.
    let peak = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
            line.split_whitespace().nth(1)?.parse::<u64>().ok()
        })
        .unwrap_or(0);
    println!(
        "{} {} {} {peak}",
        phases[0].as_nanos(),
        phases[1].as_nanos(),
        phases[2].as_nanos()
    );
}

/// One run of ours in a fresh process (this binary in child mode).
fn ours_fresh(source: &Path, out: &Path) -> OurRun {
    // A new file each time: ext4 flushes a file that is truncated and
    // written again when it is closed, a disk wait that is not ours.
    let _ = std::fs::remove_file(out);
    let exe = std::env::current_exe().expect("the benchmark knows its own path");
    let output = Command::new(exe)
        .env(
            CHILD_VAR,
            format!("{}\t{}", source.display(), out.display()),
        )
        .output()
        .expect("the benchmark starts itself");
    assert!(
        output.status.success(),
        "our run failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8_lossy(&output.stdout);
    let numbers: Vec<u64> = text
        .split_whitespace()
        .map(|n| n.parse().expect("the child prints numbers"))
        .collect();
    assert!(numbers.len() == 4, "the child printed `{text}`");
    OurRun {
        assemble: Duration::from_nanos(numbers[0]),
        link: Duration::from_nanos(numbers[1]),
        write: Duration::from_nanos(numbers[2]),
        peak_kib: (numbers[3] > 0).then_some(numbers[3]),
    }
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

fn timed(command: &mut Command, what: &str) -> Duration {
    let start = Instant::now();
    run(command, what);
    start.elapsed()
}

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times.get(times.len() / 2).copied().unwrap_or_default()
}

fn best(times: &[Duration]) -> Duration {
    times.iter().copied().min().unwrap_or_default()
}

fn seconds(duration: Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

fn ns_per_line(time: Duration, lines: usize) -> f64 {
    time.as_secs_f64() * 1e9 / lines as f64
}

/// The slope of the least-squares line through (ln lines, ln seconds):
/// the exponent `k` in time = c * lines^k.
fn exponent(points: &[(usize, Duration)]) -> Option<f64> {
    let points: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, time)| !time.is_zero())
        .map(|&(lines, time)| ((lines as f64).ln(), time.as_secs_f64().ln()))
        .collect();
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let mean_x = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
    let covariance: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let variance: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    (variance > 0.0).then(|| covariance / variance)
}

fn env_number(name: &str) -> Option<usize> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// A generated program written to `dir` in both syntaxes.
struct Written {
    /// The size asked for.
    size: usize,
    /// The lines written (a little more: the generator ends its block).
    lines: usize,
    ca65: PathBuf,
    tass: PathBuf,
    ca65_bytes: usize,
}

fn write_program(dir: &Path, lines: usize) -> Written {
    let program = asm_gen::generate(2024, lines, asm_gen::Flavor::Benchmark);
    let (_, text) = &program.files[0];
    let ca65 = dir.join(format!("bench{lines}.s"));
    let tass = dir.join(format!("bench{lines}.asm"));
    std::fs::write(&ca65, text).expect("write the ca65 source");
    std::fs::write(&tass, &program.tass).expect("write the 64tass source");
    Written {
        size: lines,
        lines: program.lines,
        ca65,
        tass,
        ca65_bytes: text.len(),
    }
}

/// The outside tools, when they are there and wanted.
struct Peers {
    ca65: Option<(PathBuf, PathBuf)>,
    tass: Option<PathBuf>,
}

impl Peers {
    fn tass(&self, dir: &Path, source: &Path) -> Option<Command> {
        let tass = self.tass.as_ref()?;
        let mut command = Command::new(tass);
        command.current_dir(dir).arg("-q").arg("--flat");
        command.arg("-o").arg(dir.join("64tass.bin")).arg(source);
        Some(command)
    }

    /// ca65 then ld65 on `source`, timed together.
    fn cc65(&self, dir: &Path, source: &Path) -> Option<Duration> {
        let (ca65, ld65) = self.ca65.as_ref()?;
        let object = dir.join("bench.o");
        let start = Instant::now();
        run(
            Command::new(ca65)
                .current_dir(dir)
                .arg(source)
                .arg("-o")
                .arg(&object),
            "ca65",
        );
        run(
            Command::new(ld65)
                .current_dir(dir)
                .args(["-C", "bench.cfg", "-o", "ld65.bin"])
                .arg(&object),
            "ld65",
        );
        Some(start.elapsed())
    }
}

#[allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
fn main() {
    if let Ok(spec) = std::env::var(CHILD_VAR) {
        child(&spec);
        return;
    }
    if let Ok(source) = std::env::var(ERRORS_CHILD_VAR) {
        errors_child(Path::new(&source));
        return;
    }
    let runs = env_number("ASM_BENCH_RUNS").unwrap_or(9).max(1);
    if std::env::var_os("ASM_BENCH_ERRORS_ONLY").is_some() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        error_case(dir.path(), runs);
        return;
    }
    let max_lines = env_number("ASM_BENCH_MAX_LINES").unwrap_or(1_600_000);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let dir_path = dir.path().to_path_buf();
    std::fs::write(dir_path.join("bench.cfg"), LD65_CONFIG).expect("write the ld65 config");
    let wanted = std::env::var_os("ASM_BENCH_OURS_ONLY").is_none();
    let peers = Peers {
        ca65: wanted
            .then(|| {
                let ca65 = scorpion_tests::tools::require("ca65", "asm_200k")?;
                let ld65 = scorpion_tests::tools::require("ld65", "asm_200k")?;
                Some((ca65, ld65))
            })
            .flatten(),
        tass: wanted
            .then(|| scorpion_tests::tools::require("64tass", "asm_200k"))
            .flatten(),
    };

    let main = write_program(&dir_path, 200_000);
    let cc65_runs = runs.min(3);
    println!(
        "asm_200k: {} lines ({} KiB of source); rounds of scorpion, 64tass and ca65+ld65 interleaved \
         ({runs} rounds, ca65 in the first {cc65_runs}), every run a fresh process",
        main.lines,
        main.ca65_bytes / 1024,
    );
    let our_out = dir_path.join("ours.bin");
    // Warm-up (page cache) for every tool.
    ours_fresh(&main.ca65, &our_out);
    if let Some(mut command) = peers.tass(&dir_path, &main.tass) {
        run(&mut command, "64tass");
    }
    let (mut our_runs, mut tass_times, mut cc65_times) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..runs {
        our_runs.push(ours_fresh(&main.ca65, &our_out));
        if let Some(mut command) = peers.tass(&dir_path, &main.tass) {
            tass_times.push(timed(&mut command, "64tass"));
        }
        if round < cc65_runs
            && let Some(time) = peers.cc65(&dir_path, &main.ca65)
        {
            cc65_times.push(time);
        }
    }
    let our_binary = std::fs::read(&our_out).expect("our binary was written");
    let lines_per_second = |time: Duration| main.lines as f64 / time.as_secs_f64();
    let our_times: Vec<Duration> = our_runs.iter().map(OurRun::total).collect();
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
        let binary = std::fs::read(dir_path.join("ld65.bin")).expect("ld65 wrote its output");
        compare("ca65 + ld65:", &cc65_times, &binary);
        assert!(binary == our_binary, "ld65's binary differs from ours");
    }
    if !tass_times.is_empty() {
        let binary = std::fs::read(dir_path.join("64tass.bin")).expect("64tass wrote its output");
        compare("64tass:", &tass_times, &binary);
        assert!(binary == our_binary, "64tass's binary differs from ours");
    }
    if !cc65_times.is_empty() && !tass_times.is_empty() {
        println!("  the three binaries are identical");
    }
    let phase = |pick: fn(&OurRun) -> Duration| median(our_runs.iter().map(pick).collect());
    println!(
        "  scorpion's phases (median): assemble {}, link {}, write {}",
        seconds(phase(|r| r.assemble)),
        seconds(phase(|r| r.link)),
        seconds(phase(|r| r.write)),
    );

    linearity(&dir_path, &peers, runs, max_lines, (main.size, &cc65_times));
    error_case(&dir_path, runs);

    if std::env::var_os("ASM_BENCH_KEEP").is_some() {
        println!("sources kept in {}", dir.keep().display());
    }
}

/// The linearity table and the fitted exponents.
#[allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
fn linearity(
    dir: &Path,
    peers: &Peers,
    runs: usize,
    max_lines: usize,
    main_cc65: (usize, &[Duration]),
) {
    let programs: Vec<Written> = SIZES
        .iter()
        .filter(|&&size| size <= max_lines)
        .map(|&size| write_program(dir, size))
        .collect();
    println!(
        "linearity: the same generator at each size; {runs} rounds, each running every size once (so that \
         a slow spell of the machine falls on all sizes alike); every run a fresh process; best of the rounds"
    );
    // One output file per size: overwriting a large binary with a small
    // one would charge the small run for the truncation.
    let out = |program: &Written| dir.join(format!("lines{}.bin", program.size));
    // Warm-up: the page cache holds every source.
    for program in &programs {
        ours_fresh(&program.ca65, &out(program));
    }
    let mut our_best: Vec<Option<OurRun>> = vec![None; programs.len()];
    let mut tass_times: Vec<Vec<Duration>> = vec![Vec::new(); programs.len()];
    for _ in 0..runs {
        for (i, program) in programs.iter().enumerate() {
            let run = ours_fresh(&program.ca65, &out(program));
            if our_best[i].is_none_or(|best| run.total() < best.total()) {
                our_best[i] = Some(run);
            }
            if let Some(mut command) = peers.tass(dir, &program.tass) {
                tass_times[i].push(timed(&mut command, "64tass"));
            }
        }
    }
    println!(
        "      lines   scorpion  ns/line  (assemble   link  write)  peak MiB     64tass  ns/line   ca65+ld65  ns/line"
    );
    let (mut ours_points, mut tass_points, mut cc65_points) = (Vec::new(), Vec::new(), Vec::new());
    let mut phase_points: [Vec<(usize, Duration)>; 3] = Default::default();
    for ((program, our), tass) in programs.iter().zip(our_best).zip(&tass_times) {
        let lines = program.lines;
        let our = our.unwrap_or_default();
        ours_points.push((lines, our.total()));
        for (points, time) in phase_points
            .iter_mut()
            .zip([our.assemble, our.link, our.write])
        {
            points.push((lines, time));
        }
        let tass = (!tass.is_empty()).then(|| best(tass));
        if let Some(time) = tass {
            tass_points.push((lines, time));
        }
        // ca65 is too slow to repeat: one run per size up to its limit,
        // the main comparison's runs at 200,000 lines.
        let cc65 = if program.size == main_cc65.0 {
            (!main_cc65.1.is_empty()).then(|| best(main_cc65.1))
        } else if program.size <= CA65_MAX_LINES {
            peers.cc65(dir, &program.ca65)
        } else {
            None
        };
        if let Some(time) = cc65 {
            cc65_points.push((lines, time));
        }
        let peer = |time: Option<Duration>| {
            time.map_or_else(
                || format!("{:>10}  {:>7}", "-", "-"),
                |t| format!("{:>10}  {:>7.0}", seconds(t), ns_per_line(t, lines)),
            )
        };
        println!(
            "  {lines:>9}  {:>9}  {:>7.0}  ({:>8.0} {:>6.0} {:>6.0})  {:>8}  {}  {}",
            seconds(our.total()),
            ns_per_line(our.total(), lines),
            ns_per_line(our.assemble, lines),
            ns_per_line(our.link, lines),
            ns_per_line(our.write, lines),
            our.peak_kib.map_or_else(
                || "-".to_string(),
                |kib| format!("{:.0}", kib as f64 / 1024.0)
            ),
            peer(tass),
            peer(cc65),
        );
    }
    let show = |points: &[(usize, Duration)]| {
        exponent(points).map_or_else(|| "-".to_string(), |k| format!("{k:.2}"))
    };
    println!(
        "  fitted exponent of time against lines (log-log least squares; 1.00 = linear, 2.00 = quadratic):"
    );
    println!(
        "    scorpion {} (assemble {}, link {}, write {}); 64tass {}; ca65+ld65 {} (up to {} lines)",
        show(&ours_points),
        show(&phase_points[0]),
        show(&phase_points[1]),
        show(&phase_points[2]),
        show(&tass_points),
        show(&cc65_points),
        cc65_points.last().map_or(0, |p| p.0),
    );
    // Which of our parts grows: the one whose time per line rose most
    // from the smallest size to the largest, if the whole grows at all.
    let names = ["assembling", "linking", "writing"];
    let per_line = |points: &[(usize, Duration)]| -> Option<(f64, f64)> {
        let (first, last) = (points.first()?, points.last()?);
        Some((ns_per_line(first.1, first.0), ns_per_line(last.1, last.0)))
    };
    let worst = names
        .iter()
        .zip(&phase_points)
        .filter_map(|(name, points)| Some((*name, per_line(points)?)))
        .max_by(|a, b| (a.1.1 - a.1.0).total_cmp(&(b.1.1 - b.1.0)));
    let (Some(k), Some((small, large)), Some((part, (from, to)))) =
        (exponent(&ours_points), per_line(&ours_points), worst)
    else {
        return;
    };
    let (first, last) = (ours_points[0].0, ours_points[ours_points.len() - 1].0);
    if k <= 1.02 {
        println!(
            "  what grows: nothing measurable (exponent {k:.2}); {small:.0} ns/line at {first} lines, \
             {large:.0} at {last}"
        );
    } else {
        println!(
            "  what grows: {small:.0} -> {large:.0} ns/line from {first} to {last} lines ({:.2}x per doubling), \
             most of it in {part} ({from:.0} -> {to:.0} ns/line); why: assembler/README.md, \"Linearity\"",
            2f64.powf(k - 1.0)
        );
    }
}

/// The error case's source: `defined` constants and labels, then `used`
/// lines naming a symbol that is not defined (a near miss of a defined
/// name every other time, so "did you mean" has something to find).
fn error_source(defined: usize, used: usize) -> String {
    let mut text = String::with_capacity(defined * 24 + used * 24);
    for n in 0..defined {
        if n % 2 == 0 {
            text.push_str(&format!("value_{n:05} = {}\n", n % 256));
        } else {
            text.push_str(&format!("label_{n:05}: nop\n"));
        }
    }
    for n in 0..used {
        if n % 2 == 0 {
            text.push_str(&format!("        lda valeu_{:05}\n", (n * 37) % defined));
        } else {
            text.push_str(&format!("        jmp missing_name_{n}\n"));
        }
    }
    text
}

/// The error case's child: one timed assembly that must fail, its time in
/// nanoseconds on stdout.
#[allow(clippy::print_stdout, reason = "the child reports to its parent")]
fn errors_child(source: &Path) {
    let start = Instant::now();
    let result = assembler::assemble(&assembler::FsSource, source, &assembler::Options::default());
    let elapsed = start.elapsed();
    assert!(result.is_err(), "the error case assembled");
    println!("{}", elapsed.as_nanos());
}

/// A file with errors: ca65 and us, each failing, fresh processes,
/// interleaved; the ratio of the medians.
#[allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]
fn error_case(dir: &Path, runs: usize) {
    let (defined, used) = ERROR_CASE;
    let source = dir.join("errors.s");
    std::fs::write(&source, error_source(defined, used)).expect("write the error case");
    let ca65 = scorpion_tests::tools::require("ca65", "asm_200k (error case)");
    let exe = std::env::current_exe().expect("the benchmark knows its own path");
    let (mut ours, mut theirs) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let output = Command::new(&exe)
            .env(ERRORS_CHILD_VAR, &source)
            .output()
            .expect("the benchmark starts itself");
        assert!(
            output.status.success(),
            "our error run failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let nanos: u64 = String::from_utf8_lossy(&output.stdout)
            .trim()
            .parse()
            .expect("the child prints a number");
        ours.push(Duration::from_nanos(nanos));
        if let Some(ca65) = &ca65 {
            let start = Instant::now();
            let status = Command::new(ca65)
                .arg(&source)
                .args(["-o", "/dev/null"])
                .output()
                .expect("ca65 runs");
            theirs.push(start.elapsed());
            assert!(!status.status.success(), "ca65 accepted the error case");
        }
    }
    let our_median = median(ours);
    println!(
        "error case ({defined} symbols defined, {used} undefined names used, each with a suggestion): \
         scorpion {} (median of {runs})",
        seconds(our_median)
    );
    if !theirs.is_empty() {
        let their_median = median(theirs);
        println!(
            "  ca65 {} -> scorpion takes {:.2}x ca65's time (the target: at most 2x)",
            seconds(their_median),
            our_median.as_secs_f64() / their_median.as_secs_f64()
        );
    }
}
