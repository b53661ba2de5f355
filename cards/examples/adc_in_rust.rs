//! A KIM-bus card in Rust, for those who embed our crates instead of
//! writing a card script: the ADC of `examples/adc/adc.rhai` as an
//! `emulator::board::Device`, mapped into the virtual Scorpion next to the
//! `examples/adc/adc.s` extension, which it answers through.
//!
//! `cargo run -p cards --example adc_in_rust` prints the robot's answers.
//!
//! A `Device` is told the robot time (CPU cycles) of every access and
//! catches up itself; `next_event` says when its interrupt output may rise
//! on its own so the board can let the CPU run until then.
#![allow(clippy::print_stdout, reason = "an example program prints its results")]

use std::any::Any;
use std::collections::BTreeMap;
use std::path::Path;

use emulator::board::Device;
use romlib::VirtualScorpion;

/// Conversion time: 100 us of the 1 MHz CPU.
const CONVERSION: u64 = 100;

/// Eight channels, a conversion on request, an interrupt when done.
#[derive(Debug)]
struct Adc {
    inputs: [u8; 8],
    /// When the running conversion ends, and its result.
    done_at: Option<(u64, u8)>,
    result: u8,
    ready: bool,
    interrupt_enabled: bool,
}

impl Adc {
    fn catch_up(&mut self, cycle: u64) {
        if let Some((at, value)) = self.done_at
            && cycle >= at
        {
            self.done_at = None;
            self.result = value;
            self.ready = true;
        }
    }
}

impl Device for Adc {
    fn read(&mut self, offset: u16, cycle: u64) -> u8 {
        self.catch_up(cycle);
        match offset {
            1 => self.peek(1),
            2 => {
                self.ready = false;
                self.result
            }
            _ => 0,
        }
    }

    fn write(&mut self, offset: u16, value: u8, cycle: u64) {
        self.catch_up(cycle);
        if offset == 0 && value & 0x80 != 0 && self.done_at.is_none() {
            let channel = usize::from(value & 7);
            self.interrupt_enabled = value & 0x40 != 0;
            self.done_at = Some((cycle + CONVERSION, self.inputs[channel]));
        }
    }

    fn peek(&self, offset: u16) -> u8 {
        match offset {
            1 => u8::from(self.done_at.is_some()) << 7 | u8::from(self.ready) << 6,
            2 => self.result,
            _ => 0,
        }
    }

    fn sync(&mut self, cycle: u64) {
        self.catch_up(cycle);
    }

    fn next_event(&self) -> Option<u64> {
        self.done_at.map(|(at, _)| at)
    }

    fn irq(&self) -> bool {
        self.ready && self.interrupt_enabled
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// `examples/adc/adc.s`, assembled and linked against the reference ROM.
fn extension() -> linker::Image {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/adc/adc.s");
    let options = assembler::Options {
        builtin_includes: BTreeMap::from([(
            "scorpion.inc".to_owned(),
            romlib::SCORPION_INC.as_bytes().to_vec(),
        )]),
        ..assembler::Options::default()
    };
    let assembly = assembler::assemble(&assembler::FsSource, &source, &options)
        .expect("the example assembles");
    romlib::link_against_rom("adc.s", &assembly.object, "scorpion-ext").expect("the example links")
}

/// The robot's answers to reading three channels.
pub(crate) fn answers() -> Vec<(&'static str, String)> {
    let mut robot = VirtualScorpion::new();
    let adc = Adc {
        inputs: [192, 87, 0, 0, 0, 0, 0, 255],
        done_at: None,
        result: 0,
        ready: false,
        interrupt_enabled: false,
    };
    robot
        .map_card(0x9000, 0x9002, Box::new(adc))
        .expect("$9000 is free KIM-bus space");
    robot.load_image(&extension()).expect("the extension loads");
    ["/2A0", "/2A1", "/2A7"]
        .into_iter()
        .map(|command| {
            let answer = robot
                .transact(command.as_bytes(), romlib::sim::ANSWER_TIMEOUT)
                .expect("the extension answers");
            (
                command,
                String::from_utf8_lossy(&answer).trim_end().to_owned(),
            )
        })
        .collect()
}

#[allow(dead_code, reason = "a test includes this file for `answers`")]
fn main() {
    for (command, answer) in answers() {
        println!("{command} -> {answer}");
    }
}
