//! Punctual lights, as glTF's `KHR_lights_punctual` defines them: point, spot and directional.
//!
//! Reference: *Physically Based Rendering*, 4th ed., section 12.1 (`PointLight`, `SpotLight`),
//! 12.4 (`DistantLight`); the glTF extension's specification for the spot cone falloff.
//!
//! | light | parameters | radiance arriving at `p` |
//! |---|---|---|
//! | [`PointLight`] | position, intensity `I` (per steradian) | `I / d^2` |
//! | [`SpotLight`] | position, direction, intensity, inner and outer cone angles | `I f(cos) / d^2`, `f` = 1 inside the inner cone, 0 outside the outer one, `((cos - cos_outer) / (cos_inner - cos_outer))^2` between (glTF's recommended falloff) |
//! | [`DirectionalLight`] | direction the light travels, irradiance `E` on a surface facing it | `E` along `-direction` |
//!
//! All are delta lights: only light sampling reaches them (`pdf_li` is 0 and MIS does not
//! apply), and rays never hit them. Units follow the scene's: glTF's candela and lux map to
//! intensity and irradiance one to one.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};
use pt_accel::Bounds3;

use crate::color::Rgb;
use crate::interaction::SurfacePoint;
use crate::light::{Light, LightError, LightFlags, LightSample, LightSampleContext};

fn check(name: &str, v: Rgb) -> Result<(), LightError> {
    if v.is_valid_nonnegative() {
        Ok(())
    } else {
        Err(LightError::BadParameter(format!(
            "{name} must be finite and >= 0, got {v:?}"
        )))
    }
}

fn check_point(name: &str, p: Vec3) -> Result<(), LightError> {
    if p.is_finite() {
        Ok(())
    } else {
        Err(LightError::BadParameter(format!(
            "{name} must be finite, got {p}"
        )))
    }
}

fn unit(name: &str, d: Vec3) -> Result<Vec3, LightError> {
    let n = d.normalize_or_zero();
    if d.is_finite() && n != Vec3::ZERO {
        Ok(n)
    } else {
        Err(LightError::BadParameter(format!(
            "{name} must be a finite non-zero vector, got {d}"
        )))
    }
}

/// The sample toward a point light at `pos` with intensity `i` (times any falloff).
fn toward(ctx: &LightSampleContext, pos: Vec3, i: Rgb) -> Option<LightSample> {
    let to = pos - ctx.p();
    let d2 = to.length_squared();
    if d2 == 0.0 || !d2.is_finite() {
        return None;
    }
    let wi = to / d2.sqrt();
    Some(LightSample {
        li: i / d2,
        wi,
        pdf: 1.0,
        point: SurfacePoint {
            p: pos,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
        },
    })
}

/// Light emitted equally in all directions from a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    position: Vec3,
    intensity: Rgb,
}

impl PointLight {
    /// A point light. Fails on a non-finite position or a negative or non-finite intensity.
    pub fn new(position: Vec3, intensity: Rgb) -> Result<Self, LightError> {
        check_point("point light position", position)?;
        check("point light intensity", intensity)?;
        Ok(Self {
            position,
            intensity,
        })
    }
}

impl Light for PointLight {
    fn flags(&self) -> LightFlags {
        LightFlags::DELTA_POSITION
    }

    fn power(&self) -> Rgb {
        self.intensity * (4.0 * PI)
    }

    fn sample_li(&self, ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        toward(ctx, self.position, self.intensity)
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }
}

/// A point light restricted to a cone, with a smooth edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    position: Vec3,
    direction: Vec3,
    intensity: Rgb,
    cos_inner: f32,
    cos_outer: f32,
}

impl SpotLight {
    /// A spot light at `position` shining along `direction`, full intensity within
    /// `inner_angle` radians of the axis, fading to zero at `outer_angle` (glTF's
    /// `innerConeAngle` and `outerConeAngle`, `0 <= inner < outer <= pi / 2`).
    pub fn new(
        position: Vec3,
        direction: Vec3,
        intensity: Rgb,
        inner_angle: f32,
        outer_angle: f32,
    ) -> Result<Self, LightError> {
        check_point("spot light position", position)?;
        check("spot light intensity", intensity)?;
        let direction = unit("spot light direction", direction)?;
        if !(inner_angle >= 0.0 && inner_angle < outer_angle && outer_angle <= PI / 2.0 + 1e-6) {
            return Err(LightError::BadParameter(format!(
                "spot light cone angles need 0 <= inner < outer <= pi/2, got {inner_angle} and {outer_angle}"
            )));
        }
        Ok(Self {
            position,
            direction,
            intensity,
            cos_inner: inner_angle.cos(),
            cos_outer: outer_angle.cos(),
        })
    }

