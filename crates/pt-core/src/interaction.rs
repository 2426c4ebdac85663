//! Points on surfaces with floating-point error bounds, and robust spawning of rays from them.
//!
//! A computed hit point is only known up to a rounding error. Every point carries a conservative
//! per-axis bound on that error (`p_error`), derived from how it was computed (barycentric
//! interpolation, then an instance transform). A ray leaving the surface starts from the point
//! pushed along the geometric normal by the projection of that error box onto the normal, then
//! rounded one ulp further away: the true surface then lies provably behind the origin, so the
//! watertight triangle test (which also rejects `t` below its own error bound) cannot report the
//! surface the ray left. This is the method of *Physically Based Rendering*, 4th ed., section 6.8.6.
//! No fixed epsilon is involved, so it works identically at any scene scale and distance from the
//! origin.

use glam::{Affine3A, Vec2, Vec3, Vec3A, Vec4};
use pt_accel::Ray;
use pt_accel::float::{gamma, next_float_down};

use crate::frame::Frame;

/// A point on a surface: position, per-axis absolute error bound, and unit geometric normal
/// (zero for points that are not on a surface, such as a point light).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfacePoint {
    /// Position.
    pub p: Vec3,
    /// Conservative bound on `|computed p - exact p|` per axis.
    pub p_error: Vec3,
    /// Unit geometric normal, or zero.
    pub n: Vec3,
}

impl SurfacePoint {
    /// A point with no error and no normal.
    #[inline]
    #[must_use]
    pub fn exact(p: Vec3) -> Self {
        Self {
            p,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
        }
    }

    /// The point moved off the surface toward the side of `w`, far enough that rays leaving it in
    /// any direction on that side cannot hit the surface it lies on.
    #[inline]
    #[must_use]
    pub fn offset_origin(&self, w: Vec3) -> Vec3 {
        // Four-lane vectors: the same operations per axis (and the same order of the dot
        // product's sums) as with `Vec3`, in a third of the instructions.
        let (n, p, w) = (Vec3A::from(self.n), Vec3A::from(self.p), Vec3A::from(w));
        let d = n.abs().dot(Vec3A::from(self.p_error));
        let mut offset = n * d;
        if w.dot(n) < 0.0 {
            offset = -offset;
        }
        let po = p + offset;
        // Round away from p so that the rounding of the sum cannot undo the offset: a step of
        // |po| 2^-23 is between one and two ulps of po (at least the smallest normal float near
        // zero), and adding it in the direction of the offset moves po by one or two ulps. This
        // is pbrt's one-ulp `NextFloatUp/Down` made branch-free (at most one ulp more offset).
        let step = (po.abs() * (1.0 / 8_388_608.0)).max(Vec3A::splat(f32::MIN_POSITIVE));
        let zero = Vec3A::ZERO;
        let step = Vec3A::select(
            offset.cmpgt(zero),
            step,
            Vec3A::select(offset.cmplt(zero), -step, zero),
        );
        (po + step).into()
    }

    /// An unbounded ray leaving this point in direction `w`.
    #[inline]
    #[must_use]
    pub fn spawn_ray(&self, w: Vec3) -> Ray {
        Ray::new(self.offset_origin(w), w)
    }

    /// A shadow ray from this point to `to`: both ends are offset off their surfaces, the
    /// direction is the unnormalised segment and `t_max` is the float just below 1, so neither
    /// end's own surface can block it.
    #[inline]
    #[must_use]
    pub fn spawn_ray_to(&self, to: &SurfacePoint) -> Ray {
        let from = self.offset_origin(to.p - self.p);
        let target = to.offset_origin(from - to.p);
        Ray::with_t_max(from, target - from, next_float_down(1.0))
    }
}

/// The error bound of a barycentric combination `b0 p0 + b1 p1 + b2 p2` computed in f32.
#[inline]
#[must_use]
pub fn barycentric_error(b: [f32; 3], p: [Vec3; 3]) -> Vec3 {
    ((p[0] * b[0]).abs() + (p[1] * b[1]).abs() + (p[2] * b[2]).abs()) * gamma(7)
}

