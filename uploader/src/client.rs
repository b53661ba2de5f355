//! The protocol client: questions with timeouts derived from the baud rate,
//! and a pipeline that keeps several `/7R` questions in flight while
//! writes go out, matching each answer to its question.
//!
//! Answers carry no tag, and line noise can lose one, so the pipeline never
//! has two questions of the same byte count in flight: an answer's length
//! says which question it answers, and every earlier question still waiting
//! is known lost. Each question also has a deadline computed from the
//! characters ahead of it on both wires.

use std::collections::VecDeque;
use std::time::Duration;

use romlib::protocol::{Answer, BusyByte, Command, EOL, MAX_READ, ProtocolError, ReadSpan};

use crate::transport::{Transport, char_time};
use crate::{Error, Result};

/// How the client paces itself.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClientConfig {
    /// The most characters sent after a question whose answer has not fully
    /// arrived. While the ROM sends an answer it may not read its input,
    /// so this must fit its receive buffer; 0 is stop-and-wait.
    pub window: usize,
    /// The most questions in flight at once (at most 4: byte counts 8
    /// apart tell their answers apart).
    pub max_questions: usize,
    /// Slack added to every computed deadline (USB adapters add up to
    /// 16 ms a turn; ROM work adds more).
    pub margin: Duration,
    /// How long the line may stay silent with answers due before the work
    /// is abandoned.
    pub stall_limit: Duration,
    /// Attempts at a single question before giving up.
    pub question_attempts: u32,
}

impl Default for ClientConfig {
    fn default() -> Self {
        ClientConfig {
            window: crate::RomProfile::reference().window(),
            max_questions: 4,
            margin: Duration::from_millis(150),
            stall_limit: Duration::from_secs(3),
            question_attempts: 5,
        }
    }
}

/// A question in flight.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    span: ReadSpan,
    tag: u64,
    /// Host characters sent when this question's last character was sent.
    sent_mark: usize,
    deadline: Duration,
}

/// What the pipeline learned.
#[derive(Debug)]
pub(crate) enum Outcome {
    /// A question was answered.
    Answered {
        span: ReadSpan,
        tag: u64,
        data: Vec<u8>,
    },
    /// A question's answer was lost, late or garbled.
    Lost { span: ReadSpan, tag: u64 },
    /// A frame that answers nothing (noise, an extension's answer).
    Stray(Option<ProtocolError>),
}

/// Talks to one robot over a transport.
#[derive(Debug)]
pub struct Client<T> {
    transport: T,
    config: ClientConfig,
    rx: Vec<u8>,
    in_flight: VecDeque<InFlight>,
    next_tag: u64,
    /// Host characters sent so far.
    sent: usize,
    /// Host characters sent when the last fully answered question was sent.
    /// When the host-to-robot wire is expected to be free again, and the
    /// robot-to-host wire.
    host_free: Duration,
    robot_free: Duration,
    last_rx: Duration,
    /// Questions were lost since the last byte came: asking again keeps
    /// the stall's clock running.
    losing: bool,
    stats: ClientStats,
    /// Whether the debug stub's stop frame was heard since the exchange
    /// began: a breakpoint in code the robot runs on its own (a
    /// `HOOK_LOOP` handler) stops it between two questions.
    heard_stop: bool,
}

/// Counters of one client's traffic.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClientStats {
    /// Characters sent.
    pub sent: usize,
    /// Characters received.
    pub received: usize,
    /// Questions whose answer was lost, late or garbled.
    pub lost: usize,
    /// Frames that answered no question.
    pub stray: usize,
}

impl<T: Transport> Client<T> {
    /// A client over `transport`.
    pub fn new(transport: T, config: ClientConfig) -> Self {
        let now = transport.now();
        Client {
            transport,
            config,
            rx: Vec::new(),
            in_flight: VecDeque::new(),
            next_tag: 0,
            sent: 0,
            host_free: now,
            robot_free: now,
            last_rx: now,
            losing: false,
            stats: ClientStats::default(),
            heard_stop: false,
        }
    }

    /// The transport.
    pub fn transport(&mut self) -> &mut T {
        &mut self.transport
    }

    /// Unwraps the transport.
    pub fn into_transport(self) -> T {
        self.transport
    }

    /// The pacing in use.
    #[must_use]
    pub fn config(&self) -> &ClientConfig {
        &self.config
    }

