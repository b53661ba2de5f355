//! A script, sandboxed: Rhai with no file, network or process access (no
//! module loading, no `eval`), an operation budget on every call, bounded
//! recursion and sizes; what it prints is kept for the host to show.

use std::sync::{Arc, Mutex};

use miette::{NamedSource, SourceSpan};
use rhai::{AST, CallFnOptions, Dynamic, Engine, EvalAltResult, ParseError, Position, Scope};

use crate::error::{Located, ScriptError, offset_of};

/// Operations one call into a script may take: about a millisecond of the
/// host's time. A script that loops without end is stopped here.
pub const OPERATION_BUDGET: u64 = 200_000;

/// Deepest call nesting a script may reach.
const MAX_CALL_LEVELS: usize = 32;

/// A loaded script: its engine (with the host's functions), its compiled
/// form, its top-level constants and the `this` it keeps state in.
pub(crate) struct Script {
    pub(crate) engine: Engine,
    ast: AST,
    scope: Scope<'static>,
    /// The state the script's functions see as `this`.
    this: Dynamic,
    name: String,
    text: String,
    printed: Arc<Mutex<Vec<String>>>,
}

impl std::fmt::Debug for Script {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Script")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

/// What a script prints (`print`, `debug`), kept for the host to show: a
/// handle that stays valid after the card is mapped into the board.
#[derive(Debug, Clone, Default)]
pub struct Printed(pub(crate) Arc<Mutex<Vec<String>>>);

impl Printed {
    /// The lines printed since the last call.
    #[must_use]
    pub fn take(&self) -> Vec<String> {
        self.0
            .lock()
            .map(|mut lines| std::mem::take(&mut *lines))
            .unwrap_or_default()
    }
}

/// An engine with the sandbox's limits; `register` adds the host's
/// functions for the kind of script.
pub(crate) fn engine(printed: &Arc<Mutex<Vec<String>>>) -> Engine {
    // Rhai's standard library, built once and shared by every script's
    // engine: a robot with cards is set up per transcript test.
    static STANDARD: std::sync::OnceLock<rhai::Shared<rhai::Module>> = std::sync::OnceLock::new();
    let standard = STANDARD.get_or_init(|| {
        use rhai::packages::Package as _;
        rhai::packages::StandardPackage::new().as_shared_module()
    });
    let mut engine = Engine::new_raw();
    engine.register_global_module(standard.clone());
    engine.set_max_strings_interned(256);
    engine.set_max_operations(OPERATION_BUDGET);
    engine.set_max_call_levels(MAX_CALL_LEVELS);
    engine.set_max_expr_depths(64, 32);
    engine.set_max_string_size(4096);
    engine.set_max_array_size(65_536);
    engine.set_max_map_size(4096);
    // Nothing outside the script: no modules from files, no `eval`.
    engine.set_module_resolver(rhai::module_resolvers::DummyModuleResolver::new());
    engine.disable_symbol("eval");
    let out = Arc::clone(printed);
    engine.on_print(move |text| {
        if let Ok(mut lines) = out.lock() {
            lines.push(text.to_string());
        }
    });
    let out = Arc::clone(printed);
    engine.on_debug(move |text, _, _| {
        if let Ok(mut lines) = out.lock() {
            lines.push(text.to_string());
        }
    });
    // Robot time is counted in cycles of the 1 MHz CPU.
    engine.register_fn("us", |n: i64| n);
    engine.register_fn("ms", |n: i64| n.saturating_mul(1000));
    engine
}

impl Script {
    /// Compiles `text` and runs its top level (constants, `let`s).
    pub(crate) fn load(
        engine: Engine,
        name: &str,
        text: &str,
        printed: Arc<Mutex<Vec<String>>>,
    ) -> Result<Script, ScriptError> {
        let located =
            |line, column, message: String, help| located(name, text, line, column, message, help);
        let ast = engine.compile(text).map_err(|error: ParseError| {
            let (line, column) = place(error.1);
            located(line, column, error.0.to_string(), None)
        })?;
        let mut scope = Scope::new();
        let mut script = Script {
            engine,
            ast,
            scope: Scope::new(),
            this: Dynamic::from_map(rhai::Map::new()),
            name: name.to_owned(),
            text: text.to_owned(),
            printed,
        };
        script
            .engine
            .run_ast_with_scope(&mut scope, &script.ast)
            .map_err(|error| script.runtime_error_in(&error, None))?;
        script.scope = scope;
        Ok(script)
    }

