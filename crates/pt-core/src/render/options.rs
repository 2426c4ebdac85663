//! What a render is asked to do: [`RenderOptions`] and their checks.

use std::ops::Range;

use crate::aov::Aovs;
use crate::integrator::LightStrategy;
use crate::render::OptionsError;
use crate::sampler::{SamplerFactory, SamplerKind};

/// Adaptive sampling: a pixel stops taking samples once the estimated relative error of its mean
/// is below `threshold`.
///
/// Each pixel first takes `min_spp` samples, then checks after every doubling (`min_spp`,
/// `2 min_spp`, `4 min_spp`, ... up to the render's `spp`, so that Sobol points stop at complete
/// power-of-two sets): the standard error of its mean luminance, from the running variance of
/// the samples, relative to the mean plus 0.01 (the same floor as relMSE's), is compared with
/// the threshold. The decision depends only on that pixel's own samples, so adaptive renders are
/// as deterministic as fixed ones (any thread count or tile size). Stopping on an estimate adds
/// a small bias: a pixel whose first samples all missed a rare bright path stops early.
/// `min_spp` bounds that risk; 16-32 is a sound choice.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct AdaptiveSampling {
    /// Target relative standard error of a pixel's mean (0.01 = 1%).
    pub threshold: f32,
    /// Samples every pixel takes before its error is first estimated (at least 2).
    pub min_spp: u32,
}

impl AdaptiveSampling {
    /// Stop at relative error `threshold`, after at least `min_spp` samples.
    #[must_use]
    pub fn new(threshold: f32, min_spp: u32) -> Self {
        Self { threshold, min_spp }
    }
}

impl Default for AdaptiveSampling {
    /// 2% relative error, at least 16 samples.
    fn default() -> Self {
        Self::new(0.02, 16)
    }
}

/// Everything a render needs besides the scene and camera.
///
/// ```
/// use pt_core::RenderOptions;
/// let opts = RenderOptions::new(320, 240).spp(16).max_depth(8).seed(7);
/// assert_eq!(opts.width, 320);
/// ```
///
/// With the `serde` feature the options serialise (every field, by name) and deserialise with
/// missing fields taken from [`RenderOptions::default`], so stored options survive new fields.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "K: serde::Serialize",
        deserialize = "K: serde::Deserialize<'de>, RenderOptions<K>: Default"
    ))
)]
#[non_exhaustive]
pub struct RenderOptions<K = SamplerKind> {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel of the complete render.
    pub spp: u32,
    /// The sample indices this render takes, a part of `0..spp` (`None`: all of them).
    ///
    /// Renders of disjoint ranges with the same scene, options and seed are independent parts
    /// of the complete render: their films merged with [`Film::merge`](crate::Film::merge) (or as files with
    /// [`crate::PartialRender`]) equal the film of the complete render bit for bit, so a render
    /// can be spread over processes or machines.
    pub spp_range: Option<Range<u32>>,
    /// Maximum number of scattering events along a path (0: emission only, 1: direct light).
    pub max_depth: u32,
    /// Russian roulette may end paths after this many bounces.
    pub rr_depth: u32,
    /// Russian roulette plays for paths whose throughput (its largest channel) has fallen
    /// below this, and a path survives with probability throughput over threshold (the
    /// survivors' throughput divided by it, so the estimate stays unbiased).
    ///
    /// The default, 0.4 with `rr_depth` 1, measured the most efficient (the least error for
    /// the time) on Mitsuba's Cornell box and the figure scenes: 1.2-1.5x as efficient as
    /// pbrt's threshold of 1 with `rr_depth` 3 (the default until 2026-12-07) on most of them
    /// (docs/PERFORMANCE.md). A higher threshold ends more paths early (faster, noisier).
    pub rr_threshold: f32,
    /// Seed of every random number in the render.
    pub seed: u64,
    /// Worker threads; `None` uses rayon's global pool (one per core).
    pub threads: Option<usize>,
    /// Edge length of the square tiles scheduled on threads.
    pub tile_size: u32,
    /// How direct lighting is estimated.
    pub strategy: LightStrategy,
    /// The sample generator: a [`SamplerKind`] (the default) or a user's [`SamplerFactory`].
    pub sampler: K,
    /// Firefly clamp: a sample whose largest RGB component exceeds this value is scaled down
    /// to it (hue kept). `None` (the default) keeps the estimator unbiased; a clamp darkens
    /// exactly the paths that carry rare, large contributions (caustics seen through glass,
    /// small bright lights reached by BSDF sampling), so it trades bias for lower variance.
    /// [`RenderStats::clamped_samples`](crate::RenderStats::clamped_samples) counts how often it acted.
    pub sample_clamp: Option<f32>,
    /// Adaptive sampling (`None`, the default: every pixel takes `spp` samples); `spp` is then
    /// the most a pixel takes. Cannot be combined with `spp_range`.
    pub adaptive: Option<AdaptiveSampling>,
    /// The most memory the film may take, in bytes, checked before any work: a pixel's exact
    /// sums take [`FILM_BYTES_PER_PIXEL`] bytes, held twice while the tiles are merged.
    /// Default 4 GiB (about 33 million pixels, an 8K frame).
    pub max_film_bytes: u64,
    /// Trace eight paths at once in SIMD lanes (the lane path tracer) where the scene allows it:
    /// Lambertian, mirror and smooth glass materials, any lights, no absorbing media, the Sobol
    /// sampler, no adaptive sampling, no auxiliary outputs; other scenes render with the
    /// one-path tracer whatever this says. Same estimator, same sample values, the same film
    /// bit for bit on every scene tested (the tests compare them); faster. On by default; off
    /// renders with the one-path tracer, the reference (docs/PERFORMANCE.md).
    pub lanes: bool,
    /// Auxiliary outputs (albedo and normal of the first non-specular hit, [`crate::aov`]): in
    /// [`RenderOutput`](crate::RenderOutput)'s `albedo` and `normal`, and in partial renders.
    /// None by default; any of them adds [`AOV_BYTES_PER_PIXEL`] to the film and renders with
    /// the one-path tracer (not the lanes).
    pub aovs: Aovs,
}

