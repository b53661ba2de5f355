//! No input makes the assembler panic: random bytes, random token soup in
//! ca65's vocabulary, and the case files mutated (lines deleted, repeated,
//! swapped, tokens inserted). Every run must end in an object or in
//! diagnostics, and every diagnostic must point inside a file it names.
//!
//! The coverage-guided counterpart is the cargo-fuzz target in
//! `assembler/fuzz/` (see its README for how long it ran).

use std::path::Path;

use assembler::{MemorySource, Options};
use proptest::prelude::*;

/// Assembles `text` as `t.s` (with `inc.s` includable) and checks the
/// result is well-formed.
fn check(text: &[u8]) {
    let source = MemorySource::new().with("t.s", text.to_vec()).with(
        "inc.s",
        b"inc_value = 1\n.macro inc_macro p\n lda #p\n.endmacro\n".to_vec(),
    );
    let options = Options {
        listing: true,
        max_errors: 20,
        ..Options::default()
    };
    match assembler::assemble(&source, Path::new("t.s"), &options) {
        Ok(assembly) => {
            assert!(assembly.object.starts_with(b"\x7FELF"), "an ELF object");
            goblin::elf::Elf::parse(&assembly.object).expect("our object parses");
            assert!(assembly.listing.is_some());
        }
        Err(error) => {
            assert!(
                !error.diagnostics().is_empty(),
                "a failure carries diagnostics"
            );
            for diagnostic in error.diagnostics() {
                if let Some(location) = diagnostic.location() {
                    assert!(location.line >= 1 && location.column >= 1, "{location}");
                }
                // Rendering must not panic either.
                let _ = format!("{:?}", miette::Report::new(diagnostic.clone()));
            }
        }
    }
}

const VOCABULARY: &[&str] = &[
    // ca65's token functions, features and linker-side directives.
    ".left",
    ".mid",
    ".right",
    ".concat",
    ".string",
    ".ident",
    ".sprintf",
    ".tcount",
    ".match",
    ".xmatch",
    "\"%d\"",
    ".feature c_comments, string_escapes, dollar_is_pc, labels_without_colons\n",
    ".feature pc_assignment, bracket_as_indirect, loose_string_term\n",
    ".linecont +\n",
    "/*",
    "*/",
    "\\",
    "[",
    "]",
    ".constructor",
    ".condes",
    ".forceimport",
    ".faraddr",
    ".addrsize",
    ".cpu",
    ".macpack cpu\n",
    "lda",
    "sta",
    "ldx",
    "jmp",
    "jsr",
    "bne",
    "beq",
    "rts",
    "asl",
    "inc",
    "lax",
    "nop",
    "brk",
    ".byte",
    ".word",
    ".dbyt",
    ".dword",
    ".res",
    ".asciiz",
    ".align",
    ".org",
    ".reloc",
    ".segment",
    "\"CODE\"",
    "\"ZEROPAGE\"",
    ": zeropage",
    ".code",
    ".bss",
    ".zeropage",
    ".import",
    ".importzp",
    ".export",
    ".global",
    ".macro",
    ".endmacro",
    ".local",
    ".exitmacro",
    ".repeat",
    ".endrepeat",
    ".if",
    ".elseif",
    ".else",
    ".endif",
    ".ifdef",
    ".ifblank",
    ".define",
    ".undefine",
    ".struct",
    ".endstruct",
    ".union",
    ".endunion",
    ".enum",
    ".endenum",
    ".tag",
    ".charmap",
    ".assert",
    ".error",
    ".warning",
    ".out",
    ".proc",
    ".endproc",
    ".scope",
    ".endscope",
    ".set",
    ".include",
    "\"inc.s\"",
    "\"t.s\"",
    ".incbin",
    ".setcpu",
    "\"6502X\"",
    ".sizeof",
    ".defined",
    ".lobyte",
    ".hibyte",
    ".paramcount",
    ".blank",
    ".strlen",
    ".mod",
    ".and",
    ".or",
    ".xor",
    ".not",
    "inc_macro",
    "name",
    "other",
    "@cheap",
    ":",
    ":+",
    ":-",
    ":++",
    "::",
    ":=",
    "=",
    "a",
    "x",
    "y",
    "z:",
    "a:",
    "#",
    "(",
    ")",
    "{",
    "}",
    ",",
    "+",
    "-",
    "*",
    "/",
    "&",
    "|",
    "^",
    "~",
    "!",
    "<",
    ">",
    "<=",
    ">=",
    "<>",
    "<<",
    ">>",
    "&&",
    "||",
    "$12",
    "$1234",
    "%101",
    "0",
    "1",
    "255",
    "256",
    "65536",
    "$FFFFFFFF",
    "'a'",
    "\"str\"",
    ";c",
    "\n",
    "\n",
    "\n",
    "\n",
];

