//! The debugger attached to a robot through the stub: the stub written
//! and hooked, breakpoints patched in and out safely, the stub's frames
//! at a stop (memory read and written, continue, step), commands sent
//! while it runs.
//!
//! Safety of the patches: a trampoline is written and read back before
//! any `JSR` can reach it, and the three bytes of a patch (or of its
//! removal) are staged in the stub, read back, then copied by the robot
//! in one command (`/1@`) while it runs, or written in one frame while it
//! is stopped: no moment exists where the code holds part of a `JSR`, or
//! a `JSR` into bytes not verified. A reset in between unhooks the stub,
//! so a `/1@` after it does nothing; the bytes are read back after every
//! patch, so the host always knows which of the two the code holds.

use std::collections::BTreeMap;
use std::ops::RangeInclusive;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use romlib::protocol::Command;

use super::error::{StubError, StubResult, hex};
use super::frame::{self, Heard, IN_MAX};
use super::guard::{self, Guard};
use super::host_step::{self, Step};
use super::link::{StubPlan, TRAMPOLINE_LEN, TRAMPOLINES};
use super::patch::{self, JSR, Patch};
use crate::client::{Client, LiveRead};
use crate::image::{RomProfile, UploadImage};
use crate::transport::{Transport, char_time};
use isa::objfmt::HookKind;
use isa::{AddressingMode, Instruction, Mnemonic};
use romlib::installed::Installed;

/// The registers at a stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Registers {
    /// Where it stopped: the instruction not run yet.
    pub pc: u16,
    /// The accumulator.
    pub a: u8,
    /// Index X.
    pub x: u8,
    /// Index Y.
    pub y: u8,
    /// The status register.
    pub p: u8,
    /// The stack pointer.
    pub s: u8,
}

/// What came back after a command was sent to a running robot.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// Its answer (through the carriage return).
    Answer(Vec<u8>),
    /// A breakpoint stopped it first.
    Stopped(Registers),
    /// Nothing in the time waited.
    Silent,
}

/// Attempts at a frame exchange, or at a write read back, before the line
/// is given up: as many as an upload makes (`UploadOptions::max_writes`).
/// On a line that loses or flips one byte in a hundred, a frame of twenty
/// is lost one time in three; four attempts gave up now and then in a
/// session, and a `quit` that gave up left the robot stopped (hostile10
/// F13).
const ATTEMPTS: u32 = 8;

/// Bytes written with the ROM's commands before they are read back.
const ROM_PIECE: usize = 32;

/// Bytes a stopped stub is asked for at once.
const READ_CHUNK: usize = frame::READ_MAX;

/// Garbled frames, or frames and pieces of text that are neither a stop
/// nor an answer, taken while waiting for one before the wait gives up:
/// a robot that sends garbage for ever must not hold the host for ever.
const STRIKES: u32 = 8;

/// How often a wait looks at the interrupt flag.
const SLICE: Duration = Duration::from_millis(100);

/// A debugger attached to a robot.
#[derive(Debug)]
pub struct RobotDebug<T> {
    client: Client<T>,
    stub: StubPlan,
    image: UploadImage,
    /// Breakpoints by address, each with its trampoline's slot.
    breakpoints: BTreeMap<u16, (Patch, usize)>,
    /// The registers while stopped.
    stopped: Option<Registers>,
    rx: Vec<u8>,
    margin: Duration,
    /// `HOOK_UNKNOWN`'s address.
    hook: u16,
    /// The part of an answer that came before a stop.
    partial: Vec<u8>,
    /// The trampoline of the breakpoint being patched in.
    pending: Option<(u16, Vec<u8>)>,
    /// What attach found of an earlier session.
    recovery: Recovery,
    /// Where the image's instructions start, when known (sorted).
    starts: Option<Vec<u16>>,
    /// A step's breakpoints, taken out at the next stop.
    temporary: Vec<u16>,
    /// A step run alone in a trampoline: where its `JSR` back into the
    /// stub is, and the program's address it stands for (the instruction
    /// after the one stepped).
    alone: Option<(u16, u16)>,
    /// A stop that came while the host was busy with something else (a
    /// breakpoint in code the robot runs on its own, hit while a patch
    /// was read back): told by the next [`RobotDebug::poll`] or
    /// [`RobotDebug::wait_event`], or [`RobotDebug::take_unasked`].
    unasked: Option<Registers>,
    /// Set by a signal: a wait for the robot ends at once.
    interrupt: Option<Arc<AtomicBool>>,
    /// What a person's writes and registers may change.
    guard: Guard,
    /// The ROM the image was linked against (its hooks, for detach).
    profile: RomProfile,
    /// Where the RAM loader that wrote the stub went, if it did.
    loader: Option<crate::LoaderPlan>,
}

/// The pieces of `bytes` (at `address`) that `held` (read there) does not
/// hold, adjacent ones as one area.
fn differing(address: u16, bytes: &[u8], held: &[u8]) -> Vec<crate::image::Area> {
    let mut areas: Vec<crate::image::Area> = Vec::new();
    for (i, piece) in bytes.chunks(ROM_PIECE).enumerate() {
        let start = i * ROM_PIECE;
        if held.get(start..start + piece.len()) == Some(piece) {
            continue;
        }
        crate::delta::push(&mut areas, address.wrapping_add(start as u16), piece);
    }
    areas
}

/// What attach found of an earlier session that ended without detaching
/// (its process killed), and what it did: the earlier breakpoints are
/// taken out, not adopted (their numbers and conditions died with that
/// session), and a stopped robot stays stopped where it was.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Recovery {
    /// The robot was stopped in the stub: its registers. It stays
    /// stopped; `resume` lets it go on.
    pub stopped: Option<Registers>,
    /// The stub was still hooked on `HOOK_UNKNOWN`.
    pub hooked: bool,
    /// Where `HOOK_UNKNOWN` pointed when that was inside the stub's code
    /// but not its handler (by hand, or a glitch): hooked at the handler
    /// again, so that the end of the session gives the hook back to what
    /// the stub chains to.
    pub hooked_inside: Option<u16>,
    /// `JSR`s into the stub left in the code: the image's bytes put back
    /// and read back.
    pub removed: Vec<u16>,
    /// Code bytes that differ from the image on a robot found stopped in
    /// the stub (changed at a stop, or by the program): taken as the
    /// robot's, so that the session can let it go on (hostile16 F2: the
    /// robot was refused as "not the image" and stayed stopped for good).
    pub changed: Vec<u16>,
    /// Bytes among the code that the running program changed while they
    /// were read (a counter kept there), and the three after each where
    /// the robot's differ from the image (that counter's higher bytes):
    /// not compared, and taken as the robot's, so that a breakpoint or a
    /// step there works on what the robot holds (hostile19 F3: a wrong
    /// image's byte there was put back by a breakpoint's removal).
    pub data_among_code: Vec<u16>,
    /// Of those, the bytes after a changing one that differ from the image
    /// (a counter's higher bytes, or another build's code): the robot's.
    pub differing_after: Vec<u16>,
}

impl Recovery {
    /// What [`Recovery::data_among_code`] holds, in a sentence, if it holds
    /// anything.
    #[must_use]
    pub fn data_note(&self) -> Option<String> {
        let changing: Vec<u16> = self
            .data_among_code
            .iter()
            .copied()
            .filter(|at| !self.differing_after.contains(at))
            .collect();
        (!changing.is_empty()).then(|| {
            let after = if self.differing_after.is_empty() {
                String::new()
            } else {
                format!(
                    "; {} after it differ from the image (its higher bytes, or another build's code): taken as the robot holds them",
                    crate::error::addresses_text(&self.differing_after)
                )
            };
            format!(
                "note: {} among the image's code changed while it was read, as the robot runs (a counter kept there): taken as the program's data, with the three bytes after it, and not compared{after}",
                crate::error::addresses_text(&changing)
            )
        })
    }

    /// Whether anything of an earlier session was found.
    #[must_use]
    pub fn found(&self) -> bool {
        self.stopped.is_some() || self.hooked || !self.removed.is_empty()
    }

    /// What was found and done, in a sentence; empty when nothing was.
    #[must_use]
    pub fn describe(&self) -> String {
        if !self.found() {
            return String::new();
        }
        let mut parts = Vec::new();
        if let Some(registers) = self.stopped {
            parts.push(format!(
                "the robot was stopped in its stub at ${:04X} and stays stopped there (`continue` lets it go on)",
                registers.pc
            ));
        }
        match (self.hooked, self.hooked_inside) {
            (true, Some(at)) => parts.push(format!(
                "HOOK_UNKNOWN led to ${at:04X}, inside its stub's code rather than to its handler (hooked at the handler again)"
            )),
            (true, None) => {
                parts.push("its stub was still hooked on HOOK_UNKNOWN (hooked again)".to_owned());
            }
            (false, _) => {}
        }
        if !self.changed.is_empty() {
            // recheck16 F2: every place named, not the first alone.
            let n = self.changed.len();
            parts.push(format!(
                "its code differs from the image in {n} {} ({}; changed while it ran or at a stop): taken as the robot's, so that it can go on; upload the image again to put {} back",
                if n == 1 { "byte" } else { "bytes" },
                crate::error::addresses_text(&self.changed),
                if n == 1 { "it" } else { "them" },
            ));
        }
        if !self.removed.is_empty() {
            let at: Vec<String> = self.removed.iter().map(|a| format!("${a:04X}")).collect();
            parts.push(format!(
                "its breakpoints at {} were taken out: the image's bytes put back and read back",
                at.join(", ")
            ));
        }
        format!(
            "an earlier session did not detach (cleaned up, not adopted): {}",
            parts.join("; ")
        )
    }
}

