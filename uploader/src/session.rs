//! Running the RAM loader: `rate` put in through the ROM at the base rate,
//! verified and hooked; `/1F` and the host moved to the fast rate; the
//! rest of the loader put in there, verified and hooked; the body carried
//! in frames; the loader recovered after a reset; `/1F` again at the end,
//! which puts the line back on the base rate.
//!
//! Resets are why this is more than a sequence of steps. A `/1R` (the
//! ROM's soft reset) puts the hooks back but leaves the 6551 at whatever
//! rate it runs; the reset button also puts the 6551 back on its DIP
//! switches. Either way the loader is no longer hooked, so frames stop
//! landing. [`Session::ensure`] finds the rate the robot answers at,
//! checks `HOOK_UNKNOWN`, verifies the loader (it is still in RAM, so that
//! is a read), hooks it again and switches the line again if it has to.

use std::time::Duration;

use isa::objfmt::HookKind;
use romlib::protocol::{Answer, Command, Extension, ReadSpan};

use crate::body::{Body, Limits, RunEnd, Writer};
use crate::client::Client;
use crate::hooks::{read_hook, switch_hook};
use crate::image::{Area, RomProfile, UploadImage};
use crate::loader::{Loader, ZERO_PAGE_LEN, rate_toggle};
use crate::progress::{Event, NoProgress, Phase, Progress};
use crate::summed::{Summed, write_summed};
use crate::transport::{Transport, char_time};
use crate::{Error, Result};

/// Called with what the loader is about to overwrite, before its first
/// write (the upload keeps it for an undo then).
pub(crate) type BeforeWrite<'a, T> = dyn FnMut(&mut Client<T>, &[Area]) -> Result<()> + 'a;

/// How often the loader is restored before the upload gives up.
const MAX_RECOVERIES: u32 = 6;

/// Looks for the loader after its sums went silent, before giving up.
const ENSURE_ATTEMPTS: u32 = 3;

/// Time the robot is given to obey `/1F` once its last character has
/// arrived: the ROM's dispatch and `rate`'s toggle take well under a
/// millisecond at 1 MHz.
const SWITCH_SETTLE: Duration = Duration::from_millis(2);

/// The loader during one upload.
#[derive(Debug)]
pub(crate) struct Session {
    loader: Loader,
    hook: u16,
    /// `HOOK_UNKNOWN`'s target before the upload (the ROM's own: the
    /// loader is used only then), where it goes back to at the end.
    original: u16,
    /// The ROM's reset target of `HOOK_UNKNOWN`, if known.
    reset: Option<u16>,
    base: u32,
    /// The rate the transfer runs at once the loader is in: `fast` if the
    /// switch worked, else `base`.
    target: u32,
    /// The rate to switch to; `None` once a switch failed (the transfer
    /// then runs at the base rate).
    fast: Option<u32>,
    limits: Limits,
    /// Whether `sums` goes in and is hooked (an upload too small to gain
    /// from it leaves it out: `frames` is then hooked).
    with_sums: bool,
    /// The profile whose jump table the robot's is compared with before
    /// `frames` goes in, if the upload left that to the loader (at the
    /// fast rate); `None` once it was.
    rom_check: Option<RomProfile>,
    /// Whether the loader was written (not found in RAM, verified).
    wrote: bool,
    /// Whether an earlier upload may have left the loader in RAM (the
    /// robot's table lists an extension): only then is it looked for.
    pub(crate) maybe_resident: bool,
    /// Times the loader was restored.
    pub(crate) recoveries: u32,
    /// Whether what the loader overwrites is read first (for an undo).
    pub(crate) keep_under: bool,
    /// What the loader's code and zero page held before it was written
    /// (only what was read: see [`Session::keep_under`]).
    under: Vec<Area>,
    /// Whether the zero page is in `under` already.
    zero_page_kept: bool,
}

impl Session {
    /// A session for `loader`, linked for a line at `base` and `fast`.
    pub(crate) fn new(
        loader: Loader,
        profile: &RomProfile,
        original: u16,
        (base, fast): (u32, Option<u32>),
        limits: Limits,
        with_sums: bool,
        rom_check: Option<RomProfile>,
    ) -> Self {
        Session {
            loader,
            hook: profile.hook_address(HookKind::Unknown),
            original,
            reset: profile.reset_target(HookKind::Unknown),
            base,
            target: base,
            fast: fast.filter(|&fast| fast != base && rate_toggle((base, fast)) != 0),
            limits,
            with_sums,
            rom_check,
            wrote: false,
            maybe_resident: true,
            recoveries: 0,
            keep_under: false,
            under: Vec::new(),
            zero_page_kept: false,
        }
    }

