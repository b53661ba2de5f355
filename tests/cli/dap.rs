//! `scorpion dap` spoken to as an editor would: a scripted session of the
//! Debug Adapter Protocol's own messages (Content-Length framed JSON) on
//! the ADC example with its card: initialize, launch, a breakpoint by file
//! and line, stop at it, the call chain with source lines, registers, step
//! over, step back, memory, continue to the answer, pause, disconnect.
//!
//! The client reads exactly the framing the protocol defines (a
//! `Content-Length` header, a blank line, the body, and nothing between
//! messages): a byte more fails the test. Every read has a deadline, so
//! an adapter that stops answering fails a test instead of hanging it.
//! Hostile input (issue 23, items 7 to 10 and 1 under dap) follows.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// How long a message may take to come (a loaded machine's margin).
const PATIENCE: Duration = Duration::from_secs(30);

pub(crate) struct Client {
    child: Child,
    /// `None` once closed, as by an editor that went away.
    input: Option<ChildStdin>,
    /// Messages as the reader thread framed them, or why it could not.
    messages: Receiver<Result<Value, String>>,
    seq: i64,
    /// Events read while waiting for responses.
    pub(crate) events: Vec<Value>,
}

/// One message read exactly as the protocol frames it: `Content-Length: `,
/// digits, CRLF, CRLF, the body. `None` at the end of the output.
fn read_exactly(output: &mut impl Read) -> Result<Option<Value>, String> {
    let mut byte = [0u8; 1];
    let mut header = Vec::new();
    loop {
        match output.read(&mut byte) {
            Ok(0) if header.is_empty() => return Ok(None),
            Ok(0) => return Err(format!("the output ended in a header: {header:?}")),
            Ok(_) => header.push(byte[0]),
            Err(error) => return Err(error.to_string()),
        }
        if header.ends_with(b"\r\n\r\n") {
            break;
        }
        if header.len() > 40 {
            break;
        }
    }
    let text = String::from_utf8_lossy(&header).into_owned();
    let length = text
        .strip_prefix("Content-Length: ")
        .and_then(|rest| rest.strip_suffix("\r\n\r\n"))
        .filter(|digits| !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|digits| digits.parse::<usize>().ok())
        .ok_or_else(|| format!("not exactly a header: {text:?}"))?;
    let mut body = vec![0; length];
    output
        .read_exact(&mut body)
        .map_err(|error| format!("the body: {error}"))?;
    serde_json::from_slice(&body)
        .map(Some)
        .map_err(|error| format!("the body is not JSON ({error}): {body:?}"))
}

