//! The Scorpion reference ROM, its symbols, its include file, the typed host
//! protocol, and the virtual Scorpion set up with it.
//!
//! - [`ROM`], [`ROM_ELF`]: the reference ROM (6502 assembly in `rom/`),
//!   assembled and linked by our own assembler and linker when this crate
//!   is built. The ELF is the ROM profile extensions link against
//!   (`--just-symbols`) and loaders read hook addresses from.
//! - [`symbols`]: every name the ROM exports (docs/PROTOCOL.md section 4, plus
//!   `USER_*` and more services) as a Rust constant, and [`SCORPION_INC`]:
//!   the same names as an assembler include file with the hook macros. Both
//!   are generated from the one linked symbol table.
//! - [`protocol`]: every command built and every answer parsed, typed.
//! - [`sim`]: [`VirtualScorpion`], the emulated robot running a ROM, with
//!   images loaded as an upload leaves them and a host that speaks the
//!   protocol at the line's baud rate.

mod error;
pub mod installed;
pub mod protocol;
pub mod sim;
pub mod symbols;

pub use error::{Error, ScriptFault};
pub use sim::{InstalledHook, Runner, Surroundings, VirtualScorpion};

/// The reference ROM image, `$F000-$FFFF`.
pub const ROM: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/scorpion-rom.bin"));

/// The reference ROM's linked ELF (areas, symbols): its ROM profile.
pub const ROM_ELF: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/scorpion-rom.elf"));

/// `scorpion.inc`: the ROM's exported names and the hook macros, for
/// `.include "scorpion.inc"` in extensions.
pub const SCORPION_INC: &str = include_str!(concat!(env!("OUT_DIR"), "/scorpion.inc"));

/// Links one assembled object (`name` for messages) against the reference
/// ROM's symbols with the built-in target `target` (`scorpion-ext`,
/// `scorpion-os`): what a test or a tool needs to turn an extension's
/// object into an image the virtual Scorpion loads.
///
/// # Errors
/// The linker's: an unknown target, an undefined symbol, an overflow.
pub fn link_against_rom(
    name: &str,
    object: &[u8],
    target: &str,
) -> Result<linker::Image, linker::Error> {
    let rom = linker::Image::parse("scorpion-rom.elf", ROM_ELF)?;
    let target = linker::Target::builtin(target, None)?;
    let symbols = linker::SymbolFile {
        name: "scorpion-rom.elf",
        image: &rom,
    };
    Ok(linker::link_one(name, object, &target, symbols)?.image)
}
