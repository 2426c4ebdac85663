//! Per-query constants shared by the node tests of every BVH layout.

use glam::Vec3A;

use crate::float::gamma;
use crate::ray::Ray;

/// Direction components smaller than this are treated as this (with their sign), which keeps
/// every slab distance finite: coordinates up to 1e17 times the smallest direction component stay
/// far below f32::MAX, and distances along such an axis only matter when the ray origin lies
/// within 1e-20 * (hit distance) of a slab plane.
pub(crate) const MIN_DIR: f32 = 1e-20;

/// Bound on the relative rounding error of a slab distance computed from a box coordinate, the
/// ray origin and the reciprocal direction (three roundings, plus margin for the quantised
/// planes of the wide BVH).
pub(crate) const SLAB_GAMMA: f32 = gamma(7);

/// Widening of a box's exit distance for the conservative slab test.
const BOX_EXIT_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NodeRay {
    pub origin: Vec3A,
    /// Reciprocal direction with tiny components clamped (see `MIN_DIR`), for the quantised
    /// wide-BVH test.
    pub inv_dir: Vec3A,
    /// Exact reciprocal direction (infinite for zero components), for the plain box test.
    pub inv_dir_exact: Vec3A,
    /// True when `inv_dir_exact` has an infinite component, so slab distances can be NaN.
    pub has_infinite_inverse: bool,
    /// |origin|, for the rounding error bound of slab distances.
    pub origin_abs: Vec3A,
    /// `SLAB_GAMMA * |inv_dir|`: slab distance error per unit of coordinate magnitude.
    pub slack_scale: Vec3A,
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
            inv_dir_exact: Vec3A::ZERO,
            has_infinite_inverse: false,
            origin_abs: origin.abs(),
            slack_scale: inv_abs * SLAB_GAMMA,
            neg,
            t_min: ray.t_min.max(0.0),
        }
    }

    /// The ray prepared for [`box_entry`](Self::box_entry) (the binary BVH), which also needs
    /// the exact reciprocal direction.
    #[inline]
    pub fn for_boxes(ray: &Ray) -> Self {
        let mut r = Self::new(ray);
        r.inv_dir_exact = Vec3A::ONE / Vec3A::from(ray.dir);
        r.has_infinite_inverse = !r.inv_dir_exact.is_finite();
        r
    }

    /// Entry distance of the box `[lo, hi]` if the ray overlaps it within `[t_min, t_max]`,
    /// else infinity. Each slab distance `(bound - origin) * inv_dir` is within 3 ulps of its
    /// real value relative to itself (no cancellation is possible), so widening the exit distance
    /// by `1 + 2 gamma(3)` makes the test conservative (*Physically Based Rendering*, 4th ed.,
    /// section 6.8.2).
    ///
    /// With the exact reciprocal, a direction component of zero gives infinite slab distances,
    /// and NaN (`0 * inf`) exactly when the origin lies in one of that slab's planes: the ray then
    /// runs along the slab's face and that axis does not bound it, so NaN counts as `-inf` for the
    /// entry and `+inf` for the exit.
    #[inline(always)]
    pub fn box_entry(&self, lo: Vec3A, hi: Vec3A, t_max: f32) -> f32 {
        let t0 = (lo - self.origin) * self.inv_dir_exact;
        let t1 = (hi - self.origin) * self.inv_dir_exact;
        if !self.has_infinite_inverse {
            // Finite times finite cannot be NaN: the plain test (the common case, chosen per ray).
            let near = t0.min(t1).max_element().max(self.t_min);
            let far = t0.max(t1).min_element() * BOX_EXIT_SCALE;
            return if near <= far.min(t_max) {
                near
            } else {
                f32::INFINITY
            };
        }
        let (nan0, nan1) = (t0.is_nan_mask(), t1.is_nan_mask());
        let lo_side = Vec3A::select(nan0, Vec3A::NEG_INFINITY, t0).min(Vec3A::select(
            nan1,
            Vec3A::NEG_INFINITY,
            t1,
        ));
        let hi_side =
            Vec3A::select(nan0, Vec3A::INFINITY, t0).max(Vec3A::select(nan1, Vec3A::INFINITY, t1));
        let near = lo_side.max_element().max(self.t_min);
        let far = hi_side.min_element() * BOX_EXIT_SCALE;
        if near <= far.min(t_max) {
            near
        } else {
            f32::INFINITY
        }
    }
}
