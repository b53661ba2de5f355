//! Running the RAM loader: install its stages through the ROM (each
//! verified before it is hooked), switch the line to the fast rate, carry
//! the body in frames, recover the loader after a reset, and put the line
//! back on the base rate at the end.
//!
//! Resets are why this is more than a sequence of steps. A `/1R` (the
//! ROM's soft reset) puts the hooks back but leaves the 6551 at whatever
//! rate it runs; the reset button also puts the 6551 back on its DIP
//! switches. Either way the loader is no longer hooked, so frames stop
//! landing. [`Session::ensure`] finds the rate the robot answers at, checks
//! `HOOK_UNKNOWN`, verifies the stages (they are still in RAM, so that is a
//! read) and hooks them again.

use std::time::Duration;

use isa::objfmt::HookKind;
use romlib::protocol::{Command, Extension};

use crate::body::{Body, Limits, RunEnd, Writer};
use crate::client::Client;
use crate::hooks::{read_hook, switch_hook};
use crate::image::{RomProfile, UploadImage};
use crate::loader::Loader;
use crate::progress::{Event, NoProgress, Phase, Progress};
use crate::transport::{Transport, char_time};
use crate::{Error, Result};

/// How often the loader is restored before the upload gives up.
const MAX_RECOVERIES: u32 = 6;

/// The loader during one upload.
#[derive(Debug)]
pub(crate) struct Session {
    loader: Loader,
    hook: u16,
    /// `HOOK_UNKNOWN`'s target before the upload: the frames stage's
    /// fallthrough.
    original: u16,
    /// The ROM's reset target of `HOOK_UNKNOWN`, if known.
    reset: Option<u16>,
    base: u32,
    /// The rate the transfer runs at once the loader is in: `fast` if the
    /// switch worked, else `base`.
    target: u32,
    fast: Option<u32>,
    limits: Limits,
    /// Times the loader was restored.
    pub(crate) recoveries: u32,
}

impl Session {
    /// A session for `loader`; `fast` is the rate to switch to, if any.
    pub(crate) fn new(
        loader: Loader,
        profile: &RomProfile,
        original: u16,
        base: u32,
        fast: Option<u32>,
        limits: Limits,
    ) -> Self {
        Session {
            loader,
            hook: profile.hook_address(HookKind::Unknown),
            original,
            reset: profile.reset_target(HookKind::Unknown),
            base,
            target: base,
            fast: fast.filter(|&fast| {
                fast != base
                    && crate::loader::acia_control(fast).is_some()
                    && crate::loader::acia_control(base).is_some()
            }),
            limits,
            recoveries: 0,
        }
    }

    /// Where the frames stage runs: `HOOK_UNKNOWN`'s target while the
    /// loader is in.
    pub(crate) fn handler(&self) -> u16 {
        self.loader.frames.handler
    }

    /// The rate the transfer ran at.
    pub(crate) fn rate(&self) -> u32 {
        self.target
    }

    /// The loader's first address and size.
    pub(crate) fn placement(&self) -> (u16, usize) {
        (self.loader.address(), self.loader.len())
    }

    /// The frames stage with its chain slot filled: the rate switch, whose
    /// `/1F` takes the line back to the base rate (and which drops other
    /// commands, as the ROM's `BAD_COMMAND` does), or without a switch the
    /// hook's original target.
    fn frames_image(&self) -> UploadImage {
        let mut image = self.loader.frames.image.clone();
        let fallthrough = if self.fast.is_some() {
            self.loader.fast.handler
        } else {
            self.original
        };
        if let Some(slot) = self.loader.frames.chain {
            let [low, high] = fallthrough.to_le_bytes();
            image.set_byte(slot, low);
            image.set_byte(slot + 1, high);
        }
        image
    }

