//! Hostile requests for the DAP server (issue 23; issue 25's requests
//! too): any command, known or not, with arguments of any shape (missing, of the wrong type, huge,
//! negative), before and after `launch`, is answered and the session
//! goes on; never a panic. The framing's own fuzzing is in
//! `debugger::dap::framing`, the messages' in `debugger::dap::protocol`.

use std::cell::RefCell;
use std::path::Path;
use std::sync::Arc;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use serde_json::{Map, Value, json};

use debugger::dap::protocol::{Outbox, Request};
use debugger::dap::session::{Busy, Session};

/// Values of every JSON type, and the extremes of integers.
fn value() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        (-3i64..70_000).prop_map(Value::from),
        Just(json!(i64::MAX)),
        Just(json!(i64::MIN)),
        Just(json!(u64::MAX)),
        Just(json!(1.5)),
        Just(json!("0x9000")),
        Just(json!("read_channel")),
        Just(json!("/2A1")),
        Just(json!("$FFFF")),
        "\\PC{0,10}".prop_map(Value::from),
        Just(json!([])),
        Just(json!([{"line": 33}, {"line": -1}, {"line": 4294967296u64}, {}])),
        Just(json!({"path": "adc.s"})),
        Just(json!({})),
        Just(json!("AAEC")),
        Just(json!("not base64!")),
        Just(json!("A == $31")),
        Just(json!("((")),
        Just(json!("== 2")),
        Just(json!("% 0")),
        Just(json!("A={A} [CMDBUF]={[CMDBUF]}")),
        Just(json!("{")),
        Just(json!(["jam", "brk", "card"])),
        Just(json!(["frob"])),
        Just(
            json!([{"name": "read_channel", "condition": "A == 1"}, {"name": "/2A"}, {"name": "nowhere"}])
        ),
        Just(
            json!([{"dataId": "0x0200..0x0201", "accessType": "write"}, {"dataId": "CMDBUF", "accessType": "sideways"}])
        ),
        Just(json!([{"instructionReference": "0x0400", "offset": -5, "hitCondition": "3"}])),
        Just(json!([{"line": 33, "logMessage": "A={A}"}, {"line": 33, "condition": "[["}])),
        Just(json!({"program": "/nonexistent", "stopOnEntry": "yes"})),
        Just(json!([{"filterId": "jam", "condition": "1"}])),
    ]
}

fn request() -> impl Strategy<Value = (String, Map<String, Value>)> {
    let command = prop::sample::select(vec![
        "initialize",
        "setBreakpoints",
        "setExceptionBreakpoints",
        "configurationDone",
        "threads",
        "stackTrace",
        "scopes",
        "variables",
        "readMemory",
        "evaluate",
        "continue",
        "pause",
        "next",
        "stepIn",
        "stepOut",
        "stepBack",
        "reverseContinue",
        "setFunctionBreakpoints",
        "setInstructionBreakpoints",
        "dataBreakpointInfo",
        "setDataBreakpoints",
        "disassemble",
        "setVariable",
        "writeMemory",
        "restart",
        "exceptionInfo",
        "loadedSources",
        "attach",
        "frobnicate",
        "",
    ]);
    let key = prop::sample::select(vec![
        "threadId",
        "variablesReference",
        "memoryReference",
        "offset",
        "count",
        "expression",
        "source",
        "breakpoints",
        "frameId",
        "stopOnEntry",
        "commands",
        "name",
        "value",
        "data",
        "dataId",
        "accessType",
        "asAddress",
        "bytes",
        "instructionReference",
        "instructionOffset",
        "instructionCount",
        "filters",
        "filterOptions",
        "arguments",
    ]);
    let arguments = prop::collection::btree_map(key, value(), 0..5).prop_map(|map| {
        map.into_iter()
            .map(|(key, value)| (key.to_owned(), value))
            .collect::<Map<String, Value>>()
    });
    (command.prop_map(str::to_owned), arguments)
}

/// Hands `command` to the session as the next request; false at the
/// session's end.
fn handle(session: &RefCell<(Session, i64)>, command: &str, arguments: Map<String, Value>) -> bool {
    let (session, seq) = &mut *session.borrow_mut();
    *seq += 1;
    let request = Request {
        seq: *seq,
        command: command.to_owned(),
        arguments,
    };
    let going = session.handle(&request).expect("a sink takes everything");
    if session.running() {
        session.run_slice().expect("a sink takes everything");
    }
    going
}

/// A run of random requests on `session`.
fn fuzz(session: &RefCell<(Session, i64)>) {
    let mut runner = TestRunner::new(Config::with_cases(150));
    let outcome = runner.run(&request(), |(command, arguments)| {
        prop_assert!(
            handle(session, &command, arguments),
            "`{command}` ended the session"
        );
        Ok(())
    });
    if let Err(failure) = outcome {
        panic!("{failure}");
    }
}

#[test]
fn any_request_is_answered_and_the_session_goes_on() {
    let outbox = Arc::new(Outbox::new(Box::new(std::io::sink())));
    let session = RefCell::new((
        Session::new(outbox, Arc::new(Busy::default()), Box::new(super::launch)),
        0,
    ));
    // Before launch, then after.
    fuzz(&session);
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let mut launch = Map::new();
    launch.insert("program".into(), json!(adc.display().to_string()));
    launch.insert("commands".into(), json!(["/2A1"]));
    assert!(handle(&session, "launch", launch));
    assert!(session.borrow().0.launched(), "the ADC example launches");
    fuzz(&session);
    assert!(!handle(&session, "disconnect", Map::new()));
}
