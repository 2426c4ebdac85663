//! Closest-hit and any-hit queries against a [`Bvh8`], one kernel per instruction set.
//!
//! # The node test
//!
//! A slab distance is `(plane - origin) / dir`. Two forms are used, chosen per ray:
//!
//! - **Fused** (AVX2 with FMA, rays whose direction components all exceed `1e-20` in magnitude
//!   and whose origin lies within `1e18`, which is nearly every ray): `fma(plane, inv, -o_inv)`,
//!   one instruction per plane, with `inv = 1/dir` and `o_inv = origin * inv` computed once per
//!   query, as Embree's non-robust test. Each computed distance is within `2.0001 u |t| + E` of
//!   the exact one, where `u = 2^-24` and `E`, the rounding of `o_inv` (half an ulp of its
//!   largest component), does not scale with `t`: the exit distance is therefore widened to
//!   `exit (1 + 2 gamma(4)) + 2 E` (an FMA per exit plane, before their minimum) and the range
//!   end to `t_max (1 + 2^-21) + E`, which accepts every box the exact ray enters within
//!   `[t_min, t_max]` (the relative part is pbrt-v4's conservative slab test, *Physically Based
//!   Rendering*, 4th ed., section 6.8.2; the absolute part is the price of the precomputed
//!   `o_inv`). With `|plane| <= MAX_COORDINATE = 1e18` and `|inv| <= 1e20` nothing overflows.
//! - **Robust** (every other ray, and every ray on CPUs without FMA): `(plane - origin) * inv`
//!   with the exact reciprocal, infinite where a direction component is zero. Two distinct
//!   floats never subtract to zero, so a parallel axis gives `+-inf` (outside the slab) with the
//!   right sign, or NaN exactly when the origin lies in the plane, where the ray runs along the
//!   box face: the minima and maxima ignore NaN candidates (x86's `minps`/`maxps` rule, kept by
//!   the portable kernel), so that axis does not bound the box. The near plane of an axis is
//!   chosen by the sign of `inv` (so `-0.0` directions take the far side consistently).
//!
//! Both forms give `near <= far` for every box the exact ray meets within `[t_min, t_max]`: no
//! ray aimed at a triangle's corner, which lies on its leaf box's corner, is culled.
//!
//! # Order
//!
//! Closest hits: a node whose entered children are one continues with it; two, with the nearer
//! (the other is pushed), one and two by the same branch-free steps; more, all are pushed by
//! insertion into the node's part of the stack, farthest first, and the nearest is popped.
//! Stack entries are `entry distance bits << 32 | child`: entry distances are non-negative, so
//! their bits order like the floats, and a popped entry beyond the closest hit so far is
//! skipped. Shadow rays push children in slot order and
//! stop at the first hit.
//!
//! Of triangles hit at the same distance, the one in the lowest (packet, lane) wins, and once a
//! hit is known the triangles' scaled distances are checked against a bound a little beyond it
//! ([`tie_bound`]), so that no triangle at exactly that distance is lost to rounding: the
//! answer does not depend on the order of the walk, and the packet kernels (`packet.rs`), which
//! walk the tree in another order, give the same one.
//!
//! Lane queries (eight rays per call) go through `packet.rs` where [`Bvh8::packets_pay`] says
//! so (small trees, and rays that share a direction octant), one ray at a time otherwise.

use std::mem::MaybeUninit;

use glam::Vec3A;

use crate::lanes::{FloatLanes, MaskLanes, Simd, WIDTH};
use crate::ray::{Ray, RayLanes};
use crate::simd::{Plane, Portable, Simd8};
use crate::stack::Stack;
use crate::store::PrimRef;
use crate::triangle::{RayTriangleTest, TriangleHit, tie_bound};

use super::{Bvh8, LEAF, MAX_STACK, Node8};

/// Widening of a box's exit distance for the conservative slab test (robust form).
pub(super) const BOX_EXIT_SCALE: f32 = 1.0 + 2.0 * crate::float::gamma(3);

/// Widening of a box's exit distance in the fused form (which also rounds the widening itself).
const FUSED_EXIT_SCALE: f32 = 1.0 + 2.0 * crate::float::gamma(4);

/// Rays whose direction has a component smaller than this in magnitude take the robust test.
const MIN_FUSED_DIR: f32 = 1e-20;

/// Rays whose origin has a coordinate larger than this in magnitude take the robust test.
const MAX_FUSED_ORIGIN: f32 = crate::mesh::MAX_COORDINATE;

/// The instruction set the kernels run with, detected once per BVH.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Isa {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2(crate::simd::Avx2),
    /// The AVX2 kernels compiled for AVX-512 (more registers, mask registers).
    #[cfg(target_arch = "x86_64")]
    Avx512(crate::simd::Avx2),
}

impl Isa {
    /// The fastest kernels this CPU can run.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        if let Some(t) = crate::simd::Avx2::detect() {
            return if t.has_avx512() {
                Self::Avx512(t)
            } else {
                Self::Avx2(t)
            };
        }
        Self::Portable
    }
}

