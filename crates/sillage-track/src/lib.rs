//! Trackers: one module per algorithm, each implementing [`sillage_core::Tracker`].
//!
//! - [`ptv`]: TracTrac-class particle tracking velocimetry — three-frame mutual
//!   nearest-neighbour association with a local-flow motion model and an adaptive outlier
//!   filter (Heyman, TracTrac, §3.1.2–3.1.4).
//! - [`bedload`]: MMPF+, the multi-model particle filter of bedload beads, and the MMPF, PF,
//!   Kalman IMM and deterministic baselines of its Table 1 (Lafaye de Micheaux et al. 2018).
//! - [`immpf`]: pedestrians, one IMM particle filter per person with competing motion models
//!   (Madrigal & Hayet).
//! - [`sort`]: SORT (Bewley et al. 2016), the box-tracking baseline on detections;
//!   [`bytetrack`]: ByteTrack (Zhang et al. 2022), as `supervision` implements it.
//! - [`stitch`]: joins the tracks of overlapping time windows tracked apart (distributed runs).
//!
//! ```
//! use sillage_core::{Detection, FrameObservations, Point2, TrackPoint, Tracker};
//! use sillage_track::ptv::{PtvParams, PtvTracker};
//!
//! let mut tracker = PtvTracker::new(PtvParams::default()).unwrap();
//! let mut points: Vec<TrackPoint> = Vec::new();
//! for frame in 0..4u64 {
//!     // Two particles moving right by 1.5 px/frame.
//!     let detections: Vec<Detection> = [10.0, 50.0]
//!         .iter()
//!         .map(|&y| Detection::new(Point2::new(5.0 + 1.5 * frame as f64, y), 1.0))
//!         .collect();
//!     let observations = FrameObservations::from_detections(frame, &detections);
//!     tracker.step(&observations, &mut points).unwrap();
//! }
//! tracker.finish(&mut points).unwrap();
//! // Frames 1 and 2 are the middles of the two triplets.
//! assert_eq!(points.len(), 4);
//! assert_eq!(points[0].vel_px_per_frame.unwrap().x, 1.5);
//! assert_eq!(points[0].track_id, points[2].track_id);
//! ```

pub mod bedload;
pub mod bytetrack;
pub mod immpf;
pub mod ptv;
pub mod siftpf;
pub mod sort;
pub mod stitch;
