//! Exact encodings from docs/PROTOCOL.md, every malformed-answer path, and
//! proptest round trips of every command and answer form.

use proptest::prelude::*;

use super::answer::MoveCount;
use super::*;

fn cmd(text: &str) -> Command {
    text.parse()
        .unwrap_or_else(|error| panic!("{text}: {error}"))
}

#[test]
fn commands_encode_exactly() {
    let cases: Vec<(Command, &str)> = vec![
        (Command::Reset, "/1R"),
        (Command::SetIo(0x5A), "/3Y5A"),
        (Command::SetObeyMask(0x7F), "/3Z7F"),
        (
            Command::Move {
                motor: Motor::Left,
                direction: Direction::Plus,
                speed: Speed::new(50).unwrap(),
                steps: Steps::new(1000).unwrap(),
            },
            "/8C+501000",
        ),
        (
            Command::Move {
                motor: Motor::Right,
                direction: Direction::Minus,
                speed: Speed::new(5).unwrap(),
                steps: Steps::new(7).unwrap(),
            },
            "/8D-050007",
        ),
        (
            Command::Continuous {
                motor: Motor::Right,
                direction: Direction::Plus,
                speed: Speed::new(0).unwrap(),
            },
            "/4D+00",
        ),
        (
            Command::SetEyes(Pair {
                left: true,
                right: false,
            }),
            "/2E2",
        ),
        (Command::SetLamps(true), "/2G1"),
        (Command::Tone(0x0C), "/3K0C"),
        (
            Command::Scan {
                axis: Axis::Vertical,
                steps: ScanSteps::new(15).unwrap(),
            },
            "/3V15",
        ),
        (
            Command::WriteByte {
                address: 0x0400,
                value: 0xEA,
            },
            "/7W0400EA",
        ),
        (
            Command::WriteWord(WordWrite::new(0x0201, [0x34, 0x12]).unwrap()),
            "/9W02013412",
        ),
        (Command::Bumpers, "/1B"),
        (Command::Scanner, "/1S"),
        (Command::Eyes, "/1E"),
        (Command::Lamps, "/1G"),
        (Command::Tracker, "/1T"),
        (Command::Moves, "/1M"),
        (Command::Busy, "/1X"),
        (
            Command::ReadMemory(ReadSpan::new(0x0200, 10).unwrap()),
            "/7R020010",
        ),
        (Command::Remaining(Motor::Left), "/1C"),
        (Command::Remaining(Motor::Right), "/1D"),
        (Command::Everything, "/1P"),
        (Command::Extension(Extension::new(*b"Q").unwrap()), "/1Q"),
        (
            Command::Extension(Extension::new(*b"LAB12").unwrap()),
            "/5LAB12",
        ),
    ];
    for (command, text) in cases {
        assert_eq!(command.to_string(), text);
        assert_eq!(cmd(text), command, "{text}");
    }
}

#[test]
fn ranges_are_checked() {
    assert!(matches!(
        Speed::new(100),
        Err(ProtocolError::OutOfRange {
            what: "speed",
            value: 100,
            ..
        })
    ));
    assert!(Steps::new(10_000).is_err());
    assert!(ScanSteps::new(0).is_err());
    assert!(ScanSteps::new(100).is_err());
    assert!(ReadSpan::new(0, 100).is_err());
    assert!(ReadSpan::new(0xFF9D, 99).is_ok());
    assert_eq!(
        ReadSpan::new(0xFF9E, 99),
        Err(ProtocolError::ReadWraps {
            address: 0xFF9E,
            count: 99
        })
    );
    assert!(ReadSpan::new(0xFFFF, 1).is_ok());
    assert!(WordWrite::new(0xFFFE, [1, 2]).is_ok());
    assert!(WordWrite::new(0xFFFF, [1, 2]).is_err());
    assert!(Extension::new(*b"").is_err());
    assert!(Extension::new(*b"ABCDEFGHIJ").is_err());
    assert!(Extension::new(*b"A/B").is_err());
    assert!(Extension::new(*b"A\rB").is_err());
    // The ROM's own (count, letter) pairs are not extensions.
    let error = Extension::new(*b"P").unwrap_err();
    assert!(
        error.to_string().contains("/1P is a ROM command"),
        "{error}"
    );
    assert!(Extension::new(*b"RXXXXXX").is_err());
    // Same letter, other count: the ROM does not dispatch on it.
    assert!(Extension::new(*b"PP").is_ok());
}

