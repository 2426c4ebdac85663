//! Watertight ray-triangle intersection.
//!
//! Reference: S. Woop, C. Benthin, I. Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013,
//! with the conservative lower bound on `t` of *Physically Based Rendering* (4th ed., section 6.8.4).
//!
//! The ray is translated to the origin, its axes permuted so that the dominant direction component
//! is `z`, and sheared so that the ray becomes the `+z` axis. The three 2D edge functions of the
//! transformed triangle are evaluated for all three corners at once in f32. A triangle sharing an
//! edge transforms the edge's two corners to the same coordinates and multiplies the same pairs,
//! so its f32 value for that edge is exactly the negation: the two always agree about which side
//! the ray passes, and a ray can never slip between them, whatever the rounding. An edge whose f32
//! value is exactly zero (the ray meets the edge's line within rounding) is recomputed in f64,
//! where products of f32 values are exact, so it gets its exact sign, again the same in both
//! triangles. The fallback is per edge: recomputing all three edges of a triangle when one is
//! zero, as the paper does, is not watertight, since the neighbour across another edge, without a
//! zero of its own, keeps that edge's rounded f32 sign while this triangle takes the exact one.
//! A hit is accepted only when its `t` exceeds the bound on `t`'s own rounding error, which is what
//! keeps a ray spawned from a surface from hitting that surface again. That bound grows with the
//! triangle's size, not with its distance: a ray leaving a floor a thousandth of a unit from a wall
//! of a 500-unit room meets the wall at `t` below the f32 bound. Such a hit (within the f32
//! bound, otherwise accepted) is decided again in f64 (`RayTriangleTest::near_hit`), whose
//! bound is 2^29 times smaller: a hit of another surface near the origin is kept (without it,
//! light leaked into closed rooms through their corners), and the surface a ray was spawned
//! from, whose crossing lies behind the offset origin, is still rejected.

mod lanes4;
mod lanes8;

use glam::{Vec3A, Vec3Swizzles};

use crate::float::gamma;
use crate::ray::Ray;

pub use lanes4::PackedTriangles4;
pub(crate) use lanes4::Triangles4;

/// A triangle stored transposed: the x, y and z coordinates of its three corners, so that the
/// watertight test works on all three corners at once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PackedTriangle {
    xs: Vec3A,
    ys: Vec3A,
    zs: Vec3A,
}

impl PackedTriangle {
    /// Pack three corners.
    #[inline]
    #[must_use]
    pub fn new(p: &[Vec3A; 3]) -> Self {
        Self {
            xs: Vec3A::new(p[0].x, p[1].x, p[2].x),
            ys: Vec3A::new(p[0].y, p[1].y, p[2].y),
            zs: Vec3A::new(p[0].z, p[1].z, p[2].z),
        }
    }

    /// The three corners.
    #[inline]
    #[must_use]
    pub fn corners(&self) -> [Vec3A; 3] {
        [0, 1, 2].map(|i| Vec3A::new(self.xs[i], self.ys[i], self.zs[i]))
    }
}

/// Per-ray constants of the watertight test, computed once per query and reused for every
/// candidate triangle: the axis permutation that makes the dominant direction component `z`, the
/// origin's coordinates along the permuted axes, and the shear. A corner `v` maps to
/// `x' = (v[kx] - o[kx]) + sx (v[kz] - o[kz])`, `y' = (v[ky] - o[ky]) + sy (v[kz] - o[kz])` and
/// `z' = v[kz] - o[kz]`, the same operations for every triangle, so triangles sharing a corner see
/// the same coordinates.
#[derive(Clone, Copy, Debug)]
pub struct RayTriangleTest {
    /// The axes kx, ky, kz (each 0, 1 or 2).
    pub(crate) k: [usize; 3],
    /// The origin's kx, ky and kz coordinates.
    pub(crate) o: [f32; 3],
    pub(crate) sx: f32,
    pub(crate) sy: f32,
    pub(crate) sz: f32,
    pub(crate) t_min: f32,
}

