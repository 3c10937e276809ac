//! The one error type of the libraries: every message names the file, line or frame and the fix.

use std::fmt;
use std::path::PathBuf;

/// Result with the sillage [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What can go wrong on user input. Panics are reserved for bugs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file or folder could not be opened, read or written.
    #[error("{}: {cause}{}", path.display(), hint_suffix(hint))]
    Io {
        /// The path involved.
        path: PathBuf,
        /// The operating-system error (shown in the message, so not chained as a source).
        cause: std::io::Error,
        /// What the user can do about it (may be empty).
        hint: String,
    },
    /// A text or binary file does not follow its format.
    #[error("{}{}: {message}", path.display(), line_suffix(*line))]
    Format {
        /// The file.
        path: PathBuf,
        /// 1-based line (or row) number, when it applies.
        line: Option<usize>,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// One frame of a sequence could not be used.
    #[error("frame {frame} ({}): {message}", path.display())]
    Frame {
        /// The file the frame comes from.
        path: PathBuf,
        /// 0-based frame index in the sequence.
        frame: u64,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A parameter is out of its allowed range or unknown.
    #[error("parameter `{key}` = {value}: {message}")]
    Parameter {
        /// The configuration key, as the user writes it.
        key: String,
        /// The offending value, as text.
        value: String,
        /// The allowed range or values.
        message: String,
    },
    /// Input that is wrong as a whole (an empty sequence, mismatched sizes, ...).
    #[error("{0}")]
    Input(String),
    /// An external program the user asked for is not installed.
    #[error("`{program}` was not found: {hint}")]
    MissingProgram {
        /// The program's name.
        program: String,
        /// How to install it.
        hint: String,
    },
}

fn line_suffix(line: Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

fn hint_suffix(hint: &str) -> String {
    if hint.is_empty() {
        String::new()
    } else {
        format!(" ({hint})")
    }
}

impl Error {
    /// An IO error on `path`, with no hint.
    pub fn io(path: impl Into<PathBuf>, cause: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            cause,
            hint: String::new(),
        }
    }

    /// A format error in `path` at an optional 1-based `line`.
    pub fn format(
        path: impl Into<PathBuf>,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        Error::Format {
            path: path.into(),
            line,
            message: message.into(),
        }
    }

    /// An error on one frame of a sequence.
    pub fn frame(path: impl Into<PathBuf>, frame: u64, message: impl Into<String>) -> Self {
        Error::Frame {
            path: path.into(),
            frame,
            message: message.into(),
        }
    }

    /// A parameter error: `key` has `value`, `message` says what is allowed.
    pub fn parameter(
        key: impl Into<String>,
        value: impl fmt::Display,
        message: impl Into<String>,
    ) -> Self {
        Error::Parameter {
            key: key.into(),
            value: value.to_string(),
            message: message.into(),
        }
    }

    /// An error about the input as a whole.
    pub fn input(message: impl Into<String>) -> Self {
        Error::Input(message.into())
    }

    /// The same error with the key of a parameter error placed under `section`
    /// (`particles` → `filter.particles`), so that a nested configuration's errors name the
    /// key as the user writes it; other errors are unchanged.
    pub fn in_section(self, section: &str) -> Self {
        match self {
            Error::Parameter {
                key,
                value,
                message,
            } => Error::Parameter {
                key: format!("{section}.{key}"),
                value,
                message,
            },
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_prefix_parameter_keys_only() {
        let e = Error::parameter("particles", 0, "must be ≥ 1").in_section("filter");
        assert_eq!(
            e.to_string(),
            "parameter `filter.particles` = 0: must be ≥ 1"
        );
        let e = Error::input("empty").in_section("filter");
        assert_eq!(e.to_string(), "empty");
    }

    #[test]
    fn messages_name_file_line_and_key() {
        let e = Error::format("truth.csv", Some(12), "x is NaN; remove the row");
        assert_eq!(e.to_string(), "truth.csv:12: x is NaN; remove the row");
        let e = Error::parameter("peak_neigh", -1, "must be an integer in 1..=10");
        assert!(e.to_string().contains("`peak_neigh` = -1"));
        let e = Error::frame("seq/img_0003.tif", 3, "not a TIFF file");
        assert!(e.to_string().starts_with("frame 3 (seq/img_0003.tif)"));
    }
}
