//! A debugging session on the virtual Scorpion with a card: break at a
//! handler's label, send its command, step through it, read the card's
//! register, step back and see the earlier registers, find who wrote a
//! byte, go back to the last breakpoint, and continue to the answer.

mod build;

use std::any::Any;

use debugger::{Breakpoint, Debugger, Watch, WatchKind, Why};
use emulator::board::Device;
use romlib::VirtualScorpion;

/// `/1Q` answers `Q` and one more than the card's register, in hex.
const SOURCE: &str = "
        .include \"scorpion.inc\"
CARD    = $8000
        .bss
result: .res 1
        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'Q'
        bne not_mine
        lda CARD
        tax
        inx
        stx result
        lda #'Q'
        jsr PUTCH
        lda result
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN
";

/// A card with one register that reads $41.
#[derive(Debug)]
struct Card;

impl Device for Card {
    fn read(&mut self, _offset: u16, _cycle: u64) -> u8 {
        0x41
    }
    fn write(&mut self, _offset: u16, _value: u8, _cycle: u64) {}
    fn peek(&self, _offset: u16) -> u8 {
        0x41
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

fn image() -> linker::Image {
    build::extension("q.s", SOURCE)
}

fn debugger() -> Debugger {
    let image = image();
    let loaded = image.clone();
    let make = Box::new(move || {
        let mut robot = VirtualScorpion::new();
        robot.map_card(0x8000, 0x8000, Box::new(Card))?;
        robot.load_image(&loaded)?;
        Ok(robot)
    });
    Debugger::new(make, &[image]).expect("the robot builds")
}

#[test]
fn break_step_read_the_card_step_back_and_continue_to_the_answer() {
    let mut d = debugger();
    let handler = d.symbols().address("handler").expect("the handler's label");
    let id = d.add_breakpoint(Breakpoint::At(handler));
    d.send(b"/1Q");
    let stop = d.run(1_000_000).expect("runs");
    assert_eq!(
        stop.why,
        Why::Breakpoint {
            id,
            point: Breakpoint::At(handler)
        }
    );
    assert_eq!(stop.pc, handler);
    // CPX, BNE, CMP, BNE, LDA CARD: A holds the card's register.
    let stepped = d.step(5).expect("steps");
    assert_eq!(stepped.why, Why::Stepped);
    assert_eq!(stepped.instructions, 5);
    assert_eq!(d.cpu().a, 0x41);
    // TAX, INX, STX result.
    d.step(3).expect("steps");
    let (x_after, s_after) = (d.cpu().x, d.cpu().s);
    assert_eq!(x_after, 0x42);
    // Back three: before TAX, A is the card's value and X what it was.
    let back = d.back(3).expect("goes back");
    assert_eq!(back.why, Why::Back);
    assert_eq!(back.instructions, -3);
    assert_eq!(d.cpu().a, 0x41);
    assert_ne!(d.cpu().x, 0x42);
    assert_eq!(d.cpu().s, s_after);
    // Forward again, the same way.
    d.step(3).expect("steps");
    assert_eq!(d.cpu().x, 0x42);
    let result = d.symbols().address("result").expect("`result`");
    let wrote = d.who_wrote(result).expect("re-runs").expect("a write");
    assert_eq!(wrote.value, 0x42);
    // STX result, after CPX, BNE, CMP, BNE, LDA CARD, TAX, INX.
    assert_eq!(d.symbols().place(wrote.pc).as_deref(), Some("handler+$D"));
    // Back to the breakpoint at the handler's start.
    let again = d.reverse_continue().expect("re-runs").expect("a hit");
    assert_eq!(again.pc, handler);
    // And on to the answer, the breakpoint deleted.
    assert!(d.delete_breakpoint(id));
    let done = d.run(200_000).expect("runs");
    assert_eq!(done.why, Why::Budget);
    assert_eq!(done.received, b"Q42\r");
}

#[test]
fn command_watch_next_and_finish() {
    let mut d = debugger();
    let id = d.add_breakpoint(Breakpoint::command("/1Q").expect("a command"));
    d.send(b"/1X");
    let quiet = d.run(100_000).expect("runs");
    assert_eq!(quiet.why, Why::Budget, "another command does not stop");
    assert_eq!(quiet.received, b"X00\r");
    d.send(b"/1Q");
    let arrived = d.run(100_000).expect("runs");
    assert!(matches!(arrived.why, Why::Breakpoint { id: i, .. } if i == id));
    d.delete_breakpoint(id);
    let watch = d.add_watch(Watch {
        start: 0x8000,
        end: 0x8000,
        kind: WatchKind::Read,
    });
    let read = d.run(100_000).expect("runs");
    let Why::Watch { id, access, pc } = read.why else {
        panic!("{read:?}");
    };
    assert_eq!((id, access.value, access.write), (watch, 0x41, false));
    assert_eq!(d.symbols().place(pc).as_deref(), Some("handler+$8"));
    d.delete_watch(watch);
    // Up to the JSR PUTCH, over it, then out of the handler's callee.
    while emulator::Bus::peek(&d.robot().robot().bus, d.cpu().pc) != 0x20 {
        d.step(1).expect("steps");
    }
    let before = d.cpu().pc;
    let over = d.next(100_000).expect("runs");
    assert_eq!(over.pc, before + 3);
    assert!(over.instructions > 1, "the whole of PUTCH ran");
    d.step(2).expect("into PUTHEX");
    // The call chain: here, then the JSR PUTHEX that called it (three
    // bytes before where it returns to).
    let chain = d.backtrace();
    assert_eq!(chain, vec![d.cpu().pc, before + 6], "{chain:04X?}");
    let finished = d.finish(100_000).expect("runs");
    assert_eq!(finished.why, Why::Finished);
    assert_eq!(finished.pc, before + 9, "back after the JSR PUTHEX");
}

#[test]
fn going_back_before_power_up_is_an_error() {
    let mut d = debugger();
    d.step(10).expect("steps");
    let error = d.back(11).expect_err("only ten ran");
    assert!(error.to_string().contains("only 10 have run"), "{error}");
}

/// The linked image says which source line each byte came from, in memory
/// and through its ELF file (`.scorpion.lines`); the debugger reads it.
#[test]
fn source_lines_of_the_image() {
    let image = image();
    let handler = image.symbol("handler").expect("the handler");
    // `cpx #1` is line 9 of SOURCE (its first line is empty).
    assert_eq!(image.source_of(handler), Some(("q.s", 9, 9)));
    assert_eq!(image.address_of_line("q.s", 9), Some(handler));
    assert_eq!(
        image.address_of_line("q.s", 13),
        Some(handler + 8),
        "lda CARD"
    );
    assert_eq!(image.source_of(0xF000), None, "the ROM is not the image's");
    let elf = linker::Format::Elf.write(&image).expect("an ELF image");
    let read = linker::Image::parse("q.elf", &elf).expect("it reads back");
    assert_eq!(read.lines, image.lines);
    let d = debugger();
    let at = u16::try_from(handler).expect("16-bit");
    assert_eq!(d.source_of(at), Some(("q.s".to_owned(), 9)));
    assert_eq!(d.address_of_line("q.s", 13), Some(at + 8));
    let lines = d.disassemble(at, 2);
    assert_eq!(lines[1].source, Some(("q.s".to_owned(), 10)));
}

#[test]
fn the_unknown_command_hook_and_a_watched_range() {
    let mut d = debugger();
    let hook = d.add_breakpoint(Breakpoint::UnknownHook);
    d.send(b"/1X");
    let known = d.run(100_000).expect("runs");
    assert_eq!(known.why, Why::Budget, "the ROM knows /1X");
    d.send(b"/1Q");
    let unknown = d.run(100_000).expect("runs");
    assert!(
        matches!(unknown.why, Why::Breakpoint { id, .. } if id == hook),
        "{unknown:?}"
    );
    assert_eq!(
        unknown.pc,
        d.robot().hook_address(isa::objfmt::HookKind::Unknown)
    );
    d.delete_breakpoint(hook);
    // A range around `result`: the handler's store into it stops.
    let result = d.symbols().address("result").expect("`result`");
    let watch = d.add_watch(Watch {
        start: result - 1,
        end: result + 1,
        kind: WatchKind::Write,
    });
    let wrote = d.run(100_000).expect("runs");
    let Why::Watch { id, access, .. } = wrote.why else {
        panic!("{wrote:?}");
    };
    assert_eq!((id, access.address, access.value), (watch, result, 0x42));
}
