//! Where to stop: breakpoints and watchpoints.

/// A breakpoint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Breakpoint {
    /// Before the instruction at this address.
    At(u16),
    /// When the ROM has a whole command in its buffer and starts looking
    /// for its handler (its `dispatch`, or the unknown-command hook for a
    /// ROM profile without that label): `/3A` is count 3, letter `A`.
    Command {
        /// The command's count digit, 1 to 9.
        count: u8,
        /// Its letter.
        letter: u8,
    },
    /// When the ROM jumps through `HOOK_UNKNOWN` (any command it does not
    /// know, on its way to the extensions).
    UnknownHook,
}

impl std::fmt::Display for Breakpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Breakpoint::At(address) => write!(f, "${address:04X}"),
            Breakpoint::Command { count, letter } => {
                write!(f, "command /{count}{}", char::from(*letter))
            }
            Breakpoint::UnknownHook => f.write_str("the unknown-command hook"),
        }
    }
}

impl Breakpoint {
    /// `/3A` as a command breakpoint.
    #[must_use]
    pub fn command(text: &str) -> Option<Breakpoint> {
        let bytes = text.strip_prefix('/')?.as_bytes();
        match bytes {
            [count @ b'1'..=b'9', letter] if letter.is_ascii_alphabetic() => {
                Some(Breakpoint::Command {
                    count: count - b'0',
                    letter: letter.to_ascii_uppercase(),
                })
            }
            _ => None,
        }
    }
}

/// The accesses a watchpoint stops at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WatchKind {
    /// Reads.
    Read,
    /// Writes.
    Write,
    /// Reads and writes.
    Access,
}

impl WatchKind {
    /// Whether an access (a write if `write`) is one of these.
    #[must_use]
    pub fn covers(self, write: bool) -> bool {
        match self {
            WatchKind::Read => !write,
            WatchKind::Write => write,
            WatchKind::Access => true,
        }
    }
}

/// A watchpoint: accesses of `start..=end`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Watch {
    /// First address watched.
    pub start: u16,
    /// Last address watched.
    pub end: u16,
    /// Which accesses.
    pub kind: WatchKind,
}

impl Watch {
    /// Whether an access of `address` (a write if `write`) hits this.
    #[must_use]
    pub fn hits(&self, address: u16, write: bool) -> bool {
        (self.start..=self.end).contains(&address) && self.kind.covers(write)
    }
}
