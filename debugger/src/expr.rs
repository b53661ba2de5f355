//! The expression language of conditions, log points, `set`, `display`
//! and addresses, shared by the monitor and the DAP server.
//!
//! Values are 64-bit signed integers. A term is a number (`$2F`, `0x2F`,
//! `%101`, `47`, `'A'`), a register (`A X Y S P PC`), a flag (`C Z I D V
//! N`, 0 or 1), a symbol (labels, constants, cheap locals as `@loop`,
//! scoped names as `scope::name`), the byte at an address `[CMDBUF]` or
//! the little-endian word `{HOOK_UNKNOWN}`. Operators, loosest first:
//! `||`, `&&`, `== != < <= > >=`, `|`, `^`, `&`, `<< >>`, `+ -`, `* /`,
//! and the unary `- ! ~ < >` (`<` and `>`: low and high byte, as ca65).
//!
//! Names are resolved when the expression is read, so an unknown name is
//! an error at its column then, and evaluating reads only registers and
//! memory: cheap enough for a breakpoint's condition, asked each time its
//! PC is reached.

use emulator::Cpu;

use crate::symbols::Symbols;

/// A register or flag an expression can read and `set` can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Register {
    /// The accumulator.
    A,
    /// Index register X.
    X,
    /// Index register Y.
    Y,
    /// The stack pointer.
    S,
    /// The status register as a byte.
    P,
    /// The program counter.
    Pc,
    /// A flag of P (its mask: `emulator::cpu::flag::C`...).
    Flag(u8),
}

impl Register {
    /// `A`, `pc`, `C`... (any case) as a register or flag.
    #[must_use]
    pub fn named(name: &str) -> Option<Register> {
        use emulator::cpu::flag;
        Some(match name.to_ascii_uppercase().as_str() {
            "A" => Register::A,
            "X" => Register::X,
            "Y" => Register::Y,
            "S" | "SP" => Register::S,
            "P" => Register::P,
            "PC" => Register::Pc,
            "C" => Register::Flag(flag::C),
            "Z" => Register::Flag(flag::Z),
            "I" => Register::Flag(flag::I),
            "D" => Register::Flag(flag::D),
            "V" => Register::Flag(flag::V),
            "N" => Register::Flag(flag::N),
            _ => return None,
        })
    }

    /// Its value in `cpu`.
    #[must_use]
    pub fn read(self, cpu: &Cpu) -> u16 {
        match self {
            Register::A => u16::from(cpu.a),
            Register::X => u16::from(cpu.x),
            Register::Y => u16::from(cpu.y),
            Register::S => u16::from(cpu.s),
            Register::P => u16::from(cpu.p()),
            Register::Pc => cpu.pc,
            Register::Flag(mask) => u16::from(cpu.p() & mask != 0),
        }
    }

    /// The largest value it holds: $FF, $FFFF, or 1 for a flag.
    #[must_use]
    pub fn max(self) -> u16 {
        match self {
            Register::Pc => 0xFFFF,
            Register::Flag(_) => 1,
            _ => 0xFF,
        }
    }

    /// Sets it in `cpu` to `value` (at most [`Register::max`]).
    pub fn write(self, cpu: &mut Cpu, value: u16) {
        let byte = u8::try_from(value & 0xFF).unwrap_or(0);
        match self {
            Register::A => cpu.a = byte,
            Register::X => cpu.x = byte,
            Register::Y => cpu.y = byte,
            Register::S => cpu.s = byte,
            Register::P => cpu.set_p(byte),
            Register::Pc => cpu.pc = value,
            Register::Flag(mask) => {
                let p = if value != 0 {
                    cpu.p() | mask
                } else {
                    cpu.p() & !mask
                };
                cpu.set_p(p);
            }
        }
    }
}

impl std::fmt::Display for Register {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use emulator::cpu::flag;
        let name = match self {
            Register::A => "A",
            Register::X => "X",
            Register::Y => "Y",
            Register::S => "S",
            Register::P => "P",
            Register::Pc => "PC",
            Register::Flag(flag::C) => "C",
            Register::Flag(flag::Z) => "Z",
            Register::Flag(flag::I) => "I",
            Register::Flag(flag::D) => "D",
            Register::Flag(flag::V) => "V",
            Register::Flag(_) => "N",
        };
        f.write_str(name)
    }
}

