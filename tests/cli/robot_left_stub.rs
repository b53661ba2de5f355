//! A new user's findings F3 and F5 (issue 27, the `robot7` round), on a
//! `scorpion sim --pty` robot: after `kill -9` of `scorpion debug --port`
//! the stub a session left is named by `ask` (a robot stopped in it is
//! not "line noise") and by `installed` (the hook leads to it), with the
//! one size every message gives it and what to run.

use crate::robot_debug::readme_handler_on_a_pty_robot;
use crate::robot_recovery::killed_monitor;
use crate::{scorpion, transcript};

/// F3: a robot stopped in the stub answers `ask` with the stub's stop
/// frame; `ask` says so and what to run, and fails.
#[test]
fn ask_at_a_robot_stopped_in_a_left_stub_says_so() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    killed_monitor(dir.path(), &sim, "break show\n/1Q\n", "PC=");
    let output = scorpion(dir.path(), &["ask", "--port", &sim.path, "/1Q"]);
    let printed = transcript(&output);
    assert!(!output.status.success(), "{printed}");
    let said = printed.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        said.contains("uploader::stopped_in_debug_stub"),
        "{printed}"
    );
    assert!(said.contains("stopped in the debug stub"), "{printed}");
    assert!(
        said.contains(&format!("scorpion debug --port {}", sim.path)),
        "{printed}"
    );
    assert!(!said.contains("line noise"), "{printed}");
}
