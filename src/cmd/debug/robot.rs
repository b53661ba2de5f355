//! `scorpion debug --port PORT`: the monitor on a real robot over its
//! line (docs/DEBUGGING.md, "Debug on the robot"). The stub goes in
//! beside the uploaded image, the monitor's language runs through it
//! ([`debugger::robot`]), and the end of the session (quit, end of input)
//! takes every breakpoint out and gives the hook back.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use debugger::monitor::{Failure, Reply};
use debugger::robot::RobotMonitor;
use miette::{IntoDiagnostic, WrapErr};
use uploader::stub::RobotDebug;

use super::Args;
use super::prompt::{Completion, Input, Read, Reader};
use crate::cmd::ports;

const PROMPT: &str = "(robot) ";

/// How long the line is listened to before each command, for what the
/// robot said unasked.
const NOTICE: std::time::Duration = std::time::Duration::from_millis(30);

/// The robot on `port` (empty: the environment's or the project's: the
/// one in `here`, else in the working directory) with the stub attached beside the images `args` names, the names of
/// the ROM and the images, and the images (their sources from here).
/// `say` hears what a person waiting should know (how long the attach
/// takes), before the seconds it takes.
pub(crate) fn attach(
    args: &Args,
    port: &str,
    here: Option<&Path>,
    say: &mut dyn FnMut(&str),
) -> miette::Result<debugger::dap::Attached> {
    // `--port` alone: the one the environment or the project names.
    // (An editor's launch configuration gives an empty one.)
    let configured = port.is_empty() || port == crate::cmd::ports::CONFIGURED;
    let port = (!configured).then(|| port.to_owned());
    let flags = crate::cmd::config::flags(port.as_ref(), args.baud, &args.rig, args.rom.as_ref());
    let resolved = match here {
        Some(here) => crate::cmd::config::resolve_in(&flags, here)?,
        None => crate::cmd::config::resolve(&flags)?,
    };
    let images = crate::cmd::config::images(&resolved, &args.images)?.images;
    if images.is_empty() {
        return Err(miette::miette!(
            help =
                "give the uploaded image with --image ELF, or run it in the project that built it",
            "debugging on the robot needs the image it runs: breakpoints go only into its code, compared with it"
        ));
    }
    let mut areas = Vec::new();
    let mut hooks = Vec::new();
    let mut executable = Vec::new();
    for (name, image) in &images {
        let upload = uploader::UploadImage::try_from(image)
            .wrap_err_with(|| format!("cannot debug {name}"))?;
        areas.extend(upload.areas().iter().cloned());
        hooks.extend(upload.hooks().iter().copied());
        // Attach compares only code with the robot: each image's, or all
        // it loads when its sections do not say.
        match upload.code() {
            Some(ranges) => executable.extend(ranges.iter().cloned()),
            None => executable.extend(upload.areas().iter().filter_map(|area| {
                let end = u16::try_from(area.end() - 1).ok()?;
                Some(area.address..=end)
            })),
        }
    }
    let mut code = uploader::UploadImage::new(areas, hooks)?;
    code.set_code(executable);
    let rom = crate::cmd::config::rom(&resolved)?;
    let profile = crate::cmd::config::profile(rom.as_ref())?;
    let transport = ports::open_resolved(&resolved, &images)?;
    // No `/1X` first: a robot left stopped in the stub answers none; attach
    // finds that out with a frame, and asks `/1X` of a running one.
    let mut client = uploader::client(transport, &profile);
    // Reading the code and writing the stub (through the RAM loader) takes
    // seconds at 9600 baud: said, so a silent terminal (or editor) is not
    // taken for a hang.
    if let Ok(stub) = uploader::stub::StubPlan::place(&profile, &code, 0) {
        let baud = resolved.baud.value as usize;
        let seconds = |chars: usize| (chars * 10).div_ceil(baud);
        let (all, code_len) = (stub.bytes.len(), usize::from(stub.code_end - stub.address));
        // Two characters a byte read, 5.5 written (`/9W`), about 1.5 in
        // the RAM loader's frames with their sums; the image's code read
        // once, the frame that asks for a stopped stub twice (1.3 s). The
        // loader is read where an upload left it, written (`/9W`) the
        // first time.
        let compared = code.len() * 2 + 1250 * baud / 10_000;
        let loader = uploader::loader_plan(&profile, &code, (baud as u32, uploader::FAST_BAUD))
            .ok()
            .flatten()
            .map(|plan| plan.code.bytes.len());
        let (first, again) = match loader {
            Some(loader) => (
                compared + code_len * 2 + all * 3 / 2 + loader * 15 / 2 + loader * 2,
                compared + code_len * 2 + (all - code_len) * 3 / 2 + loader * 2,
            ),
            None => (
                compared + code_len * 4 + all * 15 / 2 + all * 2,
                compared + code_len * 2 + (all - code_len) * 15 / 2 + all * 2,
            ),
        };
        say(&format!(
            "attaching to the robot on {}: comparing its code with the image and writing the debug stub (about {} s at {baud} baud; {} s the first time on this robot)",
            client.transport().name(),
            seconds(again),
            seconds(first)
        ));
    }
    let robot = RobotDebug::attach(client, &profile, code)
        .map_err(|error| ports::traced_report(miette::Report::new(error), &resolved))?;
    // The monitor and an editor alike (fresh15 F3: the adapter said
    // nothing of it).
    let stub = robot.stub();
    // fresh28 F3, fresh30 F4: the RAM loader that wrote the stub, where
    // it did, stays with its state in user zero page.
    let loader_zero_page = robot
        .loader()
        .map(|loader| {
            format!(
                ", and the RAM loader that wrote it (${:04X}-${:04X}, its state in user zero page ${:02X}-${:02X})",
                loader.code.address,
                loader.code.end() - 1,
                loader.zero_page.start(),
                loader.zero_page.end()
            )
        })
        .map_or_else(|| " stays".to_owned(), |loader| format!("{loader}, stay"));
    say(&format!(
        "the debug stub is at ${:04X}-${:04X} (and user zero page ${:02X}-${:02X}): it{loader_zero_page} in memory after the session, unhooked; no undo puts back what was there (`scorpion backup` before a session keeps it)",
        stub.address,
        u32::from(stub.address) + stub.bytes.len() as u32 - 1,
        stub.zero_page,
        stub.zero_page.wrapping_add(1),
    ));
    let linked: Vec<linker::Image> = images.into_iter().map(|(_, image)| image).collect();
    // A JSR where no instruction starts would cut one in two: the line
    // tables say where they start, for the monitor and DAP alike.
    let mut robot = robot;
    if let Some(starts) = debugger::robot::instruction_starts(&linked) {
        robot.set_instruction_starts(starts);
    }
    // The names: the ROM's and the images' labels, as the virtual robot
    // with the images loaded has them.
    let mut named = ports::bare_robot(9600, rom.as_ref())?;
    for image in &linked {
        named.load_image(image)?;
    }
    let symbols = debugger::Symbols::new(&named, &linked);
    Ok(debugger::dap::Attached {
        robot,
        symbols,
        images: linked,
        // Sources are named from the project's root, as the virtual
        // robot's launch names them (fresh11 F3: from an image's own
        // directory, `target/scorpion/src/...` did not exist).
        root: resolved.project.as_ref().map_or_else(
            || here.unwrap_or(Path::new(".")).to_path_buf(),
            |project| project.root.clone(),
        ),
    })
}

