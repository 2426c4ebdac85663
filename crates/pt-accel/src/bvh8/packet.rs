//! Eight rays through a small [`Bvh8`] together: the lanes of a vector are the rays.
//!
//! One ray at a time, a query pays its set-up, its stack, its pops and its branches for every
//! node and leaf it visits; on a scene of a few dozen triangles (Mitsuba's Cornell box, the
//! figures' boxes) that is most of the query. Here a node's children are tested one child at a
//! time against all eight rays (the child's box broadcast, the rays in lanes), and a leaf's
//! triangles one triangle at a time against all eight rays, so that the fixed costs are paid
//! once per packet. A packet visits every node and leaf that any of its active rays enters; a
//! stack entry keeps the child, the rays that entered it and their entry distances, and a ray
//! whose closest hit so far lies before its entry distance drops out of the entry when it is
//! popped. Rays of a big tree spread over many nodes with one or two rays each, where one ray at
//! a time is faster: [`Bvh8::packets_pay`] decides by the size of the tree and the rays'
//! directions.
//!
//! # The same answers as one ray at a time
//!
//! - The node test is the robust form of `traverse.rs` (exact reciprocal, the near plane chosen
//!   per ray by the sign of its direction, NaN candidates ignored, the exit distance widened),
//!   lane by lane: every box the exact ray enters within its range is entered.
//! - The triangle test is the four-lane test's operations in the same order, with the rays in
//!   the lanes instead of the triangles: the per-ray permutation of axes is a selection per lane,
//!   and every lane rounds exactly as the scalar test does. A lane with an edge function exactly
//!   zero (or NaN) in f32 is finished by the scalar test, which recomputes that edge in f64.
//! - On a small tree a crossing is accepted without working out its own bound on `t`'s
//!   rounding error when `t` exceeds a bound for every triangle of the tree, made once per
//!   query from the tree's box (`Rays::q`): the same decision, since the triangle's own bound is
//!   at most that one, with the maxima and the bound's arithmetic left for crossings near the
//!   origin (Mitsuba's box +1-3%).
//! - Of hits at the same distance the lowest (packet, lane) of the tree's triangle packets wins,
//!   as in the one-ray traversal, so the answer does not depend on the order of the walk: each
//!   lane gets exactly what [`Bvh8::closest`] gives its ray (the same triangle, the same bits),
//!   and [`Bvh8::occluded`]'s answer. One known exception: a ray that starts within rounding of
//!   two coplanar triangles in different leaves (a box resting on a floor) and crosses them at
//!   a glancing angle may find each at a `t` before the other's leaf box is entered (the
//!   triangle test's error, relative to so small a `t`, is larger than the culling margin), and
//!   then the kernel that visits the other leaf first reports the other triangle; both are
//!   crossings of the same plane at the same point up to that error.

use std::mem::MaybeUninit;

use crate::bounds::Bounds3;
use crate::lanes::{FloatLanes, MaskLanes, Simd, UintLanes, WIDTH, WithSimd, bits};
use crate::ray::RayLanes;
use crate::stack::Stack;
use crate::store::PrimRef;
use crate::triangle::{ERROR_CONSTANTS, Maxima, RayTriangleTest, TriangleHit, Triangles4};

use super::traverse::BOX_EXIT_SCALE;
use super::{Bvh8, LEAF, Node8, PacketCorners};

/// Trees with at most this many nodes are traced a packet at a time whatever the rays (a tree
/// this small has at most a few hundred triangles, and the packet's rays meet most of them).
pub(super) const MAX_NODES: usize = 16;
/// Fewer rays than this go one at a time: a packet's tests cost the same for one ray as for
/// eight. Not on a tree with corner records (small, every query through the packets): there
/// one to three rays in a packet were faster than one at a time, whose traversal branches
/// where the packet's does not (Mitsuba's box +1.5%, `cornell_box` +3.8%).
const MIN_RAYS: u32 = 4;
/// Stack entries of the packet kernels: the most any tree may need.
const STACK: usize = super::MAX_STACK;
/// The closest-hit kernel's stack for trees that need no more (Mitsuba's box, the figures'
/// boxes): an entry holds a lane vector of entry distances (64 bytes or more), so the full
/// stack is tens of KiB, whose pages the function's prologue probes on every call.
const SMALL_STACK: usize = 24;
/// Trees with more triangle packets than this go one ray at a time: the packet kernels keep
/// each lane's hit as `4 packet + lane` in an `f32`, exact below 2^24.
const MAX_PACKETS: usize = 1 << 22;

