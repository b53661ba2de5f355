//! The reference ROM's build and every copy of its facts: the image our
//! tools build equals ca65/ld65's, the symbol constants equal the linked
//! symbol table, `examples/scorpion.inc` equals the generated include file,
//! the ROM's `hardware.inc` equals the emulator's register map, and every
//! name docs/PROTOCOL.md section 4 fixes is exported.

use std::path::{Path, PathBuf};
use std::process::Command;

use emulator::board::map;
use romlib::symbols;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the workspace")
        .to_path_buf()
}

/// The names docs/PROTOCOL.md section 4 decides, which every build of the ROM
/// must export.
const PLATFORM_NAMES: [&str; 17] = [
    "HOOK_UNKNOWN",
    "HOOK_LOOP",
    "CMD_DONE",
    "CMDBUF",
    "CMDLEN",
    "PUTCH",
    "PUTHEX",
    "PUTDEC4",
    "PUTEOL",
    "GETHEX",
    "IOBYTE",
    "OBEYMASK",
    "BUSY",
    "LASTMOVE",
    "USER_ZP_START",
    "USER_ZP_END",
    "USER_RAM_START",
];

#[test]
fn every_platform_name_is_exported_with_the_decided_values() {
    let table = ["EXTTAB", "EXTTAB_ENTRIES", "EXTTAB_ENTRY_LEN"];
    for name in PLATFORM_NAMES
        .into_iter()
        .chain(["USER_RAM_END"])
        .chain(table)
    {
        assert!(symbols::find(name).is_some(), "{name} is not exported");
    }
    assert_eq!(symbols::HOOK_UNKNOWN, 0x0200);
    assert_eq!(symbols::HOOK_LOOP, 0x0203);
    assert_eq!(symbols::USER_RAM_START, 0x0400);
    // INJECT's queue, then the table of installed extensions, end the
    // controller card's RAM.
    assert_eq!(symbols::USER_RAM_END, 0x0F3F);
    assert_eq!(symbols::EXTTAB, 0x0F80);
    assert_eq!(
        u32::from(symbols::EXTTAB)
            + u32::from(symbols::EXTTAB_ENTRIES * (1 + symbols::EXTTAB_ENTRY_LEN)),
        0x1000
    );
    assert_eq!(symbols::USER_ZP_END, 0x00FF);
    let user_zp = symbols::find("USER_ZP_START").expect("exported").value;
    assert!(user_zp < 0x80, "most of the zero page is the user's");
    // The services sit in the jump table: a JMP each, from $FF00.
    for name in [
        "PUTCH", "PUTHEX", "PUTDEC4", "PUTEOL", "GETHEX", "GETDEC", "CMD_DONE",
    ] {
        let address = symbols::find(name).expect("exported").value;
        assert!(address >= 0xFF00, "{name} at ${address:04X}");
        let offset = usize::from(address - 0xF000);
        assert_eq!(romlib::ROM[offset], 0x4C, "{name} is a JMP");
    }
    assert_eq!(symbols::PUTCH, 0xFF00, "the table starts at $FF00");
}

#[test]
fn symbol_constants_match_the_linked_symbol_table() {
    let image = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("the ROM's ELF");
    let exported: Vec<(String, u32)> = image
        .symbols
        .iter()
        .filter(|s| s.global && !s.name.starts_with("__"))
        .map(|s| (s.name.clone(), s.value))
        .collect();
    assert_eq!(exported.len(), symbols::ALL.len());
    for (name, value) in exported {
        let constant = symbols::find(&name).unwrap_or_else(|| panic!("{name} has no constant"));
        assert_eq!(u32::from(constant.value), value, "{name}");
        assert!(!constant.doc.is_empty(), "{name} is documented");
        let line = format!("\n{name:<15} = ");
        assert!(
            romlib::SCORPION_INC.contains(&line),
            "{name} is in scorpion.inc"
        );
    }
    // The image in the ELF is the image romlib embeds.
    for (offset, &byte) in romlib::ROM.iter().enumerate() {
        let address = 0xF000 + u32::try_from(offset).expect("4 KiB");
        assert_eq!(image.byte_at(address), Some(byte), "${address:04X}");
    }
}

#[test]
fn the_checked_in_scorpion_inc_is_the_generated_one() {
    let path = workspace().join("examples/scorpion.inc");
    if std::env::var_os("UPDATE_SCORPION_INC").is_some() {
        std::fs::write(&path, romlib::SCORPION_INC).expect("examples/ is writable");
    }
    let checked_in = std::fs::read_to_string(&path).expect("examples/scorpion.inc exists");
    assert!(
        checked_in == romlib::SCORPION_INC,
        "examples/scorpion.inc differs from the ROM's generated include file; \
         run `UPDATE_SCORPION_INC=1 cargo test -p scorpion-tests --test rom_build` and commit it"
    );
}

/// `NAME = $XXXX` lines of an include file.
fn equates(text: &str) -> Vec<(String, u32)> {
    text.lines()
        .filter_map(|line| {
            let code = line.split(';').next()?;
            let (name, value) = code.split_once('=')?;
            let value = value.trim().strip_prefix('$')?;
            Some((name.trim().to_owned(), u32::from_str_radix(value, 16).ok()?))
        })
        .collect()
}

