//! The blob detector on rendered scenes with known truth.

mod common;

use common::{Rng, Spot, render};
use sillage_core::{Detection, Detector, GrayImage, Point2};
use sillage_detect::{
    BackgroundParams, BlobDetector, BlobFilter, BlobParams, MedianSize, Polarity, PreprocessParams,
    Preprocessor, Roi, SubpixelFit, Threshold,
};

/// Well-separated spots on a 16 px grid with seeded sub-pixel offsets.
fn grid(width: usize, height: usize, amplitude: f64, rng: &mut Rng) -> Vec<Spot> {
    let mut spots = Vec::new();
    for gy in 1..height / 16 {
        for gx in 1..width / 16 {
            spots.push(Spot {
                x: (gx * 16) as f64 + rng.uniform() - 0.5,
                y: (gy * 16) as f64 + rng.uniform() - 0.5,
                amplitude,
            });
        }
    }
    spots
}

/// Matches every spot to its nearest detection; returns (matched count, mean error px).
fn score(spots: &[Spot], detections: &[Detection]) -> (usize, f64) {
    let mut matched = 0;
    let mut total = 0.0;
    for s in spots {
        let truth = Point2::new(s.x, s.y);
        let nearest = detections
            .iter()
            .map(|d| d.pos_px.distance(truth))
            .fold(f64::INFINITY, f64::min);
        if nearest < 1.0 {
            matched += 1;
            total += nearest;
        }
    }
    (matched, total / matched.max(1) as f64)
}

fn detect(params: BlobParams, image: &GrayImage) -> Vec<Detection> {
    let mut detector = BlobDetector::new(params).unwrap();
    let mut out = Vec::new();
    detector.detect(image, &mut out).unwrap();
    out
}

#[test]
fn finds_separated_spots_with_subpixel_accuracy() {
    let mut rng = Rng(1);
    let spots = grid(256, 192, 0.6, &mut rng);
    let image = render(256, 192, 0.1, &spots, 1.2, 0.0, &mut rng);
    for (filter, max_err) in [
        (BlobFilter::Dog, 0.05),
        (BlobFilter::Log, 0.05),
        (BlobFilter::None, 0.05),
    ] {
        let params = BlobParams {
            filter,
            ..BlobParams::default()
        };
        let found = detect(params, &image);
        let (matched, err) = score(&spots, &found);
        assert_eq!(matched, spots.len(), "{filter:?}");
        assert_eq!(found.len(), spots.len(), "{filter:?}: spurious detections");
        assert!(err < max_err, "{filter:?}: mean error {err} px");
    }
}

#[test]
fn noisy_scene_keeps_most_spots() {
    let mut rng = Rng(2);
    let spots = grid(256, 256, 0.5, &mut rng);
    let image = render(256, 256, 0.1, &spots, 1.2, 0.02, &mut rng);
    let found = detect(BlobParams::default(), &image);
    let (matched, err) = score(&spots, &found);
    assert!(
        matched * 100 >= spots.len() * 98,
        "{matched}/{}",
        spots.len()
    );
    assert!(err < 0.15, "mean error {err} px");
}

#[test]
fn roi_keeps_full_frame_coordinates() {
    let mut rng = Rng(3);
    let spots = grid(256, 192, 0.6, &mut rng);
    let image = render(256, 192, 0.1, &spots, 1.2, 0.0, &mut rng);
    let roi = Roi {
        x0: 40,
        y0: 50,
        x1: 200,
        y1: 150,
    };
    let found = detect(
        BlobParams {
            roi: Some(roi),
            ..BlobParams::default()
        },
        &image,
    );
    let inside: Vec<Spot> = spots
        .iter()
        .copied()
        .filter(|s| s.x > 44.0 && s.x < 196.0 && s.y > 54.0 && s.y < 146.0)
        .collect();
    assert!(!inside.is_empty());
    let (matched, err) = score(&inside, &found);
    assert_eq!(matched, inside.len());
    assert!(err < 0.05, "mean error {err} px");
    for d in &found {
        assert!(
            d.pos_px.x >= 40.0 && d.pos_px.x < 200.0 && d.pos_px.y >= 50.0 && d.pos_px.y < 150.0
        );
    }
    // A ROI larger than the frame is an error naming the key.
    let mut detector = BlobDetector::new(BlobParams {
        roi: Some(Roi {
            x0: 0,
            y0: 0,
            x1: 300,
            y1: 10,
        }),
        ..BlobParams::default()
    })
    .unwrap();
    let e = detector
        .detect(&image, &mut Vec::new())
        .unwrap_err()
        .to_string();
    assert!(e.contains("roi"), "{e}");
}

