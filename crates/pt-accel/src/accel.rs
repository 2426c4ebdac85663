//! One accelerator type over several strategies, chosen automatically or by the caller.

use std::fmt;
use std::time::{Duration, Instant};

use obvhs::BvhBuildParams;

use crate::bounds::Bounds3;
use crate::lanes::{Simd, WIDTH, WithSimd, bits, mask_where};
use crate::mesh::{Instance, TriangleMesh};
use crate::ray::{Hit, Ray, RayLanes};
use crate::store::{PrimRef, TriangleStore};
use crate::tri_bvh::TriangleBvh;
use crate::triangle::TriangleHit;
use crate::two_level::TwoLevel;

/// Up to this many triangles, [`AccelKind::Auto`] tests every triangle instead of building a BVH:
/// a BVH query costs about as much as this many triangle tests.
pub const BRUTE_FORCE_MAX_TRIANGLES: usize = 8;

/// [`AccelKind::Auto`] bakes repeated instances into one flat BVH as long as the copies add at
/// most this many triangles (about 100 bytes each with their share of the nodes): one tree
/// culls better than a top level over overlapping instance boxes and needs no ray transforms.
/// Beyond it, a two-level BVH keeps one copy of each mesh.
pub const FLATTEN_MAX_COPIES: usize = 250_000;

/// Which acceleration strategy to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum AccelKind {
    /// Choose from the scene: brute force for a handful of triangles, a two-level BVH when
    /// instances repeat meshes so much that copying them would add more than
    /// [`FLATTEN_MAX_COPIES`] triangles, otherwise one flat BVH.
    #[default]
    Auto,
    /// Test every triangle. Slow for anything but tiny scenes; the reference in tests.
    BruteForce,
    /// One BVH over all triangles, baked into world space (instances are copied).
    Bvh,
    /// One BVH per distinct mesh and a top-level BVH over instances (no geometry copied).
    TwoLevel,
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Auto => "auto",
            Self::BruteForce => "brute force",
            Self::Bvh => "bvh",
            Self::TwoLevel => "two-level bvh",
        })
    }
}

/// Node layout of the triangle BVHs.
///
/// The default is [`BvhLayout::Eight`] on CPUs with AVX2 and FMA and [`BvhLayout::Four`]
/// elsewhere (other architectures, or x86-64 CPUs older than about 2013), detected when the
/// program runs, whatever it was compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum BvhLayout {
    /// Eight-wide nodes with full-precision child boxes (256 bytes per node), built by
    /// collapsing obvhs' binary tree; each node is tested in one 256-bit register per plane
    /// with fused multiply-adds where the CPU has AVX2 and FMA (chosen at run time), in two
    /// four-lane halves elsewhere; leaves' triangles are tested four at a time.
    Eight,
    /// Four-wide nodes with full-precision child boxes (128 bytes per node), built by collapsing
    /// obvhs' binary tree; each leaf's triangles are tested four at a time. The fastest layout
    /// to trace on a CPU with 4-lane SIMD only.
    Four,
    /// Compressed 8-wide nodes (CWBVH, 80 bytes per node): the smallest tree, at the cost of
    /// decompressing every node visited.
    Wide,
    /// Binary nodes (BVH2): simpler nodes, front-to-back child order.
    Binary,
}

impl Default for BvhLayout {
    /// [`BvhLayout::Eight`] where this CPU has AVX2 and FMA, else [`BvhLayout::Four`].
    fn default() -> Self {
        if crate::simd::has_avx2() {
            Self::Eight
        } else {
            Self::Four
        }
    }
}

/// BVH build effort: faster builds give slower traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum BuildQuality {
    /// Minimal PLOC search, no reinsertion: for scenes rebuilt every frame. Such trees trace
    /// 10-25% faster in the [`BvhLayout::Wide`] layout than in the default four-wide one.
    Fastest,
    /// Short PLOC search with a little reinsertion.
    Fast,
    /// Balanced (the default): a top-down binned-SAH build (32 bins on each axis, large
    /// primitives set apart, two threads for large subtrees). On the bunny and the dragon its
    /// trees trace incoherent rays 7-14% faster than obvhs' PLOC trees at this preset did, and
    /// build in the same time or less.
    #[default]
    Medium,
    /// The medium tree refined by obvhs' reinsertion: 1-2% faster incoherent rays on the bunny
    /// and the dragon for about 1.6 times the build time.
    High,
}

