//! The opcode dispatch: one `match` arm per opcode byte, all 256 of them.
//!
//! Each arm names the addressing helper and the operation; the helpers make
//! the bus accesses (see `access`), so each arm's cycle count follows from
//! its mode and kind. The arms were laid out from `isa::OPCODES` (mnemonic and
//! mode per byte); the test
//! `cycles::every_opcode_takes_the_cycles_and_length_of_the_isa_table` checks
//! every arm's length, cycle count (with page-cross and branch penalties) and
//! one-access-per-cycle bus traffic against that table, and the py65 and
//! Dormann tests check what the arms compute.

use super::{Cpu, JAM, LATE_POLL, NO_POLL, RETURNED, TRAP, flag};
use crate::bus::Bus;

impl Cpu {
    /// Executes the instruction whose opcode was just fetched from `pc`.
    /// Returns the flow bits (see the constants in the parent module);
    /// `TRAPS` asks for the `TRAP` bit (a run whose hooks ignore traps
    /// saves its comparisons).
    #[inline(always)]
    #[allow(clippy::too_many_lines, reason = "one arm per opcode, all 256")]
    pub(super) fn execute<B: Bus, const TRAPS: bool>(
        &mut self,
        bus: &mut B,
        opcode: u8,
        pc: u16,
    ) -> u8 {
        // Defined here so they can name `self` and `bus`. The zero-page
        // modes access page zero only, which they tell the bus.
        // Reads the operand through an addressing mode and applies `$op`.
        macro_rules! read {
            (zp, $op:ident) => {
                read!(@low zp, $op)
            };
            (zpx, $op:ident) => {
                read!(@low zpx, $op)
            };
            (zpy, $op:ident) => {
                read!(@low zpy, $op)
            };
            (@low $mode:ident, $op:ident) => {{
                let address = self.$mode(bus);
                let value = self.read_zs(bus, address);
                self.$op(value);
            }};
            ($mode:ident, $op:ident) => {{
                let address = self.$mode(bus);
                let value = self.read(bus, address);
                self.$op(value);
            }};
        }
        // Writes a value through an addressing mode.
        macro_rules! write {
            (zp, $value:expr) => {
                write!(@low zp, $value)
            };
            (zpx, $value:expr) => {
                write!(@low zpx, $value)
            };
            (zpy, $value:expr) => {
                write!(@low zpy, $value)
            };
            (@low $mode:ident, $value:expr) => {{
                let address = self.$mode(bus);
                let value = $value;
                self.write_zs(bus, address, value);
            }};
            ($mode:ident, $value:expr) => {{
                let address = self.$mode(bus);
                let value = $value;
                self.write(bus, address, value);
            }};
        }
        // Read-modify-write: read, write the old value back (the NMOS part's
        // double write, which I/O registers see), write the result.
        macro_rules! rmw {
            (zp, $op:ident) => {
                rmw!(@low zp, $op)
            };
            (zpx, $op:ident) => {
                rmw!(@low zpx, $op)
            };
            (@low $mode:ident, $op:ident) => {{
                let address = self.$mode(bus);
                let value = self.read_zs(bus, address);
                self.write_zs(bus, address, value);
                let result = self.$op(value);
                self.write_zs(bus, address, result);
            }};
            ($mode:ident, $op:ident) => {{
                let address = self.$mode(bus);
                let value = self.read(bus, address);
                self.write(bus, address, value);
                let result = self.$op(value);
                self.write(bus, address, result);
            }};
        }
        match opcode {
            0x00 => return self.brk(bus), // BRK Implied
            0x01 => read!(izx, ora),      // ORA IndirectX
            0x02 => return JAM,           // JAM Implied
            0x03 => rmw!(izx, slo),       // SLO IndirectX
            0x04 => read!(zp, nop),       // NOP ZeroPage
            0x05 => read!(zp, ora),       // ORA ZeroPage
            0x06 => rmw!(zp, asl),        // ASL ZeroPage
            0x07 => rmw!(zp, slo),        // SLO ZeroPage
            // PHP Implied
            0x08 => {
                self.dummy_pc(bus);
                let p = self.p() | flag::B;
                self.push(bus, p);
            }
            0x09 => read!(imm, ora), // ORA Immediate
            // ASL Accumulator
            0x0A => {
                self.dummy_pc(bus);
                self.a = self.asl(self.a);
            }
            0x0B => read!(imm, anc), // ANC Immediate
            0x0C => read!(abs, nop), // NOP Absolute
            0x0D => read!(abs, ora), // ORA Absolute
            0x0E => rmw!(abs, asl),  // ASL Absolute
            0x0F => rmw!(abs, slo),  // SLO Absolute
            0x10 => return self.branch::<_, TRAPS>(bus, self.n & 0x80 == 0, pc), // BPL Relative
            0x11 => read!(izy, ora), // ORA IndirectY
            0x12 => return JAM,      // JAM Implied
            0x13 => rmw!(izy_w, slo), // SLO IndirectY
            0x14 => read!(zpx, nop), // NOP ZeroPageX
            0x15 => read!(zpx, ora), // ORA ZeroPageX
            0x16 => rmw!(zpx, asl),  // ASL ZeroPageX
            0x17 => rmw!(zpx, slo),  // SLO ZeroPageX
            // CLC Implied
            0x18 => {
                self.dummy_pc(bus);
                self.c = false;
            }
            0x19 => read!(aby, ora),    // ORA AbsoluteY
            0x1A => self.dummy_pc(bus), // NOP Implied
            0x1B => rmw!(aby_w, slo),   // SLO AbsoluteY
            0x1C => read!(abx, nop),    // NOP AbsoluteX
            0x1D => read!(abx, ora),    // ORA AbsoluteX
            0x1E => rmw!(abx_w, asl),   // ASL AbsoluteX
            0x1F => rmw!(abx_w, slo),   // SLO AbsoluteX
            0x20 => self.jsr(bus),      // JSR Absolute
            0x21 => read!(izx, and),    // AND IndirectX
            0x22 => return JAM,         // JAM Implied
            0x23 => rmw!(izx, rla),     // RLA IndirectX
            0x24 => read!(zp, bit),     // BIT ZeroPage
            0x25 => read!(zp, and),     // AND ZeroPage
            0x26 => rmw!(zp, rol),      // ROL ZeroPage
            0x27 => rmw!(zp, rla),      // RLA ZeroPage
            // PLP Implied
            0x28 => {
                self.dummy_pc(bus);
                self.dummy_stack(bus);
                let p = self.pull(bus);
                let flow = self.old_i();
                self.set_p(p);
                return flow;
            }
            0x29 => read!(imm, and), // AND Immediate
            // ROL Accumulator
            0x2A => {
                self.dummy_pc(bus);
                self.a = self.rol(self.a);
            }
            0x2B => read!(imm, anc), // ANC Immediate
            0x2C => read!(abs, bit), // BIT Absolute
            0x2D => read!(abs, and), // AND Absolute
            0x2E => rmw!(abs, rol),  // ROL Absolute
            0x2F => rmw!(abs, rla),  // RLA Absolute
            0x30 => return self.branch::<_, TRAPS>(bus, self.n & 0x80 != 0, pc), // BMI Relative
            0x31 => read!(izy, and), // AND IndirectY
            0x32 => return JAM,      // JAM Implied
            0x33 => rmw!(izy_w, rla), // RLA IndirectY
            0x34 => read!(zpx, nop), // NOP ZeroPageX
            0x35 => read!(zpx, and), // AND ZeroPageX
            0x36 => rmw!(zpx, rol),  // ROL ZeroPageX
            0x37 => rmw!(zpx, rla),  // RLA ZeroPageX
            // SEC Implied
            0x38 => {
                self.dummy_pc(bus);
                self.c = true;
            }
            0x39 => read!(aby, and),      // AND AbsoluteY
            0x3A => self.dummy_pc(bus),   // NOP Implied
            0x3B => rmw!(aby_w, rla),     // RLA AbsoluteY
            0x3C => read!(abx, nop),      // NOP AbsoluteX
            0x3D => read!(abx, and),      // AND AbsoluteX
            0x3E => rmw!(abx_w, rol),     // ROL AbsoluteX
            0x3F => rmw!(abx_w, rla),     // RLA AbsoluteX
            0x40 => return self.rti(bus), // RTI Implied
            0x41 => read!(izx, eor),      // EOR IndirectX
            0x42 => return JAM,           // JAM Implied
            0x43 => rmw!(izx, sre),       // SRE IndirectX
            0x44 => read!(zp, nop),       // NOP ZeroPage
            0x45 => read!(zp, eor),       // EOR ZeroPage
            0x46 => rmw!(zp, lsr),        // LSR ZeroPage
            0x47 => rmw!(zp, sre),        // SRE ZeroPage
            // PHA Implied
            0x48 => {
                self.dummy_pc(bus);
                self.push(bus, self.a);
            }
            0x49 => read!(imm, eor), // EOR Immediate
            // LSR Accumulator
            0x4A => {
                self.dummy_pc(bus);
                self.a = self.lsr(self.a);
            }
            0x4B => read!(imm, alr),                      // ALR Immediate
            0x4C => return self.jmp::<_, TRAPS>(bus, pc), // JMP Absolute
            0x4D => read!(abs, eor),                      // EOR Absolute
            0x4E => rmw!(abs, lsr),                       // LSR Absolute
            0x4F => rmw!(abs, sre),                       // SRE Absolute
            0x50 => return self.branch::<_, TRAPS>(bus, !self.v(), pc), // BVC Relative
            0x51 => read!(izy, eor),                      // EOR IndirectY
            0x52 => return JAM,                           // JAM Implied
            0x53 => rmw!(izy_w, sre),                     // SRE IndirectY
            0x54 => read!(zpx, nop),                      // NOP ZeroPageX
            0x55 => read!(zpx, eor),                      // EOR ZeroPageX
            0x56 => rmw!(zpx, lsr),                       // LSR ZeroPageX
            0x57 => rmw!(zpx, sre),                       // SRE ZeroPageX
            // CLI Implied
            0x58 => {
                self.dummy_pc(bus);
                let flow = self.old_i();
                self.set_i(false);
                return flow;
            }
            0x59 => read!(aby, eor),    // EOR AbsoluteY
            0x5A => self.dummy_pc(bus), // NOP Implied
            0x5B => rmw!(aby_w, sre),   // SRE AbsoluteY
            0x5C => read!(abx, nop),    // NOP AbsoluteX
            0x5D => read!(abx, eor),    // EOR AbsoluteX
            0x5E => rmw!(abx_w, lsr),   // LSR AbsoluteX
            0x5F => rmw!(abx_w, sre),   // SRE AbsoluteX
            0x60 => self.rts(bus),      // RTS Implied
            0x61 => read!(izx, adc),    // ADC IndirectX
            0x62 => return JAM,         // JAM Implied
            0x63 => rmw!(izx, rra),     // RRA IndirectX
            0x64 => read!(zp, nop),     // NOP ZeroPage
            0x65 => read!(zp, adc),     // ADC ZeroPage
            0x66 => rmw!(zp, ror),      // ROR ZeroPage
            0x67 => rmw!(zp, rra),      // RRA ZeroPage
            // PLA Implied
            0x68 => {
                self.dummy_pc(bus);
                self.dummy_stack(bus);
                let value = self.pull(bus);
                self.lda(value);
            }
            0x69 => read!(imm, adc), // ADC Immediate
            // ROR Accumulator
            0x6A => {
                self.dummy_pc(bus);
                self.a = self.ror(self.a);
            }
            0x6B => read!(imm, arr), // ARR Immediate
            0x6C => return self.jmp_indirect::<_, TRAPS>(bus, pc), // JMP Indirect
            0x6D => read!(abs, adc), // ADC Absolute
            0x6E => rmw!(abs, ror),  // ROR Absolute
            0x6F => rmw!(abs, rra),  // RRA Absolute
            0x70 => return self.branch::<_, TRAPS>(bus, self.v(), pc), // BVS Relative
            0x71 => read!(izy, adc), // ADC IndirectY
            0x72 => return JAM,      // JAM Implied
            0x73 => rmw!(izy_w, rra), // RRA IndirectY
            0x74 => read!(zpx, nop), // NOP ZeroPageX
            0x75 => read!(zpx, adc), // ADC ZeroPageX
            0x76 => rmw!(zpx, ror),  // ROR ZeroPageX
            0x77 => rmw!(zpx, rra),  // RRA ZeroPageX
            // SEI Implied
            0x78 => {
                self.dummy_pc(bus);
                let flow = self.old_i();
                self.set_i(true);
                return flow;
            }
            0x79 => read!(aby, adc),              // ADC AbsoluteY
            0x7A => self.dummy_pc(bus),           // NOP Implied
            0x7B => rmw!(aby_w, rra),             // RRA AbsoluteY
            0x7C => read!(abx, nop),              // NOP AbsoluteX
            0x7D => read!(abx, adc),              // ADC AbsoluteX
            0x7E => rmw!(abx_w, ror),             // ROR AbsoluteX
            0x7F => rmw!(abx_w, rra),             // RRA AbsoluteX
            0x80 => read!(imm, nop),              // NOP Immediate
            0x81 => write!(izx, self.a),          // STA IndirectX
            0x82 => read!(imm, nop),              // NOP Immediate
            0x83 => write!(izx, self.a & self.x), // SAX IndirectX
            0x84 => write!(zp, self.y),           // STY ZeroPage
            0x85 => write!(zp, self.a),           // STA ZeroPage
            0x86 => write!(zp, self.x),           // STX ZeroPage
            0x87 => write!(zp, self.a & self.x),  // SAX ZeroPage
            // DEY Implied
            0x88 => {
                self.dummy_pc(bus);
                self.y = self.dec(self.y);
            }
            0x89 => read!(imm, nop), // NOP Immediate
            // TXA Implied
            0x8A => {
                self.dummy_pc(bus);
                self.lda(self.x);
            }
            0x8B => read!(imm, ane),              // ANE Immediate
            0x8C => write!(abs, self.y),          // STY Absolute
            0x8D => write!(abs, self.a),          // STA Absolute
            0x8E => write!(abs, self.x),          // STX Absolute
            0x8F => write!(abs, self.a & self.x), // SAX Absolute
            0x90 => return self.branch::<_, TRAPS>(bus, !self.c, pc), // BCC Relative
            0x91 => write!(izy_w, self.a),        // STA IndirectY
            0x92 => return JAM,                   // JAM Implied
            // SHA IndirectY
            0x93 => {
                let base = self.zp_pointer(bus);
                self.store_and_high(bus, base, self.y, self.a & self.x);
            }
            0x94 => write!(zpx, self.y),          // STY ZeroPageX
            0x95 => write!(zpx, self.a),          // STA ZeroPageX
            0x96 => write!(zpy, self.x),          // STX ZeroPageY
            0x97 => write!(zpy, self.a & self.x), // SAX ZeroPageY
            // TYA Implied
            0x98 => {
                self.dummy_pc(bus);
                self.lda(self.y);
            }
            0x99 => write!(aby_w, self.a), // STA AbsoluteY
            // TXS Implied
            0x9A => {
                self.dummy_pc(bus);
                self.s = self.x;
            }
            // TAS AbsoluteY
            0x9B => {
                let base = self.fetch_word(bus);
                self.s = self.a & self.x;
                self.store_and_high(bus, base, self.y, self.s);
            }
            // SHY AbsoluteX
            0x9C => {
                let base = self.fetch_word(bus);
                self.store_and_high(bus, base, self.x, self.y);
            }
            0x9D => write!(abx_w, self.a), // STA AbsoluteX
            // SHX AbsoluteY
            0x9E => {
                let base = self.fetch_word(bus);
                self.store_and_high(bus, base, self.y, self.x);
            }
            // SHA AbsoluteY
            0x9F => {
                let base = self.fetch_word(bus);
                self.store_and_high(bus, base, self.y, self.a & self.x);
            }
            0xA0 => read!(imm, ldy), // LDY Immediate
            0xA1 => read!(izx, lda), // LDA IndirectX
            0xA2 => read!(imm, ldx), // LDX Immediate
            0xA3 => read!(izx, lax), // LAX IndirectX
            0xA4 => read!(zp, ldy),  // LDY ZeroPage
            0xA5 => read!(zp, lda),  // LDA ZeroPage
            0xA6 => read!(zp, ldx),  // LDX ZeroPage
            0xA7 => read!(zp, lax),  // LAX ZeroPage
            // TAY Implied
            0xA8 => {
                self.dummy_pc(bus);
                self.ldy(self.a);
            }
            0xA9 => read!(imm, lda), // LDA Immediate
            // TAX Implied
            0xAA => {
                self.dummy_pc(bus);
                self.ldx(self.a);
            }
            0xAB => read!(imm, lxa), // LXA Immediate
            0xAC => read!(abs, ldy), // LDY Absolute
            0xAD => read!(abs, lda), // LDA Absolute
            0xAE => read!(abs, ldx), // LDX Absolute
            0xAF => read!(abs, lax), // LAX Absolute
            0xB0 => return self.branch::<_, TRAPS>(bus, self.c, pc), // BCS Relative
            0xB1 => read!(izy, lda), // LDA IndirectY
            0xB2 => return JAM,      // JAM Implied
            0xB3 => read!(izy, lax), // LAX IndirectY
            0xB4 => read!(zpx, ldy), // LDY ZeroPageX
            0xB5 => read!(zpx, lda), // LDA ZeroPageX
            0xB6 => read!(zpy, ldx), // LDX ZeroPageY
            0xB7 => read!(zpy, lax), // LAX ZeroPageY
            // CLV Implied
            0xB8 => {
                self.dummy_pc(bus);
                self.set_v(false);
            }
            0xB9 => read!(aby, lda), // LDA AbsoluteY
            // TSX Implied
            0xBA => {
                self.dummy_pc(bus);
                self.ldx(self.s);
            }
            0xBB => read!(aby, las), // LAS AbsoluteY
            0xBC => read!(abx, ldy), // LDY AbsoluteX
            0xBD => read!(abx, lda), // LDA AbsoluteX
            0xBE => read!(aby, ldx), // LDX AbsoluteY
            0xBF => read!(aby, lax), // LAX AbsoluteY
            0xC0 => read!(imm, cpy), // CPY Immediate
            0xC1 => read!(izx, cmp), // CMP IndirectX
            0xC2 => read!(imm, nop), // NOP Immediate
            0xC3 => rmw!(izx, dcp),  // DCP IndirectX
            0xC4 => read!(zp, cpy),  // CPY ZeroPage
            0xC5 => read!(zp, cmp),  // CMP ZeroPage
            0xC6 => rmw!(zp, dec),   // DEC ZeroPage
            0xC7 => rmw!(zp, dcp),   // DCP ZeroPage
            // INY Implied
            0xC8 => {
                self.dummy_pc(bus);
                self.y = self.inc(self.y);
            }
            0xC9 => read!(imm, cmp), // CMP Immediate
            // DEX Implied
            0xCA => {
                self.dummy_pc(bus);
                self.x = self.dec(self.x);
            }
            0xCB => read!(imm, sbx), // SBX Immediate
            0xCC => read!(abs, cpy), // CPY Absolute
            0xCD => read!(abs, cmp), // CMP Absolute
            0xCE => rmw!(abs, dec),  // DEC Absolute
            0xCF => rmw!(abs, dcp),  // DCP Absolute
            0xD0 => return self.branch::<_, TRAPS>(bus, self.z != 0, pc), // BNE Relative
            0xD1 => read!(izy, cmp), // CMP IndirectY
            0xD2 => return JAM,      // JAM Implied
            0xD3 => rmw!(izy_w, dcp), // DCP IndirectY
            0xD4 => read!(zpx, nop), // NOP ZeroPageX
            0xD5 => read!(zpx, cmp), // CMP ZeroPageX
            0xD6 => rmw!(zpx, dec),  // DEC ZeroPageX
            0xD7 => rmw!(zpx, dcp),  // DCP ZeroPageX
            // CLD Implied
            0xD8 => {
                self.dummy_pc(bus);
                self.set_d(false);
            }
            0xD9 => read!(aby, cmp),    // CMP AbsoluteY
            0xDA => self.dummy_pc(bus), // NOP Implied
            0xDB => rmw!(aby_w, dcp),   // DCP AbsoluteY
            0xDC => read!(abx, nop),    // NOP AbsoluteX
            0xDD => read!(abx, cmp),    // CMP AbsoluteX
            0xDE => rmw!(abx_w, dec),   // DEC AbsoluteX
            0xDF => rmw!(abx_w, dcp),   // DCP AbsoluteX
            0xE0 => read!(imm, cpx),    // CPX Immediate
            0xE1 => read!(izx, sbc),    // SBC IndirectX
            0xE2 => read!(imm, nop),    // NOP Immediate
            0xE3 => rmw!(izx, isc),     // ISC IndirectX
            0xE4 => read!(zp, cpx),     // CPX ZeroPage
            0xE5 => read!(zp, sbc),     // SBC ZeroPage
            0xE6 => rmw!(zp, inc),      // INC ZeroPage
            0xE7 => rmw!(zp, isc),      // ISC ZeroPage
            // INX Implied
            0xE8 => {
                self.dummy_pc(bus);
                self.x = self.inc(self.x);
            }
            0xE9 => read!(imm, sbc),    // SBC Immediate
            0xEA => self.dummy_pc(bus), // NOP Implied
            0xEB => read!(imm, sbc),    // SBC Immediate
            0xEC => read!(abs, cpx),    // CPX Absolute
            0xED => read!(abs, sbc),    // SBC Absolute
            0xEE => rmw!(abs, inc),     // INC Absolute
            0xEF => rmw!(abs, isc),     // ISC Absolute
            0xF0 => return self.branch::<_, TRAPS>(bus, self.z == 0, pc), // BEQ Relative
            0xF1 => read!(izy, sbc),    // SBC IndirectY
            0xF2 => return JAM,         // JAM Implied
            0xF3 => rmw!(izy_w, isc),   // ISC IndirectY
            0xF4 => read!(zpx, nop),    // NOP ZeroPageX
            0xF5 => read!(zpx, sbc),    // SBC ZeroPageX
            0xF6 => rmw!(zpx, inc),     // INC ZeroPageX
            0xF7 => rmw!(zpx, isc),     // ISC ZeroPageX
            // SED Implied
            0xF8 => {
                self.dummy_pc(bus);
                self.set_d(true);
            }
            0xF9 => read!(aby, sbc),    // SBC AbsoluteY
            0xFA => self.dummy_pc(bus), // NOP Implied
            0xFB => rmw!(aby_w, isc),   // ISC AbsoluteY
            0xFC => read!(abx, nop),    // NOP AbsoluteX
            0xFD => read!(abx, sbc),    // SBC AbsoluteX
            0xFE => rmw!(abx_w, inc),   // INC AbsoluteX
            0xFF => rmw!(abx_w, isc),   // ISC AbsoluteX
        }
        0
    }

