//! Configuration files for every command: a TOML file read into a serde structure, and
//! `--set key=value` overrides of its dotted keys. Errors name the file or the key and point
//! to `sillage config`, which lists every key.

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;
use sillage_core::{Error, Result};

/// Reads a TOML configuration file into `T`; the error names the file.
pub fn read_toml_file<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_toml(&text).map_err(|e| match e {
        Error::Input(message) => Error::format(path, None, message),
        other => other,
    })
}

/// Parses a TOML configuration into `T`.
pub fn parse_toml<T: DeserializeOwned>(text: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        Error::input(format!(
            "invalid configuration: {}; see `sillage config` for every key and its default",
            e.message()
        ))
    })
}

/// Applies one `key=value` override to `config`, `key` being a dotted path such as
/// `detector.scale_px` or `likelihood.gamma`; `value` is read as TOML (numbers, booleans,
/// strings with or without quotes, arrays).
pub fn set_key<T: Serialize + DeserializeOwned>(config: &mut T, assignment: &str) -> Result<()> {
    let (key, raw_value) = assignment.split_once('=').ok_or_else(|| {
        Error::parameter(
            assignment,
            "",
            "overrides look like `key=value`, e.g. `detector.scale_px=2.5`",
        )
    })?;
    let key = key.trim();
    let value = parse_toml_value(raw_value.trim());
    let tree = toml::Value::try_from(&*config)
        .map_err(|e| Error::input(format!("cannot serialise the configuration: {e}")))?;
    // An enum is written as a one-key table (`threshold.auto.std_factor` vs
    // `threshold.fixed`): when adding the key alone fails, choosing another variant is
    // tried by emptying each enclosing section in turn, innermost first.
    let depth = key.split('.').count();
    let attempts = std::iter::once(None).chain((1..depth).rev().map(Some));
    let mut first_error = None;
    for clear_at in attempts {
        let mut candidate = tree.clone();
        insert_dotted(&mut candidate, key, value.clone(), clear_at)
            .map_err(|message| Error::parameter(key, raw_value, message))?;
        match candidate.try_into() {
            Ok(parsed) => {
                *config = parsed;
                return Ok(());
            }
            Err(e) => {
                let e: toml::de::Error = e;
                first_error.get_or_insert(e);
            }
        }
    }
    let message = first_error
        .map(|e| e.message().to_string())
        .unwrap_or_default();
    Err(Error::parameter(
        key,
        raw_value,
        format!("{message}; see `sillage config` for every key"),
    ))
}

/// Parameters that check themselves: every settings type a command reads from `--config` and
/// `--set` implements it, so [`load`] hands out only validated settings.
pub trait Settings: Serialize + DeserializeOwned + Default {
    /// Checks every field; the error names the key and its allowed range.
    fn validate(&self) -> Result<()>;
}

/// Settings in the order every command applies them: the defaults, then the TOML `file` (read
/// once), then each `key=value` of `overrides`; not yet validated, for callers that adjust
/// them further (flags such as `--seed`) before [`Settings::validate`].
pub fn load_unvalidated<T: Serialize + DeserializeOwned + Default>(
    file: Option<&Path>,
    overrides: &[String],
) -> Result<T> {
    let mut settings = match file {
        Some(path) => read_toml_file(path)?,
        None => T::default(),
    };
    for assignment in overrides {
        set_key(&mut settings, assignment)?;
    }
    Ok(settings)
}

/// [`load_unvalidated`], then [`Settings::validate`]: the settings of `file` and `overrides`,
/// checked.
pub fn load<T: Settings>(file: Option<&Path>, overrides: &[String]) -> Result<T> {
    let settings: T = load_unvalidated(file, overrides)?;
    settings.validate()?;
    Ok(settings)
}

