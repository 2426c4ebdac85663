//! A binary BVH (BVH2) over triangles, built by `crate::build` (binned SAH, or obvhs' PLOC for the
//! faster presets, then obvhs' leaf collapsing) and traversed front to back with pt's
//! conservative slab test.
//!
//! The traversal keeps its stack in a fixed array, so it never allocates; trees deeper than the
//! stack are refused at build time (the caller falls back to another structure).

use glam::Vec3A;
use obvhs::bvh2::Bvh2;

use crate::BuildQuality;
use crate::node_ray::NodeRay;
use crate::ray::Ray;
use crate::store::TriangleStore;
use crate::triangle::{RayTriangleTest, TriangleHit};

/// Capacity of the traversal stack (one entry per level at most); deeper trees are not used.
pub(crate) const MAX_BINARY_DEPTH: usize = 128;

/// A BVH2 over a triangle store whose triangles are kept in BVH leaf order.
#[derive(Clone)]
pub(crate) struct BinaryBvh {
    bvh: Bvh2,
    pub store: TriangleStore,
}

impl std::fmt::Debug for BinaryBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BinaryBvh")
            .field("nodes", &self.bvh.nodes.len())
            .field("store", &self.store)
            .finish()
    }
}

impl BinaryBvh {
    /// Build over `store`, reordering its triangles into BVH order.
    pub fn build(store: TriangleStore, quality: BuildQuality) -> Self {
        if store.tris.is_empty() {
            return Self {
                bvh: Bvh2::default(),
                store,
            };
        }
        let tris = store.obvhs_triangles();
        let bvh = crate::build::bvh2_from_tris(&tris, quality, quality.params());
        drop(tris);
        Self {
            store: store.reordered(&bvh.primitive_indices),
            bvh,
        }
    }

    /// Depth of the tree in nodes (0 when empty), computed without recursion.
    pub fn depth(&self) -> usize {
        if self.bvh.nodes.is_empty() {
            return 0;
        }
        let mut max = 0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((i, d)) = stack.pop() {
            max = max.max(d);
            let n = &self.bvh.nodes[i];
            if n.prim_count == 0 {
                stack.push((n.first_index as usize, d + 1));
                stack.push((n.first_index as usize + 1, d + 1));
            }
        }
        max
    }

    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.capacity() * std::mem::size_of::<obvhs::bvh2::node::Bvh2Node>()
            + self.bvh.primitive_indices.capacity() * 4
            + self.store.memory_bytes()
    }

    /// Visit leaves roughly front to back while `visit(first, count, t_max)` returns a new
    /// `t_max` (`None` stops the traversal). Children are tested in pairs; a leaf child is visited
    /// at once, the nearer inner child is followed and the farther one pushed.
    #[inline(always)]
    fn traverse(&self, ray: &Ray, mut visit: impl FnMut(usize, usize, f32) -> Option<f32>) {
        let nodes = &self.bvh.nodes;
        let Some(root) = nodes.first() else { return };
        let node_ray = NodeRay::for_boxes(ray);
        let mut t_max = ray.t_max;
        if node_ray
            .box_entry(root.aabb.min, root.aabb.max, t_max)
            .is_infinite()
        {
            return;
        }
        if root.prim_count > 0 {
            visit(root.first_index as usize, root.prim_count as usize, t_max);
            return;
        }
        // Each stack entry is the index of a pair of sibling nodes.
        let mut stack = [0u32; MAX_BINARY_DEPTH];
        let mut len = 0usize;
        let mut pair = root.first_index;
        loop {
            let (mut a, mut b) = (&nodes[pair as usize], &nodes[pair as usize + 1]);
            let mut ta = node_ray.box_entry(a.aabb.min, a.aabb.max, t_max);
            let mut tb = node_ray.box_entry(b.aabb.min, b.aabb.max, t_max);
            if tb < ta {
                std::mem::swap(&mut a, &mut b);
                std::mem::swap(&mut ta, &mut tb);
            }
            let mut go = [None, None];
            for (k, (node, t)) in [(a, ta), (b, tb)].into_iter().enumerate() {
                // A miss is infinite, which `t > t_max` alone would not reject for unbounded rays;
                // `t > t_max` drops boxes beyond a hit found in the sibling.
                if t == f32::INFINITY || t > t_max {
                    continue;
                }
                if node.prim_count > 0 {
                    match visit(node.first_index as usize, node.prim_count as usize, t_max) {
                        Some(new_max) => t_max = new_max,
                        None => return,
                    }
                } else {
                    go[k] = Some(node.first_index);
                }
            }
            pair = match go {
                [Some(near), Some(far)] => {
                    stack[len] = far;
                    len += 1;
                    near
                }
                [Some(only), None] | [None, Some(only)] => only,
                [None, None] => {
                    if len == 0 {
                        return;
                    }
                    len -= 1;
                    stack[len]
                }
            };
        }
    }

    /// The closest triangle hit in `[t_min, t_max]`: its slot in the store and the hit.
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(usize, TriangleHit)> {
        let test = RayTriangleTest::new(ray);
        let mut best = None;
        self.traverse(ray, |first, count, mut t_max| {
            for slot in first..first + count {
                if let Some(h) = test.intersect_packed(&self.store.tris[slot].tri, t_max) {
                    t_max = h.t;
                    best = Some((slot, h));
                }
            }
            Some(t_max)
        });
        best
    }

    /// True when any triangle is hit in `[t_min, t_max]`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let test = RayTriangleTest::new(ray);
        let mut hit = false;
        self.traverse(ray, |first, count, t_max| {
            for slot in first..first + count {
                if test
                    .intersect_packed(&self.store.tris[slot].tri, t_max)
                    .is_some()
                {
                    hit = true;
                    return None;
                }
            }
            Some(t_max)
        });
        hit
    }
}

// The node's box type must be the Vec3A pair this file reads.
const _: fn(&obvhs::bvh2::node::Bvh2Node) -> (Vec3A, Vec3A) = |n| (n.aabb.min, n.aabb.max);