fn soup() -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(prop::sample::select(VOCABULARY), 0..200).prop_map(|words| {
        let mut text = String::new();
        for word in words {
            text.push_str(word);
            text.push(' ');
        }
        text.into_bytes()
    })
}

/// The case sources, for mutation.
fn corpus() -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cases");
    let mut files = Vec::new();
    let mut dirs = vec![root];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("the cases directory is readable") {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|ext| ext == "s") {
                files.push(std::fs::read(&path).expect("a case file"));
            }
        }
    }
    files.sort();
    files
}

#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(usize),
    RepeatLine(usize),
    SwapLines(usize, usize),
    Insert(usize, &'static str),
    Truncate(usize),
    FlipByte(usize, u8),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::RepeatLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        (any::<usize>(), prop::sample::select(VOCABULARY))
            .prop_map(|(at, word)| Mutation::Insert(at, word)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Mutation::FlipByte(at, byte)),
    ]
}

fn mutate(text: &[u8], mutations: &[Mutation]) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = text.split(|b| *b == b'\n').map(<[u8]>::to_vec).collect();
    for m in mutations {
        let n = lines.len().max(1);
        match m {
            Mutation::DeleteLine(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Mutation::RepeatLine(i) if !lines.is_empty() => {
                let line = lines[i % n].clone();
                lines.insert(i % n, line);
            }
            Mutation::SwapLines(a, b) if !lines.is_empty() => lines.swap(a % n, b % n),
            Mutation::Insert(at, word) if !lines.is_empty() => {
                let line = &mut lines[at % n];
                let pos = at % (line.len() + 1);
                line.splice(pos..pos, word.bytes().chain(std::iter::once(b' ')));
            }
            Mutation::Truncate(at) if !lines.is_empty() => {
                let line = &mut lines[at % n];
                let keep = at % (line.len() + 1);
                line.truncate(keep);
            }
            Mutation::FlipByte(at, byte) if !lines.is_empty() => {
                let line = &mut lines[at % n];
                if !line.is_empty() {
                    let len = line.len();
                    line[at % len] = *byte;
                }
            }
            _ => {}
        }
    }
    lines.join(&b'\n')
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..2048)) {
        check(&bytes);
    }

    #[test]
    fn token_soup_never_panics(text in soup()) {
        check(&text);
    }

    #[test]
    fn mutated_cases_never_panic(index in any::<usize>(), mutations in prop::collection::vec(mutation(), 1..8)) {
        let files = corpus();
        let text = mutate(&files[index % files.len()], &mutations);
        check(&text);
    }
}

#[test]
fn pathological_inputs_end_with_errors() {
    // Deep parentheses, huge repeats, long lines, many errors: bounded.
    let deep = format!(".byte {}1{}\n", "(".repeat(5000), ")".repeat(5000));
    check(deep.as_bytes());
    check(b".repeat 1000000\n.repeat 1000000\nnop\n.endrepeat\n.endrepeat\n");
    check(b".res $FFFFFFFF\n");
    check(b".macro m\nm\nm\n.endmacro\nm\n");
    check(b".define A B\n.define B A\nlda #A\n");
    check(&vec![b'x'; 100_000]);
    // A struct whose `.union` never closes, inside a `.repeat`: reading
    // members must stop at the end of the expansion (found by cargo-fuzz;
    // it used to restart the expansion forever).
    check(b".repeat 2\n.struct s\n.union\nm .byte\n.endrepeat\n");
    check(b".macro m\n.struct s\nf .byte\n.endmacro\nm\nm\n");
    // A macro whose argument contains itself doubles its line at every
    // level (found by cargo-fuzz: it used to exhaust memory).
    check(b".macro grow n\n        grow n n\n.endmacro\n        grow 1\n");
    check(b".define TWICE(v) v v\n.define X TWICE(X)\n        .byte X\n");
    // Forward definitions that double at each step: evaluated once each.
    let mut doubling = String::from("a0 = later + later\n");
    for i in 1..60 {
        doubling.push_str(&format!("a{i} = a{} + a{}\n", i - 1, i - 1));
    }
    doubling.push_str(&" .word a59 & 1\n".repeat(500));
    doubling.push_str("later = 0\n");
    check(doubling.as_bytes());
    check("é ü\u{0}\r\n\t;\u{feff}".as_bytes());
    let many_errors = ".byte 300\n".repeat(10_000);
    check(many_errors.as_bytes());
}
