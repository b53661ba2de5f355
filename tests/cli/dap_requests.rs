//! `scorpion dap`'s requests for an assembly debugger (issue 25, point 2),
//! each driven over the real server's framing on the ADC example:
//! conditional and hit-count breakpoints and log points, function,
//! instruction and data breakpoints, `disassemble`, `setVariable`,
//! `writeMemory`, `restart`, exception breakpoints (a BRK, a JAM, a card's
//! fault), `loadedSources`; and `initialize` advertising exactly the
//! requests answered.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use super::dap::Client;

fn adc() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc")
}

/// The line of adc.s that starts with `text` (the `nth` such, from 0).
fn line_of(text: &str, nth: usize) -> u64 {
    let source = std::fs::read_to_string(adc().join("adc.s")).expect("adc.s");
    let index = source
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with(text))
        .nth(nth)
        .unwrap_or_else(|| panic!("adc.s has a line starting {text}"))
        .0;
    u64::try_from(index + 1).expect("a line number")
}

fn source() -> String {
    adc().join("adc.s").display().to_string()
}

/// A session launched on `program`, stopped on entry, `commands` sent at
/// configuration; `before` runs between launch and configurationDone.
fn launched(program: &Path, commands: &[&str], before: impl FnOnce(&mut Client)) -> Client {
    let mut c = Client::start();
    let init = c.request("initialize", json!({"adapterID": "scorpion"}));
    assert_eq!(init["success"], true, "{init}");
    c.event("initialized");
    let launch = c.request(
        "launch",
        json!({"program": program.display().to_string(), "stopOnEntry": true, "commands": commands}),
    );
    assert_eq!(launch["success"], true, "{launch}");
    before(&mut c);
    assert_eq!(c.request("configurationDone", json!({}))["success"], true);
    assert_eq!(c.event("stopped")["body"]["reason"], "entry");
    c
}

fn ok(response: &Value) -> &Value {
    assert_eq!(response["success"], true, "{response}");
    &response["body"]
}

fn refused(response: &Value) -> String {
    assert_eq!(response["success"], false, "{response}");
    response["message"].as_str().unwrap_or_default().to_owned()
}

/// Continues and returns the `stopped` event's body.
fn continue_to_stop(c: &mut Client) -> Value {
    ok(&c.request("continue", json!({"threadId": 1})));
    c.event("stopped")["body"].clone()
}

/// Output events until one whose text contains `text`; all their texts.
fn output_until(c: &mut Client, text: &str) -> String {
    let mut all = String::new();
    loop {
        let output = c.event("output");
        all.push_str(output["body"]["output"].as_str().unwrap_or_default());
        if all.contains(text) {
            return all;
        }
    }
}

fn end(mut c: Client) {
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}

/// Each `supports...` capability with the request that it promises.
const PROMISES: [(&str, &str); 16] = [
    ("supportsConfigurationDoneRequest", "configurationDone"),
    ("supportsStepBack", "stepBack"),
    ("supportsReadMemoryRequest", "readMemory"),
    ("supportsWriteMemoryRequest", "writeMemory"),
    ("supportsTerminateRequest", "terminate"),
    ("supportsRestartRequest", "restart"),
    ("supportsFunctionBreakpoints", "setFunctionBreakpoints"),
    ("supportsDataBreakpoints", "setDataBreakpoints"),
    ("supportsDataBreakpoints", "dataBreakpointInfo"),
    (
        "supportsInstructionBreakpoints",
        "setInstructionBreakpoints",
    ),
    ("supportsDisassembleRequest", "disassemble"),
    ("supportsSetVariable", "setVariable"),
    ("supportsExceptionInfoRequest", "exceptionInfo"),
    ("supportsLoadedSourcesRequest", "loadedSources"),
    ("supportsStepBack", "reverseContinue"),
    (
        "supportsConfigurationDoneRequest",
        "setExceptionBreakpoints",
    ),
];

