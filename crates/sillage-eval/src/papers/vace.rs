//! The VACE scores the IMM-PF paper reports (Madrigal & Hayet, "Evaluation of multiple
//! motion models for multiple pedestrian visual tracking", §5.2, Tables 1–2): SFDA, ATA,
//! N-MODP and MOTP, as defined by Kasturi et al. ("Framework for performance evaluation of
//! face, text, and vehicle detection and tracking in video", IEEE TPAMI 31(2), 2009) and used
//! by the PETS 2009 evaluation the paper follows (its ref. 3, Ellis & Ferryman 2010).
//!
//! They differ from CLEAR MOT in three ways: objects are mapped by maximising their
//! **overlap** (the similarity, IoU for boxes), with no threshold: any overlap counts, in
//! proportion; scores are **normalised per frame** (SFDA, N-MODP) or **per trajectory**
//! (ATA); and ATA and MOTP map whole trajectories, not objects frame by frame.

use serde::Serialize;

use crate::mot::MotData;
use crate::mot::assignment::{Edge, Matcher, Objective};
use crate::mot::ids::{IdMap, pair_key, split_pair_key};
use crate::summary::{Table, count, score};

/// VACE scores of one sequence, or of several ([`VaceMetrics::combine`]).
///
/// The sums are kept so that sequences combine as TrackEval's `VACE.combine_sequences`
/// (sums, then the ratios).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VaceMetrics {
    /// Frames with a true object or an estimate.
    pub frames: u64,
    /// `Σ_t FDA(t)`.
    pub fda_sum: f64,
    /// Frames with at least one mapped pair.
    pub mapped_frames: u64,
    /// `Σ_t MODP(t)` over those frames.
    pub modp_sum: f64,
    /// True trajectories `N_G`.
    pub truth_tracks: u64,
    /// Estimated trajectories `N_D`.
    pub estimate_tracks: u64,
    /// STDA: the sum over mapped trajectory pairs of their overlap summed over frames,
    /// divided by the frames where either exists.
    pub stda: f64,
    /// Overlap summed over the frames and the mapped trajectory pairs (MOTP's numerator).
    pub track_overlap_sum: f64,
    /// Frames where both trajectories of a mapped pair exist, summed over the pairs
    /// (MOTP's denominator, `Σ_t N_mapped(t)`).
    pub track_mapped_frames: u64,
    /// Sequence Frame Detection Accuracy: `Σ_t FDA(t) / frames`.
    pub sfda: f64,
    /// Average Tracking Accuracy: `STDA / ((N_G + N_D) / 2)`.
    pub ata: f64,
    /// TrackEval's relaxed STDA: as `stda`, with each frame of a pair counting 1 when their
    /// overlap reaches [`RELAXED_OVERLAP`] and 0 otherwise.
    pub stda_relaxed: f64,
    /// TrackEval's relaxed ATA: `stda_relaxed / ((N_G + N_D) / 2)` (TrackEval's `VACE`
    /// reports it as `ATA`).
    pub ata_relaxed: f64,
    /// Normalised Multiple Object Detection Precision: mean `MODP(t)` over the frames with
    /// a mapped pair.
    pub n_modp: f64,
    /// VACE's Multiple Object Tracking Precision: mean overlap of the mapped trajectory
    /// pairs over the frames where both exist (not CLEAR MOT's MOTP).
    pub motp: f64,
}

/// The overlap from which a frame counts 1 in TrackEval's relaxed ATA (its `VACE`
/// threshold).
pub const RELAXED_OVERLAP: f64 = 0.5;

