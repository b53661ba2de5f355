//! A KIM-bus card whose registers are a script's: the emulator's
//! [`Device`] over a [`Script`].
//!
//! The script declares its window with top-level constants (`SIZE`, the
//! number of registers; `BASE`, the default address) and its behaviour
//! with functions: `read(reg, now)` returns a register's value, `write(reg,
//! value, now)` takes one, `wake(now)` runs at the robot time it asked for
//! with `wake_at(cycle)`, `init()` once at power-up. State lives in `this`.
//! Registers listed in `PLAIN` (all of them when there is no `read`) are
//! read from the card's register table without calling the script; the
//! script fills the table with `set(reg, value)`, so a program that polls a
//! status bit costs a table look-up per read. Any other register's
//! answer from `read` is kept and served again without calling the script
//! until it can have changed: a write to the card, a wake-up, or a read of
//! a register listed in `VOLATILE` (reads with effects, such as a data
//! register that clears an interrupt, or answers that change with robot
//! time alone), whose every read calls `read`. `irq(true)` pulls the bus's
//! /IRQ line low until `irq(false)`.

use std::sync::{Arc, Mutex};

use emulator::board::Device;

use crate::error::ScriptError;
use crate::sandbox::{Host, HostError, engine};
use crate::script::Script;

/// What the script changes through the host's functions.
#[derive(Debug, Default, Clone)]
struct Shared {
    /// The register table (`set`, `get`; plain reads come from here).
    table: Vec<u8>,
    /// The card's /IRQ output.
    irq: bool,
}

/// A card run by a script.
#[derive(Debug)]
pub struct ScriptCard {
    script: Script,
    shared: Arc<Mutex<Shared>>,
    /// `shared` as the script last left it: only a script call changes
    /// it, and the board asks for the card's IRQ output and next event
    /// after every access, so those (and plain reads) need no lock.
    view: Shared,
    /// The wake-up the script last asked for.
    wake: Option<u64>,
    /// Registers read from the table without calling `read`.
    plain: Vec<bool>,
    /// Registers whose reads the script declares have effects (or whose
    /// answer changes with robot time alone): `read` is called for every
    /// one.
    volatile: Vec<bool>,
    /// `read`'s last answer for each register, while it still holds: no
    /// write, wake-up or read with effects since.
    answers: Vec<Option<u8>>,
    has_write: bool,
    has_wake: bool,
    base: u16,
    size: u16,
    /// The robot time the card caught up to.
    now: u64,
    /// The first failure, until the robot's host takes it.
    fault: Option<ScriptError>,
    /// Once failed, the card answers `$FF` and runs no more script.
    failed: bool,
}

