//! A compressed wide BVH (CWBVH, Ylitie et al. 2017) over triangles, built by obvhs
//! and traversed with obvhs' `traverse!` macro and pt's own node test.
//!
//! Why a custom node test: obvhs' CWBVH test clamps each child's entry distance to a hard-coded
//! `1e-4` instead of the ray's `t_min`, so any hit closer than `1e-4` is lost; a scene measured in
//! metres and scaled by `1e-4` would lose most of its geometry. The test here uses the ray's own
//! range and widens every slab by a bound on the rounding error of its computation (the
//! conservative slab test of *Physically Based Rendering*, 4th ed., section 6.1.2, adapted to the
//! quantised child boxes), so a ray aimed exactly at a triangle's vertex, which lies on the corner
//! of its leaf box, is never culled. Triangles are stored in BVH order so that the primitive index
//! the traversal hands out addresses them directly.

use std::time::Duration;

use glam::{UVec2, Vec3A, Vec4};
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::node::{CwBvhNode, extract_byte64};
use obvhs::traverse;

use crate::BuildQuality;
use crate::node_ray::NodeRay;
use crate::ray::Ray;
use crate::store::TriangleStore;
use crate::triangle::{RayTriangleTest, TriangleHit};

#[inline(always)]
fn quad(v: &[u8; 8], i: usize) -> Vec4 {
    Vec4::new(
        v[4 * i] as f32,
        v[4 * i + 1] as f32,
        v[4 * i + 2] as f32,
        v[4 * i + 3] as f32,
    )
}

/// Hit mask of the children of `node` whose quantised box overlaps the ray over `[t_min, t_max]`.
///
/// The distance to a child plane is `q * a + b` with `a = extent * inv_dir` and
/// `b = (node_min - origin) * inv_dir`. Its rounding error is below
/// `gamma(7) * (255 |a| + (|node_min| + |origin|) |inv_dir|)`, which also covers the rounding of
/// the quantised planes themselves (relative to `|node_min|`). `slack` must bound that for every
/// node of the tree (see [`slab_slack`]); entry distances are lowered and exit distances raised by
/// it, per axis, before the overlap test.
#[inline(always)]
pub(crate) fn intersect_node(
    node: &CwBvhNode,
    r: &NodeRay,
    slack: Vec3A,
    t_max: f32,
    oct_inv4: u32,
) -> u32 {
    let p = Vec3A::from(node.p);
    let a = node.compute_extent() * r.inv_dir;
    let b = (p - r.origin) * r.inv_dir;
    let b_near = b - slack;
    let b_far = b + slack;

    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let mut hit_mask = 0u32;
    for i in 0..2 {
        // Load both planes of each axis, then pick near and far by the direction's sign.
        let (lo_x, hi_x) = (quad(&node.child_min_x, i), quad(&node.child_max_x, i));
        let (lo_y, hi_y) = (quad(&node.child_min_y, i), quad(&node.child_max_y, i));
        let (lo_z, hi_z) = (quad(&node.child_min_z, i), quad(&node.child_max_z, i));
        let (near_x, far_x) = if r.neg[0] { (hi_x, lo_x) } else { (lo_x, hi_x) };
        let (near_y, far_y) = if r.neg[1] { (hi_y, lo_y) } else { (lo_y, hi_y) };
        let (near_z, far_z) = if r.neg[2] { (hi_z, lo_z) } else { (lo_z, hi_z) };
        let t_enter = (near_x * a.x + b_near.x)
            .max(near_y * a.y + b_near.y)
            .max(near_z * a.z + b_near.z)
            .max(Vec4::splat(r.t_min));
        let t_exit = (far_x * a.x + b_far.x)
            .min(far_y * a.y + b_far.y)
            .min(far_z * a.z + b_far.z)
            .min(Vec4::splat(t_max));
        let mask = t_enter.cmple(t_exit).bitmask();
        for j in 0..4 {
            if mask & (1 << j) != 0 {
                let child = i * 4 + j;
                hit_mask |= extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
            }
        }
    }
    hit_mask
}

/// Per-axis bound on `255 * extent + |node_min|` over every node of a tree whose root box is
/// `bounds`: a node's quantisation step `extent` is at most twice `root size / 255` (rounded up to
/// a power of two), and its corner lies inside the root box.
pub(crate) fn coord_scale(bounds: &obvhs::aabb::Aabb) -> Vec3A {
    if !bounds.valid() {
        return Vec3A::ZERO;
    }
    (bounds.max - bounds.min) * 2.0 + bounds.min.abs().max(bounds.max.abs())
}

