//! Issue 27, point 4, through an editor's debugger: `scorpion dap` with a
//! `launch` that names the robot's `port` (here `scorpion sim --pty`
//! standing for the robot) drives the debug stub: a breakpoint by source
//! line in the handler (a condition refused for its breakpoint alone),
//! the command sent from the debug console stops there, the frame and the
//! registers, a register and a byte written, a step, continue and the
//! robot's answer as output, what a robot cannot do refused, disconnect;
//! then the code (read with `scorpion read`) compared with the image.

use isa::objfmt::{HookKind, HookRecord, Hooks, SourceLoc, SrcMap, SrcMapEntry};
use linker::layout::SegmentKind;
use linker::{Format, Image, ImageSection, ImageSymbol, LoadArea};
use serde_json::json;

use crate::dap::Client;
use crate::robot::Sim;
use crate::robot_debug::handler_bytes;
use crate::{scorpion, transcript};

/// The handler's source, a line for each instruction of
/// [`handler_bytes`], with where its bytes start.
const SOURCE: [(&str, u32); 10] = [
    ("        jmp chain", 0x0400),
    ("handler: cmp #'Q'", 0x0403),
    ("        bne $0400", 0x0405),
    ("        lda #'Q'", 0x0407),
    ("        jsr PUTCH", 0x0409),
    ("show:   lda value", 0x040C),
    ("        jsr PUTHEX", 0x040F),
    ("        jsr PUTEOL", 0x0412),
    ("        jmp CMD_DONE", 0x0415),
    ("value:  .byte $42", 0x0480),
];

/// The handler as a linked image with its section and line table.
fn handler_elf() -> Vec<u8> {
    let symbol = |name: &str, value: u32| ImageSymbol {
        name: name.to_owned(),
        value,
        size: 0,
        global: true,
        section: None,
    };
    let entries = SOURCE
        .iter()
        .zip(1..)
        .map(|((_, at), line)| SrcMapEntry {
            section: 0,
            offset: *at,
            loc: SourceLoc {
                file: 0,
                line,
                column: 1,
            },
        })
        .collect();
    let bytes = handler_bytes();
    let image = Image {
        entry: 0x0403,
        flags: 0,
        sections: vec![ImageSection {
            name: "CODE".into(),
            run: 0x0400,
            load: 0x0400,
            size: u32::try_from(bytes.len()).expect("small"),
            kind: SegmentKind::ReadOnly,
            exec: true,
        }],
        areas: vec![LoadArea {
            load: 0x0400,
            run: 0x0400,
            bytes,
        }],
        symbols: vec![
            symbol("handler", 0x0403),
            symbol("show", 0x040C),
            symbol("value", 0x0480),
        ],
        hooks: Hooks {
            records: vec![HookRecord {
                kind: HookKind::Unknown,
                handler: 0x0403,
                chain: Some(0x0401),
            }],
        },
        lines: SrcMap {
            files: vec!["handler.s".into()],
            entries,
            ..SrcMap::default()
        },
    };
    Format::Elf.write(&image).expect("an ELF image")
}

/// The handler and its source in a new directory, uploaded to a new pty
/// robot.
fn handler_on_a_pty_robot() -> (tempfile::TempDir, Sim) {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), handler_elf()).expect("the image");
    let source: String = SOURCE.iter().map(|(line, _)| format!("{line}\n")).collect();
    std::fs::write(dir.path().join("handler.s"), source).expect("the source");
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(
        dir.path(),
        &["upload", "ext.elf", "--port", &sim.path, "--no-dry-run"],
    );
    assert!(output.status.success(), "{}", transcript(&output));
    (dir, sim)
}

/// The robot's code ($0400, the handler's 129 bytes) and `HOOK_UNKNOWN`,
/// read on `sim`'s line.
fn code_and_hook(dir: &std::path::Path, sim: &Sim) -> (Vec<u8>, Vec<u8>) {
    let read = |at: &str, len: &str, file: &str| {
        let output = scorpion(dir, &["read", at, len, "-o", file, "--port", &sim.path]);
        assert!(output.status.success(), "{}", transcript(&output));
        std::fs::read(dir.join(file)).expect("a dump")
    };
    (
        read("$0400", "129", "after.bin"),
        read("$0200", "3", "hook.bin"),
    )
}

