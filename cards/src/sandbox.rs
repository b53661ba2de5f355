//! The engine a script runs in: Rhai with no file, network or process
//! access (no module loading, no `eval`), nothing that sees or spends the
//! host's time (no `timestamp`, no `sleep`: a script sees robot time only,
//! so a run is the same every time and the debugger can step back), an
//! operation budget per call and per microsecond of robot time, bounded
//! recursion, sizes, variables and output.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use rhai::packages::{
    ArithmeticPackage, BasicArrayPackage, BasicBlobPackage, BasicFnPackage, BasicIteratorPackage,
    BasicMapPackage, BasicMathPackage, BasicStringPackage, BitFieldPackage, LogicPackage,
    MoreStringPackage, Package as _,
};
use rhai::{Dynamic, Engine, EvalAltResult, OptimizationLevel};

use crate::clock::Alarm;
use crate::printed::Printed;

/// Operations one call into a script may take: about a millisecond of the
/// host's time. A script that loops without end is stopped here.
pub const OPERATION_BUDGET: u64 = 200_000;

/// Variables a script may have in sight at once (its top level's, or a
/// function's with its blocks'): Rhai looks a name up through all of
/// them, so more would make loading quadratic in the script's length.
pub const MAX_VARIABLES: usize = 256;

/// Functions (and closures) a script may define: the compiler looks every
/// name a script uses up through all of them.
pub const MAX_FUNCTIONS: usize = 256;

/// Deepest call nesting a script may reach.
pub(crate) const MAX_CALL_LEVELS: usize = 32;

/// The token of a call stopped for its share of robot time.
const ROBOT_TIME: &str = "robot time";

rhai::def_package! {
    /// Rhai's standard library without `LanguageCorePackage` (`sleep`,
    /// `exit`, `take`, tags) and `BasicTimePackage` (`timestamp`).
    SandboxPackage(lib):
        ArithmeticPackage,
        BasicStringPackage,
        BasicIteratorPackage,
        BasicFnPackage,
        BitFieldPackage,
        LogicPackage,
        BasicMathPackage,
        BasicArrayPackage,
        BasicBlobPackage,
        BasicMapPackage,
        MoreStringPackage
    {}
}

/// What the engine's callbacks share with the script's host.
#[derive(Debug, Default)]
pub(crate) struct Host {
    /// What the script printed.
    pub(crate) printed: Printed,
    /// The wake-up it asked for.
    pub(crate) alarm: Mutex<Alarm>,
    /// Operations the running call may take under the robot-time budget.
    pub(crate) allowance: AtomicU64,
    /// Operations the running call has taken.
    pub(crate) spent: AtomicU64,
    /// A declaration went past [`MAX_VARIABLES`] while compiling.
    pub(crate) crowded: AtomicBool,
}

impl Host {
    /// The host of a copy of the script (a debugger's checkpoint): the
    /// wake-up asked for copied, what the copy prints its own. `None` if a
    /// lock is poisoned.
    pub(crate) fn fork(&self) -> Option<Host> {
        Some(Host {
            printed: Printed::default(),
            alarm: Mutex::new(self.alarm.lock().ok()?.clone()),
            allowance: AtomicU64::new(self.allowance.load(Ordering::Relaxed)),
            spent: AtomicU64::new(self.spent.load(Ordering::Relaxed)),
            crowded: AtomicBool::new(self.crowded.load(Ordering::Relaxed)),
        })
    }
}

/// A failure of a host function a script called, with what to do.
#[derive(Debug, Clone)]
pub(crate) struct HostError {
    pub(crate) message: String,
    pub(crate) help: String,
}

impl HostError {
    /// The error as Rhai carries it to the call's place.
    pub(crate) fn thrown(self) -> Box<EvalAltResult> {
        Box::new(EvalAltResult::ErrorRuntime(
            Dynamic::from(self),
            rhai::Position::NONE,
        ))
    }
}

/// The error of a call stopped (or refused) for its share of robot time.
pub(crate) fn robot_time_spent() -> EvalAltResult {
    EvalAltResult::ErrorTerminated(Dynamic::from(ROBOT_TIME), rhai::Position::NONE)
}

