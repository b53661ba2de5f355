//! The Debug Adapter Protocol's messages, as JSON: requests taken from a
//! message's body, and the responses and events sent back through an
//! [`Outbox`] that frames them ([`super::framing`]) and numbers them.
//!
//! Every request gets exactly one response, and every response names its
//! request's `command` and `request_seq`, as the protocol requires, an
//! error response too: a client waits for it.

use std::collections::HashMap;
use std::io::Write;
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

use serde_json::{Map, Value, json};

use super::framing;

/// A request from the client.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// Its sequence number.
    pub seq: i64,
    /// Its command: `launch`, `next`...
    pub command: String,
    /// Its arguments (an empty object when it had none).
    pub arguments: Map<String, Value>,
}

/// A message that is not a request this adapter can take: what is known
/// of it, to answer it.
#[derive(Debug, Clone, PartialEq)]
pub struct Refused {
    /// Its `seq`, if one could be found.
    pub seq: Option<i64>,
    /// Its `command`, if one could be found.
    pub command: Option<String>,
    /// Why it is refused.
    pub why: String,
}

/// What a message's body is.
#[derive(Debug, Clone, PartialEq)]
pub enum Incoming {
    /// A request.
    Request(Request),
    /// Something else a client may send (a response to a reverse request:
    /// this adapter sends none): nothing to answer.
    Ignored,
    /// A message that cannot be taken.
    Refused(Refused),
}

/// A message's body as a request, or why it is not one.
pub fn parse(body: &[u8]) -> Incoming {
    let value: Value = match serde_json::from_slice(body) {
        Ok(value) => value,
        Err(error) => {
            // Not JSON (or cut short): its `seq` and `command` may still be
            // readable, and the client waits for an answer to them.
            let (seq, command) = salvage(body);
            return Incoming::Refused(Refused {
                seq,
                command,
                why: format!("the message is not JSON: {error}"),
            });
        }
    };
    let Value::Object(mut message) = value else {
        return Incoming::Refused(Refused {
            seq: None,
            command: None,
            why: "the message is not a JSON object".into(),
        });
    };
    let seq = message.get("seq").and_then(Value::as_i64);
    let command = message
        .get("command")
        .and_then(Value::as_str)
        .map(str::to_owned);
    let refuse = |why: String| {
        Incoming::Refused(Refused {
            seq,
            command: command.clone(),
            why,
        })
    };
    match message.get("type").and_then(Value::as_str) {
        Some("request") => {}
        Some("response" | "event") => return Incoming::Ignored,
        _ => return refuse("the message's `type` is not `request`".into()),
    }
    let (Some(seq), Some(command)) = (seq, command.clone()) else {
        return refuse("a request has a `seq` (an integer) and a `command` (a string)".into());
    };
    let arguments = match message.remove("arguments") {
        None | Some(Value::Null) => Map::new(),
        Some(Value::Object(arguments)) => arguments,
        Some(_) => return refuse(format!("`{command}`'s `arguments` is not an object")),
    };
    Incoming::Request(Request {
        seq,
        command,
        arguments,
    })
}

/// `"seq": N` and `"command": "..."` read from a body that is not JSON
/// (or the first bytes of one too large to take).
pub(crate) fn salvage(body: &[u8]) -> (Option<i64>, Option<String>) {
    let text = String::from_utf8_lossy(body);
    let after = |key: &str| -> Option<String> {
        let at = text.find(&format!("\"{key}\""))? + key.len() + 2;
        let rest = text[at..].trim_start().strip_prefix(':')?.trim_start();
        Some(rest.to_owned())
    };
    let seq = after("seq").and_then(|rest| {
        let end = rest
            .find(|c: char| !c.is_ascii_digit() && c != '-')
            .unwrap_or(rest.len());
        rest[..end].parse().ok()
    });
    let command = after("command").and_then(|rest| {
        let rest = rest.strip_prefix('"')?;
        let end = rest.find('"')?;
        let name = &rest[..end];
        name.bytes()
            .all(|b| b.is_ascii_alphanumeric())
            .then(|| name.to_owned())
    });
    (seq, command)
}

/// What goes to the client: framed, numbered, one response per request.
///
/// Responses may come from two threads (the robot's, and the one that
/// answers `pause` and `disconnect` when the robot does not come back):
/// the first answer to a request [`Outbox::watch`]ed goes out, a later
/// one does not.
pub struct Outbox {
    state: Mutex<State>,
    answered: Condvar,
}

