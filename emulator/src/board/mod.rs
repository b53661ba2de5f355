//! The Scorpion controller card (docs/PROTOCOL.md section 3): its memory map,
//! its chips and what they are wired to, as a [`Bus`](crate::Bus) for the
//! CPU, plus the host's side of the robot.
//!
//! - [`Scorpion`] (a [`Machine`](crate::Machine) of a [`Board`]): the
//!   virtual robot. The host sends and receives serial bytes at the line's
//!   pace, presses bumpers, sets what the sensors see and reads the
//!   actuators.
//! - [`Board`]: RAM `$0000-$0FFF`, KIM-bus space `$1000-$BFFF` (RAM unless a
//!   [`Device`] is mapped there), the I/O page `$C000-$C0FF`, the
//!   write-protected ROM `$F000-$FFFF`.
//! - [`Via`] (6522) and [`Acia`] (6551): the chips, after their datasheets,
//!   each usable on its own; [`Stepper`], [`Scene`]: what they drive and
//!   read.
//! - The register map of the I/O page and the pin wiring are the
//!   `platform` crate's (`platform::map`), shared with the ROM's sources,
//!   the linker and the uploader. In short: VIA at `$C000`, ACIA at `$C010`, the `DRIVE` latch (eyes,
//!   lamps, stepper-driver enables, speaker amplifier) at `$C020`, the
//!   ground-tracker phototransistors at `$C021`, the DIP switches at
//!   `$C022`, the scanner's detector at `$C023`; bumpers on VIA port A and
//!   CA1, step and direction lines and the speaker on port B.
//!
//! Time is lazy: every device catches up when it is accessed and tells the
//! board when it will next raise its interrupt output by itself; the CPU's
//! once-per-instruction [`Bus::poll`](crate::Bus::poll) compares its cycle
//! with the earliest such event and otherwise runs freely.

pub mod acia;
mod device;
mod motor;
mod scene;
mod scorpion;
pub mod serial;
pub mod via;
pub mod wire;

pub use acia::{Acia, HostByte};
pub use device::Device;
pub use motor::Stepper;
pub use scene::Scene;
pub use scorpion::{Board, KimSlotId, Motor, Scorpion};
pub use serial::{Baud, CPU_HZ, FrameFormat, Parity};
pub use via::Via;
