//! A BVH over one set of triangles in either layout, with a fallback for trees too deep for the
//! fixed-size traversal stacks.

use crate::binary::{BinaryBvh, MAX_BINARY_DEPTH};
use crate::brute::BruteForce;
use crate::bvh4::Bvh4;
use crate::bvh8::Bvh8;
use crate::lanes::{Simd, WIDTH, bits, mask_where};
use crate::ray::{Ray, RayLanes};
use crate::store::{PrimRef, TriangleStore};
use crate::triangle::TriangleHit;
use crate::wide::{MAX_WIDE_DEPTH, WideBvh};
use crate::{BuildQuality, BvhLayout};

/// One triangle BVH (or, for pathological input, a flat list).
#[derive(Clone, Debug)]
pub(crate) enum TriangleBvh {
    Eight(Bvh8),
    Four(Bvh4),
    Wide(WideBvh),
    Binary(BinaryBvh),
    Brute(BruteForce),
}

impl TriangleBvh {
    /// Build in the requested layout. If the tree is deeper than that layout's traversal stack
    /// (only degenerate input does this), the other layouts are tried, then a flat list, so that
    /// no query can silently lose nodes. `lane_queries` as for [`Bvh8::build`].
    pub fn build(
        store: TriangleStore,
        layout: BvhLayout,
        quality: BuildQuality,
        lane_queries: bool,
    ) -> Self {
        let eight = |s: TriangleStore| {
            Bvh8::build(s, quality, lane_queries)
                .map(Self::Eight)
                .map_err(|e| e.0)
        };
        let four = |s: TriangleStore| Bvh4::build(s, quality).map(Self::Four).map_err(|e| e.0);
        let wide = |s: TriangleStore| {
            let b = WideBvh::build(s, quality);
            if b.depth() <= MAX_WIDE_DEPTH {
                Ok(Self::Wide(b))
            } else {
                Err(b.store)
            }
        };
        let binary = |s: TriangleStore| {
            let b = BinaryBvh::build(s, quality);
            if b.depth() <= MAX_BINARY_DEPTH {
                Ok(Self::Binary(b))
            } else {
                Err(b.store)
            }
        };
        let first = match layout {
            BvhLayout::Eight => eight(store),
            BvhLayout::Four => four(store),
            BvhLayout::Wide => wide(store),
            BvhLayout::Binary => binary(store),
        };
        // The binary tree's stack is the deepest, so it comes second whatever was asked for.
        let second = first.or_else(|s| match layout {
            BvhLayout::Binary => wide(s),
            _ => binary(s),
        });
        let third = second.or_else(|s| match layout {
            BvhLayout::Wide => four(s),
            _ => wide(s),
        });
        third.unwrap_or_else(|s| {
            log::warn!(
                "BVH deeper than the traversal stacks allow; testing all {} triangles instead",
                s.tris.len()
            );
            Self::Brute(BruteForce::new(s))
        })
    }

    /// The closest triangle hit in `[t_min, t_max]`: where the triangle came from and the hit.
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(PrimRef, TriangleHit)> {
        let from_store = |(slot, h): (usize, TriangleHit)| (self.store().tris[slot].r, h);
        match self {
            Self::Eight(b) => b.closest(ray),
            Self::Four(b) => b.closest(ray),
            Self::Wide(b) => b.closest(ray).map(from_store),
            Self::Binary(b) => b.closest(ray).map(from_store),
            Self::Brute(b) => b.closest(ray).map(from_store),
        }
    }

    /// [`Self::closest`] for the rays in the lanes set in `mask` (other lanes `None`), from a
    /// caller running with the lanes of `s` (inside [`crate::lanes::dispatch`]): all of them
    /// in one call in the eight-wide BVH, with `s`'s instruction set; one query after another
    /// otherwise.
    #[inline(always)]
    pub fn closest_lanes_in<S: Simd>(
        &self,
        s: S,
        rays: &RayLanes,
        mask: u32,
    ) -> [Option<(PrimRef, TriangleHit)>; WIDTH] {
        if let Self::Eight(b) = self {
            return b.closest_lanes_in(s, rays, mask);
        }
        let mut out = [None; WIDTH];
        let rays = rays.to_rays(s);
        for lane in bits(mask) {
            out[lane] = self.closest(&rays[lane]);
        }
        out
    }

