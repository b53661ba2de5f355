//! A DAP session on a real robot over its line (`launch` or `attach` with
//! `port`; docs/DEBUGGING.md, "Debug on the robot"): the requests a robot
//! can answer are run through the debug stub ([`uploader::stub::RobotDebug`])
//! with the monitor's robot language ([`crate::robot::RobotMonitor`]) for
//! expressions, steps and registers; the rest are refused with the reason.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use base64::Engine as _;
use serde_json::{Value, json};
use uploader::Transport;
use uploader::stub::{Registers, Reply as Heard, RobotDebug};

use super::arguments::Arguments;
use super::disassemble;
use super::memory::REGISTERS;
use super::protocol::{Outbox, Request};
use crate::monitor::Reply;
use crate::robot::{RobotMonitor, WAIT, failure};

/// How long a running robot is listened to between looks for requests.
const LISTEN: Duration = Duration::from_millis(20);
/// The only thread: the 6502.
const THREAD: i64 = 1;
/// The most bytes `readMemory` asks the robot for at once.
const MAX_READ: i64 = 4096;

/// What a robot cannot do, and why: the answer to those requests.
const CANNOT: &str = "a real robot cannot do this over its line";

/// The robot attached and what the session knows of it.
pub struct RobotSession {
    robot: Option<RobotDebug<Box<dyn Transport>>>,
    monitor: RobotMonitor,
    root: PathBuf,
    /// Breakpoints by the client's numbers: the source they came from and
    /// their address.
    breakpoints: BTreeMap<i64, (String, u16)>,
    next_id: i64,
    running: bool,
    /// A `next` or `stepIn` ran on (its stop had not come when it was
    /// answered): the next stop that no breakpoint of the client's made is
    /// where the step ended.
    stepping: bool,
    /// The launch's `stopOnEntry`.
    stop_on_entry: bool,
    /// The launch's `commands`, sent at `configurationDone`.
    commands: Vec<String>,
}

impl std::fmt::Debug for RobotSession {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RobotSession")
            .field("breakpoints", &self.breakpoints)
            .field("running", &self.running)
            .finish_non_exhaustive()
    }
}

/// What follows a response.
enum After {
    Nothing,
    Run,
    Heard(Heard, &'static str),
    /// A line for the editor's console, after the response.
    Console(String),
    /// `configurationDone` on a running robot: the launch's `stopOnEntry`
    /// and `commands` are seen to.
    Configured,
    Exit,
}

impl RobotSession {
    /// Lets the robot go as `disconnect` does (breakpoints out, a stopped
    /// robot let go on, the hook given back), where no `disconnect` came:
    /// the editor went away, or the adapter was told to stop.
    ///
    /// # Errors
    /// What went wrong on the line, said.
    pub fn let_go(&mut self) -> Result<(), String> {
        self.running = false;
        match self.robot.take() {
            Some(robot) => robot.detach().map(|_| ()).map_err(|e| failure(e).message()),
            None => Ok(()),
        }
    }

    /// A session on the `attached` robot.
    #[must_use]
    pub fn new(attached: super::Attached) -> RobotSession {
        let super::Attached {
            robot,
            symbols,
            images,
            root,
        } = attached;
        let mut monitor = RobotMonitor::new(symbols, images);
        monitor.set_root(root.clone());
        RobotSession {
            robot: Some(robot),
            monitor,
            root,
            breakpoints: BTreeMap::new(),
            next_id: 1,
            running: false,
            stepping: false,
            stop_on_entry: false,
            commands: Vec::new(),
        }
    }

    /// The launch's `stopOnEntry` and `commands` (fresh10 F18: both were
    /// ignored on a port, with no word).
    pub fn configure(&mut self, stop_on_entry: bool, commands: Vec<String>) {
        self.stop_on_entry = stop_on_entry;
        self.commands = commands;
    }

