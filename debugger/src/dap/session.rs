//! The robot's side of a DAP session: each request answered on the
//! debugger, and a running robot run in slices of robot time between
//! looks for the next request.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use base64::Engine as _;
use serde_json::{Map, Value, json};

use super::Launcher;
use super::protocol::{Outbox, Request};
use crate::sources::Sources;
use crate::{Breakpoint, Debugger, Stopped, Why};

/// Robot time a running robot gets between looks for requests (10 ms).
pub const SLICE: u64 = 10_000;
/// The only thread: the 6502.
const THREAD: i64 = 1;
/// `variablesReference` of the registers and of the flags.
const REGISTERS: i64 = 1;
const FLAGS: i64 = 2;
/// Robot time a `next` or `stepOut` may take (a second).
const STEP_BUDGET: u64 = 1_000_000;
/// The most bytes one `readMemory` answers: the address space.
const MAX_READ: i64 = 0x1_0000;

const NOT_LAUNCHED: &str = "launch a program first";

/// What the robot's thread is doing, for the one that answers when it
/// does not come back: since when, and what.
#[derive(Debug, Default)]
pub struct Busy(Mutex<Option<(Instant, String)>>);

impl Busy {
    fn start(&self, what: String) {
        if let Ok(mut busy) = self.0.lock() {
            *busy = Some((Instant::now(), what));
        }
    }

    fn end(&self) {
        if let Ok(mut busy) = self.0.lock() {
            *busy = None;
        }
    }

    /// What it has been doing, and for how long; `None` when idle.
    pub fn describe(&self) -> Option<String> {
        let busy = self.0.lock().ok()?;
        let (since, what) = busy.as_ref()?;
        Some(format!("{what} for {:.1} s", since.elapsed().as_secs_f64()))
    }
}

/// The session's state.
pub struct Session {
    outbox: Arc<Outbox>,
    launcher: Launcher,
    busy: Arc<Busy>,
    debugger: Option<Debugger>,
    sources: Sources,
    /// Breakpoint numbers by source path (`setBreakpoints` replaces a
    /// source's set).
    by_source: HashMap<String, Vec<usize>>,
    stop_on_entry: bool,
    commands: Vec<String>,
    running: bool,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("debugger", &self.debugger)
            .field("running", &self.running)
            .finish_non_exhaustive()
    }
}

/// What happens after a response.
enum Then {
    Nothing,
    Initialized,
    Configured,
    Run,
    Pause,
    Report(Stopped),
    NothingBefore,
    Exit,
}

/// A response's body (`None`: none) and what follows it, or the error
/// to answer with.
type Answer = Result<(Option<Value>, Then), String>;

impl Session {
    /// A session, not launched, answering through `outbox`.
    #[must_use]
    pub fn new(outbox: Arc<Outbox>, busy: Arc<Busy>, launcher: Launcher) -> Session {
        Session {
            outbox,
            launcher,
            busy,
            debugger: None,
            sources: Sources::new(PathBuf::from(".")),
            by_source: HashMap::new(),
            stop_on_entry: false,
            commands: Vec::new(),
            running: false,
        }
    }

    /// The robot runs (between requests).
    pub fn running(&self) -> bool {
        self.running
    }

    /// A program is launched.
    #[must_use]
    pub fn launched(&self) -> bool {
        self.debugger.is_some()
    }

    fn stopped(&self, reason: &str, description: Option<String>) -> std::io::Result<()> {
        let mut body = json!({"reason": reason, "threadId": THREAD, "allThreadsStopped": true});
        if let Some(description) = description {
            body["description"] = json!(description);
        }
        self.outbox.event("stopped", Some(body))
    }

    /// What the robot sent, as console output.
    fn show_received(&self, received: &[u8]) -> std::io::Result<()> {
        if received.is_empty() {
            return Ok(());
        }
        let text = String::from_utf8_lossy(received).replace('\r', "\n");
        self.outbox.output("stdout", &text)
    }

