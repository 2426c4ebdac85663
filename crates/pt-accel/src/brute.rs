//! Brute force: every ray against every triangle. The reference the BVHs are tested against, and
//! the fastest choice for a handful of triangles.

use crate::ray::Ray;
use crate::store::TriangleStore;
use crate::triangle::{RayTriangleTest, TriangleHit};

/// A flat list of triangles tested one by one.
#[derive(Clone, Debug)]
pub(crate) struct BruteForce {
    pub store: TriangleStore,
}

impl BruteForce {
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(usize, TriangleHit)> {
        let test = RayTriangleTest::new(ray);
        let mut t_max = ray.t_max;
        let mut best = None;
        for (slot, t) in self.store.tris.iter().enumerate() {
            if let Some(h) = test.intersect_packed(&t.tri, t_max) {
                t_max = h.t;
                best = Some((slot, h));
            }
        }
        best
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let test = RayTriangleTest::new(ray);
        self.store
            .tris
            .iter()
            .any(|t| test.intersect_packed(&t.tri, ray.t_max).is_some())
    }
}
