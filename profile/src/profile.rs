//! A finished profile: what the profiler counted, with routines and
//! stacks named, ready to be merged with others (every test's robot is a
//! fresh one) and reported.

use std::collections::BTreeMap;

use crate::engine::{CommandRun, Profiler};
use crate::stack::Routine;

/// What one routine's calls cost, in cycles.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RoutineCost {
    /// Times entered.
    pub calls: u64,
    /// Calls that ended before the run did.
    pub ended: u64,
    /// From entry to exit, summed over the calls that ended (a call's
    /// `RTS` is its own, the `JSR` its caller's); a recursive routine's
    /// outermost calls only, since the inner ones are inside them.
    pub inclusive: u64,
    /// Spent in its own instructions (not in routines it called, nor in
    /// interrupts, which are roots of their own).
    pub exclusive: u64,
    /// The cheapest call.
    pub min: u64,
    /// The dearest call.
    pub max: u64,
    /// The routines on the stack at the dearest call, outermost first,
    /// `;`-separated (`main;/2A1;read_channel`).
    pub worst_path: String,
    /// The command the dearest call ran in (an index into
    /// [`Profile::commands`]).
    pub worst_command: Option<usize>,
}

/// Everything counted on one or more robots.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Profile {
    /// Executions by address (65536 entries).
    pub counts: Vec<u64>,
    /// Cycles by address (none counted for coverage alone,
    /// [`crate::Profiler::coverage_only`]).
    pub cycles: Vec<u64>,
    /// Conditional branches taken, by address.
    pub taken: Vec<u64>,
    /// Conditional branches not taken, by address.
    pub not_taken: Vec<u64>,
    /// Routines by name (`main`, `IRQ`, `NMI`, a `JSR` target's label,
    /// a command's text `/2A1`).
    pub routines: BTreeMap<String, RoutineCost>,
    /// The folded stacks: `main;/2A1;read_channel` and the cycles spent
    /// with exactly that stack.
    pub stacks: BTreeMap<String, u64>,
    /// Every command seen, in order.
    pub commands: Vec<CommandRun>,
    /// Every cycle counted (0 for coverage alone).
    pub total: u64,
    /// Laps of idle loops counted without being run.
    pub skipped_laps: u64,
    /// The labels of the robots profiled (ROM and images), to name
    /// addresses no source line covers.
    pub labels: Vec<(u16, String)>,
    /// A routine's other labels (the same address under two names:
    /// `cmd_q:` then `rec:`), each to the name [`Profile::routines`]
    /// keeps it under.
    pub aliases: BTreeMap<String, String>,
}

impl Default for Profile {
    fn default() -> Profile {
        Profile {
            counts: vec![0; 0x1_0000],
            cycles: vec![0; 0x1_0000],
            taken: vec![0; 0x1_0000],
            not_taken: vec![0; 0x1_0000],
            routines: BTreeMap::new(),
            stacks: BTreeMap::new(),
            commands: Vec::new(),
            total: 0,
            skipped_laps: 0,
            labels: Vec::new(),
            aliases: BTreeMap::new(),
        }
    }
}

impl Profile {
    pub(crate) fn from_profiler(profiler: &Profiler) -> Profile {
        let stack = &profiler.stack;
        let labels = &profiler.labels;
        let routine_name = |routine: &Routine| match routine {
            Routine::Main => "main".to_owned(),
            Routine::Irq => "IRQ".to_owned(),
            Routine::Nmi => "NMI".to_owned(),
            Routine::Brk => "BRK".to_owned(),
            Routine::Sub(address) => labels.name(*address),
            Routine::Command(text) => text.clone(),
        };
        let names: Vec<String> = stack.routines.iter().map(routine_name).collect();
        let frame_names: Vec<String> = names.iter().map(|name| frame_name(name)).collect();
        let path_of = |node: u32| -> String {
            stack
                .path(node)
                .iter()
                .map(|&routine| frame_names[routine as usize].as_str())
                .collect::<Vec<_>>()
                .join(";")
        };
        let mut routines: BTreeMap<String, RoutineCost> = BTreeMap::new();
        let mut stacks: BTreeMap<String, u64> = BTreeMap::new();
        let mut exclusive = vec![0u64; names.len()];
        // Inclusive cycles of the roots that are no frame (`main`): every
        // cell under them.
        let mut under_main = 0u64;
        for (&(node, label), &cycles) in stack.cell_keys.iter().zip(&stack.cells) {
            if cycles == 0 {
                continue;
            }
            let routine = stack.nodes[node as usize].routine;
            exclusive[routine as usize] += cycles;
            let path = stack.path(node);
            if path
                .first()
                .is_some_and(|&root| names[root as usize] == "main")
            {
                under_main += cycles;
            }
            let mut folded = path_of(node);
            if let Some(name) = labels.label(label) {
                if name != names[routine as usize] {
                    folded.push(';');
                    folded.push_str(&frame_name(name));
                }
            }
            *stacks.entry(folded).or_default() += cycles;
        }
        for (id, name) in names.iter().enumerate() {
            let calls = &stack.calls[id];
            let mut cost = RoutineCost {
                calls: calls.calls,
                ended: calls.ended,
                inclusive: calls.inclusive,
                exclusive: exclusive[id],
                min: calls.min,
                max: calls.max,
                worst_path: if calls.ended > 0 {
                    path_of(calls.worst_node)
                } else {
                    String::new()
                },
                worst_command: calls.worst_command.map(|c| c as usize),
            };
            if stack.routines[id] == Routine::Main {
                cost = RoutineCost {
                    calls: 1,
                    ended: 1,
                    inclusive: under_main,
                    exclusive: exclusive[id],
                    min: under_main,
                    max: under_main,
                    worst_path: "main".to_owned(),
                    worst_command: None,
                };
            }
            merge_cost(routines.entry(name.clone()).or_default(), &cost, 0);
        }
        let mut aliases = BTreeMap::new();
        for routine in &stack.routines {
            if let Routine::Sub(address) = routine {
                for (_, alias) in labels.aliases.iter().filter(|(at, _)| at == address) {
                    aliases.insert(alias.clone(), labels.name(*address));
                }
            }
        }
        Profile {
            aliases,
            counts: profiler.counts(),
            cycles: profiler.cycles(),
            taken: profiler.taken.clone(),
            not_taken: profiler.not_taken.clone(),
            routines,
            stacks,
            commands: profiler.commands.clone(),
            total: profiler.total_cycles(),
            skipped_laps: profiler.skipped_laps,
            labels: labels.names.clone(),
        }
    }

