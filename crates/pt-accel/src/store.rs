//! World-space triangle lists shared by the flat accelerators.

use glam::{Vec3, Vec3A};

use crate::triangle::PackedTriangle;

use crate::bounds::Bounds3;
use crate::mesh::{Instance, TriangleMesh, is_valid_triangle};

/// Where a stored triangle came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PrimRef {
    pub instance: u32,
    pub prim: u32,
}

/// A triangle with its origin, in one cache line: a hit needs the id right after the
/// coordinates, and a separate array would cost a cache miss per ray.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct StoredTriangle {
    pub tri: PackedTriangle,
    pub r: PrimRef,
}

/// Valid triangles of all instances, baked into world space, with their origin.
#[derive(Clone, Debug, Default)]
pub(crate) struct TriangleStore {
    pub tris: Vec<StoredTriangle>,
    pub bounds: Bounds3,
    /// Triangles left out because they are degenerate or not finite.
    pub skipped: usize,
    /// Triangles looked at (valid or not).
    pub input: usize,
}

impl TriangleStore {
    /// Bake every instance's valid triangles into world space.
    pub fn flatten<T: AsRef<TriangleMesh>>(meshes: &[T], instances: &[Instance]) -> Self {
        let mut store = Self::default();
        let total: usize = instances
            .iter()
            .map(|inst| meshes[inst.mesh as usize].as_ref().triangle_count())
            .sum();
        store.tris.reserve(total);
        let mut world: Vec<Vec3> = Vec::new();
        for (instance, inst) in instances.iter().enumerate() {
            let mesh = meshes[inst.mesh as usize].as_ref();
            // Transform each vertex once so that shared vertices stay bit-identical, which the
            // watertight test relies on.
            world.clear();
            world.extend(
                mesh.positions()
                    .iter()
                    .map(|&p| inst.transform.transform_point3(p)),
            );
            for (prim, idx) in mesh.indices().iter().enumerate() {
                store.input += 1;
                let p = idx.map(|i| world[i as usize]);
                if !is_valid_triangle(&p) {
                    store.skipped += 1;
                    continue;
                }
                store.bounds = store.bounds.union(Bounds3::from_points(p));
                store.tris.push(StoredTriangle {
                    tri: PackedTriangle::new(&p.map(Vec3A::from)),
                    r: PrimRef {
                        instance: instance as u32,
                        prim: prim as u32,
                    },
                });
            }
        }
        store
    }

    /// The valid triangles of one mesh in its own (object) space; `instance` is 0 in every
    /// reference.
    pub fn from_mesh(mesh: &TriangleMesh) -> Self {
        Self::flatten(&[mesh], &[Instance::new(0)])
    }

    /// The store with its triangles listed in `order` (a BVH's primitive order; with spatial
    /// splits an index may appear more than once).
    pub fn reordered(self, order: &[u32]) -> Self {
        Self {
            tris: order.iter().map(|&i| self.tris[i as usize]).collect(),
            ..self
        }
    }

    /// The triangles as obvhs' builders take them (a temporary copy for a build).
    pub(crate) fn obvhs_triangles(&self) -> Vec<obvhs::triangle::Triangle> {
        self.tris
            .iter()
            .map(|t| {
                let [v0, v1, v2] = t.tri.corners();
                obvhs::triangle::Triangle { v0, v1, v2 }
            })
            .collect()
    }

    /// Bytes held by this store.
    pub fn memory_bytes(&self) -> usize {
        self.tris.capacity() * std::mem::size_of::<StoredTriangle>()
    }
}
