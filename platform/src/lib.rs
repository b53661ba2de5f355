//! The Scorpion board's facts, in one place for every crate: the memory map
//! and the I/O page ([`map`]), the two chips' registers ([`via`], [`acia`]),
//! the clock and serial line ([`line`]), and the reference ROM's
//! `hardware.inc` made from them ([`hardware_inc`]).
//!
//! The emulator wires its chips at these addresses, the linker's built-in
//! layouts and the uploader's image checks take their bounds from here, and
//! the ROM's sources include the generated file, so the numbers cannot
//! drift apart.

pub mod acia;
mod hardware;
pub mod line;
pub mod map;
pub mod via;

pub use hardware::hardware_inc;
