//! Every diagnostic, rendered as the CLI shows it, as an insta snapshot.

use isa::elf::*;
use isa::objfmt::{AssertAction, Assertion, BinaryOp, Expr, ExprOp};
use isa::objfmt::{ObjectBuilder, SymbolDef};
use linker::{Error, Format, Image, Layout, MemorySources, SymbolFile, Target};

use crate::support::{fake_rom, link_flat, link_with, render};

fn flat() -> Target {
    Target::builtin("flat", Some(0x1000)).expect("flat")
}

/// Links and renders the failure.
fn failure(objects: &[(&str, Vec<u8>)], target: &Target, sources: &MemorySources) -> String {
    let error = link_with(objects, target, &[], sources).expect_err("the link must fail");
    render(&error)
}

fn sources(files: &[(&str, &str)]) -> MemorySources {
    MemorySources {
        files: files
            .iter()
            .map(|(name, text)| ((*name).to_owned(), (*text).to_owned()))
            .collect(),
    }
}

#[test]
fn undefined_symbols_name_every_reference() {
    let mut a = ObjectBuilder::new();
    let code = a.code("CODE", &[0x20, 0, 0, 0x4C, 0, 0]);
    let missing = a.import("print_line", false);
    a.reloc(code, 1, R_MOS_ADDR16, missing, 0);
    a.reloc(code, 4, R_MOS_ADDR16, missing, 0);
    a.source(code, 0, "main.s", 3, 5)
        .source(code, 3, "main.s", 4, 5);
    let mut b = ObjectBuilder::new();
    let code_b = b.code("CODE", &[0xAD, 0, 0]);
    let missing_b = b.import("print_line", false);
    let rom = b.import("PUTHEX", false);
    b.reloc(code_b, 1, R_MOS_ADDR16, missing_b, 0);
    let more = b.code("RODATA", &[0, 0]);
    b.reloc(more, 0, R_MOS_ADDR16, rom, 0);
    // No source map in b.o: the place is object(section+offset).
    let text = "; demo\n.import print_line\n    jsr print_line\n    jmp print_line\n";
    let rendered = failure(
        &[("main.o", a.build()), ("util.o", b.build())],
        &flat(),
        &sources(&[("main.s", text)]),
    );
    insta::assert_snapshot!("undefined_symbols", rendered);
}

#[test]
fn duplicate_symbols_name_both_definitions() {
    let mut a = ObjectBuilder::new();
    let code = a.code("CODE", &[0x60]);
    let first = a.global("init", SymbolDef::Section(code, 0));
    a.symbol_source(first, "a.s", 7, 1);
    let mut b = ObjectBuilder::new();
    let code_b = b.code("CODE", &[0xEA, 0x60]);
    let second = b.global("init", SymbolDef::Section(code_b, 1));
    b.symbol_source(second, "b.s", 2, 1);
    let rendered = failure(
        &[("a.o", a.build()), ("b.o", b.build())],
        &flat(),
        &sources(&[("b.s", "    nop\ninit: rts\n")]),
    );
    insta::assert_snapshot!("duplicate_symbol", rendered);
}

#[test]
fn branch_out_of_range_names_the_distance_and_line() {
    let mut obj = ObjectBuilder::new();
    let mut code = vec![0xD0, 0x00];
    code.extend(std::iter::repeat_n(0xEA, 200));
    let section = obj.code("CODE", &code);
    let far = obj.local("far", SymbolDef::Section(section, 202));
    obj.reloc(section, 1, R_MOS_PCREL_8, far, 0);
    obj.source(section, 0, "loop.s", 2, 5);
    let rendered = failure(
        &[("loop.o", obj.build())],
        &flat(),
        &sources(&[("loop.s", "start:\n    bne far   ; too far\n")]),
    );
    insta::assert_snapshot!("branch_out_of_range", rendered);
}

