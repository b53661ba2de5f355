//! The upload: connect, read the hooks, write every loaded byte with
//! `/9W` (and `/7W` for an odd one) while `/7R` questions verify what was
//! written on the otherwise idle return wire, rewrite what differs, and
//! install hooks only once the whole body has verified.
//!
//! Safety rules, in order of importance:
//! - A hook is switched only after every byte of the image verified, by one
//!   `/9W` of its operand, then read back twice.
//! - When anything suspicious happened (a lost, late or garbled answer, a
//!   byte that read back wrong), a `/9W` could have had its address digits
//!   changed by noise and landed on bytes already verified: so a read-only
//!   pass over every byte follows, and the upload is done only after a pass
//!   in which nothing had to be written.
//! - A chain slot receives the hook's target as read just before the
//!   switch, so an extension falls through to whatever was there.

use std::collections::{HashMap, VecDeque};
use std::time::Duration;

use isa::objfmt::HookKind;
use romlib::protocol::{Answer, Command, ReadSpan, WordWrite};

use crate::client::{Client, ClientConfig, Outcome, pieces, spans};
use crate::image::{RomProfile, UploadImage};
use crate::progress::{Event, Phase, Progress};
use crate::transport::Transport;
use crate::{Error, Result};

/// How an upload behaves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UploadOptions {
    /// Where the ROM keeps its hooks and what may be written.
    pub profile: RomProfile,
    /// The most times one byte is written before the upload fails.
    pub max_writes: u32,
    /// The most read-only verification passes after faults.
    pub max_passes: u32,
    /// Consecutive lost or garbled answers tolerated.
    pub max_lost: u32,
}

impl Default for UploadOptions {
    fn default() -> Self {
        UploadOptions {
            profile: RomProfile::default(),
            max_writes: 8,
            max_passes: 6,
            max_lost: 200,
        }
    }
}

/// A hook the upload switched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InstalledHook {
    /// Which hook.
    pub kind: HookKind,
    /// Where it points now.
    pub handler: u16,
    /// Where it pointed before: the extension's fallthrough.
    pub previous: u16,
}

/// What an upload did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UploadReport {
    /// Bytes loaded and verified.
    pub bytes: usize,
    /// Time on the transport's clock (emulated seconds on the virtual
    /// Scorpion) from the first probe to the last hook verified.
    pub device_time: Duration,
    /// Characters sent to the robot.
    pub chars_sent: usize,
    /// Characters received from it.
    pub chars_received: usize,
    /// Bytes written again after reading back wrong.
    pub rewrites: usize,
    /// Answers lost, late or garbled.
    pub lost_answers: usize,
    /// Read-only verification passes run after faults.
    pub final_passes: u32,
    /// The hooks switched.
    pub hooks: Vec<InstalledHook>,
}

/// One loaded byte's state.
#[derive(Debug, Clone, Copy, Default)]
struct ByteState {
    verified: bool,
    /// A rewrite is queued and not yet sent.
    queued: bool,
    writes: u32,
    /// Sequence number of the last command that wrote it.
    last_write: u64,
    /// A wrong value one read showed since the last write: rewritten only
    /// when a second read agrees, so a corrupted answer costs a read, not
    /// a write.
    suspect: Option<u8>,
    /// The last wrong value seen, for the failure message.
    found: Option<u8>,
}

#[derive(Debug, Clone, Copy)]
enum Work {
    Write { address: u16, len: u8 },
    Read(ReadSpan),
}

/// The body transfer: the image's bytes, flattened, with their states.
struct Body<'a> {
    image: &'a UploadImage,
    /// (address, offset into the flat arrays) per area.
    index: Vec<(u16, usize, usize)>,
    expected: Vec<u8>,
    state: Vec<ByteState>,
    verified: usize,
    seq: u64,
    read_seq: HashMap<u64, u64>,
    queue: VecDeque<Work>,
    anomalies: usize,
    wrote: bool,
    lost_in_row: u32,
    /// The longest question asked now: halved when an answer is lost.
    read_size: u8,
    last_error: Option<romlib::protocol::ProtocolError>,
    rewrites: usize,
}