/// The bound a closest-hit query checks a triangle's scaled distance against once it has a hit
/// at `t_best` (the ray's range ends at `t_max`): `t_best` widened by 2^-21 of itself, which is
/// more than the rounding of the scaled distance and of the division, so that every triangle
/// whose divided distance is at most `t_best` passes the check, whatever was found first; the
/// divided distance is then compared with `t_best` itself. Without the widening, a triangle at
/// exactly `t_best` could fail the check by rounding, and which of two triangles at the same
/// distance a query returns would depend on the order it tested them in.
#[inline(always)]
pub(crate) fn tie_bound(t_max: f32, t_best: f32) -> f32 {
    t_max.min(t_best + t_best * 2.0f32.powi(-21))
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
        // kx and ky follow kz cyclically. One division: any per-ray rounding of the shear is
        // fine, as long as every triangle of the query sees the same values.
        let k = [(kz + 1) % 3, (kz + 2) % 3, kz];
        let sz = 1.0 / d[kz];
        let o = Vec3A::from(ray.origin);
        Self {
            k,
            o: k.map(|a| o[a]),
            sx: -d[k[0]] * sz,
            sy: -d[k[1]] * sz,
            sz,
            t_min: ray.t_min,
        }
    }

    /// Intersect the triangle with corners `p` for `t` in `(max(t_min, error bound), t_max]`.
    #[inline]
    #[must_use]
    pub fn intersect(&self, p: &[Vec3A; 3], t_max: f32) -> Option<TriangleHit> {
        self.intersect_packed(&PackedTriangle::new(p), t_max)
    }

    /// Intersect a packed triangle for `t` in `(max(t_min, error bound), t_max]`.
    ///
    /// Always inlined, with `near_hit`: the vector tests call it for the rare triangle
    /// they cannot decide, and a call inside a kernel's loop, however rarely taken, made the
    /// compiler keep the loop's vector values on the stack (inlined: Mitsuba's box +2.5-3%,
    /// the glass bunny +2%, incoherent any-hit queries +4-5%; docs/performance-log.md).
    #[inline(always)]
    #[must_use]
    pub fn intersect_packed(&self, tri: &PackedTriangle, t_max: f32) -> Option<TriangleHit> {
        // Translate, permute and shear the corners into ray space (one lane per corner). The
        // fourth entry only lets the compiler see that every index is in range.
        let axes = [tri.xs, tri.ys, tri.zs, tri.zs];
        let [kx, ky, kz] = self.k.map(|a| a & 3);
        let z_raw = axes[kz] - self.o[2];
        let x = (axes[kx] - self.o[0]) + z_raw * self.sx;
        let y = (axes[ky] - self.o[1]) + z_raw * self.sy;

        // Edge functions: lane i is the weight of corner i (the edge opposite it).
        let mut e = x.yzx() * y.zxy() - y.yzx() * x.zxy();
        let neg = e.cmplt(Vec3A::ZERO);
        let pos = e.cmpgt(Vec3A::ZERO);
        // An edge function that is exactly zero (or NaN) in f32 is recomputed in f64, where the
        // f32 products are exact, so its sign is the exact one; every other edge keeps its f32
        // value. Which of the two an edge takes depends only on that edge's own f32 value, and
        // a triangle sharing the edge computes the same two products and so exactly the negated
        // value: both always agree about which side the ray passes, and no ray can pass between
        // them.
        if (neg | pos).bitmask() != 0b111 {
            let (xd, yd) = (x.to_array().map(f64::from), y.to_array().map(f64::from));
            let ed = [
                xd[1] * yd[2] - yd[1] * xd[2],
                xd[2] * yd[0] - yd[2] * xd[0],
                xd[0] * yd[1] - yd[0] * xd[1],
            ];
            let decided = (neg | pos).bitmask();
            let mut signs = [0.0f64; 3];
            for i in 0..3 {
                signs[i] = if decided & (1 << i) != 0 {
                    f64::from(e[i])
                } else {
                    e[i] = ed[i] as f32;
                    ed[i]
                };
            }
            if signs.iter().any(|&v| v < 0.0) && signs.iter().any(|&v| v > 0.0) {
                return None;
            }
        } else if neg.any() && pos.any() {
            return None;
        }
        let det = e.x + e.y + e.z;
        // Scaled hit distance, compared against the range before the division.
        let z = z_raw * self.sz;
        let t_scaled = e.dot(z);
        match self.finish(
            det,
            t_scaled,
            t_max,
            Maxima {
                x: x.abs().max_element(),
                y: y.abs().max_element(),
                z: z.abs().max_element(),
                z_raw: z_raw.abs().max_element(),
                e: e.abs().max_element(),
            },
            e.y,
            e.z,
        ) {
            Finished::Hit(h) => Some(h),
            Finished::Miss => None,
            Finished::Near => self.near_hit(tri, t_max),
        }
    }

    /// A hit that the f32 test accepted except for its error bound (`0 < t <= delta_t`),
    /// decided again in f64 (see the module docs): the same translation, shear, edge functions
    /// and distance, and the same bound on `t`'s rounding error with f64's unit roundoff. The
    /// constants of the test (the origin, `sx`, `sy`, `sz`) and the corners are f32 values and
    /// exact in f64, so the bound holds for the same sheared ray as the f32 test's. Whether the
    /// ray passes inside the triangle stays the f32 test's decision (which is what keeps
    /// neighbouring triangles watertight); only the sign of `t` is decided here. The lane tests
    /// hand such lanes to the scalar test, so every kernel gives this answer. Inlined with
    /// [`Self::intersect_packed`], for the same reason.
    #[inline(always)]
    fn near_hit(&self, tri: &PackedTriangle, t_max: f32) -> Option<TriangleHit> {
        let axes = [tri.xs, tri.ys, tri.zs];
        let [kx, ky, kz] = self.k.map(|a| a.min(2));
        let o = self.o.map(f64::from);
        let (sx, sy, sz) = (f64::from(self.sx), f64::from(self.sy), f64::from(self.sz));
        let (mut x, mut y, mut z_raw, mut z) = ([0.0f64; 3], [0.0f64; 3], [0.0f64; 3], [0.0f64; 3]);
        for i in 0..3 {
            z_raw[i] = f64::from(axes[kz][i]) - o[2];
            x[i] = (f64::from(axes[kx][i]) - o[0]) + z_raw[i] * sx;
            y[i] = (f64::from(axes[ky][i]) - o[1]) + z_raw[i] * sy;
            z[i] = z_raw[i] * sz;
        }
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        let det = e[0] + e[1] + e[2];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = ((e[0] * z[0] + e[1] * z[1]) + e[2] * z[2]) * inv_det;
        let [mx, my, mz, mz_raw, me] =
            [x, y, z, z_raw, e].map(|v| v[0].abs().max(v[1].abs()).max(v[2].abs()));
        let m = Maxima {
            x: mx,
            y: my,
            z: mz,
            z_raw: mz_raw,
            e: me,
        };
        let bound = m.t_error_bound(inv_det.abs(), ERROR_CONSTANTS_F64);
        let t32 = t as f32;
        // Each comparison is false for NaN.
        let kept = t > bound && t32 > 0.0 && t32 >= self.t_min && t32 <= t_max;
        kept.then(|| TriangleHit {
            t: t32,
            b1: (e[1] * inv_det) as f32,
            b2: (e[2] * inv_det) as f32,
        })
    }

    /// The end of the scalar test: the range check on the scaled distance, the division, and the
    /// check that `t` is provably positive given the rounding error of its computation
    /// (pbrt-v4's bound, except that the shear error of x and y is bounded with the unscaled z:
    /// pbrt uses z / d_z there, which is only of the same size when |d| is about 1); a `t` that
    /// is not is [`Finished::Near`], for [`Self::near_hit`] to decide. The four-triangle test
    /// repeats these operations lane-wise in the same order, so that both round identically
    /// (`four_lanes_equal_the_scalar_test_bit_for_bit` checks it).
    #[inline(always)]
    fn finish(&self, det: f32, t_scaled: f32, t_max: f32, m: Maxima, e1: f32, e2: f32) -> Finished {
        if det == 0.0 || !det.is_finite() {
            return Finished::Miss;
        }
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return Finished::Miss;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return Finished::Miss;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if t < self.t_min || !t.is_finite() {
            return Finished::Miss;
        }
        if t > m.t_error_bound(inv_det.abs(), ERROR_CONSTANTS) {
            Finished::Hit(TriangleHit {
                t,
                b1: e1 * inv_det,
                b2: e2 * inv_det,
            })
        } else {
            // Also a NaN bound: f64 decides.
            Finished::Near
        }
    }
}