    /// `HOOK_UNKNOWN`'s target while the loader is in: `sums`, or
    /// `frames` without it.
    pub(crate) fn handler(&self) -> u16 {
        if self.with_sums {
            self.loader.sums
        } else {
            self.loader.frames
        }
    }

    /// Whether the loader was written, rather than found in RAM from an
    /// earlier upload and verified.
    pub(crate) fn wrote_loader(&self) -> bool {
        self.wrote
    }

    /// The profile whose jump table is still to be compared with the
    /// robot's (a loader found in RAM leaves that to `sums`); taken.
    pub(crate) fn take_rom_check(&mut self) -> Option<RomProfile> {
        self.rom_check.take()
    }

    /// Whether `sums` is in (and hooked).
    pub(crate) fn has_sums(&self) -> bool {
        self.with_sums
    }

    /// The rate the transfer ran at.
    pub(crate) fn rate(&self) -> u32 {
        self.target
    }

    /// Whether `address` is the loader's: its code (both parts) or its
    /// state in the zero page.
    pub(crate) fn owns(&self, address: u16) -> bool {
        let start = u32::from(self.loader.address());
        let code = start..start + self.loader.len() as u32;
        let zero_page = u16::from(self.loader.zero_page);
        code.contains(&u32::from(address))
            || (zero_page..zero_page + u16::from(crate::loader::ZERO_PAGE_LEN)).contains(&address)
    }

    /// The loader's code byte at `address`, if its code is there.
    pub(crate) fn code_byte(&self, address: u16) -> Option<u8> {
        self.loader.image.byte(address)
    }

    /// The loader's first address and the size of what went in.
    pub(crate) fn placement(&self) -> (u16, usize) {
        let len = if self.with_sums {
            self.loader.len()
        } else {
            usize::from(self.loader.sums - self.loader.address())
        };
        (self.loader.address(), len)
    }

