//! `scorpion ask`: send commands to a robot (or the virtual one) and print
//! the answers, raw or field by field.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use miette::{Context, IntoDiagnostic};
use romlib::VirtualScorpion;
use romlib::protocol::{Answer, BusyByte, Command, MoveCount, Pair, Status};
use uploader::{Client, ClientConfig, Transport};

use crate::cmd::{ports, sim};

/// Send commands to a robot and print each answer, one per line.
///
/// Commands are written as on the line: `/1P`, `/8C+501000`, `/7R020010`.
/// Instructions print nothing; an extension's command prints its answer if
/// one comes within --timeout, and is a failure when none comes (the ROM
/// ignores a command no extension owns) unless --allow-silence says the
/// extension's command is an instruction. `--port emu` talks to the
/// virtual Scorpion in this process.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    #[command(flatten)]
    line: ports::Line,
    /// Print each answer field by field.
    #[arg(long)]
    decode: bool,
    /// How long an extension's command may take to answer, in milliseconds
    /// (at least 1).
    #[arg(long, default_value_t = 500, value_name = "MS", value_parser = clap::value_parser!(u64).range(1..))]
    timeout: u64,
    /// An extension's command that answers nothing within --timeout is not
    /// a failure (an extension's instruction).
    #[arg(long)]
    allow_silence: bool,
    /// With `--port emu`: a linked image to load first (repeatable); in a
    /// project its images are built and loaded when none is given.
    #[arg(long = "image", value_name = "ELF")]
    images: Vec<PathBuf>,
    /// The commands, in order.
    #[arg(required = true, value_name = "CMD", value_parser = command)]
    commands: Vec<Command>,
}

fn command(text: &str) -> Result<Command, String> {
    Command::parse(text.as_bytes()).map_err(|error| error.to_string())
}

/// One robot: the virtual one or a serial line.
enum Robot {
    /// The virtual robot, and what its scripts print (shown after each
    /// command, and on the way out when one fails).
    Virtual(Box<VirtualScorpion>, ports::Shown),
    Serial(Client<Box<dyn uploader::Transport>>),
}

impl Robot {
    /// [`Robot::exchange`] with the virtual robot.
    fn exchange_virtual(
        robot: &mut VirtualScorpion,
        command: &Command,
        timeout: Duration,
        extension: bool,
    ) -> miette::Result<Option<Answer>> {
        if !extension {
            return Ok(robot.exchange(command)?);
        }
        let cycles = u64::try_from(timeout.as_micros()).unwrap_or(u64::MAX);
        match robot.transact(&command.encode(), cycles) {
            Ok(raw) => Ok(Some(command.parse_answer(&raw)?)),
            Err(romlib::Error::NoAnswer { received, .. }) if received.is_empty() => Ok(None),
            Err(error) => Err(error.into()),
        }
    }

    /// Sends `command`; returns its answer, if it has one.
    fn exchange(&mut self, command: &Command, timeout: Duration) -> miette::Result<Option<Answer>> {
        let extension = matches!(command, Command::Extension(_));
        match self {
            Robot::Virtual(robot, shown) => {
                let answer = Self::exchange_virtual(robot, command, timeout, extension);
                shown.show();
                answer
            }
            Robot::Serial(client) => {
                if command.is_question() {
                    return Ok(Some(client.ask(command)?));
                }
                client.send(command)?;
                if !extension {
                    return Ok(None);
                }
                let transport = client.transport();
                let mut raw = Vec::new();
                let deadline = transport.now() + timeout;
                while !raw.contains(&b'\r') {
                    let now = transport.now();
                    if now >= deadline {
                        break;
                    }
                    transport.receive(&mut raw, deadline - now)?;
                }
                if raw.is_empty() {
                    return Ok(None);
                }
                // A robot a killed debug session left at a breakpoint
                // answers every line with the stub's stop frame: calling
                // that a garbled answer would send the user after the cable.
                if uploader::stopped_in_stub(&raw) {
                    return Err(uploader::Error::StoppedInDebugStub {
                        port: transport.name(),
                    }
                    .into());
                }
                Ok(Some(command.parse_answer(&raw)?))
            }
        }
    }

