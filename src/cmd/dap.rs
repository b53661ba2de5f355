//! `scorpion dap`: the debugger as a Debug Adapter Protocol server on
//! stdin and stdout, for editors (VS Code, Neovim's nvim-dap): launch an
//! image or a project, breakpoints by source line, the 6502's call chain
//! with source lines, registers and flags, memory, stepping both ways.
//!
//! Requests are read on a thread of their own, so that `pause` reaches a
//! running robot; the robot runs in slices of robot time between looks.

use std::io::{BufReader, BufWriter};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::mpsc::{self, TryRecvError};
use std::sync::{Arc, Mutex};

use base64::Engine as _;
use dap::events::{Event, OutputEventBody, StoppedEventBody};
use dap::requests::{Command, Request};
use dap::responses::{
    ContinueResponse, EvaluateResponse, ReadMemoryResponse, ResponseBody, ScopesResponse,
    SetBreakpointsResponse, StackTraceResponse, ThreadsResponse, VariablesResponse,
};
use dap::server::{Server, ServerOutput};
use dap::types::{
    Breakpoint as DapBreakpoint, Capabilities, OutputEventCategory, Scope, Source, StackFrame,
    StoppedEventReason, Thread, Variable,
};
use debugger::{Breakpoint, Debugger, Stopped, Why};
use miette::IntoDiagnostic;

use crate::cmd::debug::{self, Sources};

/// Serve the Debug Adapter Protocol on stdin and stdout (for an editor's
/// debugger: see docs/DEBUGGING.md).
///
/// `launch`'s `program` is a linked image (ELF) or a project's directory;
/// `stopOnEntry` stops before anything runs; `commands` (a list like
/// `["/2A1"]`) go down the robot's serial line once configured; `cwd` is
/// where an image's source paths start (default: the project's root, or
/// the image's directory). In the
/// debug console, a line starting with `/` is sent to the robot; anything
/// else is an address whose byte is shown.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {}

/// Robot time a running robot gets between looks for requests (10 ms).
const SLICE: u64 = 10_000;
/// The only thread: the 6502.
const THREAD: i64 = 1;
/// `variablesReference` of the registers and of the flags.
const REGISTERS: i64 = 1;
const FLAGS: i64 = 2;

type Output = Arc<Mutex<ServerOutput<std::io::Stdout>>>;

/// The session's state.
struct Session {
    output: Output,
    debugger: Option<Debugger>,
    sources: Sources,
    /// Breakpoint numbers by source path (`setBreakpoints` replaces a
    /// source's set).
    by_source: std::collections::HashMap<String, Vec<usize>>,
    stop_on_entry: bool,
    commands: Vec<String>,
    running: bool,
}

