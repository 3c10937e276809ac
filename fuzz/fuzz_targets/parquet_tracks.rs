//! Parquet track tables, saved as `tracks.parquet` and read through `read_track_table`
//! (the track reader has no in-memory entry point).
//!
//! The reader turns panics of the `parquet` crate on damaged files into errors
//! (`catch_unwind`); libFuzzer's panic hook aborts before any unwinding, so this target puts
//! the default hook back: a panic the reader catches is no crash, one that escapes it still
//! aborts (libfuzzer-sys aborts on a panic leaving the closure).
#![no_main]

use std::sync::Once;

use libfuzzer_sys::fuzz_target;
use sillage_io::{TrackFormat, read_track_table};

static QUIET_CAUGHT_PANICS: Once = Once::new();

fuzz_target!(|data: &[u8]| {
    QUIET_CAUGHT_PANICS.call_once(|| std::panic::set_hook(Box::new(|_| {})));
    let path = sillage_fuzz::scratch_file("tracks.parquet", data);
    let _ = read_track_table(&path, TrackFormat::Parquet);
});
