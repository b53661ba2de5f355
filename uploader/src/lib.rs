//! Verified uploads of extensions into a Scorpion over RS-232.
//!
//! Not landed yet (issue 6): this crate has no API.