pub(crate) fn run(args: &Args, port: &str) -> miette::Result<ExitCode> {
    let debugger::dap::Attached {
        mut robot,
        symbols,
        images: linked,
        root,
    } = attach(args, port, None, &mut |said| {
        // Progress of a long attach, before the session starts.
        crate::cmd::say_err(&format!("{said}\n"));
    })?;
    let mut completion = Completion::default();
    completion.names.extend(symbols.names().map(str::to_owned));
    let mut monitor = RobotMonitor::new(symbols, linked);
    monitor.set_root(root);
    let input = Input::new(
        std::io::IsTerminal::is_terminal(&std::io::stdin()),
        completion,
        None,
    );
    let mut out = std::io::stdout().lock();
    // fresh21 F2: an output that fails here (stdout piped into `head`) must
    // not end the process with the stub hooked: the robot is given back.
    if let Err(error) = introduce(&mut robot, &monitor, &mut out) {
        let _ = robot.detach();
        return Err(error);
    }
    // A Ctrl-C, a closed terminal or a `kill` must not end the process
    // with the robot stopped in the stub or a JSR left in its code: each
    // ends the session at the next line read (or the end of input), and
    // the robot is given back as at `quit`.
    let signals = [
        signal_hook::consts::SIGINT,
        signal_hook::consts::SIGHUP,
        signal_hook::consts::SIGTERM,
    ];
    let ended = crate::cmd::flag_on_signals(&signals)?;
    // Which one, for the exit status (hostile15 F8: a session a signal
    // ended exited 0, as if every command had run).
    let signal = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    for number in signals {
        signal_hook::flag::register_usize(number, std::sync::Arc::clone(&signal), number as usize)
            .into_diagnostic()?;
    }
    // A wait for the robot (a continue's, a step's) ends at the signal
    // too, not only the next line read.
    robot.set_interrupt(std::sync::Arc::clone(&ended));
    // The terminal as it is now: a signal that ends the session while the
    // line editor holds it raw leaves it so, for the shell after.
    let terminal = input
        .is_terminal()
        .then(|| nix::sys::termios::tcgetattr(std::io::stdin()).ok())
        .flatten();
    let reader = Reader::start(input, PROMPT);
    let session = converse(&mut robot, &mut monitor, &reader, &mut out, &ended);
    if let Some(terminal) = &terminal
        && ended.load(Ordering::Relaxed)
    {
        let _ = nix::sys::termios::tcsetattr(
            std::io::stdin(),
            nix::sys::termios::SetArg::TCSANOW,
            terminal,
        );
    }
    // Given back whatever ended the conversation (an unwritable terminal
    // too), before its error is said.
    let robot_port = robot.client().transport().name();
    let detached = robot.detach();
    let broken = session?;
    if let Err(error) = detached {
        // The line's own help speaks of uploads ("safe to retry"): here a
        // stub and breakpoints may be left on a robot that went astray.
        return Err(miette::miette!(
            code = "scorpion::debug::not_given_back",
            help = format!(
                "the stub may still be hooked and breakpoints' JSRs left in the code: if the robot answers no command, reset it (its hooks go back to the ROM); then `scorpion debug --port {}` with the same image finds what is left and takes it out (if the reset unhooked the image, it says so: upload the image again, which writes its code whole)",
                robot_port
            ),
            "the session could not give the robot back: {error}"
        ));
    }
    // The terminal may be gone: what cannot be said is dropped.
    let _ = writeln!(
        out,
        "detached: the breakpoints taken out, HOOK_UNKNOWN given back"
    );
    let number = signal.load(Ordering::Relaxed);
    if ended.load(Ordering::Relaxed) && number != 0 {
        let _ = writeln!(
            out,
            "interrupted (signal {number}): the session ended as `quit` ends it; the commands after were not run"
        );
        return Ok(ExitCode::from(128 + number as u8));
    }
    Ok(if broken {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// The session's first lines: where the stub is, what attach found, and
/// the stop the robot is in, if any.
fn introduce<T: uploader::transport::Transport>(
    robot: &mut RobotDebug<T>,
    monitor: &RobotMonitor,
    out: &mut impl Write,
) -> miette::Result<()> {
    let stub = robot.stub().clone();
    writeln!(
        out,
        "the robot on {}: the stub at ${:04X}-${:04X}, hooked ahead of ${:04X}; `help` lists the commands",
        robot.client().transport().name(),
        stub.address,
        u32::from(stub.address) + stub.bytes.len() as u32 - 1,
        stub.previous
    )
    .into_diagnostic()?;
    if robot.recovery().found() {
        writeln!(out, "{}", robot.recovery().describe()).into_diagnostic()?;
    }
    if let Some(note) = robot.recovery().data_note() {
        writeln!(out, "{note}").into_diagnostic()?;
    }
    if let Some(registers) = robot.stopped() {
        writeln!(
            out,
            "stopped at {}: {}",
            monitor.place(registers.pc),
            debugger::robot::show_registers(&registers)
        )
        .into_diagnostic()?;
    }
    Ok(())
}

/// Reads and answers the monitor's lines until `quit`, the end of input
/// or a signal (`ended`); whether the line failed on the way.
fn converse<T: uploader::transport::Transport>(
    robot: &mut RobotDebug<T>,
    monitor: &mut RobotMonitor,
    input: &Reader,
    out: &mut impl Write,
    ended: &AtomicBool,
) -> miette::Result<bool> {
    let mut broken = false;
    while !ended.load(Ordering::Relaxed) {
        if !input.is_terminal() {
            write!(out, "{PROMPT}").into_diagnostic()?;
        }
        out.flush().into_diagnostic()?;
        let Some(read) = input.read(ended) else {
            // A signal while the line was awaited.
            writeln!(out).into_diagnostic()?;
            break;
        };
        let line = match read.into_diagnostic()? {
            Read::Line(line) => line,
            Read::Interrupted => {
                // rustyline read the key; the signal's flag is not set.
                ended.store(false, Ordering::Relaxed);
                writeln!(out, "(Ctrl-C: `quit` or Ctrl-D leaves)").into_diagnostic()?;
                continue;
            }
            Read::End => {
                writeln!(out).into_diagnostic()?;
                break;
            }
            Read::Invalid(why) => {
                writeln!(out, "error: {why}").into_diagnostic()?;
                continue;
            }
        };
        if !input.is_terminal() {
            writeln!(out, "{line}").into_diagnostic()?;
        }
        if ended.load(Ordering::Relaxed) {
            break;
        }
        // A stop that came unasked (a step that ran on, a command sent by
        // another program) is said first: the command runs on the robot
        // as it is.
        match monitor.notice(robot, NOTICE) {
            Ok(Some(text)) => write!(out, "{text}").into_diagnostic()?,
            Ok(None) => {}
            Err(error) => {
                broken |= matches!(error, Failure::Line(_));
                writeln!(out, "error: {}", error.message()).into_diagnostic()?;
            }
        }
        match monitor.command(robot, line.trim()) {
            Ok(Reply::Text(text)) => write!(out, "{text}").into_diagnostic()?,
            Ok(Reply::Quit) => break,
            Err(error) => {
                broken |= matches!(error, Failure::Line(_));
                writeln!(out, "error: {}", error.message()).into_diagnostic()?;
            }
        }
    }
    Ok(broken)
}
