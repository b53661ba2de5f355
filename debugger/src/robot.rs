//! The monitor's language on a real robot (docs/DEBUGGING.md, "Debug on
//! the robot"): the same words and expressions as [`crate::monitor`], run
//! on an [`uploader::stub::RobotDebug`] over the robot's line. What a real
//! robot can do (break, delete, continue, step, next, regs, set, mem,
//! print, display, dis, `/` commands) is done; what it cannot (step back,
//! watchpoints, conditions asked at each hit...) is refused with the
//! reason. Nothing here prints: the CLI prints the replies.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::Duration;

use emulator::Cpu;
use uploader::stub::{Registers, Reply as Heard, RobotDebug, StubError};
use uploader::{LiveRead, Transport};

use crate::expr::{Expr, Machine, Register};
use crate::monitor::{Failure, Reply};
use crate::symbols::Symbols;

/// How long a command's answer, or a stop after `continue`, is waited for.
pub const WAIT: Duration = Duration::from_secs(2);

/// The monitor's commands on the robot, as `help` lists them.
pub const HELP: &str = "\
commands on the robot (addresses and values are expressions, as in the monitor):
  /1Q                  send a command down the line; its answer, or the stop it hits
  break ADDR | FILE:LINE
                       a JSR into the stub over the instruction there           (b)
  delete N             the image's bytes put back and read back
  info                 the breakpoints and displays
  continue             let the stopped handler go on; its answer or the next stop (c)
  step | next          one instruction (next, nexti: a JSR with its subroutine) (s, n)
  regs                 the registers at the stop                                  (r)
  set REG VALUE        a register or flag at the stop (PC: where it goes on)
  mem ADDR [LEN] | mem ADDR BYTE... | poke ADDR BYTE...
                       read or write memory (written bytes read back)             (m)
  print EXPR           an expression's value                                      (p)
  display [EXPR]       show EXPR after each command and stop (read with /7R while it
                       runs); undisplay N
  dis [ADDR] [N]       N instructions from ADDR (the PC)                          (d)
  help, quit (q)       quit removes the breakpoints and the stub's hook
refused on the robot: back, reverse-continue, who-wrote (a robot cannot be re-run),
watch (no data breakpoints), break in the ROM, if/hits/log (a JSR always stops),
finish/until (break where it should stop), trace, bt, list";

/// Where the images' instructions start, when their line tables say so
/// (a built image starts a source line at every instruction; its labels
/// count too): for [`RobotDebug::set_instruction_starts`], which refuses
/// a breakpoint anywhere else in the code. `None` for images without
/// line tables.
#[must_use]
pub fn instruction_starts(images: &[linker::Image]) -> Option<Vec<u16>> {
    if images.iter().all(|image| image.lines.entries.is_empty()) {
        return None;
    }
    Some(starts_of(images))
}

/// The images' labels and source lines' addresses, sorted: where every
/// instruction starts (the line tables start a line at each).
fn starts_of(images: &[linker::Image]) -> Vec<u16> {
    let mut starts: Vec<u16> = images
        .iter()
        .flat_map(|image| {
            let lines = image
                .lines
                .entries
                .iter()
                .filter_map(|entry| u16::try_from(entry.offset).ok());
            labels(image).chain(lines)
        })
        .collect();
    starts.sort_unstable();
    starts.dedup();
    starts
}

/// The addresses `image`'s symbols name.
fn labels(image: &linker::Image) -> impl Iterator<Item = u16> + '_ {
    image
        .symbols
        .iter()
        .filter_map(|symbol| u16::try_from(symbol.value).ok())
}

/// Where code may be jumped to, which a breakpoint's `JSR` must not
/// cover past its first instruction: the images' labels, and the target
/// of every branch, `JMP` and `JSR` among their instructions (decoded
/// where the line tables start one). Not every source line: a `JSR` over
/// an instruction of two bytes and the next is fine where nothing jumps
/// to that next one (fresh10 F4b: in `scorpion new`'s handler only
/// `jsr PUTCH` took a breakpoint, and no step could leave it).
fn jump_targets(images: &[linker::Image]) -> Vec<u16> {
    let mut targets: Vec<u16> = images.iter().flat_map(labels).collect();
    for image in images {
        let byte = |at: u16| {
            image.areas.iter().find_map(|area| {
                let offset = usize::try_from(u32::from(at).checked_sub(area.run)?).ok()?;
                area.bytes.get(offset).copied()
            })
        };
        for entry in &image.lines.entries {
            let Ok(at) = u16::try_from(entry.offset) else {
                continue;
            };
            let bytes: Vec<u8> = (0..3).map_while(|i| byte(at.wrapping_add(i))).collect();
            let Some(instruction) = isa::Instruction::decode(&bytes, at) else {
                continue;
            };
            let jumps = matches!(
                instruction.opcode.mnemonic,
                isa::Mnemonic::Jmp | isa::Mnemonic::Jsr
            ) && instruction.opcode.mode == isa::AddressingMode::Absolute;
            if jumps || instruction.opcode.mode == isa::AddressingMode::Relative {
                targets.extend(instruction.target());
            }
        }
    }
    targets.sort_unstable();
    targets.dedup();
    targets
}