    /// Traffic so far.
    #[must_use]
    pub fn stats(&self) -> ClientStats {
        self.stats
    }

    fn chars(&self, count: usize) -> Duration {
        char_time(count, self.transport.baud())
    }

    /// Sends raw bytes, tracking when they will have left.
    pub(crate) fn send_raw(&mut self, bytes: &[u8]) -> Result<()> {
        let now = self.transport.now();
        self.host_free = self.host_free.max(now) + self.chars(bytes.len());
        self.sent += bytes.len();
        self.stats.sent += bytes.len();
        self.transport.send(bytes)
    }

    /// Sends an instruction (no answer expected).
    ///
    /// # Errors
    /// An I/O error on the line.
    pub fn send(&mut self, command: &Command) -> Result<()> {
        self.send_raw(&command.encode())
    }

    /// Reads from the line, waiting up to `timeout`; records the time of
    /// the last byte.
    fn fill(&mut self, timeout: Duration) -> Result<usize> {
        let before = self.rx.len();
        let count = self.transport.receive(&mut self.rx, timeout)?;
        if count > 0 {
            self.last_rx = self.transport.now();
            self.losing = false;
            self.stats.received += count;
            // The frame's start may have come with the last bytes.
            self.heard_stop |= stopped_in_stub(&self.rx[before.saturating_sub(2)..]);
        }
        Ok(count)
    }

    /// Ends an exchange the stub's stop frame broke into: its questions
    /// get no answer (a stopped robot reads frames only), so they are
    /// dropped with what was heard.
    fn stopped_now(&mut self) -> Error {
        self.heard_stop = false;
        self.in_flight.clear();
        self.rx.clear();
        Error::StoppedInDebugStub {
            port: self.transport.name(),
        }
    }

    /// Takes the next complete frame (through its carriage return).
    fn take_frame(&mut self) -> Option<Vec<u8>> {
        let end = self.rx.iter().position(|&b| b == EOL)?;
        Some(self.rx.drain(..=end).collect())
    }

    /// How many characters may go out now without overrunning a robot that
    /// is busy answering.
    pub(crate) fn room(&self) -> usize {
        match self.in_flight.front() {
            None => usize::MAX,
            Some(oldest) => (oldest.sent_mark + self.config.window).saturating_sub(self.sent),
        }
    }

    /// Whether a question of `count` bytes can be sent now.
    pub(crate) fn can_ask(&self, count: u8) -> bool {
        self.in_flight.len() < self.config.max_questions.clamp(1, 4)
            && !self
                .in_flight
                .iter()
                .any(|q| q.span.count().abs_diff(count) < COUNT_SPACING)
            && self.room() >= 9
    }

    /// Questions in flight.
    pub(crate) fn in_flight(&self) -> usize {
        self.in_flight.len()
    }

    /// Whether part of an answer has arrived: the robot is sending now.
    /// (After [`Client::poll`], every complete answer is taken.)
    pub(crate) fn robot_sending(&self) -> bool {
        !self.rx.is_empty()
    }

    /// Sends a `/7R` question into the pipeline; its answer comes back
    /// through [`Client::poll`].
    pub(crate) fn ask_read(&mut self, span: ReadSpan) -> Result<u64> {
        // A stall is a wait with answers due: it starts with the first
        // question after a quiet spell, not at the last byte this client
        // read (the debug stub's frames are read past it, for minutes
        // maybe); questions asked again after losses keep its clock.
        if self.in_flight.is_empty() && !self.losing {
            self.last_rx = self.last_rx.max(self.transport.now());
        }
        let command = Command::ReadMemory(span);
        let bytes = command.encode();
        self.send_raw(&bytes)?;
        let answer_len = command.answer_len().unwrap_or(2);
        let arrival = self.host_free;
        self.robot_free = self.robot_free.max(arrival) + self.chars(answer_len);
        let expected = self.robot_free.saturating_sub(self.transport.now());
        let deadline = self.robot_free + self.config.margin + expected / 4;
        let tag = self.next_tag;
        self.next_tag += 1;
        self.in_flight.push_back(InFlight {
            span,
            tag,
            sent_mark: self.sent,
            deadline,
        });
        Ok(tag)
    }

