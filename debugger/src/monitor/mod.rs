//! The monitor's command language (`scorpion debug`'s prompt): each
//! command line run on a [`Debugger`] and answered as text, or as a typed
//! [`Failure`]. The commands are in the spirit of VICE's monitor and gdb:
//! breakpoints with conditions, hit counts and log points, watchpoints,
//! stepping both ways, registers and memory shown and set, disassembly
//! that names targets as the source does. Nothing here reads a terminal
//! or prints: the CLI reads the lines and prints the answers.

use crate::session::{Line, Stopped};
use crate::sources::Sources;
use crate::{Breakpoint, Debugger, Expr, Watch, WatchKind, Why};

pub(crate) mod breaks;
mod counts;
mod edit;

use counts::{
    BACK_COUNT, CONTINUE_CYCLES, CONTINUE_CYCLES_PAUSABLE, DIS_COUNT, MEM_LEN, STEP_COUNT,
};

/// What `continue`, `next` and `finish` run for at most, in robot cycles,
/// unless given: one second of the robot's time.
pub const BUDGET: u64 = 1_000_000;

/// The most `display` expressions shown at each stop.
pub(crate) const DISPLAYS_MAX: usize = 64;

/// The monitor's commands, as `help` lists them.
pub const HELP: &str = "\
commands (addresses and values are expressions: $C011, 49152, %1010, 'A', a label,
CMDBUF+1, registers A X Y S P PC, flags C Z I D V N, [ADDR] a byte, {ADDR} a word,
== != < <= > >= && || & | ^ << >> + - * / ! ~, < and > the low and high byte)
  /1P                  send a command down the serial line (any line starting with /)
  send TEXT            send TEXT as it is
  bumpers HEX          close the bumpers whose bits are set ($00 opens them all)
  break ADDR | FILE:LINE | /3A | unknown [if COND] [hits N] [log MESSAGE]
                       stop before the instruction at ADDR or from FILE:LINE, when the ROM
                       has command /3A, or when it jumps through HOOK_UNKNOWN;
                       only when COND holds (A == 1 && [CMDBUF] == $2F), from the Nth
                       hit (hits 3, hits == 3, hits % 3); a log point prints MESSAGE
                       ({A}, {[CMDBUF]} filled in) and goes on                   (b)
  watch [read|write|access] ADDR[..ADDR]
                       stop after an instruction that reads or writes there       (w)
  delete N | delete watch N
                       remove breakpoint N or watchpoint N
  info                 list the breakpoints and watchpoints
  continue [CYCLES]    run until a stop, at most CYCLES (1 s; 60000000 at most);
                       Ctrl-C pauses it                                          (c)
  step [N]             run N instructions (1; 10000000 at most)                   (s)
  next                 one source line (a macro's call one line), each JSR with its
                       whole subroutine                                           (n)
  nexti                one instruction, a JSR with its whole subroutine           (ni)
  finish               run until the current subroutine returns                   (f)
  until [ADDR|FILE:LINE]
                       run until the PC reaches there (alone: the next instruction
                       in memory, out of a loop)                                  (u)
  (an empty line at a terminal repeats the last step, next or back)
  back [N]             go back N instructions (1), exactly                        (bs)
  reverse-continue     go back to the last breakpoint or watchpoint hit           (rc)
  who-wrote ADDR       the last instruction that wrote ADDR, and the byte
  regs                 the registers                                              (r)
  set REG VALUE        set A X Y S P PC or a flag C Z I D V N: set A $05, set C 1,
                       set PC label (also regs A=$05)
  mem ADDR [LEN]       bytes from ADDR (16, or LEN: 32, $20; 65536 at most)       (m)
  mem ADDR BYTE BYTE...| mem ADDR = BYTE... | poke ADDR BYTE...
                       write RAM (each BYTE an expression)
  print EXPR           an expression's value                                      (p)
  display [EXPR]       show EXPR at each stop (alone: show them now); undisplay N
  bt                   the call chain, from the return addresses on the stack
  dis [ADDR] [N]       N instructions from ADDR (the PC; 8; 65536 at most)        (d)
  trace FILE | trace off
                       write every instruction run to FILE
  list [FILE:LINE|ADDR] the source around the PC (or there)                       (l)
  help, quit (q)";

/// What the monitor keeps between commands besides the debugger: the
/// sources it shows and the expressions shown at each stop.
#[derive(Debug)]
pub struct Monitor {
    /// The sources it shows.
    pub sources: Sources,
    /// `display`'s expressions, by number (from 1; deleted ones `None`).
    displays: Vec<Option<Expr>>,
    /// Ctrl-C pauses a run (at a terminal): a run may be longer.
    pausable: bool,
}

impl Monitor {
    /// A monitor showing `sources`, with nothing displayed.
    #[must_use]
    pub fn new(sources: Sources) -> Monitor {
        Monitor {
            sources,
            displays: Vec::new(),
            pausable: false,
        }
    }
}

/// What a command prints, or the end of the session.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// Text to show (each line ends in a newline).
    Text(String),
    /// `quit`: the session ends.
    Quit,
}