/// Film memory per pixel during a render: the exact per-pixel sums (64 bytes), once in the
/// tiles and once in the merged film.
pub const FILM_BYTES_PER_PIXEL: u64 = 2 * std::mem::size_of::<crate::film::PixelSum>() as u64;

/// Film memory per pixel added by auxiliary outputs: their exact sums (48 bytes), once in the
/// tiles and once in the merged film.
pub const AOV_BYTES_PER_PIXEL: u64 = 2 * std::mem::size_of::<crate::film::AuxSum>() as u64;

/// The largest Russian roulette threshold ([`RenderOptions::rr_threshold`]): a path then
/// survives a bounce with probability at least its throughput over this.
pub const MAX_RR_THRESHOLD: f32 = 1e6;

/// The most worker threads a render takes (more is a mistake, not a machine).
pub const MAX_THREADS: usize = 1024;

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 32,
            rr_depth: 1,
            rr_threshold: 0.4,
            seed: 0,
            threads: None,
            tile_size: 16,
            strategy: LightStrategy::Mis,
            sampler: SamplerKind::Sobol,
            spp_range: None,
            sample_clamp: None,
            adaptive: None,
            max_film_bytes: 4 << 30,
            lanes: true,
            aovs: Aovs::NONE,
        }
    }
}

impl RenderOptions {
    /// Defaults for an image of the given size.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            ..Self::default()
        }
    }
}

impl<K> RenderOptions<K> {
    /// Set the samples per pixel.
    #[must_use]
    pub fn spp(mut self, spp: u32) -> Self {
        self.spp = spp;
        self
    }

    /// Render only the sample indices `range` (a part of `0..spp`); see
    /// [`RenderOptions::spp_range`](struct.RenderOptions.html#structfield.spp_range).
    #[must_use]
    pub fn spp_range(mut self, range: Range<u32>) -> Self {
        self.spp_range = Some(range);
        self
    }

    /// Clamp each sample's largest component to `max` (`None`: no clamp, the default).
    #[must_use]
    pub fn sample_clamp(mut self, max: Option<f32>) -> Self {
        self.sample_clamp = max;
        self
    }

    /// Sample adaptively (`None`: a fixed `spp` per pixel, the default).
    #[must_use]
    pub fn adaptive(mut self, adaptive: Option<AdaptiveSampling>) -> Self {
        self.adaptive = adaptive;
        self
    }

    /// The sample indices this render takes: `spp_range`, or `0..spp`.
    #[must_use]
    pub fn samples(&self) -> Range<u32> {
        self.spp_range.clone().unwrap_or(0..self.spp)
    }

    /// Set the maximum path depth.
    #[must_use]
    pub fn max_depth(mut self, depth: u32) -> Self {
        self.max_depth = depth;
        self
    }

    /// Set the depth after which Russian roulette may end paths.
    #[must_use]
    pub fn rr_depth(mut self, depth: u32) -> Self {
        self.rr_depth = depth;
        self
    }