    /// Answers a request; false at `disconnect` (or `terminate`).
    ///
    /// # Errors
    /// The output's write errors.
    pub fn handle(&mut self, request: &Request) -> std::io::Result<bool> {
        self.busy.start(format!("answering `{}`", request.command));
        let answer = self.answer(request);
        self.busy.end();
        let (result, then) = match answer {
            Ok((body, then)) => (Ok(body), then),
            Err(why) => (Err(why), Then::Nothing),
        };
        self.outbox.respond(request.seq, &request.command, result)?;
        match then {
            Then::Nothing => {}
            Then::Initialized => self.outbox.event("initialized", None)?,
            Then::Configured => {
                if self.stop_on_entry {
                    self.stopped("entry", None)?;
                } else {
                    self.running = true;
                }
            }
            Then::Run => self.running = true,
            Then::Pause => {
                self.running = false;
                self.stopped("pause", None)?;
            }
            Then::Report(stop) => self.report(&stop)?,
            Then::NothingBefore => {
                self.stopped("step", Some("no breakpoint was hit before here".into()))?;
            }
            Then::Exit => return Ok(false),
        }
        Ok(true)
    }

    fn answer(&mut self, request: &Request) -> Answer {
        let args = Arguments {
            command: &request.command,
            map: &request.arguments,
        };
        let body = match request.command.as_str() {
            "initialize" => {
                let capabilities = json!({
                    "supportsConfigurationDoneRequest": true,
                    "supportsStepBack": true,
                    "supportsReadMemoryRequest": true,
                    "supportsTerminateRequest": true,
                });
                return Ok((Some(capabilities), Then::Initialized));
            }
            "launch" => {
                let program = args.string("program")?.ok_or(
                    "launch needs `program`: a linked image (ELF) or a project's directory",
                )?;
                let stop_on_entry = args.boolean("stopOnEntry")?.unwrap_or(false);
                let commands = args.strings("commands")?.unwrap_or_default();
                crate::line::commands(&commands).map_err(|e| format!("launch: {e}"))?;
                let cwd = args.string("cwd")?.map(PathBuf::from);
                self.launch(Path::new(program), cwd)
                    .map_err(|e| format!("{e:?}"))?;
                self.stop_on_entry = stop_on_entry;
                self.commands = commands;
                None
            }
            "setBreakpoints" => return self.set_breakpoints(&args),
            "setExceptionBreakpoints" => None,
            "configurationDone" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                for command in &self.commands {
                    debugger.send(command.as_bytes());
                }
                return Ok((None, Then::Configured));
            }
            "threads" => Some(json!({"threads": [{"id": THREAD, "name": "6502"}]})),
            "stackTrace" => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let frames: Vec<Value> = debugger
                    .backtrace()
                    .into_iter()
                    .enumerate()
                    .map(|(index, pc)| frame(&self.sources.root, debugger, index, pc))
                    .collect();
                Some(json!({"totalFrames": frames.len(), "stackFrames": frames}))
            }
            "scopes" => Some(json!({"scopes": [
                {"name": "Registers", "variablesReference": REGISTERS, "expensive": false},
                {"name": "Flags", "variablesReference": FLAGS, "expensive": false},
            ]})),
            "variables" => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let reference = args.integer("variablesReference")?.unwrap_or(0);
                Some(json!({"variables": variables(debugger, reference)}))
            }
            "readMemory" => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let reference = args
                    .string("memoryReference")?
                    .ok_or("readMemory needs `memoryReference`")?
                    .replace("0x", "$");
                let base = debugger
                    .symbols()
                    .address(&reference)
                    .map_err(|e| e.to_string())?;
                let offset = args.integer("offset")?.unwrap_or(0);
                let count = args.integer("count")?.unwrap_or(0).clamp(0, MAX_READ);
                let start = i64::from(base).saturating_add(offset);
                let end = start.saturating_add(count).min(MAX_READ);
                let bytes: Vec<u8> = (start.max(0)..end)
                    .filter_map(|at| u16::try_from(at).ok())
                    .map(|at| emulator::Bus::peek(&debugger.robot().robot().bus, at))
                    .collect();
                let unreadable = count - i64::try_from(bytes.len()).unwrap_or(count);
                let mut body = json!({
                    "address": format!("0x{:04X}", start.clamp(0, MAX_READ)),
                    "data": base64::engine::general_purpose::STANDARD.encode(bytes),
                });
                if unreadable > 0 {
                    // Outside the 6502's addresses.
                    body["unreadableBytes"] = json!(unreadable);
                }
                Some(body)
            }
            "evaluate" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                let expression = args
                    .string("expression")?
                    .ok_or("evaluate needs `expression`")?
                    .trim();
                let result = if expression.starts_with('/') {
                    crate::line::command(expression)?;
                    debugger.send(expression.as_bytes());
                    format!("sent {expression}")
                } else {
                    let address = debugger
                        .symbols()
                        .address(expression)
                        .map_err(|e| e.to_string())?;
                    let byte = emulator::Bus::peek(&debugger.robot().robot().bus, address);
                    format!("${byte:02X} at ${address:04X}")
                };
                Some(json!({"result": result, "variablesReference": 0}))
            }
            "continue" => {
                self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                return Ok((Some(json!({"allThreadsContinued": true})), Then::Run));
            }
            "pause" => {
                self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                return Ok((None, Then::Pause));
            }
            "next" => return self.step_by(|d| d.next(STEP_BUDGET)),
            "stepIn" => return self.step_by(|d| d.step(1)),
            "stepOut" => return self.step_by(|d| d.finish(STEP_BUDGET)),
            "stepBack" => return self.step_by(|d| d.back(1)),
            "reverseContinue" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                let stop = debugger.reverse_continue().map_err(|e| e.to_string())?;
                return Ok((None, stop.map_or(Then::NothingBefore, Then::Report)));
            }
            "disconnect" | "terminate" => return Ok((None, Then::Exit)),
            other => return Err(format!("`{other}` is not a request this adapter takes")),
        };
        Ok((body, Then::Nothing))
    }

    fn set_breakpoints(&mut self, args: &Arguments<'_>) -> Answer {
        let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
        let source = match args.map.get("source") {
            Some(Value::Object(source)) => source.clone(),
            _ => return Err("setBreakpoints needs `source`, an object with a `path`".into()),
        };
        let path = source
            .get("path")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_owned();
        let wanted = match args.map.get("breakpoints") {
            None | Some(Value::Null) => Vec::new(),
            Some(Value::Array(wanted)) => wanted.clone(),
            Some(_) => return Err("setBreakpoints: `breakpoints` is a list".into()),
        };
        // Checked before the old set goes: a refused request changes nothing.
        let mut lines = Vec::with_capacity(wanted.len());
        for breakpoint in &wanted {
            let line = breakpoint.get("line").and_then(Value::as_i64).ok_or(
                "setBreakpoints: each of `breakpoints` is an object with a `line`, a number",
            )?;
            lines.push(line);
        }
        for id in self.by_source.remove(&path).unwrap_or_default() {
            debugger.delete_breakpoint(id);
        }
        let mut ids = Vec::new();
        let mut answers = Vec::new();
        for line in lines {
            let address = u32::try_from(line)
                .ok()
                .and_then(|line| debugger.address_of_line(&path, line));
            let mut answer = json!({
                "verified": address.is_some(),
                "line": line,
                "source": Value::Object(source.clone()),
            });
            match address {
                Some(address) => {
                    let id = debugger.add_breakpoint(Breakpoint::At(address));
                    ids.push(id);
                    answer["id"] = json!(id);
                    answer["instructionReference"] = json!(format!("0x{address:04X}"));
                }
                None => answer["message"] = json!(format!("no code came from line {line}")),
            }
            answers.push(answer);
        }
        self.by_source.insert(path, ids);
        Ok((Some(json!({"breakpoints": answers})), Then::Nothing))
    }

    /// A stepping request: done at once, its stop reported after the
    /// response.
    fn step_by(
        &mut self,
        step: impl FnOnce(&mut Debugger) -> Result<Stopped, crate::Error>,
    ) -> Answer {
        let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
        let stop = step(debugger).map_err(|e| e.to_string())?;
        Ok((None, Then::Report(stop)))
    }

    /// Says where the robot stopped, after what it sent.
    fn report(&self, stop: &Stopped) -> std::io::Result<()> {
        self.show_received(&stop.received)?;
        let (reason, description) = match &stop.why {
            Why::Breakpoint { .. } => ("breakpoint", None),
            Why::Watch { id, .. } => ("data breakpoint", Some(format!("watchpoint {id}"))),
            Why::Stepped | Why::Finished | Why::Back => ("step", None),
            Why::Budget => ("pause", Some("the step ran out of robot time".into())),
            Why::Paused => ("pause", None),
        };
        self.stopped(reason, description)
    }

    /// One slice of a running robot: a stop is reported, and the robot's
    /// answers shown as they come.
    ///
    /// # Errors
    /// The output's write errors.
    pub fn run_slice(&mut self) -> std::io::Result<()> {
        let Some(debugger) = self.debugger.as_mut() else {
            self.running = false;
            return Ok(());
        };
        self.busy.start(format!(
            "running the robot from cycle {}",
            debugger.robot().cycles()
        ));
        let run = debugger.run(SLICE);
        self.busy.end();
        match run {
            Ok(stop) if stop.why == Why::Budget => self.show_received(&stop.received),
            Ok(stop) => {
                self.running = false;
                self.report(&stop)
            }
            Err(error) => {
                self.running = false;
                self.outbox.output("stderr", &format!("{error}\n"))?;
                self.stopped("exception", Some(error.to_string()))
            }
        }
    }

    /// `launch`: the robot with `program` (an image, or a project's
    /// directory).
    fn launch(&mut self, program: &Path, cwd: Option<PathBuf>) -> miette::Result<()> {
        let super::Launched { make, images, root } = (self.launcher)(program)?;
        self.debugger = Some(Debugger::new(make, &images)?);
        self.by_source.clear();
        self.running = false;
        // An image's source paths are as its build was given them: `cwd`
        // says from where.
        self.sources = Sources::new(cwd.unwrap_or(root));
        Ok(())
    }
}

