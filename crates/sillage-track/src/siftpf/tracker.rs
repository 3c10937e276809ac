//! The SIFT-PF tracker, frame by frame (Fig. 1 of Souded et al.): features followed by their
//! particle filters, objects linked to detections through the link scores of Eq. (6), the four
//! cases of §2.3, occlusion management (§2.4), new objects validated over ten frames (§2.5).

use rayon::prelude::*;
use sillage_core::{
    Error, FrameIndex, GrayImage, Homography, Image, Point2, Result, RgbImage, TrackId,
};
use sillage_filter::{
    FilterParams, FilterSpec, KinematicModel, Noise2,
    params::KinematicParams,
    resample::{ResampleScheme, Resampling},
};
use sillage_image::{DominantColours, SiftDetector, SiftKeypoint};

use super::association::{DetectedObject, LinkMatrix};
use super::coherence::WorldScale;
use super::cuts::join_straddled_cuts;
use super::feature::{FeatureFate, FeatureFrame, TrackedFeature};
use super::object::{HistoryEntry, ObjectState, TrackedObject};
use super::occlusion::{ResumeCandidate, resume_pairs};
use super::params::SiftPfParams;
use super::selection::{FeatureSelector, SelectionRequest, anchor_in};
use super::validation::is_object_of_interest;
use sillage_core::BoundingBox;

/// A free detection lying at least this share inside an object linked this frame is a
/// fragment of it (legs or a head cut off by the background subtraction), not a newcomer.
const FRAGMENT_SHARE: f64 = 0.5;
/// An object in a merge whose features place it further than this many box widths from
/// where its pre-merge velocity puts it has lost its features.
const MERGE_DRIFT_WIDTHS: f64 = 0.5;

/// One frame as the tracker sees it.
#[derive(Clone, Copy)]
pub struct SiftPfFrame<'a> {
    /// Index of the frame.
    pub frame: FrameIndex,
    /// The grey frame, SIFT's input.
    pub grey: &'a GrayImage,
    /// The colour frame, for the dominant colours (optional).
    pub colour: Option<&'a RgbImage>,
    /// The motion pixels of the frame.
    pub foreground: &'a Image<bool>,
    /// The detected objects `do(t)`: motion blobs.
    pub detections: &'a [DetectedObject],
}

/// One reported box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiftPfEstimate {
    /// Frame of the box.
    pub frame: FrameIndex,
    /// Identity of the object.
    pub id: TrackId,
    /// The box.
    pub bbox: BoundingBox,
    /// True when the box was estimated from the features inside a merged detection.
    pub merged: bool,
}

/// The SIFT-PF tracker of one sequence.
pub struct SiftPfTracker {
    params: SiftPfParams,
    sift: SiftDetector,
    spec: FilterSpec,
    model: KinematicModel,
    scale: WorldScale,
    selector: FeatureSelector,
    objects: Vec<TrackedObject>,
    next_object_id: TrackId,
    next_feature_id: u64,
    keypoints: Vec<SiftKeypoint>,
    edge_threshold: f32,
}

/// How each object fared in the association of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Link {
    /// No detection holds its features.
    None,
    /// It has detection `j` to itself.
    Alone(usize),
    /// It shares detection `j` with other objects.
    Merged(usize),
    /// It was a group and split: it ends, its detections start new objects.
    GroupSplit,
}

