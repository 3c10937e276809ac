//! `sillage synth walkers`: the MOTChallenge sequence folder it writes reads back through
//! `sillage-io` as the generator made it, and bad options are user errors naming the option.

mod common;

use common::{path_str, run_ok, run_user_error};
use sillage::io::{FrameOptions, open_frames, read_mot_rows, read_seqinfo};
use sillage::synth::{GroupSplitParams, Scenario, WalkersParams, WalkersSequence};

#[test]
fn the_sequence_folder_reads_back_as_generated() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("walkers-split");
    let seq_arg = path_str(&seq);
    run_ok(&[
        "synth",
        "walkers",
        "--scenario",
        "group-split",
        "--frames",
        "40",
        "--seed",
        "2",
        "--out",
        seq_arg,
    ]);
    let info = read_seqinfo(seq.join("seqinfo.ini")).unwrap();
    assert_eq!(info.name.as_deref(), Some("walkers-split"));
    assert_eq!(info.frame_count, Some(40));
    assert_eq!(
        (info.image_width, info.image_height),
        (Some(320), Some(240))
    );
    assert_eq!(info.image_dir.as_deref(), Some("img1"));
    assert_eq!(info.image_ext.as_deref(), Some(".png"));
    let pngs = std::fs::read_dir(seq.join("img1")).unwrap().count();
    assert_eq!(pngs, 40);
    assert!(seq.join("img1/000001.png").is_file() && seq.join("img1/000040.png").is_file());

    // The generator itself, with the parameters the command line stands for.
    let expected: Vec<_> = WalkersSequence::new(WalkersParams {
        n_frames: 40,
        seed: 2,
        scenario: Scenario::GroupSplit(GroupSplitParams::default()),
        ..Default::default()
    })
    .unwrap()
    .collect();
    let options = FrameOptions {
        colour: true,
        ..Default::default()
    };
    for (frame, generated) in open_frames(path_str(&seq.join("img1")), &options)
        .unwrap()
        .zip(&expected)
    {
        let frame = frame.unwrap();
        assert_eq!(frame.colour.as_ref(), Some(&generated.colour));
        // The grey the readers compute from the PNG is the generator's, bit for bit.
        assert_eq!(frame.image, generated.grey, "frame {}", frame.index);
    }

    let rows = read_mot_rows(seq.join("gt/gt.txt")).unwrap();
    let truth: Vec<_> = expected
        .iter()
        .flat_map(|f| f.truth.iter().map(move |t| (f.index, t)))
        .collect();
    assert!(!rows.is_empty());
    assert_eq!(rows.len(), truth.len());
    for (row, (frame, t)) in rows.iter().zip(truth) {
        assert_eq!((row.frame, row.id), (frame, Some(t.id)));
        // Boxes move to the trackers' convention: a blob's first column is its left edge.
        assert_eq!(row.left_px, t.left_px + 0.5);
        assert_eq!(row.top_px, t.top_px + 0.5);
        assert_eq!((row.width_px, row.height_px), (t.width_px, t.height_px));
        assert_eq!((row.confidence, row.class), (Some(1.0), Some(1)));
        assert_eq!(row.visibility, Some(t.visibility));
    }
}

#[test]
fn bad_options_are_user_errors_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seq");
    let out = path_str(&out);
    for (args, option) in [
        (&["--scenario", "random", "--walkers", "0"][..], "--walkers"),
        (
            &["--scenario", "crossing", "--walkers", "3"][..],
            "--walkers",
        ),
        (&["--scenario", "crossing", "--width", "120"][..], "--width"),
        (
            &["--scenario", "group-split", "--height", "50"][..],
            "--height",
        ),
        (&["--frames", "5"][..], "--frames"),
    ] {
        let mut command = vec!["synth", "walkers", "--out", out];
        command.extend_from_slice(args);
        let message = run_user_error(&command);
        assert!(message.contains(option), "{args:?}: {message}");
    }
}

#[test]
fn a_seqinfo_that_disagrees_with_the_frames_is_named_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("walkers");
    common::synth_walkers(&seq, "crossing", 12);
    let img1 = seq.join("img1");
    let ini = seq.join("seqinfo.ini");
    let written = std::fs::read_to_string(&ini).unwrap();
    let line_of = |key: &str| 1 + written.lines().position(|l| l.starts_with(key)).unwrap();
    let out = dir.path().join("out.txt");
    let track =
        |tracker: &'static str| ["track", tracker, path_str(&img1), "--out", path_str(&out)];
    // As generated, and as the first frames of a longer sequence (seqLength above the count).
    run_ok(&track("immpf"));
    std::fs::write(&ini, written.replace("seqLength=12", "seqLength=795")).unwrap();
    run_ok(&track("siftpf"));
    // More frames than seqLength, or another frame size: the file and the key's line.
    std::fs::write(&ini, written.replace("seqLength=12", "seqLength=10")).unwrap();
    for tracker in ["immpf", "siftpf"] {
        let message = run_user_error(&track(tracker));
        let at = format!("seqinfo.ini:{}:", line_of("seqLength"));
        assert!(
            message.contains(&at) && message.contains("holds 12 frames"),
            "{message}"
        );
    }
    std::fs::write(&ini, written.replace("imWidth=320", "imWidth=640")).unwrap();
    let message = run_user_error(&track("immpf"));
    let at = format!("seqinfo.ini:{}:", line_of("imWidth"));
    assert!(
        message.contains(&at) && message.contains("imWidth is 640"),
        "{message}"
    );
}
