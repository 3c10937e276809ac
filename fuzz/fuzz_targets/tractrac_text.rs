//! TracTrac's text files: `_track.txt` track tables (saved as `seq_track.txt` and read
//! through `read_track_table`, with the table-format sniffing) and `*_par.txt` parameter
//! files; BeadTracking's `sequence_param.txt` (the same `name value` line shape).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use sillage_io::{
    TrackFormat, detect_table_format, parse_bead_sequence_params, parse_tractrac_par,
    read_track_table,
};

fuzz_target!(|data: &[u8]| {
    let path = sillage_fuzz::scratch_file("seq_track.txt", data);
    let _ = detect_table_format(&path);
    let _ = read_track_table(&path, TrackFormat::Tractrac);
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_tractrac_par(Path::new("seq_par.txt"), text);
        let _ = parse_bead_sequence_params(Path::new("sequence_param.txt"), text);
    }
});