impl<T: Transport> RobotDebug<T> {
    /// Attaches to the robot on `client` running `image` (as uploaded,
    /// linked against `profile`).
    ///
    /// Nothing is written before the robot is known to hold the image:
    /// first a frame to a stub (a running robot ignores it) tells whether
    /// the robot is stopped in one left by an earlier session, then the
    /// robot's code is read and compared with the image. The bytes of
    /// the image's chain slots are the robot's (the uploader filled them),
    /// and are taken from it. A `JSR` into the stub left in the code by a
    /// session that died is taken out (the image's bytes put back and
    /// read back), and a robot found stopped stays stopped, its PC at the
    /// image's instruction: [`RobotDebug::recovery`] says what was found.
    /// Then the stub is linked where the image leaves room, written
    /// through the RAM loader's summed frames (with the ROM's commands,
    /// read back, where the image leaves the loader no room; only its
    /// code, through the stub's frames, when it is the one running), and
    /// hooked into `HOOK_UNKNOWN` ahead of what was there, every hook read
    /// back whole.
    ///
    /// # Errors
    /// The line's errors, [`StubError::NotTheImage`] (nothing written),
    /// [`StubError::NoRoom`], [`StubError::Verify`], [`StubError::Refused`]
    /// for a robot stopped in a stub that is not this image's.
    pub fn attach(client: Client<T>, profile: &RomProfile, image: UploadImage) -> StubResult<Self> {
        let hook = profile.hook_unknown;
        // A first guess at where the stub goes, for the frame that asks
        // whether one is stopped (any stub answers it). Where it goes
        // depends on what the robot has installed, read below; what it
        // chains to is learnt after that.
        let guess = StubPlan::place(profile, &image, hook)?;
        let margin = client.config().margin * 4;
        let mut debug = RobotDebug {
            client,
            stub: guess,
            image,
            breakpoints: BTreeMap::new(),
            stopped: None,
            rx: Vec::new(),
            margin,
            hook,
            partial: Vec::new(),
            pending: None,
            recovery: Recovery::default(),
            loader: None,
            starts: None,
            temporary: Vec::new(),
            alone: None,
            unasked: None,
            interrupt: None,
            guard: Guard::new(profile),
            profile: profile.clone(),
        };
        let stopped = debug.probe()?.is_some();
        if stopped {
            // Reads go through the stopped stub's frames from here.
            debug.stopped = Some(Registers::default());
        } else {
            debug.client.probe()?;
        }
        let (taken, installed) = debug.taken(profile)?;
        let placed = StubPlan::place_beside(profile, &debug.image, hook, &taken)?;
        debug.stub = placed.clone();
        if stopped {
            let block = debug.read(placed.regs, 8)?;
            let mut registers = debug
                .take_stop(&block)
                .ok_or_else(|| stopped_in_another_stub(placed.address))?;
            // hostile15 F6: stopped after a step run alone in a
            // trampoline, whose session died: the program goes on where
            // the trampoline's `JMP` after the `JSR` says.
            let tramps = placed.tramps..placed.tramps + TRAMPOLINE_LEN * TRAMPOLINES as u16;
            if tramps.contains(&registers.pc) {
                let code = debug.read(registers.pc, 6)?;
                if let Some(next) = patch::alone_next(&code, placed.entry) {
                    registers.pc = next;
                    debug.stopped = Some(registers);
                }
            }
            debug.recovery.stopped = Some(registers);
        }
        let jump = debug.read(hook, 3)?;
        let target = u16::from_le_bytes([jump[1], jump[2]]);
        let left = if !stopped
            && target != placed.handler
            && profile.reset_target(isa::objfmt::HookKind::Unknown) != Some(target)
        {
            super::left::at_target(&mut debug.client, profile, target)?
        } else {
            None
        };
        // A hook into the middle of this image's own stub is that stub
        // hooked: chaining to it would make the new stub run itself.
        debug.recovery.hooked_inside = left
            .filter(|left| left.address == placed.address)
            .map(|_| target);
        if let Some(other) = left.filter(|left| left.address != placed.address) {
            // Chaining to it would keep it, and its breakpoints, reachable.
            return Err(StubError::Refused {
                what: "attaching".into(),
                reason: format!(
                    "HOOK_UNKNOWN leads to a debug stub at ${:04X}, not where this image's goes (${:04X}): a session with another image, or beside other extensions, left it; attach with that image (and `quit`), or reset the robot",
                    other.address, placed.address
                ),
            });
        }
        let code_len = usize::from(placed.code_end - placed.address);
        let code = if debug.stopped.is_none() {
            // Read once where it is there already (a session before this
            // one put it there), as the stub but for `JMP PREV`'s operand.
            let expected: Vec<Option<u8>> = placed.bytes[..code_len]
                .iter()
                .enumerate()
                .map(|(i, &byte)| (i < code_len - 2).then_some(byte))
                .collect();
            debug.client.read_expecting(placed.address, &expected)?
        } else {
            debug.read(placed.address, code_len)?
        };
        // The stub's code but for `JMP PREV`'s operand, its last two bytes.
        let present = code[..code_len - 2] == placed.bytes[..code_len - 2];
        if debug.stopped.is_some() && !present {
            return Err(stopped_in_another_stub(placed.address));
        }
        if debug.recovery.hooked_inside.is_none()
            && target != placed.handler
            && present
            && placed.contains(target)
        {
            // hostile10 F11: the hook at the stub's own `JMP PREV` or its
            // data, which a few bytes there cannot tell as a stub's: the
            // code where this image's stub goes is its stub, hooked.
            debug.recovery.hooked_inside = Some(target);
        }
        debug.recovery.hooked = target == placed.handler || debug.recovery.hooked_inside.is_some();
        let previous = if debug.recovery.hooked {
            if !present {
                return Err(StubError::NotTheImage {
                    address: placed.address,
                    expected: hex(&placed.bytes[..8]),
                    found: hex(&code[..8]),
                });
            }
            u16::from_le_bytes([code[code_len - 2], code[code_len - 1]])
        } else {
            target
        };
        debug.stub = StubPlan::place_beside(profile, &debug.image, previous, &taken)?;
        let chained = debug.stub.clone();
        if debug.stopped.is_none()
            && let Some(path) = crate::chain::comes_back(
                &mut debug.client,
                profile,
                &[],
                (isa::objfmt::HookKind::Unknown, previous),
                &|at| chained.contains(at),
            )?
        {
            // The stub would chain to code that jumps back into it.
            return Err(StubError::Refused {
                what: "attaching".into(),
                reason: format!(
                    "HOOK_UNKNOWN leads {path}, into where the stub goes (${:04X}-${:04X}): chained to it, the stub would run in a loop at the robot's next unknown command; point HOOK_UNKNOWN back at the ROM (`scorpion restore` of a backup taken before, or reset the robot), upload the image again and attach",
                    chained.address,
                    u32::from(chained.address) + chained.bytes.len() as u32 - 1
                ),
            });
        }
        if debug.stopped.is_none() {
            // Nothing is written before: code a hook runs that no entry
            // lists is refused (hostile26 F4, hostile28 F1, F2); this
            // image's stub, where it goes, is not such code.
            let stub = |at: u16| present && placed.contains(at);
            super::unlisted::refuse(&mut debug.client, profile, &installed, &debug.image, &stub)?;
        }
        // The image's code compared first: a robot that does not hold it is
        // told so with the bytes that differ, not as "not installed"
        // (fresh14 F9).
        let mut leftovers = debug.check_image()?;
        if debug.stopped.is_none() {
            debug.refuse_unreachable(profile, &installed, previous)?;
        }
        if stopped || debug.recovery.hooked {
            // A session with another image may have left breakpoints in
            // its own extension, which this image's bytes do not show.
            let elsewhere = debug.left_elsewhere(&taken)?;
            leftovers.extend(elsewhere);
        }
        let stub = debug.stub.clone();
        if debug.stopped.is_some() {
            // The stub runs: its data (the stop's registers) is kept.
            debug.write_verified(stub.address, &stub.bytes[..code_len])?;
        } else {
            let held: &[u8] = if stub.address == placed.address {
                &code
            } else {
                &[]
            };
            let todo = differing(stub.address, &stub.bytes, held);
            let loader = if todo.is_empty() {
                None
            } else {
                super::summed::write_summed(
                    &mut debug.client,
                    profile,
                    (&debug.image, &installed),
                    &todo,
                )?
            };
            let summed = loader.is_some();
            debug.loader = loader;
            if !summed {
                debug.rom_write_over(stub.address, &stub.bytes, held)?;
            }
        }
        if debug.stopped.is_some() {
            debug.write_verified(hook + 1, &stub.handler.to_le_bytes())?;
        } else {
            crate::hooks::switch_hook_among(
                &mut debug.client,
                profile,
                hook,
                stub.handler,
                ATTEMPTS,
            )?;
        }
        for (address, original) in leftovers {
            debug.patch(address, original)?;
            debug.recovery.removed.push(address);
        }
        Ok(debug)
    }

    /// Refuses an image that is in RAM but not installed (fresh10 F14: a
    /// `/1R` cleared the table and the hooks, an upload did not finish):
    /// none of its hooks' chains leads to its handler, so a breakpoint in
    /// it would never be hit. `unknown` is what the stub will chain to.
    fn refuse_unreachable(
        &mut self,
        profile: &RomProfile,
        installed: &[Installed],
        unknown: u16,
    ) -> StubResult<()> {
        let records: Vec<(HookKind, u16)> = self
            .image
            .hooks()
            .iter()
            .map(|record| (record.kind, record.handler))
            .collect();
        for (kind, handler) in records {
            let target = if kind == HookKind::Unknown {
                unknown
            } else {
                let jump = self.read(profile.hook_address(kind), 3)?;
                u16::from_le_bytes([jump[1], jump[2]])
            };
            let reached = crate::chain::comes_back(
                &mut self.client,
                profile,
                installed,
                (kind, target),
                &|at| at == handler,
            )?;
            if reached.is_none() {
                return Err(StubError::Refused {
                    what: "attaching".into(),
                    reason: format!(
                        "the image is in RAM but not installed: {}'s chain (from ${target:04X}) does not lead to its handler ${handler:04X}, so no breakpoint in it would be hit; upload it (`scorpion upload ELF --port PORT`) and attach again",
                        kind.rom_symbol()
                    ),
                });
            }
        }
        Ok(())
    }

    /// What the stub must not go over besides the image: the extensions
    /// the robot's table names (read from the robot) and the RAM loader's
    /// memory (an upload of the image puts it there, and may find it
    /// again).
    fn taken(
        &mut self,
        profile: &RomProfile,
    ) -> StubResult<(Vec<RangeInclusive<u16>>, Vec<Installed>)> {
        let installed = crate::table::installed_with(profile, &mut |at, len| self.read(at, len))?;
        let mut taken: Vec<RangeInclusive<u16>> = installed
            .iter()
            .flat_map(|installed| installed.extents.iter().cloned())
            .collect();
        let rates = (self.client.transport().baud(), crate::loader::FAST_BAUD);
        if let Some(loader) = crate::loader::loader_plan(profile, &self.image, rates)? {
            let code = &loader.code;
            taken.push(code.address..=code.address.wrapping_add(code.bytes.len() as u16 - 1));
            taken.push(u16::from(*loader.zero_page.start())..=u16::from(*loader.zero_page.end()));
        }
        Ok((taken, installed))
    }

