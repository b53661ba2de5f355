//! `scorpion sim`: the virtual Scorpion, serving a pseudo-terminal or the
//! terminal it runs in, at the baud rate's pace.

use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use emulator::board::CPU_HZ;
use miette::{Context, IntoDiagnostic};
use romlib::VirtualScorpion;

use crate::cmd::host_line::{self, HostLine};

/// Run the virtual Scorpion: the reference ROM (or your ROM profile) on the
/// emulated board, extensions loaded as an upload leaves them.
///
/// With `--pty` it opens a pseudo-terminal, prints its path as the first
/// line on stdout and serves it until interrupted: point a terminal program
/// or `scorpion upload --port PATH` at it. Without, it reads commands from
/// stdin and prints the answers, one per line, until stdin ends.
///
/// Either way the line is a real one's: bytes go to the robot at the baud
/// rate, at most 4 KiB wait for it (a serial port's buffer), and what is
/// written faster than that is dropped and said on stderr, as are
/// characters the 6551 overran.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// Serve a pseudo-terminal instead of stdin and stdout.
    #[arg(long)]
    pty: bool,
    /// The line's baud rate (the robot's DIP switches are set to match)
    /// [env: SCORPION_BAUD; else the per-user file's or Scorpion.toml's;
    /// default 9600].
    #[arg(long)]
    baud: Option<u32>,
    /// A linked image (ELF) to load into RAM before serving, hooks
    /// installed last; repeat to chain extensions, in order.
    #[arg(long = "image", value_name = "ELF")]
    images: Vec<PathBuf>,
    /// Bumper microswitches closed at power-up, one bit each: `01`, `$80`.
    #[arg(long, value_name = "HEX", value_parser = bumper_mask)]
    bumpers: Option<u8>,
    /// A ROM profile (the ROM's linked ELF) to run instead of the
    /// reference ROM.
    #[arg(long, value_name = "ELF")]
    rom: Option<PathBuf>,
    /// Cards on the KIM bus and the robot's surroundings.
    #[command(flatten)]
    rig: crate::cmd::rig::Rig,
    /// Draw the robot's path in its room (a world file, `--world
    /// room.toml`) to FILE.svg when the run ends (stdin's end; with
    /// `--pty` or `--view`, Ctrl-C or SIGTERM): the room, the trail with
    /// a mark every second, the bumps and the commands received.
    /// FILE.png draws the same picture rasterized (without its labels).
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    path: Option<PathBuf>,
    /// Serve the live view instead of stdin: the room, the robot moving,
    /// its serial console, bumpers, trackers, lamps and eyes, in the
    /// browser at the address printed on stdout (`open
    /// http://127.0.0.1:PORT/`; default 127.0.0.1 and a free port).
    /// Ctrl-C stops it (and draws --path).
    #[arg(
        long,
        value_name = "ADDR",
        num_args = 0..=1,
        default_missing_value = "127.0.0.1:0",
        conflicts_with = "pty"
    )]
    view: Option<std::net::SocketAddr>,
}

/// A bumper mask in hex: `05`, `$05` or `0x05`.
fn bumper_mask(text: &str) -> Result<u8, String> {
    let digits = text
        .trim()
        .trim_start_matches('$')
        .trim_start_matches("0x")
        .trim_start_matches("0X");
    u8::from_str_radix(digits, 16)
        .map_err(|_| format!("`{text}` is not a hex byte (write 05 or $80: a bit per bumper)"))
}

