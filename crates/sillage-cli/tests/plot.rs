//! `sillage plot` and `sillage overlay` end to end on a small generated vortex tracked by
//! `sillage ptv`, on hand-written bead and MOTChallenge tables, and their errors.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{path_str, run_ok, run_user_error};

const FRAMES: usize = 12;

/// A 96×64 vortex of 120 particles over [`FRAMES`] frames, tracked: (frames folder, tracks).
fn tracked_vortex(dir: &Path) -> (PathBuf, PathBuf) {
    let frames = dir.join("frames");
    let tracks = dir.join("tracks.csv");
    common::synth_vortex(&frames, FRAMES as u64, 120, (96, 64), &["--delta", "0.02"]);
    run_ok(&["ptv", path_str(&frames), "--out", path_str(&tracks)]);
    (frames, tracks)
}

/// Checks that `path` is a PNG of `width × height` with more than one colour.
fn assert_png(path: &Path, width: u32, height: u32) {
    let picture = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    assert_eq!(picture.dimensions(), (width, height), "{}", path.display());
    let first = picture.get_pixel(0, 0);
    assert!(
        picture.pixels().any(|p| p != first),
        "{} is blank",
        path.display()
    );
}

/// Checks that `path` is an SVG document of `width × height` holding `texts`.
fn assert_svg(path: &Path, width: u32, height: u32, texts: &[&str]) {
    let svg = std::fs::read_to_string(path).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{}",
        path.display()
    );
    assert!(
        svg.contains(&format!("width=\"{width}\" height=\"{height}\"")),
        "{}",
        &svg[..200]
    );
    for text in texts {
        assert!(svg.contains(text), "{}: {text} missing", path.display());
    }
}

#[test]
fn every_plot_kind_writes_a_png_and_an_svg_of_the_asked_size() {
    let dir = tempfile::tempdir().unwrap();
    let (_, tracks) = tracked_vortex(dir.path());
    let detections = dir.path().join("det.csv");
    let rows: String = (0..FRAMES)
        .map(|f| format!("{f},10,10\n{f},20,20\n"))
        .collect();
    std::fs::write(&detections, format!("frame,x,y\n{rows}")).unwrap();
    let kinds: [(&str, &[&str], &[&str]); 5] = [
        (
            "trajectories",
            &["--colour", "speed", "--min-length", "3"],
            &["px/frame", "x (px)"],
        ),
        (
            "quiver",
            &["--frame", "5"],
            &["Velocities at frame 5", "px/frame"],
        ),
        (
            "displacements",
            &["--log-y"],
            &["displacement (px/frame)", "count (log scale)"],
        ),
        (
            "prediction-error",
            &["--bins", "20"],
            &["log10 prediction error (px)"],
        ),
        (
            "counts",
            &["--detections", path_str(&detections)],
            &["detections", "tracks"],
        ),
    ];
    for (kind, options, texts) in kinds {
        let png = dir.path().join(format!("{kind}.png"));
        let svg = dir.path().join(format!("{kind}.svg"));
        for out in [&png, &svg] {
            let mut args = vec![
                "plot",
                kind,
                path_str(&tracks),
                "--out",
                path_str(out),
                "--size",
                "480x360",
            ];
            args.extend(options);
            run_ok(&args);
        }
        assert_png(&png, 480, 360);
        assert_svg(&svg, 480, 360, texts);
    }
    // Coloured by id, default size.
    let by_id = dir.path().join("by_id.png");
    run_ok(&[
        "plot",
        "trajectories",
        path_str(&tracks),
        "--out",
        path_str(&by_id),
        "--colour",
        "id",
    ]);
    assert_png(&by_id, 800, 600);
}

#[test]
fn overlays_are_png_frames_and_an_mp4_of_the_frame_count_and_size() {
    let dir = tempfile::tempdir().unwrap();
    let (frames, tracks) = tracked_vortex(dir.path());
    let out = dir.path().join("overlays");
    let have_ffmpeg = ["ffmpeg", "ffprobe"].iter().all(|p| {
        Command::new(p)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    });
    let video = dir.path().join("tracks.mp4");
    let mut args = vec![
        "overlay",
        path_str(&tracks),
        "--frames",
        path_str(&frames),
        "--out",
        path_str(&out),
        "--colour",
        "id",
        "--tail",
        "5",
    ];
    if have_ffmpeg {
        args.extend(["--mp4", path_str(&video), "--fps", "5"]);
    } else {
        eprintln!("MP4 part skipped: ffmpeg/ffprobe not installed (apt-get install ffmpeg)");
    }
    run_ok(&args);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), FRAMES);
    assert_eq!(names[0], "overlay_00000.png");
    assert_png(&out.join("overlay_00005.png"), 96, 64);
    if have_ffmpeg {
        let probe = Command::new("ffprobe")
            .args(["-v", "error", "-select_streams", "v:0", "-count_frames"])
            .args([
                "-show_entries",
                "stream=width,height,nb_read_frames",
                "-of",
                "csv=p=0",
            ])
            .arg(&video)
            .output()
            .unwrap();
        assert!(
            probe.status.success(),
            "{}",
            String::from_utf8_lossy(&probe.stderr)
        );
        assert_eq!(
            String::from_utf8_lossy(&probe.stdout).trim(),
            format!("96,64,{FRAMES}")
        );
        // Written under a temporary name, renamed at the end: nothing else left beside it.
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("partial"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }
}

