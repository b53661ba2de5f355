//! A read-modify-write instruction (`INC`, `ASL`, ...) writes twice on the
//! NMOS 6502: the byte it read, then the result. A watchpoint and
//! `who-wrote` must tell the byte the instruction left, not the first,
//! dummy write of the old value.

mod build;

use debugger::{Debugger, Watch, WatchKind, Why};
use romlib::VirtualScorpion;

/// `/1Q` counts its calls in `passes` with `INC` and answers `Q`.
const SOURCE: &str = "
        .include \"scorpion.inc\"
        .bss
passes: .res 1
        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'Q'
        bne not_mine
        inc passes
        lda #'Q'
        jsr PUTCH
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

fn debugger() -> Debugger {
    let image = build::extension("p.s", SOURCE);
    let loaded = image.clone();
    let make = Box::new(move || {
        let mut robot = VirtualScorpion::new();
        robot.load_image(&loaded)?;
        Ok(robot)
    });
    Debugger::new(make, &[image]).expect("the robot builds")
}

#[test]
fn a_watchpoint_and_who_wrote_tell_the_byte_an_inc_left() {
    let mut d = debugger();
    let passes = d.symbols().address("passes").expect("`passes`");
    let watch = d.add_watch(Watch {
        start: passes,
        end: passes,
        kind: WatchKind::Write,
    });
    for expected in [1u8, 2] {
        d.send(b"/1Q");
        let stopped = d.run(1_000_000).expect("runs");
        let Why::Watch { id, access, .. } = stopped.why else {
            panic!("{stopped:?}");
        };
        assert_eq!((id, access.address), (watch, passes));
        assert_eq!(access.value, expected, "the byte INC left, pass {expected}");
        assert_eq!(
            emulator::Bus::peek(&d.robot().robot().bus, passes),
            expected
        );
        let last = d.who_wrote(passes).expect("re-runs").expect("INC wrote it");
        assert_eq!(last.value, expected, "who-wrote, pass {expected}");
    }
}
