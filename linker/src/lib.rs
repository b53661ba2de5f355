//! The linker: 6502 ELF objects to Scorpion images, maps and symbol files.
//!
//! - [`link`] reads relocatable objects (`goblin`), places their sections
//!   by a [`layout`], resolves symbols (with `--just-symbols` images as a
//!   fallback), applies `R_MOS_*` relocations with lld's semantics and range
//!   checks, computes the fields and symbols the assembler left as
//!   expressions (`.scorpion.exprs`, `.scorpion.values`), builds ld65's
//!   constructor tables, checks deferred `.assert`s and records ROM hooks.
//!   Layouts are built in, TOML files or ld65 configurations. Problems are
//!   collected: one [`Error::Failed`] carries them all, each naming its
//!   source line through the objects' `.scorpion.srcmap`.
//! - [`image`]: the linked image model and its one reader, used by the
//!   emulator CLI, the virtual Scorpion and the uploader.
//! - [`output`]: the ELF executable, raw binary, Intel HEX, S-record and
//!   KIM-1 tape writers; [`Linked::map`] and [`Linked::vice_labels`].
//!
//! The library never prints; sources for diagnostics come through
//! [`SourceProvider`].

mod checks;
mod emit;
mod error;
pub mod image;
mod input;
pub mod layout;
mod link;
mod map;
mod model;
pub mod output;
mod place;
mod relocate;
mod resolve;
mod source;

pub use error::Error;
pub use image::{Image, ImageSection, ImageSymbol, LoadArea};
pub use input::Input;
pub use layout::{Layout, Target};
pub use link::{LinkOptions, SymbolFile, link, link_one};
pub use model::Linked;
pub use output::{Format, OutputFile};
pub use source::{MemorySources, NoSources, SourceProvider};
