//! How much the reference ROM takes back to back at 9600 baud without
//! losing a byte: commands sent with no gap between them, every answer
//! checked, the 6551 never overrun (the interrupt handler always empties
//! it in time; what can overflow is the ROM's 255-byte receive ring, when
//! answers take longer on the wire than the questions that asked for them).
//!
//! `cargo test -p scorpion-tests --test rom_burst -- --nocapture` prints
//! the longest burst of each kind of command; README.md quotes them.

use romlib::VirtualScorpion;
use romlib::sim::ANSWER_TIMEOUT;

/// Sends `count` copies of `command` back to back and checks that exactly
/// `count` copies of `answer` come back and the 6551 never overran.
fn question_burst(command: &[u8], answer: &[u8], count: usize) -> bool {
    let mut robot = VirtualScorpion::new();
    let burst: Vec<u8> = command.repeat(count);
    robot.send(&burst);
    let mut received = Vec::new();
    while let Ok(line) = robot.read_answer(ANSWER_TIMEOUT) {
        received.extend(line);
    }
    assert_eq!(
        robot.robot().board().acia().overruns(),
        0,
        "the 6551 overran"
    );
    received == answer.repeat(count)
}

/// The longest burst of `command` answered in full, up to `limit`.
fn longest(command: &[u8], answer: &[u8], limit: usize) -> usize {
    assert!(
        question_burst(command, answer, 1),
        "one question is answered"
    );
    if question_burst(command, answer, limit) {
        return limit;
    }
    let (mut good, mut bad) = (1, limit);
    while bad - good > 1 {
        let middle = (good + bad) / 2;
        if question_burst(command, answer, middle) {
            good = middle;
        } else {
            bad = middle;
        }
    }
    good
}

/// `count` `/9W` writes back to back into KIM-bus RAM, each a different
/// word; true when every word landed and nothing was answered.
fn write_burst(count: usize) -> bool {
    let mut robot = VirtualScorpion::new();
    let mut burst = Vec::with_capacity(11 * count);
    for index in 0..count {
        let address = 0x1000 + 2 * index;
        let value = index as u16 ^ 0xA5A5;
        burst.extend(format!("/9W{address:04X}{:02X}{:02X}", value >> 8, value & 0xFF).bytes());
    }
    robot.send(&burst);
    robot.settle().expect("the CPU runs");
    let memory = robot.robot().board().memory();
    let landed = (0..count).all(|index| {
        let address = 0x1000 + 2 * index;
        let value = index as u16 ^ 0xA5A5;
        memory[address] == (value >> 8) as u8 && memory[address + 1] == (value & 0xFF) as u8
    });
    landed && robot.receive().is_empty() && robot.robot().board().acia().overruns() == 0
}

#[test]
fn writes_are_taken_without_limit() {
    // 10,000 commands: 110,000 characters, two minutes of line time.
    assert!(write_burst(10_000));
    println!("/9Waaaahhhh: 10000 back to back, all taken (no limit)");
}

#[test]
fn question_bursts_fill_the_receive_ring_only_when_answers_outrun_questions() {
    let rom_start: String = romlib::ROM[..16]
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect();
    let read16 = format!("R{rom_start}\r");
    let rom_all: String = romlib::ROM[..99]
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect();
    let read99 = format!("R{rom_all}\r");
    let cases: [(&str, &[u8], &[u8]); 5] = [
        ("/1X", b"/1X", b"X00\r"),
        ("/1M", b"/1M", b"M+0000+0000\r"),
        ("/1P", b"/1P", b"PB00E0G0T0M+0000+0000Y00X00C0000D0000\r"),
        ("/7RF00016", b"/7RF00016", read16.as_bytes()),
        ("/7RF00099", b"/7RF00099", read99.as_bytes()),
    ];
    let mut longest_seen = Vec::new();
    for (name, command, answer) in cases {
        let n = longest(command, answer, 2000);
        println!(
            "{name}: {} characters in, {} out: longest burst {n}",
            command.len(),
            answer.len()
        );
        longest_seen.push((name, n));
    }
    // A question whose answer is no longer than itself never fills the
    // ring. The others fill it once the characters received but not yet
    // parsed pass 255: after a burst of n questions of `i` characters
    // answered with `o`, that backlog is about n * i * (1 - i / o), so
    // n = 255 / (i * (1 - i / o)): 340 for /1X, 93 for /1P, 38 and 30 for
    // the 16- and 99-byte reads.
    let get = |name: &str| {
        longest_seen
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, n)| *n)
            .expect("measured")
    };
    assert!(get("/1X") >= 200, "/1X: {}", get("/1X"));
    assert!(get("/1P") >= 80, "/1P: {}", get("/1P"));
    assert!(get("/7RF00016") >= 35, "/7R 16 bytes: {}", get("/7RF00016"));
    assert!(get("/7RF00099") >= 25, "/7R 99 bytes: {}", get("/7RF00099"));
}
