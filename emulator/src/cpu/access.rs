//! Bus accesses and addressing modes, cycle by cycle as in the datasheet's
//! tables (and "64doc"): each helper makes exactly the accesses the NMOS part
//! makes, dummy ones included, and returns the effective address. The
//! operand access itself (read, write or read-modify-write) is the caller's.

use super::Cpu;
use crate::bus::Bus;

impl Cpu {
    /// One read cycle.
    #[inline(always)]
    pub(super) fn read<B: Bus>(&mut self, bus: &mut B, address: u16) -> u8 {
        let value = bus.read(address, self.cycles);
        self.cycles += 1;
        value
    }

    /// One read cycle whose value is ignored (a dummy read, see
    /// [`Bus::dummy_read`]).
    #[inline(always)]
    pub(super) fn dummy_read<B: Bus>(&mut self, bus: &mut B, address: u16) {
        bus.dummy_read(address, self.cycles);
        self.cycles += 1;
    }

    /// One read cycle in page zero or the stack page.
    #[inline(always)]
    pub(super) fn read_zs<B: Bus>(&mut self, bus: &mut B, address: u16) -> u8 {
        let value = bus.read_zp_stack(address, self.cycles);
        self.cycles += 1;
        value
    }

    /// One write cycle in page zero or the stack page.
    #[inline(always)]
    pub(super) fn write_zs<B: Bus>(&mut self, bus: &mut B, address: u16, value: u8) {
        bus.write_zp_stack(address, value, self.cycles);
        self.cycles += 1;
    }

    /// One write cycle.
    #[inline(always)]
    pub(super) fn write<B: Bus>(&mut self, bus: &mut B, address: u16, value: u8) {
        bus.write(address, value, self.cycles);
        self.cycles += 1;
    }

    /// Reads the byte at PC (as an instruction fetch, [`Bus::fetch`]) and
    /// steps past it.
    #[inline(always)]
    pub(super) fn fetch<B: Bus>(&mut self, bus: &mut B) -> u8 {
        let value = bus.fetch(self.pc, self.cycles);
        self.cycles += 1;
        self.pc = self.pc.wrapping_add(1);
        value
    }

