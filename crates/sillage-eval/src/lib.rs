//! Metrics as pure functions of truth and estimate: PTV recovery indexes, detection recall/precision.