#[test]
fn dark_polarity_finds_dark_spots() {
    let mut rng = Rng(4);
    let spots = grid(192, 192, -0.5, &mut rng);
    let image = render(192, 192, 0.8, &spots, 1.2, 0.0, &mut rng);
    let dark = BlobParams {
        polarity: Polarity::Dark.into(),
        ..BlobParams::default()
    };
    let (matched, err) = score(&spots, &detect(dark, &image));
    assert_eq!(matched, spots.len());
    assert!(err < 0.05, "mean error {err} px");
    // The default measures the polarity and finds them too.
    let (matched_auto, _) = score(&spots, &detect(BlobParams::default(), &image));
    assert_eq!(matched_auto, spots.len());
    // Looking for bright blobs instead finds none of them.
    let bright = BlobParams {
        polarity: Polarity::Bright.into(),
        ..BlobParams::default()
    };
    let (matched_bright, _) = score(&spots, &detect(bright, &image));
    assert_eq!(matched_bright, 0);
}

#[test]
fn detection_is_deterministic_and_reuses_buffers() {
    let mut rng = Rng(5);
    let spots = grid(128, 128, 0.5, &mut rng);
    let image = render(128, 128, 0.1, &spots, 1.2, 0.03, &mut rng);
    let mut detector = BlobDetector::new(BlobParams::default()).unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    detector.detect(&image, &mut a).unwrap();
    detector.detect(&image, &mut b).unwrap();
    assert_eq!(a, b);
    assert!(detector.last_threshold().is_some());
    let quad = BlobParams {
        subpixel: SubpixelFit::Quadratic,
        threshold: Threshold::Fixed(0.02),
        ..BlobParams::default()
    };
    assert!(!detect(quad, &image).is_empty());
}

#[test]
fn validate_rejects_bad_values_naming_the_key() {
    let cases = [
        (
            BlobParams {
                scale_px: sillage_detect::Scale::Px(0.0),
                ..BlobParams::default()
            },
            "scale_px",
        ),
        (
            BlobParams {
                scale_px: sillage_detect::Scale::Px(51.0),
                ..BlobParams::default()
            },
            "scale_px",
        ),
        (
            BlobParams {
                neighbourhood: 0,
                ..BlobParams::default()
            },
            "neighbourhood",
        ),
        (
            BlobParams {
                neighbourhood: 11,
                ..BlobParams::default()
            },
            "neighbourhood",
        ),
        (
            BlobParams {
                threshold: Threshold::Auto { std_factor: -1.0 },
                ..BlobParams::default()
            },
            "std_factor",
        ),
        (
            BlobParams {
                threshold: Threshold::Fixed(f64::NAN),
                ..BlobParams::default()
            },
            "threshold",
        ),
        (
            BlobParams {
                roi: Some(Roi {
                    x0: 5,
                    y0: 0,
                    x1: 5,
                    y1: 9,
                }),
                ..BlobParams::default()
            },
            "roi",
        ),
    ];
    for (params, key) in cases {
        let e = BlobDetector::new(params).unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
    }
    let bad_bg = PreprocessParams {
        background: Some(BackgroundParams {
            speed: 2.0,
            init_frames: 10,
        }),
        ..PreprocessParams::default()
    };
    assert!(
        Preprocessor::new(bad_bg)
            .unwrap_err()
            .to_string()
            .contains("background.speed")
    );
}