impl<'a> Body<'a> {
    fn new(image: &'a UploadImage) -> Self {
        let mut index = Vec::new();
        let mut expected = Vec::with_capacity(image.len());
        for area in image.areas() {
            index.push((area.address, expected.len(), area.bytes.len()));
            expected.extend_from_slice(&area.bytes);
        }
        let state = vec![ByteState::default(); expected.len()];
        Body {
            image,
            index,
            expected,
            state,
            verified: 0,
            seq: 1,
            read_seq: HashMap::new(),
            queue: VecDeque::new(),
            anomalies: 0,
            wrote: false,
            lost_in_row: 0,
            read_size: romlib::protocol::MAX_READ,
            last_error: None,
            rewrites: 0,
        }
    }

    fn offset(&self, address: u16) -> Option<usize> {
        self.index.iter().find_map(|&(start, offset, len)| {
            let delta = usize::from(address.wrapping_sub(start));
            (address >= start && delta < len).then_some(offset + delta)
        })
    }

    /// Writes of every byte with a verifying read after each span.
    fn plan_writes(&mut self) {
        for area in self.image.areas() {
            let mut next_write = u32::from(area.address);
            let end = area.end();
            for span in spans(area.address, area.bytes.len()) {
                let span_end = u32::from(span.address()) + u32::from(span.count());
                while next_write < span_end {
                    let len = if next_write + 1 < end { 2 } else { 1 };
                    self.queue.push_back(Work::Write {
                        address: next_write as u16,
                        len,
                    });
                    next_write += u32::from(len);
                }
                self.queue.push_back(Work::Read(span));
            }
        }
    }

    /// Reads of every byte (a verification pass).
    fn plan_reads(&mut self) {
        for area in self.image.areas() {
            for span in pieces(area.address, area.bytes.len(), self.read_size) {
                self.queue.push_back(Work::Read(span));
            }
        }
    }

    fn command(&self, address: u16, len: u8) -> Result<Command> {
        let value = |at: u16| self.offset(at).map_or(0, |offset| self.expected[offset]);
        Ok(if len == 2 {
            Command::WriteWord(WordWrite::new(
                address,
                [value(address), value(address + 1)],
            )?)
        } else {
            Command::WriteByte {
                address,
                value: value(address),
            }
        })
    }

    /// Sends queued work while the client has room.
    fn pump<T: Transport>(&mut self, client: &mut Client<T>, max_writes: u32) -> Result<()> {
        while let Some(&work) = self.queue.front() {
            match work {
                Work::Write { address, len } => {
                    let command = self.command(address, len)?;
                    if client.room() < command.encode().len() {
                        break;
                    }
                    for at in address..address + u16::from(len) {
                        if let Some(offset) = self.offset(at) {
                            let state = &mut self.state[offset];
                            if state.writes >= max_writes {
                                return Err(Error::VerifyFailed {
                                    address: at,
                                    expected: self.expected[offset],
                                    found: state.found.unwrap_or(self.expected[offset]),
                                    attempts: state.writes,
                                });
                            }
                            state.writes += 1;
                            state.queued = false;
                            state.suspect = None;
                            state.last_write = self.seq;
                        }
                    }
                    client.send(&command)?;
                    self.wrote = true;
                }
                Work::Read(span) => {
                    if !client.can_ask(span.count()) {
                        break;
                    }
                    let tag = client.ask_read(span)?;
                    self.read_seq.insert(tag, self.seq);
                }
            }
            self.seq += 1;
            self.queue.pop_front();
        }
        Ok(())
    }

