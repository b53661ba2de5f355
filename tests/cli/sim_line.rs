//! Issue 23, item 12: `scorpion sim --pty`'s line behaves as a real one.
//! A flood written to the pseudo-terminal keeps the simulator's memory
//! small (a real serial port holds a few KiB; the rest is dropped, and
//! said) and does not hold up the commands after it for longer than that
//! much takes on the line; and a character that reaches the 6551 while
//! its receive register is still full is lost to overrun, visibly, as on
//! the robot. Each run on a real pseudo-terminal, under a memory limit.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::{scorpion, transcript};

/// Address space for the simulator: several times what it needs, far
/// less than queueing a 64 MiB flood at 48 bytes a byte takes.
const MEMORY_KIB: u64 = 1 << 20;

/// `scorpion sim --pty ARGS` in `dir` under [`MEMORY_KIB`], killed when
/// dropped, its stderr collected as it comes.
struct Sim {
    child: std::process::Child,
    path: String,
    stderr: Arc<Mutex<String>>,
}

impl Sim {
    fn start(dir: &Path, args: &[&str]) -> Sim {
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(format!("ulimit -v {MEMORY_KIB} && exec \"$0\" \"$@\""))
            .arg(env!("CARGO_BIN_EXE_scorpion"))
            .args(["sim", "--pty"])
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the scorpion binary runs");
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut pipe = child.stderr.take().expect("stderr is piped");
        let collected = Arc::clone(&stderr);
        std::thread::spawn(move || {
            let mut buffer = [0u8; 1024];
            while let Ok(count) = pipe.read(&mut buffer) {
                if count == 0 {
                    break;
                }
                let text = String::from_utf8_lossy(&buffer[..count]).into_owned();
                collected.lock().expect("not poisoned").push_str(&text);
            }
        });
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout is piped"));
        let mut path = String::new();
        stdout
            .read_line(&mut path)
            .expect("the first line is the path");
        let path = path.trim().to_owned();
        assert!(
            path.starts_with("/dev/"),
            "no path: {path:?}, stderr: {}",
            stderr.lock().expect("not poisoned")
        );
        Sim {
            child,
            path,
            stderr,
        }
    }

    fn stderr(&self) -> String {
        self.stderr.lock().expect("not poisoned").clone()
    }

    /// The simulator's peak resident memory, in KiB (Linux's `VmHWM`).
    fn peak_kib(&self) -> u64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id()))
            .expect("the simulator is running");
        status
            .lines()
            .find_map(|line| line.strip_prefix("VmHWM:"))
            .and_then(|rest| rest.trim().trim_end_matches("kB").trim().parse().ok())
            .expect("VmHWM in /proc/PID/status")
    }

    fn running(&mut self) -> bool {
        self.child.try_wait().expect("waitable").is_none()
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Sends `command` and reads up to its carriage return, for at most
/// `limit`; the answer and how long it took.
fn ask(
    port: &mut dyn serialport::SerialPort,
    command: &[u8],
    limit: Duration,
) -> (String, Duration) {
    let started = Instant::now();
    port.write_all(command).expect("the command is written");
    let mut answer = Vec::new();
    let mut buffer = [0u8; 256];
    while !answer.contains(&b'\r') && started.elapsed() < limit {
        if let Ok(count) = port.read(&mut buffer) {
            answer.extend_from_slice(&buffer[..count]);
        }
    }
    (
        String::from_utf8_lossy(&answer).into_owned(),
        started.elapsed(),
    )
}

/// Writes `total` bytes of `x` (outside any command: the ROM ignores
/// them) to the pseudo-terminal as fast as it takes them, giving up at
/// `limit`; the bytes written.
fn flood(path: &str, total: usize, limit: Duration) -> usize {
    let mut slave = std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .expect("the pseudo-terminal opens for writing");
    let chunk = vec![b'x'; 64 << 10];
    let started = Instant::now();
    let mut written = 0;
    while written < total && started.elapsed() < limit {
        match slave.write(&chunk[..chunk.len().min(total - written)]) {
            Ok(count) => written += count,
            Err(_) => break,
        }
    }
    written
}

/// Asks `/1E` every half second until the robot answers `E0` (while the
/// line is full a question is dropped, as a full port refuses a write),
/// for at most a minute; how long that took.
fn recover(port: &mut dyn serialport::SerialPort) -> Duration {
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(60) {
        let (answer, _) = ask(port, b"/1E", Duration::from_millis(500));
        if answer.ends_with("E0\r") {
            let _ = port.clear(serialport::ClearBuffer::Input);
            return started.elapsed();
        }
    }
    panic!("no answer a minute after the flood");
}

#[test]
fn a_flood_keeps_memory_small_and_the_next_command_is_answered_soon() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut sim = Sim::start(dir.path(), &[]);
    let mut port = serialport::new(&sim.path, 9600)
        .timeout(Duration::from_millis(50))
        .open()
        .expect("the pseudo-terminal opens");
    let (answer, _) = ask(&mut *port, b"/1E", Duration::from_secs(5));
    assert_eq!(answer, "E0\r");
    let before = sim.peak_kib();

    // A megabyte: the old simulator queued it all and answered the
    // command behind it 18 minutes later.
    let written = flood(&sim.path, 1 << 20, Duration::from_secs(60));
    assert_eq!(written, 1 << 20, "the flood was taken");
    let took = recover(&mut *port);
    // What a port holds (4 KiB) takes 4.3 s at 9600 baud; then the ROM
    // answers at once.
    assert!(took < Duration::from_secs(8), "answered after {took:?}");

    // 64 MiB: the old simulator grew by 48 bytes a byte until the memory
    // limit killed it.
    let written = flood(&sim.path, 64 << 20, Duration::from_secs(120));
    assert!(sim.running(), "the simulator died: {}", sim.stderr());
    assert_eq!(written, 64 << 20, "the flood was taken");
    let grown = sim.peak_kib().saturating_sub(before);
    assert!(grown < 16 << 10, "the simulator grew by {grown} KiB");
    let took = recover(&mut *port);
    assert!(took < Duration::from_secs(8), "answered after {took:?}");
    let said = sim.stderr();
    assert!(
        said.contains("line full:") && said.contains("bytes dropped"),
        "the drops are said: {said}"
    );
}

