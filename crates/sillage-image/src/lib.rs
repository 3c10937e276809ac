//! Pixel algorithms with no file IO, on [`GrayImage`](sillage_core::GrayImage) (`f32`, row-major,
//! grey levels in `[0, 1]`): the building blocks of the detectors of `sillage-detect`.
//!
//! - [`gaussian`]: a fast separable Gaussian blur ([`GaussianFilter`]);
//! - [`bandpass`]: blob filters at scale δ, a true difference of Gaussians ([`DogFilter`]) and a
//!   Laplacian of Gaussian ([`LogFilter`]), with a [`Polarity`];
//! - [`median`]: 3×3 and 5×5 median filters;
//! - [`maxima`]: local maxima above a threshold, deterministic ([`PeakFinder`]);
//! - [`subpixel`]: 3-point quadratic and Gaussian fits (TracTrac Eqs. (3)–(4));
//! - [`stats`]: thread-count-independent mean and standard deviation, and a robust noise
//!   level (median and MAD of a fixed subsample);
//! - [`background`]: TracTrac's slew-limited background model (Eqs. (1)–(2));
//! - [`levels`]: 8-bit grey levels, encoded from and decoded to `f32` frames;
//! - [`mask`]: masks and rectangular regions of interest ([`Roi`]);
//! - [`histogram`]: HSV colour and frame-difference histograms of boxes ([`BinImage`],
//!   [`HsvBinning`]) compared by the Bhattacharyya coefficient, the observation model of the
//!   pedestrian IMM particle filter (Pérez, Vermaak & Blake 2004);
//! - [`sift`]: SIFT keypoints and descriptors (Lowe 2004, as OpenCV), with descriptors at any
//!   position, scale and orientation for the SIFT-PF tracker ([`SiftDetector`]).
//!
//! Filters own their scratch buffers, so processing frame after frame allocates nothing once
//! the first frame has sized them, and every result is bit-identical whatever the number of
//! rayon threads.
//!
//! ```
//! use sillage_core::GrayImage;
//! use sillage_image::{DogFilter, PeakFinder, Polarity, SubpixelFit, refine_peak};
//!
//! // One bright Gaussian spot centred at (20.3, 15.8).
//! let (w, h) = (40, 32);
//! let data = (0..w * h)
//!     .map(|i| {
//!         let (x, y) = ((i % w) as f64 - 20.3, (i / w) as f64 - 15.8);
//!         (-(x * x + y * y) / (2.0 * 1.2 * 1.2)).exp() as f32
//!     })
//!     .collect();
//! let frame = GrayImage::from_vec(w, h, data)?;
//!
//! let mut filtered = GrayImage::default();
//! DogFilter::new(2.0)?.apply(&frame, Polarity::Bright, &mut filtered);
//! let mut peaks = Vec::new();
//! PeakFinder::new().find(&filtered, 1, 0.05, &mut peaks);
//! assert_eq!(peaks.len(), 1);
//! let pos = refine_peak(&filtered, peaks[0].x, peaks[0].y, SubpixelFit::Gaussian).unwrap();
//! assert!((pos.x - 20.3).abs() < 0.05 && (pos.y - 15.8).abs() < 0.05);
//! # Ok::<(), sillage_core::Error>(())
//! ```

pub mod background;
pub mod bandpass;
pub mod box_mean;
pub mod components;
pub mod dominant_colours;
pub mod gaussian;
pub mod histogram;
pub mod levels;
pub mod mask;
pub mod maxima;
pub mod median;
pub mod morphology;
pub mod ncc;
pub mod reconstruct;
mod separable;
pub mod sift;
pub mod stats;
pub mod structuring;
pub mod subpixel;

pub use background::BackgroundModel;
pub use bandpass::{DogFilter, LogFilter, MAX_SCALE_PX, Polarity};
pub use box_mean::{BoxMean, box_mean_3x3};
pub use components::{Component, ComponentLabeller, PixelBox};
pub use dominant_colours::{DominantColours, WeightedColour};
pub use gaussian::{GaussianFilter, GaussianKernel, MAX_SIGMA_PX};
pub use histogram::{
    BinImage, BoxPx, HsvBinning, MAX_BINS, bhattacharyya_coefficient, bhattacharyya_distance,
};
pub use levels::{decode_levels, encode_levels};
pub use mask::{Roi, apply_mask};
pub use maxima::{Peak, PeakFinder};
pub use median::{MedianSize, median_filter};
pub use morphology::Morphology;
pub use ncc::{MAX_TEMPLATE_RADIUS_PX, RingCorrelator, RingTemplate};
pub use reconstruct::Reconstruction;
pub use sift::{SiftDescriptor, SiftDetector, SiftKeypoint, SiftParams};
pub use stats::{MeanStd, MedianMad, mean_std, median_mad, median_mad_of};
pub use structuring::{MAX_ELEMENT_RADIUS_PX, StructuringElement};
pub use subpixel::{SubpixelFit, parabola_offset, refine_peak};
