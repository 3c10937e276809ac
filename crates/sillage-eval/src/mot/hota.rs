//! HOTA, Higher Order Tracking Accuracy (Luiten et al., IJCV 129, 2021), exactly as its
//! reference implementation TrackEval `metrics/hota.py` computes it: per localisation
//! threshold α ∈ {0.05, 0.10, …, 0.95}, a per-frame matching that maximises
//! `global alignment × similarity`, then DetA, AssA and their geometric mean, averaged over
//! α.
//!
//! The global counts (co-occurrences and matches per (true id, estimate id) pair) are hash
//! maps over the pairs that occur, so a sequence costs time linear in its rows when few
//! objects overlap each frame.

use serde::Serialize;

use super::assignment::{Edge, Matcher, Objective};
use super::data::MotData;
use super::ids::{IdMap, pair_key, split_pair_key};

/// Number of localisation thresholds α.
pub const HOTA_ALPHA_COUNT: usize = 19;

/// The localisation thresholds α = 0.05, 0.10, …, 0.95, computed as NumPy's
/// `np.arange(0.05, 0.99, 0.05)` does (`0.05 + i · 0.05`), so that threshold ties fall the
/// same way as in TrackEval.
pub fn hota_alphas() -> [f64; HOTA_ALPHA_COUNT] {
    std::array::from_fn(|i| 0.05 + i as f64 * 0.05)
}

/// Values per α (index `i` is α = `alpha[i]`).
pub type PerAlpha<T> = [T; HOTA_ALPHA_COUNT];

/// The HOTA family at every α.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HotaCurves {
    /// The thresholds α.
    pub alpha: PerAlpha<f64>,
    /// `√(DetA · AssA)`.
    pub hota: PerAlpha<f64>,
    /// Detection accuracy `TP / (TP + FN + FP)`.
    pub det_a: PerAlpha<f64>,
    /// Association accuracy: mean over true positives of `TPA / (TPA + FNA + FPA)`.
    pub ass_a: PerAlpha<f64>,
    /// Detection recall `TP / (TP + FN)`.
    pub det_re: PerAlpha<f64>,
    /// Detection precision `TP / (TP + FP)`.
    pub det_pr: PerAlpha<f64>,
    /// Association recall: mean over true positives of `TPA / (TPA + FNA)`.
    pub ass_re: PerAlpha<f64>,
    /// Association precision: mean over true positives of `TPA / (TPA + FPA)`.
    pub ass_pr: PerAlpha<f64>,
    /// Localisation accuracy: mean similarity of the true positives (1 without any).
    pub loc_a: PerAlpha<f64>,
    /// Open-world tracking accuracy `√(DetRe · AssA)` (TrackEval's `OWTA`, formerly `RHOTA`).
    pub owta: PerAlpha<f64>,
    /// True positives.
    pub true_positives: PerAlpha<u64>,
    /// False negatives.
    pub false_negatives: PerAlpha<u64>,
    /// False positives.
    pub false_positives: PerAlpha<u64>,
}

/// HOTA scores of one sequence, or of several combined ([`HotaMetrics::combine`]): the
/// summary values are means over α, as TrackEval reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HotaMetrics {
    /// HOTA, mean over α.
    pub hota: f64,
    /// DetA, mean over α.
    pub det_a: f64,
    /// AssA, mean over α.
    pub ass_a: f64,
    /// DetRe, mean over α.
    pub det_re: f64,
    /// DetPr, mean over α.
    pub det_pr: f64,
    /// AssRe, mean over α.
    pub ass_re: f64,
    /// AssPr, mean over α.
    pub ass_pr: f64,
    /// LocA, mean over α.
    pub loc_a: f64,
    /// OWTA, mean over α.
    pub owta: f64,
    /// HOTA at the lowest α (0.05): association and detection with almost no
    /// localisation requirement.
    pub hota_0: f64,
    /// LocA at the lowest α.
    pub loc_a_0: f64,
    /// `HOTA(0) · LocA(0)`.
    pub hota_loc_a_0: f64,
    /// Every value at every α.
    pub per_alpha: HotaCurves,
}