/// The point at barycentrics `b` of the triangle `p` with its error bound
/// ([`barycentric_error`]), pulled inside the triangle where it lies within twice that bound
/// of an edge ([`near_edge`], [`pull_inside`]).
#[inline(always)]
#[must_use]
pub(crate) fn barycentric_point(b: [f32; 3], p: [Vec3; 3]) -> (Vec3, Vec3) {
    let q = p[0] * b[0] + p[1] * b[1] + p[2] * b[2];
    let e = barycentric_error(b, p);
    if near_edge(b, p, e, 1.0)
        && let Some(pulled) = pull_inside(b, p, e)
    {
        return pulled;
    }
    (q, e)
}

/// Whether a hit at barycentrics `b` of the triangle `p`, computed with error bound `err`,
/// may lie closer to one of the triangle's edges than twice that bound ([`pull_inside`]'s
/// condition): `min b_i < 2 |err| |e_i| / |N|` with `|err|` bounded by the sum of its
/// components and `|e_i|` by the longest edge, compared squared (no square root or division).
/// `scale2` multiplies the right side: 1 where `err` and `p` are in the same space, the square
/// of a bound on the inverse transform's norm where `err` is in world space and `p` in
/// object space (a linear map shrinks an altitude by at most that norm).
///
/// Cheap (about 40 operations in `f32`) and conservative up to rounding: a hit it clears is
/// at least twice its bound from every edge. Triangles more than about 1e9 across overflow
/// it and are never pulled. The lane tracer computes the same in lanes, operation for
/// operation.
#[inline(always)]
#[must_use]
pub(crate) fn near_edge(b: [f32; 3], p: [Vec3; 3], err: Vec3, scale2: f32) -> bool {
    let e0 = p[2] - p[1];
    let e1 = p[0] - p[2];
    let e2 = p[1] - p[0];
    let c = [
        e1.y * e2.z - e1.z * e2.y,
        e1.z * e2.x - e1.x * e2.z,
        e1.x * e2.y - e1.y * e2.x,
    ];
    let nn = (c[0] * c[0] + c[1] * c[1]) + c[2] * c[2];
    let l = [e0, e1, e2].map(|e| (e.x * e.x + e.y * e.y) + e.z * e.z);
    let ll = l[0].max(l[1].max(l[2]));
    let s = (err.x + err.y) + err.z;
    let bm = b[0].min(b[1].min(b[2]));
    bm < 0.0 || (bm * bm) * nn < (((s * s) * 4.0) * ll) * scale2
}

/// [`near_edge`]'s `scale2` for a transform whose normal matrix (inverse transpose of its
/// linear part) is `normal_matrix`: the square of the inverse's Frobenius norm, which bounds
/// how far the transform can shrink an altitude, rounded up.
#[must_use]
pub(crate) fn edge_scale2(normal_matrix: &glam::Mat3A) -> f32 {
    let f: f64 = normal_matrix
        .to_cols_array()
        .iter()
        .map(|&v| f64::from(v).powi(2))
        .sum();
    (f * (1.0 + 1e-6)) as f32
}