/// `initialize` advertises what is answered and nothing else: every
/// promised request is taken (before launch: "launch a program first",
/// never "not a request this adapter takes"), requests of capabilities
/// not advertised are refused as unknown, and the exception filters are
/// the three this debugger stops at.
#[test]
fn initialize_advertises_exactly_the_requests_answered() {
    let mut c = Client::start();
    let init = c.request("initialize", json!({"adapterID": "scorpion"}));
    let capabilities = ok(&init).clone();
    let advertised: Vec<&str> = capabilities
        .as_object()
        .expect("an object")
        .iter()
        .filter(|(_, v)| **v == true)
        .map(|(k, _)| k.as_str())
        .collect();
    for (capability, request) in PROMISES {
        assert!(advertised.contains(&capability), "{capability}: {init}");
        if request == "terminate" {
            // It ends the session: `disconnect`'s twin, taken below.
            continue;
        }
        let answer = c.request(request, json!({}));
        let message = answer["message"].as_str().unwrap_or_default();
        assert!(
            !message.contains("not a request this adapter takes"),
            "{request}: {answer}"
        );
    }
    // Every capability advertised is one of those promised, or a
    // breakpoint option checked by the sessions below.
    let options = [
        "supportsConditionalBreakpoints",
        "supportsHitConditionalBreakpoints",
        "supportsLogPoints",
        "supportsDataBreakpointBytes",
    ];
    for capability in &advertised {
        assert!(
            PROMISES.iter().any(|(c, _)| c == capability) || options.contains(capability),
            "{capability} is advertised but not tested"
        );
    }
    for (capability, request) in [
        ("supportsGotoTargetsRequest", "gotoTargets"),
        ("supportsStepInTargetsRequest", "stepInTargets"),
        ("supportsCompletionsRequest", "completions"),
        ("supportsModulesRequest", "modules"),
    ] {
        assert!(capabilities.get(capability).is_none(), "{capability}");
        let message = refused(&c.request(request, json!({})));
        assert!(
            message.contains("not a request this adapter takes"),
            "{message}"
        );
    }
    let filters: Vec<&str> = capabilities["exceptionBreakpointFilters"]
        .as_array()
        .expect("filters")
        .iter()
        .filter_map(|f| f["filter"].as_str())
        .collect();
    assert_eq!(filters, ["jam", "brk", "card"]);
    assert_eq!(c.request("terminate", json!({}))["success"], true);
    // The client is told the debuggee ended (fresh11's nit: it was not).
    assert_eq!(c.event("terminated")["event"], "terminated");
    assert!(c.ends());
}

/// The monitor's `break ... if A == $32`, `hits 2` and `log` through
/// `setBreakpoints`: /2A1 passes the conditional breakpoint (A is $31
/// there) and is the first hit of the counted one; the log point logs
/// each lap of the wait loop with the status it read; /2A2 stops at the
/// condition, then at the second hit.
#[test]
fn conditions_hit_counts_and_log_points() {
    let (sec, wait, answer) = (
        line_of("sec", 0),
        line_of("@wait:", 0),
        line_of("lda #'A'", 1),
    );
    let mut ids = Vec::new();
    let mut c = launched(&adc(), &["/2A1"], |c| {
        let set = c.request(
            "setBreakpoints",
            json!({"source": {"path": source()}, "breakpoints": [
                {"line": sec, "condition": "A == $32"},
                {"line": wait, "logMessage": "lap: status {[$9001]}"},
                {"line": answer, "hitCondition": "2"},
                {"line": sec, "condition": "A =="},
            ]}),
        );
        let answers = ok(&set)["breakpoints"].as_array().expect("answers").clone();
        for answer in &answers[..3] {
            assert_eq!(answer["verified"], true, "{set}");
            ids.push(answer["id"].clone());
        }
        assert_eq!(answers[3]["verified"], false, "{set}");
        assert!(
            answers[3]["message"]
                .as_str()
                .is_some_and(|m| m.contains("condition")),
            "{set}"
        );
    });
    ok(&c.request("continue", json!({"threadId": 1})));
    let printed = output_until(&mut c, "A57");
    assert!(printed.contains("lap: status $"), "{printed}");
    // Still running: nothing stopped /2A1.
    ok(&c.request("evaluate", json!({"expression": "/2A2", "context": "repl"})));
    let stop = c.event("stopped")["body"].clone();
    assert_eq!(stop["reason"], "breakpoint", "{stop}");
    assert_eq!(stop["hitBreakpointIds"], json!([ids[0]]), "{stop}");
    assert_eq!(c.register("A"), "$32");
    assert_eq!(c.top_frame()["line"], sec);
    let stop = continue_to_stop(&mut c);
    assert_eq!(stop["hitBreakpointIds"], json!([ids[2]]), "{stop}");
    assert_eq!(c.top_frame()["line"], answer);
    end(c);
}