    /// Set the throughput below which Russian roulette plays ([`Self::rr_threshold`]).
    #[must_use]
    pub fn rr_threshold(mut self, threshold: f32) -> Self {
        self.rr_threshold = threshold;
        self
    }

    /// Set the seed.
    #[must_use]
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Set the number of worker threads (`None`: one per core).
    #[must_use]
    pub fn threads(mut self, threads: Option<usize>) -> Self {
        self.threads = threads;
        self
    }

    /// Set the tile size.
    #[must_use]
    pub fn tile_size(mut self, size: u32) -> Self {
        self.tile_size = size;
        self
    }

    /// Trace eight paths at once where the scene allows it ([`RenderOptions::lanes`]).
    #[must_use]
    pub fn lanes(mut self, on: bool) -> Self {
        self.lanes = on;
        self
    }

    /// Set the auxiliary outputs ([`crate::aov`]).
    #[must_use]
    pub fn aovs(mut self, aovs: Aovs) -> Self {
        self.aovs = aovs;
        self
    }

    /// The film memory a pixel takes during the render: [`FILM_BYTES_PER_PIXEL`], plus
    /// [`AOV_BYTES_PER_PIXEL`] with AOVs.
    #[must_use]
    pub fn film_bytes_per_pixel(&self) -> u64 {
        FILM_BYTES_PER_PIXEL
            + if self.aovs.any() {
                AOV_BYTES_PER_PIXEL
            } else {
                0
            }
    }

    /// Set the direct-lighting strategy.
    #[must_use]
    pub fn strategy(mut self, strategy: LightStrategy) -> Self {
        self.strategy = strategy;
        self
    }

    /// Set the sample generator: a [`SamplerKind`], or a user's [`SamplerFactory`] (the
    /// options then have its type).
    #[must_use]
    pub fn sampler<F: SamplerFactory>(self, sampler: F) -> RenderOptions<F> {
        RenderOptions {
            width: self.width,
            height: self.height,
            spp: self.spp,
            spp_range: self.spp_range,
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            rr_threshold: self.rr_threshold,
            seed: self.seed,
            threads: self.threads,
            tile_size: self.tile_size,
            strategy: self.strategy,
            sampler,
            sample_clamp: self.sample_clamp,
            adaptive: self.adaptive,
            max_film_bytes: self.max_film_bytes,
            lanes: self.lanes,
            aovs: self.aovs,
        }
    }

    /// Check the options make sense, before any work.
    ///
    /// # Errors
    ///
    /// The first option found out of range.
    pub fn validate(&self) -> Result<(), OptionsError> {
        let (width, height, spp) = (self.width, self.height, self.spp);
        if width == 0 || height == 0 {
            return Err(OptionsError::EmptyImage { width, height });
        }
        if u64::from(width) * u64::from(height) > MAX_PIXELS {
            return Err(OptionsError::TooManyPixels { width, height });
        }
        if spp == 0 {
            return Err(OptionsError::NoSamples);
        }
        if self.tile_size == 0 {
            return Err(OptionsError::EmptyTiles);
        }
        if let Some(range) = &self.spp_range
            && (range.start >= range.end || range.end > spp)
        {
            return Err(OptionsError::SampleRange {
                range: range.clone(),
                spp,
            });
        }
        if let Some(clamp) = self.sample_clamp
            && !(clamp > 0.0 && clamp.is_finite())
        {
            return Err(OptionsError::SampleClamp(clamp));
        }
        let t = self.rr_threshold;
        if !(t > 0.0 && t <= MAX_RR_THRESHOLD) {
            return Err(OptionsError::RouletteThreshold(t));
        }
        if let Some(threads) = self.threads.filter(|&t| t == 0 || t > MAX_THREADS) {
            return Err(OptionsError::Threads(threads));
        }
        let bytes = u64::from(width) * u64::from(height) * self.film_bytes_per_pixel();
        if bytes > self.max_film_bytes {
            return Err(OptionsError::FilmTooLarge {
                width,
                height,
                bytes,
                max_bytes: self.max_film_bytes,
            });
        }
        if let Some(a) = &self.adaptive {
            if !(a.threshold > 0.0 && a.threshold.is_finite()) {
                return Err(OptionsError::AdaptiveThreshold(a.threshold));
            }
            if a.min_spp < 2 || a.min_spp > spp {
                return Err(OptionsError::AdaptiveMinSpp {
                    min_spp: a.min_spp,
                    spp,
                });
            }
            if self.spp_range.is_some() {
                return Err(OptionsError::AdaptiveWithSampleRange);
            }
        }
        Ok(())
    }
}

