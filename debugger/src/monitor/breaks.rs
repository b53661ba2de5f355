//! `break PLACE [if CONDITION] [hits COUNT] [log MESSAGE]`: a breakpoint
//! with what it asks before it stops. The condition, the count and the
//! message are the debugger crate's ([`crate::PointOptions`]), shared
//! with the DAP server; this reads the monitor's words for them.

use crate::{Breakpoint, Debugger, Expr, HitCondition, PointOptions, Template};

use super::{Failure, address, describe, file_line, pointed, usage};

const USAGE: &str = "break ADDR | FILE:LINE | /3A | unknown [if CONDITION] [hits N] [log MESSAGE]";

/// A clause of the line: its keyword, its text and where the text starts
/// (in characters from the start of the line).
struct Clause<'a> {
    keyword: &'a str,
    text: &'a str,
    column: usize,
}

/// Splits what follows the verb at the keywords `if`, `hits` and `log`
/// (`log` takes the rest of the line, whatever it holds): the place, then
/// the clauses.
fn clauses(line: &str, from: usize) -> (&str, Vec<Clause<'_>>) {
    // Byte offsets of the words after the verb.
    let mut words = Vec::new();
    let mut start = None;
    for (i, c) in line.char_indices().skip_while(|&(i, _)| i < from) {
        match (c.is_whitespace(), start) {
            (false, None) => start = Some(i),
            (true, Some(s)) => {
                words.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        words.push((s, line.len()));
    }
    let mut cuts = Vec::new();
    for &(s, e) in &words {
        let word = &line[s..e];
        if matches!(word, "if" | "hits" | "log") {
            cuts.push((s, e, &line[s..e]));
            if word == "log" {
                break;
            }
        }
    }
    let place_end = cuts.first().map_or(line.len(), |&(s, _, _)| s);
    let place = line[from.min(place_end)..place_end].trim();
    let mut found = Vec::new();
    for (index, &(_, e, keyword)) in cuts.iter().enumerate() {
        let end = cuts.get(index + 1).map_or(line.len(), |&(s, _, _)| s);
        let raw = &line[e..end];
        let text = raw.trim();
        let lead = raw.len() - raw.trim_start().len();
        found.push(Clause {
            keyword,
            text,
            column: line[..e + lead].chars().count(),
        });
    }
    (place, found)
}

/// Adds the breakpoint `line` describes (`verb` bytes of it are the verb).
pub(super) fn add(d: &mut Debugger, line: &str, verb: usize) -> Result<String, Failure> {
    let (what, found) = clauses(line, verb);
    if what.is_empty() {
        return Err(usage(USAGE));
    }
    let mut options = PointOptions::default();
    for clause in found {
        if clause.text.is_empty() {
            return Err(usage(&format!(
                "`{}` needs something after it: {USAGE}",
                clause.keyword
            )));
        }
        match clause.keyword {
            "if" => {
                let condition = Expr::parse(clause.text, d.symbols())
                    .map_err(|e| Failure::Usage(at_line(&e, line, clause.column)))?;
                options.condition = Some(condition);
            }
            "hits" => {
                let hits = HitCondition::parse(clause.text).map_err(|e| {
                    Failure::Usage(format!("{e} (a hit count is N, >= N, == N or % N)"))
                })?;
                options.hits = Some(hits);
            }
            _ => {
                let message = Template::parse(clause.text, d.symbols())
                    .map_err(|e| Failure::Usage(at_line(&e, line, clause.column)))?;
                options.log = Some(message);
            }
        }
    }
    let point = place(d, what)?;
    let shown = describe(d, &point);
    let extra = options.describe();
    let kind = if options.log.is_some() {
        "log point"
    } else {
        "breakpoint"
    };
    let id = d.add_breakpoint_with(point, options);
    Ok(format!("{kind} {id}: {shown}{extra}\n"))
}

/// Where `what` stops, as `break` (and the DAP server's function
/// breakpoints) take it: `unknown` (the unknown-command hook), a robot
/// command `/3A`, `FILE:LINE`, or an address expression (`checksum`,
/// `$0403`, `CMDBUF+1`).
///
/// # Errors
/// [`Failure::Usage`]: none of those.
pub(crate) fn place(d: &Debugger, what: &str) -> Result<Breakpoint, Failure> {
    Ok(if what == "unknown" {
        Breakpoint::UnknownHook
    } else if what.starts_with('/') {
        Breakpoint::command(what)
            .ok_or_else(|| usage("a command breakpoint is /, a count 1-9 and a letter: /3A"))?
    } else if let Some((file, n)) = file_line(what) {
        Breakpoint::At(
            d.address_of_line(file, n)
                .ok_or_else(|| usage(&format!("no code came from {file}:{n}")))?,
        )
    } else {
        Breakpoint::At(address(d, what)?)
    })
}

/// A parse error in a clause, its column counted in the whole line and
/// pointed at under it.
fn at_line(error: &crate::expr::ParseError, line: &str, column: usize) -> String {
    let whole = crate::expr::ParseError {
        text: line.to_owned(),
        column: error.column + column,
        reason: error.reason.clone(),
        span: error.span,
    };
    pointed(&whole, 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_place_and_the_clauses_are_split_at_their_keywords() {
        let line = "break checksum if A == 1 && [CMDBUF] == $2F hits 3 log A={A} if";
        let (place, found) = clauses(line, "break".len());
        assert_eq!(place, "checksum");
        let got: Vec<(&str, &str, usize)> = found
            .iter()
            .map(|c| (c.keyword, c.text, c.column))
            .collect();
        assert_eq!(
            got,
            [
                ("if", "A == 1 && [CMDBUF] == $2F", 18),
                ("hits", "3", 49),
                ("log", "A={A} if", 55),
            ]
        );
        assert_eq!(&line[18..19], "A");
        assert_eq!(&line[49..50], "3");
    }
}