    /// Waits up to `timeout` for answers and returns what happened: answers
    /// matched to their questions, questions known lost (overtaken or past
    /// their deadline), stray frames.
    pub(crate) fn poll(&mut self, timeout: Duration) -> Result<Vec<Outcome>> {
        let now = self.transport.now();
        let wait = match self.in_flight.front() {
            Some(oldest) => timeout.min(oldest.deadline.saturating_sub(now)),
            None => timeout,
        };
        if self.take_frame_available() {
            self.fill(Duration::ZERO)?;
        } else {
            self.fill(wait)?;
        }
        let mut outcomes = Vec::new();
        let due = self.in_flight.len();
        while let Some(frame) = self.take_frame() {
            self.match_frame(&frame, &mut outcomes);
        }
        let now = self.transport.now();
        while let Some(oldest) = self.in_flight.front().copied() {
            if now < oldest.deadline {
                break;
            }
            self.in_flight.pop_front();
            self.stats.lost += 1;
            self.losing = true;
            outcomes.push(Outcome::Lost {
                span: oldest.span,
                tag: oldest.tag,
            });
            // Its answer may still be on its way: resynchronise the
            // robot-to-host estimate so later deadlines are not shortened.
            self.robot_free = self.robot_free.max(now);
        }
        if due > 0 && now.saturating_sub(self.last_rx) > self.config.stall_limit {
            return Err(Error::Stalled {
                port: self.transport.name(),
                waited: now.saturating_sub(self.last_rx),
                outstanding: due,
            });
        }
        Ok(outcomes)
    }

    fn take_frame_available(&self) -> bool {
        self.rx.contains(&EOL)
    }

    fn match_frame(&mut self, frame: &[u8], outcomes: &mut Vec<Outcome>) {
        let data = match Answer::parse(frame) {
            Ok(Answer::Memory(data)) => data,
            Ok(_) => {
                self.stats.stray += 1;
                outcomes.push(Outcome::Stray(None));
                return;
            }
            Err(error) => {
                self.stats.stray += 1;
                outcomes.push(Outcome::Stray(Some(error)));
                return;
            }
        };
        let Some(index) = self
            .in_flight
            .iter()
            .position(|q| usize::from(q.span.count()) == data.len())
        else {
            self.stats.stray += 1;
            outcomes.push(Outcome::Stray(None));
            return;
        };
        // Answers come in order: every question before this one is lost.
        for lost in self.in_flight.drain(..index) {
            self.stats.lost += 1;
            outcomes.push(Outcome::Lost {
                span: lost.span,
                tag: lost.tag,
            });
        }
        if let Some(question) = self.in_flight.pop_front() {
            outcomes.push(Outcome::Answered {
                span: question.span,
                tag: question.tag,
                data,
            });
        }
    }

    /// Drops every question in flight and any partial input, waiting until
    /// their answers are due so none arrives later.
    pub(crate) fn drain(&mut self) -> Result<()> {
        let until = self.in_flight.back().map(|q| q.deadline);
        if let Some(until) = until {
            loop {
                let now = self.transport.now();
                if now >= until {
                    break;
                }
                self.fill(until - now)?;
            }
        }
        self.in_flight.clear();
        self.rx.clear();
        Ok(())
    }

    /// Lets the line run until `until` on the transport's clock, dropping
    /// whatever arrives (after a command that changes the rate, say).
    pub(crate) fn wait_until(&mut self, until: Duration) -> Result<()> {
        loop {
            let now = self.transport.now();
            if now >= until {
                break;
            }
            self.fill(until - now)?;
        }
        self.rx.clear();
        Ok(())
    }

