//! The memory bus: the one interface between the CPU and everything it
//! talks to (RAM, ROM, the Scorpion board's I/O chips, test fixtures).
//!
//! # The contract
//!
//! **Every bus cycle is one call.** The NMOS 6502 reads or writes memory in
//! every clock cycle, including the "dummy" accesses the datasheet's cycle
//! tables list: the opcode-following read of a one-byte instruction, the read
//! of the un-carried address by indexed modes, the stack read before a pull,
//! and the double write of a read-modify-write instruction (old value, then
//! new value). [`crate::Cpu`] makes exactly those calls, in that order, so an
//! I/O register with read side effects (the 6551's receive data register, the
//! 6522's interrupt flags) sees what it would see on the real board, and the
//! number of calls an instruction makes is its cycle count.
//!
//! **The `cycle` argument is exact.** It is the number of the bus cycle in
//! which the access happens, counted from 0 when the [`crate::Cpu`] was
//! created (the CPU's `u64` cycle counter before the access). Devices never
//! run on their own thread and are never ticked per cycle: a device keeps the
//! cycle it last caught up to and, when it is accessed at `cycle`, first
//! brings itself up to date ("lazy catch-up"). See docs/ARCHITECTURE.md, "The
//! emulator's time base".
//!
//! **Interrupt inputs are polled.** After every instruction the CPU calls
//! [`Bus::poll`] once with the cycle at which the datasheet samples the
//! interrupt inputs for that instruction: its second-to-last cycle (one
//! earlier for a taken branch that stays in its page, the 6502's
//! "branch delays the interrupt" quirk). The call comes *after* the
//! instruction's last access, so `cycle` can lie up to two cycles before the
//! most recent access; a device whose line changed on such a later access
//! reports the level as it was at `cycle` ([`Line`] keeps that bookkeeping).
//! IRQ is a level: the CPU takes it while it is asserted and the I flag (as it
//! was at the poll point, hence the one-instruction delay of CLI, SEI and PLP)
//! is clear. NMI is an edge: the CPU remembers the level it saw at the
//! previous poll and takes the NMI when it goes from released to asserted.
//! The BRK, IRQ and NMI sequences poll once more, on their fourth cycle, which
//! is how an NMI hijacks a BRK or an IRQ. An NMI pulse must therefore stay
//! asserted until the next poll; a device that pulses NMI holds it until then.
//!
//! **`poll` is where timed devices catch up between accesses.** A device with
//! timed behaviour (a VIA timer, the ACIA's baud clock) knows the next cycle
//! at which it will change state by itself. `poll` is called once per
//! instruction with a cycle that only grows, so a board keeps the earliest of
//! its devices' next events in one field and does
//! `if cycle >= self.next_event { self.catch_up(cycle) }` before answering:
//! one comparison per instruction, and the timer's IRQ reaches the CPU at the
//! same instruction boundary as on the real chip. Between events, timed
//! devices cost nothing. [`crate::Cpu::run`] additionally returns at the first
//! instruction boundary at or after a caller-given cycle, for hosts that
//! slice time (real-time pacing, cycle limits).
//!
//! **A bus may let the CPU skip polls.** [`Bus::quiet_until`] names a
//! cycle before which every poll would answer [`Interrupts::NONE`] and change
//! nothing; the CPU compares each instruction's poll point with it (one
//! comparison) and calls `poll` only from there on. The default, 0, has
//! every poll made; [`Ram`] answers `u64::MAX`; the Scorpion board answers
//! the cycle of its next device event while its IRQ line rests released.
//! A skipped poll counts as NMI released, so a bus must not report a quiet
//! stretch while the NMI level it last answered was asserted.
//!
//! **Dummy reads are marked.** A read whose value the CPU throws away (the
//! byte after a one-byte opcode, the stack read before a pull, an indexed
//! mode's un-carried address, a taken branch's extra fetches, the interrupt
//! sequences' suppressed fetches) is made with [`Bus::dummy_read`]. It still
//! happens in its own cycle and must have every side effect a read has; the
//! default calls [`Bus::read`]. A bus may skip the work for addresses where
//! a read has no effect (plain memory), which is all the marking is for.
//!
//! **Page zero and the stack are marked too.** Accesses the addressing
//! mode confines to `$0000-$01FF` (zero-page modes, their pointers, pushes
//! and pulls) go through [`Bus::read_zp_stack`] and
//! [`Bus::write_zp_stack`], which default to `read` and `write`; a bus
//! whose low pages are always RAM serves them without decoding the
//! address.
//!
//! **`peek` has no side effects.** Tracers, disassemblers and debuggers read
//! memory through [`Bus::peek`], which must not change any state (no flag
//! cleared, no catch-up); a register that cannot be read without a side
//! effect returns its current value as it would be read now.
//!
//! A bus is a generic parameter of the CPU, never a trait object, so a plain
//! RAM bus compiles to direct array accesses and its dummy reads vanish.