    /// Whether the robot is stopped in a stub, wherever it is: `Some`
    /// when a stub answered a frame (which a running robot ignores), with
    /// the registers when they were where this stub keeps them.
    fn probe(&mut self) -> StubResult<Option<Option<Registers>>> {
        let regs = self.stub.regs.to_le_bytes();
        let payload = [b'R', regs[0], regs[1], 8];
        // Twice when nothing answers (a running robot ignores the frame);
        // a stub's `N` says it is there, stopped: asked until it answers
        // (seed 75 of the noisy-line runs: a lost frame, then an `N`, and
        // `quit` took the robot for running and left it stopped).
        let mut nak = false;
        for attempt in 0..ATTEMPTS {
            if attempt >= 2 && !nak {
                break;
            }
            self.rx.clear();
            self.client.transport().clear_input()?;
            self.client.send_raw(&frame::encode(&payload))?;
            let wait =
                char_time(2 * payload.len() + 32, self.client.transport().baud()) + self.margin;
            let deadline = self.client.transport().now() + wait;
            loop {
                let now = self.client.transport().now();
                if now >= deadline {
                    break;
                }
                match self.next_heard(deadline - now)? {
                    Some(Heard::Frame(reply)) => {
                        if let [b'M', lo, hi, rest @ ..] = reply.as_slice() {
                            if [*lo, *hi] != regs || rest.len() != 8 {
                                // A late reply to an earlier request.
                                continue;
                            }
                            let registers = self.take_stop(rest);
                            self.stopped = None;
                            return Ok(Some(registers));
                        }
                        if let Some(registers) = self.take_stop(&reply) {
                            self.stopped = None;
                            return Ok(Some(Some(registers)));
                        }
                        if reply == [b'N'] {
                            // A stub, which heard the frame damaged: again.
                            nak = true;
                            break;
                        }
                        return Err(stopped_in_another_stub(self.stub.address));
                    }
                    Some(_) => {}
                    None => break,
                }
            }
        }
        self.rx.clear();
        if nak {
            return Err(StubError::Garbled {
                asked: "the registers of a stop (the stub answered `N`: it is stopped)".into(),
                expected: "a frame with a good sum".into(),
                found: "N".into(),
            });
        }
        Ok(None)
    }

    /// Looks for a stop the host did not hear (its frame lost on a noisy
    /// line): while the host takes the robot for running, one frame to the
    /// stub, which only a stopped stub answers. A stop found is kept to be
    /// told ([`RobotDebug::take_unasked`]) and the step's temporary
    /// breakpoints come out, as at any stop (hostile10 F8: `regs`, `step`
    /// and `continue` were refused as "running" at a stop whose frame lost
    /// a byte).
    ///
    /// # Errors
    /// The line's errors; a stop in another stub.
    pub fn look_for_stop(&mut self) -> StubResult<Option<Registers>> {
        if let Some(registers) = self.stopped {
            return Ok(Some(registers));
        }
        let Some(registers) = self.probe_stopped()? else {
            return Ok(None);
        };
        self.found_stop(registers)?;
        Ok(Some(registers))
    }

    /// Whether the robot is stopped in this stub: its registers.
    fn probe_stopped(&mut self) -> StubResult<Option<Registers>> {
        match self.probe()? {
            None => Ok(None),
            Some(Some(registers)) => Ok(Some(registers)),
            Some(None) => Err(stopped_in_another_stub(self.stub.address)),
        }
    }

    /// Reads the robot's code where the image has it and compares: the
    /// chain slots' bytes taken from the robot, a `JSR` into the stub over
    /// the image's bytes kept aside (a breakpoint an earlier session left:
    /// its address and the image's bytes), any other difference refused.
    fn check_image(&mut self) -> StubResult<Vec<(u16, [u8; 3])>> {
        let slots: Vec<u16> = self
            .image
            .hooks()
            .iter()
            .filter_map(|record| record.chain)
            .collect();
        let entry = self.stub.entry.to_le_bytes();
        let call = [JSR, entry[0], entry[1]];
        let mut leftovers = Vec::new();
        let mut adopted = Vec::new();
        let slot_bytes = self.image.chain_slot_bytes();
        for area in self.image.areas().to_vec() {
            let (mut found, data) = self.read_code(&area, &slots)?;
            // Only code is compared: the program may have changed its
            // data (a `poke` of the README's session did), and a `JSR`
            // into the stub is patched only into code.
            let code: Vec<bool> = (0..found.len())
                .map(|i| self.image.is_code(area.address.wrapping_add(i as u16)))
                .collect();
            let mut i = 0;
            while i + 3 <= found.len() {
                if code[i..i + 3].iter().all(|&c| c)
                    && found[i..i + 3] == call
                    && area.bytes[i..i + 3] != call
                {
                    let at = area.address.wrapping_add(i as u16);
                    let mut original = [area.bytes[i], area.bytes[i + 1], area.bytes[i + 2]];
                    if self.stopped.is_some()
                        && let Some(copy) = self.program_copy(at)?
                    {
                        // hostile16 F3: found stopped, the program runs
                        // what the trampoline holds, a `poke` at the stop
                        // included: that is put back (and told as a
                        // change below), as `quit` would have.
                        original.copy_from_slice(&copy[..3]);
                    } else if (0..3).any(|k| slot_bytes.contains(&at.wrapping_add(k))) {
                        // A chain slot's bytes under the JSR are the
                        // robot's (the uploader wrote them), not the
                        // image's: the trampoline's copy on the robot
                        // holds them.
                        let copy = self.displaced_copy(at, &slot_bytes)?;
                        original.copy_from_slice(&copy[..3]);
                    }
                    leftovers.push((at, original));
                    found[i..i + 3].copy_from_slice(&original);
                    i += 3;
                } else {
                    i += 1;
                }
            }
            for &at in &slot_bytes {
                if area.contains(at) {
                    let i = usize::from(at - area.address);
                    adopted.push((at, found[i]));
                    found[i] = area.bytes[i];
                }
            }
            for &at in &data {
                let i = usize::from(at.wrapping_sub(area.address));
                if found[i] != area.bytes[i] {
                    adopted.push((at, found[i]));
                    found[i] = area.bytes[i];
                    self.recovery.differing_after.push(at);
                }
            }
            self.recovery.data_among_code.extend(data);
            let differs = |i: &usize| code[*i] && found[*i] != area.bytes[*i];
            if self.stopped.is_some() {
                // Found stopped in the stub: it must be let go on whatever
                // its code now holds.
                for i in (0..found.len()).filter(differs) {
                    let at = area.address.wrapping_add(i as u16);
                    self.recovery.changed.push(at);
                    adopted.push((at, found[i]));
                }
            } else if let Some(i) = (0..found.len()).find(differs) {
                let end = (i..found.len().min(i + 4))
                    .take_while(|&j| code[j])
                    .last()
                    .map_or(i + 1, |j| j + 1);
                return Err(StubError::NotTheImage {
                    address: area.address.wrapping_add(i as u16),
                    expected: hex(&area.bytes[i..end]),
                    found: hex(&found[i..end]),
                });
            }
        }
        for (at, byte) in adopted {
            self.image.set_byte(at, byte);
        }
        Ok(leftovers)
    }

    /// The robot's bytes of `area` where the image has code (its data
    /// is the image's, unread), each run of code read once when it is the
    /// image's (`Client::read_expecting`; the chain slots `slots`, which
    /// the robot holds as the uploader filled them, may be anything): a
    /// robot that holds the image is read at half the line time, and a
    /// difference is read until two answers agree, so that it is named
    /// with the robot's bytes. Bytes among the code that the running
    /// program keeps changing (a counter kept in its code section,
    /// hostile17 F4) are data, not code: they are given as the image's,
    /// and named with the three after each (that counter's higher bytes,
    /// given as the robot holds them) where those differ from the image.
    fn read_code(
        &mut self,
        area: &crate::image::Area,
        slots: &[u16],
    ) -> StubResult<(Vec<u8>, Vec<u16>)> {
        /// The longest counter a byte that keeps changing is taken to be
        /// the lowest byte of (little-endian, as the 6502 counts).
        const COUNTER_LEN: usize = 4;
        let mut found = area.bytes.clone();
        let mut data = Vec::new();
        let slot = |address: u16| {
            slots
                .iter()
                .any(|&slot| address == slot || address == slot.wrapping_add(1))
        };
        let code: Vec<bool> = (0..area.bytes.len())
            .map(|i| {
                let address = area.address.wrapping_add(i as u16);
                self.image.is_code(address) || slot(address)
            })
            .collect();
        let mut i = 0;
        while i < code.len() {
            if !code[i] {
                i += 1;
                continue;
            }
            let end = (i..code.len()).find(|&j| !code[j]).unwrap_or(code.len());
            let at = area.address.wrapping_add(i as u16);
            let bytes = if self.stopped.is_some() {
                // Through the stub's frames, which carry their own sum.
                self.read(at, end - i)?
            } else {
                let expected: Vec<Option<u8>> = (i..end)
                    .map(|j| (!slot(area.address.wrapping_add(j as u16))).then_some(area.bytes[j]))
                    .collect();
                let mut read = self.client.read_live_expecting(at, &expected)?;
                for changing in read.changing {
                    let k = usize::from(changing.wrapping_sub(at));
                    read.bytes[k] = area.bytes[i + k];
                    data.push(changing);
                    // recheck18 F3: the bytes after it, up to a 32-bit
                    // counter's, are its higher bytes, which move seldom
                    // and may hold still while they are read. A chain
                    // slot's bytes are the robot's anyway.
                    let counter = k + 1..(k + COUNTER_LEN).min(end - i);
                    for ((image, robot), after) in expected[counter.clone()]
                        .iter()
                        .zip(&read.bytes[counter.clone()])
                        .zip(counter.map(|j| at.wrapping_add(j as u16)))
                    {
                        if image.is_some_and(|image| image != *robot) && !data.contains(&after) {
                            data.push(after);
                        }
                    }
                }
                read.bytes
            };
            found[i..end].copy_from_slice(&bytes);
            i = end;
        }
        data.sort_unstable();
        data.dedup();
        Ok((found, data))
    }

    /// Breakpoints an earlier session left outside this image (a session
    /// with another image installed beside it), with the bytes they
    /// displaced: each found by a trampoline of the stub (the displaced
    /// instructions, then a `JMP` back past them) whose place, in memory an
    /// installed extension owns (`taken`), still holds the `JSR` into the
    /// stub. Read before the stub is written again.
    fn left_elsewhere(&mut self, taken: &[RangeInclusive<u16>]) -> StubResult<Vec<(u16, [u8; 3])>> {
        let entry = self.stub.entry.to_le_bytes();
        let call = [JSR, entry[0], entry[1]];
        let len = TRAMPOLINE_LEN as usize;
        let tramps = self.read(self.stub.tramps, TRAMPOLINES * len)?;
        let mut found: Vec<(u16, [u8; 3])> = Vec::new();
        for copy in tramps.chunks(len) {
            let Some((at, displaced)) = patch::read_trampoline(copy, self.stub.entry) else {
                continue;
            };
            let owned = taken
                .iter()
                .any(|extent| extent.contains(&at) && extent.contains(&at.wrapping_add(2)));
            if !owned || self.image.contains(at) || found.iter().any(|(seen, _)| *seen == at) {
                continue;
            }
            if self.read(at, 3)? == call {
                found.push((at, [displaced[0], displaced[1], displaced[2]]));
            }
        }
        Ok(found)
    }