    /// A copy of the script as it is now, on `engine` (an engine like
    /// this one's, with the host's functions bound to the copy's own
    /// state), printing into `printed`: the compiled script and its
    /// constants shared, `this` copied. The engine keeps no state between
    /// calls (its limits are per call), so the copy goes on as this script
    /// would. `None` if part of `this` is shared (a closure's captured
    /// variable), which a copy could not keep apart from the original.
    pub(crate) fn fork(&self, engine: Engine, printed: Arc<Mutex<Vec<String>>>) -> Option<Script> {
        if has_shared(&self.this) {
            return None;
        }
        Some(Script {
            engine,
            ast: self.ast.clone(),
            scope: self.scope.clone(),
            this: self.this.clone(),
            name: self.name.clone(),
            text: self.text.clone(),
            printed,
        })
    }

    /// Whether the script defines `name` with `params` parameters.
    pub(crate) fn has_fn(&self, name: &str, params: usize) -> bool {
        self.ast
            .iter_functions()
            .any(|f| f.name == name && f.params.len() == params)
    }

    /// A top-level integer constant or variable.
    pub(crate) fn constant(&self, name: &str) -> Option<Dynamic> {
        self.scope.get_value::<Dynamic>(name)
    }

    /// Calls `function` with `this` bound to the script's state.
    pub(crate) fn call(
        &mut self,
        function: &str,
        args: impl rhai::FuncArgs,
    ) -> Result<Dynamic, ScriptError> {
        let options = CallFnOptions::new()
            .eval_ast(true)
            .rewind_scope(true)
            .bind_this_ptr(&mut self.this);
        let result = self.engine.call_fn_with_options::<Dynamic>(
            options,
            &mut self.scope,
            &self.ast,
            function,
            args,
        );
        result.map_err(|error| self.runtime_error_in(&error, Some(function)))
    }

    /// The handle to what the script prints.
    pub(crate) fn printed(&self) -> Printed {
        Printed(Arc::clone(&self.printed))
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
        let (line, column) = if inner.position().is_none() {
            within.as_deref().map_or((1, 1), |name| self.fn_line(name))
        } else {
            place(inner.position())
        };
        let help = match inner {
            EvalAltResult::ErrorTooManyOperations(_) => Some(format!(
                "one call may take {OPERATION_BUDGET} operations: a loop that waits for the robot never ends, since robot time stands still while the script runs; ask to be woken later with `wake_at(now + us(100))`"
            )),
            EvalAltResult::ErrorStackOverflow(_) => {
                Some(format!("calls nest at most {MAX_CALL_LEVELS} deep"))
            }
            _ => None,
        };
        let message = match inner {
            EvalAltResult::ErrorTooManyOperations(_) => {
                "the script ran out of its operation budget".to_string()
            }
            other => strip_position(&other.to_string()),
        };
        located(&self.name, &self.text, line, column, message, help)
    }

    /// An error the host found at a script's place (a value out of range
    /// returned by `read`).
    pub(crate) fn error_at_fn(&self, function: &str, message: String) -> ScriptError {
        let (line, column) = self.fn_line(function);
        located(&self.name, &self.text, line, column, message, None)
    }

    /// Where `fn name` is written.
    fn fn_line(&self, name: &str) -> (usize, usize) {
        let needle = format!("fn {name}");
        self.text
            .lines()
            .enumerate()
            .find_map(|(index, line)| line.find(&needle).map(|at| (index + 1, at + 1)))
            .unwrap_or((1, 1))
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
