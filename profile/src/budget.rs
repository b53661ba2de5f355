//! Cycle budgets: the most a robot command (from its arrival to
//! `CMD_DONE`) or a routine (from its entry to its `RTS`) may cost,
//! checked against a profile of every test.

use crate::profile::Profile;
use crate::report;

/// What a budget limits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Subject {
    /// A robot command by count and letter: `/2A`.
    Command(String),
    /// A routine by its label.
    Routine(String),
}

/// A budget: at most `cycles` for `subject`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Budget {
    /// What it limits.
    pub subject: Subject,
    /// The most one run or call may cost.
    pub cycles: u64,
}

impl Budget {
    /// A budget from a project file's key: `/2A` is a command, anything
    /// else a routine's label.
    #[must_use]
    pub fn new(key: &str, cycles: u64) -> Budget {
        let subject = if key.starts_with('/') {
            Subject::Command(key.to_owned())
        } else {
            Subject::Routine(key.to_owned())
        };
        Budget { subject, cycles }
    }
}

/// A budget the tests exceeded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Overrun {
    /// The budget.
    pub budget: Budget,
    /// The worst case's cycles (of the runs that finished).
    pub worst: u64,
    /// Runs of a command that never reached `CMD_DONE`: over any budget,
    /// since they never finished within it.
    pub unfinished: u64,
    /// Where the worst case came from (a transcript's `file:line`, the
    /// command's text), if known.
    pub origin: Option<String>,
    /// The routines on the stack at the worst case, outermost first
    /// (`main;/2A1;read_channel`).
    pub path: String,
}

impl std::fmt::Display for Overrun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match &self.budget.subject {
            Subject::Command(command) => format!("command {command}"),
            Subject::Routine(routine) => format!("routine {routine}"),
        };
        if self.unfinished > 0 {
            write!(
                f,
                "{what} never finished ({} run(s) never reached CMD_DONE), over its budget of {}",
                self.unfinished, self.budget.cycles
            )?;
        } else {
            write!(
                f,
                "{what} took {} cycles, over its budget of {}",
                self.worst, self.budget.cycles
            )?;
        }
        if let Some(origin) = &self.origin {
            write!(f, " at {origin}")?;
        }
        write!(f, " (stack: {})", self.path)
    }
}

/// A budget with no command or routine of that name in the profile.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unused {
    /// The budget.
    pub budget: Budget,
}

/// Checks `budgets` against `profile`: the overruns, and the budgets
/// that name nothing the tests ran.
#[must_use]
pub fn check(profile: &Profile, budgets: &[Budget]) -> (Vec<Overrun>, Vec<Unused>) {
    let commands = report::commands(profile);
    let mut overruns = Vec::new();
    let mut unused = Vec::new();
    for budget in budgets {
        match &budget.subject {
            Subject::Command(key) => {
                let Some(cost) = commands.get(key.as_str()) else {
                    unused.push(Unused {
                        budget: budget.clone(),
                    });
                    continue;
                };
                let unfinished = cost.unfinished;
                if unfinished > 0 || (cost.runs > 0 && cost.worst > budget.cycles) {
                    // The run to point at: the first that never finished,
                    // else the dearest.
                    let index = if unfinished > 0 {
                        profile.commands.iter().position(|run| {
                            run.cycles.is_none()
                                && run.text.chars().take(3).collect::<String>() == *key
                        })
                    } else {
                        Some(cost.worst_run)
                    };
                    let run = index.and_then(|i| profile.commands.get(i));
                    overruns.push(Overrun {
                        budget: budget.clone(),
                        worst: cost.worst,
                        unfinished,
                        origin: run.map(origin_of),
                        path: run.map_or_else(String::new, |run| format!("main;{}", run.text)),
                    });
                }
            }
            Subject::Routine(name) => {
                let Some(cost) = profile.routine(name) else {
                    unused.push(Unused {
                        budget: budget.clone(),
                    });
                    continue;
                };
                if cost.ended > 0 && cost.max > budget.cycles {
                    let run = cost.worst_command.and_then(|i| profile.commands.get(i));
                    overruns.push(Overrun {
                        budget: budget.clone(),
                        worst: cost.max,
                        unfinished: 0,
                        origin: run.map(origin_of),
                        path: cost.worst_path.clone(),
                    });
                }
            }
        }
    }
    (overruns, unused)
}

fn origin_of(run: &crate::CommandRun) -> String {
    match &run.origin {
        Some(origin) => format!("{origin} ({})", run.text),
        None => run.text.clone(),
    }
}
