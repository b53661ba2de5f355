//! Hostile command lines for the monitor (issue 23): any line, made of the
//! monitor's own verbs and the numbers, addresses and words a careless or
//! hostile user types, is answered (text or an error) on the ADC example;
//! never a panic, and never a run or an output beyond the bounds
//! (`debugger::monitor`'s counts).

use std::cell::RefCell;
use std::path::Path;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

use debugger::monitor::{Monitor, Reply};
use debugger::sources::Sources;

use super::{Args, recipe};

/// Numbers as typed: small, at and around the bounds of u32 and u64,
/// negative, in other bases, not numbers. (Numbers between a bound's tenth
/// and the bound are left out: each would be a valid run of seconds.)
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        (0u64..300).prop_map(|n| n.to_string()),
        Just("4294967296".to_owned()),
        Just("18446744073709551615".to_owned()),
        Just("18446744073709551616".to_owned()),
        Just("99999999999999999999999999".to_owned()),
        Just("100000000".to_owned()),
        Just("65537".to_owned()),
        Just("-1".to_owned()),
        Just("+3".to_owned()),
        Just("$FFFF".to_owned()),
        Just("0x10".to_owned()),
        Just("1e9".to_owned()),
        "[a-z]{1,6}",
    ]
}

/// Addresses as typed: numbers, labels, sums, ranges, source lines.
fn address() -> impl Strategy<Value = String> {
    prop_oneof![
        number(),
        Just("read_channel".to_owned()),
        Just("read_channel+$B".to_owned()),
        Just("CMDBUF+1".to_owned()),
        Just("$FFF0..$0010".to_owned()),
        Just("$20..$10".to_owned()),
        Just("adc.s:43".to_owned()),
        Just("adc.s:99999999999".to_owned()),
        Just("adc.s:4294967295".to_owned()),
        Just(":4".to_owned()),
        Just("$10000".to_owned()),
        Just("%".to_owned()),
        Just("+".to_owned()),
        "\\PC{0,12}",
    ]
}

fn line() -> impl Strategy<Value = String> {
    let verb = prop::sample::select(vec![
        "mem",
        "m",
        "dis",
        "d",
        "step",
        "s",
        "continue",
        "c",
        "back",
        "bs",
        "next",
        "finish",
        "break",
        "b",
        "watch",
        "w",
        "delete",
        "info",
        "regs",
        "list",
        "l",
        "who-wrote",
        "reverse-continue",
        "rc",
        "bumpers",
        "send",
        "/1X",
        "/2A1",
        "trace",
        "help",
        "frob",
        "set",
        "poke",
        "print",
        "display",
        "undisplay",
        "until",
        "bt",
        "break read_channel if",
        "break read_channel hits",
        "break read_channel log",
    ]);
    let word = prop_oneof![
        number(),
        address(),
        Just("read".to_owned()),
        Just("write".to_owned()),
        Just("watch".to_owned()),
        Just("unknown".to_owned()),
        Just("off".to_owned()),
        Just("/dev/full".to_owned()),
        Just("/nonexistent/dir/trace.txt".to_owned()),
        Just("/9Z".to_owned()),
        Just("A".to_owned()),
        Just("PC".to_owned()),
        Just("=".to_owned()),
        Just("[CMDBUF]".to_owned()),
        Just("{A}".to_owned()),
        Just("((((".to_owned()),
        Just("A==1&&".to_owned()),
        Just("1/0".to_owned()),
        Just(">=".to_owned()),
        Just("%".to_owned()),
    ];
    (verb, prop::collection::vec(word, 0..4)).prop_map(|(verb, words)| {
        if verb == "trace" {
            // Only where a trace can do no harm: no file made here.
            let to = ["/dev/full", "/dev/null", "off", "/nonexistent/dir/t"];
            return format!("trace {}", to[words.len() % to.len()]);
        }
        let mut line = verb.to_owned();
        for word in words {
            line.push(' ');
            line.push_str(&word);
        }
        line
    })
}

#[test]
fn any_command_line_is_answered_within_its_bounds() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let args = Args {
        baud: None,
        ..Args::default()
    };
    let (make, images, root) = recipe(&args, &adc).expect("the ADC example builds");
    let session = RefCell::new((
        debugger::Debugger::new(make, &images).expect("the robot builds"),
        Monitor::new(Sources::new(root)),
    ));
    let mut runner = TestRunner::new(Config::with_cases(400));
    let outcome = runner.run(&line(), |line| {
        let mut session = session.borrow_mut();
        let (debugger, monitor) = &mut *session;
        if let Ok(Reply::Text(text)) = monitor.command(debugger, &line) {
            // Output bounded: a whole address space's dump or listing.
            prop_assert!(text.len() < 8 << 20, "{line}: {} bytes", text.len());
        }
        Ok(())
    });
    if let Err(failure) = outcome {
        panic!("{failure}");
    }
}
