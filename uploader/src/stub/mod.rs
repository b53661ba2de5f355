//! Debugging on the robot itself, over its line (docs/DEBUGGING.md,
//! "Debug on the robot"; the framing in docs/PROTOCOL.md, section 5).
//! The ROM has no BRK hook, so a breakpoint is a `JSR` into a small stub
//! (`uploader/stub/stub.s`) patched over the uploaded code; the stub
//! reports the registers and serves the host's frames through the ROM's
//! `GETCH`/`PUTCH` until it is told to go on.
//!
//! - [`link`]: the stub linked where the image leaves room;
//! - [`left`]: a stub a killed session left hooked, recognised;
//! - [`frame`]: the stub's framing;
//! - [`guard`]: what a person at a stop may change;
//! - [`patch`]: what a breakpoint displaces, and where a step goes;
//! - [`session`]: [`RobotDebug`], the debugger attached;
//! - `summed`: the stub's code written through the RAM loader's frames;
//! - [`unlisted`]: code a hook leads to that no entry lists, refused.

pub mod error;
pub mod frame;
pub mod guard;
pub mod host_step;
pub mod left;
pub mod link;
pub mod patch;
pub mod session;
mod summed;
pub mod unlisted;

pub use error::{StubError, StubResult, hex as error_hex};
pub use link::StubPlan;
pub use patch::Patch;
pub use session::{Recovery, Registers, Reply, RobotDebug};