/// What the monitor keeps on a robot between commands.
#[derive(Debug)]
pub struct RobotMonitor {
    symbols: Symbols,
    images: Vec<linker::Image>,
    /// Where code may be jumped to: labels and the targets of branches,
    /// jumps and calls.
    entries: Vec<u16>,
    /// Breakpoints by number.
    breakpoints: BTreeMap<u32, u16>,
    next_id: u32,
    displays: Vec<Option<Expr>>,
    /// The last command sent that nothing came back for in the time
    /// waited: the robot answers in order, so the next answer may be its.
    owed: Option<String>,
    /// The last command, when it was a step: what an empty line repeats.
    repeat: Option<String>,
    /// Where the images' source paths start (a stop names the user's
    /// line, not a built-in include's).
    root: std::path::PathBuf,
}

impl RobotMonitor {
    /// A monitor naming addresses with `symbols`, the images' line tables
    /// for `FILE:LINE`.
    #[must_use]
    pub fn new(symbols: Symbols, images: Vec<linker::Image>) -> RobotMonitor {
        let entries = jump_targets(&images);
        RobotMonitor {
            symbols,
            images,
            entries,
            breakpoints: BTreeMap::new(),
            next_id: 1,
            displays: Vec::new(),
            owed: None,
            repeat: None,
            root: std::path::PathBuf::from("."),
        }
    }

    /// Where the images' source paths start (by default, here).
    pub fn set_root(&mut self, root: std::path::PathBuf) {
        self.root = root;
    }

    /// Where code may be jumped to (labels and the targets of branches,
    /// jumps and calls), which a breakpoint's `JSR` must not cover.
    #[must_use]
    pub fn entries(&self) -> &[u16] {
        &self.entries
    }

    /// The names the monitor knows.
    #[must_use]
    pub fn symbols(&self) -> &Symbols {
        &self.symbols
    }

    /// The images the robot runs (their line tables).
    #[must_use]
    pub fn images(&self) -> &[linker::Image] {
        &self.images
    }

    /// An expression's value, as `print` gives it: its memory read from
    /// the robot (`/7R` while it runs, the stub at a stop).
    ///
    /// # Errors
    /// [`Failure::Usage`] for an expression that does not read, or a
    /// register while running; [`Failure::Line`] when the line failed.
    pub fn value<T: Transport>(&self, d: &mut RobotDebug<T>, text: &str) -> Result<i64, Failure> {
        let expr = self.parse(text)?;
        self.eval(d, &expr)
    }

    /// A breakpoint at `address` not set, as said: a refusal with the
    /// nearest instruction after it that takes one, as a place to type
    /// (the one a refusal advises may be refused in turn).
    pub fn refused_breakpoint<T: Transport>(
        &self,
        d: &RobotDebug<T>,
        address: u16,
        error: StubError,
    ) -> Failure {
        // fresh15 F4: not where one is already, nor one whose bytes the
        // breakpoints set would overlap.
        let already = d.breakpoints().any(|at| at == address);
        let instead = (matches!(error, StubError::Refused { .. }) && !already)
            .then(|| self.nearest_free(d, address))
            .flatten();
        match (failure(error), instead) {
            (Failure::Usage(said), Some(instead)) => Failure::Usage(format!(
                "{said}\n  the nearest instruction after it that takes one: {}{} (`break ${instead:04X}`)",
                self.place(instead),
                self.user_line(instead)
            )),
            (other, _) => other,
        }
    }