#[test]
fn range_errors() {
    let mut obj = ObjectBuilder::new();
    let code = obj.code("CODE", &[0xA5, 0, 0xA9, 0, 0, 0, 0]);
    let table = obj.local("table", SymbolDef::Section(code, 0));
    let big = obj.global("BIG", SymbolDef::Absolute(300));
    obj.reloc(code, 1, R_MOS_ADDR8, table, 0);
    obj.reloc(code, 3, R_MOS_IMM8, big, 0);
    let huge = obj.global("HUGE", SymbolDef::Absolute(0x0100_0000));
    obj.reloc(code, 4, R_MOS_ADDR24, huge, 0);
    obj.source(code, 0, "zp.s", 1, 5)
        .source(code, 2, "zp.s", 2, 5)
        .source(code, 4, "zp.s", 3, 5);
    let rendered = failure(
        &[("zp.o", obj.build())],
        &flat(),
        &sources(&[("zp.s", "    lda z:table\n    lda #BIG\n    .faraddr HUGE\n")]),
    );
    insta::assert_snapshot!("range_errors", rendered);
}

#[test]
fn overflow_names_the_amount_and_the_largest_inputs() {
    let rom = fake_rom(&[]);
    let objects: Vec<(String, Vec<u8>)> = [
        ("main.o", 2000),
        ("music.o", 1100),
        ("font.o", 9),
        ("util.o", 3),
    ]
    .iter()
    .map(|(name, size)| {
        let mut obj = ObjectBuilder::new();
        obj.code("CODE", &vec![0xEA; *size]);
        ((*name).to_owned(), obj.build())
    })
    .collect();
    let named: Vec<(&str, Vec<u8>)> = objects
        .iter()
        .map(|(name, bytes)| (name.as_str(), bytes.clone()))
        .collect();
    let error = link_with(
        &named,
        &Target::ScorpionExt,
        &[SymbolFile {
            name: "rom.elf",
            image: &rom,
        }],
        &MemorySources::default(),
    )
    .expect_err("3112 bytes do not fit in 3072");
    insta::assert_snapshot!("overflow", render(&error));
}

#[test]
fn placement_errors() {
    // VECTORS must start at $FFFA but CODE runs past it; zero-page data
    // outside page zero; bytes in an area that is not written; a section
    // the layout does not place.
    let layout = Layout::from_toml(
        "bad.toml",
        r#"
            [[area]]
            name = "ZP"
            start = "$F0"
            size = "$20"
            output = false
            [[area]]
            name = "ROM"
            start = "$FFF0"
            size = 16
            [[segment]]
            name = "ZEROPAGE"
            load = "ZP"
            kind = "zp"
            [[segment]]
            name = "CODE"
            load = "ROM"
            [[segment]]
            name = "VECTORS"
            load = "ROM"
            start = "$FFFA"
            [[segment]]
            name = "DATA"
            load = "ZP"
            kind = "rw"
        "#,
    )
    .expect("layout parses");
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0xEA; 12]);
    obj.code("VECTORS", &[0; 6]);
    obj.zeropage("ZEROPAGE", 0x18);
    obj.data("DATA", &[1]);
    obj.code(".text", &[0x60]);
    let rendered = failure(
        &[("rom.o", obj.build())],
        &Target::Custom(layout),
        &MemorySources::default(),
    );
    insta::assert_snapshot!("placement_errors", rendered);
}

#[test]
fn other_producers_objects_are_checked() {
    let mut cases = Vec::new();
    let mut x86 = ObjectBuilder::new();
    x86.machine(62);
    cases.push(("x86.o", x86.build()));
    let mut c02 = ObjectBuilder::new();
    c02.flags(EF_MOS_ARCH_6502 | EF_MOS_ARCH_65C02);
    cases.push(("c02.o", c02.build()));
    let mut w816 = ObjectBuilder::new();
    w816.flags(EF_MOS_ARCH_W65816);
    cases.push(("w816.o", w816.build()));
    let mut brl = ObjectBuilder::new();
    let text = brl.code(".text", &[0x82, 0, 0]);
    let target = brl.local("there", SymbolDef::Section(text, 0));
    brl.reloc(text, 1, R_MOS_PCREL_16, target, 0);
    cases.push(("brl.o", brl.build()));
    let mut rel = ObjectBuilder::new();
    let code = rel.code("CODE", &[0, 0]);
    let sym = rel.local("x", SymbolDef::Section(code, 0));
    rel.reloc(code, 0, R_MOS_ADDR16, sym, 0).use_rel();
    cases.push(("rel.o", rel.build()));
    let mut outside = ObjectBuilder::new();
    let code = outside.code("CODE", &[0]);
    let sym = outside.local("x", SymbolDef::Section(code, 0));
    outside.reloc(code, 0, R_MOS_ADDR16, sym, 0);
    cases.push(("outside.o", outside.build()));
    let mut exec = ObjectBuilder::new();
    exec.file_type(2);
    cases.push(("exec.o", exec.build()));
    cases.push(("text.o", b"not an object at all".to_vec()));
    let rendered = failure(&cases, &flat(), &MemorySources::default());
    insta::assert_snapshot!("foreign_objects", rendered);
}

