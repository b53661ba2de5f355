//! The robot's surroundings as a script: what closes its bumpers, lights
//! its ground-tracker phototransistors and fills the scanner's scene, over
//! robot time and in answer to its motion.
//!
//! The script asks to be woken with `wake_at(cycle)` (from `init()` or a
//! previous `wake`), and `wake(now)` then sets the inputs: `bumpers(mask)`
//! (a bit per microswitch, 1 = closed), `tracker(left_lit, right_lit)`,
//! `scene(value)` (every scanner position reads `value`) and `scene_at(h, v,
//! value)`; a mask or reading past a byte, or a position past the scene's
//! edge, is an error at the call (the script's mistake, not eight bits of
//! it or the nearest edge). It reads the drive motors' positions in steps with
//! `left_position()` and `right_position()` (forward counts up).

use std::sync::{Arc, Mutex};

use emulator::board::{Motor, Scorpion};
use romlib::Surroundings;

use crate::error::ScriptError;
use crate::sandbox::{Host, HostError, engine};
use crate::script::Script;

/// One change to the robot's inputs a script asked for.
#[derive(Debug, Clone, Copy)]
enum Change {
    Bumpers(u8),
    Tracker { left: bool, right: bool },
    Scene(u8),
    SceneAt(i64, i64, u8),
}

#[derive(Debug, Default, Clone)]
struct Shared {
    changes: Vec<Change>,
    positions: (i64, i64),
}

/// Surroundings run by a script.
#[derive(Debug)]
pub struct ScriptWorld {
    script: Script,
    shared: Arc<Mutex<Shared>>,
    has_wake: bool,
    /// Changes `init` asked for, applied at the first wake-up.
    pending: bool,
}

impl ScriptWorld {
    /// Loads the surroundings script `text` (named `name` in errors) and
    /// runs its `init()`.
    ///
    /// # Errors
    /// [`ScriptError::Script`] for a syntax error or a failing top level or
    /// `init`.
    pub fn load(name: &str, text: &str) -> Result<ScriptWorld, ScriptError> {
        let host = Arc::new(Host::default());
        let shared = Arc::new(Mutex::new(Shared::default()));
        let mut engine = engine(&host);
        register(&mut engine, &shared);
        let mut script = Script::load(engine, host, name, text)?;
        if script.has_fn("init", 0) {
            let _ = script.call("init", None, ())?;
        }
        // What `init` set applies at once, at the first wake-up.
        let pending = shared.lock().is_ok_and(|s| !s.changes.is_empty());
        Ok(ScriptWorld {
            has_wake: script.has_fn("wake", 1),
            script,
            shared,
            pending,
        })
    }

    /// What the script prints, to show as the robot runs.
    #[must_use]
    pub fn printed(&self) -> crate::Printed {
        self.script.printed()
    }
}

/// The scanner's positions each way: a scene is 256 by 256 readings,
/// centre at (0, 0).
const SCENE_STEPS: std::ops::RangeInclusive<i64> = -128..=127;

/// `value` as a byte, or the error `call` (`bumpers(...)`, written as the
/// script wrote it) throws at the call: a value past a byte is a mistake,
/// not eight bits of it.
fn checked_byte(value: i64, call: &str, what: &str) -> Result<u8, Box<rhai::EvalAltResult>> {
    u8::try_from(value).map_err(|_| {
        HostError {
            message: format!("`{call}`: {what} is 0 to 255, not {value}"),
            help: "give a byte: `value & 0xFF` keeps the low eight bits".into(),
        }
        .thrown()
    })
}

/// A scanner position, or the error `call` throws: the scene has no
/// readings past its edge, so a position there is a mistake.
fn checked_step(step: i64, call: &str, axis: &str) -> Result<i64, Box<rhai::EvalAltResult>> {
    if SCENE_STEPS.contains(&step) {
        return Ok(step);
    }
    Err(HostError {
        message: format!(
            "`{call}`: {axis} is {step}, outside the scene ({} to {})",
            SCENE_STEPS.start(),
            SCENE_STEPS.end()
        ),
        help: "positions count scanner steps from the centre, (0, 0); a scan reaches 99 each side"
            .into(),
    }
    .thrown())
}

