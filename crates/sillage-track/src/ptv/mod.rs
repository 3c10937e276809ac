//! TracTrac-class particle tracking velocimetry (Heyman, TracTrac, §3.1.2–3.1.4).
//!
//! At each new frame t, [`PtvTracker`]:
//! 1. predicts where the points of frame t−1 go, `x + U·dt`, with a motion model averaged
//!    over the k nearest velocity samples (Eqs. 8–9; `U = 0` until two samples exist),
//!    optionally corrected by displacement voting (`vote_search_px`, see `voting`), and
//!    blended with each trajectory's own last displacement where that errs less
//!    (`own_motion`);
//! 2. keeps the mutual nearest-neighbour pairs between the predictions and frame t;
//! 3. makes a tracklet of every point of frame t−1 paired both backwards (t−2 ↔ t−1) and
//!    forwards (t−1 ↔ t), with central-difference kinematics (Eqs. 6–7);
//! 4. rejects tracklets whose log prediction error is an outlier (Eqs. 10–12);
//! 5. hands track ids over from link to link (§3.1.4) and emits frame t−1, its velocities
//!    and accelerations fitted along each trajectory over up to `velocity_window` frames
//!    (see `smoothing`; 3 is TracTrac's Eqs. 6–7), which holds points back
//!    `velocity_window / 2 − 1` frames; a point rejected in step 4 between two kept points of
//!    its trajectory, on a path smooth to the positions' noise, is written too
//!    (`restore_flanked`).
//!
//! It follows what TracTrac's Python code does where it differs from the paper's text; each
//! function says where. Training passes (TracTrac's `vid_loop`) are driven by the caller
//! through [`PtvTracker::start_pass`].

mod filter;
mod motion;
mod params;
mod smoothing;
mod tracker;
mod voting;

pub use params::{
    AUTO_VOTE_FIRST_LINK_SPACINGS, AUTO_VOTE_MARGIN, AUTO_VOTE_MIN_VALID_SHARE, AUTO_VOTE_SPACINGS,
    AUTO_VOTE_UNRESOLVED_SPACINGS, DEFAULT_OWN_MOTION, DEFAULT_RESTORE_FLANKED,
    DEFAULT_VELOCITY_WINDOW, DEFAULT_WARM_UP_FRAMES, MAX_VELOCITY_WINDOW, MAX_WARM_UP_FRAMES,
    PtvParams, VoteMode, VoteSearch,
};
pub use tracker::{PassDirection, PtvTracker};
