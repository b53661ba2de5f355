//! Hostile scripts (issue 23): each file in `tests/hostile/` says how it
//! runs (`// run: card` on a board whose program reads the card's first
//! register in a loop, `// run: world` as the surroundings of the virtual
//! Scorpion) and what must come of it (`// expect: TEXT`, a failure whose
//! message contains TEXT, or `// expect: ok`): never a panic, a hang or a
//! host that runs out of memory. Each runs in its own thread, watched.

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use cards::{MAX_PRINTED_LINES, Printed, ScriptCard, ScriptWorld};
use emulator::board::Scorpion;
use romlib::VirtualScorpion;

/// Robot time each script is run for: a tenth of a second.
const ROBOT_CYCLES: u64 = 100_000;

/// Host time a run may take before it counts as a hang.
const WATCHDOG: Duration = Duration::from_secs(120);

/// A 4 KiB ROM whose program reads `address` for ever.
fn polling_rom(address: u16) -> Vec<u8> {
    let [low, high] = address.to_le_bytes();
    let mut rom = vec![0xEA; 0x1000];
    // loop: LDA address / JMP loop
    rom[..6].copy_from_slice(&[0xAD, low, high, 0x4C, 0x00, 0xF0]);
    rom[0xFFC..].copy_from_slice(&[0x00, 0xF0, 0x00, 0xF0]);
    rom
}

/// Runs a card: its failure (loading or running) and what it printed.
fn run_card(name: &str, text: &str) -> (Option<String>, Option<Printed>) {
    let card = match ScriptCard::load(name, text, None) {
        Ok(card) => card,
        Err(error) => return (Some(error.to_string()), None),
    };
    let printed = card.printed();
    let (start, end) = card.window();
    let mut robot = Scorpion::scorpion(&polling_rom(start)).expect("a 4 KiB ROM");
    robot
        .map_kim(start, end, Box::new(card))
        .expect("a free window");
    robot.run(ROBOT_CYCLES);
    let fault = robot
        .board_mut()
        .take_device_fault()
        .map(|(_, fault)| fault.to_string());
    (fault, Some(printed))
}

/// Runs surroundings: their failure (loading or running) and what they
/// printed.
fn run_world(name: &str, text: &str) -> (Option<String>, Option<Printed>) {
    let world = match ScriptWorld::load(name, text) {
        Ok(world) => world,
        Err(error) => return (Some(error.to_string()), None),
    };
    let printed = world.printed();
    let mut robot = VirtualScorpion::new();
    robot.set_surroundings(Box::new(world));
    let fault = robot.run_for(ROBOT_CYCLES).err().map(|error| match error {
        // The robot's error says whose; the script's says where and what.
        romlib::Error::Surroundings { message, .. } => message,
        other => other.to_string(),
    });
    (fault, Some(printed))
}

/// The value of `// key: value` in the script's header.
fn header<'a>(text: &'a str, key: &str) -> &'a str {
    let prefix = format!("// {key}: ");
    text.lines()
        .find_map(|line| line.strip_prefix(prefix.as_str()))
        .unwrap_or_else(|| panic!("no `{prefix}` line"))
}

/// Runs one case under the watchdog; `Err` says what went wrong.
fn check(path: &Path) -> Result<(), String> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .expect("a file name")
        .to_owned();
    let text = std::fs::read_to_string(path).expect("the case");
    let run = header(&text, "run").to_owned();
    let expect = header(&text, "expect").to_owned();
    let (done, outcome) = mpsc::channel();
    std::thread::spawn(move || {
        let (fault, printed) = match run.as_str() {
            "card" => run_card(&name, &text),
            "world" => run_world(&name, &text),
            other => panic!("`run: {other}` is neither card nor world"),
        };
        let lines = printed.map(|p| p.take());
        let _ = done.send((fault, lines));
    });
    let (fault, lines) = match outcome.recv_timeout(WATCHDOG) {
        Ok(outcome) => outcome,
        Err(mpsc::RecvTimeoutError::Timeout) => return Err("hangs".into()),
        Err(mpsc::RecvTimeoutError::Disconnected) => return Err("panics".into()),
    };
    if let Some(lines) = &lines
        && lines.len() > MAX_PRINTED_LINES + 1
    {
        return Err(format!("kept {} printed lines", lines.len()));
    }
    match (expect.as_str(), fault) {
        ("ok", None) => Ok(()),
        ("ok", Some(fault)) => Err(format!("fails: {fault}")),
        (_, None) => Err(format!("runs without the failure `{expect}`")),
        (_, Some(fault)) if fault.contains(&expect) => Ok(()),
        (_, Some(fault)) => Err(format!("fails otherwise: {fault}\n  expected: {expect}")),
    }
}

#[test]
fn hostile_scripts_end_in_a_located_error_or_run_as_asked() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile");
    let mut cases: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/hostile")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "rhai"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 10, "the cases are there");
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|path| {
            check(path)
                .err()
                .map(|why| format!("{}: {why}", path.display()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
