//! Issue 6's benchmark: device time (emulated seconds on the virtual
//! Scorpion, the reference ROM at real baud timing) to upload and fully
//! verify a 2 KiB extension at 9600 baud, through the ROM's commands and
//! through the RAM loader (with and without its switch to 19200 baud),
//! printed beside the line-rate bound (bytes x 10 / baud) and the
//! ROM-only bound (11 characters per 2 bytes).
//!
//! `cargo bench -p uploader` (a `harness = false` bench). Device time is
//! deterministic, so one run of each is the figure. The target (issue 27:
//! 1.15x, issue 6's was 1.3x) is for the loader switching the line to
//! 19200 baud, as esptool's stub raises the rate (the lead's decision);
//! the loader at a line kept at 9600 is printed too, and does not meet it.
//! Issue 27's one-byte change to the installed extension is measured
//! against one second of robot time. `cargo run -p uploader
//! --release --example trace` shows where each run's time goes.

#![allow(clippy::print_stdout, reason = "a benchmark prints its figures")]

use std::time::{Duration, Instant};

use uploader::transport::{VirtualTransport, char_time};
use uploader::{Backup, Keep, LoaderChoice, NoProgress, UploadOptions, UploadReport};

#[path = "../tests/common/image.rs"]
mod image;

use image::{extension, one_byte_changed};

const BYTES: usize = 2048;
const BAUD: u32 = 9600;

fn upload(options: &UploadOptions) -> (UploadReport, Duration) {
    let started = Instant::now();
    let mut client = uploader::client(VirtualTransport::default(), &options.profile);
    let report = uploader::upload(&mut client, &extension(BYTES, 0), options, &mut NoProgress)
        .unwrap_or_else(|error| panic!("the benchmark upload failed: {error}"));
    (report, started.elapsed())
}

/// Keeps what an upload overwrote, as `scorpion upload` does for
/// `--undo` (its file aside).
#[derive(Default)]
struct Undo(usize);

impl Keep for Undo {
    fn keep(&mut self, overwritten: &Backup) {
        self.0 = overwritten.len();
    }
}

