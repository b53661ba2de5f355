//! The robot's side of a DAP session: each request answered on the
//! debugger, and a running robot run in slices of robot time between
//! looks for the next request.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde_json::{Value, json};

use super::Launcher;
use super::arguments::Arguments;
use super::exceptions::{self, Exception};
use super::memory::{self, FLAGS, REGISTERS};
use super::points::{Kind, Points};
use super::protocol::{Outbox, Request};
use super::{breakpoints, disassemble};
use crate::sources::Sources;
use crate::{Debugger, Stopped, Why};

/// Robot time a running robot gets between looks for requests (10 ms).
pub const SLICE: u64 = 10_000;
/// The only thread: the 6502.
const THREAD: i64 = 1;
/// Robot time a `next` or `stepOut` may take (a second).
const STEP_BUDGET: u64 = 1_000_000;

const NOT_LAUNCHED: &str = "launch a program first";

/// What the robot's thread is doing, for the one that answers when it
/// does not come back: since when, and what.
#[derive(Debug, Default)]
pub struct Busy(Mutex<Option<(Instant, String)>>);

/// What the robot's thread does at the end of the requests.
const LETTING_GO: &str = "letting the robot go";

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

    /// Whether the robot on a port is being let go (the process waits for
    /// that before it ends).
    pub fn letting_go(&self) -> bool {
        self.0
            .lock()
            .is_ok_and(|busy| busy.as_ref().is_some_and(|(_, what)| what == LETTING_GO))
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
    /// The breakpoints of every kind, by the client's numbers.
    points: Points,
    /// The exception filters on.
    filters: Vec<&'static str>,
    /// The exception the robot is stopped at, for `exceptionInfo`.
    exception: Option<Exception>,
    /// `launch`'s `program` and `cwd`, for `restart`.
    launched_with: Option<(PathBuf, Option<PathBuf>)>,
    /// The source files the images' line tables name (`loadedSources`).
    files: BTreeSet<String>,
    stop_on_entry: bool,
    commands: Vec<String>,
    running: bool,
    /// Attaches to a real robot, for a `launch` or `attach` with `port`.
    pub(crate) attacher: Option<super::Attacher>,
    /// The real robot attached: it answers every request after.
    robot: Option<super::robot::RobotSession>,
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
            points: Points::default(),
            filters: exceptions::defaults(),
            exception: None,
            launched_with: None,
            files: BTreeSet::new(),
            stop_on_entry: false,
            commands: Vec::new(),
            running: false,
            attacher: None,
            robot: None,
        }
    }

    /// The robot runs (between requests).
    pub fn running(&self) -> bool {
        self.running
            || self
                .robot
                .as_ref()
                .is_some_and(super::robot::RobotSession::running)
    }

    /// A program is launched.
    #[must_use]
    pub fn launched(&self) -> bool {
        self.debugger.is_some()
    }

    fn stopped(&self, reason: &str, description: Option<String>) -> std::io::Result<()> {
        self.stopped_at(reason, description, &[])
    }

    /// The `stopped` event, naming the breakpoints hit.
    fn stopped_at(
        &self,
        reason: &str,
        description: Option<String>,
        hit: &[i64],
    ) -> std::io::Result<()> {
        let mut body = json!({"reason": reason, "threadId": THREAD, "allThreadsStopped": true});
        if let Some(description) = description {
            if reason == "exception" {
                body["text"] = json!(description);
            }
            body["description"] = json!(description);
        }
        if !hit.is_empty() {
            body["hitBreakpointIds"] = json!(hit);
        }
        self.outbox.event("stopped", Some(body))
    }

    /// What log points logged, as console output.
    fn show_logs(&mut self) -> std::io::Result<()> {
        let Some(debugger) = self.debugger.as_mut() else {
            return Ok(());
        };
        let (logs, dropped) = debugger.take_logs();
        let mut text: String = logs.into_iter().map(|l| l.text + "\n").collect();
        if dropped > 0 {
            text.push_str(&format!(
                "({dropped} more log lines dropped: at most {} between stops)\n",
                crate::session::MAX_LOGS
            ));
        }
        if text.is_empty() {
            return Ok(());
        }
        self.outbox.output("console", &text)
    }

    /// What the robot sent, as console output.
    fn show_received(&self, received: &[u8]) -> std::io::Result<()> {
        if received.is_empty() {
            return Ok(());
        }
        let text = String::from_utf8_lossy(received).replace('\r', "\n");
        self.outbox.output("stdout", &text)
    }

    /// The end of the requests with no `disconnect` (the editor went
    /// away, or the adapter was told to stop): a robot on a port is let go
    /// as `disconnect` lets it go, not left with the stub hooked and the
    /// breakpoints in its code.
    pub fn end_of_requests(&mut self) {
        if let Some(robot) = self.robot.as_mut() {
            self.busy.start(LETTING_GO.into());
            // Nobody is left to be told of a line that failed.
            let _ = robot.let_go();
            self.busy.end();
        }
    }

    /// Answers a request; false at `disconnect` (or `terminate`).
    ///
    /// # Errors
    /// The output's write errors.
    pub fn handle(&mut self, request: &Request) -> std::io::Result<bool> {
        if let Some(robot) = self.robot.as_mut() {
            self.busy
                .start(format!("answering `{}` on the robot", request.command));
            let more = robot.handle(&self.outbox, request);
            self.busy.end();
            return more;
        }
        if matches!(request.command.as_str(), "launch" | "attach")
            && request.arguments.get("port").is_some()
        {
            return self.attach(request);
        }
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
            Then::Exit => {
                // `terminate` ends the debuggee; the client is told so
                // (a `disconnect` needs no event).
                if request.command == "terminate" {
                    self.outbox.event("terminated", None)?;
                }
                return Ok(false);
            }
        }
        Ok(true)
    }

    fn answer(&mut self, request: &Request) -> Answer {
        let args = Arguments {
            command: &request.command,
            map: &request.arguments,
        };
        let body = match request.command.as_str() {
            "initialize" => return Ok((Some(capabilities()), Then::Initialized)),
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
            "restart" => return self.restart(&args),
            "setBreakpoints" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                Some(breakpoints::set_source(&mut self.points, debugger, &args)?)
            }
            "setFunctionBreakpoints" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                Some(breakpoints::set_functions(
                    &mut self.points,
                    debugger,
                    &args,
                )?)
            }
            "setInstructionBreakpoints" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                Some(breakpoints::set_instructions(
                    &mut self.points,
                    debugger,
                    &args,
                )?)
            }
            "dataBreakpointInfo" => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let scope = args.integer("variablesReference")?.unwrap_or(0);
                let registers = scope == REGISTERS || scope == FLAGS;
                Some(breakpoints::data_info(debugger, &args, registers)?)
            }
            "setDataBreakpoints" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                Some(breakpoints::set_data(&mut self.points, debugger, &args)?)
            }
            "setExceptionBreakpoints" => Some(self.set_exceptions(&args)?),
            "exceptionInfo" => {
                let exception = self
                    .exception
                    .as_ref()
                    .ok_or("the robot is not stopped at an exception")?;
                Some(exception.info())
            }
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
                Some(json!({"variables": memory::variables(debugger, reference)}))
            }
            "setVariable" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                Some(memory::set(debugger, &args)?)
            }
            "readMemory" => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                Some(memory::read(debugger, &args)?)
            }
            "writeMemory" => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                Some(memory::write(debugger, &args)?)
            }
            "disassemble" => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let reference = args
                    .string("memoryReference")?
                    .ok_or("disassemble needs `memoryReference`")?;
                let base = memory::address(debugger, reference, 0)?;
                let offset = args.integer("offset")?.unwrap_or(0);
                let instruction_offset = args.integer("instructionOffset")?.unwrap_or(0);
                let count = args
                    .integer("instructionCount")?
                    .ok_or("disassemble needs `instructionCount`, an integer")?;
                let instructions = disassemble::instructions(
                    debugger,
                    &mut self.sources,
                    i64::from(base).saturating_add(offset),
                    instruction_offset,
                    count,
                );
                Some(json!({ "instructions": instructions }))
            }
            "loadedSources" => {
                self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let sources: Vec<Value> = self
                    .files
                    .iter()
                    .map(|file| disassemble::source(&self.sources.root, file))
                    .collect();
                Some(json!({ "sources": sources }))
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
                } else if let Ok(address) = debugger.symbols().address(expression) {
                    let byte = emulator::Bus::peek(&debugger.robot().robot().bus, address);
                    format!("${byte:02X} at ${address:04X}")
                } else {
                    // Registers, `[ADDR]`, arithmetic: as the monitor's
                    // `print` (and the robot's adapter) take them
                    // (fresh11 F2).
                    let value = crate::monitor::evaluate(debugger, expression)
                        .map_err(|failure| failure.message())?;
                    crate::monitor::shown_value(value)
                };
                Some(json!({"result": result, "variablesReference": 0}))
            }
            "continue" => {
                self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                self.exception = None;
                return Ok((Some(json!({"allThreadsContinued": true})), Then::Run));
            }
            "pause" => {
                self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                return Ok((None, Then::Pause));
            }
            "next" => return self.step_by(|d| d.next_line(STEP_BUDGET)),
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

    /// `setExceptionBreakpoints`: the filters on (`jam`, `brk`, `card`);
    /// kept before `launch` too, and set on each robot launched.
    fn set_exceptions(&mut self, args: &Arguments<'_>) -> Result<Value, String> {
        let names = args.strings("filters")?.unwrap_or_default();
        let mut filters = Vec::new();
        for name in &names {
            let filter = exceptions::named(name).ok_or_else(|| {
                format!("setExceptionBreakpoints: no filter `{name}`; they are jam, brk and card")
            })?;
            filters.push(filter);
        }
        // `filterOptions` (conditions on filters) are not offered.
        if let Some(options) = args.objects("filterOptions")?.first() {
            let filter = args.of(options).string("filterId")?.unwrap_or_default();
            return Err(format!(
                "setExceptionBreakpoints: the filters take no conditions (`filterOptions` for `{filter}`)"
            ));
        }
        self.filters = filters;
        self.install_brk()?;
        let answers: Vec<Value> = names.iter().map(|_| json!({"verified": true})).collect();
        Ok(json!({ "breakpoints": answers }))
    }

    /// The BRK filter's breakpoint, set or removed as the filters say.
    fn install_brk(&mut self) -> Result<(), String> {
        let Some(debugger) = self.debugger.as_mut() else {
            return Ok(());
        };
        let kind = Kind::Exception("brk");
        let wanted = self.filters.contains(&"brk");
        if wanted == self.points.has(&kind) {
            return Ok(());
        }
        self.points.clear(debugger, &kind);
        if wanted {
            let point = exceptions::brk_point(debugger)?;
            self.points.add(debugger, kind, point);
        }
        Ok(())
    }

    /// `restart`: the robot built again from power-up (with the
    /// arguments' new launch configuration, if given), every breakpoint
    /// set again, the launch's commands sent again; stopped on entry or
    /// running as `launch` said.
    fn restart(&mut self, args: &Arguments<'_>) -> Answer {
        let (old_program, old_cwd) = self.launched_with.clone().ok_or(NOT_LAUNCHED)?;
        let new = match args.map.get("arguments") {
            None | Some(Value::Null) => None,
            Some(Value::Object(map)) => Some(args.of(map)),
            Some(_) => return Err(args.wrong("arguments", "an object (a launch configuration)")),
        };
        let (program, cwd, stop_on_entry, commands) = match &new {
            Some(new) => {
                let commands = new.strings("commands")?.unwrap_or_default();
                crate::line::commands(&commands).map_err(|e| format!("restart: {e}"))?;
                (
                    new.string("program")?.map_or(old_program, PathBuf::from),
                    new.string("cwd")?.map(PathBuf::from).or(old_cwd),
                    new.boolean("stopOnEntry")?.unwrap_or(false),
                    commands,
                )
            }
            None => (
                old_program,
                old_cwd,
                self.stop_on_entry,
                self.commands.clone(),
            ),
        };
        let super::Launched { make, images, root } =
            (self.launcher)(&program).map_err(|e| format!("{e:?}"))?;
        let mut debugger = Debugger::new(make, &images).map_err(|e| e.to_string())?;
        debugger.set_source_root(cwd.clone().unwrap_or_else(|| root.clone()));
        self.points.install_all(&mut debugger);
        for command in &commands {
            debugger.send(command.as_bytes());
        }
        self.debugger = Some(debugger);
        self.files = files(&images);
        self.sources = Sources::new(cwd.clone().unwrap_or(root));
        self.launched_with = Some((program, cwd));
        self.stop_on_entry = stop_on_entry;
        self.commands = commands;
        self.exception = None;
        self.running = false;
        Ok((None, Then::Configured))
    }

    /// A stepping request: done at once, its stop reported after the
    /// response.
    fn step_by(
        &mut self,
        step: impl FnOnce(&mut Debugger) -> Result<Stopped, crate::Error>,
    ) -> Answer {
        let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
        self.exception = None;
        let stop = step(debugger).map_err(|e| e.to_string())?;
        Ok((None, Then::Report(stop)))
    }

    /// Says where the robot stopped, after what it sent and logged.
    fn report(&mut self, stop: &Stopped) -> std::io::Result<()> {
        self.show_logs()?;
        self.show_received(&stop.received)?;
        let Some(debugger) = self.debugger.as_ref() else {
            return Ok(());
        };
        let mut hit = Vec::new();
        let (reason, description) = match &stop.why {
            Why::Breakpoint { id, .. } => match self.points.breakpoint(*id) {
                Some((_, Kind::Exception(_))) => {
                    let exception = Exception::brk(debugger);
                    let description = exception.description.clone();
                    self.exception = Some(exception);
                    ("exception", Some(description))
                }
                Some((number, kind)) => {
                    hit.push(number);
                    (kind.reason(), None)
                }
                None => ("breakpoint", None),
            },
            Why::Watch { id, access, pc } => {
                hit.extend(self.points.watch(*id));
                (
                    "data breakpoint",
                    Some(breakpoints::watch_text(debugger, access, *pc)),
                )
            }
            Why::Stepped | Why::Finished | Why::Back => ("step", None),
            Why::Budget => ("pause", Some("the step ran out of robot time".into())),
            Why::Paused => ("pause", None),
        };
        self.stopped_at(reason, description, &hit)
    }

    /// One slice of a running robot: a stop is reported, and the robot's
    /// answers and log points' lines shown as they come. A run that fails
    /// (a JAM, a card's fault) stops at an exception if its filter is on;
    /// otherwise the program has ended.
    ///
    /// # Errors
    /// The output's write errors.
    pub fn run_slice(&mut self) -> std::io::Result<()> {
        if let Some(robot) = self.robot.as_mut() {
            return robot.listen(&self.outbox);
        }
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
            Ok(stop) if stop.why == Why::Budget => {
                // The log points' lines first, as the monitor shows them:
                // most were logged before the robot answered.
                self.show_logs()?;
                self.show_received(&stop.received)
            }
            Ok(stop) => {
                self.running = false;
                self.report(&stop)
            }
            Err(error) => {
                self.running = false;
                self.show_logs()?;
                let exception = Exception::from_error(&error);
                self.outbox
                    .output("stderr", &format!("{}\n", exception.details))?;
                if exception.id == "error" || self.filters.contains(&exception.id) {
                    let description = exception.description.clone();
                    self.exception = Some(exception);
                    self.stopped("exception", Some(description))
                } else {
                    // The robot cannot go on, and nobody asked to stop
                    // there: the program has ended.
                    self.outbox.event("terminated", None)
                }
            }
        }
    }

    /// `launch`: the robot with `program` (an image, or a project's
    /// directory).
    fn launch(&mut self, program: &Path, cwd: Option<PathBuf>) -> miette::Result<()> {
        let super::Launched { make, images, root } = (self.launcher)(program)?;
        let mut debugger = Debugger::new(make, &images)?;
        debugger.set_source_root(cwd.clone().unwrap_or_else(|| root.clone()));
        self.debugger = Some(debugger);
        self.points.forget();
        self.files = files(&images);
        self.exception = None;
        self.running = false;
        // An image's source paths are as its build was given them: `cwd`
        // says from where.
        self.sources = Sources::new(cwd.clone().unwrap_or(root));
        self.launched_with = Some((program.to_path_buf(), cwd));
        self.install_brk().map_err(|e| miette::miette!("{e}"))?;
        Ok(())
    }
}