/// An adapter initialized and launched on `sim`'s robot with `dir`'s
/// `ext.elf`.
fn launched(dir: &std::path::Path, sim: &Sim) -> Client {
    let program = dir.join("ext.elf");
    launched_with(json!({"program": program.to_str().expect("a path"), "port": sim.path}))
}

/// An adapter initialized and launched with `arguments`.
fn launched_with(arguments: serde_json::Value) -> Client {
    let mut dap = Client::start();
    let init = dap.request("initialize", json!({"adapterID": "scorpion"}));
    assert_eq!(init["success"], true, "{init}");
    let launch = dap.request("launch", arguments);
    assert_eq!(launch["success"], true, "{launch}");
    dap
}

/// Lets the stopped robot go on, then disconnects; the adapter ends.
fn continue_and_disconnect(mut dap: Client) {
    let go = dap.request("continue", json!({"threadId": 1}));
    assert_eq!(go["success"], true, "{go}");
    let bye = dap.request("disconnect", json!({}));
    assert_eq!(bye["success"], true, "{bye}");
    assert!(dap.ends());
}

#[test]
fn a_dap_session_on_the_pty_robot_and_the_code_compared_after() {
    let (dir, sim) = handler_on_a_pty_robot();
    let mut dap = launched(dir.path(), &sim);
    // The seconds of the attach are said in the editor's console first.
    let said = dap.event("output");
    assert_eq!(said["body"]["category"], "console", "{said}");
    assert!(
        said["body"]["output"].as_str().is_some_and(
            |text| text.starts_with(&format!("attaching to the robot on {}", sim.path))
        ),
        "{said}"
    );
    // fresh15 F3: what stays in RAM after it, as the monitor says it.
    let said = dap.event("output");
    assert!(
        said["body"]["output"]
            .as_str()
            .is_some_and(|text| text.starts_with("the debug stub is at $")
                && text.contains("in memory after the session, unhooked; no undo puts back")),
        "{said}"
    );
    // On the robot there is no going back and no data breakpoint.
    let capabilities = dap.event("capabilities");
    assert_eq!(
        capabilities["body"]["capabilities"]["supportsStepBack"], false,
        "{capabilities}"
    );
    assert_eq!(
        capabilities["body"]["capabilities"]["supportsDataBreakpoints"], false,
        "{capabilities}"
    );

    // Line 6 is `show`; line 7's condition is refused, for it alone.
    let path = dir.path().join("handler.s");
    let set = dap.request(
        "setBreakpoints",
        json!({"source": {"path": path.to_str().expect("a path")},
               "breakpoints": [{"line": 6}, {"line": 7, "condition": "A == 1"}]}),
    );
    assert_eq!(set["success"], true, "{set}");
    let answers = &set["body"]["breakpoints"];
    assert_eq!(answers[0]["verified"], true, "{set}");
    assert_eq!(answers[0]["instructionReference"], "0x040C", "{set}");
    assert_eq!(answers[1]["verified"], false, "{set}");
    assert!(
        answers[1]["message"]
            .as_str()
            .is_some_and(|m| m.contains("refused on the robot")),
        "{set}"
    );
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");

    // The command goes down the line and stops at the breakpoint.
    let sent = dap.request("evaluate", json!({"expression": "/1Q", "context": "repl"}));
    assert_eq!(sent["success"], true, "{sent}");
    assert!(
        sent["body"]["result"]
            .as_str()
            .is_some_and(|r| r.contains("stopped at $040C")),
        "{sent}"
    );
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "breakpoint", "{stopped}");
    assert_eq!(
        stopped["body"]["hitBreakpointIds"],
        json!([answers[0]["id"]])
    );
    let frame = dap.top_frame();
    assert_eq!(frame["line"], 6, "{frame}");
    assert_eq!(frame["instructionPointerReference"], "0x040C", "{frame}");
    // At the stop: A holds the letter, X the count (docs/PROTOCOL.md).
    assert_eq!(dap.register("A"), "$51");
    assert_eq!(dap.register("X"), "$01");
    let print = dap.request("evaluate", json!({"expression": "A + 1"}));
    assert_eq!(print["body"]["result"], "$52", "{print}");

    // A register written back (the handler loads A next: harmless).
    let set = dap.request(
        "setVariable",
        json!({"variablesReference": 1, "name": "A", "value": "$77"}),
    );
    assert_eq!(set["success"], true, "{set}");
    assert_eq!(dap.register("A"), "$77");

    // A byte written through the stub and read back.
    let written = dap.request(
        "writeMemory",
        json!({"memoryReference": "0x0480", "data": "mQ=="}),
    );
    assert_eq!(written["success"], true, "{written}");
    let read = dap.request(
        "readMemory",
        json!({"memoryReference": "0x0480", "count": 1}),
    );
    assert_eq!(read["body"]["data"], "mQ==", "{read}");
    // fresh15 F7: a view running into the KIM bus does not read it.
    let read = dap.request(
        "readMemory",
        json!({"memoryReference": "0x0FFE", "count": 4}),
    );
    assert_eq!(read["body"]["unreadableBytes"], 2, "{read}");

    // One instruction, LDA value: A holds the changed byte.
    let next = dap.request("next", json!({"threadId": 1}));
    assert_eq!(next["success"], true, "{next}");
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "step", "{stopped}");
    assert_eq!(dap.top_frame()["instructionPointerReference"], "0x040F");
    assert_eq!(dap.register("A"), "$99");

    // What a robot cannot do is refused, with the reason.
    for refused in ["stepBack", "setDataBreakpoints", "disassemble"] {
        let answer = dap.request(refused, json!({"threadId": 1}));
        assert_eq!(answer["success"], false, "{answer}");
        assert!(
            answer["message"]
                .as_str()
                .is_some_and(|m| m.contains("refused on the robot")),
            "{answer}"
        );
    }

    // Continue: the robot's answer comes as output.
    let go = dap.request("continue", json!({"threadId": 1}));
    assert_eq!(go["success"], true, "{go}");
    let mut heard = String::new();
    while !heard.contains("Q99") {
        let output = dap.event("output");
        if output["body"]["category"] == "stdout" {
            heard.push_str(output["body"]["output"].as_str().unwrap_or_default());
        }
    }
    let pause = dap.request("pause", json!({"threadId": 1}));
    assert_eq!(pause["success"], false, "{pause}");
    assert!(
        pause["message"]
            .as_str()
            .is_some_and(|m| m.contains("refused on the robot")),
        "{pause}"
    );

    let bye = dap.request("disconnect", json!({}));
    assert_eq!(bye["success"], true, "{bye}");
    assert!(dap.ends());

    // The code is the image's again, but for the byte changed; the hook
    // is the handler's again.
    let (code, hook) = code_and_hook(dir.path(), &sim);
    let mut expected = handler_bytes();
    expected[0x80] = 0x99;
    assert_eq!(code, expected);
    assert_eq!(hook, [0x4C, 0x03, 0x04]);
}

