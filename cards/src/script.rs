//! A loaded script: its compiled form, its top-level constants and the
//! `this` it keeps state in; calls into it at a robot time, within its
//! budget, and its failures located in its text.

use std::sync::Arc;
use std::sync::atomic::Ordering;

use miette::{NamedSource, SourceSpan};
use rhai::{AST, CallFnOptions, Dynamic, Engine, EvalAltResult, ParseError, Position, Scope};

use crate::clock::{Budget, CALL_COST, OPERATIONS_PER_MICROSECOND};
use crate::error::{Located, ScriptError, offset_of};
use crate::printed::Printed;
use crate::sandbox::{
    Host, HostError, MAX_CALL_LEVELS, MAX_VARIABLES, OPERATION_BUDGET, is_robot_time,
    robot_time_spent,
};

/// The namespace functions read the top level's constants from
/// (`global::NAME`, Rhai's own name for them).
const GLOBAL: &str = "global";

/// A loaded script.
pub(crate) struct Script {
    engine: Engine,
    ast: AST,
    /// The top level's variables and constants, as it left them.
    scope: Scope<'static>,
    /// The scope calls run in: empty (a function sees only its
    /// parameters), kept so a call allocates none.
    calls: Scope<'static>,
    /// The top level's constants, which functions read as `global::NAME`:
    /// a static module of the engine's, so a call need not run the top
    /// level again to declare them.
    constants: rhai::Shared<rhai::Module>,
    /// The state the script's functions see as `this`.
    this: Dynamic,
    name: String,
    text: String,
    host: Arc<Host>,
    budget: Budget,
}

impl std::fmt::Debug for Script {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Script")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

impl Script {
    /// Compiles `text` and runs its top level (constants, `let`s), with
    /// `engine` made by [`crate::sandbox::engine`] for `host`.
    pub(crate) fn load(
        engine: Engine,
        host: Arc<Host>,
        name: &str,
        text: &str,
    ) -> Result<Script, ScriptError> {
        let ast = engine.compile(text).map_err(|error: ParseError| {
            let (line, column) = place(error.1);
            let (message, help) = if host.crowded.load(Ordering::Relaxed) {
                (
                    format!("more than {MAX_VARIABLES} variables in sight at once"),
                    Some("keep many values in an array or a map (`const TABLE = [1, 2, 3];`), or in `this`".to_owned()),
                )
            } else {
                (error.0.to_string(), None)
            };
            located(name, text, line, column, message, help)
        })?;
        let mut script = Script {
            engine,
            ast,
            scope: Scope::new(),
            calls: Scope::new(),
            constants: rhai::Module::new().into(),
            this: Dynamic::from_map(rhai::Map::new()),
            name: name.to_owned(),
            text: text.to_owned(),
            host,
            budget: Budget::default(),
        };
        let mut scope = Scope::new();
        // Before robot time starts a call always has its full budget.
        let _ = script.start(None);
        let result = script.engine.run_ast_with_scope(&mut scope, &script.ast);
        result.map_err(|error| script.runtime_error_in(&error, None))?;
        let mut constants = rhai::Module::new();
        for (name, constant, value) in scope.iter_raw() {
            if constant {
                constants.set_var(name, value.clone());
            }
        }
        constants.build_index();
        script.constants = constants.into();
        script
            .engine
            .register_static_module(GLOBAL, script.constants.clone());
        script.scope = scope;
        Ok(script)
    }

    /// A copy of the script as it is now, on `engine` (an engine like
    /// this one's, made for `host` from [`Host::fork`] and with the
    /// card's or surroundings' functions bound to the copy's own state):
    /// the compiled script and its constants shared, `this` and the
    /// robot-time budget copied. The engine keeps no state between calls
    /// (its limits are per call), so the copy goes on as this script
    /// would. `None` if part of `this` is shared (a closure's captured
    /// variable), which a copy could not keep apart from the original.
    pub(crate) fn fork(&self, mut engine: Engine, host: Arc<Host>) -> Option<Script> {
        if has_shared(&self.this) {
            return None;
        }
        engine.register_static_module(GLOBAL, self.constants.clone());
        Some(Script {
            engine,
            ast: self.ast.clone(),
            scope: self.scope.clone(),
            calls: Scope::new(),
            constants: self.constants.clone(),
            this: self.this.clone(),
            name: self.name.clone(),
            text: self.text.clone(),
            host,
            budget: self.budget.clone(),
        })
    }

