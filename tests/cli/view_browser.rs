//! The live view (`scorpion sim --view`, issue 28 point 3) in a real
//! browser: Debian's chromium, headless, driven by playwright-core from
//! tests/view/ (its own package.json and lock; `npm ci` there, as
//! `.ci/install-test-tools` does). The page loads, `/2A1` typed in its
//! console is answered, and the motor commands move the drawn robot to
//! the post, whose contact lights the bumper named "4 front" (the
//! indicators are labelled, in lists named by their headers). Without chromium,
//! node or the package the test skips here and fails in CI.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How long the browser's script may run (a loaded machine).
const PATIENCE: Duration = Duration::from_secs(180);

fn package() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/view")
}

#[test]
fn the_live_view_in_chromium_answers_its_console_and_moves_the_robot() {
    let test = "the_live_view_in_chromium_answers_its_console_and_moves_the_robot";
    let Some(chromium) = scorpion_tests::tools::require("chromium", test) else {
        return;
    };
    let Some(node) =
        scorpion_tests::tools::require_npm_packages(&package(), &["playwright-core"], test)
    else {
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary directory");
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/room/room.toml");
    std::fs::copy(example, dir.path().join("room.toml")).expect("the example room");
    // The ADC example's rig: /2A1 is its extension's command.
    crate::build_example(
        dir.path(),
        "adc/adc.s",
        "adc.elf",
        &["--target", "scorpion-ext"],
    );
    let card = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc/adc.rhai");
    let mut sim = Command::new(env!("CARGO_BIN_EXE_scorpion"))
        .args([
            "sim",
            "--world",
            "room.toml",
            "--image",
            "adc.elf",
            "--card",
        ])
        .arg(&card)
        .arg("--view")
        .current_dir(dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("scorpion runs");
    let mut line = String::new();
    let _ = BufReader::new(sim.stdout.take().expect("stdout")).read_line(&mut line);
    let url = line.trim().strip_prefix("open ").map(str::to_owned);
    let Some(url) = url else {
        let _ = sim.kill();
        let _ = sim.wait();
        panic!("the first line is the page's address, not {line:?}");
    };
    let out = dir.path().join("out.txt");
    let mut browser = Command::new(node)
        .arg("view.js")
        .arg(&url)
        .arg(&chromium)
        .arg(dir.path().join("view.png"))
        .current_dir(package())
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).expect("an output file"))
        .stderr(Stdio::inherit())
        .spawn()
        .expect("node runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = browser.try_wait().expect("node is waited for") {
            break Some(status);
        }
        if start.elapsed() > PATIENCE {
            let _ = browser.kill();
            let _ = browser.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let _ = sim.kill();
    let _ = sim.wait();
    let said = std::fs::read_to_string(&out).unwrap_or_default();
    let status =
        status.unwrap_or_else(|| panic!("the browser ran longer than {PATIENCE:?}: {said}"));
    assert!(status.success(), "{said}");
    for step in [
        "view: connected",
        "view: console > /2A1 < A57",
        "view: robot moved to x=",
        "view: bumper named \"4 front closed\", drawn as \"bumper 4 front\"",
        "view: trackers, lamps and eyes named",
        "view: bumper 4 front closed at the post",
        "view: done",
    ] {
        assert!(said.contains(step), "{step:?} in {said}");
    }
}
