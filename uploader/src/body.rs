//! The body transfer: every loaded byte written (with the ROM's `/9W` and
//! `/7W`, or in the RAM loader's frames) while `/7R` questions verify what
//! was written on the otherwise idle return wire; what reads back wrong is
//! written again, and after any fault a read-only pass covers every byte.
//!
//! Why the read-only pass: noise can change the address digits of a `/9W`
//! (or the header of a frame that still checks), so a write may land on
//! bytes already verified. The transfer is done only after a pass in which
//! nothing had to be written.

use std::collections::{HashMap, VecDeque};

use romlib::protocol::{Command, MAX_READ, ProtocolError, ReadSpan, WordWrite};

use crate::client::{Client, Outcome, pieces};
use crate::image::UploadImage;
use crate::loader::{FRAME_MAX, frame};
use crate::progress::{Event, Phase, Progress};
use crate::taper::{TAIL, rom_tail};
use crate::transport::Transport;
use crate::{Error, Result};

/// The first spans of a frame transfer. The return wire idles until the
/// first question arrives, so the first frame is short; each answer
/// (two characters a byte) must then last while the next frame and
/// question go out (one character a byte, eighteen more) and are taken,
/// so the spans grow by less than double. They differ by at least eight
/// bytes, so their questions can be in flight together.
const RAMP: [usize; 4] = [20, 28, 44, 60];

/// How bytes are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Writer {
    /// The ROM's `/9W` (two bytes) and `/7W` (an odd last one).
    Rom,
    /// The RAM loader's `/1L` frames.
    Frames,
}

/// The limits of one transfer.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    /// The most times one byte is written.
    pub(crate) max_writes: u32,
    /// The most read-only passes.
    pub(crate) max_passes: u32,
    /// Consecutive lost or garbled answers tolerated.
    pub(crate) max_lost: u32,
}

/// Why [`Body::run`] returned without an error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RunEnd {
    /// Every byte verified, in a pass that wrote nothing after a fault.
    Done,
    /// Frames keep not landing: the loader may be gone (a reset). The
    /// caller checks it and calls [`Body::run`] again.
    CheckLoader,
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
    Write {
        address: u16,
        len: u8,
    },
    Read(ReadSpan),
    /// A read-only comparison (see [`Body::add_checks`]), by index.
    Check(usize),
}

/// Bytes outside the image compared with what they should be (the ROM's
/// jump table), read on the return wire's idle time.
struct Check {
    span: ReadSpan,
    expected: Vec<u8>,
    tag: Option<u64>,
    /// Whether the answer matched; `None` until one came.
    matched: Option<bool>,
}

/// The transfer of one image: its bytes, flattened, with their states.
pub(crate) struct Body {
    /// (address, offset into the flat arrays, length) per area.
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
    /// The longest frame sent now: halved when a frame did not land.
    frame_size: usize,
    last_error: Option<ProtocolError>,
    writer: Writer,
    /// Read-only passes so far.
    pass: u32,
    /// Frames sent since the loader was last checked.
    frames_unchecked: usize,
    /// An answer just ended and another is due: the robot is between
    /// answers, taking in the frames it holds. Frames wait until the next
    /// answer starts (see [`Body::pump`]).
    between_answers: bool,
    /// Bytes written again after reading back wrong.
    pub(crate) rewrites: usize,
    checks: Vec<Check>,
}

impl Body {
    /// The transfer of `image`'s bytes, written by `writer`.
    pub(crate) fn new(image: &UploadImage, writer: Writer) -> Self {
        let mut index = Vec::new();
        let mut expected = Vec::with_capacity(image.len());
        for area in image.areas() {
            index.push((area.address, expected.len(), area.bytes.len()));
            expected.extend_from_slice(&area.bytes);
        }
        let state = vec![ByteState::default(); expected.len()];
        Body {
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
            read_size: MAX_READ,
            frame_size: FRAME_MAX,
            last_error: None,
            writer,
            pass: 0,
            frames_unchecked: 0,
            between_answers: false,
            rewrites: 0,
            checks: Vec::new(),
        }
    }