    /// Installs the loader: `rate` at the base rate, the switch, `frames`
    /// at the fast rate. Each part verifies before it is hooked.
    pub(crate) fn install<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        progress: &mut dyn Progress,
        before_write: &mut BeforeWrite<'_, T>,
    ) -> Result<()> {
        progress.phase(Phase::Loader, self.loader.len());
        if let Some(fast) = self.fast {
            // Can the host's end run at the fast rate at all?
            let now = client.transport().baud();
            if client.transport().set_baud(fast).is_err() {
                self.fast = None;
            }
            client.transport().set_baud(now)?;
        }
        // A loader left in RAM by an earlier upload at the same place (the
        // usual case when an extension is uploaded again after an edit)
        // only needs verifying: reading it back costs less than writing it.
        let seen = if self.maybe_resident {
            self.read_rate(client)?
        } else {
            None
        };
        let rate = self.loader.rate_part()?;
        let resident = seen.as_deref() == Some(&rate.areas()[0].bytes[..]);
        if self.keep_under {
            self.under = self.read_under(client, resident, seen.as_deref())?;
            // Kept before the first change (a hook switched to a loader
            // found in RAM is one): a kill from here on leaves something to
            // undo.
            before_write(client, &self.under)?;
        }
        let mut start = if resident {
            Start::Resident
        } else {
            self.wrote = true;
            Start::Write
        };
        loop {
            let error = match self.hook_loader(client, start, before_write) {
                Ok(()) => break,
                Err(error) if recoverable(&error) && self.recoveries < MAX_RECOVERIES => error,
                Err(error) => return Err(error),
            };
            // A reset, most likely: find the robot and start over (what is
            // in RAM already only needs verifying).
            self.recoveries += 1;
            let rate = self.find_rate(client).map_err(|_| error)?;
            progress.event(&Event::LoaderRestored {
                hook: None,
                baud: rate,
            });
            start = Start::Verify;
        }
        let (address, len) = self.placement();
        progress.event(&Event::LoaderInstalled {
            address,
            len,
            baud: self.target,
        });
        Ok(())
    }

    /// What `rate`'s place holds (one read; `None` for a lost or garbled
    /// answer): `rate` as linked means the loader is probably in RAM
    /// already.
    fn read_rate<T: Transport>(&self, client: &mut Client<T>) -> Result<Option<Vec<u8>>> {
        let rate = self.loader.rate_part()?;
        let area = &rate.areas()[0];
        let Ok(span) = ReadSpan::new(area.address, area.bytes.len() as u8) else {
            return Ok(None);
        };
        match client.ask(&Command::ReadMemory(span)) {
            Ok(Answer::Memory(bytes)) => Ok(Some(bytes)),
            Ok(_) | Err(Error::Protocol(_) | Error::NoAnswer { .. } | Error::WrongBaud { .. }) => {
                Ok(None)
            }
            Err(error) => Err(error),
        }
    }

    /// What the loader's code and zero page are about to overwrite, read
    /// until two answers agree (nothing when it was found in RAM,
    /// `resident`: an earlier upload left it, and that is what was there;
    /// its zero page is then read after `/1F`, see `keep_zero_page`). `seen` is the
    /// one answer `read_rate` had for the start of that place: a second
    /// read that agrees is taken at once, as is RAM that reads as zeros at
    /// the first answer (the virtual robot's, or a fresh one's), with the
    /// trust a delta upload puts in a sum.
    fn read_under<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        resident: bool,
        seen: Option<&[u8]>,
    ) -> Result<Vec<Area>> {
        if resident {
            return Ok(Vec::new());
        }
        let address = self.loader.address();
        let expected: Vec<Option<u8>> = (0..self.loader.len())
            .map(|at| Some(seen.and_then(|seen| seen.get(at).copied()).unwrap_or(0)))
            .collect();
        let code = Area {
            address,
            bytes: client.read_expecting(address, &expected)?,
        };
        // The zero page too, now: all of it is then kept before the first
        // write (time matters less where the loader is written at all).
        let zero_page = u16::from(self.loader.zero_page);
        let state = Area {
            address: zero_page,
            bytes: client.read_expecting(zero_page, &[Some(0); ZERO_PAGE_LEN as usize])?,
        };
        self.zero_page_kept = true;
        Ok(vec![code, state])
    }

    /// The loader's zero page as it was, read until two answers agree,
    /// once (a recovery finds it written by `frames`): read after `/1F`,
    /// at the fast rate, where nothing of the loader that touches it
    /// (`frames`, `sums`) has run yet; `rate` does not.
    fn keep_zero_page<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        before_write: &mut BeforeWrite<'_, T>,
    ) -> Result<()> {
        if !self.keep_under || self.zero_page_kept {
            return Ok(());
        }
        let address = u16::from(self.loader.zero_page);
        let bytes = client.read_memory(address, usize::from(ZERO_PAGE_LEN))?;
        self.under.push(Area { address, bytes });
        self.zero_page_kept = true;
        // In the file before `frames` runs and uses it.
        before_write(client, &self.under)
    }

    /// What the loader overwrote, as [`Session::keep_under`] asked (empty
    /// once taken).
    pub(crate) fn take_under(&mut self) -> Vec<Area> {
        std::mem::take(&mut self.under)
    }

    /// Verifies (or writes) the loader and hooks it, switching the line
    /// to the fast rate on the way if it is not there: `rate` and `frames`
    /// through the ROM, `frames` hooked, `sums` through `frames`, `sums`
    /// hooked. Each part is hooked only once it and every part it falls
    /// into verified. The robot answers at the host's rate when this
    /// starts.
    fn hook_loader<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        mut start: Start,
        before_write: &mut BeforeWrite<'_, T>,
    ) -> Result<()> {
        match self.fast {
            Some(fast) if client.transport().baud() != fast => {
                // `rate` found in RAM was read whole already, and ran on
                // this robot before (see `Start::Resident`). `rate` is
                // hooked before the jump table is compared: it obeys only
                // `/1F` and calls only CMD_DONE, so on another ROM the worst
                // it does is leave the robot for its reset button, with
                // nothing of the image written.
                if start != Start::Resident {
                    self.put_checked(client, &self.loader.rate_part()?, start, Vec::new())?;
                }
                switch_hook(client, self.hook, self.loader.rate, self.limits.max_writes)?;
                if !self.switch_rate(client, fast)? {
                    // This robot does not follow: the transfer runs at the
                    // base rate, and no later recovery tries again.
                    self.fast = None;
                }
                self.keep_zero_page(client, before_write)?;
                // A loader found in RAM: `frames` and `sums` read in one go
                // and, both as linked, `sums` hooked at once (it falls only
                // into parts now verified), sparing a hook and a wait.
                if start == Start::Resident && self.with_sums && self.keep_under {
                    let both = self.loader.frames_and_sums_part()?;
                    if self.resident_as_linked(client, &both, start, before_write)? {
                        self.target = client.transport().baud();
                        return switch_hook(
                            client,
                            self.hook,
                            self.loader.sums,
                            self.limits.max_writes,
                        );
                    }
                    // Changed since (kept above): written again, verified.
                    start = Start::Verify;
                }
                let part = self.loader.frames_part()?;
                self.verify_rom_part(client, &part, start, before_write)?;
            }
            _ => {
                self.keep_zero_page(client, before_write)?;
                let part = self.loader.rom_part()?;
                self.verify_rom_part(client, &part, start, before_write)?;
            }
        }
        self.target = client.transport().baud();
        switch_hook(
            client,
            self.hook,
            self.loader.frames,
            self.limits.max_writes,
        )?;
        if !self.with_sums {
            return Ok(());
        }
        let part = self.loader.sums_part()?;
        if !self.resident_as_linked(client, &part, start, before_write)? {
            self.put_framed(client, &part, start)?;
        }
        switch_hook(client, self.hook, self.loader.sums, self.limits.max_writes)
    }

    /// [`Session::put_then_check_rom`], after [`Session::resident_as_linked`].
    fn verify_rom_part<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        part: &UploadImage,
        start: Start,
        before_write: &mut BeforeWrite<'_, T>,
    ) -> Result<()> {
        if !self.resident_as_linked(client, part, start, before_write)? {
            return self.put_then_check_rom(client, part, start);
        }
        if !self.with_sums {
            self.check_rom(client)?;
        }
        Ok(())
    }

    /// Under [`Session::keep_under`], a part of a loader found in RAM is
    /// read before it is verified, so that bytes changed since the upload
    /// that left it (by hand, a glitch) are kept for the undo, and in its
    /// file, before the verification writes over them. Whether the part
    /// holds what it should (then it needs nothing more: that read was
    /// the verification); `false` where there is nothing to keep.
    fn resident_as_linked<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        part: &UploadImage,
        start: Start,
        before_write: &mut BeforeWrite<'_, T>,
    ) -> Result<bool> {
        if start != Start::Resident || !self.keep_under {
            return Ok(false);
        }
        let mut changed = false;
        for area in part.areas() {
            let expected: Vec<Option<u8>> = area.bytes.iter().copied().map(Some).collect();
            let held = client.read_expecting(area.address, &expected)?;
            let differing = held.iter().zip(&area.bytes).enumerate();
            let mut differing = differing.filter(|(_, (held, linked))| held != linked);
            if let Some((first, _)) = differing.next() {
                let last = differing.next_back().map_or(first, |(at, _)| at);
                self.under.push(Area {
                    address: area.address + first as u16,
                    bytes: held[first..=last].to_vec(),
                });
                changed = true;
            }
        }
        if changed {
            before_write(client, &self.under)?;
        }
        Ok(!changed)
    }

    /// Puts a part of the loader in through the ROM's commands with the
    /// robot's jump table compared on the way (its answers ride on the
    /// return wire while the `/9W`s go out); the part is hooked only after
    /// this returns. A comparison that did not pass (a lost answer, noise,
    /// another ROM) is read again until two answers agree.
    fn put_then_check_rom<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        part: &UploadImage,
        start: Start,
    ) -> Result<()> {
        if start == Start::Resident && self.with_sums {
            // `sums` compares the table, cheaper than reading it.
            return self
                .put_checked(client, part, start, Vec::new())
                .map(|_| ());
        }
        let checks = match &self.rom_check {
            Some(profile) => crate::fingerprint::table_checks(profile),
            None => Vec::new(),
        };
        if self.put_checked(client, part, start, checks)? {
            self.rom_check = None;
        }
        self.check_rom(client)
    }

    /// Puts loader bytes into the robot through the ROM, verified, with
    /// read-only comparisons on the way; whether they passed.
    fn put_checked<T: Transport>(
        &self,
        client: &mut Client<T>,
        image: &UploadImage,
        start: Start,
        checks: Vec<(ReadSpan, Vec<u8>)>,
    ) -> Result<bool> {
        let mut body = Body::new(image, Writer::Rom);
        match start {
            Start::Write => body.plan_writes(client.transport().baud(), &mut NoProgress),
            Start::Verify | Start::Resident => body.plan_reads(&mut NoProgress),
        }
        body.add_checks(checks);
        match body.run(client, self.limits, &mut NoProgress)? {
            RunEnd::Done | RunEnd::CheckLoader => Ok(body.checks_passed()),
        }
    }

    /// The right ROM before `frames`, which calls into its jump table, is
    /// hooked (once): the whole table read until two answers agree.
    fn check_rom<T: Transport>(&mut self, client: &mut Client<T>) -> Result<()> {
        if let Some(profile) = &self.rom_check {
            crate::fingerprint::check_jump_table(client, profile)?;
            self.rom_check = None;
        }
        Ok(())
    }

    /// Puts loader bytes into the robot through `frames` (hooked),
    /// verified.
    fn put_framed<T: Transport>(
        &self,
        client: &mut Client<T>,
        image: &UploadImage,
        start: Start,
    ) -> Result<()> {
        let mut body = Body::new(image, Writer::Frames);
        match start {
            Start::Write => body.plan_writes(client.transport().baud(), &mut NoProgress),
            Start::Verify | Start::Resident => body.plan_reads(&mut NoProgress),
        }
        for _ in 0..3 {
            match body.run(client, self.limits, &mut NoProgress)? {
                RunEnd::Done => return Ok(()),
                RunEnd::CheckLoader => body.interrupted(),
            }
        }
        // Frames keep not landing: `frames` is gone (a reset). A recovery
        // starts over from the ROM's commands.
        Err(Error::NoAnswer {
            port: client.transport().name(),
            baud: client.transport().baud(),
            question: "/1L".into(),
            waited: Duration::ZERO,
        })
    }

    /// Sends `/1F` (`rate` toggles the line, reached directly or through
    /// `frames`), then moves the host to `to` and checks the robot answers
    /// there. If it does not, the robot is looked for: `false` means it
    /// stayed at the rate it was at.
    fn switch_rate<T: Transport>(&mut self, client: &mut Client<T>, to: u32) -> Result<bool> {
        let from = client.transport().baud();
        for _ in 0..client.config().question_attempts.max(1) {
            send_toggle(client, to)?;
            // Two asks at each rate: a lost answer is rare, and
            // `find_rate` asks again at both if neither answers.
            if client.probe_with(2).is_ok() {
                return Ok(true);
            }
            client.transport().set_baud(from)?;
            client.transport().clear_input()?;
            if client.probe_with(2).is_err() {
                break;
            }
            // Still at the old rate: the command was lost; again.
        }
        // Neither rate answers cleanly: leave it to `find_rate`.
        let rate = self.find_rate(client)?;
        Ok(rate == to)
    }

    /// Finds the rate the robot answers at among the host's current rate,
    /// the base and the fast rate, and leaves the host there.
    fn find_rate<T: Transport>(&self, client: &mut Client<T>) -> Result<u32> {
        let mut rates = vec![client.transport().baud()];
        for rate in [Some(self.base), self.fast, Some(self.target)]
            .into_iter()
            .flatten()
        {
            if !rates.contains(&rate) {
                rates.push(rate);
            }
        }
        let mut last = None;
        for _ in 0..2 {
            for &rate in &rates {
                client.transport().set_baud(rate)?;
                client.transport().clear_input()?;
                match client.probe() {
                    Ok(_) => return Ok(rate),
                    Err(error) => last = Some(error),
                }
            }
        }
        Err(last.unwrap_or(Error::NoAnswer {
            port: client.transport().name(),
            baud: self.base,
            question: "/1X".into(),
            waited: Duration::ZERO,
        }))
    }

    /// Makes sure `frames` is hooked and the line at the transfer's rate,
    /// restoring both after a reset.
    fn ensure<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        let rate = self.find_rate(client)?;
        let mut known = vec![
            self.loader.sums,
            self.loader.frames,
            self.loader.rate,
            self.original,
        ];
        known.extend(self.reset);
        // A hook that no longer holds a `JMP` (a `/9W` whose address noise
        // changed) is written whole again by `hook_loader`.
        let current = match read_hook(client, HookKind::Unknown, self.hook, &known) {
            Ok(current) => Some(current),
            Err(Error::NotAHook { .. }) => None,
            Err(error) => return Err(error),
        };
        if current == Some(self.handler()) && rate == self.target {
            return Ok(());
        }
        progress.event(&Event::LoaderRestored {
            hook: current,
            baud: rate,
        });
        self.recoveries += 1;
        self.hook_loader(client, Start::Verify, &mut |_, _| Ok(()))
    }

    /// Carries the body in frames, checking and restoring the loader when
    /// frames stop landing or the line goes quiet.
    pub(crate) fn transfer<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        body: &mut Body,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        loop {
            let error = match body.run(client, self.limits, progress) {
                Ok(RunEnd::Done) => return Ok(()),
                Ok(RunEnd::CheckLoader) => None,
                Err(error) if recoverable(&error) => Some(error),
                Err(error) => return Err(error),
            };
            body.interrupted();
            if self.recoveries >= MAX_RECOVERIES {
                return Err(error.unwrap_or(Error::LoaderUnavailable {
                    reason: format!(
                        "it was lost and restored {MAX_RECOVERIES} times; the line is too noisy or the robot keeps resetting"
                    ),
                }));
            }
            match self.ensure(client, progress) {
                Ok(()) => {}
                // The line is dead: the first error says it best.
                Err(later) => return Err(error.unwrap_or(later)),
            }
            body.set_writer(Writer::Frames);
        }
    }

    /// Writes `areas` in frames verified by the robot's sums (`sums` must
    /// be in), checking and restoring the loader when the sums stop
    /// coming; after a restore the sums tell which ranges landed.
    pub(crate) fn transfer_summed<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        areas: &[crate::image::Area],
        progress: &mut dyn Progress,
    ) -> Result<Summed> {
        let mut held_maybe = false;
        let mut total = Summed::default();
        for _ in 0..=MAX_RECOVERIES {
            match write_summed(client, areas, held_maybe, self.limits, progress) {
                Ok(done) => {
                    total.rewrites += done.rewrites;
                    total.passes += done.passes;
                    return Ok(total);
                }
                Err(error) if recoverable(&error) => {
                    // fresh15 F5: on a noisy line the look for the loader
                    // can fail as the sums did; one failed look gave up
                    // with the loader hooked.
                    tried(ENSURE_ATTEMPTS, || self.ensure(client, progress)).map_err(|_| error)?;
                    held_maybe = true;
                    total.passes += 1;
                }
                Err(Error::SumFailed {
                    address,
                    len,
                    attempts,
                }) => {
                    // A range that will not hold: written and read back
                    // byte by byte, which names the byte (or, if noise was
                    // all it was, ends verified).
                    let part = areas_within(areas, address, len);
                    let image = UploadImage::new(part, Vec::new())?;
                    let mut body = Body::new(&image, Writer::Frames);
                    body.plan_writes(client.transport().baud(), progress);
                    let limits = self.limits;
                    self.limits.max_writes = limits.max_writes.saturating_sub(attempts).max(1);
                    let done = self.transfer(client, &mut body, progress);
                    self.limits = limits;
                    done?;
                    total.rewrites += body.rewrites;
                    total.passes += body.passes();
                    held_maybe = true;
                }
                Err(error) => return Err(error),
            }
        }
        Err(Error::LoaderUnavailable {
            reason: format!(
                "its sums stopped answering {MAX_RECOVERIES} times; the line is too noisy or the robot keeps resetting"
            ),
        })
    }

    /// Puts the line back on the base rate: `/1F` through the loader,
    /// restored first if a reset unhooked it. Unless `confirm`, the host
    /// moves without asking whether the robot followed: the questions the
    /// upload asks next (the hooks) tell, and if it did not, they reached
    /// it as characters at half its rate, which its 6551 takes as even
    /// bytes, never a slash, so the ROM ignores them; the caller then finds
    /// the robot and calls this again with `confirm`.
    pub(crate) fn back_to_base<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        confirm: bool,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        if client.transport().baud() == self.base {
            return Ok(());
        }
        if !confirm && self.base < client.transport().baud() {
            return send_toggle(client, self.base);
        }
        for _ in 0..=MAX_RECOVERIES {
            if client.transport().baud() == self.base || self.switch_rate(client, self.base)? {
                return Ok(());
            }
            // Still fast: the loader may be gone (a `/1R`); restore it so
            // that its `/1F` can be obeyed.
            if client.transport().baud() != self.base {
                self.ensure(client, progress)?;
            }
        }
        Err(Error::BaudChange {
            port: client.transport().name(),
            baud: self.base,
            message: "the robot did not come back to its base rate".into(),
        })
    }

    /// Takes the loader out after an upload failed on a line that still
    /// works (a byte that would not hold, say): the line back on the base
    /// rate, `HOOK_UNKNOWN` back on its target before the upload. A failed
    /// upload then leaves the robot answering where the user expects it,
    /// with nothing of this upload hooked.
    pub(crate) fn remove<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        self.back_to_base(client, true, progress)?;
        switch_hook(client, self.hook, self.original, self.limits.max_writes)?;
        progress.event(&Event::LoaderRemoved);
        Ok(())
    }

    /// Checks the loader after an error a reset explains and restores it
    /// (and the line's rate) if it has to.
    pub(crate) fn recover<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        self.ensure(client, progress)
    }

    /// Finds the robot after an error a reset explains, and leaves the
    /// host at its rate.
    pub(crate) fn find<T: Transport>(&mut self, client: &mut Client<T>) -> Result<u32> {
        self.find_rate(client)
    }
}