impl SiftPfTracker {
    /// A tracker with `params` (validated), box sizes and speeds learned in metres through
    /// `homography` when given, its particle filters seeded from `seed`.
    pub fn new(params: &SiftPfParams, homography: Option<Homography>, seed: u64) -> Result<Self> {
        params.validate()?;
        let filter = FilterParams {
            particles: params.filter.particles,
            resampling: Resampling {
                scheme: ResampleScheme::Systematic,
                ess_fraction: None,
            },
        };
        let var = |sigma: f64| Noise2::diagonal(sigma * sigma, sigma * sigma);
        let model = KinematicModel::new(
            "filter",
            &KinematicParams::ConstantVelocity {
                pos_noise: var(params.filter.position_noise_px),
                vel_noise: var(params.filter.velocity_noise_px_per_frame),
            },
        )?;
        Ok(Self {
            sift: SiftDetector::new(&params.detector_params())?,
            spec: FilterSpec::new(&filter, seed)?,
            model,
            scale: WorldScale::new(homography),
            selector: FeatureSelector::default(),
            objects: Vec::new(),
            next_object_id: 1,
            next_feature_id: 0,
            keypoints: Vec::new(),
            edge_threshold: params.detector_params().edge_threshold,
            params: params.clone(),
        })
    }

    /// The objects alive (intermediate, tracked and occluded).
    pub fn objects(&self) -> &[TrackedObject] {
        &self.objects
    }

    /// Tracks one frame; returns the boxes of the validated objects seen in it, and, when an
    /// object is validated, the boxes of its frames before (so rows may come from earlier
    /// frames).
    pub fn step(&mut self, input: SiftPfFrame<'_>) -> Result<Vec<SiftPfEstimate>> {
        check_sizes(&input)?;
        self.sift.analyse(input.grey)?;
        self.follow_features(&input);
        let active = self.active_objects();
        let mut scores = self.link_scores(&active, input.detections);
        let joined = self.join_straddled_cuts(input.detections, &active, &scores);
        if let Some(joined) = &joined {
            scores = self.link_scores(&active, joined);
        }
        let input = SiftPfFrame {
            detections: joined.as_deref().unwrap_or(input.detections),
            ..input
        };
        let mut links = self.associate(&active, &scores);
        let mut free = self.apply_links(&input, &mut links);
        self.resume_occluded(&input, &mut free);
        self.start_objects(&input, &free);
        self.end_occlusions(input.frame);
        Ok(self.report(input.frame))
    }

    /// §2.2 for every feature of every active object, in parallel (each feature has its
    /// own random stream, so the result does not depend on the thread count).
    fn follow_features(&mut self, input: &SiftPfFrame<'_>) {
        let frame = FeatureFrame {
            sift: &self.sift,
            foreground: input.foreground,
        };
        let (model, params) = (&self.model, &self.params.filter);
        self.objects
            .par_iter_mut()
            .filter(|o| o.is_active())
            .for_each(|object| {
                object.coast();
                let c0 =
                    motion_confidence(&object.bbox, input.foreground, params.min_motion_confidence);
                let fates: Vec<FeatureFate> = object
                    .features
                    .par_iter_mut()
                    .map(|f| f.step(model, frame, c0, params))
                    .collect();
                retain_indices(&mut object.features, |k| fates[k] == FeatureFate::Kept);
            });
    }

    /// The indices of the active objects (tracked and intermediate).
    fn active_objects(&self) -> Vec<usize> {
        (0..self.objects.len())
            .filter(|&i| self.objects[i].is_active())
            .collect()
    }

    /// The link scores of the `active` objects (rows) against `detections` (Eq. 6); an
    /// object without features is scored by box overlap.
    fn link_scores(&self, active: &[usize], detections: &[DetectedObject]) -> LinkMatrix {
        let feature_lists: Vec<Vec<(Point2, f64)>> = active
            .iter()
            .map(|&i| scored_features(&self.objects[i]))
            .collect();
        let mut scores = LinkMatrix::new(feature_lists.iter().map(Vec::as_slice), detections);
        for (row, &i) in active.iter().enumerate() {
            if self.objects[i].features.is_empty() {
                for (j, d) in detections.iter().enumerate() {
                    scores.set_score(row, j, self.objects[i].bbox.iou(&person_box(d)));
                }
            }
        }
        scores
    }

