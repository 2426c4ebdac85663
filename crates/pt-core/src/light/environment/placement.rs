//! Where an environment sits: its orientation, intensity scale, and the scene's bounding sphere
//! that shadow-ray targets are placed beyond.

use glam::{Mat3, Vec3};
use pt_accel::Bounds3;

use crate::color::Rgb;
use crate::light::{LightError, LightSample, LightSampleContext};

/// The part every environment light shares: orientation, scale and the scene's bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Placement {
    /// Map frame to world.
    pub(crate) to_world: Mat3,
    /// World to map frame.
    pub(crate) to_map: Mat3,
    pub(crate) scale: f32,
    center: Vec3,
    radius: f32,
}

impl Placement {
    pub(crate) fn new() -> Self {
        Self {
            to_world: Mat3::IDENTITY,
            to_map: Mat3::IDENTITY,
            scale: 1.0,
            center: Vec3::ZERO,
            radius: 1.0,
        }
    }

    pub(crate) fn set_rotation(&mut self, rotation: Mat3) -> Result<(), LightError> {
        let orthonormal = (rotation.transpose() * rotation - Mat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|v| v.abs() < 1e-4)
            && (rotation.determinant() - 1.0).abs() < 1e-4;
        if !orthonormal {
            return Err(LightError::BadParameter(format!(
                "rotation must be a proper rotation matrix, got {rotation}"
            )));
        }
        self.to_world = rotation;
        self.to_map = rotation.transpose();
        Ok(())
    }

    /// Set the scale of a map whose brightest radiance is `brightest`: refused when the scaled
    /// radiance would not be finite (`--env-intensity 3e38` made every lookup infinite).
    pub(crate) fn set_scale(&mut self, scale: f32, brightest: f32) -> Result<(), LightError> {
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(LightError::BadParameter(format!(
                "intensity scale must be finite and >= 0, got {scale}"
            )));
        }
        if !(brightest * scale).is_finite() {
            return Err(LightError::BadParameter(format!(
                "intensity scale {scale} makes the brightest radiance of the map ({brightest}) \
                 overflow"
            )));
        }
        self.scale = scale;
        Ok(())
    }

    pub(crate) fn preprocess(&mut self, bounds: &Bounds3) {
        if bounds.min.is_finite() && bounds.max.is_finite() && bounds.min.cmple(bounds.max).all() {
            self.center = (bounds.min + bounds.max) * 0.5;
            self.radius = ((bounds.max - bounds.min).length() * 0.5).max(1e-3);
        }
    }

    /// A light sample toward world direction `wi` from `ctx`, with a target point beyond the
    /// scene.
    pub(crate) fn sample(
        &self,
        ctx: &LightSampleContext,
        wi: Vec3,
        li: Rgb,
        pdf: f32,
    ) -> LightSample {
        LightSample {
            li: li * self.scale,
            wi,
            pdf,
            point: ctx.point_beyond(wi, self.center, self.radius),
        }
    }

    /// Flux through the scene's bounding disk for a given integral of radiance over the sphere.
    pub(crate) fn power(&self, integral: Rgb) -> Rgb {
        // In f64 and capped: for a scene 1e18 across, R^2 alone overflows f32, and a light of
        // infinite power would be dropped by the light sampler.
        let k = f64::from(self.scale) * std::f64::consts::PI * f64::from(self.radius).powi(2);
        let cap = |c: f32| (f64::from(c) * k).min(f64::from(f32::MAX)) as f32;
        Rgb::new(cap(integral.r), cap(integral.g), cap(integral.b))
    }
}
