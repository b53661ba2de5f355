//! `.scorpion.srcmap`: where each piece of a section came from.
//!
//! Layout (version 1): magic `SCSM`, version, then
//! - files: count, then each path as a length-prefixed UTF-8 string;
//! - entries: count, then `section: u32, offset: u32, file: u32, line: u32,
//!   column: u32`, sorted by (section, offset). An entry covers the bytes from
//!   its offset up to the next entry's offset in the same section;
//! - symbols: count, then `symbol: u32, file: u32, line: u32, column: u32`
//!   (symbol = index in `.symtab`);
//! - version 2 adds expansions: count, then `symbol: u32, file: u32, line:
//!   u32, column: u32`, the outermost macro call that defined the symbol
//!   (the user's line, where the definition's own place is in the macro's
//!   body). Version 1 maps decode with none.
//! - version 3 adds calls: count, then entries as above (`section, offset,
//!   file, line, column`), one for each entry a macro made, at the same
//!   (section, offset), giving the outermost macro call (the user's line)
//!   those bytes came from. Older maps decode with none.
//!
//! Which of the two places a user is shown is decided once, by
//! [`user_place`]: the debuggers' stops, frames and listings, the
//! profile's line report and the coverage all call it.
//!
//! `section` is an ELF section header index. Lines and columns count from 1.

use super::SRCMAP_SECTION;
use super::codec::{FormatError, Reader, Writer};

const MAGIC: &[u8; 4] = b"SCSM";
const VERSION: u8 = 3;

/// A place in a source file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SourceLoc {
    /// Index into [`SrcMap::files`].
    pub file: u32,
    /// Line, from 1.
    pub line: u32,
    /// Column (in characters), from 1.
    pub column: u32,
}

/// The source of the bytes of a section from `offset` on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SrcMapEntry {
    /// ELF section header index.
    pub section: u32,
    /// Byte offset in the section.
    pub offset: u32,
    /// Where those bytes were written.
    pub loc: SourceLoc,
}

/// Where a symbol was defined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SymbolLoc {
    /// Index in `.symtab`.
    pub symbol: u32,
    /// Where it was defined.
    pub loc: SourceLoc,
    /// The outermost macro call that expanded to the definition, when a
    /// macro defined it: `loc` is then in the macro's body, and this is
    /// the user's line.
    pub expanded_at: Option<SourceLoc>,
}

/// The decoded `.scorpion.srcmap` section.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SrcMap {
    /// Source file paths, as given to the assembler.
    pub files: Vec<String>,
    /// Byte ranges of sections, sorted by (section, offset).
    pub entries: Vec<SrcMapEntry>,
    /// Symbol definitions.
    pub symbols: Vec<SymbolLoc>,
    /// For the entries a macro made: the same (section, offset), and the
    /// outermost macro call as the place (the user's line). Sorted.
    pub calls: Vec<SrcMapEntry>,
}