pub(crate) fn run(_args: &Args) -> miette::Result<ExitCode> {
    // The crate's server frames what we send; requests are read here, so
    // that one the crate's types do not take (an empty `arguments` where
    // none are defined, a request it does not know) is answered with an
    // error instead of ending the session.
    let server = Server::new(
        BufReader::new(std::io::empty()),
        BufWriter::new(std::io::stdout()),
    );
    let output = Arc::clone(&server.output);
    let (requests, incoming) = mpsc::channel();
    let refusals = Arc::clone(&output);
    std::thread::spawn(move || {
        let mut input = BufReader::new(std::io::stdin());
        while let Ok(Some(message)) = read_message(&mut input) {
            match parse_request(message) {
                Ok(request) => {
                    if requests.send(request).is_err() {
                        break;
                    }
                }
                Err((seq, why)) => {
                    if let Ok(mut out) = refusals.lock() {
                        let _ = out.respond(dap::responses::Response {
                            request_seq: seq,
                            success: false,
                            message: Some(dap::responses::ResponseMessage::Error(why)),
                            body: None,
                            error: None,
                        });
                    }
                }
            }
        }
    });
    let mut session = Session {
        output,
        debugger: None,
        sources: Sources::new(PathBuf::from(".")),
        by_source: std::collections::HashMap::new(),
        stop_on_entry: false,
        commands: Vec::new(),
        running: false,
    };
    loop {
        let request = if session.running {
            match incoming.try_recv() {
                Ok(request) => Some(request),
                Err(TryRecvError::Empty) => None,
                Err(TryRecvError::Disconnected) => break,
            }
        } else {
            match incoming.recv() {
                Ok(request) => Some(request),
                Err(_) => break,
            }
        };
        if let Some(request) = request
            && !session.handle(request)?
        {
            break;
        }
        if session.running {
            session.run_slice()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

impl Session {
    fn respond(&self, response: dap::responses::Response) -> miette::Result<()> {
        let mut output = self
            .output
            .lock()
            .map_err(|_| miette::miette!("the output lock is poisoned"))?;
        output.respond(response).into_diagnostic()
    }

    fn event(&self, event: Event) -> miette::Result<()> {
        let mut output = self
            .output
            .lock()
            .map_err(|_| miette::miette!("the output lock is poisoned"))?;
        output.send_event(event).into_diagnostic()
    }

    fn stopped(
        &self,
        reason: StoppedEventReason,
        description: Option<String>,
    ) -> miette::Result<()> {
        self.event(Event::Stopped(StoppedEventBody {
            reason,
            description,
            thread_id: Some(THREAD),
            preserve_focus_hint: None,
            text: None,
            all_threads_stopped: Some(true),
            hit_breakpoint_ids: None,
        }))
    }

    /// What the robot sent, as console output.
    fn show_received(&self, received: &[u8]) -> miette::Result<()> {
        if received.is_empty() {
            return Ok(());
        }
        let text = String::from_utf8_lossy(received).replace('\r', "\n");
        self.event(Event::Output(OutputEventBody {
            category: Some(OutputEventCategory::Stdout),
            output: text,
            ..Default::default()
        }))
    }

    /// Handles a request; false at `disconnect`.
    fn handle(&mut self, request: Request) -> miette::Result<bool> {
        let reply = self.answer(&request);
        let (response, then) = match reply {
            Ok((Some(body), then)) => (request.success(body), then),
            Ok((None, then)) => (request.ack().into_diagnostic()?, then),
            Err(message) => (request.error(&message), Then::Nothing),
        };
        self.respond(response)?;
        match then {
            Then::Nothing => {}
            Then::Initialized => self.event(Event::Initialized)?,
            Then::Configured => {
                if self.stop_on_entry {
                    self.stopped(StoppedEventReason::Entry, None)?;
                } else {
                    self.running = true;
                }
            }
            Then::Run => self.running = true,
            Then::Pause => {
                self.running = false;
                self.stopped(StoppedEventReason::Pause, None)?;
            }
            Then::Report(stop) => self.report(&stop)?,
            Then::NothingBefore => self.stopped(
                StoppedEventReason::Step,
                Some("no breakpoint was hit before here".into()),
            )?,
            Then::Exit => return Ok(false),
        }
        Ok(true)
    }

    /// The response's body (`None`: an acknowledgement without one) and
    /// what follows it, or the error to answer with.
    fn answer(&mut self, request: &Request) -> Result<(Option<ResponseBody>, Then), String> {
        let body = match &request.command {
            Command::Initialize(_) => {
                let capabilities = Capabilities {
                    supports_configuration_done_request: Some(true),
                    supports_step_back: Some(true),
                    supports_read_memory_request: Some(true),
                    ..Default::default()
                };
                return Ok((
                    Some(ResponseBody::Initialize(capabilities)),
                    Then::Initialized,
                ));
            }
            Command::Launch(args) => {
                let data = args.additional_data.clone().unwrap_or_default();
                let program = data.get("program").and_then(|p| p.as_str()).ok_or(
                    "launch needs `program`: a linked image (ELF) or a project's directory",
                )?;
                self.stop_on_entry =
                    data.get("stopOnEntry").and_then(serde_json::Value::as_bool) == Some(true);
                self.commands = data
                    .get("commands")
                    .and_then(|c| c.as_array())
                    .map(|c| {
                        c.iter()
                            .filter_map(|v| v.as_str().map(str::to_owned))
                            .collect()
                    })
                    .unwrap_or_default();
                let cwd = data.get("cwd").and_then(|c| c.as_str()).map(PathBuf::from);
                self.launch(Path::new(program), cwd)
                    .map_err(|e| format!("{e:?}"))?;
                None
            }
            Command::SetBreakpoints(args) => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                let path = args.source.path.clone().unwrap_or_default();
                for id in self.by_source.remove(&path).unwrap_or_default() {
                    debugger.delete_breakpoint(id);
                }
                let mut ids = Vec::new();
                let mut answers = Vec::new();
                for wanted in args.breakpoints.clone().unwrap_or_default() {
                    let line = u32::try_from(wanted.line).unwrap_or(0);
                    let address = debugger.address_of_line(&path, line);
                    let mut answer = DapBreakpoint {
                        verified: address.is_some(),
                        line: Some(wanted.line),
                        source: Some(args.source.clone()),
                        ..Default::default()
                    };
                    match address {
                        Some(address) => {
                            let id = debugger.add_breakpoint(Breakpoint::At(address));
                            ids.push(id);
                            answer.id = i64::try_from(id).ok();
                            answer.instruction_reference = Some(format!("0x{address:04X}"));
                        }
                        None => answer.message = Some(format!("no code came from line {line}")),
                    }
                    answers.push(answer);
                }
                self.by_source.insert(path, ids);
                Some(ResponseBody::SetBreakpoints(SetBreakpointsResponse {
                    breakpoints: answers,
                }))
            }
            Command::SetExceptionBreakpoints(_) => None,
            Command::ConfigurationDone => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                for command in &self.commands {
                    debugger.send(command.as_bytes());
                }
                return Ok((None, Then::Configured));
            }
            Command::Threads => Some(ResponseBody::Threads(ThreadsResponse {
                threads: vec![Thread {
                    id: THREAD,
                    name: "6502".into(),
                }],
            })),
            Command::StackTrace(_) => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let frames: Vec<StackFrame> = debugger
                    .backtrace()
                    .into_iter()
                    .enumerate()
                    .map(|(index, pc)| frame(&self.sources.root, debugger, index, pc))
                    .collect();
                let total = i64::try_from(frames.len()).ok();
                Some(ResponseBody::StackTrace(StackTraceResponse {
                    stack_frames: frames,
                    total_frames: total,
                }))
            }
            Command::Scopes(_) => Some(ResponseBody::Scopes(ScopesResponse {
                scopes: vec![
                    Scope {
                        name: "Registers".into(),
                        variables_reference: REGISTERS,
                        ..Default::default()
                    },
                    Scope {
                        name: "Flags".into(),
                        variables_reference: FLAGS,
                        ..Default::default()
                    },
                ],
            })),
            Command::Variables(args) => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                Some(ResponseBody::Variables(VariablesResponse {
                    variables: variables(debugger, args.variables_reference),
                }))
            }
            Command::ReadMemory(args) => {
                let debugger = self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                let reference = args.memory_reference.replace("0x", "$");
                let base = debugger
                    .symbols()
                    .address(&reference)
                    .map_err(|e| e.to_string())?;
                let start = i64::from(base) + args.offset.unwrap_or(0);
                let end = (start + args.count.max(0)).min(0x1_0000);
                let bytes: Vec<u8> = (start.max(0)..end)
                    .filter_map(|at| u16::try_from(at).ok())
                    .map(|at| emulator::Bus::peek(&debugger.robot().robot().bus, at))
                    .collect();
                Some(ResponseBody::ReadMemory(ReadMemoryResponse {
                    address: format!("0x{start:04X}"),
                    unreadable_bytes: None,
                    data: Some(base64::engine::general_purpose::STANDARD.encode(bytes)),
                }))
            }
            Command::Evaluate(args) => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                let expression = args.expression.trim();
                let result = if expression.starts_with('/') {
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
                Some(ResponseBody::Evaluate(EvaluateResponse {
                    result,
                    ..Default::default()
                }))
            }
            Command::Continue(_) => {
                self.debugger.as_ref().ok_or(NOT_LAUNCHED)?;
                return Ok((
                    Some(ResponseBody::Continue(ContinueResponse {
                        all_threads_continued: Some(true),
                    })),
                    Then::Run,
                ));
            }
            Command::Pause(_) => return Ok((None, Then::Pause)),
            Command::Next(_) => return self.step_by(|d| d.next(STEP_BUDGET)),
            Command::StepIn(_) => return self.step_by(|d| d.step(1)),
            Command::StepOut(_) => return self.step_by(|d| d.finish(STEP_BUDGET)),
            Command::StepBack(_) => return self.step_by(|d| d.back(1)),
            Command::ReverseContinue(_) => {
                let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
                let stop = debugger.reverse_continue().map_err(|e| e.to_string())?;
                return Ok((None, stop.map_or(Then::NothingBefore, Then::Report)));
            }
            Command::Disconnect(_) | Command::Terminate(_) => return Ok((None, Then::Exit)),
            _ => return Err("this request is not supported".into()),
        };
        Ok((body, Then::Nothing))
    }

    /// A stepping request: done at once, its stop reported after the
    /// response.
    fn step_by(
        &mut self,
        step: impl FnOnce(&mut Debugger) -> Result<Stopped, debugger::Error>,
    ) -> Result<(Option<ResponseBody>, Then), String> {
        let debugger = self.debugger.as_mut().ok_or(NOT_LAUNCHED)?;
        let stop = step(debugger).map_err(|e| e.to_string())?;
        Ok((None, Then::Report(stop)))
    }

    /// Says where the robot stopped, after what it sent.
    fn report(&self, stop: &Stopped) -> miette::Result<()> {
        self.show_received(&stop.received)?;
        let (reason, description) = match &stop.why {
            Why::Breakpoint { .. } => (StoppedEventReason::Breakpoint, None),
            Why::Watch { id, .. } => (StoppedEventReason::Data, Some(format!("watchpoint {id}"))),
            Why::Stepped | Why::Finished | Why::Back => (StoppedEventReason::Step, None),
            Why::Budget => (
                StoppedEventReason::Pause,
                Some("the step ran out of robot time".into()),
            ),
        };
        self.stopped(reason, description)
    }

    /// One slice of a running robot: a stop is reported, and the robot's
    /// answers shown as they come.
    fn run_slice(&mut self) -> miette::Result<()> {
        let Some(debugger) = self.debugger.as_mut() else {
            self.running = false;
            return Ok(());
        };
        match debugger.run(SLICE) {
            Ok(stop) if stop.why == Why::Budget => self.show_received(&stop.received),
            Ok(stop) => {
                self.running = false;
                self.report(&stop)
            }
            Err(error) => {
                self.running = false;
                self.event(Event::Output(OutputEventBody {
                    category: Some(OutputEventCategory::Stderr),
                    output: format!("{error}\n"),
                    ..Default::default()
                }))?;
                self.stopped(StoppedEventReason::Exception, Some(error.to_string()))
            }
        }
    }

    /// `launch`: the robot with `program` (an image, or a project's
    /// directory).
    fn launch(&mut self, program: &Path, cwd: Option<PathBuf>) -> miette::Result<()> {
        let (here, images) = if program.is_dir() {
            (program.to_path_buf(), Vec::new())
        } else {
            let dir = program
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            (dir.to_path_buf(), vec![program.to_path_buf()])
        };
        let args = debug::Args {
            images,
            ..debug::Args::default()
        };
        let (make, images, root) = debug::recipe(&args, &here)?;
        self.debugger = Some(Debugger::new(make, &images)?);
        // An image's source paths are as its build was given them: `cwd`
        // says from where.
        self.sources = Sources::new(cwd.unwrap_or(root));
        Ok(())
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

/// Robot time a `next` or `stepOut` may take (a second).
const STEP_BUDGET: u64 = 1_000_000;

const NOT_LAUNCHED: &str = "launch a program first";

/// Frame `index` of the call chain, at `pc`, with its source line.
fn frame(root: &Path, debugger: &Debugger, index: usize, pc: u16) -> StackFrame {
    let name = debugger
        .symbols()
        .place(pc)
        .unwrap_or_else(|| format!("${pc:04X}"));
    let (source, line) = match debugger.source_of(pc) {
        Some((file, line)) => (
            Some(Source {
                name: Path::new(&file)
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned()),
                path: Some(root.join(&file).display().to_string()),
                ..Default::default()
            }),
            i64::from(line),
        ),
        None => (None, 0),
    };
    StackFrame {
        id: i64::try_from(index).unwrap_or(0),
        name,
        source,
        line,
        column: 1,
        instruction_pointer_reference: Some(format!("0x{pc:04X}")),
        ..Default::default()
    }
}

