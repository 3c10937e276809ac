//! HSV and difference binning against a naive `f64` reference, box histograms against a
//! per-pixel scan, and the Bhattacharyya coefficient.

use sillage_core::{Error, GrayImage, RgbImage};
use sillage_image::{
    BinImage, BoxPx, HsvBinning, bhattacharyya_coefficient, bhattacharyya_distance,
};

/// SplitMix64, for seeded test images.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Random colours; with `levels` set, channels take only that many evenly spaced values
/// (0, 255/(levels−1), …), which puts many pixels exactly on bin edges and thresholds.
fn random_rgb(width: usize, height: usize, seed: u64, levels: Option<u64>) -> RgbImage {
    let mut rng = Rng(seed);
    let pixels = (0..width * height)
        .map(|_| {
            [0; 3].map(|_: u8| match levels {
                Some(n) => (rng.below(n) * 255 / (n - 1)) as u8,
                None => rng.below(256) as u8,
            })
        })
        .collect();
    RgbImage::from_vec(width, height, pixels).unwrap()
}

/// `floor(x · n)` clamped to the last bin, `x · n` first rid of `f64` rounding noise (exact
/// values here are ratios of small integers, far more than 1e-9 from the next edge).
fn quantise(x: f64, n: usize) -> usize {
    let q = x * n as f64;
    let q = if (q - q.round()).abs() < 1e-9 {
        q.round()
    } else {
        q
    };
    (q.floor().max(0.0) as usize).min(n - 1)
}

/// The textbook HSV conversion in `f64` and Pérez et al.'s binning, pixel by pixel.
fn reference_hsv_bin(pixel: [u8; 3], binning: &HsvBinning) -> usize {
    let [r, g, b] = pixel.map(|v| f64::from(v) / 255.0);
    let max = r.max(g).max(b);
    let delta = max - r.min(g).min(b);
    let value = max;
    let saturation = if max > 0.0 { delta / max } else { 0.0 };
    let hue = if delta == 0.0 {
        0.0
    } else if max == r {
        ((g - b) / delta).rem_euclid(6.0) / 6.0
    } else if max == g {
        ((b - r) / delta + 2.0) / 6.0
    } else {
        ((r - g) / delta + 4.0) / 6.0
    };
    let (nh, ns, nv) = (
        binning.hue_bins,
        binning.saturation_bins,
        binning.value_bins,
    );
    if saturation >= binning.min_saturation - 1e-9 && value >= binning.min_value - 1e-9 {
        quantise(hue, nh) * ns + quantise(saturation, ns)
    } else {
        nh * ns + quantise(value, nv)
    }
}

fn binnings() -> Vec<HsvBinning> {
    vec![
        HsvBinning::default(),
        HsvBinning {
            hue_bins: 8,
            saturation_bins: 6,
            value_bins: 4,
            min_saturation: 0.25,
            min_value: 0.3,
        },
        HsvBinning {
            hue_bins: 15,
            saturation_bins: 17,
            value_bins: 1,
            min_saturation: 0.0,
            min_value: 0.0,
        },
        HsvBinning {
            hue_bins: 1,
            saturation_bins: 1,
            value_bins: 254,
            min_saturation: 1.0,
            min_value: 1.0,
        },
    ]
}

#[test]
fn hsv_bins_match_the_f64_reference() {
    let mut bins = BinImage::new();
    for (seed, levels) in [(1, None), (2, Some(16)), (3, Some(6)), (4, Some(11))] {
        let rgb = random_rgb(67, 41, seed, levels);
        for binning in binnings() {
            bins.fill_hsv(&rgb, &binning).unwrap();
            assert_eq!(bins.bins(), binning.bins());
            assert_eq!(bins.image().dimensions(), rgb.dimensions());
            for (&got, &pixel) in bins.image().as_slice().iter().zip(rgb.as_slice()) {
                assert_eq!(
                    usize::from(got),
                    reference_hsv_bin(pixel, &binning),
                    "pixel {pixel:?} with {binning:?}"
                );
            }
        }
    }
}