impl SrcMap {
    /// Serialises the map (entries are sorted first).
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let entries = sorted(&self.entries);
        let calls = sorted(&self.calls);
        let mut out = Writer::header(MAGIC, VERSION);
        let strings: usize = self.files.iter().map(|f| 4 + f.len()).sum();
        out.bytes
            .reserve(16 + strings + 20 * (entries.len() + calls.len()) + 16 * self.symbols.len());
        out.len32(self.files.len());
        for file in &self.files {
            out.string(file);
        }
        write_entries(&mut out, &entries);
        out.len32(self.symbols.len());
        for symbol in &self.symbols {
            out.u32(symbol.symbol);
            write_loc(&mut out, symbol.loc);
        }
        let expanded: Vec<(u32, SourceLoc)> = self
            .symbols
            .iter()
            .filter_map(|s| Some((s.symbol, s.expanded_at?)))
            .collect();
        out.len32(expanded.len());
        for (symbol, loc) in expanded {
            out.u32(symbol);
            write_loc(&mut out, loc);
        }
        write_entries(&mut out, &calls);
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not a version-1 source map, or an
    /// entry names a file that is not in the table.
    pub fn decode(bytes: &[u8]) -> Result<SrcMap, FormatError> {
        let mut input = Reader::new(SRCMAP_SECTION, bytes);
        let version = input.header_versions(MAGIC, 1..=VERSION)?;
        let file_count = input.count(4)?;
        let mut files = Vec::with_capacity(file_count);
        for _ in 0..file_count {
            files.push(input.string()?);
        }
        let entries = read_entries(&mut input, files.len())?;
        let symbol_count = input.count(16)?;
        let mut symbols = Vec::with_capacity(symbol_count);
        for _ in 0..symbol_count {
            let symbol = input.u32()?;
            let loc = read_loc(&mut input, files.len())?;
            symbols.push(SymbolLoc {
                symbol,
                loc,
                expanded_at: None,
            });
        }
        if version >= 2 {
            let by_symbol: std::collections::HashMap<u32, usize> = symbols
                .iter()
                .enumerate()
                .map(|(index, s)| (s.symbol, index))
                .collect();
            for _ in 0..input.count(16)? {
                let symbol = input.u32()?;
                let loc = read_loc(&mut input, files.len())?;
                let Some(&index) = by_symbol.get(&symbol) else {
                    return Err(input.error(format!(
                        "an expansion names symbol {symbol}, which has no place"
                    )));
                };
                symbols[index].expanded_at = Some(loc);
            }
        }
        let calls = if version >= 3 {
            read_entries(&mut input, files.len())?
        } else {
            Vec::new()
        };
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the last table"));
        }
        Ok(SrcMap {
            files,
            entries,
            symbols,
            calls,
        })
    }

    /// The source of the byte at `offset` in section `section`: the entry
    /// with the greatest offset not above it.
    #[must_use]
    pub fn lookup(&self, section: u32, offset: u32) -> Option<SourceLoc> {
        let index = self
            .entries
            .partition_point(|entry| (entry.section, entry.offset) <= (section, offset));
        let entry = self.entries.get(index.checked_sub(1)?)?;
        (entry.section == section).then_some(entry.loc)
    }

    /// The outermost macro call that made the byte at `offset` in
    /// `section`, when a macro made it: the user's line.
    #[must_use]
    pub fn call(&self, section: u32, offset: u32) -> Option<SourceLoc> {
        let index = self
            .entries
            .partition_point(|entry| (entry.section, entry.offset) <= (section, offset));
        let entry = self.entries.get(index.checked_sub(1)?)?;
        if entry.section != section {
            return None;
        }
        let key = (entry.section, entry.offset);
        let at = self
            .calls
            .binary_search_by(|call| (call.section, call.offset).cmp(&key))
            .ok()?;
        Some(self.calls[at].loc)
    }

    /// Where symbol `symbol` (a `.symtab` index) was defined.
    #[must_use]
    pub fn symbol(&self, symbol: u32) -> Option<SourceLoc> {
        self.symbol_entry(symbol).map(|entry| entry.loc)
    }

    /// The whole record of symbol `symbol`: its place and, when a macro
    /// defined it, the macro call that did.
    #[must_use]
    pub fn symbol_entry(&self, symbol: u32) -> Option<&SymbolLoc> {
        self.symbols.iter().find(|entry| entry.symbol == symbol)
    }

    /// The path of a location's file.
    #[must_use]
    pub fn file_name(&self, loc: SourceLoc) -> Option<&str> {
        self.files.get(loc.file as usize).map(String::as_str)
    }
}

/// The place a user is shown for bytes whose own place (file, line) is
/// `own`, made by a macro called at `call` when a macro made them;
/// `is_users` says whether a file is one the user can open (their own
/// sources, not a built-in include such as `scorpion.inc`).
///
/// The rule, the same in every view: code a macro from a file that is not
/// the user's made (`SCORPION_CHAIN_UNKNOWN`'s `JMP`) is shown at the
/// user's line that called the macro; everything else at its own line,
/// so a macro the user defined shows its own lines inside it, and code
/// of an include of their own shows the include's line.
#[must_use]
pub fn user_place<'a>(
    own: (&'a str, u32),
    call: Option<(&'a str, u32)>,
    is_users: &dyn Fn(&str) -> bool,
) -> (&'a str, u32) {
    match call {
        Some(call) if !is_users(own.0) && is_users(call.0) => call,
        _ => own,
    }
}

/// `list` sorted: itself when it already is, as it usually arrives (a
/// large program's map runs to megabytes: no copy then).
fn sorted(list: &[SrcMapEntry]) -> std::borrow::Cow<'_, [SrcMapEntry]> {
    if list.is_sorted() {
        std::borrow::Cow::Borrowed(list)
    } else {
        let mut copy = list.to_vec();
        copy.sort_unstable();
        std::borrow::Cow::Owned(copy)
    }
}

/// A count, then each entry: `section, offset, file, line, column`.
fn write_entries(out: &mut Writer, list: &[SrcMapEntry]) {
    out.len32(list.len());
    for entry in list {
        out.u32(entry.section);
        out.u32(entry.offset);
        write_loc(out, entry.loc);
    }
}