/// The largest image a render takes, in pixels (2^28, a 16K x 16K frame).
pub const MAX_PIXELS: u64 = 1 << 28;

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(feature = "serde")]
    #[test]
    fn options_round_trip_through_json_and_fill_missing_fields() {
        let o = RenderOptions::new(320, 200)
            .spp(64)
            .spp_range(16..32)
            .seed(u64::MAX)
            .strategy(LightStrategy::BsdfOnly)
            .sample_clamp(Some(20.0))
            .threads(Some(3));
        let text = serde_json::to_string(&o).unwrap();
        let back: RenderOptions = serde_json::from_str(&text).unwrap();
        assert_eq!(back, o);
        let partial: RenderOptions = serde_json::from_str(r#"{"width": 64, "spp": 8}"#).unwrap();
        let mut expected = RenderOptions::default().spp(8);
        expected.width = 64;
        assert_eq!(partial, expected);
        assert!(serde_json::from_str::<RenderOptions>(r#"{"strategy": "Nope"}"#).is_err());
    }

    #[test]
    fn invalid_options_are_reported_by_kind() {
        let e = |o: RenderOptions| o.validate().unwrap_err();
        assert_eq!(
            e(RenderOptions::new(0, 10)),
            OptionsError::EmptyImage {
                width: 0,
                height: 10
            }
        );
        assert_eq!(
            e(RenderOptions::new(10, 10).spp(0)),
            OptionsError::NoSamples
        );
        assert_eq!(
            e(RenderOptions::new(10, 10).tile_size(0)),
            OptionsError::EmptyTiles
        );
        assert_eq!(
            e(RenderOptions::new(10, 10).threads(Some(0))),
            OptionsError::Threads(0)
        );
        assert_eq!(
            e(RenderOptions::new(10, 10).threads(Some(MAX_THREADS + 1))),
            OptionsError::Threads(MAX_THREADS + 1)
        );
        assert!(matches!(
            e(RenderOptions::new(1 << 15, 1 << 14)),
            OptionsError::TooManyPixels { .. }
        ));
        for t in [0.0, -1.0, f32::NAN, f32::INFINITY, MAX_RR_THRESHOLD * 2.0] {
            assert!(matches!(
                e(RenderOptions::new(10, 10).rr_threshold(t)),
                OptionsError::RouletteThreshold(_)
            ));
        }
        for t in [1e-6, 0.4, 1.0, MAX_RR_THRESHOLD] {
            assert!(
                RenderOptions::new(10, 10)
                    .rr_threshold(t)
                    .validate()
                    .is_ok()
            );
        }
        let mut small_film = RenderOptions::new(100, 100);
        small_film.max_film_bytes = 1000;
        assert!(matches!(
            e(small_film),
            OptionsError::FilmTooLarge {
                max_bytes: 1000,
                ..
            }
        ));
        assert!(RenderOptions::new(10, 10).validate().is_ok());
        let o = RenderOptions::new(10, 10).spp(8);
        assert!(o.clone().spp_range(0..8).validate().is_ok());
        assert_eq!(
            e(o.clone().spp_range(4..4)),
            OptionsError::SampleRange {
                range: 4..4,
                spp: 8
            }
        );
        assert!(matches!(
            e(o.clone().spp_range(4..9)),
            OptionsError::SampleRange { .. }
        ));
        assert_eq!(
            e(o.clone().sample_clamp(Some(0.0))),
            OptionsError::SampleClamp(0.0)
        );
        assert!(matches!(
            e(o.clone().sample_clamp(Some(f32::NAN))),
            OptionsError::SampleClamp(_)
        ));
        assert!(o.clone().sample_clamp(Some(10.0)).validate().is_ok());
        let a = |t, m| Some(AdaptiveSampling::new(t, m));
        assert!(o.clone().adaptive(a(0.01, 4)).validate().is_ok());
        assert_eq!(
            e(o.clone().adaptive(a(0.0, 4))),
            OptionsError::AdaptiveThreshold(0.0)
        );
        assert_eq!(
            e(o.clone().adaptive(a(0.01, 1))),
            OptionsError::AdaptiveMinSpp { min_spp: 1, spp: 8 }
        );
        assert!(matches!(
            e(o.clone().adaptive(a(0.01, 9))),
            OptionsError::AdaptiveMinSpp { .. }
        ));
        assert_eq!(
            e(o.adaptive(a(0.01, 4)).spp_range(0..4)),
            OptionsError::AdaptiveWithSampleRange
        );
        // The messages name the option and the value.
        assert_eq!(
            OptionsError::SampleRange {
                range: 4..9,
                spp: 8
            }
            .to_string(),
            "sample range 4..9 is empty or not within 0..8 (the spp)"
        );
    }
}
