//! Detectors built from `sillage-image`: TracTrac's blob detector (DoG/LoG, threshold, local
//! maxima, sub-pixel fit) and the frame pre-processing in front of it (median filter,
//! background subtraction, mask); the bedload bead detectors; the motion detector (Gaussian
//! mixture background, person-sized blobs) of the pedestrian trackers.
//!
//! Both are deterministic, validate their parameters once at construction (errors name the
//! key and its allowed range) and reuse their buffers from frame to frame.
//!
//! ```
//! use sillage_core::{Detector, GrayImage};
//! use sillage_detect::{BlobDetector, BlobParams, PreprocessParams, Preprocessor};
//!
//! // Two bright Gaussian spots, σ = 1.2 px, at (12.25, 10.5) and (30.0, 20.75).
//! let (w, h) = (48, 32);
//! let spot = |x: f64, y: f64, cx: f64, cy: f64| {
//!     (-((x - cx).powi(2) + (y - cy).powi(2)) / (2.0 * 1.44)).exp()
//! };
//! let data = (0..w * h)
//!     .map(|i| {
//!         let (x, y) = ((i % w) as f64, (i / w) as f64);
//!         (0.1 + 0.5 * (spot(x, y, 12.25, 10.5) + spot(x, y, 30.0, 20.75))) as f32
//!     })
//!     .collect();
//! let frame = GrayImage::from_vec(w, h, data)?;
//!
//! let mut preprocessor = Preprocessor::new(PreprocessParams::default())?;
//! let mut detector = BlobDetector::new(BlobParams::default())?;
//! let (mut image, mut detections) = (GrayImage::default(), Vec::new());
//! preprocessor.process(&frame, None, &mut image)?;
//! detector.detect(&image, &mut detections)?;
//! assert_eq!(detections.len(), 2);
//! assert!((detections[0].pos_px.x - 12.25).abs() < 0.05);
//! assert!((detections[1].pos_px.y - 20.75).abs() < 0.05);
//! # Ok::<(), sillage_core::Error>(())
//! ```

pub mod bead;
pub mod blob;
mod cell_grid;
mod deblend;
mod matched_refine;
pub mod motion;
pub mod particle_size;
pub mod preprocess;

pub use bead::{BeadDetections, BeadDetector, BeadGeometry, BeadParams};
pub use blob::{
    AUTO_SCALE_BASE_PX, BlobDetector, BlobFilter, BlobParams, Calibration, DEFAULT_NOISE_K,
    PolarityChoice, Scale, Threshold, auto_scale_px,
};
pub use motion::{MotionBlob, MotionDetector, MotionParams};
pub use particle_size::{ParticleImages, measure_particle_images};
pub use preprocess::{BackgroundParams, PreprocessParams, Preprocessor};
pub use sillage_image::{MedianSize, Polarity, Roi, SubpixelFit};
