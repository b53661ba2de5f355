//! Where the cycles go on the virtual Scorpion, and what the tests ran.
//!
//! - [`engine`]: the [`Profiler`], [`emulator::Hooks`] that count every
//!   instruction's cycles by address, each conditional branch taken and
//!   not taken, the calls on a shadow call stack (IRQ and NMI handlers as
//!   roots of their own) and every robot command from its arrival to the
//!   ROM's `CMD_DONE`, exactly, idle loops the emulator skips included;
//! - [`runner`]: the profiler set on a virtual robot ([`Recorder`]), so
//!   that everything a test does runs under it;
//! - [`profile`]: the finished, mergeable [`Profile`] (per routine, per
//!   stack, per command);
//! - [`lines`]: the images' line tables, through macros and includes:
//!   which source lines hold code, where their instructions and branches
//!   are;
//! - [`report`]: the tables a terminal shows, sorted by cost;
//! - [`flame`]: the folded stacks as an SVG flame graph;
//! - [`speedscope`]: the folded stacks as a speedscope file;
//! - [`coverage`]: line and branch coverage, as LCOV and HTML;
//! - [`budget`]: cycle budgets per command and per routine, checked.
//!
//! Nothing here prints: the CLI does.

pub mod budget;
pub mod coverage;
pub mod engine;
mod error;
pub mod flame;
mod flow;
pub mod lines;
pub mod profile;
pub mod report;
pub mod runner;
pub mod speedscope;
mod stack;

pub use engine::{CommandRun, Places, Profiler};
pub use error::Error;
pub use flow::is_branch;
pub use profile::{Profile, RoutineCost};
pub use runner::Recorder;
pub use stack::Routine;