impl std::fmt::Debug for Outbox {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Outbox").finish_non_exhaustive()
    }
}

struct State {
    out: Box<dyn Write + Send>,
    /// The last `seq` sent.
    seq: i64,
    /// Requests watched: answered yet?
    watched: HashMap<i64, bool>,
}

impl Outbox {
    /// Messages into `out`.
    pub fn new(out: Box<dyn Write + Send>) -> Outbox {
        Outbox {
            state: Mutex::new(State {
                out,
                seq: 0,
                watched: HashMap::new(),
            }),
            answered: Condvar::new(),
        }
    }

    fn send(&self, state: &mut State, mut message: Map<String, Value>) -> std::io::Result<()> {
        state.seq += 1;
        message.insert("seq".into(), json!(state.seq));
        let body = Value::Object(message).to_string();
        framing::write_message(&mut state.out, body.as_bytes())
    }

    fn lock(&self) -> std::io::Result<std::sync::MutexGuard<'_, State>> {
        self.state
            .lock()
            .map_err(|_| std::io::Error::other("the output's lock is poisoned"))
    }

    /// The response to `request_seq` (`command`): its body on success, its
    /// message on failure. Not sent if the request was watched and is
    /// answered already.
    ///
    /// # Errors
    /// The output's write errors.
    pub fn respond(
        &self,
        request_seq: i64,
        command: &str,
        result: Result<Option<Value>, String>,
    ) -> std::io::Result<()> {
        let mut state = self.lock()?;
        if let Some(answered) = state.watched.get_mut(&request_seq) {
            if *answered {
                return Ok(());
            }
            *answered = true;
        }
        let mut message = Map::new();
        message.insert("type".into(), json!("response"));
        message.insert("request_seq".into(), json!(request_seq));
        message.insert("command".into(), json!(command));
        match result {
            Ok(body) => {
                message.insert("success".into(), json!(true));
                if let Some(body) = body {
                    message.insert("body".into(), body);
                }
            }
            Err(why) => {
                message.insert("success".into(), json!(false));
                message.insert("message".into(), json!(why));
            }
        }
        let sent = self.send(&mut state, message);
        self.answered.notify_all();
        sent
    }

    /// Event `event`, with `body`.
    ///
    /// # Errors
    /// The output's write errors.
    pub fn event(&self, event: &str, body: Option<Value>) -> std::io::Result<()> {
        let mut state = self.lock()?;
        let mut message = Map::new();
        message.insert("type".into(), json!("event"));
        message.insert("event".into(), json!(event));
        if let Some(body) = body {
            message.insert("body".into(), body);
        }
        self.send(&mut state, message)
    }

    /// `text` as console output of `category` (`stdout`, `stderr`,
    /// `console`).
    ///
    /// # Errors
    /// The output's write errors.
    pub fn output(&self, category: &str, text: &str) -> std::io::Result<()> {
        self.event(
            "output",
            Some(json!({"category": category, "output": text})),
        )
    }

    /// Notes that request `seq` is to be answered once only: whoever
    /// answers first.
    pub fn watch(&self, seq: i64) {
        if let Ok(mut state) = self.state.lock() {
            state.watched.insert(seq, false);
        }
    }

    /// Waits up to `wait` for request `seq` (watched) to be answered;
    /// true if it was.
    pub fn wait_answered(&self, seq: i64, wait: Duration) -> bool {
        let deadline = Instant::now() + wait;
        let Ok(mut state) = self.state.lock() else {
            return false;
        };
        loop {
            if state.watched.get(&seq).copied() != Some(false) {
                state.watched.remove(&seq);
                return true;
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return false;
            }
            match self.answered.wait_timeout(state, left) {
                Ok((next, _)) => state = next,
                Err(_) => return false,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_with_and_without_arguments() {
        let with =
            parse(br#"{"seq":3,"type":"request","command":"next","arguments":{"threadId":1}}"#);
        let Incoming::Request(request) = with else {
            panic!("{with:?}")
        };
        assert_eq!((request.seq, request.command.as_str()), (3, "next"));
        assert_eq!(request.arguments["threadId"], 1);
        // `disconnect`'s arguments are optional.
        let without = parse(br#"{"seq":4,"type":"request","command":"disconnect"}"#);
        assert!(
            matches!(&without, Incoming::Request(r) if r.arguments.is_empty()),
            "{without:?}"
        );
    }

    #[test]
    fn refusals_keep_what_is_known_of_the_request() {
        let cases: [(&[u8], Option<i64>, Option<&str>); 7] = [
            (b"not json", None, None),
            (
                br#"{"seq":7,"type":"request","command":"next","argu"#,
                Some(7),
                Some("next"),
            ),
            (
                br#"{"seq" : 8, "command" : "launch", }"#,
                Some(8),
                Some("launch"),
            ),
            (br#"[1,2]"#, None, None),
            (br#"{"seq":9,"type":"request"}"#, Some(9), None),
            (
                br#"{"seq":10,"type":"request","command":"x","arguments":5}"#,
                Some(10),
                Some("x"),
            ),
            (br#"{"seq":"11","command":"next"}"#, None, Some("next")),
        ];
        for (body, seq, command) in cases {
            let parsed = parse(body);
            let Incoming::Refused(refused) = &parsed else {
                panic!("{}: {parsed:?}", String::from_utf8_lossy(body))
            };
            assert_eq!(
                (refused.seq, refused.command.as_deref()),
                (seq, command),
                "{}",
                String::from_utf8_lossy(body)
            );
        }
        assert_eq!(
            parse(br#"{"seq":1,"type":"response","request_seq":1}"#),
            Incoming::Ignored
        );
    }

    /// A shared buffer, to read what an outbox wrote.
    #[derive(Clone, Default)]
    struct Shared(std::sync::Arc<Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.lock().expect("the lock").extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    fn messages(shared: &Shared) -> Vec<Value> {
        let bytes = shared.0.lock().expect("the lock").clone();
        let mut reader = framing::FrameReader::new(&bytes[..]);
        let mut all = Vec::new();
        while let Some(message) = reader.next_message().expect("reads") {
            all.push(serde_json::from_slice(&message.expect("framed")).expect("JSON"));
        }
        all
    }

    /// Issue 23, item 9: an error response names its command.
    #[test]
    fn responses_name_their_request_and_command_and_are_numbered() {
        let shared = Shared::default();
        let outbox = Outbox::new(Box::new(shared.clone()));
        outbox
            .respond(5, "stackTrace", Err("launch a program first".into()))
            .expect("writes");
        outbox
            .respond(6, "threads", Ok(Some(json!({"threads": []}))))
            .expect("writes");
        outbox.event("initialized", None).expect("writes");
        let all = messages(&shared);
        assert_eq!(
            all[0],
            json!({"seq": 1, "type": "response", "request_seq": 5, "command": "stackTrace",
                   "success": false, "message": "launch a program first"})
        );
        assert_eq!(all[1]["command"], "threads");
        assert_eq!(all[1]["body"], json!({"threads": []}));
        assert_eq!(
            all[2],
            json!({"seq": 3, "type": "event", "event": "initialized"})
        );
    }

    #[test]
    fn a_watched_request_is_answered_once() {
        let shared = Shared::default();
        let outbox = Outbox::new(Box::new(shared.clone()));
        outbox.watch(2);
        assert!(!outbox.wait_answered(2, Duration::from_millis(10)));
        outbox
            .respond(2, "pause", Err("busy".into()))
            .expect("writes");
        outbox.respond(2, "pause", Ok(None)).expect("writes");
        assert!(outbox.wait_answered(2, Duration::from_millis(10)));
        assert_eq!(messages(&shared).len(), 1);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(500))]

        /// Any body: a request, ignored, or refused; never a panic.
        #[test]
        fn any_body_parses_or_is_refused(body in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..300)) {
            let _ = parse(&body);
        }

        /// Near-requests: each part of a request's shape broken in turn.
        #[test]
        fn near_requests_parse_or_are_refused(
            seq in "-?[0-9]{0,25}|\"[0-9]\"|null|1\\.5",
            kind in "\"request\"|\"event\"|\"\"|7",
            command in "\"[a-zA-Z]{0,12}\"|null|\\[\\]",
            arguments in "\\{\\}|null|\\[\\]|\"x\"|\\{\"threadId\":[0-9]\\}",
        ) {
            let body = format!(r#"{{"seq":{seq},"type":{kind},"command":{command},"arguments":{arguments}}}"#);
            if let Incoming::Request(request) = parse(body.as_bytes()) {
                proptest::prop_assert_eq!(kind.as_str(), "\"request\"");
                proptest::prop_assert!(!request.command.is_empty() || command == "\"\"");
            }
        }
    }
}
