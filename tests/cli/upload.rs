//! `scorpion upload` through a real pseudo-terminal to the robot double of
//! `read.rs`: the body verified, the chain slot filled with the hook's old
//! target, the hook switched last; and images it must refuse.

use isa::objfmt::{HookKind, HookRecord, Hooks};
use linker::{Format, Image, LoadArea};

use crate::read::{PtyRobot, memory};
use crate::{scorpion, transcript};

/// An extension image of `len` bytes at $0400: handler at $0403, chain
/// slot at $0401 (the operand of a `JMP` at $0400).
fn extension_elf(len: usize) -> (Vec<u8>, Vec<u8>) {
    let mut bytes: Vec<u8> = (0..len).map(|i| (i * 31 + 7) as u8).collect();
    bytes[0] = 0x4C;
    let image = Image {
        entry: 0x0403,
        flags: 0,
        areas: vec![LoadArea {
            load: 0x0400,
            run: 0x0400,
            bytes: bytes.clone(),
        }],
        sections: vec![],
        symbols: vec![],
        hooks: Hooks {
            records: vec![HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0403,
                chain: Some(0x0401),
            }],
        },
    };
    (Format::Elf.write(&image).expect("an ELF image"), bytes)
}

/// Replaces the timing figures of the summary line.
fn without_timing(text: &str) -> String {
    let Some(start) = text.find(" bytes in ") else {
        return text.to_owned();
    };
    let end = text[start..]
        .find(")\n")
        .map_or(text.len(), |end| start + end + 1);
    format!("{} bytes in [TIME]{}", &text[..start], &text[end..])
}

#[test]
fn uploads_verifies_and_hooks_through_a_pseudo_terminal() {
    let robot = PtyRobot::spawn(memory());
    let dir = tempfile::tempdir().expect("temporary directory");
    let (elf, bytes) = extension_elf(600);
    std::fs::write(dir.path().join("ext.elf"), elf).expect("write the image");
    let output = scorpion(dir.path(), &["upload", "ext.elf", "--port", &robot.path]);
    let text = transcript(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    insta::assert_snapshot!("upload_summary", without_timing(&text));
    let memory = robot.memory.lock().expect("the robot's memory");
    let mut expected = bytes;
    expected[1..3].copy_from_slice(&[0x23, 0xF1]);
    assert_eq!(
        &memory[0x0400..0x0400 + expected.len()],
        expected.as_slice()
    );
    assert_eq!(&memory[0x0200..0x0203], &[0x4C, 0x03, 0x04]);
    assert_eq!(
        &memory[0x0203..0x0206],
        &[0x4C, 0x45, 0xF0],
        "HOOK_LOOP untouched"
    );
}

#[test]
fn refuses_what_it_cannot_upload_safely() {
    let robot = PtyRobot::spawn(memory());
    let dir = tempfile::tempdir().expect("temporary directory");
    let image = Image {
        entry: 0x0100,
        flags: 0,
        areas: vec![LoadArea {
            load: 0x0100,
            run: 0x0100,
            bytes: vec![0xEA; 16],
        }],
        sections: vec![],
        symbols: vec![],
        hooks: Hooks::default(),
    };
    std::fs::write(
        dir.path().join("stack.elf"),
        Format::Elf.write(&image).expect("an ELF image"),
    )
    .expect("write the image");
    let output = scorpion(dir.path(), &["upload", "stack.elf", "--port", &robot.path]);
    assert_eq!(output.status.code(), Some(1));
    insta::assert_snapshot!("upload_outside_user_memory", transcript(&output));
    assert_eq!(
        robot.memory.lock().expect("the robot's memory")[0x0100..0x0110],
        memory()[0x0100..0x0110],
        "nothing was written"
    );

    std::fs::write(dir.path().join("junk.elf"), b"not an image").expect("write");
    let output = scorpion(dir.path(), &["upload", "junk.elf", "--port", &robot.path]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        transcript(&output).contains("junk.elf"),
        "{}",
        transcript(&output)
    );
}