impl Session {
    /// `launch` or `attach` with `port`: the stub attached to the robot
    /// there, the robot's capabilities sent.
    fn attach(&mut self, request: &Request) -> std::io::Result<bool> {
        let args = Arguments {
            command: &request.command,
            map: &request.arguments,
        };
        let attached = (|| -> Result<(super::Attached, bool, Vec<String>), String> {
            // Read first: a launch that names them wrongly attaches nothing.
            let stop_on_entry = args.boolean("stopOnEntry")?.unwrap_or(false);
            let commands = args.strings("commands")?.unwrap_or_default();
            let port = args
                .string("port")?
                .ok_or("`port` is the robot's serial port (empty: the project's)")?;
            let program = args.string("program")?.ok_or(
                "launch with `port` needs `program`: the image the robot runs (ELF) or its project's directory",
            )?;
            let attacher = self
                .attacher
                .as_ref()
                .ok_or("this adapter cannot open a robot's port")?;
            self.busy.start(format!("attaching to the robot on {port}"));
            let outbox = &self.outbox;
            let mut say = |said: &str| {
                // A console line lost with the editor gone is no matter.
                let _ = outbox.output("console", &format!("{said}\n"));
            };
            let attached =
                attacher(Path::new(program), port, &mut say).map_err(|e| format!("{e:?}"));
            self.busy.end();
            Ok((attached?, stop_on_entry, commands))
        })();
        match attached {
            Ok((attached, stop_on_entry, commands)) => {
                let mut robot = super::robot::RobotSession::new(attached);
                robot.configure(stop_on_entry, commands);
                let recovery = robot.recovery();
                self.robot = Some(robot);
                self.debugger = None;
                self.running = false;
                self.outbox
                    .respond(request.seq, &request.command, Ok(None))?;
                self.outbox.event(
                    "capabilities",
                    Some(json!({"capabilities": super::robot::RobotSession::capabilities()})),
                )?;
                // What the monitor prints when attach cleaned up a session
                // that died: the editor's console says it before the
                // first stop (`configurationDone` shows a robot found
                // stopped).
                if let Some(sentence) = recovery {
                    self.outbox.output("console", &format!("{sentence}\n"))?;
                }
            }
            Err(why) => self
                .outbox
                .respond(request.seq, &request.command, Err(why))?,
        }
        Ok(true)
    }
}