/// Whether the fused node test is exact enough for this ray (see the module docs).
#[inline(always)]
fn fused_ok(ray: &Ray) -> bool {
    let d = glam::Vec3A::from(ray.dir).abs();
    let o = glam::Vec3A::from(ray.origin).abs();
    d.cmpge(glam::Vec3A::splat(MIN_FUSED_DIR)).all()
        & o.cmple(glam::Vec3A::splat(MAX_FUSED_ORIGIN)).all()
}

/// [`fused_ok`] for the rays of `mask`'s lanes, checked in lanes.
#[inline(always)]
fn fused_lanes<S: Simd>(s: S, rays: &RayLanes, mask: u32) -> u32 {
    let (small, large) = (s.splat(MIN_FUSED_DIR), s.splat(MAX_FUSED_ORIGIN));
    let (o, d) = (&rays.origin, &rays.dir);
    let dirs =
        s.load(d[0]).abs().ge(small) & s.load(d[1]).abs().ge(small) & s.load(d[2]).abs().ge(small);
    let origins =
        s.load(o[0]).abs().le(large) & s.load(o[1]).abs().le(large) & s.load(o[2]).abs().le(large);
    (dirs & origins).bits() & mask
}

/// Per-query constants of the node test.
#[derive(Clone, Copy)]
struct NodeRay<S: Simd8> {
    /// Per axis, the plane a box is entered through (its max plane where the direction is
    /// negative) and the one it is left through.
    near: [Plane; 3],
    far: [Plane; 3],
    inv: [S::F; 3],
    /// Fused: `origin * inv`. Robust: the origin.
    off: [S::F; 3],
    t_min: S::F,
    scale: S::F,
    /// Fused: `2 E`, added to exit distances. Robust: `+inf`, where the exit minimum starts.
    slack: f32,
    slack_v: S::F,
}

impl<S: Simd8> NodeRay<S> {
    #[inline(always)]
    fn new<const FUSED: bool>(s: S, ray: &Ray) -> Self {
        let inv = Vec3A::from(ray.dir).recip();
        let o = Vec3A::from(ray.origin);
        let neg = inv.cmplt(Vec3A::ZERO).bitmask() as usize;
        let (off, slack) = if FUSED {
            let oi = o * inv;
            // Twice the rounding error of `oi`, with margin: 2^-22 of its largest component,
            // plus the smallest normal float (for subnormal products).
            (
                oi,
                oi.abs().max_element() * 2.0f32.powi(-22) + 2.0 * f32::MIN_POSITIVE,
            )
        } else {
            (o, f32::INFINITY)
        };
        // Entry distances are never -0.0 (their bits order the stack).
        let t_min = if ray.t_min > 0.0 { ray.t_min } else { 0.0 };
        Self {
            // Plane 2a is axis a's minimum, 2a + 1 its maximum.
            near: std::array::from_fn(|a| Plane::new(2 * a + ((neg >> a) & 1))),
            far: std::array::from_fn(|a| Plane::new(2 * a + 1 - ((neg >> a) & 1))),
            // Splatted one by one: no closure over lane values (see `lanes::WithSimd`).
            inv: [s.splat(inv.x), s.splat(inv.y), s.splat(inv.z)],
            off: [s.splat(off.x), s.splat(off.y), s.splat(off.z)],
            t_min: s.splat(t_min),
            scale: s.splat(if FUSED {
                FUSED_EXIT_SCALE
            } else {
                BOX_EXIT_SCALE
            }),
            slack,
            slack_v: s.splat(slack),
        }
    }

    /// The end of the ray's range as entry distances are compared with it: widened by more
    /// than their relative error (and, in the fused form, their absolute error `E`), so that
    /// no box holding a hit before `t_max` is culled or skipped on the stack.
    #[inline(always)]
    fn range_end<const FUSED: bool>(&self, t_max: f32) -> f32 {
        let widened = t_max + t_max * 2.0f32.powi(-21);
        if FUSED {
            widened + 0.5 * self.slack
        } else {
            widened
        }
    }

    /// Which of the node's children the ray enters within `[t_min, t_max]` (bit `i` for child
    /// `i`), and their entry distances; `end` is [`Self::range_end`].
    #[inline(always)]
    fn hit<const FUSED: bool>(&self, s: S, node: &Node8, end: S::F) -> (u32, S::F) {
        if FUSED {
            // No NaN here (finite planes, finite non-zero `inv`): the minima and maxima are
            // taken as two independent pairs, and the exit widening applied per plane before
            // the minimum (it is monotone, so the minimum is the same bits), which shortens
            // the chain from the last plane to the comparison by two operations.
            let near = s.max_or(
                s.max_or(
                    self.slab::<FUSED>(s, node, self.near[0], 0),
                    self.slab::<FUSED>(s, node, self.near[1], 1),
                ),
                s.max_or(self.slab::<FUSED>(s, node, self.near[2], 2), self.t_min),
            );
            let (f0, f1, f2) = (
                self.widened_exit(s, node, self.far[0], 0),
                self.widened_exit(s, node, self.far[1], 1),
                self.widened_exit(s, node, self.far[2], 2),
            );
            let far = s.min_or(s.min_or(f0, f1), s.min_or(f2, end));
            return (s.le_mask(near, far), near);
        }
        let near = s.max_or(
            self.slab::<FUSED>(s, node, self.near[0], 0),
            s.max_or(
                self.slab::<FUSED>(s, node, self.near[1], 1),
                s.max_or(self.slab::<FUSED>(s, node, self.near[2], 2), self.t_min),
            ),
        );
        let (f0, f1, f2) = (
            self.slab::<FUSED>(s, node, self.far[0], 0),
            self.slab::<FUSED>(s, node, self.far[1], 1),
            self.slab::<FUSED>(s, node, self.far[2], 2),
        );
        // Robust: a NaN candidate (the origin in a parallel axis's plane) is ignored only as
        // the first operand, so each candidate joins a NaN-free accumulator, one at a time.
        let far = s.min_or(f0, s.min_or(f1, s.min_or(f2, self.slack_v)));
        let far = s.min_or(s.mul(far, self.scale), end);
        (s.le_mask(near, far), near)
    }

