//! LZW-compressed 8-bit grey TIFF strips decoded without the general decoder: the usual form
//! of camera and ImageJ/PIL exports, whose decoding took ~30 % of a whole PTV run's CPU in the
//! `tiff` crate's path (issue "Speed end to end").
//!
//! TIFF's LZW (TIFF 6.0 §13: codes of 9–12 bits, most significant bit first, Clear = 256,
//! EndOfInformation = 257, the code width growing one code early). Every code after the
//! literals stands for an earlier code's string plus one byte, and that string sits in the
//! output already, so the table keeps only where each string starts in the strip's output and
//! its length: decoding a code is one copy from earlier output. Other layouts (tiles, several
//! samples per pixel, other depths, the floating-point predictor, white-is-zero) take the
//! `tiff` crate's path.

use std::io::{Read, Seek};

use sillage_core::GrayImage;
use tiff::decoder::Decoder;
use tiff::tags::Tag;

use super::decode::{DecodeResult, u8_unit};
use super::strips::{Strips, read_strip};

/// TIFF's compression tag value for LZW.
pub(crate) const LZW: u16 = 5;
const CLEAR: u16 = 256;
const END: u16 = 257;
const FIRST_CODE: usize = 258;
/// TIFF's predictor tag values: none, horizontal differencing.
const NO_PREDICTOR: u16 = 1;
const HORIZONTAL: u16 = 2;
const MAX_CODES: usize = 4096;

/// Decodes the current page of `decoder` when it is an LZW-compressed 8-bit grey image in
/// strips, with or without the horizontal predictor (TIFF 6.0 §14); `None` for any other
/// layout (left to the general path).
pub(crate) fn decode_grey8_strips<R: Read + Seek>(
    decoder: &mut Decoder<R>,
) -> DecodeResult<Option<GrayImage>> {
    let tiff_error = |e: tiff::TiffError| e.to_string();
    let tag = |decoder: &mut Decoder<R>, tag: Tag| -> DecodeResult<Option<u16>> {
        decoder.find_tag_unsigned::<u16>(tag).map_err(tiff_error)
    };
    let plain = tag(decoder, Tag::Compression)? == Some(LZW)
        && tag(decoder, Tag::BitsPerSample)? == Some(8)
        && tag(decoder, Tag::SamplesPerPixel)?.unwrap_or(1) == 1
        && tag(decoder, Tag::PhotometricInterpretation)? == Some(1)
        && matches!(
            tag(decoder, Tag::Predictor)?.unwrap_or(1),
            NO_PREDICTOR | HORIZONTAL
        )
        && tag(decoder, Tag::FillOrder)?.unwrap_or(1) == 1
        && tag(decoder, Tag::TileWidth)?.is_none();
    if !plain {
        return Ok(None);
    }
    let horizontal = tag(decoder, Tag::Predictor)? == Some(HORIZONTAL);
    let layout = Strips::of(decoder)?;
    let (w, h) = (layout.width, layout.height);
    let mut pixels: Vec<u8> = Vec::with_capacity(w * h);
    let (mut compressed, mut table) = (Vec::new(), Table::default());
    for (s, &span) in layout.spans.iter().enumerate() {
        read_strip(decoder.inner(), span, &mut compressed)
            .map_err(|e| format!("strip {s}: {e}"))?;
        let size = layout.rows(s) * w;
        let start = pixels.len();
        table.decode(&compressed, &mut pixels, start + size);
        if pixels.len() < start + size {
            return Err(format!(
                "strip {s} decodes to {} of its {size} bytes; the file is damaged",
                pixels.len() - start
            ));
        }
        if horizontal {
            // Each row holds differences from the pixel to its left.
            for row in pixels[start..].chunks_exact_mut(w) {
                for x in 1..row.len() {
                    row[x] = row[x].wrapping_add(row[x - 1]);
                }
            }
        }
    }
    let grey = pixels.into_iter().map(u8_unit).collect();
    GrayImage::from_vec(w, h, grey)
        .map(Some)
        .map_err(|e| e.to_string())
}

/// The string table of one strip: per code, where its string starts in the output and its
/// length (reused from strip to strip).
#[derive(Debug)]
struct Table {
    strings: Vec<(u32, u32)>,
}

impl Default for Table {
    fn default() -> Self {
        Self {
            strings: vec![(0, 0); MAX_CODES],
        }
    }
}

/// Bytes a string copy may write past its end (then overwritten): short strings, the most
/// common, move as one fixed-size copy.
const SLACK: usize = 16;

