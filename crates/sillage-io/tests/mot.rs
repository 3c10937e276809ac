//! MOTChallenge files: the shipped data, folders and seqinfo.ini, the results writer, and a
//! parser that never panics on arbitrary bytes.

use std::path::Path;

use proptest::prelude::*;
use sillage_io::{
    MotFileRole, MotResultsWriter, MotRow, parse_mot_rows, parse_seqinfo, read_mot_rows,
    read_mot_sequence, write_mot_results,
};

const SHARED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");

#[test]
fn reads_a_sequence_folder_with_its_seqinfo() {
    let folder = format!("{SHARED}/mot15_train_gt_det/TUD-Campus");
    let gt = read_mot_sequence(&folder, MotFileRole::GroundTruth).unwrap();
    assert!(gt.path.ends_with("gt/gt.txt"));
    // The README's verified contents: 359 rows, 8 ids, 71 frames.
    assert_eq!(gt.rows.len(), 359);
    let mut ids: Vec<u64> = gt.rows.iter().filter_map(|r| r.id).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), 8);
    let info = gt.seqinfo.unwrap();
    assert_eq!(info.frame_count, Some(71));
    assert_eq!(
        (info.image_width, info.image_height),
        (Some(640), Some(480))
    );
    assert_eq!(info.name.as_deref(), Some("TUD-Campus"));
    assert_eq!(gt.rows.iter().map(|r| r.frame).max(), Some(70));

    // The same file given directly finds seqinfo.ini one folder up.
    let direct =
        read_mot_sequence(format!("{folder}/gt/gt.txt"), MotFileRole::GroundTruth).unwrap();
    assert_eq!(direct.rows, gt.rows);
    assert_eq!(direct.seqinfo.and_then(|i| i.frame_count), Some(71));

    let det = read_mot_sequence(&folder, MotFileRole::Detections).unwrap();
    assert_eq!(det.rows.len(), 321);
    assert!(
        det.rows
            .iter()
            .all(|r| r.id.is_none() && r.confidence.is_some())
    );

    // A folder without the file names what is missing.
    let dir = tempfile::tempdir().unwrap();
    let err = read_mot_sequence(dir.path(), MotFileRole::GroundTruth)
        .unwrap_err()
        .to_string();
    assert!(err.contains("gt/gt.txt"), "{err}");
}

#[test]
fn reads_the_motmetrics_fixtures() {
    let rows = read_mot_rows(format!(
        "{SHARED}/motmetrics_tud_reference/iotest/motchallenge.txt"
    ))
    .unwrap();
    assert_eq!(
        rows[0],
        MotRow {
            frame: 0,
            id: Some(1),
            left_px: 399.0,
            top_px: 182.0,
            width_px: 121.0,
            height_px: 229.0,
            confidence: Some(1.0),
            class: None,
            visibility: None,
            world: None,
        }
    );
    let test = read_mot_rows(format!(
        "{SHARED}/motmetrics_tud_reference/TUD-Campus/test.txt"
    ))
    .unwrap();
    assert_eq!(
        (test[0].id, test[0].left_px, test[0].height_px),
        (Some(3), 113.84, 130.05)
    );
    // vatic is not MOTChallenge: its first line is named in the error.
    let err = read_mot_rows(format!(
        "{SHARED}/motmetrics_tud_reference/iotest/vatic.txt"
    ))
    .unwrap_err();
    assert!(err.to_string().contains("vatic.txt:1:"), "{err}");
}

#[test]
fn results_round_trip_through_a_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seq.txt");
    let rows = [
        MotRow {
            frame: 0,
            id: Some(3),
            left_px: 113.84,
            top_px: -2.5,
            width_px: 57.307,
            height_px: 130.05,
            confidence: Some(0.93),
            class: None,
            visibility: None,
            world: None,
        },
        MotRow {
            frame: 41,
            id: None,
            left_px: 0.1 + 0.2,
            top_px: 1e-7,
            width_px: 3.0,
            height_px: 4.0,
            confidence: None,
            class: None,
            visibility: None,
            world: Some([1.5, -2.0, 0.25]),
        },
    ];
    let mut writer = MotResultsWriter::create(&path).unwrap();
    writer.push(&rows[..1]).unwrap();
    assert!(
        !path.exists(),
        "written under a temporary name until finished"
    );
    writer.push(&rows[1..]).unwrap();
    let summary = writer.finish().unwrap();
    assert_eq!(summary.rows, 2);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        text.lines().next(),
        Some("1,3,113.84,-2.5,57.307,130.05,0.93,-1,-1,-1")
    );
    let mut back = read_mot_rows(&path).unwrap();
    // A missing confidence is written as -1.
    assert_eq!(back[1].confidence, Some(-1.0));
    back[1].confidence = None;
    assert_eq!(back, rows);
    write_mot_results(&path, &rows[..1]).unwrap();
    assert_eq!(read_mot_rows(&path).unwrap().len(), 1);
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no partial file left"
    );
}

/// Lines made of the characters MOTChallenge files use, so that most reach the number
/// parsers and field checks rather than failing on the first byte.
fn plausible_text() -> impl Strategy<Value = String> {
    prop::collection::vec("[-0-9.,eE \tna\r]{0,40}", 0..6).prop_map(|lines| lines.join("\n"))
}

proptest! {
    // 60 000 + 40 000 + 20 000 inputs: the 10^5, in about a second.
    #![proptest_config(ProptestConfig { cases: 60_000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn row_parser_never_panics_on_bytes(bytes in prop::collection::vec(any::<u8>(), 0..120)) {
        let _ = parse_mot_rows(Path::new("f.txt"), &bytes);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40_000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn row_parser_never_panics_on_plausible_rows(text in plausible_text()) {
        if let Ok(rows) = parse_mot_rows(Path::new("f.txt"), text.as_bytes()) {
            for row in rows {
                prop_assert!(row.width_px >= 0.0 && row.height_px >= 0.0 && row.left_px.is_finite());
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn seqinfo_parser_never_panics(text in "(\\[Sequence\\]\n)?([a-zA-Z]{0,10}[=:]?[-0-9a-z.]{0,8}\n){0,5}|.{0,100}") {
        let _ = parse_seqinfo(Path::new("seqinfo.ini"), &text);
    }
}
