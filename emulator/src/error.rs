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
        help("load it lower, or cut it to {} bytes", 0x1_0000 - usize::from(*address))
    )]
    ImageTooLarge {
        /// Where the image was to be loaded.
        address: u16,
        /// Its length in bytes.
        len: usize,
    },
}