/// A request's arguments, read with their types checked.
struct Arguments<'a> {
    command: &'a str,
    map: &'a Map<String, Value>,
}

impl<'a> Arguments<'a> {
    fn wrong(&self, name: &str, kind: &str) -> String {
        format!("{}: `{name}` is {kind}", self.command)
    }

    fn string(&self, name: &str) -> Result<Option<&'a str>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::String(text)) => Ok(Some(text)),
            Some(_) => Err(self.wrong(name, "a string")),
        }
    }

    fn boolean(&self, name: &str) -> Result<Option<bool>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Bool(value)) => Ok(Some(*value)),
            Some(_) => Err(self.wrong(name, "true or false")),
        }
    }

    fn integer(&self, name: &str) -> Result<Option<i64>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(value) => value
                .as_i64()
                .map(Some)
                .ok_or_else(|| self.wrong(name, "an integer")),
        }
    }

    fn strings(&self, name: &str) -> Result<Option<Vec<String>>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Array(items)) => items
                .iter()
                .map(|item| item.as_str().map(str::to_owned))
                .collect::<Option<Vec<_>>>()
                .map(Some)
                .ok_or_else(|| self.wrong(name, "a list of strings")),
            Some(_) => Err(self.wrong(name, "a list of strings")),
        }
    }
}