/// A label as a function breakpoint (with a robot command and a name that
/// is nowhere), watchpoints on the card's control register through
/// `dataBreakpointInfo` (registers refused), and an instruction breakpoint
/// at an address `disassemble` gave.
#[test]
fn function_data_and_instruction_breakpoints() {
    let mut c = launched(&adc(), &["/2A1"], |_| {});
    let set = c.request(
        "setFunctionBreakpoints",
        json!({"breakpoints": [{"name": "read_channel"}, {"name": "nowhere"}]}),
    );
    let answers = ok(&set)["breakpoints"].clone();
    assert_eq!(answers[0]["verified"], true, "{set}");
    assert_eq!(answers[1]["verified"], false, "{set}");
    assert!(
        answers[1]["message"]
            .as_str()
            .is_some_and(|m| m.contains("nowhere")),
        "{set}"
    );
    let stop = continue_to_stop(&mut c);
    assert_eq!(stop["reason"], "function breakpoint", "{stop}");
    assert_eq!(
        stop["hitBreakpointIds"],
        json!([answers[0]["id"]]),
        "{stop}"
    );
    let frame = c.top_frame();
    assert_eq!(frame["name"], "read_channel", "{frame}");
    assert_eq!(
        frame["instructionPointerReference"], answers[0]["instructionReference"],
        "{frame}"
    );
    ok(&c.request("setFunctionBreakpoints", json!({"breakpoints": []})));

    let registers = ok(&c.request(
        "dataBreakpointInfo",
        json!({"name": "A", "variablesReference": 1}),
    ))
    .clone();
    assert!(registers["dataId"].is_null(), "{registers}");
    let info = ok(&c.request("dataBreakpointInfo", json!({"name": "ADC_CONTROL"}))).clone();
    assert_eq!(info["dataId"], "0x9000", "{info}");
    assert_eq!(info["accessTypes"], json!(["read", "write", "readWrite"]));
    // An address and a length (supportsDataBreakpointBytes): the card's
    // three registers.
    let card = ok(&c.request(
        "dataBreakpointInfo",
        json!({"name": "0x9000", "asAddress": true, "bytes": 3}),
    ))
    .clone();
    assert_eq!(card["dataId"], "0x9000..0x9002", "{card}");
    // Two bytes from $FFFF would be one: said, not watched short.
    let past = ok(&c.request(
        "dataBreakpointInfo",
        json!({"name": "0xFFFF", "asAddress": true, "bytes": 2}),
    ))
    .clone();
    assert!(past["dataId"].is_null(), "{past}");
    assert!(
        past["description"]
            .as_str()
            .is_some_and(|d| d.contains("run past $FFFF")),
        "{past}"
    );
    let set = c.request(
        "setDataBreakpoints",
        json!({"breakpoints": [{"dataId": info["dataId"], "accessType": "write"}]}),
    );
    let watch = ok(&set)["breakpoints"][0].clone();
    assert_eq!(watch["verified"], true, "{set}");
    let stop = continue_to_stop(&mut c);
    assert_eq!(stop["reason"], "data breakpoint", "{stop}");
    assert_eq!(stop["hitBreakpointIds"], json!([watch["id"]]), "{stop}");
    let said = stop["description"].as_str().unwrap_or_default();
    assert!(said.starts_with("wrote $81 to $9000 by $"), "{stop}");
    ok(&c.request("setDataBreakpoints", json!({"breakpoints": []})));

    // The `jsr PUTCH` after the wait loop, found by disassembling.
    let pc = c.top_frame()["instructionPointerReference"].clone();
    let listing = ok(&c.request(
        "disassemble",
        json!({"memoryReference": pc, "instructionCount": 10}),
    ))
    .clone();
    let call = listing["instructions"]
        .as_array()
        .expect("instructions")
        .iter()
        .find(|i| {
            i["instruction"]
                .as_str()
                .is_some_and(|t| t.starts_with("JSR"))
        })
        .unwrap_or_else(|| panic!("a JSR in {listing}"))
        .clone();
    let set = c.request(
        "setInstructionBreakpoints",
        json!({"breakpoints": [{"instructionReference": call["address"]}]}),
    );
    let at = ok(&set)["breakpoints"][0].clone();
    assert_eq!(at["verified"], true, "{set}");
    let stop = continue_to_stop(&mut c);
    assert_eq!(stop["reason"], "instruction breakpoint", "{stop}");
    assert_eq!(stop["hitBreakpointIds"], json!([at["id"]]), "{stop}");
    assert_eq!(
        c.top_frame()["instructionPointerReference"],
        call["address"]
    );
    end(c);
}

