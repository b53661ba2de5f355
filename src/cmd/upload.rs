//! `scorpion upload`: put a linked image into a robot, verify every byte,
//! then switch its hooks.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use miette::{Context, IntoDiagnostic};
use uploader::{Client, ClientConfig, Event, Phase, Progress, UploadImage, UploadOptions};

use crate::cmd::ports;

/// Upload a linked image (`scorpion link` output) into the robot with its
/// own RAM-write commands: every byte verified with `/7R` reads while the
/// writes go out, what differs rewritten, hooks switched only after the
/// whole body verified.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The linked ELF image.
    image: PathBuf,
    /// The serial port the robot is on.
    #[arg(long)]
    port: String,
    /// The line's baud rate.
    #[arg(long, default_value_t = ports::DEFAULT_BAUD)]
    baud: u32,
    /// Characters sent after a question whose answer has not arrived (the
    /// robot's receive buffer); 0 waits for every answer.
    #[arg(long, default_value_t = ClientConfig::default().window)]
    window: usize,
}

/// A progress bar on stderr (hidden when stderr is not a terminal), with
/// bytes/s and ETA.
struct Bar {
    bar: ProgressBar,
}

impl Bar {
    fn new() -> Bar {
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{msg:>10} [{bar:32}] {bytes}/{total_bytes} {bytes_per_sec} ETA {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        Bar { bar }
    }
}

impl Progress for Bar {
    fn phase(&mut self, phase: Phase, total: usize) {
        let name = match phase {
            Phase::Connect => "connecting",
            Phase::Write => "writing",
            Phase::FinalVerify => "verifying",
            Phase::Loader => "loader",
            Phase::Hooks => "hooking",
        };
        self.bar.set_message(name);
        self.bar.set_length(total as u64);
        self.bar.set_position(0);
    }

    fn advanced(&mut self, done: usize) {
        self.bar.set_position(done as u64);
    }

    fn event(&mut self, event: &Event) {
        // Faults are routine and the summary counts them; only changes to
        // the robot's hooks deserve a line of their own.
        let line = match event {
            Event::HookChanged {
                kind,
                before,
                after,
            } => format!(
                "warning: {} changed from ${before:04X} to ${after:04X} during the upload (a reset?)",
                kind.rom_symbol()
            ),
            Event::HookDisarmed { kind, from, to } => format!(
                "{} pointed into the upload (${from:04X}); reset it to ${to:04X} first",
                kind.rom_symbol()
            ),
            _ => return,
        };
        self.bar.suspend(|| {
            #[allow(clippy::print_stderr, reason = "the CLI reports progress")]
            {
                eprintln!("{line}");
            }
        });
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let name = args.image.display().to_string();
    let bytes = std::fs::read(&args.image)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read {name}"))?;
    let linked = linker::Image::parse(&name, &bytes)?;
    let image = UploadImage::try_from(&linked)?;
    let transport = ports::open(&args.port, args.baud)?;
    let config = ClientConfig {
        window: args.window,
        ..ClientConfig::default()
    };
    let mut client = Client::new(transport, config);
    let mut bar = Bar::new();
    let result = uploader::upload(&mut client, &image, &UploadOptions::default(), &mut bar);
    bar.bar.finish_and_clear();
    let report = result?;
    let seconds = report
        .device_time
        .max(Duration::from_millis(1))
        .as_secs_f64();
    let mut summary = format!(
        "uploaded and verified {} bytes in {:.2} s ({:.0} bytes/s)",
        report.bytes,
        seconds,
        report.bytes as f64 / seconds
    );
    for area in image.areas() {
        summary.push_str(&format!(
            "\n  ${:04X}-${:04X}",
            area.address,
            area.end() - 1
        ));
    }
    if report.rewrites > 0 || report.lost_answers > 0 {
        summary.push_str(&format!(
            "\n  line faults: {} bytes rewritten, {} answers lost, {} extra verification passes",
            report.rewrites, report.lost_answers, report.final_passes
        ));
    }
    for hook in &report.hooks {
        summary.push_str(&format!(
            "\n  {} -> ${:04X} (falls through to ${:04X})",
            hook.kind.rom_symbol(),
            hook.handler,
            hook.previous
        ));
    }
    #[allow(clippy::print_stdout, reason = "the CLI reports the result")]
    {
        println!("{summary}");
    }
    Ok(ExitCode::SUCCESS)
}
