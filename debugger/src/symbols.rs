//! Names for addresses and addresses for names: the ROM's labels and
//! exported names, and every loaded image's symbols.

use std::collections::HashMap;

use crate::Error;

/// The names the debugger knows.
#[derive(Debug, Clone, Default)]
pub struct Symbols {
    /// Every name and its value (labels and constants).
    by_name: HashMap<String, u16>,
    /// Labels (names of places in code or data), by address.
    labels: Vec<(u16, String)>,
    /// Names that two images define at different addresses: each place,
    /// for the refusal.
    ambiguous: HashMap<String, Vec<Place>>,
}

impl Symbols {
    /// The robot's labels, the ROM's exported names, and `images`'
    /// symbols (constants too, for expressions).
    #[must_use]
    pub fn new(robot: &romlib::VirtualScorpion, images: &[linker::Image]) -> Symbols {
        let mut symbols = Symbols::default();
        for symbol in romlib::symbols::ALL {
            symbols.by_name.insert(symbol.name.to_owned(), symbol.value);
        }
        let mut defined: HashMap<&str, Vec<Place>> = HashMap::new();
        for (number, image) in images.iter().enumerate() {
            for symbol in &image.symbols {
                if let Ok(value) = u16::try_from(symbol.value) {
                    let places = defined.entry(symbol.name.as_str()).or_default();
                    if !places.iter().any(|place| place.address == value) {
                        places.push(Place {
                            address: value,
                            image: number + 1,
                            line: image
                                .source_of(u32::from(value))
                                .map(|(file, line, _)| format!("{file}:{line}")),
                        });
                    }
                    let entry = symbols.by_name.entry(symbol.name.clone());
                    if symbol.global {
                        *entry.or_default() = value;
                    } else {
                        entry.or_insert(value);
                    }
                }
            }
        }
        symbols.ambiguous = defined
            .into_iter()
            .filter(|(_, places)| places.len() > 1)
            .map(|(name, places)| (name.to_owned(), places))
            .collect();
        symbols.labels = robot.labels();
        for (at, name) in &symbols.labels {
            symbols.by_name.entry(name.clone()).or_insert(*at);
        }
        // One label per address: the user's own before the toolchain's
        // `__scorpion_...` names.
        symbols
            .labels
            .sort_by_key(|(at, name)| (*at, name.starts_with("__"), name.clone()));
        symbols.labels.dedup_by_key(|(at, _)| *at);
        symbols
    }

    /// The value of `name`.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<u16> {
        self.by_name.get(name).copied()
    }

    /// Why `name` cannot be taken for an address, when two images define
    /// it at different addresses: each address and the image it is in,
    /// and how to choose one (by address or by `file:line`).
    #[must_use]
    pub fn ambiguity(&self, name: &str) -> Option<String> {
        let places = self.ambiguous.get(name)?;
        let said: Vec<String> = places
            .iter()
            .map(|place| {
                let line = place
                    .line
                    .as_ref()
                    .map(|line| format!(" ({line})"))
                    .unwrap_or_default();
                format!("${:04X} in image {}{line}", place.address, place.image)
            })
            .collect();
        let first = &places[0];
        let line = first
            .line
            .as_ref()
            .map(|line| format!(" or its FILE:LINE (`{line}`)"))
            .unwrap_or_default();
        Some(format!(
            "`{}` is ambiguous: {} images define it, at {}; name the place by its address (`${:04X}`){line}",
            shown(name),
            places.len(),
            said.join(" and "),
            first.address
        ))
    }

    /// The label at `address` exactly.
    #[must_use]
    pub fn label(&self, address: u16) -> Option<&str> {
        let index = self
            .labels
            .binary_search_by_key(&address, |(at, _)| *at)
            .ok()?;
        Some(&self.labels[index].1)
    }

    /// `address` as `label` or `label+$offset` (a label within a page
    /// below it), if there is one.
    #[must_use]
    pub fn place(&self, address: u16) -> Option<String> {
        let index = self.labels.partition_point(|(at, _)| *at <= address);
        let (at, name) = self.labels.get(index.checked_sub(1)?)?;
        match address - at {
            0 => Some(name.clone()),
            offset if offset < 0x100 => Some(format!("{name}+${offset:X}")),
            _ => None,
        }
    }

    /// Evaluates an address expression: numbers (`$C000`, `0xC000`,
    /// `%1010`, `49152`) and names joined by `+` and `-`.
    ///
    /// # Errors
    /// [`Error::Address`] for an unknown name, a malformed number, or a
    /// value outside `$0000-$FFFF`.
    pub fn address(&self, text: &str) -> Result<u16, Error> {
        let bad = |reason: String| Error::Address {
            text: shown(text),
            reason,
        };
        let mut total: i64 = 0;
        let mut sign = 1;
        let mut rest = text.trim();
        if rest.is_empty() {
            return Err(bad("no address given".into()));
        }
        loop {
            let end = rest.find(['+', '-']).unwrap_or(rest.len());
            let term = rest[..end].trim();
            if term.is_empty() {
                return Err(bad("a `+` or `-` with nothing beside it".into()));
            }
            total += sign * self.term(term).map_err(bad)?;
            if end == rest.len() {
                break;
            }
            sign = if rest.as_bytes()[end] == b'+' { 1 } else { -1 };
            rest = &rest[end + 1..];
        }
        u16::try_from(total).map_err(|_| bad(format!("{total} is not an address ($0000-$FFFF)")))
    }

    fn term(&self, term: &str) -> Result<i64, String> {
        let number = |digits: &str, radix| {
            i64::from_str_radix(&digits.replace('_', ""), radix)
                .map_err(|_| format!("`{term}` is not a number"))
        };
        if let Some(hex) = term.strip_prefix('$').or_else(|| term.strip_prefix("0x")) {
            return number(hex, 16);
        }
        if let Some(binary) = term.strip_prefix('%') {
            return number(binary, 2);
        }
        if term.starts_with(|c: char| c.is_ascii_digit()) {
            return number(term, 10);
        }
        if let Some(why) = self.ambiguity(term) {
            return Err(why);
        }
        self.get(term)
            .map(i64::from)
            .ok_or_else(|| self.unknown(term))
    }

    /// What to say of `term`, which is no name known: the nearest name a
    /// letter or two away (or only in case), if there is one.
    #[must_use]
    pub fn unknown(&self, term: &str) -> String {
        // Names more than two letters longer or shorter cannot be within two
        // edits; skipping them keeps a megabyte-long mistyped name from costing
        // a Levenshtein table against every label (seconds, with the session
        // unable to answer anything else meanwhile).
        let length = term.chars().count();
        let near = self
            .by_name
            .keys()
            .filter(|name| name.chars().count().abs_diff(length) <= 2)
            .map(|name| {
                let distance = if name.eq_ignore_ascii_case(term) {
                    0
                } else {
                    strsim::levenshtein(name, term)
                };
                (distance, name)
            })
            .filter(|(distance, _)| *distance <= 2)
            .min();
        let term = shown(term);
        match near {
            Some((_, name)) => format!("no label `{term}` (did you mean `{name}`?)"),
            None => format!("no label `{term}`"),
        }
    }

    /// Every name known, for completion.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.by_name.keys().map(String::as_str)
    }
}