impl ScriptCard {
    /// Loads the card script `text` (named `name` in errors), at `base`
    /// or the script's own `BASE`.
    ///
    /// # Errors
    /// [`ScriptError::Script`] for a syntax error, a failing top level or
    /// `init`, or a `SIZE` or `BASE` out of range (at its declaration);
    /// [`ScriptError::Window`] for a missing `SIZE` or `BASE`, or a window
    /// given with `base` outside the KIM bus.
    pub fn load(name: &str, text: &str, base: Option<u16>) -> Result<ScriptCard, ScriptError> {
        let host = Arc::new(Host::default());
        let shared = Arc::new(Mutex::new(Shared::default()));
        let mut engine = engine(&host);
        register(&mut engine, &shared);
        let script = Script::load(engine, host, name, text)?;
        let window = |message: String, help: &str| ScriptError::Window {
            file: name.to_owned(),
            message,
            help: Some(help.to_owned()),
        };
        let integer = |constant: &str| {
            script
                .constant(constant)
                .map(|value| value.as_int().map_err(|kind| (value, kind)))
        };
        let size = match integer("SIZE") {
            None => {
                return Err(window(
                    "the card declares no `SIZE`".into(),
                    "start the script with `const SIZE = 4;`: how many registers the card has",
                ));
            }
            Some(Ok(size)) if (1..=0x1000).contains(&size) => size,
            Some(Ok(size)) => {
                return Err(script.error_at_declaration(
                    "SIZE",
                    format!("SIZE = {size}: a card has 1 to 4096 registers"),
                    "SIZE is the number of registers (bytes) the card decodes".into(),
                ));
            }
            Some(Err((value, kind))) => {
                return Err(script.error_at_declaration(
                    "SIZE",
                    format!("SIZE = {value:?} is a {kind}, not a number of registers"),
                    "SIZE is the number of registers (bytes) the card decodes, 1 to 4096".into(),
                ));
            }
        };
        let (kim_start, kim_end) = (
            u32::from(platform::map::KIM_START),
            u32::from(platform::map::KIM_END),
        );
        let outside = |base: u32| {
            format!(
                "the window ${base:04X}-${:04X} is not inside the KIM bus (${kim_start:04X}-${kim_end:04X})",
                base + size as u32 - 1
            )
        };
        let inside = |base: u32| base >= kim_start && base + size as u32 - 1 <= kim_end;
        let base = match (base, integer("BASE")) {
            (Some(base), _) if inside(u32::from(base)) => base,
            (Some(base), _) => {
                return Err(window(
                    outside(u32::from(base)),
                    "cards sit on the KIM bus; move the card: `--card FILE@ADDR`, or `\"FILE@ADDR\"` in a project's [robot] cards",
                ));
            }
            (None, None) => {
                return Err(window(
                    "the card declares no `BASE` and none was given".into(),
                    "declare `const BASE = 0x9000;` or give the address: `--card card.rhai@9000`, or `\"card.rhai@9000\"` in a project's [robot] cards",
                ));
            }
            (None, Some(Ok(base))) => match u16::try_from(base) {
                Ok(base) if inside(u32::from(base)) => base,
                Ok(base) => {
                    return Err(script.error_at_declaration(
                        "BASE",
                        outside(u32::from(base)),
                        "cards sit on the KIM bus; move the card: `--card FILE@ADDR`, or `\"FILE@ADDR\"` in a project's [robot] cards".into(),
                    ));
                }
                Err(_) => {
                    return Err(script.error_at_declaration(
                        "BASE",
                        format!("BASE = {base} is not a 16-bit address"),
                        format!("the KIM bus lies at ${kim_start:04X}-${kim_end:04X}"),
                    ));
                }
            },
            (None, Some(Err((value, kind)))) => {
                return Err(script.error_at_declaration(
                    "BASE",
                    format!("BASE = {value:?} is a {kind}, not an address"),
                    "write `const BASE = 0x9000;`".into(),
                ));
            }
        };
        // In 1..=0x1000, as checked above.
        let size = u16::try_from(size).unwrap_or(1);
        let has_read = script.has_fn("read", 2);
        let mut plain = vec![!has_read; usize::from(size)];
        for index in registers(&script, name, "PLAIN", size)? {
            plain[index] = true;
        }
        let mut volatile = vec![false; usize::from(size)];
        for index in registers(&script, name, "VOLATILE", size)? {
            volatile[index] = true;
        }
        if let Ok(mut shared) = shared.lock() {
            shared.table = vec![0; usize::from(size)];
        }
        let mut card = ScriptCard {
            view: Shared::default(),
            wake: None,
            has_write: script.has_fn("write", 3),
            has_wake: script.has_fn("wake", 1),
            script,
            shared,
            plain,
            volatile,
            answers: vec![None; usize::from(size)],
            base,
            size,
            now: 0,
            fault: None,
            failed: false,
        };
        if card.script.has_fn("init", 0) {
            let _ = card.call("init", None, ())?;
        } else {
            card.look();
        }
        Ok(card)
    }

    /// The window: first and last address.
    #[must_use]
    pub fn window(&self) -> (u16, u16) {
        (self.base, self.base + (self.size - 1))
    }

    /// What the script prints, to show as the robot runs.
    #[must_use]
    pub fn printed(&self) -> crate::Printed {
        self.script.printed()
    }

    /// A register of the table (what a plain read returns).
    #[must_use]
    pub fn table(&self, register: u16) -> u8 {
        self.view
            .table
            .get(usize::from(register))
            .copied()
            .unwrap_or(0xFF)
    }

    /// Calls the script's `function` at robot time `now`, then looks at
    /// what it changed.
    fn call(
        &mut self,
        function: &str,
        now: Option<u64>,
        args: impl rhai::FuncArgs,
    ) -> Result<rhai::Dynamic, ScriptError> {
        let result = self.script.call(function, now, args);
        self.look();
        result
    }

