//! Decoding one image file (PNG, JPEG, single-page TIFF) or one TIFF page into a [`GrayImage`]
//! (1-bit TIFFs with CCITT modified Huffman compression through [`super::ccitt`]).
//!
//! Grey levels are normalised to `[0, 1]`: 8-bit values are divided by 255, 16-bit by 65535;
//! 32/64-bit float grey is kept as is. Colour is converted to grey with the Rec. 601 luma
//! weights `0.299 R + 0.587 G + 0.114 B` (the weights OpenCV's `BGR2GRAY` uses, so frames
//! match TracTrac's); an alpha channel is dropped.

use std::path::Path;

use sillage_core::{GrayImage, Result};
use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult};

use super::ccitt;

/// Rec. 601 luma weights for R, G, B.
const LUMA_601: [f32; 3] = [0.299, 0.587, 0.114];

/// Why a frame could not be decoded; the caller adds the file and the frame index.
pub(crate) type DecodeResult<T> = std::result::Result<T, String>;

/// True when `path` has a TIFF extension (`.tif`, `.tiff`, any case).
pub(crate) fn is_tiff(path: &Path) -> bool {
    has_extension(path, &["tif", "tiff"])
}

/// True when the extension of `path` is one of `extensions` (lower case), ignoring case.
pub(crate) fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// Decodes the image file at `path` (for a TIFF, its first page).
pub(crate) fn decode_file(path: &Path) -> DecodeResult<GrayImage> {
    if is_tiff(path) {
        let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
        let mut decoder = Decoder::new(std::io::BufReader::new(file)).map_err(|e| e.to_string())?;
        decode_tiff_page(&mut decoder)
    } else {
        let image = image::ImageReader::open(path)
            .map_err(|e| e.to_string())?
            .with_guessed_format()
            .map_err(|e| e.to_string())?
            .decode()
            .map_err(|e| e.to_string())?;
        dynamic_to_gray(image)
    }
}

/// Width and height of the image file at `path`, read from its header only.
pub(crate) fn file_dimensions(path: &Path) -> DecodeResult<(usize, usize)> {
    let (w, h) = if is_tiff(path) {
        let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
        Decoder::new(std::io::BufReader::new(file))
            .and_then(|mut d| d.dimensions())
            .map_err(|e| e.to_string())?
    } else {
        image::ImageReader::open(path)
            .map_err(|e| e.to_string())?
            .with_guessed_format()
            .map_err(|e| e.to_string())?
            .into_dimensions()
            .map_err(|e| e.to_string())?
    };
    Ok((w as usize, h as usize))
}

/// Decodes the current page of a TIFF decoder.
pub(crate) fn decode_tiff_page<R: std::io::Read + std::io::Seek>(
    decoder: &mut Decoder<R>,
) -> DecodeResult<GrayImage> {
    let compression = decoder
        .find_tag_unsigned::<u16>(tiff::tags::Tag::Compression)
        .map_err(|e| e.to_string())?;
    if compression == Some(ccitt::MODIFIED_HUFFMAN) {
        return ccitt::decode_modified_huffman(decoder);
    }
    let (w, h) = decoder.dimensions().map_err(|e| e.to_string())?;
    let colour = decoder.colortype().map_err(|e| e.to_string())?;
    let channels = match colour {
        ColorType::Gray(_) => 1,
        ColorType::GrayA(_) => 2,
        ColorType::RGB(_) => 3,
        ColorType::RGBA(_) => 4,
        other => return Err(unsupported(&format!("TIFF colour type {other:?}"))),
    };
    let pixels = match decoder.read_image().map_err(|e| e.to_string())? {
        DecodingResult::U8(v) => to_luma(&v, channels, |p| f32::from(p) / 255.0),
        DecodingResult::U16(v) => to_luma(&v, channels, |p| f32::from(p) / 65535.0),
        DecodingResult::F32(v) => to_luma(&v, channels, |p| p),
        DecodingResult::F64(v) => to_luma(&v, channels, |p| p as f32),
        _ => return Err(unsupported(&format!("TIFF sample type of {colour:?}"))),
    };
    GrayImage::from_vec(w as usize, h as usize, pixels).map_err(|e| e.to_string())
}