#[test]
fn a_launch_on_a_port_that_is_not_there_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(dir.path().join("ext.elf"), handler_elf()).expect("the image");
    let port = dir.path().join("no-such-tty");
    let port = port.to_str().expect("a path");
    let mut dap = Client::start();
    let init = dap.request("initialize", json!({"adapterID": "scorpion"}));
    assert_eq!(init["success"], true, "{init}");
    let program = dir.path().join("ext.elf");
    let launch = dap.request(
        "launch",
        json!({"program": program.to_str().expect("a path"), "port": port}),
    );
    assert_eq!(launch["success"], false, "{launch}");
    assert!(
        launch["message"].as_str().is_some_and(|m| m.contains(port)),
        "{launch}"
    );
    // The session goes on: nothing is attached, and it ends cleanly.
    let trace = dap.request("stackTrace", json!({"threadId": 1}));
    assert_eq!(trace["success"], false, "{trace}");
    let bye = dap.request("disconnect", json!({}));
    assert_eq!(bye["success"], true, "{bye}");
    assert!(dap.ends());
}

/// Issue 27, round 6: a `next` over `JSR PUTEOL` runs on (the answer ends
/// before it stops): its stop, heard later, is where the step ended, so
/// its reason is `step` with no breakpoint named (it was `breakpoint`).
#[test]
fn a_step_that_ran_on_stops_with_the_reason_step() {
    let (dir, sim) = handler_on_a_pty_robot();
    let mut dap = launched(dir.path(), &sim);
    let path = dir.path().join("handler.s");
    // Line 8 is `jsr PUTEOL`, at $0412.
    let set = dap.request(
        "setBreakpoints",
        json!({"source": {"path": path.to_str().expect("a path")},
               "breakpoints": [{"line": 8}]}),
    );
    let id = set["body"]["breakpoints"][0]["id"].clone();
    assert_eq!(set["body"]["breakpoints"][0]["verified"], true, "{set}");
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");
    let sent = dap.request("evaluate", json!({"expression": "/1Q", "context": "repl"}));
    assert_eq!(sent["success"], true, "{sent}");
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "breakpoint", "{stopped}");
    assert_eq!(
        stopped["body"]["hitBreakpointIds"],
        json!([id]),
        "{stopped}"
    );
    assert_eq!(dap.top_frame()["instructionPointerReference"], "0x0412");

    let next = dap.request("next", json!({"threadId": 1}));
    assert_eq!(next["success"], true, "{next}");
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "step", "{stopped}");
    assert!(
        stopped["body"].get("hitBreakpointIds").is_none(),
        "{stopped}"
    );
    assert_eq!(dap.top_frame()["instructionPointerReference"], "0x0415");
    let mut heard = String::new();
    while !heard.contains("Q42") {
        let output = dap.event("output");
        if output["body"]["category"] == "stdout" {
            heard.push_str(output["body"]["output"].as_str().unwrap_or_default());
        }
    }
    continue_and_disconnect(dap);
}