    /// The fused form's exit distances through plane `plane` (of axis `a`), widened.
    #[inline(always)]
    fn widened_exit(&self, s: S, node: &Node8, plane: Plane, a: usize) -> S::F {
        s.mul_add(
            self.slab::<true>(s, node, plane, a),
            self.scale,
            self.slack_v,
        )
    }

    /// The distances along the ray to plane `plane` (of axis `a`) of the node's children.
    #[inline(always)]
    fn slab<const FUSED: bool>(&self, s: S, node: &Node8, plane: Plane, a: usize) -> S::F {
        let p = s.load_plane(&node.planes, plane);
        if FUSED {
            s.mul_sub(p, self.inv[a], self.off[a])
        } else {
            s.mul(s.sub(p, self.off[a]), self.inv[a])
        }
    }
}

impl Bvh8 {
    /// Ask for the first cache lines of a child: a node's planes, or a leaf's first packet and,
    /// with `REFS` (closest hits), where its triangles came from.
    ///
    /// The references are asked for when the leaf is entered, not when one of its triangles is
    /// hit: a query ends soon after its last hit, and the look-up of the hit's reference was
    /// then a cache miss of its own (about 9% of an incoherent closest-hit query on the bunny,
    /// measured by dropping the look-up). Asking at entry costs a prefetch per entered leaf.
    #[inline(always)]
    fn prefetch<S: Simd8, const REFS: bool>(&self, s: S, child: u32) {
        // By address, without bounds checks: a prefetch never faults, and the children of a
        // built tree are in range anyway. (Without the branch on the child's kind, by
        // `select_unpredictable`, incoherent closest hits on the bunny ran 2.5% slower.)
        if child & LEAF == 0 {
            s.prefetch_at(self.node_address(child));
        } else {
            let first = ((child & !LEAF) >> super::COUNT_BITS) as usize;
            s.prefetch_at(self.packets.as_ptr().wrapping_add(first));
            if REFS {
                s.prefetch_at(self.refs.as_ptr().wrapping_add(first));
            }
        }
    }
}

/// A closest-hit stack entry: the child's entry distance above its reference.
#[inline(always)]
fn key(t: f32, child: u32) -> u64 {
    (u64::from(t.to_bits()) << 32) | u64::from(child)
}