    /// The detections with the cuts that an object's features straddle joined back
    /// ([`super::cuts`]), from the `scores` of the `active` objects against them; `None`
    /// when every cut stands. Objects without features, scored by box overlap, say nothing
    /// of a cut.
    fn join_straddled_cuts(
        &self,
        detections: &[DetectedObject],
        active: &[usize],
        scores: &LinkMatrix,
    ) -> Option<Vec<DetectedObject>> {
        if detections.iter().all(|d| d.cut_from.is_none()) {
            return None;
        }
        let with_features: Vec<usize> = (0..active.len())
            .filter(|&row| !self.objects[active[row]].features.is_empty())
            .collect();
        join_straddled_cuts(
            detections,
            scores,
            &with_features,
            self.params.association.min_link_score,
        )
    }

    /// §2.3: from the link `scores` of the `active` objects, the case of each active object
    /// (in the order of `self.objects`, occluded ones as `Link::None`).
    fn associate(&self, active: &[usize], scores: &LinkMatrix) -> Vec<Link> {
        let min_link = self.params.association.min_link_score;
        let targets = scores.targets(min_link);
        let mut members = vec![0usize; scores.cols()];
        for j in targets.iter().flatten() {
            members[*j] += 1;
        }
        let mut links = vec![Link::None; self.objects.len()];
        for (row, &i) in active.iter().enumerate() {
            let Some(j) = targets[row] else { continue };
            if members[j] > 1 {
                links[i] = Link::Merged(j);
                continue;
            }
            let min_share = self.params.association.split_min_share;
            let split = (0..scores.cols()).any(|k| {
                k != j && members[k] == 0 && scores.holds_part(row, k, min_link, min_share)
            });
            links[i] = if split && !self.objects[i].has_merged {
                Link::GroupSplit
            } else {
                Link::Alone(j)
            };
        }
        links
    }

    /// Applies the four cases of §2.3; returns the detections no object keeps (candidates for
    /// resumption or new objects), each with a flag saying it came from a split.
    fn apply_links(&mut self, input: &SiftPfFrame<'_>, links: &mut [Link]) -> Vec<(usize, bool)> {
        let mut kept = vec![false; input.detections.len()];
        let mut split_off = vec![false; input.detections.len()];
        let mut ended = vec![false; self.objects.len()];
        for i in 0..links.len() {
            match links[i] {
                Link::Alone(j) => {
                    kept[j] = true;
                    self.update_alone(i, &input.detections[j], input);
                }
                Link::Merged(j) => {
                    kept[j] = true;
                    if !self.follow_in_merge(i, &input.detections[j], input.frame) {
                        links[i] = Link::None;
                    }
                }
                Link::GroupSplit => ended[i] = true,
                Link::None => {}
            }
        }
        // Detections a group's features reach start new objects after the split (§2.3).
        for (i, link) in links.iter().enumerate() {
            if *link != Link::GroupSplit {
                continue;
            }
            for (j, d) in input.detections.iter().enumerate() {
                if !kept[j] && self.objects[i].features.iter().any(|f| d.holds(f.pos_px())) {
                    split_off[j] = true;
                }
            }
        }
        self.handle_unlinked(input, links);
        retain_indices(&mut self.objects, |i| !ended[i]);
        // A detection mostly inside an object linked this frame is a fragment of it.
        let linked_boxes: Vec<BoundingBox> = links
            .iter()
            .enumerate()
            .filter_map(|(i, l)| match l {
                Link::Alone(j) | Link::Merged(j) => Some((i, *j)),
                _ => None,
            })
            .map(|(_, j)| person_box(&input.detections[j]))
            .collect();
        (0..input.detections.len())
            .filter(|&j| !kept[j])
            .filter(|&j| {
                split_off[j] || {
                    let b = person_box(&input.detections[j]);
                    !linked_boxes
                        .iter()
                        .any(|o| inside_share(&b, o) >= FRAGMENT_SHARE)
                }
            })
            .map(|j| (j, split_off[j]))
            .collect()
    }