    /// Adds read-only comparisons of `spans` (address span, expected
    /// bytes), asked after the first write: while the ROM's `/9W`s go out
    /// the return wire carries little, so their answers cost almost no
    /// time. Nothing is written because of them; [`Body::checks_passed`]
    /// says whether every answer came and matched.
    pub(crate) fn add_checks(&mut self, spans: Vec<(ReadSpan, Vec<u8>)>) {
        let at = self.queue.len().min(1);
        for (i, (span, expected)) in spans.into_iter().enumerate() {
            self.queue.insert(at + i, Work::Check(self.checks.len()));
            self.checks.push(Check {
                span,
                expected,
                tag: None,
                matched: None,
            });
        }
    }

    /// Whether every comparison added by [`Body::add_checks`] was answered
    /// with the expected bytes (a lost or noisy answer says no: the caller
    /// reads again to tell).
    pub(crate) fn checks_passed(&self) -> bool {
        self.checks.iter().all(|check| check.matched == Some(true))
    }

    /// Records a comparison's answer; `false` when `tag` is none of them.
    fn checked(&mut self, tag: u64, data: Option<&[u8]>) -> bool {
        let Some(check) = self.checks.iter_mut().find(|check| check.tag == Some(tag)) else {
            return false;
        };
        check.tag = None;
        check.matched = Some(data == Some(check.expected.as_slice()));
        true
    }

    /// Read-only passes run.
    pub(crate) fn passes(&self) -> u32 {
        self.pass
    }

    /// Switches how bytes are written from now on (after the loader was
    /// lost and could not be restored, say).
    pub(crate) fn set_writer(&mut self, writer: Writer) {
        self.writer = writer;
    }

    fn offset(&self, address: u16) -> Option<usize> {
        self.index.iter().find_map(|&(start, offset, len)| {
            let delta = usize::from(address.wrapping_sub(start));
            (address >= start && delta < len).then_some(offset + delta)
        })
    }

    /// Writes of every byte, with a verifying read after each span, for
    /// a line at `baud`.
    pub(crate) fn plan_writes(&mut self, baud: u32, progress: &mut dyn Progress) {
        progress.phase(Phase::Write, self.expected.len());
        let mut area = None;
        let mut next_write = 0u32;
        for (start, len, span) in self.write_spans(baud) {
            let end = u32::from(start) + len as u32;
            if area != Some(start) {
                area = Some(start);
                next_write = u32::from(start);
            }
            // A `/9W` may have covered the span's first byte already.
            let span_end = u32::from(span.address()) + u32::from(span.count());
            while next_write < span_end {
                let len = match self.writer {
                    Writer::Rom if next_write + 1 < end => 2,
                    Writer::Rom => 1,
                    Writer::Frames => (span_end - next_write) as u8,
                };
                self.queue.push_back(Work::Write {
                    address: next_write as u16,
                    len,
                });
                next_write += u32::from(len);
            }
            self.queue.push_back(Work::Read(span));
        }
    }

    /// The verification spans of a write pass, with their area (start,
    /// length). Frames: a short first span, so the return wire, which
    /// carries two characters a byte against the frames' one, starts
    /// early. The ROM's commands: the sending wire is the slow one, so the
    /// last spans taper (see `taper`): each answer ends about when the
    /// writes behind it are in, and the last answer is short.
    fn write_spans(&self, baud: u32) -> Vec<(u16, usize, ReadSpan)> {
        let mut out = Vec::new();
        let areas = self.index.len();
        for (i, &(start, _, len)) in self.index.iter().enumerate() {
            let mut sizes = Vec::new();
            let mut left = len;
            if self.writer == Writer::Frames && i == 0 {
                for size in RAMP {
                    if left > size + MAX_READ as usize {
                        sizes.push(size);
                        left -= size;
                    }
                }
            }
            let mut tail = Vec::new();
            if self.writer == Writer::Rom && i + 1 == areas {
                // The tail starts on a `/9W` boundary.
                let bytes = if len <= TAIL {
                    len
                } else {
                    TAIL - (len - TAIL) % 2
                };
                tail = rom_tail(bytes, baud);
                left -= bytes;
            }
            let mut at = start;
            for size in sizes {
                out.extend(pieces(at, size, MAX_READ).map(|span| (start, len, span)));
                at += size as u16;
            }
            out.extend(pieces(at, left, MAX_READ).map(|span| (start, len, span)));
            at += left as u16;
            for size in tail {
                out.extend(pieces(at, size, MAX_READ).map(|span| (start, len, span)));
                at += size as u16;
            }
        }
        out
    }