/// The closest hit, with a stack of `N` entries (at least the tree's `stack_need`).
#[inline(always)]
fn closest<S: Simd8, const FUSED: bool, const N: usize>(
    bvh: &Bvh8,
    s: S,
    ray: &Ray,
) -> Option<(PrimRef, TriangleHit)> {
    let mut cur = bvh.root?;
    let r = NodeRay::<S>::new::<FUSED>(s, ray);
    // Many rays reach no leaf: the triangle test's set-up waits for the first.
    let mut test = None;
    let mut t_max = ray.t_max;
    // Entry distances are compared with `end`, hits with `t_max`.
    let mut end = r.range_end::<FUSED>(t_max);
    // What the triangles' scaled distances are checked against (`tie_bound`).
    let mut bound = t_max;
    let mut best: Option<(usize, usize, TriangleHit)> = None;
    let mut slots = [const { MaybeUninit::uninit() }; N];
    let mut stack = Stack::<u64>::new(&mut slots);
    // Next: the nearest pushed child not beyond the closest hit so far.
    macro_rules! pop {
        () => {
            loop {
                let Some(e) = stack.pop() else {
                    return best.map(|(packet, lane, h)| (bvh.refs[packet][lane], h));
                };
                if f32::from_bits((e >> 32) as u32) <= end {
                    cur = e as u32;
                    break;
                }
            }
        };
    }
    loop {
        // The walk over inner nodes, with the node test's constants read afresh after each
        // leaf: their live range is this loop, where they stay in registers.
        let r = *std::hint::black_box(&r);
        let end_v = s.splat(end);
        while cur & LEAF == 0 {
            let node = bvh.node(cur);
            s.prefetch(&node.child[0]);
            let (mut mask, near) = r.hit::<FUSED>(s, node, end_v);
            if mask != 0 {
                // One entered child or two take one path, without a branch on which (the
                // predictor missed it about 1.6 times per incoherent query): with one child,
                // `second` is `first` again, so `nearer` is that child, and the entry written
                // above the top of the stack is not kept.
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                let second = (rest | u32::from(rest == 0) << first).trailing_zeros() as usize;
                bvh.prefetch::<S, true>(s, node.child[first]);
                let near = s.to_array(near);
                let (k0, k1) = (
                    key(near[first], node.child[first]),
                    key(near[second], node.child[second]),
                );
                // Branch-free: which child is nearer is a coin toss for the predictor.
                let (nearer, farther) = (k0.min(k1), k0.max(k1));
                mask = rest & rest.wrapping_sub(1);
                // With one child, a repeated prefetch rather than a branch.
                bvh.prefetch::<S, true>(s, node.child[second]);
                if mask == 0 {
                    stack.push_if(farther, rest != 0);
                    cur = nearer as u32;
                    continue;
                }
                // Three or more: keep this node's entries sorted, nearest on top.
                let base = stack.len();
                stack.push(farther);
                stack.push(nearer);
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    bvh.prefetch::<S, true>(s, node.child[i]);
                    stack.insert_sorted(base, key(near[i], node.child[i]));
                }
                cur = stack.pop().unwrap_or_default() as u32;
                continue;
            }
            pop!();
        }
        let before = t_max;
        let test = test.get_or_insert_with(|| RayTriangleTest::new(ray));
        let (first, packets) = bvh.leaf_packets(cur);
        // Packets two at a time in eight lanes (a full leaf is two), exactly as one at a
        // time with `t_max` lowered after each.
        // Of hits at the same distance the lowest (packet, lane) wins, whatever order the
        // tree is walked in: the packet traversal (`packet.rs`) gives the same answer.
        macro_rules! found {
            ($k:expr, $hit:expr) => {
                if let Some((lane, h)) = $hit
                    && (h.t < t_max || best.is_none_or(|(p, l, _)| (first + $k, lane) < (p, l)))
                {
                    t_max = h.t;
                    best = Some((first + $k, lane, h));
                    // A second packet's references may lie in the next cache line.
                    if let Some(r) = bvh.refs.get(first + $k) {
                        s.prefetch(r);
                    }
                }
            };
        }
        let pairs = packets.chunks_exact(2);
        let last = pairs.remainder().first();
        for (k, pair) in pairs.enumerate() {
            let [a, b] = test.closest8_full(s, [&pair[0], &pair[1]], bound, t_max);
            found!(2 * k, a);
            found!(2 * k + 1, b);
        }
        if let Some(p) = last {
            found!(packets.len() - 1, test.closest4_full(p, bound, t_max));
        }
        if t_max != before {
            end = r.range_end::<FUSED>(t_max);
            bound = tie_bound(ray.t_max, t_max);
        }
        pop!();
    }
}

/// Whether anything is hit, with a stack of `N` entries (at least the tree's `stack_need`).
#[inline(always)]
fn occluded<S: Simd8, const FUSED: bool, const N: usize>(bvh: &Bvh8, s: S, ray: &Ray) -> bool {
    let Some(mut cur) = bvh.root else {
        return false;
    };
    let r = NodeRay::<S>::new::<FUSED>(s, ray);
    let mut test = None;
    let end_v = s.splat(r.range_end::<FUSED>(ray.t_max));
    let mut slots = [const { MaybeUninit::uninit() }; N];
    let mut stack = Stack::<u32>::new(&mut slots);
    loop {
        if cur & LEAF == 0 {
            let node = bvh.node(cur);
            s.prefetch(&node.child[0]);
            let (mut mask, _) = r.hit::<FUSED>(s, node, end_v);
            if mask != 0 {
                // The first entered child next; a second, if any, pushed without a branch on
                // whether there is one (as in the closest-hit kernel).
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                let second = (rest | u32::from(rest == 0) << first).trailing_zeros() as usize;
                cur = node.child[first];
                let c = node.child[second];
                bvh.prefetch::<S, false>(s, cur);
                bvh.prefetch::<S, false>(s, c);
                stack.push_if(c, rest != 0);
                mask = rest & rest.wrapping_sub(1);
                while mask != 0 {
                    let c = node.child[mask.trailing_zeros() as usize];
                    bvh.prefetch::<S, false>(s, c);
                    stack.push(c);
                    mask &= mask - 1;
                }
                continue;
            }
        } else {
            let test = test.get_or_insert_with(|| RayTriangleTest::new(ray));
            // Plain loops: `Iterator::any` was left out of line, a call per leaf.
            let pairs = bvh.leaf_packets(cur).1.chunks_exact(2);
            if let Some(p) = pairs.remainder().first()
                && test.any4_full(p, ray.t_max)
            {
                return true;
            }
            for pair in pairs {
                if test.any8_full(s, [&pair[0], &pair[1]], ray.t_max) {
                    return true;
                }
            }
        }
        let Some(next) = stack.pop() else {
            return false;
        };
        cur = next;
    }
}

