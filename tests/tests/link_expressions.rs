//! What the linker computes for ca65 programs, when it cannot: a field
//! out of its range, a re-exported name whose import nothing defines, a
//! table whose helper routine is missing; each named at its place.

fn objects(files: &[(&str, &str)]) -> Vec<(String, Vec<u8>)> {
    files
        .iter()
        .map(|(name, text)| {
            let assembly = assembler::assemble_str(name, text, &assembler::Options::default())
                .unwrap_or_else(|e| panic!("{name} assembles: {e}"));
            ((*name).to_owned(), assembly.object)
        })
        .collect()
}

fn link(files: &[(&str, &str)], cfg: &str) -> Result<linker::Linked, String> {
    let objects = objects(files);
    let inputs: Vec<linker::Input<'_>> = objects
        .iter()
        .map(|(name, bytes)| linker::Input { name, bytes })
        .collect();
    let sources = linker::MemorySources {
        files: files
            .iter()
            .map(|(name, text)| ((*name).to_owned(), (*text).to_owned()))
            .collect(),
    };
    let layout = linker::Layout::from_ld65("test.cfg", cfg, None).map_err(|e| format!("{e:?}"))?;
    linker::link(
        &inputs,
        &linker::LinkOptions {
            target: &linker::Target::Custom(layout),
            just_symbols: &[],
            sources: &sources,
        },
    )
    .map_err(|error| format!("{:?}", miette::Report::new(error)))
}

const CFG: &str = "MEMORY { M: start = $1000, size = $1000; }\nSEGMENTS { CODE: load = M; RODATA: load = M, optional = yes; }\n";

#[test]
fn a_computed_field_out_of_range_is_named_with_its_value() {
    let error = link(
        &[
            (
                "main.s",
                ".import ext\n.code\n.byte ext * 2\n.word ext * 2\n",
            ),
            ("ext.s", ".export ext\next = $100\n"),
        ],
        CFG,
    )
    .expect_err("$200 does not fit a byte");
    assert!(error.contains("main.s:3:1"), "{error}");
    assert!(error.contains("512 ($200)"), "{error}");
    assert!(error.contains("a byte (0 to 255)"), "{error}");
    assert!(!error.contains("main.s:4"), "the word holds $200: {error}");
}

#[test]
fn a_re_exported_name_whose_import_is_missing_is_named() {
    let error = link(
        &[
            (
                "alias.s",
                ".import nowhere\n.export alias\nalias = nowhere + 1\n",
            ),
            ("main.s", ".import alias\n.code\njmp alias\n"),
        ],
        CFG,
    )
    .expect_err("nothing defines `nowhere`");
    assert!(error.contains("the value of `alias`"), "{error}");
    assert!(error.contains("`nowhere`"), "{error}");
}

#[test]
fn a_table_that_needs_a_missing_helper_is_an_error_at_the_configuration() {
    let cfg = format!(
        "{CFG}FEATURES {{ CONDES: type = interruptor, label = __INTERRUPTOR_TABLE__, segment = RODATA, import = __CALLIRQ__; }}\n"
    );
    let program = [(
        "irq.s",
        ".interruptor on_irq\n.import __INTERRUPTOR_TABLE__\n.code\non_irq: rts\n.word __INTERRUPTOR_TABLE__\n",
    )];
    let error = link(&program, &cfg).expect_err("__CALLIRQ__ is missing");
    assert!(error.contains("imports `__CALLIRQ__`"), "{error}");
    // Without entries the helper is not needed, as in ld65.
    let empty = [(
        "main.s",
        ".import __INTERRUPTOR_TABLE__\n.code\n.word __INTERRUPTOR_TABLE__\n",
    )];
    let linked = link(&empty, &cfg).expect("an empty table needs no helper");
    let bytes = linked.write(linker::Format::Bin).expect("bin");
    assert_eq!(
        bytes,
        [0x02, 0x10],
        "the empty table sits at the end of RODATA"
    );
}