    /// Installs the loader: the fast stage at the base rate, the switch,
    /// the frames stage at the fast rate. Every stage verifies before it
    /// is hooked.
    pub(crate) fn install<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        progress.phase(Phase::Loader, self.loader.len());
        if let Some(fast) = self.fast {
            // Can the host's end run at the fast rate at all?
            let base = client.transport().baud();
            if client.transport().set_baud(fast).is_err() {
                self.fast = None;
            }
            client.transport().set_baud(base)?;
        }
        let mut start = Start::Write;
        loop {
            let error = match self.hook_stages(client, start) {
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

    /// Verifies (or writes) the stages and hooks them, switching the rate
    /// on the way. The robot answers at the host's rate when this starts.
    fn hook_stages<T: Transport>(&mut self, client: &mut Client<T>, start: Start) -> Result<()> {
        let at_fast = self
            .fast
            .is_some_and(|fast| client.transport().baud() == fast);
        if self.fast.is_some() {
            // The frames stage falls through to it, so it is verified
            // whether or not the line still needs switching.
            let stage = self.loader.fast.image.clone();
            self.put(client, &stage, start)?;
        }
        if let Some(fast) = self.fast
            && !at_fast
        {
            let handler = self.loader.fast.handler;
            switch_hook(client, self.hook, handler, self.limits.max_writes)?;
            self.target = if self.switch_rate(client, fast)? {
                fast
            } else {
                self.base
            };
        } else {
            self.target = client.transport().baud();
        }
        let frames = self.frames_image();
        self.put(client, &frames, start)?;
        switch_hook(
            client,
            self.hook,
            self.loader.frames.handler,
            self.limits.max_writes,
        )
    }

    /// Puts a stage's bytes into the robot through the ROM, verified.
    fn put<T: Transport>(
        &self,
        client: &mut Client<T>,
        image: &UploadImage,
        start: Start,
    ) -> Result<()> {
        let mut body = Body::new(image, Writer::Rom);
        match start {
            Start::Write => body.plan_writes(&mut NoProgress),
            Start::Verify => body.plan_reads(&mut NoProgress),
        }
        match body.run(client, self.limits, &mut NoProgress)? {
            RunEnd::Done | RunEnd::CheckLoader => Ok(()),
        }
    }

    /// Sends `/1F` (the rate switch toggles the line, directly or through
    /// the frames stage), then moves the host to `to` and checks the robot
    /// answers there. If it does not, the robot is looked for at the rate it was
    /// at: `false` means it never left it.
    fn switch_rate<T: Transport>(&mut self, client: &mut Client<T>, to: u32) -> Result<bool> {
        let from = client.transport().baud();
        let command = Command::Extension(Extension::new(b"F".as_slice())?);
        for _ in 0..client.config().question_attempts.max(1) {
            client.drain()?;
            client.send(&command)?;
            // The command's three characters, then the ROM's dispatch.
            let settle = char_time(3, from) + Duration::from_millis(3);
            let until = client.transport().now() + settle;
            client.wait_until(until)?;
            client.transport().set_baud(to)?;
            client.transport().clear_input()?;
            if client.probe().is_ok() {
                return Ok(true);
            }
            client.transport().set_baud(from)?;
            if client.probe().is_err() {
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
        let mut rates = vec![client.transport().baud(), self.base];
        rates.extend(self.fast);
        rates.dedup();
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

    /// Makes sure the frames stage is hooked and the line at the
    /// transfer's rate, restoring both after a reset.
    fn ensure<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        let rate = self.find_rate(client)?;
        let mut known = vec![
            self.loader.frames.handler,
            self.loader.fast.handler,
            self.original,
        ];
        known.extend(self.reset);
        let current = read_hook(client, HookKind::Unknown, self.hook, &known)?;
        if current == self.loader.frames.handler && rate == self.target {
            return Ok(());
        }
        progress.event(&Event::LoaderRestored {
            hook: Some(current),
            baud: rate,
        });
        self.recoveries += 1;
        self.hook_stages(client, Start::Verify)
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

    /// Puts the line back on the base rate and, unless `keep_hooked` (the
    /// image takes `HOOK_UNKNOWN` next, replacing the loader in one
    /// switch), points `HOOK_UNKNOWN` back at its original target.
    pub(crate) fn finish<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        keep_hooked: bool,
        progress: &mut dyn Progress,
    ) -> Result<()> {
        if client.transport().baud() != self.base {
            for _ in 0..=MAX_RECOVERIES {
                if self.switch_rate(client, self.base)? {
                    break;
                }
                // Still fast: the loader may be gone (a `/1R`); restore it
                // so that its `/1F` can be obeyed.
                self.ensure(client, progress)?;
            }
            if client.transport().baud() != self.base {
                return Err(Error::BaudChange {
                    port: client.transport().name(),
                    baud: self.base,
                    message: "the robot did not come back to its base rate".into(),
                });
            }
        }
        if !keep_hooked {
            switch_hook(client, self.hook, self.original, self.limits.max_writes)?;
            progress.event(&Event::LoaderRemoved);
        }
        Ok(())
    }
}

/// Errors a reset or a passing line fault explains: the robot may answer
/// again, at one of the two rates.
fn recoverable(error: &Error) -> bool {
    matches!(
        error,
        Error::Stalled { .. }
            | Error::Unreadable { .. }
            | Error::NoAnswer { .. }
            | Error::WrongBaud { .. }
    )
}

/// Whether a stage is written or only verified (it may be there already).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Start {
    Write,
    Verify,
}