/// The virtual robot as the options describe it, powered up, and what
/// each of its scripts prints.
pub(crate) fn robot(
    baud: u32,
    rom: Option<&(String, linker::Image)>,
    rig: &crate::cmd::rig::Rig,
    images: &crate::cmd::config::Images,
) -> miette::Result<Rigged> {
    let mut robot = match rom {
        Some((name, image)) => VirtualScorpion::with_rom(name, image)?,
        None => VirtualScorpion::new(),
    };
    if !robot.set_baud(baud) {
        miette::bail!(
            help = format!("the 6551's rates: {}", platform::acia::rates_text()),
            "the Scorpion's 6551 cannot run at {baud} baud"
        );
    }
    // Cards first: an image cannot be loaded over a card's registers.
    let printed = rig.apply(&mut robot)?;
    for (name, image) in &images.images {
        let hooks = robot
            .load_image(image)
            .wrap_err_with(|| format!("cannot load {name}"))?;
        let mut err = std::io::stderr().lock();
        if images.from_project {
            writeln!(err, "loaded {name} from {}", scorpion_project::FILE).into_diagnostic()?;
            continue;
        }
        for area in &image.areas {
            writeln!(
                err,
                "loaded {name}: ${:04X}-${:04X}",
                area.load,
                u64::from(area.load) + area.bytes.len() as u64 - 1
            )
            .into_diagnostic()?;
        }
        for hook in hooks {
            writeln!(
                err,
                "{} -> ${:04X} (was ${:04X})",
                hook.kind.rom_symbol(),
                hook.handler,
                hook.previous
            )
            .into_diagnostic()?;
        }
    }
    Ok((robot, printed))
}