#[test]
fn command_parser_names_the_character() {
    let error = Command::parse(b"/7R02G010").unwrap_err();
    assert_eq!(
        error,
        ProtocolError::BadCommand {
            text: "/7R02G010".into(),
            position: 5,
            expected: "a hex digit".into(),
            found: "`G`".into(),
        }
    );
    let error = Command::parse(b"/8C+50100").unwrap_err();
    assert!(
        matches!(&error, ProtocolError::BadCommand { position: 9, .. }),
        "{error:?}"
    );
    let error = Command::parse(b"/8C*501000").unwrap_err();
    assert!(
        matches!(&error, ProtocolError::BadCommand { position: 3, expected, .. } if expected.contains("direction")),
        "{error:?}"
    );
    assert!(Command::parse(b"").is_err());
    assert!(Command::parse(b"1R").is_err());
    assert!(Command::parse(b"/0").is_err());
    assert!(Command::parse(b"/3H00").is_err());
    assert!(Command::parse(b"/7RFFFF02").is_err());
    assert!(Command::parse(b"/9WFFFF0102").is_err());
    // Lower-case hex is accepted on input, as by the ROM.
    assert_eq!(
        cmd("/7w04000a"),
        Command::Extension(Extension::new(*b"w04000a").unwrap())
    );
    assert_eq!(
        cmd("/7W04ff0a"),
        Command::WriteByte {
            address: 0x04FF,
            value: 0x0A
        }
    );
}

#[test]
fn answers_parse_every_form() {
    assert_eq!(Answer::parse(b"B81\r"), Ok(Answer::Bumpers(Bumpers(0x81))));
    assert_eq!(
        Answer::parse(b"SH00FF7F\r"),
        Ok(Answer::Scan(ScanAnswer {
            axis: Axis::Horizontal,
            data: vec![0, 0xFF, 0x7F]
        }))
    );
    assert_eq!(
        Answer::parse(b"E1\r"),
        Ok(Answer::Eyes(Pair {
            left: false,
            right: true
        }))
    );
    assert_eq!(Answer::parse(b"G0\r"), Ok(Answer::Lamps(false)));
    assert_eq!(
        Answer::parse(b"T3\r"),
        Ok(Answer::Tracker(Pair {
            left: true,
            right: true
        }))
    );
    let moves = MoveCounts {
        left: MoveCount {
            direction: Direction::Plus,
            steps: Steps::new(120).unwrap(),
        },
        right: MoveCount {
            direction: Direction::Minus,
            steps: Steps::new(9999).unwrap(),
        },
    };
    assert_eq!(Answer::parse(b"M+0120-9999\r"), Ok(Answer::Moves(moves)));
    assert_eq!(Answer::parse(b"M+0120 -9999\r"), Ok(Answer::Moves(moves)));
    assert_eq!(Answer::parse(b"XA0\r"), Ok(Answer::Busy(BusyByte(0xA0))));
    assert_eq!(Answer::parse(b"R\r"), Ok(Answer::Memory(vec![])));
    assert_eq!(
        Answer::parse(b"R4C0002\r"),
        Ok(Answer::Memory(vec![0x4C, 0x00, 0x02]))
    );
    assert_eq!(
        Answer::parse(b"C0042\r"),
        Ok(Answer::Remaining {
            motor: Motor::Left,
            steps: Steps::new(42).unwrap()
        })
    );
    assert_eq!(
        Answer::parse(b"D0000\r"),
        Ok(Answer::Remaining {
            motor: Motor::Right,
            steps: Steps::new(0).unwrap()
        })
    );
    let text = b"PB00E0G1T2M+0000-0003Y80XA4C0010D0000\r";
    let Ok(Answer::Everything(status)) = Answer::parse(text) else {
        panic!("{:?}", Answer::parse(text));
    };
    assert_eq!(status.io, 0x80);
    assert!(status.lamps);
    assert_eq!(status.tracker, Pair::from_digit(2));
    assert_eq!(status.busy, BusyByte(0xA4));
    assert!(status.busy.has(BusyByte::LAMPS | BusyByte::LEFT_MOTOR));
    assert_eq!(status.moves.right.steps.get(), 3);
    assert_eq!(status.left_remaining.get(), 10);
    assert_eq!(Answer::Everything(status).encode(), text.to_vec());
    assert!(Answer::parse(b"PB00E0G1T2M+0000 -0003Y80XA4C0010D0000\r").is_ok());
    assert_eq!(
        Command::Everything.answer_len(),
        Some(text.len()),
        "the /1P answer length"
    );
}

