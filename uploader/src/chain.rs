//! Where a hook's chain leads past what the robot's table names. Whatever
//! a hook points at, an upload chains the image to it, and a debug session
//! chains its stub to it: when that code jumps back into what is written
//! now (an owner's `JMP` to an earlier copy of the image, a stub's own
//! `JMP PREV`), the robot runs in a loop at its next unknown command. A
//! target that is a `JMP abs` is followed, as are an installed extension's
//! chain slot and a debug stub's chain; other code ends the look (where it
//! goes cannot be known without running it).

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use emulator::{Bus, Cpu};
use isa::Mnemonic;
use isa::objfmt::HookKind;
use romlib::installed::Installed;

use crate::client::Client;
use crate::hooks::{JMP, read_word};
use crate::image::RomProfile;
use crate::transport::Transport;
use crate::{Error, Result};

mod reach;

/// Jumps followed at most: a longer run is a loop of the robot's own
/// (it already hangs there), not one through what is written now.
const MOST_STEPS: usize = 16;

/// The way a chain comes back: each address it went through, the last
/// one inside what `comes_back` named.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Path(pub(crate) Vec<u16>);

impl std::fmt::Display for Path {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut text = String::new();
        for (i, at) in self.0.iter().enumerate() {
            if i > 0 {
                text.push_str(" -> ");
            }
            let _ = write!(text, "${at:04X}");
        }
        f.write_str(&text)
    }
}

/// Follows `kind`'s chain from `target` through `JMP`s, installed
/// extensions' chain slots (`everyone`), debug stubs' chains and other
/// code run on the host ([`run_to_landing`]), reading only memory an
/// extension may hold; `Some` with the way when it comes to an address
/// `inside` says is written now. The ROM's own target, the ROM, and code
/// whose way cannot be followed end it (`None`).
///
/// # Errors
/// The line's errors.
pub(crate) fn comes_back<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    inside: &dyn Fn(u16) -> bool,
) -> Result<Option<Path>> {
    Ok(
        match follow(
            client,
            profile,
            everyone,
            (kind, target),
            &|at, _| inside(at),
            false,
        )? {
            End::Inside(path) => Some(path),
            _ => None,
        },
    )
}

/// hostile25 F4: before a replacement frees anything, the way of `kind`
/// from `target` into `image`'s memory, where it gets there other than as
/// the replacement re-points it (from the hook itself, or from the chain
/// slot of an extension `everyone` lists): through code no entry lists,
/// which the replacement cannot re-point. It freed the old entry, then
/// refused as a loop, and the undo of a robot left so was refused too.
///
/// # Errors
/// The line's errors.
pub(crate) fn unlisted_way_into<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    image: &crate::image::UploadImage,
) -> Result<Option<Path>> {
    let End::Inside(path) = follow(
        client,
        profile,
        everyone,
        (kind, target),
        &|at, _| image.contains(at),
        false,
    )?
    else {
        return Ok(None);
    };
    let listed = |at: u16| {
        everyone
            .iter()
            .flat_map(|other| other.hooks.iter())
            .any(|hook| hook.kind == kind && hook.handler == at)
    };
    let before = path.0.len().checked_sub(2).map(|i| path.0[i]);
    Ok(match before {
        None => None,
        Some(at) if listed(at) => None,
        Some(_) => Some(path),
    })
}

/// How a chain followed from a hook's target ends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum End {
    /// At an address the caller named: the way there.
    Inside(Path),
    /// At code that stops the CPU (a `JAM`, a `BRK` whose interrupt
    /// handler returns into the middle of nothing): the way there.
    Stops(Path),
    /// Where no extension's code can be: in the ROM but not at one of
    /// its entries ([`rom_entry`]), or in memory no extension may hold (the
    /// ROM's own RAM, the I/O page): the way there. Told only where asked
    /// ([`follow`]'s `strict`).
    Strays(Path),
    /// In a loop of code run on the host that never gets anywhere (the
    /// same registers at the same place, nothing written between): the
    /// way there, the loop's address last.
    Loops(Path),
    /// At a return the code pushed nothing for: the way there.
    Returns(Path),
    /// In the ROM, or somewhere this module cannot follow (a call where
    /// calls are not followed, a run longer than it looks).
    Elsewhere,
}

