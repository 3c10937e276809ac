//! The ETISEO tracking scores the SIFT-PF paper reports (Souded, Giulieri & Bremond, "An
//! object tracking in particle filtering and data association framework, using SIFT
//! features", ICDP 2011, §3, Tables 3–4): M1 tracking time, M2 object ID persistence, M3
//! object ID confusion and their mean M̄, as defined by the ETISEO benchmark (Nghiem et al.,
//! AVSS 2007) and used by Chau et al. (the paper's ref. 34).
//!
//! A reference (true) object is tracked in a frame when the CLEAR MOT matching
//! ([`clear_events`](crate::mot::clear_events)) pairs it with a tracked object (estimate);
//! ETISEO's own per-frame test is an overlap criterion, of which the similarity threshold of
//! `MotParams` is the counterpart.

use serde::Serialize;

use super::tally::TrajectoryTally;
use crate::mot::FrameEvents;
use crate::summary::{Table, count, score};

/// ETISEO M1–M3 of one sequence, or of several ([`EtiseoMetrics::combine`]); all in
/// `[0, 1]`, 1 best.
///
/// Each score is a mean over objects; the sums and counts are kept so that sequences
/// combine as one longer sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EtiseoMetrics {
    /// Reference (true) objects.
    pub reference_objects: u64,
    /// `Σ` over reference objects of their tracking time share (M1's numerator).
    pub tracking_time_sum: f64,
    /// Reference objects tracked at least once (M2's denominator).
    pub tracked_references: u64,
    /// `Σ` over them of `1 / (tracked objects associated with it)` (M2's numerator).
    pub persistence_sum: f64,
    /// Tracked objects associated with some reference object (M3's denominator).
    pub associated_tracks: u64,
    /// `Σ` over them of `1 / (reference objects associated with it)` (M3's numerator).
    pub confusion_sum: f64,
    /// M1, tracking time: mean over reference objects of the share of their frames in which
    /// they are tracked by the tracked object that tracks them longest.
    pub tracking_time: f64,
    /// M2, object ID persistence: mean over tracked reference objects of
    /// `1 / (number of tracked objects associated with it)`.
    pub id_persistence: f64,
    /// M3, object ID confusion: mean over associated tracked objects of
    /// `1 / (number of reference objects associated with it)`.
    pub id_confusion: f64,
    /// `M̄ = (M1 + M2 + M3) / 3`.
    pub mean: f64,
}

/// Scores the CLEAR MOT `events` of one sequence with ETISEO's M1–M3 (SIFT-PF paper §3).
///
/// - **M1, tracking time**, "the percentage of time during which a reference object is
///   tracked": per reference object, the frames in which it is matched to the one tracked
///   object it is matched to longest (ETISEO keeps "the tracked object which has the
///   greatest intersection time interval with the reference"), over its frames; then the
///   mean over reference objects (0 for one never tracked).
/// - **M2, object ID persistence**, "how many tracked objects are associated with one
///   reference object": the mean of `1 / n` over the reference objects tracked at least once,
///   `n` the number of distinct tracked objects matched to it.
/// - **M3, object ID confusion**, "the number of reference object IDs per tracked object":
///   the mean of `1 / n` over the tracked objects matched at least once, `n` the number of
///   distinct reference objects matched to it.
///
/// M2 and M3 leave out the objects never matched: misses and false tracks are M1's and
/// CLEAR MOT's business, and "these metrics must be used together". A mean without objects
/// is 0.
pub fn etiseo(events: &[FrameEvents]) -> EtiseoMetrics {
    let tally = TrajectoryTally::new(events);
    let mut sums = EtiseoSums {
        reference_objects: tally.truths.len() as u64,
        associated_tracks: tally.estimate_partners.len() as u64,
        ..EtiseoSums::default()
    };
    for t in &tally.truths {
        sums.tracking_time_sum += t.longest_partner_frames as f64 / t.present as f64;
        if t.partners > 0 {
            sums.tracked_references += 1;
            sums.persistence_sum += 1.0 / t.partners as f64;
        }
    }
    for &n in &tally.estimate_partners {
        sums.confusion_sum += 1.0 / n as f64;
    }
    EtiseoMetrics::from_sums(sums)
}

/// The additive fields of [`EtiseoMetrics`].
#[derive(Debug, Clone, Copy, Default)]
struct EtiseoSums {
    reference_objects: u64,
    tracking_time_sum: f64,
    tracked_references: u64,
    persistence_sum: f64,
    associated_tracks: u64,
    confusion_sum: f64,
}

impl EtiseoMetrics {
    fn from_sums(s: EtiseoSums) -> Self {
        let mean = |sum: f64, n: u64| if n > 0 { sum / n as f64 } else { 0.0 };
        let tracking_time = mean(s.tracking_time_sum, s.reference_objects);
        let id_persistence = mean(s.persistence_sum, s.tracked_references);
        let id_confusion = mean(s.confusion_sum, s.associated_tracks);
        Self {
            reference_objects: s.reference_objects,
            tracking_time_sum: s.tracking_time_sum,
            tracked_references: s.tracked_references,
            persistence_sum: s.persistence_sum,
            associated_tracks: s.associated_tracks,
            confusion_sum: s.confusion_sum,
            tracking_time,
            id_persistence,
            id_confusion,
            mean: (tracking_time + id_persistence + id_confusion) / 3.0,
        }
    }

    /// Combines sequences: sums the per-object sums and counts, then recomputes the means
    /// (every object of every sequence weighs the same).
    pub fn combine(sequences: &[EtiseoMetrics]) -> EtiseoMetrics {
        let mut s = EtiseoSums::default();
        for m in sequences {
            s.reference_objects += m.reference_objects;
            s.tracking_time_sum += m.tracking_time_sum;
            s.tracked_references += m.tracked_references;
            s.persistence_sum += m.persistence_sum;
            s.associated_tracks += m.associated_tracks;
            s.confusion_sum += m.confusion_sum;
        }
        EtiseoMetrics::from_sums(s)
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        "ETISEO, SIFT-PF paper §3 (CLEAR MOT matching; scores in %)".to_owned()
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        vec![
            ("M1", score(self.tracking_time)),
            ("M2", score(self.id_persistence)),
            ("M3", score(self.id_confusion)),
            ("Mean", score(self.mean)),
            ("RefObjects", count(self.reference_objects)),
            ("Tracks", count(self.associated_tracks)),
        ]
    }
}

impl std::fmt::Display for EtiseoMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        Table::single(&self.columns()).fmt(f)
    }
}
