//! MOTChallenge files: `gt.txt` / `det.txt` / results rows and `seqinfo.ini`.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = sillage_io::parse_mot_rows(Path::new("gt.txt"), data);
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = sillage_io::parse_seqinfo(Path::new("seqinfo.ini"), text);
    }
});
