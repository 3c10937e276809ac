//! The detector model: true beads to detections (misses, bursts of misses, false positives,
//! position noise) and the detector-confidence candidates of Eq. (1) of the MMPF+ paper.

use rand::RngExt;
use rand_distr::{Distribution, Poisson, StandardNormal};
use serde::{Deserialize, Serialize};
use sillage_core::{
    Detection, FrameIndex, FrameObservations, ObjectClass, Point2, Result, RngStream,
    TRANSPARENT_BEAD_CLASS, TrackId, Vec2, rng_stream,
};

use super::motion::uniform;
use super::{BedloadDetectionParams, BedloadFrame, BedloadSceneParams};

/// Streams of the detector model, apart from the scene's so that changing the detector
/// leaves the truth alone, and apart from each other so that, e.g., more false positives
/// leave the true detections alone.
const STREAM_NOISE: u64 = 0xDE7_0001;
const STREAM_MISS: u64 = 0xDE7_0002;
const STREAM_BURST: u64 = 0xDE7_0003;
const STREAM_SCORE: u64 = 0xDE7_0004;
const STREAM_WEAK: u64 = 0xDE7_0005;
const STREAM_FALSE: u64 = 0xDE7_0006;

/// Why a true bead was not detected in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum MissCause {
    /// An independent miss (`black_miss_probability`, `transparent_miss_probability`).
    Independent,
    /// Frame `frame_in_burst` (0-based) of a burst of `burst_length` consecutive misses.
    Burst {
        /// Position of this frame in its burst, 0 at the burst's first frame.
        frame_in_burst: u32,
    },
}

/// A true bead the detector missed in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MissedBead {
    /// Identity of the missed bead.
    pub track_id: TrackId,
    /// Its class.
    pub class: ObjectClass,
    /// Why it was missed.
    pub cause: MissCause,
}

/// What the detector model reports for one frame, with the truth of each report beside it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BedloadObservation {
    /// Index of the frame.
    pub index: FrameIndex,
    /// Detections of both classes, black first, each class in raster order (by y, then x),
    /// so that their order says nothing of their identity.
    pub detections: Vec<Detection>,
    /// The true bead each detection came from, `None` for a false positive (parallel to
    /// `detections`), to score association accuracy.
    pub detection_sources: Vec<Option<TrackId>>,
    /// The set `D` of Eq. (1), transparent only: every transparent detection (true or
    /// false) with its score, and the weak candidates of missed transparent beads; raster
    /// order. Black beads have none.
    pub candidates: Vec<Detection>,
    /// The true bead each candidate came from, `None` for a false positive.
    pub candidate_sources: Vec<Option<TrackId>>,
    /// The true beads not detected in this frame, in slot order.
    pub missed: Vec<MissedBead>,
}

impl BedloadObservation {
    /// The observations a [`sillage_core::Tracker`] takes: detections and candidates, no
    /// image.
    pub fn observations(&self) -> FrameObservations<'_> {
        FrameObservations {
            frame: self.index,
            detections: &self.detections,
            image: None,
            candidates: &self.candidates,
        }
    }
}

/// Turns the true beads of each frame into detections and candidates; it keeps the bursts
/// under way from frame to frame, so feed it the frames of one scene in order.
#[derive(Debug, Clone)]
pub struct BeadDetectionModel {
    params: BedloadDetectionParams,
    last: Point2,
    false_positives: Option<Poisson<f64>>,
    /// Per slot: the bead and the position in its burst of its next frame, if in a burst.
    bursts: Vec<(TrackId, Option<u32>)>,
    noise: RngStream,
    miss: RngStream,
    burst: RngStream,
    score: RngStream,
    weak: RngStream,
    false_rng: RngStream,
}

impl BeadDetectionModel {
    /// The model `params` describe for frames of `scene` (its size and its seed); fails on
    /// invalid parameters, naming the key.
    pub fn new(params: BedloadDetectionParams, scene: &BedloadSceneParams) -> Result<Self> {
        params.validate()?;
        let seed = scene.seed;
        let false_positives = (params.false_positive_mean > 0.0)
            .then(|| Poisson::new(params.false_positive_mean).expect("validated mean"));
        Ok(Self {
            params,
            last: Point2::new(scene.width as f64 - 1.0, scene.height as f64 - 1.0),
            false_positives,
            bursts: Vec::new(),
            noise: rng_stream(seed, STREAM_NOISE),
            miss: rng_stream(seed, STREAM_MISS),
            burst: rng_stream(seed, STREAM_BURST),
            score: rng_stream(seed, STREAM_SCORE),
            weak: rng_stream(seed, STREAM_WEAK),
            false_rng: rng_stream(seed, STREAM_FALSE),
        })
    }

    /// The parameters of the model.
    pub fn params(&self) -> &BedloadDetectionParams {
        &self.params
    }

