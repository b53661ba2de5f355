//! The expression language of conditions, log points, `set` and
//! `display`: values, precedence, and what is wrong with a bad one, at
//! its column.

use debugger::expr::{Machine, show};
use debugger::{Expr, HitCondition, Symbols, Template};
use emulator::Cpu;

/// Registers and a memory of 64 KiB, each byte its address's low byte
/// plus one.
struct Fixed(Cpu);

impl Machine for Fixed {
    fn cpu(&self) -> &Cpu {
        &self.0
    }
    fn peek(&self, address: u16) -> u8 {
        (address as u8).wrapping_add(1)
    }
}

fn machine() -> Fixed {
    let mut cpu = Cpu::new();
    cpu.a = 0x2F;
    cpu.x = 3;
    cpu.pc = 0x0C3A;
    cpu.set_p(0x01);
    Fixed(cpu)
}

fn symbols() -> Symbols {
    Symbols::new(&romlib::VirtualScorpion::new(), &[])
}

fn value(text: &str) -> i64 {
    Expr::parse(text, &symbols())
        .unwrap_or_else(|e| panic!("{text}: {e}"))
        .eval(&machine())
        .unwrap_or_else(|e| panic!("{text}: {e}"))
}

#[test]
fn values_and_precedence() {
    let cmdbuf = i64::from(romlib::symbols::CMDBUF);
    for (text, expected) in [
        ("$2F", 0x2F),
        ("0x2f", 0x2F),
        ("%101", 5),
        ("'A'", 65),
        ("A", 0x2F),
        ("pc", 0x0C3A),
        ("C", 1),
        ("Z", 0),
        ("1 + 2 * 3", 7),
        ("(1 + 2) * 3", 9),
        ("1 + 2 * 3 == 7 && A == $2F", 1),
        ("A == 1 || X == 3", 1),
        ("<$1234", 0x34),
        (">$1234", 0x12),
        ("~0 & $FF", 0xFF),
        ("1 << 4 | 1", 17),
        ("-3 + 1", -2),
        ("!0", 1),
        ("[X]", 4),
        ("[CMDBUF + 1]", ((cmdbuf + 1) & 0xFF) + 1),
        ("{$10}", 0x1211),
        ("A >= $2F", 1),
        ("A > $2F", 0),
        ("CMDBUF", cmdbuf),
    ] {
        assert_eq!(value(text), expected, "{text}");
    }
}

#[test]
fn bad_expressions_say_what_at_their_column() {
    for (text, column, reason) in [
        ("A == ", 6, "expected a value at the end"),
        ("A == 1 &&", 10, "expected a value at the end"),
        ("[CMDBUF", 8, "expected `]`"),
        ("A == nosuch", 6, "no label `nosuch`"),
        ("cmdbuf", 1, "did you mean `CMDBUF`?"),
        ("$1G", 3, "not a hexadecimal digit"),
        ("%102", 4, "not a binary digit"),
        ("A = 1", 3, "`==` compares"),
        ("A 1", 3, "expected an operator or the end here"),
        ("1 < 2 < 3", 7, "expected an operator or the end here"),
        ("99999999999999999999", 1, "too large"),
        ("", 1, "no expression given"),
        ("'AB'", 1, "a character is one ASCII letter"),
    ] {
        let error = Expr::parse(text, &symbols()).expect_err(text);
        assert_eq!(error.column, column, "{text}: {error}");
        assert!(error.reason.contains(reason), "{text}: {error}");
    }
    let deep = "(".repeat(10_000);
    assert!(Expr::parse(&deep, &symbols()).is_err(), "no stack overflow");
    // A long flat chain builds a tree as deep as it is long: 100,000
    // terms overflowed the stack when evaluated or dropped (the monitor's
    // `print`, `display`, `break ... if`). Bounded, said at its place.
    let flat = format!("{}1", "1+".repeat(100_000));
    let error = Expr::parse(&flat, &symbols()).expect_err("too long");
    assert!(error.reason.contains("at most 1000 operators"), "{error}");
    assert_eq!(error.column, 2003, "{error}");
    let most = format!("{}1", "1+".repeat(1000));
    let expr = Expr::parse(&most, &symbols()).expect("1000 operators");
    assert_eq!(expr.eval(&machine()).expect("evaluates"), 1001);
}

#[test]
fn what_cannot_be_evaluated_is_an_error_not_a_panic() {
    for text in [
        "1 / 0",
        "[$10000]",
        "{-1}",
        "1 << 64",
        "$7FFFFFFFFFFFFFFF + 1",
    ] {
        let expr = Expr::parse(text, &symbols()).expect(text);
        assert!(expr.eval(&machine()).is_err(), "{text}");
        // A condition that cannot be evaluated stops, so that it is seen.
        assert!(expr.holds(&machine()), "{text}");
    }
}

#[test]
fn log_messages_fill_in_their_values() {
    let template = Template::parse("A={A} at {PC}, {{braces}} {1/0}", &symbols()).expect("parses");
    assert_eq!(
        template.render(&machine()),
        "A=$2F at $0C3A, {braces} <division by zero>"
    );
    let open = Template::parse("value {A", &symbols()).expect_err("open brace");
    assert_eq!(open.column, 7);
    let bad = Template::parse("x {A ==}", &symbols()).expect_err("bad value");
    assert_eq!(bad.column, 8, "{bad}");
    assert_eq!(show(5), "$05");
    assert_eq!(show(0x1234), "$1234");
}

#[test]
fn hit_counts_read_and_refuse() {
    assert_eq!(HitCondition::parse("3"), Ok(HitCondition::AtLeast(3)));
    assert_eq!(HitCondition::parse(">= 3"), Ok(HitCondition::AtLeast(3)));
    assert_eq!(HitCondition::parse("==3"), Ok(HitCondition::Exactly(3)));
    assert_eq!(HitCondition::parse("% 4"), Ok(HitCondition::Every(4)));
    assert_eq!(
        HitCondition::parse("18446744073709551615"),
        Ok(HitCondition::AtLeast(u64::MAX))
    );
    for (text, reason) in [
        ("18446744073709551616", "beyond 18446744073709551615"),
        ("0", "at least 1"),
        ("-1", "expected a count"),
        ("three", "expected a count"),
        ("", "expected a count"),
    ] {
        let error = HitCondition::parse(text).expect_err(text);
        assert!(error.reason.contains(reason), "{text}: {error}");
    }
}