/// An expression that does not parse: what was expected, and where.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, miette::Diagnostic)]
#[error("`{text}` column {column}: {reason}")]
#[diagnostic(
    code(debugger::expression),
    help(
        "terms: $2F 47 %101 'A', registers A X Y S P PC, flags C Z I D V N, labels, [ADDR] a byte, {{ADDR}} a word; operators || && == != < <= > >= | ^ & << >> + - * / ! ~"
    )
)]
pub struct ParseError {
    /// The expression as given.
    pub text: String,
    /// The column (from 1, in characters) where it goes wrong.
    pub column: usize,
    /// Why.
    pub reason: String,
    /// The place, for miette.
    #[label("here")]
    pub span: miette::SourceSpan,
}

impl ParseError {
    /// The expression with a caret under the column: for a terminal. A
    /// column past what an error repeats of the text gets no caret.
    #[must_use]
    pub fn pointed(&self) -> String {
        if self.column > SHOWN {
            return format!("  {}", self.text);
        }
        format!(
            "  {}\n  {}^",
            self.text,
            " ".repeat(self.column.saturating_sub(1))
        )
    }
}

/// The most characters of an expression an error repeats.
const SHOWN: usize = 200;

/// `text` as an error repeats it: an expression of a megabyte is cut, not
/// echoed whole into a response or onto the terminal.
fn clipped(text: &str) -> String {
    match text.char_indices().nth(SHOWN) {
        Some((at, _)) => format!("{}... ({} bytes)", &text[..at], text.len()),
        None => text.to_owned(),
    }
}

/// An expression that parsed but cannot be evaluated now.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, miette::Diagnostic)]
#[error("`{text}`: {reason}")]
#[diagnostic(code(debugger::evaluate))]
pub struct EvalError {
    /// The expression.
    pub text: String,
    /// Why: a division by zero, an overflow, a byte read past $FFFF.
    pub reason: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Unary {
    Negate,
    Not,
    Complement,
    Low,
    High,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Binary {
    Or,
    And,
    Equal,
    NotEqual,
    Less,
    LessEqual,
    Greater,
    GreaterEqual,
    BitOr,
    BitXor,
    BitAnd,
    Shl,
    Shr,
    Add,
    Sub,
    Mul,
    Div,
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Node {
    Number(i64),
    Register(Register),
    Byte(Box<Node>),
    Word(Box<Node>),
    Unary(Unary, Box<Node>),
    Binary(Binary, Box<Node>, Box<Node>),
}

/// A parsed expression, its names resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Expr {
    text: String,
    node: Node,
}

impl std::fmt::Display for Expr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.text)
    }
}

/// What an expression reads: the CPU and memory (without side effects).
pub trait Machine {
    /// The registers.
    fn cpu(&self) -> &Cpu;
    /// The byte at `address`, as a debugger peeks it.
    fn peek(&self, address: u16) -> u8;
}

/// A CPU and a peek function, as the hooks have them.
pub struct Peeking<'a> {
    /// The registers.
    pub cpu: &'a Cpu,
    /// Memory.
    pub peek: &'a dyn Fn(u16) -> u8,
}

impl std::fmt::Debug for Peeking<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Peeking").field("cpu", self.cpu).finish()
    }
}

impl Machine for Peeking<'_> {
    fn cpu(&self) -> &Cpu {
        self.cpu
    }

    fn peek(&self, address: u16) -> u8 {
        (self.peek)(address)
    }
}

impl Expr {
    /// Reads `text`, resolving names with `symbols`.
    ///
    /// # Errors
    /// [`ParseError`] at the column where it goes wrong: a name that is
    /// no label, a number that is not one, a missing operand or bracket.
    pub fn parse(text: &str, symbols: &Symbols) -> Result<Expr, ParseError> {
        let mut parser = Parser {
            text,
            chars: text.char_indices().collect(),
            at: 0,
            symbols,
            operators: 0,
        };
        parser.blank();
        if parser.at == parser.chars.len() {
            return Err(parser.error_here("no expression given"));
        }
        let node = parser.or()?;
        parser.blank();
        if parser.at < parser.chars.len() {
            let reason = if parser.peek() == Some('=') {
                "`=` is no operator: `==` compares"
            } else {
                "expected an operator or the end here"
            };
            return Err(parser.error_here(reason));
        }
        Ok(Expr {
            text: text.trim().to_owned(),
            node,
        })
    }

