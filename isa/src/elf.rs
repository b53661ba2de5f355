//! The 6502 ELF numbering, as llvm-mos defines it (`llvm/BinaryFormat/ELF.h`
//! and `ELFRelocs/MOS.def` in llvm-mos/llvm-mos), so that our objects link
//! with theirs and their tools read ours. Neither `object` nor `goblin`
//! knows these values.

/// `e_machine` for the MOS 6502 family: 6502 (`0x1966`).
pub const EM_MOS: u16 = 6502;

/// `e_flags` bit: the plain NMOS 6502 instruction set.
pub const EF_MOS_ARCH_6502: u32 = 0x0000_0001;
/// `e_flags` bit: the object uses decimal mode (BCD).
pub const EF_MOS_ARCH_6502_BCD: u32 = 0x0000_0002;
/// `e_flags` bit: the object uses the undocumented NMOS opcodes.
pub const EF_MOS_ARCH_6502X: u32 = 0x0000_0004;
/// `e_flags` bit: 65C02 instructions (rejected by our NMOS tools).
pub const EF_MOS_ARCH_65C02: u32 = 0x0000_0008;
/// `e_flags` bit: Rockwell R65C02 instructions (rejected).
pub const EF_MOS_ARCH_R65C02: u32 = 0x0000_0010;
/// `e_flags` bit: WDC W65C02 instructions (rejected).
pub const EF_MOS_ARCH_W65C02: u32 = 0x0000_0020;
/// `e_flags` bit: 65816 instructions (rejected).
pub const EF_MOS_ARCH_W65816: u32 = 0x0000_0100;
/// The `e_flags` bits an NMOS 6502 can run: anything else is another CPU.
pub const EF_MOS_NMOS_COMPATIBLE: u32 = EF_MOS_ARCH_6502 | EF_MOS_ARCH_6502_BCD | EF_MOS_ARCH_6502X;

/// `sh_flags` bit: the section lives in page zero; references to it take
/// 8-bit (`R_MOS_ADDR8`) relocations.
pub const SHF_MOS_ZEROPAGE: u32 = 0x1000_0000;
/// `st_other` bit: an undefined symbol that is known to be in page zero
/// (`.importzp`).
pub const STO_MOS_ZEROPAGE: u8 = 0x20;

/// No relocation.
pub const R_MOS_NONE: u32 = 0;
/// An 8-bit immediate value (`LDA #sym` where `sym` is a small constant);
/// the value must fit in 8 bits.
pub const R_MOS_IMM8: u32 = 1;
/// An 8-bit zero-page address; the value must be `$00`–`$FF`.
pub const R_MOS_ADDR8: u32 = 2;
/// A 16-bit little-endian address.
pub const R_MOS_ADDR16: u32 = 3;
/// The low byte of a 16-bit address (`#<sym`, `.lobyte`).
pub const R_MOS_ADDR16_LO: u32 = 4;
/// The high byte of a 16-bit address (`#>sym`, `.hibyte`).
pub const R_MOS_ADDR16_HI: u32 = 5;
/// A branch displacement: `S + A - P - 1` where P is the operand byte's
/// address; must fit in a signed byte.
pub const R_MOS_PCREL_8: u32 = 6;
/// A 24-bit address.
pub const R_MOS_ADDR24: u32 = 7;
/// The bank byte (bits 16–23) of a 24-bit address (`^sym`, `.bankbyte`).
pub const R_MOS_ADDR24_BANK: u32 = 8;
/// Segment-relative 24-bit address (65816; not produced by our tools).
pub const R_MOS_ADDR24_SEGMENT: u32 = 9;
/// Low byte of a segment-relative address (65816; not produced).
pub const R_MOS_ADDR24_SEGMENT_LO: u32 = 10;
/// High byte of a segment-relative address (65816; not produced).
pub const R_MOS_ADDR24_SEGMENT_HI: u32 = 11;
/// A 16-bit PC-relative displacement (65816 `BRL`; not produced).
pub const R_MOS_PCREL_16: u32 = 12;
/// A 32-bit data word (DWARF).
pub const R_MOS_FK_DATA_4: u32 = 13;
/// A 64-bit data word (DWARF).
pub const R_MOS_FK_DATA_8: u32 = 14;
/// An address as decimal ASCII (not produced).
pub const R_MOS_ADDR_ASCIZ: u32 = 15;
/// A 16-bit immediate (65816; not produced).
pub const R_MOS_IMM16: u32 = 16;
/// A 13-bit address (SPC700; not produced).
pub const R_MOS_ADDR13: u32 = 17;

/// The spec name of a relocation type (`"R_MOS_ADDR16_LO"`), for messages.
#[must_use]
pub fn relocation_name(r_type: u32) -> Option<&'static str> {
    Some(match r_type {
        R_MOS_NONE => "R_MOS_NONE",
        R_MOS_IMM8 => "R_MOS_IMM8",
        R_MOS_ADDR8 => "R_MOS_ADDR8",
        R_MOS_ADDR16 => "R_MOS_ADDR16",
        R_MOS_ADDR16_LO => "R_MOS_ADDR16_LO",
        R_MOS_ADDR16_HI => "R_MOS_ADDR16_HI",
        R_MOS_PCREL_8 => "R_MOS_PCREL_8",
        R_MOS_ADDR24 => "R_MOS_ADDR24",
        R_MOS_ADDR24_BANK => "R_MOS_ADDR24_BANK",
        R_MOS_ADDR24_SEGMENT => "R_MOS_ADDR24_SEGMENT",
        R_MOS_ADDR24_SEGMENT_LO => "R_MOS_ADDR24_SEGMENT_LO",
        R_MOS_ADDR24_SEGMENT_HI => "R_MOS_ADDR24_SEGMENT_HI",
        R_MOS_PCREL_16 => "R_MOS_PCREL_16",
        R_MOS_FK_DATA_4 => "R_MOS_FK_DATA_4",
        R_MOS_FK_DATA_8 => "R_MOS_FK_DATA_8",
        R_MOS_ADDR_ASCIZ => "R_MOS_ADDR_ASCIZ",
        R_MOS_IMM16 => "R_MOS_IMM16",
        R_MOS_ADDR13 => "R_MOS_ADDR13",
        _ => return None,
    })
}