/// `disassemble` around a label, backwards and forwards: targets named as
/// the monitor names them, each instruction's label and source line;
/// past $FFFF, invalid placeholders; `loadedSources` lists adc.s.
#[test]
fn disassemble_and_loaded_sources() {
    let mut c = launched(&adc(), &[], |_| {});
    let set = c.request(
        "setFunctionBreakpoints",
        json!({"breakpoints": [{"name": "read_channel"}]}),
    );
    let start = ok(&set)["breakpoints"][0]["instructionReference"].clone();
    let listing = ok(&c.request(
        "disassemble",
        json!({"memoryReference": start, "instructionOffset": -3, "instructionCount": 14}),
    ))
    .clone();
    let instructions = listing["instructions"].as_array().expect("instructions");
    assert_eq!(instructions.len(), 14, "{listing}");
    let first = &instructions[3];
    assert_eq!(first["address"], start, "{listing}");
    assert_eq!(first["symbol"], "read_channel", "{first}");
    assert_eq!(first["instruction"], "CPX #$02", "{first}");
    assert_eq!(first["line"], line_of("cpx #2", 0), "{first}");
    assert_eq!(first["location"]["path"], source(), "{first}");
    let texts: Vec<&str> = instructions
        .iter()
        .filter_map(|i| i["instruction"].as_str())
        .collect();
    assert!(
        texts.iter().any(|t| t.starts_with("BNE not_mine")),
        "{texts:?}"
    );
    assert!(
        texts.iter().any(|t| t.starts_with("BCC @channel")),
        "{texts:?}"
    );
    let top = ok(&c.request(
        "disassemble",
        json!({"memoryReference": "0xFFFE", "instructionCount": 4}),
    ))
    .clone();
    let last = &top["instructions"][3];
    assert_eq!(last["presentationHint"], "invalid", "{top}");
    let loaded = ok(&c.request("loadedSources", json!({}))).clone();
    let paths: Vec<&str> = loaded["sources"]
        .as_array()
        .expect("sources")
        .iter()
        .filter_map(|s| s["path"].as_str())
        .collect();
    assert!(paths.contains(&source().as_str()), "{loaded}");
    end(c);
}

/// `setVariable` on a register changes the robot's answer (A set before
/// PUTHEX prints it), and on a flag; `writeMemory` writes RAM (read back
/// with `readMemory`) and refuses the ROM; malformed arguments are error
/// responses.
#[test]
fn set_variable_and_write_memory() {
    let puthex = line_of("jsr PUTHEX", 0);
    let mut c = launched(&adc(), &["/2A1"], |c| {
        c.request(
            "setBreakpoints",
            json!({"source": {"path": source()}, "breakpoints": [{"line": puthex}]}),
        );
    });
    let stop = continue_to_stop(&mut c);
    assert_eq!(stop["reason"], "breakpoint", "{stop}");
    assert_eq!(c.register("A"), "$57", "the reading");
    let set = c.request(
        "setVariable",
        json!({"variablesReference": 1, "name": "A", "value": "$99"}),
    );
    assert_eq!(ok(&set)["value"], "$99", "{set}");
    let set = c.request(
        "setVariable",
        json!({"variablesReference": 2, "name": "C", "value": "1"}),
    );
    assert_eq!(ok(&set)["value"], "1", "{set}");
    let flags = ok(&c.request("variables", json!({"variablesReference": 2}))).clone();
    let carry = flags["variables"]
        .as_array()
        .expect("flags")
        .iter()
        .find(|v| v["name"] == "C")
        .expect("C")
        .clone();
    assert_eq!(carry["value"], "1", "{flags}");
    for (arguments, says) in [
        (
            json!({"variablesReference": 1, "name": "Q", "value": "1"}),
            "cannot be set",
        ),
        (
            json!({"variablesReference": 1, "name": "A", "value": "$100"}),
            "0 to 255",
        ),
        (
            json!({"variablesReference": 2, "name": "A", "value": "1"}),
            "cannot be set",
        ),
        (
            json!({"variablesReference": 1, "name": "A", "value": "(("}),
            "expected",
        ),
        (
            json!({"variablesReference": 1, "name": 5, "value": "1"}),
            "`name` is a string",
        ),
    ] {
        let message = refused(&c.request("setVariable", arguments.clone()));
        assert!(message.contains(says), "{arguments}: {message}");
    }

    let wrote = c.request(
        "writeMemory",
        json!({"memoryReference": "0x0300", "offset": 2, "data": "ASNF"}),
    );
    assert_eq!(ok(&wrote)["bytesWritten"], 3, "{wrote}");
    let read = c.request(
        "readMemory",
        json!({"memoryReference": "0x0302", "count": 3}),
    );
    assert_eq!(ok(&read)["data"], "ASNF", "{read}");
    let rom = refused(&c.request(
        "writeMemory",
        json!({"memoryReference": "0xF000", "data": "AA=="}),
    ));
    assert!(rom.contains("is not RAM"), "{rom}");
    let bad = refused(&c.request(
        "writeMemory",
        json!({"memoryReference": "0x0300", "data": "!!"}),
    ));
    assert!(bad.contains("not base64"), "{bad}");

    // On: the answer printed is the A that was set.
    ok(&c.request(
        "setBreakpoints",
        json!({"source": {"path": source()}, "breakpoints": []}),
    ));
    ok(&c.request("continue", json!({"threadId": 1})));
    let printed = output_until(&mut c, "\n");
    assert_eq!(printed, "A99\n");
    end(c);
}

