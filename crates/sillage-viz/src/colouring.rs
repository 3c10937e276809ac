//! How tracks are coloured on trajectory plots and overlays: by speed (viridis), by motion
//! state, or by identity.

use sillage_core::{Error, MotionState, Result, TrackPoint};

use crate::colormap::viridis;
use crate::history::velocity_px_per_frame;
use crate::palette::{id_rgb, state_rgb};

/// The colour of points without a speed (a track of one point).
pub(crate) const NO_SPEED_RGB: [u8; 3] = [160, 160, 160];

/// What a track's colour shows; each segment takes the colour of the point it ends at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackColouring {
    /// Speed on the viridis map, from 0 (dark violet) to `max_px_per_frame` (yellow) and
    /// beyond (clamped); see [`speed_scale`].
    Speed {
        /// The speed drawn yellow, px/frame.
        max_px_per_frame: f64,
    },
    /// Motion state (resting blue, rolling orange, saltating vermillion, unknown grey).
    State,
    /// Identity: a hue per track ([`id_rgb`]).
    Id,
}

impl Default for TrackColouring {
    /// By motion state, as overlays always were.
    fn default() -> Self {
        Self::State
    }
}

impl TrackColouring {
    /// Checks the speed scale.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Self::Speed { max_px_per_frame }
                if !(max_px_per_frame.is_finite() && max_px_per_frame > 0.0) =>
            {
                Err(Error::parameter(
                    "max_px_per_frame",
                    max_px_per_frame,
                    "give the speed of the top of the colour scale, > 0 px/frame",
                ))
            }
            _ => Ok(()),
        }
    }

    /// The colour of `track[i]` (`track`: one track's points in frame order, or a tail of
    /// them), and of the segment that ends there.
    pub fn point_rgb(&self, track: &[TrackPoint], i: usize) -> [u8; 3] {
        match *self {
            Self::Speed { max_px_per_frame } => velocity_px_per_frame(track, i)
                .map_or(NO_SPEED_RGB, |v| viridis(v.norm() / max_px_per_frame)),
            Self::State => state_rgb(
                track
                    .get(i)
                    .map_or(MotionState::Unknown, |p| p.motion_state),
            ),
            Self::Id => track.first().map_or(NO_SPEED_RGB, |p| id_rgb(p.track_id)),
        }
    }
}

/// A speed scale for [`TrackColouring::Speed`]: the 98th percentile of the speeds of every
/// point of `tracks` (so a few outliers do not darken everything), px/frame; 1 without any
/// positive speed.
pub fn speed_scale<'a>(tracks: impl IntoIterator<Item = &'a [TrackPoint]>) -> f64 {
    let mut speeds: Vec<f64> = tracks
        .into_iter()
        .flat_map(|track| (0..track.len()).filter_map(move |i| velocity_px_per_frame(track, i)))
        .map(|v| v.norm())
        .filter(|s| s.is_finite())
        .collect();
    if speeds.is_empty() {
        return 1.0;
    }
    speeds.sort_by(f64::total_cmp);
    let at = ((speeds.len() - 1) as f64 * 0.98).round() as usize;
    Some(speeds[at]).filter(|&s| s > 0.0).unwrap_or(1.0)
}

#[cfg(test)]
mod tests {
    use sillage_core::{Point2, Vec2};

    use super::*;

    #[test]
    fn each_colouring_reads_its_field() {
        let mut track: Vec<TrackPoint> = (0..3)
            .map(|k| TrackPoint::at(k, 9, Point2::new(2.0 * k as f64, 0.0)))
            .collect();
        track[2].motion_state = MotionState::Saltating;
        track[2].vel_px_per_frame = Some(Vec2::new(0.0, 8.0));
        let speed = TrackColouring::Speed {
            max_px_per_frame: 4.0,
        };
        assert_eq!(speed.point_rgb(&track, 0), viridis(0.5));
        assert_eq!(speed.point_rgb(&track, 2), viridis(1.0));
        assert_eq!(speed.point_rgb(&track[..1], 0), NO_SPEED_RGB);
        assert_eq!(
            TrackColouring::State.point_rgb(&track, 2),
            state_rgb(MotionState::Saltating)
        );
        assert_eq!(TrackColouring::Id.point_rgb(&track, 1), id_rgb(9));
        assert!(speed.validate().is_ok());
        let flat = TrackColouring::Speed {
            max_px_per_frame: 0.0,
        };
        assert!(
            flat.validate()
                .unwrap_err()
                .to_string()
                .contains("max_px_per_frame")
        );
    }

    #[test]
    fn the_speed_scale_ignores_the_fastest_two_percent() {
        let tracks: Vec<Vec<TrackPoint>> = (0..100)
            .map(|id| {
                let step = if id == 99 {
                    1000.0
                } else {
                    1.0 + id as f64 / 100.0
                };
                (0..2)
                    .map(|k| TrackPoint::at(k, id, Point2::new(step * k as f64, 0.0)))
                    .collect()
            })
            .collect();
        let scale = speed_scale(tracks.iter().map(Vec::as_slice));
        assert!((1.9..2.0).contains(&scale), "{scale}");
        assert_eq!(speed_scale(std::iter::empty()), 1.0);
    }
}