/// The interrupt inputs as the CPU samples them at a poll point.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Interrupts {
    /// The IRQ input is asserted (the /IRQ pin is low). Level-sensitive.
    pub irq: bool,
    /// The NMI input is asserted (the /NMI pin is low). The CPU detects the
    /// transition from released to asserted.
    pub nmi: bool,
}

impl Interrupts {
    /// Neither input asserted.
    pub const NONE: Interrupts = Interrupts {
        irq: false,
        nmi: false,
    };
}

/// What the CPU reads, writes and polls. See the [module documentation](self)
/// for the timing contract.
pub trait Bus {
    /// Reads the byte at `address` during bus cycle `cycle`. Side effects of
    /// the read (a status flag cleared by reading) happen here.
    fn read(&mut self, address: u16, cycle: u64) -> u8;

    /// Writes `value` to `address` during bus cycle `cycle`.
    fn write(&mut self, address: u16, value: u8, cycle: u64);

    /// A read of the instruction stream at the PC (an opcode or an operand
    /// byte): the same access as [`Bus::read`], which the default calls.
    /// A debugger's watching bus tells it apart from the program's reads
    /// of data, and leaves it unwatched.
    #[inline(always)]
    fn fetch(&mut self, address: u16, cycle: u64) -> u8 {
        self.read(address, cycle)
    }

    /// A read of `address` during bus cycle `cycle` whose value the CPU
    /// ignores (see the [module documentation](self)). Its side effects are
    /// those of [`Bus::read`]; a bus may skip the rest.
    #[inline(always)]
    fn dummy_read(&mut self, address: u16, cycle: u64) {
        self.read(address, cycle);
    }

    /// A read in page zero or the stack page (`address < $0200`: the CPU
    /// knows it from the addressing mode). Same contract as [`Bus::read`],
    /// which the default calls; a bus whose two low pages are always RAM
    /// reads it without decoding the address.
    #[inline(always)]
    fn read_zp_stack(&mut self, address: u16, cycle: u64) -> u8 {
        self.read(address, cycle)
    }

    /// A write in page zero or the stack page, as
    /// [`Bus::read_zp_stack`]; the default calls [`Bus::write`].
    #[inline(always)]
    fn write_zp_stack(&mut self, address: u16, value: u8, cycle: u64) {
        self.write(address, value, cycle);
    }

    /// The byte a read of `address` would return now, without any side
    /// effect. For tracers and debuggers.
    fn peek(&self, address: u16) -> u8;

    /// The interrupt inputs as they were during bus cycle `cycle`, called once
    /// per instruction at its interrupt poll point (and once more inside the
    /// BRK, IRQ and NMI sequences). `cycle` never decreases from one call to
    /// the next. The default: no interrupt source.
    #[inline(always)]
    fn poll(&mut self, cycle: u64) -> Interrupts {
        let _ = cycle;
        Interrupts::NONE
    }

    /// A cycle before which [`Bus::poll`] would answer
    /// [`Interrupts::NONE`] for every cycle and change nothing, so the CPU
    /// skips those polls. Read after every instruction, so it may move
    /// either way with any access or poll. A skipped poll counts as NMI
    /// released: while the NMI level last answered by `poll` is asserted,
    /// return no more than the next poll's cycle (0 will do). The default,
    /// 0, has every poll made.
    #[inline(always)]
    fn quiet_until(&self) -> u64 {
        0
    }