/// The walk of [`comes_back`], ending where `inside(at, way)` says (`way`:
/// the addresses gone through before `at`), or at code that stops the
/// CPU.
///
/// # Errors
/// The line's errors.
pub(crate) fn follow<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    inside: &dyn Fn(u16, &[u16]) -> bool,
    strict: bool,
) -> Result<End> {
    follow_noting(
        client,
        profile,
        everyone,
        (kind, target),
        (inside, strict),
        &mut Noted::default(),
    )
}

/// hostile26 F4: the code the way of `kind` from `target` runs that no
/// entry of `everyone` lists (nor a debug stub's): the bytes of its `JMP`s
/// and of each instruction run on the host, as the robot would run it
/// once (a branch not taken this time is not seen).
///
/// # Errors
/// The line's errors.
pub(crate) fn unlisted_touched<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
) -> Result<BTreeSet<u16>> {
    let mut noted = Noted::default();
    follow_noting(
        client,
        profile,
        everyone,
        (kind, target),
        (&|_, _| false, false),
        &mut noted,
    )?;
    let mut touched = noted.code;
    touched.retain(|&at| !everyone.iter().any(|other| other.contains(at)));
    Ok(touched)
}

/// What a walk ([`follow_noting`]) reads over the robot's memory and what
/// it notes on the way.
#[derive(Debug, Default)]
pub(crate) struct Noted {
    /// Bytes taken instead of the robot's (a file's, as a restore would
    /// write them).
    pub(crate) laid: BTreeMap<u16, u8>,
    /// Every readable address of the code the way runs: the bytes of its
    /// `JMP`s and of each instruction run on the host.
    pub(crate) code: BTreeSet<u16>,
    /// The addresses the way went through, as far as it was followed.
    pub(crate) way: Vec<u16>,
    /// What the code run on the host wrote: its data (a counter after a
    /// branch always taken, an operand it changes), not code to check.
    pub(crate) data: BTreeSet<u16>,
    /// The first jump the way makes to where its data says (a `JMP`
    /// through a pointer, an `RTS` or `RTI` to an address it pushed): the
    /// code it may reach from there cannot all be known (hostile29 F1).
    pub(crate) computed: Option<u16>,
    /// Whether the way ends where a command's way may: the ROM, or code
    /// past every listed extension (not a loop, code that stops the CPU,
    /// a return nothing called, or memory no code may be in).
    pub(crate) fine: bool,
    /// The lowest address of a listed extension's code the way runs, if
    /// it runs any: where it goes into one (for messages).
    pub(crate) entered: Option<u16>,
}

/// `len` bytes from `at`: the `laid` ones, the robot's elsewhere.
fn laid_read<T: Transport>(
    client: &mut Client<T>,
    laid: &BTreeMap<u16, u8>,
    at: u16,
    len: usize,
) -> Result<Vec<u8>> {
    let held: Option<Vec<u8>> = (0..len)
        .map(|i| laid.get(&at.wrapping_add(i as u16)).copied())
        .collect();
    if let Some(held) = held {
        return Ok(held);
    }
    let mut bytes = client.read_live(at, len)?.bytes;
    for (i, byte) in bytes.iter_mut().enumerate() {
        if let Some(&over) = laid.get(&at.wrapping_add(i as u16)) {
            *byte = over;
        }
    }
    Ok(bytes)
}

/// A chain slot's word: the `laid` bytes, the robot's elsewhere.
fn laid_word<T: Transport>(
    client: &mut Client<T>,
    laid: &BTreeMap<u16, u8>,
    at: u16,
) -> Result<Option<u16>> {
    let over = (laid.get(&at), laid.get(&at.wrapping_add(1)));
    if let (Some(&lo), Some(&hi)) = over {
        return Ok(Some(u16::from_le_bytes([lo, hi])));
    }
    let Some(word) = read_word(client, at)? else {
        return Ok(None);
    };
    let [lo, hi] = word.to_le_bytes();
    Ok(Some(u16::from_le_bytes([
        over.0.copied().unwrap_or(lo),
        over.1.copied().unwrap_or(hi),
    ])))
}

