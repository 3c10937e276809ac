//! Validation of new objects (§2.5 of Souded et al.): a new object is tracked normally but
//! watched for a number of frames; noise (reflections, foliage, a ghost of the background
//! model) disappears, oscillates, stays put or moves impossibly fast, and is dropped.

use super::object::HistoryEntry;
use super::params::ValidationParams;

/// True when the intermediate object with `history` (one entry per frame since its birth)
/// is an object of interest: linked to a blob in enough frames (persistence), its foot
/// point going somewhere (net displacement and straightness of the path through its linked
/// frames: the trajectory), at a possible speed.
pub fn is_object_of_interest(history: &[HistoryEntry], params: &ValidationParams) -> bool {
    if history.is_empty() {
        return false;
    }
    let linked: Vec<_> = history
        .iter()
        .filter(|e| e.linked)
        .map(|e| e.bbox.foot())
        .collect();
    let presence = linked.len() as f64 / history.len() as f64;
    if presence < params.min_presence || linked.len() < 2 {
        return false;
    }
    let path: f64 = linked.windows(2).map(|w| w[0].distance(w[1])).sum();
    let net = linked[0].distance(linked[linked.len() - 1]);
    let frames = (history[history.len() - 1].frame - history[0].frame).max(1) as f64;
    net >= params.min_displacement_px
        && net >= params.min_straightness * path
        && path / frames <= params.max_speed_px_per_frame
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::BoundingBox;
    use sillage_core::Point2;

    fn history(feet: &[(f64, bool)]) -> Vec<HistoryEntry> {
        feet.iter()
            .zip(0..)
            .map(|(&(x, linked), frame)| HistoryEntry {
                frame,
                bbox: BoundingBox::standing_on(Point2::new(x, 50.0), 10.0, 30.0),
                linked,
            })
            .collect()
    }

    #[test]
    fn walkers_pass_noise_fails() {
        let params = ValidationParams::default();
        let walker: Vec<_> = (0..10).map(|i| (2.0 * f64::from(i), true)).collect();
        assert!(is_object_of_interest(&history(&walker), &params));
        let still: Vec<_> = (0..10).map(|_| (5.0, true)).collect();
        assert!(!is_object_of_interest(&history(&still), &params));
        let flicker: Vec<_> = (0..10).map(|i| (10.0 * f64::from(i % 2), true)).collect();
        assert!(!is_object_of_interest(&history(&flicker), &params));
        let mut rare = walker.clone();
        rare.iter_mut().skip(3).step_by(2).for_each(|e| e.1 = false);
        assert!(!is_object_of_interest(&history(&rare), &params));
        let fast: Vec<_> = (0..10).map(|i| (40.0 * f64::from(i), true)).collect();
        assert!(!is_object_of_interest(&history(&fast), &params));
    }
}