    /// At `configurationDone` on a running robot: `stopOnEntry` said to
    /// be impossible, and `commands` sent down the line in order, each
    /// answer as output, until one stops the robot.
    fn configured(&mut self, outbox: &Outbox) -> std::io::Result<()> {
        self.running = true;
        if self.stop_on_entry {
            outbox.output(
                "console",
                "stopOnEntry: a robot cannot be stopped from its line (its control loop runs on; the stub runs only when a breakpoint's JSR calls it): set a breakpoint where it should stop\n",
            )?;
        }
        let commands = std::mem::take(&mut self.commands);
        for (i, command) in commands.iter().enumerate() {
            let sent = crate::line::command(command).and_then(|_| {
                self.robot()?
                    .command(command.as_bytes(), WAIT)
                    .map_err(|e| failure(e).message())
            });
            match sent {
                Ok(heard) => {
                    self.heard(outbox, &heard, "breakpoint")?;
                    if matches!(heard, Heard::Stopped(_)) {
                        if i + 1 < commands.len() {
                            outbox.output(
                                "console",
                                &format!(
                                    "`commands`: {} not sent, the robot is stopped at a breakpoint\n",
                                    commands[i + 1..].join(" ")
                                ),
                            )?;
                        }
                        break;
                    }
                }
                Err(why) => {
                    outbox.output("stderr", &format!("`commands`: {command}: {why}\n"))?;
                    break;
                }
            }
        }
        Ok(())
    }

    /// What attach found of a session that did not detach and cleaned up,
    /// and of data among the code (the sentences the monitor prints), if
    /// anything: for the editor's console before the first stop.
    #[must_use]
    pub fn recovery(&self) -> Option<String> {
        let recovery = self.robot.as_ref()?.recovery();
        let sentences: Vec<String> = recovery
            .found()
            .then(|| recovery.describe())
            .into_iter()
            .chain(recovery.data_note())
            .collect();
        (!sentences.is_empty()).then(|| sentences.join("\n"))
    }

    /// The robot runs its control loop (between requests, its line is
    /// listened to).
    #[must_use]
    pub fn running(&self) -> bool {
        self.running
    }

    /// What the robot's `initialize` capabilities are: no going back, no
    /// data breakpoints, no conditions (sent as a `capabilities` event
    /// once the robot is attached).
    #[must_use]
    pub fn capabilities() -> Value {
        json!({
            "supportsConfigurationDoneRequest": true,
            "supportsStepBack": false,
            "supportsDataBreakpoints": false,
            "supportsConditionalBreakpoints": false,
            "supportsHitConditionalBreakpoints": false,
            "supportsLogPoints": false,
            "supportsFunctionBreakpoints": false,
            "supportsInstructionBreakpoints": false,
            "supportsSetVariable": true,
            "supportsReadMemoryRequest": true,
            "supportsWriteMemoryRequest": true,
            "supportsDisassembleRequest": false,
            "supportsRestartRequest": false,
            "supportsTerminateRequest": false,
            "supportsStepInTargetsRequest": false,
            "supportsEvaluateForHovers": true,
            "supportsExceptionInfoRequest": false,
            "exceptionBreakpointFilters": [],
        })
    }

