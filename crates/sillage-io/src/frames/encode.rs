//! Writing pictures: frames as 16-bit grey PNG (the synthetic generator's output format),
//! charts and overlays as 8-bit colour PNG, vector charts as text (SVG). Every file is written
//! under a temporary name and renamed when complete.

use std::path::Path;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use sillage_core::{Error, GrayImage, Image, Result, RgbImage};

use crate::partial::PartialFile;

/// Writes `image` as a 16-bit grey PNG at `path`; values are clamped to `[0, 1]` and scaled
/// to 0..=65535.
pub fn write_png16(path: impl AsRef<Path>, image: &GrayImage) -> Result<()> {
    let bytes: Vec<u8> = image
        .as_slice()
        .iter()
        .flat_map(|&v| {
            // NaN clamps to 0 through the saturating cast.
            ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_ne_bytes()
        })
        .collect();
    write_png(path.as_ref(), image, &bytes, ExtendedColorType::L16)
}

/// Writes `image` as an 8-bit colour PNG at `path` (charts, overlays).
pub fn write_png_rgb(path: impl AsRef<Path>, image: &RgbImage) -> Result<()> {
    let bytes = image.as_slice().as_flattened();
    write_png(path.as_ref(), image, bytes, ExtendedColorType::Rgb8)
}

/// Writes `text` at `path` (an SVG chart, a report).
pub fn write_text(path: impl AsRef<Path>, text: &str) -> Result<()> {
    let path = path.as_ref();
    let mut file = PartialFile::create(path)?;
    match file.write_all(text.as_bytes()) {
        Ok(()) => file.commit().map(drop),
        Err(e) => {
            file.abandon();
            Err(e)
        }
    }
}

/// Encodes `bytes`, the pixels of `image` in `colour`, as PNG at `path`.
fn write_png<T>(
    path: &Path,
    image: &Image<T>,
    bytes: &[u8],
    colour: ExtendedColorType,
) -> Result<()>
where
    T: Copy + Default,
{
    let (width, height) = image.dimensions();
    let (Ok(w), Ok(h)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(Error::input(format!(
            "{}: a {width}×{height} image is too large for PNG",
            path.display()
        )));
    };
    let mut file = PartialFile::create(path)?;
    match PngEncoder::new(&mut file).write_image(bytes, w, h, colour) {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_png_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rgb.png");
        let pixels = vec![
            [255, 0, 0],
            [0, 255, 0],
            [0, 0, 255],
            [7, 8, 9],
            [1, 2, 3],
            [0, 0, 0],
        ];
        write_png_rgb(&path, &RgbImage::from_vec(3, 2, pixels.clone()).unwrap()).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (3, 2));
        assert_eq!(back.as_raw().as_slice(), pixels.as_flattened());
    }

    #[test]
    fn text_is_written_whole_under_its_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("chart.svg");
        write_text(&path, "<svg/>").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "<svg/>");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