    /// Adds `other`'s counts to these (another test's robot).
    pub fn merge(&mut self, other: &Profile) {
        for (mine, theirs) in [
            (&mut self.counts, &other.counts),
            (&mut self.cycles, &other.cycles),
            (&mut self.taken, &other.taken),
            (&mut self.not_taken, &other.not_taken),
        ] {
            for (a, b) in mine.iter_mut().zip(theirs) {
                *a += b;
            }
        }
        let offset = self.commands.len();
        for (name, cost) in &other.routines {
            merge_cost(self.routines.entry(name.clone()).or_default(), cost, offset);
        }
        for (stack, cycles) in &other.stacks {
            *self.stacks.entry(stack.clone()).or_default() += cycles;
        }
        self.commands.extend(other.commands.iter().cloned());
        for (alias, name) in &other.aliases {
            self.aliases
                .entry(alias.clone())
                .or_insert_with(|| name.clone());
        }
        self.total += other.total;
        self.skipped_laps += other.skipped_laps;
        if self.labels.is_empty() {
            self.labels.clone_from(&other.labels);
        } else {
            let mut labels = std::mem::take(&mut self.labels);
            labels.extend(other.labels.iter().cloned());
            labels.sort();
            labels.dedup();
            self.labels = labels;
        }
    }

    /// The routine named `name`, by its shown name or another label of
    /// its address.
    #[must_use]
    pub fn routine(&self, name: &str) -> Option<&RoutineCost> {
        self.routines.get(name).or_else(|| {
            self.aliases
                .get(name)
                .and_then(|shown| self.routines.get(shown))
        })
    }

    /// `address` as `label` or `label+$offset`, or `$ADDR`.
    #[must_use]
    pub fn name_of(&self, address: u16) -> String {
        let index = self.labels.partition_point(|(at, _)| *at <= address);
        match index.checked_sub(1).and_then(|i| self.labels.get(i)) {
            Some((at, name)) if *at == address => name.clone(),
            Some((at, name)) => format!("{name}+${:X}", address - at),
            None => format!("${address:04X}"),
        }
    }

    /// The folded-stack text (`main;/2A1;read_channel 123`, a line per
    /// stack), as flame graph tools read it.
    #[must_use]
    pub fn folded(&self) -> String {
        let mut text = String::new();
        for (stack, cycles) in &self.stacks {
            if *cycles > 0 {
                text.push_str(stack);
                text.push(' ');
                text.push_str(&cycles.to_string());
                text.push('\n');
            }
        }
        text
    }
}

/// `name` as a frame of a folded stack, where `;` parts frames: a `;` in
/// it (a command letter, `/1;`) becomes the fullwidth semicolon U+FF1B.
fn frame_name(name: &str) -> String {
    name.replace(';', "\u{FF1B}")
}

/// Adds `theirs` into `mine`; `offset` shifts the command index.
fn merge_cost(mine: &mut RoutineCost, theirs: &RoutineCost, offset: usize) {
    if theirs.ended > 0 {
        if mine.ended == 0 || theirs.min < mine.min {
            mine.min = theirs.min;
        }
        if mine.ended == 0 || theirs.max > mine.max {
            mine.max = theirs.max;
            mine.worst_path.clone_from(&theirs.worst_path);
            mine.worst_command = theirs.worst_command.map(|c| c + offset);
        }
    }
    mine.calls += theirs.calls;
    mine.ended += theirs.ended;
    mine.inclusive += theirs.inclusive;
    mine.exclusive += theirs.exclusive;
}