/// The virtual robot and what each of its scripts prints.
type Rigged = (VirtualScorpion, Vec<(String, cards::Printed)>);

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    // In a project: its ROM profile, cards and surroundings, and its
    // images built and loaded; each given on the command line (`--rom`,
    // `--card`, `--world`, `--image`) instead replaces that part.
    let resolved = crate::cmd::config::resolve(&crate::cmd::config::flags(
        None,
        args.baud,
        &args.rig,
        args.rom.as_ref(),
    ))?;
    let rom = crate::cmd::config::rom(&resolved)?;
    let images = crate::cmd::config::images(&resolved, &args.images)?;
    let rig = crate::cmd::config::rig(&resolved);
    let (mut robot, printed) = robot(resolved.baud.value, rom.as_ref(), &rig, &images)?;
    let room = crate::cmd::rig::path_picture(args.path.as_ref(), rig.room.get())?;
    if let Some(mask) = args.bumpers {
        robot.set_bumpers(mask);
    }
    if let Some(address) = args.view {
        let ended = crate::cmd::view::serve(
            &mut robot,
            crate::cmd::view::Session {
                address,
                baud: resolved.baud.value,
                printed: &printed,
                room: rig.room.get(),
            },
        )?;
        if let Some((path, view)) = room {
            // The room as the session left it: obstacles where they were
            // dragged.
            let layout = ended.layout.unwrap_or_else(|| view.layout().clone());
            let svg = cards::room::picture::svg(&layout, &view.trail(), &ended.commands);
            let bytes = if cards::room::raster::wants_png(path) {
                cards::room::raster::png(&svg)?
            } else {
                svg.into_bytes()
            };
            crate::cmd::rig::write_picture(path, &bytes)?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let mut commands = Vec::new();
    // Kept only for a picture, and then bounded: a flood on stdin is not
    // a list of commands to draw.
    let drawn = room.is_some().then_some(&mut commands);
    let exit = if args.pty {
        serve_pty(&mut robot, resolved.baud.value, &printed)
    } else {
        serve_stdio(&mut robot, resolved.baud.value, &printed, drawn)
    }?;
    if let Some((path, view)) = room {
        crate::cmd::rig::write_picture(path, &view.picture_for(path, &commands)?)?;
    }
    Ok(exit)
}

/// The most commands a picture of the path names: a session that sends
/// more is a flood, and its picture would be unreadable anyway.
const COMMANDS_DRAWN: usize = 4096;

/// Emulated cycles for a wall-clock duration (the CPU runs at 1 MHz).
fn cycles(elapsed: Duration) -> u64 {
    u64::try_from(elapsed.as_micros()).unwrap_or(u64::MAX) * CPU_HZ / 1_000_000
}

/// Keeps the robot's clock level with the wall clock.
struct Pace {
    started: Instant,
    first_cycle: u64,
}

impl Pace {
    fn new(robot: &VirtualScorpion) -> Pace {
        Pace {
            started: Instant::now(),
            first_cycle: robot.cycles(),
        }
    }

    /// The robot time the wall clock has reached.
    fn target(&self) -> u64 {
        self.first_cycle + cycles(self.started.elapsed())
    }

    fn run_to(&self, robot: &mut VirtualScorpion, target: u64) -> miette::Result<()> {
        let behind = target.saturating_sub(robot.cycles());
        robot.run_for(behind)?;
        Ok(())
    }
}

#[cfg(unix)]
fn serve_pty(
    robot: &mut VirtualScorpion,
    baud: u32,
    printed: &[(String, cards::Printed)],
) -> miette::Result<ExitCode> {
    use serialport::{SerialPort, TTYPort};

    let (mut master, slave) = TTYPort::pair()
        .into_diagnostic()
        .wrap_err("cannot open a pseudo-terminal")?;
    let path = slave
        .name()
        .ok_or_else(|| miette::miette!("the pseudo-terminal has no path"))?;
    {
        let mut out = std::io::stdout().lock();
        writeln!(out, "{path}").into_diagnostic()?;
        out.flush().into_diagnostic()?;
    }
    writeln!(
        std::io::stderr().lock(),
        "the virtual Scorpion is on {path} at {baud} baud; Ctrl-C stops it"
    )
    .into_diagnostic()?;
    master
        .set_timeout(Duration::from_millis(2))
        .into_diagnostic()?;
    // Ctrl-C (or SIGTERM) ends the session, not the process: `--path` is
    // drawn after it, as `--view` draws it.
    let stop =
        crate::cmd::flag_on_signals(&[signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM])?;
    // Our end of the slave stays open, so the master never sees a hang-up
    // between the clients' opens and closes.
    let _slave = slave;
    let pace = Pace::new(robot);
    let mut line = HostLine::new(host_line::HOLDS);
    let mut overruns = Overruns::new(robot);
    // A read takes what a flood has in the kernel's buffers at once, so
    // the pseudo-terminal never holds back more than a real line would.
    let mut buffer = vec![0u8; host_line::HOLDS];
    loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Ok(ExitCode::SUCCESS);
        }
        match master.read(&mut buffer) {
            Ok(count) => line.accept(&buffer[..count]),
            Err(error) if error.kind() == std::io::ErrorKind::TimedOut => {}
            Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
            Err(error) => {
                return Err(error)
                    .into_diagnostic()
                    .wrap_err("the pseudo-terminal failed");
            }
        }
        let target = pace.target();
        line.feed(robot, target);
        pace.run_to(robot, target)?;
        crate::cmd::rig::show_printed(printed);
        overruns.report(robot, line.take_dropped(), baud);
        let answer = robot.receive();
        if !answer.is_empty() {
            let unread = write_answer(&mut master, &answer)?;
            overruns.unread += unread;
        }
    }
}

/// Writes the robot's answer to the pseudo-terminal; returns how many of
/// its bytes were dropped because the clients are not reading (the
/// kernel's buffer is full): a host UART nobody reads loses them too,
/// where waiting would stop the robot's clock.
#[cfg(unix)]
fn write_answer(master: &mut impl Write, answer: &[u8]) -> miette::Result<u64> {
    let mut rest = answer;
    while !rest.is_empty() {
        // A byte at a time: the kernel takes one whenever it says it has
        // room, where a longer write could wait for room it never gets.
        match master.write(&rest[..1]) {
            Ok(0) => break,
            Ok(count) => rest = &rest[count..],
            Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
            Err(error) if error.kind() == std::io::ErrorKind::TimedOut => break,
            Err(error) => {
                return Err(error)
                    .into_diagnostic()
                    .wrap_err("cannot write to the pseudo-terminal");
            }
        }
    }
    Ok(rest.len() as u64)
}