fn main() {
    let line_bound = char_time(BYTES, BAUD);
    let rom_bound = char_time(BYTES / 2 * 11, BAUD);
    println!(
        "upload and verify {BYTES} bytes on the virtual Scorpion at {BAUD} baud (device time)"
    );
    println!(
        "  line-rate bound (bytes x 10 / baud):     {:>7.3} s",
        line_bound.as_secs_f64()
    );
    println!(
        "  ROM-only bound (11 chars per 2 bytes):   {:>7.3} s",
        rom_bound.as_secs_f64()
    );
    println!();
    println!(
        "  {:<34} {:>9} {:>10} {:>10} {:>8} {:>8}",
        "path", "device s", "x line", "x ROM-only", "chars", "wall ms"
    );
    let runs = [
        (
            "ROM only (/9W, /7R)",
            LoaderChoice::Never,
            None,
            Some(rom_bound),
            1.1,
        ),
        (
            "RAM loader, line kept at 9600",
            LoaderChoice::Always,
            None,
            None,
            f64::INFINITY,
        ),
        (
            "RAM loader, line at 19200",
            LoaderChoice::Always,
            Some(uploader::FAST_BAUD),
            None,
            1.15,
        ),
    ];
    let mut missed = Vec::new();
    for (name, loader, fast_baud, against_rom, target) in runs {
        let options = UploadOptions {
            loader,
            fast_baud,
            ..UploadOptions::default()
        };
        let (report, wall) = upload(&options);
        let seconds = report.device_time.as_secs_f64();
        let x_line = seconds / line_bound.as_secs_f64();
        let x_rom = seconds / rom_bound.as_secs_f64();
        println!(
            "  {name:<34} {seconds:>9.3} {x_line:>9.3}x {x_rom:>9.3}x {:>8} {:>8}",
            report.chars_sent + report.chars_received,
            wall.as_millis()
        );
        let ratio = if against_rom.is_some() { x_rom } else { x_line };
        if ratio > target {
            missed.push(format!("{name}: {ratio:.3}x, target {target}x"));
        }
    }
    // Issue 27: the full upload within 1.15x of the line-rate bound, and
    // a one-byte change to the installed extension (at 9600 baud, the
    // loader switching to 19200) within one second of robot time.
    let options = UploadOptions {
        replace: true,
        ..UploadOptions::default()
    };
    let mut client = uploader::client(VirtualTransport::default(), &options.profile);
    let image = extension(BYTES, 0);
    let full = uploader::upload(&mut client, &image, &options, &mut NoProgress)
        .unwrap_or_else(|error| panic!("the benchmark upload failed: {error}"));
    let started = Instant::now();
    let delta = uploader::upload(
        &mut client,
        &one_byte_changed(&image, 1000),
        &options,
        &mut NoProgress,
    )
    .unwrap_or_else(|error| panic!("the one-byte upload failed: {error}"));
    let wall = started.elapsed();
    // What `scorpion upload` does: the same upload keeping what it
    // overwrites for `--undo`, into a fresh robot and as a one-byte change.
    let mut client = uploader::client(VirtualTransport::default(), &options.profile);
    let mut undo = Undo::default();
    let kept_full =
        uploader::upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut undo)
            .unwrap_or_else(|error| panic!("the benchmark upload failed: {error}"));
    let kept_delta = uploader::upload_keeping(
        &mut client,
        &one_byte_changed(&image, 1000),
        &options,
        &mut NoProgress,
        &mut undo,
    )
    .unwrap_or_else(|error| panic!("the one-byte upload failed: {error}"));
    let full_ratio = full.device_time.as_secs_f64() / line_bound.as_secs_f64();
    let delta_ratio = delta.device_time.as_secs_f64() / 1.0;
    println!(
        "  {:<34} {:>9.3} {full_ratio:>9.3}x {:>10} {:>8} {:>8}",
        "default options (delta), full",
        full.device_time.as_secs_f64(),
        "",
        full.chars_sent + full.chars_received,
        "",
    );
    println!(
        "  {:<34} {:>9.3} {:>10} {:>10} {:>8} {:>8}",
        "one byte changed (delta)",
        delta.device_time.as_secs_f64(),
        format!("{delta_ratio:.3}x 1 s"),
        format!("{} B", delta.written_bytes()),
        delta.chars_sent + delta.chars_received,
        wall.as_millis()
    );
    for (name, report, bound) in [
        ("keeping for undo, full", &kept_full, &full),
        ("keeping for undo, one byte", &kept_delta, &delta),
    ] {
        println!(
            "  {name:<34} {:>9.3} {:>10} {:>10} {:>8}",
            report.device_time.as_secs_f64(),
            format!(
                "{:.3}x",
                report.device_time.as_secs_f64() / bound.device_time.as_secs_f64()
            ),
            "no keep",
            report.chars_sent + report.chars_received,
        );
    }
    if full_ratio > 1.15 {
        missed.push(format!(
            "the full upload with default options: {full_ratio:.3}x, target 1.15x"
        ));
    }
    // `scorpion upload` keeps what it overwrites: the goal is for what
    // users run, so both one-byte figures are held to it.
    for (name, report) in [
        ("the one-byte change", &delta),
        ("the one-byte change keeping for undo", &kept_delta),
    ] {
        if report.device_time.as_secs_f64() > 1.0 {
            missed.push(format!(
                "{name}: {:.3} s of robot time, target 1 s",
                report.device_time.as_secs_f64()
            ));
        }
    }
    println!();
    println!(
        "  targets: ROM only within 1.1x of the ROM-only bound ({:.3} s); the loader, line at 19200, within 1.15x of the line-rate bound ({:.3} s); a one-byte change within 1 s, kept for undo or not",
        rom_bound.as_secs_f64() * 1.1,
        line_bound.as_secs_f64() * 1.15
    );
    if missed.is_empty() {
        println!("  all targets met");
    } else {
        for line in missed {
            println!("  MISSED {line}");
        }
    }
}