/// A closest-hit query's answer: where the triangle came from and the hit.
type Closest = Option<(PrimRef, TriangleHit)>;

/// Stack sizes the kernels are compiled for; a tree uses the smallest that holds its need.
const SMALL_STACK: usize = 64;
const _: () = assert!(SMALL_STACK < MAX_STACK);

impl Bvh8 {
    /// The closest triangle hit in `[t_min, t_max]`: where the triangle came from and the hit.
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Closest {
        let small = self.stack_need <= SMALL_STACK;
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2(t) => x86::closest(self, t, ray, fused_ok(ray), small),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512(t) => x86::closest512(self, t, ray, fused_ok(ray), small),
            Isa::Portable if small => closest::<Portable, false, SMALL_STACK>(self, Portable, ray),
            Isa::Portable => closest::<Portable, false, MAX_STACK>(self, Portable, ray),
        }
    }

    /// True when any triangle is hit in `[t_min, t_max]`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let small = self.stack_need <= SMALL_STACK;
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2(t) => x86::occluded(self, t, ray, fused_ok(ray), small),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512(t) => x86::occluded512(self, t, ray, fused_ok(ray), small),
            Isa::Portable if small => occluded::<Portable, false, SMALL_STACK>(self, Portable, ray),
            Isa::Portable => occluded::<Portable, false, MAX_STACK>(self, Portable, ray),
        }
    }

    /// The closest hits of the rays in the lanes set in `mask` (bit `i` for lane `i` of
    /// `rays`), each exactly what [`Self::closest`] gives it; other lanes `None`: the lane
    /// path tracer's queries, from a caller running with the lanes of `s` (inside
    /// [`crate::lanes::dispatch`]). Packets with `s`'s instruction set
    /// ([`Self::closest_packet`], out of line) where they pay, one ray after another otherwise.
    #[inline(always)]
    pub fn closest_lanes_in<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32) -> [Closest; WIDTH] {
        if self.packets_pay(s, rays, mask) {
            return self.closest_packet(rays, mask);
        }
        self.closest_rays(rays, mask, fused_lanes(s, rays, mask))
    }

    /// The rays of `mask`'s lanes one at a time, in one entry of the kernels.
    #[inline]
    fn closest_rays(&self, rays: &RayLanes, mask: u32, fused: u32) -> [Closest; WIDTH] {
        let small = self.stack_need <= SMALL_STACK;
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2(t) => x86::closest_lanes(self, t, rays, mask, fused, small),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512(t) => x86::closest_lanes512(self, t, rays, mask, fused, small),
            Isa::Portable => {
                let mut out = [None; WIDTH];
                for lane in crate::lanes::bits(mask) {
                    out[lane] = self.closest(&rays.get(lane));
                }
                out
            }
        }
    }

    /// Which rays of the lanes set in `mask` hit anything (bit `i` for lane `i` of `rays`),
    /// each exactly as [`Self::occluded`] says, from a caller running with the lanes of `s`, as
    /// [`Self::closest_lanes_in`].
    #[inline(always)]
    pub fn occluded_lanes_in<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32) -> u32 {
        if self.packets_pay(s, rays, mask) {
            return self.occluded_packet(rays, mask);
        }
        self.occluded_rays(rays, mask, fused_lanes(s, rays, mask))
    }

    /// The rays of `mask`'s lanes one at a time, in one entry of the kernels.
    #[inline]
    fn occluded_rays(&self, rays: &RayLanes, mask: u32, fused: u32) -> u32 {
        let small = self.stack_need <= SMALL_STACK;
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2(t) => x86::occluded_lanes(self, t, rays, mask, fused, small),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512(t) => x86::occluded_lanes512(self, t, rays, mask, fused, small),
            Isa::Portable => crate::lanes::mask_where(mask, |lane| self.occluded(&rays.get(lane))),
        }
    }

    /// The same queries through the portable kernels, whatever the CPU (for tests).
    #[cfg(test)]
    pub fn closest_portable(&self, ray: &Ray) -> Option<(PrimRef, TriangleHit)> {
        closest::<Portable, false, MAX_STACK>(self, Portable, ray)
    }

    #[cfg(test)]
    pub fn occluded_portable(&self, ray: &Ray) -> bool {
        occluded::<Portable, false, MAX_STACK>(self, Portable, ray)
    }
}