    /// Sends `questions` (commands whose answers are `answer_len`
    /// characters, the carriage return included) back to back and returns
    /// the frames that came back, in order, once every question is
    /// answered or the answers stop coming (`work` is the robot's time per
    /// question besides the characters). A question may carry a loader
    /// frame before it, which the loader takes as it arrives. As with
    /// [`Client::room`], at most a window of characters goes out after a
    /// question whose answer has not arrived: what the robot's receive
    /// ring holds while it works on that question and answers it. Answers
    /// carry what they answer (an address, say): the caller matches them,
    /// and asks again for what is missing.
    ///
    /// # Errors
    /// A line error.
    pub(crate) fn batch(
        &mut self,
        questions: &[Vec<u8>],
        answer_len: usize,
        work: Duration,
    ) -> Result<Vec<Vec<u8>>> {
        self.drain()?;
        let mut frames = Vec::new();
        let mut next = 0;
        // The host's character count just after each unanswered question.
        let mut marks: VecDeque<usize> = VecDeque::new();
        let mut deadline = self.transport.now();
        while next < questions.len() || !marks.is_empty() {
            while next < questions.len()
                && marks.front().is_none_or(|&oldest| {
                    self.sent + questions[next].len() <= oldest + self.config.window
                })
            {
                let bytes = &questions[next];
                self.send_raw(bytes)?;
                let now = self.transport.now();
                deadline = deadline.max(now) + self.chars(bytes.len() + answer_len) + work;
                marks.push_back(self.sent);
                next += 1;
            }
            if let Some(frame) = self.take_frame() {
                frames.push(frame);
                marks.pop_front();
                continue;
            }
            let now = self.transport.now();
            let until = deadline + self.config.margin;
            if now >= until {
                // The rest are lost: the caller asks again.
                self.stats.lost += marks.len();
                marks.clear();
                deadline = now;
                continue;
            }
            self.fill(until - now)?;
        }
        self.rx.clear();
        Ok(frames)
    }

    /// Asks one question and waits for its answer (stop-and-wait), with a
    /// timeout from the baud rate and the configured retries.
    ///
    /// # Errors
    /// [`Error::NoAnswer`] when nothing at all came back,
    /// [`Error::WrongBaud`] when only garbage did, or the last
    /// [`ProtocolError`] when answers kept being malformed.
    pub fn ask(&mut self, command: &Command) -> Result<Answer> {
        self.ask_with(command, self.config.question_attempts)
    }

    /// How long `command` (encoded as `bytes`) and its answer take on the
    /// line, with margin; `/1S` and extensions get the longest answer
    /// there is.
    fn answer_timeout(&self, command: &Command, bytes: &[u8]) -> Duration {
        let answer_len = command.answer_len().unwrap_or(2 * 199 + 3);
        self.chars(bytes.len() + answer_len) + self.config.margin * 2
    }

    /// Sends a command that may or may not be answered (an extension's, in
    /// an expectation file) and waits as long as the longest answer takes:
    /// the answer if one came, `None` if the line stayed silent. Never
    /// retried: sending an instruction twice could do it twice.
    ///
    /// # Errors
    /// A line error, or the [`ProtocolError`] of an answer that is not
    /// printable text ending in a carriage return.
    pub fn listen(&mut self, command: &Command) -> Result<Option<Answer>> {
        let bytes = command.encode();
        let timeout = self.answer_timeout(command, &bytes);
        self.drain()?;
        self.transport.clear_input()?;
        self.heard_stop = false;
        self.send_raw(&bytes)?;
        let deadline = self.transport.now() + timeout;
        loop {
            if self.heard_stop {
                return Err(self.stopped_now());
            }
            if let Some(frame) = self.take_frame() {
                let answer = match command {
                    Command::Extension(_) => Answer::parse_text(&frame),
                    _ => Answer::parse(&frame),
                };
                return answer.map(Some).map_err(Error::Protocol);
            }
            let now = self.transport.now();
            if now >= deadline {
                if self.rx.is_empty() {
                    return Ok(None);
                }
                let heard = std::mem::take(&mut self.rx);
                return Err(self.garbage(heard));
            }
            self.fill(deadline - now)?;
        }
    }

    /// What bytes that are no answer say: the debug stub's stop frame
    /// among them, a robot left stopped by a debug session; otherwise
    /// the usual sign of a baud-rate mismatch, a sample of them named.
    fn garbage(&self, mut heard: Vec<u8>) -> Error {
        if stopped_in_stub(&heard) {
            return Error::StoppedInDebugStub {
                port: self.transport.name(),
            };
        }
        heard.truncate(40);
        Error::WrongBaud {
            port: self.transport.name(),
            baud: self.transport.baud(),
            sample: heard.escape_ascii().to_string(),
        }
    }