/// Issue 27, round 6: a launch that cleans up after a monitor killed at a
/// stop says so in the editor's console (the monitor's sentence), before
/// the first stop, which is where the robot was found.
#[test]
fn a_launch_says_what_it_cleaned_up_in_the_console_before_the_first_stop() {
    let (dir, sim) = crate::robot_debug::readme_handler_on_a_pty_robot();
    crate::robot_recovery::killed_monitor(dir.path(), &sim, "break show\n/1Q\n", "PC=");
    let mut dap = launched(dir.path(), &sim);
    let said = loop {
        let output = dap.event("output");
        let text = output["body"]["output"].as_str().unwrap_or_default();
        if output["body"]["category"] == "console"
            && !text.starts_with("attaching")
            && !text.starts_with("the debug stub is at")
        {
            break output;
        }
    };
    let text = said["body"]["output"].as_str().unwrap_or_default();
    for expected in [
        "an earlier session did not detach",
        "stopped in its stub at $0409",
        "breakpoints at $0409 were taken out",
    ] {
        assert!(text.contains(expected), "{expected}: {said}");
    }
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "entry", "{stopped}");
    assert!(
        said["seq"].as_i64().expect("a seq") < stopped["seq"].as_i64().expect("a seq"),
        "the sentence before the stop: {said} {stopped}"
    );
    continue_and_disconnect(dap);
}