    /// The first instruction after `address` that takes a breakpoint and
    /// whose bytes no breakpoint set covers, a few instructions on at most.
    fn nearest_free<T: Transport>(&self, d: &RobotDebug<T>, address: u16) -> Option<u16> {
        use uploader::stub::patch::{nearest, plan};
        let image = d.image();
        let span = |at: u16| {
            let len = plan(at, image, &self.entries).map_or(3, |p| p.displaced.len() as u32);
            u32::from(at)..u32::from(at) + len
        };
        let set: Vec<std::ops::Range<u32>> = d.breakpoints().map(span).collect();
        let mut at = address;
        for _ in 0..16 {
            at = nearest(at, image, &self.entries)?;
            let here = span(at);
            if !set.iter().any(|b| b.start < here.end && here.start < b.end) {
                return Some(at);
            }
        }
        None
    }

    /// ` at FILE:LINE`, the user's source line `address` came from (not a
    /// built-in include's); empty where none did.
    fn user_line(&self, address: u16) -> String {
        let is_users = |file: &str| hostfs::is_users_source(&self.root, file);
        self.images
            .iter()
            .find_map(|image| image.user_source_of(u32::from(address), &is_users))
            .map(|(file, line)| format!(" at {file}:{line}"))
            .unwrap_or_default()
    }

    /// The name of `address` (a label or a source line), for a frame.
    #[must_use]
    pub fn place(&self, address: u16) -> String {
        match self.symbols.place(address) {
            Some(name) => format!("${address:04X} ({name})"),
            None => format!("${address:04X}"),
        }
    }

