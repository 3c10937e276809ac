//! The walkers sequence: colour and grey frames with their truth, one frame at a time.

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{FrameIndex, GrayImage, Result, RgbImage, rng_stream};

use super::appearance::{Appearance, Stride};
use super::motion::{WalkerPath, walker_paths};
use super::params::WalkersParams;
use super::render::{Background, Placed, finish_frame, paint_walker, visible_shares};

/// Tag of the per-frame noise streams `(seed, tag | frame)`.
const NOISE_STREAM_TAG: u64 = 1 << 63;

/// The truth of one walker in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WalkerTruth {
    /// Identity, from 1.
    pub id: u64,
    /// Left edge of the full (unoccluded) box, px (pixel centres at whole numbers, so the
    /// first column spans `[-0.5, 0.5]`).
    pub left_px: f64,
    /// Top edge of the full box, px.
    pub top_px: f64,
    /// Box width, px.
    pub width_px: f64,
    /// Box height, px.
    pub height_px: f64,
    /// Share of the walker's silhouette inside the frame and not covered by nearer walkers,
    /// in `[0, 1]` (MOTChallenge's visibility).
    pub visibility: f64,
    /// Distance from the camera in walker units (size ∝ 1 / depth): the smaller covers.
    pub depth: f64,
}

/// One frame of a walkers sequence: its pictures and the truth of the walkers in it.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkersFrame {
    /// Index of the frame, from 0.
    pub index: FrameIndex,
    /// The 8-bit colour frame (what `sillage synth walkers` writes as PNG).
    pub colour: RgbImage,
    /// Its Rec. 601 grey, bit for bit what reading the colour PNG back gives.
    pub grey: GrayImage,
    /// Walkers with part of their silhouette inside the frame, by id.
    pub truth: Vec<WalkerTruth>,
}

/// Synthetic people walking over a static background with occlusions, for the pedestrian
/// trackers (the SIFT-PF acceptance cases of Souded et al. 2011: a full occlusion, a group
/// that splits). Streams frames in bounded memory; the same parameters give the same frames
/// whatever the number of threads.
#[derive(Debug, Clone)]
pub struct WalkersSequence {
    params: WalkersParams,
    paths: Vec<WalkerPath>,
    looks: Vec<Appearance>,
    background: Background,
    noise_seed: u64,
    next_index: usize,
    canvas: Vec<[f32; 3]>,
    noise_buffer: Vec<f32>,
}

impl WalkersSequence {
    /// The sequence `params` describe; fails on invalid parameters or a frame too small for
    /// the scenario, naming the key.
    pub fn new(params: WalkersParams) -> Result<Self> {
        params.validate()?;
        let paths = walker_paths(&params);
        let aspect = params.walker_width_px / params.walker_height_px;
        let looks = paths
            .iter()
            .map(|path| Appearance::new(params.seed, path.id, aspect))
            .collect();
        Ok(Self {
            background: Background::new(params.width, params.height, params.seed),
            noise_seed: rng_stream(params.seed, NOISE_STREAM_TAG).random(),
            paths,
            looks,
            next_index: 0,
            canvas: Vec::with_capacity(params.width * params.height),
            noise_buffer: Vec::new(),
            params,
        })
    }

    /// The parameters of the sequence.
    pub fn params(&self) -> &WalkersParams {
        &self.params
    }

    /// The walkers present in `frame`, farthest first (ties by id): the painting order.
    fn placed(&self, frame: usize) -> Vec<(u64, f64, Placed<'_>)> {
        let mut placed: Vec<_> = self
            .paths
            .iter()
            .zip(&self.looks)
            .filter_map(|(path, look)| {
                let top_left = path.top_left_at(frame)?;
                let walker = Placed {
                    look,
                    top_left,
                    width_px: path.width_px,
                    height_px: path.height_px,
                    stride: Stride::after(frame - path.first_frame),
                };
                Some((path.id, path.depth, walker))
            })
            .collect();
        placed.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        placed
    }

    /// Renders frame `index` (assumed < `n_frames`).
    fn render(&mut self, index: usize) -> WalkersFrame {
        let (width, height) = (self.params.width, self.params.height);
        let mut canvas = std::mem::take(&mut self.canvas);
        canvas.clear();
        canvas.extend_from_slice(self.background.pixels());
        let placed = self.placed(index);
        let mut truth = Vec::with_capacity(placed.len());
        for (k, (id, depth, walker)) in placed.iter().enumerate() {
            paint_walker(&mut canvas, width, walker);
            let nearer: Vec<Placed> = placed[k + 1..].iter().map(|p| p.2).collect();
            let (in_frame, visibility) = visible_shares(walker, &nearer, width, height);
            if in_frame > 0.0 {
                truth.push(WalkerTruth {
                    id: *id,
                    left_px: walker.top_left.x,
                    top_px: walker.top_left.y,
                    width_px: walker.width_px,
                    height_px: walker.height_px,
                    visibility,
                    depth: *depth,
                });
            }
        }
        truth.sort_by_key(|t| t.id);
        let frame_seed: u64 = rng_stream(self.noise_seed, index as u64).random();
        let mut colour = RgbImage::new(width, height);
        let mut grey = GrayImage::new(width, height);
        finish_frame(
            &canvas,
            self.params.noise,
            frame_seed,
            &mut self.noise_buffer,
            &mut colour,
            &mut grey,
        );
        self.canvas = canvas;
        WalkersFrame {
            index: index as FrameIndex,
            colour,
            grey,
            truth,
        }
    }
}

impl Iterator for WalkersSequence {
    type Item = WalkersFrame;

    fn next(&mut self) -> Option<WalkersFrame> {
        if self.next_index >= self.params.n_frames {
            return None;
        }
        let frame = self.render(self.next_index);
        self.next_index += 1;
        Some(frame)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.params.n_frames - self.next_index;
        (left, Some(left))
    }
}

impl ExactSizeIterator for WalkersSequence {}