/// A hit point moved off its triangle's edges: the point at barycentrics `b` of the triangle
/// `p`, with error bound `err`, pulled inside so that it lies at least twice its error bound
/// from every edge, or `None` where it already does (or the triangle is too small or
/// degenerate for it). Returns the new point and its error bound.
///
/// A point computed within its error bound of an edge can be rounded past the edge: at a
/// corner where two walls meet, onto the far side of the adjacent wall's plane, where a ray
/// spawned from it (offset off its own surface only) starts outside the room and leaves
/// through the wall. Far from the origin the bound reaches centimetres (0.04 units at
/// 1e5) and light leaks into a closed box. The move is within the point's own uncertainty
/// scale; images change only at hits that close to an edge.
///
/// In `f64`, out of line: [`near_edge`] calls for it rarely.
#[cold]
#[inline(never)]
#[must_use]
pub(crate) fn pull_inside(b: [f32; 3], p: [Vec3; 3], err: Vec3) -> Option<(Vec3, Vec3)> {
    let w = p.map(|v| v.as_dvec3());
    let delta = 2.0 * err.as_dvec3().length();
    let nn = (w[1] - w[0]).cross(w[2] - w[0]).length();
    if !(nn > 0.0 && nn.is_finite() && delta.is_finite()) {
        return None;
    }
    let edges = [w[2] - w[1], w[0] - w[2], w[1] - w[0]];
    let margin = edges.map(|e| delta * e.length() / nn);
    let sum_margin = margin[0] + margin[1] + margin[2];
    if (0..3).all(|i| f64::from(b[i]) >= margin[i]) || sum_margin >= 0.5 {
        return None;
    }
    let raised = [0, 1, 2].map(|i| f64::from(b[i]).max(margin[i]));
    let total = raised[0] + raised[1] + raised[2];
    let bb = raised.map(|v| (v / total) as f32);
    let q = p[0] * bb[0] + p[1] * bb[1] + p[2] * bb[2];
    // The rounded weights sum to 1 only within rounding: the point moves off the plane by
    // that much of the corners' sizes more.
    let off = (bb.iter().map(|&v| f64::from(v)).sum::<f64>() - 1.0).abs() as f32;
    let size = p[0].abs().max(p[1].abs()).max(p[2].abs());
    Some((
        q,
        barycentric_error(bb, p) + size * (off * (1.0 + gamma(3))),
    ))
}

/// Apply an affine transform to a point with error bound, propagating the bound (pbrt-v4's
/// `Transform::operator()(Point3fi)`).
#[inline]
#[must_use]
pub fn transform_point_with_error(m: &Affine3A, p: Vec3, p_error: Vec3) -> (Vec3, Vec3) {
    let out = m.transform_point3(p);
    let (cx, cy, cz) = (
        Vec3::from(m.matrix3.x_axis).abs(),
        Vec3::from(m.matrix3.y_axis).abs(),
        Vec3::from(m.matrix3.z_axis).abs(),
    );
    // Error of computing the transform itself, plus the propagated input error.
    let rounding =
        (cx * p.x.abs() + cy * p.y.abs() + cz * p.z.abs() + Vec3::from(m.translation).abs())
            * gamma(3);
    let propagated = (cx * p_error.x + cy * p_error.y + cz * p_error.z) * (1.0 + gamma(3));
    (out, rounding + propagated)
}

/// A material's shading normal `n` (such as a normal map's) made usable at a point with
/// geometric normal `ng` seen from direction `wo`: bent toward the geometric normal just enough
/// that the mirror reflection of `wo` about it leaves the surface on `wo`'s side.
///
/// A bumped normal can face away from the viewer, or reflect the view direction into the
/// surface; paths there find no valid direction and normal-mapped surfaces show black patches
/// at grazing angles. The bend (bisection toward `ng`, which always qualifies) changes only the
/// normals that would cause it, and keeps the side of the surface `n` was given for. Non-finite
/// or zero `n` gives `ng`.
#[must_use]
pub fn bend_shading_normal(n: Vec3, ng: Vec3, wo: Vec3) -> Vec3 {
    let n = n.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        return ng;
    }
    // Work on the viewer's side: `g` faces `wo`, `m` is `n` on the same side as `ng`'s.
    let side = if wo.dot(ng) < 0.0 { -1.0 } else { 1.0 };
    let g = ng * side;
    let flip = if n.dot(ng) < 0.0 { -side } else { side };
    let m = n * flip;
    let cos_g = wo.dot(g);
    // The reflection must rise at least this far above the surface (never more than `wo` does,
    // which the geometric normal's own reflection achieves).
    let min_rise = (0.9 * cos_g).min(0.01);
    let rise = |m: Vec3| (2.0 * wo.dot(m) * m - wo).dot(g);
    if m.dot(g) > 0.0 && rise(m) >= min_rise {
        return n;
    }
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..12 {
        let mid = 0.5 * (lo + hi);
        if rise(m.lerp(g, mid).normalize()) >= min_rise {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let bent = m.lerp(g, hi).normalize_or_zero();
    if bent == Vec3::ZERO { ng } else { bent * flip }
}

/// The interpolated vertex attributes at a hit beyond position and normal, for materials that
/// read them. Filled only when some material of the scene needs them
/// ([`MaterialProperties`](crate::MaterialProperties)); otherwise, and where the mesh lacks an
/// attribute, the defaults: coordinates zero, colour opaque white, tangent zero.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SurfaceAttributes {
    /// Texture coordinates of each set ([`Mesh::uv_set`](crate::Mesh::uv_set)); set 0 is also
    /// [`SurfaceInteraction::uv`] when the mesh has it.
    pub uv: [Vec2; crate::scene::MAX_UV_SETS],
    /// Linear RGBA vertex colour (`COLOR_0`).
    pub color: Vec4,
    /// World-space unit tangent (direction of increasing `u` of set 0, orthogonal to the shading
    /// normal) with the bitangent's handedness in `w`; zero when the mesh has no tangents.
    pub tangent: Vec4,
}

