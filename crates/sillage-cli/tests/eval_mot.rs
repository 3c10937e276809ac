//! `sillage eval mot` end to end: the golden values of the TUD files shipped with
//! py-motmetrics (`../shared/data/motmetrics_tud_reference/README.md`) from files and from
//! folders paired by name, the per-frame events, the bead ground truth with disc matching and
//! the papers' scores, and every kind of bad input with its exit code and message.

use std::fs;
use std::path::Path;

mod common;
use common::{path_str, sillage, stderr};

use serde_json::Value;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");

/// Runs `eval mot` with `args` and `--json`, and parses what it prints.
fn eval_json(args: &[&str]) -> Value {
    let mut all = vec!["eval", "mot", "--json"];
    all.extend_from_slice(args);
    let out = sillage(&all);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("--json prints JSON")
}

#[track_caller]
fn close(value: &Value, pointer: &str, expected: f64) {
    let actual = value
        .pointer(pointer)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("no number at {pointer}"));
    assert!(
        (actual - expected).abs() <= 1e-6,
        "{pointer}: {actual} vs golden {expected}"
    );
}

#[track_caller]
fn count(value: &Value, pointer: &str, expected: u64) {
    assert_eq!(
        value.pointer(pointer).and_then(Value::as_u64),
        Some(expected),
        "{pointer}"
    );
}

/// py-motmetrics' table: IDF1 IDP IDR Rcll Prcn, then GT MT PT ML FP FN IDs FM, MOTA and
/// MOTP(1-IoU); under `prefix` (a sequence's or the combined `metrics`).
fn check_motmetrics(
    json: &Value,
    prefix: &str,
    rates: [f64; 5],
    counts: [u64; 8],
    mota_motp: [f64; 2],
) {
    let names = [
        "identity/idf1",
        "identity/idp",
        "identity/idr",
        "clear/recall",
        "clear/precision",
    ];
    for (name, golden) in names.iter().zip(rates) {
        close(json, &format!("{prefix}/{name}"), golden);
    }
    let clear = |name: &str| format!("{prefix}/clear/{name}");
    let gt = ["mostly_tracked", "partially_tracked", "mostly_lost"]
        .iter()
        .map(|n| json.pointer(&clear(n)).and_then(Value::as_u64).unwrap())
        .sum::<u64>();
    assert_eq!(gt, counts[0], "GT of {prefix}");
    let names = [
        "mostly_tracked",
        "partially_tracked",
        "mostly_lost",
        "false_positives",
        "false_negatives",
        "id_switches",
        "fragmentations",
    ];
    for (name, golden) in names.iter().zip(&counts[1..]) {
        count(json, &clear(name), *golden);
    }
    close(json, &clear("mota"), mota_motp[0]);
    close(json, &clear("motp_distance"), mota_motp[1]);
}

/// TrackEval's HOTA table: HOTA DetA AssA DetRe DetPr AssRe AssPr LocA OWTA HOTA(0) LocA(0)
/// HOTALocA(0), then MOTP (mean IoU) and MODA.
fn check_hota(json: &Value, prefix: &str, golden: [f64; 14]) {
    let names = [
        "hota/hota",
        "hota/det_a",
        "hota/ass_a",
        "hota/det_re",
        "hota/det_pr",
        "hota/ass_re",
        "hota/ass_pr",
        "hota/loc_a",
        "hota/owta",
        "hota/hota_0",
        "hota/loc_a_0",
        "hota/hota_loc_a_0",
        "clear/motp",
        "clear/moda",
    ];
    for (name, value) in names.iter().zip(golden) {
        close(json, &format!("{prefix}/{name}"), value);
    }
}

const CAMPUS_HOTA: [f64; 14] = [
    0.391397, 0.418047, 0.369121, 0.441577, 0.714083, 0.383225, 0.754050, 0.770052, 0.403395,
    0.549351, 0.702803, 0.386086, 0.722799, 0.545961,
];
const STADTMITTE_HOTA: [f64; 14] = [
    0.397849, 0.392268, 0.408841, 0.413131, 0.637622, 0.449219, 0.631203, 0.737521, 0.409711,
    0.629305, 0.633085, 0.398404, 0.654096, 0.570069,
];
const COMBINED_HOTA: [f64; 14] = [
    0.399957, 0.397683, 0.412450, 0.419871, 0.655103, 0.450665, 0.692211, 0.732480, 0.413066,
    0.611329, 0.649058, 0.396788, 0.669823, 0.564356,
];