#[test]
fn hsv_bins_of_known_colours() {
    let pixels = vec![
        [255, 0, 0],     // red: hue 0, full saturation
        [0, 255, 0],     // green: hue 1/3
        [0, 0, 255],     // blue: hue 2/3
        [255, 0, 128],   // magenta-red: hue ≈ 0.92
        [40, 0, 0],      // red but too dark (value 0.16 < 0.2): value bin 1
        [200, 190, 185], // bright but grey (saturation 0.075 < 0.1)
        [255, 255, 255], // white: last value bin
        [0, 0, 0],       // black: first value bin
    ];
    let rgb = RgbImage::from_vec(8, 1, pixels).unwrap();
    let mut bins = BinImage::new();
    bins.fill_hsv(&rgb, &HsvBinning::default()).unwrap();
    let expected = [9, 3 * 10 + 9, 6 * 10 + 9, 9 * 10 + 9, 101, 107, 109, 100];
    assert_eq!(bins.image().as_slice(), expected);
}

#[test]
fn invalid_binnings_are_refused_naming_the_key() {
    let key_of = |binning: HsvBinning| match binning.validate().unwrap_err() {
        Error::Parameter { key, .. } => key,
        other => panic!("unexpected {other:?}"),
    };
    let base = HsvBinning::default();
    assert_eq!(
        key_of(HsvBinning {
            saturation_bins: 0,
            ..base
        }),
        "saturation_bins"
    );
    assert_eq!(
        key_of(HsvBinning {
            hue_bins: 16,
            saturation_bins: 16,
            ..base
        }),
        "hue_bins"
    );
    assert_eq!(
        key_of(HsvBinning {
            min_value: f64::NAN,
            ..base
        }),
        "min_value"
    );
    assert_eq!(
        key_of(HsvBinning {
            min_saturation: -0.1,
            ..base
        }),
        "min_saturation"
    );
    assert_eq!(base.bins(), 110);
    assert!(base.validate().is_ok());
    let rgb = random_rgb(4, 4, 9, None);
    let bad = HsvBinning {
        value_bins: 0,
        ..base
    };
    assert!(BinImage::new().fill_hsv(&rgb, &bad).is_err());
}

/// The histogram of `region` by scanning every pixel of the image: the columns and rows
/// whose centre lies in the box, then every `stride`-th of them.
fn reference_box_histogram(bins: &BinImage, region: &BoxPx, stride: usize) -> (Vec<f64>, usize) {
    let (width, height) = bins.image().dimensions();
    let inside = |v: usize, lo: f64, hi: f64| lo <= v as f64 && (v as f64) < hi;
    let columns: Vec<usize> = (0..width)
        .filter(|&x| inside(x, region.x_min, region.x_max))
        .step_by(stride)
        .collect();
    let rows: Vec<usize> = (0..height)
        .filter(|&y| inside(y, region.y_min, region.y_max))
        .step_by(stride)
        .collect();
    let mut counts = vec![0usize; bins.bins()];
    for &y in &rows {
        for &x in &columns {
            counts[usize::from(bins.image().get(x, y))] += 1;
        }
    }
    let total = columns.len() * rows.len();
    let histogram = counts
        .iter()
        .map(|&c| {
            if total == 0 {
                0.0
            } else {
                c as f64 / total as f64
            }
        })
        .collect();
    (histogram, total)
}

fn random_box(rng: &mut Rng, width: usize, height: usize) -> BoxPx {
    // Corners from 10 px outside to 10 px beyond the image, so many boxes are clipped.
    let x = |rng: &mut Rng| rng.unit() * (width + 20) as f64 - 10.0;
    let y = |rng: &mut Rng| rng.unit() * (height + 20) as f64 - 10.0;
    let (x_min, y_min) = (x(rng), y(rng));
    BoxPx {
        x_min,
        y_min,
        x_max: x_min + rng.unit() * 30.0,
        y_max: y_min + rng.unit() * 40.0,
    }
}

#[test]
fn box_histograms_match_a_per_pixel_scan_including_clipped_boxes() {
    let rgb = random_rgb(53, 37, 5, Some(9));
    let mut bins = BinImage::new();
    bins.fill_hsv(&rgb, &HsvBinning::default()).unwrap();
    let mut rng = Rng(77);
    let mut histogram = vec![0.0; bins.bins()];
    let (mut clipped, mut empty) = (0, 0);
    for _ in 0..400 {
        let region = random_box(&mut rng, 53, 37);
        for stride in [1, 2, 3] {
            let counted = bins.box_histogram(&region, stride, &mut histogram).unwrap();
            let (expected, total) = reference_box_histogram(&bins, &region, stride);
            assert_eq!(counted, total, "{region:?} stride {stride}");
            for (&got, &want) in histogram.iter().zip(&expected) {
                assert!((f64::from(got) - want).abs() < 1e-6, "{region:?}");
            }
            if counted > 0 {
                let sum: f32 = histogram.iter().sum();
                assert!((sum - 1.0).abs() < 1e-5, "sum {sum}");
            }
        }
        empty += usize::from(bins.box_histogram(&region, 1, &mut histogram).unwrap() == 0);
        clipped += usize::from(region.x_min < 0.0 || region.y_max > 37.0);
    }
    assert!(
        clipped > 50 && empty > 5,
        "{clipped} clipped, {empty} empty"
    );
}

