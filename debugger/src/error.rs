//! What can go wrong while debugging.

/// A debugger error.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum Error {
    /// The robot failed (a JAM, a card's or the surroundings' fault).
    #[error(transparent)]
    #[diagnostic(transparent)]
    Robot(#[from] romlib::Error),
    /// Building the robot again (for a step back) failed: its files
    /// changed or went since the session began.
    #[error("cannot build the robot again: {message}")]
    #[diagnostic(code(debugger::setup))]
    Setup {
        /// What went wrong.
        message: String,
    },
    /// An address expression that does not evaluate.
    #[error("`{text}`: {reason}")]
    #[diagnostic(
        code(debugger::address),
        help(
            "an address is a number ($C000, 49152, %1100...), a label, or a sum of them: CMDBUF+1"
        )
    )]
    Address {
        /// The expression as given.
        text: String,
        /// Why it does not evaluate.
        reason: String,
    },
    /// A step back further than the robot has run in the session. (Its
    /// power-up and the images' install ran before the session began and
    /// cannot be stepped back into.)
    #[error(
        "cannot go back {asked} instructions: only {ran} have run since the session began (power-up and the images' install come before it)"
    )]
    #[diagnostic(code(debugger::history))]
    BeforePowerUp {
        /// Instructions asked for.
        asked: u64,
        /// Instructions run so far.
        ran: u64,
    },
    /// Re-running from power-up did not come back to the same state: a
    /// card or the surroundings behave differently the second time.
    #[error(
        "re-running from power-up reached instruction {instruction} at cycle {found}, not {expected}: the robot's set-up is not deterministic"
    )]
    #[diagnostic(code(debugger::replay))]
    Diverged {
        /// The instruction count compared at.
        instruction: u64,
        /// The cycle the first run had there.
        expected: u64,
        /// The cycle the re-run had.
        found: u64,
    },
    /// The trace of the instructions run could not be written: the run
    /// stopped there, and the trace ended.
    #[error("cannot write the trace to {name}: {message}")]
    #[diagnostic(
        code(debugger::trace),
        help("the trace is off; `trace FILE` starts another")
    )]
    Trace {
        /// Where the trace went, as named.
        name: String,
        /// The write's error.
        message: String,
    },
    /// A value a register or flag does not hold.
    #[error("{what} holds 0 to {max}, not {value}")]
    #[diagnostic(code(debugger::value))]
    Value {
        /// The register or flag.
        what: String,
        /// The value given.
        value: i64,
        /// The largest it holds.
        max: u16,
    },
    /// Bytes to write that would land outside RAM.
    #[error(
        "${address:04X} is not RAM: only RAM can be written (not the ROM, the I/O page or a card's registers)"
    )]
    #[diagnostic(code(debugger::not_ram))]
    NotRam {
        /// The first address that is not RAM.
        address: u16,
    },
    /// An expression that does not parse.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Parse(#[from] crate::expr::ParseError),
    /// An expression that cannot be evaluated.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Eval(#[from] crate::expr::EvalError),
    /// A hit count that does not read.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Hits(#[from] crate::points::HitsError),
}
