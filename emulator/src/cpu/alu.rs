//! The arithmetic and logic of every instruction, flags included: binary
//! and NMOS decimal ADC/SBC, compares, shifts, and the combined operations
//! of the undocumented opcodes.
//!
//! NMOS decimal mode follows Bruce Clark's description (6502.org, "Decimal
//! Mode", appendix A), which the real part obeys for valid and invalid BCD
//! alike: ADC takes N and V from the sum after the low-nibble adjustment and
//! Z from the binary sum; SBC takes every flag from the binary difference.
//! No extra cycle is spent in decimal mode (that is the 65C02).

use super::Cpu;

impl Cpu {
    /// Sets N and Z from a result.
    #[inline(always)]
    pub(super) fn nz(&mut self, value: u8) {
        self.n = value;
        self.z = value;
    }

    #[inline(always)]
    pub(super) fn lda(&mut self, value: u8) {
        self.a = value;
        self.nz(value);
    }

    #[inline(always)]
    pub(super) fn ldx(&mut self, value: u8) {
        self.x = value;
        self.nz(value);
    }

    #[inline(always)]
    pub(super) fn ldy(&mut self, value: u8) {
        self.y = value;
        self.nz(value);
    }

    /// LAX: A and X both loaded.
    #[inline(always)]
    pub(super) fn lax(&mut self, value: u8) {
        self.a = value;
        self.x = value;
        self.nz(value);
    }

    #[inline(always)]
    pub(super) fn ora(&mut self, value: u8) {
        self.a |= value;
        self.nz(self.a);
    }

    #[inline(always)]
    pub(super) fn and(&mut self, value: u8) {
        self.a &= value;
        self.nz(self.a);
    }

    #[inline(always)]
    pub(super) fn eor(&mut self, value: u8) {
        self.a ^= value;
        self.nz(self.a);
    }

    /// BIT: N and V from the operand, Z from A AND operand.
    #[inline(always)]
    pub(super) fn bit(&mut self, value: u8) {
        self.n = value;
        self.set_v(value & 0x40 != 0);
        self.z = self.a & value;
    }

    /// CMP, CPX, CPY: C is "no borrow".
    #[inline(always)]
    pub(super) fn compare(&mut self, register: u8, value: u8) {
        self.c = register >= value;
        self.nz(register.wrapping_sub(value));
    }

    #[inline(always)]
    pub(super) fn cmp(&mut self, value: u8) {
        self.compare(self.a, value);
    }

    #[inline(always)]
    pub(super) fn cpx(&mut self, value: u8) {
        self.compare(self.x, value);
    }

    #[inline(always)]
    pub(super) fn cpy(&mut self, value: u8) {
        self.compare(self.y, value);
    }

    #[inline(always)]
    pub(super) fn adc(&mut self, value: u8) {
        if self.d() {
            self.adc_decimal(value);
        } else {
            self.adc_binary(value);
        }
    }

    #[inline(always)]
    fn adc_binary(&mut self, value: u8) {
        let sum = u16::from(self.a) + u16::from(value) + u16::from(self.c);
        let result = sum as u8;
        self.set_v((!(self.a ^ value) & (self.a ^ result) & 0x80) != 0);
        self.c = sum > 0xFF;
        self.a = result;
        self.nz(result);
    }

    /// NMOS decimal ADC (Clark's sequences 1 and 2).
    #[inline(always)]
    fn adc_decimal(&mut self, value: u8) {
        let a = self.a;
        let carry = u16::from(self.c);
        let mut low = u16::from(a & 0x0F) + u16::from(value & 0x0F) + carry;
        if low >= 0x0A {
            low = ((low + 0x06) & 0x0F) + 0x10;
        }
        let mut sum = u16::from(a & 0xF0) + u16::from(value & 0xF0) + low;
        // N and V come from the sum before the high-nibble adjustment, read
        // as a signed byte; Z from the plain binary sum.
        let intermediate = sum as u8;
        self.n = intermediate;
        self.set_v((!(a ^ value) & (a ^ intermediate) & 0x80) != 0);
        self.z = (u16::from(a) + u16::from(value) + carry) as u8;
        if sum >= 0xA0 {
            sum += 0x60;
        }
        self.c = sum >= 0x100;
        self.a = sum as u8;
    }

    #[inline(always)]
    pub(super) fn sbc(&mut self, value: u8) {
        if self.d() {
            self.sbc_decimal(value);
        } else {
            self.adc_binary(!value);
        }
    }

    /// NMOS decimal SBC (Clark's sequence 3); flags as in binary.
    #[inline(always)]
    fn sbc_decimal(&mut self, value: u8) {
        let a = self.a;
        let borrow = i16::from(!self.c);
        let mut low = i16::from(a & 0x0F) - i16::from(value & 0x0F) - borrow;
        if low < 0 {
            low = ((low - 0x06) & 0x0F) - 0x10;
        }
        let mut result = i16::from(a & 0xF0) - i16::from(value & 0xF0) + low;
        if result < 0 {
            result -= 0x60;
        }
        self.adc_binary(!value);
        self.a = result as u8;
    }