    /// [`Client::ask`] with `attempts` attempts (at least one).
    fn ask_with(&mut self, command: &Command, attempts: u32) -> Result<Answer> {
        let attempts = attempts.max(1);
        let bytes = command.encode();
        let timeout = self.answer_timeout(command, &bytes);
        let mut heard = Vec::new();
        let mut last_error = None;
        for _ in 0..attempts {
            self.drain()?;
            self.transport.clear_input()?;
            self.send_raw(&bytes)?;
            let start = self.transport.now();
            let deadline = start + timeout;
            loop {
                if let Some(frame) = self.take_frame() {
                    match command.parse_answer(&frame) {
                        Ok(answer) => return Ok(answer),
                        Err(error) => {
                            heard.extend_from_slice(&frame);
                            last_error = Some(error);
                            continue;
                        }
                    }
                }
                let now = self.transport.now();
                if now >= deadline {
                    heard.append(&mut self.rx);
                    break;
                }
                self.fill(deadline - now)?;
            }
        }
        if heard.is_empty() {
            return Err(Error::NoAnswer {
                port: self.transport.name(),
                baud: self.transport.baud(),
                question: command.to_string(),
                waited: timeout * attempts,
            });
        }
        // The stub's stop frame starts with a byte outside ASCII: it
        // takes this way too.
        if heard
            .iter()
            .any(|&b| !(0x20..0x7F).contains(&b) && b != EOL)
            || last_error.is_none()
        {
            return Err(self.garbage(heard));
        }
        Err(last_error.map_or_else(
            || Error::NoAnswer {
                port: self.transport.name(),
                baud: self.transport.baud(),
                question: command.to_string(),
                waited: timeout,
            },
            Error::Protocol,
        ))
    }

    /// Probes the robot with `/1X`: is something there, at this baud rate,
    /// speaking the protocol?
    ///
    /// # Errors
    /// As [`Client::ask`].
    pub fn probe(&mut self) -> Result<BusyByte> {
        self.probe_with(self.config.question_attempts)
    }

    /// [`Client::probe`] with `attempts` attempts: after a rate switch,
    /// where a silent line is better checked at the other rate than asked
    /// again.
    pub(crate) fn probe_with(&mut self, attempts: u32) -> Result<BusyByte> {
        match self.ask_with(&Command::Busy, attempts)? {
            Answer::Busy(busy) => Ok(busy),
            // `parse_answer` only accepts `X` answers to `/1X`.
            other => Err(Error::Protocol(ProtocolError::UnexpectedAnswer {
                question: "/1X".into(),
                text: format!("{other:?}"),
                expected: "`Xhh`".into(),
            })),
        }
    }

    /// Reads `len` bytes from `address` with pipelined `/7R` questions (up
    /// to 99 bytes each). Each span is read until two answers agree, since
    /// an answer that lost one character and gained another elsewhere
    /// parses as well as a true one.
    ///
    /// # Errors
    /// [`Error::BadImage`] if the range runs past `$FFFF`,
    /// [`Error::Unreadable`] when a span keeps failing, [`Error::Stalled`],
    /// [`Error::MemoryChanging`] when well-formed answers kept differing at
    /// the same addresses ([`CHANGING`] times or more): memory the robot
    /// writes while it runs.
    pub fn read_memory(&mut self, address: u16, len: usize) -> Result<Vec<u8>> {
        Ok(self.read_agreeing(address, len, None, false)?.bytes)
    }

    /// Reads `expected.len()` bytes from `address` as [`Client::read_memory`]
    /// does, but a span whose first answer is what `expected` says (`None`:
    /// any byte) is taken at once: a memory that holds what the host
    /// expects is read once, not twice. For a wrong byte to pass, noise
    /// would have to turn the robot's digits into exactly the expected
    /// ones; an answer that differs is read until two agree, as always,
    /// so what differs is named with the bytes the robot holds.
    ///
    /// # Errors
    /// As [`Client::read_memory`].
    pub fn read_expecting(&mut self, address: u16, expected: &[Option<u8>]) -> Result<Vec<u8>> {
        Ok(self
            .read_agreeing(address, expected.len(), Some(expected), false)?
            .bytes)
    }

    /// Reads `len` bytes from `address` as [`Client::read_memory`] does,
    /// but memory the robot writes while it runs (a counter its control
    /// loop keeps) does not fail the read: once the same addresses have
    /// differed between well-formed answers [`CHANGING`] times, and their
    /// answers seldom repeat a value (noise answers the true one most of
    /// the time), two answers of one span that agree everywhere else are
    /// taken, with the later answer's bytes at those addresses, and the
    /// addresses are named in [`LiveRead::changing`]. For a backup of a running robot, and for
    /// following code that shares its spans with the program's data.
    ///
    /// # Errors
    /// As [`Client::read_memory`], but for [`Error::MemoryChanging`].
    pub fn read_live(&mut self, address: u16, len: usize) -> Result<LiveRead> {
        self.read_agreeing(address, len, None, true)
    }

