//! `scorpion dap`: the debugger as a Debug Adapter Protocol server on
//! stdin and stdout, for editors (VS Code, Neovim's nvim-dap). The server
//! is the debugger crate's ([`debugger::dap`]); this gives it the process's
//! streams and builds the robot a `launch` asks for by the project's and
//! the configuration's rules, as `scorpion debug` does.

use std::io::{BufReader, BufWriter};
use std::path::Path;
use std::process::ExitCode;

use miette::IntoDiagnostic;

use crate::cmd::debug;

#[cfg(test)]
mod fuzz;

/// Serve the Debug Adapter Protocol on stdin and stdout (for an editor's
/// debugger: see docs/DEBUGGING.md).
///
/// `launch`'s `program` is a linked image (ELF) or a project's directory;
/// `stopOnEntry` stops before anything runs; `commands` (a list like
/// `["/2A1"]`) go down the robot's serial line once configured; `cwd` is
/// where an image's source paths start (default: the project's root, or
/// the image's directory); `port` debugs the real robot on that serial
/// port instead, through the debug stub (empty: the project's `[robot]
/// port`; see DEBUGGING.md, "Debug on the robot"). In the
/// debug console, a line starting with `/` is sent to the robot; anything
/// else is an address whose byte is shown.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {}

pub(crate) fn run(_args: &Args) -> miette::Result<ExitCode> {
    let stop = std::sync::Arc::new(debugger::dap::Stop::default());
    let_go_on_signals(std::sync::Arc::clone(&stop))?;
    debugger::dap::serve_with(
        BufReader::new(std::io::stdin()),
        Box::new(BufWriter::new(std::io::stdout())),
        Box::new(launch),
        Some(Box::new(attach)),
        &stop,
    )
    .into_diagnostic()?;
    Ok(ExitCode::SUCCESS)
}

/// An editor ends an adapter whose session went wrong with a signal: a
/// robot on a port is let go first (breakpoints out, the hook given
/// back), as at `disconnect`, then the process ends as the signal would
/// have ended it.
fn let_go_on_signals(stop: std::sync::Arc<debugger::dap::Stop>) -> miette::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .map_err(|error| miette::miette!("cannot watch for signals: {error}"))?;
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            stop.ask();
            // Breakpoints taken out one by one at 9600 baud: seconds.
            stop.wait(std::time::Duration::from_secs(60));
            std::process::exit(128 + signal);
        }
    });
    Ok(())
}

/// `launch` or `attach` with `port`: the real robot there (empty: the
/// environment's or the project's `[robot] port`), running `program`
/// (its image; a directory: the project's images), the stub attached as
/// `scorpion debug --port` attaches it.
pub(crate) fn attach(
    program: &Path,
    port: &str,
    say: &mut dyn FnMut(&str),
) -> miette::Result<debugger::dap::Attached> {
    let (images, here) = if program.is_dir() {
        (Vec::new(), program.to_path_buf())
    } else {
        let dir = program
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        (vec![program.to_path_buf()], dir.to_path_buf())
    };
    let args = debug::Args {
        images,
        ..debug::Args::default()
    };
    // The project is the program's, wherever the editor started us.
    debug::robot::attach(&args, port, Some(&here), say)
}

/// `launch`: the robot with `program` (an image, or a project's
/// directory), as `scorpion debug` would set it up there.
pub(crate) fn launch(program: &Path) -> miette::Result<debugger::dap::Launched> {
    // A directory that is no project's would launch the bare ROM
    // without a word: most likely a slip in the editor's settings.
    if program.is_dir()
        && !std::path::absolute(program).is_ok_and(|dir| {
            dir.ancestors()
                .any(|dir| dir.join(scorpion_project::FILE).is_file())
        })
    {
        miette::bail!(
            help = "`program` is a linked image (ELF) or a project's directory (with a Scorpion.toml in it or above)",
            "{} is a directory with no {} in it or above",
            program.display(),
            scorpion_project::FILE
        );
    }
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
    Ok(debugger::dap::Launched { make, images, root })
}