    /// The second case of §2.3: the object's box is estimated from its features' pre-merge
    /// layout, inside the merged detection. Its velocity is kept from before the merge; when
    /// the estimate strays more than [`MERGE_DRIFT_WIDTHS`] from where that velocity puts it,
    /// its features have left it (onto the background or the object in front) and it is
    /// treated as unlinked (false).
    fn follow_in_merge(&mut self, i: usize, detection: &DetectedObject, frame: FrameIndex) -> bool {
        let object = &mut self.objects[i];
        let predicted = match object.merge_prediction {
            Some(mut p) => {
                p.left_px += object.vel_px_per_frame.x;
                p.top_px += object.vel_px_per_frame.y;
                p
            }
            None => object.bbox,
        };
        let Some(estimated) = object
            .box_from_features()
            .map(|b| clip_into(b, &person_box(detection)))
        else {
            return false;
        };
        let drift = predicted_offset(&predicted, &estimated);
        if drift > MERGE_DRIFT_WIDTHS {
            object.merge_prediction = None;
            return false;
        }
        object.merge_prediction = Some(predicted);
        object.bbox = estimated;
        object.has_merged = true;
        if object.state == ObjectState::Intermediate {
            object.history.push(HistoryEntry {
                frame,
                bbox: estimated,
                linked: true,
            });
        }
        true
    }

    /// The first case of §2.3: the object takes the detection's box; features off the
    /// detection or too close to a more reliable one are dropped and replaced; its colours,
    /// size, speed and signature are learned.
    fn update_alone(&mut self, i: usize, detection: &DetectedObject, input: &SiftPfFrame<'_>) {
        let bbox = person_box(detection);
        let others: Vec<BoundingBox> = self
            .objects
            .iter()
            .enumerate()
            .filter(|(k, o)| *k != i && o.is_active())
            .map(|(_, o)| o.bbox)
            .collect();
        let spacing2 = self.params.placement.min_spacing_px.powi(2);
        let object = &mut self.objects[i];
        object.merge_prediction = None;
        object.move_to(bbox);
        object.features.retain(|f| detection.holds(f.pos_px()));
        object
            .features
            .sort_by(|a, b| b.reliability().total_cmp(&a.reliability()));
        let mut kept: Vec<Point2> = Vec::new();
        object.features.retain(|f| {
            let p = f.pos_px();
            let crowded = kept.iter().any(|q| (*q - p).norm_squared() < spacing2);
            if !crowded {
                kept.push(p);
            }
            !crowded
        });
        for f in &mut object.features {
            f.set_anchor(anchor_in(&bbox, f.pos_px()));
        }
        if let Some(colour) = input.colour {
            object.colours = DominantColours::extract(
                &masked_pixels(colour, detection),
                self.params.association.dominant_colours,
            );
        }
        let ground = self.scale.ground(&bbox);
        let step = object.last_ground.map(|(g, frame)| {
            g.distance(ground) / (input.frame.saturating_sub(frame).max(1) as f64)
        });
        object.coherence.learn(self.scale.size(&bbox), step);
        object.last_ground = Some((ground, input.frame));
        if object.state == ObjectState::Intermediate {
            object.history.push(HistoryEntry {
                frame: input.frame,
                bbox,
                linked: true,
            });
        }
        self.replenish(i, input, &others);
        let object = &mut self.objects[i];
        object.signature = object.features.iter().map(|f| *f.descriptor()).collect();
    }

    /// Adds features to the sub-regions of object `i` that lack them (§2.1, §2.3).
    fn replenish(&mut self, i: usize, input: &SiftPfFrame<'_>, others: &[BoundingBox]) {
        let frame = FeatureFrame {
            sift: &self.sift,
            foreground: input.foreground,
        };
        let object = &self.objects[i];
        if self.params.selection == super::params::FeatureSelection::WholeObject
            && !object.features.is_empty()
        {
            return;
        }
        let existing: Vec<Point2> = object.features.iter().map(|f| f.pos_px()).collect();
        let request = SelectionRequest {
            bbox: object.bbox,
            existing: &existing,
            others,
            motion_confidence: motion_confidence(
                &object.bbox,
                input.foreground,
                self.params.filter.min_motion_confidence,
            ),
        };
        let seeds = self.selector.select(
            self.params.selection,
            frame,
            &request,
            &self.params.placement,
            self.edge_threshold,
        );
        let velocity = object.vel_px_per_frame;
        for seed in seeds {
            let feature = TrackedFeature::new(
                &self.spec,
                self.next_feature_id,
                seed,
                velocity,
                &self.params.filter,
            );
            self.next_feature_id += 1;
            self.objects[i].features.push(feature);
        }
    }