/// Converts a decoded PNG/JPEG (or any `image` crate picture) to grey.
fn dynamic_to_gray(image: image::DynamicImage) -> DecodeResult<GrayImage> {
    use image::DynamicImage as D;
    let (w, h) = (image.width() as usize, image.height() as usize);
    let u8_scale = |p: u8| f32::from(p) / 255.0;
    let u16_scale = |p: u16| f32::from(p) / 65535.0;
    let pixels = match image {
        D::ImageLuma8(b) => to_luma(b.as_raw(), 1, u8_scale),
        D::ImageLumaA8(b) => to_luma(b.as_raw(), 2, u8_scale),
        D::ImageRgb8(b) => to_luma(b.as_raw(), 3, u8_scale),
        D::ImageRgba8(b) => to_luma(b.as_raw(), 4, u8_scale),
        D::ImageLuma16(b) => to_luma(b.as_raw(), 1, u16_scale),
        D::ImageLumaA16(b) => to_luma(b.as_raw(), 2, u16_scale),
        D::ImageRgb16(b) => to_luma(b.as_raw(), 3, u16_scale),
        D::ImageRgba16(b) => to_luma(b.as_raw(), 4, u16_scale),
        D::ImageRgb32F(b) => to_luma(b.as_raw(), 3, |p| p),
        D::ImageRgba32F(b) => to_luma(b.as_raw(), 4, |p| p),
        other => return Err(unsupported(&format!("{:?}", other.color()))),
    };
    GrayImage::from_vec(w, h, pixels).map_err(|e| e.to_string())
}

/// Grey values from interleaved samples with `channels` per pixel: 1 grey, 2 grey + alpha,
/// 3 RGB, 4 RGBA. `scale` maps a sample to `[0, 1]`.
fn to_luma<T: Copy>(samples: &[T], channels: usize, scale: impl Fn(T) -> f32) -> Vec<f32> {
    match channels {
        1 => samples.iter().map(|&p| scale(p)).collect(),
        2 => samples.chunks_exact(2).map(|p| scale(p[0])).collect(),
        _ => samples
            .chunks_exact(channels)
            .map(|p| {
                LUMA_601[0] * scale(p[0]) + LUMA_601[1] * scale(p[1]) + LUMA_601[2] * scale(p[2])
            })
            .collect(),
    }
}

fn unsupported(what: &str) -> String {
    format!(
        "unsupported pixel type ({what}); convert the frames to 8- or 16-bit grey, RGB, or 32-bit float grey"
    )
}

/// Reads one image file (PNG, JPEG or the first page of a TIFF) as a grey image in `[0, 1]`:
/// used for masks and single frames.
pub fn read_image(path: impl AsRef<Path>) -> Result<GrayImage> {
    let path = path.as_ref();
    super::input::check_exists(path)?;
    decode_file(path).map_err(|message| {
        sillage_core::Error::format(
            path,
            None,
            format!("cannot decode: {message}; check that it is a valid PNG, JPEG or TIFF image"),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_becomes_rec601_luma_and_alpha_is_dropped() {
        let rgb = [255u8, 0, 0, 0, 255, 0, 0, 0, 255];
        let grey = to_luma(&rgb, 3, |p| f32::from(p) / 255.0);
        assert!((grey[0] - 0.299).abs() < 1e-6);
        assert!((grey[1] - 0.587).abs() < 1e-6);
        assert!((grey[2] - 0.114).abs() < 1e-6);
        let grey_alpha = [10u16, 65535, 65535, 0];
        assert_eq!(to_luma(&grey_alpha, 2, f32::from), vec![10.0, 65535.0]);
    }
}
