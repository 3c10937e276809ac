//! Track tables: round trips for every format, TracTrac's exact header, hand-made TracTrac
//! files, partial files, and errors that name the line.

use std::path::Path;

use sillage_core::{MotionState, Point2, TrackPoint, Vec2};
use sillage_io::{
    TRACTRAC_COLUMNS_LINE, TrackFileHeader, TrackFormat, TrackLayout, create_track_writer,
    for_each_track_point, read_track_table, read_tracks,
};

fn sample_points(n: u64) -> Vec<TrackPoint> {
    (0..n)
        .map(|i| {
            let mut p = TrackPoint::at(
                i / 3,
                70_000 + i % 3,
                Point2::new(i as f64 * 1.25 + 0.123456, 7.0 - i as f64 / 7.0),
            );
            if i % 2 == 0 {
                p.vel_px_per_frame = Some(Vec2::new(0.5 + i as f64 * 1e-3, -0.25));
                p.acc_px_per_frame2 = Some(Vec2::new(0.01, 0.02));
                p.vel_pred_px_per_frame = Some(Vec2::new(0.49, -0.26));
                p.log10_pred_err = Some(-1.2345);
            }
            p
        })
        .collect()
}

fn header() -> TrackFileHeader {
    TrackFileHeader {
        program_version: "3.0 (sillage 0.1.0)".into(),
        parameters: vec![
            ("peak_th".into(), "0.02".into()),
            ("tracker".into(), "ptv".into()),
        ],
        ..TrackFileHeader::default()
    }
}

fn write(path: &Path, format: TrackFormat, points: &[TrackPoint]) {
    let mut writer = create_track_writer(path, format, &header()).unwrap();
    for chunk in points.chunks(4) {
        writer.accept(chunk).unwrap();
    }
    let summary = writer.finish().unwrap();
    assert_eq!(summary.rows, points.len() as u64);
    assert_eq!(summary.path, path);
}

fn assert_close(a: &[TrackPoint], b: &[TrackPoint], tol: f64) {
    assert_eq!(a.len(), b.len());
    let close = |x: f64, y: f64| (x - y).abs() <= tol;
    let close_v = |x: Option<Vec2>, y: Option<Vec2>| match (x, y) {
        (Some(x), Some(y)) => close(x.x, y.x) && close(x.y, y.y),
        (None, None) => true,
        _ => false,
    };
    for (p, q) in a.iter().zip(b) {
        assert_eq!((p.frame, p.track_id), (q.frame, q.track_id));
        assert!(
            close(p.pos_px.x, q.pos_px.x) && close(p.pos_px.y, q.pos_px.y),
            "{p:?} {q:?}"
        );
        assert!(
            close_v(p.vel_px_per_frame, q.vel_px_per_frame),
            "{p:?} {q:?}"
        );
        assert!(
            close_v(p.acc_px_per_frame2, q.acc_px_per_frame2),
            "{p:?} {q:?}"
        );
        assert!(
            close_v(p.vel_pred_px_per_frame, q.vel_pred_px_per_frame),
            "{p:?} {q:?}"
        );
        match (p.log10_pred_err, q.log10_pred_err) {
            (Some(x), Some(y)) => assert!(close(x, y)),
            (x, y) => assert_eq!(x, y),
        }
    }
}

#[test]
fn tractrac_round_trip_within_its_decimals() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seq_track.txt");
    let points = sample_points(20);
    write(&path, TrackFormat::Tractrac, &points);
    assert_close(
        &read_tracks(&path, TrackFormat::Tractrac).unwrap(),
        &points,
        5e-4,
    );
}

#[test]
fn csv_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tracks.csv");
    let points = sample_points(20);
    write(&path, TrackFormat::Csv, &points);
    assert_eq!(read_tracks(&path, TrackFormat::Csv).unwrap(), points);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err\n"));
}

#[cfg(feature = "parquet")]
#[test]
fn parquet_round_trip_is_exact_across_row_groups() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tracks.parquet");
    let points = sample_points(150_000);
    let mut writer = create_track_writer(&path, TrackFormat::Parquet, &header()).unwrap();
    for chunk in points.chunks(1000) {
        writer.accept(chunk).unwrap();
    }
    assert_eq!(writer.finish().unwrap().rows, 150_000);
    assert_eq!(read_tracks(&path, TrackFormat::Parquet).unwrap(), points);
}

