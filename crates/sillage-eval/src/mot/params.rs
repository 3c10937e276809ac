//! The matching threshold and the reference evaluator whose conventions CLEAR MOT and
//! Identity follow (`../shared/reference/metric-conventions.md`, §2.3).

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

/// Which reference evaluator's conventions to follow where TrackEval and py-motmetrics
/// 1.4.0 differ. HOTA exists only in TrackEval's form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MotConvention {
    /// TrackEval (the default, MOTChallenge's official evaluator): a pair matches when
    /// `similarity ≥ threshold − ε` (Identity: `≥ threshold`); matching favours the pair of
    /// the immediately previous frame; MT is a tracked ratio `> 0.8`, PT `0.2 ≤ r ≤ 0.8`;
    /// Frag counts track restarts minus one; a frame without estimates (or without truth)
    /// leaves the continuation state untouched.
    #[default]
    TrackEval,
    /// py-motmetrics 1.4.0: a pair matches when `1 − similarity ≤ 1 − threshold`; the last
    /// pair of a true object is kept first whenever still allowed, even across gaps, then
    /// the rest is matched with as many pairs as possible at least total `1 − similarity`;
    /// MT is `r ≥ 0.8`, PT `0.2 ≤ r < 0.8`; Frag counts tracked → missed transitions
    /// inside each true object's tracked span.
    PyMotMetrics,
}

impl MotConvention {
    /// Whether a pair at `similarity` may be matched by CLEAR MOT at `threshold`.
    pub(crate) fn clear_allows(self, similarity: f64, threshold: f64) -> bool {
        match self {
            MotConvention::TrackEval => similarity >= threshold - f64::EPSILON,
            MotConvention::PyMotMetrics => 1.0 - similarity <= 1.0 - threshold,
        }
    }

    /// Whether a pair at `similarity` counts toward Identity's co-occurrences.
    pub(crate) fn identity_allows(self, similarity: f64, threshold: f64) -> bool {
        match self {
            MotConvention::TrackEval => similarity >= threshold,
            MotConvention::PyMotMetrics => self.clear_allows(similarity, threshold),
        }
    }

    /// The name shown in tables.
    pub fn label(self) -> &'static str {
        match self {
            MotConvention::TrackEval => "TrackEval",
            MotConvention::PyMotMetrics => "py-motmetrics",
        }
    }
}

/// Parameters of CLEAR MOT and Identity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MotParams {
    /// Least similarity of a match: 0.5, the value of both references (IoU ≥ 0.5, or
    /// distance ≤ half of `zero_distance_px`). The MMPF+ paper uses 0.43 with disc IoU.
    pub threshold: f64,
    /// Whose conventions to follow where the references differ.
    pub convention: MotConvention,
}

impl Default for MotParams {
    fn default() -> Self {
        Self {
            threshold: 0.5,
            convention: MotConvention::TrackEval,
        }
    }
}

impl MotParams {
    /// Checks `threshold` (a number in `(0, 1]`).
    pub fn validate(&self) -> Result<()> {
        if self.threshold > 0.0 && self.threshold <= 1.0 {
            Ok(())
        } else {
            Err(Error::parameter(
                "threshold",
                self.threshold,
                "must be a similarity in (0, 1], e.g. 0.5",
            ))
        }
    }
}