    /// The last case of §2.3: an object no detection holds is lost near the frame's border
    /// (it left) and occluded elsewhere; the objects it overlaps hid it (they merged). An
    /// intermediate object only records its absence.
    fn handle_unlinked(&mut self, input: &SiftPfFrame<'_>, links: &[Link]) {
        let (width, height) = input.grey.dimensions();
        let margin = self.params.association.exit_margin_px;
        let mut lost = vec![false; self.objects.len()];
        for i in 0..self.objects.len() {
            if links[i] != Link::None || !self.objects[i].is_active() {
                continue;
            }
            let object = &mut self.objects[i];
            if object.state == ObjectState::Intermediate {
                object.history.push(HistoryEntry {
                    frame: input.frame,
                    bbox: object.bbox,
                    linked: false,
                });
                continue;
            }
            let b = object.bbox;
            let near_exit = b.left_px < margin
                || b.top_px < margin
                || b.right_px() > width as f64 - 1.0 - margin
                || b.bottom_px() > height as f64 - 1.0 - margin;
            if near_exit {
                lost[i] = true;
                continue;
            }
            object.state = ObjectState::Occluded { since: input.frame };
            for k in 0..self.objects.len() {
                if k != i && self.objects[k].is_active() && self.objects[k].bbox.iou(&b) > 0.0 {
                    self.objects[k].has_merged = true;
                }
            }
        }
        retain_indices(&mut self.objects, |i| !lost[i]);
    }

    /// §2.4: free detections matched to occluded objects resume them; the detections used
    /// are removed from `free`.
    fn resume_occluded(&mut self, input: &SiftPfFrame<'_>, free: &mut Vec<(usize, bool)>) {
        let occluded: Vec<usize> = (0..self.objects.len())
            .filter(|&i| !self.objects[i].is_active())
            .collect();
        if occluded.is_empty() || free.is_empty() {
            return;
        }
        let candidates: Vec<ResumeCandidate> = free
            .iter()
            .map(|&(j, _)| self.candidate(&input.detections[j], input))
            .collect();
        let objects: Vec<&TrackedObject> = occluded.iter().map(|&i| &self.objects[i]).collect();
        let pairs = resume_pairs(&objects, &candidates, input.frame, &self.params.association);
        let mut used = vec![false; free.len()];
        for (o, c) in pairs {
            used[c] = true;
            let i = occluded[o];
            let detection = &input.detections[free[c].0];
            let object = &mut self.objects[i];
            object.state = ObjectState::Tracked;
            object.features.clear();
            object.bbox = person_box(detection);
            self.update_alone(i, detection, input);
        }
        retain_indices(free, |c| !used[c]);
    }

    /// A free detection's appearance for the occlusion management.
    fn candidate(
        &mut self,
        detection: &DetectedObject,
        input: &SiftPfFrame<'_>,
    ) -> ResumeCandidate {
        let bbox = person_box(detection);
        self.keypoints.clear();
        self.sift
            .keypoints(Some(detection.bbox), &mut self.keypoints);
        let descriptors = self
            .keypoints
            .iter()
            .filter_map(|k| self.sift.describe(k))
            .collect();
        let colours = input.colour.map_or_else(DominantColours::default, |c| {
            DominantColours::extract(
                &masked_pixels(c, detection),
                self.params.association.dominant_colours,
            )
        });
        ResumeCandidate {
            bbox,
            descriptors,
            colours,
            ground: self.scale.ground(&bbox),
            size: self.scale.size(&bbox),
        }
    }