impl BuildQuality {
    /// Every preset, fastest build first.
    pub const ALL: [Self; 4] = [Self::Fastest, Self::Fast, Self::Medium, Self::High];

    /// Whether the binary tree is built top-down by binned SAH (`build::build_sah`) rather than
    /// by obvhs' PLOC.
    pub(crate) fn top_down(self) -> bool {
        matches!(self, Self::Medium | Self::High)
    }

    pub(crate) fn params(self) -> BvhBuildParams {
        match self {
            Self::Fastest => BvhBuildParams::fastest_build(),
            Self::Fast => BvhBuildParams::fast_build(),
            Self::Medium => BvhBuildParams::medium_build(),
            Self::High => BvhBuildParams::slow_build(),
        }
    }
}

/// How to build an [`Accel`].
///
/// ```
/// use pt_accel::{AccelKind, AccelOptions, BuildQuality};
/// let opts = AccelOptions::new().kind(AccelKind::TwoLevel).quality(BuildQuality::High);
/// assert_eq!(opts.kind, AccelKind::TwoLevel);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct AccelOptions {
    /// Strategy (default: automatic).
    pub kind: AccelKind,
    /// Build effort (default: medium).
    pub quality: BuildQuality,
    /// Node layout (default: eight-wide where the CPU has AVX2 and FMA, else four-wide).
    pub layout: BvhLayout,
}

impl AccelOptions {
    /// The defaults.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Set the strategy.
    #[must_use]
    pub fn kind(mut self, kind: AccelKind) -> Self {
        self.kind = kind;
        self
    }

    /// Set the build effort.
    #[must_use]
    pub fn quality(mut self, quality: BuildQuality) -> Self {
        self.quality = quality;
        self
    }

    /// Set the node layout.
    #[must_use]
    pub fn layout(mut self, layout: BvhLayout) -> Self {
        self.layout = layout;
        self
    }
}

/// What was built, for summaries and memory accounting.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct AccelStats {
    /// The strategy in use (never `Auto`).
    pub kind: AccelKind,
    /// Triangles over all instances, before validation.
    pub input_triangles: usize,
    /// Triangles skipped because they have zero area or a non-finite vertex (over all instances).
    pub skipped_triangles: usize,
    /// BVH nodes, over all levels (0 for brute force).
    pub nodes: usize,
    /// Bytes held by the accelerator: nodes, triangle copies, instance transforms.
    pub memory_bytes: usize,
    /// Wall time of the build.
    pub build_time: Duration,
}

#[derive(Clone, Debug)]
enum Imp {
    /// Brute force or one BVH over world-space triangles.
    Flat(TriangleBvh),
    TwoLevel(TwoLevel),
}

/// [`Accel::intersect_lanes`]'s work inside its dispatch.
struct IntersectLanes<'a> {
    accel: &'a Accel,
    rays: &'a RayLanes,
    mask: u32,
}

impl WithSimd for IntersectLanes<'_> {
    type Output = [Option<Hit>; WIDTH];
    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> Self::Output {
        self.accel.intersect_lanes_in(s, self.rays, self.mask)
    }
}

/// [`Accel::occluded_lanes`]'s work inside its dispatch.
struct OccludedLanes<'a> {
    accel: &'a Accel,
    rays: &'a RayLanes,
    mask: u32,
}

impl WithSimd for OccludedLanes<'_> {
    type Output = u32;
    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> u32 {
        self.accel.occluded_lanes_in(s, self.rays, self.mask)
    }
}

/// The two-level BVH's answers for the rays of `mask`'s lanes, one query after another.
/// Always inlined, as all lane code: out of line in a build for baseline x86-64 it runs
/// without the instruction set of its caller, every lane operation a call.
#[inline(always)]
fn two_level_lanes<S: Simd>(
    s: S,
    t: &TwoLevel,
    rays: &RayLanes,
    mask: u32,
) -> [Option<Hit>; WIDTH] {
    let mut out = [None; WIDTH];
    let rays = rays.to_rays(s);
    for lane in bits(mask) {
        out[lane] = t.intersect(&rays[lane]);
    }
    out
}

