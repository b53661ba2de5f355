//! A CPU together with its bus, and the plain 64 KiB RAM machine.

use crate::bus::{Bus, Ram};
use crate::cpu::{Cpu, Step, Stop};
use crate::hooks::{Hooks, NoHooks};

/// A [`Cpu`] wired to a [`Bus`]. The fields are public: a board reaches its
/// devices through `bus`, a debugger its registers through `cpu`.
#[derive(Debug, Clone)]
pub struct Machine<B: Bus> {
    /// The processor.
    pub cpu: Cpu,
    /// Everything it addresses.
    pub bus: B,
}

/// The plain machine: 64 KiB of RAM, no I/O, no interrupt source.
pub type RamMachine = Machine<Ram>;

impl<B: Bus> Machine<B> {
    /// A machine in the power-on state (see [`Cpu::new`]); call
    /// [`Machine::reset`] before running.
    pub fn new(bus: B) -> Machine<B> {
        Machine {
            cpu: Cpu::new(),
            bus,
        }
    }

    /// Runs the 7-cycle RESET sequence, which loads PC from `$FFFC`.
    pub fn reset(&mut self) {
        self.cpu.reset(&mut self.bus);
    }

    /// Executes one instruction or the pending interrupt sequence.
    pub fn step(&mut self) -> Step {
        self.cpu.step(&mut self.bus)
    }

    /// Runs until the cycle counter reaches `until`, or a JAM (see
    /// [`Cpu::run`]).
    pub fn run(&mut self, until: u64) -> Stop {
        self.cpu.run(&mut self.bus, until, &mut NoHooks)
    }

    /// Runs for about `cycles` more cycles (to the first instruction boundary
    /// at or after that), or to a JAM.
    pub fn run_for(&mut self, cycles: u64) -> Stop {
        let until = self.cpu.cycles().saturating_add(cycles);
        self.run(until)
    }

    /// [`Machine::run`] with hooks (tracing, breakpoints, stop at traps).
    pub fn run_with<H: Hooks>(&mut self, until: u64, hooks: &mut H) -> Stop {
        self.cpu.run(&mut self.bus, until, hooks)
    }
}

impl Machine<Ram> {
    /// 64 KiB of zeroed RAM with `image` loaded at `address`, in the
    /// power-on state.
    ///
    /// # Errors
    /// [`crate::Error::ImageTooLarge`] if the image runs past `$FFFF`.
    pub fn with_image(address: u16, image: &[u8]) -> Result<RamMachine, crate::Error> {
        let mut ram = Ram::new();
        ram.load(address, image)?;
        Ok(Machine::new(ram))
    }
}
