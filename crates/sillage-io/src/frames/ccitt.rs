//! TIFF compression 2, CCITT modified Huffman: the one-dimensional run-length coding of
//! ITU-T T.4 with every row starting on a byte boundary and no end-of-line codes (TIFF 6.0,
//! section 10). Bi-level masks are often saved this way (BeadTracking's flume-base mask is),
//! and the `tiff` crate decodes only Group 4. The run-length code tables are T.4's, from the
//! `fax` crate; rows and strips are assembled here.

use std::convert::Infallible;
use std::io::{Read, Seek};

use fax::maps::{black, white};
use fax::{BitReader, ByteReader};
use sillage_core::GrayImage;
use tiff::decoder::Decoder;
use tiff::tags::Tag;

use super::decode::DecodeResult;
use super::strips::{Strips, read_strip};

/// TIFF's `Compression` value of modified Huffman run-length coding.
pub(crate) const MODIFIED_HUFFMAN: u16 = 2;

/// Decodes the current page of `decoder`, compressed with [`MODIFIED_HUFFMAN`], as grey
/// levels as displayed: white 1, black 0 (whatever the photometric interpretation).
pub(crate) fn decode_modified_huffman<R: Read + Seek>(
    decoder: &mut Decoder<R>,
) -> DecodeResult<GrayImage> {
    let tiff_error = |e: tiff::TiffError| e.to_string();
    let bits: u16 = decoder
        .find_tag_unsigned(Tag::BitsPerSample)
        .map_err(tiff_error)?
        .unwrap_or(1);
    if bits != 1 {
        return Err(format!(
            "modified Huffman (CCITT) compression of {bits}-bit samples; TIFF allows it for \
             1-bit images only, so the file is damaged"
        ));
    }
    // Photometric 0 (WhiteIsZero) is the usual one for fax codings.
    let white_is_zero = decoder
        .find_tag_unsigned::<u16>(Tag::PhotometricInterpretation)
        .map_err(tiff_error)?
        .unwrap_or(0)
        == 0;
    let lsb_first = decoder
        .find_tag_unsigned::<u16>(Tag::FillOrder)
        .map_err(tiff_error)?
        == Some(2);
    let layout = Strips::of(decoder)?;
    let (w, h) = (layout.width, layout.height);
    let mut pixels = Vec::new();
    let mut strip = Vec::new();
    for (s, &span) in layout.spans.iter().enumerate() {
        read_strip(decoder.inner(), span, &mut strip)
            .map_err(|e| format!("cannot read strip {s}: {e}"))?;
        if lsb_first {
            strip.iter_mut().for_each(|b| *b = b.reverse_bits());
        }
        let first_row = s * layout.rows_per_strip;
        decode_rows(&strip, w, layout.rows(s), &mut pixels)
            .map_err(|e| format!("row {}: {e}", first_row + e.row + 1))?;
    }
    let (white, black) = if white_is_zero {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    // `decode_rows` writes 0 for a T.4 white run and 1 for a black one; with BlackIsZero the
    // "white" runs carry the value 0, which displays black.
    let grey = pixels
        .into_iter()
        .map(|bit| if bit == 0 { white } else { black })
        .collect();
    GrayImage::from_vec(w, h, grey).map_err(|e| e.to_string())
}

/// Why a row could not be decoded (its 0-based index within the strip, for the caller).
#[derive(Debug)]
struct RowError {
    row: usize,
    message: &'static str,
}

impl std::fmt::Display for RowError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.message)
    }
}