/// A flat BVH's lane answers as hits.
#[inline(always)]
fn lane_hits(found: [Option<(PrimRef, TriangleHit)>; WIDTH]) -> [Option<Hit>; WIDTH] {
    found.map(|c| {
        c.map(|(r, h)| Hit {
            t: h.t,
            instance: r.instance,
            prim: r.prim,
            b1: h.b1,
            b2: h.b2,
        })
    })
}

/// Answers closest-hit and any-hit queries against a set of mesh instances.
///
/// Build it with [`Accel::build`]; degenerate and non-finite triangles are skipped and counted,
/// and an empty scene answers "no hit" to every query. Hits report the instance and the triangle's
/// index in its mesh, with `t` in units of the query ray's direction, whatever the strategy.
#[derive(Clone, Debug)]
pub struct Accel {
    imp: Imp,
    bounds: Bounds3,
    stats: AccelStats,
}

/// The strategy [`AccelKind::Auto`] picks for these instances.
fn auto_kind<T: AsRef<TriangleMesh>>(meshes: &[T], instances: &[Instance]) -> AccelKind {
    let triangles: usize = instances
        .iter()
        .map(|i| meshes[i.mesh as usize].as_ref().triangle_count())
        .sum();
    if triangles <= BRUTE_FORCE_MAX_TRIANGLES {
        return AccelKind::BruteForce;
    }
    // Triangles of the distinct meshes the instances use: what a two-level BVH stores.
    let mut used = vec![false; meshes.len()];
    let mut distinct = 0usize;
    for i in instances {
        if !std::mem::replace(&mut used[i.mesh as usize], true) {
            distinct += meshes[i.mesh as usize].as_ref().triangle_count();
        }
    }
    if triangles - distinct > FLATTEN_MAX_COPIES {
        AccelKind::TwoLevel
    } else {
        AccelKind::Bvh
    }
}

impl Accel {
    /// Build an accelerator over `instances` of `meshes`.
    ///
    /// # Panics
    /// If an instance refers to a mesh index outside `meshes`.
    pub fn build<T: AsRef<TriangleMesh>>(
        meshes: &[T],
        instances: &[Instance],
        options: &AccelOptions,
    ) -> Self {
        let start = Instant::now();
        let kind = match options.kind {
            AccelKind::Auto => auto_kind(meshes, instances),
            k => k,
        };
        let (imp, bounds, input, skipped) = match kind {
            AccelKind::TwoLevel => {
                let t = TwoLevel::build(meshes, instances, options.layout, options.quality);
                let (b, i, s) = (t.bounds, t.input, t.skipped);
                (Imp::TwoLevel(t), b, i, s)
            }
            _ => {
                let store = TriangleStore::flatten(meshes, instances);
                let (b, i, s) = (store.bounds, store.input, store.skipped);
                let flat = if kind == AccelKind::BruteForce {
                    TriangleBvh::Brute(crate::brute::BruteForce::new(store))
                } else {
                    TriangleBvh::build(store, options.layout, options.quality, true)
                };
                (Imp::Flat(flat), b, i, s)
            }
        };
        let (nodes, memory_bytes) = match &imp {
            Imp::Flat(f) => (f.node_count(), f.memory_bytes()),
            Imp::TwoLevel(t) => (t.node_count(), t.memory_bytes()),
        };
        Self {
            imp,
            bounds,
            stats: AccelStats {
                kind,
                input_triangles: input,
                skipped_triangles: skipped,
                nodes,
                memory_bytes,
                build_time: start.elapsed(),
            },
        }
    }

