//! `.scorpion.hooks`: which ROM hooks a linked image takes over.
//!
//! An extension declares a hook by exporting two symbols (the ROM's
//! `scorpion.inc` wraps them in macros):
//! - [`HOOK_UNKNOWN_SYMBOL`] / [`HOOK_LOOP_SYMBOL`]: the handler that the
//!   hook's `JMP` must point at;
//! - [`CHAIN_UNKNOWN_SYMBOL`] / [`CHAIN_LOOP_SYMBOL`] (optional): the address
//!   of a two-byte little-endian slot, normally the operand of the
//!   extension's fallthrough `JMP`, that receives the hook's previous target
//!   so that extensions chain.
//!
//! The linker turns those symbols into this section; the uploader and
//! `scorpion sim` read it and install each hook only after the image
//! verified: chain slot first, then the hook's operand in one write.
//!
//! Layout (version 1): magic `SCHK`, version, a count, then per record:
//! kind `u8` (0 `HOOK_UNKNOWN`, 1 `HOOK_LOOP`), handler `u16`, a `u8` that is
//! 1 when a chain slot follows, chain slot `u16`.

use super::HOOKS_SECTION;
use super::codec::{FormatError, Reader, Writer};

const MAGIC: &[u8; 4] = b"SCHK";
const VERSION: u8 = 1;

/// Exported by an extension: its `HOOK_UNKNOWN` handler.
pub const HOOK_UNKNOWN_SYMBOL: &str = "__scorpion_hook_unknown";
/// Exported by an extension: the 2-byte slot for `HOOK_UNKNOWN`'s previous target.
pub const CHAIN_UNKNOWN_SYMBOL: &str = "__scorpion_chain_unknown";
/// Exported by an operating system: its `HOOK_LOOP` handler.
pub const HOOK_LOOP_SYMBOL: &str = "__scorpion_hook_loop";
/// Exported by an operating system: the 2-byte slot for `HOOK_LOOP`'s previous target.
pub const CHAIN_LOOP_SYMBOL: &str = "__scorpion_chain_loop";

/// The two RAM hooks of the Scorpion ROM (docs/PROTOCOL.md section 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum HookKind {
    /// `HOOK_UNKNOWN`: unknown commands.
    Unknown,
    /// `HOOK_LOOP`: every pass of the control loop.
    Loop,
}

impl HookKind {
    /// Both hooks.
    pub const ALL: [HookKind; 2] = [HookKind::Unknown, HookKind::Loop];

    /// The ROM symbol of the hook's `JMP` (`"HOOK_UNKNOWN"`).
    #[must_use]
    pub const fn rom_symbol(self) -> &'static str {
        match self {
            HookKind::Unknown => "HOOK_UNKNOWN",
            HookKind::Loop => "HOOK_LOOP",
        }
    }

    /// The symbol an image exports for its handler.
    #[must_use]
    pub const fn handler_symbol(self) -> &'static str {
        match self {
            HookKind::Unknown => HOOK_UNKNOWN_SYMBOL,
            HookKind::Loop => HOOK_LOOP_SYMBOL,
        }
    }

    /// The symbol an image exports for its chain slot.
    #[must_use]
    pub const fn chain_symbol(self) -> &'static str {
        match self {
            HookKind::Unknown => CHAIN_UNKNOWN_SYMBOL,
            HookKind::Loop => CHAIN_LOOP_SYMBOL,
        }
    }
}

/// One hook an image takes over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HookRecord {
    /// Which hook.
    pub kind: HookKind,
    /// Where the hook must jump once the image verified.
    pub handler: u16,
    /// Where the hook's previous target goes (two bytes, little-endian).
    pub chain: Option<u16>,
}

/// The decoded `.scorpion.hooks` section.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Hooks {
    /// At most one record per hook kind.
    pub records: Vec<HookRecord>,
}

impl Hooks {
    /// Serialises the records.
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Writer::header(MAGIC, VERSION);
        out.len32(self.records.len());
        for record in &self.records {
            out.u8(match record.kind {
                HookKind::Unknown => 0,
                HookKind::Loop => 1,
            });
            out.u16(record.handler);
            match record.chain {
                Some(slot) => {
                    out.u8(1);
                    out.u16(slot);
                }
                None => {
                    out.u8(0);
                    out.u16(0);
                }
            }
        }
        out.bytes
    }

    /// Parses a section's contents.
    ///
    /// # Errors
    /// [`FormatError`] if the bytes are not a version-1 hooks section or
    /// name a hook twice.
    pub fn decode(bytes: &[u8]) -> Result<Hooks, FormatError> {
        let mut input = Reader::new(HOOKS_SECTION, bytes);
        input.header(MAGIC, VERSION)?;
        let count = input.count(6)?;
        let mut records: Vec<HookRecord> = Vec::with_capacity(count);
        for _ in 0..count {
            let kind = match input.u8()? {
                0 => HookKind::Unknown,
                1 => HookKind::Loop,
                other => return Err(input.error(format!("unknown hook kind {other}"))),
            };
            let handler = input.u16()?;
            let has_chain = input.u8()?;
            let slot = input.u16()?;
            let chain = match has_chain {
                0 => None,
                1 => Some(slot),
                other => return Err(input.error(format!("chain flag {other} is not 0 or 1"))),
            };
            if records.iter().any(|record| record.kind == kind) {
                return Err(input.error(format!("{} is hooked twice", kind.rom_symbol())));
            }
            records.push(HookRecord {
                kind,
                handler,
                chain,
            });
        }
        if !input.is_empty() {
            return Err(input.error("trailing bytes after the last record"));
        }
        Ok(Hooks { records })
    }

    /// The record for one hook, if the image takes it.
    #[must_use]
    pub fn get(&self, kind: HookKind) -> Option<&HookRecord> {
        self.records.iter().find(|record| record.kind == kind)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let hooks = Hooks {
            records: vec![
                HookRecord {
                    kind: HookKind::Unknown,
                    handler: 0x0400,
                    chain: Some(0x0431),
                },
                HookRecord {
                    kind: HookKind::Loop,
                    handler: 0x0500,
                    chain: None,
                },
            ],
        };
        let decoded = Hooks::decode(&hooks.encode()).unwrap();
        assert_eq!(decoded, hooks);
        assert_eq!(decoded.get(HookKind::Loop).unwrap().handler, 0x0500);
    }

    #[test]
    fn rejects_duplicates_and_truncation() {
        let record = HookRecord {
            kind: HookKind::Unknown,
            handler: 1,
            chain: None,
        };
        let twice = Hooks {
            records: vec![record, record],
        };
        let error = Hooks::decode(&twice.encode()).unwrap_err();
        assert!(error.reason.contains("twice"), "{error}");
        let bytes = Hooks {
            records: vec![record],
        }
        .encode();
        for len in 0..bytes.len() {
            assert!(Hooks::decode(&bytes[..len]).is_err());
        }
    }
}
