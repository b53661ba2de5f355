//! Verified uploads of extensions into a Scorpion over RS-232.
//!
//! Layers, bottom up:
//! - [`transport`]: the [`Transport`] trait (bytes with deadlines on the
//!   transport's own clock) and its implementations: a serial port, the
//!   in-process virtual Scorpion (emulated time), a fault-injecting wrapper
//!   for tests.
//! - [`Client`]: the command protocol over a transport, through
//!   [`romlib::protocol`]: probe (`/1X`), questions with timeouts from the
//!   baud rate, pipelined `/7R` reads.
//! - [`upload()`]: writes an [`UploadImage`] with `/9W`/`/7W` or through the
//!   RAM loader (`uploader/loader/`, frames at 19200 baud), verifies every
//!   byte with overlapping `/7R` reads, rewrites what differs, and installs
//!   hooks only after the body verified. [`RomProfile`] says where the
//!   hooks are and what may be written, from the ROM's exported names.
//!
//! - [`Expectations`]: commands and the answers they must produce, checked
//!   on the virtual Scorpion before a real robot is touched.
//!
//! Nothing here prints: progress goes through [`Progress`], failures are
//! [`Error`]s.

mod always;
mod backup;
mod beside;
mod body;
mod chain;
mod client;
mod delta;
mod error;
mod expect;
mod fingerprint;
mod held_way;
mod hooks;
mod image;
mod loader;
mod progress;
mod relisted;
mod room;
mod session;
pub mod stub;
mod summed;
mod sums;
mod table;
mod taper;
pub mod transport;
mod unchanged;
mod undo;
mod upload;
mod way_checked;

pub use backup::{
    Backup, BrokenHook, Checksum, Keep, MAGIC, MAGIC_1, NoKeep, Saved, Witness, backup,
    backup_live, backup_ranges, restore,
};
pub use client::{Client, ClientConfig, ClientStats, LiveRead, stopped_in_stub};
pub use delta::{COARSE, FINE};
pub use error::{Error, Result, addresses_text, human_duration};
pub use expect::{Checked, Expectation, Expectations, Mismatch, NOTHING, Required, answer_text};
pub use fingerprint::{RomSum, SERVICES, rom_profile_image};
pub use held_way::Disagreement;
pub use image::{
    Area, CONSERVATIVE_RX_BUFFER, REFERENCE_RX_BUFFER, ReceiveRing, RomProfile, Services,
    UploadImage,
};
pub use loader::{
    FAST_BAUD, FRAME_MAX, LoaderPlan, loader_estimate, loader_frame, loader_left_at, loader_plan,
    rom_only_estimate,
};
pub use progress::{Event, NoProgress, Phase, Progress};
pub use room::refuse_what_cannot_go_in;
pub use sums::{EXACT, fletcher16, robot_sum};
pub use table::{chain_from, chain_of, read_installed};
pub use transport::Transport;
pub use upload::{
    InstalledHook, LoaderChoice, LoaderReport, UploadOptions, UploadReport, client, upload,
    upload_keeping,
};
