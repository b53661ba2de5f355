//! The debugger as a Debug Adapter Protocol server, for editors (VS
//! Code, Neovim's nvim-dap): launch an image or a project, breakpoints by
//! source line, the 6502's call chain with source lines, registers and
//! flags, memory, stepping both ways. `scorpion dap` serves it on stdin
//! and stdout; it builds the robot a `launch` asks for through a
//! [`Launcher`] (the CLI's project and configuration rules).
//!
//! Three parts, each with its own types: [`framing`] reads and writes the
//! base protocol with bounded lengths; [`protocol`] takes requests from
//! messages and numbers the responses and events; [`session`] answers
//! requests on the robot, with a module for each family of them
//! (`breakpoints` and the `points` they set, `exceptions`, `memory` with
//! the registers, `disassemble`; `arguments` reads them typed), and
//! [`robot`] on a real robot when `launch` names its `port`. [`serve`]
//! runs them on two threads: the caller's
//! reads the requests and answers what cannot wait (a message that is not
//! a request; `pause` and `disconnect` when the robot does not come back),
//! the robot's thread answers the rest and runs the robot in slices of
//! robot time between looks for requests.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::time::{Duration, Instant};

mod arguments;
mod breakpoints;
mod disassemble;
mod exceptions;
pub mod framing;
mod memory;
mod points;
pub mod protocol;
pub mod robot;
pub mod session;

use protocol::{Incoming, Outbox, Request};
use session::{Busy, Session};

/// A robot as `launch` asks for it: how to build it, its images, and
/// where their source paths start.
pub struct Launched {
    /// Builds the robot at power-up, everything loaded.
    pub make: crate::MakeRobot,
    /// The images loaded (for their symbols and source lines).
    pub images: Vec<linker::Image>,
    /// Where the images' source paths start (unless `launch`'s `cwd`
    /// says).
    pub root: PathBuf,
}

impl std::fmt::Debug for Launched {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Launched")
            .field("images", &self.images.len())
            .field("root", &self.root)
            .finish_non_exhaustive()
    }
}

/// A real robot attached over its line (`launch` or `attach` with
/// `port`): the debug stub in place beside the image it runs.
pub struct Attached {
    /// The robot, the stub attached.
    pub robot: uploader::stub::RobotDebug<Box<dyn uploader::Transport>>,
    /// The ROM's and the images' names.
    pub symbols: crate::Symbols,
    /// The images the robot runs (for their code and source lines).
    pub images: Vec<linker::Image>,
    /// Where the images' source paths start.
    pub root: PathBuf,
}

impl std::fmt::Debug for Attached {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Attached")
            .field("images", &self.images.len())
            .field("root", &self.root)
            .finish_non_exhaustive()
    }
}

/// Attaches to the robot on `port` (empty: the project's `[robot] port`)
/// running `program` (an image or a project's directory), or says why
/// it cannot, in full; what a person waiting should know meanwhile (how
/// long it takes) goes to the callback, for the editor's console.
pub type Attacher =
    Box<dyn Fn(&Path, &str, &mut dyn FnMut(&str)) -> miette::Result<Attached> + Send>;

/// Builds the robot for `launch`'s `program` (a linked image or a
/// project's directory), or says why it cannot, in full.
pub type Launcher = Box<dyn Fn(&Path) -> miette::Result<Launched> + Send>;