#[cfg(feature = "hdf5")]
#[test]
fn hdf5_round_trip_is_exact_with_large_ids() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tracks.h5");
    let points = sample_points(70_000);
    let mut writer = create_track_writer(&path, TrackFormat::Hdf5, &header()).unwrap();
    for chunk in points.chunks(5000) {
        writer.accept(chunk).unwrap();
    }
    assert_eq!(writer.finish().unwrap().rows, 70_000);
    assert!(!dir.path().join(".tracks.h5.partial").exists());
    assert_eq!(read_tracks(&path, TrackFormat::Hdf5).unwrap(), points);
}

#[test]
fn tractrac_header_is_exactly_tractracs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seq_track.txt");
    let mut point = TrackPoint::at(1, 0, Point2::new(12.0, 3.5));
    point.vel_px_per_frame = Some(Vec2::new(1.0, -0.5));
    write(&path, TrackFormat::Tractrac, &[point]);
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# TracTrac v3.0 (sillage 0.1.0) ");
    assert_eq!(
        lines[1],
        "#  Parameters: {'peak_th': 0.02, 'tracker': 'ptv'}"
    );
    assert_eq!(
        lines[2],
        "#  Frame ID x y Vx Vy Ax Ay Vx(prediction) Vy(prediction) Error(prediction)"
    );
    assert_eq!(lines[2], format!("#  {TRACTRAC_COLUMNS_LINE}"));
    assert_eq!(
        lines[3],
        "1 0 12.000 3.500 1.00000 -0.50000 nan nan nan nan nan"
    );
    assert_eq!(lines.len(), 4);
}

#[test]
fn hand_made_tractrac_file_is_read() {
    // As numpy.savetxt writes it from TracTrac v3.0 (one row per tracklet per frame).
    let text = "# TracTrac v3.0 (22/05/2021) | J. Heyman \n\
#  Parameters: {'vid_loop': 2.0, 'peak_th': 0.02, 'ROIxmin': 0}\n\
#  Frame ID x y Vx Vy Ax Ay Vx(prediction) Vy(prediction) Error(prediction)\n\
1 0 101.234 55.500 1.20000 -0.30000 0.0100 -0.0200 1.1900 -0.2900 -1.523\n\
1 1 12.000 13.000 nan nan nan nan 0.0000 0.0000 -10.000\n\
\n\
2 0 102.434 55.200 1.20000 -0.30000 0.0000 0.0000 1.2000 -0.3000 -2.000\n";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("videotest_track.txt");
    std::fs::write(&path, text).unwrap();
    let points = read_tracks(&path, TrackFormat::from_path(&path).unwrap()).unwrap();
    assert_eq!(points.len(), 3);
    assert_eq!((points[0].frame, points[0].track_id), (1, 0));
    assert_eq!(points[0].pos_px, Point2::new(101.234, 55.5));
    assert_eq!(points[0].vel_px_per_frame, Some(Vec2::new(1.2, -0.3)));
    assert_eq!(points[0].log10_pred_err, Some(-1.523));
    assert_eq!(points[1].vel_px_per_frame, None);
    assert_eq!(points[1].acc_px_per_frame2, None);
    assert_eq!(points[1].vel_pred_px_per_frame, Some(Vec2::new(0.0, 0.0)));
    assert_eq!(points[2].frame, 2);
}

#[test]
fn tractrac_errors_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad_track.txt");
    std::fs::write(
        &path,
        "# header\n1 0 1 2 0 0 0 0 0 0 0\n2 0 nan 2 0 0 0 0 0 0 0\n",
    )
    .unwrap();
    let err = read_tracks(&path, TrackFormat::Tractrac)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad_track.txt:3:") && err.contains("not finite"),
        "{err}"
    );
    std::fs::write(&path, "1 0 1 2 0 0 0\n").unwrap();
    let err = read_tracks(&path, TrackFormat::Tractrac)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(":1:") && err.contains("7 columns instead of 11"),
        "{err}"
    );
}

#[test]
fn csv_errors_name_the_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    std::fs::write(&path, "frame,particle,x,y\n0,1,2.0,3.0\n1,1,NaN,3.0\n").unwrap();
    let err = read_tracks(&path, TrackFormat::Csv)
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&format!("{}:3:", path.display())), "{err}");
    assert!(err.contains("`x`"), "{err}");
    std::fs::write(&path, "frame,x,y\n0,2.0,3.0\n").unwrap();
    let err = read_tracks(&path, TrackFormat::Csv)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(":1:") && err.contains("missing column `particle`"),
        "{err}"
    );
    std::fs::write(&path, "frame,particle,x,y\n0,1,2.0\n").unwrap();
    let err = read_tracks(&path, TrackFormat::Csv)
        .unwrap_err()
        .to_string();
    assert!(err.contains(":2:") && err.contains("fields"), "{err}");
    std::fs::write(&path, "frame,particle,x,y\n-1,1,2.0,3\n").unwrap();
    let err = read_tracks(&path, TrackFormat::Csv)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(":2:") && err.contains("`frame` = `-1`"),
        "{err}"
    );
}

