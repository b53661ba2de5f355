//! The interrupt sequences, cycle by cycle: IRQ as a level, NMI as an edge,
//! the B flag, the one-instruction delay of CLI/SEI/PLP, RTI, the
//! branch quirk, NMI hijacking BRK, RESET, and the run loop's stops.

use emulator::{
    Breakpoints, Bus, Cpu, Interrupt, Interrupts, Line, Machine, NoHooks, Ram, Step, Stop,
    StopAtTrap, Tracer,
};

/// RAM plus IRQ and NMI inputs driven from a schedule of
/// `(cycle, irq level, nmi level)` changes, applied as the CPU polls.
#[derive(Debug)]
struct Scheduled {
    ram: Ram,
    schedule: Vec<(u64, Option<bool>, Option<bool>)>,
    irq: Line,
    nmi: Line,
}

impl Bus for Scheduled {
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        self.ram.read(address, cycle)
    }

    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        self.ram.write(address, value, cycle);
    }

    fn peek(&self, address: u16) -> u8 {
        self.ram.peek(address)
    }

    fn poll(&mut self, cycle: u64) -> Interrupts {
        // Apply every change due by the most recent access (cycle + 2 at
        // most); `Line` answers for the earlier cycle asked.
        while let Some(&(at, irq, nmi)) = self.schedule.first() {
            if at > cycle + 2 {
                break;
            }
            if let Some(level) = irq {
                self.irq.set(level, at);
            }
            if let Some(level) = nmi {
                self.nmi.set(level, at);
            }
            self.schedule.remove(0);
        }
        Interrupts {
            irq: self.irq.at(cycle),
            nmi: self.nmi.at(cycle),
        }
    }
}

const IRQ_HANDLER: u16 = 0x3000;
const NMI_HANDLER: u16 = 0x4000;

/// A machine with `program` at $0200 (PC there, S = $FD, P = `p`), handlers
/// of NOPs at $3000 (IRQ/BRK) and $4000 (NMI), and the given schedule.
fn machine(
    program: &[u8],
    p: u8,
    schedule: Vec<(u64, Option<bool>, Option<bool>)>,
) -> Machine<Scheduled> {
    let mut ram = Ram::new();
    ram.load(0x0200, program).expect("fits");
    ram.load(0xFFFA, &[0x00, 0x40, 0x00, 0x02, 0x00, 0x30])
        .expect("fits");
    ram.load(IRQ_HANDLER, &[0xEA; 16]).expect("fits");
    ram.load(NMI_HANDLER, &[0xEA; 16]).expect("fits");
    let mut machine = Machine::new(Scheduled {
        ram,
        schedule,
        irq: Line::new(),
        nmi: Line::new(),
    });
    machine.cpu.pc = 0x0200;
    machine.cpu.s = 0xFD;
    machine.cpu.set_p(p);
    machine
}

/// The three bytes an interrupt pushed: P, then the return address.
fn pushed(machine: &Machine<Scheduled>) -> (u8, u16) {
    let s = u16::from(machine.cpu.s);
    let at = |offset: u16| machine.bus.peek(0x0100 + s + offset);
    (at(1), u16::from_le_bytes([at(2), at(3)]))
}

const NOP: u8 = 0xEA;
const CLI: u8 = 0x58;
const SEI: u8 = 0x78;
const PLP: u8 = 0x28;
const RTI: u8 = 0x40;
const BRK: u8 = 0x00;

#[test]
fn irq_is_a_level_taken_while_asserted_and_i_is_clear() {
    // IRQ asserted from the start, I set: nothing happens.
    let mut m = machine(
        &[NOP, NOP, CLI, NOP, NOP],
        0x24,
        vec![(0, Some(true), None)],
    );
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.cpu.pc, 0x0202);
    // CLI polls with the old I: one more instruction runs first.
    assert_eq!(m.step(), Step::Instruction, "CLI");
    assert_eq!(m.step(), Step::Instruction, "the instruction after CLI");
    let before = m.cpu.cycles();
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    assert_eq!(m.cpu.cycles() - before, 7);
    assert_eq!(m.cpu.pc, IRQ_HANDLER);
    assert_ne!(m.cpu.p() & 0x04, 0, "the sequence sets I");
    let (p, ret) = pushed(&m);
    assert_eq!(ret, 0x0204, "returns to the instruction not yet executed");
    assert_eq!(p & 0x30, 0x20, "IRQ pushes B clear, bit 5 set");
    assert_eq!(p & 0x04, 0, "I was clear when the IRQ came");
}

