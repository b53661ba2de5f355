//! Line and branch coverage of source files, from a profile of the tests:
//! each code line run or not, each conditional branch taken and not
//! taken; written as LCOV (`lcov.info`, what editors' coverage gutters and
//! genhtml read) and as a self-contained HTML page.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::lines::LineTable;
use crate::profile::Profile;

/// One code line's counts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LineHits {
    /// The line, from 1.
    pub line: u32,
    /// Times its instructions began (summed over its instructions'
    /// first: a line is one instruction, or a macro body line used
    /// several times).
    pub hits: u64,
    /// Each conditional branch on it: (taken, not taken).
    pub branches: Vec<(u64, u64)>,
}

/// One file's coverage.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileCoverage {
    /// The file, as the assembler was given it.
    pub file: String,
    /// Its code lines, in order.
    pub lines: Vec<LineHits>,
}

impl FileCoverage {
    /// Code lines, and those run.
    #[must_use]
    pub fn line_counts(&self) -> (usize, usize) {
        let hit = self.lines.iter().filter(|l| l.hits > 0).count();
        (self.lines.len(), hit)
    }

    /// Branch outcomes (two per conditional branch), and those seen.
    #[must_use]
    pub fn branch_counts(&self) -> (usize, usize) {
        let mut found = 0;
        let mut hit = 0;
        for line in &self.lines {
            for (taken, not_taken) in &line.branches {
                found += 2;
                hit += usize::from(*taken > 0) + usize::from(*not_taken > 0);
            }
        }
        (found, hit)
    }
}

/// A branch outcome no test saw.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MissedBranch {
    /// The file.
    pub file: String,
    /// The line.
    pub line: u32,
    /// True if it was never taken, false if it was never not taken
    /// (always taken).
    pub never_taken: bool,
}

/// The coverage of some files.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Coverage {
    /// Every file kept, in name order.
    pub files: Vec<FileCoverage>,
}

impl Coverage {
    /// The coverage `profile` gives the code lines of `table`, of the
    /// files `keep` accepts (the user's own: not the ROM's, not built-in
    /// includes, unless asked). Each instruction counts at the line a
    /// user is shown for it ([`isa::objfmt::user_place`], as the
    /// debuggers and the profile show it): the code a macro from a file
    /// not kept made (a built-in include's `SCORPION_CHAIN_UNKNOWN`)
    /// counts at the kept line that called it.
    #[must_use]
    pub fn new(profile: &Profile, table: &LineTable, keep: &dyn Fn(&str) -> bool) -> Coverage {
        let mut kept: BTreeMap<String, BTreeMap<u32, LineHits>> = BTreeMap::new();
        let mut count = |file: &str, line: u32, at: Option<u16>, is_branch: bool| {
            let hits = kept
                .entry(file.to_owned())
                .or_default()
                .entry(line)
                .or_insert_with(|| LineHits {
                    line,
                    hits: 0,
                    branches: Vec::new(),
                });
            let Some(at) = at else {
                return;
            };
            hits.hits += profile.counts[usize::from(at)];
            if is_branch {
                hits.branches.push((
                    profile.taken[usize::from(at)],
                    profile.not_taken[usize::from(at)],
                ));
            }
        };
        for line in &table.lines {
            if keep(&line.file) {
                count(&line.file, line.line, None, false);
            }
            for &at in &line.starts {
                let is_branch = line.branches.contains(&at);
                let call = table.call_of(at);
                let (file, shown) = isa::objfmt::user_place((&line.file, line.line), call, keep);
                if keep(file) {
                    count(file, shown, Some(at), is_branch);
                }
            }
        }
        Coverage {
            files: kept
                .into_iter()
                .map(|(file, lines)| FileCoverage {
                    file,
                    lines: lines.into_values().collect(),
                })
                .collect(),
        }
    }

    /// Code lines and those run, over every file.
    #[must_use]
    pub fn line_counts(&self) -> (usize, usize) {
        self.files
            .iter()
            .map(FileCoverage::line_counts)
            .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }

    /// Branch outcomes and those seen, over every file.
    #[must_use]
    pub fn branch_counts(&self) -> (usize, usize) {
        self.files
            .iter()
            .map(FileCoverage::branch_counts)
            .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }

    /// Every code line no test ran: (file, line).
    #[must_use]
    pub fn never_run(&self) -> Vec<(String, u32)> {
        self.files
            .iter()
            .flat_map(|file| {
                file.lines
                    .iter()
                    .filter(|line| line.hits == 0)
                    .map(|line| (file.file.clone(), line.line))
            })
            .collect()
    }

    /// Every branch outcome no test saw, on lines that ran.
    #[must_use]
    pub fn missed_branches(&self) -> Vec<MissedBranch> {
        let mut missed = Vec::new();
        for file in &self.files {
            for line in file.lines.iter().filter(|line| line.hits > 0) {
                for (taken, not_taken) in &line.branches {
                    for (count, never_taken) in [(taken, true), (not_taken, false)] {
                        if *count == 0 {
                            missed.push(MissedBranch {
                                file: file.file.clone(),
                                line: line.line,
                                never_taken,
                            });
                        }
                    }
                }
            }
        }
        missed
    }