#[test]
fn trackpy_style_csv_without_kinematics_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trackpy.csv");
    std::fs::write(&path, "y,x,frame,particle\n3.5,2.25,4,9\n").unwrap();
    let points = read_tracks(&path, TrackFormat::Csv).unwrap();
    assert_eq!(points, vec![TrackPoint::at(4, 9, Point2::new(2.25, 3.5))]);
}

#[test]
fn csv_fields_and_names_padded_with_spaces_are_read_and_streamed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("padded.csv");
    std::fs::write(
        &path,
        " frame , particle,x ,y, vx\n# a comment\n 4 , 9,2.25 , 3.5,  \n5,9, 3 ,4 , 0.75\n",
    )
    .unwrap();
    let mut streamed = Vec::new();
    let layout = for_each_track_point(&path, TrackFormat::Csv, |p| {
        streamed.push(p);
        Ok(())
    })
    .unwrap();
    assert_eq!(layout, TrackLayout::Kinematics);
    let mut second = TrackPoint::at(5, 9, Point2::new(3.0, 4.0));
    second.vel_px_per_frame = None; // vy is absent: no velocity
    assert_eq!(
        streamed,
        vec![TrackPoint::at(4, 9, Point2::new(2.25, 3.5)), second]
    );
    // An error raised by the consumer stops the reading and comes back as it is.
    let mut seen = 0;
    let error = for_each_track_point(&path, TrackFormat::Csv, |_| {
        seen += 1;
        Err(sillage_core::Error::input("stop here"))
    })
    .unwrap_err();
    assert_eq!((seen, error.to_string().contains("stop here")), (1, true));
}

#[test]
fn unfinished_writer_leaves_complete_rows_in_the_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.csv");
    let mut writer = create_track_writer(&path, TrackFormat::Csv, &header()).unwrap();
    writer.accept(&sample_points(3)).unwrap();
    drop(writer);
    assert!(!path.exists());
    let partial = std::fs::read_to_string(dir.path().join(".run.csv.partial")).unwrap();
    assert_eq!(partial.lines().count(), 4);
    assert!(partial.ends_with('\n'));
}

#[test]
fn formats_from_paths_and_names() {
    let from = |p: &str| TrackFormat::from_path(Path::new(p)).unwrap();
    assert_eq!(from("a/seq_track.txt"), TrackFormat::Tractrac);
    assert_eq!(from("a.CSV"), TrackFormat::Csv);
    assert_eq!(from("a.parquet"), TrackFormat::Parquet);
    assert_eq!(from("a.h5"), TrackFormat::Hdf5);
    assert_eq!(from("a.hdf5"), TrackFormat::Hdf5);
    assert!(TrackFormat::from_path(Path::new("a.xlsx")).is_err());
    for format in TrackFormat::ALL {
        assert_eq!(format.to_string().parse::<TrackFormat>().unwrap(), format);
        let named = format!("x.{}", format.extension());
        assert_eq!(TrackFormat::from_path(Path::new(&named)).unwrap(), format);
    }
    let err = "xml".parse::<TrackFormat>().unwrap_err().to_string();
    assert!(err.contains("`format` = xml"), "{err}");
}

#[test]
fn non_finite_positions_are_refused_by_writers() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.csv");
    let mut writer = create_track_writer(&path, TrackFormat::Csv, &header()).unwrap();
    let bad = TrackPoint::at(0, 1, Point2::new(f64::NAN, 0.0));
    assert!(writer.accept(&[bad]).is_err());
}

/// Points with classes, motion states and spreads, as the bedload trackers emit them.
fn bead_points(n: u64) -> Vec<TrackPoint> {
    sample_points(n)
        .into_iter()
        .enumerate()
        .map(|(i, p)| TrackPoint {
            class: (i % 2) as u32,
            motion_state: MotionState::ALL[i % 4],
            spread_px: (i % 3 != 0).then_some(0.25 * i as f64),
            ..p
        })
        .collect()
}

