//! Masks and rectangular regions of interest.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Result};

/// Errors unless `b` has the size of `a`; `what` names `b` in the message.
pub(crate) fn check_same_size(a: &GrayImage, b: &GrayImage, what: &str) -> Result<()> {
    if a.dimensions() == b.dimensions() {
        Ok(())
    } else {
        Err(Error::input(format!(
            "the {what} is {}×{} px but {}×{} px was expected; give images of one size",
            b.width(),
            b.height(),
            a.width(),
            a.height()
        )))
    }
}

/// `image ← image · mask`, pixel by pixel (TracTrac's `<name>_mask.tif`, multiplied into every
/// frame). Errors when the sizes differ.
pub fn apply_mask(image: &mut GrayImage, mask: &GrayImage) -> Result<()> {
    check_same_size(image, mask, "mask")?;
    let width = image.width().max(1);
    image
        .as_mut_slice()
        .par_chunks_mut(width)
        .zip(mask.as_slice().par_chunks(width))
        .for_each(|(row, m)| {
            for (v, &m) in row.iter_mut().zip(m) {
                *v *= m;
            }
        });
    Ok(())
}

/// A rectangle of pixels `x0 ≤ x < x1`, `y0 ≤ y < y1` (0-based, exclusive maximum).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Roi {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl Roi {
    /// The whole `width × height` frame.
    pub fn full(width: usize, height: usize) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.x1.saturating_sub(self.x0)
    }

    /// Number of rows.
    pub fn height(&self) -> usize {
        self.y1.saturating_sub(self.y0)
    }

    /// Errors unless the rectangle is non-empty (`x0 < x1`, `y0 < y1`); `key` names the
    /// parameter in the message.
    pub fn validate(&self, key: &str) -> Result<()> {
        if self.x0 < self.x1 && self.y0 < self.y1 {
            Ok(())
        } else {
            Err(Error::parameter(
                key,
                self,
                "needs x0 < x1 and y0 < y1 (pixel bounds, exclusive maximum)",
            ))
        }
    }

    /// Errors unless the rectangle is non-empty and inside a `width × height` frame.
    pub fn validate_for(&self, key: &str, width: usize, height: usize) -> Result<()> {
        self.validate(key)?;
        if self.x1 <= width && self.y1 <= height {
            Ok(())
        } else {
            Err(Error::parameter(
                key,
                self,
                format!(
                    "must lie inside the {width}×{height} px frame (x1 ≤ {width}, y1 ≤ {height})"
                ),
            ))
        }
    }

    /// Copies the region of `src` into `dst` (reshaped to the region's size), after checking
    /// it lies inside `src`.
    pub fn crop(&self, src: &GrayImage, dst: &mut GrayImage) -> Result<()> {
        self.validate_for("roi", src.width(), src.height())?;
        dst.reshape(self.width(), self.height());
        for (y, out) in (self.y0..self.y1).zip(dst.as_mut_slice().chunks_exact_mut(self.width())) {
            out.copy_from_slice(&src.row(y)[self.x0..self.x1]);
        }
        Ok(())
    }
}

impl std::fmt::Display for Roi {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{{ x0 = {}, y0 = {}, x1 = {}, y1 = {} }}",
            self.x0, self.y0, self.x1, self.y1
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roi_validates_and_crops() {
        let src = GrayImage::from_vec(4, 3, (0..12).map(|v| v as f32).collect()).unwrap();
        let roi = Roi {
            x0: 1,
            y0: 1,
            x1: 3,
            y1: 3,
        };
        let mut dst = GrayImage::default();
        roi.crop(&src, &mut dst).unwrap();
        assert_eq!(dst.as_slice(), &[5.0, 6.0, 9.0, 10.0]);
        let e = Roi {
            x0: 0,
            y0: 0,
            x1: 5,
            y1: 3,
        }
        .crop(&src, &mut dst)
        .unwrap_err();
        assert!(e.to_string().contains("roi"), "{e}");
        assert!(
            Roi {
                x0: 2,
                y0: 0,
                x1: 2,
                y1: 1
            }
            .validate("roi")
            .is_err()
        );
        assert_eq!(Roi::full(4, 3).width(), 4);
    }

    #[test]
    fn mask_multiplies_and_checks_size() {
        let mut im = GrayImage::from_vec(2, 1, vec![0.5, 0.8]).unwrap();
        apply_mask(&mut im, &GrayImage::from_vec(2, 1, vec![1.0, 0.0]).unwrap()).unwrap();
        assert_eq!(im.as_slice(), &[0.5, 0.0]);
        assert!(apply_mask(&mut im, &GrayImage::new(1, 1)).is_err());
    }
}
