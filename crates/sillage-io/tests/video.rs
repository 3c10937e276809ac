//! Videos through the `ffmpeg` program. The decoding test skips (with a note) when ffmpeg
//! is not installed; CI installs it.

use std::path::Path;
use std::process::Command;

use sillage_core::Error;
use sillage_io::{FrameOptions, open_frames};

fn ffmpeg_available() -> bool {
    let works = |program: &str| {
        Command::new(program)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    works("ffmpeg") && works("ffprobe")
}

fn make_video(path: &Path) {
    let status = Command::new("ffmpeg")
        .args([
            "-v",
            "error",
            "-y",
            "-f",
            "lavfi",
            "-i",
            "testsrc=size=64x48:rate=10",
        ])
        .args(["-frames:v", "5", "-pix_fmt", "gray", "-c:v", "ffv1"])
        .arg(path)
        .status()
        .unwrap();
    assert!(status.success());
}

#[test]
fn lossless_video_gives_its_frames() {
    if !ffmpeg_available() {
        eprintln!("note: ffmpeg/ffprobe not installed; skipping the video decoding test");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for name in ["test.avi", "test.mkv"] {
        let path = dir.path().join(name);
        make_video(&path);
        let source = open_frames(path.to_str().unwrap(), &FrameOptions::default()).unwrap();
        assert_eq!(source.dimensions(), (64, 48));
        if name.ends_with(".avi") {
            assert_eq!(source.len(), Some(5));
        }
        let frames: Vec<_> = source.map(Result::unwrap).collect();
        assert_eq!(frames.len(), 5, "{name}");
        for (i, frame) in frames.iter().enumerate() {
            assert_eq!(frame.index, i as u64);
            assert_eq!(frame.image.dimensions(), (64, 48));
            // 8-bit grey widened to 16 bits: every value is a multiple of 257/65535 = 1/255.
            let v = frame.image.get(10, 10) * 255.0;
            assert!((v - v.round()).abs() < 1e-3, "{v}");
        }
        let spread = frames[0]
            .image
            .as_slice()
            .iter()
            .fold((1.0f32, 0.0f32), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        assert!(
            spread.1 - spread.0 > 0.3,
            "test pattern should not be flat: {spread:?}"
        );
    }
}

#[test]
fn dropping_a_video_source_early_stops_ffmpeg() {
    if !ffmpeg_available() {
        eprintln!("note: ffmpeg/ffprobe not installed; skipping");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("test.avi");
    make_video(&path);
    let options = FrameOptions {
        read_ahead: 1,
        ..FrameOptions::default()
    };
    let mut source = open_frames(path.to_str().unwrap(), &options).unwrap();
    assert!(source.next().unwrap().is_ok());
    drop(source);
}

#[test]
fn missing_ffprobe_says_how_to_install_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("clip.mp4");
    std::fs::write(&path, b"not decoded").unwrap();
    let options = FrameOptions {
        ffprobe: dir.path().join("no-such-ffprobe"),
        ..FrameOptions::default()
    };
    match open_frames(path.to_str().unwrap(), &options).unwrap_err() {
        Error::MissingProgram { hint, .. } => {
            assert!(hint.contains("apt-get install ffmpeg"), "{hint}");
            assert!(hint.contains("brew install ffmpeg"), "{hint}");
            assert!(hint.contains("image sequence"), "{hint}");
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn colour_video_gives_rgb_frames_and_their_rec601_grey() {
    if !ffmpeg_available() {
        eprintln!("note: ffmpeg/ffprobe not installed; skipping the colour video test");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.mkv");
    // Lossless RGB (ffv1 in bgr0), so the frames come back exactly as generated.
    let status = Command::new("ffmpeg")
        .args(["-v", "error", "-y", "-f", "lavfi", "-i"])
        .arg("testsrc=size=64x48:rate=10")
        .args(["-frames:v", "3", "-pix_fmt", "bgr0", "-c:v", "ffv1"])
        .arg(&path)
        .status()
        .unwrap();
    assert!(status.success());
    let options = FrameOptions {
        colour: true,
        ..FrameOptions::default()
    };
    let frames: Vec<_> = open_frames(path.to_str().unwrap(), &options)
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(frames.len(), 3);
    let rgb = frames[0].colour.as_ref().expect("colour was requested");
    assert_eq!(rgb.dimensions(), (64, 48));
    // testsrc draws saturated colour bars: some pixel has distinct channels.
    assert!(rgb.as_slice().iter().any(|p| p[0] != p[1] || p[1] != p[2]));
    for (&p, &grey) in rgb.as_slice().iter().zip(frames[0].image.as_slice()) {
        let [r, g, b] = p.map(|v| f32::from(v) / 255.0);
        assert!((grey - (0.299 * r + 0.587 * g + 0.114 * b)).abs() < 1e-6);
    }
    let grey_only = open_frames(path.to_str().unwrap(), &FrameOptions::default())
        .unwrap()
        .next()
        .unwrap()
        .unwrap();
    assert!(grey_only.colour.is_none());
}