impl Client {
    pub(crate) fn start() -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .arg("dap")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("scorpion dap runs");
        let input = child.stdin.take().expect("stdin");
        let mut output = child.stdout.take().expect("stdout");
        let (send, messages) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            loop {
                match read_exactly(&mut output) {
                    Ok(Some(message)) => {
                        if send.send(Ok(message)).is_err() {
                            return;
                        }
                    }
                    Ok(None) => return,
                    Err(why) => {
                        let _ = send.send(Err(why));
                        return;
                    }
                }
            }
        });
        Client {
            child,
            input: Some(input),
            messages,
            seq: 0,
            events: Vec::new(),
        }
    }

    pub(crate) fn read(&mut self) -> Value {
        match self.messages.recv_timeout(PATIENCE) {
            Ok(Ok(message)) => message,
            Ok(Err(why)) => panic!("the adapter's output is not framed exactly: {why}"),
            Err(RecvTimeoutError::Timeout) => {
                panic!("no message from the adapter in {PATIENCE:?}")
            }
            Err(RecvTimeoutError::Disconnected) => panic!("the adapter ended"),
        }
    }

    /// Sends `bytes` as they are (a hostile client's framing).
    pub(crate) fn send_raw(&mut self, bytes: &[u8]) {
        let input = self.input.as_mut().expect("the adapter's input is open");
        input.write_all(bytes).expect("write");
        input.flush().expect("flush");
    }

    /// The response to request `seq` (events meanwhile are kept).
    pub(crate) fn response_to(&mut self, seq: i64) -> Value {
        loop {
            let message = self.read();
            if message["type"] == "response" && message["request_seq"] == seq {
                return message;
            }
            self.events.push(message);
        }
    }

    /// Closes the adapter's input, as an editor that crashed does.
    pub(crate) fn close_input(&mut self) {
        self.input = None;
    }

    /// Sends the adapter a signal (`TERM`, `HUP`...), as an editor that
    /// ends it does.
    pub(crate) fn signal(&self, name: &str) {
        let sent = Command::new("kill")
            .args([&format!("-{name}"), &self.child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(sent.success(), "kill -{name}");
    }

    /// Waits for the adapter to end, at most `PATIENCE`; its success.
    pub(crate) fn ends(&mut self) -> bool {
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().expect("the adapter's status") {
                return status.success();
            }
            if start.elapsed() > PATIENCE {
                let _ = self.child.kill();
                panic!("the adapter still runs {PATIENCE:?} after disconnect");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Sends a request; returns its response (events meanwhile are kept).
    pub(crate) fn request(&mut self, command: &str, arguments: Value) -> Value {
        self.seq += 1;
        let message =
            json!({"seq": self.seq, "type": "request", "command": command, "arguments": arguments});
        let text = message.to_string();
        self.send_raw(format!("Content-Length: {}\r\n\r\n{text}", text.len()).as_bytes());
        self.response_to(self.seq)
    }

    /// The next event named `name` (kept ones first).
    pub(crate) fn event(&mut self, name: &str) -> Value {
        if let Some(index) = self.events.iter().position(|e| e["event"] == name) {
            return self.events.remove(index);
        }
        loop {
            let message = self.read();
            if message["event"] == name {
                return message;
            }
            self.events.push(message);
        }
    }

    pub(crate) fn top_frame(&mut self) -> Value {
        let trace = self.request("stackTrace", json!({"threadId": 1}));
        assert_eq!(trace["success"], true, "{trace}");
        trace["body"]["stackFrames"][0].clone()
    }

    pub(crate) fn register(&mut self, name: &str) -> String {
        let variables = self.request("variables", json!({"variablesReference": 1}));
        variables["body"]["variables"]
            .as_array()
            .and_then(|v| v.iter().find(|v| v["name"] == name))
            .and_then(|v| v["value"].as_str())
            .expect("the register")
            .to_owned()
    }
}

#[test]
fn a_dap_session_on_the_adc_example() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let source = adc.join("adc.s").display().to_string();
    let mut c = Client::start();
    let init = c.request(
        "initialize",
        json!({"adapterID": "scorpion", "linesStartAt1": true}),
    );
    assert_eq!(init["body"]["supportsStepBack"], true, "{init}");
    c.event("initialized");
    let launch = c.request(
        "launch",
        json!({"program": adc.display().to_string(), "stopOnEntry": true, "commands": ["/2A1"]}),
    );
    assert_eq!(launch["success"], true, "{launch}");
    let set = c.request(
        "setBreakpoints",
        json!({"source": {"path": source}, "breakpoints": [{"line": 33}, {"line": 2}]}),
    );
    let answers = &set["body"]["breakpoints"];
    assert_eq!(answers[0]["verified"], true, "{set}");
    assert_eq!(answers[1]["verified"], false, "line 2 is a comment: {set}");
    assert_eq!(c.request("configurationDone", json!({}))["success"], true);
    assert_eq!(c.event("stopped")["body"]["reason"], "entry");

    // On to the breakpoint at `sec` (line 33), /2A1 having been sent.
    assert_eq!(
        c.request("continue", json!({"threadId": 1}))["success"],
        true
    );
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    let frame = c.top_frame();
    assert_eq!(frame["line"], 33, "{frame}");
    assert_eq!(frame["source"]["path"], source, "{frame}");
    assert_eq!(frame["name"], "read_channel+$B", "{frame}");
    let scopes = c.request("scopes", json!({"frameId": 0}));
    assert_eq!(scopes["body"]["scopes"][0]["name"], "Registers");
    assert_eq!(c.register("A"), "$31", "the channel digit");

    // Step over `sec`, then back over it.
    assert_eq!(c.request("next", json!({"threadId": 1}))["success"], true);
    assert_eq!(c.event("stopped")["body"]["reason"], "step");
    assert_eq!(c.top_frame()["line"], 34);
    assert_eq!(
        c.request("stepBack", json!({"threadId": 1}))["success"],
        true
    );
    assert_eq!(c.event("stopped")["body"]["reason"], "step");
    assert_eq!(c.top_frame()["line"], 33);
    assert_eq!(c.register("A"), "$31");

    // Into a subroutine and out: step to the `jsr PUTCH` after the wait
    // loop's breakpoint, in, out.
    c.request(
        "setBreakpoints",
        json!({"source": {"path": source}, "breakpoints": [{"line": 51}]}),
    );
    assert_eq!(
        c.request("continue", json!({"threadId": 1}))["success"],
        true
    );
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    assert_eq!(c.top_frame()["line"], 51, "jsr PUTCH");
    assert_eq!(c.request("stepIn", json!({"threadId": 1}))["success"], true);
    c.event("stopped");
    let trace = c.request("stackTrace", json!({"threadId": 1}));
    let frames = trace["body"]["stackFrames"]
        .as_array()
        .expect("frames")
        .clone();
    assert_eq!(
        frames.len(),
        2,
        "PUTCH, and the handler it returns to: {trace}"
    );
    // The caller's frame is where it called, as gdb and editors show it
    // (and as the monitor's `bt` does), not the line the call returns to.
    assert_eq!(frames[1]["line"], 51, "the line of the JSR: {trace}");
    assert!(
        frames[0]["source"].is_null(),
        "the ROM has no source here: {trace}"
    );
    assert_eq!(
        c.request("stepOut", json!({"threadId": 1}))["success"],
        true
    );
    c.event("stopped");
    assert_eq!(c.top_frame()["line"], 52);
    // Back to the last breakpoint hit (line 51), then on.
    assert_eq!(
        c.request("reverseContinue", json!({"threadId": 1}))["success"],
        true
    );
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    assert_eq!(c.top_frame()["line"], 51);

    // The card's registers, as memory.
    let memory = c.request(
        "readMemory",
        json!({"memoryReference": "0x9000", "count": 3}),
    );
    assert_eq!(memory["body"]["address"], "0x9000", "{memory}");
    assert_eq!(
        memory["body"]["data"], "AEAA",
        "the status register's result bit: {memory}"
    );

    // No more breakpoints: the answer comes, the robot runs on until paused.
    c.request(
        "setBreakpoints",
        json!({"source": {"path": source}, "breakpoints": []}),
    );
    assert_eq!(
        c.request("continue", json!({"threadId": 1}))["success"],
        true
    );
    let output = c.event("output");
    assert_eq!(output["body"]["output"], "A57\n", "{output}");
    assert_eq!(c.request("pause", json!({"threadId": 1}))["success"], true);
    assert_eq!(c.event("stopped")["body"]["reason"], "pause");
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}

#[test]
fn requests_before_launch_and_bad_programs_are_errors() {
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let early = c.request("stackTrace", json!({"threadId": 1}));
    assert_eq!(early["success"], false);
    assert_eq!(early["message"], "launch a program first", "{early}");
    let bad = c.request("launch", json!({"program": "/nonexistent/x.elf"}));
    assert_eq!(bad["success"], false);
    assert!(
        bad["message"].as_str().is_some_and(|m| m.contains("x.elf")),
        "{bad}"
    );
    c.request("disconnect", json!({}));
    assert!(c.ends());
}

/// `program` an image: built here from a copy of the ADC source, its
/// source lines found from `cwd`; without `stopOnEntry` it runs at once.
#[test]
fn an_image_launched_runs_to_a_breakpoint_by_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    std::fs::copy(examples.join("adc.s"), dir.path().join("adc.s")).expect("copy");
    let built = crate::scorpion(
        dir.path(),
        &[
            "build",
            "adc.s",
            "-o",
            "adc.elf",
            "--target",
            "scorpion-ext",
        ],
    );
    assert_eq!(
        built.status.code(),
        Some(0),
        "{}",
        crate::transcript(&built)
    );
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let launch = c.request(
        "launch",
        json!({
            "program": dir.path().join("adc.elf").display().to_string(),
            "cwd": dir.path().display().to_string(),
            "commands": ["/2A1"],
        }),
    );
    assert_eq!(launch["success"], true, "{launch}");
    let source = dir.path().join("adc.s").display().to_string();
    let set = c.request(
        "setBreakpoints",
        json!({"source": {"path": source}, "breakpoints": [{"line": 28}]}),
    );
    assert_eq!(set["body"]["breakpoints"][0]["verified"], true, "{set}");
    c.request("configurationDone", json!({}));
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    let frame = c.top_frame();
    assert_eq!(
        (frame["line"].clone(), frame["source"]["path"].clone()),
        (json!(28), json!(source))
    );
    c.request("disconnect", json!({}));
    assert!(c.ends());
}

/// A line that calls a built-in macro (`scorpion new`'s
/// `SCORPION_CHAIN_UNKNOWN`, whose code is `scorpion.inc`'s) takes a
/// breakpoint at the macro's first byte: verified at that line, hit when
/// a command goes down the chain, and the frame shows the user's line,
/// the one they can open (the old adapter answered "no code came from
/// line 26").
#[test]
fn a_breakpoint_on_a_line_that_calls_a_built_in_macro_stops_there() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (project, text) = crate::new_project(dir.path());
    let chain = crate::lines_with(&text, "SCORPION_CHAIN_UNKNOWN")[0];
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let launch = c.request(
        "launch",
        json!({"program": project.display().to_string(), "commands": ["/1W"]}),
    );
    assert_eq!(launch["success"], true, "{launch}");
    let source = project.join("src/myext.s").display().to_string();
    let set = c.request(
        "setBreakpoints",
        json!({"source": {"path": source}, "breakpoints": [{"line": chain}]}),
    );
    let answer = &set["body"]["breakpoints"][0];
    assert_eq!(answer["verified"], true, "{set}");
    assert_eq!(answer["line"], chain, "{set}");
    c.request("configurationDone", json!({}));
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    let frame = c.top_frame();
    assert_eq!(frame["line"], chain, "{frame}");
    assert!(
        frame["source"]["path"]
            .as_str()
            .is_some_and(|path| path.ends_with("src/myext.s")),
        "{frame}"
    );
    c.request("disconnect", json!({}));
    assert!(c.ends());
}