/// `restart` builds the robot again from power-up: stopped on entry as
/// the launch said, the breakpoints still set, the launch's commands sent
/// again, so the same stop comes again with the robot's clock back at
/// its start.
#[test]
fn restart_runs_the_launch_again_with_its_breakpoints() {
    let sec = line_of("sec", 0);
    let mut c = launched(&adc(), &["/2A1"], |c| {
        c.request(
            "setBreakpoints",
            json!({"source": {"path": source()}, "breakpoints": [{"line": sec}]}),
        );
    });
    let first = continue_to_stop(&mut c);
    assert_eq!(first["reason"], "breakpoint");
    let cycles =
        |c: &mut Client| -> u64 { c.register("cycles").parse().expect("a count of cycles") };
    let before = cycles(&mut c);
    ok(&c.request("restart", json!({})));
    assert_eq!(c.event("stopped")["body"]["reason"], "entry");
    assert!(cycles(&mut c) < before, "the clock starts again");
    let again = continue_to_stop(&mut c);
    assert_eq!(again["reason"], "breakpoint");
    assert_eq!(again["hitBreakpointIds"], first["hitBreakpointIds"]);
    assert_eq!(c.top_frame()["line"], sec);
    assert_eq!(cycles(&mut c), before, "the same run, exactly");
    end(c);
}

/// Plants `byte` at the `sec` of a session stopped there (the extension
/// is in RAM), with the exception filters `filters`; continues.
fn planted(byte: &str, filters: &[&str]) -> (Client, Value) {
    let sec = line_of("sec", 0);
    let mut c = launched(&adc(), &["/2A1"], |c| {
        c.request(
            "setBreakpoints",
            json!({"source": {"path": source()}, "breakpoints": [{"line": sec}]}),
        );
        ok(&c.request("setExceptionBreakpoints", json!({"filters": filters})));
    });
    assert_eq!(continue_to_stop(&mut c)["reason"], "breakpoint");
    let pc = c.top_frame()["instructionPointerReference"].clone();
    ok(&c.request("writeMemory", json!({"memoryReference": pc, "data": byte})));
    ok(&c.request(
        "setBreakpoints",
        json!({"source": {"path": source()}, "breakpoints": []}),
    ));
    ok(&c.request("continue", json!({"threadId": 1})));
    (c, pc)
}

