//! Sample warps from the unit square to common domains, each with its density, and the MIS
//! heuristics.
//!
//! Every `sample_*` function maps a uniform `u` in `[0, 1)^2` to the domain; the matching `*_pdf`
//! gives the density with respect to the domain's natural measure (area for disks and triangles,
//! solid angle for directions).

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};

use glam::{DVec3, Vec2, Vec3};

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
    // The angle is pi/4 o.y/o.x in the wedges around the x axis and pi/2 - pi/4 o.x/o.y in
    // those around the y axis, whose cosine and sine are the sine and cosine of pi/4 o.x/o.y:
    // both come from `sin_cos_quarter` on [-pi/4, pi/4] (the lane tracer computes the same
    // polynomials in lanes, bit for bit).
    if o.x.abs() > o.y.abs() {
        let (sin, cos) = sin_cos_quarter(FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(cos, sin)
    } else {
        let (sin, cos) = sin_cos_quarter(FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(sin, cos)
    }
}

/// Coefficients of [`sin_cos_quarter`]'s polynomials (the minimax fits of Cephes' `sinf` and
/// `cosf` on `[-pi/4, pi/4]`), highest degree first.
pub(crate) const SIN_COEFFS: [f32; 3] = [-1.951_529_6e-4, 8.332_161e-3, -1.666_665_5e-1];
/// See [`SIN_COEFFS`].
pub(crate) const COS_COEFFS: [f32; 3] = [2.443_315_7e-5, -1.388_731_6e-3, 4.166_664_6e-2];

/// The sine and cosine of `x` in `[-pi/4, pi/4]` by polynomials, within 2 ulp of the exact
/// values (`sin_cos_quarter_is_accurate`). Plain multiplications and additions, no fused ones,
/// so it rounds the same on every machine and in [`FloatLanes`](pt_accel::lanes::FloatLanes)
/// form; about a tenth of the cost of the C library's `sincosf` call per value.
#[inline(always)]
#[must_use]
pub fn sin_cos_quarter(x: f32) -> (f32, f32) {
    let z = x * x;
    let [s0, s1, s2] = SIN_COEFFS;
    let [c0, c1, c2] = COS_COEFFS;
    let sin = x + x * z * ((s0 * z + s1) * z + s2);
    let cos = (1.0 - 0.5 * z) + z * z * ((c0 * z + c1) * z + c2);
    (sin, cos)
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

/// The spherical triangle that a planar triangle subtends at a point: the corners' directions,
/// one interior angle and the solid angle, for uniform sampling of the solid angle
/// ([`sample`](Self::sample)).
///
/// Computed in `f64`: Arvo's construction takes a square root of `1 - q^2` with `q` near 1 at
/// the corners, which in `f32` moves directions by up to 1e-3 radians and loses a few samples
/// in 10,000 across the edges of large triangles. The arithmetic is scalar either way (glam's
/// `Vec3` is), so `f64` costs little more. The trigonometry is one `atan2` per triangle (the
/// solid angle, by Van Oosterom and Strackee's formula, accurate also for small triangles,
/// unlike the angle excess) and one sine-cosine pair per sample; the interior angle's sine and
/// cosine come from the sides' great-circle normals.
///
/// Reference: J. Arvo, "Stratified sampling of spherical triangles", SIGGRAPH 1995;
/// A. Van Oosterom, J. Strackee, "The solid angle of a plane triangle", IEEE Trans. Biomed. Eng.
/// 30(2), 1983.
#[derive(Clone, Copy, Debug)]
pub struct SphericalTriangle {
    /// Unit directions from the point to the corners (relabelled cyclically, see `new`).
    a: DVec3,
    b: DVec3,
    c: DVec3,
    /// Sine and cosine of the interior angle at `a`.
    sin_alpha: f64,
    cos_alpha: f64,
    /// Solid angle in steradians.
    area: f64,
}

/// Spherical triangles none of whose angles has a larger sine are not sampled directly: the
/// cancellation in Arvo's construction grows as `1 / sin(alpha)^2` (a sliver with every angle
/// within about 0.06 degrees of 0 or 180).
const MIN_SPHERICAL_SINE: f64 = 1e-3;

impl SphericalTriangle {
    /// The triangle with corners `v` seen from `p`; `None` when `p` lies in its plane, the
    /// triangle is degenerate (no solid angle to sample), or it is an extreme sliver.
    #[inline]
    #[must_use]
    pub fn new(v: &[Vec3; 3], p: Vec3) -> Option<Self> {
        let p = p.as_dvec3();
        let [a, b, c] = v.map(|x| (x.as_dvec3() - p).normalize_or_zero());
        // Van Oosterom and Strackee: tan(area / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a).
        let triple = a.dot(b.cross(c)).abs();
        let area = 2.0 * triple.atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a));
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        // Normals of the great circles through the sides. The interior angle at a corner is the
        // angle between the planes of the two sides that meet there: its cosine is minus the
        // dot product of their normals, its sine the triple product over the two cross
        // products' lengths (the spherical law of sines).
        let (ab, bc, ca) = (a.cross(b), b.cross(c), c.cross(a));
        let (l_ab, l_bc, l_ca) = (ab.length(), bc.length(), ca.length());
        if !(l_ab > 0.0 && l_bc > 0.0 && l_ca > 0.0) {
            return None;
        }
        let (n_ab, n_bc, n_ca) = (ab / l_ab, bc / l_bc, ca / l_ca);
        let sines = [
            triple / (l_ab * l_ca),
            triple / (l_bc * l_ab),
            triple / (l_ca * l_bc),
        ];
        let cosines = [-n_ab.dot(n_ca), -n_bc.dot(n_ab), -n_ca.dot(n_bc)];
        // Arvo's formulas divide by sin(alpha): start at the corner whose angle has the largest
        // sine (a cyclic relabelling, the same triangle).
        let k = (0..3)
            .max_by(|&i, &j| sines[i].total_cmp(&sines[j]))
            .unwrap_or(0);
        if sines[k].is_nan() || sines[k] < MIN_SPHERICAL_SINE {
            return None;
        }
        let corners = [a, b, c];
        Some(Self {
            a: corners[k],
            b: corners[(k + 1) % 3],
            c: corners[(k + 2) % 3],
            sin_alpha: sines[k].min(1.0),
            cos_alpha: cosines[k].clamp(-1.0, 1.0),
            area,
        })
    }

    /// Solid angle in steradians (the density of [`sample`](Self::sample) is its inverse).
    #[inline]
    #[must_use]
    pub fn area(&self) -> f32 {
        self.area as f32
    }

    /// A unit direction uniformly distributed over the spherical triangle (Arvo's method: `u.x`
    /// picks the sub-triangle `a b c'` of area `u.x * area`, `u.y` the point on the arc from
    /// `b` to `c'` with the right density). The map is continuous in `u`, so stratified or
    /// low-discrepancy `u` stays well distributed over the solid angle.
    #[inline]
    #[must_use]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (a, b, c) = (self.a, self.b, self.c);
        let (sin_alpha, cos_alpha) = (self.sin_alpha, self.cos_alpha);
        // phi = u.x area - alpha, by the angle-difference formulas.
        let (sin_area, cos_area) = (f64::from(u.x) * self.area).sin_cos();
        let sin_phi = sin_area * cos_alpha - cos_area * sin_alpha;
        let cos_phi = cos_area * cos_alpha + sin_area * sin_alpha;
        // q: the cosine of the arc from a to c', the third corner of the sub-triangle (Arvo's
        // u and v; a . b is the cosine of the side opposite c).
        let (arvo_u, arvo_v) = (cos_phi - cos_alpha, sin_phi + sin_alpha * a.dot(b));
        let q = ((arvo_v * cos_phi - arvo_u * sin_phi) * cos_alpha - arvo_v)
            / ((arvo_v * sin_phi + arvo_u * cos_phi) * sin_alpha);
        let q = if q.is_finite() {
            q.clamp(-1.0, 1.0)
        } else {
            1.0
        };
        let c_sub = q * a + (1.0 - q * q).max(0.0).sqrt() * orthogonal_unit(c, a);
        // Along the arc from b to c', cos(theta) uniform between 1 and b . c'.
        let z = 1.0 - f64::from(u.y) * (1.0 - c_sub.dot(b));
        (z * b + (1.0 - z * z).max(0.0).sqrt() * orthogonal_unit(c_sub, b))
            .normalize()
            .as_vec3()
    }
}

