//! The programs bundled in `emulator/programs/`: each binary must be exactly
//! what ca65/ld65 build from its source, and must compute what it says.

use std::path::Path;
use std::process::Command;

use emulator::{RamMachine, Stop, StopAtTrap};
use scorpion_tests::tools::require;

const PROGRAMS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/programs");

#[test]
fn sieve_binary_is_what_its_source_builds() {
    const TEST: &str = "programs::sieve_binary_is_what_its_source_builds";
    let (Some(ca65), Some(ld65)) = (require("ca65", TEST), require("ld65", TEST)) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    let programs = Path::new(PROGRAMS);
    let object = dir.path().join("sieve.o");
    let binary = dir.path().join("sieve.bin");
    let assembled = Command::new(ca65)
        .arg("-o")
        .arg(&object)
        .arg(programs.join("sieve.s"))
        .status()
        .expect("run ca65");
    assert!(assembled.success(), "ca65 failed on sieve.s");
    let linked = Command::new(ld65)
        .arg("-C")
        .arg(programs.join("sieve.cfg"))
        .arg("-o")
        .arg(&binary)
        .arg(&object)
        .status()
        .expect("run ld65");
    assert!(linked.success(), "ld65 failed on sieve.o");
    let built = std::fs::read(&binary).expect("read the built binary");
    let committed = std::fs::read(programs.join("sieve.bin")).expect("read sieve.bin");
    assert!(
        built == committed,
        "emulator/programs/sieve.bin is stale: rebuild it as sieve.s says"
    );
}

#[test]
fn sieve_counts_the_1028_primes_below_8192() {
    let image = std::fs::read(Path::new(PROGRAMS).join("sieve.bin")).expect("read sieve.bin");
    let mut machine = RamMachine::with_image(0x0400, &image).expect("fits");
    machine.reset();
    machine.cpu.pc = 0x0400;
    let stop = machine.run_with(100_000_000, &mut StopAtTrap);
    assert!(
        matches!(stop, Stop::Trap { .. }),
        "{stop:?}: {:?}",
        machine.cpu
    );
    let count = u16::from_le_bytes([machine.cpu.x, machine.cpu.y]);
    assert_eq!(count, 1028, "{:?}", machine.cpu);
}