    /// The LCOV tracefile (`lcov.info`); `path_of` turns a file's name
    /// into the path the tracefile gives (an absolute one, for tools run
    /// elsewhere).
    #[must_use]
    pub fn lcov(&self, test_name: &str, path_of: &dyn Fn(&str) -> String) -> String {
        let mut text = String::new();
        for file in &self.files {
            let _ = writeln!(text, "TN:{test_name}");
            let _ = writeln!(text, "SF:{}", path_of(&file.file));
            for line in &file.lines {
                for (block, (taken, not_taken)) in line.branches.iter().enumerate() {
                    for (branch, count) in [taken, not_taken].into_iter().enumerate() {
                        if line.hits == 0 {
                            let _ = writeln!(text, "BRDA:{},{block},{branch},-", line.line);
                        } else {
                            let _ = writeln!(text, "BRDA:{},{block},{branch},{count}", line.line);
                        }
                    }
                }
            }
            let (branches, branches_hit) = file.branch_counts();
            let _ = writeln!(text, "BRF:{branches}");
            let _ = writeln!(text, "BRH:{branches_hit}");
            for line in &file.lines {
                let _ = writeln!(text, "DA:{},{}", line.line, line.hits);
            }
            let (lines, lines_hit) = file.line_counts();
            let _ = writeln!(text, "LF:{lines}");
            let _ = writeln!(text, "LH:{lines_hit}");
            text.push_str("end_of_record\n");
        }
        text
    }

    /// A self-contained HTML page: a summary per file, then each file's
    /// source with its lines marked run, never run, or run with a branch
    /// outcome missing. `read` gives a file's text.
    #[must_use]
    pub fn html(&self, title: &str, read: &dyn Fn(&str) -> Option<String>) -> String {
        let mut page = String::new();
        let _ = write!(
            page,
            "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{}</title>\n<style>\
             body{{font-family:sans-serif}} pre{{margin:0}} table.src td{{font-family:monospace;white-space:pre;padding:0 .5em}}\
             tr.run{{background:#dfd}} tr.never{{background:#fdd}} tr.partial{{background:#ffd}}\
             td.n{{text-align:right;color:#666}}</style></head><body>\n<h1>{}</h1>\n",
            escape(title),
            escape(title)
        );
        let (lines, lines_hit) = self.line_counts();
        let (branches, branches_hit) = self.branch_counts();
        let _ = writeln!(
            page,
            "<p>Lines: {lines_hit} of {lines} ({}). Branches: {branches_hit} of {branches} ({}).</p>",
            percent(lines_hit, lines),
            percent(branches_hit, branches)
        );
        page.push_str(
            "<table class=\"summary\"><tr><th>file</th><th>lines</th><th>branches</th></tr>\n",
        );
        for (index, file) in self.files.iter().enumerate() {
            let (l, lh) = file.line_counts();
            let (b, bh) = file.branch_counts();
            let _ = writeln!(
                page,
                "<tr><td><a href=\"#f{index}\">{}</a></td><td>{lh}/{l} ({})</td><td>{bh}/{b} ({})</td></tr>",
                escape(&file.file),
                percent(lh, l),
                percent(bh, b)
            );
        }
        page.push_str("</table>\n");
        for (index, file) in self.files.iter().enumerate() {
            let _ = writeln!(page, "<h2 id=\"f{index}\">{}</h2>", escape(&file.file));
            let Some(text) = read(&file.file) else {
                page.push_str("<p>(source not readable)</p>\n");
                continue;
            };
            page.push_str("<table class=\"src\">\n");
            for (number, source) in text.lines().enumerate() {
                let number = u32::try_from(number + 1).unwrap_or(u32::MAX);
                let hits = file.lines.iter().find(|l| l.line == number);
                let (class, count, note) = match hits {
                    None => ("", String::new(), String::new()),
                    Some(hits) if hits.hits == 0 => {
                        ("never", "0".to_owned(), "never run".to_owned())
                    }
                    Some(hits) => {
                        let missing: Vec<&str> = hits
                            .branches
                            .iter()
                            .flat_map(|(t, n)| {
                                [
                                    (*t == 0).then_some("never taken"),
                                    (*n == 0).then_some("always taken"),
                                ]
                            })
                            .flatten()
                            .collect();
                        if missing.is_empty() {
                            ("run", hits.hits.to_string(), String::new())
                        } else {
                            ("partial", hits.hits.to_string(), missing.join(", "))
                        }
                    }
                };
                let _ = writeln!(
                    page,
                    "<tr class=\"{class}\"><td class=\"n\">{number}</td><td class=\"n\">{count}</td><td>{}</td><td>{note}</td></tr>",
                    escape(source)
                );
            }
            page.push_str("</table>\n");
        }
        page.push_str("</body></html>\n");
        page
    }
}

/// `part` of `whole` as a percentage (100% of nothing).
#[must_use]
pub fn percent(part: usize, whole: usize) -> String {
    if whole == 0 {
        "100%".to_owned()
    } else {
        format!("{:.1}%", 100.0 * part as f64 / whole as f64)
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
