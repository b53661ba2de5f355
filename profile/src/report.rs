//! The profile as tables for a terminal, dearest first: routines, robot
//! commands (beside what one character on the line costs), hot lines.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::lines::LineTable;
use crate::profile::Profile;

/// Cycles one character takes on the line at `baud` (8N1: ten bits), at
/// the robot's 1 MHz: what a handler may cost before the robot falls
/// behind a host that sends back to back.
#[must_use]
pub fn character_cycles(baud: u32) -> u64 {
    10 * emulator::board::CPU_HZ / u64::from(baud.max(1))
}

/// One robot command's runs, by count and letter (`/2A`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct CommandCost {
    /// Runs that reached `CMD_DONE`.
    pub runs: u64,
    /// Runs that never did (`/1R`, or cut off by the end).
    pub unfinished: u64,
    /// Their cycles, summed.
    pub total: u64,
    /// The dearest run's cycles.
    pub worst: u64,
    /// The dearest run (an index into [`Profile::commands`]).
    pub worst_run: usize,
}

/// The commands seen, by count and letter.
#[must_use]
pub fn commands(profile: &Profile) -> BTreeMap<String, CommandCost> {
    let mut table: BTreeMap<String, CommandCost> = BTreeMap::new();
    for (index, run) in profile.commands.iter().enumerate() {
        let key: String = run.text.chars().take(3).collect();
        let cost = table.entry(key).or_default();
        match run.cycles {
            Some(cycles) => {
                if cost.runs == 0 || cycles > cost.worst {
                    cost.worst = cycles;
                    cost.worst_run = index;
                }
                cost.runs += 1;
                cost.total += cycles;
            }
            None => cost.unfinished += 1,
        }
    }
    table
}

/// The routines, dearest (inclusive) first, at most `limit`.
#[must_use]
pub fn routines_table(profile: &Profile, limit: usize) -> String {
    let mut rows: Vec<_> = profile
        .routines
        .iter()
        .filter(|(name, _)| !name.starts_with('/'))
        .collect();
    rows.sort_by(|a, b| {
        b.1.inclusive
            .max(b.1.exclusive)
            .cmp(&a.1.inclusive.max(a.1.exclusive))
            .then(a.0.cmp(b.0))
    });
    let mut text = format!(
        "{:<24} {:>8} {:>12} {:>12} {:>8} {:>8}\n",
        "routine", "calls", "inclusive", "exclusive", "min", "max"
    );
    for (name, cost) in rows.into_iter().take(limit) {
        let _ = writeln!(
            text,
            "{:<24} {:>8} {:>12} {:>12} {:>8} {:>8}",
            name, cost.calls, cost.inclusive, cost.exclusive, cost.min, cost.max
        );
    }
    text
}

/// The commands, dearest worst case first, beside a character's time on
/// the line at `baud`.
#[must_use]
pub fn commands_table(profile: &Profile, baud: u32) -> String {
    let character = character_cycles(baud);
    let mut rows: Vec<_> = commands(profile).into_iter().collect();
    rows.sort_by(|a, b| b.1.worst.cmp(&a.1.worst).then(a.0.cmp(&b.0)));
    let mut text = format!(
        "{:<8} {:>6} {:>10} {:>10} {:>14}  worst case\n",
        "command", "runs", "mean", "worst", "per character"
    );
    for (key, cost) in rows {
        let mean = cost.total.checked_div(cost.runs).unwrap_or(0);
        let ratio = format!("{:.2}", cost.worst as f64 / character as f64);
        let worst = profile.commands.get(cost.worst_run);
        let origin = worst
            .map(|run| match &run.origin {
                Some(origin) => format!("{} ({origin})", run.text),
                None => run.text.clone(),
            })
            .unwrap_or_default();
        let unfinished = if cost.unfinished > 0 {
            format!(", {} never reached CMD_DONE", cost.unfinished)
        } else {
            String::new()
        };
        let _ = writeln!(
            text,
            "{:<8} {:>6} {:>10} {:>10} {:>14}  {origin}{unfinished}",
            key, cost.runs, mean, cost.worst, ratio
        );
    }
    let _ = writeln!(
        text,
        "(one character at {baud} baud: {character} cycles; per character > 1.00 falls behind a host sending back to back)"
    );
    text
}

/// A source line's (or, without one, a label's) cost.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HotLine {
    /// `file:line`, or a label for code without a line table (the ROM).
    pub place: String,
    /// Instructions run there.
    pub count: u64,
    /// Cycles spent there.
    pub cycles: u64,
}

/// Every line (or label) that ran, dearest first: each at the line a
/// user is shown for it ([`LineTable::user_place_of`]: a built-in macro's
/// code at the user's line that called it, as the coverage counts it);
/// `is_users` says whether a file is one the user can open.
#[must_use]
pub fn hot_lines(
    profile: &Profile,
    lines: &LineTable,
    is_users: &dyn Fn(&str) -> bool,
) -> Vec<HotLine> {
    let mut by_place: BTreeMap<String, (u64, u64)> = BTreeMap::new();
    for (address, (&count, &cycles)) in profile.counts.iter().zip(&profile.cycles).enumerate() {
        // An interrupt's entry counted at a handler the run ended before
        // has cycles and no run.
        if count == 0 && cycles == 0 {
            continue;
        }
        let Ok(address) = u16::try_from(address) else {
            continue;
        };
        let place = match lines.user_place_of(address, is_users) {
            Some((file, line)) => format!("{file}:{line}"),
            None => {
                let name = profile.name_of(address);
                let base = name.split('+').next().unwrap_or(&name).to_owned();
                format!("{base} (no source)")
            }
        };
        let entry = by_place.entry(place).or_default();
        entry.0 += count;
        entry.1 += cycles;
    }
    let mut hot: Vec<HotLine> = by_place
        .into_iter()
        .map(|(place, (count, cycles))| HotLine {
            place,
            count,
            cycles,
        })
        .collect();
    hot.sort_by(|a, b| b.cycles.cmp(&a.cycles).then(a.place.cmp(&b.place)));
    hot
}

/// The hot source lines as a table, at most `limit` (code without a line
/// table, the ROM's, is summed on a line of its own: the routines and
/// the flame graph name it); lines as [`hot_lines`] places them.
#[must_use]
pub fn hot_lines_table(
    profile: &Profile,
    lines: &LineTable,
    is_users: &dyn Fn(&str) -> bool,
    limit: usize,
) -> String {
    let mut text = format!(
        "{:<40} {:>10} {:>12} {:>7}\n",
        "line", "runs", "cycles", "share"
    );
    let (sourced, unsourced): (Vec<HotLine>, Vec<HotLine>) = hot_lines(profile, lines, is_users)
        .into_iter()
        .partition(|line| !line.place.ends_with("(no source)"));
    let elsewhere: u64 = unsourced.iter().map(|line| line.cycles).sum();
    let _ = writeln!(
        text,
        "{:<40} {:>10} {:>12} {:>6.2}%",
        "(the ROM and code without source)",
        "",
        elsewhere,
        100.0 * elsewhere as f64 / profile.total.max(1) as f64
    );
    for line in sourced.into_iter().take(limit) {
        let share = 100.0 * line.cycles as f64 / profile.total.max(1) as f64;
        let _ = writeln!(
            text,
            "{:<40} {:>10} {:>12} {:>6.2}%",
            line.place, line.count, line.cycles, share
        );
    }
    text
}