impl Bvh8 {
    /// Whether the rays of `mask`'s lanes are traced a packet at a time: on a tree with corner
    /// records always; on another small tree from [`MIN_RAYS`] rays; on a bigger one, from
    /// [`MIN_RAYS`] rays, when their directions all lie in one octant (camera rays, and
    /// what a mirror or glass makes of them), where they stay together down the tree. Rays
    /// that spread (diffuse bounces) would visit the union of their paths with a lane or two
    /// each: one ray at a time is faster for them.
    // Always inlined, as all lane code (out of line in a baseline build, each lane operation
    // was a call).
    #[inline(always)]
    pub(super) fn packets_pay<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32) -> bool {
        if (mask.count_ones() < MIN_RAYS && self.corners.is_empty())
            || self.stack_need > STACK
            || self.packets.len() > MAX_PACKETS
        {
            return false;
        }
        if self.nodes.len() <= MAX_NODES {
            return true;
        }
        // Per axis, the lanes whose direction is negative: the rays of `mask` share an octant
        // when each axis's are all of them or none. (Where `-0.0` goes decides only which
        // kernel answers, not the answer.) No closure over lane values (see `WithSimd`).
        let (d, zero) = (&rays.dir, s.splat(0.0));
        let neg = [
            s.load(d[0]).lt(zero).bits() & mask,
            s.load(d[1]).lt(zero).bits() & mask,
            s.load(d[2]).lt(zero).bits() & mask,
        ];
        neg.iter().all(|&m| m == 0 || m == mask)
    }

    /// The closest hits of the rays of `mask`'s lanes, a packet at a time: each exactly what
    /// [`Self::closest`] gives its ray.
    ///
    /// Behind its own entry, out of line, even for a caller already running with the lanes'
    /// instruction set (the lane tracer): inlined into that caller, the kernel ran 1.6% slower
    /// in a build for the host CPU (Intel Xeon) and 2.3% slower in a build for baseline x86-64
    /// (AMD Zen 5), where out of line it runs as fast as the host build's
    /// (docs/performance-log.md). The entry's lanes were found when the tree was built.
    pub(super) fn closest_packet(
        &self,
        rays: &RayLanes,
        mask: u32,
    ) -> [Option<(PrimRef, TriangleHit)>; WIDTH] {
        self.lanes.run(ClosestJob {
            bvh: self,
            rays,
            mask,
        })
    }

    /// Which rays of `mask`'s lanes hit anything, a packet at a time, each as
    /// [`Self::occluded`] says.
    pub(super) fn occluded_packet(&self, rays: &RayLanes, mask: u32) -> u32 {
        self.lanes.run(OccludedJob {
            bvh: self,
            rays,
            mask,
        })
    }
}

/// A closest-hit packet query.
struct ClosestJob<'a> {
    bvh: &'a Bvh8,
    rays: &'a RayLanes,
    mask: u32,
}

impl WithSimd for ClosestJob<'_> {
    type Output = [Option<(PrimRef, TriangleHit)>; WIDTH];
    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> Self::Output {
        let (bvh, rays, mask) = (self.bvh, self.rays, self.mask);
        if !bvh.corners.is_empty() {
            closest::<S, SMALL_STACK, true>(bvh, s, rays, mask)
        } else if bvh.stack_need <= SMALL_STACK {
            closest::<S, SMALL_STACK, false>(bvh, s, rays, mask)
        } else {
            closest::<S, STACK, false>(bvh, s, rays, mask)
        }
    }
}

/// An any-hit packet query.
struct OccludedJob<'a> {
    bvh: &'a Bvh8,
    rays: &'a RayLanes,
    mask: u32,
}

impl WithSimd for OccludedJob<'_> {
    type Output = u32;
    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> u32 {
        if self.bvh.corners.is_empty() {
            occluded::<S, false>(self.bvh, s, self.rays, self.mask)
        } else {
            occluded::<S, true>(self.bvh, s, self.rays, self.mask)
        }
    }
}

/// `v[k]` per lane, where `k0` marks the lanes whose `k` is 0 and `k1` those whose is 1.
#[inline(always)]
fn select3<S: Simd>(k0: S::M, k1: S::M, v: [S::F; 3]) -> S::F {
    S::F::select(k0, v[0], S::F::select(k1, v[1], v[2]))
}

/// [`ERROR_CONSTANTS`] in lanes.
#[inline(always)]
fn error_constants<S: Simd>(s: S) -> [S::F; 5] {
    let [c0, c1, c2, c3, c4] = ERROR_CONSTANTS;
    [
        s.splat(c0),
        s.splat(c1),
        s.splat(c2),
        s.splat(c3),
        s.splat(c4),
    ]
}

/// The largest magnitude of three lanes.
#[inline(always)]
fn max3<F: FloatLanes>(v: [F; 3]) -> F {
    v[0].abs().max(v[1].abs()).max(v[2].abs())
}

/// The eight rays' constants: the node test's and the triangle test's, one lane per ray.
struct Rays<S: Simd> {
    o: [S::F; 3],
    /// `1 / dir`, infinite where a component is zero.
    inv: [S::F; 3],
    /// Per axis, the lanes whose `inv` is negative (the near plane is the box's maximum).
    neg: [S::M; 3],
    /// `max(t_min, 0)`: where entry distances start.
    t_near: S::F,
    /// Per permuted axis `j` (x, y, z), the lanes whose `k[j]` is 0 and those whose is 1.
    k0: [S::M; 3],
    k1: [S::M; 3],
    /// Per permuted axis `j`, each lane's `k[j]`: the same choice as an index for
    /// [`Simd::pick`].
    k: [S::U; 3],
    /// The origin's coordinates along the permuted axes.
    ko: [S::F; 3],
    sx: S::F,
    sy: S::F,
    sz: S::F,
    t_min: S::F,
    /// At least the largest `3 (...)` factor of [`Maxima::t_error_bound`] over every triangle
    /// of the tree, per ray (see [`Self::new`]): a crossing with `t > q |1 / det|` is beyond
    /// its error bound without computing it.
    q: S::F,
}

