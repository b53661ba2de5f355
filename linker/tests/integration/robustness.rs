//! No input makes the linker or the image reader panic: corrupted objects
//! and images give errors.

use linker::{Format, Image, MemorySources, SymbolFile, Target};
use proptest::prelude::*;

use crate::round_trip::extension;
use crate::support::{fake_rom, link_with};

fn link_mutated(objects: &[(&str, Vec<u8>)]) {
    let rom = fake_rom(&[("PUTCH", 0xFF00), ("CMD_DONE", 0xF123)]);
    let files = [SymbolFile {
        name: "rom.elf",
        image: &rom,
    }];
    if let Ok(linked) = link_with(
        objects,
        &Target::ScorpionExt,
        &files,
        &MemorySources::default(),
    ) {
        for format in Format::ALL {
            let _ = format.write(&linked.image);
        }
        let _ = linked.map();
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn corrupted_objects_are_errors_not_panics(
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
        truncate in any::<bool>(),
    ) {
        let mut objects = extension();
        let bytes = &mut objects[0].1;
        for (index, value) in &flips {
            let at = index.index(bytes.len());
            bytes[at] = *value;
        }
        if truncate {
            let len = cut.index(bytes.len());
            bytes.truncate(len);
        }
        link_mutated(&objects);
    }

    #[test]
    fn corrupted_images_are_errors_not_panics(
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
    ) {
        let linked = crate::round_trip::link_extension();
        let mut bytes = Format::Elf.write(&linked.image).expect("writes");
        for (index, value) in &flips {
            let at = index.index(bytes.len());
            bytes[at] = *value;
        }
        let _ = Image::parse("x.elf", &bytes);
        let len = cut.index(bytes.len());
        let _ = Image::parse("x.elf", &bytes[..len]);
    }
}
