//! Klaus Dormann's 6502 functional and interrupt tests, as the `mos6502`
//! crate's package ships them (ca65 sources and binaries; nothing of them is
//! copied here). The sources are assembled with ca65/ld65 at test time to
//! learn where the success traps are (and to build variants); the shipped
//! binaries must be exactly what the sources build.

use std::path::{Path, PathBuf};
use std::process::Command;

use emulator::{Bus, Interrupts, Line, Machine, Ram, RamMachine, Stop, StopAtTrap};
use scorpion_tests::tools::require;

use crate::mos6502_assets;

/// ca65 and ld65, or `None` (skipped locally, a failure under CI).
fn cc65(test: &str) -> Option<(PathBuf, PathBuf)> {
    Some((require("ca65", test)?, require("ld65", test)?))
}

/// Assembles `source` with ca65 and links it with `config` (ld65 syntax);
/// returns the binary and the ca65 listing.
fn build(tools: &(PathBuf, PathBuf), dir: &Path, source: &Path, config: &str) -> (Vec<u8>, String) {
    let (ca65, ld65) = tools;
    std::fs::write(dir.join("test.cfg"), config).expect("write the linker config");
    let run = |command: &mut Command| {
        let output = command
            .current_dir(dir)
            .output()
            .expect("run the cc65 tool");
        assert!(
            output.status.success(),
            "{command:?} failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    run(Command::new(ca65)
        .arg("-l")
        .arg("test.lst")
        .arg("-o")
        .arg("test.o")
        .arg(source));
    run(Command::new(ld65).args(["-C", "test.cfg", "-o", "test.bin", "test.o"]));
    let binary = std::fs::read(dir.join("test.bin")).expect("read the linked binary");
    let listing = std::fs::read_to_string(dir.join("test.lst")).expect("read the listing");
    (binary, listing)
}

/// The address of the listing line holding `marker` (ca65 listings start
/// each line with the address in six hex digits).
fn address_of(listing: &str, marker: &str) -> u16 {
    let line = listing
        .lines()
        .find(|line| line.contains(marker) && !line.contains(".macro"))
        .unwrap_or_else(|| panic!("no listing line contains {marker:?}"));
    u16::from_str_radix(&line[..6], 16)
        .unwrap_or_else(|_| panic!("no address at the start of {line:?}"))
}

/// The listing lines at `address`, to name a failing trap.
fn lines_at(listing: &str, address: u16) -> String {
    let prefix = format!("{address:06X}");
    listing
        .lines()
        .filter(|line| line.starts_with(&prefix))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The memory layout the functional test's header comment gives (ld65
/// config): RAM image with the program at $0400.
const FUNCTIONAL_CONFIG: &str = "
MEMORY {
    RAM: start = $0000, size = $8000, type = rw, fill = yes, fillval = $FF, file = %O;
    ROM: start = $8000, size = $7FFA, type = ro, fill = yes, fillval = $FF, file = %O;
    ROM_VECTORS: start = $FFFA, size = 6, type = ro, fill = yes, fillval = $FF, file = %O;
}
SEGMENTS {
    ZEROPAGE: load = RAM, type = rw;
    DATA: load = RAM, type = rw, offset = $0200;
    CODE: load = RAM, type = rw, offset = $0400;
    VECTORS: load = ROM_VECTORS, type = ro, optional = yes;
}
";

#[test]
fn functional_test_reaches_its_success_trap_in_the_cycles_mos6502_counts() {
    const TEST: &str = "dormann::functional_test";
    let Some(assets) = mos6502_assets(TEST) else {
        return;
    };
    let Some(tools) = cc65(TEST) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    let source = assets.join("6502_functional_test.ca65");
    let (built, listing) = build(&tools, dir.path(), &source, FUNCTIONAL_CONFIG);
    let shipped = std::fs::read(assets.join("6502_functional_test.bin")).expect("read the binary");
    assert!(
        built == shipped,
        "the shipped functional test binary is not what its source builds"
    );
    let success = address_of(&listing, "everything went well");

    let mut machine = RamMachine::with_image(0, &shipped).expect("a 64 KiB image fits");
    machine.reset();
    machine.cpu.pc = 0x0400;
    let start = machine.cpu.cycles();
    let stop = machine.run_with(start + 200_000_000, &mut StopAtTrap);
    assert_eq!(
        stop,
        Stop::Trap { pc: success },
        "the functional test failed; CPU: {:?}\nlisting at the stop:\n{}",
        machine.cpu,
        lines_at(&listing, machine.cpu.pc)
    );
    let ours = machine.cpu.cycles() - start;
    let instructions = machine.cpu.instructions();

    // The same program on the mos6502 crate, whose cycle counts for
    // documented opcodes are right: every instruction's cycles, page
    // crossings and branch penalties, summed over 30 million instructions.
    let mut theirs = mos6502::cpu::CPU::new(
        mos6502::memory::Memory::new(),
        mos6502::instruction::Nmos6502,
    );
    mos6502::memory::Bus::set_bytes(&mut theirs.memory, 0, &shipped);
    theirs.registers.program_counter = 0x0400;
    let mut count = 0u64;
    while theirs.registers.program_counter != success && count < 100_000_000 {
        theirs.single_step();
        count += 1;
    }
    // Our run stopped after executing the trap's `JMP *` once; so does theirs.
    theirs.single_step();
    count += 1;
    assert_eq!(
        count, instructions,
        "instruction counts differ from mos6502's"
    );
    assert_eq!(ours, theirs.cycles, "cycle totals differ from mos6502's");
}

/// The interrupt test's feedback register at $BFFC: bit 0 drives IRQ, bit 1
/// NMI (open collector: a 1 asserts), bit 7 filtered out.
#[derive(Debug)]
struct FeedbackBus {
    ram: Ram,
    port: u8,
    irq: Line,
    nmi: Line,
}

const FEEDBACK_PORT: u16 = 0xBFFC;

impl Bus for FeedbackBus {
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        if address == FEEDBACK_PORT {
            self.port
        } else {
            self.ram.read(address, cycle)
        }
    }

    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        if address == FEEDBACK_PORT {
            self.port = value & 0x7F;
            self.irq.set(self.port & 1 != 0, cycle);
            self.nmi.set(self.port & 2 != 0, cycle);
        } else {
            self.ram.write(address, value, cycle);
        }
    }

    fn peek(&self, address: u16) -> u8 {
        if address == FEEDBACK_PORT {
            self.port
        } else {
            self.ram.peek(address)
        }
    }

    fn poll(&mut self, cycle: u64) -> Interrupts {
        Interrupts {
            irq: self.irq.at(cycle),
            nmi: self.nmi.at(cycle),
        }
    }
}