impl<S: Simd> Rays<S> {
    /// The constants of [`RayTriangleTest::new`] and of the robust node test, lane by lane,
    /// with the same operations.
    #[inline(always)]
    fn new(s: S, rays: &RayLanes, bounds: &Bounds3) -> Self {
        let zero = s.splat(0.0);
        let o = [
            s.load(rays.origin[0]),
            s.load(rays.origin[1]),
            s.load(rays.origin[2]),
        ];
        let d = [
            s.load(rays.dir[0]),
            s.load(rays.dir[1]),
            s.load(rays.dir[2]),
        ];
        let t_min = s.load(rays.t_min);
        let one = s.splat(1.0);
        let inv = [one / d[0], one / d[1], one / d[2]];
        // The dominant axis kz, as `RayTriangleTest::new` chooses it; kx and ky follow it
        // cyclically.
        let (ax, ay, az) = (d[0].abs(), d[1].abs(), d[2].abs());
        let x_over_y = ax.gt(ay);
        let kz0 = x_over_y & ax.gt(az);
        let kz1 = !x_over_y & ay.gt(az);
        let kz2 = !(kz0 | kz1);
        let (k0, k1) = ([kz2, kz1, kz0], [kz0, kz2, kz1]);
        let sz = one / select3::<S>(k0[2], k1[2], d);
        let sx = -select3::<S>(k0[0], k1[0], d) * sz;
        let sy = -select3::<S>(k0[1], k1[1], d) * sz;
        // Bounds on the maxima of every triangle's test (`Maxima`), from the box of the tree's
        // triangles (the store's, over the same corners the packets hold): each
        // corner lies within `far[a]` of the origin along axis `a`, and the test's coordinates
        // are at most these sums, up to a few roundings, which the factor `M` covers many times
        // over. Each step of `t_error_bound` is monotone in the maxima (non-negative terms),
        // as is rounding, so `q` is at least the test's factor for every triangle. A NaN or
        // infinite `q` (rays or coordinates beyond f32's range) sends every crossing to the
        // exact bound.
        // Written out: no closure over lane values (see `WithSimd`).
        let (lo, hi) = (bounds.min, bounds.max);
        let far = [
            (s.splat(hi[0]) - o[0])
                .abs()
                .max((s.splat(lo[0]) - o[0]).abs()),
            (s.splat(hi[1]) - o[1])
                .abs()
                .max((s.splat(lo[1]) - o[1]).abs()),
            (s.splat(hi[2]) - o[2])
                .abs()
                .max((s.splat(lo[2]) - o[2]).abs()),
        ];
        let m = s.splat(1.0 + 2.0f32.powi(-16));
        let far_z = select3::<S>(k0[2], k1[2], far);
        let max_x = (select3::<S>(k0[0], k1[0], far) + far_z * sx.abs()) * m;
        let max_y = (select3::<S>(k0[1], k1[1], far) + far_z * sy.abs()) * m;
        let max_z_raw = far_z * m;
        let maxima = Maxima {
            x: max_x,
            y: max_y,
            z: max_z_raw * sz.abs() * m,
            z_raw: max_z_raw,
            e: max_x * max_y * s.splat(2.0) * m,
        };
        let q = maxima.t_error_bound(one, error_constants(s));
        Self {
            o,
            inv,
            neg: [inv[0].lt(zero), inv[1].lt(zero), inv[2].lt(zero)],
            // Entry distances start at the range's start, and at 0 for a negative one.
            t_near: S::F::select(t_min.gt(zero), t_min, zero),
            k: [
                index3::<S>(s, k0[0], k1[0]),
                index3::<S>(s, k0[1], k1[1]),
                index3::<S>(s, k0[2], k1[2]),
            ],
            k0,
            k1,
            ko: [
                select3::<S>(k0[0], k1[0], o),
                select3::<S>(k0[1], k1[1], o),
                select3::<S>(k0[2], k1[2], o),
            ],
            sx,
            sy,
            sz,
            t_min,
            q,
        }
    }

    /// Which of the `active` rays enter child `c` of `node` before `end` (lane `i` for ray
    /// `i`), and their entry distances.
    #[inline(always)]
    fn enter(&self, s: S, node: &Node8, c: usize, active: S::M, end: S::F) -> (S::M, S::F) {
        let p = &node.planes;
        let mut near = self.t_near;
        let mut far = s.splat(f32::INFINITY);
        for a in 0..3 {
            let (lo, hi) = (s.splat(p[2 * a].0[c]), s.splat(p[2 * a + 1].0[c]));
            let tn = (S::F::select(self.neg[a], hi, lo) - self.o[a]) * self.inv[a];
            let tf = (S::F::select(self.neg[a], lo, hi) - self.o[a]) * self.inv[a];
            // NaN (the origin in the plane of a parallel axis) leaves the bound as it was.
            near = tn.max(near);
            far = tf.min(far);
        }
        let far = (far * s.splat(BOX_EXIT_SCALE)).min(end);
        (near.le(far) & active, near)
    }

    /// Corner `c` of triangle `i` of packet `p` translated, permuted and sheared into every
    /// ray's space: its x, y and unsheared z.
    #[inline(always)]
    fn corner(&self, s: S, p: &Triangles4, i: usize, c: usize) -> (S::F, S::F, S::F) {
        let v = [
            s.splat(AsRef::<[f32; 4]>::as_ref(&p.x[c])[i]),
            s.splat(AsRef::<[f32; 4]>::as_ref(&p.y[c])[i]),
            s.splat(AsRef::<[f32; 4]>::as_ref(&p.z[c])[i]),
        ];
        let z_raw = select3::<S>(self.k0[2], self.k1[2], v) - self.ko[2];
        (
            (select3::<S>(self.k0[0], self.k1[0], v) - self.ko[0]) + z_raw * self.sx,
            (select3::<S>(self.k0[1], self.k1[1], v) - self.ko[1]) + z_raw * self.sy,
            z_raw,
        )
    }

