//! One-pass moments (Welford's update, Chan et al.'s merge): the mean of a quantity, and the
//! means, variances and covariance of a velocity's two components. Exact to rounding
//! whatever the order of the samples, with no stored samples.

/// The running mean of a quantity: `push` one sample at a time, `merge` two partial means.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunningMean {
    count: u64,
    mean: f64,
}

impl RunningMean {
    /// Adds one sample.
    pub fn push(&mut self, value: f64) {
        self.count += 1;
        self.mean += (value - self.mean) / self.count as f64;
    }

    /// Adds every sample of `other` (Chan et al. 1979, the pairwise update).
    pub fn merge(&mut self, other: &Self) {
        let count = self.count + other.count;
        if other.count == 0 {
            return;
        }
        self.mean += (other.mean - self.mean) * (other.count as f64 / count as f64);
        self.count = count;
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The mean, `None` without samples.
    pub fn mean(&self) -> Option<f64> {
        (self.count > 0).then_some(self.mean)
    }
}

/// Means, variances and covariance of a velocity `(u, v)` and its mean speed `|(u, v)|`,
/// accumulated in one pass: the Reynolds-stress terms ⟨u'²⟩, ⟨v'²⟩, ⟨u'v'⟩ of the TracTrac
/// paper's §5.1 are population moments (divided by the count).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct VelocityMoments {
    count: u64,
    mean_u: f64,
    mean_v: f64,
    /// Σ(u − ū)².
    m2_u: f64,
    /// Σ(v − v̄)².
    m2_v: f64,
    /// Σ(u − ū)(v − v̄).
    c_uv: f64,
    speed: RunningMean,
}

impl VelocityMoments {
    /// Adds one velocity sample (Welford's update, extended to the co-moment).
    pub fn push(&mut self, u: f64, v: f64) {
        self.count += 1;
        let n = self.count as f64;
        let du = u - self.mean_u;
        let dv = v - self.mean_v;
        self.mean_u += du / n;
        self.mean_v += dv / n;
        self.m2_u += du * (u - self.mean_u);
        self.m2_v += dv * (v - self.mean_v);
        self.c_uv += du * (v - self.mean_v);
        self.speed.push(u.hypot(v));
    }