    /// The host the script's functions reach.
    pub(crate) fn host(&self) -> &Host {
        &self.host
    }

    /// Whether the script defines `name` with `params` parameters.
    pub(crate) fn has_fn(&self, name: &str, params: usize) -> bool {
        self.ast
            .iter_functions()
            .any(|f| f.name == name && f.params.len() == params)
    }

    /// A top-level constant or variable.
    pub(crate) fn constant(&self, name: &str) -> Option<Dynamic> {
        self.scope.get_value::<Dynamic>(name)
    }

    /// Calls `function` at robot time `now` (`None`: `init`, before robot
    /// time starts) with `this` bound to the script's state.
    pub(crate) fn call(
        &mut self,
        function: &str,
        now: Option<u64>,
        args: impl rhai::FuncArgs,
    ) -> Result<Dynamic, ScriptError> {
        if !self.start(now) {
            // Not even the call itself is covered: refused before it runs.
            return Err(self.runtime_error_in(&robot_time_spent(), Some(function)));
        }
        // The top level ran once, at loading: its constants are the
        // engine's `global` module, so the call goes straight to the
        // function.
        let options = CallFnOptions::new()
            .eval_ast(false)
            .rewind_scope(true)
            .bind_this_ptr(&mut self.this);
        let result = self.engine.call_fn_with_options::<Dynamic>(
            options,
            &mut self.calls,
            &self.ast,
            function,
            args,
        );
        self.budget
            .spend(now, self.host.spent.load(Ordering::Relaxed));
        result.map_err(|error| self.runtime_error_in(&error, Some(function)))
    }

    /// Gets the host ready for a call at `now`: its robot time, its share
    /// of operations. `false` if the script's credit does not cover the
    /// call itself ([`CALL_COST`]).
    fn start(&mut self, now: Option<u64>) -> bool {
        if let Ok(mut alarm) = self.host.alarm.lock() {
            alarm.set_now(now);
        }
        let Some(allowance) = self.budget.allowance(now) else {
            return false;
        };
        self.host.allowance.store(allowance, Ordering::Relaxed);
        self.host.spent.store(0, Ordering::Relaxed);
        true
    }

    /// The wake-up the script asked for.
    pub(crate) fn wake(&self) -> Option<u64> {
        self.host.alarm.lock().ok().and_then(|alarm| alarm.at())
    }

    /// Forgets the wake-up asked for.
    pub(crate) fn clear_wake(&self) {
        if let Ok(mut alarm) = self.host.alarm.lock() {
            alarm.clear();
        }
    }

    /// The handle to what the script prints.
    pub(crate) fn printed(&self) -> Printed {
        self.host.printed.clone()
    }