#[test]
fn deferred_assertions() {
    let mut obj = ObjectBuilder::new();
    let code = obj.code("CODE", &[0xEA; 4]);
    let start = obj.local("table", SymbolDef::Section(code, 0));
    let end = obj.local("table_end", SymbolDef::Section(code, 4));
    let page_check = |action, message: &str, line| Assertion {
        action,
        file: "table.s".into(),
        line,
        column: 1,
        message: message.into(),
        // >table = >table_end: the table does not cross a page.
        expr: Expr {
            ops: vec![
                ExprOp::Symbol(start.0 as u32),
                ExprOp::Const(0x1100),
                ExprOp::Binary(BinaryOp::Lt),
            ],
        },
    };
    obj.assert(page_check(
        AssertAction::Error,
        "table must be below $1100",
        5,
    ));
    let mut wide = page_check(AssertAction::Warning, "table should be page-aligned", 6);
    wide.expr = Expr {
        ops: vec![
            ExprOp::Symbol(end.0 as u32),
            ExprOp::Const(0xFF),
            ExprOp::Binary(BinaryOp::BitAnd),
            ExprOp::Const(0),
            ExprOp::Binary(BinaryOp::Eq),
        ],
    };
    obj.assert(wide);
    let mut broken = page_check(AssertAction::Error, "never evaluated", 7);
    broken.expr = Expr {
        ops: vec![
            ExprOp::Const(1),
            ExprOp::Const(0),
            ExprOp::Binary(BinaryOp::Div),
        ],
    };
    obj.assert(broken);
    let source = sources(&[(
        "table.s",
        "table:\n  .byte 1,2,3,4\ntable_end:\n\n.assert table >= $1100, error, \"table must be below $1100\"\n.assert <table_end = 0, warning, \"table should be page-aligned\"\n.assert 1/0, error, \"never evaluated\"\n",
    )]);
    // $2000: the error and the invalid one fail, the warning is a warning.
    let target = Target::builtin("flat", Some(0x2000)).expect("flat");
    let error = link_with(&[("table.o", obj.build())], &target, &[], &source)
        .expect_err("the error assertion fails");
    insta::assert_snapshot!("assertions_failed", render(&error));
    // $10FC: all hold except the warning (table_end = $1100 is aligned, so
    // that one holds too); at $1000 only the warning fails.
    let mut passing = ObjectBuilder::new();
    let code = passing.code("CODE", &[0xEA; 3]);
    let end = passing.local("end", SymbolDef::Section(code, 3));
    passing.assert(Assertion {
        action: AssertAction::Warning,
        file: "table.s".into(),
        line: 6,
        column: 1,
        message: "table should be page-aligned".into(),
        expr: Expr {
            ops: vec![
                ExprOp::Symbol(end.0 as u32),
                ExprOp::Const(0x1000),
                ExprOp::Binary(BinaryOp::Eq),
            ],
        },
    });
    let linked = link_with(&[("table.o", passing.build())], &flat(), &[], &source)
        .expect("a warning does not fail the link");
    assert_eq!(linked.warnings.len(), 1);
    assert!(linked.warnings[0].is_warning());
    insta::assert_snapshot!("assertion_warning", render(&linked.warnings[0]));
}

