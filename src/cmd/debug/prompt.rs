//! Where the monitor's commands come from: a terminal, through rustyline
//! (line editing, history kept per project, completion of commands,
//! symbols and file:line), or plain lines from a script or a pipe.
//!
//! rustyline rather than reedline: the monitor is a synchronous loop that
//! reads a line, runs it and prints; rustyline is exactly that (a blocking
//! `readline`, `Interrupted` for Ctrl-C at the prompt, a file history) with
//! a handful of small dependencies, where reedline brings crossterm and an
//! event loop this REPL has no use for.

use std::collections::BTreeSet;
use std::io::{BufRead, Read as _};
use std::path::{Path, PathBuf};

use rustyline::completion::Completer;
use rustyline::error::ReadlineError;
use rustyline::highlight::Highlighter;
use rustyline::hint::Hinter;
use rustyline::history::DefaultHistory;
use rustyline::validate::Validator;
use rustyline::{CompletionType, Config, Editor, Helper};

/// The monitor's commands, completed at the start of a line.
pub(crate) const COMMANDS: &[&str] = &[
    "break",
    "back",
    "bt",
    "bumpers",
    "continue",
    "delete",
    "dis",
    "display",
    "finish",
    "help",
    "info",
    "list",
    "mem",
    "next",
    "nexti",
    "poke",
    "quit",
    "regs",
    "reverse-continue",
    "send",
    "set",
    "step",
    "trace",
    "undisplay",
    "until",
    "watch",
    "who-wrote",
];

/// What the monitor read.
pub(crate) enum Read {
    /// A line.
    Line(String),
    /// Ctrl-C at the prompt: nothing to run, the prompt again.
    Interrupted,
    /// The end of the input (Ctrl-D, the script's end).
    End,
    /// A line that cannot be a command (not UTF-8 text, or longer than
    /// [`LINE_MAX`]): said, and the session goes on.
    Invalid(String),
}

/// The longest line read from a script or a pipe; the rest of a longer
/// line is skipped.
pub(crate) const LINE_MAX: u64 = 1 << 20;

/// The monitor's input.
pub(crate) enum Input {
    /// A terminal: rustyline, with the history file it keeps.
    Terminal {
        editor: Box<Editor<Completion, DefaultHistory>>,
        history: Option<PathBuf>,
    },
    /// Plain lines (a script, a pipe).
    Plain(std::io::Stdin),
}

impl Input {
    /// A terminal's input with `completion`'s words and the history kept
    /// in `history`; plain lines when stdin is not a terminal (or the
    /// terminal cannot be set up).
    pub(crate) fn new(terminal: bool, completion: Completion, history: Option<PathBuf>) -> Input {
        if terminal {
            let config = Config::builder()
                .auto_add_history(false)
                .completion_type(CompletionType::List)
                .max_history_size(1000)
                .and_then(|c| c.history_ignore_dups(true))
                .map(rustyline::config::Builder::build);
            if let Ok(config) = config
                && let Ok(mut editor) = Editor::with_config(config)
            {
                editor.set_helper(Some(completion));
                if let Some(path) = &history {
                    // None yet is the first session.
                    let _ = editor.load_history(path);
                }
                return Input::Terminal {
                    editor: Box::new(editor),
                    history,
                };
            }
        }
        Input::Plain(std::io::stdin())
    }

    /// Whether lines come from a terminal (else they are echoed, so that
    /// a script's session reads as a transcript).
    pub(crate) fn is_terminal(&self) -> bool {
        matches!(self, Input::Terminal { .. })
    }

    /// The next line, after `prompt` (the plain input's prompt is the
    /// caller's to print).
    pub(crate) fn read(&mut self, prompt: &str) -> std::io::Result<Read> {
        match self {
            Input::Terminal { editor, history } => match editor.readline(prompt) {
                Ok(line) => {
                    if !line.trim().is_empty() {
                        let _ = editor.add_history_entry(line.as_str());
                        if let Some(path) = history {
                            // Kept as typed, so that a session killed
                            // later still has it; a history that cannot be
                            // written does not stop the monitor.
                            if let Some(dir) = path.parent() {
                                let _ = std::fs::create_dir_all(dir);
                            }
                            let _ = editor.save_history(path);
                        }
                    }
                    Ok(Read::Line(line))
                }
                Err(ReadlineError::Interrupted) => Ok(Read::Interrupted),
                Err(ReadlineError::Eof) => Ok(Read::End),
                Err(ReadlineError::Io(error))
                    if error.kind() != std::io::ErrorKind::InvalidData =>
                {
                    Err(error)
                }
                // A byte that is no UTF-8 typed at the prompt is one bad
                // line, not the end of the session and its robot.
                Err(other) => Ok(Read::Invalid(format!(
                    "that line could not be read: {other}"
                ))),
            },
            Input::Plain(stdin) => plain_line(&mut stdin.lock()),
        }
    }
}

/// The next line of a script or a pipe, as bytes first: a line that is
/// not UTF-8, or longer than [`LINE_MAX`], is refused alone.
fn plain_line(stdin: &mut impl BufRead) -> std::io::Result<Read> {
    let mut bytes = Vec::new();
    let read = stdin
        .by_ref()
        .take(LINE_MAX)
        .read_until(b'\n', &mut bytes)?;
    if read == 0 {
        return Ok(Read::End);
    }
    if bytes.last() != Some(&b'\n') && read as u64 == LINE_MAX {
        // Skip the rest of the line, however long, without keeping it.
        loop {
            let buffer = stdin.fill_buf()?;
            if buffer.is_empty() {
                break;
            }
            if let Some(end) = buffer.iter().position(|&b| b == b'\n') {
                stdin.consume(end + 1);
                break;
            }
            let all = buffer.len();
            stdin.consume(all);
        }
        return Ok(Read::Invalid(format!(
            "a line longer than {LINE_MAX} bytes was skipped"
        )));
    }
    while matches!(bytes.last(), Some(b'\n' | b'\r')) {
        bytes.pop();
    }
    Ok(match String::from_utf8(bytes) {
        Ok(line) => Read::Line(line),
        Err(_) => Read::Invalid("that line is not UTF-8 text; it was skipped".to_owned()),
    })
}

