//! Helpers shared by the toolchain's tests.
//!
//! This library depends on none of our crates, so any crate can take it as
//! a dev-dependency. The cross-crate tests themselves live in `tests/tests/`
//! (library-level) and `tests/cli/` (the `scorpion` binary, run as a
//! process; a test target of the root package).

mod render;
pub mod tools;

pub use render::render;