/// Every leaf of `config` as `(dotted.key, TOML value text)`, sorted by key within a table:
/// the parameters a track file records (`likelihood.gamma = 0.7`), the same keys as `--set`.
pub fn dotted_keys<T: Serialize>(config: &T) -> Result<Vec<(String, String)>> {
    let tree = toml::Value::try_from(config)
        .map_err(|e| Error::input(format!("cannot serialise the configuration: {e}")))?;
    let mut keys = Vec::new();
    flatten_into(&tree, "", &mut keys);
    Ok(keys)
}

fn flatten_into(node: &toml::Value, prefix: &str, keys: &mut Vec<(String, String)>) {
    match node {
        toml::Value::Table(table) => {
            for (key, value) in table {
                let dotted = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                flatten_into(value, &dotted, keys);
            }
        }
        toml::Value::String(text) => keys.push((prefix.to_string(), text.clone())),
        leaf => keys.push((prefix.to_string(), leaf.to_string())),
    }
}

/// Reads `raw` as a TOML value; bare words that are not TOML become strings.
fn parse_toml_value(raw: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("v = {raw}"))
        .ok()
        .and_then(|mut table| table.remove("v"))
        .unwrap_or_else(|| toml::Value::String(raw.to_string()))
}

/// Sets `tree[a][b]...[last] = value` for the dotted `key`, creating tables on the way; the
/// table at depth `clear_at` (the one holding the `clear_at`-th segment) is emptied first.
fn insert_dotted(
    tree: &mut toml::Value,
    key: &str,
    value: toml::Value,
    clear_at: Option<usize>,
) -> std::result::Result<(), String> {
    let mut node = tree;
    let parts: Vec<&str> = key.split('.').collect();
    for (depth, part) in parts.iter().enumerate() {
        if part.is_empty() {
            return Err("empty key segment; write keys like `tracker.motion_av`".into());
        }
        let table = node
            .as_table_mut()
            .ok_or_else(|| format!("`{}` is a value, not a section", parts[..depth].join(".")))?;
        if clear_at == Some(depth) {
            table.clear();
        }
        if depth + 1 == parts.len() {
            table.insert((*part).to_string(), value);
            return Ok(());
        }
        node = table
            .entry((*part).to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, serde::Deserialize)]
    struct Inner {
        gamma: f64,
        name: String,
    }

    #[derive(Serialize, serde::Deserialize)]
    struct Outer {
        seed: u64,
        likelihood: Inner,
    }

    #[test]
    fn dotted_keys_name_every_leaf_as_set_does() {
        let mut config = Outer {
            seed: 3,
            likelihood: Inner {
                gamma: 0.5,
                name: "mmpf".into(),
            },
        };
        set_key(&mut config, "likelihood.gamma=0.7").unwrap();
        let keys = dotted_keys(&config).unwrap();
        let expected = [
            ("likelihood.gamma", "0.7"),
            ("likelihood.name", "mmpf"),
            ("seed", "3"),
        ];
        assert_eq!(keys, expected.map(|(k, v)| (k.to_string(), v.to_string())));
    }

    #[derive(Serialize, serde::Deserialize, Default, Debug, PartialEq)]
    #[serde(default, deny_unknown_fields)]
    struct Checked {
        particles: u32,
    }

    impl Settings for Checked {
        fn validate(&self) -> Result<()> {
            if self.particles == 0 {
                return Err(Error::parameter("particles", 0, "must be at least 1"));
            }
            Ok(())
        }
    }

    #[test]
    fn load_applies_the_file_then_the_overrides_then_validates() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("run.toml");
        std::fs::write(&file, "particles = 5\n").unwrap();
        let from_file: Checked = load(Some(&file), &[]).unwrap();
        assert_eq!(from_file.particles, 5);
        let overridden: Checked = load(Some(&file), &["particles=9".to_string()]).unwrap();
        assert_eq!(overridden.particles, 9);
        let err = load::<Checked>(None, &[]).unwrap_err().to_string();
        assert!(err.contains("particles"), "{err}");
        let unchecked: Checked = load_unvalidated(None, &[]).unwrap();
        assert_eq!(unchecked, Checked::default());
    }
}