/// What the line lost, said on stderr as it happens (summed over a
/// quarter of a second, at most once a second, so a burst is one line and
/// a flood does not flood the terminal too): bytes the
/// host's end dropped (a client writing faster than the baud rate
/// carries, more than a port holds), characters the 6551 lost to overrun
/// (its receive register still full: the ROM or an extension did not
/// read it in time), and answers the clients did not read. Both modes
/// say them: the pseudo-terminal and stdin.
struct Overruns {
    /// The 6551's count when last looked at.
    seen: u64,
    /// Host bytes dropped, not said yet.
    dropped: u64,
    /// Characters overrun, not said yet.
    overrun: u64,
    /// Answer bytes dropped, not said yet.
    unread: u64,
    /// When something was last said.
    said_at: Option<Instant>,
    /// When the first loss not said yet happened.
    pending_since: Option<Instant>,
}

impl Overruns {
    fn new(robot: &VirtualScorpion) -> Overruns {
        Overruns {
            seen: robot.robot().board().acia().overruns(),
            dropped: 0,
            overrun: 0,
            unread: 0,
            said_at: None,
            pending_since: None,
        }
    }

    fn report(&mut self, robot: &VirtualScorpion, dropped: u64, baud: u32) {
        let now = robot.robot().board().acia().overruns();
        self.overrun += now.saturating_sub(self.seen);
        self.seen = now;
        self.dropped += dropped;
        if self.dropped + self.overrun + self.unread == 0 {
            return;
        }
        let since = *self.pending_since.get_or_insert_with(Instant::now);
        if since.elapsed() < Duration::from_millis(250)
            || self
                .said_at
                .is_some_and(|at| at.elapsed() < Duration::from_secs(1))
        {
            return;
        }
        self.say(baud);
    }

    /// Says what was lost and not said yet, now (also as stdin's mode
    /// ends, before the quarter second a burst is summed over is up).
    fn say(&mut self, baud: u32) {
        if self.dropped + self.overrun + self.unread == 0 {
            return;
        }
        self.said_at = Some(Instant::now());
        self.pending_since = None;
        let mut err = std::io::stderr().lock();
        if self.dropped > 0 {
            let _ = writeln!(
                err,
                "line full: {} byte{} dropped (written faster than {baud} baud carries, with {} already waiting)",
                self.dropped,
                plural(self.dropped),
                host_line::HOLDS
            );
        }
        if self.overrun > 0 {
            let _ = writeln!(
                err,
                "6551 overrun: {} character{} lost (the receive register was still full when {} arrived)",
                self.overrun,
                plural(self.overrun),
                if self.overrun == 1 { "it" } else { "they" }
            );
        }
        if self.unread > 0 {
            let _ = writeln!(
                err,
                "{} byte{} of answers dropped: no client is reading the pseudo-terminal",
                self.unread,
                plural(self.unread)
            );
        }
        self.dropped = 0;
        self.overrun = 0;
        self.unread = 0;
    }
}

fn plural(count: u64) -> &'static str {
    if count == 1 { "" } else { "s" }
}

#[cfg(not(unix))]
fn serve_pty(
    _robot: &mut VirtualScorpion,
    _baud: u32,
    _printed: &[(String, cards::Printed)],
) -> miette::Result<ExitCode> {
    miette::bail!(
        help = "run `scorpion sim` without --pty and type commands, or use --port emu",
        "pseudo-terminals are a Unix feature"
    )
}

/// Robot time the stdin mode waits after the last command for answers.
const QUIET_TIME: u64 = CPU_HZ / 5;

/// Chunks of stdin read ahead of the robot: with the host line's
/// [`host_line::HOLDS`], all the stdin mode ever holds (a pipe's writer
/// waits on the kernel beyond that).
const CHUNKS_AHEAD: usize = 4;