    /// True if a read of `address` has no side effect and returns what the
    /// CPU last wrote there (or a loader put there): memory that nothing
    /// but the CPU's writes changes, as long as the CPU runs. What lets
    /// [`crate::Cpu::run`] skip iterations of a loop that only reads such
    /// memory (see [`crate::Cpu::set_idle_skip`]). The default, false for
    /// every address, never allows it.
    #[inline(always)]
    fn is_plain_memory(&self, address: u16) -> bool {
        let _ = address;
        false
    }

    /// True if a write to `address` has no effect but to store the value
    /// where [`Bus::is_plain_memory`] reads it back (RAM: not the ROM, whose
    /// writes a board may count, and no device). A loop whose only writes
    /// store what is already there (a JSR pushing the same return address
    /// every time) changes nothing, so it may be skipped like one that
    /// only reads. The default, false for every address, never allows it.
    #[inline(always)]
    fn is_plain_store(&self, address: u16) -> bool {
        let _ = address;
        false
    }

    /// True if the run should end at this instruction's end: read only
    /// after a [`Bus::poll`], so a bus raises it in `poll` and keeps
    /// [`Bus::quiet_until`] no later than the poll that is to see it. The
    /// board raises it when a byte reaches a host that watches its line,
    /// so the host looks at the byte the moment it arrives. The default:
    /// never.
    #[inline(always)]
    fn stop_requested(&self) -> bool {
        false
    }
}

impl<B: Bus + ?Sized> Bus for &mut B {
    #[inline(always)]
    fn fetch(&mut self, address: u16, cycle: u64) -> u8 {
        (**self).fetch(address, cycle)
    }

    #[inline(always)]
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        (**self).read(address, cycle)
    }

    #[inline(always)]
    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        (**self).write(address, value, cycle);
    }

    #[inline(always)]
    fn dummy_read(&mut self, address: u16, cycle: u64) {
        (**self).dummy_read(address, cycle);
    }

    #[inline(always)]
    fn read_zp_stack(&mut self, address: u16, cycle: u64) -> u8 {
        (**self).read_zp_stack(address, cycle)
    }

    #[inline(always)]
    fn write_zp_stack(&mut self, address: u16, value: u8, cycle: u64) {
        (**self).write_zp_stack(address, value, cycle);
    }

    #[inline(always)]
    fn peek(&self, address: u16) -> u8 {
        (**self).peek(address)
    }

    #[inline(always)]
    fn poll(&mut self, cycle: u64) -> Interrupts {
        (**self).poll(cycle)
    }

    #[inline(always)]
    fn quiet_until(&self) -> u64 {
        (**self).quiet_until()
    }

    #[inline(always)]
    fn is_plain_memory(&self, address: u16) -> bool {
        (**self).is_plain_memory(address)
    }

    #[inline(always)]
    fn is_plain_store(&self, address: u16) -> bool {
        (**self).is_plain_store(address)
    }

    #[inline(always)]
    fn stop_requested(&self) -> bool {
        (**self).stop_requested()
    }
}

/// An interrupt output (a device's /IRQ or /NMI) that remembers when it last
/// changed, so it can answer [`Bus::poll`] for a cycle that precedes the
/// access which changed it.
///
/// A device calls [`Line::set`] with the cycle of the access (or of the
/// timed event) that changes its output, and answers polls with
/// [`Line::at`]. Several devices sharing the open-collector IRQ line each
/// keep their own `Line`; the board ORs their answers.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Line {
    level: bool,
    before: bool,
    changed_at: u64,
}

impl Line {
    /// A released line.
    #[must_use]
    pub const fn new() -> Line {
        Line {
            level: false,
            before: false,
            changed_at: 0,
        }
    }

    /// Asserts (`true`) or releases (`false`) the line from bus cycle `cycle`
    /// on. Cycles passed to successive calls must not decrease.
    #[inline]
    pub fn set(&mut self, asserted: bool, cycle: u64) {
        if asserted != self.level {
            self.before = self.level;
            self.level = asserted;
            self.changed_at = cycle;
        }
    }

    /// The level during bus cycle `cycle`: the current one if it was set at
    /// or before `cycle`, the previous one otherwise. Exact for any `cycle`
    /// after the change before last, which is all [`Bus::poll`] needs.
    #[inline]
    #[must_use]
    pub const fn at(&self, cycle: u64) -> bool {
        if cycle >= self.changed_at {
            self.level
        } else {
            self.before
        }
    }