    /// The expression as written.
    #[must_use]
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Its value on `machine`.
    ///
    /// # Errors
    /// [`EvalError`]: a division by zero, an overflow, a byte or word read
    /// outside $0000-$FFFF.
    pub fn eval(&self, machine: &dyn Machine) -> Result<i64, EvalError> {
        eval(&self.node, machine).map_err(|reason| EvalError {
            text: clipped(&self.text),
            reason,
        })
    }

    /// Whether it holds (is not zero) on `machine`; an expression that
    /// cannot be evaluated holds, so that the user sees why.
    #[must_use]
    pub fn holds(&self, machine: &dyn Machine) -> bool {
        !matches!(self.eval(machine), Ok(0))
    }

    /// Its value as an address.
    ///
    /// # Errors
    /// [`EvalError`] as [`Expr::eval`], or a value outside $0000-$FFFF.
    pub fn address(&self, machine: &dyn Machine) -> Result<u16, EvalError> {
        let value = self.eval(machine)?;
        u16::try_from(value).map_err(|_| EvalError {
            text: self.text.clone(),
            reason: format!("{value} is not an address ($0000-$FFFF)"),
        })
    }

    /// The register it names, if it is only a register: `set A ...`.
    #[must_use]
    pub fn register(&self) -> Option<Register> {
        match self.node {
            Node::Register(register) => Some(register),
            _ => None,
        }
    }

    /// Whether it reads nothing but constants (a label, a sum of them).
    #[must_use]
    pub fn is_constant(&self) -> bool {
        fn constant(node: &Node) -> bool {
            match node {
                Node::Number(_) => true,
                Node::Register(_) | Node::Byte(_) | Node::Word(_) => false,
                Node::Unary(_, a) => constant(a),
                Node::Binary(_, a, b) => constant(a) && constant(b),
            }
        }
        constant(&self.node)
    }
}

/// A value as the monitor shows it: `$2F` for a byte, `$0C3A` for a word,
/// decimal beyond.
#[must_use]
pub fn show(value: i64) -> String {
    match value {
        0..=0xFF => format!("${value:02X}"),
        0x100..=0xFFFF => format!("${value:04X}"),
        _ => value.to_string(),
    }
}

fn eval(node: &Node, machine: &dyn Machine) -> Result<i64, String> {
    let overflow = || "the value overflows 64 bits".to_owned();
    let address = |value: i64| {
        u16::try_from(value).map_err(|_| format!("{value} is not an address ($0000-$FFFF)"))
    };
    Ok(match node {
        Node::Number(value) => *value,
        Node::Register(register) => i64::from(register.read(machine.cpu())),
        Node::Byte(at) => i64::from(machine.peek(address(eval(at, machine)?)?)),
        Node::Word(at) => {
            let at = address(eval(at, machine)?)?;
            i64::from(u16::from_le_bytes([
                machine.peek(at),
                machine.peek(at.wrapping_add(1)),
            ]))
        }
        Node::Unary(op, a) => {
            let a = eval(a, machine)?;
            match op {
                Unary::Negate => a.checked_neg().ok_or_else(overflow)?,
                Unary::Not => i64::from(a == 0),
                Unary::Complement => !a,
                Unary::Low => a & 0xFF,
                Unary::High => (a >> 8) & 0xFF,
            }
        }
        Node::Binary(Binary::Or, a, b) => {
            i64::from(eval(a, machine)? != 0 || eval(b, machine)? != 0)
        }
        Node::Binary(Binary::And, a, b) => {
            i64::from(eval(a, machine)? != 0 && eval(b, machine)? != 0)
        }
        Node::Binary(op, a, b) => {
            let (a, b) = (eval(a, machine)?, eval(b, machine)?);
            match op {
                Binary::Equal => i64::from(a == b),
                Binary::NotEqual => i64::from(a != b),
                Binary::Less => i64::from(a < b),
                Binary::LessEqual => i64::from(a <= b),
                Binary::Greater => i64::from(a > b),
                Binary::GreaterEqual => i64::from(a >= b),
                Binary::BitOr => a | b,
                Binary::BitXor => a ^ b,
                Binary::BitAnd => a & b,
                Binary::Shl => u32::try_from(b)
                    .ok()
                    .filter(|&b| b < 64)
                    .and_then(|b| a.checked_shl(b))
                    .ok_or_else(|| format!("cannot shift by {b}"))?,
                Binary::Shr => u32::try_from(b)
                    .ok()
                    .filter(|&b| b < 64)
                    .and_then(|b| a.checked_shr(b))
                    .ok_or_else(|| format!("cannot shift by {b}"))?,
                Binary::Add => a.checked_add(b).ok_or_else(overflow)?,
                Binary::Sub => a.checked_sub(b).ok_or_else(overflow)?,
                Binary::Mul => a.checked_mul(b).ok_or_else(overflow)?,
                Binary::Div => {
                    if b == 0 {
                        return Err("division by zero".into());
                    }
                    a.checked_div(b).ok_or_else(overflow)?
                }
                Binary::Or | Binary::And => 0,
            }
        }
    })
}