#[test]
fn tud_files_give_the_golden_values_in_json_and_in_the_table() {
    let campus = format!("{DATA}/motmetrics_tud_reference/TUD-Campus");
    let (gt, pred) = (format!("{campus}/gt.txt"), format!("{campus}/test.txt"));
    let json = eval_json(&["--gt", &gt, "--pred", &pred]);
    assert_eq!(json["sequences"][0]["name"], "TUD-Campus");
    check_hota(&json, "/sequences/0/metrics", CAMPUS_HOTA);
    let json = eval_json(&["--gt", &gt, "--pred", &pred, "--convention", "pymotmetrics"]);
    check_motmetrics(
        &json,
        "/sequences/0/metrics",
        [0.557659, 0.729730, 0.451253, 0.582173, 0.941441],
        [8, 1, 6, 1, 13, 150, 7, 7],
        [0.526462, 0.277201],
    );
    count(&json, "/sequences/0/metrics/identity/idtp", 162);

    // The table prints the same numbers as percentages with three decimals.
    let out = sillage(&["eval", "mot", "--gt", &gt, "--pred", &pred]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let row = |table: &str| -> Vec<String> {
        let start = text.find(table).expect("the table is printed");
        let line = text[start..]
            .lines()
            .find(|l| l.starts_with("TUD-Campus"))
            .expect("a row per sequence");
        line.split_whitespace().skip(1).map(str::to_owned).collect()
    };
    assert_eq!(row("HOTA (")[..3], ["39.140", "41.805", "36.912"]);
    assert_eq!(row("CLEAR MOT")[..3], ["52.646", "54.596", "72.280"]);
    assert_eq!(row("Identity")[..3], ["55.766", "72.973", "45.125"]);
    assert!(text.contains("COMBINED"), "{text}");
}

/// Copies the two TUD sequences into MOTChallenge layouts: `gt/SEQ/{gt/gt.txt,seqinfo.ini}`
/// and `pred/SEQ.txt`.
fn tud_folders(root: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let (gt, pred) = (root.join("gt"), root.join("pred"));
    fs::create_dir_all(&pred).unwrap();
    for seq in ["TUD-Campus", "TUD-Stadtmitte"] {
        let folder = gt.join(seq);
        fs::create_dir_all(folder.join("gt")).unwrap();
        let source = format!("{DATA}/mot15_train_gt_det/{seq}");
        fs::copy(format!("{source}/gt/gt.txt"), folder.join("gt/gt.txt")).unwrap();
        fs::copy(format!("{source}/seqinfo.ini"), folder.join("seqinfo.ini")).unwrap();
        let test = format!("{DATA}/motmetrics_tud_reference/{seq}/test.txt");
        fs::copy(test, pred.join(format!("{seq}.txt"))).unwrap();
    }
    fs::write(pred.join(".notes"), "hidden files are not sequences").unwrap();
    (gt, pred)
}

#[test]
fn folders_pair_by_name_and_combine_as_the_references() {
    let dir = tempfile::tempdir().unwrap();
    let (gt, pred) = tud_folders(dir.path());
    let events = dir.path().join("events.csv");
    let json = eval_json(&[
        "--gt",
        path_str(&gt),
        "--pred",
        path_str(&pred),
        "--per-frame",
        path_str(&events),
    ]);
    assert_eq!(json["sequences"][1]["name"], "TUD-Stadtmitte");
    check_hota(&json, "/sequences/0/metrics", CAMPUS_HOTA);
    check_hota(&json, "/sequences/1/metrics", STADTMITTE_HOTA);
    check_hota(&json, "/combined/metrics", COMBINED_HOTA);
    let json = eval_json(&[
        "--gt",
        path_str(&gt),
        "--pred",
        path_str(&pred),
        "--convention",
        "pymotmetrics",
    ]);
    check_motmetrics(
        &json,
        "/sequences/1/metrics",
        [0.644619, 0.819760, 0.531142, 0.608997, 0.939920],
        [10, 5, 4, 1, 45, 452, 7, 6],
        [0.564014, 0.345904],
    );
    check_motmetrics(
        &json,
        "/combined/metrics",
        [0.624296, 0.799176, 0.512211, 0.602640, 0.940268],
        [18, 6, 10, 2, 58, 602, 14, 13],
        [0.555116, 0.330177],
    );

    // The events: py-motmetrics' matches without switches (202 and 697), the switches, the
    // misses and the false positives of the two sequences; the file was renamed into place.
    let text = fs::read_to_string(&events).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("sequence,frame,truth_id,estimate_id,similarity,event,previous_estimate_id")
    );
    let tally = |sequence: &str, event: &str| {
        text.lines()
            .filter(|l| l.starts_with(&format!("{sequence},")))
            .filter(|l| l.split(',').nth(5) == Some(event))
            .count()
    };
    assert_eq!(tally("TUD-Campus", "match"), 202);
    assert_eq!(tally("TUD-Stadtmitte", "match"), 697);
    assert_eq!(
        tally("TUD-Campus", "switch") + tally("TUD-Stadtmitte", "switch"),
        14
    );
    assert_eq!(
        tally("TUD-Campus", "miss") + tally("TUD-Stadtmitte", "miss"),
        602
    );
    assert_eq!(
        tally("TUD-Campus", "false_positive") + tally("TUD-Stadtmitte", "false_positive"),
        58
    );
    let switch = text.lines().find(|l| l.contains(",switch,")).unwrap();
    assert!(
        switch
            .rsplit(',')
            .next()
            .is_some_and(|p| p.parse::<u64>().is_ok()),
        "{switch}"
    );
    assert!(!dir.path().join(".events.csv.partial").exists());

    // One sequence folder alone pairs with one file.
    let json = eval_json(&[
        "--gt",
        path_str(&gt.join("TUD-Campus")),
        "--pred",
        path_str(&pred.join("TUD-Campus.txt")),
    ]);
    check_hota(&json, "/combined/metrics", CAMPUS_HOTA);
}