    /// [`Client::read_live`], a span that holds what `expected` says
    /// taken at once ([`Client::read_expecting`]).
    pub(crate) fn read_live_expecting(
        &mut self,
        address: u16,
        expected: &[Option<u8>],
    ) -> Result<LiveRead> {
        self.read_agreeing(address, expected.len(), Some(expected), true)
    }

    fn read_agreeing(
        &mut self,
        address: u16,
        len: usize,
        expected: Option<&[Option<u8>]>,
        live: bool,
    ) -> Result<LiveRead> {
        if u32::from(address) + len as u32 > 0x1_0000 {
            return Err(Error::BadImage {
                reason: format!("reading {len} bytes at ${address:04X} runs past $FFFF"),
            });
        }
        let mut out = vec![0u8; len];
        let mut todo: VecDeque<ReadSpan> = spans(address, len).collect();
        let mut remaining = len;
        let mut size = MAX_READ;
        let mut candidates: std::collections::HashMap<u16, Vec<u8>> =
            std::collections::HashMap::new();
        let mut failures = 0u32;
        let mut last_error = None;
        // How often each address differed between two well-formed answers.
        let mut changes: std::collections::HashMap<u16, u32> = std::collections::HashMap::new();
        // For a live read: the values each address answered, how often.
        let mut seen: std::collections::HashMap<u16, std::collections::HashMap<u8, u32>> =
            std::collections::HashMap::new();
        let mut pairs = 0u32;
        let mut changing = std::collections::BTreeSet::new();
        self.heard_stop = false;
        while remaining > 0 {
            while let Some(&span) = todo.front() {
                if !self.can_ask(span.count()) {
                    break;
                }
                todo.pop_front();
                self.ask_read(span)?;
            }
            let outcomes = self.poll(self.config.stall_limit)?;
            if self.heard_stop {
                return Err(self.stopped_now());
            }
            for outcome in outcomes {
                match outcome {
                    Outcome::Answered { span, data, .. } => {
                        let offset = usize::from(span.address() - address);
                        if live {
                            for (i, &byte) in data.iter().enumerate() {
                                *seen
                                    .entry(span.address() + i as u16)
                                    .or_default()
                                    .entry(byte)
                                    .or_insert(0) += 1;
                            }
                        }
                        let as_expected = expected.is_some_and(|expected| {
                            expected
                                .get(offset..offset + data.len())
                                .is_some_and(|wanted| {
                                    wanted
                                        .iter()
                                        .zip(&data)
                                        .all(|(want, got)| want.is_none_or(|want| want == *got))
                                })
                        });
                        if as_expected || candidates.get(&span.address()) == Some(&data) {
                            failures = 0;
                            size = size.saturating_add(4).min(MAX_READ);
                            remaining -= data.len();
                            out[offset..offset + data.len()].copy_from_slice(&data);
                        } else {
                            if let Some(before) = candidates.insert(span.address(), data.clone()) {
                                failures += 1;
                                pairs += 1;
                                // Two well-formed answers that differ: noise
                                // garbles a digit here and there, memory the
                                // robot writes differs at the same places.
                                let differ: Vec<u16> = before
                                    .iter()
                                    .zip(&data)
                                    .enumerate()
                                    .filter(|(_, (was, is))| was != is)
                                    .map(|(i, _)| span.address() + i as u16)
                                    .collect();
                                for &at in &differ {
                                    *changes.entry(at).or_insert(0) += 1;
                                }
                                // hostile17 F1: memory in use answers a
                                // new value nearly every time; a byte that
                                // noise hit now and then answers its own
                                // value most of the time.
                                let in_use = |at: &u16| {
                                    let values = seen.get(at);
                                    let answers: u32 = values.map_or(0, |v| v.values().sum());
                                    let most =
                                        values.and_then(|v| v.values().max().copied()).unwrap_or(0);
                                    changes
                                        .get(at)
                                        .is_some_and(|&times| differs_often(times, pairs))
                                        && most * 2 < answers
                                };
                                // hostile17 F6: two answers of different
                                // lengths (the span was split after a lost
                                // answer) differ nowhere they overlap, which
                                // is no agreement.
                                if live
                                    && before.len() == data.len()
                                    && !differ.is_empty()
                                    && differ.iter().all(in_use)
                                {
                                    // They agree but where the program writes.
                                    changing.extend(differ);
                                    remaining -= data.len();
                                    out[offset..offset + data.len()].copy_from_slice(&data);
                                    continue;
                                }
                            }
                            todo.push_back(span);
                        }
                    }
                    Outcome::Lost { span, .. } => {
                        failures += 1;
                        size = (size / 2).max(4);
                        let parts: Vec<ReadSpan> =
                            pieces(span.address(), usize::from(span.count()), size).collect();
                        for part in parts.into_iter().rev() {
                            todo.push_front(part);
                        }
                    }
                    Outcome::Stray(error) => last_error = error.or(last_error),
                }
                if failures > 40 * self.config.question_attempts {
                    let mut changed: Vec<u16> = changes
                        .iter()
                        .filter(|&(_, &times)| differs_often(times, pairs))
                        .map(|(&address, _)| address)
                        .collect();
                    if !changed.is_empty() {
                        changed.sort_unstable();
                        return Err(Error::MemoryChanging {
                            address,
                            last: (u32::from(address) + len as u32 - 1) as u16,
                            changed,
                        });
                    }
                    return Err(Error::Unreadable {
                        address,
                        attempts: failures,
                        last: last_error,
                    });
                }
            }
        }
        Ok(LiveRead {
            bytes: out,
            changing: changing.into_iter().collect(),
        })
    }
}