struct Parser<'a> {
    text: &'a str,
    chars: Vec<(usize, char)>,
    /// Index into `chars`.
    at: usize,
    symbols: &'a Symbols,
    /// Binary operators read so far (see [`MAX_OPERATORS`]).
    operators: usize,
}

/// Nesting deeper than this is refused (a hostile line of brackets must
/// not overflow the stack).
const MAX_DEPTH: usize = 64;

/// More binary operators than this are refused: a long flat chain
/// (`1+1+1...`) builds a tree as deep as it is long, which evaluating or
/// dropping would walk on the stack.
const MAX_OPERATORS: usize = 1000;

impl Parser<'_> {
    fn peek(&self) -> Option<char> {
        self.chars.get(self.at).map(|&(_, c)| c)
    }

    fn peek2(&self) -> Option<char> {
        self.chars.get(self.at + 1).map(|&(_, c)| c)
    }

    fn blank(&mut self) {
        while self.peek().is_some_and(char::is_whitespace) {
            self.at += 1;
        }
    }

    fn error_at(&self, index: usize, reason: &str) -> ParseError {
        let offset = self.chars.get(index).map_or(self.text.len(), |&(o, _)| o);
        let len = self.chars.get(index).map_or(0, |&(_, c)| c.len_utf8());
        ParseError {
            text: clipped(self.text),
            column: index + 1,
            reason: reason.to_owned(),
            span: (offset, len).into(),
        }
    }

    fn error_here(&self, reason: &str) -> ParseError {
        self.error_at(self.at, reason)
    }

    /// Takes `op` if it comes next (and, for a one-character operator, is
    /// not the start of a longer one in `not_before`).
    fn take(&mut self, op: &str, not_before: &[char]) -> bool {
        self.blank();
        let n = op.chars().count();
        let matches = op
            .chars()
            .enumerate()
            .all(|(i, c)| self.chars.get(self.at + i).is_some_and(|&(_, d)| d == c));
        let longer = self
            .chars
            .get(self.at + n)
            .is_some_and(|&(_, c)| not_before.contains(&c));
        if matches && !longer {
            self.at += n;
            true
        } else {
            false
        }
    }

    fn or(&mut self) -> Result<Node, ParseError> {
        self.binary_level(0, 0)
    }

    /// One level of binary operators (loosest at 0), left-associative.
    fn binary_level(&mut self, level: usize, depth: usize) -> Result<Node, ParseError> {
        // Operators by level, each with the characters that would make it
        // a longer operator.
        const LEVELS: &[&[(&str, &[char], Binary)]] = &[
            &[("||", &[], Binary::Or)],
            &[("&&", &[], Binary::And)],
            &[
                ("==", &[], Binary::Equal),
                ("!=", &[], Binary::NotEqual),
                ("<=", &[], Binary::LessEqual),
                (">=", &[], Binary::GreaterEqual),
                ("<", &['<', '='], Binary::Less),
                (">", &['>', '='], Binary::Greater),
            ],
            &[("|", &['|'], Binary::BitOr)],
            &[("^", &[], Binary::BitXor)],
            &[("&", &['&'], Binary::BitAnd)],
            &[("<<", &[], Binary::Shl), (">>", &[], Binary::Shr)],
            &[("+", &[], Binary::Add), ("-", &[], Binary::Sub)],
            &[("*", &[], Binary::Mul), ("/", &[], Binary::Div)],
        ];
        let Some(ops) = LEVELS.get(level) else {
            return self.unary(depth);
        };
        let mut left = self.binary_level(level + 1, depth)?;
        // Comparisons do not chain: `1 < 2 < 3` is refused.
        let chains = level != 2;
        loop {
            let found = ops
                .iter()
                .find(|(op, not_before, _)| self.take(op, not_before));
            let Some(&(_, _, op)) = found else {
                return Ok(left);
            };
            self.operators += 1;
            if self.operators > MAX_OPERATORS {
                return Err(self.error_here(&format!(
                    "too long: an expression has at most {MAX_OPERATORS} operators"
                )));
            }
            let right = self.binary_level(level + 1, depth)?;
            left = Node::Binary(op, Box::new(left), Box::new(right));
            if !chains {
                return Ok(left);
            }
        }
    }

    fn unary(&mut self, depth: usize) -> Result<Node, ParseError> {
        if depth > MAX_DEPTH {
            return Err(self.error_here("nested too deeply"));
        }
        self.blank();
        let op = match self.peek() {
            Some('-') => Unary::Negate,
            Some('!') => Unary::Not,
            Some('~') => Unary::Complement,
            Some('<') => Unary::Low,
            Some('>') => Unary::High,
            _ => return self.primary(depth),
        };
        self.at += 1;
        let operand = self.unary(depth + 1)?;
        Ok(match (op, operand) {
            (Unary::Negate, Node::Number(n)) if n != i64::MIN => Node::Number(-n),
            (op, operand) => Node::Unary(op, Box::new(operand)),
        })
    }

    fn primary(&mut self, depth: usize) -> Result<Node, ParseError> {
        self.blank();
        let start = self.at;
        let Some(c) = self.peek() else {
            return Err(self.error_here("expected a value at the end"));
        };
        match c {
            '(' | '[' | '{' => {
                let close = match c {
                    '(' => ')',
                    '[' => ']',
                    _ => '}',
                };
                self.at += 1;
                let inner = self.binary_level(0, depth + 1)?;
                self.blank();
                if self.peek() != Some(close) {
                    return Err(self.error_here(&format!(
                        "expected `{close}` (for the `{c}` at column {})",
                        start + 1
                    )));
                }
                self.at += 1;
                Ok(match c {
                    '(' => inner,
                    '[' => Node::Byte(Box::new(inner)),
                    _ => Node::Word(Box::new(inner)),
                })
            }
            '$' => {
                self.at += 1;
                self.digits(start, 16)
            }
            '%' => {
                self.at += 1;
                self.digits(start, 2)
            }
            '0' if matches!(self.peek2(), Some('x' | 'X')) => {
                self.at += 2;
                self.digits(start, 16)
            }
            '0'..='9' => self.digits(start, 10),
            '\'' => {
                let letter = self.chars.get(self.at + 1).map(|&(_, c)| c);
                let closed = self.chars.get(self.at + 2).map(|&(_, c)| c) == Some('\'');
                match letter {
                    Some(letter) if closed && letter.is_ascii() => {
                        self.at += 3;
                        Ok(Node::Number(i64::from(u32::from(letter))))
                    }
                    _ => Err(self.error_here("a character is one ASCII letter in quotes: 'A'")),
                }
            }
            c if is_name_start(c) => {
                while self.peek().is_some_and(is_name_char)
                    || (self.peek() == Some(':') && self.peek2() == Some(':'))
                {
                    self.at += if self.peek() == Some(':') { 2 } else { 1 };
                }
                let name: String = self.chars[start..self.at].iter().map(|&(_, c)| c).collect();
                // Registers first: `A` is the accumulator, as in every
                // 6502 monitor, whatever a program names `a`.
                if let Some(register) = Register::named(&name) {
                    return Ok(Node::Register(register));
                }
                if let Some(why) = self.symbols.ambiguity(&name) {
                    return Err(self.error_at(start, &why));
                }
                if let Some(value) = self.symbols.get(&name) {
                    return Ok(Node::Number(i64::from(value)));
                }
                Err(self.error_at(start, &self.symbols.unknown(&name)))
            }
            _ => Err(self.error_here(&format!("expected a value, found `{c}`"))),
        }
    }

    /// The digits from here in `radix`; `start` is where the number
    /// began (its prefix).
    fn digits(&mut self, start: usize, radix: u32) -> Result<Node, ParseError> {
        let first = self.at;
        while self
            .peek()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
        {
            self.at += 1;
        }
        let digits: String = self.chars[first..self.at]
            .iter()
            .map(|&(_, c)| c)
            .filter(|&c| c != '_')
            .collect();
        if digits.is_empty() {
            return Err(self.error_at(first, "expected digits after the prefix"));
        }
        if let Some(bad) = self.chars[first..self.at]
            .iter()
            .position(|&(_, c)| c != '_' && !c.is_digit(radix))
        {
            let base = match radix {
                2 => "binary",
                16 => "hexadecimal",
                _ => "decimal",
            };
            return Err(self.error_at(first + bad, &format!("not a {base} digit")));
        }
        i64::from_str_radix(&digits, radix)
            .map(Node::Number)
            .map_err(|_| self.error_at(start, "the number is too large (64 bits at most)"))
    }
}

