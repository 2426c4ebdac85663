//! The uniform environment: the same radiance from every direction.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};
use pt_accel::{Bounds3, Ray};

use crate::color::Rgb;
use crate::light::environment::placement::Placement;
use crate::light::{Light, LightError, LightFlags, LightSample, LightSampleContext};
use crate::sampling::{sample_uniform_sphere, uniform_sphere_pdf};

/// Radiance `radiance` from every direction.
#[derive(Clone, Debug, PartialEq)]
pub struct UniformEnvironment {
    radiance: Rgb,
    place: Placement,
}

impl UniformEnvironment {
    /// A uniform environment. Fails unless every channel is finite and non-negative.
    pub fn new(radiance: Rgb) -> Result<Self, LightError> {
        if !radiance.is_valid_nonnegative() {
            return Err(LightError::BadParameter(format!(
                "radiance must be finite and >= 0, got {radiance:?}"
            )));
        }
        Ok(Self {
            radiance,
            place: Placement::new(),
        })
    }

    /// The radiance.
    #[must_use]
    pub fn radiance(&self) -> Rgb {
        self.radiance
    }
}

impl Light for UniformEnvironment {
    fn flags(&self) -> LightFlags {
        LightFlags::INFINITE
    }

    fn power(&self) -> Rgb {
        self.place.power(self.radiance * (4.0 * PI))
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        if self.radiance.is_black() {
            return None;
        }
        let wi = sample_uniform_sphere(u);
        Some(
            self.place
                .sample(ctx, wi, self.radiance, uniform_sphere_pdf()),
        )
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        if self.radiance.is_black() {
            0.0
        } else {
            uniform_sphere_pdf()
        }
    }

    fn le(&self, _ray: &Ray) -> Rgb {
        self.radiance
    }

    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        self.place.preprocess(scene_bounds);
    }
}
