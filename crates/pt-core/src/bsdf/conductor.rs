//! Conductors (metals): GGX microfacet reflection with Smith masking-shadowing, from a mirror at
//! roughness 0 to a very rough metal at 1.
//!
//! References: Walter et al., "Microfacet Models for Refraction through Rough Surfaces", EGSR
//! 2007 (the Torrance-Sparrow form with GGX); Heitz, "Sampling the GGX Distribution of Visible
//! Normals", JCGT 2018; *Physically Based Rendering*, 4th ed., section 9.6 (`ConductorBxDF`).
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `distribution` | GGX widths `alpha_x`, `alpha_y` (`alpha = roughness^2`) | `[0, 1]` each |
//! | `fresnel` | [`ConductorFresnel::Schlick`] with a tint `F0`, or [`ConductorFresnel::Complex`] with a measured complex IOR `eta + i k` per channel | `F0` in `[0, 1]`; `eta`, `k` finite and `>= 0` |
//!
//! `f = D(wm) G(wo, wi) F(wo . wm) / (4 |cos theta_o| |cos theta_i|)` with `wm` the half vector;
//! directions are drawn from the visible normals seen from `wo`, so
//! `pdf = D_wo(wm) / (4 |wo . wm|)` and the sample weight `f cos / pdf = F G / G1(wo)` never
//! exceeds one. Below [`SMOOTH_ALPHA`](super::microfacet::SMOOTH_ALPHA) the lobe becomes a delta
//! (a Fresnel-weighted mirror). The model is two-sided and single-scattering: it loses the energy
//! of light bouncing between microfacets (up to ~60% at roughness 1 and grazing incidence).

use glam::{Vec2, Vec3};

use crate::bsdf::fresnel::{fresnel_conductor, fresnel_schlick, reflect};
use crate::bsdf::microfacet::TrowbridgeReitz;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, SampleInputs, TransportMode, same_hemisphere};
use crate::color::Rgb;

/// How a conductor's reflectance varies with the angle of incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum ConductorFresnel {
    /// Schlick's approximation from the reflectance at normal incidence `F0` (an artist's tint).
    Schlick(Rgb),
    /// The exact Fresnel equations for a complex index of refraction `eta + i k` per channel,
    /// relative to the outside medium.
    Complex {
        /// Real part.
        eta: Rgb,
        /// Imaginary part (absorption).
        k: Rgb,
    },
}

impl ConductorFresnel {
    /// Gold (complex IOR sampled at 650, 550 and 450 nm from published measurements).
    pub const GOLD: Self = Self::Complex {
        eta: Rgb::new(0.143, 0.374, 1.442),
        k: Rgb::new(3.983, 2.385, 1.603),
    };
    /// Silver.
    pub const SILVER: Self = Self::Complex {
        eta: Rgb::new(0.155, 0.117, 0.138),
        k: Rgb::new(4.828, 3.122, 2.147),
    };
    /// Copper.
    pub const COPPER: Self = Self::Complex {
        eta: Rgb::new(0.200, 0.924, 1.102),
        k: Rgb::new(3.912, 2.452, 2.142),
    };
    /// Aluminium.
    pub const ALUMINIUM: Self = Self::Complex {
        eta: Rgb::new(1.657, 0.880, 0.521),
        k: Rgb::new(9.224, 6.270, 4.837),
    };

    /// Reflectance for `cos_i = |wo . wm|` in `[0, 1]`.
    #[inline]
    #[must_use]
    pub fn eval(&self, cos_i: f32) -> Rgb {
        match *self {
            Self::Schlick(f0) => fresnel_schlick(cos_i, f0),
            Self::Complex { eta, k } => fresnel_conductor(cos_i, eta, k),
        }
    }

    /// The same model with every parameter made valid: `F0` clamped to `[0, 1]` (NaN becomes 0),
    /// `eta` to at least `1e-4` and `k` to at least 0 (non-finite values become 1 and 0).
    #[must_use]
    pub fn sanitized(self) -> Self {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let at_least = |lo: f32, d: f32| move |v: f32| if v.is_finite() { v.max(lo) } else { d };
        match self {
            Self::Schlick(f0) => Self::Schlick(f0.map(unit)),
            Self::Complex { eta, k } => Self::Complex {
                eta: eta.map(at_least(MIN_ETA, 1.0)),
                k: k.map(at_least(0.0, 0.0)),
            },
        }
    }
}

/// The smallest real part of a conductor's IOR: `eta = k = 0` would divide by zero.
const MIN_ETA: f32 = 1e-4;

/// Rough (or, below the smoothness threshold, perfectly smooth) conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    distribution: TrowbridgeReitz,
    fresnel: ConductorFresnel,
}

/// `w` moved to the upper hemisphere by mirroring about the tangent plane (a symmetry of the
/// isotropic and anisotropic GGX alike), so the model is two-sided.
#[inline]
fn upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