impl Client {
    /// Sends a request with `body` as its whole message (no `arguments`
    /// added); returns its seq.
    fn send_body(&mut self, body: &str) {
        self.send_raw(format!("Content-Length: {}\r\n\r\n{body}", body.len()).as_bytes());
    }

    /// The next `output` event on stderr (kept events first).
    fn complaint(&mut self) -> String {
        loop {
            let output = self.event("output");
            if output["body"]["category"] == "stderr" {
                return output["body"]["output"]
                    .as_str()
                    .expect("the output's text")
                    .to_owned();
            }
        }
    }
}

/// Issue 23, item 7: lengths that panicked (capacity overflow) or aborted
/// the old adapter are said, and the session goes on: the next request
/// is answered.
#[test]
fn huge_content_lengths_are_refused_and_the_session_goes_on() {
    let mut c = Client::start();
    for length in ["18446744073709551615", "99999999999", "5000000"] {
        c.send_raw(format!("Content-Length: {length}\r\n\r\n").as_bytes());
        if length == "5000000" {
            // Declared and sent: passed over whole, in step with the next.
            c.send_raw(&vec![b' '; 5_000_000]);
        }
        let said = c.complaint();
        assert!(
            said.contains(&format!("a message of {length} bytes")) || said.contains("at most"),
            "{length}: {said}"
        );
        let threads = c.request("threads", json!({}));
        assert_eq!(threads["success"], true, "{length}: {threads}");
    }
    // hostile13: a request over the limit, its seq and command at its
    // start, is answered, not only said.
    let padding = " ".repeat(5_000_000);
    c.send_body(&format!(
        r#"{{"seq": 150, "type": "request", "command": "evaluate", "arguments": {{"expression": "A{padding}"}}}}"#
    ));
    let refused = c.response_to(150);
    assert_eq!(
        (&refused["success"], &refused["command"]),
        (&json!(false), &json!("evaluate")),
        "{refused}"
    );
    assert!(
        refused["message"]
            .as_str()
            .is_some_and(|m| m.contains("at most 4194304")),
        "{refused}"
    );
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}