/// What [`write_entries`] wrote, sorted (lookups binary-search; a foreign
/// producer may not have sorted).
fn read_entries(
    input: &mut Reader<'_>,
    file_count: usize,
) -> Result<Vec<SrcMapEntry>, FormatError> {
    let count = input.count(20)?;
    let mut entries = Vec::with_capacity(count);
    for _ in 0..count {
        let section = input.u32()?;
        let offset = input.u32()?;
        let loc = read_loc(input, file_count)?;
        entries.push(SrcMapEntry {
            section,
            offset,
            loc,
        });
    }
    entries.sort_unstable();
    Ok(entries)
}

fn write_loc(out: &mut Writer, loc: SourceLoc) {
    out.u32(loc.file);
    out.u32(loc.line);
    out.u32(loc.column);
}

fn read_loc(input: &mut Reader<'_>, file_count: usize) -> Result<SourceLoc, FormatError> {
    let file = input.u32()?;
    if file as usize >= file_count {
        return Err(input.error(format!(
            "file index {file} is outside the table of {file_count} files"
        )));
    }
    Ok(SourceLoc {
        file,
        line: input.u32()?,
        column: input.u32()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> SrcMap {
        let loc = |line| SourceLoc {
            file: 0,
            line,
            column: 5,
        };
        SrcMap {
            files: vec!["main.s".into()],
            entries: vec![
                SrcMapEntry {
                    section: 2,
                    offset: 3,
                    loc: loc(11),
                },
                SrcMapEntry {
                    section: 2,
                    offset: 0,
                    loc: loc(10),
                },
                SrcMapEntry {
                    section: 4,
                    offset: 0,
                    loc: loc(20),
                },
            ],
            symbols: vec![
                SymbolLoc {
                    symbol: 7,
                    loc: loc(9),
                    expanded_at: None,
                },
                SymbolLoc {
                    symbol: 9,
                    loc: loc(30),
                    expanded_at: Some(loc(40)),
                },
            ],
            calls: vec![SrcMapEntry {
                section: 2,
                offset: 3,
                loc: loc(50),
            }],
        }
    }

    #[test]
    fn round_trips_and_looks_up() {
        let map = SrcMap::decode(&sample().encode()).unwrap();
        assert_eq!(map.lookup(2, 0).unwrap().line, 10);
        assert_eq!(map.lookup(2, 2).unwrap().line, 10);
        assert_eq!(map.lookup(2, 3).unwrap().line, 11);
        assert_eq!(map.lookup(2, 900).unwrap().line, 11);
        assert_eq!(map.lookup(3, 0), None);
        assert_eq!(map.lookup(4, 1).unwrap().line, 20);
        assert_eq!(map.symbol(7).unwrap().line, 9);
        assert_eq!(map.symbol(8), None);
        assert_eq!(map.symbol_entry(7).unwrap().expanded_at, None);
        assert_eq!(map.symbol_entry(9).unwrap().expanded_at.unwrap().line, 40);
        assert_eq!(map.call(2, 0), None, "no macro made it");
        assert_eq!(map.call(2, 4).unwrap().line, 50, "inside the macro's entry");
        assert_eq!(map.call(4, 0), None);
    }

    #[test]
    fn a_built_in_macros_code_is_shown_at_the_users_call() {
        let users = |file: &str| file.ends_with(".s");
        let call = Some(("main.s", 26));
        assert_eq!(
            user_place(("scorpion.inc", 80), call, &users),
            ("main.s", 26)
        );
        assert_eq!(
            user_place(("macros.s", 7), call, &users),
            ("macros.s", 7),
            "the user's own macro shows its own line"
        );
        assert_eq!(
            user_place(("scorpion.inc", 80), Some(("other.inc", 3)), &users),
            ("scorpion.inc", 80),
            "called from a file the user cannot open either"
        );
        assert_eq!(user_place(("scorpion.inc", 80), None, &users).1, 80);
    }

    #[test]
    fn every_truncation_is_an_error() {
        let bytes = sample().encode();
        for len in 0..bytes.len() {
            assert!(SrcMap::decode(&bytes[..len]).is_err(), "length {len}");
        }
    }

    #[test]
    fn huge_counts_are_refused_without_allocating() {
        let mut bytes = b"SCSM\x01".to_vec();
        bytes.extend_from_slice(&u32::MAX.to_le_bytes());
        let error = SrcMap::decode(&bytes).unwrap_err();
        assert!(error.reason.contains("does not fit"), "{error}");
    }

    #[test]
    fn bad_file_index_is_an_error() {
        let mut map = sample();
        map.entries[0].loc.file = 3;
        assert!(SrcMap::decode(&map.encode()).is_err());
    }
}
