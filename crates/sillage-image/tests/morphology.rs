//! Grey morphology against a direct window scan, MATLAB's disk sizes, and thread invariance.

mod common;

use common::random_image;
use sillage_core::GrayImage;
use sillage_image::{Morphology, StructuringElement};

/// Direct dilation (`max`) or erosion (`min`) over the element's offsets, outside ignored.
fn reference(src: &GrayImage, se: &StructuringElement, dilate: bool) -> Vec<f32> {
    let (w, h) = src.dimensions();
    let offsets = se.offsets();
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let values = offsets.iter().filter_map(|&(dx, dy)| {
                let (xx, yy) = (x as isize + dx, y as isize + dy);
                (xx >= 0 && yy >= 0 && (xx as usize) < w && (yy as usize) < h)
                    .then(|| src.get(xx as usize, yy as usize))
            });
            out[y * w + x] = if dilate {
                values.fold(f32::NEG_INFINITY, f32::max)
            } else {
                values.fold(f32::INFINITY, f32::min)
            };
        }
    }
    out
}

#[test]
fn disks_have_matlab_strel_sizes() {
    // MATLAB strel('disk', r, 8): side and pixel count (BeadTracking's radii 8, 15, 22, 30).
    for (r, side, pixels) in [
        (1, 3, 5),
        (2, 5, 13),
        (8, 15, 213),
        (15, 29, 673),
        (22, 43, 1605),
        (30, 59, 2857),
    ] {
        let se = StructuringElement::disk(r).unwrap();
        let offsets = se.offsets();
        assert_eq!(offsets.len(), pixels, "r = {r}");
        assert_eq!(se.extent(), (side / 2, side / 2), "r = {r}");
        assert!(
            offsets.contains(&(0, 0)) && offsets.iter().all(|&(x, y)| offsets.contains(&(-x, -y)))
        );
    }
    assert_eq!(StructuringElement::square(7).unwrap().offsets().len(), 49);
}

#[test]
fn dilation_and_erosion_match_the_direct_scan() {
    let elements = [
        StructuringElement::disk(1).unwrap(),
        StructuringElement::disk(2).unwrap(),
        StructuringElement::disk(5).unwrap(),
        StructuringElement::disk(15).unwrap(),
        StructuringElement::square(1).unwrap(),
        StructuringElement::square(9).unwrap(),
    ];
    // Sizes smaller than the element, exactly a tile, and spanning several tiles and bands.
    let sizes = [(1, 1), (5, 3), (40, 7), (341, 170), (9, 400)];
    let mut morphology = Morphology::new();
    for (seed, &(w, h)) in sizes.iter().enumerate() {
        let src = random_image(w, h, seed as u64);
        for se in &elements {
            let mut dst = GrayImage::default();
            morphology.dilate(&src, se, &mut dst);
            assert_eq!(
                dst.as_slice(),
                reference(&src, se, true).as_slice(),
                "{w}×{h}"
            );
            morphology.erode(&src, se, &mut dst);
            assert_eq!(
                dst.as_slice(),
                reference(&src, se, false).as_slice(),
                "{w}×{h}"
            );
        }
    }
}

#[test]
fn closing_and_opening_bracket_the_image_and_are_idempotent() {
    let src = random_image(300, 200, 7);
    let se = StructuringElement::disk(6).unwrap();
    let mut morphology = Morphology::new();
    let (mut closed, mut opened, mut again) = (
        GrayImage::default(),
        GrayImage::default(),
        GrayImage::default(),
    );
    morphology.close(&src, &se, &mut closed);
    morphology.open(&src, &se, &mut opened);
    for ((&c, &o), &s) in closed
        .as_slice()
        .iter()
        .zip(opened.as_slice())
        .zip(src.as_slice())
    {
        assert!(o <= s && s <= c);
    }
    morphology.close(&closed, &se, &mut again);
    assert_eq!(again, closed);
    morphology.open(&opened, &se, &mut again);
    assert_eq!(again, opened);
}

#[test]
fn one_thread_and_many_give_the_same_bits() {
    let src = random_image(1280, 320, 11);
    let se = StructuringElement::disk(22).unwrap();
    let run = || {
        let mut out = GrayImage::default();
        Morphology::new().close(&src, &se, &mut out);
        out
    };
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    assert_eq!(single, run());
}
