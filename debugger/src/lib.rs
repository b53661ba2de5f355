//! A debugger for programs on the virtual Scorpion.
//!
//! A [`Debugger`] holds a virtual robot (the reference ROM or a profile,
//! the user's images, cards and surroundings) and plays the host: it sends
//! commands down the serial line, runs the CPU under its hooks, and stops
//! where it is asked to:
//!
//! - [`points`]: breakpoints (an address, a robot command arriving, the
//!   unknown-command hook taken) and watchpoints (reads or writes of a
//!   range: a card's registers);
//! - [`hooks`]: the CPU hooks and the watching bus that find them;
//! - [`symbols`]: labels for addresses, addresses for expressions
//!   (`CMDBUF+1`, `handler`, `$8001`);
//! - [`expr`]: the expression language of conditions, log points, `set`
//!   and `display` (`A == 1 && [CMDBUF] == $2F`), shared by the monitor
//!   and the DAP server;
//! - [`session`]: run, step, next (over `JSR`), finish (to the `RTS`),
//!   and back in time;
//! - [`checkpoints`]: copies of the robot taken as it runs, to go back
//!   from.
//!
//! And its two front ends, one interpreter of conditions, expressions and
//! requests under both:
//!
//! - [`monitor`]: the monitor's command language (`scorpion debug`), each
//!   line answered as text;
//! - [`dap`]: the Debug Adapter Protocol server (`scorpion dap`);
//! - [`robot`]: the monitor's language on a real robot, through the
//!   uploader's debug stub (`scorpion debug --port`);
//! - [`sources`] and [`line`], which both use: the source lines they show,
//!   and the commands they put on the robot's serial line.
//!
//! # Back in time
//!
//! The emulator is exact and deterministic, so the debugger keeps what
//! the host did (each command sent, each bumper change) with the
//! instruction count and cycle at which it did it, and [`checkpoints`]:
//! copies of the whole robot (CPU, memory, board devices, cards' and
//! surroundings' script state) taken every [`CHECKPOINT_EVERY`] cycles,
//! at most [`MAX_CHECKPOINTS`] kept, thinned out to be dense near now and
//! log-spaced into the past. Stepping back N instructions copies the
//! newest checkpoint before the target and runs it on, replaying the
//! host's actions at their cycles, to N instructions before where it was:
//! the same state, exactly, in the time of a re-run of at most about two
//! intervals for a step back near now (measured by the bench). A robot
//! with a card or surroundings that cannot be copied is built again from
//! power-up and re-run instead, as a robot with no checkpoint would be.
//! "Who last wrote this byte" and reverse-continue re-run stretch by
//! stretch backwards, from checkpoint to checkpoint, watching on the way,
//! until a stretch has what they look for.
//!
//! # What points cost
//!
//! Breakpoints are a bitmap of the PCs where one may stop, tested once per
//! instruction (a breakpoint's condition and hit count are asked only at a
//! PC whose bit is set); watchpoints a bitmap of the addresses read or written that
//! one covers, tested on those accesses only ([`hooks`]). Both answer from
//! registers and memory alone, so an idle loop that none of them touches
//! is skipped as the plain run skips it.
//!
//! Nothing here prints: the monitor's interpreter returns text for the CLI
//! to print, and the DAP server writes its messages where it is told.

pub mod checkpoints;
pub mod dap;
pub mod error;
pub mod expr;
pub mod hooks;
pub mod line;
pub mod monitor;
pub mod points;
pub mod robot;
pub mod session;
pub mod sources;
pub mod symbols;

pub use checkpoints::{CHECKPOINT_EVERY, MAX_CHECKPOINTS};
pub use error::Error;
pub use expr::{Expr, Register, Template};
pub use points::{Breakpoint, HitCondition, PointOptions, Watch, WatchKind};
pub use session::{Debugger, Event, Logged, MakeRobot, Stopped, Why};
pub use sources::Sources;
pub use symbols::Symbols;
