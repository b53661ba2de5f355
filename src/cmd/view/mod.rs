//! `scorpion sim --view`: the virtual Scorpion in its room, live in the
//! browser. The robot runs in this thread's loop at its own pace (real
//! time, faster or slower, paused or stepped); a server
//! ([`server`]) serves the page and a WebSocket per browser, each in a
//! thread of its own. They meet in the [`Hub`]: the loop publishes a
//! frame (the latest only: a client that falls behind skips frames, it
//! never queues them) and takes the clients' requests from a bounded
//! queue, never waiting on a client.

pub(crate) mod protocol;
pub(crate) mod server;

use std::collections::VecDeque;
use std::io::Write;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use cards::RoomView;
use cards::room::drive::Pose;
use cards::room::file::Layout;
use cards::room::geometry::{PI, Point};
use cards::room::live::Edit;
use emulator::board::{CPU_HZ, Motor};
use miette::IntoDiagnostic;
use romlib::VirtualScorpion;

use crate::cmd::host_line::{self, HostLine};
use protocol::{ConsoleLine, Frame, Incoming, Outgoing, PoseJson, State};

/// Requests waiting for the robot's loop: past them a client is told
/// its request was dropped.
pub(crate) const REQUESTS_WAITING: usize = 64;

/// Console lines kept for the clients (a client that connects sees
/// these).
pub(crate) const CONSOLE_KEPT: usize = 200;

/// How often the loop publishes a frame while the robot runs.
const FRAME_EVERY: Duration = Duration::from_millis(33);

/// The longest partial answer kept waiting for its carriage return:
/// past it, it is shown as a line.
const PARTIAL_ANSWER: usize = 256;

/// What the robot's loop and the connections share.
#[derive(Debug)]
pub(crate) struct Hub {
    frame: Mutex<Arc<Frame>>,
    generation: AtomicU64,
    requests: SyncSender<Incoming>,
    /// Connections served now.
    pub(crate) connections: AtomicUsize,
    /// Connections refused (past [`server::MAX_CONNECTIONS`]) not said yet.
    pub(crate) refused: AtomicU64,
    /// Requests dropped (the queue full) not said yet.
    dropped: AtomicU64,
    stop: AtomicBool,
    /// The room's trail, read by each connection as it grows.
    pub(crate) room: Option<RoomView>,
    /// Lines said on stderr this second, and when the second began.
    said: Mutex<(Instant, u32)>,
}

impl Hub {
    fn new(room: Option<RoomView>) -> (Arc<Hub>, Receiver<Incoming>) {
        let (requests, incoming) = mpsc::sync_channel(REQUESTS_WAITING);
        let hub = Hub {
            frame: Mutex::new(Arc::new(Frame::default())),
            generation: AtomicU64::new(0),
            requests,
            connections: AtomicUsize::new(0),
            refused: AtomicU64::new(0),
            dropped: AtomicU64::new(0),
            stop: AtomicBool::new(false),
            room,
            said: Mutex::new((Instant::now(), 0)),
        };
        (Arc::new(hub), incoming)
    }

    /// The latest frame and its number.
    pub(crate) fn frame(&self) -> (u64, Arc<Frame>) {
        let frame = self
            .frame
            .lock()
            .map(|frame| Arc::clone(&frame))
            .unwrap_or_default();
        (self.generation.load(Ordering::Acquire), frame)
    }

    fn publish(&self, frame: Frame) {
        if let Ok(mut slot) = self.frame.lock() {
            *slot = Arc::new(frame);
            self.generation.fetch_add(1, Ordering::AcqRel);
        }
    }

    /// A client's message: queued for the robot's loop, or the error to
    /// answer.
    pub(crate) fn request(&self, text: &str) -> Option<Outgoing<'static>> {
        let incoming = match Incoming::parse(text) {
            Ok(incoming) => incoming,
            Err(error) => return Some(Outgoing::Error { message: error }),
        };
        match self.requests.try_send(incoming) {
            Ok(()) => None,
            Err(TrySendError::Full(_)) => {
                self.dropped.fetch_add(1, Ordering::Relaxed);
                Some(Outgoing::error(&format!(
                    "request dropped: {REQUESTS_WAITING} already wait for the robot"
                )))
            }
            Err(TrySendError::Disconnected(_)) => Some(Outgoing::error("the robot has stopped")),
        }
    }

    pub(crate) fn stopping(&self) -> bool {
        self.stop.load(Ordering::Acquire)
    }

    /// Says `line` on stderr, at most ten lines a second (a flood of bad
    /// clients does not flood the terminal).
    pub(crate) fn say(&self, line: &str) {
        let Ok(mut said) = self.said.lock() else {
            return;
        };
        if said.0.elapsed() >= Duration::from_secs(1) {
            *said = (Instant::now(), 0);
        }
        said.1 += 1;
        if said.1 <= 10 {
            let _ = writeln!(std::io::stderr().lock(), "{line}");
        }
    }
}