fn is_name_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_' || c == '@' || c == '.'
}

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '@' || c == '.'
}

/// A log point's message: text with `{EXPR}` replaced by the value at
/// each hit (`{{` and `}}` for braces), as the DAP's `logMessage`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Template {
    text: String,
    parts: Vec<Part>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Part {
    Text(String),
    Value(Expr),
}

impl Template {
    /// Reads `text`.
    ///
    /// # Errors
    /// [`ParseError`] for an expression in braces that does not parse, or
    /// a brace left open; its column is in the whole message.
    pub fn parse(text: &str, symbols: &Symbols) -> Result<Template, ParseError> {
        let mut parts = Vec::new();
        let mut literal = String::new();
        let chars: Vec<(usize, char)> = text.char_indices().collect();
        let mut i = 0;
        let error = |index: usize, reason: &str| ParseError {
            text: text.to_owned(),
            column: index + 1,
            reason: reason.to_owned(),
            span: (chars.get(index).map_or(text.len(), |&(o, _)| o), 1).into(),
        };
        while let Some(&(offset, c)) = chars.get(i) {
            let next = chars.get(i + 1).map(|&(_, c)| c);
            match (c, next) {
                ('{', Some('{')) | ('}', Some('}')) => {
                    literal.push(c);
                    i += 2;
                }
                ('{', _) => {
                    let close = chars[i..]
                        .iter()
                        .position(|&(_, c)| c == '}')
                        .ok_or_else(|| error(i, "this `{` is not closed"))?;
                    let end = chars[i + close].0;
                    let inner = &text[offset + 1..end];
                    let expr =
                        Expr::parse(inner, symbols).map_err(|e| error(i + e.column, &e.reason))?;
                    if !literal.is_empty() {
                        parts.push(Part::Text(std::mem::take(&mut literal)));
                    }
                    parts.push(Part::Value(expr));
                    i += close + 1;
                }
                ('}', _) => return Err(error(i, "a `}` with no `{` (`}}` for a brace)")),
                _ => {
                    literal.push(c);
                    i += 1;
                }
            }
        }
        if !literal.is_empty() {
            parts.push(Part::Text(literal));
        }
        Ok(Template {
            text: text.to_owned(),
            parts,
        })
    }

    /// The message as written.
    #[must_use]
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The message on `machine`: each value as [`show`] writes it, or
    /// `<why not>`.
    #[must_use]
    pub fn render(&self, machine: &dyn Machine) -> String {
        self.parts
            .iter()
            .map(|part| match part {
                Part::Text(text) => text.clone(),
                Part::Value(expr) => match expr.eval(machine) {
                    Ok(value) => show(value),
                    Err(error) => format!("<{}>", error.reason),
                },
            })
            .collect()
    }
}