/// The slab slack of [`intersect_node`] for a ray and a tree with the given [`coord_scale`]:
/// computed once per query instead of once per node.
#[inline(always)]
pub(crate) fn slab_slack(r: &NodeRay, coord_scale: Vec3A) -> Vec3A {
    (coord_scale + r.origin_abs) * r.slack_scale
}

/// Depth of a CWBVH in nodes (0 when empty).
pub(crate) fn cwbvh_depth(bvh: &CwBvh) -> usize {
    fn depth(bvh: &CwBvh, node: usize) -> usize {
        let n = &bvh.nodes[node];
        (0..8)
            .filter(|c| n.imask & (1 << c) != 0)
            .map(|c| depth(bvh, n.child_node_index(c) as usize))
            .max()
            .unwrap_or(0)
            + 1
    }
    if bvh.nodes.is_empty() {
        0
    } else {
        depth(bvh, 0)
    }
}

/// A CWBVH over a triangle store whose triangles are kept in BVH leaf order.
#[derive(Clone, Debug)]
pub(crate) struct WideBvh {
    bvh: CwBvh,
    /// See [`coord_scale`].
    coord_scale: Vec3A,
    pub store: TriangleStore,
}

/// obvhs' CWBVH traversal stack holds 32 entries and silently overwrites its top when full, so a
/// tree must be shallower than this to be traversed correctly.
pub(crate) const MAX_WIDE_DEPTH: usize = 31;

impl WideBvh {
    /// Build over `store`, reordering its triangles into BVH order.
    pub fn build(store: TriangleStore, quality: BuildQuality) -> Self {
        if store.tris.is_empty() {
            return Self {
                bvh: CwBvh::default(),
                coord_scale: Vec3A::ZERO,
                store,
            };
        }
        let tris = store.obvhs_triangles();
        let boxes: Vec<obvhs::aabb::Aabb> =
            tris.iter().map(obvhs::triangle::Triangle::aabb).collect();
        let bvh = crate::build::cwbvh_from_boxes(&boxes, quality, || {
            build_cwbvh_from_tris(&tris, quality.params(), &mut Duration::default())
        });
        drop(tris);
        Self {
            store: store.reordered(&bvh.primitive_indices),
            coord_scale: coord_scale(&bvh.total_aabb),
            bvh,
        }
    }

    /// Depth of the tree in nodes (0 when empty).
    pub fn depth(&self) -> usize {
        cwbvh_depth(&self.bvh)
    }

    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.capacity() * std::mem::size_of::<CwBvhNode>()
            + self.bvh.primitive_indices.capacity() * 4
            + self.store.memory_bytes()
    }

    /// The closest triangle hit in `[t_min, t_max]`: its slot in the store and the hit.
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(usize, TriangleHit)> {
        if self.bvh.nodes.is_empty() {
            return None;
        }
        let test = RayTriangleTest::new(ray);
        let node_ray = NodeRay::new(ray);
        let slack = slab_slack(&node_ray, self.coord_scale);
        let mut t_max = ray.t_max;
        let mut best = None;
        let mut state = self.bvh.new_traversal(Vec3A::from(ray.dir));
        let mut node;
        traverse!(
            self.bvh,
            node,
            state,
            intersect_node(node, &node_ray, slack, t_max, state.oct_inv4),
            {
                let slot = state.primitive_id as usize;
                if let Some(h) = test.intersect_packed(&self.store.tris[slot].tri, t_max) {
                    t_max = h.t;
                    best = Some((slot, h));
                }
            }
        );
        best
    }

    /// True when any triangle is hit in `[t_min, t_max]`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.bvh.nodes.is_empty() {
            return false;
        }
        let test = RayTriangleTest::new(ray);
        let node_ray = NodeRay::new(ray);
        let slack = slab_slack(&node_ray, self.coord_scale);
        let mut state = self.bvh.new_traversal(Vec3A::from(ray.dir));
        let mut node;
        let mut hit = false;
        'search: {
            traverse!(
                self.bvh,
                node,
                state,
                intersect_node(node, &node_ray, slack, ray.t_max, state.oct_inv4),
                {
                    let slot = state.primitive_id as usize;
                    if test
                        .intersect_packed(&self.store.tris[slot].tri, ray.t_max)
                        .is_some()
                    {
                        hit = true;
                        break 'search;
                    }
                }
            );
        }
        hit
    }
}

// `UVec2` is named inside obvhs' `traverse!` expansion.
const _: UVec2 = UVec2::ZERO;
