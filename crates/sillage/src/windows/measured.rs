//! What a windowed run decides once, on the sequence's first frames, and gives every window:
//! the particle images behind an `"auto"` blob scale or polarity, and PTV's `"auto"`
//! displacement-voting decision. A window deciding on its own first frames would detect or
//! link differently from its neighbours (and from the single run) wherever the flow has
//! changed since the start: on the time-periodic vortex of `docs/scale.md`, windows starting
//! in a slow phase turned voting off and lost up to 3 % of the points of the next fast phase.

use serde::{Deserialize, Serialize};
use sillage_core::{Result, TrackPoint};
use sillage_detect::ParticleImages;
use sillage_io::{Frame, FrameOptions, open_frames};
use sillage_track::ptv::VoteSearch;

use crate::config::{DetectorConfig, PipelineConfig, TrackerConfig};
use crate::pipeline::Pipeline;
use crate::tracking::Tracking;

/// Frames the voting decision is made on (the first link needs two, the tracker emits after
/// three).
const DECISION_FRAMES: usize = 3;

/// PTV's automatic voting decision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Voting {
    /// On, with this search radius, px.
    On(f64),
    /// Off.
    Off,
}

/// The decisions of a run's first frames, for its windows.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The particle images of the first frame (a blob detector with an `"auto"` scale or
    /// polarity).
    pub particles: Option<ParticleImages>,
    /// PTV's voting with `vote_search_px = "auto"` (each window still votes its own first
    /// link, then links as the run does).
    pub voting: Option<Voting>,
}

impl Measured {
    /// Decides on the first frames of `frames` (a sequence from its start, opened again at
    /// each call) what a single run with `config` decides there.
    pub fn on_frames<I>(config: &PipelineConfig, frames: impl Fn() -> Result<I>) -> Result<Self>
    where
        I: Iterator<Item = Result<Frame>>,
    {
        let mut pipeline = Pipeline::from_config(config)?;
        if pipeline.background_init_frames() > 0 {
            pipeline.prime_background(frames()?)?;
        }
        if let DetectorConfig::Blob(_) = config.detector
            && let Some(first) = frames()?.next()
        {
            pipeline.calibrate(&first?)?;
        }
        let particles = pipeline.calibration().and_then(|c| c.measured);
        let voting = match &config.tracker {
            TrackerConfig::Ptv(params) if params.vote_search_px == VoteSearch::AUTO => {
                let mut points: Vec<TrackPoint> = Vec::new();
                let summary =
                    pipeline.run(frames()?.take(DECISION_FRAMES), &mut points, &mut |_| {})?;
                Some(summary.vote_search_px.map_or(Voting::Off, Voting::On))
            }
            _ => None,
        };
        Ok(Self { particles, voting })
    }

    /// [`Measured::on_frames`] on the frames of `source` for `tracking` (nothing for the
    /// pedestrian trackers, which decide nothing on their first frames).
    pub fn on_source(source: &str, tracking: &Tracking) -> Result<Self> {
        match tracking {
            Tracking::Pipeline(config) => {
                Self::on_frames(config, || open_frames(source, &FrameOptions::default()))
            }
            Tracking::Immpf(_) | Tracking::Siftpf(_) => Ok(Self::default()),
        }
    }

    /// Gives `pipeline` (a window's) these decisions in place of its own.
    pub fn adopt(&self, pipeline: &mut Pipeline) -> Result<()> {
        if let Some(particles) = self.particles {
            pipeline.calibrate_with(particles)?;
        }
        if let Some(voting) = self.voting {
            pipeline.follow_vote_decision(match voting {
                Voting::On(radius) => Some(radius),
                Voting::Off => None,
            });
        }
        Ok(())
    }
}
