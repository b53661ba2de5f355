//! ca65's macro packages (`.macpack NAME`), written here in our own words
//! to expand to what ca65's do: `longbranch` (`jeq` and its kin: a branch
//! when a backward target is near enough, else the opposite branch over a
//! `JMP`) and `generic` (`add`, `sub`, and the comparison branches). The
//! differential test holds them to ca65's bytes.

use std::fmt::Write as _;

/// The packages: name, source.
pub(crate) fn package(name: &str) -> Option<String> {
    match name {
        "longbranch" => Some(longbranch()),
        "generic" => Some(GENERIC.to_owned()),
        "cpu" => Some(cpu()),
        _ => None,
    }
}

/// The names `package` knows, for messages.
pub(crate) const NAMES: &str = "longbranch, generic, cpu";

/// ca65's instruction-set bits (`CPU_ISET_*`), which `.cpu` and the `cpu`
/// package share.
const INSTRUCTION_SETS: [(&str, i64); 9] = [
    ("NONE", 0x0001),
    ("6502", 0x0002),
    ("6502X", 0x0004),
    ("65SC02", 0x0008),
    ("65C02", 0x0010),
    ("65816", 0x0020),
    ("SWEET16", 0x0040),
    ("HUC6280", 0x0080),
    ("4510", 0x0200),
];

/// `.cpu` under `.setcpu "6502"`: the NMOS 6502's instructions.
pub(crate) const CPU_6502: i64 = 0x0002;
/// `.cpu` under `.setcpu "6502X"`: and the undocumented ones.
pub(crate) const CPU_6502X: i64 = 0x0002 | 0x0004;

/// `.macpack cpu`: `CPU_ISET_x` for each instruction set and `CPU_x` for
/// each CPU, the sets it understands, so code can test `.cpu` against
/// them.
fn cpu() -> String {
    let set = |name: &str| {
        INSTRUCTION_SETS
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(0, |(_, bit)| *bit)
    };
    let mut text = String::new();
    for (name, bit) in INSTRUCTION_SETS {
        let _ = writeln!(text, "CPU_ISET_{name} = ${bit:04X}");
    }
    let cpus: [(&str, &[&str]); 9] = [
        ("NONE", &["NONE"]),
        ("6502", &["6502"]),
        ("6502X", &["6502", "6502X"]),
        ("65SC02", &["6502", "65SC02"]),
        ("65C02", &["6502", "65SC02", "65C02"]),
        ("65816", &["6502", "65SC02", "65816"]),
        ("SWEET16", &["SWEET16"]),
        ("HUC6280", &["6502", "65SC02", "65C02", "HUC6280"]),
        ("4510", &["6502", "65SC02", "65C02", "4510"]),
    ];
    for (name, sets) in cpus {
        let mask = sets.iter().fold(0, |mask, s| mask | set(s));
        let _ = writeln!(text, "CPU_{name} = ${mask:04X}");
    }
    text
}

/// `jXX dest`: the branch `bXX` when `dest` is already defined and the
/// branch reaches back to it, otherwise the opposite branch over a `JMP`
/// (a forward target is never known yet, so it always gets the long form,
/// as in ca65).
fn longbranch() -> String {
    let pairs = [
        ("jeq", "beq", "bne"),
        ("jne", "bne", "beq"),
        ("jmi", "bmi", "bpl"),
        ("jpl", "bpl", "bmi"),
        ("jcs", "bcs", "bcc"),
        ("jcc", "bcc", "bcs"),
        ("jvs", "bvs", "bvc"),
        ("jvc", "bvc", "bvs"),
    ];
    let mut text = String::new();
    for (name, near, opposite) in pairs {
        let _ = write!(
            text,
            "\
.macro {name} dest
.if .def(dest) .and .const((*+2)-(dest)) .and ((*+2)-(dest) <= 127)
        {near} dest
.else
        {opposite} *+5
        jmp dest
.endif
.endmacro
"
        );
    }
    text
}

/// `add`/`sub` with the carry cleared or set first (one operand, or two
/// for an indexed one), `bge`/`blt`/`bgt`/`ble` after a compare, `bnz`,
/// `bze`.
const GENERIC: &str = "\
.macro add first, second
        clc
.if .paramcount = 2
        adc first, second
.else
        adc first
.endif
.endmacro
.macro sub first, second
        sec
.if .paramcount = 2
        sbc first, second
.else
        sbc first
.endif
.endmacro
.macro bge dest
        bcs dest
.endmacro
.macro blt dest
        bcc dest
.endmacro
.macro bgt dest
        beq *+4
        bcs dest
.endmacro
.macro ble dest
        beq dest
        bcc dest
.endmacro
.macro bnz dest
        bne dest
.endmacro
.macro bze dest
        beq dest
.endmacro
";
