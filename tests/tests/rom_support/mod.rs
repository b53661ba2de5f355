//! What the ROM, conformance and example tests share: a host session with
//! the virtual Scorpion that keeps a transcript for insta snapshots, and a
//! way to build extensions with our own assembler and linker.
#![allow(dead_code, reason = "each test file uses a part")]

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use emulator::board::{CPU_HZ, Motor};
use romlib::VirtualScorpion;
use romlib::protocol::{Answer, Command, ReadSpan, WordWrite};

/// A host talking to the virtual Scorpion at 9600 baud, writing down what
/// crosses the line.
pub(crate) struct Session {
    /// The robot.
    pub(crate) robot: VirtualScorpion,
    /// `> command`, `< answer` and `# note` lines.
    pub(crate) transcript: String,
}

impl Session {
    /// A fresh robot with the reference ROM.
    pub(crate) fn new() -> Session {
        Session {
            robot: VirtualScorpion::new(),
            transcript: String::new(),
        }
    }

    /// Sends a command written as text; returns the parsed answer of a
    /// question, `None` for an instruction.
    pub(crate) fn send(&mut self, text: &str) -> Option<Answer> {
        let command = Command::parse(text.as_bytes())
            .unwrap_or_else(|error| panic!("`{text}` is a valid command: {error}"));
        writeln!(self.transcript, "> {text}").expect("writing to a String");
        let answer = self
            .robot
            .exchange(&command)
            .unwrap_or_else(|error| panic!("`{text}`: {error}\n{}", self.transcript));
        if let Some(answer) = &answer {
            let raw = answer.encode();
            writeln!(self.transcript, "< {}", text_of(&raw)).expect("writing to a String");
        }
        answer
    }

    /// Sends a question and returns the raw answer text, carriage return
    /// included.
    pub(crate) fn ask(&mut self, text: &str) -> String {
        writeln!(self.transcript, "> {text}").expect("writing to a String");
        let raw = self
            .robot
            .transact(text.as_bytes(), romlib::sim::ANSWER_TIMEOUT)
            .unwrap_or_else(|error| panic!("`{text}`: {error}\n{}", self.transcript));
        let answer = String::from_utf8(raw).expect("answers are ASCII");
        writeln!(self.transcript, "< {}", answer.escape_default()).expect("writing to a String");
        answer
    }

    /// Sends raw bytes that must not be answered, and lets the robot act.
    pub(crate) fn tell_raw(&mut self, bytes: &[u8]) {
        writeln!(self.transcript, "> {}", text_of(bytes)).expect("writing to a String");
        self.robot.receive();
        self.robot.send(bytes);
        self.robot.settle().expect("the CPU runs");
        let answer = self.robot.receive();
        assert!(
            answer.is_empty(),
            "`{}` got an answer: `{}`",
            text_of(bytes),
            text_of(&answer)
        );
    }

    /// Lets `ms` milliseconds of robot time pass.
    pub(crate) fn wait_ms(&mut self, ms: u64) {
        writeln!(self.transcript, "# {ms} ms pass").expect("writing to a String");
        self.robot
            .run_for(ms * CPU_HZ / 1000)
            .expect("the CPU does not jam");
    }

    /// Writes a note into the transcript.
    pub(crate) fn note(&mut self, text: &str) {
        writeln!(self.transcript, "# {text}").expect("writing to a String");
    }

    /// A motor's position in steps.
    pub(crate) fn position(&self, motor: Motor) -> i64 {
        self.robot.robot().board().motor(motor).position()
    }

    /// Closes the bumpers set in `mask` (opens the others).
    pub(crate) fn bumpers(&mut self, mask: u8) {
        writeln!(self.transcript, "# bumpers {mask:08b}").expect("writing to a String");
        self.robot.robot_mut().set_bumpers(mask);
    }
}

/// Bytes as printable text (`\r` escaped).
pub(crate) fn text_of(bytes: &[u8]) -> String {
    romlib::sim::escape(bytes)
}

/// The repository's `examples/` directory.
pub(crate) fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the workspace")
        .join("examples")
}