/// The AVX2 and AVX-512 entry points: the generic kernels compiled for each.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod x86 {
    use super::{
        Bvh8, Closest, MAX_STACK, SMALL_STACK, closest as closest_k, occluded as occluded_k,
    };
    use crate::lanes::{WIDTH, bits};
    use crate::ray::{Ray, RayLanes};
    use crate::simd::Avx2;

    /// Entry points for one set of target features: a dispatcher `$closest`/`$occluded` over
    /// the fused or robust node test and the small or large stack.
    macro_rules! entries {
        ($features:literal, $closest:ident, $occluded:ident, $closest_lanes:ident, $occluded_lanes:ident) => {
            /// The rays of `mask`'s lanes one after another inside one entry: those of `fused`
            /// (which [`super::fused_ok`] accepts) by the fused kernel inlined, the rare rays that
            /// need the robust node test through `$closest`.
            #[inline]
            pub fn $closest_lanes(
                bvh: &Bvh8,
                s: Avx2,
                rays: &RayLanes,
                mask: u32,
                fused: u32,
                small: bool,
            ) -> [Closest; WIDTH] {
                #[target_feature(enable = $features)]
                fn go<const N: usize>(
                    bvh: &Bvh8,
                    s: Avx2,
                    rays: &RayLanes,
                    mask: u32,
                    fused: u32,
                    small: bool,
                ) -> [Closest; WIDTH] {
                    let mut out = [None; WIDTH];
                    // The rare rays that need the robust test in a second loop: with one
                    // assignment for both kinds the inlined kernel's answer was assembled on the
                    // stack from 4- and 8-byte stores and read straight back in 16-byte loads
                    // to be copied (a store-forwarding stall per query).
                    for lane in bits(mask & fused) {
                        out[lane] = closest_k::<Avx2, true, N>(bvh, s, &rays.get(lane));
                    }
                    for lane in bits(mask & !fused) {
                        out[lane] = $closest(bvh, s, &rays.get(lane), false, small);
                    }
                    out
                }
                // SAFETY: as for the single-ray entries below.
                unsafe {
                    if small {
                        go::<SMALL_STACK>(bvh, s, rays, mask, fused, small)
                    } else {
                        go::<MAX_STACK>(bvh, s, rays, mask, fused, small)
                    }
                }
            }

            /// Any-hit queries of `mask`'s lanes inside one entry, as `$closest_lanes`.
            #[inline]
            pub fn $occluded_lanes(
                bvh: &Bvh8,
                s: Avx2,
                rays: &RayLanes,
                mask: u32,
                fused: u32,
                small: bool,
            ) -> u32 {
                #[target_feature(enable = $features)]
                fn go<const N: usize>(
                    bvh: &Bvh8,
                    s: Avx2,
                    rays: &RayLanes,
                    mask: u32,
                    fused: u32,
                    small: bool,
                ) -> u32 {
                    let mut out = 0;
                    // The rare rays that need the robust test in a second loop, as in
                    // `$closest_lanes`: a ray passed to the out-of-line entry is built on the
                    // stack, and with both kinds in one loop every lane's was, from loads that
                    // LLVM merged into one wide load across two coordinate arrays (a
                    // store-forwarding stall per query: diffuse bunny -3.5%).
                    for lane in bits(mask & fused) {
                        let hit = occluded_k::<Avx2, true, N>(bvh, s, &rays.get(lane));
                        out |= u32::from(hit) << lane;
                    }
                    for lane in bits(mask & !fused) {
                        let hit = $occluded(bvh, s, &rays.get(lane), false, small);
                        out |= u32::from(hit) << lane;
                    }
                    out
                }
                // SAFETY: as for the single-ray entries below.
                unsafe {
                    if small {
                        go::<SMALL_STACK>(bvh, s, rays, mask, fused, small)
                    } else {
                        go::<MAX_STACK>(bvh, s, rays, mask, fused, small)
                    }
                }
            }

            #[inline]
            pub fn $closest(bvh: &Bvh8, s: Avx2, ray: &Ray, fused: bool, small: bool) -> Closest {
                #[target_feature(enable = $features)]
                fn go<const F: bool, const N: usize>(bvh: &Bvh8, s: Avx2, ray: &Ray) -> Closest {
                    closest_k::<Avx2, F, N>(bvh, s, ray)
                }
                // SAFETY: `s` exists only on CPUs with AVX2 and FMA, and these entries are
                // called with AVX-512 features only where `Avx2::has_avx512` said so.
                unsafe {
                    match (fused, small) {
                        (true, true) => go::<true, SMALL_STACK>(bvh, s, ray),
                        (true, false) => go::<true, MAX_STACK>(bvh, s, ray),
                        (false, true) => go::<false, SMALL_STACK>(bvh, s, ray),
                        (false, false) => go::<false, MAX_STACK>(bvh, s, ray),
                    }
                }
            }

            #[inline]
            pub fn $occluded(bvh: &Bvh8, s: Avx2, ray: &Ray, fused: bool, small: bool) -> bool {
                #[target_feature(enable = $features)]
                fn go<const F: bool, const N: usize>(bvh: &Bvh8, s: Avx2, ray: &Ray) -> bool {
                    occluded_k::<Avx2, F, N>(bvh, s, ray)
                }
                // SAFETY: as for the closest-hit entry.
                unsafe {
                    match (fused, small) {
                        (true, true) => go::<true, SMALL_STACK>(bvh, s, ray),
                        (true, false) => go::<true, MAX_STACK>(bvh, s, ray),
                        (false, true) => go::<false, SMALL_STACK>(bvh, s, ray),
                        (false, false) => go::<false, MAX_STACK>(bvh, s, ray),
                    }
                }
            }
        };
    }

    entries!(
        "avx2,fma,bmi1,bmi2,lzcnt,popcnt",
        closest,
        occluded,
        closest_lanes,
        occluded_lanes
    );
    entries!(
        "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi1,bmi2,lzcnt,popcnt",
        closest512,
        occluded512,
        closest_lanes512,
        occluded_lanes512
    );
}