#[test]
fn bead_and_mot_tables_are_read_with_their_states_and_box_centres() {
    let dir = tempfile::tempdir().unwrap();
    // Two beads, one rolling and one saltating (BeadTracking's layout, 1-based).
    let beads = dir.path().join("beads.csv");
    let rows: String = (1..=10)
        .map(|f| {
            format!(
                "{f},1,{},50,0,2,0,1\n{f},2,{},80,1,4,-1,2\n",
                10 + 2 * f,
                5 + 4 * f
            )
        })
        .collect();
    std::fs::write(
        &beads,
        format!("frame,id,x,y,category,vx,vy,motion_state\n{rows}"),
    )
    .unwrap();
    let svg = dir.path().join("beads.svg");
    run_ok(&[
        "plot",
        "trajectories",
        path_str(&beads),
        "--out",
        path_str(&svg),
    ]);
    assert_svg(&svg, 800, 600, &["rolling", "saltating"]);
    // MOTChallenge results: boxes drawn by their centres.
    let mot = dir.path().join("results.txt");
    let rows: String = (1..=8)
        .map(|f| format!("{f},3,{},40,20,60,1,-1,-1,-1\n", 10 * f))
        .collect();
    std::fs::write(&mot, rows).unwrap();
    let png = dir.path().join("mot.png");
    run_ok(&[
        "plot",
        "trajectories",
        path_str(&mot),
        "--out",
        path_str(&png),
        "--colour",
        "id",
    ]);
    assert_png(&png, 800, 600);
    let counts = dir.path().join("counts.svg");
    run_ok(&["plot", "counts", path_str(&mot), "--out", path_str(&counts)]);
    assert_svg(&counts, 800, 600, &["tracks"]);
    // Those tables have no prediction errors, and MOT results no states.
    let e = run_user_error(&[
        "plot",
        "prediction-error",
        path_str(&mot),
        "--out",
        path_str(&png),
    ]);
    assert!(e.contains("only `sillage ptv` writes them"), "{e}");
    let e = run_user_error(&[
        "plot",
        "trajectories",
        path_str(&mot),
        "--out",
        path_str(&png),
        "--colour",
        "state",
    ]);
    assert!(
        e.contains("no motion states") && e.contains("--colour speed"),
        "{e}"
    );
}

#[test]
fn user_errors_name_the_file_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let odd = dir.path().join("tracks.dat");
    std::fs::write(&odd, "1 2 3\n").unwrap();
    let e = run_user_error(&[
        "plot",
        "trajectories",
        path_str(&odd),
        "--out",
        path_str(&png),
    ]);
    assert!(e.contains("tracks.dat") && e.contains("--format"), "{e}");
    let empty = dir.path().join("empty.csv");
    std::fs::write(&empty, "frame,particle,x,y\n").unwrap();
    let e = run_user_error(&["plot", "counts", path_str(&empty), "--out", path_str(&png)]);
    assert!(
        e.contains("empty.csv") && e.contains("no track point"),
        "{e}"
    );
    let short = dir.path().join("short.csv");
    std::fs::write(&short, "frame,particle,x,y\n0,1,5,5\n1,1,6,5\n").unwrap();
    let e = run_user_error(&[
        "plot",
        "trajectories",
        path_str(&short),
        "--out",
        path_str(&png),
        "--min-length",
        "5",
    ]);
    assert!(e.contains("--min-length"), "{e}");
    let e = run_user_error(&[
        "plot",
        "quiver",
        path_str(&short),
        "--out",
        path_str(&png),
        "--frame",
        "9",
    ]);
    assert!(e.contains("frame 9") && e.contains("0 to 1"), "{e}");
    let jpg = dir.path().join("out.jpg");
    let e = run_user_error(&[
        "plot",
        "trajectories",
        path_str(&short),
        "--out",
        path_str(&jpg),
    ]);
    assert!(e.contains(".png or .svg"), "{e}");
    let e = run_user_error(&[
        "overlay",
        path_str(&short),
        "--frames",
        path_str(&dir.path().join("none")),
        "--out",
        path_str(&dir.path().join("ov")),
    ]);
    assert!(e.contains("none"), "{e}");
}
