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

/// When a breakpoint's hits stop the robot, counted over the times it is
/// reached with its condition holding (as the DAP's `hitCondition`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HitCondition {
    /// From the Nth hit on: `3`, `>= 3`.
    AtLeast(u64),
    /// At the Nth hit only: `== 3`.
    Exactly(u64),
    /// Every Nth hit: `% 3`.
    Every(u64),
}

/// A hit condition that does not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, miette::Diagnostic)]
#[error("`{text}`: {reason}")]
#[diagnostic(
    code(debugger::hits),
    help(
        "a hit count is N (from the Nth hit on), >= N, == N or % N (every Nth), N from 1 to 18446744073709551615"
    )
)]
pub struct HitsError {
    /// As given.
    pub text: String,
    /// Why it does not read.
    pub reason: String,
}

impl HitCondition {
    /// Reads `3`, `>= 3`, `== 3` or `% 3`.
    ///
    /// # Errors
    /// [`HitsError`]: not one of those, a count of 0, or one beyond 64
    /// bits.
    pub fn parse(text: &str) -> Result<HitCondition, HitsError> {
        let bad = |reason: &str| HitsError {
            text: text.to_owned(),
            reason: reason.to_owned(),
        };
        let trimmed = text.trim();
        let (make, digits): (fn(u64) -> HitCondition, &str) =
            if let Some(rest) = trimmed.strip_prefix(">=") {
                (HitCondition::AtLeast, rest)
            } else if let Some(rest) = trimmed.strip_prefix("==") {
                (HitCondition::Exactly, rest)
            } else if let Some(rest) = trimmed.strip_prefix('%') {
                (HitCondition::Every, rest)
            } else {
                (HitCondition::AtLeast, trimmed)
            };
        let digits = digits.trim();
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad("expected a count: N, >= N, == N or % N"));
        }
        let n: u64 = digits
            .parse()
            .map_err(|_| bad("the count is beyond 18446744073709551615 (64 bits)"))?;
        if n == 0 {
            return Err(bad("the count is at least 1"));
        }
        Ok(make(n))
    }

    /// Whether the `hit`th hit (from 1) stops.
    #[must_use]
    pub fn stops(self, hit: u64) -> bool {
        match self {
            HitCondition::AtLeast(n) => hit >= n,
            HitCondition::Exactly(n) => hit == n,
            HitCondition::Every(n) => hit % n == 0,
        }
    }
}

impl std::fmt::Display for HitCondition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            HitCondition::AtLeast(n) => write!(f, ">= {n}"),
            HitCondition::Exactly(n) => write!(f, "== {n}"),
            HitCondition::Every(n) => write!(f, "% {n}"),
        }
    }
}

/// What a breakpoint asks before it stops, beyond its place: a condition
/// over registers, memory and symbols, a hit count, and a message to log
/// instead of stopping. Asked only where the breakpoint's PC bit is set.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PointOptions {
    /// Stops only when this holds.
    pub condition: Option<crate::expr::Expr>,
    /// Stops only at these hits (counted where the condition holds).
    pub hits: Option<HitCondition>,
    /// A log point: logs this and goes on, never stops.
    pub log: Option<crate::expr::Template>,
}

impl PointOptions {
    /// Whether a hit must be counted (or logged) as the robot runs: such a
    /// point keeps an idle loop from being skipped, whose laps it counts.
    #[must_use]
    pub fn counts(&self) -> bool {
        self.hits.is_some() || self.log.is_some()
    }

    /// `if A == 1 hits >= 3 log "..."`, as the monitor reads it back.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut text = String::new();
        if let Some(condition) = &self.condition {
            text.push_str(&format!(" if {condition}"));
        }
        if let Some(hits) = &self.hits {
            text.push_str(&format!(" hits {hits}"));
        }
        if let Some(log) = &self.log {
            text.push_str(&format!(" log {}", log.text()));
        }
        text
    }
}
