//! A diffuse emitting triangle (area light).
//!
//! Reference: *Physically Based Rendering*, 4th ed., sections 12.5 (`DiffuseAreaLight`) and 6.5.4
//! (sampling triangles by area and by solid angle); J. Arvo, "Stratified sampling of spherical
//! triangles", SIGGRAPH 1995.
//!
//! | parameter | meaning |
//! |---|---|
//! | `p` | the three corners in world space; the front face is the side of `(p1 - p0) x (p2 - p0)` |
//! | `radiance` | emitted radiance `Le`, constant over the surface and over directions |
//! | `two_sided` | emit from both faces (default: front face only) |
//!
//! Points are sampled uniformly by area, with `pdf = distance^2 / (|cos theta_light| * area)`.
//! Opt-in (`TriangleLight::with_solid_angle_sampling`), directions are sampled uniformly over
//! the solid angle the triangle subtends at the receiver (Arvo's spherical triangle sampling,
//! `SphericalTriangle`), with density `1 / solid angle`: the estimate then no longer carries
//! the `cos theta_light / distance^2` factor of area sampling, whose spread makes receivers
//! close to a light, or seeing it at a grazing angle, noisy. Where the solid angle is too small
//! for the angle excess to be accurate in `f32` (below `MIN_SPHERICAL_SOLID_ANGLE`, a light far
//! away, where both methods are equally good) or close to a hemisphere (above
//! `MAX_SPHERICAL_SOLID_ANGLE`), points are still sampled by area; `pdf_li` makes the same
//! choice from the same receiver point, so the two always agree (pbrt-v4's `Triangle::Sample`
//! uses the same thresholds).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};
use pt_accel::Ray;
use pt_accel::triangle::intersect_triangle;

use crate::color::Rgb;
use crate::interaction::{SurfacePoint, barycentric_error};
use crate::light::{Light, LightFlags, LightSample, LightSampleContext};
use crate::sampling::{SphericalTriangle, sample_uniform_triangle};

/// A triangle that emits constant radiance from its front face (or both faces).
///
/// `sample_li` picks points uniformly by area, or (with
/// [`with_solid_angle_sampling`](Self::with_solid_angle_sampling)) directions uniformly over
/// the solid angle the triangle subtends at the receiver ([`SphericalTriangle`]), except where
/// that solid angle is outside [`MIN_SPHERICAL_SOLID_ANGLE`](Self::MIN_SPHERICAL_SOLID_ANGLE) ..
/// [`MAX_SPHERICAL_SOLID_ANGLE`](Self::MAX_SPHERICAL_SOLID_ANGLE); `pdf_li` agrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleLight {
    p: [Vec3; 3],
    n: Vec3,
    area: f32,
    radiance: Rgb,
    two_sided: bool,
    solid_angle_sampling: bool,
}

impl TriangleLight {
    /// Below this solid angle (steradians) the light is sampled by area: the angle excess of a
    /// tiny spherical triangle cancels catastrophically in `f32`, and for a light this small in
    /// view both methods are equally good.
    pub const MIN_SPHERICAL_SOLID_ANGLE: f32 = 3e-4;
    /// Above this solid angle (steradians, just under 2 pi) the light is sampled by area: the
    /// receiver nearly touches its plane and the spherical triangle approaches a hemisphere.
    pub const MAX_SPHERICAL_SOLID_ANGLE: f32 = 6.22;

    /// An emitting triangle. Returns `None` when the triangle has zero area or non-finite
    /// corners, or the radiance is negative or not finite: such a light could only produce
    /// NaNs or nothing.
    #[must_use]
    pub fn new(p: [Vec3; 3], radiance: Rgb, two_sided: bool) -> Option<Self> {
        if !pt_accel::is_valid_triangle(&p) || !radiance.is_valid_nonnegative() {
            return None;
        }
        // In f64: in f32 the squared length of the cross product overflows for triangles 1e11
        // across and underflows below 1e-11, and the light vanished.
        let c = pt_accel::triangle_cross(&p);
        let area = (0.5 * c.length()) as f32;
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        Some(Self {
            p,
            n: (c / c.length()).as_vec3(),
            area,
            radiance,
            two_sided,
            solid_angle_sampling: false,
        })
    }

    /// Sample directions uniformly over the solid angle the light subtends (`true`) instead of
    /// points uniformly over its area (`false`, the default). Solid-angle sampling removes the
    /// `cos theta_light / distance^2` factor from the estimate: 21x less variance for a
    /// receiver under a large, near light (`tests/area_lights.rs`), but a light sample costs
    /// several times as much, and on the Cornell box (small light, far from most receivers)
    /// relMSE at equal spp stays within 1% while renders take 1.37x as long; hence off by
    /// default.
    #[must_use]
    pub fn with_solid_angle_sampling(mut self, on: bool) -> Self {
        self.solid_angle_sampling = on;
        self
    }

