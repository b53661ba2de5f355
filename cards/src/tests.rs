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

#[test]
fn scripts_reach_no_file_and_no_eval() {
    for (text, what) in [
        (
            "import \"secrets\" as s;\nconst SIZE = 1;\nconst BASE = 0x9000;\n",
            "import",
        ),
        (
            "const SIZE = 1;\nconst BASE = 0x9000;\nfn read(reg, now) { eval(\"1\") }\n",
            "eval",
        ),
    ] {
        let loaded = ScriptCard::load("sandbox.rhai", text, None);
        let failed = match loaded {
            Err(error) => Some(error.to_string()),
            Ok(mut card) => {
                let _ = card.read(0, 1);
                card.take_fault().map(|fault| fault.to_string())
            }
        };
        assert!(failed.is_some(), "{what} must fail");
    }
}

#[test]
fn recursion_without_end_is_stopped_and_located() {
    let text = "const SIZE = 1;\nconst BASE = 0x9000;\nfn deeper(n) { deeper(n + 1) }\nfn read(reg, now) { deeper(0) }\n";
    let mut card = ScriptCard::load("deep.rhai", text, None).expect("loads");
    assert_eq!(card.read(0, 1), 0xFF, "a failed card reads $FF");
    let fault = card.take_fault().expect("a fault").to_string();
    // Rhai gives no place for an overflow: the function called is named.
    assert_eq!(fault, "deep.rhai:4:1: Stack overflow");
    assert!(card.take_fault().is_none(), "taken once");
}

#[test]
fn a_read_that_returns_no_byte_is_a_located_fault() {
    let text = "const SIZE = 1;\nconst BASE = 0x9000;\n\nfn read(reg, now) { 300 }\n";
    let mut card = ScriptCard::load("wide.rhai", text, None).expect("loads");
    let _ = card.read(0, 1);
    let fault = card.take_fault().expect("a fault").to_string();
    assert_eq!(
        fault,
        "wide.rhai:4:1: `read` returned 300 for register 0, not a byte (0 to 255)"
    );
}

#[test]
fn windows_are_checked() {
    for (text, base, wanted) in [
        ("const BASE = 0x9000;", None, "no `SIZE`"),
        ("const SIZE = 4;", None, "no `BASE`"),
        ("const SIZE = 4;", Some(0xBFFE), "not inside the KIM bus"),
        ("const SIZE = 0;\nconst BASE = 0x9000;", None, "1 to 4096"),
        (
            "const SIZE = 2;\nconst BASE = 0x9000;\nconst PLAIN = [5];",
            None,
            "not a register",
        ),
    ] {
        let error = ScriptCard::load("w.rhai", text, base).expect_err(wanted);
        assert!(error.to_string().contains(wanted), "{error}");
    }
}
