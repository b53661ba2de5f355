//! `scorpion debug` at a terminal, as a person uses it: typed under tmux
//! (a real pseudo-terminal), its screen read back. History (Up recalls,
//! also in the next session of the same project), Enter repeating a step,
//! Ctrl-C at the prompt and during a `continue`, a conditional
//! breakpoint, a log point, and a register set that changes the robot's
//! answer.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use scorpion_tests::tools;

const PROMPT: &str = "(scorpion) ";

/// A tmux server of this test's own, killed when dropped.
struct Tmux {
    socket: String,
    /// The session typed into and read.
    target: std::cell::RefCell<String>,
}

impl Tmux {
    fn run(&self, args: &[&str]) -> String {
        let output = Command::new("tmux")
            .args(["-L", &self.socket])
            .args(args)
            .output()
            .expect("tmux runs");
        String::from_utf8_lossy(&output.stdout).into_owned()
    }

    /// Everything the pane has shown (its scrollback too).
    fn screen(&self) -> String {
        self.run(&[
            "capture-pane",
            "-p",
            "-J",
            "-S",
            "-",
            "-t",
            &self.target.borrow(),
        ])
    }

    /// Waits until `wanted` shows `times` times in all (or 20 s pass,
    /// failing with the screen).
    fn wait_for(&self, wanted: &str, times: usize) -> String {
        let start = Instant::now();
        loop {
            let screen = self.screen();
            if screen.matches(wanted).count() >= times {
                return screen;
            }
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "`{wanted}` not shown {times} times:\n{screen}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Types `keys` literally, then Enter, and waits for the next prompt
    /// (keys typed while a command runs could be lost when the editor
    /// takes the terminal back).
    fn type_line(&self, keys: &str) {
        let prompts = self.screen().matches(PROMPT).count();
        self.type_only(keys);
        self.wait_for(PROMPT, prompts + 1);
    }

    /// Types `keys` literally, then Enter.
    fn type_only(&self, keys: &str) {
        if !keys.is_empty() {
            self.run(&["send-keys", "-t", &self.target.borrow(), "-l", keys]);
        }
        self.run(&["send-keys", "-t", &self.target.borrow(), "Enter"]);
    }

    fn key(&self, key: &str) {
        self.run(&["send-keys", "-t", &self.target.borrow(), key]);
    }

    /// Starts `scorpion debug` in `dir` in a new session's window.
    fn start(&self, dir: &Path) {
        let command = format!(
            "cd '{}' && NO_COLOR=1 '{}' debug; sleep 30",
            dir.display(),
            env!("CARGO_BIN_EXE_scorpion")
        );
        self.run(&[
            "new-session",
            "-d",
            "-s",
            &self.target.borrow(),
            "-x",
            "250",
            "-y",
            "50",
            &command,
        ]);
        self.run(&[
            "set-option",
            "-t",
            &self.target.borrow(),
            "history-limit",
            "10000",
        ]);
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["-L", &self.socket, "kill-server"])
            .output();
    }
}

/// The ADC example as a project of its own, in a temporary directory.
fn adc_project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    for file in ["Scorpion.toml", "adc.s", "adc.rhai", "adc.expect"] {
        std::fs::copy(adc.join(file), dir.path().join(file)).expect("copy the example");
    }
    dir
}

#[test]
fn a_monitor_session_at_a_terminal() {
    if tools::require("tmux", "cli::debug_pty").is_none() {
        return;
    }
    let project = adc_project();
    let tmux = Tmux {
        socket: format!("scorpion-debug-{}", std::process::id()),
        target: std::cell::RefCell::new("monitor".to_owned()),
    };
    tmux.start(project.path());
    tmux.wait_for("(scorpion) ", 1);

    // A conditional breakpoint over registers, memory and symbols: not
    // for channel 0, for channel 1.
    tmux.type_line("break read_channel if A == 'A' && [CMDBUF+1] == '1'");
    tmux.wait_for("breakpoint 1: $0400 (read_channel) if A == 'A'", 1);
    // A log point where the reading is in A.
    tmux.type_line("break adc.s:53 log channel {[CMDBUF+1] - '0'} read {A}");
    tmux.wait_for("log point 2: $0431", 1);
    tmux.type_line("/2A0");
    tmux.type_line("continue");
    let screen = tmux.wait_for("< AC0\\r", 1);
    assert!(
        screen.contains("log 2 at $0431 (read_channel+$31): channel $00 read $C0"),
        "{screen}"
    );
    assert!(!screen.contains("breakpoint 1 ("), "{screen}");
    tmux.type_line("/2A1");
    tmux.type_line("continue");
    tmux.wait_for("breakpoint 1 ($0400 (read_channel))", 1);

    // A register set that changes the robot's answer.
    tmux.type_line("break adc.s:53 if A == $57");
    tmux.type_line("continue");
    tmux.wait_for("breakpoint 3 ($0431", 1);
    tmux.type_line("set A $05");
    tmux.wait_for("A = $05", 1);
    tmux.type_line("delete 3");
    tmux.type_line("continue");
    let screen = tmux.wait_for("< A05\\r", 1);
    assert!(!screen.contains("< A57"), "{screen}");

    // History: Up recalls the last line.
    tmux.type_line("regs");
    tmux.wait_for("\nPC=$", 1);
    tmux.key("Up");
    tmux.type_line("");
    tmux.wait_for("\nPC=$", 2);
    // Enter on an empty line repeats a step.
    tmux.type_line("step");
    tmux.wait_for("stepped: ", 1);
    tmux.type_line("");
    tmux.wait_for("stepped: ", 2);

    // Ctrl-C at the prompt does not end the monitor.
    tmux.key("C-c");
    tmux.wait_for("(Ctrl-C: `quit` or Ctrl-D leaves)", 1);
    tmux.type_line("print A + 1");
    tmux.wait_for("A + 1 = $", 1);
    // Ctrl-C during a continue of an hour of robot time pauses it.
    tmux.type_only("continue 3600000000");
    std::thread::sleep(Duration::from_millis(700));
    tmux.key("C-c");
    let screen = tmux.wait_for("paused (Ctrl-C): ", 1);
    let after = &screen[screen.rfind("continue 3600000000").unwrap_or(0)..];
    assert!(!after.contains("still running"), "{screen}");
    tmux.type_line("regs");
    tmux.wait_for("\nPC=$", 3);
    tmux.type_only("quit");

    // The next session in this project remembers: Up, Up is the long
    // continue.
    // The file is written again after each line: read it once `quit` is
    // in it.
    let history = project.path().join("target/debug-history");
    let start = Instant::now();
    let kept = loop {
        let kept = std::fs::read_to_string(&history).unwrap_or_default();
        if kept.contains("quit") || start.elapsed() > Duration::from_secs(10) {
            break kept;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(kept.contains("continue 3600000000"), "{kept}");
    // A second session beside the first (whose window waits), so that
    // the tmux server stays up.
    tmux.target.replace("again".to_owned());
    tmux.start(project.path());
    tmux.wait_for("(scorpion) ", 1);
    tmux.key("Up");
    tmux.key("Up");
    tmux.wait_for("(scorpion) regs", 1);
    tmux.key("Up");
    tmux.wait_for("(scorpion) continue 3600000000", 1);
}
