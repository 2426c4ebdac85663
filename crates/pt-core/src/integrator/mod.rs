//! Rendering: options, the tile scheduler, statistics.
//!
//! The image is split into square tiles rendered in parallel on rayon; each pixel's samples are
//! taken in sample-index order by one thread with a sampler whose values depend only on (seed,
//! pixel, sample index, dimension), and tiles are merged in a fixed order. The image is therefore
//! bit-identical for any thread count, tile schedule and run.

mod path;

use std::fmt;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use glam::{UVec2, Vec2};

use crate::camera::{Camera, CameraSample};
use crate::film::Film;
use crate::image::Image;
use crate::light::Light;
use crate::material::Material;
use crate::sampler::{
    BuiltinSampler, IndependentSampler, Sampler, SobolSampler, StratifiedSampler,
};
use crate::scene::Scene;

use path::PathSettings;

/// How direct light is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum LightStrategy {
    /// Light sampling and BSDF sampling combined by multiple importance sampling (power
    /// heuristic). The robust default.
    #[default]
    Mis,
    /// BSDF sampling only: emission is found only when a sampled ray hits a light.
    BsdfOnly,
    /// Light sampling (next-event estimation) only, except after delta bounces.
    LightOnly,
}

impl LightStrategy {
    /// Every strategy, for comparisons.
    pub const ALL: [LightStrategy; 3] = [Self::Mis, Self::BsdfOnly, Self::LightOnly];

    /// The name used on command lines and in tables (`mis`, `bsdf`, `light`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Mis => "mis",
            Self::BsdfOnly => "bsdf",
            Self::LightOnly => "light",
        }
    }
}

impl std::str::FromStr for LightStrategy {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown strategy {s:?} (expected mis, bsdf or light)"))
    }
}

/// Which sample generator to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum SamplerKind {
    /// Independent uniform random numbers (PCG32). Every sample of a pixel is independent of
    /// the others, which statistical tests over sample ranges rely on.
    Independent,
    /// Jittered stratified samples ([`crate::StratifiedSampler`]): each draw is stratified over
    /// the pixel's samples.
    Stratified,
    /// Owen-scrambled Sobol points ([`crate::SobolSampler`]); best with power-of-two spp. The
    /// default: the lowest error at equal time (docs/PERFORMANCE.md, "Samplers").
    #[default]
    Sobol,
}

impl SamplerKind {
    /// Every built-in kind, for comparisons.
    pub const ALL: [SamplerKind; 3] = [Self::Independent, Self::Stratified, Self::Sobol];

    /// The name used on command lines and in tables (`independent`, `stratified`, `sobol`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Independent => "independent",
            Self::Stratified => "stratified",
            Self::Sobol => "sobol",
        }
    }

    /// The sampler of this kind for a render with `spp` samples per pixel and `seed`.
    #[must_use]
    pub fn sampler(self, seed: u64, spp: u32) -> BuiltinSampler {
        match self {
            Self::Independent => IndependentSampler::new(seed).into(),
            Self::Stratified => StratifiedSampler::new(seed, spp).into(),
            Self::Sobol => SobolSampler::new(seed).into(),
        }
    }
}

impl std::str::FromStr for SamplerKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                format!("unknown sampler {s:?} (expected independent, stratified or sobol)")
            })
    }
}

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
#[non_exhaustive]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel of the complete render.
    pub spp: u32,
    /// The sample indices this render takes, a part of `0..spp` (`None`: all of them).
    ///
    /// Renders of disjoint ranges with the same scene, options and seed are independent parts
    /// of the complete render: their films merged with [`Film::merge`] (or as files with
    /// [`crate::PartialRender`]) equal the film of the complete render bit for bit, so a render
    /// can be spread over processes or machines.
    pub spp_range: Option<Range<u32>>,
    /// Maximum number of scattering events along a path (0: emission only, 1: direct light).
    pub max_depth: u32,
    /// Russian roulette may end paths after this many bounces.
    pub rr_depth: u32,
    /// Seed of every random number in the render.
    pub seed: u64,
    /// Worker threads; `None` uses rayon's global pool (one per core).
    pub threads: Option<usize>,
    /// Edge length of the square tiles scheduled on threads.
    pub tile_size: u32,
    /// How direct lighting is estimated.
    pub strategy: LightStrategy,
    /// The sample generator.
    pub sampler: SamplerKind,
    /// Firefly clamp: a sample whose largest RGB component exceeds this value is scaled down
    /// to it (hue kept). `None` (the default) keeps the estimator unbiased; a clamp darkens
    /// exactly the paths that carry rare, large contributions (caustics seen through glass,
    /// small bright lights reached by BSDF sampling), so it trades bias for lower variance.
    /// [`RenderStats::clamped_samples`] counts how often it acted.
    pub sample_clamp: Option<f32>,
    /// Adaptive sampling (`None`, the default: every pixel takes `spp` samples); `spp` is then
    /// the most a pixel takes. Cannot be combined with `spp_range`.
    pub adaptive: Option<AdaptiveSampling>,
    /// The most memory the film may take, in bytes, checked before any work: a pixel's exact
    /// sums take [`FILM_BYTES_PER_PIXEL`] bytes, held twice while the tiles are merged.
    /// Default 4 GiB (about 33 million pixels, an 8K frame).
    pub max_film_bytes: u64,
}