/// Issue 23, items 8 and 9: a body that is not JSON, a length shorter
/// than the body, an unknown command, a message that is no request: each
/// answered (with its `command` and `request_seq` where they can be read)
/// or said, and the next request answered. The old reader ended at the
/// first of them, silently.
#[test]
fn malformed_messages_are_answered_and_the_reader_goes_on() {
    let mut c = Client::start();
    // Not JSON, its seq and command still readable.
    c.send_body(r#"{"seq": 101, "type": "request", "command": "threads", oops}"#);
    let refused = c.response_to(101);
    assert_eq!(
        (&refused["success"], &refused["command"]),
        (&json!(false), &json!("threads")),
        "{refused}"
    );
    assert!(
        refused["message"]
            .as_str()
            .is_some_and(|m| m.contains("not JSON")),
        "{refused}"
    );
    // A length shorter than the body: the part read is refused, the rest
    // is said to be outside any message, and the next request answered.
    // A command nobody knows comes right after it.
    let whole = r#"{"seq":102,"type":"request","command":"threads","arguments":{}}"#;
    c.send_raw(format!("Content-Length: 40\r\n\r\n{whole}").as_bytes());
    c.send_body(r#"{"seq":103,"type":"request","command":"frobnicate"}"#);
    assert_eq!(c.response_to(102)["success"], false);
    let unknown = c.response_to(103);
    assert!(c.complaint().contains("outside any message"));
    assert_eq!(unknown["command"], "frobnicate", "{unknown}");
    assert_eq!(unknown["success"], false, "{unknown}");
    // JSON, but not a request.
    c.send_body("[1, 2, 3]");
    assert!(c.complaint().contains("not a JSON object"));
    // Every response so far carried its command.
    for message in c.events.iter().filter(|m| m["type"] == "response") {
        assert!(message["command"].is_string(), "{message}");
    }
    c.seq = 200;
    let threads = c.request("threads", json!({}));
    assert_eq!(threads["body"]["threads"][0]["name"], "6502", "{threads}");
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}

/// Issue 23, item 9: an error response names its command; `pause` before
/// `launch` is an error and stops nothing; `disconnect`'s arguments are
/// optional.
#[test]
fn pause_before_launch_is_an_error_and_disconnect_takes_no_arguments() {
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let early = c.request("stackTrace", json!({"threadId": 1}));
    assert_eq!(early["command"], "stackTrace", "{early}");
    let pause = c.request("pause", json!({"threadId": 1}));
    assert_eq!(
        (&pause["success"], &pause["command"]),
        (&json!(false), &json!("pause")),
        "{pause}"
    );
    assert_eq!(pause["message"], "launch a program first", "{pause}");
    // Nothing stopped: the only events so far are `initialized`.
    let threads = c.request("threads", json!({}));
    assert_eq!(threads["success"], true);
    assert!(
        c.events.iter().all(|e| e["event"] == "initialized"),
        "{:?}",
        c.events
    );
    c.seq += 1;
    let seq = c.seq;
    c.send_body(&format!(
        r#"{{"seq":{seq},"type":"request","command":"disconnect"}}"#
    ));
    let disconnect = c.response_to(seq);
    assert_eq!(disconnect["success"], true, "{disconnect}");
    assert!(c.ends());
}

/// A robot that loops for ever (`JMP *` in the handler the command
/// reaches): `pause` stops it and `disconnect` ends the session, each
/// answered.
#[test]
fn pause_and_disconnect_are_answered_while_the_robot_loops_for_ever() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("spin.s"),
        "        .include \"scorpion.inc\"\n        SCORPION_UNKNOWN_HANDLER\nhandler: jmp handler\n",
    )
    .expect("write");
    let built = crate::scorpion(
        dir.path(),
        &[
            "build",
            "spin.s",
            "-o",
            "spin.elf",
            "--target",
            "scorpion-ext",
        ],
    );
    assert_eq!(
        built.status.code(),
        Some(0),
        "{}",
        crate::transcript(&built)
    );
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let launch = c.request(
        "launch",
        json!({"program": dir.path().join("spin.elf").display().to_string(), "commands": ["/1Z"]}),
    );
    assert_eq!(launch["success"], true, "{launch}");
    c.request("configurationDone", json!({}));
    std::thread::sleep(Duration::from_millis(300));
    let pause = c.request("pause", json!({"threadId": 1}));
    assert_eq!(pause["success"], true, "{pause}");
    assert_eq!(c.event("stopped")["body"]["reason"], "pause");
    assert_eq!(c.top_frame()["name"], "handler", "in the loop");
    assert_eq!(
        c.request("continue", json!({"threadId": 1}))["success"],
        true
    );
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}

