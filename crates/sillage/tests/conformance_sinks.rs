//! One behavioural suite run against every track writer (`TrackSink`): TracTrac text,
//! CSV, Parquet and, when built with the `hdf5` feature, HDF5, in each column layout the
//! format takes, and the bedload trackers' BeadTracking CSV.
//!
//! Every writer must: read back what it was given (exactly, or within TracTrac's decimals);
//! write the same bytes whatever the batches the points came in; give a readable empty table
//! for no point; show nothing under the final name before `finish`; and refuse a
//! non-finite position with an error instead of writing it.

use std::path::Path;

use sillage::core::{MotionState, Point2, TrackPoint, TrackSink, Vec2};
use sillage::io::{
    TrackFileHeader, TrackFormat, TrackLayout, TrackWriter, create_track_writer, read_tracks,
};

/// Every (format, layout) a writer can be made for in this build.
fn writers() -> Vec<(TrackFormat, TrackLayout)> {
    let dir = tempfile::tempdir().unwrap();
    let mut all = Vec::new();
    for format in TrackFormat::ALL {
        for layout in [TrackLayout::Kinematics, TrackLayout::WithStates] {
            let path = dir.path().join(format!("probe.{}", format.extension()));
            // Formats not built in (a cargo feature) and layouts a format cannot hold are
            // refused at creation; the suite covers every writer that can be made.
            if create_track_writer(&path, format, &header(layout)).is_ok() {
                all.push((format, layout));
            }
        }
    }
    assert!(all.len() >= 5, "only {all:?}");
    all
}

fn header(layout: TrackLayout) -> TrackFileHeader {
    TrackFileHeader {
        program_version: "3.0 (sillage conformance)".into(),
        parameters: vec![("tracker.motion_av".into(), "3".into())],
        layout,
    }
}

/// Points with every optional field set on some rows and left out on others.
fn points(layout: TrackLayout) -> Vec<TrackPoint> {
    (0..200u64)
        .map(|i| {
            let mut p = TrackPoint::at(
                i / 10,
                1 + i % 10,
                Point2::new(i as f64 * 3.25 + 0.1234, 500.0 - i as f64 / 3.0),
            );
            if i % 3 != 0 {
                p.vel_px_per_frame = Some(Vec2::new(0.5 + i as f64 * 1e-3, -0.25));
                p.acc_px_per_frame2 = Some(Vec2::new(0.01, -0.02));
                p.vel_pred_px_per_frame = Some(Vec2::new(0.49, -0.26));
                p.log10_pred_err = Some(-1.25);
            }
            if layout == TrackLayout::WithStates {
                p.class = (i % 2) as u32;
                p.motion_state = MotionState::ALL[i as usize % MotionState::ALL.len()];
                p.spread_px = (i % 4 != 0).then_some(0.75);
            }
            p
        })
        .collect()
}

fn write(path: &Path, format: TrackFormat, layout: TrackLayout, batches: &[&[TrackPoint]]) {
    let mut writer: Box<dyn TrackWriter> =
        create_track_writer(path, format, &header(layout)).unwrap();
    for batch in batches {
        writer.accept(batch).unwrap();
        assert!(
            !path.exists(),
            "{format:?}: final file visible before finish"
        );
    }
    writer.finish().unwrap();
}

/// TracTrac's text keeps a fixed number of decimals; the binary formats and CSV are exact.
fn tolerance(format: TrackFormat) -> f64 {
    match format {
        TrackFormat::Tractrac => 1e-3,
        _ => 0.0,
    }
}

fn assert_same(format: TrackFormat, written: &[TrackPoint], read: &[TrackPoint]) {
    let tol = tolerance(format);
    assert_eq!(written.len(), read.len(), "{format:?}: row count");
    let close = |a: f64, b: f64| (a - b).abs() <= tol;
    let close_v = |a: Option<Vec2>, b: Option<Vec2>| match (a, b) {
        (Some(a), Some(b)) => close(a.x, b.x) && close(a.y, b.y),
        (a, b) => a.is_none() && b.is_none(),
    };
    for (w, r) in written.iter().zip(read) {
        let same = w.frame == r.frame
            && w.track_id == r.track_id
            && close(w.pos_px.x, r.pos_px.x)
            && close(w.pos_px.y, r.pos_px.y)
            && close_v(w.vel_px_per_frame, r.vel_px_per_frame)
            && close_v(w.acc_px_per_frame2, r.acc_px_per_frame2)
            && close_v(w.vel_pred_px_per_frame, r.vel_pred_px_per_frame)
            && w.class == r.class
            && w.motion_state == r.motion_state
            && w.spread_px == r.spread_px;
        assert!(same, "{format:?}: wrote {w:?}, read {r:?}");
    }
}

