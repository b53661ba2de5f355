//! The emulator's error type.

/// Everything the emulator library can refuse. Stops of a running program
/// (a JAM, a trap, a cycle limit) are not errors: see the CPU's stop reasons.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum Error {
    /// An image loaded at `address` runs past the top of memory.
    #[error("an image of {len} bytes loaded at ${address:04X} runs past $FFFF")]
    #[diagnostic(
        code(emulator::image_too_large),
        help("{}", fit_help(*len))
    )]
    ImageTooLarge {
        /// Where the image was to be loaded.
        address: u16,
        /// Its length in bytes.
        len: usize,
    },
    /// A Scorpion ROM image that is not exactly 4 KiB.
    #[error("a Scorpion ROM is 4096 bytes ($F000-$FFFF), this one has {len}")]
    #[diagnostic(
        code(emulator::rom_size),
        help("link the ROM with the scorpion-rom layout, which fills the whole 4 KiB")
    )]
    RomSize {
        /// The image's length.
        len: usize,
    },
    /// Bytes loaded into the Scorpion's memory outside RAM.
    #[error("{len} bytes cannot be loaded there: ${address:04X} is not RAM")]
    #[diagnostic(
        code(emulator::not_ram),
        help("RAM is $0000-$0FFF on the card and $1000-$BFFF on the KIM bus, less mapped devices")
    )]
    NotRam {
        /// The first address that is not RAM.
        address: u16,
        /// The length of what was to be loaded.
        len: usize,
    },
    /// A KIM-bus device that cannot be mapped where it was asked.
    #[error("cannot map a KIM-bus device at ${start:04X}-${end:04X}: {reason}")]
    #[diagnostic(code(emulator::kim_slot))]
    KimSlot {
        /// First address asked for.
        start: u16,
        /// Last address asked for.
        end: u16,
        /// Why not.
        reason: &'static str,
    },
}

/// Where an image of `len` bytes still fits.
fn fit_help(len: usize) -> String {
    match 0x1_0000usize.checked_sub(len) {
        Some(highest) => format!("an image this long fits at ${highest:04X} or lower"),
        None => "the image is larger than the 64 KiB address space".to_string(),
    }
}
