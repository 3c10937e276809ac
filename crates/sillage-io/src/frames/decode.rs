//! Decoding one image file (PNG, JPEG, BMP, single-page TIFF) or one TIFF page into a
//! [`GrayImage`] (1-bit TIFFs with CCITT modified Huffman compression through [`super::ccitt`]), and on
//! request into an 8-bit [`RgbImage`] as well.
//!
//! Grey levels are normalised to `[0, 1]`: 8-bit values are divided by 255, 16-bit by 65535;
//! 32/64-bit float grey is kept as is. Colour is converted to grey with the Rec. 601 luma
//! weights `0.299 R + 0.587 G + 0.114 B` (the weights OpenCV's `BGR2GRAY` uses, so frames
//! match TracTrac's); an alpha channel is dropped.
//!
//! The colour picture keeps 8-bit samples as they are, rounds 16-bit ones to 8 bits
//! (`v / 257`), clamps float ones to `[0, 1]` before scaling by 255, and replicates grey
//! into the three channels.

use std::io::{BufRead, Read, Seek, SeekFrom};
use std::path::Path;

use sillage_core::{GrayImage, LUMA_601, Result, RgbImage};
use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult};

use super::{ccitt, lzw};

/// Why a frame could not be decoded; the caller adds the file and the frame index.
pub(crate) type DecodeResult<T> = std::result::Result<T, String>;

/// One decoded picture: its grey levels, and its colour when it was asked for.
#[derive(Debug)]
pub(crate) struct Decoded {
    /// Grey levels (Rec. 601 luma of colour pictures).
    pub(crate) grey: GrayImage,
    /// 8-bit colour (grey pictures replicated), `Some` only when requested.
    pub(crate) colour: Option<RgbImage>,
}

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

/// Decodes the image file at `path` (for a TIFF, its first page), with its colour when
/// `colour` is true.
pub(crate) fn decode_file(path: &Path, colour: bool) -> DecodeResult<Decoded> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    decode_reader(path, std::io::BufReader::new(file), colour)
}

/// Decodes the image that `reader` holds (for a TIFF, its first page), with its colour when
/// `colour` is true. `path` names the source: a TIFF extension selects the TIFF decoder, any
/// other is the format hint when the bytes do not tell it.
fn decode_reader<R: BufRead + Seek>(path: &Path, reader: R, colour: bool) -> DecodeResult<Decoded> {
    if is_tiff(path) {
        let mut decoder = Decoder::new(reader).map_err(|e| e.to_string())?;
        decode_tiff_page(&mut decoder, colour)
    } else {
        let mut reader = reader;
        check_png_palette(&mut reader)?;
        let mut reader = image::ImageReader::new(reader);
        if let Ok(format) = image::ImageFormat::from_path(path) {
            reader.set_format(format);
        }
        let image = reader
            .with_guessed_format()
            .map_err(|e| e.to_string())?
            .decode()
            .map_err(|e| e.to_string())?;
        decode_dynamic(image, colour)
    }
}

/// Refuses a PNG whose palette (`PLTE` chunk) is not a whole number of RGB entries, 1 to 256,
/// which the `png` crate's palette expansion indexes past the end of (a panic) instead of
/// reporting. Reads the chunk headers before the image data, then rewinds `reader`; bytes
/// that are not a PNG, or a PNG cut short, are left to the decoder to report.
fn check_png_palette<R: Read + Seek>(reader: &mut R) -> DecodeResult<()> {
    let start = reader.stream_position().map_err(|e| e.to_string())?;
    let palette = png_palette_length(reader);
    reader
        .seek(SeekFrom::Start(start))
        .map_err(|e| e.to_string())?;
    match palette {
        Ok(Some(length)) if length == 0 || length > 3 * 256 || length % 3 != 0 => Err(format!(
            "PNG palette (PLTE chunk) of {length} bytes; a palette is 1 to 256 RGB entries of \
             3 bytes each, so the file is damaged"
        )),
        _ => Ok(()),
    }
}

