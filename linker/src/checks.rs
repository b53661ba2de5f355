//! Checks after resolution: deferred `.assert`s, and the ROM hooks an image
//! takes over (from its exported `__scorpion_hook_*`/`__scorpion_chain_*`).

use std::collections::BTreeMap;

use isa::objfmt::{AssertAction, EvalError, HookKind, HookRecord, Hooks};

use crate::error::Error;
use crate::input::Object;
use crate::model::{Global, Origin};
use crate::source::{Place, SourceProvider};

/// Evaluates every object's deferred assertions with `isa`'s evaluator.
pub(crate) fn check_asserts(
    objects: &[Object],
    values: &[Vec<Option<i64>>],
    unresolved: &[Vec<bool>],
    sources: &dyn SourceProvider,
    errors: &mut Vec<Error>,
    warnings: &mut Vec<Error>,
) {
    for (object_index, object) in objects.iter().enumerate() {
        for assertion in &object.asserts {
            let place = Place::source(&assertion.file, assertion.line, assertion.column);
            let result = assertion
                .expr
                .evaluate(|index| values[object_index].get(index as usize).copied().flatten());
            match result {
                Ok(0) => {
                    let (src, span) = place.snippet(sources);
                    let (message, at) = (assertion.message.clone(), place.text);
                    match assertion.action {
                        AssertAction::Error => errors.push(Error::AssertFailed {
                            message,
                            at,
                            src,
                            span,
                        }),
                        AssertAction::Warning => warnings.push(Error::AssertWarning {
                            message,
                            at,
                            src,
                            span,
                        }),
                    }
                }
                Ok(_) => {}
                // Already reported as an undefined symbol.
                Err(EvalError::UnresolvedSymbol(index))
                    if unresolved[object_index].get(index as usize) == Some(&true) => {}
                Err(error) => errors.push(Error::AssertInvalid {
                    at: place.text,
                    reason: error.to_string(),
                }),
            }
        }
    }
}

/// " (defined at main.s:12:1)" for a global an object defines, else "".
pub(crate) fn defined_at(
    objects: &[Object],
    globals: &BTreeMap<String, Global>,
    name: &str,
) -> String {
    match globals.get(name).map(|global| &global.origin) {
        Some(Origin::Object { object, symbol }) => {
            format!(
                " (defined at {})",
                objects[*object].place_of_symbol(*symbol).text
            )
        }
        _ => String::new(),
    }
}

/// The hook records an image's exported symbols ask for.
pub(crate) fn hooks(
    objects: &[Object],
    globals: &BTreeMap<String, Global>,
    errors: &mut Vec<Error>,
) -> Hooks {
    let mut hooks = Hooks::default();
    let address = |name: &str, errors: &mut Vec<Error>| -> Option<u16> {
        let value = globals.get(name)?.value?;
        match u16::try_from(value) {
            Ok(address) => Some(address),
            Err(_) => {
                errors.push(Error::Hook {
                    reason: format!(
                        "{name}{} = {value:#X} is not a 16-bit address",
                        defined_at(objects, globals, name)
                    ),
                });
                None
            }
        }
    };
    for kind in HookKind::ALL {
        let handler = address(kind.handler_symbol(), errors);
        let chain = address(kind.chain_symbol(), errors);
        match (handler, chain) {
            (Some(handler), chain) => hooks.records.push(HookRecord {
                kind,
                handler,
                chain,
            }),
            (None, Some(_)) => errors.push(Error::Hook {
                reason: format!(
                    "{}{} is exported but {} is not: a chain slot needs a handler",
                    kind.chain_symbol(),
                    defined_at(objects, globals, kind.chain_symbol()),
                    kind.handler_symbol()
                ),
            }),
            (None, None) => {}
        }
    }
    hooks
}