/// Whether Rhai's `error` is a call stopped for its share of robot time.
pub(crate) fn is_robot_time(error: &EvalAltResult) -> bool {
    matches!(error, EvalAltResult::ErrorTerminated(token, _)
        if token.clone().into_string().is_ok_and(|t| t == ROBOT_TIME))
}

/// An engine with the sandbox's limits and the functions every script
/// has; the card or the surroundings add their own.
pub(crate) fn engine(host: &Arc<Host>) -> Engine {
    // Built once and shared by every script's engine: a robot with cards
    // is set up per transcript test.
    static LIBRARY: std::sync::OnceLock<rhai::Shared<rhai::Module>> = std::sync::OnceLock::new();
    let library = LIBRARY.get_or_init(|| SandboxPackage::new().as_shared_module());
    let mut engine = Engine::new_raw();
    engine.register_global_module(library.clone());
    // Rhai's optimizer removes statements from a block one at a time
    // (quadratic in the block's length), and a script's calls are few and
    // small: compiling as written keeps loading linear.
    engine.set_optimization_level(OptimizationLevel::None);
    engine.set_max_strings_interned(256);
    engine.set_max_operations(OPERATION_BUDGET);
    engine.set_max_call_levels(MAX_CALL_LEVELS);
    engine.set_max_expr_depths(64, 32);
    engine.set_max_string_size(4096);
    engine.set_max_array_size(65_536);
    engine.set_max_map_size(4096);
    engine.set_max_variables(MAX_VARIABLES);
    engine.set_max_functions(MAX_FUNCTIONS);
    // A name used but never declared is an error when the script loads,
    // not when the line runs (and the compiler keeps no growing list of
    // such names).
    engine.set_strict_variables(true);
    // Nothing outside the script: no modules from files, no `eval`.
    engine.set_module_resolver(rhai::module_resolvers::DummyModuleResolver::new());
    engine.disable_symbol("eval");

    // The compiler looks every name up through the variables in sight: a
    // bound on them keeps compiling linear.
    let watch = Arc::clone(host);
    #[expect(
        deprecated,
        reason = "Rhai marks `on_def_var` volatile, not deprecated; it is the only hook into the compiler's variables"
    )]
    engine.on_def_var(move |runtime, _, context| {
        if !runtime && context.scope().len() >= MAX_VARIABLES {
            watch.crowded.store(true, Ordering::Relaxed);
            return Ok(false);
        }
        Ok(true)
    });
    let watch = Arc::clone(host);
    engine.on_progress(move |operations| {
        watch.spent.store(operations, Ordering::Relaxed);
        (operations > watch.allowance.load(Ordering::Relaxed)).then(|| Dynamic::from(ROBOT_TIME))
    });
    let out = host.printed.clone();
    engine.on_print(move |text| out.keep(text));
    let out = host.printed.clone();
    engine.on_debug(move |text, _, _| out.keep(text));

    // Robot time is counted in cycles of the 1 MHz CPU.
    engine.register_fn("us", |n: i64| n);
    engine.register_fn("ms", |n: i64| n.saturating_mul(1000));
    let watch = Arc::clone(host);
    engine.register_fn("wake_at", move |cycle: i64| match watch.alarm.lock() {
        Ok(mut alarm) => alarm.ask(cycle).map_err(HostError::thrown),
        Err(_) => Ok(()),
    });
    // What a script might reach for, named with what to do instead.
    let no_sleep = || {
        HostError {
            message: "there is no `sleep`: robot time stands still while a script runs".into(),
            help: "ask to be woken later with `wake_at(now + ms(10))` and carry on in `wake(now)`"
                .into(),
        }
        .thrown()
    };
    engine.register_fn("sleep", move |_: i64| -> Result<(), _> { Err(no_sleep()) });
    engine.register_fn("sleep", move |_: f64| -> Result<(), _> { Err(no_sleep()) });
    engine.register_fn("timestamp", || -> Result<(), _> {
        Err(HostError {
            message: "there is no `timestamp`: a script sees robot time only".into(),
            help: "every call is given `now`, the robot time in microseconds since power-up; the host's clock would make each run different".into(),
        }
        .thrown())
    });
    engine
}