    /// Reads of every byte, writing only what reads back wrong (for code
    /// that is probably there already, like a loader after a reset).
    pub(crate) fn plan_reads(&mut self, progress: &mut dyn Progress) {
        progress.phase(Phase::FinalVerify, self.expected.len());
        for &(start, _, len) in &self.index.clone() {
            for span in pieces(start, len, self.read_size) {
                self.queue.push_back(Work::Read(span));
            }
        }
    }

    /// The bytes of a write, as the command or frame that sends them.
    fn encode(&self, address: u16, len: u8) -> Result<Vec<u8>> {
        let value = |at: u16| self.offset(at).map_or(0, |offset| self.expected[offset]);
        Ok(match (self.writer, len) {
            (Writer::Frames, _) => {
                let data: Vec<u8> = (0..u16::from(len)).map(|i| value(address + i)).collect();
                frame(address, &data)
            }
            (Writer::Rom, 2) => Command::WriteWord(WordWrite::new(
                address,
                [value(address), value(address + 1)],
            )?)
            .encode(),
            (Writer::Rom, _) => Command::WriteByte {
                address,
                value: value(address),
            }
            .encode(),
        })
    }

    /// Sends queued work while the client has room. Returns `false` when
    /// the loader should be checked before going on.
    ///
    /// Frames are held back while the robot is between answers. The ROM
    /// cannot answer while it takes in a frame, so those pauses of the
    /// return wire are its work on the frames it holds; characters that
    /// arrive then cost it an interrupt each and lengthen them, while
    /// characters that arrive during an answer are taken in the time the
    /// ROM spends waiting for its 6551 to send. So the next frame goes out
    /// when the next answer starts.
    fn pump<T: Transport>(&mut self, client: &mut Client<T>, limits: Limits) -> Result<bool> {
        if self.between_answers && (client.robot_sending() || client.in_flight() == 0) {
            self.between_answers = false;
        }
        while let Some(&work) = self.queue.front() {
            match work {
                Work::Write { address, len } => {
                    let bytes = self.encode(address, len)?;
                    if bytes.is_empty() && len > 1 {
                        // No key for this frame: two smaller ones.
                        let half = len / 2;
                        self.queue.pop_front();
                        self.queue.push_front(Work::Write {
                            address: address + u16::from(half),
                            len: len - half,
                        });
                        self.queue.push_front(Work::Write { address, len: half });
                        continue;
                    }
                    if client.room() < bytes.len()
                        || (self.writer == Writer::Frames && self.between_answers)
                    {
                        break;
                    }
                    // A byte written twice already: noise, or the loader is
                    // gone (a `/1R` that noise made from a frame's `/1L`).
                    // Look after every 16 frames; after a third failure of
                    // the same byte, at once.
                    let writes = (address..address + u16::from(len))
                        .filter_map(|at| self.offset(at))
                        .map(|offset| self.state[offset].writes)
                        .max()
                        .unwrap_or(0);
                    let due = match writes {
                        0 | 1 => usize::MAX,
                        2 => 16,
                        _ => 1,
                    };
                    if self.writer == Writer::Frames && self.frames_unchecked >= due {
                        self.frames_unchecked = 0;
                        return Ok(false);
                    }
                    for at in address..address + u16::from(len) {
                        if let Some(offset) = self.offset(at) {
                            let state = &mut self.state[offset];
                            if state.writes >= limits.max_writes {
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
                    client.send_raw(&bytes)?;
                    if self.writer == Writer::Frames {
                        self.frames_unchecked += 1;
                    }
                    self.wrote = true;
                }
                Work::Read(span) => {
                    if !client.can_ask(span.count()) {
                        break;
                    }
                    let tag = client.ask_read(span)?;
                    self.read_seq.insert(tag, self.seq);
                }
                Work::Check(index) => {
                    let span = self.checks[index].span;
                    if !client.can_ask(span.count()) {
                        break;
                    }
                    self.checks[index].tag = Some(client.ask_read(span)?);
                }
            }
            self.seq += 1;
            self.queue.pop_front();
        }
        Ok(true)
    }

    fn answered(&mut self, span: ReadSpan, tag: u64, data: &[u8], progress: &mut dyn Progress) {
        self.lost_in_row = 0;
        self.read_size = self.read_size.saturating_add(2).min(MAX_READ);
        let asked_at = self.read_seq.remove(&tag).unwrap_or(0);
        let mut wrong = Vec::new();
        let mut doubtful = Vec::new();
        let mut landed = 0usize;
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
                landed += 1;
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
            if landed > 0 {
                self.frame_size = (self.frame_size * 2).min(FRAME_MAX);
            }
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
        // A frame that did not land was probably too long for the noise.
        self.frame_size = (self.frame_size / 2).max(8);
        self.rewrites += wrong.len();
        progress.event(&Event::Rewrite {
            address: wrong[0],
            count: wrong.len(),
        });
        let mut work = self.rewrite_work(&wrong);
        let first = reread[0];
        let last = u32::from(reread[reread.len() - 1]);
        if let Ok(span) = ReadSpan::new(first, (last - u32::from(first) + 1) as u8) {
            work.push(Work::Read(span));
        }
        for item in work.into_iter().rev() {
            self.queue.push_front(item);
        }
    }

    /// Writes that cover `wrong` (sorted): pairs for `/9W`, runs of
    /// consecutive loaded bytes for frames.
    fn rewrite_work(&mut self, wrong: &[u16]) -> Vec<Work> {
        let mut work = Vec::new();
        let mut covered = 0u32;
        for (i, &address) in wrong.iter().enumerate() {
            if u32::from(address) < covered {
                continue;
            }
            let next_loaded = |at: u16| {
                at < 0xFFFF
                    && self
                        .offset(at + 1)
                        .is_some_and(|next| Some(next) == self.offset(at).map(|o| o + 1))
            };
            let len = match self.writer {
                Writer::Rom => 1 + u8::from(next_loaded(address)),
                Writer::Frames => {
                    // Up to the last wrong byte of this run that fits.
                    let mut end = address;
                    for &later in &wrong[i + 1..] {
                        let fits = usize::from(later - address) < self.frame_size;
                        let contiguous = (end..later).all(next_loaded);
                        if !(fits && contiguous) {
                            break;
                        }
                        end = later;
                    }
                    (end - address + 1) as u8
                }
            };
            work.push(Work::Write { address, len });
            covered = u32::from(address) + u32::from(len);
            for at in address..address + u16::from(len) {
                if let Some(offset) = self.offset(at) {
                    self.state[offset].queued = true;
                }
            }
        }
        work
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
    /// overtaken by a rewrite or dropped for a loader check).
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

    /// Runs the planned work until every byte verified (in a pass that
    /// wrote nothing, if anything went wrong), or until the loader needs a
    /// check.
    pub(crate) fn run<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        limits: Limits,
        progress: &mut dyn Progress,
    ) -> Result<RunEnd> {
        loop {
            if !self.pump(client, limits)? {
                self.anomalies += 1;
                return Ok(RunEnd::CheckLoader);
            }
            if self.queue.is_empty() && client.in_flight() == 0 {
                if self.verified < self.expected.len() {
                    self.requeue_unverified();
                    continue;
                }
                let done = if self.pass == 0 {
                    self.anomalies == 0
                } else {
                    !self.wrote
                };
                if done {
                    return Ok(RunEnd::Done);
                }
                self.pass += 1;
                if self.pass > limits.max_passes {
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
                self.plan_reads(progress);
                continue;
            }
            let limit = client.config().stall_limit;
            for outcome in client.poll(limit)? {
                match outcome {
                    Outcome::Answered { tag, data, .. } if self.checked(tag, Some(&data)) => {
                        self.between_answers = true;
                    }
                    Outcome::Answered { span, tag, data } => {
                        self.answered(span, tag, &data, progress);
                        self.between_answers = true;
                    }
                    Outcome::Lost { tag, .. } if self.checked(tag, None) => {}
                    Outcome::Lost { span, tag } => {
                        progress.event(&Event::LostAnswer {
                            address: span.address(),
                        });
                        self.lost(span, tag, limits.max_lost)?;
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

    /// Drops queued work and unverifies nothing: after an interruption
    /// (a loader check, a recovery), the questions in flight are gone and
    /// [`Body::run`] finds the bytes they were to verify still unverified.
    pub(crate) fn interrupted(&mut self) {
        self.anomalies += 1;
        self.read_seq.clear();
        // Writes still queued stay queued; reads of bytes not yet written
        // would say nothing, so only the reads go.
        self.queue.retain(|work| matches!(work, Work::Write { .. }));
        for state in &mut self.state {
            state.suspect = None;
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