    /// Runs one command line on the robot.
    ///
    /// # Errors
    /// [`Failure::Usage`] for a line that cannot be run, or is refused on
    /// a robot (with the reason); [`Failure::Line`] when the line failed.
    pub fn command<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        line: &str,
    ) -> Result<Reply, Failure> {
        // Enter on an empty line repeats the last step, as the virtual
        // monitor's does (fresh10 F13).
        let repeated;
        let line = if line.trim().is_empty() {
            match self.repeat.clone() {
                Some(step) => {
                    repeated = step;
                    repeated.as_str()
                }
                None => return Ok(Reply::Text(String::new())),
            }
        } else {
            line
        };
        let mut words = line.split_whitespace();
        let Some(verb) = words.next() else {
            return Ok(Reply::Text(String::new()));
        };
        self.repeat = matches!(
            verb,
            "step" | "s" | "stepi" | "si" | "next" | "n" | "nexti" | "ni"
        )
        .then(|| verb.to_owned());
        let rest: Vec<&str> = words.collect();
        let after = line[verb.len()..].trim();
        // A command that needs a stop, while the robot seems to run: the
        // stop's frame may have been lost on the line. Looked for (one
        // frame to the stub), told first, then the command runs.
        let mut found = String::new();
        if NEEDS_A_STOP.contains(&verb) && d.stopped().is_none() {
            d.look_for_stop().map_err(failure)?;
            found = self.with_unasked(d, found)?;
        }
        let text = match verb {
            "help" | "h" | "?" => format!("{HELP}\n"),
            "quit" | "q" | "exit" => return Ok(Reply::Quit),
            _ if verb.starts_with('/') => self.send(d, line)?,
            "send" => self.send(d, after)?,
            "break" | "b" => self.add_break(d, after)?,
            "delete" => {
                let [n] = rest.as_slice() else {
                    return Err(usage("delete N (watchpoints are refused on the robot)"));
                };
                let id: u32 = n.parse().map_err(|_| usage("delete N"))?;
                let address = *self
                    .breakpoints
                    .get(&id)
                    .ok_or_else(|| usage(&format!("no breakpoint {id}")))?;
                // Forgotten once out: a removal the line cut short leaves it
                // listed, to be deleted again (or taken out at `quit`).
                d.remove_breakpoint(address).map_err(failure)?;
                self.breakpoints.remove(&id);
                format!(
                    "deleted breakpoint {id}: ${address:04X} holds its own bytes again (read back)\n"
                )
            }
            "info" => {
                let mut text = String::new();
                for (id, address) in &self.breakpoints {
                    text.push_str(&format!("breakpoint {id}: {}\n", self.place(*address)));
                }
                for (id, shown) in self.displays.iter().enumerate() {
                    if let Some(shown) = shown {
                        text.push_str(&format!("display {}: {shown}\n", id + 1));
                    }
                }
                if text.is_empty() {
                    text = "no breakpoints\n".into();
                }
                text
            }
            "continue" | "c" | "run" => {
                d.resume().map_err(failure)?;
                let heard = d.wait_event(WAIT).map_err(failure)?;
                self.heard(d, &heard)?
            }
            "step" | "s" | "stepi" | "si" | "next" | "n" | "nexti" | "ni" => {
                if !rest.is_empty() {
                    return Err(usage(
                        "step takes no count on the robot: each step patches and unpatches over the line",
                    ));
                }
                let over = matches!(verb, "next" | "n" | "nexti" | "ni");
                // fresh19 F6: the refusal names the command given.
                let heard = d
                    .step(&self.entries, over, WAIT)
                    .map_err(|error| match error {
                        uploader::stub::StubError::Refused { what, reason } if what == "step" => {
                            failure(uploader::stub::StubError::Refused {
                                what: if over { "next" } else { "step" }.into(),
                                reason,
                            })
                        }
                        other => failure(other),
                    })?;
                let mut text = self.heard(d, &heard)?;
                if matches!(heard, Heard::Answer(_)) {
                    // The instruction ended the answer (`JSR PUTEOL`): the
                    // stop comes after it, or it ran on.
                    if let Some(more) = d.poll(WAIT).map_err(failure)? {
                        text.push_str(&self.heard(d, &more)?);
                    }
                }
                text
            }
            "regs" | "r" => {
                let registers = stopped(d, "regs")?;
                format!("{}\n", show_registers(&registers))
            }
            "set" => self.set(d, &rest)?,
            "mem" | "m" | "poke" => self.mem(d, verb, &rest)?,
            "print" | "p" => {
                let expr = self.parse(after)?;
                let (value, changing) = self.eval_live(d, &expr)?;
                format!("{}\n", shown_value(value, &changing))
            }
            "display" => {
                if after.is_empty() {
                    self.displays(d)?
                } else {
                    if self.displays.iter().flatten().count() >= crate::monitor::DISPLAYS_MAX {
                        return Err(usage(&format!(
                            "at most {} expressions are displayed at once; `undisplay N` one first",
                            crate::monitor::DISPLAYS_MAX
                        )));
                    }
                    let expr = self.parse(after)?;
                    // fresh13 F2: shown at once, as on the virtual robot,
                    // not only at the next stop.
                    let value = self.shown(d, &expr)?;
                    self.displays.push(Some(expr));
                    format!("display {}: {after} = {value}\n", self.displays.len())
                }
            }
            "undisplay" => {
                let n: usize = after.parse().map_err(|_| usage("undisplay N"))?;
                match self.displays.get_mut(n.wrapping_sub(1)) {
                    Some(slot @ Some(_)) => *slot = None,
                    _ => return Err(usage(&format!("no display {n}"))),
                }
                format!("display {n} removed\n")
            }
            "dis" | "d" => self.dis(d, &rest)?,
            "watch" | "w" => {
                return Err(refused(
                    "watchpoints",
                    "the 6502 has no data breakpoints and the ROM no hook on every access; `display` an expression to see it after each command",
                ));
            }
            "back" | "bs" | "reverse-step" | "reverse-continue" | "rc" | "who-wrote" => {
                return Err(refused(
                    verb,
                    "going back re-runs the robot from copies of it, and a real robot can be neither copied nor re-run; use the virtual Scorpion (`scorpion debug` without --port)",
                ));
            }
            "finish" | "f" | "until" | "u" => {
                return Err(refused(
                    verb,
                    "where the code returns or a line ends may be in the ROM, which cannot be patched: set a breakpoint where it should stop and `continue`",
                ));
            }
            "trace" | "bumpers" | "bt" | "list" | "l" => {
                return Err(refused(
                    verb,
                    "it needs the virtual Scorpion's insides; the robot shows only its line",
                ));
            }
            _ => {
                return Err(usage(&format!(
                    "unknown command `{verb}`; `help` lists them"
                )));
            }
        };
        Ok(Reply::Text(found + &self.with_unasked(d, text)?))
    }

    /// `text`, then the stop that came while the command was busy on the
    /// line (a breakpoint in code the control loop runs, hit while it was
    /// set or while memory was read), if one did.
    fn with_unasked<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        mut text: String,
    ) -> Result<String, Failure> {
        if let Some(registers) = d.take_unasked() {
            text.push_str("(a stop no command waited for) ");
            text.push_str(&self.heard(d, &Heard::Stopped(registers))?);
            text.push_str(&garbled_own(&registers));
        }
        Ok(text)
    }

    /// What the running robot said unasked within `wait` (a stop a step
    /// ran on to, a command another program sent, an answer), as text:
    /// the front end asks before each command, so that it is run on the
    /// robot as it is.
    ///
    /// # Errors
    /// [`Failure::Line`] when the line failed.
    pub fn notice<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        wait: Duration,
    ) -> Result<Option<String>, Failure> {
        match d.poll(wait).map_err(failure)? {
            None => Ok(None),
            Some(heard) => {
                let what = match heard {
                    Heard::Stopped(_) => "(a stop no command waited for) ",
                    _ => "(unasked) ",
                };
                if let Heard::Answer(_) = heard {
                    // Most likely the answer the last silent command owed.
                    self.owed = None;
                }
                let own = match &heard {
                    Heard::Stopped(registers) => garbled_own(registers),
                    _ => String::new(),
                };
                Ok(Some(format!("{what}{}{own}", self.heard(d, &heard)?)))
            }
        }
    }

    fn send<T: Transport>(&mut self, d: &mut RobotDebug<T>, text: &str) -> Result<String, Failure> {
        crate::line::command(text).map_err(Failure::Usage)?;
        let heard = d.command(text.as_bytes(), WAIT).map_err(failure)?;
        let mut said = format!("sent {text}\n{}", self.heard(d, &heard)?);
        match (&heard, self.owed.take()) {
            // fresh10 F23: a slow command's answer came after the next was
            // sent, and was shown as that one's.
            (Heard::Answer(_), Some(earlier)) => {
                let _ = writeln!(
                    said,
                    "  (the robot answers in order: this may be the answer of {earlier}, which had not answered; this command's would follow)"
                );
            }
            (Heard::Silent, _) => self.owed = Some(text.to_owned()),
            _ => {}
        }
        Ok(said)
    }

    /// What came back, as text: an answer, a stop, or silence; then the
    /// displays.
    fn heard<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        heard: &Heard,
    ) -> Result<String, Failure> {
        let mut text = match heard {
            Heard::Answer(answer) => format!(
                "answer: {}\n",
                String::from_utf8_lossy(answer.strip_suffix(b"\r").unwrap_or(answer))
            ),
            Heard::Stopped(registers) => {
                let id = self
                    .breakpoints
                    .iter()
                    .find(|(_, at)| **at == registers.pc)
                    .map(|(id, _)| format!("breakpoint {id}, "))
                    .unwrap_or_default();
                // The source line too (fresh11 F7): `list` and `bt` are
                // refused on the robot, so the stop says where it is.
                let line = self.user_line(registers.pc);
                format!(
                    "stopped: {id}{}{line}\n  {}\n",
                    self.place(registers.pc),
                    show_registers(registers)
                )
            }
            Heard::Silent => format!("running (nothing came back within {} s)\n", WAIT.as_secs()),
        };
        if self.displays.iter().any(Option::is_some) {
            text.push_str(&self.displays(d)?);
        }
        Ok(text)
    }

    fn add_break<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        after: &str,
    ) -> Result<String, Failure> {
        if after.is_empty() {
            return Err(usage("break ADDR | FILE:LINE"));
        }
        if after
            .split_whitespace()
            .any(|w| matches!(w, "if" | "hits" | "log"))
        {
            return Err(refused(
                "a condition, a hit count or a log point",
                "on the robot a breakpoint is a JSR that always stops the handler; the host would have to be asked at each hit, over the line",
            ));
        }
        if after.starts_with('/') || after == "unknown" {
            return Err(refused(
                "a breakpoint on a command or the hook",
                "the ROM's command parser cannot be patched; break on the handler's first instruction",
            ));
        }
        let address = match file_line(after) {
            Some((file, line)) => self
                .images
                .iter()
                .filter_map(|image| image.address_of_line(file, line))
                .min()
                .and_then(|at| u16::try_from(at).ok())
                .ok_or_else(|| usage(&format!("no code came from {file}:{line}")))?,
            None => {
                let expr = self.parse(after)?;
                u16::try_from(self.eval(d, &expr)?)
                    .map_err(|_| usage(&format!("{after} is no address")))?
            }
        };
        if let Err(error) = d.set_breakpoint(address, &self.entries) {
            return Err(self.refused_breakpoint(d, address, error));
        }
        let id = self.next_id;
        self.next_id += 1;
        self.breakpoints.insert(id, address);
        Ok(format!("breakpoint {id}: {}\n", self.place(address)))
    }

    fn set<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        rest: &[&str],
    ) -> Result<String, Failure> {
        let [name, value @ ..] = rest else {
            return Err(usage("set REG VALUE"));
        };
        let register = Register::named(name).ok_or_else(|| {
            usage(&format!(
                "`{name}` is no register or flag: A X Y S P PC C Z I D V N"
            ))
        })?;
        let old = stopped(d, "set")?;
        let mut registers = old;
        let expr = self.parse(&value.join(" "))?;
        let value = self.eval(d, &expr)?;
        let value = u16::try_from(value)
            .ok()
            .filter(|v| *v <= register.max())
            .ok_or_else(|| usage(&format!("{value} does not fit {register}")))?;
        let mut cpu = cpu_of(&registers);
        register.write(&mut cpu, value);
        registers = Registers {
            pc: cpu.pc,
            a: cpu.a,
            x: cpu.x,
            y: cpu.y,
            // B and the unused bit as the stop had them (PHP's): they are
            // no flags, and `set P` leaves them as shown.
            p: (cpu.p() & !0x30) | (old.p & 0x30),
            s: cpu.s,
        };
        d.set_registers(registers).map_err(failure)?;
        Ok(format!("{}\n", show_registers(&registers)))
    }

    fn mem<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        verb: &str,
        rest: &[&str],
    ) -> Result<String, Failure> {
        let words: Vec<&str> = rest.iter().copied().filter(|w| *w != "=").collect();
        let [at, values @ ..] = words.as_slice() else {
            return Err(usage("mem ADDR [LEN] | mem ADDR BYTE..."));
        };
        let expr = self.parse(at)?;
        let address = u16::try_from(self.eval(d, &expr)?).map_err(|_| usage("no address"))?;
        let writing = verb == "poke" || values.len() > 1 || rest.contains(&"=");
        if writing {
            let mut bytes = Vec::new();
            for word in values {
                let expr = self.parse(word)?;
                let value = self.eval(d, &expr)?;
                bytes.push(u8::try_from(value).map_err(|_| usage(&format!("{word} is no byte")))?);
            }
            let changing = d.write_as_program_live(address, &bytes).map_err(failure)?;
            if !changing.is_empty() {
                // fresh17 F8: a counter the program keeps took the write,
                // and has moved on since.
                return Ok(format!(
                    "${address:04X}: {} (written; the robot's program writes {} as it runs, and has changed {} since)\n",
                    uploader::stub::error_hex(&bytes),
                    uploader::addresses_text(&changing),
                    if changing.len() == 1 { "it" } else { "them" }
                ));
            }
            return Ok(format!(
                "${address:04X}: {} (read back)\n",
                uploader::stub::error_hex(&bytes)
            ));
        }
        let len = match values.first() {
            Some(word) => {
                let expr = self.parse(word)?;
                usize::try_from(self.eval(d, &expr)?)
                    .ok()
                    .filter(|n| (1..=4096).contains(n))
                    .ok_or_else(|| usage("mem ADDR LEN: 1 to 4096 bytes on the robot"))?
            }
            None => 16,
        };
        let len = len.min(0x1_0000 - usize::from(address));
        let read = read_for_person(d, address, len)?;
        let mut text = String::new();
        for (i, row) in read.bytes.chunks(16).enumerate() {
            let at = address.wrapping_add(16 * i as u16);
            text.push_str(&format!("${at:04X}: {}\n", uploader::stub::error_hex(row)));
        }
        if !read.changing.is_empty() {
            text.push_str(&format!("{}\n", changing_note(&read.changing)));
        }
        Ok(text)
    }

    fn dis<T: Transport>(
        &mut self,
        d: &mut RobotDebug<T>,
        rest: &[&str],
    ) -> Result<String, Failure> {
        let address = match rest.first() {
            Some(word) => {
                let expr = self.parse(word)?;
                u16::try_from(self.eval(d, &expr)?).map_err(|_| usage("no address"))?
            }
            None => stopped(d, "dis without an address")?.pc,
        };
        let count: usize = match rest.get(1) {
            Some(n) => n
                .parse()
                .ok()
                .filter(|n| (1..=256).contains(n))
                .ok_or_else(|| usage("dis [ADDR] [N]: N 1 to 256 on the robot"))?,
            None => 8,
        };
        let len = (count * 3).min(0x1_0000 - usize::from(address));
        let bytes = read_for_person(d, address, len)?.bytes;
        let mut text = String::new();
        for line in isa::Disassembler::new(&bytes, address).take(count) {
            let shown = line.display_with(|at| self.symbols.label(at));
            text.push_str(&format!("{shown}\n"));
        }
        Ok(text)
    }

    fn displays<T: Transport>(&mut self, d: &mut RobotDebug<T>) -> Result<String, Failure> {
        let mut text = String::new();
        let shown: Vec<(usize, Expr)> = self
            .displays
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.clone().map(|e| (i + 1, e)))
            .collect();
        for (n, expr) in shown {
            let value = self.shown(d, &expr)?;
            text.push_str(&format!("{n}: {expr} = {value}\n"));
        }
        Ok(text)
    }

    /// A displayed expression's value, or why it has none now (a register
    /// while the robot runs).
    fn shown<T: Transport>(&self, d: &mut RobotDebug<T>, expr: &Expr) -> Result<String, Failure> {
        // hostile14 F8, hostile16 F4: memory the robot writes as it runs
        // (a counter) is a value that changes: shown as read at one
        // moment, and said to change.
        match self.eval_live(d, expr) {
            Ok((value, changing)) => Ok(shown_value(value, &changing)),
            Err(Failure::Usage(why)) => Ok(format!("({why})")),
            Err(other) => Err(other),
        }
    }

    fn parse(&self, text: &str) -> Result<Expr, Failure> {
        Expr::parse(text, &self.symbols).map_err(|error| {
            Failure::Usage(format!(
                "column {}: {}\n{}",
                error.column,
                error.reason,
                error.pointed()
            ))
        })
    }

    /// An expression's value: its memory read from the robot (`/7R` while
    /// it runs, the stub at a stop), its registers the stop's.
    fn eval<T: Transport>(&self, d: &mut RobotDebug<T>, expr: &Expr) -> Result<i64, Failure> {
        Ok(self.eval_live(d, expr)?.0)
    }

    /// [`Self::eval`], with the addresses it read that the program wrote
    /// while they were read (sorted).
    fn eval_live<T: Transport>(
        &self,
        d: &mut RobotDebug<T>,
        expr: &Expr,
    ) -> Result<(i64, Vec<u16>), Failure> {
        let snapshot = Snapshot {
            cpu: d.stopped().map(|r| cpu_of(&r)).unwrap_or_default(),
            registers_read: Cell::new(false),
            memory: RefCell::new(BTreeMap::new()),
            missing: RefCell::new(Vec::new()),
        };
        let mut changing = std::collections::BTreeSet::new();
        // Each round reads what the last one found missing ([[x]] reads twice).
        for _ in 0..8 {
            let value = expr.eval(&snapshot);
            // hostile14 F3: told by the evaluation itself, not the text
            // (`$A`, `'X'` read no register).
            if d.stopped().is_none() && snapshot.registers_read.get() {
                return Err(usage(
                    "the robot is running: registers are known only at a stop",
                ));
            }
            let mut missing: Vec<u16> = snapshot.missing.borrow_mut().drain(..).collect();
            if missing.is_empty() {
                return value
                    .map(|value| (value, changing.into_iter().collect()))
                    .map_err(|error| Failure::Usage(error.to_string()));
            }
            missing.sort_unstable();
            missing.dedup();
            // hostile14 F4: a byte a question took 18 s for a display of a
            // thousand bytes, at every command. Neighbours are read in one
            // span (a question costs as much as a few bytes more).
            for (start, len) in spans(&missing) {
                if d.interrupted() {
                    return Err(usage("interrupted"));
                }
                let read = read_for_person(d, start, len)?;
                changing.extend(read.changing);
                let mut memory = snapshot.memory.borrow_mut();
                for (i, byte) in read.bytes.into_iter().enumerate() {
                    memory.insert(start.wrapping_add(i as u16), byte);
                }
            }
        }
        Err(usage("the expression reads memory through too many levels"))
    }
}

