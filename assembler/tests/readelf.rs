//! binutils' `readelf -a` reads our objects without a warning or an error:
//! every section, relocation section, symbol table and our metadata
//! sections are well-formed ELF as other tools see it.

use std::path::Path;
use std::process::Command;

use assembler::{MemorySource, Options};

const SOURCE: &str = r#"
        .importzp zp_import
        .import far, near
        .export entry, table
        .segment "ZEROPAGE"
ptr:    .res 2
        .bss
buffer: .res 32
        .data
table:  .word entry, buffer, far
        .dbyt far
        .rodata
text:   .asciiz "hello"
        .code
entry:  lda #<text
        sta ptr
        lda #>text
        sta ptr+1
        ldy #0
@loop:  lda (ptr),y
        beq :+
        jsr near
        iny
        bne @loop
:       lda zp_import
        lda #^far
        jmp (table)
        .assert * - entry < 256, error, "entry fits in a page"
        .org $C000
fixed:  jmp fixed
"#;

#[test]
fn readelf_reads_our_objects_without_warnings() {
    let Some(readelf) =
        scorpion_tests::tools::require("readelf", "readelf_reads_our_objects_without_warnings")
    else {
        return;
    };
    let mut objects = vec![(
        "mixed.s".to_string(),
        assembler::assemble_str("mixed.s", SOURCE, &Options::default())
            .expect("the test program assembles")
            .object,
    )];
    // Every ok_ case of the case tests too.
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cases");
    for dir in std::fs::read_dir(&cases).expect("the cases directory") {
        let dir = dir.expect("an entry").path();
        let mut source = MemorySource::new();
        let mut names = Vec::new();
        for file in std::fs::read_dir(&dir).expect("a case directory") {
            let file = file.expect("an entry").path();
            let name = file
                .file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned();
            source.insert(name.clone(), std::fs::read(&file).expect("a case file"));
            if name.starts_with("ok_") && name.ends_with(".s") {
                names.push(name);
            }
        }
        let options = Options {
            builtin_includes: [(
                "builtin.inc".to_string(),
                b"BUILTIN_VALUE = 1\n.macro builtin_macro\n.endmacro\n".to_vec(),
            )]
            .into_iter()
            .collect(),
            ..Options::default()
        };
        for name in names {
            let assembly = assembler::assemble(&source, Path::new(&name), &options)
                .expect("an ok_ case assembles");
            objects.push((name, assembly.object));
        }
    }
    assert!(objects.len() > 20, "the cases were found");
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, object) in objects {
        let path = dir.path().join(format!("{name}.o"));
        std::fs::write(&path, &object).expect("write the object");
        let output = Command::new(&readelf)
            .args(["-a", "-W"])
            .arg(&path)
            .output()
            .expect("readelf runs");
        let stdout = String::from_utf8_lossy(&output.stdout);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "{name}: readelf failed:\n{stderr}");
        assert!(
            stderr.trim().is_empty() && !stdout.contains("Warning") && !stdout.contains("Error"),
            "{name}: readelf complained:\n{stderr}\n{stdout}"
        );
        assert!(
            stdout.contains("REL (Relocatable file)"),
            "{name}: {stdout}"
        );
        assert!(
            stdout.contains(".scorpion.srcmap"),
            "{name}: the source map is listed"
        );
    }
}
