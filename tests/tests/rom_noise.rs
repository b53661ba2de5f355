//! Line noise: the reference ROM takes seeded random byte streams built from
//! the protocol's own alphabet (so that many are commands, nearly commands,
//! or commands with wild arguments), back to back at 9600 baud, and
//! afterwards still resets and answers exactly. RAM writes are left out of
//! the alphabet: a random `/9W` into the stack may rightly crash a robot.

use romlib::VirtualScorpion;
use romlib::sim::ANSWER_TIMEOUT;

/// A small deterministic generator (xorshift64*), so failures replay.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        usize::try_from(self.next() % n as u64).expect("small")
    }
}

const ALPHABET: &[u8] = b"///123456789123456789ABCDEFabcdef0123+-RYZCDBSEGTMXPKHV\r\n \x00\xFF";

/// Command shapes, `h` a hex digit, `d` a decimal digit, `s` a sign, `L` a
/// letter of the alphabet: real commands with wild fields.
const SHAPES: [&str; 12] = [
    "/1L",
    "/2Ed",
    "/2Gd",
    "/3Yhh",
    "/3Zhh",
    "/3Khh",
    "/3Hdd",
    "/3Vdd",
    "/4Csdd",
    "/4Dsdd",
    "/8Csdddddd",
    "/7Rhhhhdd",
];

impl Noise {
    /// One token: a command shape filled at random, sometimes cut short or
    /// with a stray byte inside, or a stray byte alone.
    fn token(&mut self, out: &mut Vec<u8>) {
        if self.below(4) == 0 {
            out.push(ALPHABET[self.below(ALPHABET.len())]);
            return;
        }
        let shape = SHAPES[self.below(SHAPES.len())].as_bytes();
        let cut = if self.below(8) == 0 {
            self.below(shape.len())
        } else {
            shape.len()
        };
        for &byte in &shape[..cut] {
            let filled = match byte {
                b'h' => b"0123456789ABCDEFabcdefG"[self.below(23)],
                b'd' => b"0123456789x"[self.below(11)],
                b's' => b"+-*"[self.below(3)],
                b'L' => ALPHABET[self.below(ALPHABET.len())],
                other => other,
            };
            out.push(filled);
            if self.below(40) == 0 {
                out.push(ALPHABET[self.below(ALPHABET.len())]);
            }
        }
    }
}

#[test]
fn random_streams_never_wedge_the_rom() {
    for seed in 1..=20u64 {
        let mut noise = Noise(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let mut robot = VirtualScorpion::new();
        let mut stream = Vec::new();
        while stream.len() < 3000 {
            noise.token(&mut stream);
        }
        robot.send(&stream);
        robot
            .settle()
            .unwrap_or_else(|error| panic!("seed {seed}: {error}"));
        // Let whatever the noise started (scans, moves) run its course.
        robot
            .run_for(3_000_000)
            .unwrap_or_else(|error| panic!("seed {seed}: {error}"));
        let answers = robot.receive().iter().filter(|&&b| b == b'\r').count();
        assert!(
            answers > 10,
            "seed {seed}: the noise asked only {answers} questions"
        );
        // A slash ends any half-received command; then reset and ask.
        robot.send(b"/");
        robot
            .settle()
            .unwrap_or_else(|error| panic!("seed {seed}: {error}"));
        robot.send(b"/1R");
        robot
            .settle()
            .unwrap_or_else(|error| panic!("seed {seed}: {error}"));
        let answer = robot
            .transact(b"/1P", ANSWER_TIMEOUT)
            .unwrap_or_else(|error| panic!("seed {seed}: {error}"));
        let text = String::from_utf8_lossy(&answer).into_owned();
        assert!(
            text.starts_with("PB00E0G0T0M") && text.ends_with("Y00X00C0000D0000\r"),
            "seed {seed}: {text:?}"
        );
        let hooks = robot
            .transact(b"/7R020006", ANSWER_TIMEOUT)
            .unwrap_or_else(|error| panic!("seed {seed}: {error}"));
        assert_eq!(hooks, b"R4C21FF4C24FF\r", "seed {seed}");
        assert_eq!(
            robot.robot().board().acia().overruns(),
            0,
            "seed {seed}: the 6551 overran"
        );
        // The stack is where a reset leaves it, give or take the loop.
        let sp = robot.robot().cpu.s;
        assert!(sp >= 0xF0, "seed {seed}: S = ${sp:02X}");
    }
}
