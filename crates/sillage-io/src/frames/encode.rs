//! Writing frames as 16-bit grey PNG (the synthetic generator's output format).

use std::path::Path;

use image::ImageEncoder;
use image::codecs::png::PngEncoder;
use sillage_core::{Error, GrayImage, Result};

use crate::partial::PartialFile;

/// Writes `image` as a 16-bit grey PNG at `path`; values are clamped to `[0, 1]` and scaled
/// to 0..=65535. The file is written under a temporary name and renamed when complete.
pub fn write_png16(path: impl AsRef<Path>, image: &GrayImage) -> Result<()> {
    let path = path.as_ref();
    let (width, height) = image.dimensions();
    let (Ok(w), Ok(h)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(Error::input(format!(
            "{}: a {width}×{height} image is too large for PNG",
            path.display()
        )));
    };
    let bytes: Vec<u8> = image
        .as_slice()
        .iter()
        .flat_map(|&v| {
            // NaN clamps to 0 through the saturating cast.
            ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_ne_bytes()
        })
        .collect();
    let mut file = PartialFile::create(path)?;
    match PngEncoder::new(&mut file).write_image(&bytes, w, h, image::ExtendedColorType::L16) {
        Ok(()) => file.commit().map(drop),
        Err(e) => {
            let partial = file.partial_path().to_path_buf();
            file.abandon();
            Err(Error::format(
                partial,
                None,
                format!("cannot encode PNG: {e}"),
            ))
        }
    }
}