    /// The displaced bytes of each trampoline of the stub for a
    /// breakpoint at `address` that displaces `len` bytes, as the robot
    /// holds them (decoded: the displaced bytes, then `JMP` past them).
    fn trampoline_copies(&mut self, address: u16, len: usize) -> StubResult<Vec<Vec<u8>>> {
        let tramps = self.read(self.stub.tramps, TRAMPOLINES * TRAMPOLINE_LEN as usize)?;
        Ok(tramps
            .chunks(TRAMPOLINE_LEN as usize)
            .filter_map(|copy| patch::read_trampoline(copy, self.stub.entry))
            .filter(|(at, copy)| *at == address && copy.len() == len)
            .map(|(_, copy)| copy)
            .collect())
    }

    /// The bytes the one trampoline of the stub for a breakpoint at
    /// `address` runs in their place (the program's, as a `poke` at a stop
    /// left them), when exactly one trampoline is for it and it displaces
    /// as many bytes as a breakpoint there does; `None` else.
    fn program_copy(&mut self, address: u16) -> StubResult<Option<Vec<u8>>> {
        let Ok(plan) = patch::plan(address, &self.image, &[]) else {
            return Ok(None);
        };
        let mut copies = self.trampoline_copies(address, plan.displaced.len())?;
        copies.sort_unstable();
        copies.dedup();
        Ok((copies.len() == 1).then(|| copies.remove(0)))
    }

    /// The bytes a breakpoint an earlier session left at `address`
    /// displaced, as the robot held them: its trampoline's copy in the
    /// stub, found by that copy and the image's bytes but for the chain
    /// slots' (`slot_bytes`).
    fn displaced_copy(&mut self, address: u16, slot_bytes: &[u16]) -> StubResult<Vec<u8>> {
        let patch = patch::plan(address, &self.image, &[])?;
        let len = patch.displaced.len();
        self.trampoline_copies(address, len)?
            .into_iter()
            .find(|copy| {
                (0..len).all(|k| {
                    slot_bytes.contains(&address.wrapping_add(k as u16))
                        || copy[k] == patch.displaced[k]
                })
            })
            .ok_or_else(|| StubError::Refused {
                what: "attaching".into(),
                reason: format!(
                    "an earlier session's breakpoint at ${address:04X} covers a chain slot, and no trampoline of the stub at ${:04X} holds the robot's bytes it displaced: reset the robot and upload the image again",
                    self.stub.address
                ),
            })
    }

    /// Tells where every instruction of the image starts (a built
    /// image's line tables start a line at each): a breakpoint anywhere
    /// else in the image is refused, since its `JSR` would cut an
    /// instruction in two. Without it, only the image's decoding guides.
    pub fn set_instruction_starts(&mut self, mut starts: Vec<u16>) {
        starts.sort_unstable();
        starts.dedup();
        self.starts = Some(starts);
    }

    /// The image the robot runs, as attached.
    #[must_use]
    pub fn image(&self) -> &UploadImage {
        &self.image
    }

    /// What attach found of an earlier session, and did about it.
    #[must_use]
    pub fn recovery(&self) -> &Recovery {
        &self.recovery
    }

    /// The stub as placed.
    #[must_use]
    pub fn stub(&self) -> &StubPlan {
        &self.stub
    }

    /// Where the RAM loader that wrote the stub went (and stays), if the
    /// stub went in through it.
    #[must_use]
    pub fn loader(&self) -> Option<&crate::LoaderPlan> {
        self.loader.as_ref()
    }

    /// The registers, when stopped.
    #[must_use]
    pub fn stopped(&self) -> Option<Registers> {
        self.stopped
    }

