//! The timeline of one upload on the virtual Scorpion: every command the
//! host sends and every burst of answer characters, in device time, then
//! where the robot-to-host wire sat idle. The benchmark's figure is one
//! number; this shows where its time goes.
//!
//! ```text
//! cargo run -p uploader --release --example trace            # the loader, 19200 baud
//! cargo run -p uploader --release --example trace -- 9600    # the loader at 9600 throughout
//! cargo run -p uploader --release --example trace -- rom     # the ROM's commands only
//! cargo run -p uploader --release --example trace -- delta   # one byte changed, once installed
//! cargo run -p uploader --release --example trace -- undo    # the same, keeping for `--undo` (as `scorpion upload`)
//! cargo run -p uploader --release --example trace -- small   # 109 bytes, as the README's main job
//! ```
//!
//! The image is the benchmark's: a 2 KiB extension at `$0400`
//! (`tests/common/image.rs`).

#![allow(clippy::print_stdout, reason = "an example prints its timeline")]

use std::time::Duration;

use uploader::transport::{VirtualTransport, char_time};
use uploader::{LoaderChoice, NoProgress, Transport, UploadOptions};

#[path = "../tests/common/image.rs"]
mod image;

use image::{extension, one_byte_changed};

/// One thing that crossed the line.
enum Entry {
    /// Bytes the host sent, at the host's rate.
    Sent(Vec<u8>),
    /// Bytes that arrived from the robot.
    Received(usize),
    /// The host changed its rate.
    Rate(u32),
}

/// A transport that records what crosses it, with the time and the rate.
struct Log<T> {
    inner: T,
    entries: Vec<(Duration, u32, Entry)>,
}

impl<T: Transport> Log<T> {
    fn note(&mut self, entry: Entry) {
        let (now, baud) = (self.inner.now(), self.inner.baud());
        self.entries.push((now, baud, entry));
    }
}

impl<T: Transport> Transport for Log<T> {
    fn send(&mut self, bytes: &[u8]) -> uploader::Result<()> {
        self.note(Entry::Sent(bytes.to_vec()));
        self.inner.send(bytes)
    }
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> uploader::Result<usize> {
        let count = self.inner.receive(into, timeout)?;
        if count > 0 {
            self.note(Entry::Received(count));
        }
        Ok(count)
    }
    fn baud(&self) -> u32 {
        self.inner.baud()
    }
    fn set_baud(&mut self, baud: u32) -> uploader::Result<()> {
        self.inner.set_baud(baud)?;
        self.note(Entry::Rate(baud));
        Ok(())
    }
    fn now(&self) -> Duration {
        self.inner.now()
    }
    fn clear_input(&mut self) -> uploader::Result<()> {
        self.inner.clear_input()
    }
    fn name(&self) -> String {
        self.inner.name()
    }
}

/// Keeps what an upload overwrote, as `scorpion upload` does for `--undo`
/// (the file aside).
struct Undo;

impl uploader::Keep for Undo {
    fn keep(&mut self, _overwritten: &uploader::Backup) {}
}

/// A command for the timeline: frames by size, the rest as text.
fn describe(bytes: &[u8]) -> String {
    if bytes.starts_with(b"/1L") && bytes.len() > 9 {
        format!("/1L frame, {} bytes of data", bytes.len() - 9)
    } else {
        bytes.escape_ascii().to_string()
    }
}

fn main() -> uploader::Result<()> {
    let mode = std::env::args().nth(1);
    let (loader, fast_baud) = match mode.as_deref() {
        Some("rom") => (LoaderChoice::Never, None),
        Some("delta" | "undo") => (LoaderChoice::Auto, Some(uploader::FAST_BAUD)),
        Some("9600") => (LoaderChoice::Always, None),
        _ => (LoaderChoice::Always, Some(uploader::FAST_BAUD)),
    };
    let options = UploadOptions {
        loader,
        fast_baud,
        replace: true,
        ..UploadOptions::default()
    };
    let log = Log {
        inner: VirtualTransport::default(),
        entries: Vec::new(),
    };
    let mut client = uploader::client(log, &options.profile);
    // `small`: an image the size of the README's main job (109 bytes).
    let mut image = extension(
        if mode.as_deref() == Some("small") {
            109
        } else {
            2048
        },
        0,
    );
    let keeping = mode.as_deref() == Some("undo");
    if matches!(mode.as_deref(), Some("delta" | "undo")) {
        uploader::upload(&mut client, &image, &options, &mut NoProgress)?;
        client.transport().entries.clear();
        image = one_byte_changed(&image, 1000);
    }
    let report = if keeping {
        uploader::upload_keeping(&mut client, &image, &options, &mut NoProgress, &mut Undo)?
    } else {
        uploader::upload(&mut client, &image, &options, &mut NoProgress)?
    };
    let log = client.into_transport();

    // Answer characters arrive in bursts; print each burst once.
    let mut burst: Option<(Duration, Duration, usize)> = None;
    let flush = |burst: &mut Option<(Duration, Duration, usize)>| {
        if let Some((first, last, count)) = burst.take() {
            println!(
                "{:9.4}-{:.4}  <- {count} chars",
                first.as_secs_f64(),
                last.as_secs_f64()
            );
        }
    };
    for (at, baud, entry) in &log.entries {
        match entry {
            Entry::Received(count) => {
                burst = Some(match burst {
                    Some((first, _, total)) => (first, *at, total + count),
                    None => (*at, *at, *count),
                });
            }
            Entry::Sent(bytes) => {
                flush(&mut burst);
                println!("{:9.4}  -> {} @{baud}", at.as_secs_f64(), describe(bytes));
            }
            Entry::Rate(baud) => {
                flush(&mut burst);
                println!("{:9.4}  host now at {baud} baud", at.as_secs_f64());
            }
        }
    }
    flush(&mut burst);

    // The return wire's idle spells longer than two characters: the time
    // the robot spent on something other than answering.
    let mut previous: Option<Duration> = None;
    let mut idle = Duration::ZERO;
    let mut spells = Vec::new();
    for (at, baud, entry) in &log.entries {
        let Entry::Received(count) = entry else {
            continue;
        };
        if let Some(previous) = previous {
            let gap = at.saturating_sub(previous);
            let busy = char_time(*count, *baud);
            if gap > busy + char_time(2, *baud) {
                idle += gap - busy;
                spells.push((previous, gap - busy));
            }
        }
        previous = Some(*at);
    }
    println!();
    println!("the return wire idle (more than two characters' time):");
    for (after, length) in &spells {
        println!(
            "{:9.4}  {:6.1} ms",
            after.as_secs_f64(),
            length.as_secs_f64() * 1000.0
        );
    }
    println!(
        "device time {:.3} s; {} chars sent, {} received; the return wire idle {:.3} s in {} spells",
        report.device_time.as_secs_f64(),
        report.chars_sent,
        report.chars_received,
        idle.as_secs_f64(),
        spells.len()
    );
    Ok(())
}