    /// An operand read whose value is ignored (the NOP forms that address
    /// memory still read it, which an I/O register notices).
    #[inline(always)]
    fn nop(&mut self, _value: u8) {}

    /// Bcc/Bcs/...: 2 cycles; 3 if taken (a dummy read of the next opcode);
    /// 4 if the target is in another page (a dummy read at the target's low
    /// byte in the old page). A taken branch that stays in its page polls
    /// interrupts one cycle early.
    #[inline(always)]
    fn branch<B: Bus, const TRAPS: bool>(&mut self, bus: &mut B, taken: bool, pc: u16) -> u8 {
        let offset = self.fetch(bus) as i8;
        if !taken {
            return 0;
        }
        self.dummy_pc(bus);
        let target = self.pc.wrapping_add_signed(i16::from(offset));
        let mut flow = if (target ^ self.pc) & 0xFF00 != 0 {
            self.dummy_read(bus, (self.pc & 0xFF00) | (target & 0x00FF));
            0
        } else {
            LATE_POLL
        };
        self.pc = target;
        if TRAPS && target == pc {
            flow |= TRAP;
        }
        flow
    }

    /// JMP nnnn (3 cycles).
    #[inline(always)]
    fn jmp<B: Bus, const TRAPS: bool>(&mut self, bus: &mut B, pc: u16) -> u8 {
        self.pc = self.fetch_word(bus);
        if TRAPS && self.pc == pc { TRAP } else { 0 }
    }