/// The robot's clock against the wall clock: a speed, paused or not.
struct Clock {
    wall: Instant,
    cycle: u64,
    speed: f64,
    paused: bool,
}

impl Clock {
    /// Robot time the wall clock has reached.
    fn target(&self) -> u64 {
        if self.paused {
            return self.cycle;
        }
        let elapsed = self.wall.elapsed().as_secs_f64() * self.speed;
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            clippy::cast_precision_loss,
            reason = "a positive number of cycles, far below 2^52"
        )]
        let cycles = (elapsed * CPU_HZ as f64) as u64;
        self.cycle + cycles
    }

    /// Counts from robot time `cycle` now (after a change of speed, a
    /// pause, a step, or a robot that fell behind).
    fn rebase(&mut self, cycle: u64) {
        self.wall = Instant::now();
        self.cycle = cycle;
    }
}

/// The console's last lines.
#[derive(Default)]
struct Console {
    lines: VecDeque<ConsoleLine>,
    seq: u64,
    partial: Vec<u8>,
    changed: bool,
}

impl Console {
    fn push(&mut self, kind: &'static str, text: String) {
        self.seq += 1;
        self.lines.push_back(ConsoleLine {
            seq: self.seq,
            kind,
            text,
        });
        while self.lines.len() > CONSOLE_KEPT {
            self.lines.pop_front();
        }
        self.changed = true;
    }

    /// The robot's bytes: a line at each carriage return.
    fn answer(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            if byte == b'\r' || self.partial.len() >= PARTIAL_ANSWER {
                let text = romlib::sim::escape(&std::mem::take(&mut self.partial));
                self.push("answer", text);
                if byte == b'\r' {
                    continue;
                }
            }
            self.partial.push(byte);
        }
    }
}

/// The view's session: where it serves and what the robot has.
pub(crate) struct Session<'a> {
    pub(crate) address: SocketAddr,
    pub(crate) baud: u32,
    pub(crate) printed: &'a [(String, cards::Printed)],
    pub(crate) room: Option<RoomView>,
}

/// What the session leaves for `--path`: the room as it was left (moved
/// obstacles), the commands typed with their robot time.
pub(crate) struct Ended {
    pub(crate) layout: Option<Layout>,
    pub(crate) commands: Vec<(u64, String)>,
}

/// The most commands kept for the picture.
const COMMANDS_DRAWN: usize = 4096;

