//! `scorpion read` and `scorpion ports`, through a real pseudo-terminal to
//! a small robot double on its master side, and with a port that is
//! missing or busy.

use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use romlib::protocol::{Answer, BusyByte, Command};
use serialport::{SerialPort, TTYPort};

use crate::{scorpion, transcript};

/// A robot double on the master side of a pty: it answers `/1X` and
/// `/7R` from its memory and obeys `/7W` and `/9W`, with the ROM's resync
/// rule (a `/` restarts).
pub(crate) struct PtyRobot {
    pub(crate) path: String,
    pub(crate) memory: Arc<Mutex<Vec<u8>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    // The slave stays open so the master never sees a hang-up between
    // the CLI's opens.
    _slave: TTYPort,
}

impl PtyRobot {
    pub(crate) fn spawn(memory: Vec<u8>) -> PtyRobot {
        let memory = Arc::new(Mutex::new(memory));
        let shared = Arc::clone(&memory);
        let (mut master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
        let path = slave.name().expect("the slave's path");
        master
            .set_timeout(Duration::from_millis(20))
            .expect("a read timeout");
        let stop = Arc::new(AtomicBool::new(false));
        let stopping = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            let mut command: Option<Vec<u8>> = None;
            let mut buffer = [0u8; 256];
            while !stopping.load(Ordering::Relaxed) {
                let count = match master.read(&mut buffer) {
                    Ok(count) => count,
                    Err(_) => continue,
                };
                for &byte in &buffer[..count] {
                    if byte == b'/' {
                        command = Some(vec![byte]);
                        continue;
                    }
                    let Some(text) = command.as_mut() else {
                        continue;
                    };
                    text.push(byte);
                    if text.len() < 2 || text.len() != usize::from(text[1].wrapping_sub(b'0')) + 2 {
                        continue;
                    }
                    let mut memory = shared.lock().expect("the robot's memory");
                    let answer = match Command::parse(text) {
                        Ok(Command::Busy) => Some(Answer::Busy(BusyByte(0))),
                        Ok(Command::ReadMemory(span)) => {
                            let start = usize::from(span.address());
                            let end = start + usize::from(span.count());
                            Some(Answer::Memory(memory[start..end].to_vec()))
                        }
                        Ok(Command::WriteByte { address, value }) => {
                            memory[usize::from(address)] = value;
                            None
                        }
                        Ok(Command::WriteWord(write)) => {
                            let at = usize::from(write.address());
                            memory[at..at + 2].copy_from_slice(&write.bytes());
                            None
                        }
                        _ => None,
                    };
                    drop(memory);
                    command = None;
                    if let Some(answer) = answer {
                        master.write_all(&answer.encode()).expect("answer");
                    }
                }
            }
        });
        PtyRobot {
            path,
            memory,
            stop,
            thread: Some(thread),
            _slave: slave,
        }
    }
}

impl Drop for PtyRobot {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            thread.join().expect("the robot thread ends");
        }
    }
}

pub(crate) fn memory() -> Vec<u8> {
    let mut memory = vec![0u8; 0x1_0000];
    memory[0x0200..0x0206].copy_from_slice(&[0x4C, 0x23, 0xF1, 0x4C, 0x45, 0xF0]);
    memory[0x0400..0x0410].copy_from_slice(b"HELLO, SCORPION!");
    for (i, byte) in memory[0x1000..0x1200].iter_mut().enumerate() {
        *byte = (i * 13) as u8;
    }
    memory
}

#[test]
fn reads_memory_through_a_pseudo_terminal() {
    let robot = PtyRobot::spawn(memory());
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = scorpion(dir.path(), &["read", "--port", &robot.path, "$0200", "32"]);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    insta::assert_snapshot!("read_hex_dump", text);

    let output = scorpion(
        dir.path(),
        &[
            "read",
            "--port",
            &robot.path,
            "0x1000",
            "0x200",
            "-o",
            "dump.bin",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
    let dumped = std::fs::read(dir.path().join("dump.bin")).expect("the dump");
    assert_eq!(dumped, memory()[0x1000..0x1200]);
}

#[test]
fn missing_and_busy_ports_are_clear_errors() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = scorpion(dir.path(), &["read", "--port", "/dev/ttyNOPE9", "0", "1"]);
    assert_eq!(output.status.code(), Some(1));
    insta::assert_snapshot!("read_missing_port", transcript(&output));

    let robot = PtyRobot::spawn(memory());
    let _held = uploader::transport::SerialTransport::open(&robot.path, 9600)
        .expect("the first open succeeds");
    let output = scorpion(dir.path(), &["read", "--port", &robot.path, "0", "1"]);
    assert_eq!(output.status.code(), Some(1));
    let text = transcript(&output).replace(&robot.path, "[PTY]");
    insta::assert_snapshot!("read_busy_port", text);

    let output = scorpion(dir.path(), &["read", "--port", &robot.path, "$FFF0", "17"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(transcript(&output).contains("runs past $FFFF"));
}

#[test]
fn a_silent_line_is_no_answer() {
    // A pty with nobody on the master side: the bytes go nowhere.
    let (_master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    let path = slave.name().expect("the slave's path");
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = scorpion(dir.path(), &["read", "--port", &path, "0", "1"]);
    assert_eq!(output.status.code(), Some(1));
    let text = transcript(&output).replace(&path, "[PTY]");
    insta::assert_snapshot!("read_no_answer", text);
}

#[test]
fn ports_lists_without_failing() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = scorpion(dir.path(), &["ports"]);
    assert_eq!(output.status.code(), Some(0), "{}", transcript(&output));
}