/// Film memory per pixel during a render: the exact per-pixel sums (64 bytes), once in the
/// tiles and once in the merged film.
pub const FILM_BYTES_PER_PIXEL: u64 = 2 * std::mem::size_of::<crate::film::PixelSum>() as u64;

/// The most worker threads a render takes (more is a mistake, not a machine).
pub const MAX_THREADS: usize = 1024;

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 32,
            rr_depth: 3,
            seed: 0,
            threads: None,
            tile_size: 16,
            strategy: LightStrategy::Mis,
            sampler: SamplerKind::Sobol,
            spp_range: None,
            sample_clamp: None,
            adaptive: None,
            max_film_bytes: 4 << 30,
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

    /// Set the direct-lighting strategy.
    #[must_use]
    pub fn strategy(mut self, strategy: LightStrategy) -> Self {
        self.strategy = strategy;
        self
    }

    /// Set the sampler.
    #[must_use]
    pub fn sampler(mut self, sampler: SamplerKind) -> Self {
        self.sampler = sampler;
        self
    }

    /// Check the options make sense.
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |reason: String| Err(RenderError::InvalidOptions(reason));
        if self.width == 0 || self.height == 0 {
            return bad(format!(
                "image size {}x{} is empty",
                self.width, self.height
            ));
        }
        if u64::from(self.width) * u64::from(self.height) > (1 << 28) {
            return bad(format!(
                "image size {}x{} exceeds 2^28 pixels",
                self.width, self.height
            ));
        }
        if self.spp == 0 {
            return bad("spp must be at least 1".into());
        }
        if self.tile_size == 0 {
            return bad("tile size must be at least 1".into());
        }
        if let Some(r) = &self.spp_range {
            if r.start >= r.end || r.end > self.spp {
                return bad(format!(
                    "sample range {}..{} is empty or not within 0..{} (the spp)",
                    r.start, r.end, self.spp
                ));
            }
        }
        if let Some(c) = self.sample_clamp {
            if !(c > 0.0 && c.is_finite()) {
                return bad(format!("sample clamp must be positive and finite, got {c}"));
            }
        }
        if self.threads == Some(0) {
            return bad("thread count must be at least 1".into());
        }
        if let Some(t) = self.threads.filter(|&t| t > MAX_THREADS) {
            return bad(format!(
                "{t} threads is above the most a render takes ({MAX_THREADS})"
            ));
        }
        let film = u64::from(self.width) * u64::from(self.height) * FILM_BYTES_PER_PIXEL;
        if film > self.max_film_bytes {
            return bad(format!(
                "a {}x{} film needs {:.1} GiB ({FILM_BYTES_PER_PIXEL} bytes per pixel while tiles \
                 are merged), above max_film_bytes = {:.1} GiB (raise RenderOptions::max_film_bytes)",
                self.width,
                self.height,
                film as f64 / f64::from(1u32 << 30),
                self.max_film_bytes as f64 / f64::from(1u32 << 30)
            ));
        }
        if let Some(a) = &self.adaptive {
            if !(a.threshold > 0.0 && a.threshold.is_finite()) {
                return bad(format!(
                    "adaptive threshold must be positive and finite, got {}",
                    a.threshold
                ));
            }
            if a.min_spp < 2 || a.min_spp > self.spp {
                return bad(format!(
                    "adaptive minimum spp must be in 2..={} (the spp), got {}",
                    self.spp, a.min_spp
                ));
            }
            if self.spp_range.is_some() {
                return bad(
                    "adaptive sampling cannot be split into sample ranges: a pixel's \
                     stopping point depends on all its samples"
                        .into(),
                );
            }
        }
        Ok(())
    }
}