impl Table {
    /// Appends the bytes `data` (one LZW strip) decodes to `out`, stopping at the end code,
    /// at the end of the data, at a code the table cannot have yet, or when `out` reaches
    /// `limit` bytes (the strip's size; extra bytes are dropped).
    fn decode(&mut self, data: &[u8], out: &mut Vec<u8>, limit: usize) {
        let base = out.len();
        let size = limit.saturating_sub(base);
        out.resize(limit.max(base) + SLACK, 0);
        let buffer = &mut out[base..];
        let mut bits = BitReader::new(data);
        let (mut width, mut next, mut at) = (9, FIRST_CODE, 0usize);
        // The previous code's string: where it starts and its length; none after a clear.
        let mut previous: Option<(usize, usize)> = None;
        while at < size {
            let Some(code) = bits.read(width) else {
                break;
            };
            if code == CLEAR {
                (width, next, previous) = (9, FIRST_CODE, None);
                continue;
            }
            if code == END {
                break;
            }
            let code = usize::from(code);
            let length = if code < 256 {
                buffer[at] = code as u8;
                1
            } else if let Some((p_start, p_len)) = previous {
                let (source, length) = if code < next {
                    let (start, len) = self.strings[code];
                    (start as usize, len as usize)
                } else if code == next {
                    // The string being defined: the previous one and its own first byte,
                    // which is what follows the previous string in the output.
                    (p_start, p_len + 1)
                } else {
                    break;
                };
                // The copy may not run past the strip's end.
                let length = length.min(size - at);
                copy_string(buffer, source, at, length);
                length
            } else {
                break;
            };
            if let Some((p_start, p_len)) = previous
                && next < MAX_CODES
            {
                self.strings[next] = (p_start as u32, (p_len + 1) as u32);
                next += 1;
            }
            previous = Some((at, length));
            at += length;
            // TIFF's "early change": the width grows one code before the table needs it.
            if next + 1 >= (1 << width) && width < 12 {
                width += 1;
            }
        }
        out.truncate(base + at.min(size));
    }
}

/// Copies `buffer[source..source + length]` to `at` (`source + length ≤ at + 1`: the string
/// is earlier output, or the one being defined, whose last byte is its own first); `buffer`
/// has [`SLACK`] bytes beyond the strip.
#[inline]
fn copy_string(buffer: &mut [u8], source: usize, at: usize, length: usize) {
    if length <= SLACK && source + SLACK <= at {
        buffer.copy_within(source..source + SLACK, at);
    } else if source + length <= at {
        buffer.copy_within(source..source + length, at);
    } else {
        // Overlapping: the string being defined, byte by byte.
        for k in 0..length {
            buffer[at + k] = buffer[source + k];
        }
    }
}

/// Codes read most significant bit first.
struct BitReader<'a> {
    data: &'a [u8],
    position: usize,
    buffer: u64,
    available: u32,
}

impl<'a> BitReader<'a> {
    fn new(data: &'a [u8]) -> Self {
        Self {
            data,
            position: 0,
            buffer: 0,
            available: 0,
        }
    }

    /// The next `width` bits as a code; `None` when the data ends first.
    #[inline]
    fn read(&mut self, width: u32) -> Option<u16> {
        if self.available < width
            && let Some(word) = self.data.get(self.position..self.position + 4)
        {
            // Four bytes at once where the data has them (at most 7 + 32 bits held).
            let word = u32::from_be_bytes([word[0], word[1], word[2], word[3]]);
            self.buffer = (self.buffer << 32) | u64::from(word);
            self.position += 4;
            self.available += 32;
        }
        while self.available < width {
            let &byte = self.data.get(self.position)?;
            self.position += 1;
            self.buffer = (self.buffer << 8) | u64::from(byte);
            self.available += 8;
        }
        self.available -= width;
        Some(((self.buffer >> self.available) & ((1 << width) - 1)) as u16)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Encodes `data` as TIFF LZW with the reference encoder (`weezl`, the `tiff` crate's).
    fn encoded(data: &[u8]) -> Vec<u8> {
        weezl::encode::Encoder::with_tiff_size_switch(weezl::BitOrder::Msb, 8)
            .encode(data)
            .unwrap()
    }

    fn decoded(compressed: &[u8], limit: usize) -> Vec<u8> {
        let mut out = vec![7, 7];
        Table::default().decode(compressed, &mut out, 2 + limit);
        out.split_off(2)
    }

    #[test]
    fn strips_decode_to_what_the_reference_encoder_was_given() {
        // Runs (KwKwK codes), noise, a long ramp that fills the table past 4,096 codes (the
        // encoder then clears it), and the empty strip.
        let mut state = 12345u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 56) as u8
        };
        let cases: Vec<Vec<u8>> = vec![
            vec![],
            vec![42],
            vec![9; 10_000],
            (0..70_000).map(|_| noise()).collect(),
            (0..200_000u32)
                .map(|i| ((i / 3) % 251) as u8 ^ (noise() & 3))
                .collect(),
            b"TOBEORNOTTOBEORTOBEORNOT#".repeat(500),
        ];
        for data in cases {
            assert_eq!(
                decoded(&encoded(&data), data.len()),
                data,
                "{} bytes",
                data.len()
            );
        }
    }