#[test]
fn layout_errors() {
    let syntax = Layout::from_toml(
        "my.toml",
        "[[area]]\nname = \"RAM\"\nstart = \"$zz\"\nsize = 1\n",
    )
    .expect_err("bad number");
    let unknown_area = Layout::from_toml(
        "my.toml",
        "[[area]]\nname = \"RAM\"\nstart = 0\nsize = 16\n\n[[segment]]\nname = \"CODE\"\nload = \"ROM\"\n",
    )
    .expect_err("no ROM area");
    let unknown_key = Layout::from_toml(
        "my.toml",
        "[[area]]\nname = \"RAM\"\nstart = 0\nsize = 16\nfil = true\n",
    )
    .expect_err("typo");
    let target = Target::builtin("c64", None).expect_err("no such target");
    let no_start = Target::builtin("flat", None).expect_err("flat needs --start");
    let start_elsewhere = Target::builtin("scorpion-ext", Some(0x1000)).expect_err("only flat");
    let no_rom = link_with(&[], &Target::ScorpionOs, &[], &MemorySources::default())
        .expect_err("no ROM symbols");
    let all = [
        syntax,
        unknown_area,
        unknown_key,
        target,
        no_start,
        start_elsewhere,
        no_rom,
    ]
    .iter()
    .map(|error| render(error))
    .collect::<Vec<_>>()
    .join("\n");
    insta::assert_snapshot!("layout_errors", all);
}

