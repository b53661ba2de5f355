//! Cross-crate and snapshot tests of the Scorpion toolchain live in `tests/`.
