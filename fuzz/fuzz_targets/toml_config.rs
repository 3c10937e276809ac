//! TOML settings through the functions the commands load them with: the first byte picks the
//! settings type, the bytes up to the next NUL are the `--config` file (saved as
//! `config.toml`), each following line is a `--set key=value` override.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sillage::detect::{BeadParams, MotionParams};
use sillage::pedestrian::{GroundPlaneFile, ImmpfSettings, SiftPfSettings};
use sillage::toml_config::{load, load_unvalidated};
use sillage::track::bedload::BedloadTrackerParams;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let (file, overrides) = match rest.iter().position(|&b| b == 0) {
        Some(nul) => (&rest[..nul], &rest[nul + 1..]),
        None => (rest, &[][..]),
    };
    let overrides: Vec<String> = String::from_utf8_lossy(overrides)
        .lines()
        .map(str::to_string)
        .collect();
    let path = sillage_fuzz::scratch_file("config.toml", file);
    let file = Some(path.as_path());
    let _ = match selector % 7 {
        0 => sillage::ptv_run::load_ptv_config(file, None, &overrides).map(drop),
        1 => load_unvalidated::<BedloadTrackerParams>(file, &overrides).and_then(|p| p.validate()),
        2 => load_unvalidated::<BeadParams>(file, &overrides).and_then(|p| p.validate()),
        3 => ImmpfSettings::load(file, &overrides, None).map(drop),
        4 => SiftPfSettings::load(file, &overrides, None).map(drop),
        5 => load::<MotionParams>(file, &overrides).map(drop),
        _ => GroundPlaneFile::read_sizing(&path).map(drop),
    };
});
