//! The two-level BVH: one bottom-level BVH per distinct mesh, in the mesh's own space, and a
//! top-level BVH over the world bounds of the instances.
//!
//! Geometry is never copied per instance: a hundred instances of a mesh share its one bottom-level
//! BVH and cost one transform each. A query walks the top level with the world ray; at each
//! instance it maps the ray into object space with the inverse transform, **without renormalising
//! the direction**, so hit distances stay in world units and compare across instances directly.
//!
//! Mapping the origin into object space rounds it. So that this rounding cannot move a ray that was
//! robustly spawned off a surface back onto that surface, the object-space origin is advanced along
//! the direction by the projection of its error bound (pbrt-v4's `Transform::ApplyInverse(Ray,
//! tMax)`), and the hit distance is corrected by the same amount. Surfaces closer to the origin
//! than that advance are skipped, so the bound must be tight: pt maps the origin in f64 (products
//! of f32 values are exact there) and rounds once to f32, so the bound is one ulp of the
//! object-space origin instead of pbrt's `gamma(3)` times the world-space magnitudes. For an
//! instance translated 1e5 away, pbrt's bound is about 0.04 world units and a wall 0.01 away
//! from a point near a corner was skipped (light leaked into a closed box, `tests/stress_scale.rs`);
//! the f64 bound there is about 3e-5.

use std::mem::MaybeUninit;

