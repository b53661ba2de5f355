//! layouts tests.