#[test]
fn unpaired_sequences_are_reported_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (gt, pred) = tud_folders(dir.path());
    fs::remove_file(pred.join("TUD-Campus.txt")).unwrap();
    fs::write(pred.join("ETH-Bahnhof.txt"), "1,1,1,1,1,1,-1,-1,-1,-1\n").unwrap();
    let out = sillage(&[
        "eval",
        "mot",
        "--gt",
        path_str(&gt),
        "--pred",
        path_str(&pred),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("ground-truth sequence(s) TUD-Campus")
            && err.contains("prediction(s) ETH-Bahnhof"),
        "{err}"
    );

    // Several sequences against one file cannot be paired either.
    let one = pred.join("TUD-Stadtmitte.txt");
    let out = sillage(&[
        "eval",
        "mot",
        "--gt",
        path_str(&gt),
        "--pred",
        path_str(&one),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("holds 2 sequences"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn predictions_beyond_the_sequence_and_malformed_rows_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (gt, pred) = tud_folders(dir.path());
    let campus = pred.join("TUD-Campus.txt");
    let mut text = fs::read_to_string(&campus).unwrap();
    // seqinfo.ini says 71 frames.
    text.push_str("72,3,113.8,274.5,57.3,130.0,-1,-1,-1,-1\n");
    fs::write(&campus, &text).unwrap();
    let args = [
        "eval",
        "mot",
        "--gt",
        path_str(&gt),
        "--pred",
        path_str(&pred),
    ];
    let out = sillage(&args);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("TUD-Campus.txt") && err.contains("beyond"),
        "{err}"
    );

    fs::write(
        &campus,
        "1,3,113.8,274.5,57.3,130.0,-1,-1,-1,-1\n\n2,3,oops,1,1,1\n",
    )
    .unwrap();
    let out = sillage(&args);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("TUD-Campus.txt:3:"),
        "{}",
        stderr(&out)
    );

    fs::write(&campus, "1,-1,113.8,274.5,57.3,130.0,-1,-1,-1,-1\n").unwrap();
    let out = sillage(&args);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("id -1"), "{}", stderr(&out));
}

