//! One behavioural suite run against every implementation of the `Detector` role: the
//! DoG/LoG blob detector of PTV, the MMPF+ bead detector and the motion-blob detector of the
//! pedestrian trackers.
//!
//! Every detector must: give the same detections run twice from scratch and on 1 or 4
//! threads; find nothing in blank frames (or refuse them, saying there are no particles to
//! measure, when measuring its scale from the frame); keep its detections inside the frame, with finite
//! coordinates and one box per detection when it gives boxes; and take frames too small for
//! its filters, or a change of frame size, without panicking.

use sillage::core::{Detection, Detector, GrayImage};
use sillage::detect::bead::{BeadDetector, BeadParams};
use sillage::detect::blob::{BlobDetector, BlobParams, PolarityChoice, Scale};
use sillage::detect::motion::{MotionDetector, MotionParams};

const W: usize = 160;
const H: usize = 120;

/// A detector under test, made fresh for each check.
type Maker = Box<dyn Fn() -> Box<dyn Detector> + Sync>;

fn detectors() -> Vec<(&'static str, Maker)> {
    vec![
        (
            "blob",
            Box::new(|| Box::new(BlobDetector::new(BlobParams::default()).unwrap())),
        ),
        (
            "blob with a given scale and polarity",
            Box::new(|| {
                let params = BlobParams {
                    scale_px: Scale::Px(2.0),
                    polarity: PolarityChoice::Bright,
                    ..BlobParams::default()
                };
                Box::new(BlobDetector::new(params).unwrap())
            }),
        ),
        (
            "bead",
            Box::new(|| Box::new(BeadDetector::new(BeadParams::default()).unwrap())),
        ),
        (
            "motion",
            Box::new(|| Box::new(MotionDetector::new(&MotionParams::default(), W, H).unwrap())),
        ),
    ]
}

/// Frames with bright and dark discs moving over a grey, slightly textured background.
fn scene(frames: usize) -> Vec<GrayImage> {
    (0..frames)
        .map(|t| {
            let mut image = GrayImage::new(W, H);
            let discs = [
                (30.0 + 3.0 * t as f64, 40.0, 5.0, 0.95),
                (110.0 - 2.0 * t as f64, 80.0, 8.0, 0.05),
                (80.0, 30.0 + 2.0 * t as f64, 12.0, 0.9),
            ];
            for y in 0..H {
                for x in 0..W {
                    let mut v = 0.5 + 0.02 * (((x * 7 + y * 13) % 5) as f32 - 2.0);
                    for &(cx, cy, r, level) in &discs {
                        let d2 = (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2);
                        if d2 <= r * r {
                            v = level;
                        }
                    }
                    image.as_mut_slice()[y * W + x] = v;
                }
            }
            image
        })
        .collect()
}

/// Every frame's detections and boxes, from a fresh detector.
fn run(make: &Maker, frames: &[GrayImage]) -> Vec<(Vec<Detection>, usize)> {
    let mut detector = make();
    frames
        .iter()
        .map(|frame| {
            let mut out = Vec::new();
            detector.detect(frame, &mut out).unwrap();
            (out, detector.boxes().len())
        })
        .collect()
}

#[test]
fn every_detector_repeats_itself_on_any_thread_count() {
    let frames = scene(12);
    for (name, make) in detectors() {
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| run(&make, &frames))
        };
        let one = on(1);
        assert_eq!(one, on(4), "{name}: thread count changed the detections");
        assert_eq!(one, on(1), "{name}: not repeatable");
        assert!(
            one.iter().any(|(found, _)| !found.is_empty()),
            "{name}: found nothing in the scene"
        );
    }
}

#[test]
fn every_detector_keeps_detections_in_the_frame_with_a_box_each_or_none() {
    let frames = scene(12);
    for (name, make) in detectors() {
        for (t, (found, boxes)) in run(&make, &frames).iter().enumerate() {
            assert!(
                *boxes == 0 || *boxes == found.len(),
                "{name}, frame {t}: boxes"
            );
            for d in found {
                let (x, y) = (d.pos_px.x, d.pos_px.y);
                assert!(
                    (-0.5..W as f64).contains(&x) && (-0.5..H as f64).contains(&y),
                    "{name}, frame {t}: detection at ({x}, {y}) outside the frame"
                );
                assert!(d.strength.is_finite(), "{name}: strength {}", d.strength);
            }
        }
    }
}

#[test]
fn every_detector_finds_nothing_in_blank_frames() {
    let blank: Vec<GrayImage> = (0..6)
        .map(|_| {
            let mut image = GrayImage::new(W, H);
            image.as_mut_slice().fill(0.5);
            image
        })
        .collect();
    for (name, make) in detectors() {
        let mut detector = make();
        for (t, frame) in blank.iter().enumerate() {
            let mut found = Vec::new();
            match detector.detect(frame, &mut found) {
                Ok(()) => assert!(
                    found.is_empty(),
                    "{name}: {} detections in blank frame {t}",
                    found.len()
                ),
                Err(e) => assert!(
                    e.to_string().contains("no particles found"),
                    "{name}, blank frame {t}: {e}"
                ),
            }
        }
    }
}

#[test]
fn every_detector_takes_tiny_frames_and_size_changes_without_panicking() {
    for (name, make) in detectors() {
        for (w, h) in [(1, 1), (3, 2), (W, H), (W / 2, H)] {
            let mut detector = make();
            let mut image = GrayImage::new(w, h);
            image.as_mut_slice().fill(0.25);
            let mut out = Vec::new();
            // Refusing a frame is allowed (with an error); panicking is not.
            if detector.detect(&image, &mut out).is_ok() {
                assert!(
                    out.len() <= w * h,
                    "{name}: {w}x{h} gave {} detections",
                    out.len()
                );
            }
        }
        let mut detector = make();
        let mut out = Vec::new();
        let _ = detector.detect(&GrayImage::new(W, H), &mut out);
        let _ = detector.detect(&GrayImage::new(W / 2, H / 3), &mut out);
    }
}
