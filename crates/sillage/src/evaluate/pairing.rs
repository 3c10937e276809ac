//! Pairing ground truth with predictions: the sequences of a truth path (a file, a
//! MOTChallenge sequence folder, or a folder of them) matched by name with the prediction
//! files of a prediction path.

use std::path::{Path, PathBuf};

use sillage_core::{Error, Result};
use sillage_io::MotFileRole;

use crate::tables::{TABLE_EXTENSIONS, has_extension};

/// One sequence to score: its name and its ground-truth and prediction files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SequencePaths {
    /// The name shown in the tables.
    pub name: String,
    /// The ground-truth file.
    pub gt: PathBuf,
    /// The prediction file.
    pub pred: PathBuf,
}

/// The sequences of `gt` (a file, a sequence folder, or a folder of them) paired with the
/// predictions in `pred` (a file, or a folder of files named `<sequence>.<ext>`).
/// Unpaired sequences are an error that names them.
pub fn pair_sequences(gt: &Path, pred: &Path) -> Result<Vec<SequencePaths>> {
    let truths = gt_sequences(gt)?;
    if !pred.exists() {
        return Err(Error::input(format!(
            "--pred {} does not exist",
            pred.display()
        )));
    }
    if !pred.is_dir() {
        return match truths.as_slice() {
            [(name, file)] => Ok(vec![SequencePaths {
                name: name.clone(),
                gt: file.clone(),
                pred: pred.to_path_buf(),
            }]),
            _ => Err(Error::input(format!(
                "--gt {} holds {} sequences but --pred {} is one file; give a folder of \
                 predictions named <sequence>.txt",
                gt.display(),
                truths.len(),
                pred.display()
            ))),
        };
    }
    let preds = files_by_stem(pred)?;
    let mut pairs = Vec::with_capacity(truths.len());
    let mut missing = Vec::new();
    for (name, file) in &truths {
        match preds.iter().find(|(stem, _)| stem == name) {
            Some((_, pred_file)) => pairs.push(SequencePaths {
                name: name.clone(),
                gt: file.clone(),
                pred: pred_file.clone(),
            }),
            None => missing.push(name.as_str()),
        }
    }
    let extra: Vec<&str> = preds
        .iter()
        .map(|(stem, _)| stem.as_str())
        .filter(|stem| truths.iter().all(|(name, _)| name != stem))
        .collect();
    if missing.is_empty() && extra.is_empty() {
        return Ok(pairs);
    }
    let mut problems = Vec::new();
    if !missing.is_empty() {
        problems.push(format!(
            "no prediction in {} for the ground-truth sequence(s) {}",
            pred.display(),
            missing.join(", ")
        ));
    }
    if !extra.is_empty() {
        problems.push(format!(
            "no ground truth in {} for the prediction(s) {}",
            gt.display(),
            extra.join(", ")
        ));
    }
    Err(Error::input(format!(
        "{}; sequences pair by name (SEQ/gt/gt.txt with SEQ.txt): rename or remove the \
         unpaired files, or score one pair with --gt FILE --pred FILE",
        problems.join("; ")
    )))
}

/// The ground-truth sequences of `gt` by name: a file; a sequence folder (`gt/gt.txt` or
/// `gt.txt` in it); or a folder of sequence folders and ground-truth files.
fn gt_sequences(gt: &Path) -> Result<Vec<(String, PathBuf)>> {
    if !gt.exists() {
        return Err(Error::input(format!(
            "--gt {} does not exist",
            gt.display()
        )));
    }
    if !gt.is_dir() {
        return Ok(vec![(file_sequence_name(gt), gt.to_path_buf())]);
    }
    if let Some(file) = sequence_folder_gt(gt) {
        return Ok(vec![(file_name(gt), file)]);
    }
    let mut sequences = Vec::new();
    for path in folder_entries(gt)? {
        if path.is_dir() {
            if let Some(file) = sequence_folder_gt(&path) {
                sequences.push((file_name(&path), file));
            }
        } else if has_extension(&path, &["txt", "csv"]) {
            sequences.push((file_stem(&path), path));
        }
    }
    if sequences.is_empty() {
        return Err(Error::input(format!(
            "--gt {} holds no sequence: expected sequence folders (SEQ/gt/gt.txt) or \
             ground-truth files (.txt, .csv)",
            gt.display()
        )));
    }
    Ok(sequences)
}

/// The ground-truth file of a MOTChallenge sequence folder, if it is one.
fn sequence_folder_gt(folder: &Path) -> Option<PathBuf> {
    [
        folder.join(MotFileRole::GroundTruth.path_in_sequence()),
        folder.join("gt.txt"),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// The files of a prediction folder by stem (`SEQ.txt` → `SEQ`); a stem twice is an error.
fn files_by_stem(folder: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for path in folder_entries(folder)? {
        if path.is_dir() || !has_extension(&path, &TABLE_EXTENSIONS) {
            continue;
        }
        let stem = file_stem(&path);
        if let Some((_, other)) = files.iter().find(|(s, _)| *s == stem) {
            return Err(Error::input(format!(
                "{} and {} are both predictions for sequence {stem}; keep one",
                other.display(),
                path.display()
            )));
        }
        files.push((stem, path));
    }
    Ok(files)
}

/// The entries of `folder` in name order, hidden ones left out.
fn folder_entries(folder: &Path) -> Result<Vec<PathBuf>> {
    let mut paths = Vec::new();
    let cannot_list =
        |e: std::io::Error| Error::input(format!("cannot list {}: {e}", folder.display()));
    for entry in std::fs::read_dir(folder).map_err(cannot_list)? {
        let path = entry.map_err(cannot_list)?.path();
        if !file_name(&path).starts_with('.') {
            paths.push(path);
        }
    }
    paths.sort();
    Ok(paths)
}

/// The last component of `path` (empty for none).
fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The file name of `path` without its extension.
fn file_stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The sequence a ground-truth file is named after: the folder of a `gt.txt` (above a `gt`
/// folder, as in `SEQ/gt/gt.txt`), else the file's stem.
fn file_sequence_name(path: &Path) -> String {
    if !file_name(path).eq_ignore_ascii_case("gt.txt") {
        return file_stem(path);
    }
    let mut folder = path.parent();
    if folder.is_some_and(|f| file_name(f).eq_ignore_ascii_case("gt")) {
        folder = folder.and_then(Path::parent);
    }
    folder
        .map(file_name)
        .filter(|name| !name.is_empty())
        .unwrap_or_else(|| file_stem(path))
}