#[test]
fn rti_restores_i_at_once_so_a_held_irq_comes_straight_back() {
    let mut m = machine(&[NOP, NOP], 0x20, vec![(0, Some(true), None)]);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    m.bus.ram.bytes_mut()[usize::from(IRQ_HANDLER)] = RTI;
    assert_eq!(m.step(), Step::Instruction, "RTI");
    assert_eq!(m.cpu.pc, 0x0201);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq), "still asserted");
    // Released: RTI returns for good.
    m.bus.irq.set(false, m.cpu.cycles());
    assert_eq!(m.step(), Step::Instruction, "RTI");
    assert_eq!(m.step(), Step::Instruction, "the NOP at $0201");
    assert_eq!(m.cpu.pc, 0x0202);
}

#[test]
fn sei_lets_an_irq_already_polled_through_with_i_set_in_the_pushed_p() {
    let mut m = machine(&[SEI, NOP], 0x20, vec![(0, Some(true), None)]);
    // The IRQ is asserted before SEI's poll, which still sees I clear.
    m.bus.schedule.clear();
    m.bus.irq.set(true, 0);
    assert_eq!(m.step(), Step::Instruction, "SEI");
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    let (p, ret) = pushed(&m);
    assert_eq!(ret, 0x0201);
    assert_ne!(p & 0x04, 0, "SEI had already set I when P was pushed");
}

#[test]
fn plp_changes_i_one_instruction_late() {
    // PLP pulls I clear: the IRQ waits for one more instruction.
    let mut m = machine(&[PLP, NOP, NOP], 0x24, vec![(0, Some(true), None)]);
    m.bus.ram.bytes_mut()[0x01FE] = 0x20;
    assert_eq!(m.step(), Step::Instruction, "PLP");
    assert_eq!(m.cpu.p() & 0x04, 0);
    assert_eq!(m.step(), Step::Instruction, "one more instruction");
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    assert_eq!(pushed(&m).1, 0x0202);

    // PLP pulls I set while I was clear: the IRQ still gets in after it.
    let mut m = machine(&[PLP, NOP], 0x20, vec![(0, Some(true), None)]);
    m.bus.ram.bytes_mut()[0x01FE] = 0x24;
    // The first poll happens at PLP's end, so the IRQ was not seen before.
    assert_eq!(m.step(), Step::Instruction, "PLP");
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    assert_eq!(pushed(&m).1, 0x0201);
}

#[test]
fn irq_must_arrive_by_the_second_to_last_cycle() {
    // LDA $1234 (4 cycles, 0..=3) then NOPs, I clear.
    let program = [0xAD, 0x34, 0x12, NOP, NOP];
    // Asserted at cycle 2, the second-to-last: taken after the LDA.
    let mut m = machine(&program, 0x20, vec![(2, Some(true), None)]);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    assert_eq!(pushed(&m).1, 0x0203);
    // Asserted at cycle 3, the last: one more instruction first.
    let mut m = machine(&program, 0x20, vec![(3, Some(true), None)]);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    assert_eq!(pushed(&m).1, 0x0204);
}

#[test]
fn a_taken_branch_within_its_page_delays_an_irq_by_one_instruction() {
    // BNE +1 (taken, same page: 3 cycles, 0..=2), IRQ asserted at cycle 1,
    // which a 3-cycle instruction of any other kind would have seen.
    let same_page = [0xD0, 0x01, NOP, NOP, NOP];
    let mut m = machine(&same_page, 0x20, vec![(1, Some(true), None)]);
    assert_eq!(m.step(), Step::Instruction, "BNE");
    assert_eq!(m.cpu.pc, 0x0203);
    assert_eq!(m.step(), Step::Instruction, "the branch target runs first");
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    // Asserted at cycle 0 it is seen at once.
    let mut m = machine(&same_page, 0x20, vec![(0, Some(true), None)]);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
    // A taken branch into the next page (4 cycles) polls at its cycle 2.
    let mut ram_program = vec![NOP; 0x100];
    ram_program[0xFB] = 0xD0; // BNE at $02FB...
    ram_program[0xFC] = 0x10; // ...to $030D
    let mut m = machine(&ram_program, 0x20, vec![]);
    m.cpu.pc = 0x02FB;
    m.bus.ram.load(0x030D, &[NOP, NOP]).expect("fits");
    m.bus.schedule = vec![(m.cpu.cycles() + 2, Some(true), None)];
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.cpu.pc, 0x030D);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
}

