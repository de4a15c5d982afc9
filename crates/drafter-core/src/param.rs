//! A parameter outside its documented range: shared by every stage that validates options.

use std::fmt;

/// A parameter outside its documented range (gradient parameters, projectors, transfer tables).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    /// The parameter's name as it appears in configuration files (`q`, `f`, `p`, `scale`, ...).
    pub name: &'static str,
    /// The rejected value, formatted.
    pub value: String,
    /// The accepted range, e.g. `"[1, 255]"`.
    pub expected: &'static str,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} is out of range; expected {}", self.name, self.value, self.expected)
    }
}

impl std::error::Error for ParamError {}
