//! Source lines from the images' line tables (`.scorpion.lines`, what the
//! debugger's `list` reads): which lines of which files hold code, where
//! their instructions begin, and which of those are conditional branches.
//!
//! The table maps every byte an image loads to the file and line it was
//! written at, through includes (the included file's line) and macros (the
//! macro body's line, so a macro used twice counts both uses on its
//! lines). A line holds code when its text is an instruction (a 6502
//! mnemonic after an optional label): data in a code section (`.byte`
//! tables) is not a line a test could run, unless the code around it runs
//! into it: a line of data that a branch, `JMP` or `JSR` of a code line
//! targets, or that a code line falls through into, is an instruction
//! written as bytes (the chain `JMP` of `SCORPION_CHAIN_UNKNOWN` is
//! `.byte $4C` + `.addr`), so it is a code line too. Falling through a
//! `JSR` does not count (routines that read their arguments from after
//! the call return past them), nor through a conditional branch (one
//! that always goes, `CLC` then `BCC`, is often followed by data). When
//! the source cannot be read, the bytes of executable sections count as
//! code.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use isa::{AddressingMode, Instruction, Mnemonic};

/// A source line with code.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Line {
    /// The file, as the assembler was given it.
    pub file: String,
    /// The line, from 1.
    pub line: u32,
    /// The address of each instruction the line assembled to (several
    /// for a macro body line used several times).
    pub starts: Vec<u16>,
    /// Those that are conditional branches.
    pub branches: Vec<u16>,
}

/// The code lines of some images, and which line each address is in.
#[derive(Debug, Clone, Default)]
pub struct LineTable {
    /// Every code line, by file then line.
    pub lines: Vec<Line>,
    /// The byte ranges of every line, code or not: (first, last, file,
    /// line), sorted.
    ranges: Vec<(u16, u16, usize)>,
    /// Every (file, line) the ranges point at.
    places: Vec<(String, u32)>,
    /// The byte ranges a macro made: (first, last, the place of the
    /// outermost call), sorted.
    calls: Vec<(u16, u16, usize)>,
}

/// Whether a source line's text is an instruction: a mnemonic, maybe
/// after a label.
#[must_use]
pub fn is_instruction(text: &str) -> bool {
    let code = text.split(';').next().unwrap_or("");
    let mut words = code.split_whitespace();
    let Some(mut word) = words.next() else {
        return false;
    };
    if let Some((_label, rest)) = word.split_once(':') {
        if rest.is_empty() {
            let Some(next) = words.next() else {
                return false;
            };
            word = next;
        } else {
            word = rest;
        }
    }
    Mnemonic::from_name(word).is_some()
}

impl LineTable {
    /// The lines of `images`; `read` gives a source file's text by the
    /// name the assembler was given (`None` if it cannot be read).
    #[must_use]
    pub fn new(images: &[&linker::Image], read: &dyn Fn(&str) -> Option<String>) -> LineTable {
        let mut texts: HashMap<String, Option<Vec<String>>> = HashMap::new();
        let mut code: BTreeMap<(String, u32), Line> = BTreeMap::new();
        let mut table = LineTable::default();
        let mut place_ids: HashMap<(String, u32), usize> = HashMap::new();
        // Lines of data in executable sections: (image, first, end, file, line).
        let mut data: Vec<(usize, u32, u32, (String, u32))> = Vec::new();
        for (image_index, image) in images.iter().enumerate() {
            let entries = &image.lines.entries;
            for (index, entry) in entries.iter().enumerate() {
                let Some(file) = image.lines.file_name(entry.loc) else {
                    continue;
                };
                let start = entry.offset;
                let Some(section) = image.sections.iter().find(|s| {
                    u64::from(s.run) <= u64::from(start)
                        && u64::from(start) < u64::from(s.run) + u64::from(s.size)
                }) else {
                    continue;
                };
                let section_end = section.run.saturating_add(section.size);
                let end = entries
                    .get(index + 1)
                    .map_or(section_end, |next| next.offset.min(section_end))
                    .max(start + 1);
                let (Ok(first), Ok(last)) = (u16::try_from(start), u16::try_from(end - 1)) else {
                    continue;
                };
                let key = (file.to_owned(), entry.loc.line);
                let place = *place_ids.entry(key.clone()).or_insert_with(|| {
                    table.places.push(key.clone());
                    table.places.len() - 1
                });
                table.ranges.push((first, last, place));
                if let Some(call) = image.lines.call(0, start)
                    && let Some(call_file) = image.lines.file_name(call)
                {
                    let key = (call_file.to_owned(), call.line);
                    let call_place = *place_ids.entry(key.clone()).or_insert_with(|| {
                        table.places.push(key);
                        table.places.len() - 1
                    });
                    table.calls.push((first, last, call_place));
                }
                if !section.exec {
                    continue;
                }
                let text = texts
                    .entry(file.to_owned())
                    .or_insert_with(|| read(file).map(|t| t.lines().map(str::to_owned).collect()));
                let is_code = match text {
                    Some(lines) => (entry.loc.line as usize)
                        .checked_sub(1)
                        .and_then(|line| lines.get(line))
                        .is_some_and(|t| is_instruction(t)),
                    None => true,
                };
                if !is_code {
                    data.push((image_index, start, end, key));
                    continue;
                }
                decode_into(&mut code, key, image, start, end);
            }
        }
        // Data lines the code runs into, until no more are found (one
        // such line may run into the next).
        loop {
            let entries = entry_points(&code, images);
            let (reached, rest): (Vec<_>, Vec<_>) = data
                .into_iter()
                .partition(|(_, start, _, _)| entries.contains(start));
            data = rest;
            if reached.is_empty() {
                break;
            }
            for (image_index, start, end, key) in reached {
                decode_into(&mut code, key, images[image_index], start, end);
            }
        }
        table.ranges.sort_unstable();
        table.calls.sort_unstable();
        table.lines = code.into_values().collect();
        table
    }