/// Decodes `rows` byte-aligned rows of `width` pixels from `data`, appending 0 for white
/// and 1 for black to `out`.
fn decode_rows(data: &[u8], width: usize, rows: usize, out: &mut Vec<u8>) -> Result<(), RowError> {
    // The code tables peek up to 13 bits ahead, even for a shorter last code: two zero
    // bytes after the strip let the last row's codes be read (zeros are no code, so a
    // truncated strip is still an error).
    let mut reader = ByteReader::new(data.iter().copied().chain([0, 0]).map(Ok::<u8, Infallible>))
        .unwrap_or_else(|never| match never {});
    for row in 0..rows {
        let error = |message| RowError { row, message };
        let mut filled = 0;
        let mut black_run = false;
        let mut make_up_pending = false;
        // A row alternates white and black runs, white first (possibly of length 0); a run
        // is make-up codes (multiples of 64) then one terminating code (< 64), which ends
        // it even when the make-up codes already fill the row.
        while filled < width || make_up_pending {
            let run = if black_run {
                black::decode(&mut reader)
            } else {
                white::decode(&mut reader)
            }
            .ok_or_else(|| error("invalid or truncated run-length code"))?;
            let run = usize::from(run);
            if filled + run > width {
                return Err(error("the runs add up to more than the image width"));
            }
            out.extend(std::iter::repeat_n(u8::from(black_run), run));
            filled += run;
            make_up_pending = run >= 64;
            if !make_up_pending {
                black_run = !black_run;
            }
        }
        // Rows start on a byte boundary.
        let padding = reader.bits_to_byte_boundary();
        reader
            .consume(padding)
            .unwrap_or_else(|never| match never {});
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bits written MSB first, padded with zeros to whole bytes.
    fn pack(bits: &str) -> Vec<u8> {
        let bits: Vec<u8> = bits.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
        bits.chunks(8)
            .map(|chunk| {
                chunk
                    .iter()
                    .enumerate()
                    .fold(0u8, |byte, (i, &b)| byte | (u8::from(b == b'1') << (7 - i)))
            })
            .collect()
    }

    #[test]
    fn rows_of_runs_with_make_up_codes_and_byte_alignment() {
        // T.4 codes: white 2 = 0111, black 3 = 10, white 3 = 1000, white 64 (make-up) =
        // 11011, white 0 = 00110101, black 2 = 11, black 0 = 0000110111.
        // Row 1 (8 px): white 2, black 3, white 3 — 10 bits, padded to 16.
        // Row 2 (66 px): white 64 + white 0, black 2.
        // Row 3 (8 px): white 0, black 3, white 3, black 2.
        let mut data = pack("0111 10 1000 000000");
        data.extend(pack("11011 00110101 11"));
        data.extend(pack("00110101 10 1000 11"));
        let mut out = Vec::new();
        decode_rows(&data[..2], 8, 1, &mut out).unwrap();
        assert_eq!(out, [0, 0, 1, 1, 1, 0, 0, 0]);
        out.clear();
        decode_rows(&data[2..], 66, 1, &mut out).unwrap();
        assert_eq!(out.len(), 66);
        assert!(out[..64].iter().all(|&p| p == 0) && out[64..] == [1, 1]);
        out.clear();
        decode_rows(&data[4..], 8, 1, &mut out).unwrap();
        assert_eq!(out, [1, 1, 1, 0, 0, 0, 1, 1]);
    }

    /// A little-endian one-strip TIFF of `width` × `height` 1-bit pixels compressed with
    /// modified Huffman, whose strip is `strip`.
    fn mh_tiff(width: u32, height: u32, strip: &[u8]) -> Vec<u8> {
        const ENTRIES: u16 = 8;
        let strip_offset = 8 + 2 + 12 * u32::from(ENTRIES) + 4;
        let mut bytes = b"II*\0".to_vec();
        bytes.extend(8u32.to_le_bytes());
        bytes.extend(ENTRIES.to_le_bytes());
        // (tag, type 3 SHORT / 4 LONG, value), in increasing tag order.
        for (tag, kind, value) in [
            (256u16, 4u16, width),
            (257, 4, height),
            (258, 3, 1),
            (259, 3, u32::from(MODIFIED_HUFFMAN)),
            (262, 3, 0),
            (273, 4, strip_offset),
            (278, 4, height),
            (279, 4, strip.len() as u32),
        ] {
            bytes.extend(tag.to_le_bytes());
            bytes.extend(kind.to_le_bytes());
            bytes.extend(1u32.to_le_bytes());
            bytes.extend(value.to_le_bytes());
        }
        bytes.extend(0u32.to_le_bytes());
        bytes.extend(strip);
        bytes
    }

    #[test]
    fn a_huge_size_in_the_header_is_refused_before_any_allocation() {
        // 2³² − 1 pixels square: the size alone once sized the pixel buffer (capacity
        // overflow); a fuzzed header of 10⁵ × 10⁵ reserved 10 GB.
        for side in [u32::MAX, 100_000] {
            let tiff = mh_tiff(side, side, &[0x35, 0x00]);
            let error = crate::read_image_from_bytes(std::path::Path::new("mask.tif"), &tiff)
                .unwrap_err()
                .to_string();
            assert!(
                error.contains("mask.tif") && error.contains("is more than the"),
                "{error}"
            );
        }
        // The same file at 8 × 1 px decodes (white 8 = 10011, then black 0 = 0000110111).
        let tiff = mh_tiff(8, 1, &[0b1001_1000, 0b0110_1110]);
        let image = crate::read_image_from_bytes(std::path::Path::new("mask.tif"), &tiff).unwrap();
        assert_eq!(image.as_slice(), &[1.0; 8]);
    }

    #[test]
    fn runs_beyond_the_width_and_truncated_rows_are_errors() {
        let data = pack("0111 10 1000 000000");
        let mut out = Vec::new();
        let error = decode_rows(&data, 6, 1, &mut out).unwrap_err();
        assert!(
            error.message.contains("more than the image width"),
            "{error}"
        );
        let error = decode_rows(&data, 8, 2, &mut out).unwrap_err();
        assert_eq!(error.row, 1);
        assert!(error.message.contains("truncated"), "{error}");
    }
}
