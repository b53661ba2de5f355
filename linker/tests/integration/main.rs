//! Linker integration tests: objects built with `isa::objfmt::ObjectBuilder`, linked,
//! written and read back. One test binary, one module per concern.

mod support;

mod diagnostics;
mod formats;
mod layouts;
mod ld65;
mod ld65_config;
mod properties;
mod relocations;
mod robustness;
pub(crate) mod round_trip;
