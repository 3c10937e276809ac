//! The dominant colour descriptor of MPEG-7 (Manjunath et al. 2001): an object's few main
//! colours with the share of its pixels each covers, and the descriptor's similarity. The
//! SIFT-PF tracker weighs the resumption of an occluded person with it (§2.4 of Souded et al.).

/// One dominant colour: its mean RGB (0-255) and the share of the pixels it covers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightedColour {
    /// Mean colour of the cluster, RGB in 0-255.
    pub rgb: [f32; 3],
    /// Share of the pixels in the cluster, in `(0, 1]`.
    pub share: f32,
}

/// Up to k dominant colours, by decreasing share.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DominantColours {
    colours: Vec<WeightedColour>,
}

/// At most this many pixels are clustered (an even subsample of larger sets): enough for
/// four colours' shares to within a percent.
const MAX_SAMPLES: usize = 2048;
/// Lloyd iterations of the k-means.
const ITERATIONS: usize = 8;
/// Colours further apart than this (RGB, 0-255) are unrelated (MPEG-7's `T_d`).
const UNRELATED_DISTANCE: f32 = 48.0;
/// MPEG-7's `d_max = α·T_d`, α = 1.2.
const MAX_DISTANCE: f32 = 1.2 * UNRELATED_DISTANCE;

impl DominantColours {
    /// Clusters `pixels` into at most `k` colours by k-means (Lloyd), seeded
    /// deterministically: the mean colour first, then each time the pixel furthest from the
    /// centres so far (ties to the first). Empty input gives no colours.
    pub fn extract(pixels: &[[u8; 3]], k: usize) -> Self {
        if pixels.is_empty() || k == 0 {
            return Self::default();
        }
        let stride = pixels.len().div_ceil(MAX_SAMPLES);
        let samples: Vec<[f32; 3]> = pixels
            .iter()
            .step_by(stride)
            .map(|p| p.map(f32::from))
            .collect();
        let mut centres = seed_centres(&samples, k);
        let mut labels = vec![0usize; samples.len()];
        for _ in 0..ITERATIONS {
            for (label, s) in labels.iter_mut().zip(&samples) {
                *label = nearest(&centres, s);
            }
            let mut sums = vec![([0.0f64; 3], 0usize); centres.len()];
            for (&label, s) in labels.iter().zip(&samples) {
                let (sum, count) = &mut sums[label];
                for c in 0..3 {
                    sum[c] += f64::from(s[c]);
                }
                *count += 1;
            }
            for (centre, (sum, count)) in centres.iter_mut().zip(&sums) {
                if *count > 0 {
                    *centre = sum.map(|v| (v / *count as f64) as f32);
                }
            }
        }
        let mut counts = vec![0usize; centres.len()];
        for s in &samples {
            counts[nearest(&centres, s)] += 1;
        }
        let mut colours: Vec<WeightedColour> = centres
            .into_iter()
            .zip(counts)
            .filter(|&(_, count)| count > 0)
            .map(|(rgb, count)| WeightedColour {
                rgb,
                share: count as f32 / samples.len() as f32,
            })
            .collect();
        colours.sort_by(|a, b| b.share.total_cmp(&a.share));
        Self { colours }
    }

    /// The colours, by decreasing share.
    pub fn colours(&self) -> &[WeightedColour] {
        &self.colours
    }

    /// Similarity in `[0, 1]` from MPEG-7's distance
    /// `D² = Σpᵢ² + Σqⱼ² − 2·Σᵢⱼ aᵢⱼ·pᵢ·qⱼ`, `aᵢⱼ = 1 − dᵢⱼ/d_max` for colours closer than
    /// `T_d` (0 otherwise), as `1 − D² / (Σpᵢ² + Σqⱼ²)`: 1 for the same colours in the same
    /// shares, 0 for colours all unrelated. 0 when either side has no colour.
    pub fn similarity(&self, other: &Self) -> f64 {
        let self_energy: f32 = self.colours.iter().map(|c| c.share * c.share).sum();
        let other_energy: f32 = other.colours.iter().map(|c| c.share * c.share).sum();
        let energy = self_energy + other_energy;
        if energy <= 0.0 {
            return 0.0;
        }
        let mut cross = 0.0f32;
        for a in &self.colours {
            for b in &other.colours {
                let d = distance(&a.rgb, &b.rgb);
                if d <= UNRELATED_DISTANCE {
                    cross += 2.0 * (1.0 - d / MAX_DISTANCE) * a.share * b.share;
                }
            }
        }
        f64::from(1.0 - (energy - cross) / energy).clamp(0.0, 1.0)
    }
}

/// The farthest-point seeding: the mean, then the sample furthest from every centre so far.
fn seed_centres(samples: &[[f32; 3]], k: usize) -> Vec<[f32; 3]> {
    let n = samples.len() as f64;
    let mut mean = [0.0f64; 3];
    for s in samples {
        for c in 0..3 {
            mean[c] += f64::from(s[c]) / n;
        }
    }
    let mut centres = vec![mean.map(|v| v as f32)];
    let mut nearest_distance: Vec<f32> = samples.iter().map(|s| distance(s, &centres[0])).collect();
    while centres.len() < k {
        let (far, &d) = nearest_distance
            .iter()
            .enumerate()
            .fold(
                (0, &f32::MIN),
                |best, cur| if cur.1 > best.1 { cur } else { best },
            );
        if d <= 0.0 {
            break;
        }
        let centre = samples[far];
        for (nd, s) in nearest_distance.iter_mut().zip(samples) {
            *nd = nd.min(distance(s, &centre));
        }
        centres.push(centre);
    }
    centres
}

fn nearest(centres: &[[f32; 3]], s: &[f32; 3]) -> usize {
    let mut best = (0, f32::INFINITY);
    for (i, c) in centres.iter().enumerate() {
        let d = distance(c, s);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

fn distance(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixels(parts: &[([u8; 3], usize)]) -> Vec<[u8; 3]> {
        parts
            .iter()
            .flat_map(|&(rgb, n)| std::iter::repeat_n(rgb, n))
            .collect()
    }

    #[test]
    fn finds_the_colours_and_their_shares() {
        let red_blue = pixels(&[([200, 20, 20], 300), ([20, 20, 200], 100)]);
        let dc = DominantColours::extract(&red_blue, 4);
        assert_eq!(dc.colours().len(), 2, "{dc:?}");
        assert_eq!(dc.colours()[0].rgb, [200.0, 20.0, 20.0]);
        assert!((dc.colours()[0].share - 0.75).abs() < 1e-6);
        assert!((dc.colours()[1].share - 0.25).abs() < 1e-6);
    }

    #[test]
    fn similarity_is_one_for_the_same_and_zero_for_unrelated_colours() {
        let a = DominantColours::extract(&pixels(&[([200, 20, 20], 300), ([20, 20, 200], 100)]), 3);
        let b = DominantColours::extract(&pixels(&[([20, 200, 20], 50), ([240, 240, 240], 50)]), 3);
        let a_shifted =
            DominantColours::extract(&pixels(&[([205, 25, 20], 280), ([20, 25, 195], 120)]), 3);
        assert!((a.similarity(&a) - 1.0).abs() < 1e-6);
        assert_eq!(a.similarity(&b), 0.0);
        let near = a.similarity(&a_shifted);
        assert!(near > 0.7 && near < 1.0, "{near}");
        assert_eq!(a.similarity(&DominantColours::default()), 0.0);
        assert!(DominantColours::extract(&[], 3).colours().is_empty());
    }
}