/// `len` bytes at `address` as the program sees them, for a person (a
/// `mem`, a `dis`, an expression's `[...]`): refused where a read would
/// change a card's or the board's register ([`RobotDebug::refuse_read`]).
///
/// Memory the program writes as it runs (a counter) is read as it was at
/// one moment, its addresses named in [`LiveRead::changing`]: a person
/// watching a running robot wants its value, not a refusal.
fn read_for_person<T: Transport>(
    d: &mut RobotDebug<T>,
    address: u16,
    len: usize,
) -> Result<LiveRead, Failure> {
    if let Some((_, reason)) = d.refuse_read(address, len) {
        let bytes = if len == 1 { "byte" } else { "bytes" };
        return Err(Failure::Usage(format!(
            "a read of ${address:04X} ({len} {bytes}) is refused on the robot: {reason}"
        )));
    }
    d.read_live_as_program(address, len).map_err(failure)
}

/// fresh15 F6: a stop no command waited for whose A and X are a command the
/// monitor itself sends (a `/7R` read, a `/9W` or `/7W` write, a `/1X`)
/// is most likely that command, garbled on a noisy line into one the ROM
/// passed down `HOOK_UNKNOWN` (a well-formed one never goes there): said,
/// so that it is not taken for a command of the user's. Empty otherwise.
pub(crate) fn garbled_own(registers: &Registers) -> String {
    let own = match (registers.a, registers.x) {
        (b'R', 7) => "/7R (a read of memory)",
        (b'W', 9 | 7) => "/9W or /7W (a write of memory)",
        (b'X', 1) => "/1X (a look at the robot)",
        _ => return String::new(),
    };
    format!(
        "note: A='{}' X={} is the monitor's own {own}, garbled on the line into a command the ROM passes down HOOK_UNKNOWN: no command of yours; `continue` lets it go on\n",
        char::from(registers.a),
        registers.x
    )
}

