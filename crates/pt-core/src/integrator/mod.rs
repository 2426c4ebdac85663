//! Light transport: the integrators that estimate the radiance arriving along a camera ray.
//!
//! `path.rs` holds the path tracer: unidirectional, with next-event estimation, multiple
//! importance sampling and Russian roulette, as the textbook loop. The render driver
//! ([`crate::render`](mod@crate::render)) is generic over the crate's `Integrator` trait, so a second integrator
//! (one tracing SIMD lanes of paths, say) plugs in beside it without touching the scheduler.
//! [`LightStrategy`] chooses how the path tracer finds direct light.

mod lanes;
mod path;

use pt_accel::Ray;

use crate::aov::AovRecord;
use crate::color::Rgb;
use crate::light::Light;
use crate::material::Material;
use crate::sampler::Sampler;
use crate::scene::Scene;

pub(crate) use lanes::{LaneTile, LaneTracer};
pub(crate) use path::PathTracer;

/// Estimates the radiance arriving along a ray: what the render driver calls for every sample.
pub(crate) trait Integrator<M: Material, L: Light>: Sync {
    /// The radiance arriving along `ray` (one sample of it), drawing from `sampler` and adding
    /// the rays traced to `rays`; the first non-specular hit's albedo and normal go to `aov`.
    fn radiance<S: Sampler, A: AovRecord>(
        &self,
        scene: &Scene<M, L>,
        ray: Ray,
        sampler: &mut S,
        rays: &mut u64,
        aov: &mut A,
    ) -> Rgb;
}

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
