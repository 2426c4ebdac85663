//! Sample generators.
//!
//! A [`Sampler`] hands out the random numbers of one pixel sample at a time. The values are a pure
//! function of (seed, pixel, sample index, dimension): after `start_pixel_sample(p, i)`, the `d`-th
//! value drawn is always the same, whatever was drawn for other pixels or samples before, on
//! whichever thread. This is what makes renders bit-identical for any thread count and tile order.

mod independent;
mod kind;
mod scramble;
mod sobol;
mod sobol_lanes;
mod stratified;

use glam::{UVec2, Vec2};

pub use independent::IndependentSampler;
pub use kind::{SamplerFactory, SamplerKind};
pub use sobol::SobolSampler;
pub(crate) use sobol_lanes::SobolLanes;
pub use stratified::StratifiedSampler;

/// A source of sample values in `[0, 1)`, deterministic per (seed, pixel, sample index, dimension).
///
/// The renderer clones one sampler per tile; implementations should be cheap to clone.
pub trait Sampler: Clone + Send + Sync {
    /// Start sample `index` of `pixel`: the next values drawn are dimensions 0, 1, 2, ...
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32);

    /// The next value in `[0, 1)`.
    fn next_1d(&mut self) -> f32;

    /// The next two values in `[0, 1)^2`.
    fn next_2d(&mut self) -> Vec2;

    /// The position of the sample inside its pixel, in `[0, 1)^2`. Drawn first for each sample;
    /// samplers that stratify the image plane treat it specially.
    fn pixel_2d(&mut self) -> Vec2 {
        self.next_2d()
    }
}

/// The samplers that ship with pt, dispatched by a `match` (no virtual calls).
// The stratified sampler's per-pixel seed cache makes its variant large; a render holds one
// sampler per thread, and a box would add an indirection to every draw.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum BuiltinSampler {
    /// Independent uniform random numbers.
    Independent(IndependentSampler),
    /// Jittered stratified samples.
    Stratified(StratifiedSampler),
    /// Owen-scrambled Sobol points.
    Sobol(SobolSampler),
}

/// One `match` arm per built-in sampler, calling the same method on each.
macro_rules! each_sampler {
    ($self:ident, $s:ident => $call:expr) => {
        match $self {
            Self::Independent($s) => $call,
            Self::Stratified($s) => $call,
            Self::Sobol($s) => $call,
        }
    };
}

impl Sampler for BuiltinSampler {
    // Always, as the draws below: once per sample from the tile loop.
    #[inline(always)]
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        each_sampler!(self, s => s.start_pixel_sample(pixel, index));
    }

    // Always: called a few times per bounce from the path loop, which LLVM otherwise leaves
    // calling out of line once the loop is large (a 4% slower Cornell box, by callgrind).
    #[inline(always)]
    fn next_1d(&mut self) -> f32 {
        each_sampler!(self, s => s.next_1d())
    }

    // Always: called a few times per bounce from the path loop, which LLVM otherwise leaves
    // calling out of line once the loop is large (a 4% slower Cornell box, by callgrind).
    #[inline(always)]
    fn next_2d(&mut self) -> Vec2 {
        each_sampler!(self, s => s.next_2d())
    }

    #[inline(always)]
    fn pixel_2d(&mut self) -> Vec2 {
        each_sampler!(self, s => s.pixel_2d())
    }
}

impl From<IndependentSampler> for BuiltinSampler {
    fn from(s: IndependentSampler) -> Self {
        Self::Independent(s)
    }
}

impl From<StratifiedSampler> for BuiltinSampler {
    fn from(s: StratifiedSampler) -> Self {
        Self::Stratified(s)
    }
}

impl From<SobolSampler> for BuiltinSampler {
    fn from(s: SobolSampler) -> Self {
        Self::Sobol(s)
    }
}