    /// §2.5: every free detection starts an intermediate object with its features.
    fn start_objects(&mut self, input: &SiftPfFrame<'_>, free: &[(usize, bool)]) {
        for &(j, _) in free {
            let detection = &input.detections[j];
            let id = self.next_object_id;
            self.next_object_id += 1;
            self.objects
                .push(TrackedObject::new(id, person_box(detection), input.frame));
            let i = self.objects.len() - 1;
            let others: Vec<BoundingBox> = self.objects[..i]
                .iter()
                .filter(|o| o.is_active())
                .map(|o| o.bbox)
                .collect();
            self.replenish(i, input, &others);
            let object = &mut self.objects[i];
            if let Some(colour) = input.colour {
                object.colours = DominantColours::extract(
                    &masked_pixels(colour, detection),
                    self.params.association.dominant_colours,
                );
            }
            object.coherence.learn(self.scale.size(&object.bbox), None);
            object.last_ground = Some((self.scale.ground(&object.bbox), input.frame));
            object.signature = object.features.iter().map(|f| *f.descriptor()).collect();
        }
    }

    /// Occluded objects move on at their velocity and are dropped after the time limit
    /// (§2.4).
    fn end_occlusions(&mut self, frame: FrameIndex) {
        let limit = u64::from(self.params.association.max_occluded_frames);
        self.objects.retain_mut(|o| match o.state {
            ObjectState::Occluded { since } => {
                o.coast();
                frame.saturating_sub(since) < limit
            }
            _ => true,
        });
    }

    /// Validates intermediate objects that were watched long enough (§2.5) and reports the
    /// boxes of the validated objects seen this frame.
    fn report(&mut self, frame: FrameIndex) -> Vec<SiftPfEstimate> {
        let params = &self.params.validation;
        let mut out = Vec::new();
        self.objects.retain_mut(|o| {
            if o.state != ObjectState::Intermediate {
                return true;
            }
            if frame.saturating_sub(o.born) + 1 < u64::from(params.frames) {
                return true;
            }
            if !is_object_of_interest(&o.history, params) {
                return false;
            }
            o.state = ObjectState::Tracked;
            out.extend(
                o.history
                    .iter()
                    .filter(|e| e.linked && e.frame < frame)
                    .map(|e| SiftPfEstimate {
                        frame: e.frame,
                        id: o.id,
                        bbox: e.bbox,
                        merged: false,
                    }),
            );
            o.history.clear();
            true
        });
        out.extend(
            self.objects
                .iter()
                .filter(|o| o.state == ObjectState::Tracked)
                .map(|o| SiftPfEstimate {
                    frame,
                    id: o.id,
                    bbox: o.bbox,
                    merged: o.merge_prediction.is_some(),
                }),
        );
        out
    }
}

/// An object's features as Eq. (6) scores them: positions and reliabilities.
fn scored_features(object: &TrackedObject) -> Vec<(Point2, f64)> {
    object
        .features
        .iter()
        .map(|f| (f.pos_px(), f.reliability()))
        .collect()
}

/// How far (in box widths) the centre of `estimated` lies from that of `predicted`.
fn predicted_offset(predicted: &BoundingBox, estimated: &BoundingBox) -> f64 {
    let centre = |b: &BoundingBox| (b.left_px + b.width_px / 2.0, b.top_px + b.height_px / 2.0);
    let (a, b) = (centre(predicted), centre(estimated));
    (a.0 - b.0).hypot(a.1 - b.1) / predicted.width_px.max(1.0)
}

/// Keeps the items whose index passes `keep`.
fn retain_indices<T>(items: &mut Vec<T>, keep: impl Fn(usize) -> bool) {
    let mut index = 0;
    items.retain(|_| {
        index += 1;
        keep(index - 1)
    });
}

