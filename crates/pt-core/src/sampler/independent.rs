//! Independent uniform random samples from PCG32.

use glam::{UVec2, Vec2};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::RngCore;

use crate::hash::hash_words;
use crate::sampler::Sampler;
use crate::sampler::scramble::fixed_to_unit;

/// Independent uniform samples: a PCG32 generator re-seeded from a hash of
/// (seed, pixel, sample index) at the start of every pixel sample, so dimension `d` of a sample is
/// the `d`-th output of that stream.
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    seed: u64,
    rng: Pcg32,
}

/// PCG32 stream selector (any odd constant; fixed so that streams depend only on the state seed).
const STREAM: u64 = 0xda3e_39cb_94b9_5bdb;

impl IndependentSampler {
    /// A sampler for the given global seed.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            rng: Pcg32::new(seed, STREAM),
        }
    }
}

impl Sampler for IndependentSampler {
    #[inline]
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let state = hash_words(&[
            self.seed,
            u64::from(pixel.x) | (u64::from(pixel.y) << 32),
            u64::from(index),
        ]);
        self.rng = Pcg32::new(state, STREAM);
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        fixed_to_unit(self.rng.next_u32())
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        Vec2::new(x, self.next_1d())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_depend_only_on_seed_pixel_index_dimension() {
        let mut a = IndependentSampler::new(7);
        a.start_pixel_sample(UVec2::new(3, 4), 5);
        let first: Vec<f32> = (0..10).map(|_| a.next_1d()).collect();
        // Visit other pixels and samples, then come back: the same values.
        a.start_pixel_sample(UVec2::new(9, 1), 0);
        let _ = a.next_2d();
        let mut b = a.clone();
        b.start_pixel_sample(UVec2::new(3, 4), 5);
        let again: Vec<f32> = (0..10).map(|_| b.next_1d()).collect();
        assert_eq!(first, again);
        // Different seeds, pixels and indices give different streams.
        let mut c = IndependentSampler::new(8);
        c.start_pixel_sample(UVec2::new(3, 4), 5);
        assert_ne!(c.next_1d(), first[0]);
        b.start_pixel_sample(UVec2::new(4, 3), 5);
        assert_ne!(b.next_1d(), first[0]);
    }

    #[test]
    fn values_are_in_unit_interval_with_uniform_mean() {
        let mut s = IndependentSampler::new(1);
        let mut sum = 0.0f64;
        let n = 100_000;
        for i in 0..n {
            s.start_pixel_sample(UVec2::new(i % 300, i / 300), i);
            let v = s.next_1d();
            assert!((0.0..1.0).contains(&v));
            sum += v as f64;
        }
        // Standard error of the mean of U(0,1) over 1e5 values is 9e-4; 5 sigma.
        assert!((sum / n as f64 - 0.5).abs() < 4.6e-3);
        assert!(fixed_to_unit(u32::MAX) < 1.0);
    }
}
