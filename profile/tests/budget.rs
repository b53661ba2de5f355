//! Budgets find the routine they name: by any label of its address.

use emulator::{Machine, StopAtTrap};
use scorpion_profile::budget::{Budget, check};
use scorpion_profile::{Places, Profiler};

fn no_places() -> Places {
    Places {
        arrival: None,
        done: Vec::new(),
        main_loop: None,
        command_length: 0,
        command_buffer: 0,
    }
}

/// `cmd_q:` and `rec:` label one address (recx's handler: `cmd_q:` on
/// its own line, then `rec: jsr rec`): the routine is shown under the
/// first name, and a budget on the other finds it all the same.
///
/// ```text
/// 0400  20 08 04  JSR $0408    (cmd_q, rec)
/// 0403  4C 03 04  JMP *
/// 0408  EA        NOP
/// 0409  60        RTS
/// ```
#[test]
fn a_budget_names_a_routine_by_its_second_label() {
    let mut machine = Machine::with_image(0x0400, &[0x20, 0x08, 0x04, 0x4C, 0x03, 0x04])
        .expect("the caller fits");
    machine.bus.load(0x0408, &[0xEA, 0x60]).expect("it fits");
    machine.cpu.pc = 0x0400;
    machine.cpu.s = 0xFF;
    let labels = [
        (0x0400, "start".to_owned()),
        (0x0408, "rec".to_owned()),
        (0x0408, "cmd_q".to_owned()),
    ];
    let mut profiler = Profiler::new(&labels, no_places());
    let _ = machine.run_with(1_000, &mut (&mut profiler, StopAtTrap));
    profiler.end_run(&machine.cpu);
    let profile = profiler.finish(machine.cpu.cycles());

    // NOP 2 + RTS 6.
    let over = [Budget::new("rec", 7)];
    let (overruns, unused) = check(&profile, &over);
    assert!(unused.is_empty(), "`rec` is a routine the run called");
    assert_eq!(overruns.len(), 1);
    assert_eq!(overruns[0].worst, 8);
    let (overruns, unused) = check(&profile, &[Budget::new("rec", 8)]);
    assert!(overruns.is_empty() && unused.is_empty());
    let (_, unused) = check(&profile, &[Budget::new("cmd_q", 8)]);
    assert!(unused.is_empty(), "the name it is shown under too");
}
