//! Cards and surroundings against the board, without the ROM.

use emulator::board::Device;

use crate::{ScriptCard, ScriptError};

const ECHO: &str = r#"
const SIZE = 2;
const BASE = 0x9000;
const STEP = 3;
fn init() { this.count = 0; }
fn read(reg, now) { this.count += global::STEP; this.count & 0xFF }
"#;

#[test]
fn state_lives_in_this_and_constants_in_global() {
    let mut card = ScriptCard::load("echo.rhai", ECHO, None).expect("loads");
    assert_eq!(card.window(), (0x9000, 0x9001));
    assert_eq!(card.read(0, 10), 3);
    assert_eq!(card.read(1, 20), 6);
}

#[test]
fn a_syntax_error_is_located() {
    let error = ScriptCard::load(
        "bad.rhai",
        "const SIZE = 1;\nfn read(reg, now) { reg + }\n",
        None,
    )
    .expect_err("refused");
    let ScriptError::Script(located) = &error else {
        panic!("{error:?}")
    };
    assert_eq!((located.line, located.column), (2, 27), "{error}");
}