#[test]
fn characters_the_6551_overran_are_lost_and_said() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // `/1Q` runs 50 ms with interrupts off: the ROM takes no byte meanwhile.
    std::fs::write(
        dir.path().join("deaf.s"),
        ".include \"scorpion.inc\"\nSCORPION_UNKNOWN_HANDLER\n        cmp #'Q'\n        bne pass\n        sei\n        ldx #0\n        ldy #40\nspin:   dex\n        bne spin\n        dey\n        bne spin\n        cli\n        jmp CMD_DONE\npass:   SCORPION_CHAIN_UNKNOWN\n",
    )
    .expect("write the source");
    let built = scorpion(dir.path(), &["build", "deaf.s", "-o", "deaf.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let sim = Sim::start(dir.path(), &["--image", "deaf.elf"]);
    let mut port = serialport::new(&sim.path, 9600)
        .timeout(Duration::from_millis(50))
        .open()
        .expect("the pseudo-terminal opens");
    // Four questions right behind /1Q reach the 6551 while it is deaf:
    // the first waits in its receive register, the other eleven bytes
    // overrun it. No answer comes.
    let (answer, _) = ask(&mut *port, b"/1Q/1E/1E/1E/1E", Duration::from_millis(500));
    assert_eq!(answer, "", "the questions were lost");
    let started = Instant::now();
    while !sim.stderr().contains("6551 overrun") && started.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let said = sim.stderr();
    let lost: u64 = said
        .lines()
        .filter_map(|line| line.strip_prefix("6551 overrun: "))
        .filter_map(|rest| rest.split(' ').next()?.parse::<u64>().ok())
        .sum();
    assert_eq!(lost, 11, "the overrun is said: {said}");
    // The robot recovers: the next question is answered.
    let (answer, _) = ask(&mut *port, b"/1E", Duration::from_secs(5));
    assert_eq!(answer, "E0\r");
}

/// `scorpion sim` without `--pty` takes stdin as the pty's line is taken:
/// 64 MiB written at once keeps the simulator's memory small (the old one
/// read it as one line and queued it all, about 48 bytes a byte, until
/// the memory limit killed it), the drop is said, and a command written
/// once the line has carried what it holds is answered.
#[test]
fn a_flood_on_stdin_keeps_memory_small_and_is_said() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_scorpion"))
        .arg("sim")
        .current_dir(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the scorpion binary runs");
    let mut stdin = child.stdin.take().expect("stdin is piped");
    stdin.write_all(b"/1E\n").expect("the first command");
    std::thread::sleep(Duration::from_secs(1));
    let peak = |pid: u32| -> Option<u64> {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
        status
            .lines()
            .find_map(|line| line.strip_prefix("VmHWM:"))
            .and_then(|rest| rest.trim().trim_end_matches("kB").trim().parse().ok())
    };
    let before = peak(child.id()).expect("the simulator runs");
    let chunk = vec![b'x'; 64 << 10];
    let started = Instant::now();
    let mut written = 0usize;
    while written < 64 << 20 && started.elapsed() < Duration::from_secs(120) {
        match stdin.write(&chunk) {
            Ok(count) => written += count,
            Err(_) => break,
        }
    }
    assert_eq!(written, 64 << 20, "the flood was taken");
    // What a port holds (4 KiB) takes 4.3 s at 9600 baud; then the line
    // has room for the next command.
    std::thread::sleep(Duration::from_secs(6));
    let grown = peak(child.id())
        .expect("the simulator still runs")
        .saturating_sub(before);
    stdin.write_all(b"/1E\n").expect("the last command");
    drop(stdin);
    let started = Instant::now();
    while child.try_wait().expect("waitable").is_none() {
        if started.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("the simulator did not end a minute after stdin did");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let output = child.wait_with_output().expect("the output");
    let said = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "{said}");
    assert!(grown < 16 << 10, "the simulator grew by {grown} KiB");
    assert_eq!(
        String::from_utf8_lossy(&output.stdout),
        "E0\nE0\n",
        "{said}"
    );
    let dropped: u64 = said
        .lines()
        .filter_map(|line| line.strip_prefix("line full: "))
        .filter_map(|rest| rest.split(' ').next()?.parse::<u64>().ok())
        .sum();
    // Everything but what the line carried or held.
    assert!(
        dropped > (64 << 20) - (64 << 10),
        "{dropped} dropped: {said}"
    );
}
