//! `scorpion debug`: a monitor on the virtual Scorpion. The robot with
//! the project's (or the given) images, cards and surroundings; commands
//! in the spirit of VICE's monitor read from stdin (typed, or a script),
//! the robot's serial line driven from the same prompt.

use std::io::{BufRead, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use debugger::session::{Line, Stopped};
use debugger::{Breakpoint, Debugger, Watch, WatchKind, Why};
use miette::IntoDiagnostic;

use crate::cmd::ports;

mod counts;
#[cfg(test)]
mod fuzz;
pub(crate) mod line;

use counts::{BACK_COUNT, CONTINUE_CYCLES, DIS_COUNT, MEM_LEN, STEP_COUNT};

/// Debug a program on the virtual Scorpion: breakpoints (an address, a
/// label, a robot command arriving), watchpoints, step, next, finish, and
/// back in time. Type `help` at the prompt.
///
/// In a project it loads the project's images, cards and surroundings;
/// `--image`, `--card`, `--world` and `--rom` replace them. Commands come
/// from stdin, so a file of them is a repeatable session:
/// `scorpion debug < session.txt`.
#[derive(Debug, Default, clap::Args)]
pub(crate) struct Args {
    /// The line's baud rate [env: SCORPION_BAUD; else the per-user file's
    /// or Scorpion.toml's; default 9600].
    #[arg(long)]
    pub(crate) baud: Option<u32>,
    /// A linked image (ELF) to load, as an upload leaves it; repeat to
    /// chain extensions.
    #[arg(long = "image", value_name = "ELF")]
    pub(crate) images: Vec<PathBuf>,
    /// A ROM profile (the ROM's linked ELF) instead of the reference ROM.
    #[arg(long, value_name = "ELF")]
    pub(crate) rom: Option<PathBuf>,
    /// Cards on the KIM bus and the robot's surroundings.
    #[command(flatten)]
    pub(crate) rig: crate::cmd::rig::Rig,
}

/// What `continue`, `next` and `finish` run for at most, in robot cycles,
/// unless given: one second of the robot's time.
const BUDGET: u64 = 1_000_000;

const HELP: &str = "\
commands (addresses: $C011, 49152, %1010, a label, sums: CMDBUF+1)
  /1P                  send a command down the serial line (any line starting with /)
  send TEXT            send TEXT as it is
  bumpers HEX          close the bumpers whose bits are set ($00 opens them all)
  break ADDR | FILE:LINE | /3A | unknown
                       stop before the instruction at ADDR or from FILE:LINE, when the ROM
                       has command /3A,
                       or when it jumps through HOOK_UNKNOWN                    (b)
  watch [read|write|access] ADDR[..ADDR]
                       stop after an instruction that reads or writes there       (w)
  delete N | delete watch N
                       remove breakpoint N or watchpoint N
  info                 list the breakpoints and watchpoints
  continue [CYCLES]    run until a stop, at most CYCLES (1 s; 60000000 at most)   (c)
  step [N]             run N instructions (1; 10000000 at most)                   (s)
  next                 one instruction, a JSR with its whole subroutine            (n)
  finish               run until the current subroutine returns                   (f)
  back [N]             go back N instructions (1), exactly                        (bs)
  reverse-continue     go back to the last breakpoint or watchpoint hit           (rc)
  who-wrote ADDR       the last instruction that wrote ADDR, and the byte
  regs                 the registers                                              (r)
  mem ADDR [LEN]       bytes from ADDR (16; 65536 at most)                        (m)
  dis [ADDR] [N]       N instructions from ADDR (the PC; 8; 65536 at most)        (d)
  trace FILE | trace off
                       write every instruction run to FILE
  list [FILE:LINE|ADDR] the source around the PC (or there)                       (l)
  help, quit (q)";

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let here = std::env::current_dir().into_diagnostic()?;
    let (make, images, root) = recipe(args, &here)?;
    let mut debugger = Debugger::new(make, &images)?;
    let mut sources = Sources::new(root);
    let stdin = std::io::stdin();
    let interactive = stdin.is_terminal();
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "the virtual Scorpion, stopped at ${:04X} after power-up; `help` lists the commands",
        debugger.cpu().pc
    )
    .into_diagnostic()?;
    let mut broken = false;
    let mut lines = stdin.lock().lines();
    loop {
        write!(out, "(scorpion) ").into_diagnostic()?;
        out.flush().into_diagnostic()?;
        let Some(line) = lines.next() else {
            writeln!(out).into_diagnostic()?;
            break;
        };
        let line = line.into_diagnostic()?;
        if !interactive {
            // A script's session reads as a transcript.
            writeln!(out, "{line}").into_diagnostic()?;
        }
        match command(&mut debugger, &mut sources, line.trim()) {
            Ok(Reply::Text(text)) => write!(out, "{text}").into_diagnostic()?,
            Ok(Reply::Quit) => break,
            Err(error) => {
                let robot_broke = matches!(error, Failure::Robot(_));
                broken |= robot_broke;
                writeln!(out, "error: {}", error.message()).into_diagnostic()?;
            }
        }
    }
    // The trace's last lines, and its last chance to say it failed.
    if let Err(error) = debugger.trace_off() {
        broken = true;
        writeln!(out, "error: {}", Failure::from(error).message()).into_diagnostic()?;
    }
    // A session in which the robot broke (a JAM, a card's fault) or whose
    // trace could not be written fails.
    Ok(if broken {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// The source files the images name, read when shown: relative to the
/// project's root (or the current directory); `scorpion.inc` built in.
pub(crate) struct Sources {
    pub(crate) root: PathBuf,
    files: std::collections::HashMap<String, Option<Vec<String>>>,
}

impl Sources {
    /// Sources relative to `root`.
    pub(crate) fn new(root: PathBuf) -> Sources {
        Sources {
            root,
            files: std::collections::HashMap::new(),
        }
    }

    /// Line `line` (from 1) of `file`, if it can be read.
    pub(crate) fn line(&mut self, file: &str, line: u32) -> Option<String> {
        let root = &self.root;
        let lines = self.files.entry(file.to_owned()).or_insert_with(|| {
            let text = if file == "scorpion.inc" && !root.join(file).is_file() {
                Some(romlib::SCORPION_INC.to_owned())
            } else {
                hostfs::read_text(root.join(file), hostfs::TEXT).ok()
            };
            text.map(|t| t.lines().map(str::to_owned).collect())
        });
        lines
            .as_ref()?
            .get(usize::try_from(line).ok()?.checked_sub(1)?)
            .cloned()
    }
}

/// What [`recipe`] makes: the robot's builder, the images it loads, and
/// where their sources are.
pub(crate) type Recipe = (debugger::MakeRobot, Vec<linker::Image>, PathBuf);

/// The robot the options (or the project found from `here` up) describe,
/// as a function that builds it afresh, the images it loads, and the
/// directory their source paths are relative to.
pub(crate) fn recipe(args: &Args, here: &std::path::Path) -> miette::Result<Recipe> {
    let resolved = crate::cmd::config::resolve_in(
        &crate::cmd::config::flags(None, args.baud, &args.rig, args.rom.as_ref()),
        here,
    )?;
    let rig = crate::cmd::config::rig(&resolved);
    let rom = crate::cmd::config::rom(&resolved)?;
    let images: Vec<linker::Image> = crate::cmd::config::images(&resolved, &args.images)?
        .images
        .into_iter()
        .map(|(_, image)| image)
        .collect();
    let root = resolved
        .project
        .as_ref()
        .map_or_else(|| here.to_path_buf(), |p| p.root.clone());
    let baud = resolved.baud.value;
    let loaded = images.clone();
    let build = move || -> miette::Result<romlib::VirtualScorpion> {
        let mut robot = ports::bare_robot(baud, rom.as_ref())?;
        // Cards first: an image cannot be loaded over a card's registers.
        rig.attach(&mut robot, &mut |_, _, _| {})?;
        for image in &loaded {
            robot.load_image(image)?;
        }
        Ok(robot)
    };
    // The first build shows its errors in full.
    build()?;
    let make: debugger::MakeRobot = Box::new(move || {
        build().map_err(|report| debugger::Error::Setup {
            message: format!("{report}"),
        })
    });
    Ok((make, images, root))
}

/// What a command prints, or the end of the session.
enum Reply {
    Text(String),
    Quit,
}

/// A command's failure: the user's mistake, or the robot's.
enum Failure {
    Usage(String),
    Robot(debugger::Error),
}

impl Failure {
    fn message(&self) -> String {
        match self {
            Failure::Usage(text) => text.clone(),
            Failure::Robot(error) => {
                let help = miette::Diagnostic::help(error)
                    .map(|help| format!(" ({help})"))
                    .unwrap_or_default();
                format!("{error}{help}")
            }
        }
    }
}

impl From<debugger::Error> for Failure {
    fn from(error: debugger::Error) -> Failure {
        match error {
            debugger::Error::Address { .. } | debugger::Error::BeforePowerUp { .. } => {
                Failure::Usage(error.to_string())
            }
            other => Failure::Robot(other),
        }
    }
}

fn usage(text: &str) -> Failure {
    Failure::Usage(text.to_owned())
}

/// Runs one monitor command.
fn command(d: &mut Debugger, sources: &mut Sources, line: &str) -> Result<Reply, Failure> {
    let mut words = line.split_whitespace();
    let Some(verb) = words.next() else {
        return Ok(Reply::Text(String::new()));
    };
    let rest: Vec<&str> = words.collect();
    let text = match verb {
        "help" | "h" | "?" => format!("{HELP}\n"),
        "quit" | "q" | "exit" => return Ok(Reply::Quit),
        _ if verb.starts_with('/') => {
            line::command(line).map_err(Failure::Usage)?;
            d.send(line.as_bytes());
            format!("sent {line}\n")
        }
        "send" => {
            let what = line.trim_start_matches("send").trim();
            line::command(what).map_err(Failure::Usage)?;
            d.send(what.as_bytes());
            format!("sent {what}\n")
        }
        "bumpers" => {
            let mask = rest
                .first()
                .and_then(|t| u8::from_str_radix(t.trim_start_matches('$'), 16).ok())
                .ok_or_else(|| usage("bumpers HEX: a bit per closed bumper, 00 to FF"))?;
            d.set_bumpers(mask);
            format!("bumpers ${mask:02X}\n")
        }
        "break" | "b" => {
            let what = rest
                .first()
                .ok_or_else(|| usage("break ADDR, break /3A or break unknown"))?;
            let point = if *what == "unknown" {
                Breakpoint::UnknownHook
            } else if what.starts_with('/') {
                Breakpoint::command(what).ok_or_else(|| {
                    usage("a command breakpoint is /, a count 1-9 and a letter: /3A")
                })?
            } else if let Some((file, line)) = file_line(what) {
                Breakpoint::At(
                    d.address_of_line(file, line)
                        .ok_or_else(|| usage(&format!("no code came from {file}:{line}")))?,
                )
            } else {
                Breakpoint::At(d.symbols().address(&rest.join(" "))?)
            };
            let shown = describe(d, &point);
            let id = d.add_breakpoint(point);
            format!("breakpoint {id}: {shown}\n")
        }
        "watch" | "w" => {
            let (kind, range) = match rest.first().copied() {
                Some("read") => (WatchKind::Read, &rest[1..]),
                Some("write") => (WatchKind::Write, &rest[1..]),
                Some("access") => (WatchKind::Access, &rest[1..]),
                _ => (WatchKind::Access, &rest[..]),
            };
            let range = range.join(" ");
            if range.is_empty() {
                return Err(usage("watch [read|write|access] ADDR[..ADDR]"));
            }
            let (start, end) = match range.split_once("..") {
                Some((a, b)) => (d.symbols().address(a)?, d.symbols().address(b)?),
                None => {
                    let a = d.symbols().address(&range)?;
                    (a, a)
                }
            };
            if end < start {
                return Err(usage("the range's end is below its start"));
            }
            let id = d.add_watch(Watch { start, end, kind });
            format!(
                "watchpoint {id}: {} of {}\n",
                kind_name(kind),
                range_text(start, end)
            )
        }
        "delete" => match rest.as_slice() {
            ["watch", n] => {
                let id = n.parse().map_err(|_| usage("delete watch N"))?;
                if !d.delete_watch(id) {
                    return Err(usage(&format!("no watchpoint {id}")));
                }
                format!("deleted watchpoint {id}\n")
            }
            [n] => {
                let id = n.parse().map_err(|_| usage("delete N"))?;
                if !d.delete_breakpoint(id) {
                    return Err(usage(&format!("no breakpoint {id}")));
                }
                format!("deleted breakpoint {id}\n")
            }
            _ => return Err(usage("delete N or delete watch N")),
        },
        "info" => {
            let mut text = String::new();
            for (id, point) in d.breakpoints() {
                text.push_str(&format!("breakpoint {id}: {}\n", describe(d, &point)));
            }
            for (id, watch) in d.watches() {
                text.push_str(&format!(
                    "watchpoint {id}: {} of {}\n",
                    kind_name(watch.kind),
                    range_text(watch.start, watch.end)
                ));
            }
            if text.is_empty() {
                text = "no breakpoints or watchpoints\n".into();
            }
            text
        }
        "continue" | "c" | "run" => {
            let budget = CONTINUE_CYCLES
                .or(rest.first(), BUDGET)
                .map_err(Failure::Usage)?;
            {
                let stop = d.run(budget)?;
                stop_report(d, sources, &stop)
            }
        }
        "step" | "s" | "stepi" | "si" => {
            let n = STEP_COUNT.or(rest.first(), 1).map_err(Failure::Usage)?;
            {
                let stop = d.step(n)?;
                stop_report(d, sources, &stop)
            }
        }
        "next" | "n" => {
            let stop = d.next(BUDGET)?;
            stop_report(d, sources, &stop)
        }
        "finish" | "f" => {
            let stop = d.finish(BUDGET)?;
            stop_report(d, sources, &stop)
        }
        "back" | "bs" | "reverse-step" => {
            let n = BACK_COUNT.or(rest.first(), 1).map_err(Failure::Usage)?;
            {
                let stop = d.back(n)?;
                stop_report(d, sources, &stop)
            }
        }
        "reverse-continue" | "rc" => match d.reverse_continue()? {
            Some(stopped) => stop_report(d, sources, &stopped),
            None => "no breakpoint or watchpoint was hit before here\n".into(),
        },
        "who-wrote" => {
            let address = d.symbols().address(&rest.join(" "))?;
            match d.who_wrote(address)? {
                Some(write) => format!(
                    "${address:04X} was last written ${:02X} by instruction {} at {}\n",
                    write.value,
                    write.instruction,
                    place(d, write.pc)
                ),
                None => format!(
                    "no instruction has written ${address:04X} since the session began (images are loaded before it)\n"
                ),
            }
        }
        "regs" | "r" => format!("{}\n", registers(d)),
        "list" | "l" => {
            let (file, line) = match rest.first() {
                Some(place) => match file_line(place) {
                    Some((file, line)) => (file.to_owned(), line),
                    None => d
                        .source_of(d.symbols().address(place)?)
                        .ok_or_else(|| usage(&format!("no source line for {place}")))?,
                },
                None => d.source_of(d.cpu().pc).ok_or_else(|| {
                    usage("no source line for the PC (the ROM, or an image without a source map)")
                })?,
            };
            listing(sources, &file, line)
        }
        "mem" | "m" => {
            let (address, len) = match rest.as_slice() {
                [] => return Err(usage("mem ADDR [LEN]")),
                [a] => (d.symbols().address(a)?, 16),
                [a, n] => (
                    d.symbols().address(a)?,
                    MEM_LEN.parse(n).map_err(Failure::Usage)?,
                ),
                _ => return Err(usage("mem ADDR [LEN]")),
            };
            memory(d, address, len)
        }
        "dis" | "d" => {
            let address = match rest.first() {
                Some(a) => d.symbols().address(a)?,
                None => d.cpu().pc,
            };
            let n = DIS_COUNT.or(rest.get(1), 8).map_err(Failure::Usage)?;
            d.disassemble(address, usize::try_from(n).unwrap_or(usize::MAX))
                .iter()
                .map(|l| line_text(d, l))
                .collect()
        }
        "trace" => match rest.first() {
            Some(&"off") => {
                d.trace_off()?;
                "trace off\n".into()
            }
            Some(path) => {
                let file = std::fs::File::create(path)
                    .map_err(|e| usage(&format!("cannot write {path}: {e}")))?;
                d.trace(path, Box::new(std::io::BufWriter::new(file)))?;
                format!("tracing into {path}\n")
            }
            None => return Err(usage("trace FILE or trace off")),
        },
        other => {
            return Err(usage(&format!("no command `{other}`; `help` lists them")));
        }
    };
    Ok(Reply::Text(text))
}

fn kind_name(kind: WatchKind) -> &'static str {
    match kind {
        WatchKind::Read => "reads",
        WatchKind::Write => "writes",
        WatchKind::Access => "reads and writes",
    }
}

fn range_text(start: u16, end: u16) -> String {
    if start == end {
        format!("${start:04X}")
    } else {
        format!("${start:04X}-${end:04X}")
    }
}

fn describe(d: &Debugger, point: &Breakpoint) -> String {
    match point {
        Breakpoint::At(address) => place(d, *address),
        other => other.to_string(),
    }
}

/// `$0403 (handler+$3)`.
fn place(d: &Debugger, address: u16) -> String {
    match d.symbols().place(address) {
        Some(name) => format!("${address:04X} ({name})"),
        None => format!("${address:04X}"),
    }
}

fn registers(d: &Debugger) -> String {
    let cpu = d.cpu();
    format!(
        "PC=${:04X} A=${:02X} X=${:02X} Y=${:02X} S=${:02X} P={} cycle {} instruction {}",
        cpu.pc,
        cpu.a,
        cpu.x,
        cpu.y,
        cpu.s,
        emulator::cpu::flags_text(cpu.p()),
        d.robot().cycles(),
        cpu.instructions()
    )
}

/// `len` bytes from `address` (at most the address space, [`MEM_LEN`]:
/// past $FFFF it wraps to $0000 as the 6502's addresses do).
fn memory(d: &Debugger, address: u16, len: u64) -> String {
    let bus = &d.robot().robot().bus;
    let len = len.min(MEM_LEN.max);
    // Up to $FFFF, then on from $0000: each part dumped at its own
    // addresses.
    let to_top = (0x1_0000 - u64::from(address)).min(len);
    let mut text = Vec::new();
    for (start, count) in [(address, to_top), (0, len - to_top)] {
        let bytes: Vec<u8> = (0..count)
            .filter_map(|i| u16::try_from(u64::from(start) + i).ok())
            .map(|at| emulator::Bus::peek(bus, at))
            .collect();
        // As `scorpion read` shows a robot's memory.
        let _ = crate::cmd::read::write_dump(&mut text, start, &bytes);
    }
    String::from_utf8_lossy(&text).into_owned()
}

fn line_text(d: &Debugger, line: &Line) -> String {
    let bytes: Vec<String> = line.bytes.iter().map(|b| format!("{b:02X}")).collect();
    let label = line
        .label
        .clone()
        .or_else(|| d.symbols().place(line.address))
        .unwrap_or_default();
    let marker = if line.address == d.cpu().pc { '>' } else { ' ' };
    let text = match &line.source {
        Some((file, n)) => format!("{:<30} {file}:{n}", line.text),
        None => line.text.clone(),
    };
    format!(
        "{marker} ${:04X}  {:<8}  {:<20} {}\n",
        line.address,
        bytes.join(" "),
        label,
        text.trim_end()
    )
}

fn stop_report(d: &Debugger, sources: &mut Sources, stop: &Stopped) -> String {
    let why = match &stop.why {
        Why::Breakpoint { id, point } => format!("breakpoint {id} ({})", describe(d, point)),
        Why::Watch { id, access, pc } => format!(
            "watchpoint {id}: {} ${:02X} {} ${:04X} by {}",
            if access.write { "wrote" } else { "read" },
            access.value,
            if access.write { "to" } else { "from" },
            access.address,
            place(d, *pc)
        ),
        Why::Stepped => "stepped".into(),
        Why::Finished => "returned".into(),
        Why::Budget => "still running (no stop in the cycles given)".into(),
        Why::Back => "back".into(),
    };
    let mut text = String::new();
    if !stop.received.is_empty() {
        let answer = String::from_utf8_lossy(&stop.received).replace('\r', "\\r");
        text.push_str(&format!("< {answer}\n"));
    }
    let plural = |n: i64| if n.abs() == 1 { "" } else { "s" };
    // Back in time, the cycles count down as the instructions do.
    let sign = if stop.instructions < 0 { "-" } else { "" };
    text.push_str(&format!(
        "{why}: {sign}{} cycles, {} instruction{}\n",
        stop.cycles,
        stop.instructions,
        plural(stop.instructions)
    ));
    if let Some(line) = d.disassemble(d.cpu().pc, 1).first() {
        text.push_str(&line_text(d, line));
        if let Some((file, n)) = &line.source
            && let Some(source) = sources.line(file, *n)
        {
            text.push_str(&format!("  {file}:{n}: {}\n", source.trim_end()));
        }
    }
    text.push_str(&format!("  {}\n", registers(d)));
    text
}

/// `adc.s:27` as a file and a line.
fn file_line(text: &str) -> Option<(&str, u32)> {
    let (file, line) = text.rsplit_once(':')?;
    Some((file, line.parse().ok()?)).filter(|(file, _)| !file.is_empty())
}

/// The source around `line` of `file`, the line marked.
fn listing(sources: &mut Sources, file: &str, line: u32) -> String {
    let mut text = String::new();
    for n in line.saturating_sub(4).max(1)..=line.saturating_add(4) {
        let Some(source) = sources.line(file, n) else {
            break;
        };
        let marker = if n == line { '>' } else { ' ' };
        let shown = format!("{marker} {file}:{n:<4} {source}");
        text.push_str(shown.trim_end());
        text.push('\n');
    }
    if text.is_empty() {
        text = if sources.line(file, 1).is_some() {
            format!("{file} has no line {line}\n")
        } else {
            format!("cannot read {file}\n")
        };
    }
    text
}