/// hostile10 F6: an adapter whose editor went away without `disconnect`
/// (its input closed), or that the editor ended with a signal, left the
/// robot stopped in the stub, or with the stub hooked and its breakpoints
/// in the code (exit 0): the next command froze the robot. Now either lets
/// the robot go as `disconnect` does.
#[test]
fn an_editor_gone_without_disconnect_lets_the_robot_go() {
    for how in ["input closed", "TERM", "HUP"] {
        let (dir, sim) = handler_on_a_pty_robot();
        let mut dap = launched(dir.path(), &sim);
        let path = dir.path().join("handler.s");
        let set = dap.request(
            "setBreakpoints",
            json!({"source": {"path": path.to_str().expect("a path")},
                   "breakpoints": [{"line": 6}]}),
        );
        assert_eq!(set["body"]["breakpoints"][0]["verified"], true, "{set}");
        let done = dap.request("configurationDone", json!({}));
        assert_eq!(done["success"], true, "{done}");
        let sent = dap.request("evaluate", json!({"expression": "/1Q", "context": "repl"}));
        assert_eq!(sent["success"], true, "{sent}");
        let stopped = dap.event("stopped");
        assert_eq!(stopped["body"]["reason"], "breakpoint", "{how}: {stopped}");
        match how {
            "input closed" => dap.close_input(),
            signal => dap.signal(signal),
        }
        // Ended (its exit status is the signal's, or 0 at the end of input).
        let _ = dap.ends();
        let (code, hook) = code_and_hook(dir.path(), &sim);
        assert_eq!(
            code,
            handler_bytes(),
            "{how}: the image's code, no JSR left"
        );
        assert_eq!(hook, [0x4C, 0x03, 0x04], "{how}: the hook given back");
        let output = scorpion(dir.path(), &["ask", "/1Q", "--port", &sim.path]);
        assert!(output.status.success(), "{how}: {}", transcript(&output));
    }
}

/// fresh10 F21 in an editor: a breakpoint in code the control loop runs
/// (examples/patrol's `rom`, the `JMP` on to the ROM's loop) took 35 s to
/// be refused as line noise, though its `JSR` was in. Now it is verified
/// and its stop comes as a `stopped` event, each `continue` stops there
/// again, and with it cleared the robot goes on. The adapter runs outside
/// the project (as an editor may start it): `program`, the project's
/// directory, says where the project is.
#[test]
fn a_breakpoint_in_the_control_loops_handler_stops_there_in_an_editor() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, sim) = crate::robot::patrol_on_a_pty_robot(dir.path());
    let source = project.join("patrol.s");
    let line = std::fs::read_to_string(&source)
        .expect("the source")
        .lines()
        .position(|l| l.trim() == "rom:")
        .expect("`rom:`")
        + 2;
    let mut dap =
        launched_with(json!({"program": project.to_str().expect("a path"), "port": sim.path}));
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");
    let breakpoints = |lines: &[usize]| {
        json!({"source": {"path": source.to_str().expect("a path")},
               "breakpoints": lines.iter().map(|l| json!({"line": l})).collect::<Vec<_>>()})
    };
    let set = dap.request("setBreakpoints", breakpoints(&[line]));
    assert_eq!(set["body"]["breakpoints"][0]["verified"], true, "{set}");
    let id = set["body"]["breakpoints"][0]["id"].clone();
    for _ in 0..2 {
        let stopped = dap.event("stopped");
        assert_eq!(stopped["body"]["reason"], "breakpoint", "{stopped}");
        assert_eq!(
            stopped["body"]["hitBreakpointIds"],
            json!([id]),
            "{stopped}"
        );
        assert_eq!(dap.top_frame()["instructionPointerReference"], "0x104E");
        let go = dap.request("continue", json!({"threadId": 1}));
        assert_eq!(go["success"], true, "{go}");
    }
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "breakpoint", "{stopped}");
    let cleared = dap.request("setBreakpoints", breakpoints(&[]));
    assert_eq!(cleared["success"], true, "{cleared}");
    let go = dap.request("continue", json!({"threadId": 1}));
    assert_eq!(go["success"], true, "{go}");
    let bye = dap.request("disconnect", json!({}));
    assert_eq!(bye["success"], true, "{bye}");
    assert!(dap.ends());
    let output = scorpion(&project, &["installed", "--port", &sim.path]);
    let said = transcript(&output);
    assert!(output.status.success(), "{said}");
    assert!(!said.contains("debug stub"), "{said}");
    let output = scorpion(&project, &["read", "--port", &sim.path, "$104E", "3"]);
    assert!(
        transcript(&output).contains("4C 24 FF"),
        "{}",
        transcript(&output)
    );
}

