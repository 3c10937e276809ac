//! The strips of a TIFF page read by sillage's own decoders (`ccitt`, `lzw`): their layout
//! from the tags, checked before any allocation, and their bytes.

use std::io::{Read, Seek, SeekFrom};

use tiff::decoder::Decoder;
use tiff::tags::Tag;

use super::decode::DecodeResult;

/// Where the strips of a page lie and how many rows each holds.
pub(crate) struct Strips {
    /// Width and height of the page, pixels.
    pub(crate) width: usize,
    pub(crate) height: usize,
    /// Rows per strip (the last may hold fewer).
    pub(crate) rows_per_strip: usize,
    /// Per strip: its offset in the file and its length in bytes.
    pub(crate) spans: Vec<(u64, u64)>,
}

impl Strips {
    /// The strips of the current page of `decoder`. Errors tell a damaged file: fewer strips
    /// listed than the height needs, or more pixels than the `tiff` crate allows a frame
    /// (the header's size is not trusted for an allocation).
    pub(crate) fn of<R: Read + Seek>(decoder: &mut Decoder<R>) -> DecodeResult<Self> {
        let tiff_error = |e: tiff::TiffError| e.to_string();
        let (width, height) = decoder.dimensions().map_err(tiff_error)?;
        let limit = tiff::decoder::Limits::default().decoding_buffer_size as u64;
        if u64::from(width) * u64::from(height) > limit {
            return Err(format!(
                "{width} × {height} pixels is more than the {limit} a frame may have; the \
                 file is damaged, or crop the image"
            ));
        }
        let rows_per_strip: u32 = decoder
            .find_tag_unsigned(Tag::RowsPerStrip)
            .map_err(tiff_error)?
            .unwrap_or(height)
            .clamp(1, height.max(1));
        let offsets = decoder
            .get_tag_u64_vec(Tag::StripOffsets)
            .map_err(tiff_error)?;
        let counts = decoder
            .get_tag_u64_vec(Tag::StripByteCounts)
            .map_err(tiff_error)?;
        let strips = height.div_ceil(rows_per_strip) as usize;
        if offsets.len() < strips || counts.len() < strips {
            return Err(format!(
                "the image needs {strips} strips of {rows_per_strip} rows and the file lists \
                 {} offsets and {} byte counts; the file is damaged",
                offsets.len(),
                counts.len()
            ));
        }
        Ok(Self {
            width: width as usize,
            height: height as usize,
            rows_per_strip: rows_per_strip as usize,
            spans: offsets.into_iter().zip(counts).take(strips).collect(),
        })
    }

    /// The rows strip `s` holds.
    pub(crate) fn rows(&self, s: usize) -> usize {
        (self.height - s * self.rows_per_strip).min(self.rows_per_strip)
    }
}

/// Reads the `count` bytes of the strip at `offset` into `strip` (a short file is an error).
pub(crate) fn read_strip<R: Read + Seek>(
    reader: &mut R,
    (offset, count): (u64, u64),
    strip: &mut Vec<u8>,
) -> std::io::Result<()> {
    reader.seek(SeekFrom::Start(offset))?;
    strip.clear();
    reader.take(count).read_to_end(strip)?;
    if (strip.len() as u64) < count {
        return Err(std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            format!(
                "the file ends {} bytes into a strip of {count}",
                strip.len()
            ),
        ));
    }
    Ok(())
}