/// A command's failure: the user's mistake, or the robot's.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum Failure {
    /// A command that cannot be run as written: what is wrong with it
    /// (with its column pointed at, for an expression).
    #[error("{0}")]
    #[diagnostic(code(debugger::monitor::usage), help("`help` lists the commands"))]
    Usage(String),
    /// The robot failed (a JAM, a card's fault), or its trace could not be
    /// written: the session goes on, and fails at its end.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Robot(crate::Error),
    /// The line to a real robot failed (`scorpion debug --port`): the
    /// session goes on, and fails at its end.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Line(Box<uploader::stub::StubError>),
}

impl Failure {
    /// The failure as the monitor shows it, on one line after `error: `
    /// (the robot's help in parentheses).
    #[must_use]
    pub fn message(&self) -> String {
        match self {
            Failure::Usage(text) => text.clone(),
            Failure::Line(error) => {
                let help = miette::Diagnostic::help(error.as_ref())
                    .map(|help| format!(" ({help})"))
                    .unwrap_or_default();
                format!("{error}{help}")
            }
            Failure::Robot(error) => {
                let help = miette::Diagnostic::help(error)
                    .map(|help| format!(" ({help})"))
                    .unwrap_or_default();
                format!("{error}{help}")
            }
        }
    }
}

impl From<crate::Error> for Failure {
    fn from(error: crate::Error) -> Failure {
        match error {
            crate::Error::Address { .. }
            | crate::Error::BeforePowerUp { .. }
            | crate::Error::Value { .. }
            | crate::Error::NotRam { .. }
            | crate::Error::Parse(_)
            | crate::Error::Eval(_)
            | crate::Error::Hits(_) => Failure::Usage(error.to_string()),
            other => Failure::Robot(other),
        }
    }
}

fn usage(text: &str) -> Failure {
    Failure::Usage(text.to_owned())
}

impl Monitor {
    /// Whether Ctrl-C can pause a run (the CLI at a terminal): a
    /// `continue` may then be given an hour of robot time.
    pub fn set_pausable(&mut self, pausable: bool) {
        self.pausable = pausable;
    }

    /// Runs one command line on `d`: the text to show, or why not.
    ///
    /// # Errors
    /// [`Failure::Usage`] for a line that cannot be run as written,
    /// [`Failure::Robot`] when the robot failed while it ran.
    pub fn command(&mut self, d: &mut Debugger, line: &str) -> Result<Reply, Failure> {
        command(d, self, line)
    }
}