/// Scores `data` with the VACE metrics of the IMM-PF paper (§5.2), all in `[0, 1]`, 1 best.
/// The overlap of a true and an estimated object is their similarity in `data` (IoU with
/// [`Similarity::BoxIou`](crate::mot::Similarity::BoxIou), as the paper).
///
/// Per frame `t` with `N_G(t)` true objects and `N_D(t)` estimates, objects are mapped one to
/// one maximising the summed overlap (pairs that overlap at all; Kasturi et al. §4.1):
/// - `FDA(t) = Σ_mapped overlap / ((N_G(t) + N_D(t)) / 2)`, and
///   `SFDA = Σ_t FDA(t) / (frames with N_G(t) > 0 or N_D(t) > 0)`;
/// - `MODP(t) = Σ_mapped overlap / N_mapped(t)`, and N-MODP is its mean over the frames
///   with `N_mapped(t) > 0`. (Kasturi et al. divide by all frames, but `MODP(t)` is undefined
///   without a mapped pair; averaging over the frames that have one keeps N-MODP a pure
///   precision, as the paper's tables, where N-MODP ≈ MOTP, suggest.)
///
/// Trajectories are mapped one to one maximising the sum of
/// `Σ_t overlap(G_i(t), D_j(t)) / |frames where G_i or D_j exists|` over the pairs (the
/// pairs that overlap in some frame); STDA is that maximum, and
/// - `ATA = STDA / ((N_G + N_D) / 2)`, `N_G`, `N_D` the numbers of true and estimated
///   trajectories;
/// - `MOTP = Σ_mapped Σ_t overlap / Σ_t N_mapped(t)`, `N_mapped(t)` the mapped trajectory
///   pairs that both exist in frame `t`.
///
/// `ata` follows Kasturi et al.; TrackEval's `VACE` gives the same SFDA but a "relaxed" ATA
/// that counts a frame of a pair as 1 when their overlap reaches 0.5 and 0 otherwise (every
/// pair of the frame, not only the mapped ones), trajectories then mapped one to one
/// maximising `Σ_t [overlap ≥ 0.5] / |frames where either exists|`: `ata_relaxed`, so that
/// figures computed by either convention can be compared. A score whose denominator is 0
/// (an empty sequence) is 0.
pub fn vace(data: &MotData) -> VaceMetrics {
    let mut matcher = Matcher::default();
    let mut edges: Vec<Edge> = Vec::new();
    let mut matched = Vec::new();
    // The frames (by position in `data`) where each trajectory exists, in increasing order.
    let mut truth_frames: Vec<Vec<u32>> = vec![Vec::new(); data.truth_id_count()];
    let mut estimate_frames: Vec<Vec<u32>> = vec![Vec::new(); data.estimate_id_count()];
    let mut overlap: IdMap<u64, f64> = IdMap::default();
    let mut relaxed_frames: IdMap<u64, u64> = IdMap::default();
    let mut sums = VaceSums::default();
    for (k, frame) in data.frames().enumerate() {
        let (n, m) = (frame.truth_ids.len(), frame.estimate_ids.len());
        for &g in frame.truth_ids {
            truth_frames[g as usize].push(k as u32);
        }
        for &e in frame.estimate_ids {
            estimate_frames[e as usize].push(k as u32);
        }
        edges.clear();
        for p in frame.pairs {
            edges.push(Edge {
                row: p.truth,
                col: p.estimate,
                value: p.similarity,
            });
            let key = pair_key(
                frame.truth_ids[p.truth as usize],
                frame.estimate_ids[p.estimate as usize],
            );
            *overlap.entry(key).or_insert(0.0) += p.similarity;
            if p.similarity >= RELAXED_OVERLAP {
                *relaxed_frames.entry(key).or_insert(0) += 1;
            }
        }
        matcher.solve(n, m, &edges, Objective::MaxWeight, &mut matched);
        let mapped: f64 = matched.iter().map(|&i| edges[i].value).sum();
        sums.frames += 1;
        sums.fda_sum += mapped / (0.5 * (n + m) as f64);
        if !matched.is_empty() {
            sums.mapped_frames += 1;
            sums.modp_sum += mapped / matched.len() as f64;
        }
    }
    // Trajectory mapping. Sorted pairs: the matching does not depend on hash order.
    let mut pairs: Vec<(u64, f64)> = overlap.into_iter().collect();
    pairs.sort_unstable_by_key(|&(key, _)| key);
    let mut both_present = Vec::with_capacity(pairs.len());
    let mut relaxed_edges = Vec::new();
    edges.clear();
    for &(key, overlap_sum) in &pairs {
        let (g, e) = split_pair_key(key);
        let (g_frames, e_frames) = (&truth_frames[g as usize], &estimate_frames[e as usize]);
        let both = common_count(g_frames, e_frames);
        both_present.push(both);
        let either = (g_frames.len() as u64 + e_frames.len() as u64 - both) as f64;
        edges.push(Edge {
            row: g,
            col: e,
            value: overlap_sum / either,
        });
        if let Some(&frames) = relaxed_frames.get(&key) {
            relaxed_edges.push(Edge {
                row: g,
                col: e,
                value: frames as f64 / either,
            });
        }
    }
    matcher.solve(
        data.truth_id_count(),
        data.estimate_id_count(),
        &edges,
        Objective::MaxWeight,
        &mut matched,
    );
    for &k in &matched {
        sums.stda += edges[k].value;
        sums.track_overlap_sum += pairs[k].1;
        sums.track_mapped_frames += both_present[k];
    }
    matcher.solve(
        data.truth_id_count(),
        data.estimate_id_count(),
        &relaxed_edges,
        Objective::MaxWeight,
        &mut matched,
    );
    sums.stda_relaxed = matched.iter().map(|&k| relaxed_edges[k].value).sum();
    sums.truth_tracks = data.truth_id_count() as u64;
    sums.estimate_tracks = data.estimate_id_count() as u64;
    VaceMetrics::from_sums(sums)
}

