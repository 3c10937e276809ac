//! Helpers for configuration values.

use serde::{Deserialize, Deserializer, de::Error};

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

impl NumberOrWord {
    /// Deserialises a setting that is a number or one of some keywords: `number` maps a number,
    /// `word` a keyword (`None` when it is not one of them); errors say `expected {expected}`
    /// and name a wrong keyword.
    pub fn read<'de, D: Deserializer<'de>, T>(
        deserializer: D,
        expected: &str,
        number: impl FnOnce(f64) -> T,
        word: impl FnOnce(&str) -> Option<T>,
    ) -> Result<T, D::Error> {
        match NumberOrWord::deserialize(deserializer) {
            Ok(NumberOrWord::Number(value)) => Ok(number(value)),
            Ok(NumberOrWord::Word(text)) => word(&text)
                .ok_or_else(|| D::Error::custom(format!("expected {expected}, found \"{text}\""))),
            Err(_) => Err(D::Error::custom(format!("expected {expected}"))),
        }
    }
}