    /// [`Self::corner`] from the corner's record `[x, y, z, 0]`: the same values, each
    /// coordinate picked per lane by one permutation instead of three broadcasts and two
    /// blends.
    #[inline(always)]
    fn picked_corner(&self, s: S, v: &[f32; 4]) -> (S::F, S::F, S::F) {
        let z_raw = s.pick(v, self.k[2]) - self.ko[2];
        (
            (s.pick(v, self.k[0]) - self.ko[0]) + z_raw * self.sx,
            (s.pick(v, self.k[1]) - self.ko[1]) + z_raw * self.sy,
            z_raw,
        )
    }

    /// The three corners of triangle `i` of packet `p` in every ray's space: from the
    /// packet's corner records `pc` when `PICK` (trees that have them), else from `p`.
    #[inline(always)]
    fn corners<const PICK: bool>(
        &self,
        s: S,
        p: &Triangles4,
        pc: &PacketCorners,
        i: usize,
    ) -> Corners<S> {
        if PICK {
            let c = &pc[i];
            [
                self.picked_corner(s, &c[0]),
                self.picked_corner(s, &c[1]),
                self.picked_corner(s, &c[2]),
            ]
        } else {
            [
                self.corner(s, p, i, 0),
                self.corner(s, p, i, 1),
                self.corner(s, p, i, 2),
            ]
        }
    }

    /// A triangle whose corners are `c` against the `live` rays, up to the choice of hits: the
    /// four-lane test's operations, lane by lane (see the module docs), with the scaled
    /// distances checked against `t_max`. `SMALL`: for a small tree (the one whose corners
    /// are read from records), see below.
    #[inline(always)]
    fn triangle<const SMALL: bool>(&self, s: S, c: Corners<S>, t_max: S::F, live: u32) -> Pass<S> {
        let zero = s.splat(0.0);
        let [c0, c1, c2] = c;
        let (x, y, z_raw) = ([c0.0, c1.0, c2.0], [c0.1, c1.1, c2.1], [c0.2, c1.2, c2.2]);
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        let neg = [e[0].lt(zero), e[1].lt(zero), e[2].lt(zero)];
        let pos = [e[0].gt(zero), e[1].gt(zero), e[2].gt(zero)];
        let decided = ((neg[0] | pos[0]) & (neg[1] | pos[1]) & (neg[2] | pos[2])).bits();
        let uncertain = live & !decided;
        let straddles = ((neg[0] | neg[1] | neg[2]) & (pos[0] | pos[1] | pos[2])).bits();
        let inside = live & decided & !straddles;
        let miss = Pass {
            hit: 0,
            uncertain,
            t: zero,
            inv_det: zero,
            e1: zero,
            e2: zero,
        };
        // Where no ray is inside the edges, the test ends here, except on a small tree: there
        // every ray takes the packets, incoherent ones too, for which this branch went either
        // way and its mispredictions cost more than the distance test it skips (Mitsuba's
        // box +2.8%). Coherent packets on a big tree mostly miss a leaf's triangles together
        // and gain from it (the glass bunny lost 5% without it). The exit after the distance
        // test stays for both (without it, the box -3%; docs/performance-log.md).
        if !SMALL && inside == 0 {
            return miss;
        }
        let det = e[0] + e[1] + e[2];
        let z = [z_raw[0] * self.sz, z_raw[1] * self.sz, z_raw[2] * self.sz];
        let t_scaled = (e[0] * z[0] + e[1] * z[1]) + e[2] * z[2];
        let det_ok = !det.eq(zero) & det.is_finite();
        let bound = t_max * det;
        let in_range = (det.gt(zero) & t_scaled.gt(zero) & t_scaled.le(bound))
            | (det.lt(zero) & t_scaled.lt(zero) & t_scaled.ge(bound));
        if (det_ok & in_range).bits() & inside == 0 {
            return miss;
        }
        let inv_det = s.splat(1.0) / det;
        let t = t_scaled * inv_det;
        let t_ok = t.ge(self.t_min) & t.is_finite();
        let crossed = (det_ok & in_range & t_ok).bits() & inside;
        // On a small tree, crossings beyond the bound for any of its triangles (`Rays::q`)
        // are accepted without the triangle's own bound (the same decision: that bound is at
        // most `q |1 / det|`), which is worked out only for crossings nearer the origin. On a
        // big tree `q` is far too loose (its triangles are small against the tree's box,
        // which bounds their ray-space coordinates) and every crossing takes its own bound.
        let far = t.gt(self.q * inv_det.abs()).bits();
        let mut accepted = crossed & far;
        if !SMALL || crossed & !far != 0 {
            let m = Maxima {
                x: max3(x),
                y: max3(y),
                z: max3(z),
                z_raw: max3(z_raw),
                e: max3(e),
            };
            accepted = crossed
                & t.gt(m.t_error_bound(inv_det.abs(), error_constants(s)))
                    .bits();
        }
        Pass {
            hit: accepted,
            // Crossings within the error bound: the scalar test decides them in f64.
            uncertain: uncertain | (crossed & !accepted),
            t,
            inv_det,
            e1: e[1],
            e2: e[2],
        }
    }
}

