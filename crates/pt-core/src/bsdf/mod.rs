//! Bidirectional scattering distribution functions.
//!
//! # Conventions
//!
//! Every BSDF works in the **local shading frame**: `z` is the shading normal, `x` and `y` span
//! the tangent plane (see [`Frame`](crate::Frame)). Both `wo` (toward the viewer, the direction
//! light leaves in) and `wi` (toward the light, the direction light arrives from) are unit vectors
//! **pointing away from the surface**. A direction with `z > 0` is on the side the normal points
//! to; BSDFs must handle `wo` on either side (for example a ray hitting glass from inside).
//!
//! - [`Bsdf::eval`] returns `f(wo, wi)` **without** the cosine factor `|cos theta_i|`.
//! - [`Bsdf::pdf`] is the density of [`Bsdf::sample`] returning `wi`, **per unit solid angle**.
//!   Both are zero for delta (specular) lobes, which only `sample` can produce.
//! - [`Bsdf::sample`] draws `wi` from `uc` (one value, used to choose between lobes) and `u`
//!   (two values, used inside the lobe), and returns `None` when it fails (no lobe, the sample is
//!   below the surface for a reflection-only model, ...). For a non-delta lobe it returns
//!   `f = eval(wo, wi)` and `pdf = pdf(wo, wi)`. For a delta lobe `pdf` is the discrete
//!   probability of choosing that lobe and `f` is the lobe's weight divided by `|cos theta_i|`,
//!   so that `f * |cos theta_i| / pdf` is always the path throughput factor.
//! - [`TransportMode`] says whether radiance (paths traced from the camera) or importance (paths
//!   traced from lights) is carried; non-symmetric BSDFs (refraction) scale differently.
//!
//! # Adding a model
//!
//! A built-in model is a plain struct in its own file implementing [`Bsdf`], a `mod` and `pub use`
//! here and at the crate root, a variant of [`BuiltinBsdf`], a material that produces it, and
//! entries in the registry (`testing/registry.rs`: statistical cases, a benchmark instance);
//! CONTRIBUTING.md lists the steps, and the crate's `tests/registry.rs` fails while a variant
//! has no registry entries. Users compose their own models with the built-ins through
//! [`bsdf_enum!`](crate::bsdf_enum), with no edits here.

mod conductor;
mod dielectric;
pub mod fresnel;
mod lambertian;
mod metallic_roughness;
pub mod microfacet;
mod mirror;
mod rough_dielectric;
mod thin_film;

use std::fmt;
use std::ops::BitOr;

use glam::{Vec2, Vec3};

use crate::color::Rgb;

pub use conductor::{ConductorFresnel, RoughConductor};
pub use dielectric::SmoothDielectric;
pub use lambertian::Lambertian;
pub use metallic_roughness::MetallicRoughness;
pub use microfacet::TrowbridgeReitz;
pub use mirror::SpecularReflection;
pub use rough_dielectric::RoughDielectric;
pub use thin_film::{ThinFilm, thin_film_fresnel};

/// Which quantity a path carries, for BSDFs whose adjoint differs (refraction).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TransportMode {
    /// Paths start at the camera and carry radiance (the path tracer).
    #[default]
    Radiance,
    /// Paths start at lights and carry importance (light tracing, photon mapping).
    Importance,
}

/// Properties of a BSDF or of one sampled lobe: reflection and/or transmission, and
/// diffuse, glossy or specular (delta).
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    /// Scatters nothing.
    pub const NONE: Self = Self(0);
    /// Scatters into the hemisphere of `wo`.
    pub const REFLECTION: Self = Self(1);
    /// Scatters into the opposite hemisphere.
    pub const TRANSMISSION: Self = Self(2);
    /// A smooth, wide lobe (Lambertian-like).
    pub const DIFFUSE: Self = Self(4);
    /// A lobe with a finite but peaked density.
    pub const GLOSSY: Self = Self(8);
    /// A Dirac delta lobe: only sampling can find it.
    pub const SPECULAR: Self = Self(16);

    /// Diffuse reflection.
    pub const DIFFUSE_REFLECTION: Self = Self(1 | 4);
    /// Glossy reflection.
    pub const GLOSSY_REFLECTION: Self = Self(1 | 8);
    /// Specular reflection.
    pub const SPECULAR_REFLECTION: Self = Self(1 | 16);
    /// Glossy transmission.
    pub const GLOSSY_TRANSMISSION: Self = Self(2 | 8);
    /// Specular transmission.
    pub const SPECULAR_TRANSMISSION: Self = Self(2 | 16);

    /// True when every flag of `other` is set.
    #[inline]
    #[must_use]
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// True when no flag is set (the BSDF scatters nothing).
    #[inline]
    #[must_use]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Has a reflection lobe.
    #[inline]
    #[must_use]
    pub const fn is_reflective(self) -> bool {
        self.0 & 1 != 0
    }

    /// Has a transmission lobe.
    #[inline]
    #[must_use]
    pub const fn is_transmissive(self) -> bool {
        self.0 & 2 != 0
    }

    /// Has a diffuse lobe.
    #[inline]
    #[must_use]
    pub const fn is_diffuse(self) -> bool {
        self.0 & 4 != 0
    }

    /// Has a glossy lobe.
    #[inline]
    #[must_use]
    pub const fn is_glossy(self) -> bool {
        self.0 & 8 != 0
    }

    /// Has a delta lobe.
    #[inline]
    #[must_use]
    pub const fn is_specular(self) -> bool {
        self.0 & 16 != 0
    }

    /// Has a lobe that `eval`/`pdf` can see (diffuse or glossy): light sampling is useful.
    #[inline]
    #[must_use]
    pub const fn is_non_specular(self) -> bool {
        self.0 & (4 | 8) != 0
    }
}

