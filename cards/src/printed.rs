//! What scripts print (`print`, `debug`), kept for the host to show and
//! bounded: a script that prints in a loop costs the host a fixed amount
//! of memory, and what did not fit is counted and said.

use std::sync::{Arc, Mutex};

/// Lines kept between two looks of the host ([`Printed::take`]).
pub const MAX_PRINTED_LINES: usize = 1000;

/// Bytes of text kept between two looks of the host.
pub const MAX_PRINTED_BYTES: usize = 64 * 1024;

/// The lines kept and the count of those that did not fit.
#[derive(Debug, Default)]
pub(crate) struct Output {
    lines: Vec<String>,
    bytes: usize,
    dropped: u64,
}

impl Output {
    /// Keeps `text` if it fits, counts it as dropped otherwise.
    pub(crate) fn keep(&mut self, text: &str) {
        if self.lines.len() < MAX_PRINTED_LINES && self.bytes + text.len() <= MAX_PRINTED_BYTES {
            self.bytes += text.len();
            self.lines.push(text.to_owned());
        } else {
            self.dropped += 1;
        }
    }
}

/// What a script prints, kept for the host to show: a handle that stays
/// valid after the card is mapped into the board.
#[derive(Debug, Clone, Default)]
pub struct Printed(pub(crate) Arc<Mutex<Output>>);

impl Printed {
    /// The lines printed since the last call. Past [`MAX_PRINTED_LINES`]
    /// lines or [`MAX_PRINTED_BYTES`] bytes, lines are dropped; the last
    /// line then says how many.
    #[must_use]
    pub fn take(&self) -> Vec<String> {
        let Ok(mut output) = self.0.lock() else {
            return Vec::new();
        };
        let Output {
            mut lines, dropped, ..
        } = std::mem::take(&mut *output);
        if dropped > 0 {
            lines.push(format!(
                "({dropped} more lines dropped: a script's output is kept up to {MAX_PRINTED_LINES} lines and {MAX_PRINTED_BYTES} bytes between looks)"
            ));
        }
        lines
    }

    /// Keeps `text` as the script printed it.
    pub(crate) fn keep(&self, text: &str) {
        if let Ok(mut output) = self.0.lock() {
            output.keep(text);
        }
    }
}