/// The length of the `PLTE` chunk of the PNG `reader` is at, `None` when there is none before
/// the image data or the bytes are not a PNG.
fn png_palette_length<R: Read + Seek>(reader: &mut R) -> std::io::Result<Option<u32>> {
    let mut signature = [0u8; 8];
    reader.read_exact(&mut signature)?;
    if signature != *b"\x89PNG\r\n\x1a\n" {
        return Ok(None);
    }
    loop {
        // Each chunk: length (big-endian u32), type, data, CRC (4 bytes).
        let mut header = [0u8; 8];
        reader.read_exact(&mut header)?;
        let length = u32::from_be_bytes([header[0], header[1], header[2], header[3]]);
        match &header[4..] {
            b"PLTE" => return Ok(Some(length)),
            b"IDAT" | b"IEND" => return Ok(None),
            _ => reader.seek(SeekFrom::Current(i64::from(length) + 4))?,
        };
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

/// Decodes the current page of a TIFF decoder, with its colour when `colour` is true.
pub(crate) fn decode_tiff_page<R: std::io::Read + std::io::Seek>(
    decoder: &mut Decoder<R>,
    colour: bool,
) -> DecodeResult<Decoded> {
    let compression = decoder
        .find_tag_unsigned::<u16>(tiff::tags::Tag::Compression)
        .map_err(|e| e.to_string())?;
    if compression == Some(ccitt::MODIFIED_HUFFMAN) {
        let grey = ccitt::decode_modified_huffman(decoder)?;
        let colour = if colour {
            Some(grey_to_rgb(&grey)?)
        } else {
            None
        };
        return Ok(Decoded { grey, colour });
    }
    if let Some(grey) = lzw::decode_grey8_strips(decoder)? {
        let colour = if colour {
            Some(grey_to_rgb(&grey)?)
        } else {
            None
        };
        return Ok(Decoded { grey, colour });
    }
    let (w, h) = decoder.dimensions().map_err(|e| e.to_string())?;
    let colour_type = decoder.colortype().map_err(|e| e.to_string())?;
    let channels = match colour_type {
        ColorType::Gray(_) => 1,
        ColorType::GrayA(_) => 2,
        ColorType::RGB(_) => 3,
        ColorType::RGBA(_) => 4,
        other => return Err(unsupported(&format!("TIFF colour type {other:?}"))),
    };
    let (w, h) = (w as usize, h as usize);
    match decoder.read_image().map_err(|e| e.to_string())? {
        DecodingResult::U8(v) => decoded(w, h, &v, channels, colour, u8_unit, |p| p),
        DecodingResult::U16(v) => decoded(w, h, &v, channels, colour, u16_unit, u16_to_u8),
        DecodingResult::F32(v) => decoded(w, h, &v, channels, colour, |p| p, f32_to_u8),
        DecodingResult::F64(v) => decoded(
            w,
            h,
            &v,
            channels,
            colour,
            |p| p as f32,
            |p| f32_to_u8(p as f32),
        ),
        _ => Err(unsupported(&format!("TIFF sample type of {colour_type:?}"))),
    }
}

/// Converts a decoded PNG/JPEG/BMP (or any `image` crate picture) to grey, and to colour when
/// `colour` is true.
fn decode_dynamic(image: image::DynamicImage, colour: bool) -> DecodeResult<Decoded> {
    use image::DynamicImage as D;
    let (w, h) = (image.width() as usize, image.height() as usize);
    let c = colour;
    match image {
        D::ImageLuma8(b) => decoded(w, h, b.as_raw(), 1, c, u8_unit, |p| p),
        D::ImageLumaA8(b) => decoded(w, h, b.as_raw(), 2, c, u8_unit, |p| p),
        D::ImageRgb8(b) => decoded(w, h, b.as_raw(), 3, c, u8_unit, |p| p),
        D::ImageRgba8(b) => decoded(w, h, b.as_raw(), 4, c, u8_unit, |p| p),
        D::ImageLuma16(b) => decoded(w, h, b.as_raw(), 1, c, u16_unit, u16_to_u8),
        D::ImageLumaA16(b) => decoded(w, h, b.as_raw(), 2, c, u16_unit, u16_to_u8),
        D::ImageRgb16(b) => decoded(w, h, b.as_raw(), 3, c, u16_unit, u16_to_u8),
        D::ImageRgba16(b) => decoded(w, h, b.as_raw(), 4, c, u16_unit, u16_to_u8),
        D::ImageRgb32F(b) => decoded(w, h, b.as_raw(), 3, c, |p| p, f32_to_u8),
        D::ImageRgba32F(b) => decoded(w, h, b.as_raw(), 4, c, |p| p, f32_to_u8),
        other => Err(unsupported(&format!("{:?}", other.color()))),
    }
}

/// An 8-bit sample in `[0, 1]`.
pub(crate) fn u8_unit(p: u8) -> f32 {
    f32::from(p) / 255.0
}

/// A 16-bit sample in `[0, 1]`.
fn u16_unit(p: u16) -> f32 {
    f32::from(p) / 65535.0
}

/// A 16-bit sample rounded to 8 bits (`65535 / 255 = 257`).
fn u16_to_u8(p: u16) -> u8 {
    ((u32::from(p) + 128) / 257) as u8
}

/// A float sample in `[0, 1]` (clamped) scaled to 8 bits, rounded.
fn f32_to_u8(p: f32) -> u8 {
    (p.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Builds a [`Decoded`] from interleaved samples with `channels` per pixel (1 grey, 2 grey +
/// alpha, 3 RGB, 4 RGBA): `unit` maps a sample to `[0, 1]` for grey, `byte` to 8 bits for
/// colour.
fn decoded<T: Copy>(
    width: usize,
    height: usize,
    samples: &[T],
    channels: usize,
    colour: bool,
    unit: impl Fn(T) -> f32,
    byte: impl Fn(T) -> u8,
) -> DecodeResult<Decoded> {
    let grey = GrayImage::from_vec(width, height, to_luma(samples, channels, unit))
        .map_err(|e| e.to_string())?;
    let colour = if colour {
        let pixels = to_rgb8(samples, channels, byte);
        Some(RgbImage::from_vec(width, height, pixels).map_err(|e| e.to_string())?)
    } else {
        None
    };
    Ok(Decoded { grey, colour })
}

/// Grey values from interleaved samples with `channels` per pixel: 1 grey, 2 grey + alpha,
/// 3 RGB, 4 RGBA. `scale` maps a sample to `[0, 1]`. The one place the Rec. 601 luma is
/// computed (video frames decoded as RGB come through here too).
pub(crate) fn to_luma<T: Copy>(
    samples: &[T],
    channels: usize,
    scale: impl Fn(T) -> f32,
) -> Vec<f32> {
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

/// 8-bit RGB pixels from interleaved samples laid out as in [`to_luma`]; grey is replicated
/// into the three channels and alpha dropped. `byte` maps a sample to 8 bits.
fn to_rgb8<T: Copy>(samples: &[T], channels: usize, byte: impl Fn(T) -> u8) -> Vec<[u8; 3]> {
    match channels {
        1 | 2 => samples
            .chunks_exact(channels)
            .map(|p| [byte(p[0]); 3])
            .collect(),
        _ => samples
            .chunks_exact(channels)
            .map(|p| [byte(p[0]), byte(p[1]), byte(p[2])])
            .collect(),
    }
}

/// A grey picture in `[0, 1]` as 8-bit colour, each level replicated into the three channels.
fn grey_to_rgb(grey: &GrayImage) -> DecodeResult<RgbImage> {
    let pixels = grey.as_slice().iter().map(|&v| [f32_to_u8(v); 3]).collect();
    RgbImage::from_vec(grey.width(), grey.height(), pixels).map_err(|e| e.to_string())
}

fn unsupported(what: &str) -> String {
    format!(
        "unsupported pixel type ({what}); convert the frames to 8- or 16-bit grey, RGB, or 32-bit float grey"
    )
}

/// Reads one image file (PNG, JPEG, BMP or the first page of a TIFF) as a grey image in
/// `[0, 1]`: used for masks and single frames.
pub fn read_image(path: impl AsRef<Path>) -> Result<GrayImage> {
    let path = path.as_ref();
    super::input::check_exists(path)?;
    decode_file(path, false)
        .map(|decoded| decoded.grey)
        .map_err(|message| decode_error(path, &message))
}

/// Decodes one image held in `bytes` as [`read_image`] decodes a file: `path` names it in
/// errors, and its extension tells a TIFF (`.tif`, `.tiff`, first page decoded) from PNG,
/// JPEG and BMP, whose format is read from the bytes.
pub fn read_image_from_bytes(path: &Path, bytes: &[u8]) -> Result<GrayImage> {
    decode_reader(path, std::io::Cursor::new(bytes), false)
        .map(|decoded| decoded.grey)
        .map_err(|message| decode_error(path, &message))
}

fn decode_error(path: &Path, message: &str) -> sillage_core::Error {
    sillage_core::Error::format(
        path,
        None,
        format!("cannot decode: {message}; check that it is a valid PNG, JPEG, BMP or TIFF image"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1 × 1 indexed PNG with the `PLTE` chunk `plte` (length, type, data and CRC).
    fn indexed_png(plte: &[u8]) -> Vec<u8> {
        let signature_and_header = [
            0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
            0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x03, 0x00, 0x00,
            0x00, 0x28, 0xcb, 0x34, 0xbb,
        ];
        // IDAT (zlib of the row: filter 0, index 0), then IEND.
        let data_and_end = [
            0x00, 0x00, 0x00, 0x0a, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60, 0x00, 0x00,
            0x00, 0x02, 0x00, 0x01, 0x48, 0xaf, 0xa4, 0x71, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45,
            0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
        ];
        [&signature_and_header[..], plte, &data_and_end].concat()
    }

    #[test]
    fn a_png_palette_of_a_partial_entry_is_an_error_not_a_panic() {
        // Found by `cargo fuzz run frame_decode` (docs/fuzzing.md): a 4-byte PLTE chunk made
        // the png crate's palette expansion panic (range end index 3 out of range).
        let partial = indexed_png(&[
            0x00, 0x00, 0x00, 0x04, 0x50, 0x4c, 0x54, 0x45, 0x33, 0x66, 0x99, 0x01, 0xcd, 0xe3,
            0x4f, 0x62,
        ]);
        let error = read_image_from_bytes(Path::new("mask.png"), &partial)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("mask.png") && error.contains("(PLTE chunk) of 4 bytes"),
            "{error}"
        );
        // One whole entry (0x33, 0x66, 0x99) decodes.
        let whole = indexed_png(&[
            0x00, 0x00, 0x00, 0x03, 0x50, 0x4c, 0x54, 0x45, 0x33, 0x66, 0x99, 0x3b, 0x23, 0x81,
            0xd2,
        ]);
        let image = read_image_from_bytes(Path::new("mask.png"), &whole).unwrap();
        let luma = LUMA_601[0] * 0.2 + LUMA_601[1] * 0.4 + LUMA_601[2] * 0.6;
        assert!((image.get(0, 0) - luma).abs() < 1e-6, "{}", image.get(0, 0));
    }

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
