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
        _ => None,
    }
}

/// The names `package` knows, for messages.
pub(crate) const NAMES: &str = "longbranch, generic";

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