use glam::{Affine3A, DAffine3, Mat3A, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;

use crate::bounds::Bounds3;
use crate::mesh::{Instance, TriangleMesh};
use crate::node_ray::NodeRay;
use crate::ray::{Hit, Ray};
use crate::stack::Stack;
use crate::store::TriangleStore;
use crate::tri_bvh::TriangleBvh;
use crate::{BuildQuality, BvhLayout};

/// One ulp of an f32 relative to its magnitude, as an upper bound (2^-23).
const F32_ULP: f32 = f32::EPSILON;

/// `gamma(3)` for f64 arithmetic, `3 u / (1 - 3 u)` with `u = 2^-53`, rounded up (and then
/// enlarged a little: it is also applied to the f32 sum that bounds the magnitudes).
const F64_GAMMA3: f32 = 4e-16;

/// Per-instance data used at query time.
#[derive(Clone, Debug)]
struct InstanceData {
    world_to_object: Affine3A,
    /// The same transform in f64, for mapping ray origins with a tight error bound.
    world_to_object_f64: DAffine3,
    /// Absolute values of `world_to_object`'s matrix, for the origin's error bound.
    abs_matrix: Mat3A,
    abs_translation: Vec3A,
    /// Index into `TwoLevel::blas`.
    blas: u32,
}

impl InstanceData {
    /// World bounds `[lo, hi]` widened by `1e-4` of their extent and of their coordinates'
    /// magnitudes (the corners' transform and the ray's mapping into object space round at
    /// about `1e-7` of those), and by the smallest normal float: a ray found outside them
    /// meets none of the instance's triangles within the range tested. The top level's leaves
    /// have these boxes, so the walk itself culls an instance the ray misses or meets only
    /// beyond the closest hit so far (on the dragons figure 1.29 of 3.28 instances met per
    /// closest-hit query), before its ray is mapped into object space.
    fn padded(lo: Vec3A, hi: Vec3A) -> (Vec3A, Vec3A) {
        let extent = (hi - lo).max_element();
        let pad =
            |v: Vec3A| (v.abs() + Vec3A::splat(extent)) * 1e-4 + Vec3A::splat(f32::MIN_POSITIVE);
        (lo - pad(lo), hi + pad(hi))
    }

    /// The ray in object space, and the distance its origin was advanced by.
    #[inline(always)]
    fn to_object(&self, ray: &Ray, t_max: f32) -> (Ray, f32) {
        let o = Vec3A::from(ray.origin);
        let d = self
            .world_to_object
            .transform_vector3a(Vec3A::from(ray.dir));
        // In f64 the three products of each row are exact and the two sums round at 2^-53, so
        // the bound is the f64 rounding (gamma(3) of f64 on the world-space magnitudes) plus the
        // one rounding to f32 (half an ulp; one ulp is taken).
        let o_obj = Vec3A::from(
            self.world_to_object_f64
                .transform_point3(ray.origin.as_dvec3())
                .as_vec3(),
        );
        let err =
            o_obj.abs() * F32_ULP + (self.abs_matrix * o.abs() + self.abs_translation) * F64_GAMMA3;
        let len2 = d.length_squared();
        let dt = if len2 > 0.0 {
            d.abs().dot(err) / len2
        } else {
            0.0
        };
        (
            Ray {
                origin: (o_obj + d * dt).into(),
                dir: d.into(),
                t_min: (ray.t_min - dt).max(0.0),
                t_max: t_max - dt,
            },
            dt,
        )
    }
}

/// The top level: a binary tree over the instances' padded world bounds, built by binned SAH
/// (`build::build_sah`, whatever the preset: instances are few next to triangles) and walked
/// front to back with the conservative box test. Its leaves hold one instance each; no nodes
/// when no instance has geometry.
///
/// It replaced a CWBVH walked by obvhs' `traverse!` (the dragons figure +4.5%: the compressed
/// nodes' decoding cost more than the two plain box tests per node).
#[derive(Clone, Debug, Default)]
struct Top {
    nodes: Vec<Bvh2Node>,
    /// The instance of each leaf (`first_index` of a leaf indexes this).
    instances: Vec<u32>,
}

/// Entries of the top-level walk's stack: at most one per level, and `build_sah`'s trees are at
/// most `SAH_MAX_DEPTH + log2 n` deep.
const TOP_STACK: usize = 128;
const _: () = assert!(crate::build::SAH_MAX_DEPTH as usize + 64 < TOP_STACK);

/// Instances of meshes, each mesh with its own BVH.
#[derive(Clone, Debug)]
pub(crate) struct TwoLevel {
    blas: Vec<TriangleBvh>,
    instances: Vec<InstanceData>,
    top: Top,
    pub bounds: Bounds3,
    pub input: usize,
    pub skipped: usize,
}

impl TwoLevel {
    pub fn build<T: AsRef<TriangleMesh>>(
        meshes: &[T],
        instances: &[Instance],
        layout: BvhLayout,
        quality: BuildQuality,
    ) -> Self {
        // One bottom-level BVH per mesh that some instance uses, built once.
        let mut blas_of_mesh = vec![u32::MAX; meshes.len()];
        let mut blas = Vec::new();
        let mut skipped_of_blas = Vec::new();
        for inst in instances {
            let m = inst.mesh as usize;
            if blas_of_mesh[m] == u32::MAX {
                let store = TriangleStore::from_mesh(meshes[m].as_ref());
                skipped_of_blas.push(store.skipped);
                blas_of_mesh[m] = blas.len() as u32;
                // Bottom-level trees answer one ray at a time.
                blas.push(TriangleBvh::build(store, layout, quality, false));
            }
        }

        let mut data = Vec::with_capacity(instances.len());
        let mut bounds = Bounds3::EMPTY;
        let mut boxes = Vec::new();
        let mut boxed = Vec::new();
        let (mut input, mut skipped) = (0, 0);
        for (i, inst) in instances.iter().enumerate() {
            let b = blas_of_mesh[inst.mesh as usize];
            let w2o = inst.transform.inverse();
            let object_bounds = blas[b as usize].store().bounds;
            let world = object_bounds.transformed(&inst.transform);
            let (world_lo, world_hi) = InstanceData::padded(world.min.into(), world.max.into());
            data.push(InstanceData {
                world_to_object: w2o,
                world_to_object_f64: DAffine3::from_cols_array(&w2o.to_cols_array().map(f64::from)),
                abs_matrix: Mat3A::from_cols(
                    w2o.matrix3.x_axis.abs(),
                    w2o.matrix3.y_axis.abs(),
                    w2o.matrix3.z_axis.abs(),
                ),
                abs_translation: w2o.translation.abs(),
                blas: b,
            });
            input += meshes[inst.mesh as usize].as_ref().triangle_count();
            skipped += skipped_of_blas[b as usize];
            if object_bounds.is_empty() {
                continue;
            }
            let extent = world.min.abs().max(world.max.abs()).max_element();
            if extent.is_nan() || extent > crate::mesh::MAX_COORDINATE {
                // Placed beyond the coordinates a BVH can handle (see `MAX_COORDINATE`).
                skipped += blas[b as usize].store().tris.len();
                continue;
            }
            bounds = bounds.union(world);
            // The padded bounds: the walk culls an instance by the box of its leaf.
            boxes.push(Aabb::new(world_lo, world_hi));
            boxed.push(i as u32);
        }

        let top = if boxes.is_empty() {
            Top::default()
        } else {
            let bvh = crate::build::build_sah(&boxes);
            Top {
                instances: bvh
                    .primitive_indices
                    .iter()
                    .map(|&p| boxed[p as usize])
                    .collect(),
                nodes: bvh.nodes,
            }
        };
        Self {
            blas,
            instances: data,
            top,
            bounds,
            input,
            skipped,
        }
    }

    pub fn node_count(&self) -> usize {
        self.top.nodes.len() + self.blas.iter().map(TriangleBvh::node_count).sum::<usize>()
    }

    pub fn memory_bytes(&self) -> usize {
        let top = self.top.nodes.capacity() * std::mem::size_of::<Bvh2Node>()
            + self.top.instances.capacity() * 4;
        top + self.instances.capacity() * std::mem::size_of::<InstanceData>()
            + self
                .blas
                .iter()
                .map(TriangleBvh::memory_bytes)
                .sum::<usize>()
    }

    /// Call `visit(instance, t_max)` for every instance whose padded bounds the ray may enter
    /// before `t_max`, front to back by entry distance; `visit` returns the new `t_max`, or
    /// `None` to stop.
    #[inline(always)]
    fn for_candidates(&self, ray: &Ray, mut visit: impl FnMut(u32, f32) -> Option<f32>) {
        let nodes = &self.top.nodes;
        let Some(root) = nodes.first() else {
            return;
        };
        let boxes = NodeRay::for_boxes(ray);
        let mut t_max = ray.t_max;
        // Entry distances round: boxes are compared with `t_max` widened by far more.
        let end = |t: f32| t + t * 2.0f32.powi(-20);
        let entry = |n: &Bvh2Node, t: f32| boxes.box_entry(n.aabb.min, n.aabb.max, end(t));
        if entry(root, t_max) == f32::INFINITY {
            return;
        }
        // Uninitialised slots: zeroing 1 KB per query would cost more than the walk's pushes.
        let mut slots = [const { MaybeUninit::uninit() }; TOP_STACK];
        let mut stack = Stack::<(u32, f32)>::new(&mut slots);
        let mut cur = 0;
        loop {
            let node = &nodes[cur];
            if node.prim_count > 0 {
                match visit(self.top.instances[node.first_index as usize], t_max) {
                    Some(t) => t_max = t,
                    None => return,
                }
            } else {
                let left = node.first_index as usize;
                let (tl, tr) = (entry(&nodes[left], t_max), entry(&nodes[left + 1], t_max));
                let (near, t_near, far, t_far) = if tl <= tr {
                    (left, tl, left + 1, tr)
                } else {
                    (left + 1, tr, left, tl)
                };
                if t_near != f32::INFINITY {
                    // At most one entry per level below this one: it fits (`TOP_STACK`).
                    stack.push_if((far as u32, t_far), t_far != f32::INFINITY);
                    cur = near;
                    continue;
                }
            }
            // The nearest pushed node not beyond the closest hit so far.
            loop {
                let Some((n, t)) = stack.pop() else {
                    return;
                };
                if t <= end(t_max) {
                    cur = n as usize;
                    break;
                }
            }
        }
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best = None;
        self.for_candidates(ray, |i, t_max| {
            let inst = &self.instances[i as usize];
            let (local, dt) = inst.to_object(ray, t_max);
            if local.t_max <= local.t_min {
                return Some(t_max);
            }
            let blas = &self.blas[inst.blas as usize];
            match blas.closest(&local) {
                Some((r, h)) if h.t + dt < t_max => {
                    let t = h.t + dt;
                    best = Some(Hit {
                        t,
                        instance: i,
                        prim: r.prim,
                        b1: h.b1,
                        b2: h.b2,
                    });
                    Some(t)
                }
                _ => Some(t_max),
            }
        });
        best
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut hit = false;
        self.for_candidates(ray, |i, t_max| {
            let inst = &self.instances[i as usize];
            let (local, _) = inst.to_object(ray, t_max);
            if local.t_max > local.t_min && self.blas[inst.blas as usize].occluded(&local) {
                hit = true;
                return None;
            }
            Some(t_max)
        });
        hit
    }
}