/// Scores `data` with HOTA (see the module docs).
pub fn hota(data: &MotData) -> HotaMetrics {
    let alphas = hota_alphas();
    let truth_frames = count_frames(
        data.truth_id_count(),
        data.frames().flat_map(|f| f.truth_ids),
    );
    let estimate_frames = count_frames(
        data.estimate_id_count(),
        data.frames().flat_map(|f| f.estimate_ids),
    );

    // Global alignment of every co-occurring pair: the Jaccard index of their co-occurrence,
    // each frame weighted by the pair's share of the similarity of its row and column
    // (hota.py's `potential_matches_count` / `global_alignment_score`).
    let mut alignment: IdMap<u64, f64> = IdMap::default();
    let (mut row_sum, mut col_sum) = (Vec::new(), Vec::new());
    for frame in data.frames() {
        row_sum.clear();
        row_sum.resize(frame.truth_ids.len(), 0.0);
        col_sum.clear();
        col_sum.resize(frame.estimate_ids.len(), 0.0);
        for p in frame.pairs {
            row_sum[p.truth as usize] += p.similarity;
            col_sum[p.estimate as usize] += p.similarity;
        }
        for p in frame.pairs {
            let denominator =
                col_sum[p.estimate as usize] + row_sum[p.truth as usize] - p.similarity;
            if denominator > f64::EPSILON {
                let key = pair_key(
                    frame.truth_ids[p.truth as usize],
                    frame.estimate_ids[p.estimate as usize],
                );
                *alignment.entry(key).or_insert(0.0) += p.similarity / denominator;
            }
        }
    }
    for (&key, value) in alignment.iter_mut() {
        let (g, t) = split_pair_key(key);
        let both = f64::from(truth_frames[g as usize]) + f64::from(estimate_frames[t as usize]);
        *value /= both - *value;
    }

    // Per frame: the matching, then the true positives at each α.
    let mut counts = AlphaCounts::default();
    let mut pair_matches: IdMap<u64, u32> = IdMap::default();
    let mut histograms: Vec<PerAlpha<u32>> = Vec::new();
    let (mut matcher, mut edges, mut edge_similarity, mut matched) =
        (Matcher::default(), Vec::new(), Vec::new(), Vec::new());
    for frame in data.frames() {
        edges.clear();
        edge_similarity.clear();
        for p in frame.pairs {
            let key = pair_key(
                frame.truth_ids[p.truth as usize],
                frame.estimate_ids[p.estimate as usize],
            );
            let score = alignment.get(&key).copied().unwrap_or(0.0) * p.similarity;
            if score > 0.0 {
                edges.push(Edge {
                    row: p.truth,
                    col: p.estimate,
                    value: score,
                });
                edge_similarity.push(p.similarity);
            }
        }
        let (n, m) = (frame.truth_ids.len(), frame.estimate_ids.len());
        matcher.solve(n, m, &edges, Objective::MaxWeight, &mut matched);
        let mut frame_tp = [0u64; HOTA_ALPHA_COUNT];
        for &k in &matched {
            let similarity = edge_similarity[k];
            // The α at which this match still counts: a prefix of the increasing α.
            let passed = alphas
                .iter()
                .take_while(|&&alpha| similarity >= alpha - f64::EPSILON)
                .count();
            if passed == 0 {
                continue;
            }
            for (tp, sum) in frame_tp
                .iter_mut()
                .zip(&mut counts.similarity_sum)
                .take(passed)
            {
                *tp += 1;
                *sum += similarity;
            }
            let e = edges[k];
            let key = pair_key(
                frame.truth_ids[e.row as usize],
                frame.estimate_ids[e.col as usize],
            );
            let slot = *pair_matches.entry(key).or_insert_with(|| {
                histograms.push([0; HOTA_ALPHA_COUNT]);
                (histograms.len() - 1) as u32
            });
            histograms[slot as usize][passed - 1] += 1;
        }
        for (a, &tp) in frame_tp.iter().enumerate() {
            counts.true_positives[a] += tp;
            counts.false_negatives[a] += n as u64 - tp;
            counts.false_positives[a] += m as u64 - tp;
        }
    }

    // Association scores: per pair, its matches at α are those that passed α or more.
    let (mut ass_a, mut ass_re, mut ass_pr) = (
        [0.0; HOTA_ALPHA_COUNT],
        [0.0; HOTA_ALPHA_COUNT],
        [0.0; HOTA_ALPHA_COUNT],
    );
    let mut pairs: Vec<(u64, u32)> = pair_matches.into_iter().collect();
    pairs.sort_unstable_by_key(|&(key, _)| key);
    for (key, slot) in pairs {
        let (g, t) = split_pair_key(key);
        let gt = f64::from(truth_frames[g as usize]);
        let tr = f64::from(estimate_frames[t as usize]);
        let mut at_or_above = 0u32;
        for a in (0..HOTA_ALPHA_COUNT).rev() {
            at_or_above += histograms[slot as usize][a];
            let matches = f64::from(at_or_above);
            if at_or_above == 0 {
                continue;
            }
            ass_a[a] += matches * (matches / (gt + tr - matches).max(1.0));
            ass_re[a] += matches * (matches / gt.max(1.0));
            ass_pr[a] += matches * (matches / tr.max(1.0));
        }
    }
    let mut loc_a = [0.0; HOTA_ALPHA_COUNT];
    for a in 0..HOTA_ALPHA_COUNT {
        let tp = (counts.true_positives[a] as f64).max(1.0);
        ass_a[a] /= tp;
        ass_re[a] /= tp;
        ass_pr[a] /= tp;
        loc_a[a] =
            counts.similarity_sum[a].max(1e-10) / (counts.true_positives[a] as f64).max(1e-10);
    }
    HotaMetrics::from_parts(&counts, ass_a, ass_re, ass_pr, loc_a)
}

/// Frames in which each dense id appears.
fn count_frames<'a>(ids: usize, appearances: impl Iterator<Item = &'a u32>) -> Vec<u32> {
    let mut frames = vec![0u32; ids];
    for &id in appearances {
        frames[id as usize] += 1;
    }
    frames
}