#[test]
fn nmi_is_an_edge_taken_once_per_assertion() {
    let mut m = machine(&[NOP; 16], 0x24, vec![(0, None, Some(true))]);
    m.bus.ram.bytes_mut()[usize::from(NMI_HANDLER)] = RTI;
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(
        m.step(),
        Step::Interrupt(Interrupt::Nmi),
        "I does not mask NMI"
    );
    let (p, ret) = pushed(&m);
    assert_eq!((p & 0x30, ret), (0x20, 0x0201), "B clear");
    assert_eq!(m.step(), Step::Instruction, "RTI");
    // Still asserted: no second NMI.
    for _ in 0..4 {
        assert_eq!(m.step(), Step::Instruction);
    }
    // Released, then asserted again: a new edge.
    let now = m.cpu.cycles();
    m.bus.schedule = vec![(now, None, Some(false)), (now + 4, None, Some(true))];
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Nmi));
}

#[test]
fn nmi_wins_over_irq_and_irq_follows() {
    let mut m = machine(&[NOP; 4], 0x20, vec![(0, Some(true), Some(true))]);
    m.bus.ram.bytes_mut()[usize::from(NMI_HANDLER)] = RTI;
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Nmi));
    assert_eq!(m.step(), Step::Instruction, "RTI restores I clear");
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Irq));
}

#[test]
fn brk_pushes_b_set_and_the_address_after_its_padding_byte() {
    let mut m = machine(&[BRK, 0xFF, NOP], 0x20 | 0x08 | 0x01, vec![]);
    assert_eq!(m.step(), Step::Instruction);
    assert_eq!(m.cpu.cycles(), 7);
    assert_eq!(m.cpu.pc, IRQ_HANDLER);
    let (p, ret) = pushed(&m);
    assert_eq!(ret, 0x0202);
    assert_eq!(
        p,
        0x20 | 0x10 | 0x08 | 0x01,
        "B and bit 5 set; D kept (NMOS)"
    );
    assert_eq!(m.cpu.p() & 0x0C, 0x0C, "I set, D not cleared");
}

#[test]
fn an_nmi_by_brks_fourth_cycle_hijacks_its_vector() {
    // NMI asserted at BRK's cycle 3 (the fourth): NMI vector, B still set.
    let mut m = machine(&[BRK, 0xFF, NOP], 0x20, vec![(3, None, Some(true))]);
    assert_eq!(m.step(), Step::Instruction, "BRK");
    assert_eq!(m.cpu.pc, NMI_HANDLER);
    let (p, ret) = pushed(&m);
    assert_eq!((p & 0x10, ret), (0x10, 0x0202));
    // The NMI was consumed by the hijack: the handler runs undisturbed.
    for _ in 0..4 {
        assert_eq!(m.step(), Step::Instruction);
    }

    // One cycle later (cycle 4) it is too late for the vector: BRK goes to
    // the IRQ vector, and the NMI follows the handler's first instruction.
    let mut m = machine(&[BRK, 0xFF, NOP], 0x20, vec![(4, None, Some(true))]);
    assert_eq!(m.step(), Step::Instruction, "BRK");
    assert_eq!(m.cpu.pc, IRQ_HANDLER);
    assert_eq!(
        m.step(),
        Step::Instruction,
        "the handler's first instruction"
    );
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Nmi));
    assert_eq!(pushed(&m).1, IRQ_HANDLER + 1);
}

#[test]
fn an_nmi_during_an_irq_sequence_hijacks_it_with_b_clear() {
    let mut m = machine(&[NOP; 4], 0x20, vec![(0, Some(true), None)]);
    assert_eq!(m.step(), Step::Instruction);
    // The IRQ sequence starts at cycle 2; its fourth cycle is 5.
    m.bus.schedule = vec![(5, None, Some(true))];
    assert_eq!(m.step(), Step::Interrupt(Interrupt::Nmi));
    assert_eq!(m.cpu.pc, NMI_HANDLER);
    assert_eq!(pushed(&m).0 & 0x10, 0);
}