/// The way of `kind` from `target` over the robot's memory with `laid`
/// bytes over it (a file's, as a restore would leave them), looking for a
/// broken way (`strict`: calls into RAM followed), and every byte of the
/// code it runs outside what `everyone` lists: each `JMP`, each
/// instruction run on the host, and every instruction reachable from a
/// step on a branch or call not taken in that run (hostile28 F3: code
/// before a step's `JMP` hid where it went).
///
/// # Errors
/// The line's errors.
pub(crate) fn way_code<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    laid: BTreeMap<u16, u8>,
) -> Result<Noted> {
    let mut noted = Noted {
        laid,
        ..Noted::default()
    };
    let end = follow_noting(
        client,
        profile,
        everyone,
        (kind, target),
        (&|at, way| way.contains(&at), true),
        &mut noted,
    )?;
    noted.fine = end == End::Elsewhere;
    // hostile30 F5: code the run ran that the run wrote (a `JMP` whose
    // operand it bumps) goes where its data says. (Bytes only reached
    // below, on an arm not run, may be data: a counter in line.)
    if let Some(&own) = noted.code.iter().find(|at| noted.data.contains(at)) {
        noted.computed.get_or_insert(own);
    }
    let listed = |at: u16| everyone.iter().any(|other| other.contains(at));
    let starts: Vec<u16> = noted
        .way
        .iter()
        .copied()
        .filter(|&at| readable(profile, at) && !listed(at))
        .collect();
    let mut bus = ChainBus::over(
        (client, profile),
        &noted.laid,
        (&mut noted.code, &mut noted.data, &mut noted.computed),
    );
    reach::reach(&mut bus, &starts, &listed)?;
    noted.entered = noted.code.iter().copied().find(|&at| listed(at));
    let data = &noted.data;
    noted.code.retain(|&at| !listed(at) && !data.contains(&at));
    Ok(noted)
}

/// Where a walk ends: `inside(at, way)`, `way` the addresses gone
/// through before `at`.
type Inside<'a> = &'a dyn Fn(u16, &[u16]) -> bool;

/// [`follow`], adding to `touched` every byte of code the way runs (the
/// caller leaves out what entries list).
fn follow_noting<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    (inside, strict): (Inside<'_>, bool),
    noted: &mut Noted,
) -> Result<End> {
    let Noted {
        laid,
        code: touched,
        way: path,
        data: written,
        computed,
        ..
    } = noted;
    path.clear();
    let mut at = target;
    for _ in 0..MOST_STEPS {
        if inside(at, path) {
            path.push(at);
            return Ok(End::Inside(Path(path.clone())));
        }
        path.push(at);
        let readable = profile
            .writable
            .iter()
            .any(|range| range.contains(&at) && range.contains(&at.saturating_add(2)));
        if profile.reset_target(kind) == Some(at) {
            return Ok(End::Elsewhere);
        }
        if !readable {
            return Ok(if strict && !rom_entry(profile, at) {
                End::Strays(Path(path.clone()))
            } else {
                End::Elsewhere
            });
        }
        let handler = everyone
            .iter()
            .flat_map(|other| other.hooks.iter())
            .find(|hook| hook.kind == kind && hook.handler == at);
        // hostile15 F7: into an installed extension but not at its
        // handler: the middle of its code, where no chain goes.
        if strict && handler.is_none() && everyone.iter().any(|other| other.contains(at)) {
            return Ok(End::Strays(Path(path.clone())));
        }
        let slot = handler.and_then(|hook| hook.chain);
        let next = match slot {
            Some(slot) => laid_word(client, laid, slot)?,
            None => {
                let bytes = laid_read(client, laid, at, 3)?;
                if bytes[0] == JMP {
                    touched.extend([at, at.wrapping_add(1), at.wrapping_add(2)]);
                    Some(u16::from_le_bytes([bytes[1], bytes[2]]))
                } else if let Some(stub) = crate::stub::left::at_target(client, profile, at)? {
                    // A debug stub (hooked or left in RAM by a session)
                    // goes on where its chain does.
                    Some(stub.previous)
                } else {
                    // Other code: run on the host over the robot's memory
                    // as an unknown command would run it, to where it goes.
                    let landing = |pc: u16| {
                        inside(pc, path)
                            || everyone
                                .iter()
                                .flat_map(|other| other.hooks.iter())
                                .any(|hook| hook.kind == kind && hook.handler == pc)
                    };
                    let bus = ChainBus::over((client, profile), laid, (touched, written, computed));
                    let landed = run_to_landing(bus, at, &landing, strict)?;
                    match landed {
                        Landing::At(pc) | Landing::Left(pc) => Some(pc),
                        Landing::Stops(pc) => {
                            path.push(pc);
                            return Ok(End::Stops(Path(path.clone())));
                        }
                        Landing::Loops(pc) => {
                            path.push(pc);
                            return Ok(End::Loops(Path(path.clone())));
                        }
                        Landing::Returns(pc) => {
                            path.push(pc);
                            return Ok(End::Returns(Path(path.clone())));
                        }
                        Landing::Elsewhere => None,
                    }
                }
            }
        };
        match next {
            Some(next) => at = next,
            None => return Ok(End::Elsewhere),
        }
    }
    Ok(End::Elsewhere)
}

