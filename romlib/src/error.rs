//! The errors of romlib outside the typed protocol (which has its own
//! [`ProtocolError`], wrapped here).

use crate::protocol::ProtocolError;

/// What the ROM profile, the simulator set-up or a conversation with the
/// virtual Scorpion can refuse.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum Error {
    /// A command or an answer that the protocol rejects.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Protocol(#[from] ProtocolError),

    /// The emulated board refused something (an image outside RAM, a ROM
    /// of the wrong size).
    #[error(transparent)]
    #[diagnostic(transparent)]
    Emulator(#[from] emulator::Error),

    /// A ROM profile that cannot run on the virtual Scorpion.
    #[error("the ROM profile `{name}` cannot be used: {reason}")]
    #[diagnostic(
        code(romlib::rom_profile),
        help(
            "a ROM profile is the ROM's linked ELF: bytes for all of $F000-$FFFF and its exported symbols"
        )
    )]
    RomProfile {
        /// The profile's name.
        name: String,
        /// What is wrong.
        reason: String,
    },

    /// A hook that does not hold a `JMP` where the ROM's symbols say.
    #[error(
        "{hook} at ${address:04X} holds ${found:02X}, not a JMP ($4C): the hook cannot be installed"
    )]
    #[diagnostic(
        code(romlib::hook_not_jmp),
        help("reset the robot (/1R) so the ROM rebuilds its hooks, or check the ROM profile")
    )]
    HookNotJmp {
        /// The hook's name.
        hook: &'static str,
        /// Its address.
        address: u16,
        /// The byte found there.
        found: u8,
    },

    /// The robot did not finish its answer in time.
    #[error(
        "no complete answer to `{command}` within {timeout_ms} ms of robot time (got `{received}`)"
    )]
    #[diagnostic(
        code(romlib::no_answer),
        help(
            "an extension command that answers must end its answer with PUTEOL; check that its hook is installed"
        )
    )]
    NoAnswer {
        /// The command sent.
        command: String,
        /// What arrived, escaped.
        received: String,
        /// How long the host waited, in milliseconds of emulated time.
        timeout_ms: u64,
    },

    /// An image would overwrite memory an installed extension owns.
    #[error("the image's memory {new} overlaps {old}, owned by the installed extension {id:06X}")]
    #[diagnostic(
        code(romlib::overlap),
        help(
            "link the image somewhere else (another layout: --target FILE.toml), replace the installed one (`scorpion upload --replace`), or reset the robot (/1R) to start afresh"
        )
    )]
    Overlap {
        /// The new image's extent, `$0400-$0452`.
        new: String,
        /// The installed extension's extent.
        old: String,
        /// The installed extension's id.
        id: u32,
    },

    /// The hook already jumps to the handler: installing it again would
    /// make the chain jump to itself.
    #[error("{hook} already jumps to ${handler:04X}: that handler is installed already")]
    #[diagnostic(
        code(romlib::hooked_twice),
        help("an image installs once; to load it again, reset the robot (/1R) first")
    )]
    HookedTwice {
        /// The hook's name.
        hook: &'static str,
        /// The handler.
        handler: u16,
    },

    /// An image whose memory lies where the ROM keeps its own (or nowhere
    /// an extension may be).
    #[error("the image's memory {extent} is not memory an extension may use ({allowed})")]
    #[diagnostic(
        code(romlib::not_user_memory),
        help(
            "link extensions with --target scorpion-ext (or scorpion-os, or a layout inside those ranges): the rest of the RAM is the ROM's"
        )
    )]
    NotUserMemory {
        /// The extent outside.
        extent: String,
        /// The ranges an extension may use.
        allowed: String,
    },

    /// The table of installed extensions has no room for another.
    #[error("the robot's table of installed extensions is full ({capacity} entries): {reason}")]
    #[diagnostic(
        code(romlib::table_full),
        help("reset the robot (/1R) to remove every extension, or replace one")
    )]
    TableFull {
        /// Entries in the table.
        capacity: usize,
        /// What did not fit.
        reason: String,
    },

    /// The table of installed extensions holds something no loader wrote.
    #[error(transparent)]
    #[diagnostic(
        code(romlib::damaged_table),
        help("reset the robot (/1R): the table and the hooks start afresh")
    )]
    DamagedTable(#[from] crate::installed::DamagedTable),

    /// The control loop stopped running: a handler that never returns.
    #[error(
        "the robot stopped answering: its control loop did not run in {for_ms} ms of robot time; the CPU is at ${pc:04X}{place}"
    )]
    #[diagnostic(
        code(romlib::stuck),
        help(
            "a handler must end with JMP CMD_DONE (or its chain) without waiting for ever: check the loop around that address, or a card it waits for"
        )
    )]
    Stuck {
        /// Where the CPU is.
        pc: u16,
        /// ` (handler+$12)`: the nearest label, or nothing.
        place: String,
        /// Robot time watched, in milliseconds.
        for_ms: u64,
    },

    /// The emulated CPU hit a JAM opcode.
    #[error("the robot's CPU jammed at ${pc:04X} (opcode ${opcode:02X})")]
    #[diagnostic(
        code(romlib::jam),
        help("an extension jumped into data or a bad address; check its listing")
    )]
    Jam {
        /// Where.
        pc: u16,
        /// The JAM opcode.
        opcode: u8,
    },

    /// A KIM-bus card failed on its own (a card script's runtime error):
    /// the robot stops, since what it read from the card is not what the
    /// card meant.
    #[error("the card at ${base:04X} failed")]
    #[diagnostic(code(romlib::card))]
    Card {
        /// The base address of the card's window.
        base: u16,
        /// The failure, in one line.
        message: String,
        /// The failure, located in the card's script: one diagnostic,
        /// related rather than a source so that its place and snippet
        /// are shown through the callers' `wrap_err` (which keeps only a
        /// cause's text).
        #[related]
        fault: [ScriptFault; 1],
    },

    /// The script of the robot's surroundings failed.
    #[error("the surroundings failed")]
    #[diagnostic(code(romlib::surroundings))]
    Surroundings {
        /// The failure, in one line.
        message: String,
        /// The failure, located in the script: one diagnostic, related
        /// for the reason [`Error::Card`]'s is.
        #[related]
        fault: [ScriptFault; 1],
    },
}

/// A card's or the surroundings' script failure as the script's host
/// located it (file:line:col, snippet, help), shown in full as a related
/// diagnostic of [`Error::Card`] and [`Error::Surroundings`].
#[derive(Debug)]
pub struct ScriptFault(pub Box<dyn miette::Diagnostic + Send + Sync>);

impl std::fmt::Display for ScriptFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for ScriptFault {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

impl miette::Diagnostic for ScriptFault {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.0.code()
    }
    fn severity(&self) -> Option<miette::Severity> {
        self.0.severity()
    }
    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.0.help()
    }
    fn url<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.0.url()
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.0.source_code()
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        self.0.labels()
    }
    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
        self.0.related()
    }
    fn diagnostic_source(&self) -> Option<&dyn miette::Diagnostic> {
        self.0.diagnostic_source()
    }
}
