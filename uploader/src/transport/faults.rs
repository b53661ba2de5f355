//! A fault-injecting wrapper around any transport, for tests: bytes dropped,
//! corrupted or duplicated at a rate from a seed, a reset sent into the
//! middle of the stream, a line that goes dead for a while or for good.
//!
//! Faults are decided by a seeded generator, so a failing case replays.

use std::time::Duration;

use super::Transport;
use crate::Result;

/// What to inject. Rates are per byte, in each direction that is enabled.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultConfig {
    /// Seed of the fault generator.
    pub seed: u64,
    /// Probability that a byte is lost.
    pub drop_rate: f64,
    /// Probability that a byte is replaced by a different random byte.
    pub corrupt_rate: f64,
    /// Probability that a byte arrives twice.
    pub duplicate_rate: f64,
    /// Apply the rates to host-to-robot bytes.
    pub to_robot: bool,
    /// Apply the rates to robot-to-host bytes.
    pub to_host: bool,
    /// Send `/1R` into the host's stream at the first command boundary
    /// (before a `/`) after this many host bytes: a robot that resets in
    /// the middle. At a boundary, so that it is obeyed: inside a loader
    /// frame it would only be data.
    pub reset_after: Option<usize>,
    /// After this many host bytes, the line goes dead: nothing passes either
    /// way for [`FaultConfig::stall_for`] (on the transport's clock).
    pub stall_after: Option<usize>,
    /// How long a stall lasts; `None` is for good.
    pub stall_for: Option<Duration>,
}

impl FaultConfig {
    /// No faults.
    #[must_use]
    pub fn none(seed: u64) -> Self {
        FaultConfig {
            seed,
            drop_rate: 0.0,
            corrupt_rate: 0.0,
            duplicate_rate: 0.0,
            to_robot: true,
            to_host: true,
            reset_after: None,
            stall_after: None,
            stall_for: None,
        }
    }

    /// Drops, corrupts and duplicates each at `rate`, both ways.
    #[must_use]
    pub fn noise(seed: u64, drop: f64, corrupt: f64, duplicate: f64) -> Self {
        FaultConfig {
            drop_rate: drop,
            corrupt_rate: corrupt,
            duplicate_rate: duplicate,
            ..FaultConfig::none(seed)
        }
    }
}

/// What the wrapper did, for test assertions.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FaultStats {
    /// Bytes dropped.
    pub dropped: usize,
    /// Bytes corrupted.
    pub corrupted: usize,
    /// Bytes duplicated.
    pub duplicated: usize,
    /// Resets injected.
    pub resets: usize,
    /// Bytes lost to a stall.
    pub stalled: usize,
}

/// Wraps a transport and damages the bytes that cross it.
#[derive(Debug)]
pub struct FaultyTransport<T> {
    inner: T,
    config: FaultConfig,
    state: u64,
    sent: usize,
    stall_started: Option<Duration>,
    stats: FaultStats,
}

impl<T: Transport> FaultyTransport<T> {
    /// Wraps `inner`.
    pub fn new(inner: T, config: FaultConfig) -> Self {
        FaultyTransport {
            inner,
            state: config.seed ^ 0x9E37_79B9_7F4A_7C15,
            config,
            sent: 0,
            stall_started: None,
            stats: FaultStats::default(),
        }
    }

    /// What was injected so far.
    #[must_use]
    pub fn stats(&self) -> FaultStats {
        self.stats
    }

    /// The wrapped transport.
    pub fn inner_mut(&mut self) -> &mut T {
        &mut self.inner
    }

    /// Unwraps.
    pub fn into_inner(self) -> T {
        self.inner
    }

    /// splitmix64: small, seedable, good enough for fault decisions.
    fn next(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn chance(&mut self, rate: f64) -> bool {
        rate > 0.0 && (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= rate
    }

    fn damage(&mut self, bytes: &[u8], enabled: bool) -> Vec<u8> {
        if !enabled {
            return bytes.to_vec();
        }
        let mut out = Vec::with_capacity(bytes.len() + 4);
        for &byte in bytes {
            if self.chance(self.config.drop_rate) {
                self.stats.dropped += 1;
                continue;
            }
            let byte = if self.chance(self.config.corrupt_rate) {
                self.stats.corrupted += 1;
                byte ^ ((self.next() % 255) as u8 + 1)
            } else {
                byte
            };
            out.push(byte);
            if self.chance(self.config.duplicate_rate) {
                self.stats.duplicated += 1;
                out.push(byte);
            }
        }
        out
    }

    /// Whether the line is dead now; starts the stall when its byte count
    /// is reached.
    fn stalled(&mut self) -> bool {
        let Some(after) = self.config.stall_after else {
            return false;
        };
        if self.sent < after {
            return false;
        }
        let now = self.inner.now();
        let started = *self.stall_started.get_or_insert(now);
        match self.config.stall_for {
            None => true,
            Some(length) => now < started + length,
        }
    }
}

impl<T: Transport> Transport for FaultyTransport<T> {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        let mut bytes = bytes.to_vec();
        if let Some(at) = self.config.reset_after
            && self.stats.resets == 0
            && at < self.sent + bytes.len()
        {
            let from = at.saturating_sub(self.sent);
            if let Some(slash) = bytes[from..].iter().position(|&b| b == b'/') {
                bytes.splice(from + slash..from + slash, *b"/1R");
                self.stats.resets += 1;
            }
        }
        self.sent += bytes.len();
        if self.stalled() {
            self.stats.stalled += bytes.len();
            return Ok(());
        }
        let damaged = self.damage(&bytes, self.config.to_robot);
        self.inner.send(&damaged)
    }

    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        let mut raw = Vec::new();
        self.inner.receive(&mut raw, timeout)?;
        if self.stalled() {
            self.stats.stalled += raw.len();
            return Ok(0);
        }
        let damaged = self.damage(&raw, self.config.to_host);
        into.extend_from_slice(&damaged);
        Ok(damaged.len())
    }

    fn baud(&self) -> u32 {
        self.inner.baud()
    }

    fn set_baud(&mut self, baud: u32) -> Result<()> {
        self.inner.set_baud(baud)
    }

    fn now(&self) -> Duration {
        self.inner.now()
    }

    fn clear_input(&mut self) -> Result<()> {
        self.inner.clear_input()
    }

    fn name(&self) -> String {
        format!("{} (with injected faults)", self.inner.name())
    }
}