#[test]
fn every_writer_reads_back_what_it_was_given() {
    let dir = tempfile::tempdir().unwrap();
    for (format, layout) in writers() {
        let path = dir
            .path()
            .join(format!("t_{layout:?}.{}", format.extension()));
        let given = points(layout);
        write(&path, format, layout, &[&given]);
        assert_same(format, &given, &read_tracks(&path, format).unwrap());
    }
}

#[test]
fn every_writer_writes_the_same_bytes_whatever_the_batches() {
    let dir = tempfile::tempdir().unwrap();
    for (format, layout) in writers() {
        let given = points(layout);
        let one = dir
            .path()
            .join(format!("one_{layout:?}.{}", format.extension()));
        let many = dir
            .path()
            .join(format!("many_{layout:?}.{}", format.extension()));
        write(&one, format, layout, &[&given]);
        let batches: Vec<&[TrackPoint]> = given.chunks(7).collect();
        write(&many, format, layout, &batches);
        if format == TrackFormat::Hdf5 {
            // HDF5 files record their own creation; compare what they hold.
            assert_eq!(
                read_tracks(&one, format).unwrap(),
                read_tracks(&many, format).unwrap()
            );
        } else {
            assert_eq!(
                std::fs::read(&one).unwrap(),
                std::fs::read(&many).unwrap(),
                "{format:?} {layout:?}: batches changed the file"
            );
        }
    }
}

#[test]
fn every_writer_gives_a_readable_empty_table_for_no_point() {
    let dir = tempfile::tempdir().unwrap();
    for (format, layout) in writers() {
        let path = dir
            .path()
            .join(format!("empty_{layout:?}.{}", format.extension()));
        write(&path, format, layout, &[]);
        assert!(read_tracks(&path, format).unwrap().is_empty(), "{format:?}");
    }
}

#[test]
fn every_writer_refuses_a_non_finite_position() {
    let dir = tempfile::tempdir().unwrap();
    for (format, layout) in writers() {
        let path = dir
            .path()
            .join(format!("nan_{layout:?}.{}", format.extension()));
        let mut writer = create_track_writer(&path, format, &header(layout)).unwrap();
        let bad = TrackPoint::at(0, 1, Point2::new(f64::NAN, 1.0));
        let refused = writer.accept(&[bad]).is_err() || writer.finish().is_err();
        assert!(refused, "{format:?}: wrote a NaN position");
    }
}

#[test]
fn the_bead_track_writer_reads_back_positions_classes_velocities_and_states() {
    use sillage::bedload::output::{BeadTrackKind, BeadTrackOutput};
    use sillage::track::bedload::BedloadTrackerParams;

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("beads.csv");
    let given = points(TrackLayout::WithStates);
    let params = BedloadTrackerParams::default();
    let mut writer = BeadTrackOutput::create(&path, Some(BeadTrackKind::Beads), &params).unwrap();
    for batch in given.chunks(9) {
        writer.accept(batch).unwrap();
        assert!(!path.exists(), "bead CSV visible before finish");
    }
    let kind = writer.kind();
    writer.finish().unwrap();
    let read = kind.read(&path).unwrap();
    assert_eq!(read.len(), given.len());
    // BeadTracking's 1-based pixels: positions come back within the rounding of the shift.
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9;
    for (w, r) in given.iter().zip(&read) {
        let same = w.frame == r.frame
            && w.track_id == r.track_id
            && close(w.pos_px.x, r.pos_px.x)
            && close(w.pos_px.y, r.pos_px.y)
            && w.vel_px_per_frame == r.vel_px_per_frame
            && w.class == r.class
            && w.motion_state == r.motion_state;
        assert!(same, "wrote {w:?}, read {r:?}");
    }
    let mut refused = BeadTrackOutput::create(&path, Some(BeadTrackKind::Beads), &params).unwrap();
    let bad = TrackPoint::at(0, 1, Point2::new(f64::NAN, 1.0));
    assert!(
        refused.accept(&[bad]).is_err(),
        "bead CSV took a NaN position"
    );
}
