//! ld65 tests.
