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
