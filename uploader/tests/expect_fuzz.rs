//! Issue 23's fuzz target for transcripts (`.expect` files): whatever the
//! text, parsing ends with the lines or an error naming a line that
//! exists, never a panic; and well-formed lines, spaced and commented any
//! way, parse to the commands and answers they say. Short runs: CI takes
//! a few seconds.

use proptest::prelude::*;
use uploader::{Expectations, Required};

/// Pieces a transcript is made of, and pieces that break one.
const PIECES: &[&str] = &[
    "/1X",
    "/1P",
    "/2E3",
    "/9W10000102",
    "/1Q",
    "/7R020102",
    "=>",
    "*",
    "nothing",
    "X00",
    "E3",
    "within",
    "2ms",
    "500us",
    "3000 cycles",
    "18446744073709551615ms",
    "99999999999999999999999ms",
    "#",
    "# comment",
    " ",
    "\t",
    "\n",
    "\r\n",
    "/",
    "/0",
    "/9",
    "é",
    "\u{0}",
    "=> =>",
    "within within",
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

/// A well-formed line: a question and its exact answer, `*`, or an
/// instruction; `within` sometimes; blanks and a comment anywhere they may be.
fn line() -> impl Strategy<Value = (String, &'static str, Option<&'static str>)> {
    let question = prop::sample::select(vec![("/1X", "X00"), ("/1E", "E0"), ("/1G", "G0")]);
    (
        question,
        0..3u8,
        prop::sample::select(vec!["", " ", "   ", "\t"]),
        prop::bool::ANY,
        prop::bool::ANY,
    )
        .prop_map(|((command, answer), shape, blank, within, comment)| {
            let (text, wanted) = match shape {
                0 => (format!("{command}{blank}=>{blank}{answer}"), Some(answer)),
                1 => (format!("{command}{blank}=> *"), None),
                _ => ("/2E3".to_owned(), None),
            };
            let text = if within && shape < 2 {
                format!("{text} within 2ms")
            } else {
                text
            };
            let text = if comment {
                format!("{blank}{text}{blank}# note => X99")
            } else {
                format!("{blank}{text}")
            };
            let command = if shape < 2 { command } else { "/2E3" };
            (text, command, wanted)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn any_text_parses_or_names_a_line_that_exists(text in soup()) {
        match Expectations::parse(&text) {
            Ok(parsed) => {
                let count = text.lines().count();
                for line in &parsed.lines {
                    prop_assert!(line.line >= 1 && line.line <= count);
                }
            }
            Err(error) => {
                let shown = error.to_string();
                prop_assert!(!shown.is_empty());
            }
        }
    }

    #[test]
    fn well_formed_lines_parse_to_what_they_say(
        lines in prop::collection::vec(line(), 1..20),
        blank_lines in prop::collection::vec(prop::bool::ANY, 20),
    ) {
        let mut text = String::new();
        let mut numbers = Vec::new();
        for (index, (line, _, _)) in lines.iter().enumerate() {
            if blank_lines[index] {
                text.push_str("   # only a comment\n");
            }
            text.push_str(line);
            text.push('\n');
            numbers.push(text.lines().count());
        }
        let parsed = Expectations::parse(&text)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(parsed.lines.len(), lines.len());
        for ((got, (_, command, wanted)), number) in parsed.lines.iter().zip(&lines).zip(&numbers) {
            prop_assert_eq!(got.line, *number);
            prop_assert_eq!(got.command.to_string(), *command);
            if let Some(answer) = wanted {
                prop_assert_eq!(&got.required, &Required::Exactly((*answer).to_owned()));
            }
        }
    }
}
