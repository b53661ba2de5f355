//! The counts and lengths the monitor takes from the user, each with its
//! bounds: a session's command must never ask for gigabytes of output or
//! hours of robot time, since nothing typed afterwards can stop it (the
//! monitor reads its next command only after the last one ends).

/// A count a command takes: its name in the command's usage, and the
/// range it may take.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Count {
    /// The command's usage: `mem ADDR [LEN]`.
    pub(crate) usage: &'static str,
    /// The count's name in it: `LEN`.
    pub(crate) name: &'static str,
    /// What it counts: `bytes`.
    pub(crate) unit: &'static str,
    /// The smallest it may be.
    pub(crate) min: u64,
    /// The largest it may be.
    pub(crate) max: u64,
    /// Why it stops there (said when it is too large).
    pub(crate) why: &'static str,
}

/// The 6502's address space, which `mem` and `dis` cover at most.
const ADDRESS_SPACE: u64 = 0x1_0000;

/// `mem ADDR [LEN]`.
pub(crate) const MEM_LEN: Count = Count {
    usage: "mem ADDR [LEN]",
    name: "LEN",
    unit: "bytes",
    min: 1,
    max: ADDRESS_SPACE,
    why: "the whole address space",
};

/// `dis [ADDR] [N]`.
pub(crate) const DIS_COUNT: Count = Count {
    usage: "dis [ADDR] [N]",
    name: "N",
    unit: "instructions",
    min: 1,
    max: ADDRESS_SPACE,
    why: "more than the whole address space holds",
};

/// `step [N]`: ten million instructions are about 30 s of robot time, a
/// few seconds of ours with the hooks on.
pub(crate) const STEP_COUNT: Count = Count {
    usage: "step [N]",
    name: "N",
    unit: "instructions",
    min: 1,
    max: 10_000_000,
    why: "nothing can stop a step once it runs; step again to go on",
};

/// `back [N]` (bounded anyway by the instructions run so far).
pub(crate) const BACK_COUNT: Count = Count {
    usage: "back [N]",
    name: "N",
    unit: "instructions",
    min: 1,
    max: u64::MAX,
    why: "",
};

/// `continue [CYCLES]`: a minute of robot time.
pub(crate) const CONTINUE_CYCLES: Count = Count {
    usage: "continue [CYCLES]",
    name: "CYCLES",
    unit: "cycles",
    min: 1,
    max: 60_000_000,
    why: "a minute of robot time: nothing can stop a run once it goes; continue again to go on",
};

/// `continue [CYCLES]` at a terminal, where Ctrl-C pauses the run: an
/// hour of robot time.
pub(crate) const CONTINUE_CYCLES_PAUSABLE: Count = Count {
    usage: "continue [CYCLES]",
    name: "CYCLES",
    unit: "cycles",
    min: 1,
    max: 3_600_000_000,
    why: "an hour of robot time; Ctrl-C pauses a run",
};

impl Count {
    /// `text` as this count, or what is wrong with it.
    pub(crate) fn parse(&self, text: &str) -> Result<u64, String> {
        let Count {
            usage,
            name,
            unit,
            min,
            max,
            why,
        } = *self;
        let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
        if !digits {
            return Err(format!(
                "{usage}: {name} is a number of {unit} from {min} to {max}, not `{text}`"
            ));
        }
        // All digits: a parse failure is a number beyond u64.
        match text.parse::<u64>() {
            Ok(n) if (min..=max).contains(&n) => Ok(n),
            Ok(n) if n < min => Err(format!("{usage}: {name} is at least {min}, not {n}")),
            _ => Err(format!(
                "{usage}: {name} is at most {max} {unit} ({why}), not {text}"
            )),
        }
    }

    /// The count given as `word`, or `default` without one.
    pub(crate) fn or(&self, word: Option<&&str>, default: u64) -> Result<u64, String> {
        word.map_or(Ok(default), |text| self.parse(text))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_in_range_are_taken() {
        assert_eq!(MEM_LEN.parse("1"), Ok(1));
        assert_eq!(MEM_LEN.parse("65536"), Ok(65536));
        assert_eq!(STEP_COUNT.parse("10000000"), Ok(10_000_000));
    }

    #[test]
    fn too_large_too_small_and_not_numbers_are_said() {
        let large = MEM_LEN.parse("18446744073709551615").unwrap_err();
        assert!(large.contains("at most 65536 bytes"), "{large}");
        let beyond = DIS_COUNT.parse("99999999999999999999999").unwrap_err();
        assert!(beyond.contains("at most 65536"), "{beyond}");
        let zero = STEP_COUNT.parse("0").unwrap_err();
        assert!(zero.contains("at least 1"), "{zero}");
        for bad in ["", "-1", "+5", "1e9", "0x10", "ten"] {
            let said = CONTINUE_CYCLES.parse(bad).unwrap_err();
            assert!(said.contains("is a number of cycles"), "{bad}: {said}");
        }
    }

    proptest::proptest! {
        /// Any word: a count in range, or an error; never a panic.
        #[test]
        fn any_word_is_a_count_in_range_or_an_error(word in "\\PC{0,30}|[0-9]{1,40}") {
            for count in [MEM_LEN, DIS_COUNT, STEP_COUNT, BACK_COUNT, CONTINUE_CYCLES] {
                if let Ok(n) = count.parse(&word) {
                    proptest::prop_assert!((count.min..=count.max).contains(&n));
                }
            }
        }
    }
}