/// What the f32 test's last steps ([`RayTriangleTest::finish`]) decided.
enum Finished {
    Hit(TriangleHit),
    Miss,
    /// A hit in every respect but `t`'s error bound: [`RayTriangleTest::near_hit`] decides.
    Near,
}

/// The largest magnitudes of a triangle's ray-space coordinates and edge functions, for the
/// error bound on `t`: one value each, or a vector of them (the lane tests).
#[derive(Clone, Copy)]
pub(crate) struct Maxima<F = f32> {
    pub x: F,
    pub y: F,
    pub z: F,
    pub z_raw: F,
    pub e: F,
}

/// The constants of [`Maxima::t_error_bound`]: gamma(2), gamma(3), gamma(5), 2 and 3 (a lane
/// test passes them splatted).
pub(crate) const ERROR_CONSTANTS: [f32; 5] = [gamma(2), gamma(3), gamma(5), 2.0, 3.0];

/// [`ERROR_CONSTANTS`] for the f64 recomputation ([`RayTriangleTest::near_hit`]): the gammas of
/// f64's unit roundoff.
const ERROR_CONSTANTS_F64: [f64; 5] = [gamma_f64(2), gamma_f64(3), gamma_f64(5), 2.0, 3.0];

/// `gamma(n)` for f64 arithmetic: `n u / (1 - n u)` with `u = 2^-53`.
const fn gamma_f64(n: i32) -> f64 {
    let ne = n as f64 * (f64::EPSILON * 0.5);
    ne / (1.0 - ne)
}