    /// The detections and candidates of `frame`. Every bead draws the same numbers whatever
    /// happens to it, so each stream stays aligned with the truth.
    pub fn observe(&mut self, frame: &BedloadFrame) -> BedloadObservation {
        let p = self.params.clone();
        let mut detections = Vec::with_capacity(frame.beads.len() + 4);
        let mut candidates = Vec::new();
        let mut missed = Vec::new();
        self.bursts.resize(frame.beads.len(), (TrackId::MAX, None));
        for (slot, bead) in frame.beads.iter().enumerate() {
            let noise = Vec2::new(
                self.noise.sample(StandardNormal),
                self.noise.sample(StandardNormal),
            );
            let pos = self.clamp(bead.pos_px + noise * p.position_sigma_px);
            let (u_miss, u_burst) = (self.miss.random::<f64>(), self.burst.random::<f64>());
            let (u_score, u_weak) = (self.score.random::<f64>(), self.weak.random::<f64>());
            let transparent = bead.class == TRANSPARENT_BEAD_CLASS;
            let cause = if transparent {
                self.transparent_miss(slot, bead.track_id, u_miss, u_burst)
            } else {
                (u_miss < p.black_miss_probability).then_some(MissCause::Independent)
            };
            let source = Some(bead.track_id);
            match cause {
                None if transparent => {
                    let detection = Detection::of_class(
                        pos,
                        score(p.detection_score_range, u_score),
                        bead.class,
                    );
                    detections.push((detection, source));
                    candidates.push((detection, source));
                }
                None => detections.push((Detection::of_class(pos, 1.0, bead.class), source)),
                Some(cause) => {
                    missed.push(MissedBead {
                        track_id: bead.track_id,
                        class: bead.class,
                        cause,
                    });
                    if transparent && u_weak < p.weak_candidate_probability {
                        let weak = score(p.weak_score_range, u_score);
                        candidates.push((Detection::of_class(pos, weak, bead.class), source));
                    }
                }
            }
        }
        self.add_false_positives(&mut detections, &mut candidates);
        let (detections, detection_sources) = raster_order(detections);
        let (candidates, candidate_sources) = raster_order(candidates);
        BedloadObservation {
            index: frame.index,
            detections,
            detection_sources,
            candidates,
            candidate_sources,
            missed,
        }
    }

    /// Whether the transparent bead in `slot` is missed, and why; starts or continues its
    /// burst (a new bead in the slot starts with none).
    fn transparent_miss(
        &mut self,
        slot: usize,
        id: TrackId,
        u_miss: f64,
        u_burst: f64,
    ) -> Option<MissCause> {
        let length = self.params.burst_length;
        let state = &mut self.bursts[slot];
        if state.0 != id {
            *state = (id, None);
        }
        let frame_in_burst = match state.1 {
            Some(k) => k,
            None if u_burst < self.params.burst_probability => 0,
            None => {
                let miss = u_miss < self.params.transparent_miss_probability;
                return miss.then_some(MissCause::Independent);
            }
        };
        state.1 = (frame_in_burst + 1 < length).then_some(frame_in_burst + 1);
        Some(MissCause::Burst { frame_in_burst })
    }

    /// A Poisson number of transparent false positives at uniform positions, each a
    /// detection and a candidate with a detection score.
    fn add_false_positives(
        &mut self,
        detections: &mut Vec<(Detection, Option<TrackId>)>,
        candidates: &mut Vec<(Detection, Option<TrackId>)>,
    ) {
        let Some(poisson) = self.false_positives else {
            return;
        };
        let count = poisson.sample(&mut self.false_rng) as usize;
        for _ in 0..count {
            let x = uniform(&mut self.false_rng, [0.0, self.last.x]);
            let y = uniform(&mut self.false_rng, [0.0, self.last.y]);
            let strength = score(self.params.detection_score_range, self.false_rng.random());
            let detection =
                Detection::of_class(Point2::new(x, y), strength, TRANSPARENT_BEAD_CLASS);
            detections.push((detection, None));
            candidates.push((detection, None));
        }
    }

    fn clamp(&self, p: Point2) -> Point2 {
        Point2::new(p.x.clamp(0.0, self.last.x), p.y.clamp(0.0, self.last.y))
    }
}

/// A score uniform in `[min, max)` from `u` uniform in [0, 1).
fn score([min, max]: [f64; 2], u: f64) -> f32 {
    let value = (min + (max - min) * u) as f32;
    // Rounding to f32 may reach `max`; the range stays half-open.
    if max > min && value >= max as f32 {
        (max as f32).next_down()
    } else {
        value
    }
}

/// Sorts by class (black first), then y, then x, ties in input order (an unstable sort on a
/// key made unique by the index: the same order as a stable sort, no random tie-break), and
/// splits detections from sources.
fn raster_order(
    items: Vec<(Detection, Option<TrackId>)>,
) -> (Vec<Detection>, Vec<Option<TrackId>>) {
    let mut keys: Vec<(ObjectClass, f64, f64, usize)> = items
        .iter()
        .enumerate()
        .map(|(i, (d, _))| (d.class, d.pos_px.y, d.pos_px.x, i))
        .collect();
    keys.sort_unstable_by(|a, b| {
        a.0.cmp(&b.0)
            .then(a.1.total_cmp(&b.1))
            .then(a.2.total_cmp(&b.2))
            .then(a.3.cmp(&b.3))
    });
    let mut sorted = (
        Vec::with_capacity(items.len()),
        Vec::with_capacity(items.len()),
    );
    for &(.., i) in &keys {
        sorted.0.push(items[i].0);
        sorted.1.push(items[i].1);
    }
    sorted
}