/// After a restore wrote its memory (the hooks still at the ROM's
/// targets): each hook the file points into RAM, followed over what the
/// robot now holds, must neither come back to where it has been (a loop
/// the robot would run for ever), nor reach code that stops the CPU, nor
/// be the other hook's handler in the table (hostile10 F10, F14).
///
/// Returns each hook refused, with [`Error::RestoreChainBroken`] saying
/// why: it stays at the ROM's target, the others are restored.
///
/// # Errors
/// The line's errors.
pub(crate) fn check_restored<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    hooks: &[(HookKind, u16)],
) -> Result<Vec<(HookKind, Error)>> {
    let targets = into_ram(profile, hooks);
    let mut refused = Vec::new();
    if targets.is_empty() {
        return Ok(refused);
    }
    let everyone = crate::table::read_installed(client, profile)?;
    for (kind, target) in targets {
        let broken = |why: &'static str, path: String| Error::RestoreChainBroken {
            hook: kind.rom_symbol(),
            target,
            why,
            path,
        };
        let handlers = |of: &dyn Fn(HookKind) -> bool| {
            everyone
                .iter()
                .flat_map(|entry| entry.hooks.iter())
                .any(|hook| of(hook.kind) && hook.handler == target)
        };
        if handlers(&|other| other != kind) && !handlers(&|this| this == kind) {
            refused.push((
                kind,
                broken(
                    "is the other hook's handler in the table of installed extensions",
                    format!("${target:04X}"),
                ),
            ));
        } else if let Some((why, path)) = broken_way(client, profile, &everyone, (kind, target))? {
            refused.push((kind, broken(why, path.to_string())));
        }
    }
    Ok(refused)
}

/// The hooks of `hooks` that point into RAM an upload may write (not at
/// the ROM's own targets): those whose way a file or a robot decides.
pub(crate) fn into_ram(profile: &RomProfile, hooks: &[(HookKind, u16)]) -> Vec<(HookKind, u16)> {
    hooks
        .iter()
        .copied()
        .filter(|&(kind, target)| {
            profile.reset_target(kind) != Some(target)
                && profile.writable.iter().any(|range| range.contains(&target))
        })
        .collect()
}

/// What a way out is, for a chain about to be made to it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Way {
    /// It reaches the ROM's target or an entry of the ROM, or code whose
    /// way cannot be told (a call, a return).
    Fine,
    /// It comes back into what `inside` names: the way there.
    ComesBack(Path),
    /// It is no way for a command to go: why, and the way there.
    Broken(&'static str, Path),
}

