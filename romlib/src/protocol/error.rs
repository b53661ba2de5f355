//! Errors of the typed protocol: a value out of range, a command that does
//! not parse, an answer that is malformed or not the one asked for.

/// What went wrong building a command or parsing a command or an answer.
///
/// Texts are shown escaped (`\r`, `\x07`), so line noise is visible.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum ProtocolError {
    /// A command field outside the range the protocol allows.
    #[error("{what} {value} is out of range ({min} to {max})")]
    #[diagnostic(
        code(romlib::protocol::out_of_range),
        help("the protocol's digits limit this field to {min}..={max}")
    )]
    OutOfRange {
        /// The field (`"speed"`, `"step count"`...).
        what: &'static str,
        /// The value given.
        value: u32,
        /// The smallest allowed value.
        min: u32,
        /// The largest allowed value.
        max: u32,
    },

    /// A `/7R` read that would run past `$FFFF`.
    #[error("reading {count} bytes at ${address:04X} runs past $FFFF")]
    #[diagnostic(
        code(romlib::protocol::read_wraps),
        help("split the read at $FFFF; the ROM does not wrap addresses")
    )]
    ReadWraps {
        /// The first address.
        address: u16,
        /// The byte count.
        count: u8,
    },

    /// An extension command the command grammar cannot carry.
    #[error("extension command `{text}`: {reason}")]
    #[diagnostic(
        code(romlib::protocol::bad_extension),
        help(
            "an extension command is 1 to 9 printable ASCII characters, letter first, without `/`"
        )
    )]
    BadExtension {
        /// The command bytes, escaped.
        text: String,
        /// Why it cannot be sent.
        reason: String,
    },

    /// A command string that does not parse.
    #[error("command `{text}`, character {position}: expected {expected}, found {found}")]
    #[diagnostic(
        code(romlib::protocol::bad_command),
        help("commands look like /1P, /8C+501000, /7R020010, /9W04001234")
    )]
    BadCommand {
        /// The command, escaped.
        text: String,
        /// 0-based character offset of the problem.
        position: usize,
        /// What the grammar wanted there.
        expected: String,
        /// What was there (`end of command` past the end).
        found: String,
    },

    /// An answer that does not follow its form.
    #[error(
        "malformed {form} answer `{text}`, character {position}: expected {expected}, found {found}"
    )]
    #[diagnostic(
        code(romlib::protocol::malformed_answer),
        help(
            "line noise or a wrong baud rate garbles answers; check the cable and --baud, then retry"
        )
    )]
    MalformedAnswer {
        /// The answer form (`"/1M"`, `"/7R"`...), or `"an"` when the letter is unknown.
        form: &'static str,
        /// The answer, escaped.
        text: String,
        /// 0-based character offset of the problem.
        position: usize,
        /// What the form wanted there.
        expected: String,
        /// What was there (`end of answer` past the end).
        found: String,
    },

    /// An answer that parsed but does not answer the question asked.
    #[error("`{question}` was answered with `{text}`: expected {expected}")]
    #[diagnostic(
        code(romlib::protocol::unexpected_answer),
        help(
            "answers arrive in the order of the questions; a lost or extra answer means line noise or an extension answering a ROM command"
        )
    )]
    UnexpectedAnswer {
        /// The question, as sent.
        question: String,
        /// The answer, escaped.
        text: String,
        /// What the question wanted.
        expected: String,
    },

    /// An instruction has no answer, so there is nothing to parse.
    #[error("`{command}` is an instruction: the ROM sends no answer to it")]
    #[diagnostic(code(romlib::protocol::no_answer_expected))]
    NoAnswerExpected {
        /// The instruction.
        command: String,
    },
}

/// Shows bytes as text with control characters and non-ASCII escaped.
pub(crate) fn escape(bytes: &[u8]) -> String {
    bytes
        .iter()
        .flat_map(|&b| std::ascii::escape_default(b))
        .map(char::from)
        .collect()
}

/// Describes the byte at `position` for an error message.
pub(crate) fn describe_at(bytes: &[u8], position: usize, end: &str) -> String {
    match bytes.get(position) {
        Some(&b) => format!("`{}`", escape(&[b])),
        None => end.to_owned(),
    }
}
