//! Loading a script grows linearly with its length (issue 23, 6: 25,000
//! lines took 1.0 s and 100,000 lines 18.9 s, Rhai's optimizer removing
//! statements one at a time and its compiler looking every name up through
//! every variable declared). Measured as a ratio of two sizes' times in
//! the same run, never as an absolute time.

use std::time::{Duration, Instant};

use cards::ScriptCard;

/// A script of about `lines` lines of what makes loading slow when it is
/// quadratic: statements in one block (the top level, a function's body),
/// declarations, functions.
fn script(lines: usize) -> String {
    let mut text = String::from("const SIZE = 1;\nconst BASE = 0x9000;\nfn read(reg, now) { 0 }\n");
    let mut i = 0;
    // Three lines above, eight a round.
    while 3 + 8 * i < lines {
        text.push_str(&format!(
            "fn f{i}(a) {{\n    let b = a + {i};\n    let c = b * 2;\n    c - a\n}}\n{i};\nlet v = {i};\n// a comment\n"
        ));
        i += 1;
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
    let (small, large) = (load_time(&small), load_time(&large));
    let ratio = large.as_secs_f64() / small.as_secs_f64();
    // Four times the lines: about 4 when linear, 16 when quadratic.
    assert!(
        ratio < 8.0,
        "100k lines took {large:?}, 25k lines {small:?}: {ratio:.1} times"
    );
}