    /// Reads a little-endian word at PC and steps past it.
    #[inline(always)]
    pub(super) fn fetch_word<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let lo = self.fetch(bus);
        let hi = self.fetch(bus);
        u16::from_le_bytes([lo, hi])
    }

    /// The second cycle of a one-byte instruction: the byte after the opcode
    /// is read and ignored; PC does not move.
    #[inline(always)]
    pub(super) fn dummy_pc<B: Bus>(&mut self, bus: &mut B) {
        self.dummy_read(bus, self.pc);
    }

    /// The dummy read of the stack top that precedes a pull (and JSR's
    /// internal cycle).
    #[inline(always)]
    pub(super) fn dummy_stack<B: Bus>(&mut self, bus: &mut B) {
        self.dummy_read(bus, 0x0100 | u16::from(self.s));
    }

    /// Pushes a byte: write at `$0100 + S`, then S decreases.
    #[inline(always)]
    pub(super) fn push<B: Bus>(&mut self, bus: &mut B, value: u8) {
        self.write_zs(bus, 0x0100 | u16::from(self.s), value);
        self.s = self.s.wrapping_sub(1);
    }

    /// Pulls a byte: S increases, then read at `$0100 + S`.
    #[inline(always)]
    pub(super) fn pull<B: Bus>(&mut self, bus: &mut B) -> u8 {
        self.s = self.s.wrapping_add(1);
        self.read_zs(bus, 0x0100 | u16::from(self.s))
    }

    /// `#nn`: the operand is the byte at PC.
    #[inline(always)]
    pub(super) fn imm<B: Bus>(&mut self, _bus: &mut B) -> u16 {
        let address = self.pc;
        self.pc = self.pc.wrapping_add(1);
        address
    }

    /// `nn`.
    #[inline(always)]
    pub(super) fn zp<B: Bus>(&mut self, bus: &mut B) -> u16 {
        u16::from(self.fetch(bus))
    }

    /// `nn,X`: the unindexed address is read once while X is added, and the
    /// sum wraps within page zero.
    #[inline(always)]
    pub(super) fn zpx<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch(bus);
        self.dummy_read(bus, u16::from(base));
        u16::from(base.wrapping_add(self.x))
    }

    /// `nn,Y`, as `nn,X`.
    #[inline(always)]
    pub(super) fn zpy<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch(bus);
        self.dummy_read(bus, u16::from(base));
        u16::from(base.wrapping_add(self.y))
    }

    /// `nnnn`.
    #[inline(always)]
    pub(super) fn abs<B: Bus>(&mut self, bus: &mut B) -> u16 {
        self.fetch_word(bus)
    }

    /// Adds an index to a base address. The CPU first puts the sum's low
    /// byte next to the base's high byte on the bus; `always` is true for
    /// stores and read-modify-write, which make that dummy read even when no
    /// carry needs fixing, and false for reads, which make it (and pay a
    /// cycle) only on a page cross.
    #[inline(always)]
    fn indexed<B: Bus>(&mut self, bus: &mut B, base: u16, index: u8, always: bool) -> u16 {
        let address = base.wrapping_add(u16::from(index));
        if always || (base ^ address) & 0xFF00 != 0 {
            self.dummy_read(bus, (base & 0xFF00) | (address & 0x00FF));
        }
        address
    }

    /// `nnnn,X` for reads (one more cycle on a page cross).
    #[inline(always)]
    pub(super) fn abx<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch_word(bus);
        self.indexed(bus, base, self.x, false)
    }

    /// `nnnn,Y` for reads (one more cycle on a page cross).
    #[inline(always)]
    pub(super) fn aby<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch_word(bus);
        self.indexed(bus, base, self.y, false)
    }

    /// `nnnn,X` for stores and read-modify-write (always the long count).
    #[inline(always)]
    pub(super) fn abx_w<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch_word(bus);
        self.indexed(bus, base, self.x, true)
    }

    /// `nnnn,Y` for stores and read-modify-write (always the long count).
    #[inline(always)]
    pub(super) fn aby_w<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch_word(bus);
        self.indexed(bus, base, self.y, true)
    }

    /// `(nn,X)`: the pointer is read from page zero at `nn + X`, wrapping
    /// within page zero (after a dummy read of `nn`).
    #[inline(always)]
    pub(super) fn izx<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.fetch(bus);
        self.dummy_read(bus, u16::from(base));
        let pointer = base.wrapping_add(self.x);
        let lo = self.read_zs(bus, u16::from(pointer));
        let hi = self.read_zs(bus, u16::from(pointer.wrapping_add(1)));
        u16::from_le_bytes([lo, hi])
    }

    /// The pointer of `(nn),Y`, read from page zero (a pointer at `$FF`
    /// takes its high byte from `$00`).
    #[inline(always)]
    pub(super) fn zp_pointer<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let pointer = self.fetch(bus);
        let lo = self.read_zs(bus, u16::from(pointer));
        let hi = self.read_zs(bus, u16::from(pointer.wrapping_add(1)));
        u16::from_le_bytes([lo, hi])
    }

    /// `(nn),Y` for reads (one more cycle on a page cross).
    #[inline(always)]
    pub(super) fn izy<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.zp_pointer(bus);
        self.indexed(bus, base, self.y, false)
    }

    /// `(nn),Y` for stores and read-modify-write (always the long count).
    #[inline(always)]
    pub(super) fn izy_w<B: Bus>(&mut self, bus: &mut B) -> u16 {
        let base = self.zp_pointer(bus);
        self.indexed(bus, base, self.y, true)
    }

    /// The unstable stores SHA, SHX, SHY and TAS: the value is `value &
    /// (H + 1)` where H is the high byte of the base address, and when the
    /// index crosses a page the stored value also replaces the high byte of
    /// the address (the NMOS part's behaviour as "No More Secrets"
    /// describes it). `base` has been fetched; this makes the dummy read and
    /// the write.
    #[inline(always)]
    pub(super) fn store_and_high<B: Bus>(&mut self, bus: &mut B, base: u16, index: u8, value: u8) {
        let address = self.indexed(bus, base, index, true);
        let [_, high] = base.to_le_bytes();
        let stored = value & high.wrapping_add(1);
        let address = if (base ^ address) & 0xFF00 != 0 {
            (u16::from(stored) << 8) | (address & 0x00FF)
        } else {
            address
        };
        self.write(bus, address, stored);
    }
}
