//! What can go wrong writing a report.

use miette::Diagnostic;
use thiserror::Error;

/// A report that could not be made.
#[derive(Debug, Error, Diagnostic)]
pub enum Error {
    /// The flame graph renderer refused the stacks.
    #[error("cannot draw the flame graph: {reason}")]
    #[diagnostic(
        code(profile::flame_graph),
        help("the folded stacks are written beside it; any flame graph tool reads them")
    )]
    FlameGraph {
        /// The renderer's words.
        reason: String,
    },
}