#[test]
fn reset_takes_seven_cycles_and_keeps_decimal_mode() {
    let mut ram = Ram::new();
    ram.load(0xFFFC, &[0x34, 0x12]).expect("fits");
    let mut cpu = Cpu::new();
    cpu.set_p(0x08);
    cpu.s = 0x40;
    cpu.reset(&mut ram);
    assert_eq!(cpu.pc, 0x1234);
    assert_eq!(cpu.cycles(), 7);
    assert_eq!(cpu.s, 0x3D, "three suppressed pushes");
    assert_eq!(cpu.p(), 0x20 | 0x08 | 0x04);
    assert_eq!(cpu.instructions(), 0);
    // From power-on, S ends at $FD.
    let mut cpu = Cpu::new();
    cpu.reset(&mut ram);
    assert_eq!(cpu.s, 0xFD);
}

#[test]
fn runs_stop_at_limits_traps_jams_and_breakpoints() {
    // LDX #0; loop: INX; BNE loop; JMP *  then a JAM behind it.
    let program = [0xA2, 0x00, 0xE8, 0xD0, 0xFD, 0x4C, 0x05, 0x02, 0x02];
    let mut m = machine(&program, 0x24, vec![]);
    assert_eq!(m.cpu.run(&mut m.bus, 100, &mut NoHooks), Stop::Limit);
    assert!(m.cpu.cycles() >= 100 && m.cpu.cycles() < 104);
    assert_eq!(
        m.cpu.run(&mut m.bus, 10_000, &mut StopAtTrap),
        Stop::Trap { pc: 0x0205 }
    );
    // 2 + 255 * 5 + 4 + 3 cycles, and the trap executed once.
    assert_eq!(m.cpu.cycles(), 2 + 255 * 5 + 4 + 3);
    assert_eq!(m.cpu.instructions(), 1 + 256 * 2 + 1);
    // Without StopAtTrap the trap spins to the limit.
    assert_eq!(m.run(m.cpu.cycles() + 30), Stop::Limit);
    assert_eq!(m.cpu.pc, 0x0205);

    let mut breakpoints = Breakpoints::new();
    assert!(breakpoints.insert(0x0203));
    let mut m = machine(&program, 0x24, vec![]);
    assert_eq!(
        m.run_with(10_000, &mut breakpoints),
        Stop::Hook { pc: 0x0203 }
    );
    assert_eq!(m.cpu.x, 1);

    let mut m = machine(&program, 0x24, vec![]);
    m.bus.ram.bytes_mut()[0x0205] = 0xEA; // the trap becomes NOP NOP NOP
    m.bus.ram.bytes_mut()[0x0206] = 0xEA;
    m.bus.ram.bytes_mut()[0x0207] = 0xEA;
    assert_eq!(
        m.run(10_000),
        Stop::Jam {
            pc: 0x0208,
            opcode: 0x02
        }
    );
    let cycles = m.cpu.cycles();
    assert_eq!(
        m.run(10_000),
        Stop::Jam {
            pc: 0x0208,
            opcode: 0x02
        }
    );
    assert_eq!(m.cpu.cycles(), cycles, "a JAM takes no time");
}

#[test]
fn the_tracer_writes_one_line_per_instruction_and_per_interrupt() {
    // LDA #$01; STA $0300; CLI; NOP, with an IRQ asserted.
    let program = [0xA9, 0x01, 0x8D, 0x00, 0x03, CLI, NOP, NOP];
    let mut m = machine(&program, 0x24, vec![(0, Some(true), None)]);
    let mut tracer = Tracer::new(Vec::new());
    m.run_with(20, &mut tracer);
    let text = String::from_utf8(tracer.finish().expect("no write error")).expect("utf-8");
    let expected = "\
0200  A9 01     LDA #$01        A=00 X=00 Y=00 S=FD P=nv-bdIzc cycle=0
0202  8D 00 03  STA $0300       A=01 X=00 Y=00 S=FD P=nv-bdIzc cycle=2
0205  58        CLI             A=01 X=00 Y=00 S=FD P=nv-bdIzc cycle=6
0206  EA        NOP             A=01 X=00 Y=00 S=FD P=nv-bdizc cycle=8
IRQ   -> $3000                  A=01 X=00 Y=00 S=FA P=nv-bdIzc cycle=10
3000  EA        NOP             A=01 X=00 Y=00 S=FA P=nv-bdIzc cycle=17
3001  EA        NOP             A=01 X=00 Y=00 S=FA P=nv-bdIzc cycle=19
";
    assert_eq!(text, expected);
}