/// Runs one monitor command.
fn command(d: &mut Debugger, m: &mut Monitor, line: &str) -> Result<Reply, Failure> {
    let mut words = line.split_whitespace();
    let Some(verb) = words.next() else {
        return Ok(Reply::Text(String::new()));
    };
    let rest: Vec<&str> = words.collect();
    // The line after the verb, as typed.
    let after = line[verb.len()..].trim();
    let text = match verb {
        "help" | "h" | "?" => format!("{HELP}\n"),
        "quit" | "q" | "exit" => return Ok(Reply::Quit),
        _ if verb.starts_with('/') => {
            crate::line::command(line).map_err(Failure::Usage)?;
            d.send(line.as_bytes());
            format!("sent {line}\n")
        }
        "send" => {
            crate::line::command(after).map_err(Failure::Usage)?;
            d.send(after.as_bytes());
            format!("sent {after}\n")
        }
        "bumpers" => {
            let mask = rest
                .first()
                .and_then(|t| u8::from_str_radix(t.trim_start_matches('$'), 16).ok())
                .ok_or_else(|| usage("bumpers HEX: a bit per closed bumper, 00 to FF"))?;
            d.set_bumpers(mask);
            format!("bumpers ${mask:02X}\n")
        }
        "break" | "b" => breaks::add(d, line, verb.len())?,
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
                Some((a, b)) => (address(d, a)?, address(d, b)?),
                None => {
                    let a = address(d, &range)?;
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
                text.push_str(&format!("breakpoint {id}: {}", describe(d, &point)));
                if let Some((options, hits)) = d.breakpoint_options(id) {
                    text.push_str(&options.describe());
                    if hits > 0 {
                        text.push_str(&format!(" (hit {hits} time{})", plural(hits)));
                    }
                }
                text.push('\n');
            }
            for (id, watch) in d.watches() {
                text.push_str(&format!(
                    "watchpoint {id}: {} of {}\n",
                    kind_name(watch.kind),
                    range_text(watch.start, watch.end)
                ));
            }
            for (id, shown) in m.displays.iter().enumerate() {
                if let Some(shown) = shown {
                    text.push_str(&format!("display {}: {shown}\n", id + 1));
                }
            }
            if text.is_empty() {
                text = "no breakpoints or watchpoints\n".into();
            }
            text
        }
        "continue" | "c" | "run" => {
            let count = if m.pausable {
                CONTINUE_CYCLES_PAUSABLE
            } else {
                CONTINUE_CYCLES
            };
            let budget = count.or(rest.first(), BUDGET).map_err(Failure::Usage)?;
            let stop = d.run(budget)?;
            stop_report(d, m, &stop)
        }
        "step" | "s" | "stepi" | "si" => {
            let n = STEP_COUNT.or(rest.first(), 1).map_err(Failure::Usage)?;
            let stop = d.step(n)?;
            stop_report(d, m, &stop)
        }
        "next" | "n" => {
            let stop = d.next_line(BUDGET)?;
            stop_report(d, m, &stop)
        }
        "nexti" | "ni" => {
            let stop = d.next(BUDGET)?;
            stop_report(d, m, &stop)
        }
        "finish" | "f" => {
            let stop = d.finish(BUDGET)?;
            stop_report(d, m, &stop)
        }
        "until" | "u" => {
            let target = if after.is_empty() {
                // The instruction after this one in memory: out of a loop
                // whose branch back is here.
                let pc = d.cpu().pc;
                let len = d.disassemble(pc, 1).first().map_or(1, |l| l.bytes.len());
                pc.wrapping_add(u16::try_from(len).unwrap_or(1))
            } else if let Some((file, n)) = file_line(after) {
                d.address_of_line(file, n)
                    .ok_or_else(|| usage(&format!("no code came from {file}:{n}")))?
            } else {
                address(d, after)?
            };
            let stop = d.until(target, BUDGET)?;
            stop_report(d, m, &stop)
        }
        "back" | "bs" | "reverse-step" => {
            let n = BACK_COUNT.or(rest.first(), 1).map_err(Failure::Usage)?;
            let stop = d.back(n)?;
            stop_report(d, m, &stop)
        }
        "reverse-continue" | "rc" => match d.reverse_continue()? {
            Some(stopped) => stop_report(d, m, &stopped),
            None => "no breakpoint or watchpoint was hit before here\n".into(),
        },
        "who-wrote" => {
            let address = address(d, after)?;
            match d.who_wrote(address)? {
                Some(write) => {
                    let mut text = format!(
                        "${address:04X} was last written ${:02X} by instruction {} at {}\n",
                        write.value,
                        write.instruction,
                        place(d, write.pc)
                    );
                    text.push_str(&source_line(d, &mut m.sources, write.pc));
                    text
                }
                None => format!(
                    "no instruction has written ${address:04X} since the session began (images are loaded before it)\n"
                ),
            }
        }
        "regs" | "r" if rest.is_empty() => format!("{}\n", registers(d)),
        // `r A=$05 X=1`: each set in turn.
        "regs" | "r" => {
            let mut text = String::new();
            for word in &rest {
                edit::set(d, word)?;
            }
            text.push_str(&format!("{}\n", registers(d)));
            text
        }
        "set" => edit::set(d, after)?,
        "mem" | "m" => match rest.as_slice() {
            [] => return Err(usage("mem ADDR [LEN], or mem ADDR BYTE BYTE... to write")),
            [a] => memory(d, address(d, a)?, 16),
            [a, "=", bytes @ ..] => edit::poke(d, a, bytes)?,
            [a, n] => memory(d, address(d, a)?, mem_len(d, n)?),
            [a, bytes @ ..] => edit::poke(d, a, bytes)?,
        },
        "poke" => match rest.as_slice() {
            [a, bytes @ ..] if !bytes.is_empty() => edit::poke(d, a, bytes)?,
            _ => return Err(usage("poke ADDR BYTE...")),
        },
        "print" | "p" => {
            let value = evaluate(d, after)?;
            format!("{} = {}\n", after, shown_value(value))
        }
        "display" => {
            if after.is_empty() {
                displays(d, m)
            } else {
                if m.displays.iter().flatten().count() >= DISPLAYS_MAX {
                    return Err(Failure::Usage(format!(
                        "at most {DISPLAYS_MAX} expressions are displayed at once; `undisplay N` one first"
                    )));
                }
                let shown = expression(d, after, 0)?;
                let value = shown_expression(d, &shown);
                m.displays.push(Some(shown));
                format!("display {}: {after} = {value}\n", m.displays.len())
            }
        }
        "undisplay" => {
            let id: usize = after.parse().map_err(|_| usage("undisplay N"))?;
            let taken = id
                .checked_sub(1)
                .and_then(|i| m.displays.get_mut(i))
                .and_then(Option::take);
            if taken.is_none() {
                return Err(usage(&format!("no display {id}")));
            }
            format!("display {id} removed\n")
        }
        "bt" | "backtrace" | "where" => backtrace(d, &mut m.sources),
        "list" | "l" => {
            let (file, line) = match rest.first() {
                Some(place) => match file_line(place) {
                    Some((file, line)) => (file.to_owned(), line),
                    None => d
                        .source_of(address(d, place)?)
                        .ok_or_else(|| usage(&format!("no source line for {place}")))?,
                },
                None => d.source_of(d.cpu().pc).ok_or_else(|| {
                    usage("no source line for the PC (the ROM, or an image without a source map)")
                })?,
            };
            listing(&mut m.sources, &file, line)
        }
        "dis" | "d" => {
            let address = match rest.first() {
                Some(a) => address(d, a)?,
                None => d.cpu().pc,
            };
            let n = DIS_COUNT.or(rest.get(1), 8).map_err(Failure::Usage)?;
            d.disassemble(address, usize::try_from(n).unwrap_or(usize::MAX))
                .iter()
                .map(|l| line_text(d, &mut m.sources, l))
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

fn plural(n: u64) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// `text` (which starts `offset` characters into the command line) as an
/// expression; a parse error points at its column in the line.
fn expression(d: &Debugger, text: &str, offset: usize) -> Result<Expr, Failure> {
    Expr::parse(text, d.symbols()).map_err(|error| Failure::Usage(pointed(&error, offset)))
}

/// A parse error's message and its place under the expression.
fn pointed(error: &crate::expr::ParseError, offset: usize) -> String {
    format!(
        "column {}: {}\n{}",
        error.column + offset,
        error.reason,
        error.pointed()
    )
}

/// The value of the expression `text` now.
pub(crate) fn evaluate(d: &Debugger, text: &str) -> Result<i64, Failure> {
    let parsed = expression(d, text, 0)?;
    parsed
        .eval(d)
        .map_err(|error| Failure::Usage(error.to_string()))
}

/// The address the expression `text` gives now.
fn address(d: &Debugger, text: &str) -> Result<u16, Failure> {
    let parsed = expression(d, text, 0)?;
    parsed
        .address(d)
        .map_err(|error| Failure::Usage(error.to_string()))
}

/// `mem`'s LEN: a count in decimal as every count is written, or any
/// expression (`$10`, `%10000`, `END-START`), within the same bounds.
fn mem_len(d: &Debugger, word: &str) -> Result<u64, Failure> {
    if word.bytes().all(|b| b.is_ascii_digit()) {
        return MEM_LEN.parse(word).map_err(Failure::Usage);
    }
    let value = evaluate(d, word)?;
    MEM_LEN.parse(&value.to_string()).map_err(Failure::Usage)
}

/// `$2F (47)`: a value in hexadecimal and decimal.
pub(crate) fn shown_value(value: i64) -> String {
    let hex = crate::expr::show(value);
    if hex.starts_with('$') {
        format!("{hex} ({value})")
    } else {
        hex
    }
}

/// An expression's value now, or why it has none.
fn shown_expression(d: &Debugger, shown: &Expr) -> String {
    match shown.eval(d) {
        Ok(value) => shown_value(value),
        Err(error) => format!("<{}>", error.reason),
    }
}

/// The `display` expressions with their values now.
fn displays(d: &Debugger, m: &Monitor) -> String {
    let mut text = String::new();
    for (id, shown) in m.displays.iter().enumerate() {
        let Some(shown) = shown else { continue };
        let value = shown_expression(d, shown);
        text.push_str(&format!("  {}: {shown} = {value}\n", id + 1));
    }
    if text.is_empty() && m.displays.iter().all(Option::is_none) {
        text = "nothing displayed; `display EXPR` shows EXPR at each stop\n".into();
    }
    text
}

/// The call chain: the PC, then each caller's `JSR` found on the stack,
/// with its place and source line.
fn backtrace(d: &Debugger, sources: &mut Sources) -> String {
    let mut text = String::new();
    for (depth, at) in d.backtrace().into_iter().enumerate() {
        text.push_str(&format!("#{depth} {}", place(d, at)));
        if let Some((file, n)) = d.source_of(at) {
            let source = sources
                .line(&file, n)
                .map(|s| format!(": {}", s.trim()))
                .unwrap_or_default();
            text.push_str(&format!("  {file}:{n}{source}"));
        }
        text.push('\n');
    }
    text
}

/// `  adc.s:42: @wait: bit ADC_STATUS` for `address`, if its source is
/// known.
fn source_line(d: &Debugger, sources: &mut Sources, address: u16) -> String {
    match d.source_of(address) {
        Some((file, n)) => match sources.line(&file, n) {
            Some(source) => format!("  {file}:{n}: {}\n", source.trim_end()),
            None => format!("  {file}:{n}\n"),
        },
        None => String::new(),
    }
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
        let _ = write_dump(&mut text, start, &bytes);
    }
    // Addresses as everywhere else in the monitor: `$00F4:`.
    String::from_utf8_lossy(&text)
        .lines()
        .map(|row| format!("${row}\n"))
        .collect()
}

fn line_text(d: &Debugger, sources: &mut Sources, line: &Line) -> String {
    let bytes: Vec<String> = line.bytes.iter().map(|b| format!("{b:02X}")).collect();
    let label = line
        .label
        .clone()
        .or_else(|| d.symbols().place(line.address))
        .unwrap_or_default();
    let marker = if line.address == d.cpu().pc { '>' } else { ' ' };
    let instruction = named_instruction(d, sources, line);
    let text = match &line.source {
        Some((file, n)) => format!("{instruction:<30} {file}:{n}"),
        None => instruction,
    };
    format!(
        "{marker} ${:04X}  {:<8}  {:<20} {}\n",
        line.address,
        bytes.join(" "),
        label,
        text.trim_end()
    )
}

/// The instruction with its target named as the source names it: a
/// label, a cheap local (`@wait`), an unnamed label (`:+`, `:--`), the
/// address kept beside it; as decoded where nothing names it.
pub(crate) fn named_instruction(d: &Debugger, sources: &mut Sources, line: &Line) -> String {
    let bus = &d.robot().robot().bus;
    let peek = |at: u16| emulator::Bus::peek(bus, at);
    let instruction = isa::Instruction::decode_with(line.address, peek);
    let plain = instruction.to_string();
    let Some(target) = instruction.target() else {
        return plain;
    };
    // Page zero and immediate operands are data more often than places.
    if target < 0x100 && !plain.starts_with('B') && !plain.starts_with('J') {
        return plain;
    }
    let name = d
        .symbols()
        .label(target)
        .map(str::to_owned)
        .or_else(|| source_label(d, sources, line.address, target));
    match name {
        Some(name) => {
            let named = instruction
                .display_with(|at| (at == target).then_some(name.as_str()))
                .to_string();
            if named == plain {
                plain
            } else {
                format!("{named:<14} ; ${target:04X}")
            }
        }
        None => plain,
    }
}

/// The label the source wrote on the line that made `target`, as the
/// instruction at `from` would name it: `@wait`, or `:+`/`:-` (one sign per
/// unnamed label passed) for an unnamed one.
fn source_label(d: &Debugger, sources: &mut Sources, from: u16, target: u16) -> Option<String> {
    let (file, n) = d.source_of(target)?;
    // Only a line whose bytes begin at the target is labelled there.
    if d.address_of_line(&file, n) != Some(target) {
        return None;
    }
    // The label on the line itself, or alone on a line just above it.
    let mut n = n;
    let mut text = sources.line(&file, n)?;
    for above in (n.saturating_sub(4).max(1)..n).rev() {
        if label_of(&text).is_some() {
            break;
        }
        let Some(line) = sources.line(&file, above) else {
            break;
        };
        let bare = line.split(';').next().unwrap_or_default().trim();
        if bare.is_empty() {
            continue;
        }
        let only_label = label_of(&line)
            .is_some_and(|(_, rest)| rest.split(';').next().unwrap_or_default().trim().is_empty());
        if !only_label {
            break;
        }
        (n, text) = (above, line);
    }
    let trimmed = text.trim_start();
    if let Some(after) = trimmed.strip_prefix(':')
        && (after.is_empty() || after.starts_with(char::is_whitespace))
    {
        let (from_file, from_line) = d.source_of(from)?;
        if from_file != file {
            return None;
        }
        let unnamed = |sources: &mut Sources, lines: std::ops::RangeInclusive<u32>| {
            lines
                .filter(|&k| {
                    sources.line(&file, k).is_some_and(|l| {
                        let l = l.trim_start();
                        l.strip_prefix(':')
                            .is_some_and(|a| a.is_empty() || a.starts_with(char::is_whitespace))
                    })
                })
                .count()
        };
        let (sign, count) = if n > from_line {
            ('+', unnamed(sources, from_line + 1..=n))
        } else {
            ('-', unnamed(sources, n..=from_line))
        };
        return (count > 0).then(|| format!(":{}", sign.to_string().repeat(count)));
    }
    label_of(&text)
        .map(|(name, _)| name.to_owned())
        .filter(|name| !name.is_empty())
}

/// The label a source line starts with (`@wait:`, `loop:`, `:` for an
/// unnamed one, as ""), and what follows it.
fn label_of(line: &str) -> Option<(&str, &str)> {
    let trimmed = line.trim_start();
    let end = trimmed
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '@'))
        .unwrap_or(trimmed.len());
    let rest = trimmed[end..].strip_prefix(':')?;
    // `::` is a scope, not a label's end.
    (!rest.starts_with(':')).then_some((&trimmed[..end], rest))
}

