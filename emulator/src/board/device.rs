//! The interface every memory-mapped device of the board implements: the
//! 6522, the 6551, the board latches and whatever a test or an example maps
//! into a KIM-bus slot.
//!
//! Time is lazy (docs/ARCHITECTURE.md, "The emulator's time base"): a device
//! is told the cycle of every access, catches up to it on its own, and says
//! when it will next change its interrupt output by itself so the run loop
//! can let the CPU run freely until then.

use std::any::Any;

/// A memory-mapped device. Offsets are relative to the device's base
/// address; the board masks them to the device's window.
pub trait Device: Any + std::fmt::Debug + Send {
    /// A CPU read of register `offset` at `cycle`, with the read's side
    /// effects (a status read that clears a flag, a data read that empties
    /// a buffer).
    fn read(&mut self, offset: u16, cycle: u64) -> u8;

    /// A CPU write of `value` to register `offset` at `cycle`.
    fn write(&mut self, offset: u16, value: u8, cycle: u64);

    /// What a read of `offset` would return, without side effects (for
    /// monitors, dumps and tests). The default reads nothing and returns
    /// `$FF`.
    fn peek(&self, offset: u16) -> u8 {
        let _ = offset;
        0xFF
    }

    /// True if a read of `offset` has no side effect and returns the same
    /// value until the device's next event ([`Device::next_event`]) or a
    /// write to the device: a register that only the device's own events
    /// and the CPU change. A loop that only polls such registers (and plain
    /// memory) may be skipped up to the next event, exactly (see
    /// [`crate::Bus::is_plain_memory`]). A register that changes by itself
    /// between events (a free-running counter) is not stable. The default:
    /// none is.
    fn is_stable(&self, offset: u16) -> bool {
        let _ = offset;
        false
    }

    /// Catches up to `cycle` (time never goes backwards: a smaller cycle
    /// is ignored).
    fn sync(&mut self, cycle: u64) {
        let _ = cycle;
    }

    /// The next cycle, after the last one the device caught up to, at which
    /// its interrupt output may rise by itself, or `None`.
    fn next_event(&self) -> Option<u64> {
        None
    }

    /// The level of the device's interrupt request output (`true` =
    /// asserted, the /IRQ line pulled low).
    fn irq(&self) -> bool {
        false
    }

    /// A failure of the device's own, taken once: a card script's runtime
    /// error, say. The device answers `$FF` meanwhile; the robot's host
    /// (romlib's session) asks after every run and stops with it.
    fn take_fault(&mut self) -> Option<Box<dyn miette::Diagnostic + Send + Sync>> {
        None
    }

    /// A copy of the device as it is now, which goes on exactly as this
    /// one would (for a debugger's checkpoints: the robot copied, later
    /// run again from there). `None`, the default, for a device that cannot
    /// be copied: whoever wanted the copy does without (a debugger builds
    /// the robot again from power-up instead).
    fn snapshot(&self) -> Option<Box<dyn Device>> {
        None
    }

    /// The device as [`Any`], so that its owner can get its concrete type
    /// back (`board.kim_device::<MyCard>()`).
    fn as_any(&self) -> &dyn Any;

    /// The device as mutable [`Any`].
    fn as_any_mut(&mut self) -> &mut dyn Any;
}
