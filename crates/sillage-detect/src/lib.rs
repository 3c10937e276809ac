//! Detectors built from sillage-image: DoG/LoG blob detection with sub-pixel refinement.
