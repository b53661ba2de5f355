//! Seeded random 6502 programs in ca65 syntax (and, for the benchmark, the
//! same program in 64tass syntax), shared by the ld65 differential test
//! and the 200,000-line benchmark through `#[path]`.
//!
//! Programs cover every documented opcode and addressing mode, global
//! labels, cheap locals, unnamed labels, forward references, macros with
//! `.local`, `.repeat` with a counter, conditionals, `.proc` scopes,
//! structs, enums, `.define`, `.set`, expressions with ca65's precedence,
//! and every data directive; and ca65's name rules (`scope_unit`): nested
//! `.proc`/`.scope`s whose names shadow global ones and are used before
//! the scope defines them, `::` paths in and out of scopes, cheap locals
//! and `.local` inside them, and `#` and commas in brace arguments of
//! macros and `.define`s. Sizes are tracked (as upper bounds) so that
//! branches always reach and `.org` chunks stay under 64 KiB.
//!
//! Forward references to zero-page symbols come up too: ca65 (and our
//! default) assembles them as absolute.

#![allow(dead_code, reason = "each includer uses a part")]

use std::fmt::Write as _;

use isa::{AddressingMode as Mode, OPCODES, OpcodeKind};
use rand::rngs::StdRng;
use rand::{Rng as _, RngExt as _, SeedableRng as _};

/// The generator's randomness: rand's seeded `StdRng`, so a seed names
/// one program on every platform (the lock file pins rand's version, which
/// fixes the stream).
#[derive(Debug)]
pub(crate) struct Rng(StdRng);

impl Rng {
    pub(crate) fn new(seed: u64) -> Rng {
        Rng(StdRng::seed_from_u64(seed))
    }

    pub(crate) fn next(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A number in `0..n` (`n > 0`).
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.0.random_range(0..n.max(1))
    }

    /// True with probability `percent`/100.
    pub(crate) fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }

    pub(crate) fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len() as u64) as usize]
    }
}

/// Which program to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flavor {
    /// Relocatable segments (ZEROPAGE, CODE, RODATA, DATA, BSS) in two
    /// files with imports and exports, for a flat link.
    Differential,
    /// One file, CODE only, in `.org $1000` chunks under 64 KiB, written
    /// in ca65 and 64tass syntax.
    Benchmark,
}

