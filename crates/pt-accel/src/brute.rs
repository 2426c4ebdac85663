//! Brute force: every ray against every triangle. The reference the BVHs are tested against, and
//! the fastest choice for a handful of triangles.

use crate::ray::{Hit, Ray};
use crate::store::TriangleStore;
use crate::triangle::RayTriangleTest;

/// A flat list of world-space triangles tested one by one.
#[derive(Clone, Debug)]
pub(crate) struct BruteForce {
    pub store: TriangleStore,
}

impl BruteForce {
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let test = RayTriangleTest::new(ray);
        let mut t_max = ray.t_max;
        let mut best = None;
        for (slot, tri) in self.store.verts.iter().enumerate() {
            if let Some(h) = test.intersect(tri, t_max) {
                t_max = h.t;
                best = Some((slot, h));
            }
        }
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
        let test = RayTriangleTest::new(ray);
        self.store
            .verts
            .iter()
            .any(|tri| test.intersect(tri, ray.t_max).is_some())
    }
}
