//! A request's arguments, read with their types checked: a value of the
//! wrong type is an error response naming the request and the argument,
//! never a panic nor a value taken for another.

use serde_json::{Map, Value};

/// A request's arguments, read with their types checked.
pub(crate) struct Arguments<'a> {
    pub(crate) command: &'a str,
    pub(crate) map: &'a Map<String, Value>,
}

impl<'a> Arguments<'a> {
    /// The error for argument `name`, which should be `kind`.
    pub(crate) fn wrong(&self, name: &str, kind: &str) -> String {
        format!("{}: `{name}` is {kind}", self.command)
    }

    /// A string argument.
    pub(crate) fn string(&self, name: &str) -> Result<Option<&'a str>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::String(text)) => Ok(Some(text)),
            Some(_) => Err(self.wrong(name, "a string")),
        }
    }

    /// A boolean argument.
    pub(crate) fn boolean(&self, name: &str) -> Result<Option<bool>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Bool(value)) => Ok(Some(*value)),
            Some(_) => Err(self.wrong(name, "true or false")),
        }
    }

    /// An integer argument.
    pub(crate) fn integer(&self, name: &str) -> Result<Option<i64>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(value) => value
                .as_i64()
                .map(Some)
                .ok_or_else(|| self.wrong(name, "an integer")),
        }
    }

    /// A list of strings.
    pub(crate) fn strings(&self, name: &str) -> Result<Option<Vec<String>>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Array(items)) => items
                .iter()
                .map(|item| item.as_str().map(str::to_owned))
                .collect::<Option<Vec<_>>>()
                .map(Some)
                .ok_or_else(|| self.wrong(name, "a list of strings")),
            Some(_) => Err(self.wrong(name, "a list of strings")),
        }
    }

    /// A list of objects (`breakpoints`), none when absent.
    pub(crate) fn objects(&self, name: &str) -> Result<Vec<&'a Map<String, Value>>, String> {
        match self.map.get(name) {
            None | Some(Value::Null) => Ok(Vec::new()),
            Some(Value::Array(items)) => items
                .iter()
                .map(Value::as_object)
                .collect::<Option<Vec<_>>>()
                .ok_or_else(|| self.wrong(name, "a list of objects")),
            Some(_) => Err(self.wrong(name, "a list of objects")),
        }
    }

    /// The same reading of `map`, one of this request's objects.
    pub(crate) fn of(&self, map: &'a Map<String, Value>) -> Arguments<'a> {
        Arguments {
            command: self.command,
            map,
        }
    }
}
