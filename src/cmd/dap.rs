//! `scorpion dap`: the debugger as a Debug Adapter Protocol server on
//! stdin and stdout, for editors (VS Code, Neovim's nvim-dap): launch an
//! image or a project, breakpoints by source line, the 6502's call chain
//! with source lines, registers and flags, memory, stepping both ways.
//!
//! Three parts, each with its own types: [`framing`] reads and writes the
//! base protocol with bounded lengths; [`protocol`] takes requests from
//! messages and numbers the responses and events; [`session`] answers
//! requests on the robot. This file runs them on two threads: this one
//! reads the requests and answers what cannot wait (a message that is not
//! a request; `pause` and `disconnect` when the robot does not come back),
//! the robot's thread answers the rest and runs the robot in slices of
//! robot time between looks for requests.

use std::io::{BufReader, BufWriter};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::time::{Duration, Instant};

use miette::IntoDiagnostic;

mod framing;
#[cfg(test)]
mod fuzz;
mod protocol;
mod session;

use protocol::{Incoming, Outbox, Request};
use session::{Busy, Session};

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

/// How long `pause` and `disconnect` wait for the robot's thread before
/// they are answered without it: far more than a slice of robot time
/// takes, so only a robot that never comes back (a card or world script
/// that asks to be woken at the same instant again and again) meets it.
const STUCK: Duration = Duration::from_secs(5);

/// The robot thread's stack (only what is touched is committed).
const ROBOT_STACK: usize = 64 << 20;

pub(crate) fn run(_args: &Args) -> miette::Result<ExitCode> {
    let outbox = Arc::new(Outbox::new(Box::new(BufWriter::new(std::io::stdout()))));
    let busy = Arc::new(Busy::default());
    let (to_robot, requests) = mpsc::channel();
    let robot = {
        let session = Session::new(Arc::clone(&outbox), Arc::clone(&busy));
        // Scripts (Rhai) recurse deeply in a debug build: the robot's
        // thread gets the stack a script's deepest allowed call needs.
        std::thread::Builder::new()
            .name("robot".into())
            .stack_size(ROBOT_STACK)
            .spawn(move || robot_thread(session, &requests))
            .into_diagnostic()?
    };
    let mut reader = framing::FrameReader::new(BufReader::new(std::io::stdin()));
    loop {
        let message = match reader.next_message() {
            Ok(Some(message)) => message,
            Ok(None) => break,
            Err(error) => {
                outbox
                    .output("stderr", &format!("cannot read the requests: {error}\n"))
                    .into_diagnostic()?;
                break;
            }
        };
        let body = match message {
            Ok(body) => body,
            Err(error) => {
                outbox
                    .output(
                        "stderr",
                        &format!("scorpion dap: {error}; passed over, on to the next message\n"),
                    )
                    .into_diagnostic()?;
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
                }
                .into_diagnostic()?;
                continue;
            }
        };
        match forward(&outbox, &busy, &to_robot, request).into_diagnostic()? {
            Next::Read => {}
            Next::End => break,
            // The process's end ends the robot's thread too.
            Next::Abandon => return Ok(ExitCode::SUCCESS),
        }
    }
    drop(to_robot);
    // The robot's thread ends at its next look for requests; one that
    // does not come back is left to end with the process.
    let deadline = Instant::now() + STUCK;
    while !robot.is_finished() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    if robot.is_finished() {
        match robot.join() {
            Ok(result) => result.into_diagnostic()?,
            Err(_) => miette::bail!("the robot's thread panicked"),
        }
    }
    Ok(ExitCode::SUCCESS)
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
fn robot_thread(mut session: Session, requests: &Receiver<Request>) -> std::io::Result<()> {
    loop {
        let request = if session.running() {
            match requests.try_recv() {
                Ok(request) => Some(request),
                Err(TryRecvError::Empty) => None,
                Err(TryRecvError::Disconnected) => return Ok(()),
            }
        } else {
            match requests.recv() {
                Ok(request) => Some(request),
                Err(_) => return Ok(()),
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