/// A generated program.
#[derive(Debug, Clone, Default)]
pub(crate) struct Program {
    /// Source files in ca65 syntax, `(name, text)`, main file first.
    pub(crate) files: Vec<(String, String)>,
    /// The same program in 64tass syntax (benchmark only).
    pub(crate) tass: String,
    /// Source lines in the ca65 version, macro bodies not expanded.
    pub(crate) lines: usize,
    /// The documented (mnemonic, mode) pairs the program's random
    /// instructions use.
    pub(crate) covered: std::collections::BTreeSet<(&'static str, Mode)>,
}

const ZP_CONSTS: [(&str, u8); 4] = [
    ("zpc0", 0x10),
    ("zpc1", 0x20),
    ("zpc2", 0x80),
    ("zpc3", 0xFE),
];
const ABS_CONSTS: [(&str, u16); 4] = [
    ("absc0", 0x1234),
    ("absc1", 0xC000),
    ("absc2", 0x0300),
    ("absc3", 0xFFF0),
];

/// Documented opcodes, the generator's instruction menu.
fn documented() -> Vec<(&'static str, Mode)> {
    OPCODES
        .iter()
        .filter(|op| op.kind == OpcodeKind::Documented)
        .map(|op| (op.mnemonic.name(), op.mode))
        .collect()
}

struct Gen {
    rng: Rng,
    flavor: Flavor,
    ops: Vec<(&'static str, Mode)>,
    ca: String,
    tass: String,
    lines: usize,
    /// Next global label number; labels `L_0..L_{next-1}` are defined.
    next_label: usize,
    /// Highest label number referenced (forward references included).
    max_ref: usize,
    /// Cheap locals defined in the current block, usable backward.
    cheap: Vec<usize>,
    cheap_serial: usize,
    /// Bytes in the current block (bounds branch distances).
    block_bytes: usize,
    /// Bytes in the current `.org` chunk (benchmark).
    chunk_bytes: usize,
    procs: Vec<usize>,
    /// Scope units written so far (`S_n`).
    scopes: usize,
    sets: usize,
    covered: std::collections::BTreeSet<(&'static str, Mode)>,
}

impl Gen {
    fn both(&mut self, ca: &str, tass: &str) {
        self.ca.push_str(ca);
        self.ca.push('\n');
        self.lines += 1;
        if self.flavor == Flavor::Benchmark {
            self.tass.push_str(tass);
            self.tass.push('\n');
        }
    }

    fn ca_only(&mut self, line: &str) {
        debug_assert!(self.flavor == Flavor::Differential);
        self.ca.push_str(line);
        self.ca.push('\n');
        self.lines += 1;
    }

    fn number(&mut self, value: u64) -> String {
        match self.rng.below(if self.flavor == Flavor::Benchmark {
            2
        } else {
            4
        }) {
            0 => format!("${value:X}"),
            1 => format!("{value}"),
            2 => format!("%{value:b}"),
            _ => format!("0{value:X}h"),
        }
    }

    /// A label reference, possibly forward.
    fn label(&mut self) -> usize {
        let k = if self.next_label == 0 || self.rng.chance(25) {
            self.next_label + self.rng.below(20) as usize
        } else {
            self.rng.below(self.next_label as u64) as usize
        };
        self.max_ref = self.max_ref.max(k);
        k
    }

    /// A constant expression in ca65 syntax, exercising the precedence
    /// table; divisors are literal and non-zero, products stay small.
    fn const_expr(&mut self, depth: u32) -> String {
        if depth == 0 || self.rng.chance(30) {
            return match self.rng.below(6) {
                0 => {
                    let (name, _) = *self.rng.pick(&ZP_CONSTS);
                    name.to_string()
                }
                1 => {
                    let (name, _) = *self.rng.pick(&ABS_CONSTS);
                    name.to_string()
                }
                2 => format!("'{}'", (b'A' + self.rng.below(26) as u8) as char),
                3 => "Color::red".to_string(),
                4 => ".sizeof(Point)".to_string(),
                _ => {
                    let v = self.rng.below(300);
                    self.number(v)
                }
            };
        }
        let left = self.const_expr(depth - 1);
        match self.rng.below(14) {
            0 => format!("{left} + {}", self.const_expr(depth - 1)),
            1 => format!("{left} - {}", self.const_expr(depth - 1)),
            2 => format!("{left} * {}", 1 + self.rng.below(15)),
            3 => format!("{left} / {}", 1 + self.rng.below(15)),
            4 => format!("{left} .mod {}", 1 + self.rng.below(15)),
            5 => format!("{left} & {}", self.const_expr(depth - 1)),
            6 => format!("{left} | {}", self.const_expr(depth - 1)),
            7 => format!("{left} ^ {}", self.const_expr(depth - 1)),
            8 => format!("{left} << {}", self.rng.below(8)),
            9 => format!("{left} >> {}", self.rng.below(8)),
            10 => {
                let op = *self.rng.pick(&["=", "<>", "<", ">", "<=", ">="]);
                format!("({left} {op} {})", self.const_expr(depth - 1))
            }
            11 => {
                let op = *self.rng.pick(&["&&", "||", ".xor", ".and", ".or"]);
                format!("({left} {op} {})", self.const_expr(depth - 1))
            }
            12 => format!("-({left})"),
            _ => format!("({left})"),
        }
    }

    /// An immediate operand: (ca65, 64tass).
    fn immediate(&mut self) -> (String, String) {
        let choice = if self.flavor == Flavor::Benchmark {
            self.rng.below(5)
        } else {
            self.rng.below(12)
        };
        match choice {
            0 | 1 => {
                let v = self.rng.below(256);
                let n = self.number(v);
                (format!("#{n}"), format!("#{n}"))
            }
            2 => {
                let k = self.label();
                (format!("#<L_{k}"), format!("#<L_{k}"))
            }
            3 => {
                let k = self.label();
                (format!("#>L_{k}"), format!("#>L_{k}"))
            }
            4 => {
                let k = self.label();
                let d = self.rng.below(8);
                (format!("#<(L_{k}+{d})"), format!("#<(L_{k}+{d})"))
            }
            5 => {
                let e = self.const_expr(3);
                (format!("#<({e})"), String::new())
            }
            6 => (
                format!(
                    "#{}",
                    self.rng
                        .pick(&[".sizeof(Point)", "Point::ypos", "Color::red", "TWO", "'a'"])
                ),
                String::new(),
            ),
            7 => (
                format!("#>(libdata + {})", self.rng.below(4)),
                String::new(),
            ),
            8 => (
                format!(
                    "#.{}(L_{})",
                    self.rng.pick(&["lobyte", "hibyte", "bankbyte"]),
                    self.label()
                ),
                String::new(),
            ),
            9 => (format!("#<zpx{}", self.rng.below(2)), String::new()),
            10 => ("#cnt".to_string(), String::new()),
            _ => {
                let v = self.rng.below(256);
                (
                    format!("#<({v} + 256 * {})", self.rng.below(4)),
                    String::new(),
                )
            }
        }
    }

    /// A zero-page operand (no index).
    fn zero_page(&mut self) -> (String, String) {
        let choice = if self.flavor == Flavor::Benchmark {
            self.rng.below(2)
        } else {
            self.rng.below(6)
        };
        let (name, _) = *self.rng.pick(&ZP_CONSTS[..3]);
        match choice {
            0 => (name.to_string(), name.to_string()),
            1 => (format!("{name}+1"), format!("{name}+1")),
            2 => (format!("zpv{}", self.rng.below(3)), String::new()),
            3 => (format!("zpx{}", self.rng.below(2)), String::new()),
            4 => (format!("<absc{}", self.rng.below(4)), String::new()),
            _ => ("zpv0 + Point::flags".to_string(), String::new()),
        }
    }

    /// An absolute operand.
    fn absolute(&mut self, allow_zp_override: bool) -> (String, String) {
        let choice = if self.flavor == Flavor::Benchmark {
            self.rng.below(4)
        } else {
            self.rng.below(11)
        };
        match choice {
            0 => {
                let (name, _) = *self.rng.pick(&ABS_CONSTS);
                (name.to_string(), name.to_string())
            }
            1 => {
                let k = self.label();
                (format!("L_{k}"), format!("L_{k}"))
            }
            2 => {
                let k = self.label();
                let d = self.rng.below(16);
                (format!("L_{k}+{d}"), format!("L_{k}+{d}"))
            }
            3 => {
                let v = 0x200 + self.rng.below(0xFD00);
                (format!("${v:04X}"), format!("${v:04X}"))
            }
            4 => (format!("libfn{}", self.rng.below(2)), String::new()),
            5 if allow_zp_override => (format!("a:zpc{}", self.rng.below(3)), String::new()),
            6 if !self.procs.is_empty() => {
                let p = *self.rng.pick(&self.procs.clone());
                (format!("P_{p}::inner"), String::new())
            }
            7 => (format!("bss{}", self.rng.below(3)), String::new()),
            8 => {
                let k = self.label();
                (format!("::L_{k}"), String::new())
            }
            9 => (format!("tab + {}", self.rng.below(8)), String::new()),
            _ => ("absc0 + L_1 - L_0".to_string(), String::new()),
        }
    }

    /// One random documented instruction; returns its size.
    fn instruction(&mut self) -> usize {
        let (mnemonic, mode) = *self.rng.pick(&self.ops.clone());
        self.covered.insert((mnemonic, mode));
        let m = mnemonic.to_ascii_lowercase();
        let (ca, tass, size) = match mode {
            Mode::Implied => (m.clone(), m.clone(), 1),
            Mode::Accumulator => {
                if self.flavor == Flavor::Differential && self.rng.chance(50) {
                    (m.clone(), m.clone(), 1)
                } else {
                    (format!("{m} a"), format!("{m} a"), 1)
                }
            }
            Mode::Immediate => {
                let (c, t) = self.immediate();
                (format!("{m} {c}"), format!("{m} {t}"), 2)
            }
            Mode::ZeroPage | Mode::ZeroPageX | Mode::ZeroPageY => {
                let (c, t) = self.zero_page();
                let suffix = match mode {
                    Mode::ZeroPageX => ",x",
                    Mode::ZeroPageY => ",y",
                    _ => "",
                };
                (format!("{m} {c}{suffix}"), format!("{m} {t}{suffix}"), 2)
            }
            Mode::Absolute | Mode::AbsoluteX | Mode::AbsoluteY => {
                let (c, t) = self.absolute(true);
                let suffix = match mode {
                    Mode::AbsoluteX => ",x",
                    Mode::AbsoluteY => ",y",
                    _ => "",
                };
                (format!("{m} {c}{suffix}"), format!("{m} {t}{suffix}"), 3)
            }
            Mode::Indirect => {
                let (c, t) = self.absolute(false);
                (format!("{m} ({c})"), format!("{m} ({t})"), 3)
            }
            Mode::IndirectX => {
                let (c, t) = self.zero_page();
                (format!("{m} ({c},x)"), format!("{m} ({t},x)"), 2)
            }
            Mode::IndirectY => {
                let (c, t) = self.zero_page();
                (format!("{m} ({c}),y"), format!("{m} ({t}),y"), 2)
            }
            Mode::Relative => {
                let (c, t) = match (self.rng.below(3), self.cheap.last().copied()) {
                    (0, Some(_)) => {
                        let c = *self.rng.pick(&self.cheap.clone());
                        (format!("@c{c}"), format!("_c{c}"))
                    }
                    (1, _) => (":-".to_string(), "-".to_string()),
                    _ => (":+".to_string(), "+".to_string()),
                };
                (format!("{m} {c}"), format!("{m} {t}"), 2)
            }
        };
        let indent = if self.rng.chance(10) {
            "\t"
        } else {
            "        "
        };
        let comment = if self.rng.chance(15) {
            " ; a comment"
        } else {
            ""
        };
        self.both(
            &format!("{indent}{ca}{comment}"),
            &format!("        {tass}{comment}"),
        );
        size
    }

    /// Starts a new block: a global label and an unnamed label.
    fn block(&mut self) {
        let n = self.next_label;
        self.next_label += 1;
        self.both(&format!("L_{n}:"), &format!("L_{n}"));
        self.both(":", "+\n-");
        self.cheap.clear();
        self.block_bytes = 0;
    }

    fn data_line(&mut self) -> usize {
        match self.rng.below(if self.flavor == Flavor::Benchmark {
            3
        } else {
            6
        }) {
            0 => {
                let n = 1 + self.rng.below(6) as usize;
                let values: Vec<String> = (0..n)
                    .map(|_| {
                        let v = self.rng.below(256);
                        self.number(v)
                    })
                    .collect();
                let list = values.join(", ");
                self.both(
                    &format!("        .byte {list}"),
                    &format!("        .byte {list}"),
                );
                n
            }
            1 => {
                let k = self.label();
                let (c, _) = *self.rng.pick(&ABS_CONSTS);
                self.both(
                    &format!("        .word L_{k}, {c}"),
                    &format!("        .word L_{k}, {c}"),
                );
                4
            }
            2 => {
                let n = 1 + self.rng.below(4) as usize;
                self.both(&format!("        .res {n}"), &format!("        .fill {n}"));
                n
            }
            3 => {
                let e = self.const_expr(2);
                self.ca_only(&format!("        .byte <({e}), \"Hi\""));
                3
            }
            4 => {
                let k = self.label();
                self.ca_only(&format!("        .dbyt L_{k}, $1234"));
                4
            }
            _ => {
                let k = self.label();
                self.ca_only(&format!(
                    "        .lobytes L_{k}, absc1\n        .hibytes L_{k}, absc1"
                ));
                self.lines += 1;
                4
            }
        }
    }

    fn macro_call(&mut self) -> usize {
        if self.flavor == Flavor::Benchmark {
            let (z, _) = *self.rng.pick(&ZP_CONSTS[..3]);
            let (a, _) = *self.rng.pick(&ABS_CONSTS);
            self.both(
                &format!("        add16 {z}, {a}"),
                &format!("        #add16 {z}, {a}"),
            );
            return 13;
        }
        match self.rng.below(4) {
            0 => {
                let (z, _) = *self.rng.pick(&ZP_CONSTS[..3]);
                let k = self.label();
                self.ca_only(&format!("        add16 {z}, L_{k}"));
                13
            }
            1 => {
                let n = 1 + self.rng.below(255);
                self.ca_only(&format!("        wait {n}"));
                // `.local` labels are normal labels: they end cheap scopes.
                self.cheap.clear();
                5
            }
            2 => {
                let args = match self.rng.below(3) {
                    0 => "1".to_string(),
                    1 => "1, {2, 3}".to_string(),
                    _ => format!("$FF, 2, <L_{}", self.label()),
                };
                self.ca_only(&format!("        emit {args}"));
                4
            }
            _ => {
                let value = self.rng.below(256);
                self.ca_only(&format!("        store {{#{value}}}, zpv1"));
                4
            }
        }
    }

    /// A `.proc` or `.scope` (maybe with one nested inside) that uses the
    /// global names `sh0..sh3` (labels) and `shv0..shv3` (zero-page
    /// constants) before it may define its own of the same names, which
    /// ca65 binds to the scope's own where it defines one, else to the
    /// outer one; then `::` paths into it and out of it. About 40 bytes
    /// at most, so that branches around it still reach.
    fn scope_unit(&mut self) -> usize {
        let n = self.scopes;
        self.scopes += 1;
        let mut text = String::new();
        let (size, defined) = self.scope_body(&format!("S_{n}"), &mut text, 0);
        let k = self.rng.below(4) as usize;
        let _ = writeln!(text, "        lda ::shv{k}");
        if defined[k] {
            let _ = write!(text, "        jmp S_{n}::sh{k}");
        } else {
            let _ = write!(text, "        jmp ::sh{k}");
        }
        self.lines += text.lines().count().saturating_sub(1);
        self.ca_only(&text);
        // The scope's labels are normal symbols: cheap locals end here.
        self.cheap.clear();
        size + 5
    }

    /// One scope into `text` (another nested once at most): its size and
    /// which of `sh0..sh3` it defines.
    fn scope_body(&mut self, name: &str, text: &mut String, depth: u32) -> (usize, [bool; 4]) {
        let kind = if self.rng.chance(50) { "proc" } else { "scope" };
        let defines: [bool; 4] = std::array::from_fn(|_| self.rng.chance(50));
        let values: [bool; 4] = std::array::from_fn(|_| self.rng.chance(40));
        let _ = writeln!(text, ".{kind} {name}");
        let mut size = 0;
        for _ in 0..1 + self.rng.below(4) {
            let k = self.rng.below(4) as usize;
            size += match self.rng.below(8) {
                0 => {
                    let _ = writeln!(text, "        jmp sh{k}");
                    3
                }
                // The global `.set` variable: its last value (the name is
                // bound at the end, as ca65 binds it).
                7 => {
                    let _ = writeln!(text, "        .byte cnt");
                    1
                }
                // A branch only to a label this scope defines: near.
                1 if defines[k] => {
                    let _ = writeln!(text, "        bne sh{k}");
                    2
                }
                2 => {
                    let _ = writeln!(text, "        lda shv{k}");
                    2
                }
                3 if depth == 0 => {
                    let inner = format!("I_{}", self.scopes);
                    self.scopes += 1;
                    self.scope_body(&inner, text, depth + 1).0
                }
                4 => {
                    let c = self.cheap_serial;
                    self.cheap_serial += 1;
                    let _ = writeln!(text, "@w{c}:   dex\n        bne @w{c}");
                    3
                }
                5 => {
                    let _ = writeln!(text, "        wait {}", 1 + self.rng.below(9));
                    5
                }
                _ => {
                    let _ = writeln!(text, "        .byte shv{k}, <sh{k}");
                    2
                }
            };
        }
        for k in 0..4 {
            if defines[k] {
                let _ = writeln!(text, "sh{k}:   nop");
                size += 1;
            }
            if values[k] {
                let value = 0x40 + 0x10 * k as u64 + self.rng.below(16);
                let _ = writeln!(text, "shv{k} = ${value:02X}");
            }
        }
        let _ = writeln!(text, ".end{kind}");
        (size, defines)
    }

    /// A macro or `.define` whose brace argument holds `#` or a comma:
    /// the "is this operand immediate?" idiom.
    fn brace_unit(&mut self) -> usize {
        let arg = match self.rng.below(4) {
            0 => format!("{{#${:02X}}}", self.rng.below(256)),
            1 => format!("{{#<L_{}}}", self.label()),
            2 => "{tab, x}".to_string(),
            _ => format!("zpc{}", self.rng.below(3)),
        };
        if self.rng.chance(50) {
            self.ca_only(&format!("        ldimm {arg}"));
            3
        } else {
            self.ca_only(&format!("        .byte IMM {arg}, 7"));
            2
        }
    }

    /// A unit that exercises a directive; returns its size.
    fn directive_unit(&mut self) -> usize {
        match self.rng.below(10) {
            8 => return self.scope_unit(),
            9 => return self.brace_unit(),
            _ => {}
        }
        match self.rng.below(8) {
            0 => {
                let n = 1 + self.rng.below(4);
                let mul = self.rng.below(5);
                self.ca_only(&format!(
                    ".repeat {n}, i\n        .byte i * {mul} + 1\n.endrepeat"
                ));
                self.lines += 2;
                n as usize
            }
            1 => {
                let level = self.rng.below(4);
                self.ca_only(&format!(
                    ".if DEBUG_LEVEL > {level}\n        lda #{level}\n.elseif DEBUG_LEVEL = {level}\n        ldx #{level}\n.else\n        ldy #{level}\n.endif"
                ));
                self.lines += 6;
                2
            }
            2 => {
                // A proc: a normal label, so cheap locals end here.
                let n = self.procs.len() + 1000 * (1 + self.rng.below(1000) as usize);
                if self.procs.contains(&n) {
                    return 0;
                }
                self.ca_only(&format!(
                    ".proc P_{n}\n        lda #1\ninner:  rts\n.endproc\n        .byte .sizeof(P_{n})"
                ));
                self.lines += 4;
                self.procs.push(n);
                self.cheap.clear();
                4
            }
            3 => {
                self.ca_only("cnt .set cnt + 1\n        .byte cnt");
                self.lines += 1;
                self.sets += 1;
                // Any normal symbol definition ends a cheap-local region.
                self.cheap.clear();
                1
            }
            4 => {
                // Forward cheap local and unnamed skips.
                let c = self.cheap_serial;
                self.cheap_serial += 1;
                self.ca_only(&format!(
                    "        bne @c{c}\n        nop\n@c{c}:  beq :+\n        nop\n:"
                ));
                self.lines += 4;
                self.cheap.push(c);
                6
            }
            5 => {
                let e = self.const_expr(3);
                self.ca_only(&format!(
                    "        .assert (<({e})) < 256, error, \"in range\""
                ));
                0
            }
            6 => {
                let n = self.rng.below(9);
                self.ca_only(&format!(
                    "        lda #.defined(DEBUG_LEVEL) + .defined(nothing_{n})"
                ));
                2
            }
            _ => {
                self.ca_only("        jmp *+3");
                3
            }
        }
    }

    fn statement(&mut self) -> usize {
        let roll = self.rng.below(100);
        if self.flavor == Flavor::Differential && roll < 12 {
            return self.directive_unit();
        }
        match roll {
            0..=5 => self.data_line(),
            6..=8 => self.macro_call(),
            9..=12 => {
                let c = self.cheap_serial;
                self.cheap_serial += 1;
                self.both(&format!("@c{c}:"), &format!("_c{c}"));
                self.cheap.push(c);
                0
            }
            _ => self.instruction(),
        }
    }
}

fn header(g: &mut Gen) {
    for (name, value) in ZP_CONSTS {
        g.both(
            &format!("{name} = ${value:02X}"),
            &format!("{name} = ${value:02X}"),
        );
    }
    for (name, value) in ABS_CONSTS {
        g.both(
            &format!("{name} = ${value:04X}"),
            &format!("{name} = ${value:04X}"),
        );
    }
    g.both(
        ".macro add16 dst, val\n        clc\n        lda dst\n        adc #<(val)\n        sta dst\n        lda dst+1\n        adc #>(val)\n        sta dst+1\n.endmacro",
        "add16   .macro\n        clc\n        lda \\1\n        adc #<(\\2)\n        sta \\1\n        lda \\1+1\n        adc #>(\\2)\n        sta \\1+1\n        .endm",
    );
    g.lines += 8;
    if g.flavor == Flavor::Benchmark {
        return;
    }
    g.ca_only(
        "DEBUG_LEVEL = 2
.define TWO 2
cnt .set 0
        .importzp zpx0, zpx1
        .import libfn0, libfn1, libdata
.struct Point
        xpos    .word
        ypos    .word
        flags   .byte
.endstruct
.enum Color
        black
        white = 5
        red
.endenum
.macro wait count
        .local loop
        ldx #count
loop:   dex
        bne loop
.endmacro
.macro emit a1, a2, a3
        .byte a1
.ifnblank a2
        .byte a2
.endif
.if .paramcount > 2
        .byte a3
.endif
.endmacro
.macro store value, where
        lda value
        sta where
.endmacro
; Names that scopes shadow (`scope_unit`), and the immediate idiom.
shv0 = $20
shv1 = $21
shv2 = $22
shv3 = $23
.define IMM(arg) .match(.left(1,{arg}),#)
.macro ldimm arg
.if .match(.left(1,{arg}),#)
        lda arg
.else
        ldy arg
.endif
.endmacro
        .charmap $61, $41
        .segment \"ZEROPAGE\"
zpv0:   .res 2
zpv1:   .res 1
zpv2:   .res 5
        .code
sh0:    nop
sh1:    nop
sh2:    nop
sh3:    rts",
    );
    g.lines += 57;
}

/// Writes a program of about `lines` lines.
pub(crate) fn generate(seed: u64, lines: usize, flavor: Flavor) -> Program {
    let mut g = Gen {
        rng: Rng::new(seed),
        flavor,
        ops: documented(),
        ca: String::with_capacity(lines * 24),
        tass: String::new(),
        lines: 0,
        next_label: 0,
        max_ref: 0,
        cheap: Vec::new(),
        cheap_serial: 0,
        block_bytes: 0,
        chunk_bytes: 0,
        procs: Vec::new(),
        scopes: 0,
        sets: 0,
        covered: std::collections::BTreeSet::new(),
    };
    header(&mut g);
    if flavor == Flavor::Benchmark {
        g.ca.push_str("        .org $1000\n");
        g.tass.push_str("* = 0\n        .logical $1000\n");
        g.lines += 1;
    }
    g.block();
    while g.lines < lines {
        if g.block_bytes > 80 {
            g.block();
        }
        if flavor == Flavor::Benchmark && g.chunk_bytes > 60_000 {
            // Close the chunk with a label for pending `:+` branches, and
            // start the next one with its own, so no branch crosses.
            g.block();
            g.ca.push_str("        .org $1000\n");
            g.tass.push_str("        .here\n        .logical $1000\n");
            g.lines += 1;
            g.chunk_bytes = 0;
            g.block();
        }
        let size = g.statement();
        g.block_bytes += size;
        g.chunk_bytes += size;
    }
    // Define every label referenced ahead, and a last unnamed label.
    loop {
        g.block();
        g.both("        rts", "        rts");
        if g.next_label > g.max_ref + 1 {
            break;
        }
    }
    if flavor == Flavor::Benchmark {
        g.tass.push_str("        .here\n");
        return Program {
            files: vec![("bench.s".to_string(), std::mem::take(&mut g.ca))],
            tass: g.tass,
            lines: g.lines,
            covered: g.covered,
        };
    }
    // Data segments referring back to code.
    let mut tail = String::new();
    let _ = writeln!(
        tail,
        "        .rodata\ntab:    .byte 1, 2, 3, 4, 5, 6, 7, 8\n        .asciiz \"text\""
    );
    for _ in 0..20 {
        let a = g.rng.below(g.next_label as u64);
        let b = g.rng.below(g.next_label as u64);
        let line = match g.rng.below(6) {
            0 => format!("        .word L_{a}, L_{b}+{}", g.rng.below(9)),
            1 => format!("        .addr libfn{}, libdata", g.rng.below(2)),
            2 => format!("        .byte <L_{a}, >L_{b}, ^L_{a}"),
            3 => format!("        .dbyt L_{a}, <L_{b}"),
            4 => format!("        .word L_{a} - L_{b} + $8000"),
            _ => format!("        .res {}, $EA", 1 + g.rng.below(4)),
        };
        tail.push_str(&line);
        tail.push('\n');
    }
    let _ = writeln!(
        tail,
        "        .data\n        .byte \"abc\", 0\n        .word absc0, *\nalias := L_1\n        .word alias"
    );
    let _ = writeln!(
        tail,
        "        .bss\nbss0:   .res 4\nbss1:   .res 1\nbss2:   .res 16"
    );
    g.ca.push_str(&tail);
    g.lines += tail.lines().count();
    let lib = "\
        .exportzp zpx0, zpx1
        .export libfn0, libfn1, libdata
        .segment \"ZEROPAGE\"
zpx0:   .res 2
zpx1:   .res 1
        .code
libfn0: lda #1
        rts
libfn1: ldx zpx0
        jmp libfn0
        .rodata
libdata: .byte $DE, $AD, $BE, $EF
"
    .to_string();
    Program {
        files: vec![("main.s".to_string(), g.ca), ("lib.s".to_string(), lib)],
        tass: String::new(),
        lines: g.lines,
        covered: g.covered,
    }
}

/// How many documented (mnemonic, mode) pairs there are.
pub(crate) fn documented_count() -> usize {
    documented().len()
}
