//! The Trowbridge-Reitz (GGX) microfacet distribution with Smith masking-shadowing, sampled from
//! the distribution of visible normals.
//!
//! References: B. Walter, S. Marschner, H. Li, K. Torrance, "Microfacet Models for Refraction
//! through Rough Surfaces", EGSR 2007; E. Heitz, "Understanding the Masking-Shadowing Function in
//! Microfacet-Based BRDFs", JCGT 2014; E. Heitz, "Sampling the GGX Distribution of Visible
//! Normals", JCGT 2018; *Physically Based Rendering*, 4th ed., section 9.6.
//!
//! Directions are in the local shading frame (`z` is the macro-surface normal). The distribution
//! is symmetric under `z -> -z` of the direction, so callers may pass directions from either side;
//! microfacet normals `wm` are returned in the upper hemisphere.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::sampling::sample_uniform_disk_polar;

/// Below this `alpha` a surface is treated as perfectly smooth (a delta lobe): the distribution
/// would be too peaked to evaluate in `f32`.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// Perceptual roughness (glTF, Disney: 0 smooth, 1 rough) to the distribution's `alpha`
/// (`alpha = roughness^2`). Values outside `[0, 1]` are clamped; NaN becomes 0.
#[inline]
#[must_use]
pub fn roughness_to_alpha(roughness: f32) -> f32 {
    let r = if roughness.is_nan() {
        0.0
    } else {
        roughness.clamp(0.0, 1.0)
    };
    r * r
}

/// Anisotropic Trowbridge-Reitz (GGX) distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    alpha_x: f32,
    alpha_y: f32,
}

impl TrowbridgeReitz {
    /// A distribution with widths `alpha_x` along the tangent `x` and `alpha_y` along `y`.
    /// Values are clamped to `[0, 1]` (NaN becomes 0); use [`roughness_to_alpha`] to map a
    /// perceptual roughness.
    #[must_use]
    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        let c = |a: f32| if a.is_nan() { 0.0 } else { a.clamp(0.0, 1.0) };
        Self {
            alpha_x: c(alpha_x),
            alpha_y: c(alpha_y),
        }
    }

    /// An isotropic distribution of width `alpha`.
    #[must_use]
    pub fn isotropic(alpha: f32) -> Self {
        Self::new(alpha, alpha)
    }

    /// The widths `(alpha_x, alpha_y)`.
    #[must_use]
    pub fn alpha(&self) -> (f32, f32) {
        (self.alpha_x, self.alpha_y)
    }

    /// True when the surface is so smooth that it must be treated as a delta lobe.
    #[inline]
    #[must_use]
    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < SMOOTH_ALPHA
    }

    /// Density of microfacet normals `D(wm)` (per unit projected area of the macro-surface, so
    /// that the integral of `D(wm) cos theta_m` over the hemisphere is 1).
    #[inline]
    #[must_use]
    pub fn d(&self, wm: Vec3) -> f32 {
        let cos2 = wm.z * wm.z;
        if cos2 == 0.0 {
            return 0.0;
        }
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        // tan^2 theta (cos^2 phi / ax^2 + sin^2 phi / ay^2), from the tangent components
        // directly: `1 - cos^2` would cancel catastrophically near the normal, where sharp lobes
        // live.
        let e = (wm.x * wm.x / (ax * ax) + wm.y * wm.y / (ay * ay)) / cos2;
        let cos4 = cos2 * cos2;
        let t = 1.0 + e;
        1.0 / (PI * ax * ay * cos4 * t * t)
    }

    /// Smith's auxiliary function `Lambda(w)`.
    #[inline]
    #[must_use]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let cos2 = w.z * w.z;
        if cos2 == 0.0 {
            return f32::INFINITY;
        }
        // alpha^2 tan^2 theta for the direction's azimuth.
        let a2_tan2 = (self.alpha_x * self.alpha_x * w.x * w.x
            + self.alpha_y * self.alpha_y * w.y * w.y)
            / cos2;
        ((1.0 + a2_tan2).sqrt() - 1.0) * 0.5
    }

    /// Masking function `G1(w)`.
    #[inline]
    #[must_use]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing `G(wo, wi)`.
    #[inline]
    #[must_use]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of visible normals from direction `w`: `G1(w) max(0, w . wm) D(wm) / |cos theta|`,
    /// with `w` flipped to the upper hemisphere first.
    #[inline]
    #[must_use]
    pub fn pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        let cos = w.z.abs();
        if cos == 0.0 {
            return 0.0;
        }
        let w = if w.z < 0.0 { -w } else { w };
        let dot = w.dot(wm);
        if dot <= 0.0 {
            return 0.0;
        }
        self.g1(w) / cos * self.d(wm) * dot
    }

    /// Sample a visible normal seen from `w` (Heitz 2018), returned in the upper hemisphere.
    #[inline]
    #[must_use]
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        // Stretch to the hemisphere configuration.
        let mut wh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        if wh.z < 0.0 {
            wh = -wh;
        }
        let t1 = if wh.z < 0.99999 {
            Vec3::Z.cross(wh).normalize()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        // Uniform disk, warped to the projected area of the visible hemisphere.
        let mut p = sample_uniform_disk_polar(u);
        let h = (1.0 - p.x * p.x).max(0.0).sqrt();
        let s = 0.5 * (1.0 + wh.z);
        p.y = (1.0 - s) * h + s * p.y;
        let pz = (1.0 - p.length_squared()).max(0.0).sqrt();
        let nh = t1 * p.x + t2 * p.y + wh * pz;
        // Unstretch.
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::sample_uniform_hemisphere;

    /// Integral over the hemisphere of `f(wm)` by uniform hemisphere sampling on a stratified grid.
    fn hemisphere_integral(f: impl Fn(Vec3) -> f64, n: usize) -> f64 {
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                sum += f(sample_uniform_hemisphere(u));
            }
        }
        sum / (n * n) as f64 * 2.0 * std::f64::consts::PI
    }

    #[test]
    fn projected_area_is_one() {
        for (ax, ay) in [(0.5, 0.5), (1.0, 1.0), (0.3, 0.6)] {
            let d = TrowbridgeReitz::new(ax, ay);
            let i = hemisphere_integral(|wm| f64::from(d.d(wm) * wm.z), 1000);
            assert!((i - 1.0).abs() < 5e-3, "alpha ({ax}, {ay}): {i}");
        }
    }

    #[test]
    fn visible_normals_are_normalized_for_every_view() {
        let d = TrowbridgeReitz::new(0.4, 0.7);
        for w in [
            Vec3::Z,
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(-0.3, 0.9, 0.3).normalize(),
            Vec3::new(0.2, 0.1, -0.9).normalize(),
        ] {
            let i = hemisphere_integral(|wm| f64::from(d.pdf(w, wm)), 1000);
            assert!((i - 1.0).abs() < 5e-3, "w {w}: {i}");
        }
    }

    #[test]
    fn roughness_mapping() {
        assert_eq!(roughness_to_alpha(0.5), 0.25);
        assert_eq!(roughness_to_alpha(f32::NAN), 0.0);
        assert_eq!(roughness_to_alpha(3.0), 1.0);
        assert!(TrowbridgeReitz::isotropic(roughness_to_alpha(0.01)).effectively_smooth());
        assert!(!TrowbridgeReitz::isotropic(roughness_to_alpha(0.05)).effectively_smooth());
    }
}
