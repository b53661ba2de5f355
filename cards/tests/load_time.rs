//! Loading a script grows linearly with its length (issue 23, 6: 25,000
//! lines took 1.0 s and 100,000 lines 18.9 s: Rhai's optimizer removed
//! statements one at a time, and its compiler looks every name up through
//! every variable in sight and every function defined so far). Measured
//! as a ratio of two sizes' times in the same run, never as an absolute
//! time.

#![allow(clippy::print_stdout, reason = "the figures, for the record")]

use std::time::{Duration, Instant};

use cards::{MAX_FUNCTIONS, ScriptCard};

/// A script of `lines` lines of what made loading quadratic: many
/// statements in one block, many names used, the most functions a script
/// may have, declarations.
fn script(lines: usize) -> String {
    let mut text = String::from("const SIZE = 1;\nconst BASE = 0x9000;\n");
    let functions = MAX_FUNCTIONS - 1;
    // Three quarters of the lines in functions, a quarter at the top level.
    let per_function = lines * 3 / 4 / functions;
    for f in 0..functions {
        text.push_str(&format!("fn f{f}(a) {{\n    let b = a;\n"));
        for i in 0..per_function.saturating_sub(4) / 4 {
            text.push_str(&format!(
                "    let c = b + {i};\n    b = c * 2 - a;\n    {i};\n    // {i}\n"
            ));
        }
        text.push_str("    b\n}\n");
    }
    text.push_str("fn read(reg, now) { f0(reg) & 0xFF }\nlet v = 0;\n");
    for i in 0..lines / 4 / 2 {
        text.push_str(&format!("{i};\nv = {i};\n"));
    }
    text
}

/// The shortest of three loads of `text`.
fn load_time(text: &str) -> Duration {
    (0..3)
        .map(|_| {
            let start = Instant::now();
            let card = ScriptCard::load("long.rhai", text, None);
            let took = start.elapsed();
            assert!(card.is_ok(), "{:?}", card.err());
            took
        })
        .min()
        .expect("three runs")
}

#[test]
fn loading_grows_linearly_with_the_script() {
    let (small, large) = (script(25_000), script(100_000));
    assert!(large.lines().count() >= 99_000, "{}", large.lines().count());
    let (small, large) = (load_time(&small), load_time(&large));
    let ratio = large.as_secs_f64() / small.as_secs_f64();
    println!("100k lines {large:?}, 25k lines {small:?}: {ratio:.2} times");
    // Four times the lines: about 4 when linear, 16 when quadratic.
    assert!(
        ratio < 8.0,
        "100k lines took {large:?}, 25k lines {small:?}: {ratio:.1} times"
    );
}