    /// The file and line the byte at `address` came from.
    #[must_use]
    pub fn place_of(&self, address: u16) -> Option<(&str, u32)> {
        self.find(&self.ranges, address)
    }

    /// The file and line of the outermost macro call that made the byte at
    /// `address`, when a macro made it (the user's line).
    #[must_use]
    pub fn call_of(&self, address: u16) -> Option<(&str, u32)> {
        self.find(&self.calls, address)
    }

    /// The file and line a user is shown for the byte at `address`
    /// ([`isa::objfmt::user_place`]: a built-in macro's code at the
    /// user's line that called it), as the debuggers show it; `is_users`
    /// says whether a file is one the user can open.
    #[must_use]
    pub fn user_place_of(
        &self,
        address: u16,
        is_users: &dyn Fn(&str) -> bool,
    ) -> Option<(&str, u32)> {
        let own = self.place_of(address)?;
        Some(isa::objfmt::user_place(
            own,
            self.call_of(address),
            is_users,
        ))
    }

    fn find(&self, ranges: &[(u16, u16, usize)], address: u16) -> Option<(&str, u32)> {
        let index = ranges.partition_point(|(first, _, _)| *first <= address);
        let (_, last, place) = ranges.get(index.checked_sub(1)?)?;
        if address > *last {
            return None;
        }
        let (file, line) = &self.places[*place];
        Some((file.as_str(), *line))
    }
}

/// Adds the instructions of `start..end` in `image` to the code line `key`.
fn decode_into(
    code: &mut BTreeMap<(String, u32), Line>,
    key: (String, u32),
    image: &linker::Image,
    start: u32,
    end: u32,
) {
    let line = code.entry(key.clone()).or_insert_with(|| Line {
        file: key.0,
        line: key.1,
        starts: Vec::new(),
        branches: Vec::new(),
    });
    let mut at = start;
    while at < end {
        let Some(opcode) = image.byte_at(at) else {
            break;
        };
        let Ok(address) = u16::try_from(at) else {
            break;
        };
        line.starts.push(address);
        if crate::is_branch(opcode) {
            line.branches.push(address);
        }
        at += u32::from(isa::opcode(opcode).mode.len());
    }
}

/// Where the code lines' instructions can go next: branch, `JMP` and
/// `JSR` targets, and the next instruction after one that falls through
/// (not after a `JSR` or a branch, see the module's header).
fn entry_points(code: &BTreeMap<(String, u32), Line>, images: &[&linker::Image]) -> BTreeSet<u32> {
    let byte = |address: u16| {
        images
            .iter()
            .find_map(|image| image.byte_at(u32::from(address)))
    };
    let mut entries = BTreeSet::new();
    for line in code.values() {
        for &start in &line.starts {
            if byte(start).is_none() {
                continue;
            }
            let instruction = Instruction::decode_with(start, |at| byte(at).unwrap_or(0));
            match (instruction.opcode.mnemonic, instruction.opcode.mode) {
                // A conditional branch's target only: code falls through a
                // branch into data when the branch always goes (`CLC` then
                // `BCC`), so that is no sign the data runs.
                (Mnemonic::Jmp | Mnemonic::Jsr, AddressingMode::Absolute)
                | (_, AddressingMode::Relative) => {
                    entries.extend(instruction.target().map(u32::from));
                }
                // Where these go is not in the code, or nowhere.
                (Mnemonic::Jmp | Mnemonic::Rts | Mnemonic::Rti | Mnemonic::Brk, _) => {}
                _ => {
                    entries.insert(u32::from(instruction.next_address()));
                }
            }
        }
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::is_instruction;

    #[test]
    fn instructions_are_mnemonics_after_an_optional_label() {
        assert!(is_instruction("        lda #1"));
        assert!(is_instruction("loop:   dex"));
        assert!(is_instruction(
            "@wait:  bit ADC_STATUS          ; bit 6 into V"
        ));
        assert!(is_instruction("x:inx"));
        assert!(!is_instruction("        .byte 1, 'R'"));
        assert!(!is_instruction("table:  .addr soft_reset"));
        assert!(!is_instruction("; lda #1"));
        assert!(!is_instruction("label:"));
        assert!(!is_instruction("        SCORPION_CHAIN_UNKNOWN"));
        assert!(!is_instruction("VERSION = $01"));
    }
}