impl<F: Copy + std::ops::Add<Output = F> + std::ops::Mul<Output = F>> Maxima<F> {
    /// The bound on the rounding error of a hit's `t` (see [`RayTriangleTest::finish`]), given
    /// `|1 / det|` and [`ERROR_CONSTANTS`] as `F`. The scalar test and the lane tests all compute it here, with these
    /// operations in this order, so that all of them round alike.
    #[inline(always)]
    pub fn t_error_bound(self, abs_inv_det: F, c: [F; 5]) -> F {
        let [g2, g3, g5, two, three] = c;
        let delta_z = g3 * self.z;
        let delta_x = g5 * (self.x + self.z_raw);
        let delta_y = g5 * (self.y + self.z_raw);
        let delta_e = two * (g2 * self.x * self.y + delta_y * self.x + delta_x * self.y);
        three * (g3 * self.e * self.z + delta_e * self.z + delta_z * self.e) * abs_inv_det
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

    /// A ray leaving a room's floor a thousandth of a unit from a wall of the 500-unit room
    /// meets the wall 0.0044 units away: far below the f32 bound on `t`'s error for a triangle
    /// that size (about 0.006 here), far above the f64 one. Rejected, it let light into a closed
    /// box through its corners (`tests/stress_scale.rs`). The wall is hit, by the scalar test
    /// and by the four- and eight-lane tests; the floor the ray leaves is not.
    #[test]
    fn a_wall_just_past_the_origin_is_hit() {
        let h = 250.0f32;
        let wall = [
            Vec3::new(-h, -h, -h),
            Vec3::new(h, -h, -h),
            Vec3::new(h, h, -h),
            Vec3::new(-h, h, -h),
        ];
        let floor = [
            Vec3::new(-h, -h, -h),
            Vec3::new(h, -h, -h),
            Vec3::new(h, -h, h),
            Vec3::new(-h, -h, h),
        ];
        let tri = |q: &[Vec3; 4], i: usize| {
            let c = if i == 0 {
                [q[0], q[1], q[2]]
            } else {
                [q[0], q[2], q[3]]
            };
            PackedTriangle::new(&c.map(Vec3A::from))
        };
        // The shadow ray of the failing render: from the floor (offset up by its error bound)
        // toward a distant light, up and out through the wall at z = -250.
        let ray = Ray::with_t_max(
            Vec3::new(96.63621, -249.99986, -249.99918),
            Vec3::new(-659.7703, 2199.2341, -439.8469),
            0.999_999_94,
        );
        let test = RayTriangleTest::new(&ray);
        let exact_t = 0.00082 / 439.8469;
        let hit = test
            .intersect_packed(&tri(&wall, 0), ray.t_max)
            .expect("the wall is hit");
        assert!((hit.t / exact_t - 1.0).abs() < 0.01, "t {}", hit.t);
        assert!(test.intersect_packed(&tri(&wall, 1), ray.t_max).is_none());
        for i in 0..2 {
            assert!(test.intersect_packed(&tri(&floor, i), ray.t_max).is_none());
        }
        // The lane tests hand the lane to the scalar test and return its hit.
        let tris = [tri(&floor, 0), tri(&wall, 1), tri(&wall, 0), tri(&floor, 1)];
        let four = test.intersect4(&PackedTriangles4::new(&tris), ray.t_max);
        assert_eq!(four, [None, None, Some(hit), None]);
        assert_eq!(
            test.closest4(&PackedTriangles4::new(&tris), ray.t_max),
            Some((2, hit))
        );
        assert!(test.any4(&PackedTriangles4::new(&tris), ray.t_max));
    }

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
    fn an_edge_that_rounds_to_zero_takes_its_exact_sign() {
        // The ray runs down the z axis, so ray space is world space (no shear) and the edge
        // function of the edge a-b is x_a y_b - y_a x_b = -1 + (1 - e^2) = -e^2 exactly, which f32
        // rounds to -1 - (-1) = 0. The exact sign puts the origin on d's side of the edge: B is
        // hit and A is not. (Treating the zero as a hit on both would be a double hit; as a miss
        // on both, a hole.)
        let e = f32::EPSILON;
        let (a, b) = (
            Vec3::new(-1.0, -(1.0 + e), 0.0),
            Vec3::new(1.0 - e, 1.0, 0.0),
        );
        assert_eq!(
            a.x * b.y - a.y * b.x,
            0.0,
            "the f32 edge function must round to zero"
        );
        let (c, d) = (Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, -1.0, 0.0));
        let tri_a = [a, b, c];
        let tri_b = [b, a, d];
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&ray, &tri_a).is_none(), "A is hit");
        let hit = intersect_triangle(&ray, &tri_b).expect("B is missed");
        assert_eq!(hit.t, 1.0);
        // The four-lane test hands such lanes to this test and returns the same.
        let test = RayTriangleTest::new(&ray);
        let packed = [tri_a, tri_b].map(|t| PackedTriangle::new(&t.map(Vec3A::from)));
        let lanes = test.intersect4(&PackedTriangles4::new(&packed), ray.t_max);
        assert!(lanes[0].is_none());
        assert_eq!(lanes[1], Some(hit));
    }

    #[test]
    fn rays_at_a_shared_edge_never_slip_through() {
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
        // The open edge only: its end points are outer corners of the pair, where a ray may
        // legitimately pass outside (inner vertices are tested on closed meshes in tests/).
        for i in 1..100 {
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