/// Issue 23, item 1 under dap: a card that asks to be woken at the same
/// instant again and again never lets the robot's slice end. Whatever
/// `launch` makes of it (the card sandbox may refuse it), `pause` and
/// `disconnect` are answered and the adapter ends; the old adapter
/// answered neither.
#[test]
fn a_card_that_never_lets_time_move_does_not_silence_the_adapter() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("Scorpion.toml"),
        "[project]\nname = \"spin\"\n\n[[image]]\nname = \"idle\"\nsources = [\"idle.s\"]\ntarget = \"scorpion-ext\"\n\n[robot]\ncards = [\"spin.rhai\"]\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("idle.s"),
        "        .include \"scorpion.inc\"\n        SCORPION_UNKNOWN_HANDLER\nhandler:\n        SCORPION_CHAIN_UNKNOWN\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("spin.rhai"),
        "const SIZE = 1;\nconst BASE = 0x9000;\nfn init() { wake_at(0); }\nfn wake(now) { wake_at(now); }\nfn read(reg, now) { 0 }\nfn write(reg, value, now) { }\n",
    )
    .expect("write");
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let launch = c.request(
        "launch",
        json!({"program": dir.path().display().to_string()}),
    );
    if launch["success"] == true {
        c.request("configurationDone", json!({}));
        std::thread::sleep(Duration::from_millis(300));
    } else {
        // Refused at launch (by the card sandbox): nothing runs to spin.
        let message = launch["message"].as_str().unwrap_or_default();
        assert!(message.contains("spin.rhai"), "{launch}");
    }
    let start = Instant::now();
    let pause = c.request("pause", json!({"threadId": 1}));
    assert_eq!(pause["command"], "pause", "{pause}");
    let disconnect = c.request("disconnect", json!({}));
    assert_eq!(disconnect["success"], true, "{disconnect}");
    assert!(c.ends());
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "{:?}",
        start.elapsed()
    );
}

