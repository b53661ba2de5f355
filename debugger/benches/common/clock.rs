//! The benchmarks' clock (the debugger's and the profiler's): this
//! thread's time on a CPU, so that other work on a shared machine does not
//! count against a run.

use std::time::{Duration, Instant};

/// A clock of this thread's time on a CPU: the machine is shared with
/// other work, whose turns a wall clock would count. The scheduler's own
/// account (`/proc/thread-self/schedstat`, nanoseconds), or the wall clock
/// where there is none.
#[derive(Clone, Copy)]
pub(crate) enum Clock {
    Cpu(u64),
    Wall(Instant),
}

impl Clock {
    pub(crate) fn start() -> Clock {
        let on_cpu = std::fs::read_to_string("/proc/thread-self/schedstat")
            .ok()
            .and_then(|text| text.split_whitespace().next()?.parse().ok());
        match on_cpu {
            Some(ns) => Clock::Cpu(ns),
            None => Clock::Wall(Instant::now()),
        }
    }

    pub(crate) fn elapsed(self) -> Duration {
        match (self, Clock::start()) {
            (Clock::Cpu(then), Clock::Cpu(now)) => Duration::from_nanos(now - then),
            (Clock::Wall(then), _) | (_, Clock::Wall(then)) => then.elapsed(),
        }
    }
}