/// The three exception filters: a BRK planted in the handler stops at the
/// ROM's interrupt handler with the BRK's place; a JAM stops as an
/// exception with the filter on and ends the program with it off.
#[test]
fn exception_breakpoints_for_a_brk_and_a_jam() {
    // BRK is $00: "AA==".
    let (mut c, pc) = planted("AA==", &["brk"]);
    let stop = c.event("stopped")["body"].clone();
    assert_eq!(stop["reason"], "exception", "{stop}");
    let info = ok(&c.request("exceptionInfo", json!({"threadId": 1}))).clone();
    assert_eq!(info["exceptionId"], "brk", "{info}");
    let at = pc.as_str().expect("a reference").replace("0x", "$");
    assert!(
        info["description"]
            .as_str()
            .is_some_and(|d| d.starts_with(&format!("BRK at {at} (read_channel+$"))),
        "{info} {at}"
    );
    end(c);

    // JAM ($02): "Ag==".
    let (mut c, _) = planted("Ag==", &["jam"]);
    let stop = c.event("stopped")["body"].clone();
    assert_eq!(stop["reason"], "exception", "{stop}");
    let info = ok(&c.request("exceptionInfo", json!({"threadId": 1}))).clone();
    assert_eq!(info["exceptionId"], "jam", "{info}");
    assert!(
        info["description"]
            .as_str()
            .is_some_and(|d| d.contains("jammed")),
        "{info}"
    );
    end(c);

    let (mut c, _) = planted("Ag==", &[]);
    c.event("terminated");
    let none = refused(&c.request("exceptionInfo", json!({"threadId": 1})));
    assert!(none.contains("not stopped at an exception"), "{none}");
    end(c);
}

/// A card whose script fails when read (a copy of the ADC project whose
/// card throws): with the `card` filter, the session stops at an
/// exception naming the card.
#[test]
fn exception_breakpoint_for_a_cards_fault() {
    let dir = tempfile::tempdir().expect("a scratch directory");
    let project = dir.path().join("adc");
    std::fs::create_dir(&project).expect("the project");
    std::fs::copy(
        adc().join("../scorpion.inc"),
        dir.path().join("scorpion.inc"),
    )
    .expect("scorpion.inc");
    for name in ["Scorpion.toml", "adc.s", "adc.rhai"] {
        std::fs::copy(adc().join(name), project.join(name)).expect("a copy");
    }
    let card = std::fs::read_to_string(project.join("adc.rhai")).expect("the card");
    let broken = card.replacen(
        "fn read(",
        "fn read(reg, now) { throw \"the converter broke\"; }\nfn unused_read(",
        1,
    );
    assert_ne!(broken, card, "the card has a read function");
    std::fs::write(project.join("adc.rhai"), broken).expect("the broken card");
    let mut c = launched(&project, &["/2A1"], |c| {
        ok(&c.request("setExceptionBreakpoints", json!({"filters": ["card"]})));
    });
    ok(&c.request("continue", json!({"threadId": 1})));
    let stop = c.event("stopped")["body"].clone();
    assert_eq!(stop["reason"], "exception", "{stop}");
    let info = ok(&c.request("exceptionInfo", json!({"threadId": 1}))).clone();
    assert_eq!(info["exceptionId"], "card", "{info}");
    assert!(
        info["description"]
            .as_str()
            .is_some_and(|d| d.contains("$9000") && d.contains("the converter broke")),
        "{info}"
    );
    end(c);
}

/// fresh11 F2: on the virtual robot `evaluate` took only a label or an
/// address ("no label `A`"), where the robot's adapter and the monitor's
/// `print` take any expression: an editor's watch of `A` or `[ADDR]`
/// worked on hardware and failed in the emulator. A label still shows its
/// byte as before.
#[test]
fn evaluate_takes_the_monitors_expressions() {
    let puthex = line_of("jsr PUTHEX", 0);
    let mut c = launched(&adc(), &["/2A1"], |c| {
        c.request(
            "setBreakpoints",
            json!({"source": {"path": source()}, "breakpoints": [{"line": puthex}]}),
        );
    });
    let stop = continue_to_stop(&mut c);
    assert_eq!(stop["reason"], "breakpoint", "{stop}");
    let evaluate = |c: &mut Client, expression: &str| {
        let answer = c.request(
            "evaluate",
            json!({"expression": expression, "context": "watch"}),
        );
        ok(&answer)["result"]
            .as_str()
            .unwrap_or_default()
            .to_owned()
    };
    assert_eq!(evaluate(&mut c, "A"), "$57 (87)");
    assert_eq!(evaluate(&mut c, "A+1"), "$58 (88)");
    let pc = evaluate(&mut c, "PC");
    assert!(pc.starts_with('$'), "{pc}");
    assert_eq!(
        evaluate(&mut c, "[$FFFC]"),
        "$00 (0)",
        "the reset vector's low byte"
    );
    let byte = evaluate(&mut c, "$FFFD");
    assert_eq!(byte, "$F0 at $FFFD", "an address shows its byte, as before");
    let said = refused(&c.request(
        "evaluate",
        json!({"expression": "nosuchlabel", "context": "watch"}),
    ));
    assert!(said.contains("nosuchlabel"), "{said}");
    end(c);
}