/// The ld65 config the package's Makefile builds the interrupt test with.
fn interrupt_config(assets: &Path) -> String {
    std::fs::read_to_string(assets.join("linker.cfg")).expect("read the package's linker.cfg")
}

fn run_interrupt_test(image: &[u8]) -> Machine<FeedbackBus> {
    let mut ram = Ram::new();
    ram.load(0, image).expect("a 64 KiB image fits");
    let mut machine = Machine::new(FeedbackBus {
        ram,
        port: 0,
        irq: Line::new(),
        nmi: Line::new(),
    });
    machine.reset();
    machine.cpu.pc = 0x0400;
    let until = machine.cpu.cycles() + 10_000_000;
    machine.run_with(until, &mut StopAtTrap);
    machine
}

#[test]
fn interrupt_test_reaches_its_success_trap() {
    const TEST: &str = "dormann::interrupt_test";
    let Some(assets) = mos6502_assets(TEST) else {
        return;
    };
    let Some(tools) = cc65(TEST) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    let source = assets.join("6502_interrupt_test.s");
    let (built, listing) = build(&tools, dir.path(), &source, &interrupt_config(&assets));
    let shipped = std::fs::read(assets.join("6502_interrupt_test.bin")).expect("read the binary");
    assert!(
        built == shipped,
        "the shipped interrupt test is not what its source builds"
    );
    let success = address_of(&listing, "everything went well");
    let machine = run_interrupt_test(&shipped);
    assert_eq!(
        machine.cpu.pc,
        success,
        "the interrupt test failed; CPU: {:?}, feedback port ${:02X}\nlisting at the stop:\n{}",
        machine.cpu,
        machine.bus.port,
        lines_at(&listing, machine.cpu.pc)
    );
}

/// The variant with the concurrent BRK + IRQ + NMI test switched on. Its
/// source says a real NMOS 6502 fails it: the NMI arrives during the BRK,
/// hijacks its vector, and the NMI handler finds the B flag BRK pushed
/// ("unexpected B-flag! - this may fail on a real 6502 due to a hardware bug
/// on concurrent BRK & NMI"). Our CPU must end in exactly that trap.
#[test]
fn interrupt_test_concurrent_variant_shows_nmi_hijacking_brk() {
    const TEST: &str = "dormann::interrupt_test_concurrent";
    let Some(assets) = mos6502_assets(TEST) else {
        return;
    };
    let Some(tools) = cc65(TEST) else {
        return;
    };
    let dir = tempfile::tempdir().expect("temporary directory");
    let original =
        std::fs::read_to_string(assets.join("6502_interrupt_test.s")).expect("read the source");
    let switch = "test_concurrent_brk_and_nmi_bug = 0";
    assert!(
        original.contains(switch),
        "the source no longer has {switch:?}"
    );
    let variant = dir.path().join("concurrent.s");
    std::fs::write(
        &variant,
        original.replace(switch, "test_concurrent_brk_and_nmi_bug = 1"),
    )
    .expect("write the variant");
    let (image, listing) = build(&tools, dir.path(), &variant, &interrupt_config(&assets));
    let hijacked = address_of(&listing, "unexpected B-flag");
    let machine = run_interrupt_test(&image);
    assert_eq!(
        machine.cpu.pc,
        hijacked,
        "expected the NMI handler's B-flag trap; CPU: {:?}\nlisting at the stop:\n{}",
        machine.cpu,
        lines_at(&listing, machine.cpu.pc)
    );
    // The NMI handler took it: the B flag is set in the P it pushed.
    let pushed_p = machine.bus.peek(0x0100 + u16::from(machine.cpu.s) + 2);
    assert_ne!(pushed_p & 0x10, 0, "the pushed P should carry BRK's B flag");
}
