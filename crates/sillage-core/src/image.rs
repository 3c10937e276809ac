//! Owned row-major image buffers. Frames travel as [`GrayImage`]: grey levels in `[0, 1]`.

use crate::{Error, Result};

/// A row-major image of `width × height` pixels of type `T`.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Image<T> {
    width: usize,
    height: usize,
    data: Vec<T>,
}

/// A grey-level frame as `f32`, normalised so that the sensor's full scale is 1 (8-bit values
/// are divided by 255, 16-bit by 65535).
pub type GrayImage = Image<f32>;

/// An 8-bit colour picture (red, green, blue), as charts and overlays are drawn.
pub type RgbImage = Image<[u8; 3]>;

/// Rec. 601 luma weights for R, G, B: the weights OpenCV's `BGR2GRAY` uses, the one colour to
/// grey conversion of the workspace (frame decoding, synthetic colour frames).
pub const LUMA_601: [f32; 3] = [0.299, 0.587, 0.114];

/// The Rec. 601 luma of an 8-bit colour pixel, in `[0, 1]`: bit for bit what decoding the
/// pixel from a colour PNG gives (each sample / 255, then the weighted sum).
pub fn luma_601(rgb: [u8; 3]) -> f32 {
    let unit = |v: u8| f32::from(v) / 255.0;
    LUMA_601[0] * unit(rgb[0]) + LUMA_601[1] * unit(rgb[1]) + LUMA_601[2] * unit(rgb[2])
}

impl<T: Copy + Default> Image<T> {
    /// A `width × height` image filled with `T::default()`.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![T::default(); width * height],
        }
    }

    /// Wraps `data` (row-major, `width × height` values).
    pub fn from_vec(width: usize, height: usize, data: Vec<T>) -> Result<Self> {
        if data.len() != width * height {
            return Err(Error::input(format!(
                "an image of {width}×{height} pixels needs {} values, got {}",
                width * height,
                data.len()
            )));
        }
        Ok(Self {
            width,
            height,
            data,
        })
    }

    /// Re-shapes this buffer to `width × height`, keeping its allocation when it is large
    /// enough (so per-frame buffers are reused). Pixel values are unspecified afterwards.
    pub fn reshape(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.resize(width * height, T::default());
    }

    /// Width in pixels (number of columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels (number of rows).
    pub fn height(&self) -> usize {
        self.height
    }

    /// `(width, height)`.
    pub fn dimensions(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// All pixels, row-major.
    pub fn as_slice(&self) -> &[T] {
        &self.data
    }

    /// All pixels, row-major, mutable.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// The pixel buffer, consumed.
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }

    /// Row `y`.
    pub fn row(&self, y: usize) -> &[T] {
        &self.data[y * self.width..(y + 1) * self.width]
    }

    /// Row `y`, mutable.
    pub fn row_mut(&mut self, y: usize) -> &mut [T] {
        &mut self.data[y * self.width..(y + 1) * self.width]
    }

    /// Pixel at column `x`, row `y`.
    pub fn get(&self, x: usize, y: usize) -> T {
        self.data[y * self.width + x]
    }

    /// Sets the pixel at column `x`, row `y`.
    pub fn set(&mut self, x: usize, y: usize, value: T) {
        self.data[y * self.width + x] = value;
    }

    /// True when the image has no pixel.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indexing_is_row_major() {
        let mut im = GrayImage::new(3, 2);
        im.set(2, 1, 0.5);
        assert_eq!(im.as_slice()[5], 0.5);
        assert_eq!(im.row(1), &[0.0, 0.0, 0.5]);
        assert!(Image::<u8>::from_vec(2, 2, vec![0; 3]).is_err());
        im.reshape(1, 1);
        assert_eq!(im.dimensions(), (1, 1));
    }
}
