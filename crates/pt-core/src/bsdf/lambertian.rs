//! Ideal diffuse (Lambertian) reflection.
//!
//! Reference: *Physically Based Rendering*, 4th ed., section 9.2 (`DiffuseBxDF`).
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `reflectance` | albedo R: fraction of incident energy reflected, per channel | `[0, 1]` |
//!
//! `f = R / pi` for `wo` and `wi` on the same side of the surface (either side: the model is
//! two-sided), sampled with a cosine-weighted hemisphere so `f cos / pdf = R` exactly.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use crate::bsdf::clamp_unit;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, SampleInputs, TransportMode, same_hemisphere};
use crate::color::Rgb;
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// Ideal diffuse reflection with albedo `reflectance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambertian {
    reflectance: Rgb,
}

impl Lambertian {
    /// A Lambertian reflector. Channels are clamped to `[0, 1]` (energy conservation); NaN
    /// becomes 0.
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Self {
            reflectance: clamp_unit(reflectance),
        }
    }

    /// The albedo.
    #[must_use]
    pub fn reflectance(&self) -> Rgb {
        self.reflectance
    }
}

impl Bsdf for Lambertian {
    #[inline]
    fn sample_inputs(&self) -> SampleInputs {
        SampleInputs::DIRECTION
    }

    #[inline]
    fn flags(&self) -> BsdfFlags {
        if self.reflectance.is_black() {
            BsdfFlags::NONE
        } else {
            BsdfFlags::DIFFUSE_REFLECTION
        }
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if same_hemisphere(wo, wi) {
            self.reflectance * FRAC_1_PI
        } else {
            Rgb::BLACK
        }
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if same_hemisphere(wo, wi) {
            cosine_hemisphere_pdf(wi.z.abs())
        } else {
            0.0
        }
    }

    #[inline]
    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if self.reflectance.is_black() || wo.z == 0.0 {
            return None;
        }
        let mut wi = sample_cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = cosine_hemisphere_pdf(wi.z.abs());
        if pdf == 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.reflectance * FRAC_1_PI,
            pdf,
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_matches_eval_and_pdf_on_both_sides() {
        let b = Lambertian::new(Rgb::new(0.2, 0.5, 0.8));
        for wo in [
            Vec3::new(0.3, 0.1, 0.9).normalize(),
            Vec3::new(0.3, 0.1, -0.9).normalize(),
        ] {
            let s = b
                .sample(wo, 0.5, Vec2::new(0.3, 0.7), TransportMode::Radiance)
                .unwrap();
            assert!(same_hemisphere(wo, s.wi));
            assert_eq!(s.f, b.eval(wo, s.wi, TransportMode::Radiance));
            assert_eq!(s.pdf, b.pdf(wo, s.wi, TransportMode::Radiance));
            // Throughput is exactly the albedo.
            let w = s.f * s.wi.z.abs() / s.pdf;
            assert!((w - Rgb::new(0.2, 0.5, 0.8)).max_component().abs() < 1e-5);
        }
        assert!(
            b.eval(Vec3::Z, -Vec3::Z, TransportMode::Radiance)
                .is_black()
        );
    }

    #[test]
    fn black_and_invalid_reflectance() {
        assert!(Lambertian::new(Rgb::BLACK).flags().is_empty());
        assert_eq!(
            Lambertian::new(Rgb::new(2.0, f32::NAN, -1.0)).reflectance(),
            Rgb::new(1.0, 0.0, 0.0)
        );
    }
}