/// Why a render could not run.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum RenderError {
    /// The options are out of range; the message says which.
    InvalidOptions(String),
    /// The worker thread pool could not be created.
    ThreadPool(String),
    /// The caller's cancellation flag was set ([`RenderControl::cancel`]).
    Cancelled,
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidOptions(r) => write!(f, "invalid render options: {r}"),
            Self::ThreadPool(r) => write!(f, "could not create worker threads: {r}"),
            Self::Cancelled => write!(f, "render cancelled"),
        }
    }
}

impl std::error::Error for RenderError {}

/// Progress of a running render, reported after each finished tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Progress {
    /// Tiles finished.
    pub tiles_done: usize,
    /// Tiles in the image.
    pub tiles_total: usize,
}

/// Figures of a finished render.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RenderStats {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel taken by this render (the length of [`RenderStats::sample_range`]).
    pub spp: u32,
    /// The sample indices taken, out of `0..total_spp`.
    pub sample_range: Range<u32>,
    /// Samples per pixel of the complete render.
    pub total_spp: u32,
    /// The seed of the render.
    pub seed: u64,
    /// Wall time of the render (not of scene building).
    pub elapsed: Duration,
    /// Camera samples taken (with adaptive sampling, fewer than width x height x spp).
    pub samples: u64,
    /// With adaptive sampling, the fraction of the `width x height x spp` samples that pixels
    /// did not need (0 without it).
    pub adaptive_saved: f64,
    /// Rays traced: camera, continuation and shadow rays.
    pub rays: u64,
    /// Samples dropped because their value was NaN or infinite.
    pub non_finite_samples: u64,
    /// Samples scaled down by [`RenderOptions::sample_clamp`].
    pub clamped_samples: u64,
    /// Samples that reached the film's fixed-point limit (a channel of about 4.6e18 or more):
    /// their pixels are capped. See [`Film::saturated_samples`].
    pub saturated_samples: u64,
    /// The work this render left out because the scene does not need it, each with its reason
    /// (from [`SceneFeatures::skipped`](crate::SceneFeatures::skipped), plus the lens
    /// sample of cameras that do not use it).
    pub skipped: Vec<&'static str>,
}

impl RenderStats {
    /// Millions of camera samples per second.
    #[must_use]
    pub fn msamples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }

    /// Millions of rays per second.
    #[must_use]
    pub fn mrays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }
}

impl fmt::Display for RenderStats {
    /// The summary line of DESIGN.md section 8, without the leading name.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}, {} spp", self.width, self.height, self.spp)?;
        if self.spp != self.total_spp {
            write!(
                f,
                " (samples {}..{} of {})",
                self.sample_range.start, self.sample_range.end, self.total_spp
            )?;
        }
        write!(
            f,
            ", {:.2} s, {} Msamples/s, {} Mrays/s, {} non-finite samples dropped",
            self.elapsed.as_secs_f64(),
            Sig3(self.msamples_per_second()),
            Sig3(self.mrays_per_second()),
            self.non_finite_samples
        )?;
        if self.saturated_samples > 0 {
            write!(
                f,
                ", {} samples saturated the film (radiance of 4.6e18 or more: those pixels are capped)",
                self.saturated_samples
            )?;
        }
        if self.clamped_samples > 0 {
            write!(f, ", {} samples clamped", self.clamped_samples)?;
        }
        if self.adaptive_saved > 0.0 {
            write!(
                f,
                ", adaptive: {:.1}% of samples saved",
                100.0 * self.adaptive_saved
            )?;
        }
        if !self.skipped.is_empty() {
            write!(f, ", skipped: {}", self.skipped.join(", "))?;
        }
        Ok(())
    }
}

/// A rate printed with three significant figures (at least two decimals).
struct Sig3(f64);

impl fmt::Display for Sig3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let digits = if self.0 > 0.0 && self.0.is_finite() {
            (2 - self.0.log10().floor() as i32).max(2)
        } else {
            2
        };
        write!(f, "{:.*}", digits as usize, self.0)
    }
}

