//! Watertight ray-triangle intersection.
//!
//! Reference: S. Woop, C. Benthin, I. Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013,
//! with the conservative lower bound on `t` of *Physically Based Rendering* (4th ed., section 6.8.4).
//!
//! The ray is translated to the origin, its axes permuted so that the dominant direction component
//! is `z`, and sheared so that the ray becomes the `+z` axis. The three 2D edge functions of the
//! transformed triangle are evaluated in f64, where products of f32 values are exact: every edge
//! function has the exact sign of its real value, and two triangles sharing an edge get exactly
//! opposite values for it, so a ray can never pass between them. (Evaluating in f32 and falling
//! back to f64 only on an exact zero, as the paper suggests, is not watertight: a neighbour that
//! did not fall back may round the shared edge to the opposite sign.)
//! A hit is accepted only when its `t` exceeds the bound on `t`'s own rounding error, which is what
//! keeps a ray spawned from a surface from hitting that surface again.

use glam::Vec3A;

use crate::float::gamma;
use crate::ray::Ray;

/// Per-ray constants of the watertight test, computed once per query and reused for every
/// candidate triangle.
#[derive(Clone, Copy, Debug)]
pub struct RayTriangleTest {
    origin: Vec3A,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
    t_min: f32,
}

/// A successful ray-triangle intersection: ray parameter and barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter.
    pub t: f32,
    /// Weight of the second vertex.
    pub b1: f32,
    /// Weight of the third vertex.
    pub b2: f32,
}

impl RayTriangleTest {
    /// Precompute the permutation and shear for `ray`.
    #[inline]
    #[must_use]
    pub fn new(ray: &Ray) -> Self {
        let d = Vec3A::from(ray.dir);
        let ad = d.abs();
        let kz = if ad.x > ad.y {
            if ad.x > ad.z { 0 } else { 2 }
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        let dz = d[kz];
        Self {
            origin: ray.origin.into(),
            kx,
            ky,
            kz,
            sx: -d[kx] / dz,
            sy: -d[ky] / dz,
            sz: 1.0 / dz,
            t_min: ray.t_min,
        }
    }

    /// Intersect the triangle `p` for `t` in `(max(t_min, error bound), t_max]`.
    #[inline]
    #[must_use]
    pub fn intersect(&self, p: &[Vec3A; 3], t_max: f32) -> Option<TriangleHit> {
        // Translate, permute and shear the vertices into ray space.
        let (mut x, mut y, mut z) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 3]);
        for i in 0..3 {
            let v = p[i] - self.origin;
            let vz = v[self.kz];
            x[i] = v[self.kx] + self.sx * vz;
            y[i] = v[self.ky] + self.sy * vz;
            z[i] = vz;
        }

        // Edge functions: e0 is the weight of vertex 0 (opposite edge 1-2), and so on. They are
        // evaluated in f64, where the f32 products are exact and the difference is correctly
        // rounded: each edge function then has exactly the sign of its real value, and two
        // triangles sharing an edge compute exactly negated values for it.
        let (xd, yd) = (x.map(f64::from), y.map(f64::from));
        let e0 = xd[1] * yd[2] - yd[1] * xd[2];
        let e1 = xd[2] * yd[0] - yd[2] * xd[0];
        let e2 = xd[0] * yd[1] - yd[0] * xd[1];
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 {
            return None;
        }

        // Scaled hit distance, compared against the range before the division.
        let z_raw = z;
        let z = z.map(|v| v * self.sz);
        let t_scaled = e0 * f64::from(z[0]) + e1 * f64::from(z[1]) + e2 * f64::from(z[2]);
        let t_max_scaled = f64::from(t_max) * det;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max_scaled) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max_scaled) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = (t_scaled * inv_det) as f32;
        if t < self.t_min || !t.is_finite() {
            return None;
        }

        // Reject t that is not provably positive given the rounding error of its computation
        // (pbrt-v4's bound, except that the shear error of x and y is bounded with the unscaled z:
        // pbrt uses z / d_z there, which is only of the same size when |d| is about 1).
        let max_zt = z[0].abs().max(z[1].abs()).max(z[2].abs());
        let max_z_raw = z_raw[0].abs().max(z_raw[1].abs()).max(z_raw[2].abs());
        let delta_z = gamma(3) * max_zt;
        let max_xt = x[0].abs().max(x[1].abs()).max(x[2].abs());
        let max_yt = y[0].abs().max(y[1].abs()).max(y[2].abs());
        let delta_x = gamma(5) * (max_xt + max_z_raw);
        let delta_y = gamma(5) * (max_yt + max_z_raw);
        let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs()) as f32;
        let delta_t = 3.0
            * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs() as f32;
        if t <= delta_t {
            return None;
        }

        Some(TriangleHit {
            t,
            b1: (e1 * inv_det) as f32,
            b2: (e2 * inv_det) as f32,
        })
    }
}

/// Intersect one triangle with a ray (convenience wrapper around [`RayTriangleTest`]).
#[inline]
#[must_use]
pub fn intersect_triangle(ray: &Ray, p: &[glam::Vec3; 3]) -> Option<TriangleHit> {
    RayTriangleTest::new(ray).intersect(&p.map(Vec3A::from), ray.t_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn tri() -> [Vec3; 3] {
        [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn hits_front_and_back() {
        let front = Ray::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let h = intersect_triangle(&front, &tri()).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        let p = tri()[0] * (1.0 - h.b1 - h.b2) + tri()[1] * h.b1 + tri()[2] * h.b2;
        assert!((p - front.at(h.t)).length() < 1e-6);
        let back = Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.0, 0.0, 1.0));
        assert!(intersect_triangle(&back, &tri()).is_some());
    }

    #[test]
    fn respects_t_range_and_misses() {
        let r = Ray::with_t_max(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0), 1.5);
        assert!(intersect_triangle(&r, &tri()).is_none());
        let away = Ray::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, 1.0));
        assert!(intersect_triangle(&away, &tri()).is_none());
        let outside = Ray::new(Vec3::new(5.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&outside, &tri()).is_none());
        let parallel = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        assert!(intersect_triangle(&parallel, &tri()).is_none());
    }

    #[test]
    fn origin_on_the_triangle_is_not_a_hit() {
        // A ray starting exactly on the surface must not report t ~ 0 (self-intersection).
        let r = Ray::new(Vec3::new(0.1, 0.1, 0.0), Vec3::new(0.3, 0.2, 1.0));
        assert!(intersect_triangle(&r, &tri()).is_none());
    }

    #[test]
    fn shared_edge_and_vertex_are_hit_exactly_once_or_twice_never_missed() {
        // Two triangles sharing the edge x = 0; rays aimed exactly at points on the edge.
        let a = [
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
        ];
        let b = [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        for i in 0..=100 {
            let y = -1.0 + 2.0 * i as f32 / 100.0;
            let target = Vec3::new(0.0, y, 0.0);
            let origin = Vec3::new(0.37, 0.11, 3.0);
            let r = Ray::new(origin, target - origin);
            let hits = [&a, &b]
                .iter()
                .filter(|t| intersect_triangle(&r, t).is_some())
                .count();
            assert!(hits >= 1, "ray at y = {y} slipped through the shared edge");
        }
    }
}