    /// The falloff for a direction leaving the light with cosine `cos` to the axis.
    #[must_use]
    pub fn falloff(&self, cos: f32) -> f32 {
        let t = ((cos - self.cos_outer) / (self.cos_inner - self.cos_outer)).clamp(0.0, 1.0);
        t * t
    }
}

impl Light for SpotLight {
    fn flags(&self) -> LightFlags {
        LightFlags::DELTA_POSITION
    }

    fn power(&self) -> Rgb {
        // 2 pi times the integral of the falloff over cos theta: 1 - cos_inner for the full
        // cone, (cos_inner - cos_outer) / 3 for the quadratic edge.
        self.intensity
            * (2.0 * PI * ((1.0 - self.cos_inner) + (self.cos_inner - self.cos_outer) / 3.0))
    }

    fn sample_li(&self, ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        let mut s = toward(ctx, self.position, self.intensity)?;
        let f = self.falloff((-s.wi).dot(self.direction));
        if f == 0.0 {
            return None;
        }
        s.li *= f;
        Some(s)
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }
}

/// Parallel light from infinitely far away (the sun).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    direction: Vec3,
    irradiance: Rgb,
    radius: f32,
}

impl DirectionalLight {
    /// Light travelling along `direction` with irradiance `irradiance` on a surface facing it.
    pub fn new(direction: Vec3, irradiance: Rgb) -> Result<Self, LightError> {
        check("directional light irradiance", irradiance)?;
        Ok(Self {
            direction: unit("directional light direction", direction)?,
            irradiance,
            radius: 1.0,
        })
    }
}

impl Light for DirectionalLight {
    fn flags(&self) -> LightFlags {
        LightFlags::DELTA_DIRECTION
    }

    fn power(&self) -> Rgb {
        self.irradiance * (PI * self.radius * self.radius)
    }

    fn sample_li(&self, ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        let wi = -self.direction;
        Some(LightSample {
            li: self.irradiance,
            wi,
            pdf: 1.0,
            // `radius` covers the scene's bounds as seen from the origin (see `preprocess`).
            point: ctx.point_beyond(wi, Vec3::ZERO, self.radius),
        })
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }

    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        let (lo, hi) = (scene_bounds.min, scene_bounds.max);
        if lo.is_finite() && hi.is_finite() && lo.cmple(hi).all() {
            self.radius = ((hi - lo).length() * 0.5 + lo.abs().max(hi.abs()).length()).max(1e-3);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(p: Vec3) -> LightSampleContext {
        LightSampleContext {
            point: SurfacePoint {
                p,
                p_error: Vec3::ZERO,
                n: Vec3::Y,
            },
            ns: Vec3::Y,
        }
    }

    #[test]
    fn inverse_square_and_cone() {
        let l = PointLight::new(Vec3::new(0.0, 2.0, 0.0), Rgb::splat(8.0)).unwrap();
        let s = l.sample_li(&at(Vec3::ZERO), Vec2::ZERO).unwrap();
        assert_eq!(s.li, Rgb::splat(2.0));
        assert_eq!(s.wi, Vec3::Y);
        let spot = SpotLight::new(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::NEG_Y,
            Rgb::splat(8.0),
            0.2,
            0.4,
        )
        .unwrap();
        assert_eq!(
            spot.sample_li(&at(Vec3::ZERO), Vec2::ZERO).unwrap().li,
            Rgb::splat(2.0)
        );
        // Half way through the edge in cosine: falloff 1/4.
        let c = 0.5 * (0.2f32.cos() + 0.4f32.cos());
        assert!((spot.falloff(c) - 0.25).abs() < 1e-5);
        // Outside the outer cone: nothing.
        let far = Vec3::new(2.0 * 0.5f32.tan(), 0.0, 0.0);
        assert!(spot.sample_li(&at(far), Vec2::ZERO).is_none());
        // Power: numerical integral of the falloff over the sphere.
        let n = 200_000;
        let mut sum = 0.0f64;
        for k in 0..n {
            let cos = -1.0 + 2.0 * (k as f32 + 0.5) / n as f32;
            sum += f64::from(spot.falloff(cos));
        }
        let integral = sum / n as f64 * 4.0 * std::f64::consts::PI;
        assert!((f64::from(spot.power().r) / 8.0 - integral).abs() < 1e-4);
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(PointLight::new(Vec3::splat(f32::NAN), Rgb::WHITE).is_err());
        assert!(PointLight::new(Vec3::ZERO, Rgb::splat(-1.0)).is_err());
        assert!(SpotLight::new(Vec3::ZERO, Vec3::ZERO, Rgb::WHITE, 0.1, 0.2).is_err());
        assert!(SpotLight::new(Vec3::ZERO, Vec3::Y, Rgb::WHITE, 0.3, 0.2).is_err());
        assert!(DirectionalLight::new(Vec3::ZERO, Rgb::WHITE).is_err());
    }
}