    #[inline(always)]
    pub(super) fn asl(&mut self, value: u8) -> u8 {
        self.c = value & 0x80 != 0;
        let result = value << 1;
        self.nz(result);
        result
    }

    #[inline(always)]
    pub(super) fn lsr(&mut self, value: u8) -> u8 {
        self.c = value & 0x01 != 0;
        let result = value >> 1;
        self.nz(result);
        result
    }

    #[inline(always)]
    pub(super) fn rol(&mut self, value: u8) -> u8 {
        let result = (value << 1) | u8::from(self.c);
        self.c = value & 0x80 != 0;
        self.nz(result);
        result
    }

    #[inline(always)]
    pub(super) fn ror(&mut self, value: u8) -> u8 {
        let result = (value >> 1) | (u8::from(self.c) << 7);
        self.c = value & 0x01 != 0;
        self.nz(result);
        result
    }

    #[inline(always)]
    pub(super) fn inc(&mut self, value: u8) -> u8 {
        let result = value.wrapping_add(1);
        self.nz(result);
        result
    }

    #[inline(always)]
    pub(super) fn dec(&mut self, value: u8) -> u8 {
        let result = value.wrapping_sub(1);
        self.nz(result);
        result
    }

    /// SLO: ASL memory, then ORA.
    #[inline(always)]
    pub(super) fn slo(&mut self, value: u8) -> u8 {
        let result = self.asl(value);
        self.ora(result);
        result
    }

    /// RLA: ROL memory, then AND.
    #[inline(always)]
    pub(super) fn rla(&mut self, value: u8) -> u8 {
        let result = self.rol(value);
        self.and(result);
        result
    }

    /// SRE: LSR memory, then EOR.
    #[inline(always)]
    pub(super) fn sre(&mut self, value: u8) -> u8 {
        let result = self.lsr(value);
        self.eor(result);
        result
    }

    /// RRA: ROR memory, then ADC (decimal mode applies).
    #[inline(always)]
    pub(super) fn rra(&mut self, value: u8) -> u8 {
        let result = self.ror(value);
        self.adc(result);
        result
    }

    /// DCP: DEC memory, then CMP.
    #[inline(always)]
    pub(super) fn dcp(&mut self, value: u8) -> u8 {
        let result = value.wrapping_sub(1);
        self.cmp(result);
        result
    }

    /// ISC: INC memory, then SBC (decimal mode applies).
    #[inline(always)]
    pub(super) fn isc(&mut self, value: u8) -> u8 {
        let result = value.wrapping_add(1);
        self.sbc(result);
        result
    }

    /// ANC: AND, then C copies N.
    #[inline(always)]
    pub(super) fn anc(&mut self, value: u8) {
        self.and(value);
        self.c = self.a & 0x80 != 0;
    }

    /// ALR: AND, then LSR A.
    #[inline(always)]
    pub(super) fn alr(&mut self, value: u8) {
        let masked = self.a & value;
        self.a = self.lsr(masked);
    }

    /// ARR: AND, then ROR A with odd flags; in decimal mode the result is
    /// also BCD-fixed nibble by nibble (the NMOS part's ALU, as "64doc"
    /// describes it).
    #[inline(always)]
    pub(super) fn arr(&mut self, value: u8) {
        let masked = self.a & value;
        let rotated = (masked >> 1) | (u8::from(self.c) << 7);
        self.nz(rotated);
        if !self.d() {
            self.c = rotated & 0x40 != 0;
            self.set_v(((rotated >> 6) ^ (rotated >> 5)) & 1 != 0);
            self.a = rotated;
            return;
        }
        // V: bit 6 changed between the AND and the rotation.
        self.set_v((masked ^ rotated) & 0x40 != 0);
        let mut result = rotated;
        let (high, low) = (masked >> 4, masked & 0x0F);
        if low + (low & 1) > 5 {
            result = (result & 0xF0) | (result.wrapping_add(6) & 0x0F);
        }
        self.c = high + (high & 1) > 5;
        if self.c {
            result = result.wrapping_add(0x60);
        }
        self.a = result;
    }

    /// ANE (XAA): `A = (A | $EE) & X & operand`. The OR constant varies
    /// between chips and with temperature; `$EE` is the common value.
    #[inline(always)]
    pub(super) fn ane(&mut self, value: u8) {
        self.a = (self.a | 0xEE) & self.x & value;
        self.nz(self.a);
    }

    /// LXA (LAX #): `A = X = (A | $EE) & operand`, same magic constant.
    #[inline(always)]
    pub(super) fn lxa(&mut self, value: u8) {
        let result = (self.a | 0xEE) & value;
        self.lax(result);
    }

    /// SBX (AXS): `X = (A & X) - operand`, flags as CMP; ignores D and C.
    #[inline(always)]
    pub(super) fn sbx(&mut self, value: u8) {
        let masked = self.a & self.x;
        self.c = masked >= value;
        self.x = masked.wrapping_sub(value);
        self.nz(self.x);
    }

    /// LAS: `A = X = S = memory & S`.
    #[inline(always)]
    pub(super) fn las(&mut self, value: u8) {
        let result = value & self.s;
        self.s = result;
        self.lax(result);
    }
}