/// Why a DAP session ended in failure (a client's bad message never ends
/// one: it is answered, and the session goes on).
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum Error {
    /// The messages could not be written (the client went away).
    #[error("cannot write to the client: {0}")]
    #[diagnostic(code(debugger::dap::output))]
    Output(#[from] std::io::Error),
    /// The robot's thread could not be started.
    #[error("cannot start the robot's thread: {0}")]
    #[diagnostic(code(debugger::dap::thread))]
    Thread(std::io::Error),
    /// The robot's thread panicked (a bug: its message went to stderr).
    #[error("the robot's thread panicked")]
    #[diagnostic(code(debugger::dap::panic))]
    Panicked,
}

/// How long `pause` and `disconnect` wait for the robot's thread before
/// they are answered without it: far more than a slice of robot time
/// takes, so only a robot that never comes back (a card or world script
/// that asks to be woken at the same instant again and again) meets it.
const STUCK: Duration = Duration::from_secs(5);

/// The robot thread's stack (only what is touched is committed).
const ROBOT_STACK: usize = 64 << 20;

/// Serves the Debug Adapter Protocol: requests read from `input`,
/// responses and events written to `output`, a `launch` built by
/// `launcher`; until `disconnect` or the input's end.
///
/// # Errors
/// [`Error`]: the output's write errors, the robot's thread.
pub fn serve(
    input: impl BufRead,
    output: Box<dyn Write + Send>,
    launcher: Launcher,
) -> Result<(), Error> {
    serve_with(input, output, launcher, None, &Arc::default())
}

/// How often a robot's thread with nothing to do looks whether it is
/// asked to stop.
const STOP_LOOK: Duration = Duration::from_millis(100);

/// How long the end of the session waits for a robot on a port to be let
/// go (its breakpoints out at 9600 baud, a few seconds each at worst).
const LETTING_GO: Duration = Duration::from_secs(60);

/// Asks a session to end from outside its requests (a signal): a robot on
/// a port is let go as at `disconnect`, and [`Stop::wait`] says when.
#[derive(Debug, Default)]
pub struct Stop {
    asked: std::sync::atomic::AtomicBool,
    done: std::sync::atomic::AtomicBool,
}

impl Stop {
    /// Asks the session to end.
    pub fn ask(&self) {
        self.asked.store(true, std::sync::atomic::Ordering::SeqCst);
    }

    fn asked(&self) -> bool {
        self.asked.load(std::sync::atomic::Ordering::SeqCst)
    }

    fn done(&self) {
        self.done.store(true, std::sync::atomic::Ordering::SeqCst);
    }

    /// Waits (at most `limit`) until the session asked to end has let its
    /// robot go; whether it has.
    pub fn wait(&self, limit: Duration) -> bool {
        let deadline = Instant::now() + limit;
        while !self.done.load(std::sync::atomic::Ordering::SeqCst) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        self.done.load(std::sync::atomic::Ordering::SeqCst)
    }
}

/// [`serve`], with `attacher` for a `launch` or `attach` that names a
/// robot's `port`.
///
/// # Errors
/// [`Error`]: the output's write errors, the robot's thread.
pub fn serve_with(
    input: impl BufRead,
    output: Box<dyn Write + Send>,
    launcher: Launcher,
    attacher: Option<Attacher>,
    stop: &Arc<Stop>,
) -> Result<(), Error> {
    let outbox = Arc::new(Outbox::new(output));
    let busy = Arc::new(Busy::default());
    let (to_robot, requests) = mpsc::channel();
    let robot = {
        let (outbox, busy, stop) = (Arc::clone(&outbox), Arc::clone(&busy), Arc::clone(stop));
        // Scripts (Rhai) recurse deeply in a debug build: the robot's
        // thread gets the stack a script's deepest allowed call needs.
        // The session is made there: a real robot's line stays on it.
        std::thread::Builder::new()
            .name("robot".into())
            .stack_size(ROBOT_STACK)
            .spawn(move || {
                let mut session = Session::new(outbox, busy, launcher);
                session.attacher = attacher;
                robot_thread(session, &requests, &stop)
            })
            .map_err(Error::Thread)?
    };
    let mut reader = framing::FrameReader::new(input);
    loop {
        let message = match reader.next_message() {
            Ok(Some(message)) => message,
            Ok(None) => break,
            Err(error) => {
                outbox.output("stderr", &format!("cannot read the requests: {error}\n"))?;
                break;
            }
        };
        let body = match message {
            Ok(body) => body,
            Err(error) => {
                // hostile13: a request too large to take was passed over
                // with no response, and the client waited for one.
                if let framing::FrameError::TooLarge { head, .. } = &error
                    && let (Some(seq), command) = protocol::salvage(head)
                {
                    outbox.respond(
                        seq,
                        command.as_deref().unwrap_or_default(),
                        Err(format!("{error}; the request was passed over")),
                    )?;
                    continue;
                }
                outbox.output(
                    "stderr",
                    &format!("scorpion dap: {error}; passed over, on to the next message\n"),
                )?;
                continue;
            }
        };
        let request = match protocol::parse(&body) {
            Incoming::Request(request) => request,
            Incoming::Ignored => continue,
            Incoming::Refused(refused) => {
                match refused.seq {
                    Some(seq) => outbox.respond(
                        seq,
                        refused.command.as_deref().unwrap_or_default(),
                        Err(refused.why),
                    ),
                    None => outbox.output(
                        "stderr",
                        &format!("scorpion dap: {}; passed over\n", refused.why),
                    ),
                }?;
                continue;
            }
        };
        match forward(&outbox, &busy, &to_robot, request)? {
            Next::Read => {}
            Next::End => break,
            // The process's end ends the robot's thread too.
            Next::Abandon => return Ok(()),
        }
    }
    drop(to_robot);
    // The robot's thread ends at its next look for requests; one that
    // does not come back is left to end with the process.
    let deadline = Instant::now() + STUCK;
    let letting_go = Instant::now() + LETTING_GO;
    while !robot.is_finished()
        && (Instant::now() < deadline || (busy.letting_go() && Instant::now() < letting_go))
    {
        std::thread::sleep(Duration::from_millis(10));
    }
    if robot.is_finished() {
        match robot.join() {
            Ok(result) => result?,
            Err(_) => return Err(Error::Panicked),
        }
    }
    Ok(())
}

/// What follows a request.
enum Next {
    /// The next request.
    Read,
    /// The session is over: the robot's thread ends.
    End,
    /// The session is over, the robot's thread stuck: it is left behind.
    Abandon,
}

/// Hands `request` to the robot's thread. `pause` and `disconnect` (and
/// `terminate`) are answered here if that thread does not answer them in
/// [`STUCK`].
fn forward(
    outbox: &Outbox,
    busy: &Busy,
    to_robot: &mpsc::Sender<Request>,
    request: Request,
) -> std::io::Result<Next> {
    let (seq, command) = (request.seq, request.command.clone());
    let ending = matches!(command.as_str(), "disconnect" | "terminate");
    let urgent = ending || command == "pause";
    if urgent {
        outbox.watch(seq);
    }
    if to_robot.send(request).is_err() {
        // The robot's thread ended (its output failed): nobody to answer.
        outbox.respond(seq, &command, Err("the session is over".into()))?;
        return Ok(Next::End);
    }
    if !urgent || outbox.wait_answered(seq, STUCK) {
        return Ok(if ending { Next::End } else { Next::Read });
    }
    let doing = busy.describe().unwrap_or_else(|| "its last request".into());
    if ending {
        outbox.output(
            "stderr",
            &format!("the robot did not come back ({doing}); the session ends without it\n"),
        )?;
        outbox.respond(seq, &command, Ok(None))?;
        return Ok(Next::Abandon);
    }
    outbox.respond(
        seq,
        &command,
        Err(format!(
            "the robot has not come back to look for requests ({doing}): a card or world script may be asking to be woken at the same instant again and again; `disconnect` ends the session"
        )),
    )?;
    Ok(Next::Read)
}

/// The robot's thread: requests answered in turn; while the robot runs,
/// a slice of robot time between looks for them.
fn robot_thread(
    mut session: Session,
    requests: &Receiver<Request>,
    stop: &Stop,
) -> std::io::Result<()> {
    loop {
        if stop.asked() {
            session.end_of_requests();
            stop.done();
            return Ok(());
        }
        let request = if session.running() {
            match requests.try_recv() {
                Ok(request) => Some(request),
                Err(TryRecvError::Empty) => None,
                Err(TryRecvError::Disconnected) => {
                    session.end_of_requests();
                    return Ok(());
                }
            }
        } else {
            match requests.recv_timeout(STOP_LOOK) {
                Ok(request) => Some(request),
                Err(mpsc::RecvTimeoutError::Timeout) => None,
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    session.end_of_requests();
                    return Ok(());
                }
            }
        };
        if let Some(request) = request
            && !session.handle(&request)?
        {
            return Ok(());
        }
        if session.running() {
            session.run_slice()?;
        }
    }
}
