//! Connected components against a flood fill.

use sillage_core::{Image, Point2};
use sillage_image::{Component, ComponentLabeller, PixelBox};

/// Components by 8-connected flood fill, in order of first pixel.
fn reference(mask: &Image<bool>) -> Vec<Component> {
    let (w, h) = mask.dimensions();
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    for start in 0..w * h {
        if !mask.as_slice()[start] || seen[start] {
            continue;
        }
        let (mut stack, mut area, mut sx, mut sy) = (vec![start], 0, 0.0, 0.0);
        let mut bbox = PixelBox {
            x0: w,
            y0: h,
            x1: 0,
            y1: 0,
        };
        seen[start] = true;
        while let Some(p) = stack.pop() {
            let (x, y) = (p % w, p / w);
            area += 1;
            sx += x as f64;
            sy += y as f64;
            bbox = bbox.union(&PixelBox {
                x0: x,
                y0: y,
                x1: x + 1,
                y1: y + 1,
            });
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    let q = yy * w + xx;
                    if mask.as_slice()[q] && !seen[q] {
                        seen[q] = true;
                        stack.push(q);
                    }
                }
            }
        }
        out.push(Component {
            area,
            centroid: Point2::new(sx / area as f64, sy / area as f64),
            bbox,
        });
    }
    out
}

#[test]
fn matches_flood_fill_on_random_masks() {
    let mut labeller = ComponentLabeller::new();
    let mut state = 99u64;
    for (w, h, density) in [
        (1, 1, 50),
        (30, 20, 35),
        (64, 64, 55),
        (200, 3, 60),
        (129, 6, 95),
        (70, 9, 5),
        (128, 2, 100),
    ] {
        let data = (0..w * h)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 33) % 100 < density
            })
            .collect();
        let mask = Image::from_vec(w, h, data).unwrap();
        let mut got = Vec::new();
        labeller.label(&mask, &mut got);
        let want = reference(&mask);
        assert_eq!(got.len(), want.len());
        for (g, r) in got.iter().zip(&want) {
            assert_eq!(g.area, r.area);
            assert_eq!(g.bbox, r.bbox);
            assert!(g.centroid.distance(r.centroid) < 1e-9);
        }
    }
}

#[test]
fn diagonal_contact_joins_and_gaps_split() {
    // Two diagonal pixels are one component; a column of zeros splits.
    let rows = ["#..#", ".#.#", "...."];
    let data = rows
        .iter()
        .flat_map(|r| r.chars().map(|c| c == '#'))
        .collect();
    let mask = Image::from_vec(4, 3, data).unwrap();
    let mut got = Vec::new();
    ComponentLabeller::new().label(&mask, &mut got);
    assert_eq!(got.len(), 2);
    assert_eq!((got[0].area, got[0].centroid), (2, Point2::new(0.5, 0.5)));
    assert_eq!((got[1].area, got[1].centroid), (2, Point2::new(3.0, 0.5)));
}
