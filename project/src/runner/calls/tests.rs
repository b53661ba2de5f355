//! Issue 23's fuzz target for `.calls` files, and what it found: whatever
//! the text, parsing ends with the calls or an error naming a line, never
//! a panic; well-formed lines, blanks anywhere a blank may be, parse to
//! what they say; counts and extents are bounded with a clear error.

use std::collections::HashMap;

use proptest::prelude::*;

use super::*;

fn symbols() -> HashMap<String, u16> {
    HashMap::from([("double".to_owned(), 0x0400), ("buffer".to_owned(), 0x0480)])
}

#[test]
fn blanks_after_call_are_blanks() {
    for text in [
        "call  double A=$21 => A=$42",
        "call\tdouble A=$21 => A=$42",
        "call double  A=$21 => A=$42",
    ] {
        let calls = parse(text, &symbols()).unwrap_or_else(|e| panic!("{text:?}: {e}"));
        assert_eq!(calls[0].address, 0x0400, "{text:?}");
        assert_eq!(calls[0].set_regs, vec![(Reg::A, 0x21)], "{text:?}");
        assert_eq!(calls[0].want_regs, vec![(Reg::A, 0x42)], "{text:?}");
    }
    assert!(parse("calldouble", &symbols()).is_err());
}

#[test]
fn a_within_of_hours_is_refused() {
    let error = parse("call double => A=0 within 4000000000 cycles", &symbols())
        .expect_err("over a minute of robot time");
    assert!(error.contains("at most 60000000 cycles"), "{error}");
    parse("call double => A=0 within 60000000 cycles", &symbols()).expect("a minute");
}

#[test]
fn bytes_that_run_past_the_address_space_are_refused() {
    let error = parse("call double $FFFF=01 02", &symbols()).expect_err("past $FFFF");
    assert!(
        error.contains("2 bytes from $FFFF run past $FFFF"),
        "{error}"
    );
    parse("call double $FFFF=01", &symbols()).expect("the last byte");
}

/// Pieces a calls file is made of, and pieces that break one.
const PIECES: &[&str] = &[
    "call",
    "call ",
    "double",
    "buffer",
    "nowhere",
    "=>",
    "A=",
    "X=$",
    "C=1",
    "$FFFF",
    "$10000",
    "=",
    "FF",
    "00 01",
    "within",
    "cycles",
    "4294967295",
    "99999999999",
    "#",
    " ",
    "\t",
    "\n",
    "é",
];

fn soup() -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop_oneof![
            4 => prop::sample::select(PIECES).prop_map(str::to_owned),
            1 => any::<String>(),
        ],
        0..40,
    )
    .prop_map(|pieces| pieces.concat())
}

/// A well-formed line and what it says: the registers set and wanted,
/// bytes set at `buffer`, `within` if any.
type Line = (String, Vec<(Reg, u8)>, Vec<u8>, Vec<(Reg, u8)>, Option<u64>);

fn line() -> impl Strategy<Value = Line> {
    let reg = prop::sample::select(vec![
        (Reg::A, "A"),
        (Reg::X, "x"),
        (Reg::Y, "Y"),
        (Reg::C, "C"),
    ]);
    let regs = prop::collection::vec((reg, any::<u8>()), 0..4);
    let blank = prop::sample::select(vec![" ", "  ", "\t", " \t "]);
    (
        regs.clone(),
        prop::collection::vec(any::<u8>(), 0..4),
        regs,
        prop::option::of(0..MAX_WITHIN),
        blank,
        prop::bool::ANY,
    )
        .prop_map(|(set, bytes, want, within, blank, comment)| {
            let value = |(_, name): (Reg, &str), v: u8| match name {
                "C" => format!("{name}={}", v & 1),
                _ => format!("{name}=${v:02X}"),
            };
            let said = |regs: &[((Reg, &str), u8)]| {
                regs.iter()
                    .map(|&(r, v)| value(r, v))
                    .collect::<Vec<_>>()
                    .join(blank)
            };
            let mut text = format!("call{blank}double{blank}{}", said(&set));
            if !bytes.is_empty() {
                let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02X}")).collect();
                text.push_str(&format!("{blank}buffer={}", hex.join(blank)));
            }
            text.push_str(&format!("{blank}=>{blank}{}", said(&want)));
            if let Some(cycles) = within {
                text.push_str(&format!("{blank}within {cycles} cycles"));
            }
            if comment {
                text.push_str(" # A=$00 => nothing");
            }
            let flag = |((r, name), v): ((Reg, &str), u8)| (r, if name == "C" { v & 1 } else { v });
            (
                text,
                set.into_iter().map(flag).collect(),
                bytes,
                want.into_iter().map(flag).collect(),
                within,
            )
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn any_text_parses_or_names_a_line(text in soup()) {
        match parse(&text, &symbols()) {
            Ok(calls) => {
                for call in calls {
                    prop_assert!(call.line >= 1 && call.line <= text.lines().count());
                    prop_assert!(call.within.is_none_or(|w| w <= MAX_WITHIN));
                }
            }
            Err(error) => prop_assert!(!error.is_empty()),
        }
    }

    #[test]
    fn well_formed_lines_parse_to_what_they_say(lines in prop::collection::vec(line(), 1..10)) {
        let text: String = lines.iter().map(|line| format!("{}\n", line.0)).collect();
        let calls = parse(&text, &symbols()).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(calls.len(), lines.len());
        for (index, (call, (_, set, bytes, want, within))) in calls.iter().zip(&lines).enumerate() {
            prop_assert_eq!(call.line, index + 1);
            prop_assert_eq!(call.address, 0x0400);
            prop_assert_eq!(&call.set_regs, set);
            prop_assert_eq!(&call.want_regs, want);
            let set_mem: Vec<(u16, Vec<u8>)> = if bytes.is_empty() {
                Vec::new()
            } else {
                vec![(0x0480, bytes.clone())]
            };
            prop_assert_eq!(&call.set_mem, &set_mem);
            prop_assert_eq!(call.within, *within);
        }
    }
}
