//! `scorpion dap` spoken to as an editor would: a scripted session of the
//! Debug Adapter Protocol's own messages (Content-Length framed JSON) on
//! the ADC example with its card: initialize, launch, a breakpoint by file
//! and line, stop at it, the call chain with source lines, registers, step
//! over, step back, memory, continue to the answer, pause, disconnect.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use serde_json::{Value, json};

struct Client {
    child: Child,
    input: ChildStdin,
    output: BufReader<ChildStdout>,
    seq: i64,
    /// Events read while waiting for responses.
    events: Vec<Value>,
}

impl Client {
    fn start() -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scorpion"))
            .arg("dap")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("scorpion dap runs");
        let input = child.stdin.take().expect("stdin");
        let output = BufReader::new(child.stdout.take().expect("stdout"));
        Client {
            child,
            input,
            output,
            seq: 0,
            events: Vec::new(),
        }
    }

    fn read(&mut self) -> Value {
        let mut length = None;
        loop {
            let mut line = String::new();
            assert!(
                self.output.read_line(&mut line).expect("a header") > 0,
                "the adapter ended"
            );
            let line = line.trim();
            if let Some(n) = line.strip_prefix("Content-Length:") {
                length = Some(n.trim().parse::<usize>().expect("a length"));
            } else if line.is_empty() && length.is_some() {
                break;
            }
        }
        let mut body = vec![0; length.unwrap_or(0)];
        self.output.read_exact(&mut body).expect("the body");
        serde_json::from_slice(&body).expect("JSON")
    }

    /// Sends a request; returns its response (events meanwhile are kept).
    fn request(&mut self, command: &str, arguments: Value) -> Value {
        self.seq += 1;
        let message =
            json!({"seq": self.seq, "type": "request", "command": command, "arguments": arguments});
        let text = message.to_string();
        write!(self.input, "Content-Length: {}\r\n\r\n{text}", text.len()).expect("write");
        self.input.flush().expect("flush");
        loop {
            let message = self.read();
            if message["type"] == "response" && message["request_seq"] == self.seq {
                return message;
            }
            self.events.push(message);
        }
    }

    /// The next event named `name` (kept ones first).
    fn event(&mut self, name: &str) -> Value {
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

    fn top_frame(&mut self) -> Value {
        let trace = self.request("stackTrace", json!({"threadId": 1}));
        assert_eq!(trace["success"], true, "{trace}");
        trace["body"]["stackFrames"][0].clone()
    }

    fn register(&mut self, name: &str) -> String {
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
        json!({"source": {"path": source}, "breakpoints": [{"line": 45}]}),
    );
    assert_eq!(
        c.request("continue", json!({"threadId": 1}))["success"],
        true
    );
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    assert_eq!(c.top_frame()["line"], 45, "jsr PUTCH");
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
    assert_eq!(frames[1]["line"], 46, "the line after the JSR: {trace}");
    assert!(
        frames[0]["source"].is_null(),
        "the ROM has no source here: {trace}"
    );
    assert_eq!(
        c.request("stepOut", json!({"threadId": 1}))["success"],
        true
    );
    c.event("stopped");
    assert_eq!(c.top_frame()["line"], 46);
    // Back to the last breakpoint hit (line 45), then on.
    assert_eq!(
        c.request("reverseContinue", json!({"threadId": 1}))["success"],
        true
    );
    assert_eq!(c.event("stopped")["body"]["reason"], "breakpoint");
    assert_eq!(c.top_frame()["line"], 45);

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
    let status = c.child.wait().expect("the adapter ends");
    assert!(status.success(), "{status}");
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
    assert!(c.child.wait().expect("the adapter ends").success());
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
    assert!(c.child.wait().expect("the adapter ends").success());
}