#[test]
fn the_roms_hardware_map_is_the_emulators() {
    let text = std::fs::read_to_string(workspace().join("romlib/rom/hardware.inc"))
        .expect("hardware.inc is readable");
    let equates = equates(&text);
    let value = |name: &str| {
        equates
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("hardware.inc defines {name}"))
    };
    let expected: [(&str, u32); 35] = [
        ("VIA_ORB", u32::from(map::VIA)),
        ("VIA_ORA", u32::from(map::VIA) + 1),
        ("VIA_DDRB", u32::from(map::VIA) + 2),
        ("VIA_DDRA", u32::from(map::VIA) + 3),
        ("VIA_T1CL", u32::from(map::VIA) + 4),
        ("VIA_T1CH", u32::from(map::VIA) + 5),
        ("VIA_T2CL", u32::from(map::VIA) + 8),
        ("VIA_T2CH", u32::from(map::VIA) + 9),
        ("VIA_ACR", u32::from(map::VIA) + 11),
        ("VIA_PCR", u32::from(map::VIA) + 12),
        ("VIA_IFR", u32::from(map::VIA) + 13),
        ("VIA_IER", u32::from(map::VIA) + 14),
        ("VIA_ORA_NH", u32::from(map::VIA) + 15),
        ("ACIA_DATA", u32::from(map::ACIA)),
        ("ACIA_STATUS", u32::from(map::ACIA) + 1),
        ("ACIA_CMD", u32::from(map::ACIA) + 2),
        ("ACIA_CTRL", u32::from(map::ACIA) + 3),
        ("DRIVE", u32::from(map::DRIVE)),
        ("SENSE", u32::from(map::SENSE)),
        ("SWITCHES", u32::from(map::SWITCHES)),
        ("SCANNER", u32::from(map::SCANNER)),
        ("DRV_RIGHT_EYE", u32::from(map::drive::RIGHT_EYE)),
        ("DRV_LEFT_EYE", u32::from(map::drive::LEFT_EYE)),
        ("DRV_LAMPS", u32::from(map::drive::LAMPS)),
        ("DRV_LEFT", u32::from(map::drive::LEFT_MOTOR)),
        ("DRV_RIGHT", u32::from(map::drive::RIGHT_MOTOR)),
        ("DRV_HSCAN", u32::from(map::drive::H_SCANNER)),
        ("DRV_VSCAN", u32::from(map::drive::V_SCANNER)),
        ("DRV_SPEAKER", u32::from(map::drive::SPEAKER)),
        ("PB_LEFT_STEP", u32::from(map::port_b::LEFT_STEP)),
        ("PB_LEFT_DIR", u32::from(map::port_b::LEFT_DIR)),
        ("PB_RIGHT_STEP", u32::from(map::port_b::RIGHT_STEP)),
        ("PB_RIGHT_DIR", u32::from(map::port_b::RIGHT_DIR)),
        ("PB_H_STEP", u32::from(map::port_b::H_STEP)),
        ("PB_SCAN_DIR", u32::from(map::port_b::SCAN_DIR)),
    ];
    for (name, expected) in expected {
        assert_eq!(value(name), expected, "{name}");
    }
    assert_eq!(value("PB_V_STEP"), u32::from(map::port_b::V_STEP));
}

/// ca65 and ld65 (Debian's cc65) build the same sources into the same
/// image: the ROM does not depend on a quirk of our own tools.
#[test]
fn ca65_and_ld65_build_the_same_rom() {
    let test = "ca65_and_ld65_build_the_same_rom";
    let (Some(ca65), Some(ld65)) = (
        scorpion_tests::tools::require("ca65", test),
        scorpion_tests::tools::require("ld65", test),
    ) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("scorpion-rom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let config = dir.join("rom.cfg");
    std::fs::write(
        &config,
        "MEMORY { ROM: start = $F000, size = $1000, fill = yes, fillval = $FF, file = %O; }\n\
         SEGMENTS {\n\
           CODE: load = ROM, type = ro;\n\
           RODATA: load = ROM, type = ro, optional = yes;\n\
           JUMPTABLE: load = ROM, type = ro, start = $FF00;\n\
           VECTORS: load = ROM, type = ro, start = $FFFA;\n\
         }\n",
    )
    .expect("the config is written");
    let object = dir.join("scorpion.o");
    let image = dir.join("scorpion.bin");
    let rom_dir = workspace().join("romlib/rom");
    let assembled = Command::new(ca65)
        .current_dir(&rom_dir)
        .arg("-o")
        .arg(&object)
        .arg("scorpion.s")
        .output()
        .expect("ca65 runs");
    assert!(
        assembled.status.success(),
        "ca65: {}",
        String::from_utf8_lossy(&assembled.stderr)
    );
    let linked = Command::new(ld65)
        .arg("-C")
        .arg(&config)
        .arg("-o")
        .arg(&image)
        .arg(&object)
        .output()
        .expect("ld65 runs");
    assert!(
        linked.status.success(),
        "ld65: {}",
        String::from_utf8_lossy(&linked.stderr)
    );
    let theirs = std::fs::read(&image).expect("ld65 wrote the image");
    std::fs::remove_dir_all(&dir).expect("the temporary directory is removed");
    assert!(
        theirs == romlib::ROM,
        "ca65/ld65 and our tools build different ROMs"
    );
}
