//! Ideal specular reflection: a perfect, optionally tinted mirror.
//!
//! Reference: *Physically Based Rendering*, 4th ed., section 9.4 (the smooth case of
//! `ConductorBxDF`).
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `reflectance` | fraction of energy reflected, per channel, at every angle | `[0, 1]` |
//!
//! A single delta lobe in the mirror direction `(-wo.x, -wo.y, wo.z)`, on both sides of the
//! surface. `eval` and `pdf` are zero; `sample` returns the lobe with probability one and
//! `f = R / |cos theta_i|`, so the path throughput is multiplied by exactly `R`. Unlike
//! [`RoughConductor`](super::RoughConductor) at roughness 0 there is no Fresnel term: the
//! reflectance is the same at every angle, which is what "ideal mirror" means in the report.

use glam::{Vec2, Vec3};

use crate::bsdf::clamp_unit;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, SampleInputs, TransportMode};
use crate::color::Rgb;

/// A perfect mirror with reflectance `reflectance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularReflection {
    reflectance: Rgb,
}

impl SpecularReflection {
    /// A mirror. Channels are clamped to `[0, 1]`; NaN becomes 0.
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Self {
            reflectance: clamp_unit(reflectance),
        }
    }

    /// The reflectance.
    #[must_use]
    pub fn reflectance(&self) -> Rgb {
        self.reflectance
    }
}

impl Bsdf for SpecularReflection {
    #[inline]
    fn sample_inputs(&self) -> SampleInputs {
        SampleInputs::NONE
    }

    #[inline]
    fn flags(&self) -> BsdfFlags {
        if self.reflectance.is_black() {
            BsdfFlags::NONE
        } else {
            BsdfFlags::SPECULAR_REFLECTION
        }
    }

    #[inline]
    fn eval(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> Rgb {
        Rgb::BLACK
    }

    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3, _uc: f32, _u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 || self.reflectance.is_black() {
            return None;
        }
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        Some(BsdfSample {
            wi,
            f: self.reflectance / wi.z.abs(),
            pdf: 1.0,
            flags: BsdfFlags::SPECULAR_REFLECTION,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflects_about_the_normal_on_both_sides() {
        let m = SpecularReflection::new(Rgb::new(0.9, 0.8, 0.7));
        for wo in [
            Vec3::new(0.3, -0.2, 0.9).normalize(),
            Vec3::new(0.3, -0.2, -0.9).normalize(),
        ] {
            let s = m
                .sample(wo, 0.3, Vec2::splat(0.5), TransportMode::Radiance)
                .unwrap();
            assert!((s.wi + wo - Vec3::new(0.0, 0.0, 2.0 * wo.z)).length() < 1e-6);
            let w = s.f * s.wi.z.abs() / s.pdf;
            assert!((w - Rgb::new(0.9, 0.8, 0.7)).max_component().abs() < 1e-6);
        }
        assert!(
            m.sample(Vec3::X, 0.3, Vec2::ZERO, TransportMode::Radiance)
                .is_none()
        );
        assert!(SpecularReflection::new(Rgb::BLACK).flags().is_empty());
    }
}
