//! The papers' scores of one sequence together, their combination over sequences, and the
//! tables of a multi-sequence evaluation (as [`MotReport`](crate::mot::MotReport) for CLEAR
//! MOT, Identity and HOTA).

use std::fmt;

use serde::Serialize;
use sillage_core::Result;

use super::bedload::{
    BedloadScores, MotionStateScores, StateLabel, bedload_scores, motion_state_scores,
};
use super::etiseo::{EtiseoMetrics, etiseo};
use super::vace::{VaceMetrics, vace};
use crate::mot::{FrameEvents, MotData};
use crate::summary::{FamilyColumns, Table, family_tables};

/// Every paper's own scores of one sequence (or of several combined).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PaperMetrics {
    /// MMPF+ paper §5.3: correct tracks, FN and FP rates.
    pub bedload: BedloadScores,
    /// MMPF+ paper §5.3, Fig. 7: motion-state scores, when states were given.
    pub motion_states: Option<MotionStateScores>,
    /// IMM-PF paper §5.2: SFDA, ATA, N-MODP, MOTP.
    pub vace: VaceMetrics,
    /// SIFT-PF paper §3: ETISEO M1, M2, M3 and their mean.
    pub etiseo: EtiseoMetrics,
}

impl PaperMetrics {
    /// Scores one sequence: `events` is the CLEAR MOT matching of `data`
    /// ([`clear_events`](crate::mot::clear_events)); `states`, the true and estimated motion
    /// states, adds the motion-state scores.
    pub fn new(
        data: &MotData,
        events: &[FrameEvents],
        states: Option<(&[StateLabel], &[StateLabel])>,
    ) -> Result<Self> {
        let motion_states = match states {
            Some((truth, estimates)) => Some(motion_state_scores(events, truth, estimates)?),
            None => None,
        };
        Ok(Self {
            bedload: bedload_scores(events),
            motion_states,
            vace: vace(data),
            etiseo: etiseo(events),
        })
    }

    /// Combines sequences, each family with its own `combine` (motion states over the
    /// sequences that have them).
    pub fn combine(sequences: &[PaperMetrics]) -> PaperMetrics {
        let bedload: Vec<BedloadScores> = sequences.iter().map(|s| s.bedload).collect();
        let states: Vec<MotionStateScores> =
            sequences.iter().filter_map(|s| s.motion_states).collect();
        let vace: Vec<VaceMetrics> = sequences.iter().map(|s| s.vace).collect();
        let etiseo: Vec<EtiseoMetrics> = sequences.iter().map(|s| s.etiseo).collect();
        PaperMetrics {
            bedload: BedloadScores::combine(&bedload),
            motion_states: (!states.is_empty()).then(|| MotionStateScores::combine(&states)),
            vace: VaceMetrics::combine(&vace),
            etiseo: EtiseoMetrics::combine(&etiseo),
        }
    }
}

/// The papers' scores of several named sequences and their combination. Displays one table
/// per paper, a row per sequence and a `COMBINED` row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PapersReport {
    /// Each sequence by name, in the order given.
    pub sequences: Vec<(String, PaperMetrics)>,
    /// All sequences combined ([`PaperMetrics::combine`]).
    pub combined: PaperMetrics,
}

impl PapersReport {
    /// The report of `sequences`, with their combination.
    pub fn new(sequences: Vec<(String, PaperMetrics)>) -> Self {
        let metrics: Vec<PaperMetrics> = sequences.iter().map(|(_, m)| *m).collect();
        let combined = PaperMetrics::combine(&metrics);
        Self {
            sequences,
            combined,
        }
    }
}

impl fmt::Display for PapersReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let rows: Vec<(&str, &PaperMetrics)> = self
            .sequences
            .iter()
            .map(|(name, m)| (name.as_str(), m))
            .chain([("COMBINED", &self.combined)])
            .collect();
        let c = &self.combined;
        let mut families: Vec<(String, FamilyColumns<PaperMetrics>)> =
            vec![(c.bedload.title(), |m| Some(m.bedload.columns()))];
        if let Some(states) = &c.motion_states {
            families.push((states.title(), |m| m.motion_states.map(|s| s.columns())));
        }
        family_tables(f, &rows, &families)?;
        if let Some(states) = &c.motion_states {
            writeln!(f, "\n{}", states.confusion_title())?;
            write!(f, "{}", confusion_table(&rows))?;
        }
        writeln!(f)?;
        family_tables(
            f,
            &rows,
            &[
                (c.vace.title(), |m| Some(m.vace.columns())),
                (c.etiseo.title(), |m| Some(m.etiseo.columns())),
            ],
        )
    }
}

/// The confusion matrices of the rows that have motion states, one after the other: the
/// sequence's name on its first line, then the true state and the counts of each estimated
/// state.
fn confusion_table(rows: &[(&str, &PaperMetrics)]) -> Table {
    let header = ["sequence", "true"]
        .into_iter()
        .chain(MotionStateScores::CONFUSION_COLUMNS);
    let mut table = Table::new(header.map(str::to_owned));
    for (name, m) in rows {
        let Some(states) = &m.motion_states else {
            continue;
        };
        for (i, row) in states.confusion_rows().enumerate() {
            let label = if i == 0 { *name } else { "" };
            table.push(std::iter::once(label.to_owned()).chain(row));
        }
    }
    table
}