    fn answered(&mut self, span: ReadSpan, tag: u64, data: &[u8], progress: &mut dyn Progress) {
        self.lost_in_row = 0;
        self.read_size = self
            .read_size
            .saturating_add(2)
            .min(romlib::protocol::MAX_READ);
        let asked_at = self.read_seq.remove(&tag).unwrap_or(0);
        let mut wrong = Vec::new();
        let mut doubtful = Vec::new();
        for (i, &found) in data.iter().enumerate() {
            let address = span.address() + i as u16;
            let Some(offset) = self.offset(address) else {
                continue;
            };
            let state = &mut self.state[offset];
            // A read sent before the byte's last write says nothing about it.
            if state.queued || state.last_write > asked_at {
                continue;
            }
            if found == self.expected[offset] {
                if !state.verified {
                    state.verified = true;
                    self.verified += 1;
                }
            } else {
                if state.verified {
                    state.verified = false;
                    self.verified -= 1;
                }
                state.found = Some(found);
                if state.suspect == Some(found) {
                    wrong.push(address);
                } else {
                    state.suspect = Some(found);
                    doubtful.push(address);
                }
            }
        }
        progress.advanced(self.verified);
        if wrong.is_empty() && doubtful.is_empty() {
            return;
        }
        self.anomalies += 1;
        let mut reread = [wrong.as_slice(), doubtful.as_slice()].concat();
        reread.sort_unstable();
        if wrong.is_empty() {
            if let Ok(span) =
                ReadSpan::new(reread[0], (reread[reread.len() - 1] - reread[0] + 1) as u8)
            {
                self.queue.push_front(Work::Read(span));
            }
            return;
        }
        self.rewrites += wrong.len();
        progress.event(&Event::Rewrite {
            address: wrong[0],
            count: wrong.len(),
        });
        let mut work = Vec::new();
        let mut covered = 0u32;
        for &address in &wrong {
            if u32::from(address) < covered {
                continue;
            }
            let pair = address < 0xFFFF
                && self
                    .offset(address + 1)
                    .is_some_and(|next| Some(next) == self.offset(address).map(|o| o + 1));
            let len = if pair { 2 } else { 1 };
            work.push(Work::Write { address, len });
            covered = u32::from(address) + u32::from(len);
            for at in address..address + u16::from(len) {
                if let Some(offset) = self.offset(at) {
                    self.state[offset].queued = true;
                }
            }
        }
        let first = reread[0];
        let last = u32::from(reread[reread.len() - 1]);
        if let Ok(span) = ReadSpan::new(first, (last - u32::from(first) + 1) as u8) {
            work.push(Work::Read(span));
        }
        for item in work.into_iter().rev() {
            self.queue.push_front(item);
        }
    }

    fn lost(&mut self, span: ReadSpan, tag: u64, max_lost: u32) -> Result<()> {
        self.read_seq.remove(&tag);
        self.anomalies += 1;
        self.lost_in_row += 1;
        if self.lost_in_row > max_lost {
            return Err(Error::Unreadable {
                address: span.address(),
                attempts: self.lost_in_row,
                last: self.last_error.take(),
            });
        }
        // Ask again for the bytes of the span still unverified.
        let pending: Vec<u16> = (0..u16::from(span.count()))
            .map(|i| span.address() + i)
            .filter(|&at| self.offset(at).is_some_and(|o| !self.state[o].verified))
            .collect();
        self.read_size = (self.read_size / 2).max(4);
        if let (Some(&first), Some(&last)) = (pending.first(), pending.last()) {
            let parts: Vec<ReadSpan> =
                pieces(first, usize::from(last - first) + 1, self.read_size).collect();
            for part in parts.into_iter().rev() {
                self.queue.push_front(Work::Read(part));
            }
        }
        Ok(())
    }

