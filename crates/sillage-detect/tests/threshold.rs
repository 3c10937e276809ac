//! Detection recall and precision of the thresholds on rendered vortex-like scenes: Gaussian
//! spots σ = 2 px of peak 0.5 on uniform noise U(0, 0.5/SNR), as in the TracTrac paper §4.1.2.

use sillage_core::{Detection, Detector, GrayImage, Point2};
use sillage_detect::{BlobDetector, BlobParams, Threshold};
use sillage_synth::{Noise, NoiseKind, render_spots};

/// Seeded SplitMix64 in [0, 1).
fn uniform(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// `count` spots at uniform random positions (3 px from the border), at least `min_gap` px
/// apart (rejection sampling; 0 for none), and the rendered frame.
fn scene(side: usize, count: usize, min_gap: f64, snr: f64, seed: u64) -> (Vec<Point2>, GrayImage) {
    let mut state = seed;
    let span = side as f64 - 6.0;
    let mut centres: Vec<Point2> = Vec::with_capacity(count);
    while centres.len() < count {
        let c = Point2::new(
            3.0 + span * uniform(&mut state),
            3.0 + span * uniform(&mut state),
        );
        if min_gap == 0.0 || centres.iter().all(|&o| o.distance(c) >= min_gap) {
            centres.push(c);
        }
    }
    let spots: Vec<(Point2, f64, f64)> = centres.iter().map(|&c| (c, 0.5, 2.0)).collect();
    let noise = Noise::new(NoiseKind::Uniform, 0.5 / snr);
    (
        centres,
        render_spots(side, side, &spots, noise, seed).unwrap(),
    )
}

/// Recall (true centres with a detection within 1 px) and precision (detections within 1 px
/// of a true centre), with a 4 px bucket grid for the look-ups.
fn recall_precision(side: usize, truth: &[Point2], found: &[Detection]) -> (f64, f64) {
    let cells = side.div_ceil(4);
    let cell = |p: Point2| {
        ((p.x / 4.0) as usize).min(cells - 1) + cells * ((p.y / 4.0) as usize).min(cells - 1)
    };
    let near = |points: &[Point2], queries: &[Point2]| {
        let mut grid = vec![Vec::new(); cells * cells];
        for (i, &p) in points.iter().enumerate() {
            grid[cell(p)].push(i);
        }
        queries
            .iter()
            .filter(|&&q| {
                let (cx, cy) = ((q.x / 4.0) as isize, (q.y / 4.0) as isize);
                (cy - 1..=cy + 1).any(|y| {
                    (cx - 1..=cx + 1).any(|x| {
                        (0..cells as isize).contains(&x)
                            && (0..cells as isize).contains(&y)
                            && grid[x as usize + cells * y as usize]
                                .iter()
                                .any(|&i| points[i].distance(q) < 1.0)
                    })
                })
            })
            .count()
    };
    let detections: Vec<Point2> = found.iter().map(|d| d.pos_px).collect();
    let recall = near(&detections, truth) as f64 / truth.len() as f64;
    let precision = near(truth, &detections) as f64 / detections.len().max(1) as f64;
    (recall, precision)
}

fn measure(
    threshold: Threshold,
    side: usize,
    truth: &[Point2],
    frame: &GrayImage,
) -> (f64, f64, usize) {
    let mut detector = BlobDetector::new(BlobParams {
        threshold,
        ..BlobParams::default()
    })
    .unwrap();
    let mut found = Vec::new();
    detector.detect(frame, &mut found).unwrap();
    let (r, p) = recall_precision(side, truth, &found);
    (r, p, found.len())
}

/// The paper's vortex density and contrast (1000 spots σ = 2 px on 1024², SNR 4), spots at
/// least 8 px apart so that every one is resolvable: the default robust threshold finds them
/// all and almost nothing else, while the paper's `mean + 0.5·std` keeps thousands of noise
/// maxima, because the mean and std of a sparse filtered frame are those of its noise.
#[test]
fn default_threshold_is_accurate_where_the_paper_rule_is_not() {
    let side = 1024;
    let (truth, frame) = scene(side, 1000, 8.0, 4.0, 7);
    assert_eq!(BlobParams::default().threshold, Threshold::Noise { k: 4.0 });
    let (recall, precision, _) = measure(Threshold::default(), side, &truth, &frame);
    assert!(
        recall >= 0.98 && precision >= 0.98,
        "default: recall {recall}, precision {precision}"
    );
    let (paper_recall, paper_precision, found) =
        measure(Threshold::Auto { std_factor: 0.5 }, side, &truth, &frame);
    assert!(paper_recall >= 0.98, "{paper_recall}");
    assert!(
        paper_precision < 0.5,
        "Auto 0.5: precision {paper_precision} ({found} detections)"
    );
}

/// Prints the recall / precision table of the thresholds (quoted in the documentation of
/// `Threshold::Noise`) on random scenes, overlaps included. Slow in debug builds: run with
/// `cargo test --release -p sillage-detect --test threshold -- --ignored --nocapture`.
#[test]
#[ignore]
fn sweep() {
    for (side, count) in [(1024, 1000), (1024, 25_000), (2048, 1000), (2048, 25_000)] {
        for snr in [2.0, 4.0, 10.0] {
            let (truth, frame) = scene(side, count, 0.0, snr, 42);
            let mut line = format!("{side} {count:6} snr {snr:4}:");
            for th in [
                Threshold::Auto { std_factor: 0.5 },
                Threshold::Auto { std_factor: 2.0 },
                Threshold::Noise { k: 3.0 },
                Threshold::Noise { k: 4.0 },
                Threshold::Noise { k: 5.0 },
                Threshold::Noise { k: 6.0 },
            ] {
                let (r, p, n) = measure(th, side, &truth, &frame);
                line += &format!(" | {r:.3} {p:.3} ({n})");
            }
            println!("{line}");
        }
    }
}
