//! The size limits, one per kind of file, each with the reason it is that
//! size.

/// The most a kind of file may hold, and its name in messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    bytes: u64,
    what: &'static str,
}

impl Limit {
    /// A limit of `bytes` for files called `what` ("a text file").
    #[must_use]
    pub const fn new(bytes: u64, what: &'static str) -> Limit {
        Limit { bytes, what }
    }

    /// The limit in bytes.
    #[must_use]
    pub const fn bytes(self) -> u64 {
        self.bytes
    }

    /// What the files under this limit are called.
    #[must_use]
    pub const fn what(self) -> &'static str {
        self.what
    }
}

/// Text a user writes: sources and includes, scripts, transcripts,
/// `.calls`, layouts, ld65 configurations, `Scorpion.toml`. A 6502 fills
/// its 64 KiB with a few hundred KiB of source; 16 MiB is far beyond any
/// real program and still cheap to hold.
pub const TEXT: Limit = Limit::new(16 << 20, "a text file");

/// What the assembler reads: a source, its `.include`s and its `.incbin`
/// data, through one reader that cannot tell them apart; as [`TEXT`].
pub const SOURCE: Limit = Limit::new(16 << 20, "a source or .incbin file");

/// Objects, linked images and ROM profiles (ELF), and `.incbin` data: the
/// program's bytes are at most 64 KiB, but symbols, relocations, source
/// maps and a slice taken out of a larger file make room for more.
pub const BINARY: Limit = Limit::new(16 << 20, "an object or image");

/// A raw image loaded byte for byte into the 6502's address space, which
/// is 64 KiB.
pub const RAW_IMAGE: Limit = Limit::new(1 << 16, "a raw 6502 image");

/// A backup of a robot (`scorpion backup`, an upload's undo file): its
/// memory records cover at most the 64 KiB address space, each with a
/// five-byte header; 1 MiB leaves room for any record layout and still
/// refuses `/dev/zero` at once.
pub const BACKUP: Limit = Limit::new(1 << 20, "a backup file");

/// `bytes` as people read sizes: `16 MiB`, `64 KiB`, `123 bytes`.
pub(crate) fn bytes_text(bytes: u64) -> String {
    const KIB: u64 = 1 << 10;
    const MIB: u64 = 1 << 20;
    const GIB: u64 = 1 << 30;
    match bytes {
        b if b >= GIB && b % GIB == 0 => format!("{} GiB", b / GIB),
        b if b >= MIB && b % MIB == 0 => format!("{} MiB", b / MIB),
        b if b >= KIB && b % KIB == 0 => format!("{} KiB", b / KIB),
        1 => "1 byte".to_owned(),
        b => format!("{b} bytes"),
    }
}