fn state_header() -> TrackFileHeader {
    TrackFileHeader {
        layout: TrackLayout::WithStates,
        ..header()
    }
}

fn write_states(path: &Path, format: TrackFormat, points: &[TrackPoint]) {
    let mut writer = create_track_writer(path, format, &state_header()).unwrap();
    for chunk in points.chunks(7) {
        writer.accept(chunk).unwrap();
    }
    assert_eq!(writer.finish().unwrap().rows, points.len() as u64);
}

#[test]
fn csv_with_states_round_trips_exactly_and_names_the_states() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("beads.csv");
    let points = bead_points(40);
    write_states(&path, TrackFormat::Csv, &points);
    let table = read_track_table(&path, TrackFormat::Csv).unwrap();
    assert_eq!(table.layout, TrackLayout::WithStates);
    assert_eq!(table.points, points);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err,class,motion_state,spread_px"
    );
    // Row 1 (i = 1): transparent, rolling, spread 0.25.
    assert!(lines.nth(1).unwrap().ends_with(",1,rolling,0.25"), "{text}");
    // A table without the state columns reads as the kinematic layout, states unknown.
    let plain = dir.path().join("plain.csv");
    write(&plain, TrackFormat::Csv, &points);
    let table = read_track_table(&plain, TrackFormat::Csv).unwrap();
    assert_eq!(table.layout, TrackLayout::Kinematics);
    assert!(
        table.points.iter().all(|p| p.class == 0
            && p.motion_state == MotionState::Unknown
            && p.spread_px.is_none())
    );
}

#[cfg(feature = "parquet")]
#[test]
fn parquet_with_states_round_trips_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("beads.parquet");
    let points = bead_points(70_000);
    write_states(&path, TrackFormat::Parquet, &points);
    let table = read_track_table(&path, TrackFormat::Parquet).unwrap();
    assert_eq!(table.layout, TrackLayout::WithStates);
    assert_eq!(table.points, points);
}

#[cfg(feature = "hdf5")]
#[test]
fn hdf5_with_states_round_trips_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("beads.h5");
    let points = bead_points(70_000);
    write_states(&path, TrackFormat::Hdf5, &points);
    let table = read_track_table(&path, TrackFormat::Hdf5).unwrap();
    assert_eq!(table.layout, TrackLayout::WithStates);
    assert_eq!(table.points, points);
}

#[test]
fn tractrac_refuses_the_state_layout() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("beads_track.txt");
    let Err(error) = create_track_writer(&path, TrackFormat::Tractrac, &state_header()) else {
        panic!("TracTrac's layout took classes and motion states");
    };
    let error = error.to_string();
    assert!(
        error.contains("motion states") && error.contains("csv, parquet or hdf5"),
        "{error}"
    );
    assert!(!path.exists());
}

#[test]
fn csv_state_errors_name_the_line_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.csv");
    std::fs::write(
        &path,
        "frame,particle,x,y,class,motion_state\n0,1,2.5,3.5,1,resting\n1,1,2.5,3.5,0,hopping\n",
    )
    .unwrap();
    let error = read_tracks(&path, TrackFormat::Csv)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("bad.csv:3:") && error.contains("hopping"),
        "{error}"
    );
    assert!(
        error.contains("resting, rolling, saltating or unknown"),
        "{error}"
    );
    std::fs::write(
        &path,
        "frame,particle,x,y,class,motion_state\n0,1,2.5,3.5,4294967296,resting\n",
    )
    .unwrap();
    let error = read_tracks(&path, TrackFormat::Csv)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("bad.csv:2:") && error.contains("class 4294967296"),
        "{error}"
    );
}

/// The three damaged files on which the `parquet_tracks` fuzz target found `parquet` 60.1.0
/// panicking (a negative column-chunk start in the footer, definition levels shorter than a
/// page's values, a dictionary-encoded page without its dictionary): each is now an error
/// naming the file.
#[cfg(feature = "parquet")]
#[test]
fn damaged_parquet_files_found_by_fuzzing_are_errors_not_panics() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    for name in [
        "parquet_negative_column_start.parquet",
        "parquet_short_definition_levels.parquet",
        "parquet_dictionary_missing.parquet",
    ] {
        let path = data.join(name);
        let err = read_tracks(&path, TrackFormat::Parquet)
            .expect_err(name)
            .to_string();
        assert!(err.contains(name) && err.contains("Parquet"), "{err}");
    }
}
