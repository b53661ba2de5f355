//! hostile16 F4: a program whose control-loop handler counts in its own
//! `.data` (16 bits: however many passes go by between two reads, one of
//! its bytes has changed), the counter the first bytes after its code (ca65 puts `.data`
//! after `.code`), on the pty robot. `debug --port` could not attach and
//! `scorpion backup` could not save: both read the counter with the code
//! around it, and took its changing for a failed read. Now the session
//! attaches and a display shows the count as it goes; the backup and
//! `scorpion read` save and show it, and name the byte that changed; an
//! editor's watch and memory view show it too.

use crate::robot::Sim;
use crate::{scorpion, scorpion_with_input, transcript};

const SOURCE: &str = r#"        .include "scorpion.inc"
        .code
        SCORPION_UNKNOWN_HANDLER
        cmp #'W'
        bne not_mine
        lda #'W'
        jsr PUTCH
        lda count
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
not_mine:
        SCORPION_CHAIN_UNKNOWN

        SCORPION_LOOP_HANDLER
lh:     inc count
        bne done
        inc count+1
done:   SCORPION_CHAIN_LOOP
        .data
count:  .word 0
"#;

fn counting_on_a_pty_robot() -> (tempfile::TempDir, Sim) {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("count.s"), SOURCE).expect("the source");
    let built = scorpion(dir.path(), &["build", "count.s", "-o", "count.elf"]);
    assert!(built.status.success(), "{}", transcript(&built));
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(
        dir.path(),
        &["upload", "count.elf", "--port", &sim.path, "--no-dry-run"],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    (dir, sim)
}

#[test]
fn a_session_attaches_beside_a_counter_and_displays_it_as_it_goes() {
    let (dir, sim) = counting_on_a_pty_robot();
    let output = scorpion_with_input(
        Some(dir.path()),
        &["debug", "--port", &sim.path, "--image", "count.elf"],
        "display [count] + 256*[count+1]\npoke count $00 $00\nbreak lh\ncontinue\nprint [count]\ndelete 1\ncontinue\nquit\n",
    );
    let printed = transcript(&output);
    assert!(output.status.success(), "{printed}");
    // fresh17 F8: the poke took; the count goes on from it.
    assert!(
        printed.contains(": 00 00 (written; the robot's program writes $04"),
        "{printed}"
    );
    assert!(
        printed.contains("display 1: [count] + 256*[count+1] = $")
            && printed.contains("(changing: the robot wrote $"),
        "the count shown as it goes:\n{printed}"
    );
    assert!(printed.contains("stopped: breakpoint 1, $"), "{printed}");
    assert!(printed.contains("detached"), "{printed}");
    // At the stop nothing changes: the count is read without a note.
    let stop = printed
        .split("(robot) print [count]")
        .nth(1)
        .expect("the print at the stop");
    let line = stop.lines().nth(1).expect("its value");
    assert!(
        line.starts_with('$') && !line.contains("changing"),
        "{printed}"
    );
}

#[test]
fn a_backup_of_a_robot_counting_saves_and_names_the_counter() {
    let (dir, sim) = counting_on_a_pty_robot();
    // `scorpion read` over the code and the counter gives the bytes, and
    // names the counter.
    let output = scorpion(dir.path(), &["read", "--port", &sim.path, "$0400", "64"]);
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(
        said.contains("note: the robot wrote $04") && said.contains("0400: C9 57"),
        "{said}"
    );
    let output = scorpion(
        dir.path(),
        &["backup", "--port", &sim.path, "-o", "robot.bak"],
    );
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(
        said.contains("changed while") && said.contains(" read ($04"),
        "{said}"
    );
    let output = scorpion(dir.path(), &["restore", "--port", &sim.path, "robot.bak"]);
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion(dir.path(), &["ask", "--port", &sim.path, "/1W"]);
    assert!(transcript(&output).contains("W"), "{}", transcript(&output));
}

#[test]
fn an_editors_watch_and_memory_view_show_a_counter_as_it_goes() {
    use serde_json::json;
    let (dir, sim) = counting_on_a_pty_robot();
    let program = dir.path().join("count.elf");
    let mut dap = crate::dap::Client::start();
    let init = dap.request("initialize", json!({"adapterID": "scorpion"}));
    assert_eq!(init["success"], true, "{init}");
    let launch = dap.request(
        "launch",
        json!({"program": program.to_str().expect("a path"), "port": sim.path}),
    );
    assert_eq!(launch["success"], true, "{launch}");
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");
    let watch = dap.request(
        "evaluate",
        json!({"expression": "[count] + 256*[count+1]", "context": "watch"}),
    );
    assert_eq!(watch["success"], true, "{watch}");
    let result = watch["body"]["result"].as_str().unwrap_or_default();
    assert!(
        result.starts_with('$') && result.contains("(changing: the robot wrote $04"),
        "{watch}"
    );
    let read = dap.request(
        "readMemory",
        json!({"memoryReference": "0x0400", "count": 64}),
    );
    assert_eq!(read["success"], true, "{read}");
    assert!(read["body"].get("unreadableBytes").is_none(), "{read}");
    // fresh17 F2: the console says which bytes change.
    let said = (0..4)
        .map(|_| dap.event("output")["body"]["output"].clone())
        .find(|output| {
            output
                .as_str()
                .is_some_and(|text| text.starts_with("readMemory: "))
        });
    assert!(
        said.as_ref()
            .and_then(|text| text.as_str())
            .is_some_and(|text| text.contains("the robot wrote $04")),
        "{said:?}"
    );
    let bye = dap.request("disconnect", json!({}));
    assert_eq!(bye["success"], true, "{bye}");
    assert!(dap.ends());
}

/// fresh17 F1: uploaded again after it counted, the same image is no
/// change to what is installed (its data put back as built, said), and
/// the undo goes back to the robot before the first upload.
#[test]
fn the_same_image_again_after_it_counted_is_undone_to_the_robot_before() {
    let (dir, sim) = counting_on_a_pty_robot();
    let output = scorpion(
        dir.path(),
        &["upload", "count.elf", "--port", &sim.path, "--no-dry-run"],
    );
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(
        said.contains("the robot held this image already, installed as it is now")
            && said.contains("(its data, which its program had changed, is put back as built)"),
        "{said}"
    );
    let output = scorpion(dir.path(), &["upload", "--undo", "--port", &sim.path]);
    assert!(output.status.success(), "{}", transcript(&output));
    let output = scorpion(dir.path(), &["installed", "--port", &sim.path]);
    assert!(
        transcript(&output).contains("nothing installed"),
        "{}",
        transcript(&output)
    );
}