/// `c₀` of Eq. (5) for an object: 1 when its box has no motion pixels, falling linearly to
/// `min_confidence` when all of them move (§2.2.1: "for a low density, c₀ will be close to 1").
fn motion_confidence(b: &BoundingBox, foreground: &Image<bool>, min_confidence: f64) -> f64 {
    let (w, h) = foreground.dimensions();
    let x0 = b.left_px.max(0.0) as usize;
    let y0 = b.top_px.max(0.0) as usize;
    let x1 = (b.right_px().max(0.0) as usize + 1).min(w);
    let y1 = (b.bottom_px().max(0.0) as usize + 1).min(h);
    if x0 >= x1 || y0 >= y1 {
        return 1.0;
    }
    let moving: usize = (y0..y1)
        .map(|y| foreground.row(y)[x0..x1].iter().filter(|&&m| m).count())
        .sum();
    let density = moving as f64 / ((x1 - x0) * (y1 - y0)) as f64;
    1.0 - density * (1.0 - min_confidence)
}

/// The box of a detection, px (its pixels span `[x0, x1 − 1]`).
fn person_box(d: &DetectedObject) -> BoundingBox {
    BoundingBox {
        left_px: d.bbox.x0 as f64,
        top_px: d.bbox.y0 as f64,
        width_px: d.bbox.width() as f64,
        height_px: d.bbox.height() as f64,
    }
}

/// `b` moved (not resized) to lie inside `within` as far as it fits.
fn clip_into(b: BoundingBox, within: &BoundingBox) -> BoundingBox {
    let place = |start: f64, size: f64, lo: f64, hi: f64| {
        if size >= hi - lo {
            start.clamp(hi - size, lo)
        } else {
            start.clamp(lo, hi - size)
        }
    };
    BoundingBox {
        left_px: place(b.left_px, b.width_px, within.left_px, within.right_px()),
        top_px: place(b.top_px, b.height_px, within.top_px, within.bottom_px()),
        ..b
    }
}

/// The share of `b`'s area inside `other`.
fn inside_share(b: &BoundingBox, other: &BoundingBox) -> f64 {
    let w = (b.right_px().min(other.right_px()) - b.left_px.max(other.left_px)).max(0.0);
    let h = (b.bottom_px().min(other.bottom_px()) - b.top_px.max(other.top_px)).max(0.0);
    let area = b.width_px * b.height_px;
    if area > 0.0 { w * h / area } else { 0.0 }
}

/// The colours of a detection's motion pixels.
fn masked_pixels(colour: &RgbImage, d: &DetectedObject) -> Vec<[u8; 3]> {
    let mut pixels = Vec::with_capacity(d.bbox.width() * d.bbox.height());
    for y in d.bbox.y0..d.bbox.y1 {
        let row = colour.row(y);
        let mask = d.mask.row(y - d.bbox.y0);
        pixels.extend(
            row[d.bbox.x0..d.bbox.x1]
                .iter()
                .zip(mask)
                .filter(|(_, m)| **m)
                .map(|(p, _)| *p),
        );
    }
    pixels
}

/// The frame's images must share one size and hold every detection.
fn check_sizes(input: &SiftPfFrame<'_>) -> Result<()> {
    let size = input.grey.dimensions();
    let frame = input.frame;
    if input.foreground.dimensions() != size || input.colour.is_some_and(|c| c.dimensions() != size)
    {
        return Err(Error::input(format!(
            "frame {frame}: the grey frame, the colour frame and the motion mask differ in size; \
             give the tracker the images of one frame"
        )));
    }
    if let Some(d) = input.detections.iter().find(|d| {
        d.bbox.x1 > size.0
            || d.bbox.y1 > size.1
            || d.mask.dimensions() != (d.bbox.width(), d.bbox.height())
    }) {
        return Err(Error::input(format!(
            "frame {frame}: a detection's box {:?} leaves the {}×{} frame or its mask does not match it",
            d.bbox, size.0, size.1
        )));
    }
    Ok(())
}
