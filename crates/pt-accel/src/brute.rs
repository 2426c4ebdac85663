//! Brute force: every ray against every triangle, four triangles at a time. The reference the
//! BVHs are tested against, and the fastest choice for a handful of triangles.

use crate::ray::Ray;
use crate::store::TriangleStore;
use crate::triangle::{PackedTriangles4, RayTriangleTest, TriangleHit};

/// A flat list of triangles, tested in packets of four (store slot `4 k + lane` is lane `lane`
/// of packet `k`).
#[derive(Clone, Debug)]
pub(crate) struct BruteForce {
    pub store: TriangleStore,
    packets: Vec<PackedTriangles4>,
}

impl BruteForce {
    /// Test the triangles of `store`.
    pub fn new(store: TriangleStore) -> Self {
        let tris: Vec<_> = store.tris.iter().map(|t| t.tri).collect();
        let packets = tris.chunks(4).map(PackedTriangles4::new).collect();
        Self { store, packets }
    }

    /// Bytes held (the store and the packets).
    pub fn memory_bytes(&self) -> usize {
        self.store.memory_bytes() + self.packets.capacity() * size_of::<PackedTriangles4>()
    }

    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(usize, TriangleHit)> {
        let test = RayTriangleTest::new(ray);
        let mut t_max = ray.t_max;
        let mut best = None;
        for (k, packet) in self.packets.iter().enumerate() {
            // Of triangles at the same distance the first wins.
            let bound = crate::triangle::tie_bound(ray.t_max, t_max);
            if let Some((lane, h)) = test.closest4_bounded(packet, bound, t_max)
                && (h.t < t_max || best.is_none())
            {
                t_max = h.t;
                best = Some((4 * k + lane, h));
            }
        }
        best
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let test = RayTriangleTest::new(ray);
        self.packets.iter().any(|p| test.any4(p, ray.t_max))
    }
}
