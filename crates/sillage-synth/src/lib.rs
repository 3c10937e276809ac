//! Seeded synthetic scenes with ground truth: the TracTrac vortex flow and its renderer.
