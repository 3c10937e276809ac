//! Parameters chosen on some sequences and reported on others (issue 33's validation
//! protocol): every combination of a grid of settings is benched on every sequence, then for
//! each reported sequence the combination with the best mean `(MOTA + IDF1) / 2` on the
//! tuning sequences — never the reported one — is scored on it, beside SORT and ByteTrack.
//! The default split is leave one sequence out.

use std::path::Path;

use serde::Serialize;
use sillage_core::{Error, Result};
use sillage_track::immpf::ModelName;

use super::immpf::{BenchInput, BenchProgress, Row, RunScores, bench};
use crate::pedestrian::ImmpfSettings;
use crate::pedestrian::immpf::Scene;

/// One key of a grid and the values it takes (`--grid KEY=V1,V2`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridAxis {
    /// The parameter's key, as `--set` takes it.
    pub key: String,
    /// Its values, as text.
    pub values: Vec<String>,
}

impl GridAxis {
    /// Parses `KEY=V1,V2,…`; the error names the text and the form expected.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            Error::input(format!(
                "--grid {text:?}: expected KEY=V1,V2,… (e.g. tracker.detection.min_hits=3,4,5)"
            ))
        };
        let (key, values) = text.split_once('=').ok_or_else(bad)?;
        let values: Vec<String> = values.split(',').map(|v| v.trim().to_owned()).collect();
        if key.trim().is_empty() || values.iter().any(String::is_empty) {
            return Err(bad());
        }
        Ok(Self {
            key: key.trim().to_owned(),
            values,
        })
    }
}

/// Every combination of the axes' values, first axis slowest, as `KEY=VALUE` overrides; one
/// empty combination without axes.
pub fn grid_combinations(axes: &[GridAxis]) -> Vec<Vec<String>> {
    axes.iter().fold(vec![Vec::new()], |done, axis| {
        done.iter()
            .flat_map(|prefix| {
                axis.values.iter().map(move |v| {
                    let mut next = prefix.clone();
                    next.push(format!("{}={v}", axis.key));
                    next
                })
            })
            .collect()
    })
}

/// Which sequences choose and which are reported.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Split {
    /// Each sequence reported with the choice made on all the others.
    LeaveOneOut,
    /// One choice made on these sequences (by name), reported on every other one.
    TuneOn(Vec<String>),
}

/// One reported sequence.
#[derive(Debug, Clone, Serialize)]
pub struct HeldOutRow {
    /// The reported sequence.
    pub sequence: String,
    /// The sequences the choice was made on.
    pub tuned_on: Vec<String>,
    /// The chosen combination (`KEY=VALUE` overrides).
    pub chosen: Vec<String>,
    /// Its mean `(MOTA + IDF1) / 2` over the tuning sequences, %.
    pub tuning_score: f64,
    /// Its scores on the reported sequence (medians over the runs).
    pub held_out: RunScores,
    /// SORT on the reported sequence, when it has detections.
    pub sort: Option<RunScores>,
    /// ByteTrack on the reported sequence, when it has detections.
    pub bytetrack: Option<RunScores>,
}

/// `(MOTA + IDF1) / 2`, the criterion the choice maximises.
pub fn criterion(scores: &RunScores) -> f64 {
    0.5 * (scores.mota + scores.idf1)
}

