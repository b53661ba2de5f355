//! ca65's `.feature` switches (and `--feature`): the ones this assembler
//! implements, and the names of the rest, which it says it does not.

/// The switches that change what this assembler does.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Features {
    /// `force_range`: an immediate operand or a `.byte` value out of range
    /// keeps its low byte (and a constant `.word`, its low 16 bits)
    /// instead of being an error.
    pub force_range: bool,
    /// `org_per_seg`: `.org` and `.reloc` affect the current segment only
    /// (without it, absolute mode is global and carries over when the
    /// segment changes).
    pub org_per_seg: bool,
}

/// Every feature ca65 2.19 knows.
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
    /// ca65 knows it; this assembler does not implement it yet.
    Unsupported,
    /// No such feature in ca65 either.
    Unknown,
}

impl Features {
    /// Switches `name` (as ca65 spells it, any case) on or off.
    ///
    /// # Errors
    /// [`FeatureError::Unsupported`] for a ca65 feature not implemented
    /// here, [`FeatureError::Unknown`] for a name ca65 does not know.
    pub fn set(&mut self, name: &str, on: bool) -> Result<(), FeatureError> {
        match name.to_ascii_lowercase().as_str() {
            "force_range" => self.force_range = on,
            "org_per_seg" => self.org_per_seg = on,
            other if CA65_FEATURES.contains(&other) => return Err(FeatureError::Unsupported),
            _ => return Err(FeatureError::Unknown),
        }
        Ok(())
    }
}
