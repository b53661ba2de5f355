//! The linker: 6502 ELF objects to Scorpion images, maps and symbol files.
//!
//! Not landed yet (issue 4): this crate has no API.