/// A triangle's three corners in every ray's space: x, y and unsheared z.
type Corners<S> = [(<S as Simd>::F, <S as Simd>::F, <S as Simd>::F); 3];

/// Stands for the corner records of a tree that has none (the kernels that read them are not
/// run for it).
const NO_CORNERS: PacketCorners = [[[0.0; 4]; 3]; 4];

/// Per lane, 0 where `k0` is set, 1 where `k1` is, 2 elsewhere.
#[inline(always)]
fn index3<S: Simd>(s: S, k0: S::M, k1: S::M) -> S::U {
    S::U::select(
        k0,
        s.splat_u(0),
        S::U::select(k1, s.splat_u(1), s.splat_u(2)),
    )
}

/// The corner records of `bvh`'s packets ([`Bvh8`]'s `corners`) when the packet kernels take
/// every lane query of it and its stack is small; none otherwise.
pub(super) fn corners(bvh: &Bvh8) -> Vec<PacketCorners> {
    if bvh.nodes.len() > MAX_NODES || bvh.stack_need > SMALL_STACK {
        return Vec::new();
    }
    bvh.packets
        .iter()
        .map(|p| {
            std::array::from_fn(|i| std::array::from_fn(|c| [p.x[c][i], p.y[c][i], p.z[c][i], 0.0]))
        })
        .collect()
}

/// What one triangle's test decided in f32 for the eight rays.
struct Pass<S: Simd> {
    /// Rays that hit it, among those decided in f32 (before the closest-hit range check on
    /// the divided distance).
    hit: u32,
    /// Rays with an edge function exactly zero (or NaN) in f32, or crossing within the f32
    /// bound on `t`'s error: the scalar test decides them (in f64).
    uncertain: u32,
    t: S::F,
    inv_det: S::F,
    e1: S::F,
    e2: S::F,
}

/// A closest-hit stack entry: a child, the rays that entered it and their entry distances.
///
/// A node's entered children are pushed in slot order, not sorted by distance: the sort (the
/// nearest entry distance among the rays, and an insertion that moves whole entries) cost
/// more than the rays' walk gained from it, on small trees with incoherent packets (Mitsuba's
/// box 4.9% slower) and on big ones with camera rays (the bunny's closest hits 3.1%, the
/// dragon's 4.8%; docs/performance-log.md, thirteenth session). The answers do not depend on
/// the order.
struct Entry<S: Simd> {
    near: S::F,
    child: u32,
    mask: u32,
}

impl<S: Simd> Clone for Entry<S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: Simd> Copy for Entry<S> {}

/// The end of each ray's range as entry distances are compared with it (the robust form of
/// `traverse.rs`'s `range_end`).
#[inline(always)]
fn range_end<S: Simd>(s: S, t_max: S::F) -> S::F {
    t_max + t_max * s.splat(2.0f32.powi(-21))
}

/// The closest hits of `mask`'s rays, with a stack of `N` entries (at least the tree's
/// `stack_need`), the triangles' corners read from the tree's corner records when `PICK`.
#[inline(always)]
fn closest<S: Simd, const N: usize, const PICK: bool>(
    bvh: &Bvh8,
    s: S,
    rays: &RayLanes,
    mask: u32,
) -> [Option<(PrimRef, TriangleHit)>; WIDTH] {
    let mut out = [None; WIDTH];
    let Some(root) = bvh.root else {
        return out;
    };
    let r = Rays::new(s, rays, &bvh.store.bounds);
    let (zero, inf) = (s.splat(0.0), s.splat(f32::INFINITY));
    // Per ray: the closest hit so far, and its packet and lane as `4 packet + lane` (exact in
    // f32: `packets_pay` keeps bigger trees out; infinite while there is none).
    let ray_t_max = s.load(rays.t_max);
    let mut best_t = ray_t_max;
    let mut best_i = inf;
    let (mut best_b1, mut best_b2) = (zero, zero);
    let mut end = range_end(s, best_t);
    // What the triangles' scaled distances are checked against (`tie_bound`).
    let mut bound = ray_t_max;
    let mut slots = [const { MaybeUninit::uninit() }; N];
    let mut stack = Stack::<Entry<S>>::new(&mut slots);
    let (mut cur, mut active) = (root, mask);
    loop {
        if cur & LEAF == 0 {
            let node = bvh.node(cur);
            let active_m = s.mask(active);
            // Children fill the slots from the first; an empty slot ends them.
            for c in 0..8 {
                let child = node.child[c];
                if child == 0 {
                    break;
                }
                let (entered, near) = r.enter(s, node, c, active_m, end);
                // Written whether entered or not, kept only when entered: no branch on it
                // (Mitsuba's box +4%, the dragon's camera rays +7.5%).
                let m = entered.bits();
                stack.push_if(
                    Entry {
                        near,
                        child,
                        mask: m,
                    },
                    m != 0,
                );
            }
        } else {
            let (first, packets) = bvh.leaf_packets(cur);
            for (k, p) in packets.iter().enumerate() {
                let refs = &bvh.refs[first + k];
                let pc = if PICK {
                    &bvh.corners[first + k]
                } else {
                    &NO_CORNERS
                };
                for i in 0..4 {
                    // A leaf's last packet repeats its last triangle.
                    if i > 0 && refs[i] == refs[i - 1] {
                        break;
                    }
                    let pass = r.triangle::<PICK>(s, r.corners::<PICK>(s, p, pc, i), bound, active);
                    let idx = s.splat((4 * (first + k) + i) as f32);
                    let hit = pass.hit & pass.t.le(best_t).bits();
                    if hit != 0 {
                        let nearer = pass.t.lt(best_t) | (pass.t.eq(best_t) & idx.lt(best_i));
                        let take = nearer & s.mask(hit);
                        best_t = S::F::select(take, pass.t, best_t);
                        best_i = S::F::select(take, idx, best_i);
                        best_b1 = S::F::select(take, pass.e1 * pass.inv_det, best_b1);
                        best_b2 = S::F::select(take, pass.e2 * pass.inv_det, best_b2);
                    }
                    if pass.uncertain != 0 {
                        let (mut t, mut bi) = (best_t.to_array(), best_i.to_array());
                        let (mut b1, mut b2) = (best_b1.to_array(), best_b2.to_array());
                        let (tri, bound) = (p.lane(i), bound.to_array());
                        let here = (4 * (first + k) + i) as f32;
                        for lane in bits(pass.uncertain) {
                            if let Some(h) = RayTriangleTest::new(&rays.get(lane))
                                .intersect_packed(&tri, bound[lane])
                                && (h.t < t[lane] || (h.t == t[lane] && here < bi[lane]))
                            {
                                (t[lane], bi[lane], b1[lane], b2[lane]) = (h.t, here, h.b1, h.b2);
                            }
                        }
                        (best_t, best_i) = (s.load(t), s.load(bi));
                        (best_b1, best_b2) = (s.load(b1), s.load(b2));
                    }
                }
            }
            end = range_end(s, best_t);
            bound = ray_t_max.min(best_t + best_t * s.splat(2.0f32.powi(-21)));
        }
        // Next: the last pushed child that a ray still needs.
        loop {
            let Some(e) = stack.pop() else {
                let (t, bi) = (best_t.to_array(), best_i.to_array());
                let (b1, b2) = (best_b1.to_array(), best_b2.to_array());
                for lane in bits(mask) {
                    if bi[lane] != f32::INFINITY {
                        let idx = bi[lane] as usize;
                        let hit = TriangleHit {
                            t: t[lane],
                            b1: b1[lane],
                            b2: b2[lane],
                        };
                        out[lane] = Some((bvh.refs[idx / 4][idx % 4], hit));
                    }
                }
                return out;
            };
            let m = e.mask & e.near.le(end).bits();
            if m != 0 {
                (cur, active) = (e.child, m);
                break;
            }
        }
    }
}