    /// Forgets `read`'s answers: the script ran for something that can
    /// change them.
    fn forget(&mut self) {
        self.answers.fill(None);
    }

    /// Copies what the script left in `shared` into `view`.
    fn look(&mut self) {
        if let Ok(shared) = self.shared.lock() {
            self.view.clone_from(&shared);
        }
        self.wake = self.script.wake();
    }

    fn fail(&mut self, error: ScriptError) {
        if !self.failed {
            self.failed = true;
            self.fault = Some(error);
        }
        self.script.clear_wake();
        if let Ok(mut shared) = self.shared.lock() {
            shared.irq = false;
        }
        self.look();
    }

    /// Runs the wake-ups due by `cycle`. Each wake-up the script asks for
    /// lies after the one being served, so this ends.
    fn catch_up(&mut self, cycle: u64) {
        self.now = self.now.max(cycle);
        while !self.failed {
            let due = match self.wake {
                Some(at) if at <= cycle => at,
                _ => return,
            };
            self.wake = None;
            self.script.clear_wake();
            if !self.has_wake {
                continue;
            }
            self.forget();
            if let Err(error) = self.call("wake", Some(due), (as_int(due),)) {
                self.fail(error);
            }
        }
    }
}

/// The registers the script's constant `list` (`PLAIN`, `VOLATILE`)
/// names, each checked to be one of the card's `size`.
fn registers(
    script: &Script,
    name: &str,
    list: &str,
    size: u16,
) -> Result<Vec<usize>, ScriptError> {
    let window = |message: String, help: String| ScriptError::Window {
        file: name.to_owned(),
        message,
        help: Some(help),
    };
    let Some(value) = script.constant(list) else {
        return Ok(Vec::new());
    };
    let entries = value.into_array().map_err(|_| {
        window(
            format!("`{list}` is not a list of registers"),
            format!("write `const {list} = [1, 2];`: a list of register numbers"),
        )
    })?;
    entries
        .into_iter()
        .map(|register| {
            register
                .as_int()
                .ok()
                .and_then(|r| usize::try_from(r).ok())
                .filter(|&r| r < usize::from(size))
                .ok_or_else(|| {
                    window(
                        format!(
                            "`{list}` lists {register}, not a register of 0 to {}",
                            size - 1
                        ),
                        "registers are numbered from 0 to SIZE - 1".into(),
                    )
                })
        })
        .collect()
}

fn as_int(cycle: u64) -> i64 {
    i64::try_from(cycle).unwrap_or(i64::MAX)
}

/// The host's functions a card script calls.
/// `register` as an index of the card's table, or the error `function`
/// (`set`, `get`) throws at the call: a register the card does not have
/// is a mistake, not a write to nowhere or a read of `$FF`.
fn checked_register(
    shared: &Shared,
    function: &str,
    register: i64,
) -> Result<usize, Box<rhai::EvalAltResult>> {
    let size = shared.table.len();
    usize::try_from(register)
        .ok()
        .filter(|r| *r < size)
        .ok_or_else(|| {
            HostError {
                message: format!(
                    "`{function}({register}, ...)`: the card has registers 0 to {}",
                    size.saturating_sub(1)
                ),
                help: "a register is 0 to SIZE - 1, counted from the card's BASE".into(),
            }
            .thrown()
        })
}

fn register(engine: &mut rhai::Engine, shared: &Arc<Mutex<Shared>>) {
    let state = Arc::clone(shared);
    engine.register_fn(
        "set",
        move |register: i64, value: i64| -> Result<(), Box<rhai::EvalAltResult>> {
            let Ok(mut shared) = state.lock() else {
                return Ok(());
            };
            let slot = checked_register(&shared, "set", register)?;
            if !(0..=0xFF).contains(&value) {
                return Err(HostError {
                    message: format!("`set({register}, {value})`: a register holds 0 to 255"),
                    help: "give a byte: `value & 0xFF` keeps the low eight bits".into(),
                }
                .thrown());
            }
            shared.table[slot] = value as u8;
            Ok(())
        },
    );
    let state = Arc::clone(shared);
    engine.register_fn(
        "get",
        move |register: i64| -> Result<i64, Box<rhai::EvalAltResult>> {
            let Ok(shared) = state.lock() else {
                return Ok(0xFF);
            };
            let slot = checked_register(&shared, "get", register)?;
            Ok(i64::from(shared.table[slot]))
        },
    );
    let state = Arc::clone(shared);
    engine.register_fn("irq", move |on: bool| {
        if let Ok(mut shared) = state.lock() {
            shared.irq = on;
        }
    });
}