/// The rows of one bench run per combination (`per_combination[c]`, in the order of
/// `combinations`), each with one tracker row per sequence (the first also with the SORT and
/// ByteTrack rows), split by `split`. Ties go to the earlier combination.
pub fn choose_and_report(
    combinations: &[Vec<String>],
    per_combination: &[Vec<Row>],
    split: &Split,
) -> Result<Vec<HeldOutRow>> {
    assert_eq!(
        combinations.len(),
        per_combination.len(),
        "one bench run per combination"
    );
    let Some(first) = per_combination.first() else {
        return Ok(Vec::new());
    };
    let is_baseline = |row: &Row| matches!(row.models.as_str(), "SORT" | "ByteTrack");
    let sequences: Vec<String> = first
        .iter()
        .filter(|r| !is_baseline(r))
        .map(|r| r.sequence.clone())
        .collect();
    if let Split::TuneOn(names) = split
        && let Some(missing) = names.iter().find(|n| !sequences.contains(n))
    {
        return Err(Error::input(format!(
            "--tune-on {missing}: no such sequence among those benched ({}); name sequence \
             folders given on the command line",
            sequences.join(", ")
        )));
    }
    let score = |c: usize, sequence: &str, label: Option<&str>| -> Option<RunScores> {
        per_combination[c]
            .iter()
            .find(|r| {
                r.sequence == sequence
                    && match label {
                        Some(l) => r.models == l,
                        None => !is_baseline(r),
                    }
            })
            .map(|r| r.median)
    };
    let choose = |tune: &[String]| -> Option<(usize, f64)> {
        (0..combinations.len())
            .map(|c| {
                let total: f64 = tune
                    .iter()
                    .map(|s| score(c, s, None).map_or(f64::NAN, |r| criterion(&r)))
                    .sum();
                (c, total / tune.len() as f64)
            })
            .filter(|(_, mean)| !mean.is_nan())
            .fold(None, |best, (c, mean)| match best {
                Some((_, b)) if mean <= b => best,
                _ => Some((c, mean)),
            })
    };
    let mut rows = Vec::new();
    for sequence in &sequences {
        let tune: Vec<String> = match split {
            Split::LeaveOneOut => sequences
                .iter()
                .filter(|s| *s != sequence)
                .cloned()
                .collect(),
            Split::TuneOn(names) if names.contains(sequence) => continue,
            Split::TuneOn(names) => names.clone(),
        };
        if tune.is_empty() {
            return Err(Error::input(
                "leave-one-out needs at least two sequences: give more sequence folders, or \
                 --tune-on NAME to choose on some and report on the others",
            ));
        }
        let Some((chosen, tuning_score)) = choose(&tune) else {
            continue;
        };
        let held_out = score(chosen, sequence, None).expect("every combination has every row");
        rows.push(HeldOutRow {
            sequence: sequence.clone(),
            tuned_on: tune,
            chosen: combinations[chosen].clone(),
            tuning_score,
            held_out,
            sort: score(0, sequence, Some("SORT")),
            bytetrack: score(0, sequence, Some("ByteTrack")),
        });
    }
    Ok(rows)
}

/// What [`bench_held_out`] reports as it goes.
pub enum HeldOutProgress<'a> {
    /// A grid combination starts (0-based index, of `total`).
    Combination {
        /// Its index.
        index: usize,
        /// How many there are.
        total: usize,
        /// Its `KEY=VALUE` overrides.
        overrides: &'a [String],
    },
    /// Progress of that combination's bench.
    Bench(BenchProgress<'a>),
}