fn stop_report(d: &mut Debugger, m: &mut Monitor, stop: &Stopped) -> String {
    let mut text = String::new();
    let (logs, dropped) = d.take_logs();
    for logged in logs {
        text.push_str(&format!(
            "log {} at {}: {}\n",
            logged.id,
            place(d, logged.pc),
            logged.text
        ));
    }
    if dropped > 0 {
        text.push_str(&format!(
            "({dropped} more log lines dropped: at most {} between stops)\n",
            crate::session::MAX_LOGS
        ));
    }
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
        Why::Paused => "paused (Ctrl-C)".into(),
    };
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
        text.push_str(&line_text(d, &mut m.sources, line));
        if let Some((file, n)) = &line.source
            && let Some(source) = m.sources.line(file, *n)
        {
            text.push_str(&format!("  {file}:{n}: {}\n", source.trim_end()));
        }
    }
    text.push_str(&format!("  {}\n", registers(d)));
    if m.displays.iter().any(Option::is_some) {
        text.push_str(&displays(d, m));
    }
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

/// Sixteen bytes a line: address, hex, and the printable characters (as
/// `scorpion read` shows a robot's memory).
///
/// # Errors
/// `out`'s write errors.
pub fn write_dump(
    out: &mut impl std::io::Write,
    address: u16,
    bytes: &[u8],
) -> std::io::Result<()> {
    for (row, chunk) in bytes.chunks(16).enumerate() {
        let at = usize::from(address) + row * 16;
        write!(out, "{at:04X}:")?;
        for byte in chunk {
            write!(out, " {byte:02X}")?;
        }
        let pad = 3 * (16 - chunk.len());
        let text: String = chunk
            .iter()
            .map(|&b| {
                if (0x20..0x7F).contains(&b) {
                    char::from(b)
                } else {
                    '.'
                }
            })
            .collect();
        writeln!(out, "{:pad$}  {text}", "")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn dump_layout() {
        let mut out = Vec::new();
        super::write_dump(&mut out, 0x0400, b"HELLO, SCORPION!\x4C\x00").expect("in memory");
        assert_eq!(
            String::from_utf8(out).expect("ASCII"),
            "0400: 48 45 4C 4C 4F 2C 20 53 43 4F 52 50 49 4F 4E 21  HELLO, SCORPION!\n\
             0410: 4C 00                                            L.\n"
        );
    }
}
