//! `scorpion debug`: a monitor on the virtual Scorpion. The robot with
//! the project's (or the given) images, cards and surroundings; commands
//! in the spirit of VICE's monitor read from stdin (typed, or a script),
//! the robot's serial line driven from the same prompt. The command
//! language is the debugger crate's ([`debugger::monitor`]); this is its
//! terminal: the prompt, the robot's set-up from the project, printing.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use debugger::Debugger;
use debugger::monitor::{Failure, Monitor, Reply};
use debugger::sources::Sources;
use miette::IntoDiagnostic;

use crate::cmd::ports;

#[cfg(test)]
mod fuzz;
mod prompt;
pub(crate) mod robot;

use prompt::{Input, Read};

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
    /// Draw the robot's path in its room (a world file, `--world
    /// room.toml`) to FILE.svg when the session ends, as sim's --path
    /// does: the room, the trail with a mark every second, the bumps and
    /// the commands sent. The trail is the robot's whole run, its robot
    /// time going forward: a step back does not undraw it.
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    pub(crate) path: Option<PathBuf>,
    /// Debug the real robot on PORT instead (alone: the [robot] port of
    /// the environment, the per-user file or the project), through a stub
    /// uploaded beside the image: docs/DEBUGGING.md, "Debug on the robot".
    #[arg(
        long,
        value_name = "PORT",
        num_args = 0..=1,
        default_missing_value = crate::cmd::ports::CONFIGURED,
        value_parser = crate::cmd::ports::port_value
    )]
    pub(crate) port: Option<String>,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    if let Some(port) = &args.port {
        return robot::run(args, port);
    }
    let here = std::env::current_dir().into_diagnostic()?;
    let ((make, images, root), room) = recipe_in_room(args, &here)?;
    // Checked before the session; drawn at its end from the robot the
    // debugger holds then (a rebuilt robot, or a copy it went back to, has
    // a room of its own).
    let picture = crate::cmd::rig::path_picture(args.path.as_ref(), room.get())?;
    // For the picture of the path: each command sent, at its robot time,
    // and the robot's whole run as its robot time went forward.
    let mut commands = Vec::new();
    let mut run = Run::default();
    let mut debugger = Debugger::new(make, &images)?;
    run.gather(&debugger);
    let terminal = std::io::stdin().is_terminal();
    let completion = completion_words(&debugger, &images);
    let mut input = Input::new(terminal, completion, prompt::history_file(&root));
    let interrupt = Arc::new(AtomicBool::new(false));
    if input.is_terminal() {
        // Ctrl-C while the robot runs pauses it (the run looks at the flag
        // between slices); at the prompt rustyline reads it as a key.
        // Registered after the editor is made, which sets a SIGINT handler
        // of its own: signal-hook's runs first, then calls rustyline's.
        signal_hook::flag::register(signal_hook::consts::SIGINT, Arc::clone(&interrupt))
            .into_diagnostic()?;
        debugger.set_interrupt(Arc::clone(&interrupt));
    }
    debugger.set_source_root(root.clone());
    let mut monitor = Monitor::new(Sources::new(root));
    monitor.set_pausable(input.is_terminal());
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "the virtual Scorpion, stopped at ${:04X} after power-up; `help` lists the commands",
        debugger.cpu().pc
    )
    .into_diagnostic()?;
    let mut broken = false;
    // What an empty line repeats (at a terminal): the last step or next.
    let mut repeat: Option<String> = None;
    loop {
        if !input.is_terminal() {
            // rustyline writes its own.
            write!(out, "{PROMPT}").into_diagnostic()?;
        }
        out.flush().into_diagnostic()?;
        let read = input.read(PROMPT).into_diagnostic()?;
        let mut line = match read {
            Read::Line(line) => line,
            Read::Interrupted => {
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
            // A script's session reads as a transcript.
            writeln!(out, "{line}").into_diagnostic()?;
        } else if line.trim().is_empty()
            && let Some(last) = &repeat
        {
            line.clone_from(last);
        }
        if is_repeatable(&line) {
            repeat = Some(line.trim().to_owned());
        }
        // A Ctrl-C pressed since the last run pauses nothing now.
        interrupt.store(false, Ordering::Relaxed);
        let at = debugger.robot().cycles();
        let reply = monitor.command(&mut debugger, line.trim());
        run.gather(&debugger);
        match reply {
            Ok(Reply::Text(text)) => {
                if let Some(sent) = text.strip_prefix("sent ") {
                    commands.push((at, sent.trim_end().to_owned()));
                }
                write!(out, "{text}").into_diagnostic()?;
            }
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
    if let Some((path, first)) = picture {
        let view = room_now(&debugger).unwrap_or(first);
        crate::cmd::rig::write_picture(path, &view.picture_of(path, &run.trail, &commands)?)?;
    }
    // A session in which the robot broke (a JAM, a card's fault) or whose
    // trace could not be written fails.
    Ok(if broken {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

const PROMPT: &str = "(scorpion) ";

/// Whether an empty line after `line` runs it again: the steps.
fn is_repeatable(line: &str) -> bool {
    let verb = line.split_whitespace().next().unwrap_or_default();
    matches!(
        verb,
        "step"
            | "s"
            | "stepi"
            | "si"
            | "next"
            | "n"
            | "nexti"
            | "ni"
            | "back"
            | "bs"
            | "reverse-step"
    )
}

/// What Tab completes: the symbols, the registers, and every source line
/// that made code.
fn completion_words(d: &Debugger, images: &[linker::Image]) -> prompt::Completion {
    let mut completion = prompt::Completion::default();
    completion
        .names
        .extend(d.symbols().names().map(str::to_owned));
    completion
        .names
        .extend(["A", "X", "Y", "S", "P", "PC", "C", "Z", "I", "D", "V", "N"].map(str::to_owned));
    for image in images {
        for entry in &image.lines.entries {
            if let Some(file) = image.lines.file_name(entry.loc) {
                completion
                    .places
                    .insert(format!("{file}:{}", entry.loc.line));
            }
        }
    }
    completion
}

/// What [`recipe`] makes: the robot's builder, the images it loads, and
/// where their sources are.
pub(crate) type Recipe = (debugger::MakeRobot, Vec<linker::Image>, PathBuf);

/// The robot the options (or the project found from `here` up) describe,
/// as a function that builds it afresh, the images it loads, and the
/// directory their source paths are relative to.
pub(crate) fn recipe(args: &Args, here: &std::path::Path) -> miette::Result<Recipe> {
    recipe_in_room(args, here).map(|(recipe, _)| recipe)
}

/// The robot's whole run in its room, gathered after each command as its
/// robot time goes forward: a step back (to a copy of the robot, or one
/// rebuilt and run again, each with a trail of its own) undraws nothing,
/// and robot time run again after it is drawn once, as first run.
#[derive(Debug, Default)]
struct Run {
    trail: cards::room::Trail,
    /// The furthest robot time gathered.
    reached: Option<u64>,
}

impl Run {
    fn gather(&mut self, debugger: &Debugger) {
        let Some(view) = room_now(debugger) else {
            return;
        };
        let now = debugger.robot().cycles();
        let (then, tail) = match self.reached {
            None => (None, view.trail()),
            Some(reached) => view.trail_after(reached),
        };
        self.trail.follow(then, tail);
        self.reached = Some(self.reached.map_or(now, |reached| reached.max(now)));
    }
}

/// The room of the robot `debugger` holds now, if it is in one.
fn room_now(debugger: &Debugger) -> Option<cards::room::RoomView> {
    debugger
        .robot()
        .surroundings()?
        .as_any()?
        .downcast_ref::<cards::room::Room>()
        .map(cards::room::Room::view)
}

/// [`recipe`], and where the room of its robot is seen from (a world
/// file's: its pose and trail).
pub(crate) fn recipe_in_room(
    args: &Args,
    here: &std::path::Path,
) -> miette::Result<(Recipe, scorpion_project::runner::rig::RoomSlot)> {
    let resolved = crate::cmd::config::resolve_in(
        &crate::cmd::config::flags(None, args.baud, &args.rig, args.rom.as_ref()),
        here,
    )?;
    let rig = crate::cmd::config::rig(&resolved);
    let room = rig.room.clone();
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
    Ok(((make, images, root), room))
}