    /// [`Self::occluded`] for the rays in the lanes set in `mask` (bit `i` set when lane `i`'s ray
    /// hits anything), from a caller running with the lanes of `s`, as
    /// [`Self::closest_lanes_in`].
    #[inline(always)]
    pub fn occluded_lanes_in<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32) -> u32 {
        if let Self::Eight(b) = self {
            return b.occluded_lanes_in(s, rays, mask);
        }
        let rays = rays.to_rays(s);
        mask_where(mask, |lane| self.occluded(&rays[lane]))
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match self {
            Self::Eight(b) => b.occluded(ray),
            Self::Four(b) => b.occluded(ray),
            Self::Wide(b) => b.occluded(ray),
            Self::Binary(b) => b.occluded(ray),
            Self::Brute(b) => b.occluded(ray),
        }
    }

    pub fn store(&self) -> &TriangleStore {
        match self {
            Self::Eight(b) => &b.store,
            Self::Four(b) => &b.store,
            Self::Wide(b) => &b.store,
            Self::Binary(b) => &b.store,
            Self::Brute(b) => &b.store,
        }
    }

    pub fn node_count(&self) -> usize {
        match self {
            Self::Eight(b) => b.node_count(),
            Self::Four(b) => b.node_count(),
            Self::Wide(b) => b.node_count(),
            Self::Binary(b) => b.node_count(),
            Self::Brute(_) => 0,
        }
    }

    pub fn memory_bytes(&self) -> usize {
        match self {
            Self::Eight(b) => b.memory_bytes(),
            Self::Four(b) => b.memory_bytes(),
            Self::Wide(b) => b.memory_bytes(),
            Self::Binary(b) => b.memory_bytes(),
            Self::Brute(b) => b.memory_bytes(),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::mesh::TriangleMesh;

    /// Triangles at exponentially growing distances (2^-60 to 2^(n-61)): the binary tree grows
    /// about 0.6 levels per triangle.
    fn chain(n: usize) -> TriangleStore {
        let corners: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let x = 2f32.powi(i as i32 - 60);
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 1.0, 0.0),
                    Vec3::new(x, 0.0, 1.0),
                ]
            })
            .collect();
        TriangleStore::from_mesh(&TriangleMesh::from_triangles(&corners).unwrap())
    }

    /// A tree too deep for the four-wide traversal stack falls back to another layout, and every
    /// layout (including the fallback) finds what brute force finds. PLOC (the fast presets)
    /// builds the chain as deep as it is long; the top-down build bounds its depth.
    #[test]
    fn too_deep_trees_fall_back_and_still_answer_right() {
        let shallow = TriangleBvh::build(chain(30), BvhLayout::Four, BuildQuality::Fast, true);
        assert!(matches!(shallow, TriangleBvh::Four(_)));
        let n = 119;
        let store = chain(n);
        let deep = TriangleBvh::build(store.clone(), BvhLayout::Four, BuildQuality::Fast, true);
        assert!(
            !matches!(deep, TriangleBvh::Four(_)),
            "a {n}-triangle chain must not fit the four-wide stack"
        );
        let brute = TriangleBvh::Brute(BruteForce::new(store.clone()));
        let layouts = [BvhLayout::Four, BvhLayout::Wide, BvhLayout::Binary]
            .map(|l| TriangleBvh::build(store.clone(), l, BuildQuality::Fast, true));
        for i in 0..n as i32 {
            // Along the chain from between two triangles (the next one is hit), the same ray
            // stopped short of it, and a slanted ray onto it.
            let x = 2f32.powi(i - 60);
            for ray in [
                Ray::new(Vec3::new(x * 0.75, 0.25, 0.25), Vec3::X),
                Ray::with_t_max(Vec3::new(x * 0.75, 0.25, 0.25), Vec3::X, x * 0.2),
                Ray::new(
                    Vec3::new(x * 0.75, 0.25, -1.0),
                    Vec3::new(x * 0.25, 0.0, 1.25),
                ),
            ] {
                let want = brute.closest(&ray).map(|(r, h)| (r, h.t));
                for bvh in &layouts {
                    let got = bvh.closest(&ray).map(|(r, h)| (r, h.t));
                    assert_eq!(got, want, "{ray:?}");
                    assert_eq!(bvh.occluded(&ray), want.is_some(), "{ray:?}");
                }
            }
        }
    }
}
