//! Geometry and ray queries for the `pt` path tracer.
//!
//! `pt-accel` knows nothing of light or materials: it takes triangle meshes and instances of them,
//! builds an accelerator, and answers two queries, the closest hit along a ray and whether anything
//! blocks a ray segment. It can serve any ray-casting program.
//!
//! - [`Ray`] and [`Hit`]: plain data.
//! - [`TriangleMesh`] and [`Instance`]: indexed triangles and their placements.
//! - [`Accel`]: brute force, one BVH over world-space triangles, or a two-level BVH (one BVH per
//!   distinct mesh, a top-level BVH over instances, no geometry copied), chosen by [`AccelKind`]
//!   or automatically. BVHs are built with [obvhs](https://docs.rs/obvhs) and kept as eight-wide
//!   nodes with packets of four triangles (the default on CPUs with AVX2, kernels chosen at run
//!   time), four-wide nodes, obvhs' compressed 8-wide nodes or binary nodes ([`BvhLayout`]),
//!   always traversed with pt's own conservative node test. No obvhs type
//!   appears in this crate's API.
//! - [`triangle`]: the watertight ray-triangle test (Woop, Benthin, Wald 2013) every accelerator
//!   uses, so no ray slips between triangles that share an edge.
//! - [`float`]: floating-point error bounds used for robust ray offsets.
//! - [`lanes`]: eight lanes of `f32`/`u32` with the instruction set chosen at run time, for
//!   code that works on eight rays or paths at once.
//!
//! Degenerate (zero-area) and non-finite triangles are skipped at build time and counted in
//! [`AccelStats`]; an empty scene answers "no hit".
//!
//! # Example
//!
//! ```
//! use pt_accel::{Accel, AccelKind, AccelOptions, Instance, Ray, TriangleMesh};
//! use pt_accel::glam::Vec3;
//!
//! // A unit quad in the z = 0 plane, made of two triangles.
//! let mesh = TriangleMesh::new(
//!     vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0),
//!          Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! )?;
//! let accel = Accel::build(&[mesh], &[Instance::new(0)], &AccelOptions::new().kind(AccelKind::Bvh));
//!
//! let ray = Ray::new(Vec3::new(0.25, 0.75, 1.0), Vec3::new(0.0, 0.0, -1.0));
//! let hit = accel.intersect(&ray).expect("the ray points at the quad");
//! assert_eq!(hit.prim, 1);
//! assert!((hit.t - 1.0).abs() < 1e-6);
//! assert!(!accel.occluded(&Ray::with_t_max(ray.origin, ray.dir, 0.5)));
//! # Ok::<(), pt_accel::MeshError>(())
//! ```
//!
//! # Features
//!
//! - `parallel` (default): build BVHs on the rayon thread pool.

pub use glam;

mod accel;
mod binary;
mod bounds;
mod brute;
mod build;
mod bvh4;
mod bvh8;
pub mod float;
pub mod lanes;
mod mesh;
mod node_ray;
mod ray;
#[allow(unsafe_code)]
mod simd;
#[allow(unsafe_code)]
mod stack;
mod store;
#[cfg(test)]
mod test_rng;
mod tri_bvh;
pub mod triangle;
mod two_level;
mod wide;

pub use accel::{
    Accel, AccelKind, AccelOptions, AccelStats, BRUTE_FORCE_MAX_TRIANGLES, BuildQuality, BvhLayout,
    FLATTEN_MAX_COPIES,
};
pub use bounds::Bounds3;
pub use mesh::{
    Instance, MAX_COORDINATE, MeshError, TriangleMesh, is_valid_triangle, triangle_cross,
    triangle_normal,
};
pub use ray::{Hit, Ray, RayLanes};

impl AsRef<TriangleMesh> for TriangleMesh {
    fn as_ref(&self) -> &TriangleMesh {
        self
    }
}
