//! Property tests: the text parsers return errors, never panic, on arbitrary input.

use proptest::prelude::*;
use sillage_io::{
    TrackFormat, parse_bead_sequence_params, parse_tractrac_par, read_bead_csv,
    read_detections_csv, read_tracks, read_truth_csv,
};

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn par_parser_never_panics(text in ".{0,400}") {
        let _ = parse_tractrac_par(std::path::Path::new("p_par.txt"), &text);
    }

    #[test]
    fn par_parser_never_panics_on_plausible_lines(
        lines in prop::collection::vec(
            ("[A-Za-z_]{0,14}", "[-+0-9.eEnaif#x ]{0,10}", "( *#.*)?"),
            0..12,
        )
    ) {
        let text: String = lines.iter().map(|(k, v, c)| format!("{k} {v}{c}\n")).collect();
        let _ = parse_tractrac_par(std::path::Path::new("p_par.txt"), &text);
    }

    #[test]
    fn table_readers_never_panic(
        body in prop::collection::vec("[-0-9.,eEnaN# \t\"x]{0,30}", 0..8),
        header in prop::sample::select(vec![
            "frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err",
            "frame,particle,x,y",
            "frame,track_id,x,y,vx,vy",
            "frame,x,y,strength",
            "frame,id,x,y,category,vx,vy,motion_state",
            "# TracTrac v3.0",
            "",
        ]),
    ) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, format!("{header}\n{}", body.join("\n"))).unwrap();
        let _ = read_tracks(&path, TrackFormat::Csv);
        let _ = read_tracks(&path, TrackFormat::Tractrac);
        let _ = read_truth_csv(&path);
        let _ = read_detections_csv(&path);
        let _ = read_bead_csv(&path);
    }

    #[test]
    fn bead_parameter_parser_never_panics(text in "[A-Za-z \t\n0-9.eE+-]{0,200}") {
        let _ = parse_bead_sequence_params(std::path::Path::new("sequence_param.txt"), &text);
    }

    #[test]
    fn table_readers_never_panic_on_bytes(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, &bytes).unwrap();
        let _ = read_tracks(&path, TrackFormat::Csv);
        let _ = read_tracks(&path, TrackFormat::Tractrac);
        let _ = read_truth_csv(&path);
        let _ = read_bead_csv(&path);
    }
}
