//! The README's terminal-program command, run as a person would: picocom
//! on `scorpion sim --pty`, driven under tmux with typed keys, its screen
//! read back. Answers end with a carriage return only, so without
//! `--imap crcrlf` each overwrites the last; with it (and `--echo`), every
//! command and its answer stand on a line of their own.

use std::process::Command;
use std::time::{Duration, Instant};

use scorpion_tests::tools;

use crate::upload::Sim;

/// A tmux server of this test's own, killed when dropped.
struct Tmux {
    socket: String,
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
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["-L", &self.socket, "kill-server"])
            .output();
    }
}

/// Waits until the screen shows `wanted` (or a few seconds pass).
fn screen_with(tmux: &Tmux, wanted: &str) -> String {
    let start = Instant::now();
    loop {
        let screen = tmux.run(&["capture-pane", "-p", "-t", "robot"]);
        if screen.contains(wanted) || start.elapsed() > Duration::from_secs(10) {
            return screen;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn picocom_as_the_readme_writes_it_shows_one_answer_a_line() {
    let (Some(_), Some(_)) = (
        tools::require("picocom", "cli::terminal::picocom"),
        tools::require("tmux", "cli::terminal::picocom"),
    ) else {
        return;
    };
    let sim = Sim::start();
    let tmux = Tmux {
        socket: format!("scorpion-test-{}", std::process::id()),
    };
    // The README's command, with the pseudo-terminal's path.
    let picocom = format!("picocom -b 9600 --imap crcrlf --echo {}", sim.path);
    tmux.run(&[
        "new-session",
        "-d",
        "-s",
        "robot",
        "-x",
        "80",
        "-y",
        "24",
        &picocom,
    ]);
    screen_with(&tmux, "Terminal ready");
    for command in ["/1X", "/2E3", "/1E", "/7R020003"] {
        tmux.run(&["send-keys", "-t", "robot", command]);
        std::thread::sleep(Duration::from_millis(200));
        tmux.run(&["send-keys", "-t", "robot", "Enter"]);
    }
    let screen = screen_with(&tmux, "R4C21FF");
    let lines: Vec<&str> = screen.lines().map(str::trim_end).collect();
    for wanted in ["/1XX00", "/2E3", "/1EE3", "/7R020003R4C21FF"] {
        assert!(
            lines.contains(&wanted),
            "`{wanted}` is not a line of its own on the screen:\n{screen}"
        );
    }
}