/// The result of a render.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Linear RGB radiance, the mean of each pixel's samples.
    pub image: Image,
    /// Per-pixel sums and counts (for exact merging with other sample ranges).
    pub film: Film,
    /// Figures of the render.
    pub stats: RenderStats,
}

/// Render `scene` through `camera`.
///
/// ```
/// use pt_core::{render, BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, RenderOptions, Rgb, SceneBuilder};
/// use pt_core::pt_accel::TriangleMesh;
/// use pt_core::glam::Vec3;
///
/// // A glowing triangle in front of the camera.
/// let mut b = SceneBuilder::new();
/// let tri = b.add_mesh(Mesh::new(TriangleMesh::new(
///     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
///     vec![[0, 1, 2]],
/// )?));
/// let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
/// b.add_object(Object::new(tri, black).with_emission(Emission::new(Rgb::splat(2.0)).two_sided()));
/// let scene = b.build()?;
/// let camera = PinholeCamera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0)?;
/// let out = render(&scene, &camera, &RenderOptions::new(16, 16).spp(4))?;
/// assert_eq!(out.image.get(8, 8), Rgb::splat(2.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn render<M: Material, L: Light, C: Camera>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions,
) -> Result<RenderOutput, RenderError> {
    render_with_progress(scene, camera, options, &|_| {})
}

/// [`render`] with a callback invoked (from worker threads) after each finished tile.
pub fn render_with_progress<M: Material, L: Light, C: Camera>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RenderOutput, RenderError> {
    render_with_control(
        scene,
        camera,
        options,
        &RenderControl::new().progress(progress),
    )
}

/// What the caller of a render can do while it runs: watch its progress and stop it. Both
/// are optional; the library itself never prints.
///
/// ```
/// use std::sync::atomic::{AtomicBool, Ordering};
/// use pt_core::{RenderControl, RenderError, RenderOptions, render_with_control};
/// # use pt_core::{BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, Rgb, SceneBuilder};
/// # use pt_core::pt_accel::TriangleMesh;
/// # use pt_core::glam::Vec3;
/// # let mut b = SceneBuilder::new();
/// # let tri = b.add_mesh(Mesh::new(TriangleMesh::new(
/// #     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
/// #     vec![[0, 1, 2]],
/// # )?));
/// # let m = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
/// # b.add_object(Object::new(tri, m).with_emission(Emission::new(Rgb::splat(2.0))));
/// # let scene = b.build()?;
/// # let camera = PinholeCamera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0)?;
/// // Stop after the first finished tile (a user interface would set the flag from its thread).
/// let stop = AtomicBool::new(false);
/// let on_tile = |_| stop.store(true, Ordering::Relaxed);
/// let control = RenderControl::new().progress(&on_tile).cancel(&stop);
/// let result = render_with_control(&scene, &camera, &RenderOptions::new(64, 64), &control);
/// assert!(matches!(result, Err(RenderError::Cancelled)));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Default)]
#[non_exhaustive]
pub struct RenderControl<'a> {
    /// Called from worker threads after each finished tile.
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
    /// When this becomes true (set from any thread), pixels not yet rendered are skipped and
    /// the render returns [`RenderError::Cancelled`]. It is checked before every pixel.
    pub cancel: Option<&'a AtomicBool>,
}

impl<'a> RenderControl<'a> {
    /// No progress callback and no cancellation.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Call `f` after each finished tile.
    #[must_use]
    pub fn progress(mut self, f: &'a (dyn Fn(Progress) + Sync)) -> Self {
        self.progress = Some(f);
        self
    }

    /// Stop the render when `flag` becomes true.
    #[must_use]
    pub fn cancel(mut self, flag: &'a AtomicBool) -> Self {
        self.cancel = Some(flag);
        self
    }

    #[inline]
    fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

impl fmt::Debug for RenderControl<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RenderControl")
            .field("progress", &self.progress.is_some())
            .field("cancel", &self.cancel.map(|c| c.load(Ordering::Relaxed)))
            .finish()
    }
}