/// `attempt` up to `times` times, until it succeeds: its last result. For
/// looks a noisy line can fail one at a time.
pub(crate) fn tried<R>(times: u32, attempt: impl FnMut() -> Result<R>) -> Result<R> {
    tried_while(times, |_| true, attempt)
}

/// [`tried`], again only where nothing at all came back ([`Error::NoAnswer`]:
/// a line quiet a while, fresh15 F5), not where answers came damaged (a
/// noisy line, whose next try meets the same noise and whose caller gives
/// up fast).
///
/// # Errors
/// The last attempt's.
pub(crate) fn tried_quiet<R>(times: u32, attempt: impl FnMut() -> Result<R>) -> Result<R> {
    tried_while(
        times,
        |error| matches!(error, Error::NoAnswer { .. }),
        attempt,
    )
}

/// `attempt` up to `times` times, again while it fails with an error
/// `again` takes: its last result.
fn tried_while<R>(
    times: u32,
    again: impl Fn(&Error) -> bool,
    mut attempt: impl FnMut() -> Result<R>,
) -> Result<R> {
    let mut result = attempt();
    for _ in 1..times {
        match &result {
            Err(error) if again(error) => result = attempt(),
            _ => break,
        }
    }
    result
}

/// Sends `/1F` once every answer is in (the 6551 must not be sending when
/// its rate changes), waits until the robot has obeyed it, and moves the
/// host to `to`.
fn send_toggle<T: Transport>(client: &mut Client<T>, to: u32) -> Result<()> {
    let from = client.transport().baud();
    client.drain()?;
    client.send(&Command::Extension(Extension::new(b"F".as_slice())?))?;
    let until = client.transport().now() + char_time(3, from) + SWITCH_SETTLE;
    client.wait_until(until)?;
    client.transport().set_baud(to)?;
    client.transport().clear_input()
}

