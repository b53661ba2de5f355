//! Reading and switching the ROM's RAM hooks, each a `JMP` whose operand
//! one `/9W` rewrites atomically.

use isa::objfmt::HookKind;
use romlib::protocol::{Answer, Command, ReadSpan, WordWrite};

use crate::client::Client;
use crate::image::RomProfile;
use crate::transport::Transport;
use crate::{Error, Result};

/// The `JMP` opcode every hook holds.
const JMP: u8 = 0x4C;

/// Reads a hook's `JMP` target. One read is enough when it shows a target
/// in `known` (a corrupted answer does not fake a particular address);
/// otherwise reads repeat until two agree.
///
/// # Errors
/// [`Error::NotAHook`] when two reads agree the hook holds no `JMP`,
/// [`Error::Unreadable`] when the reads keep disagreeing, or the client's.
pub(crate) fn read_hook<T: Transport>(
    client: &mut Client<T>,
    kind: HookKind,
    address: u16,
    known: &[u16],
) -> Result<u16> {
    let span = ReadSpan::new(address, 3)?;
    let mut previous = None;
    let attempts = client.config().question_attempts.max(2) * 2;
    for _ in 0..attempts {
        let Answer::Memory(bytes) = client.ask(&Command::ReadMemory(span))? else {
            continue;
        };
        if bytes[0] != JMP {
            if previous == Some(None) {
                return Err(Error::NotAHook {
                    hook: kind.rom_symbol(),
                    address,
                    found: bytes[0],
                });
            }
            previous = Some(None);
            continue;
        }
        let target = u16::from_le_bytes([bytes[1], bytes[2]]);
        if previous == Some(Some(target)) || (previous.is_none() && known.contains(&target)) {
            return Ok(target);
        }
        previous = Some(Some(target));
    }
    Err(Error::Unreadable {
        address,
        attempts,
        last: None,
    })
}

/// Reads both hooks, with one question when they are adjacent (as on the
/// reference ROM); one read is enough when both show their reset targets.
///
/// # Errors
/// As [`read_hook`].
pub(crate) fn read_hooks<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
) -> Result<Vec<(HookKind, u16)>> {
    let unknown = profile.hook_address(HookKind::Unknown);
    let main = profile.hook_address(HookKind::Loop);
    let reset = profile.reset_targets;
    if main != unknown.wrapping_add(3) {
        let mut hooks = Vec::new();
        for kind in HookKind::ALL {
            let known: Vec<u16> = profile.reset_target(kind).into_iter().collect();
            hooks.push((
                kind,
                read_hook(client, kind, profile.hook_address(kind), &known)?,
            ));
        }
        return Ok(hooks);
    }
    let span = ReadSpan::new(unknown, 6)?;
    let mut previous = None;
    let attempts = client.config().question_attempts.max(2) * 2;
    for _ in 0..attempts {
        let Answer::Memory(bytes) = client.ask(&Command::ReadMemory(span))? else {
            continue;
        };
        let targets = (
            u16::from_le_bytes([bytes[1], bytes[2]]),
            u16::from_le_bytes([bytes[4], bytes[5]]),
        );
        let opcodes = (bytes[0], bytes[3]);
        let agreed = previous == Some((opcodes, targets));
        previous = Some((opcodes, targets));
        if opcodes != (JMP, JMP) {
            if agreed {
                let (address, found) = if opcodes.0 == JMP {
                    (main, opcodes.1)
                } else {
                    (unknown, opcodes.0)
                };
                let kind = if address == unknown {
                    HookKind::Unknown
                } else {
                    HookKind::Loop
                };
                return Err(Error::NotAHook {
                    hook: kind.rom_symbol(),
                    address,
                    found,
                });
            }
            continue;
        }
        if agreed || reset == Some(targets) {
            return Ok(vec![
                (HookKind::Unknown, targets.0),
                (HookKind::Loop, targets.1),
            ]);
        }
    }
    Err(Error::Unreadable {
        address: unknown,
        attempts,
        last: None,
    })
}

/// Reads a little-endian word until two reads agree; `None` if they never
/// do.
///
/// # Errors
/// The client's.
pub(crate) fn read_word<T: Transport>(client: &mut Client<T>, address: u16) -> Result<Option<u16>> {
    let span = ReadSpan::new(address, 2)?;
    let mut previous = None;
    for _ in 0..client.config().question_attempts.max(2) * 2 {
        if let Answer::Memory(bytes) = client.ask(&Command::ReadMemory(span))? {
            let word = u16::from_le_bytes([bytes[0], bytes[1]]);
            if previous == Some(word) {
                return Ok(Some(word));
            }
            previous = Some(word);
        }
    }
    Ok(None)
}

/// Writes two bytes with one `/9W` until a read shows them there (a read
/// that shows exactly the bytes written is not a corrupted one).
///
/// # Errors
/// [`Error::VerifyFailed`] after `max_writes` writes, or the client's.
pub(crate) fn write_word_verified<T: Transport>(
    client: &mut Client<T>,
    address: u16,
    value: [u8; 2],
    max_writes: u32,
) -> Result<()> {
    let span = ReadSpan::new(address, 2)?;
    let mut found = value;
    for _ in 0..max_writes {
        client.send(&Command::WriteWord(WordWrite::new(address, value)?))?;
        if let Answer::Memory(bytes) = client.ask(&Command::ReadMemory(span))? {
            if bytes.as_slice() == value {
                return Ok(());
            }
            found.copy_from_slice(&bytes[..2]);
        }
    }
    let wrong = usize::from(found[0] == value[0]);
    Err(Error::VerifyFailed {
        address: address + wrong as u16,
        expected: value[wrong],
        found: found[wrong],
        attempts: max_writes,
    })
}

/// Points the hook at `address` to `target`, verified.
pub(crate) fn switch_hook<T: Transport>(
    client: &mut Client<T>,
    address: u16,
    target: u16,
    max_writes: u32,
) -> Result<()> {
    write_word_verified(client, address + 1, target.to_le_bytes(), max_writes)
}