#[test]
fn warnings_for_ld65_habits() {
    // flat does not align segments: RODATA after 3 bytes of CODE, aligned 4.
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0xEA; 3]);
    let rodata = obj.code("RODATA", &[1, 2, 3, 4]);
    obj.align(rodata, 4);
    let linked = link_flat(&[("a.o", obj.build())], 0x1000).expect("links");
    let rendered: Vec<String> = linked.warnings.iter().map(|w| render(w)).collect();
    insta::assert_snapshot!("misaligned_segment", rendered.join("\n"));
    // A required segment nobody provides.
    let layout = Layout::from_toml(
        "req.toml",
        "[[area]]\nname = \"RAM\"\nstart = \"$400\"\nsize = 16\n[[segment]]\nname = \"CODE\"\nload = \"RAM\"\n[[segment]]\nname = \"HEADER\"\nload = \"RAM\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0x60]);
    let linked = link_with(
        &[("a.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    let rendered: Vec<String> = linked.warnings.iter().map(|w| render(w)).collect();
    insta::assert_snapshot!("empty_segment", rendered.join("\n"));
}

#[test]
fn hook_errors() {
    let mut chain_only = ObjectBuilder::new();
    let code = chain_only.code("CODE", &[0x4C, 0, 0]);
    chain_only.global("__scorpion_chain_loop", SymbolDef::Section(code, 1));
    let mut outside = ObjectBuilder::new();
    outside.code("CODE", &[0x60]);
    outside.global("__scorpion_hook_unknown", SymbolDef::Absolute(0x9000));
    let chain = failure(
        &[("os.o", chain_only.build())],
        &flat(),
        &MemorySources::default(),
    );
    let handler = failure(
        &[("ext.o", outside.build())],
        &flat(),
        &MemorySources::default(),
    );
    insta::assert_snapshot!("hook_errors", format!("{chain}\n{handler}"));
}

#[test]
fn format_and_image_errors() {
    let layout = Layout::from_toml(
        "big.toml",
        "[[area]]\nname = \"BIG\"\nstart = \"$FFF0\"\nsize = \"$1000000\"\n[[segment]]\nname = \"CODE\"\nload = \"BIG\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0xEA; 32]);
    let linked = link_with(
        &[("big.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("areas may exceed 64 KiB");
    let kim = Format::Kim
        .write(&linked.image)
        .expect_err("KIM-1 tape is 16-bit");
    let object_as_image = Image::parse("a.o", &obj.build()).expect_err("not linked");
    let garbage = Image::parse("junk.elf", b"\x7fELF").expect_err("truncated");
    let rendered: Vec<String> = [kim, object_as_image, garbage]
        .iter()
        .map(|e| render(e))
        .collect();
    insta::assert_snapshot!("format_and_image_errors", rendered.join("\n"));
}

#[test]
fn every_error_has_a_code() {
    use miette::Diagnostic;
    let error: Error = Target::builtin("nope", None).expect_err("unknown");
    assert_eq!(
        error.code().map(|c| c.to_string()),
        Some("linker::unknown_target".into())
    );
}

#[test]
fn inconsistent_layouts() {
    let twice = Layout::from_toml(
        "twice.toml",
        "[[area]]\nname = \"RAM\"\nstart = 0\nsize = 16\n[[area]]\nname = \"RAM\"\nstart = 16\nsize = 16\n",
    )
    .expect_err("RAM twice");
    let empty = Layout::from_toml(
        "empty.toml",
        "[[area]]\nname = \"RAM\"\nstart = 0\nsize = 0\n",
    )
    .expect_err("size 0");
    let both = Layout::from_toml(
        "both.toml",
        "[[area]]\nname = \"RAM\"\nstart = 0\nsize = 16\nend = 15\n",
    )
    .expect_err("size and end");
    let rom = fake_rom(&[("USER_RAM_END", 0x0100)]);
    let backwards = link_with(
        &[],
        &Target::ScorpionExt,
        &[SymbolFile {
            name: "odd-rom.elf",
            image: &rom,
        }],
        &MemorySources::default(),
    )
    .expect_err("RAM end below its start");
    // A user symbol that the layout also defines.
    let layout = Layout::from_toml(
        "def.toml",
        "[[area]]\nname = \"RAM\"\nstart = \"$400\"\nsize = 16\n[[segment]]\nname = \"CODE\"\nload = \"RAM\"\ndefine = true\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0x60]);
    obj.global("__CODE_RUN__", SymbolDef::Absolute(1));
    let clash = link_with(
        &[("a.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect_err("defined twice");
    let all = [twice, empty, both, backwards, clash]
        .iter()
        .map(|error| render(error))
        .collect::<Vec<_>>()
        .join("\n");
    insta::assert_snapshot!("inconsistent_layouts", all);
}

#[test]
fn a_failed_link_still_shows_its_warnings() {
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0xEA; 3]);
    let rodata = obj.code("RODATA", &[0, 0]);
    obj.align(rodata, 2);
    let missing = obj.import("nowhere", false);
    obj.reloc(rodata, 0, R_MOS_ADDR16, missing, 0);
    let error = link_flat(&[("a.o", obj.build())], 0x1000).expect_err("undefined");
    insta::assert_snapshot!("failure_with_warning", render(&error));
}

#[test]
fn overflow_past_a_fixed_segment_counts_the_furthest_byte() {
    let layout = Layout::from_toml(
        "rom.toml",
        "[[area]]\nname = \"ROM\"\nstart = \"$FFF0\"\nsize = 16\n[[segment]]\nname = \"CODE\"\nload = \"ROM\"\n[[segment]]\nname = \"VECTORS\"\nload = \"ROM\"\nstart = \"$FFFA\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0xEA; 20]);
    obj.code("VECTORS", &[0; 6]);
    let rendered = failure(
        &[("big.o", obj.build())],
        &Target::Custom(layout),
        &MemorySources::default(),
    );
    insta::assert_snapshot!("overflow_past_fixed_segment", rendered);
    let filled = Layout::from_toml(
        "huge.toml",
        "[[area]]\nname = \"ALL\"\nstart = 0\nsize = \"$100000000\"\nfill = true\n",
    )
    .expect_err("a 4 GiB filled area");
    insta::assert_snapshot!("filled_area_too_big", render(&filled));
}

#[test]
fn a_hook_into_bytes_that_run_elsewhere_is_refused() {
    let layout = Layout::from_toml(
        "copy.toml",
        "[[area]]\nname = \"RAM\"\nstart = \"$0400\"\nsize = \"$100\"\noutput = false\n\
         [[area]]\nname = \"KIM\"\nstart = \"$1000\"\nsize = \"$100\"\n\
         [[segment]]\nname = \"CODE\"\nload = \"KIM\"\n\
         [[segment]]\nname = \"DATA\"\nload = \"KIM\"\nrun = \"RAM\"\nkind = \"rw\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    obj.code("CODE", &[0x60]);
    let data = obj.data("DATA", &[0x4C, 0, 0]);
    obj.global("__scorpion_hook_unknown", SymbolDef::Section(data, 0));
    let error = link_with(
        &[("copy.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect_err("the handler needs a start-up copy first");
    let text = render(&error);
    assert!(text.contains("runs where it loads"), "{text}");
    assert!(text.contains("$0400"), "{text}");
}