    /// Answers a request; false at `disconnect`.
    ///
    /// # Errors
    /// The output's write errors.
    pub fn handle(&mut self, outbox: &Outbox, request: &Request) -> std::io::Result<bool> {
        let (result, after) = match self.answer(request) {
            Ok((body, after)) => (Ok(body), after),
            Err(why) => (Err(why), After::Nothing),
        };
        outbox.respond(request.seq, &request.command, result)?;
        match after {
            After::Nothing => {}
            After::Run => self.running = true,
            After::Heard(heard, reason) => self.heard(outbox, &heard, reason)?,
            After::Console(text) => outbox.output("console", &text)?,
            After::Configured => self.configured(outbox)?,
            After::Exit => {
                // `terminate` ends the debuggee; the client is told so
                // (a `disconnect` needs no event).
                if request.command == "terminate" {
                    outbox.event("terminated", None)?;
                }
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Listens to the running robot for a while: its answers go out as
    /// output, a stop as a `stopped` event.
    ///
    /// # Errors
    /// The output's write errors.
    pub fn listen(&mut self, outbox: &Outbox) -> std::io::Result<()> {
        let Some(robot) = self.robot.as_mut() else {
            self.running = false;
            return Ok(());
        };
        match robot.wait_event(LISTEN) {
            Ok(Heard::Silent) => Ok(()),
            Ok(heard) => self.heard(outbox, &heard, "breakpoint"),
            Err(error) => {
                self.running = false;
                outbox.output(
                    "stderr",
                    &format!("the robot's line failed: {}\n", failure(error).message()),
                )?;
                outbox.event("terminated", None)
            }
        }
    }

    /// What the robot said: an answer as output (it goes on running), a
    /// stop as a `stopped` event.
    fn heard(&mut self, outbox: &Outbox, heard: &Heard, reason: &str) -> std::io::Result<()> {
        match heard {
            Heard::Answer(answer) => {
                self.running = true;
                self.stepping |= reason == "step";
                let text = String::from_utf8_lossy(answer).replace('\r', "\n");
                outbox.output("stdout", &text)
            }
            Heard::Stopped(registers) => {
                self.running = false;
                let hit: Vec<i64> = self
                    .breakpoints
                    .iter()
                    .filter(|(_, (_, at))| *at == registers.pc)
                    .map(|(id, _)| *id)
                    .collect();
                // DAP: `breakpoint` (with the ids) when one of the client's
                // breakpoints stopped it; `step` where a step that ran on
                // ended (at its own breakpoints, which the client does not
                // know), however long after the step was answered.
                let reason = if !hit.is_empty() {
                    "breakpoint"
                } else if self.stepping {
                    "step"
                } else {
                    reason
                };
                self.stepping = false;
                let mut body = json!({
                    "reason": reason,
                    "threadId": THREAD,
                    "allThreadsStopped": true,
                    "description": format!("stopped at {}", self.monitor.place(registers.pc)),
                });
                if !hit.is_empty() {
                    body["hitBreakpointIds"] = json!(hit);
                }
                let own = crate::robot::garbled_own(registers);
                if !own.is_empty() {
                    outbox.output("console", &own)?;
                }
                outbox.event("stopped", Some(body))
            }
            Heard::Silent => {
                self.running = true;
                self.stepping |= reason == "step";
                Ok(())
            }
        }
    }

    fn robot(&mut self) -> Result<&mut RobotDebug<Box<dyn Transport>>, String> {
        self.robot
            .as_mut()
            .ok_or_else(|| "the robot is detached".to_owned())
    }

    fn stopped(&mut self, what: &str) -> Result<Registers, String> {
        self.robot()?.stopped().ok_or_else(|| {
            format!("{what} needs a stop: the robot is running (set a breakpoint and send the command that gets there)")
        })
    }

    fn answer(&mut self, request: &Request) -> Result<(Option<Value>, After), String> {
        let args = Arguments {
            command: &request.command,
            map: &request.arguments,
        };
        let body = match request.command.as_str() {
            "initialize" => Some(RobotSession::capabilities()),
            "launch" | "attach" => {
                return Err("the robot is attached already: `disconnect` first".into());
            }
            "setBreakpoints" => Some(self.set_breakpoints(&args)?),
            "setExceptionBreakpoints" => Some(json!({"breakpoints": []})),
            "configurationDone" => {
                // A robot an earlier session left stopped is stopped now.
                return Ok((
                    None,
                    match self.robot()?.stopped() {
                        Some(registers) => After::Heard(Heard::Stopped(registers), "entry"),
                        None => After::Configured,
                    },
                ));
            }
            "threads" => Some(json!({"threads": [{"id": THREAD, "name": "6502"}]})),
            "stackTrace" => {
                let registers = self.stopped("stackTrace")?;
                Some(json!({"totalFrames": 1, "stackFrames": [self.frame(registers.pc)]}))
            }
            "scopes" => Some(json!({"scopes": [
                {"name": "Registers", "variablesReference": REGISTERS, "expensive": false},
            ]})),
            "variables" => {
                let reference = args.integer("variablesReference")?.unwrap_or(0);
                let variables = if reference == REGISTERS {
                    variables(&self.stopped("variables")?)
                } else {
                    Vec::new()
                };
                Some(json!({ "variables": variables }))
            }
            "setVariable" => Some(self.set_variable(&args)?),
            "readMemory" => return self.read_memory(&args),
            "writeMemory" => Some(self.write_memory(&args)?),
            "evaluate" => return self.evaluate(&args),
            "continue" => {
                self.robot()?.resume().map_err(|e| failure(e).message())?;
                return Ok((Some(json!({"allThreadsContinued": true})), After::Run));
            }
            "next" | "stepIn" => {
                let over = request.command == "next";
                let entries = self.monitor.entries().to_vec();
                let heard = self
                    .robot()?
                    .step(&entries, over, WAIT)
                    .map_err(|e| failure(e).message())?;
                return Ok((None, After::Heard(heard, "step")));
            }
            "pause" => {
                return Err("pause is refused on the robot: the stub runs only when a breakpoint's JSR calls it, and the ROM's control loop has no way to be stopped from the line; set a breakpoint where it should stop".into());
            }
            "disconnect" | "terminate" => {
                if let Some(robot) = self.robot.take() {
                    robot.detach().map_err(|e| failure(e).message())?;
                }
                self.running = false;
                return Ok((None, After::Exit));
            }
            "stepBack" | "reverseContinue" | "restart" | "restartFrame" | "goto" => {
                return Err(format!(
                    "`{}` is refused on the robot: {CANNOT} (going back re-runs the robot from copies of it, and a real robot can be neither copied nor re-run; use the virtual Scorpion, without `port`)",
                    request.command
                ));
            }
            "setDataBreakpoints" | "dataBreakpointInfo" => {
                return Err(format!(
                    "`{}` is refused on the robot: {CANNOT} (the 6502 has no data breakpoints)",
                    request.command
                ));
            }
            other => {
                return Err(format!(
                    "`{other}` is refused on the robot: {CANNOT} (only the virtual Scorpion, without `port`, answers it)"
                ));
            }
        };
        Ok((body, After::Nothing))
    }

    /// `setBreakpoints`: a source's lines through the images' line
    /// tables; a condition, hit count or log message is refused for its
    /// breakpoint alone.
    fn set_breakpoints(&mut self, args: &Arguments<'_>) -> Result<Value, String> {
        let source = match args.map.get("source") {
            Some(Value::Object(source)) => source.clone(),
            _ => return Err("setBreakpoints needs `source`, an object with a `path`".into()),
        };
        let path = source
            .get("path")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_owned();
        let mut wanted = Vec::new();
        for breakpoint in args.objects("breakpoints")? {
            let line = breakpoint.get("line").and_then(Value::as_i64).ok_or(
                "setBreakpoints: each of `breakpoints` is an object with a `line`, a number",
            )?;
            let extra = ["condition", "hitCondition", "logMessage"]
                .into_iter()
                .find(|name| {
                    breakpoint
                        .get(*name)
                        .and_then(Value::as_str)
                        .is_some_and(|t| !t.trim().is_empty())
                });
            wanted.push((line, extra));
        }
        // The old set of this source goes first: a line kept is patched
        // again (its JSR is the same).
        let old: Vec<(i64, u16)> = self
            .breakpoints
            .iter()
            .filter(|(_, (file, _))| *file == path)
            .map(|(id, (_, at))| (*id, *at))
            .collect();
        for (id, at) in old {
            self.robot()?
                .remove_breakpoint(at)
                .map_err(|e| failure(e).message())?;
            self.breakpoints.remove(&id);
        }
        let entries = self.monitor.entries().to_vec();
        let mut answers = Vec::new();
        for (line, extra) in wanted {
            let address = u32::try_from(line).ok().and_then(|line| {
                self.monitor
                    .images()
                    .iter()
                    .filter_map(|image| image.address_of_line(&path, line))
                    .min()
                    .and_then(|at| u16::try_from(at).ok())
            });
            let mut answer = match (address, extra) {
                (_, Some(extra)) => json!({"verified": false, "message": format!(
                    "a `{extra}` is refused on the robot: a breakpoint there is a JSR that always stops the handler; the host would have to be asked at each hit, over the line"
                )}),
                (None, None) => {
                    json!({"verified": false, "message": format!("no code came from line {line}")})
                }
                (Some(at), None) => match self.robot()?.set_breakpoint(at, &entries) {
                    Ok(()) => {
                        let id = self.next_id;
                        self.next_id += 1;
                        self.breakpoints.insert(id, (path.clone(), at));
                        json!({"verified": true, "id": id, "instructionReference": format!("0x{at:04X}")})
                    }
                    Err(error) => {
                        let said = match &self.robot {
                            Some(robot) => self.monitor.refused_breakpoint(robot, at, error),
                            None => failure(error),
                        };
                        json!({"verified": false, "message": said.message()})
                    }
                },
            };
            answer["line"] = json!(line);
            answer["source"] = Value::Object(source.clone());
            answers.push(answer);
        }
        Ok(json!({ "breakpoints": answers }))
    }

    fn frame(&self, pc: u16) -> Value {
        let mut frame = json!({
            "id": 0,
            "name": self.monitor.place(pc),
            "line": 0,
            "column": 1,
            "instructionPointerReference": format!("0x{pc:04X}"),
        });
        let is_users = |file: &str| hostfs::is_users_source(&self.root, file);
        let source = self
            .monitor
            .images()
            .iter()
            .find_map(|image| image.user_source_of(u32::from(pc), &is_users));
        if let Some((file, line)) = source {
            frame["line"] = json!(line);
            frame["source"] = disassemble::source(&self.root, file);
        }
        frame
    }

    /// `setVariable`: a register or flag of the stop, written back through
    /// the stub (the monitor's `set`).
    fn set_variable(&mut self, args: &Arguments<'_>) -> Result<Value, String> {
        let name = args.string("name")?.ok_or("setVariable needs `name`")?;
        let value = args.string("value")?.ok_or("setVariable needs `value`")?;
        self.stopped("setVariable")?;
        let line = format!("set {name} {value}");
        let robot = self.robot.as_mut().ok_or("the robot is detached")?;
        self.monitor
            .command(robot, &line)
            .map_err(|e| e.message())?;
        let registers = self.stopped("setVariable")?;
        let shown = variables(&registers)
            .into_iter()
            .find(|v| {
                v["name"]
                    .as_str()
                    .is_some_and(|n| n.eq_ignore_ascii_case(name))
            })
            .map(|v| v["value"].clone())
            .unwrap_or_else(|| json!(value));
        Ok(json!({ "value": shown }))
    }

    fn address(&mut self, args: &Arguments<'_>, what: &str) -> Result<u16, String> {
        let reference = args
            .string("memoryReference")?
            .ok_or_else(|| format!("{what} needs `memoryReference`"))?
            .replace("0x", "$");
        let offset = args.integer("offset")?.unwrap_or(0);
        let robot = self.robot.as_mut().ok_or("the robot is detached")?;
        let base = self
            .monitor
            .value(robot, &reference)
            .map_err(|e| e.message())?;
        u16::try_from(base.saturating_add(offset)).map_err(|_| {
            format!("{reference} {offset:+} is outside the 6502's addresses ($0000-$FFFF)")
        })
    }

    /// `readMemory`: through the stub at a stop, `/7R` while running; as
    /// the program sees it (a breakpoint's `JSR` hidden).
    fn read_memory(&mut self, args: &Arguments<'_>) -> Result<(Option<Value>, After), String> {
        let start = self.address(args, "readMemory")?;
        let count = args.integer("count")?.unwrap_or(0).clamp(0, MAX_READ);
        let len = usize::try_from(count)
            .unwrap_or(0)
            .min(0x1_0000 - usize::from(start));
        // fresh15 F7: a memory view over a card's registers would read
        // them (and change them): those bytes are unreadable.
        let robot = self.robot()?;
        let len = match robot.refuse_read(start, len) {
            Some((at, _)) => usize::from(at.wrapping_sub(start)),
            None => len,
        };
        let read = if len == 0 {
            uploader::LiveRead {
                bytes: Vec::new(),
                changing: Vec::new(),
            }
        } else {
            // A memory view of a running robot shows a counter its
            // program keeps as it was at one moment (hostile16 F4).
            self.robot()?
                .read_live_as_program(start, len)
                .map_err(|e| failure(e).message())?
        };
        let mut body = json!({
            "address": format!("0x{start:04X}"),
            "data": base64::engine::general_purpose::STANDARD.encode(&read.bytes),
        });
        let unread = usize::try_from(count).unwrap_or(0) - read.bytes.len();
        if unread > 0 {
            body["unreadableBytes"] = json!(unread);
        }
        // fresh17 F2: the response has no place to mark bytes that
        // change; the console says it.
        let after = if read.changing.is_empty() {
            After::Nothing
        } else {
            After::Console(format!(
                "readMemory: the robot wrote {} while it was read, as it runs: one moment's value\n",
                uploader::addresses_text(&read.changing)
            ))
        };
        Ok((Some(body), after))
    }

    /// `writeMemory`: written, then read back.
    fn write_memory(&mut self, args: &Arguments<'_>) -> Result<Value, String> {
        let data = args
            .string("data")?
            .ok_or("writeMemory needs `data`, the bytes in base64")?;
        if data.len() > 0x1_6000 {
            return Err("writeMemory: more bytes than the 6502's 65536 addresses hold".into());
        }
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("writeMemory: `data` is not base64: {e}"))?;
        let start = self.address(args, "writeMemory")?;
        if usize::from(start) + bytes.len() > 0x1_0000 {
            return Err("writeMemory: the bytes run past $FFFF".into());
        }
        // fresh17 F8: a counter the program keeps takes the write and
        // moves on: written, not failed.
        self.robot()?
            .write_as_program_live(start, &bytes)
            .map_err(|e| failure(e).message())?;
        Ok(json!({"bytesWritten": bytes.len()}))
    }

    /// `evaluate`: `/cmd` goes down the line (its answer the result, or
    /// the stop it hits); anything else is an expression, as `print`.
    fn evaluate(&mut self, args: &Arguments<'_>) -> Result<(Option<Value>, After), String> {
        let expression = args
            .string("expression")?
            .ok_or("evaluate needs `expression`")?
            .trim()
            .to_owned();
        if expression.starts_with('/') {
            crate::line::command(&expression)?;
            let heard = self
                .robot()?
                .command(expression.as_bytes(), WAIT)
                .map_err(|e| failure(e).message())?;
            let result = match &heard {
                Heard::Answer(answer) => format!(
                    "sent {expression}: {}",
                    String::from_utf8_lossy(answer.strip_suffix(b"\r").unwrap_or(answer))
                ),
                Heard::Stopped(registers) => format!(
                    "sent {expression}: stopped at {}",
                    self.monitor.place(registers.pc)
                ),
                Heard::Silent => format!(
                    "sent {expression}: nothing came back within {} s",
                    WAIT.as_secs()
                ),
            };
            // The answer is the result already: not output again.
            let after = match heard {
                Heard::Answer(_) => After::Run,
                other => After::Heard(other, "breakpoint"),
            };
            return Ok((
                Some(json!({"result": result, "variablesReference": 0})),
                after,
            ));
        }
        let robot = self.robot.as_mut().ok_or("the robot is detached")?;
        match self.monitor.command(robot, &format!("print {expression}")) {
            Ok(Reply::Text(text)) => Ok((
                Some(json!({"result": text.trim_end(), "variablesReference": 0})),
                After::Nothing,
            )),
            Ok(Reply::Quit) => Err("evaluate: nothing to print".into()),
            Err(error) => Err(error.message()),
        }
    }
}

/// The registers of a stop, as `variables` shows them.
fn variables(r: &Registers) -> Vec<Value> {
    let variable =
        |name: &str, value: String| json!({"name": name, "value": value, "variablesReference": 0});
    vec![
        variable("A", format!("${:02X}", r.a)),
        variable("X", format!("${:02X}", r.x)),
        variable("Y", format!("${:02X}", r.y)),
        variable("S", format!("${:02X}", r.s)),
        variable("P", format!("${:02X}", r.p)),
        variable("PC", format!("${:04X}", r.pc)),
    ]
}