    /// Queues reads for bytes no answer verified (after a pass whose
    /// questions were all answered, there are none unless a read was
    /// overtaken by a rewrite).
    fn requeue_unverified(&mut self) {
        let mut unverified = Vec::new();
        for &(start, offset, len) in &self.index {
            for i in 0..len {
                if !self.state[offset + i].verified {
                    unverified.push(start + i as u16);
                }
            }
        }
        let mut i = 0;
        while i < unverified.len() {
            // A run of consecutive unverified addresses.
            let first = unverified[i];
            let mut j = i;
            while j + 1 < unverified.len() && unverified[j + 1] == unverified[j] + 1 {
                j += 1;
            }
            let len = usize::from(unverified[j] - first) + 1;
            for span in pieces(first, len, self.read_size) {
                self.queue.push_back(Work::Read(span));
            }
            i = j + 1;
        }
    }

    fn run<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        options: &UploadOptions,
        progress: &mut dyn Progress,
    ) -> Result<u32> {
        let mut pass = 0u32;
        self.plan_writes();
        progress.phase(Phase::Write, self.expected.len());
        loop {
            self.pump(client, options.max_writes)?;
            if self.queue.is_empty() && client.in_flight() == 0 {
                if self.verified < self.expected.len() {
                    self.requeue_unverified();
                    continue;
                }
                let done = if pass == 0 {
                    self.anomalies == 0
                } else {
                    !self.wrote
                };
                if done {
                    return Ok(pass);
                }
                pass += 1;
                if pass > options.max_passes {
                    let (address, expected, found, attempts) = self.worst();
                    return Err(Error::VerifyFailed {
                        address,
                        expected,
                        found,
                        attempts,
                    });
                }
                for state in &mut self.state {
                    state.verified = false;
                }
                self.verified = 0;
                self.wrote = false;
                self.plan_reads();
                progress.phase(Phase::FinalVerify, self.expected.len());
                continue;
            }
            let limit = client.config().stall_limit;
            for outcome in client.poll(limit)? {
                match outcome {
                    Outcome::Answered { span, tag, data } => {
                        self.answered(span, tag, &data, progress);
                    }
                    Outcome::Lost { span, tag } => {
                        progress.event(&Event::LostAnswer {
                            address: span.address(),
                        });
                        self.lost(span, tag, options.max_lost)?;
                    }
                    Outcome::Stray(error) => {
                        self.anomalies += 1;
                        if let Some(error) = error {
                            progress.event(&Event::MalformedAnswer(error.clone()));
                            self.last_error = Some(error);
                        }
                    }
                }
            }
        }
    }

    /// The byte written most often, for the failure message.
    fn worst(&self) -> (u16, u8, u8, u32) {
        let mut worst = (0u16, 0u8, 0u8, 0u32);
        for &(start, offset, len) in &self.index {
            for i in 0..len {
                let state = self.state[offset + i];
                if state.writes > worst.3 || worst.3 == 0 {
                    let expected = self.expected[offset + i];
                    worst = (
                        start + i as u16,
                        expected,
                        state.found.unwrap_or(expected),
                        state.writes,
                    );
                }
            }
        }
        worst
    }
}

