//! Choosing the sampler of a render: the built-in [`SamplerKind`]s, and [`SamplerFactory`] for
//! a user's own.

use crate::sampler::{
    BuiltinSampler, IndependentSampler, Sampler, SobolSampler, StratifiedSampler,
};

/// Makes the sampler of one render from its seed and samples per pixel; the render clones it
/// once per tile. [`SamplerKind`] is the factory of the built-in samplers; implement this for
/// a sampler of your own and pass it to [`RenderOptions::sampler`](crate::RenderOptions::sampler).
///
/// ```
/// use pt_core::glam::{UVec2, Vec2};
/// use pt_core::{IndependentSampler, RenderOptions, Sampler, SamplerFactory};
///
/// /// Independent random numbers, with the pixel position always at the pixel's centre.
/// #[derive(Clone)]
/// struct Centred(IndependentSampler);
///
/// impl Sampler for Centred {
///     fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
///         self.0.start_pixel_sample(pixel, index);
///     }
///     fn next_1d(&mut self) -> f32 {
///         self.0.next_1d()
///     }
///     fn next_2d(&mut self) -> Vec2 {
///         self.0.next_2d()
///     }
///     fn pixel_2d(&mut self) -> Vec2 {
///         Vec2::splat(0.5)
///     }
/// }
///
/// struct CentredSamples;
///
/// impl SamplerFactory for CentredSamples {
///     type Sampler = Centred;
///     fn sampler(&self, seed: u64, _spp: u32) -> Centred {
///         Centred(IndependentSampler::new(seed))
///     }
/// }
///
/// let options = RenderOptions::new(64, 64).sampler(CentredSamples);
/// // `render(&scene, &camera, &options, None)` now draws every sample from `Centred`.
/// # let _ = options;
/// ```
pub trait SamplerFactory: Sync {
    /// The sampler made.
    type Sampler: Sampler;

    /// The sampler of a render with `spp` samples per pixel and `seed`.
    fn sampler(&self, seed: u64, spp: u32) -> Self::Sampler;

    /// The built-in sampler this factory makes, if it is one (the lane path tracer draws from
    /// those itself). Not for use outside pt.
    #[doc(hidden)]
    fn builtin_kind(&self) -> Option<SamplerKind> {
        None
    }

    /// [`Material::render_scene`](crate::Material::render_scene)'s last step, for a scene of
    /// the built-in materials and lights through a pinhole camera: the renderer compiled in the
    /// calling crate (the default), or for [`SamplerKind`] the copy compiled in pt-core
    /// ([`render_builtin`](crate::render_builtin)). Not for use outside pt.
    #[doc(hidden)]
    fn render_builtin_pinhole(
        scene: &crate::Scene,
        camera: &crate::PinholeCamera,
        options: &crate::RenderOptions<Self>,
        control: Option<&crate::render::RenderControl<'_>>,
    ) -> Result<crate::render::RenderOutput, crate::render::RenderError>
    where
        Self: Sized,
    {
        crate::render::render_generic(scene, camera, options, control)
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
    /// Jittered stratified samples ([`StratifiedSampler`]): each draw is stratified over
    /// the pixel's samples.
    Stratified,
    /// Owen-scrambled Sobol points ([`SobolSampler`]); best with power-of-two spp. The
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

impl SamplerFactory for SamplerKind {
    type Sampler = BuiltinSampler;

    fn sampler(&self, seed: u64, spp: u32) -> BuiltinSampler {
        SamplerKind::sampler(*self, seed, spp)
    }

    fn builtin_kind(&self) -> Option<SamplerKind> {
        Some(*self)
    }

    fn render_builtin_pinhole(
        scene: &crate::Scene,
        camera: &crate::PinholeCamera,
        options: &crate::RenderOptions,
        control: Option<&crate::render::RenderControl<'_>>,
    ) -> Result<crate::render::RenderOutput, crate::render::RenderError> {
        crate::render::render_builtin(scene, camera, options, control)
    }
}