/// Which of `mask`'s rays hit anything, the triangles' corners read from the tree's corner
/// records when `PICK`.
#[inline(always)]
fn occluded<S: Simd, const PICK: bool>(bvh: &Bvh8, s: S, rays: &RayLanes, mask: u32) -> u32 {
    let Some(root) = bvh.root else {
        return 0;
    };
    let r = Rays::new(s, rays, &bvh.store.bounds);
    let t_max = s.load(rays.t_max);
    let end = range_end(s, t_max);
    let mut blocked = 0u32;
    let mut slots = [const { MaybeUninit::uninit() }; STACK];
    let mut stack = Stack::<u64>::new(&mut slots);
    let (mut cur, mut active) = (root, mask);
    loop {
        if cur & LEAF == 0 {
            let node = bvh.node(cur);
            let active_m = s.mask(active);
            for c in 0..8 {
                let child = node.child[c];
                if child == 0 {
                    break;
                }
                // No branch on whether the child is entered, as in the closest-hit kernel.
                let m = r.enter(s, node, c, active_m, end).0.bits();
                stack.push_if(u64::from(m) << 32 | u64::from(child), m != 0);
            }
        } else {
            let (first, packets) = bvh.leaf_packets(cur);
            'leaf: for (k, p) in packets.iter().enumerate() {
                let refs = &bvh.refs[first + k];
                let pc = if PICK {
                    &bvh.corners[first + k]
                } else {
                    &NO_CORNERS
                };
                for i in 0..4 {
                    if (i > 0 && refs[i] == refs[i - 1]) || active == 0 {
                        break 'leaf;
                    }
                    let pass = r.triangle::<PICK>(s, r.corners::<PICK>(s, p, pc, i), t_max, active);
                    let mut hit = pass.hit;
                    if pass.uncertain != 0 {
                        let (tri, t) = (p.lane(i), t_max.to_array());
                        for lane in bits(pass.uncertain) {
                            if RayTriangleTest::new(&rays.get(lane))
                                .intersect_packed(&tri, t[lane])
                                .is_some()
                            {
                                hit |= 1 << lane;
                            }
                        }
                    }
                    blocked |= hit;
                    active &= !hit;
                }
            }
            if blocked == mask {
                return blocked;
            }
        }
        loop {
            let Some(e) = stack.pop() else {
                return blocked;
            };
            let m = (e >> 32) as u32 & !blocked;
            if m != 0 {
                (cur, active) = (e as u32, m);
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::BuildQuality;
    use crate::Ray;
    use crate::bvh8::traverse::tests::{rays, sphere};
    use crate::mesh::TriangleMesh;
    use crate::store::TriangleStore;

    type Closest = Option<(PrimRef, TriangleHit)>;

    /// Small trees (every query through the packet kernels) are priced for those kernels:
    /// leaves of one packet, and few enough nodes to stay small. Bigger ones keep the one-ray
    /// pricing, whose leaves may hold two packets.
    #[test]
    fn small_trees_are_priced_for_the_packet_kernels() {
        let leaf_packets = |bvh: &Bvh8| -> Vec<usize> {
            bvh.nodes
                .iter()
                .flat_map(|n| n.child)
                .filter(|&c| c & LEAF != 0)
                .map(|c| bvh.leaf_packets(c).1.len())
                .collect()
        };
        let build = |n: u32| {
            let mesh = sphere(n, 1.0, Vec3::ZERO);
            let bvh = Bvh8::build(TriangleStore::from_mesh(&mesh), BuildQuality::Medium, true)
                .unwrap_or_else(|_| panic!("the sphere fits the stack"));
            (mesh.triangle_count(), bvh)
        };
        // 24, 80 and 224 triangles.
        for n in [3, 5, 8] {
            let (triangles, bvh) = build(n);
            assert!(triangles <= super::super::PACKET_PRICED_TRIANGLES);
            assert!(bvh.node_count() <= MAX_NODES, "{triangles} triangles");
            let leaves = leaf_packets(&bvh);
            assert!(
                !leaves.is_empty() && leaves.iter().all(|&p| p == 1),
                "{leaves:?}"
            );
        }
        // 960 triangles.
        let (triangles, bvh) = build(16);
        assert!(triangles > super::super::PACKET_PRICED_TRIANGLES);
        assert!(leaf_packets(&bvh).contains(&2));
        // A small tree that answers one ray at a time (a two-level accelerator's bottom tree)
        // keeps the one-ray pricing: the 80-triangle sphere, all one-packet leaves above, has
        // two-packet ones here.
        let store = TriangleStore::from_mesh(&sphere(5, 1.0, Vec3::ZERO));
        let bvh = Bvh8::build(store, BuildQuality::Medium, false)
            .unwrap_or_else(|_| panic!("the sphere fits the stack"));
        assert!(leaf_packets(&bvh).contains(&2));
    }

    fn bits_of(c: &Closest) -> Option<(PrimRef, u32, u32, u32)> {
        c.map(|(r, h)| (r, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
    }

    /// A box room of quads with two boxes inside (Mitsuba's Cornell box in shape), scaled
    /// and moved.
    fn room(scale: f32, offset: Vec3) -> TriangleMesh {
        let mut corners = Vec::new();
        let mut cuboid = |lo: Vec3, hi: Vec3, inward: bool| {
            let c = |x: usize, y: usize, z: usize| {
                Vec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z]) * scale + offset
            };
            let faces = [
                [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)],
                [c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)],
                [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)],
                [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)],
                [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)],
                [c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)],
            ];
            for [a, b, c, d] in faces {
                if inward {
                    corners.extend([[a, c, b], [a, d, c]]);
                } else {
                    corners.extend([[a, b, c], [a, c, d]]);
                }
            }
        };
        cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), true);
        cuboid(
            Vec3::new(-0.7, -1.0, -0.6),
            Vec3::new(-0.1, 0.3, 0.1),
            false,
        );
        cuboid(Vec3::new(0.1, -1.0, 0.0), Vec3::new(0.7, -0.4, 0.6), false);
        TriangleMesh::from_triangles(&corners).unwrap()
    }

    /// Rays from inside the room to every corner and edge midpoint of its triangles (where
    /// several triangles meet, at the same distance), in random directions, and along the
    /// axes in the room's planes.
    fn room_rays(mesh: &TriangleMesh, scale: f32, offset: Vec3) -> Vec<Ray> {
        let mut rnd = crate::test_rng::uniform(0x9e37_79b9_7f4a_7c15);
        let mut inside = || offset + Vec3::new(rnd() - 0.5, rnd() * 0.5 + 0.3, rnd() - 0.5) * scale;
        let mut out = Vec::new();
        for i in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle(i);
            for target in [a, b, c, (a + b) * 0.5, (a + b + c) / 3.0] {
                let o = inside();
                out.push(Ray::new(o, target - o));
            }
            let o = inside();
            out.push(Ray::with_t_max(o, b - o, 0.999));
        }
        let mut rnd = crate::test_rng::uniform(7);
        for _ in 0..2000 {
            let o = inside();
            let d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            out.push(Ray::new(o, d));
        }
        // From points on the walls (on their planes up to rounding, and lifted off them by a
        // little), in every direction: crossings of the triangle under the origin about as
        // near as their error bound, which each triangle's own bound decides (or f64), not
        // the small tree's bound for all of its triangles. Not from the floor, in whose plane
        // the cuboids' bottoms lie: there a ray's crossings of two coplanar triangles, each
        // computed with its own rounding, may fall before the other's leaf box is entered,
        // and which one a kernel reports depends on the order it visits the leaves (a known
        // limit of the exact agreement, docs/performance-log.md, twenty-second session).
        let floor = mesh.triangle(0)[0].y;
        let mut rnd = crate::test_rng::uniform(11);
        for i in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle(i);
            if [a.y, b.y, c.y] == [floor; 3] {
                continue;
            }
            let n = (b - a).cross(c - a).normalize();
            for _ in 0..4 {
                let (u, v) = (rnd(), rnd());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let p = a + (b - a) * u + (c - a) * v;
                let d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
                for lift in [0.0, 1e-6, -1e-6, 1e-4] {
                    out.push(Ray::new(p + n * (lift * scale), d));
                }
            }
        }
        // Along each axis, from origins in the planes of the room's walls across it (the
        // direction's other components are zero: the node test's NaN case on every axis).
        for a in 0..3 {
            for sign in [1.0, -1.0] {
                let mut dir = Vec3::ZERO;
                dir[a] = sign;
                for plane in (0..3).filter(|&p| p != a) {
                    for side in [-1.0, 1.0] {
                        for k in 0..=8 {
                            let mut o = Vec3::splat((k as f32 / 4.0 - 1.0) * 0.9);
                            o[plane] = side;
                            out.push(Ray::new(offset + o * scale, dir));
                        }
                    }
                }
            }
        }
        out
    }

    fn check(bvh: &Bvh8, rays: &[Ray], what: &str) -> (usize, usize) {
        let (mut hits, mut blocked) = (0, 0);
        for (k, chunk) in rays.chunks(WIDTH).enumerate() {
            let lanes: [Ray; WIDTH] = std::array::from_fn(|i| chunk[i % chunk.len()]);
            let soa = RayLanes::from(&lanes);
            let mask = [0xff, 0x5a, 0x81, 0x10, 0xfe][k % 5];
            let closest = bvh.closest_packet(&soa, mask);
            let portable = crate::lanes::dispatch_portable(ClosestJob {
                bvh,
                rays: &soa,
                mask,
            });
            let occluded = bvh.occluded_packet(&soa, mask);
            let occluded_portable = crate::lanes::dispatch_portable(OccludedJob {
                bvh,
                rays: &soa,
                mask,
            });
            assert_eq!(occluded, occluded_portable, "{what}");
            for (lane, ray) in lanes.iter().enumerate() {
                if mask & (1 << lane) == 0 {
                    assert!(closest[lane].is_none() && occluded & (1 << lane) == 0);
                    continue;
                }
                let want = bvh.closest(ray);
                assert_eq!(bits_of(&closest[lane]), bits_of(&want), "{what}: {ray:?}");
                assert_eq!(
                    bits_of(&portable[lane]),
                    bits_of(&want),
                    "{what}, portable: {ray:?}"
                );
                assert_eq!(
                    occluded & (1 << lane) != 0,
                    bvh.occluded(ray),
                    "{what}: {ray:?}"
                );
                hits += usize::from(want.is_some());
                blocked += usize::from(occluded & (1 << lane) != 0);
            }
        }
        (hits, blocked)
    }

    /// Every lane of a packet query gets exactly the one-ray answer (the same triangle, the
    /// same bits; the same occlusion), on the portable lanes and this CPU's, for small closed
    /// meshes at scales from 1e-4 to 1e4 and far from the origin: rays through vertices and
    /// edges (ties between triangles), rays whose range ends at a surface, rays along the
    /// axes in the meshes' planes (the node test's NaN case), lanes left out of the mask.
    #[test]
    fn packets_equal_one_ray_queries() {
        // The closest-hit kernel is compiled for two stack sizes: both must be exercised.
        let mut stacks = [false; 2];
        for (scale, offset) in [
            (1.0, Vec3::ZERO),
            (1e-4, Vec3::ZERO),
            (1e4, Vec3::ZERO),
            (1.0, Vec3::new(1e5, -2e5, 3e5)),
        ] {
            let mesh = room(scale, offset);
            let bvh = Bvh8::build(TriangleStore::from_mesh(&mesh), BuildQuality::Medium, true)
                .unwrap_or_else(|_| panic!("the room fits the stack"));
            // One node or a few: the packet kernels take every ray.
            assert!(bvh.node_count() <= MAX_NODES);
            let (hits, blocked) = check(&bvh, &room_rays(&mesh, scale, offset), "room");
            assert!(
                hits > 1000 && blocked > 1000,
                "room: {hits} hits, {blocked} blocked"
            );
            // A small tree reads its corners from the corner records; without them the
            // kernels take the corners from the packets, with the same answers.
            assert_eq!(bvh.corners.len(), bvh.packets.len());
            let mut no_records = bvh.clone();
            no_records.corners = Vec::new();
            let without = check(
                &no_records,
                &room_rays(&mesh, scale, offset),
                "room, packets",
            );
            assert_eq!(without, (hits, blocked));
            // Small trees (packets for every ray) and a bigger one (packets where the rays
            // share an octant; forced here for all).
            for n in [3, 5, 16] {
                let mesh = sphere(n, scale, offset);
                let bvh = Bvh8::build(TriangleStore::from_mesh(&mesh), BuildQuality::Medium, true)
                    .unwrap_or_else(|_| panic!("the sphere fits the stack"));
                if n == 5 {
                    // Several nodes, still small enough for packets everywhere.
                    let nodes = bvh.node_count();
                    assert!(nodes > 1 && nodes <= MAX_NODES, "{nodes} nodes");
                }
                let (hits, _) = check(&bvh, &rays(&mesh, scale, offset), "sphere");
                assert!(hits > 100, "sphere {n}: {hits} hits");
                // Corner records exactly where the packet kernels take every lane query.
                assert_eq!(
                    bvh.corners.is_empty(),
                    bvh.node_count() > MAX_NODES || bvh.stack_need > SMALL_STACK
                );
                stacks[usize::from(bvh.stack_need > SMALL_STACK)] = true;
            }
            stacks[usize::from(bvh.stack_need > SMALL_STACK)] = true;
        }
        assert_eq!(stacks, [true, true], "small and full stacks");
    }
}