/// A value as `print` and `display` show it, with the note of
/// [`changing_note`] where it was read from memory that changes.
fn shown_value(value: i64, changing: &[u16]) -> String {
    if changing.is_empty() {
        crate::expr::show(value)
    } else {
        format!("{} {}", crate::expr::show(value), changing_note(changing))
    }
}

/// What is said after a value read where the program writes as it runs.
fn changing_note(changing: &[u16]) -> String {
    format!(
        "(changing: the robot wrote {} while it was read, as it runs; one moment's value)",
        uploader::addresses_text(changing)
    )
}

/// The most bytes read between two wanted ones rather than asking again.
const SPAN_GAP: u16 = 16;

/// Sorted addresses as spans (first, length) that take in every one,
/// neighbours no more than [`SPAN_GAP`] apart in one.
fn spans(sorted: &[u16]) -> Vec<(u16, usize)> {
    let mut spans: Vec<(u16, u16)> = Vec::new();
    for &at in sorted {
        match spans.last_mut() {
            Some((_, last)) if at.wrapping_sub(*last) <= SPAN_GAP && at > *last => *last = at,
            _ => spans.push((at, at)),
        }
    }
    spans
        .into_iter()
        .map(|(first, last)| (first, usize::from(last - first) + 1))
        .collect()
}

