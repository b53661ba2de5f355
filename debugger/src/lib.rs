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
//! - [`session`]: run, step, next (over `JSR`), finish (to the `RTS`),
//!   and back in time.
//!
//! # Back in time
//!
//! The emulator is exact and deterministic, so the debugger keeps no
//! snapshots: it keeps what the host did (each command sent, each bumper
//! change) and the instruction count at which it did it. Stepping back N
//! instructions builds the robot again as it was at power-up and runs it,
//! replaying the host's actions at their instruction counts, to N
//! instructions before where it was: the same state, exactly. History
//! costs nothing per instruction and a few bytes per host action; a step
//! back costs a re-run from power-up (measured by the bench). "Who last
//! wrote this byte" and reverse-continue are re-runs that watch on the
//! way.
//!
//! Nothing here prints: the monitor (`scorpion debug`) does.

pub mod error;
pub mod hooks;
pub mod points;
pub mod session;
pub mod symbols;

pub use error::Error;
pub use points::{Breakpoint, Watch, WatchKind};
pub use session::{Debugger, Event, MakeRobot, Stopped, Why};
pub use symbols::Symbols;