/// Judges the chain of `kind` from `target`, followed over what the robot
/// holds ([`follow`], strict): it comes back to where `inside` says (what
/// is written now), or it is broken: it comes back to where it has been or
/// loops (the robot would run for ever), reaches code that stops the CPU,
/// or strays where no extension's code can be.
///
/// # Errors
/// The line's errors.
pub(crate) fn judge_way<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
    inside: &dyn Fn(u16) -> bool,
) -> Result<Way> {
    Ok(
        match follow(
            client,
            profile,
            everyone,
            (kind, target),
            &|at, way| inside(at) || way.contains(&at),
            true,
        )? {
            End::Inside(path) if path.0.last().is_some_and(|&at| inside(at)) => {
                Way::ComesBack(path)
            }
            End::Inside(path) | End::Loops(path) => Way::Broken(
                "comes back to where it has been, a loop the robot would run for ever",
                path,
            ),
            End::Stops(path) => {
                Way::Broken("reaches code that stops the CPU (a BRK or a JAM)", path)
            }
            End::Returns(path) => Way::Broken(
                "returns where nothing called it (an RTS or RTI for which the code pushed nothing: a hook is entered by a JMP)",
                path,
            ),
            End::Strays(path) => Way::Broken(
                "leads where no extension's code is (the ROM's own RAM or I/O, the ROM but not one of its entries, or an installed extension but not its handler)",
                path,
            ),
            End::Elsewhere => Way::Fine,
        },
    )
}

/// Why the chain of `kind` from `target` is no way for a command to go
/// ([`judge_way`] with nothing written now), if it is not.
///
/// # Errors
/// The line's errors.
pub(crate) fn broken_way<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    everyone: &[Installed],
    (kind, target): (HookKind, u16),
) -> Result<Option<(&'static str, Path)>> {
    Ok(
        match judge_way(client, profile, everyone, (kind, target), &|_| false)? {
            Way::Broken(why, path) => Some((why, path)),
            Way::Fine | Way::ComesBack(_) => None,
        },
    )
}

/// Whether `at` in the ROM is a place a handler's way may go: the entries
/// that do not return, `CMD_DONE` and the hooks' own targets
/// (`BAD_COMMAND`, the control loop). Anywhere else runs the middle of the
/// ROM, or a subroutine whose `RTS` returns where nothing called it.
fn rom_entry(profile: &RomProfile, at: u16) -> bool {
    profile
        .loader_services
        .as_ref()
        .is_some_and(|services| services.cmd_done == at)
        || profile
            .reset_targets
            .is_some_and(|(unknown, main)| at == unknown || at == main)
}

/// Where [`run_to_landing`] ended.
enum Landing {
    /// Where the caller's `landing` said.
    At(u16),
    /// At an instruction that stops the CPU (`JAM`) or a `BRK`.
    Stops(u16),
    /// Gone by a jump or a branch to memory the host does not read (the
    /// ROM, the ROM's own RAM, the I/O page): where.
    Left(u16),
    /// Back at a place with the registers it had there, nothing written
    /// between: a loop that never ends.
    Loops(u16),
    /// At an `RTS` or `RTI` that pulls more than the code pushed: it
    /// returns where nothing called it.
    Returns(u16),
    /// Anywhere else (see [`run_to_landing`]).
    Elsewhere,
}

/// Instructions run on the host before code is taken to go nowhere this
/// module can tell.
const MOST_INSTRUCTIONS: usize = 4096;

/// The stack pointer a host run starts with: below it, what the handler
/// pushes.
const ENTRY_S: u8 = 0xF0;

/// Bytes a handler's calls may push before the run takes them for a call
/// that never returns: half the 6502's stack.
const DEEPEST: u8 = 0x80;

/// Bytes read from the robot at once for the host's run.
const CHUNK: usize = 16;