    /// The level now.
    #[inline]
    #[must_use]
    pub const fn is_asserted(&self) -> bool {
        self.level
    }
}

/// 64 KiB of plain RAM, no I/O and no interrupt source: the machine test
/// programs run on.
#[derive(Clone, PartialEq, Eq)]
pub struct Ram {
    bytes: Box<[u8; 0x1_0000]>,
}

impl Ram {
    /// 64 KiB of zeros.
    #[must_use]
    pub fn new() -> Ram {
        let bytes: Box<[u8; 0x1_0000]> = vec![0u8; 0x1_0000]
            .into_boxed_slice()
            .try_into()
            .unwrap_or_else(|_| unreachable!("the vector has exactly 64 KiB"));
        Ram { bytes }
    }

    /// Copies `image` into memory from `address` on.
    ///
    /// # Errors
    /// [`crate::Error::ImageTooLarge`] if the image runs past `$FFFF` (it
    /// would wrap onto page zero, which no loader means).
    pub fn load(&mut self, address: u16, image: &[u8]) -> Result<(), crate::Error> {
        let start = usize::from(address);
        let end = start + image.len();
        if end > 0x1_0000 {
            return Err(crate::Error::ImageTooLarge {
                address,
                len: image.len(),
            });
        }
        self.bytes[start..end].copy_from_slice(image);
        Ok(())
    }

    /// The whole address space.
    #[must_use]
    pub fn bytes(&self) -> &[u8; 0x1_0000] {
        &self.bytes
    }

    /// The whole address space, writable (for loaders and tests).
    pub fn bytes_mut(&mut self) -> &mut [u8; 0x1_0000] {
        &mut self.bytes
    }
}

impl Default for Ram {
    fn default() -> Ram {
        Ram::new()
    }
}

impl core::fmt::Debug for Ram {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        // 64 KiB of bytes helps nobody; the vectors identify a loaded program.
        let word = |at: usize| u16::from_le_bytes([self.bytes[at], self.bytes[at + 1]]);
        f.debug_struct("Ram")
            .field("nmi_vector", &format_args!("${:04X}", word(0xFFFA)))
            .field("reset_vector", &format_args!("${:04X}", word(0xFFFC)))
            .field("irq_vector", &format_args!("${:04X}", word(0xFFFE)))
            .finish_non_exhaustive()
    }
}

impl Bus for Ram {
    #[inline(always)]
    fn read(&mut self, address: u16, _cycle: u64) -> u8 {
        self.bytes[usize::from(address)]
    }

    #[inline(always)]
    fn write(&mut self, address: u16, value: u8, _cycle: u64) {
        self.bytes[usize::from(address)] = value;
    }

    #[inline(always)]
    fn dummy_read(&mut self, _address: u16, _cycle: u64) {}

    #[inline(always)]
    fn peek(&self, address: u16) -> u8 {
        self.bytes[usize::from(address)]
    }

    #[inline(always)]
    fn quiet_until(&self) -> u64 {
        // No interrupt source: every poll would answer NONE.
        u64::MAX
    }

    #[inline(always)]
    fn is_plain_memory(&self, _address: u16) -> bool {
        true
    }

    #[inline(always)]
    fn is_plain_store(&self, _address: u16) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_answers_for_cycles_before_its_last_change() {
        let mut line = Line::new();
        assert!(!line.at(0));
        line.set(true, 100);
        assert!(!line.at(99), "before the change the line was released");
        assert!(line.at(100) && line.at(1000));
        line.set(true, 150); // no change: the assertion still dates from 100
        assert!(line.at(120));
        line.set(false, 200);
        assert!(line.at(199) && !line.at(200) && !line.is_asserted());
    }

    #[test]
    fn ram_loads_and_refuses_images_past_the_top() {
        let mut ram = Ram::new();
        ram.load(0xFFFE, &[1, 2]).expect("fits exactly");
        assert_eq!(ram.peek(0xFFFF), 2);
        assert_eq!(ram.read(0xFFFE, 0), 1);
        let err = ram.load(0xFFFF, &[1, 2]).expect_err("one byte too many");
        assert!(matches!(
            err,
            crate::Error::ImageTooLarge {
                address: 0xFFFF,
                len: 2
            }
        ));
    }
}