/// Commands from stdin (line ends and all: the ROM ignores bytes outside
/// commands), answers to stdout with their carriage returns as line ends.
/// Stdin is the host's end of the line as the pseudo-terminal is under
/// `--pty`: read as fast as it comes, at most [`host_line::HOLDS`] bytes
/// waiting for the line, which carries them at the baud rate; the rest is
/// dropped, and drops and 6551 overruns are said on stderr. (Queued whole,
/// a flood on stdin grew memory by about 48 bytes a byte until the
/// process was killed.)
fn serve_stdio(
    robot: &mut VirtualScorpion,
    baud: u32,
    printed: &[(String, cards::Printed)],
    mut commands: Option<&mut Vec<(u64, String)>>,
) -> miette::Result<ExitCode> {
    let (sender, chunks) = mpsc::sync_channel::<Option<Vec<u8>>>(CHUNKS_AHEAD);
    std::thread::spawn(move || {
        let stdin = std::io::stdin();
        let mut input = stdin.lock();
        let mut buffer = vec![0u8; host_line::HOLDS];
        loop {
            match input.read(&mut buffer) {
                Ok(0) => {
                    let _ = sender.send(None);
                    return;
                }
                Ok(count) => {
                    if sender.send(Some(buffer[..count].to_vec())).is_err() {
                        return;
                    }
                }
                Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
                Err(_) => {
                    let _ = sender.send(None);
                    return;
                }
            }
        }
    });
    let pace = Pace::new(robot);
    let mut line = HostLine::new(host_line::HOLDS);
    let mut overruns = Overruns::new(robot);
    let mut out = std::io::stdout().lock();
    let mut ended = false;
    let mut quiet_since = robot.cycles();
    loop {
        // Everything stdin has given, without waiting once there is some.
        let mut next = chunks.recv_timeout(Duration::from_millis(2));
        loop {
            match next {
                Ok(Some(bytes)) => {
                    // For the picture of the path: what arrived, when
                    // (the first commands, each cut to what a label shows).
                    if let Some(commands) = commands.as_deref_mut() {
                        let text = String::from_utf8_lossy(&bytes);
                        let room = COMMANDS_DRAWN.saturating_sub(commands.len());
                        commands.extend(
                            text.split(['\r', '\n'])
                                .filter(|command| !command.is_empty())
                                .take(room)
                                .map(|command| {
                                    (robot.cycles(), command.chars().take(32).collect())
                                }),
                        );
                    }
                    line.accept(&bytes);
                }
                Ok(None) | Err(mpsc::RecvTimeoutError::Disconnected) => ended = true,
                Err(mpsc::RecvTimeoutError::Timeout) => break,
            }
            if ended {
                break;
            }
            next = chunks
                .try_recv()
                .map_err(|_| mpsc::RecvTimeoutError::Timeout);
        }
        // No more input: no need to wait for the wall clock.
        let target = if ended {
            robot.cycles() + 1000
        } else {
            pace.target()
        };
        if !line.is_empty() {
            quiet_since = robot.cycles();
        }
        line.feed(robot, target);
        pace.run_to(robot, target)?;
        crate::cmd::rig::show_printed(printed);
        overruns.report(robot, line.take_dropped(), baud);
        let answer = robot.receive();
        if !answer.is_empty() {
            quiet_since = robot.cycles();
            let text: Vec<u8> = answer
                .iter()
                .map(|&b| if b == b'\r' { b'\n' } else { b })
                .collect();
            out.write_all(&text).into_diagnostic()?;
            out.flush().into_diagnostic()?;
        }
        let line_idle = line.is_empty() && robot.line_idle();
        if ended && line_idle && robot.cycles() >= quiet_since + QUIET_TIME {
            overruns.say(baud);
            // The answers so far are out; a robot whose loop stopped (a
            // handler that never returns) fails the run, saying where.
            robot.check_loop(romlib::sim::LOOP_WATCH)?;
            return Ok(ExitCode::SUCCESS);
        }
    }
}