/// What [`Client::read_live`] read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiveRead {
    /// The bytes, from the first address read.
    pub bytes: Vec<u8>,
    /// The addresses, sorted, whose bytes kept changing between answers
    /// (memory the robot writes while it runs): their bytes are the last
    /// answer's.
    pub changing: Vec<u16>,
}

/// Whether an address that differed `times` between two well-formed
/// answers, of `pairs` pairs that differed at all, differs as memory in
/// use does ([`CHANGING`] times, and in a quarter of the pairs), not as
/// noise here and there does.
fn differs_often(times: u32, pairs: u32) -> bool {
    times >= CHANGING && times * 4 >= pairs
}

/// The least difference between the byte counts of two questions in
/// flight: an answer must lose or gain 16 characters to pass for another.
pub(crate) const COUNT_SPACING: u8 = 8;

/// How many times one address must differ between well-formed answers
/// (and in a quarter of the pairs that differed at all) for a failed read
/// to be blamed on memory in use rather than noise: noise garbles a digit
/// at a random place, memory in use differs at the same ones each time.
pub(crate) const CHANGING: u32 = 4;

/// Splits a range into `/7R` spans of at most 99 bytes whose counts step
/// down 99, 91, 83, 75 and repeat, so that questions in flight differ in
/// length by [`COUNT_SPACING`].
pub(crate) fn spans(address: u16, len: usize) -> impl Iterator<Item = ReadSpan> {
    pieces(address, len, MAX_READ)
}

/// Like [`spans`], with at most `size` bytes a question: noisy lines
/// garble long answers, so the pipeline shrinks its questions when answers
/// are lost.
pub(crate) fn pieces(address: u16, len: usize, size: u8) -> impl Iterator<Item = ReadSpan> {
    let size = size.clamp(1, MAX_READ);
    let steps = (size - 1) / COUNT_SPACING + 1;
    let mut at = u32::from(address);
    let end = at + len as u32;
    let mut turn = 0u8;
    std::iter::from_fn(move || {
        if at >= end {
            return None;
        }
        let size = u32::from(size - (turn % steps.min(4)) * COUNT_SPACING).min(end - at);
        turn = turn.wrapping_add(1);
        let span = ReadSpan::new(at as u16, size as u8).ok()?;
        at += size;
        Some(span)
    })
}

/// Whether `heard` holds the debug stub's stop frame: its start, the
/// length 8 and `S` (docs/PROTOCOL.md, section 5), which no answer of
/// the ROM's has (its answers are printable ASCII). Public for what hears
/// the line without a [`Client`] (`scorpion ask`'s extension commands).
#[must_use]
pub fn stopped_in_stub(heard: &[u8]) -> bool {
    heard
        .windows(3)
        .any(|three| three == [crate::stub::frame::SOF_OUT, 8, b'S'])
}