    /// The closest hit with `t` in the ray's range, if any.
    ///
    /// Compiled here, not in the calling crate (no `#[inline]`), like the other query entry
    /// points: its kernels are generic, and a copy compiled in a program's unoptimised debug
    /// build ran about 25 times slower.
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        match &self.imp {
            Imp::Flat(f) => f.closest(ray).map(|(r, h)| Hit {
                t: h.t,
                instance: r.instance,
                prim: r.prim,
                b1: h.b1,
                b2: h.b2,
            }),
            Imp::TwoLevel(t) => t.intersect(ray),
        }
    }

    /// True when anything is hit with `t` in the ray's range (shadow rays). Stops at the first hit.
    /// Compiled here, as [`intersect`](Self::intersect).
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if !ray.is_valid() {
            return false;
        }
        match &self.imp {
            Imp::Flat(f) => f.occluded(ray),
            Imp::TwoLevel(t) => t.occluded(ray),
        }
    }

    /// [`intersect`](Self::intersect) for the rays in the lanes set in `mask` (bit `i` for
    /// lane `i` of `rays`; other lanes `None`), each answer exactly the one-ray query's. The
    /// eight-wide BVH takes them all in one dispatch, which saves each query's entry and set-up
    /// (the lane path tracer's queries); other accelerators answer them one after another.
    /// `RayLanes::from(&[Ray; 8])` makes the rays' lanes from eight rays. Compiled here, as
    /// [`intersect`](Self::intersect).
    #[must_use]
    pub fn intersect_lanes(&self, rays: &RayLanes, mask: u32) -> [Option<Hit>; WIDTH] {
        crate::lanes::dispatch(IntersectLanes {
            accel: self,
            rays,
            mask,
        })
    }

    /// [`intersect_lanes`](Self::intersect_lanes) for a caller that already runs with the
    /// lanes of `s`, inside [`lanes::dispatch`](crate::lanes::dispatch): the same answers,
    /// compiled with the caller's instruction set. A program built for baseline x86-64 would
    /// otherwise run the code between its lanes and the kernel (the valid-ray checks, the
    /// answers' copies) without the caller's instructions, as calls out of line. The
    /// eight-wide BVH's packet kernels stay out of line in every build (which measured
    /// faster), entered with the instruction set found when the tree was built.
    #[inline(always)]
    #[must_use]
    pub fn intersect_lanes_in<S: Simd>(
        &self,
        s: S,
        rays: &RayLanes,
        mask: u32,
    ) -> [Option<Hit>; WIDTH] {
        // Invalid rays miss.
        let mask = rays.valid_lanes(s, mask);
        match &self.imp {
            Imp::Flat(f) => lane_hits(f.closest_lanes_in(s, rays, mask)),
            Imp::TwoLevel(t) => two_level_lanes(s, t, rays, mask),
        }
    }

    /// [`occluded`](Self::occluded) for the rays in the lanes set in `mask`: bit `i` of the
    /// answer is set when lane `i`'s ray hits anything (as
    /// [`intersect_lanes`](Self::intersect_lanes), one dispatch in the eight-wide BVH). Compiled
    /// here, as [`intersect`](Self::intersect).
    #[must_use]
    pub fn occluded_lanes(&self, rays: &RayLanes, mask: u32) -> u32 {
        crate::lanes::dispatch(OccludedLanes {
            accel: self,
            rays,
            mask,
        })
    }

    /// [`occluded_lanes`](Self::occluded_lanes) for a caller that already runs with the
    /// lanes of `s`, as [`intersect_lanes_in`](Self::intersect_lanes_in).
    #[inline(always)]
    #[must_use]
    pub fn occluded_lanes_in<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32) -> u32 {
        let mask = rays.valid_lanes(s, mask);
        match &self.imp {
            Imp::Flat(f) => f.occluded_lanes_in(s, rays, mask),
            Imp::TwoLevel(t) => {
                let rays = rays.to_rays(s);
                mask_where(mask, |lane| t.occluded(&rays[lane]))
            }
        }
    }

    /// The most hits [`intersect_filtered`](Self::intersect_filtered) and
    /// [`occluded_filtered`](Self::occluded_filtered) reject along one ray before giving up
    /// (the ray then counts as missing everything).
    pub const MAX_REJECTED_HITS: usize = 256;

    /// The closest hit in the ray's range that `accept` accepts (an any-hit filter: alpha
    /// cut-outs, back-face culling). Rejected hits are stepped over: the query continues from
    /// just beyond each, so surfaces at exactly the same distance as a rejected one are
    /// stepped over with it. Costs one query per rejected hit; scenes without such surfaces
    /// should call [`intersect`](Self::intersect).
    #[inline]
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        mut accept: impl FnMut(&Hit) -> bool,
    ) -> Option<Hit> {
        let mut r = *ray;
        let mut last = None;
        for _ in 0..Self::MAX_REJECTED_HITS {
            let hit = self.intersect(&r)?;
            if accept(&hit) {
                return Some(hit);
            }
            let t = hit.t.max(r.t_min);
            // Instances hit in object space may round the same triangle back to the same
            // distance: step over it by a relative margin when it comes back.
            r.t_min = if last == Some((hit.instance, hit.prim)) {
                t + t.abs() * 1e-6 + f32::MIN_POSITIVE
            } else {
                next_up(t)
            };
            last = Some((hit.instance, hit.prim));
            if r.t_min.is_nan() || r.t_min > r.t_max {
                return None;
            }
        }
        None
    }

    /// True when the ray's range holds a hit that `accept` accepts (shadow rays through alpha
    /// cut-outs). An unoccluded ray costs one any-hit query; an occluded one, closest-hit
    /// queries until a hit is accepted.
    #[inline]
    pub fn occluded_filtered(&self, ray: &Ray, accept: impl FnMut(&Hit) -> bool) -> bool {
        self.occluded(ray) && self.intersect_filtered(ray, accept).is_some()
    }

    /// True when hits are computed against triangles baked into world space (brute force and the
    /// flat BVH), false when they are computed in each instance's object space (two-level). Code
    /// that reconstructs hit points with error bounds needs to know which.
    #[inline]
    #[must_use]
    pub fn hits_in_world_space(&self) -> bool {
        matches!(self.imp, Imp::Flat(_))
    }

    /// World-space bounds of all valid triangles (empty when there are none).
    #[inline]
    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// What was built.
    #[inline]
    #[must_use]
    pub fn stats(&self) -> &AccelStats {
        &self.stats
    }
}