/// [`render`] with a [`RenderControl`]: a progress callback and a cancellation flag.
pub fn render_with_control<M: Material, L: Light, C: Camera>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions,
    control: &RenderControl<'_>,
) -> Result<RenderOutput, RenderError> {
    options.validate()?;
    let start = Instant::now();
    let sampler = options.sampler.sampler(options.seed, options.spp);
    let tiles = tiles(options.width, options.height, options.tile_size);
    let done = AtomicUsize::new(0);
    let settings = PathSettings::new(scene, options.max_depth, options.rr_depth, options.strategy);
    let job = |tile: &Tile| {
        let out = render_tile(
            scene,
            camera,
            options,
            &settings,
            sampler.clone(),
            tile,
            control,
        );
        let n = done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(progress) = control.progress {
            progress(Progress {
                tiles_done: n,
                tiles_total: tiles.len(),
            });
        }
        out
    };
    let results = run_tiles(&tiles, options.threads, job)?;
    if control.cancelled() {
        return Err(RenderError::Cancelled);
    }

    // Merge in tile order: the film does not depend on which thread finished first.
    let mut film = Film::new(options.width, options.height);
    let mut rays = 0u64;
    for (tile, (tile_film, tile_rays)) in tiles.iter().zip(&results) {
        film.add_tile(tile.x0, tile.y0, tile_film);
        rays += tile_rays;
    }
    let range = options.samples();
    let spp = range.end - range.start;
    let samples = film.total_samples();
    let full = u64::from(options.width) * u64::from(options.height) * u64::from(spp);
    let stats = RenderStats {
        width: options.width,
        height: options.height,
        spp,
        sample_range: range,
        total_spp: options.spp,
        seed: options.seed,
        elapsed: start.elapsed(),
        samples,
        adaptive_saved: if options.adaptive.is_some() {
            1.0 - samples as f64 / full as f64
        } else {
            0.0
        },
        rays,
        non_finite_samples: film.non_finite_samples(),
        clamped_samples: film.clamped_samples(),
        saturated_samples: film.saturated_samples(),
        skipped: {
            let mut s = scene.features().skipped();
            if !camera.uses_lens() {
                s.push("lens samples (pinhole camera)");
            }
            s
        },
    };
    Ok(RenderOutput {
        image: film.to_image(),
        film,
        stats,
    })
}

/// A rectangle of pixels rendered as one unit of work.
#[derive(Clone, Copy, Debug)]
struct Tile {
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
}

fn tiles(width: u32, height: u32, size: u32) -> Vec<Tile> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(size as usize) {
        for x0 in (0..width).step_by(size as usize) {
            out.push(Tile {
                x0,
                y0,
                w: size.min(width - x0),
                h: size.min(height - y0),
            });
        }
    }
    out
}

#[cfg(feature = "parallel")]
fn run_tiles<R: Send>(
    tiles: &[Tile],
    threads: Option<usize>,
    job: impl Fn(&Tile) -> R + Sync,
) -> Result<Vec<R>, RenderError> {
    use rayon::prelude::*;
    let work = || tiles.par_iter().map(&job).collect();
    match threads {
        None => Ok(work()),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| RenderError::ThreadPool(e.to_string()))?;
            Ok(pool.install(work))
        }
    }
}

#[cfg(not(feature = "parallel"))]
fn run_tiles<R: Send>(
    tiles: &[Tile],
    _threads: Option<usize>,
    job: impl Fn(&Tile) -> R + Sync,
) -> Result<Vec<R>, RenderError> {
    Ok(tiles.iter().map(job).collect())
}

