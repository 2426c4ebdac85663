//! The stratified (jittered) sampler.
//!
//! For `n` samples per pixel every draw splits its domain into `n` strata, `[0, 1)` into `n`
//! intervals for `next_1d` and `[0, 1)^2` into an `nx x ny = n` grid for `next_2d` (the most
//! square factorisation of `n`), and sample `i` of a pixel takes stratum `permute(i)` of that
//! draw, jittered uniformly inside it. The permutation is hashed from (seed, pixel, dimension),
//! so different draws (bounces) pair their strata differently and stay decorrelated
//! (pbrt-v4's `StratifiedSampler` does the same with per-dimension permutations).

use glam::{UVec2, Vec2};

use crate::hash::mix_bits;
use crate::sampler::Sampler;
use crate::sampler::scramble::{PixelSeeds, dimension_hash, fixed_to_unit, permute};

/// The largest `f32` below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Jittered stratified samples for a fixed number of samples per pixel.
#[derive(Clone, Debug)]
pub struct StratifiedSampler {
    seed: u64,
    spp: u32,
    nx: u32,
    ny: u32,
    seeds: PixelSeeds,
    /// A hash of the pixel seed and the sample index, for the jitter.
    sample_seed: u64,
    index: u32,
    dimension: u32,
}

impl StratifiedSampler {
    /// A sampler for `spp` samples per pixel (taken as at least 1) and the given seed. Sample
    /// indices at or beyond `spp` wrap around.
    #[must_use]
    pub fn new(seed: u64, spp: u32) -> Self {
        let spp = spp.max(1);
        // The most square grid nx x ny = spp with nx <= ny.
        let mut nx = (f64::from(spp).sqrt() as u32).max(1);
        while !spp.is_multiple_of(nx) {
            nx -= 1;
        }
        Self {
            seed,
            spp,
            nx,
            ny: spp / nx,
            seeds: PixelSeeds::new(),
            sample_seed: 0,
            index: 0,
            dimension: 0,
        }
    }

    /// The strata grid of 2D draws, `(nx, ny)`.
    #[must_use]
    pub fn grid(&self) -> (u32, u32) {
        (self.nx, self.ny)
    }

    /// The stratum of this sample in the current draw, and 64 bits for its jitter.
    #[inline]
    fn draw(&mut self) -> (u32, u64) {
        // The permutation depends on (pixel, dimension), the jitter also on the sample.
        let h = self.seeds.dimension(self.dimension);
        let jitter = dimension_hash(self.sample_seed, self.dimension);
        self.dimension += 1;
        (permute(self.index, self.spp, h as u32), jitter)
    }
}

impl Sampler for StratifiedSampler {
    #[inline]
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        // "Strat" in ASCII: the tag that keeps this sampler's streams apart from the others'.
        self.seeds.start_pixel(pixel, self.seed, 0x5374_7261_7400);
        self.index = index % self.spp;
        self.sample_seed = mix_bits(self.seeds.pixel_seed() ^ u64::from(self.index));
        self.dimension = 0;
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        let (stratum, jitter) = self.draw();
        let v = (stratum as f32 + fixed_to_unit(jitter as u32)) / self.spp as f32;
        v.min(ONE_MINUS_EPSILON)
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        let (stratum, jitter) = self.draw();
        let (sx, sy) = (stratum % self.nx, stratum / self.nx);
        let x = (sx as f32 + fixed_to_unit(jitter as u32)) / self.nx as f32;
        let y = (sy as f32 + fixed_to_unit((jitter >> 32) as u32)) / self.ny as f32;
        Vec2::new(x.min(ONE_MINUS_EPSILON), y.min(ONE_MINUS_EPSILON))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_are_the_most_square_factorisation() {
        let grid = |n| StratifiedSampler::new(0, n).grid();
        assert_eq!(grid(16), (4, 4));
        assert_eq!(grid(32), (4, 8));
        assert_eq!(grid(12), (3, 4));
        assert_eq!(grid(7), (1, 7));
        assert_eq!(grid(1), (1, 1));
        assert_eq!(grid(0), (1, 1));
    }

    #[test]
    fn every_stratum_gets_one_sample() {
        for spp in [1u32, 4, 7, 12, 16, 64] {
            let mut s = StratifiedSampler::new(9, spp);
            let (nx, ny) = s.grid();
            for dim in 0..6 {
                let mut cells = vec![0u32; spp as usize];
                let mut bins = vec![0u32; spp as usize];
                for i in 0..spp {
                    s.start_pixel_sample(UVec2::new(5, 6), i);
                    for _ in 0..dim {
                        let _ = s.next_1d();
                    }
                    let p = s.next_2d();
                    let cell = (p.y * ny as f32) as u32 * nx + (p.x * nx as f32) as u32;
                    cells[cell as usize] += 1;
                    s.start_pixel_sample(UVec2::new(5, 6), i);
                    for _ in 0..dim {
                        let _ = s.next_1d();
                    }
                    bins[(s.next_1d() * spp as f32) as usize] += 1;
                }
                assert!(
                    cells.iter().all(|&c| c == 1),
                    "spp {spp} dim {dim}: {cells:?}"
                );
                assert!(
                    bins.iter().all(|&c| c == 1),
                    "spp {spp} dim {dim}: {bins:?}"
                );
            }
        }
    }
}