#[test]
fn boxes_outside_the_image_give_an_empty_histogram_and_bad_calls_are_errors() {
    let mut bins = BinImage::new();
    bins.fill_hsv(&random_rgb(10, 8, 6, None), &HsvBinning::default())
        .unwrap();
    let mut histogram = vec![0.5; 110];
    for region in [
        BoxPx::centred(-20.0, 4.0, 10.0, 10.0),
        BoxPx::centred(5.0, 4.0, 0.0, 10.0),
        BoxPx {
            x_min: f64::NAN,
            ..BoxPx::centred(5.0, 4.0, 4.0, 4.0)
        },
    ] {
        assert_eq!(bins.box_histogram(&region, 1, &mut histogram).unwrap(), 0);
        assert!(histogram.iter().all(|&h| h == 0.0), "{region:?}");
    }
    let whole = BoxPx::centred(4.5, 3.5, f64::INFINITY, 100.0);
    assert_eq!(bins.box_histogram(&whole, 1, &mut histogram).unwrap(), 80);
    assert!(bins.box_histogram(&whole, 0, &mut histogram).is_err());
    assert!(bins.box_histogram(&whole, 1, &mut [0.0; 109]).is_err());
}

#[test]
fn difference_bins_match_the_reference_and_sizes_must_agree() {
    let (width, height) = (31, 17);
    let mut rng = Rng(11);
    let mut frame = || {
        let data = (0..width * height).map(|_| rng.unit() as f32).collect();
        GrayImage::from_vec(width, height, data).unwrap()
    };
    let (previous, current) = (frame(), frame());
    let mut bins = BinImage::new();
    for (n, full_scale) in [(10, 0.5f32), (1, 1.0), (256, 1.0), (7, 0.05)] {
        bins.fill_difference(&previous, &current, n, full_scale)
            .unwrap();
        assert_eq!(bins.bins(), n);
        for ((&got, &p), &c) in bins
            .image()
            .as_slice()
            .iter()
            .zip(previous.as_slice())
            .zip(current.as_slice())
        {
            let d = f64::from((c - p).abs()) / f64::from(full_scale);
            let want = ((d * n as f64).floor() as usize).min(n - 1);
            assert_eq!(usize::from(got), want, "|{c} − {p}| / {full_scale} · {n}");
        }
    }
    let small = GrayImage::new(width - 1, height);
    let error = bins
        .fill_difference(&small, &current, 10, 0.5)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("30×17") && error.contains("31×17"),
        "{error}"
    );
    assert!(bins.fill_difference(&previous, &current, 0, 0.5).is_err());
    assert!(bins.fill_difference(&previous, &current, 257, 0.5).is_err());
    assert!(bins.fill_difference(&previous, &current, 10, 0.0).is_err());
    assert!(
        bins.fill_difference(&previous, &current, 10, f32::NAN)
            .is_err()
    );
}

#[test]
fn bhattacharyya_of_identical_histograms_is_one_and_of_disjoint_ones_zero() {
    let mut bins = BinImage::new();
    bins.fill_hsv(&random_rgb(40, 40, 8, None), &HsvBinning::default())
        .unwrap();
    let mut h = vec![0.0; 110];
    bins.box_histogram(&BoxPx::centred(20.0, 20.0, 30.0, 30.0), 1, &mut h)
        .unwrap();
    assert!((bhattacharyya_coefficient(&h, &h) - 1.0).abs() < 1e-6);
    assert!(bhattacharyya_distance(&h, &h) < 1e-3);
    let mut a = vec![0.0f32; 110];
    let mut b = vec![0.0f32; 110];
    a[..55].fill(1.0 / 55.0);
    b[55..].fill(1.0 / 55.0);
    assert_eq!(bhattacharyya_coefficient(&a, &b), 0.0);
    assert_eq!(bhattacharyya_distance(&a, &b), 1.0);
    // Half the mass shared: coefficient 0.5.
    let mut c = vec![0.0f32; 110];
    c[..110].fill(1.0 / 110.0);
    let coefficient = bhattacharyya_coefficient(&a, &c);
    assert!((coefficient - 0.5f64.sqrt()).abs() < 1e-6, "{coefficient}");
}
