//! Golden values: py-motmetrics' own test (`test_motchallenge_files`) and TrackEval's HOTA
//! on the TUD-Campus and TUD-Stadtmitte files shipped with py-motmetrics 1.4.0
//! (`../shared/data/motmetrics_tud_reference/README.md`), every value to 1e-6.

use sillage_eval::mot::{
    ClearMetrics, HotaMetrics, IdentityMetrics, MotChallengeProtocol, MotConvention, MotData,
    MotEstimate, MotMetrics, MotParams, MotReport, MotTruth, Shape, Similarity, clear_events,
    evaluate_mot,
};
use sillage_io::{MotRow, read_mot_rows};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/motmetrics_tud_reference"
);

fn shape(row: &MotRow) -> Shape {
    Shape::Box(row.bbox())
}

/// The evaluation data of one sequence: `gt.txt` against `test.txt`, box IoU.
fn sequence(name: &str) -> MotData {
    let gt = read_mot_rows(format!("{DATA}/{name}/gt.txt")).unwrap();
    let test = read_mot_rows(format!("{DATA}/{name}/test.txt")).unwrap();
    let truth: Vec<MotTruth> = gt
        .iter()
        .map(|r| MotTruth {
            frame: r.frame,
            id: r.id.unwrap(),
            shape: shape(r),
            role: MotChallengeProtocol::Mot15.truth_role(r.confidence.unwrap_or(1.0), r.class),
        })
        .collect();
    let estimates: Vec<MotEstimate> = test
        .iter()
        .map(|r| MotEstimate {
            frame: r.frame,
            id: r.id.unwrap(),
            shape: shape(r),
        })
        .collect();
    MotData::new(&truth, &estimates, Similarity::BoxIou, None).unwrap()
}

fn evaluate(convention: MotConvention) -> (MotMetrics, MotMetrics, MotMetrics) {
    let params = MotParams {
        convention,
        ..MotParams::default()
    };
    let campus = evaluate_mot(&sequence("TUD-Campus"), &params).unwrap();
    let stadtmitte = evaluate_mot(&sequence("TUD-Stadtmitte"), &params).unwrap();
    let combined = MotMetrics::combine(&[campus, stadtmitte]);
    (campus, stadtmitte, combined)
}

#[track_caller]
fn close(name: &str, actual: f64, expected: f64) {
    assert!(
        (actual - expected).abs() <= 1e-6,
        "{name}: {actual:.9} vs golden {expected}"
    );
}

/// One row of the py-motmetrics table: IDF1 IDP IDR Rcll Prcn GT MT PT ML FP FN IDs FM
/// MOTA MOTP(1-IoU), then IDTP IDFP IDFN and matches without switches where given.
struct MotmetricsRow {
    rates: [f64; 5],
    counts: [u64; 8],
    mota: f64,
    motp_distance: f64,
}

fn check_motmetrics(c: &ClearMetrics, i: &IdentityMetrics, g: &MotmetricsRow) {
    close("IDF1", i.idf1, g.rates[0]);
    close("IDP", i.idp, g.rates[1]);
    close("IDR", i.idr, g.rates[2]);
    close("Rcll", c.recall, g.rates[3]);
    close("Prcn", c.precision, g.rates[4]);
    let counts = [
        c.truth_objects(),
        c.mostly_tracked,
        c.partially_tracked,
        c.mostly_lost,
        c.false_positives,
        c.false_negatives,
        c.id_switches,
        c.fragmentations,
    ];
    assert_eq!(counts, g.counts, "GT MT PT ML FP FN IDs FM");
    close("MOTA", c.mota, g.mota);
    close("MOTP(1-IoU)", c.motp_distance, g.motp_distance);
}

const CAMPUS: MotmetricsRow = MotmetricsRow {
    rates: [0.557659, 0.729730, 0.451253, 0.582173, 0.941441],
    counts: [8, 1, 6, 1, 13, 150, 7, 7],
    mota: 0.526462,
    motp_distance: 0.277201,
};
const STADTMITTE: MotmetricsRow = MotmetricsRow {
    rates: [0.644619, 0.819760, 0.531142, 0.608997, 0.939920],
    counts: [10, 5, 4, 1, 45, 452, 7, 6],
    mota: 0.564014,
    motp_distance: 0.345904,
};
const OVERALL: MotmetricsRow = MotmetricsRow {
    rates: [0.624296, 0.799176, 0.512211, 0.602640, 0.940268],
    counts: [18, 6, 10, 2, 58, 602, 14, 13],
    mota: 0.555116,
    motp_distance: 0.330177,
};

