//! The papers' experiments as library calls: the tables of `sillage bench`, each score the
//! median over seeded runs.

pub mod bedload;
pub mod held_out;
pub mod immpf;
pub mod sequences;
pub mod siftpf;

/// The median of `values` (sorted in place); `None` when empty.
pub fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// The median of `score` over `runs` (one seed each); NaN when there is no run.
pub fn median_over<T>(runs: &[T], score: impl Fn(&T) -> f64) -> f64 {
    let mut values: Vec<f64> = runs.iter().map(score).collect();
    median(&mut values).unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_of_odd_even_and_empty_sets() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&mut []), None);
        assert_eq!(median_over(&[(1, 5.0), (2, 7.0)], |r| r.1), 6.0);
        assert!(median_over::<f64>(&[], |r| *r).is_nan());
    }
}