#[test]
fn params_round_trip_through_toml_and_reject_unknown_keys() {
    let text = "filter = \"log\"\nscale_px = 2.5\nneighbourhood = 2\npolarity = \"dark\"\n\
                subpixel = \"quadratic\"\nthreshold = { fixed = 0.03 }\n\
                roi = { x0 = 1, y0 = 2, x1 = 30, y1 = 40 }\n";
    let params: BlobParams = toml::from_str(text).unwrap();
    assert_eq!(params.filter, BlobFilter::Log);
    assert_eq!(params.threshold, Threshold::Fixed(0.03));
    let back: BlobParams = toml::from_str(&toml::to_string(&params).unwrap()).unwrap();
    assert_eq!(back, params);
    assert_eq!(
        toml::from_str::<BlobParams>("").unwrap(),
        BlobParams::default()
    );
    assert!(toml::from_str::<BlobParams>("peak_th = 1").is_err());
    let pre: PreprocessParams = toml::from_str("median = 5\n[background]\nspeed = 0.02\n").unwrap();
    assert_eq!(pre.median, Some(MedianSize::Five));
    assert_eq!(pre.background.unwrap().init_frames, 100);
    assert!(toml::from_str::<PreprocessParams>("median = 4").is_err());
}

#[test]
fn background_subtraction_removes_a_static_scene() {
    let mut rng = Rng(6);
    let width = 96;
    // A static bright spot (part of the background) and a moving one.
    let static_spot = Spot {
        x: 20.0,
        y: 20.0,
        amplitude: 0.5,
    };
    let frames: Vec<GrayImage> = (0..6)
        .map(|t| {
            let moving = Spot {
                x: 40.0 + 5.0 * t as f64,
                y: 60.3,
                amplitude: 0.5,
            };
            render(
                width,
                width,
                0.1,
                &[static_spot, moving],
                1.2,
                0.0,
                &mut rng,
            )
        })
        .collect();
    let params = PreprocessParams {
        median: Some(MedianSize::Three),
        background: Some(BackgroundParams {
            speed: 0.01,
            init_frames: 6,
        }),
    };
    let mut pre = Preprocessor::new(params).unwrap();
    assert_eq!(pre.prime(&frames).unwrap(), 6);
    let mut detector = BlobDetector::new(BlobParams {
        threshold: Threshold::Fixed(0.02),
        ..BlobParams::default()
    })
    .unwrap();
    let (mut image, mut found) = (GrayImage::default(), Vec::new());
    pre.process(&frames[5], None, &mut image).unwrap();
    detector.detect(&image, &mut found).unwrap();
    assert!(
        found
            .iter()
            .all(|d| d.pos_px.distance(Point2::new(20.0, 20.0)) > 3.0),
        "{found:?}"
    );
    assert!(
        found
            .iter()
            .any(|d| d.pos_px.distance(Point2::new(65.0, 60.3)) < 0.2),
        "{found:?}"
    );
    // Without priming, the first frame's foreground is I − I = 0.
    let mut fresh = Preprocessor::new(params).unwrap();
    fresh.process(&frames[0], None, &mut image).unwrap();
    assert!(image.as_slice().iter().all(|&v| v.abs() < 1e-6));
    assert!(fresh.background().is_some());
}

/// σ 2 px spots 24 px apart, every other one with a second spot 5 px away (within the
/// re-fit's 3σ); the single ones let the splitter measure the noise.
fn crowded_pairs(rng: &mut Rng) -> Vec<Spot> {
    let mut spots = Vec::new();
    for gy in 1..12 {
        for gx in 1..12 {
            let (x, y) = (
                (gx * 24) as f64 + rng.uniform(),
                (gy * 24) as f64 + rng.uniform(),
            );
            spots.push(Spot {
                x,
                y,
                amplitude: 0.8,
            });
            if (gx + gy) % 2 == 0 {
                spots.push(Spot {
                    x: x + 5.0,
                    y: y + 0.5,
                    amplitude: 0.6,
                });
            }
        }
    }
    spots
}

#[test]
fn crowded_re_fits_belong_to_the_splitter_and_change_nothing_without_it() {
    let mut rng = Rng(11);
    let spots = crowded_pairs(&mut rng);
    let image = render(300, 300, 0.1, &spots, 2.0, 0.02, &mut rng);
    let with = |deblend, refit_crowded| {
        detect(
            BlobParams {
                deblend,
                refit_crowded,
                ..BlobParams::default()
            },
            &image,
        )
    };
    // Without the splitter the key is accepted and has no effect (so that turning the
    // splitter off alone is enough).
    assert_eq!(with(false, true), with(false, false));
    // With it, the crowded detections move.
    let (refitted, plain) = (with(true, true), with(true, false));
    assert!(refitted != plain, "the re-fit moved nothing");
}
