//! The vocabulary every sillage crate speaks.
//!
//! Roles, from left to right along the pipeline (see `ARCHITECTURE.md`):
//! - a [`Detector`] turns a [`GrayImage`] into [`Detection`]s;
//! - a [`Tracker`] consumes one frame of [`FrameObservations`] at a time and pushes final
//!   [`TrackPoint`]s into a [`TrackSink`] (a writer, a collector or a metric);
//! - ground truth is a stream of [`TruthPoint`]s.
//!
//! Conventions: pixel coordinates with the origin at the centre of the top-left pixel, `x`
//! along columns, `y` down rows; positions in px, velocities in px/frame, accelerations in
//! px/frame². Physical units only through [`Calibration`].
//!
//! ```
//! use sillage_core::{Detection, Point2, TrackPoint, TrackSink};
//! let mut collected: Vec<TrackPoint> = Vec::new();
//! let point = TrackPoint::at(3, 7, Point2::new(10.5, 4.25));
//! collected.accept(&[point]).unwrap();
//! assert_eq!(collected[0].track_id, 7);
//! let detection = Detection::new(Point2::new(1.0, 2.0), 0.5);
//! assert_eq!(detection.pos_px.y, 2.0);
//! ```

mod bbox;
mod calibration;
mod error;
mod geometry;
pub mod homography;
mod image;
mod observation;
mod rng;
mod roles;
mod settings;
mod simd;

pub use bbox::BoundingBox;
pub use calibration::Calibration;
pub use error::{Error, Result};
pub use geometry::{Point2, Vec2};
pub use homography::{Homography, PedestrianSize};
pub use image::{GrayImage, Image, LUMA_601, RgbImage, luma_601};
pub use observation::{
    BLACK_BEAD_CLASS, Detection, FrameIndex, MotionState, ObjectClass, TRANSPARENT_BEAD_CLASS,
    TrackId, TrackPoint, TruthPoint,
};
pub use rng::{RngStream, rng_stream};
pub use roles::{Detector, DiscardSink, FrameObservations, TrackSink, Tracker};
pub use settings::NumberOrWord;