    /// Whether directions are sampled by solid angle ([`Self::with_solid_angle_sampling`]).
    #[must_use]
    pub fn solid_angle_sampling(&self) -> bool {
        self.solid_angle_sampling
    }

    /// Surface area.
    #[must_use]
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Unit normal of the front face.
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        self.n
    }

    /// Emitted radiance.
    #[must_use]
    pub fn radiance(&self) -> Rgb {
        self.radiance
    }

    /// Whether both faces emit.
    #[must_use]
    pub fn two_sided(&self) -> bool {
        self.two_sided
    }

    /// The spherical triangle seen from `p_ref`, when its solid angle is in the range where it
    /// is sampled directly (the same decision in `sample_li` and `pdf_li`).
    #[inline]
    fn spherical(&self, p_ref: Vec3) -> Option<SphericalTriangle> {
        if !self.solid_angle_sampling {
            return None;
        }
        SphericalTriangle::new(&self.p, p_ref).filter(|st| {
            (Self::MIN_SPHERICAL_SOLID_ANGLE..=Self::MAX_SPHERICAL_SOLID_ANGLE).contains(&st.area())
        })
    }

    /// The solid-angle density of a point at `p_light` seen from `p_ref` along unit `wi`, when
    /// points are sampled by area.
    #[inline]
    fn solid_angle_pdf(&self, p_ref: Vec3, p_light: Vec3, wi: Vec3) -> f32 {
        let cos_l = self.n.dot(-wi).abs();
        if cos_l == 0.0 {
            return 0.0;
        }
        let pdf = p_ref.distance_squared(p_light) / (cos_l * self.area);
        if pdf.is_finite() { pdf } else { 0.0 }
    }
    /// Sample a point of the light for the receiver at `ctx`: by solid angle or uniformly by
    /// area as configured, or, with `area_sampler`, by the barycentric coordinates and area
    /// density (relative to uniform) it returns for `u`. `radiance(b)` gives the emitted
    /// radiance at barycentric coordinates `b` (the front-face test is done here).
    #[inline]
    pub(crate) fn sample_point<S: Fn(Vec2) -> ([f32; 3], f32)>(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        area_sampler: Option<S>,
        radiance: impl Fn([f32; 3]) -> Rgb,
    ) -> Option<LightSample> {
        let p_ref = ctx.p();
        // A receiver behind a one-sided light (or in its plane) gets nothing from it.
        if !self.two_sided && self.n.dot(p_ref - self.p[0]) <= 0.0 {
            return None;
        }
        // (barycentrics, solid angle when sampled by it, area density relative to uniform)
        let (b, spherical, relative) = match (area_sampler, self.spherical(p_ref)) {
            (Some(sampler), _) => {
                let (b, relative) = sampler(u);
                (b, None, relative)
            }
            (None, Some(st)) => {
                // The point where the sampled direction meets the triangle. The watertight test
                // could miss by rounding on an edge (a lost sample; none in the 600,000 of
                // `tests/area_lights.rs`).
                let hit = intersect_triangle(&Ray::new(p_ref, st.sample(u)), &self.p)?;
                (
                    [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2],
                    Some(st.area()),
                    1.0,
                )
            }
            (None, None) => (sample_uniform_triangle(u), None, 1.0),
        };
        let p = self.p[0] * b[0] + self.p[1] * b[1] + self.p[2] * b[2];
        let to_light = p - p_ref;
        let dist2 = to_light.length_squared();
        if dist2 == 0.0 || !dist2.is_finite() {
            return None;
        }
        let wi = to_light / dist2.sqrt();
        if !self.two_sided && self.n.dot(-wi) <= 0.0 {
            return None;
        }
        let li = radiance(b);
        if li.is_black() {
            return None;
        }
        let pdf = match spherical {
            Some(area) => 1.0 / area,
            None => self.solid_angle_pdf(p_ref, p, wi) * relative,
        };
        if pdf == 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(LightSample {
            li,
            wi,
            pdf,
            point: SurfacePoint {
                p,
                p_error: barycentric_error(b, self.p),
                n: self.n,
            },
        })
    }

    /// The corners (the front face is the side of `(p1 - p0) x (p2 - p0)`).
    #[must_use]
    pub fn corners(&self) -> [Vec3; 3] {
        self.p
    }

    /// The solid-angle density of reaching the light along `wi` from `ctx` when points are
    /// sampled by area with the density (relative to uniform) that `relative` gives for the
    /// barycentric coordinates `(b1, b2)` of the point reached; 0 when `wi` misses it or
    /// reaches its back face of a one-sided light.
    #[inline]
    pub(crate) fn pdf_area_weighted(
        &self,
        ctx: &LightSampleContext,
        wi: Vec3,
        relative: impl Fn(Vec2) -> f32,
    ) -> f32 {
        let ray = Ray::new(ctx.p(), wi);
        match intersect_triangle(&ray, &self.p) {
            Some(hit) if self.two_sided || self.n.dot(wi) < 0.0 => {
                self.solid_angle_pdf(ctx.p(), ray.at(hit.t), wi)
                    * relative(Vec2::new(hit.b1, hit.b2))
            }
            _ => 0.0,
        }
    }
}

