//! Intel HEX, S-record and KIM-1 tape outputs decode, with Debian's srecord
//! tools, to the same bytes as the raw binary.

use std::path::Path;
use std::process::Command;

use isa::objfmt::ObjectBuilder;
use linker::{Format, Image, Layout, MemorySources, Target};

use crate::round_trip::link_extension;
use crate::support::link_with;

/// Decodes `text` (in srec_cat's `input_format`) to a binary that starts at
/// `start`, with srec_cat.
fn decode(srec_cat: &Path, dir: &Path, text: &[u8], input_format: &str, start: u32) -> Vec<u8> {
    let input = dir.join("in.txt");
    let output = dir.join("out.bin");
    std::fs::write(&input, text).expect("write the records");
    let result = Command::new(srec_cat)
        .arg(&input)
        .arg(input_format)
        .arg("-offset")
        .arg(format!("-{start:#x}"))
        .arg("-o")
        .arg(&output)
        .arg("-binary")
        .output()
        .expect("srec_cat runs");
    assert!(
        result.status.success(),
        "srec_cat {input_format}: {}\n{}",
        String::from_utf8_lossy(&result.stderr),
        String::from_utf8_lossy(text)
    );
    std::fs::read(&output).expect("srec_cat wrote the binary")
}

fn check_image(srec_cat: &Path, image: &Image) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let bin = Format::Bin.write(image).expect("bin");
    let start = image.areas[0].load;
    // One contiguous run of bytes, so the raw binary is what srec_cat
    // fills between the lowest and highest address.
    for (format, flag) in [
        (Format::Ihex, "-intel"),
        (Format::Srec, "-motorola"),
        (Format::Kim, "-mos_technologies"),
    ] {
        let text = format.write(image).expect("writes");
        let decoded = decode(srec_cat, dir.path(), &text, flag, start);
        assert_eq!(decoded, bin, "{format} decodes to different bytes");
    }
}

#[test]
fn record_formats_decode_to_the_raw_binary() {
    let test = "linker formats::record_formats_decode_to_the_raw_binary";
    let Some(srec_cat) = scorpion_tests::tools::require("srec_cat", test) else {
        return;
    };
    // An extension (one area at $0400, a few dozen bytes).
    check_image(&srec_cat, &link_extension().image);
    // 3000 bytes of varied data: many records, KIM's 24-byte records and
    // a ROM that is filled to its end.
    let layout = Layout::from_toml(
        "rom.toml",
        "[[area]]\nname = \"ROM\"\nstart = \"$F000\"\nsize = \"$1000\"\nfill = true\nfill-value = \"$FF\"\n[[segment]]\nname = \"CODE\"\nload = \"ROM\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    let data: Vec<u8> = (0..3000u32).map(|i| (i * 7 + i / 251) as u8).collect();
    obj.code("CODE", &data);
    let linked = link_with(
        &[("rom.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    assert_eq!(Format::Bin.write(&linked.image).expect("bin").len(), 0x1000);
    check_image(&srec_cat, &linked.image);
}

#[test]
fn srecords_above_64k_use_wider_addresses() {
    let test = "linker formats::srecords_above_64k_use_wider_addresses";
    let Some(srec_cat) = scorpion_tests::tools::require("srec_cat", test) else {
        return;
    };
    let layout = Layout::from_toml(
        "big.toml",
        "[[area]]\nname = \"BIG\"\nstart = \"$FF00\"\nsize = \"$1000000\"\n[[segment]]\nname = \"CODE\"\nload = \"BIG\"\n",
    )
    .expect("parses");
    let mut obj = ObjectBuilder::new();
    let data: Vec<u8> = (0..1000u32).map(|i| (i % 253) as u8).collect();
    obj.code("CODE", &data);
    let linked = link_with(
        &[("big.o", obj.build())],
        &Target::Custom(layout),
        &[],
        &MemorySources::default(),
    )
    .expect("links");
    let dir = tempfile::tempdir().expect("temporary directory");
    let bin = Format::Bin.write(&linked.image).expect("bin");
    for (format, flag) in [(Format::Ihex, "-intel"), (Format::Srec, "-motorola")] {
        let text = format.write(&linked.image).expect("writes");
        assert_eq!(
            decode(&srec_cat, dir.path(), &text, flag, 0xFF00),
            bin,
            "{format}"
        );
    }
}

/// binutils' readelf reads our images (and the objects ObjectBuilder writes)
/// without a warning, load/run split and hooks section included.
#[test]
fn readelf_reads_images_without_warnings() {
    let test = "linker formats::readelf_reads_images_without_warnings";
    let Some(readelf) = scorpion_tests::tools::require("readelf", test) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    let extension = link_extension();
    let files = [
        ("ext.elf", Format::Elf.write(&extension.image).expect("elf")),
        ("main.o", crate::round_trip::extension().remove(0).1),
    ];
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).expect("write");
        let output = Command::new(&readelf)
            .args(["-a", "-W"])
            .arg(&path)
            .output()
            .expect("readelf runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{name}: {stderr}");
        assert!(
            !stderr.contains("Warning") && !stderr.contains("Error"),
            "{name}: {stderr}"
        );
        if name.ends_with(".elf") {
            assert!(stdout.contains("EXEC (Executable file)"), "{stdout}");
            assert!(stdout.contains("LOAD"), "{stdout}");
            assert!(stdout.contains(".scorpion.hooks"), "{stdout}");
        } else {
            assert!(stdout.contains("REL (Relocatable file)"), "{stdout}");
            assert!(stdout.contains(".relaCODE"), "{stdout}");
        }
    }
}