impl Default for SurfaceAttributes {
    fn default() -> Self {
        Self {
            uv: [Vec2::ZERO; crate::scene::MAX_UV_SETS],
            color: Vec4::ONE,
            tangent: Vec4::ZERO,
        }
    }
}

/// Everything the integrator needs to know about a ray's closest hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// Position, error bound and geometric normal (oriented to agree with the shading normal).
    pub point: SurfacePoint,
    /// Shading frame; its `z` axis is the shading normal.
    pub shading: Frame,
    /// Surface parameterisation (texture coordinates).
    pub uv: Vec2,
    /// Vertex attributes for materials (texture-coordinate sets, colour, tangent).
    pub attributes: SurfaceAttributes,
    /// Unit direction toward the ray origin (`-ray.dir`, normalised).
    pub wo: Vec3,
    /// Distance along the ray in units of the ray direction.
    pub t: f32,
    /// Index of the surface's material in the scene.
    pub material: u32,
    /// Index of the area light on this triangle, if the surface emits.
    pub light: Option<u32>,
    /// Index of the object (instance) hit.
    pub instance: u32,
    /// Triangle index within the object's mesh.
    pub prim: u32,
}

impl SurfaceInteraction {
    /// Geometric normal.
    #[inline]
    #[must_use]
    pub fn n(&self) -> Vec3 {
        self.point.n
    }

    /// Shading normal.
    #[inline]
    #[must_use]
    pub fn ns(&self) -> Vec3 {
        self.shading.n()
    }

    /// A ray leaving the surface in world direction `w`.
    #[inline]
    #[must_use]
    pub fn spawn_ray(&self, w: Vec3) -> Ray {
        self.point.spawn_ray(w)
    }

