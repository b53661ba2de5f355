//! The listing (`-l`): for each source line, its address, the bytes it
//! produced and the line itself, macro and `.repeat` expansions included.
//!
//! Format (stable, for snapshot tests), after ca65's:
//!
//! ```text
//! 001000  1  A9 05        lda #5
//! 000003r 2  8D rr rr     sta ptr
//! ```
//!
//! Six hex digits of address, `r` when it is an offset in a relocatable
//! segment, the input depth (1 = main file, more in includes and
//! expansions), up to four bytes per row (`rr` where the linker patches
//! the byte), then the source. Lines from expansions show the body line
//! with the macro's arguments in place.

use std::fmt::Write as _;

use crate::asm::Frame;
use crate::diag::Files;
use crate::lexer::LineInfo;
use crate::model::{ChunkId, Program, SegId};
use crate::output::Output;

/// Two upper-case hex digits.
fn hex_byte(byte: u8) -> [u8; 2] {
    const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
    [
        DIGITS[usize::from(byte >> 4)],
        DIGITS[usize::from(byte & 15)],
    ]
}

/// Six upper-case hex digits (a listing address).
fn push_hex6(text: &mut String, value: i64) {
    let value = (value & 0xFF_FFFF) as u32;
    for shift in [16, 8, 0] {
        let [high, low] = hex_byte((value >> shift) as u8);
        text.push(char::from(high));
        text.push(char::from(low));
    }
}

/// The depth digit, the byte cells padded to 12 columns, the source line
/// (tabs as eight spaces, no trailing blanks) and the newline. The
/// listing is written by hand: `format!` cost more than assembling.
fn push_row_tail(text: &mut String, depth: u8, cells: &[[u8; 2]], source: &str) {
    text.push(char::from(b'0' + depth.min(9)));
    text.push_str("  ");
    let mut width = 0;
    for (i, cell) in cells.iter().enumerate() {
        if i > 0 {
            text.push(' ');
            width += 1;
        }
        text.push(char::from(cell[0]));
        text.push(char::from(cell[1]));
        width += 2;
    }
    for _ in width..12 {
        text.push(' ');
    }
    text.push(' ');
    let trimmed = source.trim_end();
    if trimmed.contains('\t') {
        text.push_str(&trimmed.replace('\t', "        "));
    } else {
        text.push_str(trimmed);
    }
    // A row with no source ends at its cells, as before.
    while text.ends_with(' ') {
        text.pop();
    }
    text.push('\n');
}

/// Bytes shown for one line at most; the rest is summarised.
const MAX_BYTES: usize = 16;

#[derive(Debug, Clone)]
enum Text {
    Source { file: u32, start: u32, end: u32 },
    Expanded(String),
}

#[derive(Debug, Clone)]
struct Line {
    depth: u8,
    text: Text,
    seg: SegId,
    chunk: ChunkId,
    off: u32,
    end: Option<(SegId, ChunkId, u32)>,
}

/// Collects lines during assembly; renders after layout.
#[derive(Debug, Default)]
pub(crate) struct ListingBuilder {
    /// `.list off` turns this off.
    pub(crate) enabled: bool,
    lines: Vec<Line>,
    /// The expanded text of the next line, when it comes from an expansion.
    pub(crate) expanded: Option<String>,
    /// The last line was begun and awaits its end position.
    open: bool,
    /// Lines read while the input is this many frames deep or deeper are
    /// left out: a built-in include's, when they are not listed.
    unlisted_depth: Option<usize>,
}

fn depth(frames: &[Frame]) -> u8 {
    frames.len().clamp(1, 9) as u8
}

impl ListingBuilder {
    pub(crate) fn new() -> ListingBuilder {
        ListingBuilder {
            enabled: true,
            lines: Vec::new(),
            expanded: None,
            open: false,
            unlisted_depth: None,
        }
    }

    /// Leaves out the lines of the file just pushed as frame `depth` (the
    /// frames' count with it), and of everything it includes or expands.
    pub(crate) fn unlisted_from(&mut self, depth: usize) {
        // An unlisted file inside another is already covered.
        if self.unlisted_depth.is_none() {
            self.unlisted_depth = Some(depth);
        }
    }

    /// The input is back to `depth` frames.
    pub(crate) fn frame_ended(&mut self, depth: usize) {
        if self.unlisted_depth.is_some_and(|unlisted| depth < unlisted) {
            self.unlisted_depth = None;
        }
    }

    fn listed(&self, frames: &[Frame]) -> bool {
        self.enabled
            && self
                .unlisted_depth
                .is_none_or(|unlisted| frames.len() < unlisted)
    }