/// Assembles `sources` (path, in the order given) with our assembler,
/// `scorpion.inc` built in, and links them with `target` against the ROM's
/// symbols. Returns the linked image.
pub(crate) fn build(sources: &[PathBuf], target: &str) -> linker::Image {
    let mut includes = BTreeMap::new();
    includes.insert(
        "scorpion.inc".to_owned(),
        romlib::SCORPION_INC.as_bytes().to_vec(),
    );
    let options = assembler::Options {
        builtin_includes: includes,
        ..assembler::Options::default()
    };
    let objects: Vec<(String, Vec<u8>)> = sources
        .iter()
        .map(|path| {
            let assembly = assembler::assemble(&assembler::FsSource, path, &options)
                .unwrap_or_else(|error| {
                    panic!(
                        "{} does not assemble: {error}\n{:?}",
                        path.display(),
                        error.diagnostics()
                    )
                });
            (path.display().to_string(), assembly.object)
        })
        .collect();
    let inputs: Vec<linker::Input<'_>> = objects
        .iter()
        .map(|(name, bytes)| linker::Input { name, bytes })
        .collect();
    let rom =
        linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("romlib's ROM ELF parses");
    let target = if Path::new(target)
        .extension()
        .is_some_and(|ext| ext == "toml")
    {
        let text = std::fs::read_to_string(target).expect("the layout file is readable");
        linker::Target::Custom(
            linker::Layout::from_toml(target, &text)
                .unwrap_or_else(|error| panic!("{target}: {error:?}")),
        )
    } else {
        linker::Target::builtin(target, None).expect("a built-in target")
    };
    let just_symbols = [linker::SymbolFile {
        name: "scorpion-rom.elf",
        image: &rom,
    }];
    let linked = linker::link(
        &inputs,
        &linker::LinkOptions {
            target: &target,
            just_symbols: &just_symbols,
            sources: &linker::NoSources,
        },
    )
    .unwrap_or_else(|error| panic!("the example does not link: {error:?}"));
    linked.image
}

/// Writes `image` into the robot the way an uploader does, through the
/// serial line only: every loaded area with back-to-back `/9W` commands
/// (`/7W` for an odd last byte), read back with `/7R` and compared, then
/// each hook installed: its previous target read, written into the image's
/// chain slot, and the hook re-pointed with one `/9W`. Returns the number of
/// write commands sent; notes a summary in the transcript.
pub(crate) fn upload(s: &mut Session, image: &linker::Image) -> usize {
    let mut writes = Vec::new();
    let mut bytes = 0;
    for area in &image.areas {
        let start = u16::try_from(area.load).expect("areas load below $10000");
        bytes += area.bytes.len();
        for (index, pair) in area.bytes.chunks(2).enumerate() {
            let address = start + u16::try_from(2 * index).expect("areas are under 64 KiB");
            let command = match pair {
                [first, second] => Command::WriteWord(
                    WordWrite::new(address, [*first, *second]).expect("inside the address space"),
                ),
                [only] => Command::WriteByte {
                    address,
                    value: *only,
                },
                _ => unreachable!("chunks of 1 or 2"),
            };
            writes.push(command);
        }
    }
    let mut stream = Vec::new();
    for command in &writes {
        stream.extend(command.encode());
    }
    s.robot.receive();
    s.robot.send(&stream);
    s.robot.settle().expect("the CPU runs");
    assert!(s.robot.receive().is_empty(), "writes are not answered");
    for area in &image.areas {
        let start = u16::try_from(area.load).expect("areas load below $10000");
        for (index, chunk) in area.bytes.chunks(99).enumerate() {
            let address = start + u16::try_from(99 * index).expect("areas are under 64 KiB");
            let count = u8::try_from(chunk.len()).expect("99 at most");
            let read = Command::ReadMemory(
                ReadSpan::new(address, count).expect("inside the address space"),
            );
            match s.robot.exchange(&read) {
                Ok(Some(Answer::Memory(found))) => {
                    assert_eq!(found, chunk, "verifying ${address:04X}");
                }
                other => panic!("reading back ${address:04X}: {other:?}"),
            }
        }
    }
    let mut installed = Vec::new();
    for record in &image.hooks.records {
        let hook = romlib::symbols::find(record.kind.rom_symbol())
            .expect("the ROM exports its hooks")
            .value;
        let read = Command::ReadMemory(ReadSpan::new(hook + 1, 2).expect("in RAM"));
        let Ok(Some(Answer::Memory(previous))) = s.robot.exchange(&read) else {
            panic!("reading {}", record.kind.rom_symbol())
        };
        if let Some(slot) = record.chain {
            let chain = Command::WriteWord(
                WordWrite::new(slot, [previous[0], previous[1]]).expect("in RAM"),
            );
            s.robot.exchange(&chain).expect("the chain slot is written");
            writes.push(chain);
        }
        let [low, high] = record.handler.to_le_bytes();
        let point = Command::WriteWord(WordWrite::new(hook + 1, [low, high]).expect("in RAM"));
        s.robot.exchange(&point).expect("the hook is written");
        writes.push(point);
        installed.push(format!(
            "{} -> ${:04X} (was ${:02X}{:02X})",
            record.kind.rom_symbol(),
            record.handler,
            previous[1],
            previous[0]
        ));
    }
    s.note(&format!(
        "uploaded {bytes} bytes with {} write commands, verified; hooks: {}",
        writes.len(),
        installed.join(", ")
    ));
    writes.len()
}
