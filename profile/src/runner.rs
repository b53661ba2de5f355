//! The profiler on a virtual robot: every run the robot makes for its host
//! (exchanges, settling, waiting for an answer) goes through the
//! profiler's hooks.

use std::sync::{Arc, Mutex, PoisonError};

use emulator::board::Scorpion;
use emulator::{Breakpoints, Stop};

use crate::engine::Profiler;

/// A profiler shared between the robot that runs under it and the host
/// that reads it.
#[derive(Debug, Clone)]
pub struct Recorder {
    profiler: Arc<Mutex<Profiler>>,
}

impl Recorder {
    /// Sets a fresh profiler on `robot` (its ROM and the images loaded
    /// so far named) and returns the host's handle to it.
    pub fn attach(robot: &mut romlib::VirtualScorpion) -> Recorder {
        let profiler = Profiler::for_robot(robot);
        Recorder::attach_profiler(robot, profiler)
    }

    /// Sets `profiler` on `robot` (a [`Profiler::coverage_only`] one).
    pub fn attach_profiler(robot: &mut romlib::VirtualScorpion, profiler: Profiler) -> Recorder {
        let recorder = Recorder {
            profiler: Arc::new(Mutex::new(profiler)),
        };
        robot.set_runner(Some(Box::new(recorder.clone())));
        recorder
    }

    /// Runs `f` on the profiler.
    pub fn with<T>(&self, f: impl FnOnce(&mut Profiler) -> T) -> T {
        let mut profiler = self.profiler.lock().unwrap_or_else(PoisonError::into_inner);
        f(&mut profiler)
    }

    /// Takes the profiler off `robot` and turns what it counted into a
    /// profile (at the robot's time now).
    #[must_use]
    pub fn finish(self, robot: &mut romlib::VirtualScorpion) -> crate::Profile {
        robot.set_runner(None);
        let now = robot.cycles();
        let profiler = match Arc::try_unwrap(self.profiler) {
            Ok(mutex) => mutex.into_inner().unwrap_or_else(PoisonError::into_inner),
            Err(shared) => shared
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .clone(),
        };
        profiler.finish(now)
    }
}

impl romlib::Runner for Recorder {
    fn run(&mut self, robot: &mut Scorpion, until: u64) -> Stop {
        let mut profiler = self.profiler.lock().unwrap_or_else(PoisonError::into_inner);
        let stop = robot.run_with(until, &mut *profiler);
        profiler.end_run(&robot.cpu);
        stop
    }

    fn run_to(&mut self, robot: &mut Scorpion, until: u64, stops: &mut Breakpoints) -> Stop {
        let mut profiler = self.profiler.lock().unwrap_or_else(PoisonError::into_inner);
        let stop = robot.run_with(until, &mut (&mut *profiler, stops));
        profiler.end_run(&robot.cpu);
        stop
    }

    fn entered(&mut self, robot: &Scorpion, target: u16, s_before: u8) {
        let mut profiler = self.profiler.lock().unwrap_or_else(PoisonError::into_inner);
        profiler.entered(target, s_before, robot.cpu.cycles());
    }
}
