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

#[test]
fn what_a_script_prints_is_bounded_and_the_rest_counted() {
    let text = "const SIZE = 1;\nconst BASE = 0x9000;\nfn init() { for i in 0..5000 { print(`line ${i}`); } }\n";
    let card = ScriptCard::load("loud.rhai", text, None).expect("loads");
    let lines = card.printed().take();
    assert_eq!(lines.len(), crate::MAX_PRINTED_LINES + 1);
    assert_eq!(lines[0], "line 0");
    let dropped = 5000 - crate::MAX_PRINTED_LINES;
    assert!(
        lines[crate::MAX_PRINTED_LINES].starts_with(&format!("({dropped} more lines dropped")),
        "{}",
        lines[crate::MAX_PRINTED_LINES]
    );
    assert!(card.printed().take().is_empty(), "taken");
}

#[test]
fn long_lines_are_bounded_by_bytes() {
    // 40 lines of 4000 bytes: 16 fit in 64 KiB.
    let text = "const SIZE = 1;\nconst BASE = 0x9000;\nfn init() { let line = \"\"; line.pad(4000, \"x\"); for i in 0..40 { print(line); } }\n";
    let card = ScriptCard::load("wide.rhai", text, None).expect("loads");
    let lines = card.printed().take();
    let kept = crate::MAX_PRINTED_BYTES / 4000;
    assert_eq!(lines.len(), kept + 1, "{:?}", lines.last());
    assert!(lines[kept].starts_with(&format!("({} more lines dropped", 40 - kept)));
}

#[test]
fn variables_in_sight_are_bounded_at_the_declaration_past_the_limit() {
    let mut text = String::from("const SIZE = 1;\nconst BASE = 0x9000;\n");
    for i in 0..300 {
        text.push_str(&format!("const X{i} = {i};\n"));
    }
    let error = ScriptCard::load("many.rhai", &text, None).expect_err("refused");
    let ScriptError::Script(located) = &error else {
        panic!("{error:?}")
    };
    // SIZE and BASE, then X0 to X253: X254 is the 257th.
    assert_eq!((located.line, located.column), (2 + 254 + 1, 7), "{error}");
    assert!(
        located.message.contains("more than 256 variables"),
        "{error}"
    );
}

#[test]
fn a_script_earns_its_budget_back_with_robot_time() {
    // A read of a few thousand operations: one every millisecond is
    // within 10 a microsecond; one every microsecond is not, once the
    // budget saved up is spent.
    let text = "const SIZE = 1;\nconst BASE = 0x9000;\nconst VOLATILE = [0];\nfn read(reg, now) { let n = 0; for i in 0..500 { n += 1; } n & 0xFF }\n";
    let mut card = ScriptCard::load("busy.rhai", text, None).expect("loads");
    for read in 0..2_000 {
        assert_eq!(card.read(0, read * 1000), 0xF4, "read {read}");
    }
    assert!(card.take_fault().is_none());
    let start = 2_000 * 1000;
    let mut failed_at = None;
    for read in 0..2_000 {
        let _ = card.read(0, start + read);
        if let Some(fault) = card.take_fault() {
            assert!(
                fault
                    .to_string()
                    .contains("more than its share of robot time"),
                "{fault}"
            );
            failed_at = Some(read);
            break;
        }
    }
    let failed_at = failed_at.expect("the budget runs out");
    assert!(
        failed_at > 10,
        "the budget saved up lasts a while: {failed_at}"
    );
}

#[test]
fn nothing_in_the_library_sees_the_host_clock_or_leaves_the_call() {
    for call in [
        "timestamp()",
        "sleep(1)",
        "sleep(0.1)",
        "exit()",
        "exit(1)",
        "rand()",
        "random()",
        "time()",
        "now()",
        "elapsed(1)",
        "parse_json(\"{}\")",
        "back_trace()",
    ] {
        let text =
            format!("const SIZE = 1;\nconst BASE = 0x9000;\nfn read(reg, now) {{ {call}; 0 }}\n");
        let mut card = ScriptCard::load("probe.rhai", &text, None).expect("loads");
        let _ = card.read(0, 1);
        let fault = card.take_fault().map(|fault| fault.to_string());
        assert!(
            fault
                .as_deref()
                .is_some_and(|f| f.starts_with("probe.rhai:3:")),
            "`{call}` must fail at the call: {fault:?}"
        );
    }
}
