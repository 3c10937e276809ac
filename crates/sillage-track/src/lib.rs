//! Trackers: PTV (TracTrac-class three-frame association with a local-flow predictor).