#[test]
fn malformed_answers_name_what_and_where() {
    let error = Answer::parse(b"R4C0G02\r").unwrap_err();
    assert_eq!(
        error,
        ProtocolError::MalformedAnswer {
            form: "/7R",
            text: "R4C0G02\\r".into(),
            position: 4,
            expected: "an upper-case hex digit".into(),
            found: "`G`".into(),
        }
    );
    assert!(error.to_string().contains("character 4"), "{error}");
    // An odd number of hex digits.
    let error = Answer::parse(b"R4C0\r").unwrap_err();
    assert!(
        matches!(error, ProtocolError::MalformedAnswer { position: 4, .. }),
        "{error:?}"
    );
    // Lower case is never sent by the ROM.
    assert!(Answer::parse(b"Bab\r").is_err());
    // No carriage return, or something after it.
    let error = Answer::parse(b"E1").unwrap_err();
    assert!(
        matches!(&error, ProtocolError::MalformedAnswer { position: 2, expected, found, .. }
            if expected.contains("carriage return") && found == "end of answer"),
        "{error:?}"
    );
    assert!(Answer::parse(b"E1\rX").is_err());
    assert!(Answer::parse(b"E4\r").is_err());
    assert!(Answer::parse(b"G2\r").is_err());
    assert!(Answer::parse(b"M+0120+999\r").is_err());
    assert!(Answer::parse(b"M+0120  -9999\r").is_err());
    assert!(Answer::parse(b"SH\r").is_err());
    assert!(Answer::parse(b"SX00\r").is_err());
    let mut long = b"R".to_vec();
    long.extend(std::iter::repeat_n(b'0', 200));
    long.push(b'\r');
    assert!(
        Answer::parse(&long).is_err(),
        "100 bytes is more than /7R reads"
    );
    let error = Answer::parse(b"Q12\r").unwrap_err();
    assert!(
        matches!(
            &error,
            ProtocolError::MalformedAnswer {
                form: "an",
                position: 0,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(Answer::parse(b"").is_err());
    assert!(Answer::parse(b"PB00E0G1T2M+0000-0003Y80XA4C0010\r").is_err());
}

#[test]
fn answers_match_their_questions() {
    let read = Command::ReadMemory(ReadSpan::new(0x0200, 3).unwrap());
    assert_eq!(
        read.parse_answer(b"R4C0002\r"),
        Ok(Answer::Memory(vec![0x4C, 0, 2]))
    );
    let error = read.parse_answer(b"R4C00\r").unwrap_err();
    assert!(
        matches!(&error, ProtocolError::UnexpectedAnswer { expected, .. } if expected.contains("3 bytes")),
        "{error:?}"
    );
    assert!(Command::Busy.parse_answer(b"B00\r").is_err());
    assert!(
        Command::Remaining(Motor::Left)
            .parse_answer(b"D0001\r")
            .is_err()
    );
    assert!(
        Command::Remaining(Motor::Right)
            .parse_answer(b"D0001\r")
            .is_ok()
    );
    assert!(matches!(
        Command::Reset.parse_answer(b"R\r"),
        Err(ProtocolError::NoAnswerExpected { .. })
    ));
    let extension = Command::Extension(Extension::new(*b"Q").unwrap());
    assert_eq!(
        extension.parse_answer(b"QHELLO 1\r"),
        Ok(Answer::Text("QHELLO 1".into()))
    );
    assert!(extension.parse_answer(b"Q\x07\r").is_err());
    assert!(extension.parse_answer(b"Q").is_err());
    for (command, answer) in [
        (Command::Busy, "X00\r"),
        (Command::Eyes, "E0\r"),
        (Command::Moves, "M+0000-0000\r"),
        (Command::Remaining(Motor::Left), "C0000\r"),
        (read, "R000000\r"),
    ] {
        assert_eq!(command.answer_len(), Some(answer.len()), "{command}");
    }
}

fn motor() -> impl Strategy<Value = Motor> {
    prop_oneof![Just(Motor::Left), Just(Motor::Right)]
}

fn direction() -> impl Strategy<Value = Direction> {
    prop_oneof![Just(Direction::Plus), Just(Direction::Minus)]
}

fn pair() -> impl Strategy<Value = Pair> {
    (0u8..4).prop_map(Pair::from_digit)
}

fn steps() -> impl Strategy<Value = Steps> {
    (0u16..=9999).prop_map(|value| Steps::new(value).expect("in range"))
}

fn extension() -> impl Strategy<Value = Extension> {
    proptest::collection::vec(0x20u8..0x7F, 1..=9)
        .prop_filter_map("not sendable", |bytes| Extension::new(bytes).ok())
}

fn command() -> impl Strategy<Value = Command> {
    let speed = (0u8..=99).prop_map(|value| Speed::new(value).expect("in range"));
    prop_oneof![
        Just(Command::Reset),
        any::<u8>().prop_map(Command::SetIo),
        any::<u8>().prop_map(Command::SetObeyMask),
        (motor(), direction(), speed.clone(), steps()).prop_map(
            |(motor, direction, speed, steps)| Command::Move {
                motor,
                direction,
                speed,
                steps
            }
        ),
        (motor(), direction(), speed).prop_map(|(motor, direction, speed)| {
            Command::Continuous {
                motor,
                direction,
                speed,
            }
        }),
        pair().prop_map(Command::SetEyes),
        any::<bool>().prop_map(Command::SetLamps),
        any::<u8>().prop_map(Command::Tone),
        (any::<bool>(), 1u8..=99).prop_map(|(h, steps)| Command::Scan {
            axis: if h { Axis::Horizontal } else { Axis::Vertical },
            steps: ScanSteps::new(steps).expect("in range"),
        }),
        (any::<u16>(), any::<u8>())
            .prop_map(|(address, value)| Command::WriteByte { address, value }),
        (0u16..0xFFFF, any::<[u8; 2]>()).prop_map(|(address, bytes)| {
            Command::WriteWord(WordWrite::new(address, bytes).expect("in range"))
        }),
        Just(Command::Bumpers),
        Just(Command::Scanner),
        Just(Command::Eyes),
        Just(Command::Lamps),
        Just(Command::Tracker),
        Just(Command::Moves),
        Just(Command::Busy),
        (any::<u16>(), 0u8..=99).prop_filter_map("wraps", |(address, count)| {
            ReadSpan::new(address, count).ok().map(Command::ReadMemory)
        }),
        motor().prop_map(Command::Remaining),
        Just(Command::Everything),
        extension().prop_map(Command::Extension),
    ]
}

fn move_counts() -> impl Strategy<Value = MoveCounts> {
    (direction(), steps(), direction(), steps()).prop_map(|(ld, ls, rd, rs)| MoveCounts {
        left: MoveCount {
            direction: ld,
            steps: ls,
        },
        right: MoveCount {
            direction: rd,
            steps: rs,
        },
    })
}

fn answer() -> impl Strategy<Value = Answer> {
    prop_oneof![
        any::<u8>().prop_map(|b| Answer::Bumpers(Bumpers(b))),
        (
            any::<bool>(),
            proptest::collection::vec(any::<u8>(), 1..=199)
        )
            .prop_map(|(h, data)| {
                Answer::Scan(ScanAnswer {
                    axis: if h { Axis::Horizontal } else { Axis::Vertical },
                    data,
                })
            }),
        pair().prop_map(Answer::Eyes),
        any::<bool>().prop_map(Answer::Lamps),
        pair().prop_map(Answer::Tracker),
        move_counts().prop_map(Answer::Moves),
        any::<u8>().prop_map(|b| Answer::Busy(BusyByte(b))),
        proptest::collection::vec(any::<u8>(), 0..=99).prop_map(Answer::Memory),
        (motor(), steps()).prop_map(|(motor, steps)| Answer::Remaining { motor, steps }),
        (
            any::<u8>(),
            pair(),
            any::<bool>(),
            pair(),
            move_counts(),
            any::<u8>(),
            any::<u8>(),
            steps(),
            steps()
        )
            .prop_map(|(b, eyes, lamps, tracker, moves, io, busy, lr, rr)| {
                Answer::Everything(Status {
                    bumpers: Bumpers(b),
                    eyes,
                    lamps,
                    tracker,
                    moves,
                    io,
                    busy: BusyByte(busy),
                    left_remaining: lr,
                    right_remaining: rr,
                })
            }),
    ]
}

proptest! {
    #[test]
    fn command_round_trip(command in command()) {
        let bytes = command.encode();
        prop_assert!(bytes.len() >= 3 && bytes.len() <= 11);
        prop_assert_eq!(usize::from(bytes[1] - b'0'), bytes.len() - 2);
        prop_assert_eq!(Command::parse(&bytes), Ok(command));
    }

    #[test]
    fn answer_round_trip(answer in answer()) {
        let bytes = answer.encode();
        prop_assert_eq!(bytes.last(), Some(&EOL));
        prop_assert_eq!(Answer::parse(&bytes), Ok(answer));
    }

    #[test]
    fn questions_accept_their_own_answers(command in command()) {
        // The answer a question fixes the length of has exactly that length.
        if let (Some(len), Command::ReadMemory(span)) = (command.answer_len(), &command) {
            let answer = Answer::Memory(vec![0xA5; usize::from(span.count())]).encode();
            prop_assert_eq!(answer.len(), len);
            prop_assert!(command.parse_answer(&answer).is_ok());
        }
    }

    #[test]
    fn parsers_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
        let _ = Command::parse(&bytes);
        let _ = Answer::parse(&bytes);
        let _ = Answer::parse_text(&bytes);
    }

    #[test]
    fn one_corrupted_byte_never_parses_as_the_same_answer(
        data in proptest::collection::vec(any::<u8>(), 1..=99),
        index in any::<prop::sample::Index>(),
        noise in any::<u8>(),
    ) {
        // A changed character either fails to parse or changes the data:
        // the uploader relies on this to never take noise for a verified byte.
        let answer = Answer::Memory(data);
        let mut bytes = answer.encode();
        let at = index.index(bytes.len());
        prop_assume!(bytes[at] != noise);
        bytes[at] = noise;
        prop_assert_ne!(Answer::parse(&bytes), Ok(answer));
    }
}