/// [`bench`](fn@bench) of the model combination `models` on every sequence folder for every combination
/// of `axes` (each applied as `--set` overrides after `config` and `overrides`), then
/// [`choose_and_report`] by `split`.
#[allow(clippy::too_many_arguments)]
pub fn bench_held_out(
    folders: &[impl AsRef<Path>],
    input: BenchInput,
    config: Option<&Path>,
    overrides: &[String],
    axes: &[GridAxis],
    split: &Split,
    scene: &Scene,
    models: &[Vec<ModelName>],
    runs: usize,
    on_progress: &mut dyn FnMut(HeldOutProgress),
) -> Result<Vec<HeldOutRow>> {
    if models.len() != 1 {
        return Err(Error::input(format!(
            "choosing settings on some sequences and reporting on others benches one model \
             combination; got {} (give --models with one, e.g. --models CV_CA)",
            models.len()
        )));
    }
    let combinations = grid_combinations(axes);
    let mut per_combination = Vec::with_capacity(combinations.len());
    for (index, combination) in combinations.iter().enumerate() {
        on_progress(HeldOutProgress::Combination {
            index,
            total: combinations.len(),
            overrides: combination,
        });
        let all: Vec<String> = overrides.iter().chain(combination).cloned().collect();
        let settings = ImmpfSettings::load(config, &all, None)?;
        // The baselines do not depend on the grid: benched with the first combination only.
        let input = BenchInput {
            skip_baselines: index > 0,
            ..input
        };
        per_combination.push(bench(
            folders,
            input,
            &settings,
            scene,
            models,
            runs,
            &mut |p| on_progress(HeldOutProgress::Bench(p)),
        )?);
    }
    choose_and_report(&combinations, &per_combination, split)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(sequence: &str, models: &str, mota: f64, idf1: f64) -> Row {
        Row {
            sequence: sequence.into(),
            models: models.into(),
            runs: 1,
            median: RunScores {
                mota,
                idf1,
                ..RunScores::default()
            },
        }
    }

    #[test]
    fn grids_parse_and_combine_first_axis_slowest() {
        let axes = [
            GridAxis::parse("a.b=1,2").unwrap(),
            GridAxis::parse("c=x,y,z").unwrap(),
        ];
        let all = grid_combinations(&axes);
        assert_eq!(all.len(), 6);
        assert_eq!(all[0], ["a.b=1", "c=x"]);
        assert_eq!(all[5], ["a.b=2", "c=z"]);
        assert_eq!(grid_combinations(&[]), vec![Vec::<String>::new()]);
        for bad in ["a.b", "=1,2", "a=1,,2", "a="] {
            let e = GridAxis::parse(bad).unwrap_err().to_string();
            assert!(e.contains("KEY=V1,V2"), "{bad}: {e}");
        }
    }

    #[test]
    fn each_sequence_is_reported_with_the_choice_of_the_others() {
        // Combination 0 wins on A and B, combination 1 on C by more: held out, A and B take
        // combination 1 (its mean with C is the higher) and C takes combination 0.
        let combos = vec![vec!["k=0".to_string()], vec!["k=1".to_string()]];
        let runs = vec![
            vec![
                row("A", "CV_CA", 90.0, 90.0),
                row("B", "CV_CA", 80.0, 80.0),
                row("C", "CV_CA", 40.0, 40.0),
                row("C", "SORT", 60.0, 60.0),
            ],
            vec![
                row("A", "CV_CA", 70.0, 70.0),
                row("B", "CV_CA", 50.0, 50.0),
                row("C", "CV_CA", 90.0, 90.0),
            ],
        ];
        let rows = choose_and_report(&combos, &runs, &Split::LeaveOneOut).unwrap();
        let chosen: Vec<(&str, &str, f64)> = rows
            .iter()
            .map(|r| (r.sequence.as_str(), r.chosen[0].as_str(), r.held_out.mota))
            .collect();
        assert_eq!(
            chosen,
            [("A", "k=1", 70.0), ("B", "k=1", 50.0), ("C", "k=0", 40.0)]
        );
        assert_eq!(rows[2].tuned_on, ["A", "B"]);
        assert_eq!(rows[2].sort.unwrap().mota, 60.0);
        assert!(rows[0].sort.is_none());
        // One choice on A alone, reported on B and C.
        let rows = choose_and_report(&combos, &runs, &Split::TuneOn(vec!["A".into()])).unwrap();
        let reported: Vec<_> = rows
            .iter()
            .map(|r| (r.sequence.as_str(), r.held_out.mota))
            .collect();
        assert_eq!(reported, [("B", 80.0), ("C", 40.0)]);
        let e = choose_and_report(&combos, &runs, &Split::TuneOn(vec!["D".into()]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--tune-on D") && e.contains("A, B, C"), "{e}");
        let one_sequence = vec![runs[0][..1].to_vec()];
        let e = choose_and_report(&combos[..1], &one_sequence, &Split::LeaveOneOut)
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least two sequences"), "{e}");
    }
}