/// Serves the view until SIGINT or SIGTERM.
pub(crate) fn serve(robot: &mut VirtualScorpion, session: Session<'_>) -> miette::Result<Ended> {
    let stop =
        crate::cmd::flag_on_signals(&[signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM])?;
    let (hub, requests) = Hub::new(session.room.clone());
    let mut layout = session.room.as_ref().map(|room| room.layout().clone());
    let mut room_version = 0;
    let mut room_text = Arc::new(protocol::room_message(layout.as_ref()));
    let bound = server::start(session.address, Arc::clone(&hub))
        .into_diagnostic()
        .map_err(|error| {
            miette::miette!(
                help = "give another address, or port 0 for a free one: --view 127.0.0.1:0",
                "cannot serve the view on {}: {error}",
                session.address
            )
        })?;
    {
        let mut out = std::io::stdout().lock();
        writeln!(out, "open http://{bound}/").into_diagnostic()?;
        out.flush().into_diagnostic()?;
    }
    let _ = writeln!(
        std::io::stderr().lock(),
        "the virtual Scorpion's view is served at http://{bound}/ ({} baud); Ctrl-C stops it",
        session.baud
    );
    let mut clock = Clock {
        wall: Instant::now(),
        cycle: robot.cycles(),
        speed: 1.0,
        paused: false,
    };
    let mut line = HostLine::new(host_line::HOLDS);
    let mut console = Console::default();
    let mut commands = Vec::new();
    let mut published = Instant::now();
    let mut overruns = robot.robot().board().acia().overruns();
    let mut dirty = true;
    while !stop.load(Ordering::Acquire) {
        for request in requests.try_iter().take(REQUESTS_WAITING) {
            dirty = true;
            match request {
                Incoming::Send { text } => {
                    if commands.len() < COMMANDS_DRAWN {
                        commands.push((robot.cycles(), text.chars().take(32).collect()));
                    }
                    line.accept(text.as_bytes());
                    line.accept(b"\r");
                    console.push("sent", text);
                }
                Incoming::Pause {} => {
                    clock.rebase(robot.cycles());
                    clock.paused = true;
                }
                Incoming::Run {} => {
                    clock.rebase(robot.cycles());
                    clock.paused = false;
                }
                Incoming::Step { ms } => {
                    clock.paused = true;
                    let until = robot.cycles() + ms * (CPU_HZ / 1000);
                    line.feed(robot, until);
                    robot.run_until(until)?;
                    clock.rebase(robot.cycles());
                }
                Incoming::Speed { factor } => {
                    clock.rebase(robot.cycles());
                    clock.speed = factor;
                }
                Incoming::MoveRobot { x, y, heading } => {
                    let edit = Edit::MoveRobot(Pose {
                        at: Point::new(x, y),
                        heading: heading * PI / 180.0,
                    });
                    edit_room(robot, &session.room, layout.as_mut(), edit, &mut console)?;
                }
                Incoming::MoveObstacle { index, x, y } => {
                    let edit = Edit::MoveObstacle {
                        index,
                        to: Point::new(x, y),
                    };
                    // Refused too, the room goes out again: the page
                    // that dragged the obstacle draws it back where it is.
                    let moved =
                        edit_room(robot, &session.room, layout.as_mut(), edit, &mut console)?;
                    room_version += 1;
                    if moved {
                        room_text = Arc::new(protocol::room_message(layout.as_ref()));
                    }
                }
            }
        }
        let target = clock.target();
        // A robot that cannot keep up (a slow machine, a high speed)
        // slips: the loop comes round at least every 50 ms of wall time.
        let most = robot.cycles() + u64::max(20_000, (clock.speed * 50_000.0) as u64);
        let until = target.min(most);
        line.feed(robot, until);
        robot.run_until(until)?;
        if target > most {
            clock.rebase(robot.cycles());
        }
        crate::cmd::rig::show_printed(session.printed);
        let dropped = line.take_dropped();
        if dropped > 0 {
            console.push(
                "note",
                format!(
                    "line full: {dropped} byte(s) dropped ({} wait at most)",
                    host_line::HOLDS
                ),
            );
        }
        let now_overruns = robot.robot().board().acia().overruns();
        if now_overruns > overruns {
            console.push(
                "note",
                format!(
                    "6551 overrun: {} character(s) lost",
                    now_overruns - overruns
                ),
            );
            overruns = now_overruns;
        }
        let answer = robot.receive();
        if !answer.is_empty() {
            console.answer(&answer);
        }
        let refused = hub.refused.swap(0, Ordering::Relaxed);
        if refused > 0 {
            hub.say(&format!(
                "view: {refused} connection(s) refused (at most {} at once)",
                server::MAX_CONNECTIONS
            ));
        }
        let dropped = hub.dropped.swap(0, Ordering::Relaxed);
        if dropped > 0 {
            hub.say(&format!(
                "view: {dropped} request(s) dropped ({REQUESTS_WAITING} already waited)"
            ));
        }
        let running = !clock.paused;
        if console.changed || dirty || (running && published.elapsed() >= FRAME_EVERY) {
            hub.publish(Frame {
                room_version,
                room: Arc::clone(&room_text),
                state: state(robot, &clock, &session.room, &hub),
                console: Arc::new(console.lines.iter().cloned().collect()),
            });
            console.changed = false;
            dirty = false;
            published = Instant::now();
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    hub.stop.store(true, Ordering::Release);
    Ok(Ended { layout, commands })
}

/// Makes `edit` to the room (checked against `layout`, the host's copy),
/// at once even while paused; whether it was made. A refused edit is a
/// note on the console.
fn edit_room(
    robot: &mut VirtualScorpion,
    room: &Option<RoomView>,
    layout: Option<&mut Layout>,
    edit: Edit,
    console: &mut Console,
) -> miette::Result<bool> {
    let (Some(room), Some(layout)) = (room, layout) else {
        console.push(
            "note",
            "the robot has no room to move things in (give --world room.toml)".into(),
        );
        return Ok(false);
    };
    let mut pose = room.pose().unwrap_or(layout.start);
    if let Err(why) = edit.check(layout, pose) {
        console.push("note", why);
        return Ok(false);
    }
    if !room.edit(edit) {
        console.push("note", "too many changes wait for the room".into());
        return Ok(false);
    }
    edit.apply(layout, &mut pose);
    // The room takes the edit at a wake-up: one of no time makes it now.
    robot.run_for(0)?;
    Ok(true)
}

fn state(robot: &VirtualScorpion, clock: &Clock, room: &Option<RoomView>, hub: &Hub) -> State {
    let board = robot.robot().board();
    let (left_eye, right_eye) = board.eyes();
    #[allow(clippy::cast_precision_loss, reason = "robot time in ms")]
    let ms = robot.cycles() as f64 / 1000.0;
    State {
        ms,
        paused: clock.paused,
        speed: clock.speed,
        pose: room.as_ref().and_then(RoomView::pose).map(PoseJson::from),
        bumpers: board.bumpers(),
        trackers: board.phototransistors(),
        lamps: board.lamps(),
        eyes: [left_eye, right_eye],
        motors: [
            board.motor(Motor::Left).position(),
            board.motor(Motor::Right).position(),
        ],
        clients: hub.connections.load(Ordering::Relaxed),
    }
}