    fn text(&mut self, info: LineInfo) -> Text {
        match self.expanded.take() {
            Some(text) => Text::Expanded(text),
            None => Text::Source {
                file: info.file,
                start: info.start,
                end: info.end,
            },
        }
    }

    /// A line that produces nothing (a macro or `.repeat` body being read).
    pub(crate) fn text_line(&mut self, frames: &[Frame], info: LineInfo) {
        let text = self.text(info);
        if !self.listed(frames) {
            return;
        }
        self.lines.push(Line {
            depth: depth(frames),
            text,
            seg: 0,
            chunk: 0,
            off: 0,
            end: None,
        });
    }

    pub(crate) fn begin_line(
        &mut self,
        frames: &[Frame],
        info: LineInfo,
        prog: &Program,
        seg: SegId,
    ) {
        let text = self.text(info);
        self.open = self.listed(frames);
        if !self.open {
            return;
        }
        let chunk = prog.segs[seg as usize].cur;
        self.lines.push(Line {
            depth: depth(frames),
            text,
            seg,
            chunk,
            off: prog.chunks[chunk as usize].len,
            end: Some((seg, chunk, prog.chunks[chunk as usize].len)),
        });
    }

    pub(crate) fn end_line(&mut self, prog: &Program, seg: SegId) {
        if !std::mem::take(&mut self.open) {
            return;
        }
        let Some(line) = self.lines.last_mut() else {
            return;
        };
        if line.end.is_none() {
            return;
        }
        let chunk = prog.segs[seg as usize].cur;
        line.end = Some((seg, chunk, prog.chunks[chunk as usize].len));
    }

    /// Renders the listing after layout.
    pub(crate) fn render(
        &self,
        title: &str,
        files: &Files,
        prog: &Program,
        out: &Output,
    ) -> String {
        let mut text = String::with_capacity(self.lines.len() * 40);
        let _ = writeln!(text, "; scorpion asm listing of {title}");
        let _ = writeln!(text);
        // Relocated byte offsets per output section.
        let relocated: Vec<Vec<u32>> = out
            .sections
            .iter()
            .map(|s| {
                let mut offsets: Vec<u32> = Vec::new();
                for r in &s.relocs {
                    let width = match r.r_type {
                        isa::elf::R_MOS_ADDR16 => 2,
                        _ => 1,
                    };
                    offsets.extend(r.offset..r.offset + width);
                }
                offsets.sort_unstable();
                offsets
            })
            .collect();
        for line in &self.lines {
            let source: std::borrow::Cow<'_, str> = match &line.text {
                Text::Source { file, start, end } => {
                    let bytes = files.text(*file);
                    let start = (*start as usize).min(bytes.len());
                    let end = (*end as usize).clamp(start, bytes.len());
                    String::from_utf8_lossy(&bytes[start..end])
                }
                Text::Expanded(text) => std::borrow::Cow::Borrowed(text.as_str()),
            };
            let Some((end_seg, end_chunk, end_off)) = line.end else {
                text.push_str("        ");
                push_row_tail(&mut text, line.depth, &[], &source);
                continue;
            };
            let chunk = &prog.chunks[line.chunk as usize];
            let section = out.seg_section.get(line.seg as usize).copied().flatten();
            let start = chunk.start + line.off;
            let end = if end_seg == line.seg {
                prog.chunks[end_chunk as usize].start + end_off
            } else {
                start
            };
            if chunk.org {
                push_hex6(&mut text, chunk.abs + i64::from(line.off));
                text.push(' ');
            } else {
                push_hex6(&mut text, i64::from(start));
                text.push('r');
            }
            text.push(' ');
            // Up to MAX_BYTES cells of two characters, four to a row.
            let mut cells = [[b'?'; 2]; MAX_BYTES];
            let mut count = 0;
            if let Some(section) = section {
                let s = &out.sections[section];
                for offset in start..end.max(start) {
                    if count == MAX_BYTES {
                        break;
                    }
                    cells[count] = if relocated[section].binary_search(&offset).is_ok() {
                        *b"rr"
                    } else if s.nobits {
                        *b"xx"
                    } else {
                        s.data.get(offset as usize).map_or(*b"??", |b| hex_byte(*b))
                    };
                    count += 1;
                }
            }
            push_row_tail(&mut text, line.depth, &cells[..count.min(4)], &source);
            for from in (4..count).step_by(4) {
                text.push_str("        ");
                push_row_tail(&mut text, line.depth, &cells[from..count.min(from + 4)], "");
            }
            let total = end.saturating_sub(start) as usize;
            if total > MAX_BYTES {
                let _ = writeln!(text, "{:7} {}  ({} bytes in all)", "", line.depth, total);
            }
        }
        text
    }
}