/// The registers (`REGISTERS`) or the flags (`FLAGS`).
fn variables(debugger: &Debugger, reference: i64) -> Vec<Variable> {
    let cpu = debugger.cpu();
    let variable = |name: &str, value: String| Variable {
        name: name.into(),
        value,
        ..Default::default()
    };
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

/// One message of the base protocol (`Content-Length` header, blank line,
/// JSON); `None` at the end of the input.
fn read_message(input: &mut impl std::io::BufRead) -> std::io::Result<Option<serde_json::Value>> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if input.read_line(&mut line)? == 0 {
            return Ok(None);
        }
        let line = line.trim();
        if let Some(value) = line.strip_prefix("Content-Length:") {
            length = value.trim().parse::<usize>().ok();
        } else if line.is_empty() && length.is_some() {
            break;
        }
    }
    let mut body = vec![0; length.unwrap_or(0)];
    std::io::Read::read_exact(input, &mut body)?;
    Ok(serde_json::from_slice(&body).ok())
}

/// A message as a request: as sent, or without an empty `arguments`
/// (clients send `{}` where the protocol defines none); else its `seq`
/// and why it is refused.
fn parse_request(message: serde_json::Value) -> Result<Request, (i64, String)> {
    let seq = message["seq"].as_i64().unwrap_or(0);
    let command = message["command"].as_str().unwrap_or("?").to_owned();
    if let Ok(request) = serde_json::from_value::<Request>(message.clone()) {
        return Ok(request);
    }
    let mut bare = message;
    if let Some(object) = bare.as_object_mut()
        && object
            .get("arguments")
            .is_some_and(|a| a.as_object().is_some_and(|o| o.is_empty()))
    {
        object.remove("arguments");
    }
    serde_json::from_value::<Request>(bare).map_err(|error| {
        (
            seq,
            format!("`{command}` is not a request this adapter takes: {error}"),
        )
    })
}