    /// Where `HOOK_UNKNOWN` goes now (`None` where the line did not say).
    fn unknown_hook_target(&mut self, profile: &uploader::RomProfile) -> Option<u16> {
        let at = profile.hook_address(isa::objfmt::HookKind::Unknown) + 1;
        match self {
            Robot::Virtual(robot, _) => {
                let memory = robot.robot().board().memory();
                let at = usize::from(at);
                Some(u16::from_le_bytes([*memory.get(at)?, *memory.get(at + 1)?]))
            }
            Robot::Serial(client) => client
                .read_memory(at, 2)
                .ok()
                .map(|bytes| u16::from_le_bytes([bytes[0], bytes[1]])),
        }
    }
}

/// The failure of an extension's command that got no answer: whether any
/// extension is hooked at all says which of the two usual reasons it is.
fn no_answer(
    robot: &mut Robot,
    profile: &uploader::RomProfile,
    command: &Command,
    (timeout, origin): (u64, Option<String>),
) -> miette::Report {
    let rom = profile.reset_target(isa::objfmt::HookKind::Unknown);
    match robot.unknown_hook_target(profile) {
        Some(target) if Some(target) == rom => miette::miette!(
            help = "upload one with `scorpion upload`; on the virtual robot, `--image ELF` or a project's images",
            "`{command}`: no answer within {timeout} ms: no extension is installed (HOOK_UNKNOWN goes to the ROM's own ${target:04X}, which ignores commands it does not know)"
        ),
        Some(_) => miette::miette!(
            help = "`scorpion installed` lists what the robot has; --allow-silence accepts an extension's instruction, which answers nothing; --timeout MS waits longer",
            "`{command}`: no answer within {timeout} ms: no installed extension answered it"
        ),
        None => {
            let silent = miette::miette!(
                help = "is the robot on, its cable in, and its DIP switches at the --baud rate?",
                "`{command}`: no answer within {timeout} ms, and no answer to a read of HOOK_UNKNOWN either: the robot answers nothing"
            );
            match origin {
                Some(origin) => silent.wrap_err(origin),
                None => silent,
            }
        }
    }
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let resolved = args.line.resolve()?;
    let mut robot = if resolved.port()?.value == ports::EMU {
        // The project's virtual robot: its cards, world, ROM and images.
        let rom = crate::cmd::config::rom(&resolved)?;
        let images = crate::cmd::config::images(&resolved, &args.images)?;
        let (robot, printed) = sim::robot(
            resolved.baud.value,
            rom.as_ref(),
            &crate::cmd::config::rig(&resolved),
            &images,
        )?;
        Robot::Virtual(Box::new(robot), ports::Shown(printed))
    } else {
        if !args.images.is_empty() {
            miette::bail!(
                help = "upload them with `scorpion upload IMAGE --port PORT`",
                "--image loads images into the virtual Scorpion only (--port emu)"
            );
        }
        crate::cmd::config::note_unused_rig(&resolved);
        let transport = ports::open_resolved(&resolved, &[])?;
        Robot::Serial(Client::new(transport, ClientConfig::default()))
    };
    let timeout = Duration::from_millis(args.timeout);
    let mut out = std::io::stdout().lock();
    for command in &args.commands {
        let answer = robot
            .exchange(command, timeout)
            .wrap_err_with(|| format!("`{command}`"))
            .map_err(|report| ports::traced_report(report, &resolved))?;
        let silent = answer.is_none() && matches!(command, Command::Extension(_));
        if silent && !args.allow_silence {
            out.flush().into_diagnostic()?;
            // The ROM's profile says where its hook goes: needed only here.
            let rom = crate::cmd::config::rom(&resolved)?;
            let profile = crate::cmd::config::profile(rom.as_ref())?;
            // recheck23 F2: a robot that answers nothing, on a port a file
            // or the environment named, is said with where it came from.
            let origin = ports::origin_of(&resolved);
            return Err(no_answer(
                &mut robot,
                &profile,
                command,
                (args.timeout, origin),
            ));
        }
        if args.decode {
            write!(out, "{}", decode(command, answer.as_ref())).into_diagnostic()?;
        } else if let Some(answer) = answer {
            let text = answer.encode();
            let text = String::from_utf8_lossy(text.strip_suffix(b"\r").unwrap_or(&text));
            writeln!(out, "{text}").into_diagnostic()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// A command and its answer, a field a line.
fn decode(command: &Command, answer: Option<&Answer>) -> String {
    let Some(answer) = answer else {
        return if matches!(command, Command::Extension(_)) {
            format!("{command}: no answer\n")
        } else {
            format!("{command}: done (an instruction has no answer)\n")
        };
    };
    let raw = answer.encode();
    let raw = String::from_utf8_lossy(raw.strip_suffix(b"\r").unwrap_or(&raw)).into_owned();
    let mut lines = vec![format!("{command} -> {raw}")];
    let mut field = |name: &str, value: String| lines.push(format!("  {name:<13}{value}"));
    match answer {
        Answer::Bumpers(bumpers) => field("bumpers", bits(bumpers.0, "closed")),
        Answer::Scan(scan) => {
            field("direction", format!("{:?}", scan.axis).to_lowercase());
            field("readings", format!("{}", scan.data.len()));
            for (row, chunk) in scan.data.chunks(16).enumerate() {
                let hex: Vec<String> = chunk.iter().map(|b| format!("{b:02X}")).collect();
                field(&format!("  [{:3}]", row * 16), hex.join(" "));
            }
        }
        Answer::Eyes(pair) => field("eyes", pair_text(*pair)),
        Answer::Lamps(on) => field("lamps", on_off(*on)),
        Answer::Tracker(pair) => field("tracker", pair_text(*pair)),
        Answer::Moves(moves) => {
            field("left moved", count(moves.left));
            field("right moved", count(moves.right));
        }
        Answer::Busy(busy) => field("busy", busy_text(*busy)),
        Answer::Memory(bytes) => {
            for (row, chunk) in bytes.chunks(16).enumerate() {
                let hex: Vec<String> = chunk.iter().map(|b| format!("{b:02X}")).collect();
                field(&format!("+{:02}", row * 16), hex.join(" "));
            }
        }
        Answer::Remaining { motor, steps } => field(
            &format!("{motor:?} to go").to_lowercase(),
            format!("{} steps", steps.get()),
        ),
        Answer::Everything(status) => status_fields(status, &mut field),
        Answer::Text(text) => field("text", text.clone()),
    }
    let mut text = lines.join("\n");
    text.push('\n');
    text
}

fn status_fields(status: &Status, field: &mut impl FnMut(&str, String)) {
    field("bumpers", bits(status.bumpers.0, "closed"));
    field("eyes", pair_text(status.eyes));
    field("lamps", on_off(status.lamps));
    field("tracker", pair_text(status.tracker));
    field("left moved", count(status.moves.left));
    field("right moved", count(status.moves.right));
    field("master I/O", bits(status.io, "set"));
    field("busy", busy_text(status.busy));
    field(
        "left to go",
        format!("{} steps", status.left_remaining.get()),
    );
    field(
        "right to go",
        format!("{} steps", status.right_remaining.get()),
    );
}

fn bits(value: u8, what: &str) -> String {
    if value == 0 {
        return format!("{value:02X} (none {what})");
    }
    let set: Vec<String> = (0..8)
        .filter(|bit| value & (1 << bit) != 0)
        .map(|bit| bit.to_string())
        .collect();
    format!("{value:02X} (bits {} {what})", set.join(", "))
}

fn pair_text(pair: Pair) -> String {
    let text = match (pair.left, pair.right) {
        (false, false) => "none",
        (false, true) => "right",
        (true, false) => "left",
        (true, true) => "both",
    };
    format!("{} ({text})", char::from(pair.digit()))
}

fn on_off(on: bool) -> String {
    if on { "on" } else { "off" }.to_owned()
}

fn count(count: MoveCount) -> String {
    format!(
        "{}{} steps",
        char::from(count.direction.sign()),
        count.steps.get()
    )
}

fn busy_text(busy: BusyByte) -> String {
    let names = [
        (BusyByte::TONE, "tone"),
        (BusyByte::EYE, "eyes"),
        (BusyByte::LAMPS, "lamps"),
        (BusyByte::H_SCANNER, "H scanner"),
        (BusyByte::V_SCANNER, "V scanner"),
        (BusyByte::LEFT_MOTOR, "left motor"),
        (BusyByte::RIGHT_MOTOR, "right motor"),
    ];
    let active: Vec<&str> = names
        .iter()
        .filter(|(bit, _)| busy.0 & bit != 0)
        .map(|(_, name)| *name)
        .collect();
    if active.is_empty() {
        format!("{:02X} (idle)", busy.0)
    } else {
        format!("{:02X} ({})", busy.0, active.join(", "))
    }
}
