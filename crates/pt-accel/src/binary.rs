//! A binary BVH (BVH2) over triangles, built by obvhs (PLOC with reinsertion and leaf collapsing)
//! and traversed front to back with pt's conservative slab test.
//!
//! The traversal keeps its stack in a fixed array, so it never allocates; trees deeper than the
//! stack are refused at build time (the caller falls back to another structure).

use std::time::Duration;

use glam::Vec3A;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;

use crate::BuildQuality;
use crate::node_ray::NodeRay;
use crate::ray::Ray;
use crate::store::TriangleStore;
use crate::triangle::{RayTriangleTest, TriangleHit};

/// Capacity of the traversal stack; trees deeper than this are not used.
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
        if store.verts.is_empty() {
            return Self {
                bvh: Bvh2::default(),
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
        let bvh = build_bvh2_from_tris(&tris, quality.params(), &mut Duration::default());
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

    /// Visit leaves front to back while `visit(first, count, t_max)` returns a new `t_max`
    /// (`None` stops the traversal).
    #[inline(always)]
    fn traverse(&self, ray: &Ray, mut visit: impl FnMut(usize, usize, f32) -> Option<f32>) {
        if self.bvh.nodes.is_empty() {
            return;
        }
        let node_ray = NodeRay::new(ray);
        let nodes = &self.bvh.nodes;
        let mut t_max = ray.t_max;
        let mut stack = [0u32; MAX_BINARY_DEPTH];
        let mut len = 0usize;
        let root = &nodes[0];
        let (enter, exit) = node_ray.slab(root.aabb.min, root.aabb.max, t_max);
        if enter > exit {
            return;
        }
        let mut current = 0u32;
        loop {
            let node = &nodes[current as usize];
            if node.prim_count > 0 {
                match visit(node.first_index as usize, node.prim_count as usize, t_max) {
                    Some(t) => t_max = t,
                    None => return,
                }
            } else {
                // Visit the nearer child first; push the farther one.
                let (a, b) = (node.first_index, node.first_index + 1);
                let (na, nb) = (&nodes[a as usize], &nodes[b as usize]);
                let (ea, xa) = node_ray.slab(na.aabb.min, na.aabb.max, t_max);
                let (eb, xb) = node_ray.slab(nb.aabb.min, nb.aabb.max, t_max);
                match (ea <= xa, eb <= xb) {
                    (true, true) => {
                        let (near, far) = if ea <= eb { (a, b) } else { (b, a) };
                        stack[len] = far;
                        len += 1;
                        current = near;
                        continue;
                    }
                    (true, false) => {
                        current = a;
                        continue;
                    }
                    (false, true) => {
                        current = b;
                        continue;
                    }
                    (false, false) => {}
                }
            }
            if len == 0 {
                return;
            }
            len -= 1;
            current = stack[len];
        }
    }

    /// The closest triangle hit in `[t_min, t_max]`: its slot in the store and the hit.
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(usize, TriangleHit)> {
        let test = RayTriangleTest::new(ray);
        let mut best = None;
        self.traverse(ray, |first, count, mut t_max| {
            for slot in first..first + count {
                if let Some(h) = test.intersect(&self.store.verts[slot], t_max) {
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
                if test.intersect(&self.store.verts[slot], t_max).is_some() {
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