#[test]
fn bad_match_rules_are_command_line_errors() {
    for rule in ["dist", "dist:-1", "iou:1.5", "box"] {
        let out = sillage(&["eval", "mot", "--gt", "x", "--pred", "y", "--match", rule]);
        assert_eq!(out.status.code(), Some(2), "{rule}: {}", stderr(&out));
    }
    let out = sillage(&["eval", "mot", "--gt", "no/such/gt.txt", "--pred", "y"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("no/such/gt.txt does not exist"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn beads_with_discs_points_and_the_papers_scores() {
    let beads = format!("{DATA}/bedload_beads_lafaye2018/ground_truth/trackdatatruth.csv");
    // The ground truth against itself, as the MMPF+ paper matches beads (disc IoU ≥ 0.43,
    // radii from sequence_param.txt one folder up): every track correct, every state right.
    let json = eval_json(&[
        "--gt", &beads, "--pred", &beads, "--match", "disc", "--papers",
    ]);
    close(&json, "/params/threshold", 0.43);
    close(&json, "/combined/metrics/clear/mota", 1.0);
    count(&json, "/combined/papers/bedload/correct_tracks", 397);
    count(&json, "/combined/papers/motion_states/evaluated", 3565);
    count(
        &json,
        "/combined/papers/motion_states/saltating/true_positives",
        88,
    );
    // The confusion matrix (rows true, columns estimated rest/roll/salt/unknown): diagonal.
    assert_eq!(
        json.pointer("/combined/papers/motion_states/confusion")
            .unwrap(),
        &serde_json::json!([[2305, 0, 0, 0], [0, 1172, 0, 0], [0, 0, 88, 0]])
    );
    close(&json, "/combined/papers/vace/ata", 1.0);
    close(&json, "/combined/papers/etiseo/mean", 1.0);

    // A sillage track file (0-based frames and pixels) 2 px off: matched within 3 px, not
    // within 1 px; no motion states to compare.
    let dir = tempfile::tempdir().unwrap();
    let tracks = dir.path().join("tracks.csv");
    let mut csv = String::from("frame,particle,x,y\n");
    for line in fs::read_to_string(&beads).unwrap().lines().skip(1) {
        let f: Vec<f64> = line
            .split(',')
            .take(4)
            .map(|v| v.parse().unwrap())
            .collect();
        csv.push_str(&format!(
            "{},{},{},{}\n",
            f[0] - 1.0,
            f[1],
            f[2] - 1.0 + 2.0,
            f[3] - 1.0
        ));
    }
    fs::write(&tracks, csv).unwrap();
    let json = eval_json(&[
        "--gt",
        &beads,
        "--pred",
        path_str(&tracks),
        "--match",
        "dist:3",
        "--papers",
    ]);
    count(&json, "/combined/metrics/clear/true_positives", 3962);
    assert!(
        json.pointer("/combined/papers/motion_states")
            .unwrap()
            .is_null()
    );
    let json = eval_json(&[
        "--gt",
        &beads,
        "--pred",
        path_str(&tracks),
        "--match",
        "dist:1",
    ]);
    count(&json, "/combined/metrics/clear/true_positives", 0);

    // Box IoU cannot compare points, nor disc IoU boxes.
    let out = sillage(&["eval", "mot", "--gt", &beads, "--pred", path_str(&tracks)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("holds beads"), "{}", stderr(&out));
    let campus = format!("{DATA}/motmetrics_tud_reference/TUD-Campus");
    let (gt, pred) = (format!("{campus}/gt.txt"), format!("{campus}/test.txt"));
    let out = sillage(&[
        "eval", "mot", "--gt", &gt, "--pred", &pred, "--match", "disc",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("holds boxes"), "{}", stderr(&out));
}