#[cfg(test)]
pub(super) mod tests {
    use glam::Vec3;

    use super::*;
    use crate::BuildQuality;
    use crate::brute::BruteForce;
    use crate::mesh::TriangleMesh;
    use crate::store::TriangleStore;

    /// A closed latitude-longitude sphere of `n x 2n` quads, scaled and moved.
    pub(in crate::bvh8) fn sphere(n: u32, scale: f32, offset: Vec3) -> TriangleMesh {
        let mut corners = Vec::new();
        let p = |i: u32, j: u32| {
            let (t, f) = (
                std::f32::consts::PI * i as f32 / n as f32,
                std::f32::consts::TAU * j as f32 / (2 * n) as f32,
            );
            Vec3::new(t.sin() * f.cos(), t.cos(), t.sin() * f.sin()) * scale + offset
        };
        for i in 0..n {
            for j in 0..2 * n {
                let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                if i > 0 {
                    corners.push([a, c, d]);
                }
                if i + 1 < n {
                    corners.push([a, b, c]);
                }
            }
        }
        TriangleMesh::from_triangles(&corners).unwrap()
    }

    /// Rays through the sphere's vertices and edge midpoints (where a ray meets several
    /// triangles, and a leaf box's corner), random rays from inside and outside, and rays
    /// parallel to the axes (direction components exactly zero: the robust node test).
    pub(in crate::bvh8) fn rays(mesh: &TriangleMesh, scale: f32, offset: Vec3) -> Vec<Ray> {
        let mut rnd = crate::test_rng::uniform(0x2545_f491_4f6c_dd1du64);
        let mut out = Vec::new();
        for i in (0..mesh.triangle_count()).step_by(3) {
            let [a, b, _] = mesh.triangle(i);
            let o = offset + Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * (0.5 * scale);
            out.push(Ray::new(o, a - o));
            out.push(Ray::new(o, (a + b) * 0.5 - o));
            let far = offset + Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * (6.0 * scale);
            out.push(Ray::new(far, a - far));
            out.push(Ray::with_t_max(far, b - far, 0.999));
        }
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            for _ in 0..200 {
                let o = offset + Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * (2.2 * scale);
                out.push(Ray::new(o - axis * (3.0 * scale), axis));
                out.push(Ray::new(o, axis));
            }
        }
        out
    }

    /// Every kernel (the one this CPU runs, the portable one) finds exactly what brute force
    /// finds: the same closest distance, bit for bit (the triangle test is the same), and the
    /// same occlusion answer, at scales from 1e-4 to 1e4 and 1e5 from the origin.
    #[test]
    fn kernels_agree_with_brute_force() {
        let mut checked = 0;
        for (scale, offset) in [
            (1.0, Vec3::ZERO),
            (1e-4, Vec3::ZERO),
            (1e4, Vec3::ZERO),
            (1.0, Vec3::new(1e5, -2e5, 3e5)),
        ] {
            let mesh = sphere(24, scale, offset);
            let store = TriangleStore::from_mesh(&mesh);
            let brute = BruteForce::new(store.clone());
            let Ok(bvh) = Bvh8::build(store, BuildQuality::Medium, true) else {
                panic!("the sphere's tree fits the stack");
            };
            for ray in rays(&mesh, scale, offset) {
                let want = brute.closest(&ray).map(|(_, h)| h.t.to_bits());
                let got = bvh.closest(&ray).map(|(_, h)| h.t.to_bits());
                let portable = bvh.closest_portable(&ray).map(|(_, h)| h.t.to_bits());
                assert_eq!(got, want, "scale {scale}, {ray:?}");
                assert_eq!(portable, want, "portable, scale {scale}, {ray:?}");
                let blocked = brute.occluded(&ray);
                assert_eq!(bvh.occluded(&ray), blocked, "scale {scale}, {ray:?}");
                assert_eq!(
                    bvh.occluded_portable(&ray),
                    blocked,
                    "scale {scale}, {ray:?}"
                );
                checked += usize::from(want.is_some());
            }
        }
        assert!(checked > 5000, "only {checked} rays hit");
    }

    /// Both lane queries of `rays`, with the detected lanes.
    struct LaneQueries<'a> {
        bvh: &'a Bvh8,
        rays: &'a RayLanes,
        mask: u32,
    }

    impl crate::lanes::WithSimd for LaneQueries<'_> {
        type Output = ([Closest; WIDTH], u32);
        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) -> Self::Output {
            (
                self.bvh.closest_lanes_in(s, self.rays, self.mask),
                self.bvh.occluded_lanes_in(s, self.rays, self.mask),
            )
        }
    }

    /// The lane queries answer every lane exactly as the one-ray queries do (the same triangle,
    /// the same bits), leave the lanes outside the mask empty, and send rays that need the
    /// robust node test (the axis-parallel ones among these) through it.
    #[test]
    fn lane_queries_equal_one_ray_queries() {
        let bits = |c: &Closest| c.map(|(r, h)| (r, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()));
        for (scale, offset) in [(1.0, Vec3::ZERO), (1e4, Vec3::new(1e5, -2e5, 3e5))] {
            let mesh = sphere(16, scale, offset);
            let Ok(bvh) = Bvh8::build(TriangleStore::from_mesh(&mesh), BuildQuality::Medium, true)
            else {
                panic!("the sphere's tree fits the stack");
            };
            let rays = rays(&mesh, scale, offset);
            let (mut robust, mut hits) = (0, 0);
            for (k, chunk) in rays.chunks_exact(WIDTH).enumerate() {
                let lanes: [Ray; WIDTH] = std::array::from_fn(|i| chunk[i]);
                let mask = [0xff, 0x5a, 0x81, 0x10][k % 4];
                let (closest, occluded) = crate::lanes::dispatch(LaneQueries {
                    bvh: &bvh,
                    rays: &RayLanes::from(&lanes),
                    mask,
                });
                for (lane, ray) in lanes.iter().enumerate() {
                    if mask & (1 << lane) == 0 {
                        assert!(closest[lane].is_none() && occluded & (1 << lane) == 0);
                        continue;
                    }
                    let want = bvh.closest(ray);
                    assert_eq!(bits(&closest[lane]), bits(&want), "{ray:?}");
                    assert_eq!(occluded & (1 << lane) != 0, bvh.occluded(ray), "{ray:?}");
                    robust += usize::from(!fused_ok(ray));
                    hits += usize::from(want.is_some());
                }
            }
            assert!(robust > 100 && hits > 1000, "robust {robust}, hits {hits}");
        }
    }

    /// Rays with zero direction components whose origin lies exactly in a plane of a leaf's
    /// box (the robust test's NaN case) still find the triangles on that plane's edge: unit
    /// squares at distance 5 along each axis, seen along the axis from origins on the lines
    /// through the squares' edges, with zero direction components of either sign, beside a
    /// sphere that gives the tree its nodes.
    #[test]
    fn axis_parallel_rays_in_box_planes_are_not_culled() {
        let ball = sphere(12, 1.0, Vec3::new(-5.0, -5.0, -5.0));
        let mut corners: Vec<[Vec3; 3]> = (0..ball.triangle_count())
            .map(|i| ball.triangle(i))
            .collect();
        // Axis `a` maps (along, u, v) to a point; the square spans u, v in [0, 1] at along = 5.
        let at = |a: usize, along: f32, u: f32, v: f32| {
            let mut p = [0.0; 3];
            p[a] = along;
            p[(a + 1) % 3] = u;
            p[(a + 2) % 3] = v;
            Vec3::from(p)
        };
        for a in 0..3 {
            let (p, q, r, t) = (
                at(a, 5.0, 0.0, 0.0),
                at(a, 5.0, 1.0, 0.0),
                at(a, 5.0, 1.0, 1.0),
                at(a, 5.0, 0.0, 1.0),
            );
            corners.extend([[p, q, r], [p, r, t]]);
        }
        let mesh = TriangleMesh::from_triangles(&corners).unwrap();
        let store = TriangleStore::from_mesh(&mesh);
        let brute = BruteForce::new(store.clone());
        let Ok(bvh) = Bvh8::build(store, BuildQuality::Medium, true) else {
            panic!("the tree fits the stack");
        };
        assert!(bvh.node_count() > 1);
        let mut checked = 0;
        for a in 0..3 {
            for k in 0..=8 {
                let w = k as f32 / 8.0;
                for o in [
                    at(a, 0.0, 0.0, w),
                    at(a, 0.0, 1.0, w),
                    at(a, 0.0, w, 0.0),
                    at(a, 0.0, w, 1.0),
                ] {
                    for zero in [0.0, -0.0] {
                        let dir = at(a, 1.0, zero, zero);
                        let ray = Ray::new(o, dir);
                        let want = brute.closest(&ray).map(|(_, h)| h.t.to_bits());
                        assert!(want.is_some(), "{ray:?} meets the square's edge");
                        let got = bvh.closest(&ray).map(|(_, h)| h.t.to_bits());
                        assert_eq!(got, want, "{ray:?}");
                        let portable = bvh.closest_portable(&ray).map(|(_, h)| h.t.to_bits());
                        assert_eq!(portable, want, "portable {ray:?}");
                        assert!(bvh.occluded(&ray) && bvh.occluded_portable(&ray), "{ray:?}");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 216);
    }

    /// The fused node test is only taken by rays it is exact enough for.
    #[test]
    fn flat_and_far_rays_take_the_robust_test() {
        assert!(fused_ok(&Ray::new(Vec3::ZERO, Vec3::new(1.0, 1e-19, -1.0))));
        assert!(!fused_ok(&Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.0, -1.0))));
        assert!(!fused_ok(&Ray::new(
            Vec3::ZERO,
            Vec3::new(1.0, -1e-21, 1.0)
        )));
        assert!(!fused_ok(&Ray::new(Vec3::new(2e18, 0.0, 0.0), Vec3::ONE)));
    }
}
