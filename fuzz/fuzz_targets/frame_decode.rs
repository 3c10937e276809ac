//! Frame decoding through sillage's own path (`read_image_from_bytes`, the body of
//! `read_image`): TIFF (its first page; CCITT modified Huffman through sillage's decoder,
//! other compressions through the `tiff` crate), PNG and JPEG (format told by the bytes).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The extension selects the TIFF decoder, as for a file; TIFF bytes start `II` or `MM`.
    let name = if data.starts_with(b"II") || data.starts_with(b"MM") {
        "frame.tif"
    } else {
        "frame.png"
    };
    let _ = sillage_io::read_image_from_bytes(Path::new(name), data);
});