/// Runs the code at `start` on the host, reading the robot's memory as it
/// needs it (writes kept on the host), with the registers an unknown
/// command brings (A a byte no handler takes), until the PC lands where
/// `landing` says; [`Landing::Stops`] at a `JAM` or a `BRK` (the ROM's
/// interrupt handler returns from a `BRK`, two bytes on: no handler's
/// way); [`Landing::Left`] where it goes into the ROM or to memory an
/// extension may not hold (the I/O page); [`Landing::Loops`] back at a
/// place with the same registers and nothing written between;
/// [`Landing::Returns`] at a return it pushed nothing for;
/// [`Landing::Elsewhere`] where it reads memory it may not, calls into
/// the ROM (a service returns where the ROM decides), or has run
/// [`MOST_INSTRUCTIONS`]. A call back into code the run has been through
/// is a loop; `strict` (looking for a broken way), a call into RAM is
/// followed, and one into memory no code may be in strays.
fn run_to_landing<T: Transport>(
    mut bus: ChainBus<'_, T>,
    start: u16,
    landing: &dyn Fn(u16) -> bool,
    strict: bool,
) -> Result<Landing> {
    let profile = bus.profile;
    let mut cpu = Cpu::new();
    cpu.set_idle_skip(false);
    (cpu.a, cpu.x, cpu.y, cpu.s, cpu.pc) = (0, 1, 0, ENTRY_S, start);
    let mut states = std::collections::HashSet::new();
    // Calls made and not yet returned from.
    let mut calls = 0u32;
    for _ in 0..MOST_INSTRUCTIONS {
        let opcode = bus.byte(cpu.pc);
        if let Some(error) = bus.failed.take() {
            return Err(error);
        }
        let info = isa::opcode(opcode);
        if bus.outside {
            break;
        }
        if info.cycles == 0 || info.mnemonic == Mnemonic::Brk {
            return Ok(Landing::Stops(cpu.pc));
        }
        // A handler is entered by a `JMP` (the ROM's dispatch, its loop):
        // a return it pushed nothing for pops the ROM's stack (hostile15
        // F9: a bare `RTS` jammed the CPU). One it pushed for (the
        // jump-table idiom) is run.
        if matches!(info.mnemonic, Mnemonic::Rts | Mnemonic::Rti) {
            let pulled = if info.mnemonic == Mnemonic::Rts { 2 } else { 3 };
            if u16::from(cpu.s) + pulled > u16::from(ENTRY_S) {
                return Ok(Landing::Returns(cpu.pc));
            }
            // A return no call of this run made: to an address the code
            // pushed (a jump table).
            if calls == 0 || info.mnemonic == Mnemonic::Rti {
                bus.computed.get_or_insert(cpu.pc);
            }
            calls = calls.saturating_sub(1);
        }
        if info.mnemonic == Mnemonic::Jmp && info.mode == isa::AddressingMode::Indirect {
            bus.computed.get_or_insert(cpu.pc);
        }
        if info.mnemonic == Mnemonic::Jsr {
            let target = u16::from_le_bytes([
                bus.byte(cpu.pc.wrapping_add(1)),
                bus.byte(cpu.pc.wrapping_add(2)),
            ]);
            // Where it calls is code the way runs too.
            if readable(profile, target) {
                bus.touched.insert(target);
            }
            // hostile16 F1: a call that calls itself for ever (`JSR` to
            // itself) pushes without end; a subroutine called twice, or
            // a recursion that ends, returns (hostile29 F3: taken for a
            // loop, the hook was left at the ROM). More than
            // [`DEEPEST`] bytes pushed: the robot's stack would wrap.
            if ENTRY_S.saturating_sub(cpu.s) > DEEPEST {
                return Ok(Landing::Loops(target));
            }
            // A call into the ROM (a service) returns where the ROM
            // decides: the run ends there. One into memory no code may be
            // in (the ROM's zero page) strays; one into RAM is followed.
            // Not looking for a broken way (attach's look for one back
            // into the stub), a call ends the run: it may be a breakpoint
            // a killed session left, which attaching takes out.
            if target >= platform::map::ROM_START || !strict {
                break;
            }
            if !readable(profile, target) {
                return Ok(Landing::Left(target));
            }
            calls += 1;
        }
        // The code the way runs (not the data it reads and writes, which
        // may be anyone's): each instruction's bytes.
        for i in 0..u16::from(info.len()) {
            let at = cpu.pc.wrapping_add(i);
            if readable(profile, at) {
                bus.touched.insert(at);
            }
        }
        cpu.step(&mut bus);
        if let Some(error) = bus.failed.take() {
            return Err(error);
        }
        if bus.outside {
            break;
        }
        if !readable(profile, cpu.pc) {
            return Ok(Landing::Left(cpu.pc));
        }
        if landing(cpu.pc) {
            return Ok(Landing::At(cpu.pc));
        }
        if std::mem::take(&mut bus.wrote) {
            states.clear();
        }
        if !states.insert((cpu.pc, cpu.a, cpu.x, cpu.y, cpu.s, cpu.p())) {
            return Ok(Landing::Loops(cpu.pc));
        }
    }
    Ok(Landing::Elsewhere)
}

