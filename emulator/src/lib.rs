//! An exact, fast NMOS 6502 emulator.
//!
//! - [`bus`]: the [`Bus`] trait, the contract between the CPU and memory or
//!   devices (exact bus cycles, lazy device catch-up, interrupt polling), the
//!   [`Line`] helper for devices' interrupt outputs, and [`Ram`], the plain
//!   64 KiB machine memory.
//!
//! The emulator knows nothing of ELF: callers load bytes into it.

pub mod bus;
mod error;

pub use bus::{Bus, Interrupts, Line, Ram};
pub use error::Error;