fn register(engine: &mut rhai::Engine, shared: &Arc<Mutex<Shared>>) {
    let push = |shared: &Arc<Mutex<Shared>>, change: Change| {
        if let Ok(mut s) = shared.lock() {
            s.changes.push(change);
        }
    };
    let state = Arc::clone(shared);
    engine.register_fn(
        "bumpers",
        move |mask: i64| -> Result<(), Box<rhai::EvalAltResult>> {
            let mask = checked_byte(mask, &format!("bumpers({mask})"), "the mask")?;
            push(&state, Change::Bumpers(mask));
            Ok(())
        },
    );
    let state = Arc::clone(shared);
    engine.register_fn("tracker", move |left: bool, right: bool| {
        push(&state, Change::Tracker { left, right });
    });
    let state = Arc::clone(shared);
    engine.register_fn(
        "scene",
        move |value: i64| -> Result<(), Box<rhai::EvalAltResult>> {
            let value = checked_byte(value, &format!("scene({value})"), "a reading")?;
            push(&state, Change::Scene(value));
            Ok(())
        },
    );
    let state = Arc::clone(shared);
    engine.register_fn(
        "scene_at",
        move |h: i64, v: i64, value: i64| -> Result<(), Box<rhai::EvalAltResult>> {
            let call = format!("scene_at({h}, {v}, {value})");
            let h = checked_step(h, &call, "h")?;
            let v = checked_step(v, &call, "v")?;
            let value = checked_byte(value, &call, "a reading")?;
            push(&state, Change::SceneAt(h, v, value));
            Ok(())
        },
    );
    let state = Arc::clone(shared);
    engine.register_fn("left_position", move || -> i64 {
        state.lock().map_or(0, |s| s.positions.0)
    });
    let state = Arc::clone(shared);
    engine.register_fn("right_position", move || -> i64 {
        state.lock().map_or(0, |s| s.positions.1)
    });
}

impl Surroundings for ScriptWorld {
    /// The surroundings with their script's state (`this`) and wake-up
    /// copied; what the copy prints goes to its own
    /// [`ScriptWorld::printed`]. `None` if the script's state shares a
    /// closure's variable.
    fn snapshot(&self) -> Option<Box<dyn Surroundings>> {
        let host = Arc::new(self.script.host().fork()?);
        let shared = Arc::new(Mutex::new(self.shared.lock().ok()?.clone()));
        let mut engine = engine(&host);
        register(&mut engine, &shared);
        Some(Box::new(ScriptWorld {
            script: self.script.fork(engine, host)?,
            shared,
            has_wake: self.has_wake,
            pending: self.pending,
        }))
    }

    fn next_wake(&self) -> Option<u64> {
        if self.pending {
            return Some(0);
        }
        self.script.wake()
    }

    fn wake(
        &mut self,
        now: u64,
        robot: &mut Scorpion,
    ) -> Result<(), Box<dyn miette::Diagnostic + Send + Sync>> {
        if !self.pending {
            self.script.clear_wake();
        }
        if let Ok(mut s) = self.shared.lock() {
            s.positions = (
                robot.board().motor(Motor::Left).position(),
                robot.board().motor(Motor::Right).position(),
            );
        }
        if self.pending {
            self.pending = false;
        } else if self.has_wake {
            let at = i64::try_from(now).unwrap_or(i64::MAX);
            let _ = self
                .script
                .call("wake", Some(now), (at,))
                .map_err(|error| Box::new(error) as Box<dyn miette::Diagnostic + Send + Sync>)?;
        }
        let changes = self
            .shared
            .lock()
            .map(|mut s| std::mem::take(&mut s.changes))
            .unwrap_or_default();
        for change in changes {
            match change {
                Change::Bumpers(mask) => robot.set_bumpers(mask),
                Change::Tracker { left, right } => robot
                    .board_mut()
                    .set_phototransistors(u8::from(right) | (u8::from(left) << 1)),
                Change::Scene(value) => robot
                    .board_mut()
                    .set_scene(emulator::board::Scene::uniform(value)),
                Change::SceneAt(h, v, value) => robot.board_mut().scene_mut().set(h, v, value),
            }
        }
        Ok(())
    }
}
