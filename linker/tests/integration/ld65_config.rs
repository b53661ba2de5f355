//! ld65 configurations as layouts: what the reader makes of one, and any
//! text (configuration words in any order) read and used to link without
//! a panic, as the corpus test (`tests/tests/cc65_corpus.rs`) holds the
//! results to ld65's.

use isa::objfmt::{ObjectBuilder, SymbolDef};
use linker::layout::{CondesKind, SymbolKind};
use linker::{Layout, MemorySources, Target};
use proptest::prelude::*;

use crate::support::link_with;

const CFG: &str = r#"
# C64-like: areas that follow areas, %S, a weak symbol, a table.
FEATURES { STARTADDRESS: default = $0801; }
SYMBOLS {
    __LOADADDR__:  type = import;
    __STACKSIZE__: type = weak, value = $0800;
    __HIMEM__:     type = weak, value = $D000;
}
MEMORY {
    ZP:       file = "", define = yes, start = $0002, size = $001A;
    LOADADDR: file = %O, start = %S - 2, size = $0002;
    MAIN:     file = %O, define = yes, start = %S, size = __HIMEM__ - __MAIN_START__;
    BSS:      file = "", start = __ONCE_RUN__, size = __HIMEM__ - __STACKSIZE__ - __ONCE_RUN__;
}
SEGMENTS {
    ZEROPAGE: load = ZP, type = zp;
    LOADADDR: load = LOADADDR, type = ro;
    CODE:     load = MAIN, type = ro;
    ONCE:     load = MAIN, type = ro, define = yes, optional = yes;
    BSS:      load = BSS, type = bss, define = yes;
}
FEATURES {
    CONDES: type = constructor, label = __CONSTRUCTOR_TABLE__,
            count = __CONSTRUCTOR_COUNT__, segment = ONCE;
}
"#;

#[test]
fn a_configuration_reads_into_areas_segments_symbols_and_tables() {
    let layout = Layout::from_ld65("c64.cfg", CFG, None).expect("the configuration reads");
    let names: Vec<&str> = layout.areas.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["ZP", "LOADADDR", "MAIN", "BSS"]);
    assert!(!layout.areas[0].output && layout.areas[2].output);
    assert!(
        layout.areas[1].exprs.is_some(),
        "`%S - 2` waits for placement"
    );
    assert_eq!(
        layout.config.start_address, 0x0801,
        "STARTADDRESS's default"
    );
    let with_start = Layout::from_ld65("c64.cfg", CFG, Some(0x1001)).expect("reads");
    assert_eq!(
        with_start.config.start_address, 0x1001,
        "--start wins, as -S"
    );
    let kinds: Vec<SymbolKind> = layout.config.symbols.iter().map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        [SymbolKind::Import, SymbolKind::Weak, SymbolKind::Weak]
    );
    assert_eq!(layout.config.tables[0].kind, CondesKind::Constructor);
    assert!(layout.ld65_alignment && layout.config.ld65);
}

#[test]
fn areas_are_settled_in_order_with_the_objects_symbols() {
    let layout = Layout::from_ld65("c64.cfg", CFG, None).expect("reads");
    let mut object = ObjectBuilder::new();
    let load = object.code("LOADADDR", &[0x01, 0x08]);
    object.global("__LOADADDR__", SymbolDef::Section(load, 0));
    object.code("CODE", &[0xEA; 16]);
    // The object's constant beats the weak value the configuration gives.
    object.global("__HIMEM__", SymbolDef::Absolute(0xA000));
    let linked = link_with(
        &[("prog.o", object.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    let area = |name: &str| {
        linked
            .layout
            .areas
            .iter()
            .find(|a| a.name == name)
            .cloned()
            .expect("the area")
    };
    assert_eq!(
        (area("LOADADDR").start, area("MAIN").start),
        (0x07FF, 0x0801)
    );
    assert_eq!(
        area("MAIN").size,
        0xA000 - 0x0801,
        "__HIMEM__ from the object"
    );
    assert_eq!(area("BSS").start, 0x0811, "__ONCE_RUN__: after the code");
    assert_eq!(
        linked.write(linker::Format::Bin).expect("bin")[..3],
        [0x01, 0x08, 0xEA]
    );
}

const WORDS: &[&str] = &[
    "MEMORY",
    "SEGMENTS",
    "SYMBOLS",
    "FEATURES",
    "FILES",
    "FORMATS",
    "{",
    "}",
    ":",
    ";",
    ",",
    "=",
    "start",
    "size",
    "load",
    "run",
    "type",
    "file",
    "%O",
    "%S",
    "\"x\"",
    "\"\"",
    "$FF",
    "0",
    "12",
    "$FFFFFFFF",
    "-",
    "+",
    "*",
    "/",
    "(",
    ")",
    "M",
    "N",
    "CODE",
    "ro",
    "rw",
    "bss",
    "zp",
    "yes",
    "no",
    "define",
    "fill",
    "fillval",
    "align",
    "offset",
    "optional",
    "CONDES",
    "label",
    "count",
    "segment",
    "STARTADDRESS",
    "default",
    "atari",
    "runad",
    "initad",
    "value",
    "weak",
    "import",
    "export",
    "# c\n",
    "__M_START__",
    "__M_LAST__",
    "%",
    "\n",
];

/// Links one `RTS` with `layout`, whatever comes of it.
fn link_a_return(layout: Layout) {
    let mut object = ObjectBuilder::new();
    object.code("CODE", &[0x60]);
    let _ = link_with(
        &[("p.o", object.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Any sequence of configuration words reads to a layout or an error,
    /// and a layout links a small program to an image or an error.
    #[test]
    fn any_configuration_text_is_read_and_linked_without_a_panic(
        words in proptest::collection::vec(proptest::sample::select(WORDS), 0..60),
        start in proptest::option::of(0u64..0x1_0000),
    ) {
        let text = words.join(" ");
        if let Ok(layout) = Layout::from_ld65("fuzz.cfg", &text, start) {
            link_a_return(layout);
        }
    }

    /// A valid configuration with its characters changed here and there.
    #[test]
    fn a_configuration_with_bytes_changed_is_read_without_a_panic(
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<char>()), 1..6),
    ) {
        let mut text: Vec<char> = CFG.chars().collect();
        for (index, c) in flips {
            let at = index.index(text.len());
            text[at] = c;
        }
        let text: String = text.into_iter().collect();
        if let Ok(layout) = Layout::from_ld65("fuzz.cfg", &text, None) {
            link_a_return(layout);
        }
    }
}