impl RoughConductor {
    /// A conductor with the given microfacet distribution and Fresnel model (sanitised with
    /// [`ConductorFresnel::sanitized`]).
    #[must_use]
    pub fn new(distribution: TrowbridgeReitz, fresnel: ConductorFresnel) -> Self {
        Self {
            distribution,
            fresnel: fresnel.sanitized(),
        }
    }

    /// The microfacet distribution.
    #[must_use]
    pub fn distribution(&self) -> TrowbridgeReitz {
        self.distribution
    }

    /// The Fresnel model.
    #[must_use]
    pub fn fresnel(&self) -> ConductorFresnel {
        self.fresnel
    }
}

impl Bsdf for RoughConductor {
    #[inline]
    fn sample_inputs(&self) -> SampleInputs {
        SampleInputs::DIRECTION
    }

    #[inline]
    fn flags(&self) -> BsdfFlags {
        if self.distribution.effectively_smooth() {
            BsdfFlags::SPECULAR_REFLECTION
        } else {
            BsdfFlags::GLOSSY_REFLECTION
        }
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !same_hemisphere(wo, wi) || self.distribution.effectively_smooth() {
            return Rgb::BLACK;
        }
        let (wo, wi) = (upper(wo), upper(wi));
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return Rgb::BLACK;
        }
        let wm = wm.normalize();
        let d = &self.distribution;
        self.fresnel.eval(wo.dot(wm).abs()) * (d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z))
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if !same_hemisphere(wo, wi) || self.distribution.effectively_smooth() {
            return 0.0;
        }
        let (wo, wi) = (upper(wo), upper(wi));
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        self.distribution.pdf(wo, wm) / (4.0 * wo.dot(wm).abs())
    }

    #[inline]
    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.distribution.effectively_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let f = self.fresnel.eval(wo.z.abs()) / wi.z.abs();
            return Some(BsdfSample {
                wi,
                f,
                pdf: 1.0,
                flags: BsdfFlags::SPECULAR_REFLECTION,
                eta: 1.0,
            });
        }
        let flip = wo.z < 0.0;
        let wo_u = upper(wo);
        let d = &self.distribution;
        let wm = d.sample_wm(wo_u, u);
        let mut wi = reflect(wo_u, wm);
        if wi.z <= 0.0 {
            return None;
        }
        let cos_om = wo_u.dot(wm).abs();
        let pdf = d.pdf(wo_u, wm) / (4.0 * cos_om);
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        let f = self.fresnel.eval(cos_om) * (d.d(wm) * d.g(wo_u, wi) / (4.0 * wo_u.z * wi.z));
        if flip {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            flags: BsdfFlags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_conductor_is_a_fresnel_mirror() {
        let c = RoughConductor::new(TrowbridgeReitz::isotropic(0.0), ConductorFresnel::GOLD);
        assert_eq!(c.flags(), BsdfFlags::SPECULAR_REFLECTION);
        let wo = Vec3::new(0.0, 0.6, 0.8);
        let s = c
            .sample(wo, 0.5, Vec2::splat(0.5), TransportMode::Radiance)
            .unwrap();
        assert_eq!(s.wi, Vec3::new(0.0, -0.6, 0.8));
        let w = s.f * s.wi.z / s.pdf;
        assert!((w - ConductorFresnel::GOLD.eval(0.8)).max_component().abs() < 1e-6);
    }

    #[test]
    fn rough_sample_matches_eval_from_both_sides() {
        let c = RoughConductor::new(
            TrowbridgeReitz::new(0.3, 0.15),
            ConductorFresnel::Schlick(Rgb::new(0.9, 0.6, 0.3)),
        );
        for wo in [
            Vec3::new(0.4, 0.2, 0.8).normalize(),
            Vec3::new(0.4, 0.2, -0.8).normalize(),
        ] {
            let s = c
                .sample(wo, 0.5, Vec2::new(0.3, 0.8), TransportMode::Radiance)
                .unwrap();
            assert!(same_hemisphere(wo, s.wi));
            let f = c.eval(wo, s.wi, TransportMode::Radiance);
            let pdf = c.pdf(wo, s.wi, TransportMode::Radiance);
            assert!((f - s.f).max_component().abs() < 1e-4 * f.max_component());
            assert!((pdf - s.pdf).abs() < 1e-4 * pdf);
        }
    }

    #[test]
    fn invalid_fresnel_parameters_are_sanitized() {
        let c = RoughConductor::new(
            TrowbridgeReitz::isotropic(0.5),
            ConductorFresnel::Complex {
                eta: Rgb::new(f32::NAN, -1.0, 1.0),
                k: Rgb::new(f32::INFINITY, 1.0, -2.0),
            },
        );
        assert_eq!(
            c.fresnel(),
            ConductorFresnel::Complex {
                eta: Rgb::new(1.0, MIN_ETA, 1.0),
                k: Rgb::new(0.0, 1.0, 0.0),
            }
        );
        assert!(c.fresnel().eval(0.5).is_finite());
    }
}
