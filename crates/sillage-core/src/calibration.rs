//! Conversion between pixel/frame units and physical units, used only at the edges.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Spatial and temporal calibration of a sequence: metres per pixel and frames per second.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// Size of one pixel in metres.
    pub m_per_px: f64,
    /// Acquisition rate in frames per second.
    pub fps: f64,
}

impl Calibration {
    /// A calibration, checked: both values must be finite and positive.
    pub fn new(m_per_px: f64, fps: f64) -> Result<Self> {
        for (key, value) in [("m_per_px", m_per_px), ("fps", fps)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::parameter(
                    key,
                    value,
                    "must be a finite number greater than 0",
                ));
            }
        }
        Ok(Self { m_per_px, fps })
    }

    /// A velocity in px/frame expressed in m/s.
    pub fn speed_m_per_s(&self, px_per_frame: f64) -> f64 {
        px_per_frame * self.m_per_px * self.fps
    }

    /// A length in metres expressed in px.
    pub fn px_from_m(&self, metres: f64) -> f64 {
        metres / self.m_per_px
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_and_rejects_bad_values() {
        let c = Calibration::new(1e-4, 130.0).unwrap();
        assert!((c.speed_m_per_s(10.0) - 0.13).abs() < 1e-12);
        assert!((c.px_from_m(6e-3) - 60.0).abs() < 1e-9);
        let err = Calibration::new(0.0, 130.0).unwrap_err().to_string();
        assert!(err.contains("m_per_px"), "{err}");
        assert!(Calibration::new(1e-4, f64::NAN).is_err());
    }
}
