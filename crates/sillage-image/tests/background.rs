//! The background model against TracTrac's update formula, written out literally.

mod common;

use common::random_image;
use sillage_core::GrayImage;
use sillage_image::BackgroundModel;

#[test]
fn initial_background_is_the_mean_of_the_first_frames() {
    let frames: Vec<GrayImage> = (0..5).map(|s| random_image(9, 7, s)).collect();
    let mut model = BackgroundModel::new(0.01).unwrap();
    for f in &frames {
        model.accumulate(f).unwrap();
    }
    assert_eq!(model.frames_averaged(), 5);
    for (i, &b) in model.background().as_slice().iter().enumerate() {
        let mean = frames.iter().map(|f| f.as_slice()[i]).sum::<f32>() / 5.0;
        assert!((b - mean).abs() < 1e-6);
    }
}

#[test]
fn update_matches_the_slew_limited_formula() {
    let beta = 0.05f32;
    let mut model = BackgroundModel::new(beta).unwrap();
    let first = random_image(33, 17, 1);
    model.accumulate(&first).unwrap();
    let mut expected = first.as_slice().to_vec();
    for seed in 2..6 {
        let frame = random_image(33, 17, seed);
        model.update(&frame).unwrap();
        for (b, &i) in expected.iter_mut().zip(frame.as_slice()) {
            // TracTrac: r2 = B − I; r = −β if r2 > β, +β if r2 < −β, −r2 otherwise.
            let r2 = *b - i;
            let r = if r2 > beta {
                -beta
            } else if r2 < -beta {
                beta
            } else {
                -r2
            };
            *b = (*b + r).clamp(0.0, 1.0);
        }
        assert_eq!(model.background().as_slice(), expected.as_slice());
    }
}

#[test]
fn foreground_is_masked_frame_minus_background() {
    let mut model = BackgroundModel::new(0.01).unwrap();
    let bg = random_image(6, 4, 10);
    model.accumulate(&bg).unwrap();
    let frame = random_image(6, 4, 11);
    let mask = random_image(6, 4, 12);
    let mut out = GrayImage::default();
    model.foreground(&frame, Some(&mask), &mut out).unwrap();
    for i in 0..24 {
        let want = frame.as_slice()[i] * mask.as_slice()[i] - bg.as_slice()[i];
        assert_eq!(out.as_slice()[i], want);
    }
    assert!(
        model
            .foreground(&GrayImage::new(2, 2), None, &mut out)
            .is_err()
    );
    assert!(model.update(&GrayImage::new(2, 2)).is_err());
    let e = BackgroundModel::new(0.0).unwrap_err().to_string();
    assert!(e.contains("speed"), "{e}");
    assert!(
        BackgroundModel::new(0.01)
            .unwrap()
            .foreground(&frame, None, &mut out)
            .is_err()
    );
}