/// fresh11 F3: with DEBUGGING.md's robot config (`program`, the image
/// in the project's `target/scorpion/`, and `port`), the frames named
/// `target/scorpion/src/myext.s`, which does not exist: the sources were
/// taken from the image's directory, not the project's root as the
/// virtual robot's launch takes them.
#[test]
fn a_robot_launch_on_a_projects_image_names_the_projects_sources() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (project, source) = crate::new_project(dir.path());
    let sim = Sim::start(dir.path(), &[]);
    let output = scorpion(&project, &["upload", "--port", &sim.path, "--no-dry-run"]);
    assert!(output.status.success(), "{}", transcript(&output));
    let line = crate::lines_with(&source, "jsr PUTCH")[0];
    let path = project.join("src/myext.s");
    let image = project.join("target/scorpion/myext.elf");
    let mut dap =
        launched_with(json!({"program": image.to_str().expect("a path"), "port": sim.path}));
    let set = dap.request(
        "setBreakpoints",
        json!({"source": {"path": path.to_str().expect("a path")},
               "breakpoints": [{"line": line}]}),
    );
    assert_eq!(set["body"]["breakpoints"][0]["verified"], true, "{set}");
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");
    let sent = dap.request("evaluate", json!({"expression": "/1V", "context": "repl"}));
    assert_eq!(sent["success"], true, "{sent}");
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "breakpoint", "{stopped}");
    let frame = dap.top_frame();
    assert_eq!(
        frame["source"]["path"],
        path.to_str().expect("a path"),
        "{frame}"
    );
    assert_eq!(frame["line"], line, "{frame}");
    continue_and_disconnect(dap);
}

/// fresh10 F18: with `port`, the launch's `stopOnEntry` and `commands`
/// (DEBUGGING.md's own editor configs have them) were ignored with no
/// word. The commands are sent at `configurationDone`, each answer as
/// output, until one stops at a breakpoint; `stopOnEntry` is said to be
/// impossible on a robot.
#[test]
fn a_robot_launch_sends_its_commands_and_says_it_cannot_stop_on_entry() {
    let (dir, sim) = handler_on_a_pty_robot();
    let program = dir.path().join("ext.elf");
    let mut dap = launched_with(json!({"program": program.to_str().expect("a path"),
        "port": sim.path, "stopOnEntry": true, "commands": ["/1X", "/1Q", "/1P"]}));
    let path = dir.path().join("handler.s");
    // Line 6 is `show: lda value`, at $040C.
    let set = dap.request(
        "setBreakpoints",
        json!({"source": {"path": path.to_str().expect("a path")},
               "breakpoints": [{"line": 6}]}),
    );
    assert_eq!(set["body"]["breakpoints"][0]["verified"], true, "{set}");
    let done = dap.request("configurationDone", json!({}));
    assert_eq!(done["success"], true, "{done}");
    let mut heard = String::new();
    while !heard.contains("not sent") {
        let output = dap.event("output");
        heard.push_str(output["body"]["output"].as_str().unwrap_or_default());
    }
    assert!(
        heard.contains("stopOnEntry: a robot cannot be stopped"),
        "{heard}"
    );
    assert!(heard.contains("X00"), "the first command's answer: {heard}");
    assert!(heard.contains("/1P not sent"), "{heard}");
    let stopped = dap.event("stopped");
    assert_eq!(stopped["body"]["reason"], "breakpoint", "{stopped}");
    assert_eq!(dap.top_frame()["instructionPointerReference"], "0x040C");
    continue_and_disconnect(dap);
}