/// The bytes of `areas` from `address` for `len` bytes.
fn areas_within(areas: &[crate::image::Area], address: u16, len: usize) -> Vec<crate::image::Area> {
    let (from, to) = (u32::from(address), u32::from(address) + len as u32);
    areas
        .iter()
        .filter_map(|area| {
            let start = from.max(u32::from(area.address));
            let end = to.min(area.end());
            (start < end).then(|| crate::image::Area {
                address: start as u16,
                bytes: area.bytes[(start - u32::from(area.address)) as usize
                    ..(end - u32::from(area.address)) as usize]
                    .to_vec(),
            })
        })
        .collect()
}

/// Errors a reset or a passing line fault explains: the robot may answer
/// again, at one of the two rates.
pub(crate) fn recoverable(error: &Error) -> bool {
    matches!(
        error,
        Error::Stalled { .. }
            | Error::Unreadable { .. }
            | Error::NoAnswer { .. }
            | Error::WrongBaud { .. }
    )
}

/// Whether loader bytes are written or only verified (they may be there
/// already).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Start {
    Write,
    Verify,
    /// `rate` read back as linked: the loader of an earlier upload,
    /// which compared this robot's jump table and ROM with the profile's
    /// before it hooked anything, and the robot has stayed powered since
    /// (its RAM still holds the loader). The rest only needs verifying,
    /// and the jump table is compared by `sums` (a read if the sums
    /// differ).
    Resident,
}