impl BitOr for BsdfFlags {
    type Output = Self;
    #[inline]
    fn bitor(self, o: Self) -> Self {
        Self(self.0 | o.0)
    }
}

impl fmt::Debug for BsdfFlags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = [
            "Reflection",
            "Transmission",
            "Diffuse",
            "Glossy",
            "Specular",
        ];
        let set: Vec<&str> = (0..5)
            .filter(|i| self.0 & (1 << i) != 0)
            .map(|i| names[i])
            .collect();
        write!(
            f,
            "BsdfFlags({})",
            if set.is_empty() {
                "None".into()
            } else {
                set.join("|")
            }
        )
    }
}

/// A direction drawn by [`Bsdf::sample`], with its value and density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Sampled incident direction, local frame, unit length, pointing away from the surface.
    pub wi: Vec3,
    /// `f(wo, wi)` (for a delta lobe: the lobe weight over `|cos theta_i|`).
    pub f: Rgb,
    /// Solid-angle density (for a delta lobe: the probability of choosing the lobe).
    pub pdf: f32,
    /// The kind of lobe that was sampled (exactly one of reflection/transmission).
    pub flags: BsdfFlags,
    /// Relative index of refraction across the interface for a transmission sample
    /// (`eta_i / eta_t` convention of the model), 1 otherwise.
    pub eta: f32,
}

impl BsdfSample {
    /// True when the sampled lobe is a delta lobe.
    #[inline]
    #[must_use]
    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }

    /// True when the sample crosses the surface.
    #[inline]
    #[must_use]
    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmissive()
    }
}

/// Which of [`Bsdf::sample`]'s random numbers a BSDF reads.
///
/// The path tracers draw from their sampler only the numbers a BSDF reads, so that no sampler
/// dimension (and no hashing) is spent on one that nobody looks at: a Lambertian surface takes
/// the direction's two, a mirror none, smooth glass only the lobe choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleInputs {
    /// `uc`, which chooses a lobe.
    pub uc: bool,
    /// `u`, which places the direction within the lobe.
    pub u: bool,
}

impl SampleInputs {
    /// Both numbers (the default, always correct).
    pub const ALL: Self = Self { uc: true, u: true };
    /// Neither (a single delta lobe).
    pub const NONE: Self = Self {
        uc: false,
        u: false,
    };
    /// Only the lobe choice `uc` (delta lobes chosen between).
    pub const LOBE: Self = Self { uc: true, u: false };
    /// Only the direction `u` (a single lobe).
    pub const DIRECTION: Self = Self { uc: false, u: true };
    /// What an integrator passes for a number it did not draw.
    pub const UNDRAWN: f32 = 0.5;
}

/// A BSDF in its local shading frame. See the [module documentation](self) for the conventions.
pub trait Bsdf {
    /// The lobes this BSDF has. Empty when it scatters nothing (the path ends there).
    fn flags(&self) -> BsdfFlags;

    /// `f(wo, wi)` without the cosine factor; zero for delta lobes.
    fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb;