/// A debug-console line starting with `/` goes down the robot's line, and
/// so do `launch`'s `commands`: each must be one command as the ROM reads
/// it (11 characters at most, docs/PROTOCOL.md), `commands` no more in all
/// than a serial port holds. The old adapter sent a 100 kB "command" as it
/// came (minutes of line time and megabytes queued ahead of the next);
/// now it is refused, saying so, and the session goes on: the next command
/// is answered at once.
#[test]
fn a_command_longer_than_the_rom_reads_is_refused() {
    let adc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adc");
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let flood = vec!["/2A1"; 2000];
    let refused = c.request(
        "launch",
        json!({"program": adc.display().to_string(), "stopOnEntry": true, "commands": flood}),
    );
    assert_eq!(refused["success"], false, "{refused}");
    assert!(
        refused["message"]
            .as_str()
            .is_some_and(|m| m.contains("`commands` holds 8000 bytes")),
        "{refused}"
    );
    let launch = c.request(
        "launch",
        json!({"program": adc.display().to_string(), "stopOnEntry": true}),
    );
    assert_eq!(launch["success"], true, "{launch}");
    c.request("configurationDone", json!({}));
    assert_eq!(c.event("stopped")["body"]["reason"], "entry");
    let long = format!("/2A1{}", "1".repeat(100_000));
    let refused = c.request("evaluate", json!({"expression": long, "context": "repl"}));
    assert_eq!(refused["success"], false, "{refused}");
    let message = refused["message"].as_str().unwrap_or_default().to_owned();
    assert!(
        message.contains("100004 bytes") && message.contains("11 at most"),
        "{message}"
    );
    assert!(message.len() < 300, "the command is not echoed whole");
    let sent = c.request("evaluate", json!({"expression": "/2A1", "context": "repl"}));
    assert_eq!(sent["success"], true, "{sent}");
    assert_eq!(
        c.request("continue", json!({"threadId": 1}))["success"],
        true
    );
    // Only /2A1's answer is on the line: nothing of the refused flood.
    let output = c.event("output");
    assert_eq!(output["body"]["output"], "A57\n", "{output}");
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}

/// `launch`'s `program` names a linked image or a project's directory: a
/// directory with no Scorpion.toml in it or above launched the bare ROM
/// without a word (the hostile sweep after issue 23). Refused, saying so.
#[test]
fn a_directory_that_is_no_project_is_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut c = Client::start();
    c.request("initialize", json!({"adapterID": "scorpion"}));
    let refused = c.request(
        "launch",
        json!({"program": dir.path().display().to_string()}),
    );
    assert_eq!(refused["success"], false, "{refused}");
    assert!(
        refused["message"]
            .as_str()
            .is_some_and(|m| m.contains("is a directory with no Scorpion.toml in it or above")),
        "{refused}"
    );
    assert_eq!(c.request("disconnect", json!({}))["success"], true);
    assert!(c.ends());
}