#[test]
fn clear_and_identity_equal_py_motmetrics_in_both_conventions() {
    for convention in [MotConvention::TrackEval, MotConvention::PyMotMetrics] {
        let (campus, stadtmitte, combined) = evaluate(convention);
        check_motmetrics(&campus.clear, &campus.identity, &CAMPUS);
        check_motmetrics(&stadtmitte.clear, &stadtmitte.identity, &STADTMITTE);
        check_motmetrics(&combined.clear, &combined.identity, &OVERALL);
        // The README's further counts: IDTP / IDFP / IDFN and matches without switches.
        let id = |m: &MotMetrics| (m.identity.idtp, m.identity.idfp, m.identity.idfn);
        assert_eq!(id(&campus), (162, 60, 197));
        assert_eq!(id(&stadtmitte), (614, 135, 542));
        let plain = |m: &MotMetrics| m.clear.true_positives - m.clear.id_switches;
        assert_eq!((plain(&campus), plain(&stadtmitte)), (202, 697));
    }
}

/// TrackEval's HOTA family, MOTP (mean IoU) and MODA: HOTA DetA AssA DetRe DetPr AssRe
/// AssPr LocA OWTA HOTA(0) LocA(0) HOTALocA(0) MOTP MODA.
fn check_trackeval(h: &HotaMetrics, c: &ClearMetrics, golden: [f64; 14]) {
    let actual = [
        h.hota,
        h.det_a,
        h.ass_a,
        h.det_re,
        h.det_pr,
        h.ass_re,
        h.ass_pr,
        h.loc_a,
        h.owta,
        h.hota_0,
        h.loc_a_0,
        h.hota_loc_a_0,
        c.motp,
        c.moda,
    ];
    let names = [
        "HOTA",
        "DetA",
        "AssA",
        "DetRe",
        "DetPr",
        "AssRe",
        "AssPr",
        "LocA",
        "OWTA",
        "HOTA(0)",
        "LocA(0)",
        "HOTALocA(0)",
        "MOTP",
        "MODA",
    ];
    for ((name, a), g) in names.iter().zip(actual).zip(golden) {
        close(name, a, g);
    }
}

#[test]
fn hota_family_equals_trackeval() {
    let (campus, stadtmitte, combined) = evaluate(MotConvention::TrackEval);
    check_trackeval(
        &campus.hota,
        &campus.clear,
        [
            0.391397, 0.418047, 0.369121, 0.441577, 0.714083, 0.383225, 0.754050, 0.770052,
            0.403395, 0.549351, 0.702803, 0.386086, 0.722799, 0.545961,
        ],
    );
    check_trackeval(
        &stadtmitte.hota,
        &stadtmitte.clear,
        [
            0.397849, 0.392268, 0.408841, 0.413131, 0.637622, 0.449219, 0.631203, 0.737521,
            0.409711, 0.629305, 0.633085, 0.398404, 0.654096, 0.570069,
        ],
    );
    check_trackeval(
        &combined.hota,
        &combined.clear,
        [
            0.399957, 0.397683, 0.412450, 0.419871, 0.655103, 0.450665, 0.692211, 0.732480,
            0.413066, 0.611329, 0.649058, 0.396788, 0.669823, 0.564356,
        ],
    );
}

#[test]
fn events_agree_with_the_counts_and_the_report_prints() {
    let data = sequence("TUD-Campus");
    for convention in [MotConvention::TrackEval, MotConvention::PyMotMetrics] {
        let params = MotParams {
            convention,
            ..MotParams::default()
        };
        let events = clear_events(&data, &params).unwrap();
        let sum = |f: fn(&sillage_eval::mot::FrameEvents) -> usize| -> u64 {
            events.iter().map(f).sum::<usize>() as u64
        };
        assert_eq!(sum(|e| e.matches.len()), 209);
        assert_eq!(sum(|e| e.misses.len()), 150);
        assert_eq!(sum(|e| e.false_positives.len()), 13);
        assert_eq!(
            sum(|e| e
                .matches
                .iter()
                .filter(|m| m.switched_from.is_some())
                .count()),
            7
        );
        // Frames are 0-based: the file's frame 1 is frame 0.
        assert_eq!(events[0].frame, 0);
    }
    let (campus, stadtmitte, _) = evaluate(MotConvention::TrackEval);
    let report = MotReport::new(vec![
        ("TUD-Campus".into(), campus),
        ("TUD-Stadtmitte".into(), stadtmitte),
    ]);
    let text = report.to_string();
    assert!(
        text.contains("COMBINED") && text.contains("39.996"),
        "{text}"
    );
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["combined"]["clear"]["id_switches"], 14);
}