fn render_tile<M: Material, L: Light, C: Camera, S: Sampler>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions,
    settings: &PathSettings,
    mut sampler: S,
    tile: &Tile,
    control: &RenderControl<'_>,
) -> (Film, u64) {
    let mut film = Film::new(tile.w, tile.h);
    let mut rays = 0u64;
    let inv = Vec2::new(1.0 / options.width as f32, 1.0 / options.height as f32);
    let aspect = options.width as f32 / options.height as f32;
    let range = options.samples();
    let uses_lens = camera.uses_lens();
    for ty in 0..tile.h {
        for tx in 0..tile.w {
            if control.cancelled() {
                return (film, rays);
            }
            let pixel = UVec2::new(tile.x0 + tx, tile.y0 + ty);
            // Running sums of the samples' luminance, for adaptive sampling's error estimate.
            let (mut taken, mut sum, mut sum_sq) = (0u32, 0.0f64, 0.0f64);
            let mut next_check = options.adaptive.map_or(u32::MAX, |a| a.min_spp);
            for index in range.clone() {
                sampler.start_pixel_sample(pixel, index);
                let film_pos = (pixel.as_vec2() + sampler.pixel_2d()) * inv;
                let lens = if uses_lens {
                    sampler.next_2d()
                } else {
                    Vec2::splat(0.5)
                };
                let ray = camera.generate_ray(&CameraSample {
                    film: film_pos,
                    aspect,
                    lens,
                });
                let l = path::radiance(scene, ray, &mut sampler, settings, &mut rays);
                match options.sample_clamp {
                    Some(max) => film.add_sample_clamped(tx, ty, l, max),
                    None => film.add_sample(tx, ty, l),
                }
                if let Some(adaptive) = &options.adaptive {
                    let y = f64::from(l.luminance());
                    if y.is_finite() {
                        sum += y;
                        sum_sq += y * y;
                    }
                    taken += 1;
                    if taken == next_check {
                        if converged(taken, sum, sum_sq, adaptive.threshold) {
                            break;
                        }
                        next_check = next_check.saturating_mul(2);
                    }
                }
            }
        }
    }
    (film, rays)
}

/// Whether a pixel's mean, from `n` samples with luminance sum `sum` and sum of squares
/// `sum_sq`, has a relative standard error below `threshold` (relative to the mean plus 0.01).
#[inline]
fn converged(n: u32, sum: f64, sum_sq: f64, threshold: f32) -> bool {
    let n = f64::from(n);
    let mean = sum / n;
    let variance = ((sum_sq - sum * mean) / (n - 1.0)).max(0.0);
    let standard_error = (variance / n).sqrt();
    standard_error < f64::from(threshold) * (mean.abs() + 0.01)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adaptive_error_estimate() {
        // Constant samples have no error; 1% noise on a mean of 1 with 100 samples has a
        // standard error of 0.1%.
        assert!(converged(16, 16.0, 16.0, 1e-6));
        let (n, mean, sd) = (100.0f64, 1.0f64, 0.01f64);
        let sum = n * mean;
        let sum_sq = (n - 1.0) * sd * sd + n * mean * mean;
        assert!(converged(100, sum, sum_sq, 0.0011));
        assert!(!converged(100, sum, sum_sq, 0.0009));
        // A dark pixel is judged against the floor of 0.01.
        assert!(!converged(4, 0.0, 0.01, 0.5));
    }

    #[test]
    fn tiles_cover_the_image_exactly_once() {
        let t = tiles(37, 20, 16);
        let area: u32 = t.iter().map(|t| t.w * t.h).sum();
        assert_eq!(area, 37 * 20);
        assert_eq!(t.len(), 3 * 2);
    }

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
    fn invalid_options_are_reported() {
        assert!(RenderOptions::new(0, 10).validate().is_err());
        assert!(RenderOptions::new(10, 10).spp(0).validate().is_err());
        assert!(RenderOptions::new(10, 10).tile_size(0).validate().is_err());
        assert!(
            RenderOptions::new(10, 10)
                .threads(Some(0))
                .validate()
                .is_err()
        );
        assert!(RenderOptions::new(10, 10).validate().is_ok());
        let o = RenderOptions::new(10, 10).spp(8);
        assert!(o.clone().spp_range(0..8).validate().is_ok());
        assert!(o.clone().spp_range(4..4).validate().is_err());
        assert!(o.clone().spp_range(4..9).validate().is_err());
        assert!(o.clone().sample_clamp(Some(0.0)).validate().is_err());
        assert!(o.clone().sample_clamp(Some(f32::NAN)).validate().is_err());
        assert!(o.clone().sample_clamp(Some(10.0)).validate().is_ok());
        let a = |t, m| Some(AdaptiveSampling::new(t, m));
        assert!(o.clone().adaptive(a(0.01, 4)).validate().is_ok());
        assert!(o.clone().adaptive(a(0.0, 4)).validate().is_err());
        assert!(o.clone().adaptive(a(0.01, 1)).validate().is_err());
        assert!(o.clone().adaptive(a(0.01, 9)).validate().is_err());
        assert!(o.adaptive(a(0.01, 4)).spp_range(0..4).validate().is_err());
    }
}
