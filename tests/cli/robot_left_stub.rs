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

/// F5: a monitor killed while the robot runs leaves its stub hooked;
/// `installed` names it (its range, what it chains to, as the upload's
/// refusal gives them) and what to run; the range is the one the session
/// gave when it attached (two sizes were given before: code alone, and
/// code with its data).
#[test]
fn installed_names_a_stub_a_killed_monitor_left_hooked() {
    let (dir, sim) = readme_handler_on_a_pty_robot();
    let attached = killed_monitor(dir.path(), &sim, "break show\n", "breakpoint 1:");
    let output = scorpion(dir.path(), &["installed", "--port", &sim.path]);
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    let upload = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", &sim.path, "--no-dry-run"],
    );
    let refused = transcript(&upload)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    // The range and chain the upload's refusal gives: the same here.
    let start = refused.find("debug stub at $").expect(&refused) + "debug stub at ".len();
    let range = &refused[start..start + "$0C34-$0E06".len()];
    let said = printed.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(said.contains("debug stub left hooked at"), "{printed}");
    assert!(said.contains(range), "{range}: {printed}");
    // One size for the stub: the session that left it gave the same.
    assert!(
        attached.contains(&format!("the stub at {range},")),
        "{range}: {attached}"
    );
    assert!(
        said.contains(&format!("scorpion debug --port {}", sim.path)),
        "{printed}"
    );
    // fresh19 F5: the extension the stub chains to is reached through it.
    assert!(!said.contains("not hooked"), "{printed}");
}
