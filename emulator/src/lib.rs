//! An exact, fast NMOS 6502 emulator.
//!
//! Not landed yet (issue 2): this crate has no API.