/// Registers and memory fetched from the robot for one evaluation.
struct Snapshot {
    cpu: Cpu,
    /// Whether the evaluation read a register.
    registers_read: Cell<bool>,
    memory: RefCell<BTreeMap<u16, u8>>,
    missing: RefCell<Vec<u16>>,
}

impl Machine for Snapshot {
    fn cpu(&self) -> &Cpu {
        self.registers_read.set(true);
        &self.cpu
    }

    fn peek(&self, address: u16) -> u8 {
        if let Some(&byte) = self.memory.borrow().get(&address) {
            return byte;
        }
        self.missing.borrow_mut().push(address);
        0
    }
}

fn cpu_of(registers: &Registers) -> Cpu {
    let mut cpu = Cpu::default();
    cpu.a = registers.a;
    cpu.x = registers.x;
    cpu.y = registers.y;
    cpu.s = registers.s;
    cpu.pc = registers.pc;
    cpu.set_p(registers.p);
    cpu
}

/// The registers as the monitor shows them.
#[must_use]
pub fn show_registers(r: &Registers) -> String {
    format!(
        "PC=${:04X} A=${:02X} X=${:02X} Y=${:02X} S=${:02X} P=${:02X}",
        r.pc, r.a, r.x, r.y, r.s, r.p
    )
}

