//! The patrol operating system (examples/patrol) on the virtual Scorpion,
//! for the debugger's tests.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use debugger::Debugger;
use romlib::VirtualScorpion;

/// The patrol OS, assembled and linked against the reference ROM.
pub(crate) fn patrol() -> linker::Image {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/patrol/patrol.s");
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let assembly =
        assembler::assemble(&assembler::FsSource, &source, &options).expect("patrol assembles");
    romlib::link_against_rom("patrol.s", &assembly.object, "scorpion-os").expect("patrol links")
}

/// A debugger on the patrol robot; `built` counts the robots built
/// (the first one, then every re-run from power-up).
pub(crate) fn debugger(image: &linker::Image, built: &Arc<AtomicUsize>) -> Debugger {
    let loaded = image.clone();
    let count = Arc::clone(built);
    let make = Box::new(move || {
        count.fetch_add(1, Ordering::Relaxed);
        let mut robot = VirtualScorpion::new();
        robot.load_image(&loaded)?;
        Ok(robot)
    });
    Debugger::new(make, std::slice::from_ref(image)).expect("the robot builds")
}

/// Everything of the robot a step back must restore: the CPU (registers,
/// counters, interrupt state), all 64 KiB, and every chip, latch, motor
/// and what the host has not read, as the board shows them.
pub(crate) fn state(d: &Debugger) -> (emulator::Cpu, Vec<u8>, String) {
    let board = d.robot().robot().board();
    (
        d.cpu().clone(),
        board.memory().to_vec(),
        format!("{board:?}"),
    )
}