    /// A shadow ray toward a point on a light.
    #[inline]
    #[must_use]
    pub fn spawn_ray_to(&self, to: &SurfacePoint) -> Ray {
        self.point.spawn_ray_to(to)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bent_normals_keep_reflections_above_the_surface() {
        let ng = Vec3::Z;
        // A valid normal is kept exactly.
        let n = Vec3::new(0.2, 0.0, 1.0).normalize();
        let wo = Vec3::new(0.0, 0.3, 1.0).normalize();
        assert_eq!(bend_shading_normal(n, ng, wo), n);
        // Grazing view, normal tilted away from the viewer: the mirror direction would go below.
        let wo = Vec3::new(1.0, 0.0, 0.05).normalize();
        let n = Vec3::new(-0.3, 0.0, 0.95).normalize();
        let r = |m: Vec3| 2.0 * wo.dot(m) * m - wo;
        assert!(r(n).z < 0.0);
        let b = bend_shading_normal(n, ng, wo);
        assert!(r(b).z > 0.0 && (b.length() - 1.0).abs() < 1e-5, "{b}");
        // Bent only as far as needed: still tilted away from the viewer, less so.
        assert!(b.x < 0.0 && b.x > n.x && b.z > n.z, "{b}");
        // Seen from below, the same holds on the lower side, and the given side is kept.
        let below = Vec3::new(wo.x, 0.0, -wo.z);
        let b = bend_shading_normal(-n, ng, below);
        let rb = 2.0 * below.dot(b) * b - below;
        assert!(rb.z < 0.0 && b.z < 0.0, "{b} {rb}");
        // Unusable normals give the geometric normal.
        assert_eq!(bend_shading_normal(Vec3::ZERO, ng, wo), ng);
        assert_eq!(bend_shading_normal(Vec3::NAN, ng, wo), ng);
    }

    #[test]
    fn offset_moves_to_the_side_of_w() {
        let sp = SurfacePoint {
            p: Vec3::new(1.0, 2.0, 0.0),
            p_error: Vec3::splat(1e-6),
            n: Vec3::Z,
        };
        assert!(sp.offset_origin(Vec3::new(0.3, 0.0, 1.0)).z > 0.0);
        assert!(sp.offset_origin(Vec3::new(0.3, 0.0, -1.0)).z < 0.0);
        // An exact point needs no offset: the triangle test already rejects t <= its error bound.
        let exact = SurfacePoint {
            p_error: Vec3::ZERO,
            ..sp
        };
        assert_eq!(exact.offset_origin(Vec3::Z), exact.p);
    }

    /// The branch-free rounding moves every offset component one or two ulps beyond `p +
    /// offset` (near zero: by the smallest normal float), in the offset's direction, at every
    /// magnitude and across binade boundaries.
    #[test]
    fn offset_rounds_one_or_two_ulps_outward() {
        use pt_accel::float::next_float_up;
        let values = [
            0.0f32, -0.0, 1.0, -1.0, 2.0, 0.75, -4.0, 1e-30, -3e-38, 1e5, -1e5, 1e18, 7.0e-3,
        ];
        for &x in &values {
            for dir in [1.0f32, -1.0] {
                let sp = SurfacePoint {
                    p: Vec3::new(x, x, x),
                    // Tiny error, so that p + offset rounds back to p: only the rounding step
                    // moves the origin.
                    p_error: Vec3::splat(f32::from_bits(1)),
                    n: Vec3::new(1.0, -1.0, 0.0).normalize(),
                };
                let o = sp.offset_origin(Vec3::new(dir, -dir, 0.0));
                for (i, sign) in [(0, dir), (1, -dir)] {
                    let (v, base) = (o[i], sp.p[i] + sp.n[i] * dir * sp.n.abs().dot(sp.p_error));
                    let one = if sign > 0.0 {
                        next_float_up(base)
                    } else {
                        -next_float_up(-base)
                    };
                    let two = if sign > 0.0 {
                        next_float_up(one)
                    } else {
                        -next_float_up(-one)
                    };
                    let outward = if sign > 0.0 { v >= one } else { v <= one };
                    // At most two ulps, or the smallest normal float near zero.
                    let limit = (two - base).abs().max(f32::MIN_POSITIVE);
                    assert!(
                        outward && (v - base).abs() <= limit,
                        "x {x}, axis {i}, direction {sign}: {v} not beyond {one} within {limit}"
                    );
                }
                // No offset along z (the normal has no z part): z unchanged.
                assert_eq!(o.z, sp.p.z);
            }
        }
    }

    #[test]
    fn transformed_error_covers_the_exact_result() {
        let m = Affine3A::from_scale_rotation_translation(
            Vec3::new(1e3, 2.0, 0.5),
            glam::Quat::from_rotation_z(0.3),
            Vec3::new(1e5, -3.0, 7.0),
        );
        let p = Vec3::new(0.123, 4.56, -7.89);
        let (q, e) = transform_point_with_error(&m, p, Vec3::ZERO);
        let exact = glam::DAffine3::from_cols_array(&m.to_cols_array().map(f64::from))
            .transform_point3(p.as_dvec3());
        let diff = (q.as_dvec3() - exact).abs();
        assert!(diff.cmple(e.as_dvec3()).all(), "{diff} > {e}");
    }

    /// Random triangles (scales 1e-3..1e5, far from the origin, slivers) with barycentrics near
    /// their edges and error bounds up to a thousand times the interpolation's own.
    fn near_edge_cases() -> impl Iterator<Item = ([Vec3; 3], [f32; 3], Vec3)> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        (0..200_000).map(move |_| {
            let scale = 10f32.powf(rng.random_range(-3.0..5.0));
            let origin = Vec3::from_array(std::array::from_fn(|_| rng.random_range(-1e5..1e5)));
            let origin = if rng.random_bool(0.5) {
                origin
            } else {
                Vec3::ZERO
            };
            let mut p: [Vec3; 3] = std::array::from_fn(|_| {
                origin
                    + scale * Vec3::from_array(std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
            });
            if rng.random_bool(0.2) {
                // A sliver: the third corner almost on the line through the other two.
                p[2] = p[0].lerp(p[1], rng.random_range(0.0..1.0)) + (p[2] - p[0]) * 1e-3;
            }
            let mut b: [f32; 3] = std::array::from_fn(|_| {
                if rng.random_bool(0.5) {
                    rng.random_range(0.0..1e-3f32).powi(2)
                } else {
                    rng.random_range(0.0..1.0)
                }
            });
            let sum = b[0] + b[1] + b[2];
            b = b.map(|v| v / sum);
            b[0] = (1.0 - b[1]) - b[2];
            let err = barycentric_error(b, p) * rng.random_range(1.0..1000.0f32);
            (p, b, err)
        })
    }

    /// `near_edge` clears only points `pull_inside` leaves where they are (significance: none,
    /// a property checked over 200,000 cases; the test fails with its factor 4 made 1).
    #[test]
    fn near_edge_misses_no_point_that_needs_pulling() {
        let mut pulled = 0;
        for (p, b, err) in near_edge_cases() {
            if pull_inside(b, p, err).is_some() {
                pulled += 1;
                assert!(near_edge(b, p, err, 1.0), "{p:?} {b:?} {err}");
            }
        }
        assert!(pulled > 10_000, "only {pulled} cases pulled");
    }

    /// The same with the corners in object space and the error bound in world space, under
    /// transforms that shrink, stretch and shear (`edge_scale2`).
    #[test]
    fn near_edge_misses_no_transformed_point_that_needs_pulling() {
        let transforms = [
            Affine3A::from_scale(Vec3::new(1e-3, 1.0, 50.0)),
            Affine3A::from_cols(
                Vec3A::new(1.0, 0.0, 0.0),
                Vec3A::new(0.999, 0.01, 0.0),
                Vec3A::new(0.0, 0.3, 2.0),
                Vec3A::new(1e4, -1e4, 1e5),
            ),
            Affine3A::from_scale_rotation_translation(
                Vec3::new(3.0, 0.2, 1.0),
                glam::Quat::from_rotation_y(0.7),
                Vec3::ZERO,
            ),
        ];
        let mut pulled = 0;
        for (k, (p, b, err)) in near_edge_cases().take(60_000).enumerate() {
            let m = transforms[k % 3];
            let scale2 = edge_scale2(&m.matrix3.inverse().transpose());
            let w = p.map(|v| m.transform_point3(v));
            let err = err.max(barycentric_error(b, w) * 2.0);
            if pull_inside(b, w, err).is_some() {
                pulled += 1;
                assert!(near_edge(b, p, err, scale2), "{k}: {p:?} {b:?} {err}");
            }
        }
        assert!(pulled > 3_000, "only {pulled} cases pulled");
    }

    /// A pulled point lies on the triangle's side of every edge by at least the error bound it
    /// had, and on the triangle's plane within its new bound.
    #[test]
    fn pulled_points_lie_inside_by_their_bound() {
        for (p, b, err) in near_edge_cases() {
            let Some((q, e)) = pull_inside(b, p, err) else {
                continue;
            };
            let w = p.map(|v| v.as_dvec3());
            let n = (w[1] - w[0]).cross(w[2] - w[0]);
            let q = q.as_dvec3();
            for i in 0..3 {
                let (a, c) = (w[(i + 1) % 3], w[(i + 2) % 3]);
                // Distance from q to the line through the edge opposite corner i, on the
                // triangle's side of it.
                let inward = n.cross(c - a).normalize();
                let d = (q - a).dot(inward);
                assert!(
                    d >= err.as_dvec3().length(),
                    "{p:?} {b:?}: {d} from edge {i}, bound {err}"
                );
            }
            let off_plane = (q - w[0]).dot(n.normalize()).abs();
            assert!(off_plane <= e.as_dvec3().length(), "{off_plane} > {e}");
        }
    }
}