impl Light for TriangleLight {
    #[inline]
    fn flags(&self) -> LightFlags {
        LightFlags::AREA
    }

    fn power(&self) -> Rgb {
        self.radiance * (PI * self.area * if self.two_sided { 2.0 } else { 1.0 })
    }

    #[inline]
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        self.sample_point(ctx, u, None::<fn(Vec2) -> ([f32; 3], f32)>, |_| {
            self.radiance
        })
    }

    #[inline]
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        // The density of the point this direction would reach: trace the ray against this
        // triangle alone.
        let ray = Ray::new(ctx.p(), wi);
        match intersect_triangle(&ray, &self.p) {
            Some(hit) => {
                if !self.two_sided && self.n.dot(wi) >= 0.0 {
                    return 0.0;
                }
                match self.spherical(ctx.p()) {
                    Some(st) => 1.0 / st.area(),
                    None => self.solid_angle_pdf(ctx.p(), ray.at(hit.t), wi),
                }
            }
            None => 0.0,
        }
    }

    fn lane_light(&self) -> Option<crate::light::LaneLight> {
        // Area sampling only: solid-angle sampling stays on the one-path tracer.
        (!self.solid_angle_sampling).then_some(crate::light::LaneLight::Triangle {
            p: self.p,
            n: self.n,
            area: self.area,
            radiance: self.radiance,
            two_sided: self.two_sided,
        })
    }

    /// Uses the light's own front-face normal rather than `n`, so that emission seen by a ray and
    /// emission reached by [`sample_li`](Light::sample_li) always agree about the side.
    #[inline]
    fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        if !self.two_sided && self.n.dot(w) <= 0.0 {
            Rgb::BLACK
        } else {
            self.radiance
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(p: Vec3) -> LightSampleContext {
        LightSampleContext {
            point: SurfacePoint::exact(p),
            ns: Vec3::ZERO,
        }
    }

    #[test]
    fn rejects_degenerate_and_invalid() {
        assert!(
            TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::X * 2.0], Rgb::WHITE, false).is_none()
        );
        assert!(
            TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], Rgb::splat(-1.0), false).is_none()
        );
        assert!(
            TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], Rgb::splat(f32::NAN), false)
                .is_none()
        );
    }

    #[test]
    fn one_sided_emission_and_sampling_consistency() {
        // Facing down (-z): the normal of (p1 - p0) x (p2 - p0).
        let l = TriangleLight::new(
            [
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.0, 1.0, 1.0),
                Vec3::new(1.0, 0.0, 1.0),
            ],
            Rgb::splat(2.0),
            false,
        )
        .unwrap();
        assert!((l.normal() - -Vec3::Z).length() < 1e-6);
        let below = ctx(Vec3::new(0.2, 0.2, 0.0));
        let above = ctx(Vec3::new(0.2, 0.2, 2.0));
        assert!(l.sample_li(&above, Vec2::new(0.3, 0.3)).is_none());
        let s = l.sample_li(&below, Vec2::new(0.3, 0.6)).unwrap();
        assert_eq!(s.li, Rgb::splat(2.0));
        let pdf = l.pdf_li(&below, s.wi);
        assert!((pdf - s.pdf).abs() < 1e-4 * s.pdf, "{pdf} vs {}", s.pdf);
        assert_eq!(l.pdf_li(&above, -s.wi), 0.0);
        assert!((l.power().r - 2.0 * PI * 0.5).abs() < 1e-5);
    }

    #[test]
    fn pdf_integrates_to_one_over_the_sphere() {
        // Integrate pdf_li over directions with a fine equal-area grid: it must be 1 (the light
        // is entirely visible from the reference point).
        let l = TriangleLight::new(
            [
                Vec3::new(-0.5, -0.5, 1.0),
                Vec3::new(0.5, -0.5, 1.0),
                Vec3::new(0.0, 0.7, 1.5),
            ],
            Rgb::WHITE,
            true,
        )
        .unwrap();
        let c = ctx(Vec3::ZERO);
        let (n_z, n_phi) = (800, 1600);
        let mut sum = 0.0f64;
        for i in 0..n_z {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n_z as f32;
            let r = (1.0 - z * z).sqrt();
            for j in 0..n_phi {
                let phi = 2.0 * PI * (j as f32 + 0.5) / n_phi as f32;
                sum += l.pdf_li(&c, Vec3::new(r * phi.cos(), r * phi.sin(), z)) as f64;
            }
        }
        let integral = sum * 4.0 * std::f64::consts::PI / (n_z * n_phi) as f64;
        assert!((integral - 1.0).abs() < 0.01, "{integral}");
    }
}