/// The monitor's input read on a thread of its own, a line when asked:
/// a signal then ends a session whose read waits (a `kill` at the prompt,
/// a pipe left open), where the read itself would wait for the next line.
pub(crate) struct Reader {
    ask: std::sync::mpsc::Sender<()>,
    lines: std::sync::mpsc::Receiver<std::io::Result<Read>>,
    terminal: bool,
}

impl Reader {
    /// Reads `input` on a thread, `prompt` before each line.
    pub(crate) fn start(mut input: Input, prompt: &'static str) -> Reader {
        let terminal = input.is_terminal();
        let (ask, asked) = std::sync::mpsc::channel::<()>();
        let (send, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            while asked.recv().is_ok() {
                if send.send(input.read(prompt)).is_err() {
                    break;
                }
            }
        });
        Reader {
            ask,
            lines,
            terminal,
        }
    }

    /// Whether lines come from a terminal.
    pub(crate) fn is_terminal(&self) -> bool {
        self.terminal
    }

    /// The next line; `None` once `ended` is set while it is awaited.
    pub(crate) fn read(
        &self,
        ended: &std::sync::atomic::AtomicBool,
    ) -> Option<std::io::Result<Read>> {
        if self.ask.send(()).is_err() {
            return Some(Ok(Read::End));
        }
        loop {
            match self
                .lines
                .recv_timeout(std::time::Duration::from_millis(50))
            {
                Ok(read) => return Some(read),
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return Some(Ok(Read::End)),
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if ended.load(std::sync::atomic::Ordering::Relaxed) {
                        return None;
                    }
                }
            }
        }
    }
}

/// Where the history of a session in `root` is kept: the project's
/// `target/` when `root` is a project (each project its own), else the
/// user's data directory; `SCORPION_DEBUG_HISTORY` names a file instead.
pub(crate) fn history_file(root: &Path) -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("SCORPION_DEBUG_HISTORY") {
        return Some(PathBuf::from(path));
    }
    if root.join("Scorpion.toml").is_file() {
        return Some(root.join("target").join("debug-history"));
    }
    let data = std::env::var_os("XDG_DATA_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".local/share")))?;
    Some(data.join("scorpion").join("debug-history"))
}

/// The words Tab completes: commands first on a line, then symbols,
/// registers and `file:line` places with code.
#[derive(Debug, Default)]
pub(crate) struct Completion {
    /// Symbols and registers.
    pub(crate) names: BTreeSet<String>,
    /// `file:line` for every line that made code.
    pub(crate) places: BTreeSet<String>,
}

impl Completion {
    /// The completions of `word`, the line's first word if `first`.
    pub(crate) fn words(&self, word: &str, first: bool) -> Vec<String> {
        if first {
            return COMMANDS
                .iter()
                .filter(|c| c.starts_with(word))
                .map(|c| (*c).to_owned())
                .collect();
        }
        let from = |set: &BTreeSet<String>| -> Vec<String> {
            set.range(word.to_owned()..)
                .take_while(|w| w.starts_with(word))
                .take(200)
                .cloned()
                .collect()
        };
        if word.contains(':') && !word.contains("::") {
            return from(&self.places);
        }
        let mut words = from(&self.names);
        // A file's name: its lines follow the colon.
        let files: BTreeSet<String> = from(&self.places)
            .into_iter()
            .filter_map(|place| Some(format!("{}:", place.rsplit_once(':')?.0)))
            .collect();
        words.extend(files);
        words
    }
}

impl Completer for Completion {
    type Candidate = String;

    fn complete(
        &self,
        line: &str,
        pos: usize,
        _: &rustyline::Context<'_>,
    ) -> rustyline::Result<(usize, Vec<String>)> {
        let before = &line[..pos];
        // Words end at blanks and at the expression's brackets and
        // operators.
        let start = before
            .rfind(|c: char| c.is_whitespace() || "[]{}()+-*/=!<>&|^~,".contains(c))
            .map_or(0, |i| i + 1);
        let first = before[..start].trim().is_empty();
        Ok((start, self.words(&before[start..], first)))
    }
}

impl Hinter for Completion {
    type Hint = String;
}

impl Highlighter for Completion {}

impl Validator for Completion {}

impl Helper for Completion {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_symbols_and_places_complete() {
        let completion = Completion {
            names: ["read_channel", "read_chars", "CMDBUF"]
                .map(str::to_owned)
                .into(),
            places: ["adc.s:28", "adc.s:29", "adc.s:43"]
                .map(str::to_owned)
                .into(),
        };
        assert_eq!(completion.words("wh", true), ["who-wrote"]);
        assert_eq!(
            completion.words("read_ch", false),
            ["read_channel", "read_chars"]
        );
        assert_eq!(completion.words("adc.s:2", false), ["adc.s:28", "adc.s:29"]);
        assert_eq!(completion.words("ad", false), ["adc.s:"]);
        let history = tempfile::tempdir().expect("a directory");
        std::fs::write(history.path().join("Scorpion.toml"), "").expect("write");
        if std::env::var_os("SCORPION_DEBUG_HISTORY").is_none() {
            assert_eq!(
                history_file(history.path()),
                Some(history.path().join("target/debug-history"))
            );
        }
    }
}
