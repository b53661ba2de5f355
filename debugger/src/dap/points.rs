//! The DAP session's breakpoints of every kind, by the numbers the client
//! sees: source lines (`setBreakpoints`, a set per source), labels
//! (`setFunctionBreakpoints`), addresses (`setInstructionBreakpoints`),
//! watchpoints (`setDataBreakpoints`) and the exception filters'
//! breakpoints. Each request replaces its kind's set; each point is the
//! debugger's own breakpoint or watchpoint (with the monitor's conditions,
//! hit counts and log messages), and is kept here as it was asked for, so
//! that `restart` sets them all again on a new robot.

use std::collections::BTreeMap;

use crate::{Breakpoint, Debugger, PointOptions, Watch};

/// Which request set a point, and so which request replaces it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Kind {
    /// `setBreakpoints` for this source path.
    Source(String),
    /// `setFunctionBreakpoints`.
    Function,
    /// `setInstructionBreakpoints`.
    Instruction,
    /// `setDataBreakpoints`.
    Data,
    /// `setExceptionBreakpoints`' filter (`brk`: the others need no
    /// point, the robot's run ends at them).
    Exception(&'static str),
}

impl Kind {
    /// The `stopped` event's reason for a stop at a point of this kind.
    pub(crate) fn reason(&self) -> &'static str {
        match self {
            Kind::Source(_) => "breakpoint",
            Kind::Function => "function breakpoint",
            Kind::Instruction => "instruction breakpoint",
            Kind::Data => "data breakpoint",
            Kind::Exception(_) => "exception",
        }
    }
}

/// Where a point stops.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum What {
    /// Before an instruction (or a command arriving): a breakpoint.
    Break(Breakpoint, PointOptions),
    /// After an access: a watchpoint.
    Watch(Watch),
}

#[derive(Debug, Clone)]
struct Entry {
    kind: Kind,
    what: What,
    /// The debugger's number for it (a breakpoint's or a watchpoint's).
    number: usize,
}

/// The points set, by the client's numbers (from 1, never reused).
#[derive(Debug, Default)]
pub(crate) struct Points {
    last: i64,
    entries: BTreeMap<i64, Entry>,
}

impl Points {
    /// Removes every point of `kind` from the session and from `d`.
    pub(crate) fn clear(&mut self, d: &mut Debugger, kind: &Kind) {
        self.entries.retain(|_, entry| {
            if &entry.kind != kind {
                return true;
            }
            match entry.what {
                What::Break(..) => d.delete_breakpoint(entry.number),
                What::Watch(_) => d.delete_watch(entry.number),
            };
            false
        });
    }

    /// Sets `what` on `d` as a point of `kind`; the client's number for it.
    pub(crate) fn add(&mut self, d: &mut Debugger, kind: Kind, what: What) -> i64 {
        let number = install(d, &what);
        self.last += 1;
        self.entries.insert(self.last, Entry { kind, what, number });
        self.last
    }

    /// The client's number and the kind of the debugger's breakpoint
    /// `number`.
    pub(crate) fn breakpoint(&self, number: usize) -> Option<(i64, &Kind)> {
        self.entries.iter().find_map(|(id, entry)| {
            (matches!(entry.what, What::Break(..)) && entry.number == number)
                .then_some((*id, &entry.kind))
        })
    }

    /// The client's number of the debugger's watchpoint `number`.
    pub(crate) fn watch(&self, number: usize) -> Option<i64> {
        self.entries.iter().find_map(|(id, entry)| {
            (matches!(entry.what, What::Watch(_)) && entry.number == number).then_some(*id)
        })
    }

    /// Whether a point of `kind` is set.
    pub(crate) fn has(&self, kind: &Kind) -> bool {
        self.entries.values().any(|entry| &entry.kind == kind)
    }

    /// Sets every point again on `d`, a new robot's debugger (`restart`):
    /// the client's numbers stay.
    pub(crate) fn install_all(&mut self, d: &mut Debugger) {
        for entry in self.entries.values_mut() {
            entry.number = install(d, &entry.what);
        }
    }

    /// Forgets every point (a new `launch`).
    pub(crate) fn forget(&mut self) {
        self.entries.clear();
    }
}

fn install(d: &mut Debugger, what: &What) -> usize {
    match what {
        What::Break(point, options) => d.add_breakpoint_with(point.clone(), options.clone()),
        What::Watch(watch) => d.add_watch(*watch),
    }
}