/// The summable detection counts per α.
#[derive(Debug, Clone, Copy, Default)]
struct AlphaCounts {
    true_positives: PerAlpha<u64>,
    false_negatives: PerAlpha<u64>,
    false_positives: PerAlpha<u64>,
    similarity_sum: PerAlpha<f64>,
}

impl HotaMetrics {
    /// Every field from the counts and the association and localisation scores per α
    /// (TrackEval's `_compute_final_fields`, then the means over α).
    fn from_parts(
        counts: &AlphaCounts,
        ass_a: PerAlpha<f64>,
        ass_re: PerAlpha<f64>,
        ass_pr: PerAlpha<f64>,
        loc_a: PerAlpha<f64>,
    ) -> Self {
        let per = |f: &dyn Fn(usize) -> f64| -> PerAlpha<f64> { std::array::from_fn(f) };
        let tp = |a: usize| counts.true_positives[a] as f64;
        let fn_ = |a: usize| counts.false_negatives[a] as f64;
        let fp = |a: usize| counts.false_positives[a] as f64;
        let det_re = per(&|a| tp(a) / (tp(a) + fn_(a)).max(1.0));
        let det_pr = per(&|a| tp(a) / (tp(a) + fp(a)).max(1.0));
        let det_a = per(&|a| tp(a) / (tp(a) + fn_(a) + fp(a)).max(1.0));
        let hota = per(&|a| (det_a[a] * ass_a[a]).sqrt());
        let owta = per(&|a| (det_re[a] * ass_a[a]).sqrt());
        let mean = |values: &PerAlpha<f64>| values.iter().sum::<f64>() / HOTA_ALPHA_COUNT as f64;
        HotaMetrics {
            hota: mean(&hota),
            det_a: mean(&det_a),
            ass_a: mean(&ass_a),
            det_re: mean(&det_re),
            det_pr: mean(&det_pr),
            ass_re: mean(&ass_re),
            ass_pr: mean(&ass_pr),
            loc_a: mean(&loc_a),
            owta: mean(&owta),
            hota_0: hota[0],
            loc_a_0: loc_a[0],
            hota_loc_a_0: hota[0] * loc_a[0],
            per_alpha: HotaCurves {
                alpha: hota_alphas(),
                hota,
                det_a,
                ass_a,
                det_re,
                det_pr,
                ass_re,
                ass_pr,
                loc_a,
                owta,
                true_positives: counts.true_positives,
                false_negatives: counts.false_negatives,
                false_positives: counts.false_positives,
            },
        }
    }

    /// Combines sequences as TrackEval's `combine_sequences`: sums TP / FN / FP per α,
    /// averages AssA, AssRe, AssPr and LocA weighted by each sequence's TP, then recomputes
    /// the rest. (Not the mean of the sequences' HOTA.)
    pub fn combine(sequences: &[HotaMetrics]) -> HotaMetrics {
        let mut counts = AlphaCounts::default();
        let (mut ass_a, mut ass_re, mut ass_pr, mut loc_a) = (
            [0.0; HOTA_ALPHA_COUNT],
            [0.0; HOTA_ALPHA_COUNT],
            [0.0; HOTA_ALPHA_COUNT],
            [0.0; HOTA_ALPHA_COUNT],
        );
        for s in sequences {
            let c = &s.per_alpha;
            for a in 0..HOTA_ALPHA_COUNT {
                counts.true_positives[a] += c.true_positives[a];
                counts.false_negatives[a] += c.false_negatives[a];
                counts.false_positives[a] += c.false_positives[a];
                let weight = c.true_positives[a] as f64;
                ass_a[a] += c.ass_a[a] * weight;
                ass_re[a] += c.ass_re[a] * weight;
                ass_pr[a] += c.ass_pr[a] * weight;
                loc_a[a] += c.loc_a[a] * weight;
            }
        }
        for a in 0..HOTA_ALPHA_COUNT {
            let tp = counts.true_positives[a] as f64;
            ass_a[a] /= tp.max(1.0);
            ass_re[a] /= tp.max(1.0);
            ass_pr[a] /= tp.max(1.0);
            loc_a[a] = loc_a[a].max(1e-10) / tp.max(1e-10);
        }
        HotaMetrics::from_parts(&counts, ass_a, ass_re, ass_pr, loc_a)
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        "HOTA (TrackEval; means over α = 0.05..0.95; scores in %)".to_owned()
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        use crate::summary::score;
        vec![
            ("HOTA", score(self.hota)),
            ("DetA", score(self.det_a)),
            ("AssA", score(self.ass_a)),
            ("DetRe", score(self.det_re)),
            ("DetPr", score(self.det_pr)),
            ("AssRe", score(self.ass_re)),
            ("AssPr", score(self.ass_pr)),
            ("LocA", score(self.loc_a)),
            ("OWTA", score(self.owta)),
            ("HOTA(0)", score(self.hota_0)),
            ("LocA(0)", score(self.loc_a_0)),
            ("HOTALocA(0)", score(self.hota_loc_a_0)),
        ]
    }
}

impl std::fmt::Display for HotaMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        crate::summary::Table::single(&self.columns()).fmt(f)
    }
}
