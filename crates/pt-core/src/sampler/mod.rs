//! Sample generators.
//!
//! A [`Sampler`] hands out the random numbers of one pixel sample at a time. The values are a pure
//! function of (seed, pixel, sample index, dimension): after `start_pixel_sample(p, i)`, the `d`-th
//! value drawn is always the same, whatever was drawn for other pixels or samples before, on
//! whichever thread. This is what makes renders bit-identical for any thread count and tile order.

mod independent;

use glam::{UVec2, Vec2};

pub use independent::IndependentSampler;

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
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum BuiltinSampler {
    /// Independent uniform random numbers.
    Independent(IndependentSampler),
}

impl Sampler for BuiltinSampler {
    #[inline]
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        match self {
            Self::Independent(s) => s.start_pixel_sample(pixel, index),
        }
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        match self {
            Self::Independent(s) => s.next_1d(),
        }
    }

    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        match self {
            Self::Independent(s) => s.next_2d(),
        }
    }

    #[inline]
    fn pixel_2d(&mut self) -> Vec2 {
        match self {
            Self::Independent(s) => s.pixel_2d(),
        }
    }
}

impl From<IndependentSampler> for BuiltinSampler {
    fn from(s: IndependentSampler) -> Self {
        Self::Independent(s)
    }
}