impl Device for ScriptCard {
    fn read(&mut self, offset: u16, cycle: u64) -> u8 {
        self.catch_up(cycle);
        if self.failed {
            return 0xFF;
        }
        let register = offset % self.size;
        let index = usize::from(register);
        if self.plain[index] {
            return self.table(register);
        }
        let volatile = self.volatile[index];
        if !volatile && let Some(answer) = self.answers[index] {
            return answer;
        }
        let value = self.call("read", Some(cycle), (i64::from(register), as_int(cycle)));
        if volatile {
            // Its effects may change any register's answer.
            self.forget();
        }
        match value.map(|v| v.as_int()) {
            Ok(Ok(value)) if (0..=0xFF).contains(&value) => {
                let answer = value as u8;
                if !volatile {
                    self.answers[index] = Some(answer);
                }
                answer
            }
            Ok(Ok(value)) => {
                let error = self.script.error_at_fn(
                    "read",
                    format!(
                        "`read` returned {value} for register {register}, not a byte (0 to 255)"
                    ),
                );
                self.fail(error);
                0xFF
            }
            Ok(Err(kind)) => {
                let error = self.script.error_at_fn(
                    "read",
                    format!("`read` returned a {kind} for register {register}, not a byte"),
                );
                self.fail(error);
                0xFF
            }
            Err(error) => {
                self.fail(error);
                0xFF
            }
        }
    }

    fn write(&mut self, offset: u16, value: u8, cycle: u64) {
        self.catch_up(cycle);
        if self.failed {
            return;
        }
        let register = offset % self.size;
        self.forget();
        if !self.has_write {
            if let Ok(mut shared) = self.shared.lock()
                && let Some(slot) = shared.table.get_mut(usize::from(register))
            {
                *slot = value;
            }
            self.look();
            return;
        }
        if let Err(error) = self.call(
            "write",
            Some(cycle),
            (i64::from(register), i64::from(value), as_int(cycle)),
        ) {
            self.fail(error);
        }
    }

    fn peek(&self, offset: u16) -> u8 {
        self.table(offset % self.size)
    }

    fn is_stable(&self, offset: u16) -> bool {
        // A plain register is the table, which only the script changes:
        // at a wake-up (the card's next event) or a write; an answer of
        // `read` without effects holds until then too.
        let index = usize::from(offset % self.size);
        self.failed || self.plain[index] || (!self.volatile[index] && self.answers[index].is_some())
    }

    fn sync(&mut self, cycle: u64) {
        self.catch_up(cycle);
    }

    fn next_event(&self) -> Option<u64> {
        if self.failed {
            return None;
        }
        self.wake
    }

    fn irq(&self) -> bool {
        self.view.irq
    }

    /// The card with its script's state (`this`), register table, IRQ
    /// output and wake-up copied; what the copy prints goes to its own
    /// [`ScriptCard::printed`]. `None` while a failure waits to be taken,
    /// or if the script's state shares a closure's variable.
    fn snapshot(&self) -> Option<Box<dyn Device>> {
        if self.fault.is_some() {
            return None;
        }
        let host = Arc::new(self.script.host().fork()?);
        let shared = Arc::new(Mutex::new(self.shared.lock().ok()?.clone()));
        let mut engine = engine(&host);
        register(&mut engine, &shared);
        Some(Box::new(ScriptCard {
            script: self.script.fork(engine, host)?,
            shared,
            view: self.view.clone(),
            wake: self.wake,
            plain: self.plain.clone(),
            volatile: self.volatile.clone(),
            answers: self.answers.clone(),
            has_write: self.has_write,
            has_wake: self.has_wake,
            base: self.base,
            size: self.size,
            now: self.now,
            fault: None,
            failed: self.failed,
        }))
    }

    fn take_fault(&mut self) -> Option<Box<dyn miette::Diagnostic + Send + Sync>> {
        self.fault
            .take()
            .map(|fault| Box::new(fault) as Box<dyn miette::Diagnostic + Send + Sync>)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}
