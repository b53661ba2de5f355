//! One module per subcommand.

pub(crate) mod ask;
pub(crate) mod asm;
pub(crate) mod backup;
pub(crate) mod build;
pub(crate) mod config;
pub(crate) mod dap;
pub(crate) mod debug;
pub(crate) mod disasm;
pub(crate) mod emu;
pub(crate) mod host_line;
pub(crate) mod installed;
pub(crate) mod link;
pub(crate) mod new;
pub(crate) mod ports;
pub(crate) mod profile;
pub(crate) mod read;
pub(crate) mod rig;
pub(crate) mod rom;
pub(crate) mod sim;
pub(crate) mod test;
pub(crate) mod upload;
pub(crate) mod uploaded;
pub(crate) mod view;

/// A flag that any of `signals` sets, instead of ending the process: the
/// command looks at it where stopping leaves things right (a picture
/// drawn, a robot given back).
pub(crate) fn flag_on_signals(
    signals: &[i32],
) -> miette::Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    use miette::IntoDiagnostic as _;
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    for &signal in signals {
        signal_hook::flag::register(signal, std::sync::Arc::clone(&flag)).into_diagnostic()?;
    }
    Ok(flag)
}

/// Writes `text` on stdout. A stdout that is gone (piped into `head`,
/// which has quit) is no reason to stop, least of all by a panic half way
/// through work on a robot (fresh21 F2): what cannot be said is dropped.
pub(crate) fn say_out(text: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
}

/// [`say_out`] on stderr.
pub(crate) fn say_err(text: &str) {
    use std::io::Write as _;
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

/// Says, on a signal (Ctrl-C, `kill`), what an interrupted upload, undo
/// or restore left (`said`, asked then) before the process ends as the signal would
/// have ended it.
pub(crate) fn say_when_interrupted(
    said: impl Fn() -> String + Send + 'static,
) -> miette::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .map_err(|error| miette::miette!("cannot watch for Ctrl-C: {error}"))?;
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            say_err(&format!("\n{}\n", said()));
            std::process::exit(128 + signal);
        }
    });
    Ok(())
}
