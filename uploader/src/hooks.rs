//! Reading and switching the ROM's RAM hooks, each a `JMP` whose operand
//! one `/9W` rewrites atomically.

use isa::objfmt::HookKind;
use romlib::protocol::{Answer, Command, ReadSpan, WordWrite};

use crate::client::Client;
use crate::image::RomProfile;
use crate::transport::Transport;
use crate::{Error, Result};

/// The `JMP` opcode every hook holds.
pub(crate) const JMP: u8 = 0x4C;

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
    read_word_expecting(client, address, None)
}

/// Reads a little-endian word as [`read_word`] does, but a first answer
/// that is `expected` is taken at once: for a wrong word to pass, noise
/// would have to turn the robot's digits into exactly the expected ones.
/// Anything else is read until two answers agree.
///
/// # Errors
/// The client's.
pub(crate) fn read_word_expecting<T: Transport>(
    client: &mut Client<T>,
    address: u16,
    expected: Option<u16>,
) -> Result<Option<u16>> {
    let span = ReadSpan::new(address, 2)?;
    let mut previous = None;
    for _ in 0..client.config().question_attempts.max(2) * 2 {
        if let Answer::Memory(bytes) = client.ask(&Command::ReadMemory(span))? {
            let word = u16::from_le_bytes([bytes[0], bytes[1]]);
            if previous == Some(word) || (previous.is_none() && expected == Some(word)) {
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

/// Where a hook must point once [`settle_hooks`] returns.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wanted {
    /// The hook's `JMP`.
    pub(crate) address: u16,
    /// Its target.
    pub(crate) target: u16,
    /// Another target it may keep without being written (the ROM's own,
    /// after a reset), for a hook that is only checked.
    pub(crate) also: Option<u16>,
    /// Whether the upload writes it, or only checks it.
    pub(crate) write: bool,
}

/// Points the hook at `address` to `target`, verified.
pub(crate) fn switch_hook<T: Transport>(
    client: &mut Client<T>,
    address: u16,
    target: u16,
    max_writes: u32,
) -> Result<()> {
    settle_hooks(
        client,
        &[Wanted {
            address,
            target,
            also: None,
            write: true,
        }],
        max_writes,
    )
}

/// Tries at a read a quiet line failed before it is given up (fresh15
/// F5: a line quiet for 1.5 s anywhere in an attach).
pub(crate) const QUIET_LOOKS: u32 = 3;

/// Points the hook at `address` to `target` as [`switch_hook`] does, but
/// reads every RAM hook of the ROM back whole, the others as they were
/// before (read first): a `/9W` to `HOOK_UNKNOWN`'s operand whose address
/// digits noise changed lands on a hook's `JMP` opcode (`$0201` read as
/// `$0200`, or `$0203`, `HOOK_LOOP`'s), and only a read of all of them
/// finds that before the next unknown command, or the control loop's next
/// pass, runs the byte there. The debug stub's attach and detach switch
/// with this.
pub(crate) fn switch_hook_among<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    address: u16,
    target: u16,
    max_writes: u32,
) -> Result<()> {
    let mut wanted = vec![Wanted {
        address,
        target,
        also: None,
        write: true,
    }];
    // A read only: tried again where the line went quiet a while.
    let now = crate::session::tried_quiet(QUIET_LOOKS, || read_hooks(client, profile))?;
    for (kind, now) in now {
        let other = profile.hook_address(kind);
        if other != address {
            wanted.push(Wanted {
                address: other,
                target: now,
                also: None,
                write: false,
            });
        }
    }
    settle_hooks(client, &wanted, max_writes)
}

/// Points each hook of `hooks` at its target, then reads them all back
/// whole at once ([`settle_hooks`]): a restore's hooks, the last it writes.
pub(crate) fn switch_hooks<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    hooks: &[(HookKind, u16)],
    max_writes: u32,
) -> Result<()> {
    let wanted: Vec<Wanted> = hooks
        .iter()
        .map(|&(kind, target)| Wanted {
            address: profile.hook_address(kind),
            target,
            also: None,
            write: true,
        })
        .collect();
    if wanted.is_empty() {
        return Ok(());
    }
    settle_hooks(client, &wanted, max_writes)
}

/// Writes the hooks `wanted` says to (each operand with one `/9W`), then
/// reads every hook in `wanted` back whole, opcode included (with one
/// question when they lie within nine bytes, as on the reference ROM), and
/// puts right whatever reads wrong: a `/9W` whose address digits noise
/// changed lands beside its target, on a hook's `JMP` opcode or on the
/// other hook, and only a read of all of them finds that.
///
/// # Errors
/// [`Error::VerifyFailed`] after `max_writes` rounds, or the client's.
pub(crate) fn settle_hooks<T: Transport>(
    client: &mut Client<T>,
    wanted: &[Wanted],
    max_writes: u32,
) -> Result<()> {
    let write = |client: &mut Client<T>, hook: &Wanted| {
        client.send(&Command::WriteWord(WordWrite::new(
            hook.address + 1,
            hook.target.to_le_bytes(),
        )?))
    };
    for hook in wanted.iter().filter(|hook| hook.write) {
        write(client, hook)?;
    }
    let first = wanted.iter().map(|hook| hook.address).min().unwrap_or(0);
    let last = wanted.iter().map(|hook| hook.address).max().unwrap_or(0);
    let together = u32::from(last) + 3 - u32::from(first) <= 9;
    let mut wrong = None;
    for _ in 0..max_writes.max(1) {
        let mut found: Vec<(Wanted, [u8; 3])> = Vec::new();
        if together {
            let span = ReadSpan::new(first, (last - first + 3) as u8)?;
            if let Some(Answer::Memory(bytes)) = ask_again(client, span)? {
                for hook in wanted {
                    let at = usize::from(hook.address - first);
                    found.push((*hook, [bytes[at], bytes[at + 1], bytes[at + 2]]));
                }
            }
        } else {
            for hook in wanted {
                let span = ReadSpan::new(hook.address, 3)?;
                if let Some(Answer::Memory(bytes)) = ask_again(client, span)? {
                    found.push((*hook, [bytes[0], bytes[1], bytes[2]]));
                }
            }
        }
        // An answer that never came clean is a round without news.
        wrong = (found.len() < wanted.len()).then_some((first, JMP, 0));
        for (hook, [opcode, low, high]) in found {
            let target = u16::from_le_bytes([low, high]);
            if opcode == JMP && (target == hook.target || Some(target) == hook.also) {
                continue;
            }
            if opcode != JMP {
                let [low, _] = hook.target.to_le_bytes();
                client.send(&Command::WriteWord(WordWrite::new(
                    hook.address,
                    [JMP, low],
                )?))?;
                wrong = Some((hook.address, JMP, opcode));
            } else {
                let [want_low, want_high] = hook.target.to_le_bytes();
                wrong = Some(if low == want_low {
                    (hook.address + 2, want_high, high)
                } else {
                    (hook.address + 1, want_low, low)
                });
            }
            write(client, &hook)?;
        }
        if wrong.is_none() {
            return Ok(());
        }
    }
    let (address, expected, found) = wrong.unwrap_or((first, JMP, 0));
    Err(Error::VerifyFailed {
        address,
        expected,
        found,
        attempts: max_writes,
    })
}

/// Reads `span`; `None` when every answer came back garbled (the caller
/// reads again), rather than an error: noise must not end an upload that
/// is one read from done.
fn ask_again<T: Transport>(client: &mut Client<T>, span: ReadSpan) -> Result<Option<Answer>> {
    match client.ask(&Command::ReadMemory(span)) {
        Ok(answer) => Ok(Some(answer)),
        Err(Error::Protocol(_)) => Ok(None),
        Err(error) => Err(error),
    }
}