/// The unit vector along the part of `v` orthogonal to unit `w` (zero if `v` is parallel to
/// `w`).
#[inline]
fn orthogonal_unit(v: DVec3, w: DVec3) -> DVec3 {
    (v - v.dot(w) * w).normalize_or_zero()
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
    fn sin_cos_quarter_is_accurate() {
        // Every f32 step of 2^-16 across [-pi/4, pi/4], against f64's sine and cosine: within
        // 2 ulp of the exact value (relative to the larger of the value and 2^-20 for the
        // sine near zero). Fails with any coefficient wrong in its third digit.
        let ulp = |v: f64| f64::from(f32::EPSILON) * v.abs().max(2.0f64.powi(-20));
        let mut x = -FRAC_PI_4;
        let (mut worst_s, mut worst_c) = (0.0f64, 0.0f64);
        while x <= FRAC_PI_4 {
            let (s, c) = sin_cos_quarter(x);
            let (es, ec) = (f64::from(x).sin(), f64::from(x).cos());
            worst_s = worst_s.max((f64::from(s) - es).abs() / ulp(es));
            worst_c = worst_c.max((f64::from(c) - ec).abs() / ulp(ec));
            x += 2.0f32.powi(-16);
        }
        assert!(worst_s <= 2.0 && worst_c <= 2.0, "{worst_s} {worst_c} ulp");
        assert_eq!(sin_cos_quarter(0.0), (0.0, 1.0));
    }

    #[test]
    fn concentric_map_keeps_its_angles() {
        // The polynomial form against the trigonometric map it replaces.
        for u in grid(64) {
            let o = 2.0 * u - Vec2::ONE;
            let (r, theta) = if o.x.abs() > o.y.abs() {
                (
                    f64::from(o.x),
                    std::f64::consts::FRAC_PI_4 * f64::from(o.y / o.x),
                )
            } else {
                (
                    f64::from(o.y),
                    std::f64::consts::FRAC_PI_2
                        - std::f64::consts::FRAC_PI_4 * f64::from(o.x / o.y),
                )
            };
            let d = sample_uniform_disk_concentric(u);
            assert!((f64::from(d.x) - r * theta.cos()).abs() < 1e-6, "{u}");
            assert!((f64::from(d.y) - r * theta.sin()).abs() < 1e-6, "{u}");
        }
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

    /// Solid angle as the angle excess, with each interior angle from the tangents of its two
    /// sides (independent of the formula `SphericalTriangle` uses), in f64.
    fn solid_angle_f64(v: &[Vec3; 3], p: Vec3) -> f64 {
        let [a, b, c] = v.map(|x| (x - p).as_dvec3().normalize());
        let angle = |x: DVec3, y: DVec3, z: DVec3| {
            let ty = (y - x * x.dot(y)).normalize();
            let tz = (z - x * x.dot(z)).normalize();
            ty.dot(tz).clamp(-1.0, 1.0).acos()
        };
        angle(a, b, c) + angle(b, c, a) + angle(c, a, b) - std::f64::consts::PI
    }

    /// Triangles seen from the origin: small and far, large and near, grazing, obtuse, a sliver
    /// (angles of about 1, 2 and 177 degrees).
    fn spherical_cases() -> Vec<[Vec3; 3]> {
        vec![
            [
                Vec3::new(-1.0, 0.0, 0.5),
                Vec3::new(1.0, 0.0, 0.5),
                Vec3::new(0.0, 0.02, 0.52),
            ],
            [
                Vec3::new(-0.5, -0.5, 1.0),
                Vec3::new(0.5, -0.5, 1.0),
                Vec3::new(0.0, 0.7, 1.5),
            ],
            [
                Vec3::new(-3.0, -2.0, 0.3),
                Vec3::new(4.0, -1.0, 0.4),
                Vec3::new(0.0, 5.0, 0.2),
            ],
            [
                Vec3::new(1.0, 0.0, 0.05),
                Vec3::new(2.0, 0.1, 0.05),
                Vec3::new(1.5, 1.0, 0.06),
            ],
            [
                Vec3::new(9.0, 1.0, 10.0),
                Vec3::new(9.5, 1.0, 10.0),
                Vec3::new(9.0, 1.6, 10.1),
            ],
        ]
    }

    #[test]
    fn spherical_triangle_area_is_the_solid_angle() {
        for v in spherical_cases() {
            let st = SphericalTriangle::new(&v, Vec3::ZERO).unwrap();
            let exact = solid_angle_f64(&v, Vec3::ZERO);
            let rel = (f64::from(st.area()) - exact).abs() / exact;
            assert!(rel < 2e-3, "{v:?}: {} vs {exact}", st.area());
        }
        // No solid angle from inside the plane or for a degenerate triangle.
        let v = [Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        assert!(SphericalTriangle::new(&v, Vec3::ZERO).is_none());
        assert!(SphericalTriangle::new(&[Vec3::X, Vec3::X * 2.0, Vec3::Z], Vec3::ZERO).is_none());
        // An extreme sliver (angles within 0.002 degrees of 0 and 180) is left to area sampling.
        let sliver = [
            Vec3::new(-1.0, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(0.0, 2e-5, 0.5),
        ];
        assert!(SphericalTriangle::new(&sliver, Vec3::ZERO).is_none());
    }

    /// The corners of the unit square map to the corners of the spherical triangle (`u.y = 0`
    /// is corner b, `(0, 1)` corner a, `(1, 1)` corner c); the distribution itself is tested by
    /// chi-square in the end-to-end tests (`area_lights`).
    #[test]
    fn spherical_triangle_sample_corners() {
        for v in spherical_cases() {
            let st = SphericalTriangle::new(&v, Vec3::ZERO).unwrap();
            let [a, b, c] = [st.a, st.b, st.c].map(DVec3::as_vec3);
            let corners = v.map(Vec3::normalize);
            assert!(
                corners
                    .iter()
                    .all(|x| [a, b, c].iter().any(|y| y.distance(*x) < 1e-6)),
                "a relabelling of the corners"
            );
            for (u, corner) in [
                (Vec2::new(0.0, 0.0), b),
                (Vec2::new(0.7, 0.0), b),
                (Vec2::new(0.0, 1.0), a),
                (Vec2::new(1.0, 1.0), c),
            ] {
                let w = st.sample(u);
                // sqrt(1 - q^2) turns the rounding of q (near 1 at a corner) into about 1e-8
                // radians in f64 (it was up to 1e-3 in f32).
                assert!(w.distance(corner) < 1e-5, "{v:?} {u}: {w} vs {corner}");
            }
        }
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
