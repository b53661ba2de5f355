//! Conformance of the reference ROM on the virtual Scorpion to docs/PROTOCOL.md
//! section 2: every instruction and question, sent through the emulated
//! 6551 at 9600 baud, with its answer and its effect on the board checked.
//! Each test's transcript is an insta snapshot.

mod rom_support;

use emulator::board::{Motor, Scene};
use rom_support::Session;
use romlib::protocol::Answer;
use romlib::symbols;

/// The `/1P` answer of a robot at rest after power-up.
const AT_REST: &str = "PB00E0G0T0M+0000+0000Y00X00C0000D0000\r";

#[test]
fn power_up_state() {
    let mut s = Session::new();
    assert_eq!(s.ask("/1P"), AT_REST);
    assert_eq!(s.ask("/1S"), "SH00\r", "the buffer of a scan of 0 steps");
    // The hooks: JMP BAD_COMMAND, JMP ROM_LOOP.
    let hooks = format!(
        "R4C{:02X}{:02X}4C{:02X}{:02X}\r",
        symbols::BAD_COMMAND & 0xFF,
        symbols::BAD_COMMAND >> 8,
        symbols::ROM_LOOP & 0xFF,
        symbols::ROM_LOOP >> 8
    );
    assert_eq!(s.ask("/7R020006"), hooks);
    // The obey mask is FF.
    assert_eq!(s.ask("/7R021102"), "RFF00\r");
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn reset_returns_to_the_power_up_state() {
    let mut s = Session::new();
    s.send("/2E3");
    s.send("/2G1");
    s.send("/3K20");
    s.send("/3Y01");
    s.send("/3Z7E");
    s.send("/4C+40");
    s.send("/8D-100500");
    s.send("/9W02000000");
    s.wait_ms(100);
    assert_ne!(s.ask("/1P"), AT_REST);
    s.send("/1R");
    assert_eq!(s.ask("/1P"), AT_REST);
    assert_eq!(s.ask("/7R021102"), "RFF00\r");
    let board = s.robot.robot().board();
    assert_eq!(board.eyes(), (false, false));
    assert!(!board.lamps());
    assert_eq!(board.speaker_hz(), None);
    let (left, right) = (s.position(Motor::Left), s.position(Motor::Right));
    s.wait_ms(200);
    assert_eq!(
        (s.position(Motor::Left), s.position(Motor::Right)),
        (left, right)
    );
    // The RAM vectors are rebuilt too.
    let hooks = s.ask("/7R020003");
    assert_eq!(
        hooks,
        format!(
            "R4C{:02X}{:02X}\r",
            symbols::BAD_COMMAND & 0xFF,
            symbols::BAD_COMMAND >> 8
        )
    );
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn master_io_byte_inhibits_devices_by_the_obey_mask() {
    let mut s = Session::new();
    s.send("/2E3");
    s.send("/2G1");
    s.send("/3K10");
    s.send("/4C+50");
    // Device i is inhibited iff (obey_i and io_i) or (obey_7 and io_7).
    let cases: [(u8, u8, [bool; 4]); 8] = [
        // (io, mask, [eyes, lamps, speaker, left motor] inhibited)
        (0x00, 0xFF, [false, false, false, false]),
        (0x02, 0xFF, [true, false, false, false]),
        (0x04, 0xFF, [false, true, false, false]),
        (0x21, 0xFF, [false, false, true, true]),
        (0x80, 0xFF, [true, true, true, true]),
        (0x80, 0x7F, [false, false, false, false]),
        (0x82, 0x7F, [true, false, false, false]),
        (0xFF, 0x00, [false, false, false, false]),
    ];
    for (io, mask, inhibited) in cases {
        s.send(&format!("/3Y{io:02X}"));
        s.send(&format!("/3Z{mask:02X}"));
        let before = s.position(Motor::Left);
        s.wait_ms(100);
        let moved = s.position(Motor::Left) != before;
        let board = s.robot.robot().board();
        let seen = [
            board.eyes() == (false, false),
            !board.lamps(),
            board.speaker_hz().is_none(),
            !moved,
        ];
        assert_eq!(seen, inhibited, "io {io:02X} mask {mask:02X}");
        // What was asked for is still what the questions report.
        let Some(Answer::Everything(status)) = s.send("/1P") else {
            panic!("/1P answers P...")
        };
        assert_eq!(status.io, io);
        assert_eq!(status.eyes.digit(), b'3');
        assert!(status.lamps);
    }
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn a_closed_bumper_sets_bit_7_and_stops_the_motors_until_recovery() {
    let mut s = Session::new();
    s.send("/4C+50");
    s.send("/4D+50");
    s.wait_ms(200);
    assert!(s.position(Motor::Left) > 40);
    s.bumpers(0b0000_0001);
    s.wait_ms(5);
    let (left, right) = (s.position(Motor::Left), s.position(Motor::Right));
    assert_eq!(s.ask("/1B"), "B01\r");
    let Some(Answer::Everything(status)) = s.send("/1P") else {
        panic!("/1P answers P...")
    };
    assert_eq!(status.io, 0x80, "a closed bumper sets master bit 7");
    s.wait_ms(200);
    assert_eq!(
        (s.position(Motor::Left), s.position(Motor::Right)),
        (left, right),
        "the motors stopped"
    );
    // Clearing the byte while the bumper is still closed: it is set again.
    s.send("/3Y00");
    let Some(Answer::Everything(status)) = s.send("/1P") else {
        panic!("/1P answers P...")
    };
    assert_eq!(status.io, 0x80, "the bumper keeps setting bit 7");
    // Recovery: ignore bit 7 and back away.
    s.send("/4C-30");
    s.send("/4D-30");
    s.send("/3Z7F");
    s.wait_ms(400);
    assert!(s.position(Motor::Left) < left - 40, "backing away");
    assert!(s.position(Motor::Right) < right - 40, "backing away");
    s.bumpers(0);
    s.send("/4C+00");
    s.send("/4D+00");
    s.send("/3Y00");
    s.send("/3ZFF");
    assert_eq!(s.ask("/1B"), "B00\r");
    let Some(Answer::Everything(status)) = s.send("/1P") else {
        panic!("/1P answers P...")
    };
    assert_eq!(status.io, 0x00);
    assert_eq!(s.ask("/7R021101"), "RFF\r");
    // Everything runs again.
    s.send("/4C+50");
    let before = s.position(Motor::Left);
    s.wait_ms(100);
    assert!(s.position(Motor::Left) > before + 15);
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn specific_moves_count_from_a_standstill_but_not_inside_continuous_mode() {
    let mut s = Session::new();
    s.send("/8C+500100");
    s.wait_ms(100);
    let Some(Answer::Remaining { steps, .. }) = s.send("/1C") else {
        panic!("/1C answers C####")
    };
    assert!(steps.get() > 50 && steps.get() < 100, "{steps:?}");
    s.wait_ms(400);
    assert_eq!(s.ask("/1C"), "C0000\r");
    assert_eq!(s.position(Motor::Left), 100);
    assert_eq!(s.ask("/1M"), "M+0100+0000\r");
    // LASTMOVE keeps the counts of that answer: +100 and 0, 16-bit LE.
    assert_eq!(s.ask("/7R021304"), "R64000000\r");
    assert_eq!(s.ask("/1M"), "M+0000+0000\r");

    // Right motor, backwards.
    s.send("/8D-990050");
    s.wait_ms(200);
    assert_eq!(s.ask("/1D"), "D0000\r");
    assert_eq!(s.position(Motor::Right), -50);
    assert_eq!(s.ask("/1M"), "M+0000-0050\r");
    assert_eq!(s.ask("/7R021304"), "R0000CEFF\r");

    // A 90-degree turn in the middle of continuous mode: the move runs,
    // continuous mode resumes, and the move is not counted.
    s.send("/4D+20");
    s.wait_ms(200);
    s.send("/8D-990200");
    s.wait_ms(100);
    let during = s.position(Motor::Right);
    s.wait_ms(400);
    assert_eq!(s.ask("/1D"), "D0000\r");
    let after_turn = s.position(Motor::Right);
    assert!(after_turn < during, "the move ran backwards");
    s.wait_ms(200);
    assert!(
        s.position(Motor::Right) > after_turn + 10,
        "continuous mode resumed"
    );
    s.send("/4D+00");
    let Some(Answer::Moves(moves)) = s.send("/1M") else {
        panic!("/1M answers M...")
    };
    // Everything the motor did except the 200-step move.
    let counted = i64::from(moves.right.steps.get());
    assert_eq!(counted, s.position(Motor::Right) - (-50) + 200);
    // Speed 00 cancels a specific move.
    s.send("/8C+010500");
    s.send("/8C+000000");
    assert_eq!(s.ask("/1C"), "C0000\r");
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn continuous_mode_runs_until_speed_00() {
    let mut s = Session::new();
    s.send("/4C+99");
    s.send("/4D-10");
    assert_eq!(s.ask("/1X"), "XE0\r");
    s.wait_ms(1000);
    // Speed x 5 steps per second (the second plus the few milliseconds
    // the commands took).
    let left = s.position(Motor::Left);
    let right = s.position(Motor::Right);
    assert!((495..=510).contains(&left), "{left}");
    assert!((-52..=-50).contains(&right), "{right}");
    s.send("/4C+00");
    s.send("/4D+00");
    assert_eq!(s.ask("/1X"), "X00\r");
    let stopped = s.position(Motor::Left);
    s.wait_ms(100);
    assert_eq!(s.position(Motor::Left), stopped);
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn eyes_lamps_and_tracker() {
    let mut s = Session::new();
    for (digit, lit) in [
        (0, (false, false)),
        (1, (false, true)),
        (2, (true, false)),
        (3, (true, true)),
    ] {
        s.send(&format!("/2E{digit}"));
        assert_eq!(s.ask("/1E"), format!("E{digit}\r"));
        assert_eq!(
            s.robot.robot().board().eyes(),
            lit,
            "(left, right) for E{digit}"
        );
    }
    s.send("/2G1");
    assert_eq!(s.ask("/1G"), "G1\r");
    assert!(s.robot.robot().board().lamps());
    s.send("/2G0");
    assert_eq!(s.ask("/1G"), "G0\r");
    assert!(!s.robot.robot().board().lamps());
    // Out-of-range digits are malformed: nothing changes.
    s.tell_raw(b"/2E4");
    s.tell_raw(b"/2G2");
    assert_eq!(s.ask("/1E"), "E3\r");
    for lit in 0..4u8 {
        s.robot.robot_mut().board_mut().set_phototransistors(lit);
        assert_eq!(s.ask("/1T"), format!("T{lit}\r"));
    }
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn busy_byte_has_a_bit_per_activity() {
    let mut s = Session::new();
    assert_eq!(s.ask("/1X"), "X00\r");
    let steps: [(&str, u8); 7] = [
        ("/3K40", 0x01),
        ("/2E1", 0x02),
        ("/2G1", 0x04),
        ("/3H20", 0x08),
        ("/4C+10", 0x20),
        ("/8D+100010", 0x40),
        ("/3Y80", 0x00),
    ];
    let mut expected = 0u8;
    for (command, bit) in steps {
        s.send(command);
        expected |= bit;
        assert_eq!(s.ask("/1X"), format!("X{:02X}\r", expected | 0x80));
    }
    // The Master I/O byte switches the devices off, but what is in progress
    // stays in progress.
    s.send("/3Y00");
    s.wait_ms(2000);
    // The move and the scan are over; the rest goes on.
    assert_eq!(s.ask("/1X"), "XA7\r");
    s.send("/3K00");
    s.send("/2E0");
    s.send("/2G0");
    s.send("/4C+00");
    assert_eq!(s.ask("/1X"), "X00\r");
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn read_and_write_memory() {
    let mut s = Session::new();
    s.send("/7W0400A5");
    s.send("/9W04011234");
    assert_eq!(s.ask("/7R040003"), "RA51234\r");
    assert_eq!(s.ask("/7R040000"), "R\r");
    // Lower-case hex on input.
    s.tell_raw(b"/9W0403beef");
    assert_eq!(s.ask("/7R040302"), "RBEEF\r");
    // The ROM reads back as the image.
    let answer = s.ask("/7RF00099");
    let expected: String = romlib::ROM[..99]
        .iter()
        .map(|b| format!("{b:02X}"))
        .collect();
    assert_eq!(answer, format!("R{expected}\r"));
    // KIM-bus RAM.
    s.send("/9W8000CAFE");
    assert_eq!(s.ask("/7R800002"), "RCAFE\r");
    // The ROM is write-protected.
    s.send("/7WF00000");
    assert_eq!(s.ask("/7RF00001"), format!("R{:02X}\r", romlib::ROM[0]));
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn scans_fill_the_scanner_buffer() {
    let mut s = Session::new();
    s.robot
        .robot_mut()
        .board_mut()
        .set_scene(Scene::from_fn(|h, v| {
            u8::try_from((h + 64) * 2 + (v + 64) / 2).unwrap_or(0)
        }));
    s.send("/3H05");
    assert_eq!(s.ask("/1X"), "X88\r");
    s.wait_ms(300);
    assert_eq!(s.ask("/1X"), "X00\r", "scan and return done");
    let expected: String = (-5..=5i64)
        .map(|h| format!("{:02X}", (h + 64) * 2 + 32))
        .collect();
    assert_eq!(s.ask("/1S"), format!("SH{expected}\r"));
    assert_eq!(
        s.position(Motor::HorizontalScanner),
        0,
        "back at the centre"
    );
    s.send("/3V02");
    s.wait_ms(200);
    let expected: String = (-2..=2i64)
        .map(|v| format!("{:02X}", 128 + (v + 64) / 2))
        .collect();
    assert_eq!(s.ask("/1S"), format!("SV{expected}\r"));
    // The largest scan: 99 steps each side, 199 bytes.
    s.send("/3H99");
    s.wait_ms(2500);
    let Some(Answer::Scan(scan)) = s.send("/1S") else {
        panic!("/1S answers S...")
    };
    assert_eq!(scan.data.len(), 199);
    // 00 steps is malformed, and a scan asked for during a scan is ignored.
    s.tell_raw(b"/3H00");
    assert_eq!(s.ask("/1X"), "X00\r");
    s.send("/3V10");
    s.send("/3H03");
    s.wait_ms(1000);
    let Some(Answer::Scan(scan)) = s.send("/1S") else {
        panic!("/1S answers S...")
    };
    assert_eq!(scan.data.len(), 21, "the running vertical scan went on");
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn the_speaker_plays_the_pitch_code() {
    let mut s = Session::new();
    s.send("/3K10");
    // Half period 16 x 32 + 2 cycles.
    let hz = s.robot.robot().board().speaker_hz().expect("a tone");
    assert!((hz - 1_000_000.0 / (2.0 * 514.0)).abs() < 0.01, "{hz}");
    s.send("/3K01");
    let hz = s.robot.robot().board().speaker_hz().expect("a tone");
    assert!((hz - 1_000_000.0 / 68.0).abs() < 0.01, "{hz}");
    s.send("/3Y01");
    assert_eq!(s.robot.robot().board().speaker_hz(), None, "inhibited");
    s.send("/3Y00");
    assert!(s.robot.robot().board().speaker_hz().is_some());
    s.send("/3K00");
    assert_eq!(s.robot.robot().board().speaker_hz(), None);
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn grammar_resync_unknown_and_malformed_commands() {
    let mut s = Session::new();
    // Bytes outside a command are ignored.
    s.tell_raw(b"hello\r\n");
    assert_eq!(s.ask("xyz/1X"), "X00\r");
    // A slash inside a command restarts parsing.
    assert_eq!(s.ask("/7R02/1E"), "E0\r");
    // Unknown commands: no answer, no effect.
    s.tell_raw(b"/1Q");
    s.tell_raw(b"/5Qabcd");
    s.tell_raw(b"/2X1");
    // A count digit that is not 1-9 is not a command.
    s.tell_raw(b"/0/aX");
    // Malformed arguments: dropped.
    s.tell_raw(b"/3YZZ");
    s.tell_raw(b"/4C*50");
    s.tell_raw(b"/8C+5x0100");
    s.tell_raw(b"/7WG00011");
    assert_eq!(s.ask("/1P"), AT_REST);
    // Commands are upper case; only hex digits may be lower case.
    s.tell_raw(b"/1p");
    s.tell_raw(b"/7r040001");
    insta::assert_snapshot!(s.transcript);
}

#[test]
fn every_answer_ends_with_a_carriage_return() {
    let mut s = Session::new();
    for question in [
        "/1B",
        "/1S",
        "/1E",
        "/1G",
        "/1T",
        "/1M",
        "/1X",
        "/7R000004",
        "/1C",
        "/1D",
        "/1P",
    ] {
        let answer = s.ask(question);
        assert!(answer.ends_with('\r'), "{question}: {answer:?}");
        assert_eq!(answer.matches('\r').count(), 1, "{question}: {answer:?}");
    }
}