/// The commands that need the robot stopped: before them a stop whose
/// frame was lost is looked for.
const NEEDS_A_STOP: [&str; 14] = [
    "continue", "c", "run", "step", "s", "stepi", "si", "next", "n", "nexti", "ni", "regs", "r",
    "set",
];

fn stopped<T: Transport>(d: &RobotDebug<T>, what: &str) -> Result<Registers, Failure> {
    d.stopped().ok_or_else(|| {
        usage(&format!(
            "`{what}` needs a stop: the robot is running (break somewhere, then send the command that gets there)"
        ))
    })
}

fn file_line(text: &str) -> Option<(&str, u32)> {
    let (file, line) = text.rsplit_once(':')?;
    Some((file, line.parse().ok()?)).filter(|(file, _)| !file.is_empty())
}

fn usage(text: &str) -> Failure {
    Failure::Usage(text.to_owned())
}

fn refused(what: &str, reason: &str) -> Failure {
    Failure::Usage(format!("{what} is refused on the robot: {reason}"))
}

/// A refusal is the user's to read; anything else is the line's.
pub(crate) fn failure(error: StubError) -> Failure {
    match error {
        StubError::Refused { .. } => Failure::Usage(error.to_string()),
        other => Failure::Line(Box::new(other)),
    }
}