    /// Solid-angle density of [`sample`](Self::sample) producing `wi`; zero for delta lobes.
    fn pdf(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32;

    /// Draw an incident direction. `uc` chooses a lobe, `u` places the direction within it.
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample>;

    /// Which of [`sample`](Self::sample)'s numbers this BSDF reads; the others may be anything
    /// (integrators pass [`SampleInputs::UNDRAWN`]) and must not change the sample. The default,
    /// both, is always correct. The test harness's `check_consistency` holds a model to what it
    /// declares.
    #[inline]
    fn sample_inputs(&self) -> SampleInputs {
        SampleInputs::ALL
    }
}

/// `cos theta` of a local direction.
#[inline]
#[must_use]
pub fn cos_theta(w: Vec3) -> f32 {
    w.z
}

/// `|cos theta|` of a local direction.
#[inline]
#[must_use]
pub fn abs_cos_theta(w: Vec3) -> f32 {
    w.z.abs()
}

/// Each channel clamped to `[0, 1]`, NaN to 0: what a reflectance or transmittance may be.
#[inline]
#[must_use]
pub(crate) fn clamp_unit(c: Rgb) -> Rgb {
    c.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
}

/// True when two local directions lie on the same side of the surface.
#[inline]
#[must_use]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// The `VARIANTS` list and `variant_name` of an enum defined by [`bsdf_enum!`],
/// [`light_enum!`](crate::light_enum) or [`material_enum!`](crate::material_enum).
#[doc(hidden)]
#[macro_export]
macro_rules! __variant_names {
    ($vis:vis $name:ident { $($variant:ident),+ }) => {
        impl $name {
            /// The names of the variants, in the order they are declared (for registries and
            /// tests that must cover every model).
            #[allow(dead_code)]
            $vis const VARIANTS: &'static [&'static str] = &[$(stringify!($variant)),+];

            /// The name of this value's variant, one of [`Self::VARIANTS`].
            #[allow(dead_code)]
            #[must_use]
            $vis fn variant_name(&self) -> &'static str {
                match self { $( Self::$variant(_) => stringify!($variant), )+ }
            }
        }
    };
}

/// Define an enum over BSDF types with a statically dispatched [`Bsdf`] impl (one `match` per
/// method, inlined) and a `From` impl per variant.
///
/// This is how [`BuiltinBsdf`] is made, and how a user adds a model without `dyn`: wrap the
/// built-in enum as one variant and the new model as another.
///
/// ```
/// use pt_core::{bsdf_enum, BuiltinBsdf, Lambertian, Rgb};
///
/// bsdf_enum! {
///     /// The built-in BSDFs plus a second Lambertian standing in for a user model.
///     #[derive(Clone, Debug)]
///     pub enum MyBsdf {
///         Builtin(BuiltinBsdf),
///         Other(Lambertian),
///     }
/// }
/// let b: MyBsdf = Lambertian::new(Rgb::splat(0.5)).into();
/// # let _ = b;
/// ```
#[macro_export]
macro_rules! bsdf_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident($ty:ty) ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $name {
            $( $(#[$vmeta])* #[allow(missing_docs)] $variant($ty), )+
        }

        $crate::__variant_names!($vis $name { $($variant),+ });

        // The dispatch is always inlined: the path loop is past LLVM's inlining budget, which
        // otherwise calls these (every bounce) out of line (callgrind on the Cornell box: 2%
        // more instructions per sample when the loop grew by the AOV recorder).
        impl $crate::bsdf::Bsdf for $name {
            #[inline(always)]
            fn flags(&self) -> $crate::bsdf::BsdfFlags {
                match self { $( Self::$variant(b) => $crate::bsdf::Bsdf::flags(b), )+ }
            }
            #[inline(always)]
            fn eval(
                &self,
                wo: $crate::glam::Vec3,
                wi: $crate::glam::Vec3,
                mode: $crate::bsdf::TransportMode,
            ) -> $crate::Rgb {
                match self { $( Self::$variant(b) => $crate::bsdf::Bsdf::eval(b, wo, wi, mode), )+ }
            }
            #[inline(always)]
            fn pdf(
                &self,
                wo: $crate::glam::Vec3,
                wi: $crate::glam::Vec3,
                mode: $crate::bsdf::TransportMode,
            ) -> f32 {
                match self { $( Self::$variant(b) => $crate::bsdf::Bsdf::pdf(b, wo, wi, mode), )+ }
            }
            #[inline(always)]
            fn sample(
                &self,
                wo: $crate::glam::Vec3,
                uc: f32,
                u: $crate::glam::Vec2,
                mode: $crate::bsdf::TransportMode,
            ) -> Option<$crate::bsdf::BsdfSample> {
                match self { $( Self::$variant(b) => $crate::bsdf::Bsdf::sample(b, wo, uc, u, mode), )+ }
            }
            #[inline(always)]
            fn sample_inputs(&self) -> $crate::bsdf::SampleInputs {
                match self { $( Self::$variant(b) => $crate::bsdf::Bsdf::sample_inputs(b), )+ }
            }
        }

        $(
            impl From<$ty> for $name {
                #[inline]
                fn from(b: $ty) -> Self {
                    Self::$variant(b)
                }
            }
        )+
    };
}

bsdf_enum! {
    /// The BSDFs that ship with pt.
    #[derive(Clone, Debug, PartialEq)]
    #[non_exhaustive]
    pub enum BuiltinBsdf {
        /// Ideal diffuse reflection.
        Lambertian(Lambertian),
        /// Ideal mirror.
        SpecularReflection(SpecularReflection),
        /// GGX conductor, smooth to rough.
        RoughConductor(RoughConductor),
        /// Smooth glass.
        SmoothDielectric(SmoothDielectric),
        /// GGX glass.
        RoughDielectric(RoughDielectric),
        /// glTF's metallic-roughness model: a metal and a Fresnel-layered dielectric, mixed.
        MetallicRoughness(MetallicRoughness),
    }
}