/// Where an image defines a name.
#[derive(Debug, Clone)]
struct Place {
    /// The name's value there.
    address: u16,
    /// Which image (from 1, in the order given).
    image: usize,
    /// `file:line` the address came from, when the image's line table says.
    line: Option<String>,
}

/// The most characters of an expression an error repeats.
const SHOWN: usize = 64;

/// `text` as an error repeats it: a 50 kB expression is cut, not echoed.
fn shown(text: &str) -> String {
    match text.char_indices().nth(SHOWN) {
        Some((at, _)) => format!("{}... ({} bytes)", &text[..at], text.len()),
        None => text.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_of_numbers_and_names() {
        let robot = romlib::VirtualScorpion::new();
        let symbols = Symbols::new(&robot, &[]);
        let cmdbuf = romlib::symbols::CMDBUF;
        assert_eq!(symbols.address("$C011").ok(), Some(0xC011));
        assert_eq!(symbols.address("0x10 + %11 - 1").ok(), Some(0x12));
        assert_eq!(symbols.address("CMDBUF+1").ok(), Some(cmdbuf + 1));
        assert!(
            symbols
                .address("cmdbuf")
                .is_err_and(|e| e.to_string().contains("did you mean `CMDBUF`"))
        );
        assert!(symbols.address("$10000").is_err());
        assert!(symbols.address("1+").is_err());
        // A long expression is cut in the error, not repeated whole.
        let long = "CMDBUF+1+".repeat(5000) + "1";
        let said = symbols.address(&long).expect_err("past $FFFF").to_string();
        assert!(said.len() < 200 && said.contains("(45001 bytes)"), "{said}");
        // A megabyte of unknown name: said briefly, and without comparing it
        // with every label letter by letter (that took 90 s and blocked the
        // DAP session).
        let huge = "a".repeat(1_000_000);
        let said = symbols.unknown(&huge);
        assert!(
            said.len() < 200 && said.contains("(1000000 bytes)"),
            "{said}"
        );
        let dispatch = symbols.get("dispatch").expect("the ROM's dispatch label");
        assert_eq!(symbols.place(dispatch).as_deref(), Some("dispatch"));
        assert_eq!(symbols.place(dispatch + 2), Some("dispatch+$2".into()));
    }

    /// An image whose label `name` is at `address`.
    fn image_with(name: &str, address: u16) -> linker::Image {
        linker::Image {
            symbols: vec![linker::ImageSymbol {
                name: name.into(),
                value: u32::from(address),
                size: 0,
                global: false,
                section: Some(0),
            }],
            ..linker::Image::default()
        }
    }

    /// Issue 27 F3: two images both defining `not_mine` made `break
    /// not_mine` take the first silently. Refused, naming both places
    /// and how to choose; a name both define at one address is not.
    #[test]
    fn a_label_two_images_define_apart_is_refused_naming_both() {
        let robot = romlib::VirtualScorpion::new();
        let images = [
            image_with("not_mine", 0x0412),
            image_with("not_mine", 0x0612),
            image_with("shared", 0x0700),
        ];
        let mut both = images.to_vec();
        both.push(image_with("shared", 0x0700));
        let symbols = Symbols::new(&robot, &both);
        let said = symbols
            .address("not_mine")
            .expect_err("ambiguous")
            .to_string();
        for expected in [
            "ambiguous",
            "$0412 in image 1",
            "$0612 in image 2",
            "`$0412`",
        ] {
            assert!(said.contains(expected), "{expected}: {said}");
        }
        let parsed = crate::expr::Expr::parse("not_mine+1", &symbols)
            .err()
            .map(|e| e.to_string());
        assert!(
            parsed.as_deref().is_some_and(|e| e.contains("ambiguous")),
            "{parsed:?}"
        );
        assert_eq!(symbols.address("shared").ok(), Some(0x0700));
        assert_eq!(symbols.address("$0612").ok(), Some(0x0612));
        // One image alone: no question.
        let one = Symbols::new(&robot, &images[..1]);
        assert_eq!(one.address("not_mine").ok(), Some(0x0412));
        assert!(one.ambiguity("not_mine").is_none());
    }
}
