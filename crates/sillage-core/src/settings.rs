//! Helpers for configuration values.

use serde::Deserialize;

/// A configuration value that is a number or a keyword (`"auto"`, `"off"`): what a setting
/// that takes either reads first, so that a wrong keyword can be named in its error.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum NumberOrWord {
    /// A number.
    Number(f64),
    /// A keyword.
    Word(String),
}