/// Whether `at` is memory an extension may hold (where the host reads
/// the robot's bytes: never the I/O page, whose reads change it).
fn readable(profile: &RomProfile, at: u16) -> bool {
    profile.writable.iter().any(|range| range.contains(&at))
        || profile
            .user_zero_page
            .as_ref()
            .is_some_and(|zp| at <= 0xFF && zp.contains(&(at as u8)))
}

/// Where a [`ChainBus`] notes: a [`Noted`]'s `code`, `data` and
/// `computed`.
type NotedParts<'a> = (
    &'a mut BTreeSet<u16>,
    &'a mut BTreeSet<u16>,
    &'a mut Option<u16>,
);

/// The robot's memory for [`run_to_landing`]: read through the line a
/// chunk at a time, each byte once; writes kept on the host.
struct ChainBus<'a, T: Transport> {
    client: &'a mut Client<T>,
    profile: &'a RomProfile,
    /// Bytes read (or laid: a file's), and those the run wrote.
    seen: BTreeMap<u16, u8>,
    failed: Option<crate::Error>,
    /// An access outside what may be read: the run ends there.
    outside: bool,
    /// A write since the last look: the state of memory changed.
    wrote: bool,
    /// Every readable address of the code the run ran.
    touched: &'a mut BTreeSet<u16>,
    /// Every address the run wrote.
    written: &'a mut BTreeSet<u16>,
    /// Where the run first jumped where its data said (see
    /// [`Noted::computed`]).
    computed: &'a mut Option<u16>,
}

impl<'a, T: Transport> ChainBus<'a, T> {
    /// A bus over the robot's memory with `laid` bytes over it (a file's),
    /// noting the code run, what it wrote and a jump where its data says
    /// (a [`Noted`]'s parts).
    fn over(
        (client, profile): (&'a mut Client<T>, &'a RomProfile),
        laid: &BTreeMap<u16, u8>,
        (touched, written, computed): NotedParts<'a>,
    ) -> Self {
        ChainBus {
            client,
            profile,
            seen: laid.clone(),
            failed: None,
            outside: false,
            wrote: false,
            touched,
            written,
            computed,
        }
    }

    /// The byte at `address`, read from the robot once; 0 where it may
    /// not be read or the line failed (see `outside`, `failed`).
    fn byte(&mut self, address: u16) -> u8 {
        if let Some(&byte) = self.seen.get(&address) {
            return byte;
        }
        if !readable(self.profile, address) {
            self.outside = true;
            return 0;
        }
        let len = CHUNK.min(0x1_0000 - usize::from(address));
        let len = (0..len)
            .take_while(|&i| readable(self.profile, address.wrapping_add(i as u16)))
            .count();
        // A chunk of code may end in the program's data, which its control
        // loop writes as it runs (hostile16 F4): that is no failure here.
        match self.client.read_live(address, len).map(|read| read.bytes) {
            Ok(bytes) => {
                for (i, byte) in bytes.into_iter().enumerate() {
                    self.seen
                        .entry(address.wrapping_add(i as u16))
                        .or_insert(byte);
                }
                self.seen.get(&address).copied().unwrap_or(0)
            }
            Err(error) => {
                self.failed.get_or_insert(error);
                self.outside = true;
                0
            }
        }
    }
}

impl<T: Transport> Bus for ChainBus<'_, T> {
    fn read(&mut self, address: u16, _cycle: u64) -> u8 {
        self.byte(address)
    }

    fn write(&mut self, address: u16, value: u8, _cycle: u64) {
        self.seen.insert(address, value);
        self.wrote = true;
        self.written.insert(address);
    }

    fn dummy_read(&mut self, _address: u16, _cycle: u64) {}

    fn peek(&self, address: u16) -> u8 {
        self.seen.get(&address).copied().unwrap_or(0)
    }
}
