//! Multi-page TIFF stacks: one frame per page (`image` only reads the first page, so pages
//! are walked with the `tiff` decoder).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use sillage_core::{Error, Result};
use tiff::decoder::Decoder;

use super::decode::{DecodeResult, Decoded, decode_tiff_page};

fn open(path: &Path) -> Result<Decoder<BufReader<File>>> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    Decoder::new(BufReader::new(file)).map_err(|e| {
        Error::frame(
            path,
            0,
            format!("cannot decode: {e}; check that it is a valid TIFF file"),
        )
    })
}

/// Number of pages of the TIFF at `path`, read from its directory chain without decoding
/// pixels.
pub(crate) fn count_pages(path: &Path) -> Result<usize> {
    let mut decoder = open(path)?;
    let mut pages = 1;
    while decoder.more_images() {
        decoder.next_image().map_err(|e| {
            Error::frame(
                path,
                pages as u64,
                format!("cannot read the page directory: {e}; the TIFF stack is damaged"),
            )
        })?;
        pages += 1;
    }
    Ok(pages)
}

/// Decodes the pages of the stack at `path` in order (with their colour when `colour` is
/// true), handing each to `emit` until it returns `false` or the pages run out.
pub(crate) fn read_pages(
    path: &Path,
    colour: bool,
    mut emit: impl FnMut(DecodeResult<Decoded>) -> bool,
) {
    let mut decoder = match File::open(path)
        .map_err(|e| e.to_string())
        .and_then(|f| Decoder::new(BufReader::new(f)).map_err(|e| e.to_string()))
    {
        Ok(decoder) => decoder,
        Err(message) => {
            emit(Err(message));
            return;
        }
    };
    loop {
        if !emit(decode_tiff_page(&mut decoder, colour)) || !decoder.more_images() {
            return;
        }
        if let Err(e) = decoder.next_image() {
            emit(Err(e.to_string()));
            return;
        }
    }
}
