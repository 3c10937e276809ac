//! Reconstruction by erosion and the h-concave transform against iterated geodesic erosions.

mod common;

use common::random_image;
use sillage_core::{GrayImage, Image};
use sillage_image::Reconstruction;

/// Reconstruction by erosion the obvious way: `R ← max(mask, min over the 3×3 window of R)`
/// until nothing changes.
fn reference(marker: &GrayImage, mask: &GrayImage) -> GrayImage {
    let (w, h) = mask.dimensions();
    let mut r = marker.clone();
    loop {
        let mut next = r.clone();
        for y in 0..h {
            for x in 0..w {
                let mut v = r.get(x, y);
                for yy in y.saturating_sub(1)..(y + 2).min(h) {
                    for xx in x.saturating_sub(1)..(x + 2).min(w) {
                        v = v.min(r.get(xx, yy));
                    }
                }
                next.set(x, y, v.max(mask.get(x, y)));
            }
        }
        if next == r {
            return r;
        }
        r = next;
    }
}

/// A smooth landscape with basins of several depths (quantised like an 8-bit image) plus a
/// thin spiral wall, so that some paths wind against both scan directions.
fn landscape(w: usize, h: usize, seed: u64) -> GrayImage {
    let noise = random_image(w, h, seed);
    let data = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            let wave = 0.5 + 0.25 * (x / 3.0).sin() * (y / 4.0).cos();
            let spiral = if ((x - 20.0).hypot(y - 15.0) - (y - 15.0).atan2(x - 20.0))
                .rem_euclid(6.0)
                < 1.0
            {
                0.3
            } else {
                0.0
            };
            ((wave + spiral + 0.05 * f64::from(noise.as_slice()[i])) * 255.0).round() as f32 / 255.0
        })
        .collect();
    GrayImage::from_vec(w, h, data).unwrap()
}

#[test]
fn reconstruction_matches_iterated_geodesic_erosion() {
    let mut engine = Reconstruction::new();
    for (seed, (w, h)) in [(1, 1), (13, 1), (1, 9), (50, 40), (37, 61), (150, 20)]
        .into_iter()
        .enumerate()
    {
        let mask = landscape(w, h, seed as u64);
        let mut marker = mask.clone();
        for (i, v) in marker.as_mut_slice().iter_mut().enumerate() {
            *v += if i % 7 == 0 { 0.0 } else { 0.4 };
        }
        let expected = reference(&marker, &mask);
        engine.erode_reconstruct(&mut marker, &mask).unwrap();
        assert_eq!(marker, expected, "{w}×{h}");
    }
}

/// Images tall enough to be cut into parallel bands (32 rows or more each) give the same
/// reconstruction with 1 to 4 threads: the spiral wall and the waves carry the marker across
/// the seams both ways.
#[test]
fn reconstruction_does_not_depend_on_the_thread_count() {
    let (w, h) = (60, 140);
    let mask = landscape(w, h, 21);
    let mut marker = mask.clone();
    for (i, v) in marker.as_mut_slice().iter_mut().enumerate() {
        *v += if i % 11 == 0 { 0.0 } else { 0.4 };
    }
    let expected = reference(&marker, &mask);
    let levels = Image::from_vec(
        w,
        h,
        mask.as_slice()
            .iter()
            .map(|&v| (v * 255.0).round().min(255.0) as u8)
            .collect(),
    )
    .unwrap();
    let mut single_thread_levels = None;
    for threads in 1..=4 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (got, got_levels) = pool.install(|| {
            let mut engine = Reconstruction::new();
            let mut got = marker.clone();
            engine.erode_reconstruct(&mut got, &mask).unwrap();
            let mut got_levels = Image::default();
            engine.h_concave_levels(&levels, 44, &mut got_levels);
            (got, got_levels)
        });
        assert_eq!(got, expected, "{threads} threads");
        let single = single_thread_levels.get_or_insert_with(|| got_levels.clone());
        assert_eq!(&got_levels, single, "{threads} threads");
    }
}

#[test]
fn h_concave_is_basin_depth_clipped_at_h() {
    let mut engine = Reconstruction::new();
    let src = landscape(50, 40, 3);
    let h = 0.1;
    let mut got = GrayImage::default();
    engine.h_concave(&src, h, &mut got).unwrap();
    let mut marker = src.clone();
    marker.as_mut_slice().iter_mut().for_each(|v| *v += h);
    let filled = reference(&marker, &src);
    for ((&g, &f), &s) in got
        .as_slice()
        .iter()
        .zip(filled.as_slice())
        .zip(src.as_slice())
    {
        assert_eq!(g, f - s);
        assert!((0.0..=h + 1e-6).contains(&g));
    }
    // A pit of depth 0.3 in a flat plain: h inside it, 0 on the plain... the plain itself is
    // the global minimum basin, also raised by h.
    let mut pit = GrayImage::from_vec(9, 9, vec![0.5; 81]).unwrap();
    pit.set(4, 4, 0.2);
    engine.h_concave(&pit, h, &mut got).unwrap();
    assert!((got.get(4, 4) - h).abs() < 1e-6);
    assert!(got.get(0, 0).abs() < 1e-6);
}

/// The levels path gives exactly the levels of the reference on the levels as `f32` integers
/// (exact arithmetic there), including markers above 255 (`f + h` for bright `f`; the landscape saturates at 255), on sizes
/// with and without full SIMD chunks.
#[test]
fn h_concave_levels_is_exact() {
    let mut engine = Reconstruction::new();
    for (seed, (w, h)) in [(1, 1), (31, 1), (1, 9), (50, 40), (97, 33), (150, 20)]
        .into_iter()
        .enumerate()
    {
        let src = landscape(w, h, seed as u64 + 10);
        let data = src
            .as_slice()
            .iter()
            .map(|&v| (v * 255.0).round().min(255.0) as u8);
        let levels = Image::from_vec(w, h, data.collect()).unwrap();
        for height in [1u8, 44, 200] {
            let as_f32 = |image: &Image<u8>| {
                let data = image.as_slice().iter().map(|&k| f32::from(k)).collect();
                GrayImage::from_vec(w, h, data).unwrap()
            };
            let mask = as_f32(&levels);
            let mut marker = mask.clone();
            marker
                .as_mut_slice()
                .iter_mut()
                .for_each(|v| *v += f32::from(height));
            let filled = reference(&marker, &mask);
            let mut got = Image::default();
            engine.h_concave_levels(&levels, height, &mut got);
            let expected: Vec<f32> = filled
                .as_slice()
                .iter()
                .zip(mask.as_slice())
                .map(|(r, f)| r - f)
                .collect();
            assert_eq!(as_f32(&got).as_slice(), expected, "{w}×{h}, h = {height}");
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    let mut engine = Reconstruction::new();
    let mask = GrayImage::from_vec(2, 1, vec![0.5, 0.5]).unwrap();
    let mut marker = GrayImage::from_vec(2, 1, vec![0.6, 0.4]).unwrap();
    let err = engine
        .erode_reconstruct(&mut marker, &mask)
        .unwrap_err()
        .to_string();
    assert!(err.contains("(1, 0)"), "{err}");
    assert!(
        engine
            .erode_reconstruct(&mut GrayImage::new(1, 1), &mask)
            .is_err()
    );
    assert!(
        engine
            .h_concave(&mask, -1.0, &mut marker)
            .unwrap_err()
            .to_string()
            .contains("`h`")
    );
}