/// Frame `index` of the call chain, at `pc`, with its source line.
fn frame(root: &Path, debugger: &Debugger, index: usize, pc: u16) -> Value {
    let name = debugger
        .symbols()
        .place(pc)
        .unwrap_or_else(|| format!("${pc:04X}"));
    let mut frame = json!({
        "id": index,
        "name": name,
        "line": 0,
        "column": 1,
        "instructionPointerReference": format!("0x{pc:04X}"),
    });
    if let Some((file, line)) = debugger.source_of(pc) {
        frame["line"] = json!(line);
        frame["source"] = json!({
            "name": Path::new(&file).file_name().map(|n| n.to_string_lossy().into_owned()),
            "path": root.join(&file).display().to_string(),
        });
    }
    frame
}

/// The registers (`REGISTERS`) or the flags (`FLAGS`).
fn variables(debugger: &Debugger, reference: i64) -> Vec<Value> {
    let cpu = debugger.cpu();
    let variable =
        |name: &str, value: String| json!({"name": name, "value": value, "variablesReference": 0});
    if reference == FLAGS {
        let p = cpu.p();
        return "NV-BDIZC"
            .chars()
            .enumerate()
            .filter(|(_, name)| *name != '-')
            .map(|(bit, name)| {
                let set = p & (0x80 >> bit) != 0;
                variable(&name.to_string(), u8::from(set).to_string())
            })
            .collect();
    }
    if reference != REGISTERS {
        return Vec::new();
    }
    vec![
        variable("PC", format!("${:04X}", cpu.pc)),
        variable("A", format!("${:02X}", cpu.a)),
        variable("X", format!("${:02X}", cpu.x)),
        variable("Y", format!("${:02X}", cpu.y)),
        variable("S", format!("${:02X}", cpu.s)),
        variable("P", format!("${:02X}", cpu.p())),
        variable("cycles", debugger.robot().cycles().to_string()),
    ]
}
