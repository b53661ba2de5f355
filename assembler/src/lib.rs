//! The 6502 assembler: ca65-syntax source to ELF relocatable objects.
//!
//! Not landed yet (issue 3): this crate has no API.