    /// JMP (nnnn) (5 cycles): the NMOS part does not carry into the
    /// pointer's high byte, so `JMP ($12FF)` reads `$12FF` and `$1200`.
    #[inline(always)]
    fn jmp_indirect<B: Bus, const TRAPS: bool>(&mut self, bus: &mut B, pc: u16) -> u8 {
        let pointer = self.fetch_word(bus);
        let lo = self.read(bus, pointer);
        let hi = self.read(bus, (pointer & 0xFF00) | (pointer.wrapping_add(1) & 0x00FF));
        self.pc = u16::from_le_bytes([lo, hi]);
        if TRAPS && self.pc == pc { TRAP } else { 0 }
    }

    /// JSR nnnn (6 cycles): low byte, a dummy stack read, push the address
    /// of the high byte (return address - 1), then fetch the high byte.
    #[inline(always)]
    fn jsr<B: Bus>(&mut self, bus: &mut B) {
        let lo = self.fetch(bus);
        self.dummy_stack(bus);
        let [pcl, pch] = self.pc.to_le_bytes();
        self.push(bus, pch);
        self.push(bus, pcl);
        let hi = self.read(bus, self.pc);
        self.pc = u16::from_le_bytes([lo, hi]);
    }

    /// RTS (6 cycles): pull the return address - 1, then step past it with a
    /// read.
    #[inline(always)]
    fn rts<B: Bus>(&mut self, bus: &mut B) {
        self.dummy_pc(bus);
        self.dummy_stack(bus);
        let lo = self.pull(bus);
        let hi = self.pull(bus);
        self.pc = u16::from_le_bytes([lo, hi]);
        self.dummy_read(bus, self.pc);
        self.pc = self.pc.wrapping_add(1);
    }

    /// RTI (6 cycles): pull P, then PC. The restored I flag is in force for
    /// this instruction's own interrupt poll.
    #[inline(always)]
    fn rti<B: Bus>(&mut self, bus: &mut B) -> u8 {
        self.dummy_pc(bus);
        self.dummy_stack(bus);
        let p = self.pull(bus);
        self.set_p(p);
        let lo = self.pull(bus);
        let hi = self.pull(bus);
        self.pc = u16::from_le_bytes([lo, hi]);
        RETURNED
    }

    /// BRK (7 cycles): the padding byte is read and skipped, then the
    /// interrupt sequence pushes P with B set.
    #[inline(always)]
    fn brk<B: Bus>(&mut self, bus: &mut B) -> u8 {
        self.dummy_read(bus, self.pc);
        self.pc = self.pc.wrapping_add(1);
        self.interrupt_tail(bus, flag::B);
        NO_POLL
    }
}