    /// The breakpoints' addresses.
    pub fn breakpoints(&self) -> impl Iterator<Item = u16> + '_ {
        self.breakpoints.keys().copied()
    }

    /// The client, for reads with `/7R` while the robot runs.
    pub fn client(&mut self) -> &mut Client<T> {
        &mut self.client
    }

    /// Writes `bytes` at `address` with `/9W` (`/7W` for an odd last
    /// byte) and reads them back, writing again what differs: a piece at
    /// a time, so that answers keep coming while the writes go out.
    ///
    /// Two bytes lost on the line (one inside a command, and the next
    /// command's slash) can make a command of the ROM that writes
    /// elsewhere: so the whole range is read once more after the last
    /// piece, and written again where it differs.
    fn rom_write_verified(&mut self, address: u16, bytes: &[u8]) -> StubResult<()> {
        self.rom_write_over(address, bytes, &[])
    }

    /// [`RobotDebug::rom_write_verified`] where the robot is known to hold
    /// `held` from `address` (read already): pieces that hold their bytes
    /// are not written (the read back at the end covers them all).
    fn rom_write_over(&mut self, address: u16, bytes: &[u8], held: &[u8]) -> StubResult<()> {
        for (i, piece) in bytes.chunks(ROM_PIECE).enumerate() {
            let start = i * ROM_PIECE;
            if held.get(start..start + piece.len()) == Some(piece) {
                continue;
            }
            self.rom_write_piece(address.wrapping_add(start as u16), piece)?;
        }
        let expected: Vec<Option<u8>> = bytes.iter().copied().map(Some).collect();
        for _ in 0..ATTEMPTS {
            let found = self.client.read_expecting(address, &expected)?;
            if found == bytes {
                return Ok(());
            }
            for (i, piece) in bytes.chunks(ROM_PIECE).enumerate() {
                let start = i * ROM_PIECE;
                if found[start..start + piece.len()] != *piece {
                    self.rom_write_piece(address.wrapping_add(start as u16), piece)?;
                }
            }
        }
        self.check(address, bytes)
    }

    /// Reads `bytes`' range back: [`StubError::Verify`] at the first
    /// difference.
    fn check(&mut self, address: u16, bytes: &[u8]) -> StubResult<()> {
        let found = self.client.read_memory(address, bytes.len())?;
        match (0..bytes.len()).find(|&i| found[i] != bytes[i]) {
            None => Ok(()),
            Some(i) => Err(StubError::Verify {
                address: address.wrapping_add(i as u16),
                expected: hex(&bytes[i..bytes.len().min(i + 8)]),
                found: hex(&found[i..bytes.len().min(i + 8)]),
            }),
        }
    }

    /// `bytes` at `address` with `/9W` (`/7W` for an odd last byte), sent
    /// once, not read back.
    fn rom_write_piece_once(&mut self, address: u16, bytes: &[u8]) -> StubResult<()> {
        let mut text = Vec::new();
        for (i, pair) in bytes.chunks(2).enumerate() {
            let here = address.wrapping_add(2 * i as u16);
            match pair {
                [a, b] => text.extend(format!("/9W{here:04X}{a:02X}{b:02X}").bytes()),
                [a] => text.extend(format!("/7W{here:04X}{a:02X}").bytes()),
                _ => {}
            }
        }
        Ok(self.client.send_raw(&text)?)
    }

    fn rom_write_piece(&mut self, address: u16, bytes: &[u8]) -> StubResult<()> {
        let mut todo = vec![(address, bytes.to_vec())];
        for _ in 0..ATTEMPTS {
            for (at, part) in &todo {
                self.rom_write_piece_once(*at, part)?;
            }
            let expected: Vec<Option<u8>> = bytes.iter().copied().map(Some).collect();
            let found = self.client.read_expecting(address, &expected)?;
            todo = (0..bytes.len())
                .filter(|&i| found[i] != bytes[i])
                .map(|i| (address.wrapping_add(i as u16), vec![bytes[i]]))
                .collect();
            if todo.is_empty() {
                return Ok(());
            }
        }
        self.check(address, bytes)
    }

    /// Sets a breakpoint at `address`; `entries` are the addresses code
    /// may jump to (labels, the targets of branches, jumps and calls), which a patch must not cover
    /// past its first instruction.
    ///
    /// # Errors
    /// [`StubError::Refused`] with the reason (the ROM, inside an
    /// instruction, one there already, a branch displaced, a jump target
    /// covered, no trampoline free, overlapping another breakpoint); the
    /// line's errors.
    pub fn set_breakpoint(&mut self, address: u16, entries: &[u16]) -> StubResult<()> {
        let refuse = |reason: String| StubError::Refused {
            what: format!("a breakpoint at ${address:04X}"),
            reason,
        };
        if self.breakpoints.contains_key(&address) {
            return Err(refuse("one is there already".into()));
        }
        if let Some(starts) = &self.starts
            && self.image.contains(address)
            && starts.binary_search(&address).is_err()
        {
            return Err(refuse(
                "no instruction of the image starts there (its line tables start a line at every instruction), and a JSR there would cut one in two".into(),
            ));
        }
        let patch = patch::plan(address, &self.image, entries)?;
        for (other, _) in self.breakpoints.values() {
            let overlaps = |a: &Patch, b: &Patch| {
                u32::from(a.address) < u32::from(b.address) + 3
                    && u32::from(b.address) < u32::from(a.address) + a.displaced.len() as u32
            };
            if overlaps(&patch, other) || overlaps(other, &patch) {
                return Err(refuse(format!(
                    "its bytes overlap the breakpoint at ${:04X}",
                    other.address
                )));
            }
        }
        let slot = self
            .free_trampoline()
            .ok_or_else(|| refuse(format!("the stub holds {TRAMPOLINES} breakpoints at once")))?;
        // The trampoline first, verified: the JSR can only reach it after.
        let trampoline = self.stub.trampoline(slot);
        self.write_verified(trampoline, &patch.trampoline)?;
        let entry = self.stub.entry.to_le_bytes();
        self.pending = Some((trampoline, patch.trampoline.clone()));
        let call = [JSR, entry[0], entry[1]];
        let patched = self.patch(address, call);
        self.pending = None;
        if let Err(error) = patched {
            // The JSR may be in all the same (its last read back lost): it
            // is recorded, so that it is taken out, unless the code reads
            // as the image's.
            if self
                .read(address, 3)
                .map_or(true, |found| found != patch.original())
            {
                self.breakpoints.insert(address, (patch, slot));
            }
            return Err(error);
        }
        self.breakpoints.insert(address, (patch, slot));
        Ok(())
    }

    /// Removes the breakpoint at `address`: the image's bytes put back,
    /// read back and compared with the image.
    ///
    /// # Errors
    /// [`StubError::Refused`] when there is none; the line's errors.
    pub fn remove_breakpoint(&mut self, address: u16) -> StubResult<()> {
        let Some((patch, _)) = self.breakpoints.get(&address).cloned() else {
            return Err(StubError::Refused {
                what: format!("removing a breakpoint at ${address:04X}"),
                reason: "there is none there".into(),
            });
        };
        self.patch(address, patch.original())?;
        self.breakpoints.remove(&address);
        Ok(())
    }

    /// Writes three bytes at `address` in one go: in one frame when
    /// stopped, else staged in the stub, read back, and copied by `/1@`.
    /// Reads them back either way.
    fn patch(&mut self, address: u16, bytes: [u8; 3]) -> StubResult<()> {
        // Stopped on the way (by this very patch, it may be): the bytes go
        // in through the stub, in one frame.
        if let Some(()) = self.while_running(|d| d.patch_running(address, bytes))? {
            return Ok(());
        }
        self.write_verified(address, &bytes)
    }

    /// `running` done while the robot runs, when it does: `None` when it
    /// is stopped, or a stop came on the way ([`RobotDebug::caught`]), for
    /// the caller to do it through the stub instead.
    fn while_running<R>(
        &mut self,
        running: impl FnOnce(&mut Self) -> StubResult<R>,
    ) -> StubResult<Option<R>> {
        if self.stopped.is_some() {
            return Ok(None);
        }
        match running(self) {
            Ok(done) => Ok(Some(done)),
            Err(error) => {
                self.caught(error)?;
                Ok(None)
            }
        }
    }

    /// [`RobotDebug::patch`] while the robot runs.
    fn patch_running(&mut self, address: u16, bytes: [u8; 3]) -> StubResult<()> {
        let at = address.to_le_bytes();
        let staged = [at[0], at[1], bytes[0], bytes[1], bytes[2]];
        let trampoline = self
            .breakpoints
            .get(&address)
            .map(|(patch, slot)| (self.stub.trampoline(*slot), patch.trampoline.clone()))
            .or_else(|| self.pending.clone());
        for _ in 0..ATTEMPTS {
            self.rom_write_verified(self.stub.stage, &staged)?;
            // The stage's writes may have gone astray onto the trampoline
            // the JSR will reach: it is read again first.
            if bytes[0] == JSR
                && let Some((at, code)) = &trampoline
            {
                self.rom_write_verified(*at, code)?;
            }
            let command = Command::parse(b"/1@").map_err(crate::Error::Protocol)?;
            // The answer may be lost or garbled: the read back tells
            // (hostile10 F13: a garbled `@` ended `break` with the JSR in
            // the code and no record of it).
            match self.client.listen(&command) {
                Ok(_) | Err(crate::Error::Protocol(_) | crate::Error::NoAnswer { .. }) => {}
                Err(error) => return Err(error.into()),
            }
            let found = self.client.read_memory(address, 3)?;
            if found == bytes {
                return Ok(());
            }
        }
        let found = self.client.read_memory(address, 3)?;
        Err(StubError::Verify {
            address,
            expected: hex(&bytes),
            found: hex(&found),
        })
    }

    /// Writes `bytes` at `address` and reads them back: through the stub
    /// when stopped, else with the ROM's commands.
    ///
    /// # Errors
    /// [`StubError::Verify`], the line's errors.
    pub fn write_verified(&mut self, address: u16, bytes: &[u8]) -> StubResult<()> {
        if let Some(()) = self.while_running(|d| d.rom_write_verified(address, bytes))? {
            return Ok(());
        }
        for (i, part) in bytes.chunks(IN_MAX - 4).enumerate() {
            let at = address.wrapping_add((i * (IN_MAX - 4)) as u16);
            let mut payload = vec![
                b'W',
                at.to_le_bytes()[0],
                at.to_le_bytes()[1],
                part.len() as u8,
            ];
            payload.extend_from_slice(part);
            // The frame's sum misses two changes that cancel (a bit flipped
            // the same way in two digits: 20 09 FF went in as 22 09 FD,
            // seed 111 of the noisy-line runs, and a `continue` jammed the
            // CPU on it): the read back tells, and the write is sent again.
            let mut found = Vec::new();
            for _ in 0..ATTEMPTS {
                found = self.memory_exchange(&payload, at, part.len())?;
                if found == part {
                    break;
                }
            }
            if found != part {
                return Err(StubError::Verify {
                    address: at,
                    expected: hex(part),
                    found: hex(&found),
                });
            }
        }
        Ok(())
    }

    /// Reads `len` bytes at `address`: from the stub when stopped, else
    /// with `/7R` (each span read until two answers agree).
    ///
    /// # Errors
    /// The line's errors, a garbled reply.
    pub fn read(&mut self, address: u16, len: usize) -> StubResult<Vec<u8>> {
        Ok(self.read_maybe_live(address, len, false)?.bytes)
    }

    /// [`RobotDebug::read`], with [`Client::read_live`] while the robot
    /// runs when `live` (a counter the program keeps is read as it was at
    /// one moment, and named); nothing changes while it is stopped.
    fn read_maybe_live(&mut self, address: u16, len: usize, live: bool) -> StubResult<LiveRead> {
        let running = self.while_running(|d| {
            Ok(if live {
                d.client.read_live(address, len)?
            } else {
                LiveRead {
                    bytes: d.client.read_memory(address, len)?,
                    changing: Vec::new(),
                }
            })
        })?;
        if let Some(read) = running {
            return Ok(read);
        }
        Ok(LiveRead {
            bytes: self.read_stopped(address, len)?,
            changing: Vec::new(),
        })
    }

    /// [`RobotDebug::read`] through the stopped stub's frames.
    fn read_stopped(&mut self, address: u16, len: usize) -> StubResult<Vec<u8>> {
        let mut out = Vec::with_capacity(len);
        while out.len() < len {
            let at = address.wrapping_add(out.len() as u16);
            let count = (len - out.len()).min(READ_CHUNK);
            let payload = [b'R', at.to_le_bytes()[0], at.to_le_bytes()[1], count as u8];
            out.extend(self.memory_exchange(&payload, at, count)?);
        }
        Ok(out)
    }

    /// Sends a read or write request to the stopped stub and takes its
    /// `M` reply, retrying after a NAK or a garbled frame.
    fn memory_exchange(&mut self, payload: &[u8], at: u16, count: usize) -> StubResult<Vec<u8>> {
        let asked = format!(
            "{} of {count} bytes at ${at:04X}",
            if payload[0] == b'R' {
                "a read"
            } else {
                "a write"
            }
        );
        let mut last = None;
        for attempt in 0..ATTEMPTS {
            // Only before the first: a retry's clear would cut in two the
            // replies still on their way (hostile11 F4), and garble the
            // next; late ones are told apart by their address.
            if attempt == 0 {
                self.rx.clear();
                self.client.transport().clear_input()?;
            } else {
                frame::give_up_incomplete(&mut self.rx);
            }
            self.client.send_raw(&frame::encode(payload))?;
            let wait = char_time(
                payload.len() * 2 + count + 16,
                self.client.transport().baud(),
            ) + self.margin;
            let deadline = self.client.transport().now() + wait;
            while let Some(left) = deadline.checked_sub(self.client.transport().now()) {
                match self.next_heard(left)? {
                    Some(Heard::Frame(reply)) => {
                        let expected = [b'M', at.to_le_bytes()[0], at.to_le_bytes()[1]];
                        if reply.len() == count + 3 && reply[..3] == expected {
                            return Ok(reply[3..].to_vec());
                        }
                        // A late reply to an earlier request (its stop
                        // frame came first, say): ours follows it.
                        if reply.first() == Some(&b'M') {
                            continue;
                        }
                        last = Some(if reply.first() == Some(&b'S') {
                            // The stop frame again: it took our bytes for
                            // a command.
                            ("`M` and the address".to_owned(), hex(&reply))
                        } else {
                            (format!("{} {count} bytes", hex(&expected)), hex(&reply))
                        });
                        break;
                    }
                    // The rest of a reply cut in two, or noise: the reply
                    // may still come whole.
                    Some(Heard::BadFrame(bytes) | Heard::Text(bytes)) => {
                        last = Some((
                            "a frame with a good sum".into(),
                            bytes.escape_ascii().to_string(),
                        ));
                    }
                    None => break,
                }
            }
        }
        Err(match last {
            Some((expected, found)) => StubError::Garbled {
                asked,
                expected,
                found,
            },
            None => StubError::Timeout {
                asked,
                waited: self.margin,
            },
        })
    }

    /// The next frame or answer, waiting up to `wait`.
    fn next_heard(&mut self, wait: Duration) -> StubResult<Option<Heard>> {
        let transport = self.client.transport();
        let deadline = transport.now() + wait;
        loop {
            if let Some(heard) = frame::take(&mut self.rx) {
                return Ok(Some(heard));
            }
            let now = self.client.transport().now();
            if now >= deadline {
                return Ok(None);
            }
            self.client
                .transport()
                .receive(&mut self.rx, deadline - now)?;
        }
    }

    /// Takes `error` for a stop when it is one: the stub's stop frame heard
    /// by the ROM's commands of a running robot (a breakpoint in code the
    /// control loop runs, hit between two of them). The registers are
    /// asked for, the robot is stopped from now on, and the stop is kept
    /// to be told ([`RobotDebug::take_unasked`]). Any other error is
    /// given back.
    fn caught(&mut self, error: StubError) -> StubResult<()> {
        if self.stopped.is_some()
            || !matches!(
                error,
                StubError::Line(crate::Error::StoppedInDebugStub { .. })
            )
        {
            return Err(error);
        }
        let Some(registers) = self.probe_stopped()? else {
            return Err(error);
        };
        self.found_stop(registers)
    }

    /// A stop the host came upon rather than waited for: the robot is
    /// stopped from now on, the stop kept to be told, and a step's
    /// temporary breakpoints taken out, as at any stop.
    fn found_stop(&mut self, registers: Registers) -> StubResult<()> {
        self.stopped = Some(registers);
        self.unasked = Some(registers);
        self.drop_temporary()
    }

    /// The stop that came while the host was busy with something else
    /// (setting or removing a breakpoint, reading or writing memory), not
    /// told yet; taken, so it is told once.
    pub fn take_unasked(&mut self) -> Option<Registers> {
        self.unasked.take()
    }

    /// Takes a stop frame's payload as the registers.
    fn take_stop(&mut self, payload: &[u8]) -> Option<Registers> {
        let [b'S', pcl, pch, a, x, y, p, s] = *payload else {
            return None;
        };
        let pc = u16::from_le_bytes([pcl, pch]).wrapping_sub(2);
        let registers = Registers {
            pc: match self.alone {
                Some((at, stands_for)) if at == pc => stands_for,
                _ => pc,
            },
            a,
            x,
            y,
            p,
            s,
        };
        self.stopped = Some(registers);
        Some(registers)
    }

    /// Sends `command` to the running robot and waits up to `wait` for its
    /// answer, or for a stop.
    ///
    /// # Errors
    /// [`StubError::Refused`] while stopped; the line's errors.
    pub fn command(&mut self, command: &[u8], wait: Duration) -> StubResult<Reply> {
        if self.stopped.is_some() {
            return Err(StubError::Refused {
                what: format!("sending {}", command.escape_ascii()),
                reason: "the robot is stopped (at a breakpoint, or after a step): its control loop reads no command until `continue`".into(),
            });
        }
        self.rx.clear();
        self.partial.clear();
        self.client.transport().clear_input()?;
        self.client.send_raw(command)?;
        let wait = wait + char_time(command.len(), self.client.transport().baud());
        self.wait_event(wait)
    }

    /// Waits up to `wait` for an answer or a stop.
    ///
    /// `wait` runs from the last thing heard; after [`STRIKES`] garbled
    /// frames (each answered with a slash, which makes a stub send its
    /// stop frame again) or pieces that are neither a stop nor an answer,
    /// it gives up with [`StubError::Garbled`]; the interrupt flag
    /// ([`RobotDebug::set_interrupt`]) ends it at once.
    ///
    /// # Errors
    /// The line's errors, [`StubError::Garbled`],
    /// [`StubError::Interrupted`].
    pub fn wait_event(&mut self, wait: Duration) -> StubResult<Reply> {
        if let Some(registers) = self.unasked.take() {
            return Ok(Reply::Stopped(registers));
        }
        let asked = "a stop or an answer";
        let mut deadline = self.client.transport().now() + wait;
        let mut strikes = 0;
        let mut last = String::new();
        loop {
            if self
                .interrupt
                .as_ref()
                .is_some_and(|flag| flag.load(Ordering::Relaxed))
            {
                return Err(StubError::Interrupted {
                    waiting: asked.into(),
                });
            }
            if strikes >= STRIKES {
                return Err(StubError::Garbled {
                    asked: asked.into(),
                    expected:
                        "a stop frame with a good sum, or an answer through its carriage return"
                            .into(),
                    found: format!("{strikes} times something else, the last {last}"),
                });
            }
            let now = self.client.transport().now();
            if now >= deadline {
                return Ok(Reply::Silent);
            }
            let heard = self.next_heard((deadline - now).min(SLICE))?;
            if heard.is_some() {
                deadline = self.client.transport().now() + wait;
            }
            match heard {
                None => {}
                Some(Heard::Text(text)) => {
                    // An answer begun before a stop ends after it.
                    self.partial.extend_from_slice(&text);
                    if text.last() == Some(&b'\r') {
                        return Ok(Reply::Answer(std::mem::take(&mut self.partial)));
                    }
                    strikes += 1;
                    last = text.escape_ascii().to_string();
                }
                Some(Heard::Frame(payload)) => {
                    if let Some(registers) = self.take_stop(&payload) {
                        self.drop_temporary()?;
                        return Ok(Reply::Stopped(registers));
                    }
                    strikes += 1;
                    last = format!("frame {}", hex(&payload));
                }
                Some(Heard::BadFrame(bytes)) => {
                    // A stop frame that came garbled: a slash makes the
                    // stub send it again.
                    self.client.send_raw(b"/")?;
                    strikes += 1;
                    last = format!("garbled frame {}", hex(&bytes));
                }
            }
        }
    }

    /// A flag a signal sets: while it is set, a wait for the robot (a
    /// continue's, a step's, a command's) ends at once with
    /// [`StubError::Interrupted`]. [`RobotDebug::detach`] does not look at
    /// it: it gives the robot back all the same.
    pub fn set_interrupt(&mut self, flag: Arc<AtomicBool>) {
        self.interrupt = Some(flag);
    }

    /// Whether the flag [`RobotDebug::set_interrupt`] gave is set: for
    /// work of the caller's own that takes many questions (a display that
    /// reads much memory).
    #[must_use]
    pub fn interrupted(&self) -> bool {
        self.interrupt
            .as_ref()
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
    }

    /// Changes the registers of the stopped robot, as a person asks (the
    /// PC is where `resume` goes on).
    ///
    /// # Errors
    /// [`StubError::Refused`] while running, and for registers the robot
    /// cannot go on with ([`Guard::refuse_registers`]: a PC where no
    /// instruction is known, the decimal flag); the line's errors.
    pub fn set_registers(&mut self, registers: Registers) -> StubResult<()> {
        let Some(old) = self.stopped else {
            return Err(not_stopped("setting a register"));
        };
        if let Some(reason) = self.guard.refuse_registers(
            &old,
            &registers,
            &self.image,
            self.starts.as_deref(),
            &self.stub,
        ) {
            return Err(StubError::Refused {
                what: "setting the registers".into(),
                reason,
            });
        }
        self.put_registers(registers)
    }

    /// [`RobotDebug::set_registers`] unchecked: the registers a step done
    /// on the host leaves (the program's own doing).
    fn put_registers(&mut self, registers: Registers) -> StubResult<()> {
        let Some(old) = self.stopped else {
            return Err(not_stopped("setting a register"));
        };
        // The PC too, as the stub keeps it (the JSR's return address, two
        // past the breakpoint): a `C` lost on the line leaves the stub
        // stopped, and a probe then finds where the host had it, not the
        // first stop's place, whose instructions the host has run since
        // (hostile10 F8: a lost `C` after a step made the next `continue`
        // run the stepped instruction again).
        let block = |r: &Registers| {
            let [low, high] = r.pc.wrapping_add(2).to_le_bytes();
            [low, high, r.a, r.x, r.y, r.p, r.s]
        };
        if block(&registers) != block(&old) {
            self.write_verified(self.stub.regs + 1, &block(&registers))?;
        }
        self.stopped = Some(registers);
        Ok(())
    }

    /// The program's address for `pc` in a breakpoint's trampoline: its
    /// displaced instructions and the `JMP` back stand for the program's
    /// bytes from the breakpoint on (the `JMP` for the instruction after
    /// them). A `JSR` a breakpoint displaced runs from the trampoline, so
    /// its subroutine's `RTS` comes back there (fresh10 F15: a step out of
    /// it stopped in the stub, at an address with no name); the stop is
    /// where the program goes on. [`RobotDebug::resume_address`] maps back.
    fn program_pc(&self, pc: u16) -> u16 {
        self.breakpoints
            .values()
            .find_map(|(patch, slot)| {
                let offset = pc.checked_sub(self.stub.trampoline(*slot))?;
                patch
                    .program_offset(offset)
                    .map(|offset| patch.address.wrapping_add(offset))
            })
            .unwrap_or(pc)
    }

    /// Where the stopped robot goes on: a breakpoint's address is its
    /// trampoline (the displaced instructions, then back).
    fn resume_address(&self, pc: u16) -> u16 {
        // A step done on the host can also leave the PC among the bytes
        // a breakpoint displaced: the trampoline holds them in order.
        let displaced = self.breakpoints.values().find_map(|(patch, slot)| {
            let offset = patch.offset_of(pc)?;
            Some((patch.trampoline_offset(offset).unwrap_or(offset), *slot))
        });
        match displaced {
            Some((offset, slot)) => self.stub.trampoline(slot) + offset,
            None => pc,
        }
    }

    /// Lets the stopped robot go on (the command it was handling is
    /// finished, its answer comes); `wait_event` then takes what comes.
    ///
    /// # Errors
    /// [`StubError::Refused`] while running; the line's errors.
    ///
    /// The instruction at the PC is run on the host first: one that
    /// writes into the stub is refused ([`StubError::Refused`]), the
    /// robot left stopped (going on, it would overwrite the stub it is
    /// served by).
    pub fn resume(&mut self) -> StubResult<()> {
        let Some(registers) = self.stopped else {
            return Err(not_stopped("continue"));
        };
        let stub = self.stub.clone();
        let the_stubs = |at: u16| stub.contains(at);
        let image = self.image.clone();
        let unwritable = |at: u16| !guard::ram(at, &image);
        let mut read = |at: u16| -> StubResult<u8> { Ok(self.read_as_program(at, 1)?[0]) };
        let writes = match host_step::step(registers, &mut read, &the_stubs, &unwritable)? {
            Step::Host(effects) => effects.writes,
            Step::Robot(writes) => writes,
        };
        for (at, _) in writes {
            self.refuse_stub_write(at, &format!("continuing from ${:04X}", registers.pc))?;
        }
        self.go_on()
    }

    /// [`RobotDebug::resume`] without the look at the instruction.
    fn go_on(&mut self) -> StubResult<()> {
        let Some(registers) = self.stopped else {
            return Err(not_stopped("continue"));
        };
        self.go_on_at(self.resume_address(registers.pc))
    }

    /// Lets the stopped robot go on at `to` with its registers.
    fn go_on_at(&mut self, to: u16) -> StubResult<()> {
        let to = to.to_le_bytes();
        self.alone = None;
        self.unasked = None;
        self.rx.clear();
        self.client
            .send_raw(&frame::encode(&[b'C', to[0], to[1]]))?;
        self.stopped = None;
        Ok(())
    }

    /// One instruction: temporary breakpoints at where the instruction at
    /// the PC can go (a `JSR` into the ROM stepped over, any `JSR` when
    /// `over`), continue, and
    /// the temporary ones removed at the stop. `Ok(None)` when no stop
    /// came within `wait` (the code went into the ROM: a return, say).
    ///
    /// # Errors
    /// [`StubError::Refused`] with the reason (a successor in the ROM, or
    /// in bytes a breakpoint displaced); the line's errors.
    pub fn step(&mut self, entries: &[u16], over: bool, wait: Duration) -> StubResult<Reply> {
        let Some(registers) = self.stopped else {
            return Err(not_stopped("step"));
        };
        if let Some(stop) = self.step_on_host(registers)? {
            return Ok(stop);
        }
        let alone = self.goes_on_alone(registers.pc)?;
        if let Some((instruction, bytes)) = &alone
            && let Some(stop) = self.step_alone(instruction, bytes, wait)?
        {
            return Ok(stop);
        }
        let alone = alone.is_some();
        let pc = registers.pc;
        let image = self.image.clone();
        let mut known: BTreeMap<u16, u8> = BTreeMap::new();
        let mut read = |at: u16| -> StubResult<u8> {
            if let Some(byte) = image.byte(at) {
                return Ok(byte);
            }
            if let Some(&byte) = known.get(&at) {
                return Ok(byte);
            }
            let byte = self.read(at, 1)?[0];
            known.insert(at, byte);
            Ok(byte)
        };
        let next = patch::successors(pc, registers.s, &image, over, &mut read)?;
        // hostile15 F5: where the step would have run alone but for the
        // trampolines, a refusal says how to free one.
        let busy = if alone {
            format!(
                " (all {TRAMPOLINES} trampolines hold breakpoints: delete one, and the step runs the instruction alone in it)"
            )
        } else {
            String::new()
        };
        let mut temporary = Vec::new();
        for &to in &next {
            if self.breakpoints.contains_key(&to) {
                continue;
            }
            if !self.image.contains(to) {
                return Err(StubError::Refused {
                    what: format!("a step from ${pc:04X}"),
                    reason: format!(
                        "the instruction there must run on the robot (it pushes, or touches I/O or the stub's bytes), and the next one, ${to:04X}, lies outside the uploaded code, where no breakpoint can stop it (the ROM cannot be patched; steps the host can run itself go through there): continue, with a breakpoint in the uploaded code where the robot comes back to it, if it does"
                    ),
                });
            }
            if let Some((other, _)) = self.breakpoints.values().find(|(p, _)| p.covers_inside(to)) {
                return Err(StubError::Refused {
                    what: format!("a step from ${pc:04X}"),
                    reason: format!(
                        "the next instruction, ${to:04X}, is among the bytes the breakpoint at ${:04X} displaced{busy}",
                        other.address
                    ),
                });
            }
            temporary.push(to);
        }
        for &to in &temporary {
            if let Err(error) = self.set_breakpoint(to, entries) {
                for &done in &temporary {
                    if self.breakpoints.contains_key(&done) {
                        self.remove_breakpoint(done)?;
                    }
                }
                // A step stops with a breakpoint's JSR on the next
                // instruction: where that cannot go (an instruction of one
                // or two bytes followed by a branch or a line of its own),
                // neither can the step.
                return Err(match error {
                    StubError::Refused { reason, .. } => StubError::Refused {
                        what: format!("a step from ${pc:04X}"),
                        reason: format!(
                            "it stops with a JSR (three bytes) on the next instruction, ${to:04X}, and that is refused: {reason}; set a breakpoint further on and continue{busy}"
                        ),
                    },
                    other => other,
                });
            }
        }
        // Taken out at the next stop, whenever it comes: the step may run
        // on (a `JSR` into the ROM that ends the answer, `JMP CMD_DONE`)
        // and stop there later, or at another breakpoint.
        self.temporary.extend(temporary);
        self.go_on()?;
        self.wait_event(wait)
    }

    /// A step the host does for the robot (see [`host_step`]): the
    /// instruction's bytes and the memory it reads as the program has
    /// them (a breakpoint's displaced bytes, not its `JSR`; the stub's
    /// zero page from where the stub keeps the program's), its writes
    /// given back the same way ([`RobotDebug::write_as_program`]), the
    /// registers set. `None` when it is one for the patching step: a
    /// push, a write outside RAM (an I/O register reads back other than
    /// written), a read of the stub's bytes.
    ///
    /// The host runs the instruction first either way, so a step that
    /// would write over the stub, or (left to the robot) over a
    /// breakpoint's bytes, is refused before anything is written.
    fn step_on_host(&mut self, registers: Registers) -> StubResult<Option<Reply>> {
        let stub = self.stub.clone();
        let the_stubs = |at: u16| stub.contains(at);
        let image = self.image.clone();
        let unwritable = |at: u16| !guard::ram(at, &image);
        let mut read = |at: u16| -> StubResult<u8> { Ok(self.read_as_program(at, 1)?[0]) };
        let step = host_step::step(registers, &mut read, &the_stubs, &unwritable)?;
        let what = format!("a step from ${:04X}", registers.pc);
        match step {
            Step::Robot(writes) => {
                for &(at, _) in &writes {
                    self.refuse_stub_write(at, &what)?;
                    if let Some((patch, _)) = self
                        .breakpoints
                        .values()
                        .find(|(p, _)| p.offset_of(at).is_some())
                    {
                        return Err(StubError::Refused {
                            what,
                            reason: format!(
                                "the instruction writes ${at:04X}, among the bytes the breakpoint at ${:04X} displaced, and the robot would run it with the JSR there (it would write over the JSR or the trampoline's copy): delete that breakpoint, then step",
                                patch.address
                            ),
                        });
                    }
                }
                Ok(None)
            }
            Step::Host(effects) => {
                // At a stop: nothing changes as it is read.
                self.apply_as_program(&effects.writes, &what)?;
                let mut registers = effects.registers;
                registers.pc = self.program_pc(registers.pc);
                self.put_registers(registers)?;
                Ok(Some(Reply::Stopped(registers)))
            }
        }
    }

    /// A step the robot runs in a trampoline of the stub, alone: the
    /// instruction's bytes (the program's), then `JSR` into the stub, so
    /// that it stops right after it with nothing patched into the
    /// program. For an instruction the host cannot do (a store to a
    /// card's register, a push) whose neighbour cannot take a
    /// breakpoint's `JSR` (fresh14 F7: `sta ADC_CONTROL` before a line of
    /// its own). Only for instructions that go on to the next one and do
    /// not read the PC: a branch, jump, call or return goes its own way
    /// (`None`: the patching step), as when every trampoline is in use.
    ///
    /// The host has run the instruction first ([`RobotDebug::step_on_host`]),
    /// so a write into the stub or a breakpoint's bytes is refused before.
    fn step_alone(
        &mut self,
        instruction: &Instruction,
        bytes: &[u8],
        wait: Duration,
    ) -> StubResult<Option<Reply>> {
        let Some(slot) = self.free_trampoline() else {
            return Ok(None);
        };
        let len = usize::from(instruction.len());
        let trampoline = self.stub.trampoline(slot);
        let code = patch::alone(&bytes[..len], self.stub.entry, instruction.next_address());
        self.write_verified(trampoline, &code)?;
        self.go_on_at(trampoline)?;
        self.alone = Some((
            trampoline.wrapping_add(len as u16),
            instruction.next_address(),
        ));
        // The stop frame names the trampoline's `JSR`; it is told as the
        // program's next instruction (`take_stop`), a frame sent again too.
        Ok(Some(self.wait_event(wait)?))
    }

    /// A trampoline no breakpoint holds, if there is one.
    fn free_trampoline(&self) -> Option<usize> {
        let used: Vec<usize> = self.breakpoints.values().map(|(_, slot)| *slot).collect();
        (0..TRAMPOLINES).find(|slot| !used.contains(slot))
    }

    /// The instruction at `pc` (the program's bytes) if it can run alone
    /// in a trampoline: one that goes on to the next and does not read
    /// the PC.
    fn goes_on_alone(&mut self, pc: u16) -> StubResult<Option<(Instruction, Vec<u8>)>> {
        let bytes = self.read_as_program(pc, 3)?;
        let Some(instruction) = Instruction::decode(&bytes, pc) else {
            return Ok(None);
        };
        let goes_its_own_way = matches!(
            instruction.opcode.mnemonic,
            Mnemonic::Jsr | Mnemonic::Jmp | Mnemonic::Rts | Mnemonic::Rti | Mnemonic::Brk
        ) || instruction.opcode.mode == AddressingMode::Relative
            || instruction.opcode.cycles == 0;
        Ok((!goes_its_own_way).then_some((instruction, bytes)))
    }

    /// [`StubError::Refused`] for a write into the stub's bytes.
    fn refuse_stub_write(&self, at: u16, what: &str) -> StubResult<()> {
        if !self.stub.contains(at) {
            return Ok(());
        }
        Err(StubError::Refused {
            what: what.into(),
            reason: format!(
                "it writes ${at:04X}, in the debug stub (${:04X}-${:04X}, RAM the image does not claim), which would break the stub the robot is stopped in (a continue would too, and is refused): `quit` (the breakpoints are taken out and the hook given back before the robot goes on), then make the image claim the RAM it writes (a `.bss` or `.res` there) so that the stub goes elsewhere, upload it and attach again",
                self.stub.address,
                u32::from(self.stub.address) + self.stub.bytes.len() as u32 - 1
            ),
        })
    }

    /// Where the program's byte at `at` is kept while stopped, when it is
    /// not at `at`: the stub's zero page is the stub's at a stop, the
    /// program's two bytes wait in `saved_zp`.
    fn kept_at(&self, at: u16) -> u16 {
        let zero_page = u16::from(self.stub.zero_page);
        if self.stopped.is_some() && (zero_page..=zero_page + 1).contains(&at) {
            self.stub.saved_zp + (at - zero_page)
        } else {
            at
        }
    }

    /// Why a person's read of `len` bytes at `address` is refused, if it
    /// is ([`Guard::refuse_read`]): the first address refused, and why.
    #[must_use]
    pub fn refuse_read(&self, address: u16, len: usize) -> Option<(u16, String)> {
        (0..len).find_map(|i| {
            let at = address.wrapping_add(i as u16);
            self.guard
                .refuse_read(at, &self.image)
                .map(|reason| (at, reason))
        })
    }

    /// Reads `len` bytes at `address` as the program sees them (as a
    /// debugger hides its breakpoints): a breakpoint's `JSR` shows the
    /// program's bytes under it, and at a stop the stub's two zero-page
    /// bytes show the program's values the stub keeps.
    ///
    /// # Errors
    /// As [`RobotDebug::read`].
    pub fn read_as_program(&mut self, address: u16, len: usize) -> StubResult<Vec<u8>> {
        Ok(self.program_read(address, len, false)?.bytes)
    }

    /// [`RobotDebug::read_as_program`], but memory the program writes as
    /// it runs (a counter its control loop keeps) is read as it was at one
    /// moment and named in [`LiveRead::changing`], not refused: for a
    /// display polled while the robot runs, whose point is to watch it
    /// change.
    ///
    /// # Errors
    /// As [`RobotDebug::read`], but for [`crate::Error::MemoryChanging`].
    pub fn read_live_as_program(&mut self, address: u16, len: usize) -> StubResult<LiveRead> {
        self.program_read(address, len, true)
    }

    fn program_read(&mut self, address: u16, len: usize, live: bool) -> StubResult<LiveRead> {
        let LiveRead {
            mut bytes,
            changing,
        } = self.read_maybe_live(address, len, live)?;
        for (i, byte) in bytes.iter_mut().enumerate() {
            let at = address.wrapping_add(i as u16);
            // Past the JSR's three bytes the code holds the program's own.
            if let Some(program) = self.breakpoints.values().find_map(|(patch, _)| {
                patch
                    .offset_of(at)
                    .filter(|&offset| offset < 3)
                    .map(|offset| patch.displaced[usize::from(offset)])
            }) {
                *byte = program;
            }
        }
        let kept: Vec<(usize, u16)> = (0..len)
            .filter_map(|i| {
                let at = address.wrapping_add(i as u16);
                let kept = self.kept_at(at);
                (kept != at).then_some((i, kept))
            })
            .collect();
        for (i, at) in kept {
            bytes[i] = self.read(at, 1)?[0];
        }
        Ok(LiveRead { bytes, changing })
    }

    /// Writes `bytes` at `address` as the program would (each read back):
    /// a byte under a breakpoint's `JSR` goes to its trampoline's copy
    /// (and the record put back when it is removed), the `JSR` kept; at a
    /// stop the stub's zero page to where the stub keeps the program's.
    ///
    /// # Errors
    /// [`StubError::Refused`] for a write outside the program's RAM or
    /// into the hooks or the table ([`Guard::refuse_write`]), into the
    /// stub, or a byte under a `JSR` that would make its trampoline's
    /// copy run otherwise (see [`Patch::with_byte`]); nothing is written
    /// then. The line's errors, [`StubError::Verify`].
    pub fn write_as_program(&mut self, address: u16, bytes: &[u8]) -> StubResult<()> {
        self.write_as_program_live(address, bytes).map(|_| ())
    }

    /// [`RobotDebug::write_as_program`], where a byte the program writes
    /// while it runs (a counter) is not refused for holding something
    /// else when read back: it is written, and changing since. Returns
    /// those addresses, sorted (fresh17 F8: a `poke` of a running counter
    /// was said to fail, "not RAM, or the line is very noisy", though it
    /// took).
    ///
    /// # Errors
    /// As [`RobotDebug::write_as_program`].
    pub fn write_as_program_live(&mut self, address: u16, bytes: &[u8]) -> StubResult<Vec<u16>> {
        let what = format!("a write at ${address:04X}");
        for i in 0..bytes.len() {
            let at = address.wrapping_add(i as u16);
            if let Some(reason) = self.guard.refuse_write(at, &self.image) {
                return Err(StubError::Refused { what, reason });
            }
        }
        let writes: Vec<(u16, u8)> = bytes
            .iter()
            .enumerate()
            .map(|(i, &byte)| (address.wrapping_add(i as u16), byte))
            .collect();
        self.apply_as_program(&writes, &what)
    }

    /// [`RobotDebug::write_as_program_live`] for writes in order (`what`
    /// names them in a refusal).
    fn apply_as_program(&mut self, writes: &[(u16, u8)], what: &str) -> StubResult<Vec<u16>> {
        let mut changing = Vec::new();
        // All planned first: a refusal writes nothing.
        let mut patches: BTreeMap<u16, Patch> = BTreeMap::new();
        let mut plain: Vec<(u16, u8)> = Vec::new();
        for &(at, value) in writes {
            self.refuse_stub_write(at, what)?;
            let covering = self
                .breakpoints
                .iter()
                .find(|(_, (patch, _))| patch.offset_of(at).is_some())
                .map(|(&address, (patch, _))| (address, patch.clone()));
            if let Some((address, patch)) = covering {
                let current = patches.remove(&address).unwrap_or(patch);
                let changed = current.with_byte(at, value).map_err(|reason| StubError::Refused {
                    what: what.into(),
                    reason: format!(
                        "it writes ${value:02X} at ${at:04X}, among the bytes the breakpoint at ${address:04X} displaced (they run from its trampoline), and {reason}: delete that breakpoint first"
                    ),
                })?;
                if changed.offset_of(at).is_some_and(|offset| offset >= 3) {
                    // Past the JSR the code holds the program's bytes too.
                    plain.push((at, value));
                }
                patches.insert(address, changed);
                continue;
            }
            plain.push((self.kept_at(at), value));
        }
        for (address, patch) in patches {
            let Some(slot) = self.breakpoints.get(&address).map(|(_, slot)| *slot) else {
                continue;
            };
            self.write_verified(self.stub.trampoline(slot), &patch.trampoline)?;
            self.breakpoints.insert(address, (patch, slot));
        }
        // Runs of consecutive bytes in one write each.
        let mut i = 0;
        while i < plain.len() {
            let mut run = vec![plain[i].1];
            while i + run.len() < plain.len()
                && plain[i + run.len()].0 == plain[i].0.wrapping_add(run.len() as u16)
            {
                run.push(plain[i + run.len()].1);
            }
            changing.extend(self.write_plain(plain[i].0, &run)?);
            i += run.len();
        }
        changing.sort_unstable();
        changing.dedup();
        Ok(changing)
    }

    /// Writes program bytes and reads them back ([`RobotDebug::write_verified`]);
    /// while the robot runs, the read back is [`Client::read_live`]: where
    /// bytes of the write keep changing as they are read, the program
    /// writes there as it runs (a counter), and the bytes that hold
    /// something else are returned as its; any other difference is
    /// written again, then refused.
    fn write_plain(&mut self, address: u16, bytes: &[u8]) -> StubResult<Vec<u16>> {
        let running = self.while_running(|d| {
            let mut found = Vec::new();
            for _ in 0..ATTEMPTS {
                d.rom_write_piece_once(address, bytes)?;
                let read = d.client.read_live(address, bytes.len())?;
                let differ: Vec<usize> = (0..bytes.len())
                    .filter(|&i| read.bytes[i] != bytes[i])
                    .collect();
                if differ.is_empty() {
                    return Ok(Vec::new());
                }
                // The program writes here as it runs: a byte that changed
                // as it was read, and the others of the write that hold
                // something else now (the high byte of a counter, which
                // moves more slowly), are its.
                if !read.changing.is_empty() {
                    let mut changed: Vec<u16> = differ
                        .iter()
                        .map(|&i| address.wrapping_add(i as u16))
                        .chain(read.changing)
                        .collect();
                    changed.sort_unstable();
                    changed.dedup();
                    return Ok(changed);
                }
                found = read.bytes;
            }
            Err(StubError::Verify {
                address,
                expected: hex(bytes),
                found: hex(&found),
            })
        })?;
        match running {
            Some(changing) => Ok(changing),
            None => {
                self.write_verified(address, bytes)?;
                Ok(Vec::new())
            }
        }
    }

    /// The step's breakpoints, taken out at a stop.
    fn drop_temporary(&mut self) -> StubResult<()> {
        for to in std::mem::take(&mut self.temporary) {
            if self.breakpoints.contains_key(&to) {
                self.remove_breakpoint(to)?;
            }
        }
        Ok(())
    }

    /// What the running robot said unasked, within `wait`: a stop (a
    /// step that ran on, a command another program sent), an answer, or
    /// `None`. `None` at once when it is stopped.
    ///
    /// # Errors
    /// The line's errors.
    pub fn poll(&mut self, wait: Duration) -> StubResult<Option<Reply>> {
        if let Some(registers) = self.unasked.take() {
            return Ok(Some(Reply::Stopped(registers)));
        }
        if self.stopped.is_some() {
            return Ok(None);
        }
        Ok(match self.wait_event(wait)? {
            Reply::Silent => None,
            reply => Some(reply),
        })
    }

    /// Detaches: continues a stopped robot, removes every breakpoint (the
    /// code compared with the image), and gives `HOOK_UNKNOWN` back to
    /// what it pointed at. The stub's bytes stay in RAM, unreached.
    ///
    /// # Errors
    /// The line's errors.
    pub fn detach(mut self) -> StubResult<Client<T>> {
        // A signal that ended the session must not cut its detach short.
        self.interrupt = None;
        if self.stopped.is_none() {
            // A stop nobody saw (its frame lost, or unread): the stub
            // answers a frame only when it runs.
            if let Some(registers) = self.probe_stopped()? {
                self.stopped = Some(registers);
                self.drop_temporary()?;
            }
        }
        let addresses: Vec<u16> = self.breakpoints.keys().copied().collect();
        for address in addresses {
            self.remove_breakpoint(address)?;
        }
        if self.stopped.is_some() {
            self.go_on()?;
            let _ = self.wait_event(self.margin)?;
            // Its `C` lost on a noisy line, the robot stays in the stub,
            // which answers a frame only then: sent again until none
            // comes back (hostile10 F13: `quit` left the robot stopped).
            for _ in 0..ATTEMPTS {
                let Some(registers) = self.probe_stopped()? else {
                    break;
                };
                self.stopped = Some(registers);
                self.go_on()?;
                let _ = self.wait_event(self.margin)?;
            }
        }
        let hook = self.hook;
        let jump = self.client.read_memory(hook, 3)?;
        if u16::from_le_bytes([jump[1], jump[2]]) == self.stub.handler {
            crate::hooks::switch_hook_among(
                &mut self.client,
                &self.profile,
                hook,
                self.stub.previous,
                ATTEMPTS,
            )?;
        }
        Ok(self.client)
    }

    /// Lets go of the line without detaching: the robot keeps the stub
    /// hooked, the breakpoints and a stop, as a session whose process was
    /// killed leaves it (for the tests of [`RobotDebug::attach`]'s
    /// recovery).
    #[must_use]
    pub fn abandon(self) -> Client<T> {
        self.client
    }

    /// The robot's bytes where the image has code, compared with it:
    /// the first difference, if any (address, image, robot). Its data is
    /// the program's to change, and is not compared.
    ///
    /// # Errors
    /// The line's errors.
    pub fn compare_with_image(&mut self) -> StubResult<Option<(u16, u8, u8)>> {
        for area in self.image.areas().to_vec() {
            // Only the code is read: a counter beside it changes as the
            // robot runs.
            let (found, data) = self.read_code(&area, &[])?;
            if let Some(i) = (0..found.len()).find(|&i| {
                let at = area.address.wrapping_add(i as u16);
                found[i] != area.bytes[i] && self.image.is_code(at) && !data.contains(&at)
            }) {
                return Ok(Some((
                    area.address.wrapping_add(i as u16),
                    area.bytes[i],
                    found[i],
                )));
            }
        }
        Ok(None)
    }
}

/// The refusal to attach to a robot stopped in a stub other than the one
/// this image's attach would place at `address`.
fn stopped_in_another_stub(address: u16) -> StubError {
    StubError::Refused {
        what: "attaching".into(),
        reason: format!(
            "the robot is stopped in a debug stub that is not where this image's goes (${address:04X}): it was attached with another image; attach with that one, or reset the robot"
        ),
    }
}

fn not_stopped(what: &str) -> StubError {
    StubError::Refused {
        what: what.into(),
        reason: "the robot is running: it stops at a breakpoint".into(),
    }
}