/// The smallest `f32` above `t` (`t` itself for NaN and infinity; `f32::next_up` needs a newer
/// Rust than pt's minimum).
#[inline]
fn next_up(t: f32) -> f32 {
    if t.is_nan() || t == f32::INFINITY {
        t
    } else if t == 0.0 {
        f32::from_bits(1)
    } else if t > 0.0 {
        f32::from_bits(t.to_bits() + 1)
    } else {
        f32::from_bits(t.to_bits() - 1)
    }
}

#[cfg(test)]
mod filter_tests {
    use glam::{Affine3A, Vec3};

    use super::*;

    /// The same unit triangle at z = 0, -1, -2 (instances 0, 1, 2), built as `kind`.
    fn stack(kind: AccelKind) -> Accel {
        let mesh = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
        let instances: Vec<Instance> = (0..3)
            .map(|i| Instance::with_transform(0, Affine3A::from_translation(-Vec3::Z * i as f32)))
            .collect();
        Accel::build(
            &[mesh],
            &instances,
            &AccelOptions {
                kind,
                ..AccelOptions::new()
            },
        )
    }

    #[test]
    fn filtered_queries_step_over_rejected_hits() {
        for kind in [AccelKind::BruteForce, AccelKind::Bvh, AccelKind::TwoLevel] {
            let a = stack(kind);
            let ray = Ray::new(Vec3::new(0.2, 0.3, 1.0), -Vec3::Z);
            let first = |reject: &[u32]| {
                a.intersect_filtered(&ray, |h| !reject.contains(&h.instance))
                    .map(|h| (h.instance, h.t))
            };
            assert_eq!(first(&[]), Some((0, 1.0)), "{kind:?}");
            assert_eq!(first(&[0]), Some((1, 2.0)), "{kind:?}");
            assert_eq!(first(&[0, 1]), Some((2, 3.0)), "{kind:?}");
            assert_eq!(first(&[0, 1, 2]), None, "{kind:?}");
            // Each rejected hit is offered once.
            let mut offered = Vec::new();
            let _ = a.intersect_filtered(&ray, |h| {
                offered.push(h.instance);
                false
            });
            assert_eq!(offered, [0, 1, 2], "{kind:?}");
            // Shadow rays: blocked only by an accepted hit within range.
            let seg = Ray::with_t_max(ray.origin, ray.dir, 2.5);
            assert!(a.occluded_filtered(&seg, |h| h.instance == 1), "{kind:?}");
            assert!(!a.occluded_filtered(&seg, |h| h.instance == 2), "{kind:?}");
        }
    }
}
