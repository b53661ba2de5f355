//! The Scorpion reference ROM, its symbols and the typed host protocol.
//!
//! Not landed yet (issue 5): this crate has no API.

pub mod protocol;
