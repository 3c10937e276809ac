//! The header-checked CSV tables, all on the same bytes saved as `table.csv`: BeadTracking
//! bead ground truth, detections, point truth, CSV track tables, matrix CSVs (the bead ring
//! template) and the table-format sniffing of `eval`/`plot`/`overlay`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sillage_io::{
    TrackFormat, detect_table_format, read_bead_csv, read_detections_csv, read_matrix_csv,
    read_track_table, read_truth_csv,
};

fuzz_target!(|data: &[u8]| {
    let path = sillage_fuzz::scratch_file("table.csv", data);
    let _ = detect_table_format(&path);
    let _ = read_bead_csv(&path);
    let _ = read_detections_csv(&path);
    let _ = read_truth_csv(&path);
    let _ = read_track_table(&path, TrackFormat::Csv);
    let _ = read_matrix_csv(&path);
});