    /// Adds every sample of `other` (Chan et al.'s pairwise update of the co-moments).
    pub fn merge(&mut self, other: &Self) {
        if other.count == 0 {
            return;
        }
        let (na, nb) = (self.count as f64, other.count as f64);
        let n = na + nb;
        let du = other.mean_u - self.mean_u;
        let dv = other.mean_v - self.mean_v;
        let weight = na * nb / n;
        self.m2_u += other.m2_u + du * du * weight;
        self.m2_v += other.m2_v + dv * dv * weight;
        self.c_uv += other.c_uv + du * dv * weight;
        self.mean_u += du * nb / n;
        self.mean_v += dv * nb / n;
        self.count += other.count;
        self.speed.merge(&other.speed);
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Mean velocity `(ū, v̄)`, `None` without samples.
    pub fn mean(&self) -> Option<(f64, f64)> {
        (self.count > 0).then_some((self.mean_u, self.mean_v))
    }

    /// `(⟨u'²⟩, ⟨v'²⟩, ⟨u'v'⟩)`, population moments; `None` without samples.
    pub fn stresses(&self) -> Option<(f64, f64, f64)> {
        let n = self.count as f64;
        (self.count > 0).then(|| (self.m2_u / n, self.m2_v / n, self.c_uv / n))
    }

    /// Turbulent kinetic energy per unit mass of the two measured components,
    /// `½(⟨u'²⟩ + ⟨v'²⟩)`.
    pub fn turbulent_kinetic_energy(&self) -> Option<f64> {
        self.stresses().map(|(uu, vv, _)| 0.5 * (uu + vv))
    }

    /// Mean speed `⟨|(u, v)|⟩`.
    pub fn mean_speed(&self) -> Option<f64> {
        self.speed.mean()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The two-pass reference: means first, then the centred sums.
    fn two_pass(samples: &[(f64, f64)]) -> (f64, f64, f64, f64, f64, f64) {
        let n = samples.len() as f64;
        let mu = samples.iter().map(|s| s.0).sum::<f64>() / n;
        let mv = samples.iter().map(|s| s.1).sum::<f64>() / n;
        let uu = samples.iter().map(|s| (s.0 - mu).powi(2)).sum::<f64>() / n;
        let vv = samples.iter().map(|s| (s.1 - mv).powi(2)).sum::<f64>() / n;
        let uv = samples.iter().map(|s| (s.0 - mu) * (s.1 - mv)).sum::<f64>() / n;
        let speed = samples.iter().map(|s| s.0.hypot(s.1)).sum::<f64>() / n;
        (mu, mv, uu, vv, uv, speed)
    }

    fn assert_close(got: f64, want: f64, scale: f64, what: &str) {
        assert!(
            (got - want).abs() <= 1e-9 * scale,
            "{what}: one pass {got} vs two passes {want} (scale {scale})"
        );
    }

    fn check(moments: &VelocityMoments, samples: &[(f64, f64)]) {
        let (mu, mv, uu, vv, uv, speed) = two_pass(samples);
        let (gu, gv) = moments.mean().unwrap();
        let (guu, gvv, guv) = moments.stresses().unwrap();
        // Relative to each quantity's natural scale: the root mean square for the means,
        // the variances for the second moments (a covariance near zero is compared to
        // √(⟨u'²⟩⟨v'²⟩), as a correlation would be).
        let rms_u = (uu + mu * mu).sqrt();
        let rms_v = (vv + mv * mv).sqrt();
        assert_close(gu, mu, rms_u, "mean u");
        assert_close(gv, mv, rms_v, "mean v");
        assert_close(guu, uu, uu.max(f64::MIN_POSITIVE), "<u'u'>");
        assert_close(gvv, vv, vv.max(f64::MIN_POSITIVE), "<v'v'>");
        assert_close(guv, uv, (uu * vv).sqrt().max(f64::MIN_POSITIVE), "<u'v'>");
        assert_close(moments.mean_speed().unwrap(), speed, speed, "mean speed");
        assert_eq!(moments.count(), samples.len() as u64);
    }

    fn samples() -> impl Strategy<Value = Vec<(f64, f64)>> {
        // A bin's velocities: an offset (the mean flow, up to 10⁴ times the fluctuation)
        // plus fluctuations, as in a turbulent flow measured in px/frame or m/s.
        (
            -1e3..1e3f64,
            -1e3..1e3f64,
            1e-3..10.0f64,
            prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64), 2..400),
        )
            .prop_map(|(ou, ov, scale, unit)| {
                unit.into_iter()
                    .map(|(a, b)| (ou + scale * a, ov + scale * (0.5 * a + b)))
                    .collect()
            })
    }

    proptest! {
        #[test]
        fn one_pass_equals_two_passes(samples in samples()) {
            let mut moments = VelocityMoments::default();
            for &(u, v) in &samples {
                moments.push(u, v);
            }
            check(&moments, &samples);
        }

        #[test]
        fn merged_halves_equal_the_whole(samples in samples(), cut in 0.0..1.0f64) {
            let at = ((samples.len() as f64 * cut) as usize).min(samples.len());
            let (mut left, mut right) = (VelocityMoments::default(), VelocityMoments::default());
            for &(u, v) in &samples[..at] {
                left.push(u, v);
            }
            for &(u, v) in &samples[at..] {
                right.push(u, v);
            }
            left.merge(&right);
            check(&left, &samples);
        }
    }

    #[test]
    fn empty_moments_have_no_values() {
        let moments = VelocityMoments::default();
        assert_eq!(moments.mean(), None);
        assert_eq!(moments.stresses(), None);
        assert_eq!(moments.mean_speed(), None);
        let mut mean = RunningMean::default();
        mean.merge(&RunningMean::default());
        assert_eq!(mean.mean(), None);
        mean.push(2.0);
        mean.push(4.0);
        assert_eq!(mean.mean(), Some(3.0));
    }
}
