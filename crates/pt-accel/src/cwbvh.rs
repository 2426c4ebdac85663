//! A compressed wide BVH (CWBVH, Ylitie et al. 2017) over world-space triangles, built by obvhs
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
use obvhs::triangle::Triangle;

use crate::BuildQuality;
use crate::float::gamma;
use crate::ray::{Hit, Ray};
use crate::store::TriangleStore;
use crate::triangle::RayTriangleTest;

/// Direction components smaller than this are treated as this (with their sign), which keeps
/// every slab distance finite: coordinates up to 1e17 times the smallest direction component stay
/// far below f32::MAX, and distances along such an axis only matter when the ray origin lies
/// within 1e-20 * (hit distance) of a slab plane.
const MIN_DIR: f32 = 1e-20;

/// The per-query constants of the node test.
struct NodeRay {
    origin: Vec3A,
    inv_dir: Vec3A,
    /// |origin| * |inv_dir|: the scale of the rounding error of the plane positions themselves.
    origin_scale: Vec3A,
    neg: [bool; 3],
    t_min: f32,
}

impl NodeRay {
    #[inline]
    fn new(ray: &Ray) -> Self {
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
}

/// Bound on the relative rounding error of one child's slab distance (see `intersect_node`).
const SLAB_GAMMA: f32 = gamma(7);

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
/// the quantised planes themselves (relative to `|node_min|`). Entry distances are lowered and
/// exit distances raised by that bound, per axis, before the overlap test.
#[inline(always)]
fn intersect_node(node: &CwBvhNode, r: &NodeRay, t_max: f32, oct_inv4: u32) -> u32 {
    let p = Vec3A::from(node.p);
    let a = node.compute_extent() * r.inv_dir;
    let b = (p - r.origin) * r.inv_dir;
    let slack = (a.abs() * 255.0 + p.abs() * r.inv_dir.abs() + r.origin_scale) * SLAB_GAMMA;
    let b_near = b - slack;
    let b_far = b + slack;

    let (near_x, far_x) = if r.neg[0] {
        (&node.child_max_x, &node.child_min_x)
    } else {
        (&node.child_min_x, &node.child_max_x)
    };
    let (near_y, far_y) = if r.neg[1] {
        (&node.child_max_y, &node.child_min_y)
    } else {
        (&node.child_min_y, &node.child_max_y)
    };
    let (near_z, far_z) = if r.neg[2] {
        (&node.child_max_z, &node.child_min_z)
    } else {
        (&node.child_min_z, &node.child_max_z)
    };

    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let mut hit_mask = 0u32;
    for i in 0..2 {
        let t_enter = (quad(near_x, i) * a.x + b_near.x)
            .max(quad(near_y, i) * a.y + b_near.y)
            .max(quad(near_z, i) * a.z + b_near.z)
            .max(Vec4::splat(r.t_min));
        let t_exit = (quad(far_x, i) * a.x + b_far.x)
            .min(quad(far_y, i) * a.y + b_far.y)
            .min(quad(far_z, i) * a.z + b_far.z)
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

/// A CWBVH over a triangle store whose triangles are kept in BVH leaf order.
#[derive(Clone, Debug)]
pub(crate) struct FlatBvh {
    bvh: CwBvh,
    pub store: TriangleStore,
}

impl FlatBvh {
    /// Build over `store`, reordering its triangles into BVH order.
    pub fn build(store: TriangleStore, quality: BuildQuality) -> Self {
        if store.verts.is_empty() {
            return Self {
                bvh: CwBvh::default(),
                store,
            };
        }
        let tris: Vec<Triangle> = store
            .verts
            .iter()
            .map(|v| Triangle {
                v0: v[0],
                v1: v[1],
                v2: v[2],
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&tris, quality.params(), &mut Duration::default());
        drop(tris);
        // Spatial splits may list a triangle in several leaves: store it once per slot.
        let verts = bvh
            .primitive_indices
            .iter()
            .map(|&i| store.verts[i as usize])
            .collect();
        let refs = bvh
            .primitive_indices
            .iter()
            .map(|&i| store.refs[i as usize])
            .collect();
        Self {
            bvh,
            store: TriangleStore {
                verts,
                refs,
                ..store
            },
        }
    }

    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.capacity() * std::mem::size_of::<CwBvhNode>()
            + self.bvh.primitive_indices.capacity() * 4
            + self.store.memory_bytes()
    }

    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if self.bvh.nodes.is_empty() {
            return None;
        }
        let test = RayTriangleTest::new(ray);
        let node_ray = NodeRay::new(ray);
        let mut t_max = ray.t_max;
        let mut best = None;
        let mut state = self.bvh.new_traversal(Vec3A::from(ray.dir));
        let mut node;
        traverse!(
            self.bvh,
            node,
            state,
            intersect_node(node, &node_ray, t_max, state.oct_inv4),
            {
                let slot = state.primitive_id as usize;
                if let Some(h) = test.intersect(&self.store.verts[slot], t_max) {
                    t_max = h.t;
                    best = Some((slot, h));
                }
            }
        );
        best.map(|(slot, h)| {
            let r = self.store.refs[slot];
            Hit {
                t: h.t,
                instance: r.instance,
                prim: r.prim,
                b1: h.b1,
                b2: h.b2,
            }
        })
    }

    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.bvh.nodes.is_empty() {
            return false;
        }
        let test = RayTriangleTest::new(ray);
        let node_ray = NodeRay::new(ray);
        let mut state = self.bvh.new_traversal(Vec3A::from(ray.dir));
        let mut node;
        let mut hit = false;
        'search: {
            traverse!(
                self.bvh,
                node,
                state,
                intersect_node(node, &node_ray, ray.t_max, state.oct_inv4),
                {
                    let slot = state.primitive_id as usize;
                    if test.intersect(&self.store.verts[slot], ray.t_max).is_some() {
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
