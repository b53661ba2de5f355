//! ca65's `.feature` switches (and `--feature`).

/// The switches that change what this assembler does: every feature of
/// ca65 2.19, and `line_continuations` (ca65 2.19's `.linecont`, a
/// feature in later ca65s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[allow(clippy::struct_excessive_bools, reason = "one switch per ca65 feature")]
pub struct Features {
    /// `force_range`: an immediate operand or a `.byte` value out of range
    /// keeps its low byte (and a constant `.word`, its low 16 bits)
    /// instead of being an error.
    pub force_range: bool,
    /// `org_per_seg`: `.org` and `.reloc` affect the current segment only
    /// (without it, absolute mode is global and carries over when the
    /// segment changes).
    pub org_per_seg: bool,
    /// `at_in_identifiers`: `@` may appear inside names.
    pub at_in_identifiers: bool,
    /// `dollar_in_identifiers`: `$` may appear inside names.
    pub dollar_in_identifiers: bool,
    /// `leading_dot_in_identifiers`: a name may start with `.` when it is
    /// no directive.
    pub leading_dot_in_identifiers: bool,
    /// `underline_in_numbers`: `_` between digits is ignored (`%1010_0101`).
    pub underline_in_numbers: bool,
    /// `c_comments`: `/* ... */` comments.
    pub c_comments: bool,
    /// `loose_string_term`: strings may be in single quotes.
    pub loose_string_term: bool,
    /// `loose_char_term`: characters may be in double quotes (`"a"` in
    /// an expression).
    pub loose_char_term: bool,
    /// `missing_char_term`: `'a` without its closing quote.
    pub missing_char_term: bool,
    /// `string_escapes`: `\n`, `\t`, `\r`, `\\`, `\"`, `\'` and `\xHH` in
    /// strings.
    pub string_escapes: bool,
    /// `dollar_is_pc`: `$` alone is the program counter, as `*`.
    pub dollar_is_pc: bool,
    /// `bracket_as_indirect`: `[addr]` for indirect addressing.
    pub bracket_as_indirect: bool,
    /// `labels_without_colons`: a name at the start of a line that is no
    /// instruction, macro or assignment is a label.
    pub labels_without_colons: bool,
    /// `pc_assignment`: `* = addr` is `.org addr`.
    pub pc_assignment: bool,
    /// `ubiquitous_idents`: instruction names may name macros and
    /// symbols.
    pub ubiquitous_idents: bool,
    /// `addrsize`: the `.addrsize(name)` function.
    pub addrsize: bool,
    /// `line_continuations` (`.linecont +`): `\` at the end of a line joins
    /// the next.
    pub line_continuations: bool,
}

impl Features {
    /// The switches the lexer needs.
    pub(crate) fn lexer(&self) -> crate::lexer::LexFeatures {
        crate::lexer::LexFeatures {
            at_in_identifiers: self.at_in_identifiers,
            dollar_in_identifiers: self.dollar_in_identifiers,
            leading_dot_in_identifiers: self.leading_dot_in_identifiers,
            underline_in_numbers: self.underline_in_numbers,
            c_comments: self.c_comments,
            loose_string_term: self.loose_string_term,
            missing_char_term: self.missing_char_term,
            string_escapes: self.string_escapes,
            dollar_is_pc: self.dollar_is_pc,
            bracket_as_indirect: self.bracket_as_indirect,
            line_continuations: self.line_continuations,
        }
    }
}

/// Every feature ca65 2.19 knows, and `line_continuations` (its
/// `.linecont`, a feature in later ca65s).
pub const CA65_FEATURES: &[&str] = &[
    "addrsize",
    "at_in_identifiers",
    "bracket_as_indirect",
    "c_comments",
    "dollar_in_identifiers",
    "dollar_is_pc",
    "force_range",
    "labels_without_colons",
    "leading_dot_in_identifiers",
    "line_continuations",
    "loose_char_term",
    "loose_string_term",
    "missing_char_term",
    "org_per_seg",
    "pc_assignment",
    "string_escapes",
    "ubiquitous_idents",
    "underline_in_numbers",
];

/// Why a feature could not be set.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FeatureError {
    /// No such feature in ca65.
    Unknown,
}

impl Features {
    /// Switches `name` (as ca65 spells it, any case) on or off.
    ///
    /// # Errors
    /// [`FeatureError::Unknown`] for a name ca65 does not know.
    pub fn set(&mut self, name: &str, on: bool) -> Result<(), FeatureError> {
        let switch = match name.to_ascii_lowercase().as_str() {
            "force_range" => &mut self.force_range,
            "org_per_seg" => &mut self.org_per_seg,
            "at_in_identifiers" => &mut self.at_in_identifiers,
            "dollar_in_identifiers" => &mut self.dollar_in_identifiers,
            "leading_dot_in_identifiers" => &mut self.leading_dot_in_identifiers,
            "underline_in_numbers" => &mut self.underline_in_numbers,
            "c_comments" => &mut self.c_comments,
            "loose_string_term" => &mut self.loose_string_term,
            "loose_char_term" => &mut self.loose_char_term,
            "missing_char_term" => &mut self.missing_char_term,
            "string_escapes" => &mut self.string_escapes,
            "dollar_is_pc" => &mut self.dollar_is_pc,
            "bracket_as_indirect" => &mut self.bracket_as_indirect,
            "labels_without_colons" => &mut self.labels_without_colons,
            "pc_assignment" => &mut self.pc_assignment,
            "ubiquitous_idents" => &mut self.ubiquitous_idents,
            "addrsize" => &mut self.addrsize,
            "line_continuations" => &mut self.line_continuations,
            _ => return Err(FeatureError::Unknown),
        };
        *switch = on;
        Ok(())
    }
}