/// Number of values in both sorted lists.
fn common_count(a: &[u32], b: &[u32]) -> u64 {
    let (mut i, mut j, mut common) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                common += 1;
                i += 1;
                j += 1;
            }
        }
    }
    common
}

/// The additive fields of [`VaceMetrics`].
#[derive(Debug, Clone, Copy, Default)]
struct VaceSums {
    frames: u64,
    fda_sum: f64,
    mapped_frames: u64,
    modp_sum: f64,
    truth_tracks: u64,
    estimate_tracks: u64,
    stda: f64,
    stda_relaxed: f64,
    track_overlap_sum: f64,
    track_mapped_frames: u64,
}

impl VaceMetrics {
    fn from_sums(s: VaceSums) -> Self {
        let ratio = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
        let mean_tracks = 0.5 * (s.truth_tracks as f64 + s.estimate_tracks as f64);
        Self {
            frames: s.frames,
            fda_sum: s.fda_sum,
            mapped_frames: s.mapped_frames,
            modp_sum: s.modp_sum,
            truth_tracks: s.truth_tracks,
            estimate_tracks: s.estimate_tracks,
            stda: s.stda,
            track_overlap_sum: s.track_overlap_sum,
            track_mapped_frames: s.track_mapped_frames,
            sfda: ratio(s.fda_sum, s.frames as f64),
            ata: ratio(s.stda, mean_tracks),
            stda_relaxed: s.stda_relaxed,
            ata_relaxed: ratio(s.stda_relaxed, mean_tracks),
            n_modp: ratio(s.modp_sum, s.mapped_frames as f64),
            motp: ratio(s.track_overlap_sum, s.track_mapped_frames as f64),
        }
    }

    /// Combines sequences as TrackEval's `VACE.combine_sequences`: sums the frames, the
    /// trajectories and the overlap sums, then recomputes the ratios.
    pub fn combine(sequences: &[VaceMetrics]) -> VaceMetrics {
        let mut s = VaceSums::default();
        for m in sequences {
            s.frames += m.frames;
            s.fda_sum += m.fda_sum;
            s.mapped_frames += m.mapped_frames;
            s.modp_sum += m.modp_sum;
            s.truth_tracks += m.truth_tracks;
            s.estimate_tracks += m.estimate_tracks;
            s.stda += m.stda;
            s.stda_relaxed += m.stda_relaxed;
            s.track_overlap_sum += m.track_overlap_sum;
            s.track_mapped_frames += m.track_mapped_frames;
        }
        VaceMetrics::from_sums(s)
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        "VACE, IMM-PF paper §5.2 (overlap = similarity, no threshold; ATA(0.5): TrackEval's \
         relaxed ATA; scores in %)"
            .to_owned()
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        vec![
            ("SFDA", score(self.sfda)),
            ("ATA", score(self.ata)),
            ("ATA(0.5)", score(self.ata_relaxed)),
            ("N-MODP", score(self.n_modp)),
            ("MOTP", score(self.motp)),
            ("Frames", count(self.frames)),
            ("GTtracks", count(self.truth_tracks)),
            ("Tracks", count(self.estimate_tracks)),
        ]
    }
}

impl std::fmt::Display for VaceMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        Table::single(&self.columns()).fmt(f)
    }
}
