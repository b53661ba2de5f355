//! The reference ROM's exported names as Rust constants, generated at build
//! time from the linked ROM's symbol table (the same table `scorpion.inc`
//! is generated from). Each constant's documentation is the comment on the
//! ROM source line that defines it.

/// One exported name of the ROM.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Symbol {
    /// The name, as in `scorpion.inc`.
    pub name: &'static str,
    /// Its value: an address in RAM or in the ROM.
    pub value: u16,
    /// What it is, from the ROM source.
    pub doc: &'static str,
}

/// Looks a name up in [`ALL`].
#[must_use]
pub fn find(name: &str) -> Option<&'static Symbol> {
    ALL.iter().find(|symbol| symbol.name == name)
}

include!(concat!(env!("OUT_DIR"), "/symbols.rs"));
