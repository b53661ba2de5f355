//! Issue 22: the examples' layouts stay inside the memory an upload may
//! write (the ROM's map: the user zero page, user RAM up to USER_RAM_END,
//! the KIM bus), checked when the image is built, with advice that fits a
//! layout file. `examples/checksum/checksum.toml` ended its RAM at $0FFF,
//! over the ROM's INJECT queue and extension table; the link succeeded and
//! only the upload refused.

use std::path::Path;

use crate::{scorpion, transcript};

fn examples() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples")
}

/// Every example project builds: each of its layouts is checked against
/// the ROM's map as it links.
#[test]
fn every_example_layout_links_inside_the_roms_memory_map() {
    let mut built = 0;
    for entry in std::fs::read_dir(examples()).expect("examples/") {
        let dir = entry.expect("an entry").path();
        if !dir.join("Scorpion.toml").is_file() {
            continue;
        }
        let copy = tempfile::tempdir().expect("a temporary directory");
        for file in std::fs::read_dir(&dir).expect("the example") {
            let file = file.expect("an entry").path();
            if file.is_file() {
                std::fs::copy(&file, copy.path().join(file.file_name().expect("a name")))
                    .expect("copy");
            }
        }
        let output = scorpion(copy.path(), &["build"]);
        assert_eq!(
            output.status.code(),
            Some(0),
            "{}:\n{}",
            dir.display(),
            transcript(&output)
        );
        built += 1;
    }
    assert!(built >= 4, "{built} example projects");
}

/// A layout whose RAM runs over the ROM's own is refused when it links,
/// saying which area, where the memory ends, and the line to write.
#[test]
fn a_layout_over_the_roms_own_ram_is_refused_at_link_time() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for file in ["Scorpion.toml", "checksum.s"] {
        std::fs::copy(
            examples().join("checksum").join(file),
            dir.path().join(file),
        )
        .expect("copy");
    }
    let layout =
        std::fs::read_to_string(examples().join("checksum/checksum.toml")).expect("the layout");
    assert!(layout.contains("end = \"$0F3F\""), "{layout}");
    std::fs::write(
        dir.path().join("checksum.toml"),
        layout.replace("end = \"$0F3F\"", "end = \"$0FFF\""),
    )
    .expect("write");
    let output = scorpion(dir.path(), &["build"]);
    assert_eq!(output.status.code(), Some(1), "{}", transcript(&output));
    // miette wraps the message: compare words, without its margins.
    let words = |text: &str| {
        text.split_whitespace()
            .filter(|word| *word != "│")
            .collect::<Vec<_>>()
            .join(" ")
    };
    let stderr = words(&String::from_utf8_lossy(&output.stderr));
    for said in [
        "area `RAM` at $0C00-$0FFF",
        "past the end of the memory an upload may write ($0400-$0F3F)",
        "`end = \"$0F3F\"` in checksum.toml's area `RAM`",
    ] {
        assert!(stderr.contains(said), "{said}\n{}", transcript(&output));
    }
    assert!(!dir.path().join("target/scorpion/checksum.elf").exists());
}
