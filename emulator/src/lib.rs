//! An exact, fast NMOS 6502 emulator.
//!
//! - [`bus`]: the [`Bus`] trait, the contract between the CPU and memory or
//!   devices (exact bus cycles, lazy device catch-up, interrupt polling), the
//!   [`Line`] helper for devices' interrupt outputs, and [`Ram`], the plain
//!   64 KiB machine memory.
//! - [`cpu`]: the [`Cpu`]: every opcode of the NMOS part, documented or not,
//!   exact in result, flags, cycles and bus accesses; the run loop and the
//!   interrupt sequences; idle-loop skipping ([`Cpu::set_idle_skip`]), which
//!   advances the iterations of a loop that can only repeat itself until a
//!   device acts without running them, to the same state.
//! - [`hooks`]: what a run does besides executing ([`Hooks`]): tracing,
//!   breakpoints, stopping at traps. Off means absent from the compiled loop.
//! - [`machine`]: a [`Cpu`] with its [`Bus`]; [`RamMachine`] is the plain
//!   64 KiB machine test programs run on.
//! - [`board`]: the Scorpion controller card (6522, 6551, latches, motors,
//!   sensors, KIM-bus slots) and [`board::Scorpion`], the virtual robot.
//!
//! The emulator knows nothing of ELF: callers load bytes into it.

pub mod board;
pub mod bus;
pub mod cpu;
mod error;
pub mod hooks;
pub mod machine;

pub use bus::{Bus, Interrupts, Line, Ram};
pub use cpu::{Cpu, Interrupt, Step, Stop};
pub use error::Error;
pub use hooks::{Breakpoints, Control, Hooks, NoHooks, StopAtTrap, Tracer};
pub use machine::{Machine, RamMachine};