    /// A TIFF of `pixels` (8-bit grey, `width` wide) in strips of `rows` rows, LZW-compressed
    /// by the `tiff` crate's encoder, with or without its horizontal predictor.
    fn lzw_tiff(pixels: &[u8], width: u32, rows: u32, predictor: bool) -> Vec<u8> {
        use tiff::encoder::{Compression, Predictor, TiffEncoder, colortype::Gray8};
        let mut file = std::io::Cursor::new(Vec::new());
        let predictor = if predictor {
            Predictor::Horizontal
        } else {
            Predictor::None
        };
        let mut encoder = TiffEncoder::new(&mut file)
            .unwrap()
            .with_compression(Compression::Lzw)
            .with_predictor(predictor);
        let height = pixels.len() as u32 / width;
        let mut image = encoder.new_image::<Gray8>(width, height).unwrap();
        image.rows_per_strip(rows).unwrap();
        image.write_data(pixels).unwrap();
        file.into_inner()
    }

    #[test]
    fn frames_decode_as_the_tiff_crate_decodes_them_and_other_layouts_are_left_to_it() {
        let (width, height) = (301u32, 97u32);
        let pixels: Vec<u8> = (0..width * height)
            .map(|i| {
                ((i % width) * 3 + (i / width) * 7 + (i.wrapping_mul(2_654_435_761) >> 27)) as u8
            })
            .collect();
        for (rows, predictor) in [(1, false), (8, false), (97, false), (1, true), (8, true)] {
            let file = lzw_tiff(&pixels, width, rows, predictor);
            let reference = match Decoder::new(std::io::Cursor::new(&file))
                .unwrap()
                .read_image()
                .unwrap()
            {
                tiff::decoder::DecodingResult::U8(v) => v,
                other => panic!("{other:?}"),
            };
            assert_eq!(reference, pixels);
            let mut decoder = Decoder::new(std::io::Cursor::new(&file)).unwrap();
            let tag = decoder.find_tag_unsigned::<u16>(Tag::Predictor).unwrap();
            assert_eq!(tag.unwrap_or(1) == HORIZONTAL, predictor);
            let grey = decode_grey8_strips(&mut decoder).unwrap().unwrap();
            assert_eq!(grey.dimensions(), (width as usize, height as usize));
            let expected: Vec<f32> = pixels.iter().map(|&p| u8_unit(p)).collect();
            assert_eq!(
                grey.as_slice(),
                expected.as_slice(),
                "{rows} rows per strip, predictor {predictor}"
            );
        }
        // 16-bit samples are left to the `tiff` crate.
        let mut file = std::io::Cursor::new(Vec::new());
        tiff::encoder::TiffEncoder::new(&mut file)
            .unwrap()
            .with_compression(tiff::encoder::Compression::Lzw)
            .write_image::<tiff::encoder::colortype::Gray16>(4, 2, &[1, 2, 3, 4, 5, 6, 7, 8])
            .unwrap();
        let mut decoder = Decoder::new(std::io::Cursor::new(file.into_inner())).unwrap();
        assert!(decode_grey8_strips(&mut decoder).unwrap().is_none());
        // A damaged strip (its codes overwritten past its start) is an error naming it.
        let mut file = lzw_tiff(&pixels, width, 48, false);
        let offsets = Decoder::new(std::io::Cursor::new(&file))
            .unwrap()
            .get_tag_u64_vec(Tag::StripOffsets)
            .unwrap();
        let damaged = offsets[1] as usize + 4;
        file[damaged..damaged + 64].fill(0xFF);
        let mut decoder = Decoder::new(std::io::Cursor::new(&file)).unwrap();
        let err = decode_grey8_strips(&mut decoder).unwrap_err();
        assert!(err.contains("strip 1") && err.contains("damaged"), "{err}");
    }

    #[test]
    fn a_truncated_or_damaged_strip_stops_short_without_panicking() {
        let data: Vec<u8> = (0..5_000u32).map(|i| (i % 97) as u8).collect();
        let full = encoded(&data);
        let short = decoded(&full[..full.len() / 2], data.len());
        assert!(short.len() < data.len() && data.starts_with(&short));
        // A first code that is not a literal, and codes beyond the table.
        assert!(decoded(&[0xFF, 0xFF, 0xFF, 0xFF], 100).len() <= 1);
        // More bytes than the strip holds are dropped.
        assert_eq!(decoded(&full, 10), data[..10]);
    }
}
