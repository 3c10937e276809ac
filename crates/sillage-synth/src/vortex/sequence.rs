//! The rendered vortex sequence: images plus truth, one frame at a time.

use rand::RngExt;
use sillage_core::{FrameIndex, GrayImage, Point2, Result, TruthPoint, rng_stream};

use super::{VortexParams, VortexTruth};
use crate::render::render_into;

/// Tag of the pixel-noise streams, kept apart from the particle streams `(seed, track_id)`.
const NOISE_STREAM_TAG: u64 = 1 << 63;

/// One synthetic frame: its image and the truth of the particles drawn in it.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticFrame {
    /// Index of the frame.
    pub index: FrameIndex,
    /// The rendered frame (see [`crate::render_spots`] for the pixel model).
    pub image: GrayImage,
    /// True positions and velocities (see [`VortexTruth`]).
    pub truth: Vec<TruthPoint>,
}

/// The vortex sequence of the TracTrac paper (§4.1.1): each frame is a Gaussian blob of std
/// `blob_sigma_px` and peak `peak` on every particle, plus uncorrelated noise of magnitude
/// `peak / snr`. Streams frames in bounded memory; the same parameters give the same frames.
#[derive(Debug, Clone)]
pub struct VortexSequence {
    truth: VortexTruth,
    spots: Vec<(Point2, f64, f64)>,
}

impl VortexSequence {
    /// The sequence `params` describe; fails on invalid parameters, naming the key.
    pub fn new(params: VortexParams) -> Result<Self> {
        Ok(Self {
            truth: VortexTruth::new(&params)?,
            spots: Vec::with_capacity(params.n_particles),
        })
    }

    /// The parameters of the sequence.
    pub fn params(&self) -> &VortexParams {
        self.truth.params()
    }
}

impl Iterator for VortexSequence {
    type Item = SyntheticFrame;

    fn next(&mut self) -> Option<SyntheticFrame> {
        let frame = self.truth.next()?;
        let params = self.truth.params();
        self.spots.clear();
        self.spots.extend(frame.truth.iter().map(|point| {
            let sigma = params.blob_sigma_of(point.track_id);
            (point.pos_px, params.peak, sigma)
        }));
        let noise_seed = rng_stream(params.seed, NOISE_STREAM_TAG | frame.index).random();
        let mut image = GrayImage::new(params.width, params.height);
        render_into(&mut image, &self.spots, params.pixel_noise(), noise_seed);
        Some(SyntheticFrame {
            index: frame.index,
            image,
            truth: frame.truth,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.truth.size_hint()
    }
}

impl ExactSizeIterator for VortexSequence {}
