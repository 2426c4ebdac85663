//! Per-query constants shared by the node tests of every BVH layout.

use glam::Vec3A;

use crate::float::gamma;
use crate::ray::Ray;

/// Direction components smaller than this are treated as this (with their sign), which keeps
/// every slab distance finite: coordinates up to 1e17 times the smallest direction component stay
/// far below f32::MAX, and distances along such an axis only matter when the ray origin lies
/// within 1e-20 * (hit distance) of a slab plane.
const MIN_DIR: f32 = 1e-20;

/// Bound on the relative rounding error of a slab distance computed from a box coordinate, the
/// ray origin and the reciprocal direction (three roundings, plus margin for the quantised
/// planes of the wide BVH).
pub(crate) const SLAB_GAMMA: f32 = gamma(7);

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeRay {
    pub origin: Vec3A,
    /// Reciprocal direction with tiny components clamped (see `MIN_DIR`).
    pub inv_dir: Vec3A,
    /// |origin| * |inv_dir|: the scale of the rounding error of slab distances.
    pub origin_scale: Vec3A,
    /// Which direction components are negative.
    pub neg: [bool; 3],
    pub t_min: f32,
}

impl NodeRay {
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = Vec3A::from(ray.dir);
        let safe = Vec3A::select(
            d.abs().cmplt(Vec3A::splat(MIN_DIR)),
            Vec3A::splat(MIN_DIR),
            d.abs(),
        );
        let inv_abs = Vec3A::ONE / safe;
        let neg = [d.x < 0.0, d.y < 0.0, d.z < 0.0];
        let sign = Vec3A::new(
            if neg[0] { -1.0 } else { 1.0 },
            if neg[1] { -1.0 } else { 1.0 },
            if neg[2] { -1.0 } else { 1.0 },
        );
        let origin = Vec3A::from(ray.origin);
        Self {
            origin,
            inv_dir: inv_abs * sign,
            origin_scale: origin.abs() * inv_abs,
            neg,
            t_min: ray.t_min.max(0.0),
        }
    }

    /// Entry and exit distances of the box `[lo, hi]` over `[t_min, t_max]`, widened by the
    /// rounding error bound of their computation; the box is hit when `enter <= exit`.
    #[inline(always)]
    pub fn slab(&self, lo: Vec3A, hi: Vec3A, t_max: f32) -> (f32, f32) {
        let t0 = (lo - self.origin) * self.inv_dir;
        let t1 = (hi - self.origin) * self.inv_dir;
        let slack =
            ((lo.abs().max(hi.abs())) * self.inv_dir.abs() + self.origin_scale) * SLAB_GAMMA;
        let near = t0.min(t1) - slack;
        let far = t0.max(t1) + slack;
        (
            near.max_element().max(self.t_min),
            far.min_element().min(t_max),
        )
    }
}
