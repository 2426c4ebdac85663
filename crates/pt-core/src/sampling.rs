//! Sample warps from the unit square to common domains, each with its density, and the MIS
//! heuristics.
//!
//! Every `sample_*` function maps a uniform `u` in `[0, 1)^2` to the domain; the matching `*_pdf`
//! gives the density with respect to the domain's natural measure (area for disks and triangles,
//! solid angle for directions).

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

/// 1 / (4 pi).
pub const INV_4PI: f32 = 0.25 * FRAC_1_PI;

/// The largest f32 below 1: the upper end of every sample value.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Shirley-Chiu concentric map from the square to the unit disk (area-preserving, low distortion).
#[inline]
#[must_use]
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Polar map from the square to the unit disk (area-preserving; `u.x` is the radius squared,
/// `u.y` the angle). Preferred over the concentric map where a warp must stay continuous across
/// the disk's diameter (visible-normal sampling).
#[inline]
#[must_use]
pub fn sample_uniform_disk_polar(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let theta = 2.0 * PI * u.y;
    r * Vec2::new(theta.cos(), theta.sin())
}

/// A direction in the `z > 0` hemisphere with density `cos(theta) / pi` (Malley's method).
#[inline]
#[must_use]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_uniform_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of [`sample_cosine_hemisphere`] for a direction with the given `cos(theta)`.
#[inline]
#[must_use]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// A uniformly distributed direction on the unit sphere.
#[inline]
#[must_use]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_sphere`]: `1 / (4 pi)`.
#[inline]
#[must_use]
pub fn uniform_sphere_pdf() -> f32 {
    INV_4PI
}

/// A uniformly distributed direction in the `z >= 0` hemisphere.
#[inline]
#[must_use]
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_hemisphere`]: `1 / (2 pi)`.
#[inline]
#[must_use]
pub fn uniform_hemisphere_pdf() -> f32 {
    0.5 * FRAC_1_PI
}

/// Barycentric coordinates `[b0, b1, b2]` uniformly distributed over a triangle.
///
/// Uses the area-preserving map that splits the square along its diagonal (Heitz 2019), which
/// keeps the stratification of `u` better than the square-root parameterisation.
#[inline]
#[must_use]
pub fn sample_uniform_triangle(u: Vec2) -> [f32; 3] {
    let (b0, b1) = if u.x < u.y {
        let b0 = u.x / 2.0;
        (b0, u.y - b0)
    } else {
        let b1 = u.y / 2.0;
        (u.x - b1, b1)
    };
    [b0, b1, 1.0 - b0 - b1]
}

/// Veach's power heuristic with exponent 2 for one sample from each of two strategies:
/// the MIS weight of a sample drawn with density `f_pdf` when the other strategy has `g_pdf`.
#[inline]
#[must_use]
pub fn power_heuristic(f_pdf: f32, g_pdf: f32) -> f32 {
    let (f, g) = (f_pdf * f_pdf, g_pdf * g_pdf);
    if f.is_infinite() {
        return 1.0;
    }
    if f + g == 0.0 {
        return 0.0;
    }
    f / (f + g)
}

/// Veach's balance heuristic for one sample from each of two strategies.
#[inline]
#[must_use]
pub fn balance_heuristic(f_pdf: f32, g_pdf: f32) -> f32 {
    if f_pdf.is_infinite() {
        return 1.0;
    }
    if f_pdf + g_pdf == 0.0 {
        return 0.0;
    }
    f_pdf / (f_pdf + g_pdf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            )
        })
    }

    #[test]
    fn warps_land_in_their_domain() {
        for u in grid(32) {
            assert!(sample_uniform_disk_concentric(u).length() <= 1.0 + 1e-6);
            let c = sample_cosine_hemisphere(u);
            assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-5);
            assert!((sample_uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            let b = sample_uniform_triangle(u);
            assert!(b.iter().all(|&x| (-1e-6..=1.0 + 1e-6).contains(&x)));
            assert!((b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn cosine_hemisphere_moments_match_pdf() {
        // E[cos theta] under pdf cos/pi is 2/3; the midpoint grid estimate converges quickly.
        let n = 256;
        let mean: f32 =
            grid(n).map(|u| sample_cosine_hemisphere(u).z).sum::<f32>() / (n * n) as f32;
        assert!((mean - 2.0 / 3.0).abs() < 1e-3, "{mean}");
    }

    #[test]
    fn triangle_samples_are_uniform() {
        // Uniform over the triangle: E[b0] = E[b1] = E[b2] = 1/3 and E[b0^2] = 1/6.
        let n = 256;
        let (mut m, mut m2) = ([0.0f64; 3], 0.0f64);
        for u in grid(n) {
            let b = sample_uniform_triangle(u);
            for k in 0..3 {
                m[k] += b[k] as f64;
            }
            m2 += (b[0] * b[0]) as f64;
        }
        let c = (n * n) as f64;
        for v in m {
            assert!((v / c - 1.0 / 3.0).abs() < 1e-3);
        }
        assert!((m2 / c - 1.0 / 6.0).abs() < 1e-3);
    }

    #[test]
    fn power_heuristic_weights_sum_to_one() {
        for (a, b) in [(1.0, 2.0), (0.3, 0.0), (5.0, 5.0)] {
            assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
    }
}
