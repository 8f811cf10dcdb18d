//! Drawing the sampled control vectors: one independent random stream per
//! sample index, so a sample is the same whichever thread draws it and in
//! whatever order (docs/design.md §12).

use crate::math::Rng;
use nalgebra::DVector;

/// The SplitMix64 finaliser: a bijective mix of 64 bits.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The random stream of sample `index` under `seed`. Seeds are mixed, not
/// offset: SplitMix64 streams from neighbouring states are the same
/// sequence shifted by one draw.
pub(crate) fn stream(seed: u64, index: usize) -> Rng {
    Rng(mix(
        seed ^ mix((index as u64).wrapping_add(0x9e37_79b9_7f4a_7c15))
    ))
}

/// The round of sample `index` out of `samples` split over `rounds`
/// rounds of equal size (the last round takes the remainder).
pub(crate) fn round_of(index: usize, samples: usize, rounds: usize) -> usize {
    let per = samples.div_ceil(rounds.max(1)).max(1);
    (index / per).min(rounds.max(1) - 1)
}

/// The spread of round `round`: `sigma0 · 2^round`.
pub(crate) fn sigma(sigma0: f64, round: usize) -> f64 {
    sigma0 * 2f64.powi(round.min(1000) as i32)
}

/// What sampling draws from: the current free controls, the metric and
/// the controls' ranges.
pub(crate) struct Around<'a> {
    pub u0: &'a DVector<f64>,
    /// Diagonal of `M` over the free controls.
    pub scales: &'a DVector<f64>,
    pub lo: &'a DVector<f64>,
    pub hi: &'a DVector<f64>,
}

impl Around<'_> {
    /// A sample from the normal distribution `N(u0, σ² M⁻¹)` (so `σ` is the
    /// spread of `‖Δu‖_M` per control), held within the controls' ranges.
    pub(crate) fn draw(&self, sigma: f64, rng: &mut Rng) -> DVector<f64> {
        DVector::from_iterator(
            self.u0.len(),
            (0..self.u0.len()).map(|k| {
                let step = sigma * rng.gauss() / self.scales[k].sqrt();
                (self.u0[k] + step).clamp(self.lo[k], self.hi[k])
            }),
        )
    }
}

/// `‖Δu‖_M = sqrt(Σ M_kk Δu_k²)`.
pub(crate) fn distance(du: &DVector<f64>, scales: &DVector<f64>) -> f64 {
    du.iter()
        .zip(scales.iter())
        .map(|(d, s)| s * d * d)
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_differ_per_index_and_repeat_per_seed() {
        let first = |seed, i| stream(seed, i).uniform();
        assert_eq!(first(7, 3), first(7, 3));
        assert_ne!(first(7, 3), first(7, 4));
        assert_ne!(first(7, 3), first(8, 3));
        // Neighbouring indices are not the same stream shifted by a draw.
        let mut a = stream(7, 3);
        a.uniform();
        assert_ne!(a.uniform(), first(7, 4));
    }

    #[test]
    fn rounds_split_the_samples_evenly_and_widen_by_two() {
        let rounds: Vec<usize> = (0..10).map(|i| round_of(i, 10, 3)).collect();
        assert_eq!(rounds, [0, 0, 0, 0, 1, 1, 1, 1, 2, 2]);
        assert_eq!(round_of(0, 1, 7), 0);
        assert_eq!(sigma(0.05, 3), 0.4);
    }

    /// The spread of each control is σ/√M_kk: a control with 4× the scale
    /// moves half as far, and ranges hold.
    #[test]
    fn samples_follow_the_metric_and_stay_in_range() {
        let u0 = DVector::from_vec(vec![0.0, 0.0, 0.5]);
        let scales = DVector::from_vec(vec![1.0, 4.0, 1.0]);
        let lo = DVector::from_vec(vec![f64::NEG_INFINITY, f64::NEG_INFINITY, 0.0]);
        let hi = DVector::from_vec(vec![f64::INFINITY, f64::INFINITY, 1.0]);
        let around = Around {
            u0: &u0,
            scales: &scales,
            lo: &lo,
            hi: &hi,
        };
        let n = 20_000;
        let mut sq = [0.0; 2];
        for i in 0..n {
            let u = around.draw(2.0, &mut stream(1, i));
            sq[0] += u[0] * u[0];
            sq[1] += u[1] * u[1];
            assert!((0.0..=1.0).contains(&u[2]), "{}", u[2]);
        }
        let sd = sq.map(|s| (s / n as f64).sqrt());
        assert!((sd[0] - 2.0).abs() < 0.05, "{sd:?}");
        assert!((sd[1] - 1.0).abs() < 0.03, "{sd:?}");
        let d = distance(&DVector::from_vec(vec![3.0, 2.0, 0.0]), &scales);
        assert!((d - 5.0).abs() < 1e-12);
    }
}