/// Statistical tests of the built-in samplers. Significance: every family of tests below is
/// run at a family-wise level of 1e-3, split over its tests by the Šidák correction, so a
/// correct sampler fails one of them with probability below 0.1% (they are deterministic, so
/// in practice never; a planted bug fails them, see docs/testing.md).
#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::stats::{chi2_survival, ks_uniform, sidak};
    use crate::{SamplerKind, SobolSampler};

    /// The draws of one sample: a pixel position, then alternating 1D and 2D draws, as the path
    /// tracer takes them.
    fn draws(s: &mut BuiltinSampler, pixel: UVec2, index: u32, count: usize) -> Vec<f32> {
        s.start_pixel_sample(pixel, index);
        let mut v = Vec::with_capacity(count);
        let p = s.pixel_2d();
        v.extend([p.x, p.y]);
        while v.len() < count {
            if v.len() % 3 == 2 {
                v.push(s.next_1d());
            } else {
                let u = s.next_2d();
                v.extend([u.x, u.y]);
            }
        }
        v.truncate(count);
        v
    }

    #[test]
    fn every_dimension_is_uniform_kolmogorov_smirnov() {
        const DIMS: usize = 40;
        let alpha = sidak(1e-3, DIMS * 3 * 2);
        for kind in SamplerKind::ALL {
            // Power-of-two and odd sample counts: 256 pixels x spp samples per dimension, enough
            // to see a distortion of 10% in one dimension at this level.
            for spp in [64u32, 37] {
                let mut s = kind.sampler(11, spp);
                let mut columns = vec![Vec::new(); DIMS];
                for p in 0..256u32 {
                    for i in 0..spp {
                        for (d, v) in draws(&mut s, UVec2::new(p % 16, p / 16), i, DIMS)
                            .into_iter()
                            .enumerate()
                        {
                            assert!((0.0..1.0).contains(&v), "{kind:?}: {v} out of [0, 1)");
                            columns[d].push(f64::from(v));
                        }
                    }
                }
                for (d, col) in columns.iter_mut().enumerate() {
                    let (ks, p) = ks_uniform(col);
                    assert!(
                        p > alpha,
                        "{kind:?}, spp {spp}, dimension {d}: KS D = {ks:.4}, p = {p:.2e}"
                    );
                }
            }
        }
    }

    /// Every elementary interval of a Sobol draw holds exactly one of `2^m` samples: for each
    /// split `2^i x 2^(m-i)` of the square, every cell one point, for every pixel and draw, and
    /// for a block of samples that does not start at 0 (a sample range).
    #[test]
    fn sobol_draws_are_0_m_2_nets() {
        let mut s = SobolSampler::new(3);
        for m in 0..=10u32 {
            let n = 1u32 << m;
            for (pixel, start) in [
                (UVec2::new(0, 0), 0),
                (UVec2::new(17, 5), 0),
                (UVec2::new(3, 9), 3 * n),
            ] {
                for draw in 0..5 {
                    let points: Vec<Vec2> = (start..start + n)
                        .map(|i| {
                            s.start_pixel_sample(pixel, i);
                            for _ in 0..draw {
                                let _ = s.next_2d();
                            }
                            s.next_2d()
                        })
                        .collect();
                    for i in 0..=m {
                        let (nx, ny) = (1u32 << i, 1u32 << (m - i));
                        let mut cells = vec![0u8; n as usize];
                        for p in &points {
                            let cx = (p.x * nx as f32) as u32;
                            let cy = (p.y * ny as f32) as u32;
                            cells[(cy * nx + cx) as usize] += 1;
                        }
                        assert!(
                            cells.iter().all(|&c| c == 1),
                            "spp {n}, pixel {pixel}, draw {draw}, samples {start}.., \
                             intervals {nx}x{ny}: {cells:?}"
                        );
                    }
                    // 1D draws are stratified into n intervals too.
                    let mut bins = vec![0u8; n as usize];
                    for i in start..start + n {
                        s.start_pixel_sample(pixel, i);
                        for _ in 0..draw {
                            let _ = s.next_1d();
                        }
                        bins[(s.next_1d() * n as f32) as usize] += 1;
                    }
                    assert!(
                        bins.iter().all(|&c| c == 1),
                        "1D spp {n} draw {draw}: {bins:?}"
                    );
                }
            }
        }
    }

    /// Different draws (bounces) are independent of each other: the pairs (draw a, draw b) of a
    /// pixel's samples fill the unit square uniformly (chi-square over 8x8 cells, pooled over 64
    /// pixels), for draws next to each other and far apart. Padding that reused one index
    /// shuffle for every draw would put all pairs on the graph of a bijection (8 of 64 cells).
    #[test]
    fn different_draws_are_decorrelated() {
        let pairs = [(2, 3), (2, 5), (5, 8), (3, 20), (0, 2)];
        let alpha = sidak(1e-3, pairs.len() * 3 * 2);
        for kind in SamplerKind::ALL {
            for spp in [64u32, 16] {
                let mut s = kind.sampler(5, spp);
                for (a, b) in pairs {
                    let mut cells = [0u32; 64];
                    let mut n = 0;
                    for p in 0..(4096 / spp) {
                        for i in 0..spp {
                            let v = draws(&mut s, UVec2::new(p, 7), i, 24);
                            let (x, y) = ((v[a] * 8.0) as usize, (v[b] * 8.0) as usize);
                            cells[y * 8 + x] += 1;
                            n += 1;
                        }
                    }
                    let expected = f64::from(n) / 64.0;
                    let chi2: f64 = cells
                        .iter()
                        .map(|&c| (f64::from(c) - expected).powi(2) / expected)
                        .sum();
                    let p = chi2_survival(chi2, 63);
                    assert!(
                        p > alpha,
                        "{kind:?} spp {spp}, draws {a} and {b}: chi2 {chi2:.1}, p {p:.2e}"
                    );
                }
            }
        }
    }

    /// Values are a pure function of (seed, pixel, sample index, dimension): replaying a sample
    /// after visiting others, in reverse order, gives the same values (pbrt-v4's
    /// `samplers_test.cpp` contract), and seeds and pixels change them.
    #[test]
    fn values_depend_only_on_seed_pixel_index_and_dimension() {
        for kind in SamplerKind::ALL {
            let mut s = kind.sampler(21, 16);
            let forward: Vec<Vec<f32>> = (0..16)
                .map(|i| draws(&mut s, UVec2::new(4, 2), i, 12))
                .collect();
            let _ = draws(&mut s, UVec2::new(9, 9), 3, 30);
            let mut t = s.clone();
            for i in (0..16).rev() {
                assert_eq!(
                    draws(&mut t, UVec2::new(4, 2), i, 12),
                    forward[i as usize],
                    "{kind:?}"
                );
            }
            assert_ne!(
                draws(&mut t, UVec2::new(5, 2), 0, 12),
                forward[0],
                "{kind:?}"
            );
            let mut other_seed = kind.sampler(22, 16);
            assert_ne!(
                draws(&mut other_seed, UVec2::new(4, 2), 0, 12),
                forward[0],
                "{kind:?}"
            );
        }
    }
}