/// Reads a hook's `JMP` target, twice until two reads agree, so a
/// corrupted answer cannot fake it.
fn read_hook<T: Transport>(client: &mut Client<T>, kind: HookKind, address: u16) -> Result<u16> {
    let span = ReadSpan::new(address, 3)?;
    let mut previous = None;
    for _ in 0..client.config().question_attempts.max(2) * 2 {
        let Answer::Memory(bytes) = client.ask(&Command::ReadMemory(span))? else {
            continue;
        };
        if bytes[0] != 0x4C {
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
        if previous == Some(Some(target)) {
            return Ok(target);
        }
        previous = Some(Some(target));
    }
    Err(Error::Unreadable {
        address,
        attempts: client.config().question_attempts * 2,
        last: None,
    })
}

/// Writes two bytes with `/9W` until two reads agree they are there.
fn write_word_verified<T: Transport>(
    client: &mut Client<T>,
    address: u16,
    value: [u8; 2],
    max_writes: u32,
) -> Result<()> {
    let span = ReadSpan::new(address, 2)?;
    let mut found = [0u8; 2];
    for _ in 0..max_writes {
        client.send(&Command::WriteWord(WordWrite::new(address, value)?))?;
        let first = client.ask(&Command::ReadMemory(span))?;
        let second = client.ask(&Command::ReadMemory(span))?;
        if let (Answer::Memory(a), Answer::Memory(b)) = (&first, &second) {
            if a == b && a.as_slice() == value {
                return Ok(());
            }
            found.copy_from_slice(&a[..2]);
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

/// Uploads `image` through `client`: body, verification, then hooks.
///
/// # Errors
/// Any [`Error`]; on every error path, no hook points at code that did not
/// verify (hooks are the last thing written).
pub fn upload<T: Transport>(
    client: &mut Client<T>,
    image: &UploadImage,
    options: &UploadOptions,
    progress: &mut dyn Progress,
) -> Result<UploadReport> {
    options.profile.check(image)?;
    let start = client.transport().now();
    let stats_before = client.stats();
    progress.phase(Phase::Connect, image.len());
    client.probe()?;
    let profile = &options.profile;

    // The hooks as they are now; disarm any that points into memory this
    // upload will overwrite, since the old code there is about to change.
    let mut initial = Vec::new();
    for kind in HookKind::ALL {
        let address = profile.hook_address(kind);
        let mut target = read_hook(client, kind, address)?;
        if image.contains(target) {
            let Some(reset) = profile.reset_target(kind) else {
                return Err(Error::HookInUse {
                    hook: kind.rom_symbol(),
                    target,
                });
            };
            write_word_verified(client, address + 1, reset.to_le_bytes(), options.max_writes)?;
            progress.event(&Event::HookDisarmed {
                kind,
                from: target,
                to: reset,
            });
            target = reset;
        }
        initial.push((kind, target));
    }

    // Chain slots get the hooks' current targets before the body goes out,
    // so they are verified with it.
    let mut image = image.clone();
    for record in image.hooks().to_vec() {
        if let (Some(slot), Some(&(_, target))) = (
            record.chain,
            initial.iter().find(|(kind, _)| *kind == record.kind),
        ) {
            let [low, high] = target.to_le_bytes();
            image.set_byte(slot, low);
            image.set_byte(slot + 1, high);
        }
    }

    let mut body = Body::new(&image);
    let final_passes = body.run(client, options, progress)?;
    let rewrites = body.rewrites;

    // Hooks last.
    progress.phase(Phase::Hooks, image.hooks().len());
    let mut hooks = Vec::new();
    for record in image.hooks() {
        let address = profile.hook_address(record.kind);
        let before = initial
            .iter()
            .find(|(kind, _)| *kind == record.kind)
            .map_or(0, |&(_, target)| target);
        let current = read_hook(client, record.kind, address)?;
        if current != before {
            progress.event(&Event::HookChanged {
                kind: record.kind,
                before,
                after: current,
            });
            if image.contains(current) {
                return Err(Error::RobotReset {
                    hook: record.kind.rom_symbol(),
                    before,
                    after: current,
                });
            }
            if let Some(slot) = record.chain {
                write_word_verified(client, slot, current.to_le_bytes(), options.max_writes)?;
            }
        }
        write_word_verified(
            client,
            address + 1,
            record.handler.to_le_bytes(),
            options.max_writes,
        )?;
        let installed = InstalledHook {
            kind: record.kind,
            handler: record.handler,
            previous: current,
        };
        progress.event(&Event::HookInstalled {
            kind: installed.kind,
            handler: installed.handler,
            previous: installed.previous,
        });
        hooks.push(installed);
    }

    let stats = client.stats();
    Ok(UploadReport {
        bytes: image.len(),
        device_time: client.transport().now().saturating_sub(start),
        chars_sent: stats.sent - stats_before.sent,
        chars_received: stats.received - stats_before.received,
        rewrites,
        lost_answers: stats.lost - stats_before.lost,
        final_passes,
        hooks,
    })
}

/// A client with the default pacing.
pub fn client<T: Transport>(transport: T) -> Client<T> {
    Client::new(transport, ClientConfig::default())
}