    /// A located error for a runtime failure in a call of `function`: the
    /// innermost place (inside the function that failed, not the call into
    /// it), or where that function is written when Rhai gives no place (a
    /// spent operation budget).
    fn runtime_error_in(&self, error: &EvalAltResult, function: Option<&str>) -> ScriptError {
        let mut inner = error;
        let mut within = function.map(str::to_owned);
        while let EvalAltResult::ErrorInFunctionCall(name, _, next, _) = inner {
            within = Some(name.clone());
            inner = next;
        }
        // Robot time runs out wherever the count happens to be (at a
        // call's first statement, say): the function called is the place
        // to change.
        let (line, column) = if inner.position().is_none() || is_robot_time(inner) {
            within.as_deref().map_or((1, 1), |name| self.fn_line(name))
        } else {
            place(inner.position())
        };
        let (message, help) = match inner {
            EvalAltResult::ErrorTooManyOperations(_) => (
                "the script ran out of its operation budget".to_owned(),
                Some(format!(
                    "one call may take {OPERATION_BUDGET} operations: a loop that waits for the robot never ends, since robot time stands still while the script runs; ask to be woken later with `wake_at(now + us(100))`"
                )),
            ),
            other if is_robot_time(other) => (
                format!(
                    "the script took more than its share of robot time ({OPERATIONS_PER_MICROSECOND} operations per microsecond)"
                ),
                Some(format!(
                    "a call may take {OPERATION_BUDGET} operations, earned back at {OPERATIONS_PER_MICROSECOND} per microsecond of robot time, and each call counts {CALL_COST} for itself (at most one every {} microseconds on average): wake less often (`wake_at(now + ms(1))`), do less per call, or serve registers the program polls from `PLAIN`",
                    CALL_COST / OPERATIONS_PER_MICROSECOND
                )),
            ),
            EvalAltResult::ErrorStackOverflow(_) => (
                strip_position(&inner.to_string()),
                Some(format!("calls nest at most {MAX_CALL_LEVELS} deep")),
            ),
            EvalAltResult::ErrorRuntime(value, _) if value.is::<HostError>() => {
                let host = value.clone().cast::<HostError>();
                (host.message, Some(host.help))
            }
            other => (strip_position(&other.to_string()), None),
        };
        located(&self.name, &self.text, line, column, message, help)
    }

    /// An error the host found at a script's place (a value out of range
    /// returned by `read`).
    pub(crate) fn error_at_fn(&self, function: &str, message: String) -> ScriptError {
        let (line, column) = self.fn_line(function);
        located(&self.name, &self.text, line, column, message, None)
    }

    /// An error about the top-level declaration of `name` (a `const` or a
    /// `let`), at that declaration.
    pub(crate) fn error_at_declaration(
        &self,
        name: &str,
        message: String,
        help: String,
    ) -> ScriptError {
        let (line, column) = ["const", "let"]
            .iter()
            .find_map(|keyword| self.find(&format!("{keyword} {name}")))
            .unwrap_or((1, 1));
        located(&self.name, &self.text, line, column, message, Some(help))
    }

    /// Where `fn name` is written.
    fn fn_line(&self, name: &str) -> (usize, usize) {
        self.find(&format!("fn {name}")).unwrap_or((1, 1))
    }

    /// The first place `words` is written as whole words, line and column.
    fn find(&self, words: &str) -> Option<(usize, usize)> {
        let word = |c: char| c.is_alphanumeric() || c == '_';
        self.text.lines().enumerate().find_map(|(index, line)| {
            line.match_indices(words)
                .find(|&(at, _)| {
                    !line[..at].ends_with(word) && !line[at + words.len()..].starts_with(word)
                })
                .map(|(at, _)| (index + 1, line[..at].chars().count() + 1))
        })
    }
}

/// Whether some part of `value` is shared (a closure's captured
/// variable): cloning copies everything else.
fn has_shared(value: &Dynamic) -> bool {
    if value.is_shared() {
        return true;
    }
    if let Some(map) = value.read_lock::<rhai::Map>() {
        return map.values().any(has_shared);
    }
    if let Some(array) = value.read_lock::<rhai::Array>() {
        return array.iter().any(has_shared);
    }
    if let Some(function) = value.read_lock::<rhai::FnPtr>() {
        return function.curry().iter().any(has_shared);
    }
    false
}

fn place(position: Position) -> (usize, usize) {
    (
        position.line().unwrap_or(1),
        position.position().unwrap_or(1),
    )
}

/// Rhai's messages end with ` (line L, position P)`: our location says it.
fn strip_position(message: &str) -> String {
    match message.rfind(" (line ") {
        Some(at) => message[..at].to_string(),
        None => message.to_string(),
    }
}

fn located(
    name: &str,
    text: &str,
    line: usize,
    column: usize,
    message: String,
    help: Option<String>,
) -> ScriptError {
    let offset = offset_of(text, line, column);
    let len = usize::from(offset < text.len());
    ScriptError::Script(Box::new(Located {
        file: name.to_owned(),
        line,
        column,
        message,
        source_code: NamedSource::new(name, text.to_owned()),
        at: SourceSpan::from((offset, len)),
        help,
    }))
}
