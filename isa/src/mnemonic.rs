//! Instruction mnemonics: the 56 documented ones of the MOS datasheet and the
//! undocumented ones of the NMOS part, with the aliases other assemblers use.

use core::fmt;

macro_rules! mnemonics {
    ($( $(#[doc = $doc:literal])* $variant:ident = $name:literal $(| $alias:literal)* ;)*) => {
        /// An instruction mnemonic.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Mnemonic {
            $( $(#[doc = $doc])* $variant, )*
        }

        impl Mnemonic {
            /// Every mnemonic, documented ones first.
            pub const ALL: &'static [Mnemonic] = &[ $( Mnemonic::$variant, )* ];

            /// The canonical upper-case name (`"LDA"`, `"SBX"`).
            #[must_use]
            pub const fn name(self) -> &'static str {
                match self { $( Mnemonic::$variant => $name, )* }
            }

            /// Looks a mnemonic up by name or alias, ignoring case
            /// (`"lda"`, `"AXS"` for `SBX`, `"ISB"` for `ISC`).
            #[must_use]
            pub fn from_name(text: &str) -> Option<Mnemonic> {
                if text.len() != 3 {
                    return None;
                }
                let mut upper = [0u8; 3];
                for (slot, byte) in upper.iter_mut().zip(text.bytes()) {
                    *slot = byte.to_ascii_uppercase();
                }
                match core::str::from_utf8(&upper).unwrap_or("") {
                    $( $name $(| $alias)* => Some(Mnemonic::$variant), )*
                    _ => None,
                }
            }
        }
    };
}

mnemonics! {
    /// Add with carry.
    Adc = "ADC";
    /// AND with accumulator.
    And = "AND";
    /// Arithmetic shift left.
    Asl = "ASL";
    /// Branch if carry clear.
    Bcc = "BCC";
    /// Branch if carry set.
    Bcs = "BCS";
    /// Branch if equal (Z set).
    Beq = "BEQ";
    /// Test bits in memory with accumulator.
    Bit = "BIT";
    /// Branch if minus (N set).
    Bmi = "BMI";
    /// Branch if not equal (Z clear).
    Bne = "BNE";
    /// Branch if plus (N clear).
    Bpl = "BPL";
    /// Force break (software interrupt).
    Brk = "BRK";
    /// Branch if overflow clear.
    Bvc = "BVC";
    /// Branch if overflow set.
    Bvs = "BVS";
    /// Clear carry.
    Clc = "CLC";
    /// Clear decimal mode.
    Cld = "CLD";
    /// Clear interrupt disable.
    Cli = "CLI";
    /// Clear overflow.
    Clv = "CLV";
    /// Compare with accumulator.
    Cmp = "CMP";
    /// Compare with X.
    Cpx = "CPX";
    /// Compare with Y.
    Cpy = "CPY";
    /// Decrement memory.
    Dec = "DEC";
    /// Decrement X.
    Dex = "DEX";
    /// Decrement Y.
    Dey = "DEY";
    /// Exclusive-OR with accumulator.
    Eor = "EOR";
    /// Increment memory.
    Inc = "INC";
    /// Increment X.
    Inx = "INX";
    /// Increment Y.
    Iny = "INY";
    /// Jump.
    Jmp = "JMP";
    /// Jump to subroutine.
    Jsr = "JSR";
    /// Load accumulator.
    Lda = "LDA";
    /// Load X.
    Ldx = "LDX";
    /// Load Y.
    Ldy = "LDY";
    /// Logical shift right.
    Lsr = "LSR";
    /// No operation (the documented `$EA` and the undocumented forms).
    Nop = "NOP";
    /// OR with accumulator.
    Ora = "ORA";
    /// Push accumulator.
    Pha = "PHA";
    /// Push processor status (with B and bit 5 set).
    Php = "PHP";
    /// Pull accumulator.
    Pla = "PLA";
    /// Pull processor status.
    Plp = "PLP";
    /// Rotate left through carry.
    Rol = "ROL";
    /// Rotate right through carry.
    Ror = "ROR";
    /// Return from interrupt.
    Rti = "RTI";
    /// Return from subroutine.
    Rts = "RTS";
    /// Subtract with borrow.
    Sbc = "SBC";
    /// Set carry.
    Sec = "SEC";
    /// Set decimal mode.
    Sed = "SED";
    /// Set interrupt disable.
    Sei = "SEI";
    /// Store accumulator.
    Sta = "STA";
    /// Store X.
    Stx = "STX";
    /// Store Y.
    Sty = "STY";
    /// Transfer A to X.
    Tax = "TAX";
    /// Transfer A to Y.
    Tay = "TAY";
    /// Transfer stack pointer to X.
    Tsx = "TSX";
    /// Transfer X to A.
    Txa = "TXA";
    /// Transfer X to stack pointer.
    Txs = "TXS";
    /// Transfer Y to A.
    Tya = "TYA";
    /// Undocumented: AND immediate, then LSR A.
    Alr = "ALR" | "ASR";
    /// Undocumented: AND immediate, copy N into C.
    Anc = "ANC";
    /// Undocumented, unstable: `A = (A | magic) & X & imm`.
    Ane = "ANE" | "XAA";
    /// Undocumented: AND immediate, then ROR A with odd flags.
    Arr = "ARR";
    /// Undocumented: DEC memory, then CMP.
    Dcp = "DCP" | "DCM";
    /// Undocumented: INC memory, then SBC.
    Isc = "ISC" | "ISB" | "INS";
    /// Undocumented: halts the processor until reset.
    Jam = "JAM" | "KIL" | "HLT";
    /// Undocumented: `A = X = S = memory & S`.
    Las = "LAS" | "LAR";
    /// Undocumented: LDA and LDX from the same operand.
    Lax = "LAX";
    /// Undocumented, unstable: `A = X = (A | magic) & imm`.
    Lxa = "LXA" | "OAL" | "ATX";
    /// Undocumented: ROL memory, then AND.
    Rla = "RLA";
    /// Undocumented: ROR memory, then ADC.
    Rra = "RRA";
    /// Undocumented: store `A & X`.
    Sax = "SAX";
    /// Undocumented: `X = (A & X) - imm`, flags as CMP.
    Sbx = "SBX" | "AXS";
    /// Undocumented, unstable: store `A & X & (high byte + 1)`.
    Sha = "SHA" | "AHX" | "AXA";
    /// Undocumented, unstable: store `X & (high byte + 1)`.
    Shx = "SHX" | "SXA" | "XAS";
    /// Undocumented, unstable: store `Y & (high byte + 1)`.
    Shy = "SHY" | "SYA" | "SAY";
    /// Undocumented: ASL memory, then ORA.
    Slo = "SLO" | "ASO";
    /// Undocumented: LSR memory, then EOR.
    Sre = "SRE" | "LSE";
    /// Undocumented, unstable: `S = A & X`, then store `S & (high byte + 1)`.
    Tas = "TAS" | "SHS";
}

impl Mnemonic {
    /// True for the 56 mnemonics of the MOS datasheet.
    #[must_use]
    pub fn is_documented(self) -> bool {
        self <= Mnemonic::Tya
    }

    /// True for the conditional branches (relative addressing only).
    #[must_use]
    pub const fn is_branch(self) -> bool {
        matches!(
            self,
            Mnemonic::Bcc
                | Mnemonic::Bcs
                | Mnemonic::Beq
                | Mnemonic::Bmi
                | Mnemonic::Bne
                | Mnemonic::Bpl
                | Mnemonic::Bvc
                | Mnemonic::Bvs
        )
    }
}

impl fmt::Display for Mnemonic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