/// What `initialize` answers: exactly what this adapter does.
fn capabilities() -> Value {
    json!({
        "supportsConfigurationDoneRequest": true,
        "supportsStepBack": true,
        "supportsReadMemoryRequest": true,
        "supportsWriteMemoryRequest": true,
        "supportsTerminateRequest": true,
        "supportsRestartRequest": true,
        "supportsConditionalBreakpoints": true,
        "supportsHitConditionalBreakpoints": true,
        "supportsLogPoints": true,
        "supportsFunctionBreakpoints": true,
        "supportsDataBreakpoints": true,
        "supportsDataBreakpointBytes": true,
        "supportsInstructionBreakpoints": true,
        "supportsDisassembleRequest": true,
        "supportsSetVariable": true,
        "supportsExceptionInfoRequest": true,
        "supportsLoadedSourcesRequest": true,
        "exceptionBreakpointFilters": exceptions::capabilities(),
    })
}

/// The source files the images' line tables name.
fn files(images: &[linker::Image]) -> BTreeSet<String> {
    images
        .iter()
        .flat_map(|image| {
            image
                .lines
                .entries
                .iter()
                .filter_map(|entry| image.lines.file_name(entry.loc).map(str::to_owned))
        })
        .collect()
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
        frame["source"] = disassemble::source(root, &file);
    }
    frame
}
