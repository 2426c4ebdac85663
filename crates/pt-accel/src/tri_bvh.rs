//! A BVH over one set of triangles in either layout, with a fallback for trees too deep for the
//! fixed-size traversal stacks.

use crate::binary::{BinaryBvh, MAX_BINARY_DEPTH};
use crate::brute::BruteForce;
use crate::ray::Ray;
use crate::store::{PrimRef, TriangleStore};
use crate::triangle::TriangleHit;
use crate::wide::{MAX_WIDE_DEPTH, WideBvh};
use crate::{BuildQuality, BvhLayout};

/// One triangle BVH (or, for pathological input, a flat list).
#[derive(Clone, Debug)]
pub(crate) enum TriangleBvh {
    Wide(WideBvh),
    Binary(BinaryBvh),
    Brute(BruteForce),
}

impl TriangleBvh {
    /// Build in the requested layout. If the tree is deeper than that layout's traversal stack
    /// (only degenerate input does this), the other layout is tried, then a flat list, so that no
    /// query can silently lose nodes.
    pub fn build(store: TriangleStore, layout: BvhLayout, quality: BuildQuality) -> Self {
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
            BvhLayout::Wide => wide(store),
            BvhLayout::Binary => binary(store),
        };
        let second = first.or_else(|s| match layout {
            BvhLayout::Wide => binary(s),
            BvhLayout::Binary => wide(s),
        });
        second.unwrap_or_else(|s| {
            log::warn!(
                "BVH deeper than the traversal stacks allow; testing all {} triangles instead",
                s.tris.len()
            );
            Self::Brute(BruteForce::new(s))
        })
    }

    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(usize, TriangleHit)> {
        match self {
            Self::Wide(b) => b.closest(ray),
            Self::Binary(b) => b.closest(ray),
            Self::Brute(b) => b.closest(ray),
        }
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match self {
            Self::Wide(b) => b.occluded(ray),
            Self::Binary(b) => b.occluded(ray),
            Self::Brute(b) => b.occluded(ray),
        }
    }

    #[inline]
    pub fn prim_ref(&self, slot: usize) -> PrimRef {
        self.store().tris[slot].r
    }

    pub fn store(&self) -> &TriangleStore {
        match self {
            Self::Wide(b) => &b.store,
            Self::Binary(b) => &b.store,
            Self::Brute(b) => &b.store,
        }
    }

    pub fn node_count(&self) -> usize {
        match self {
            Self::Wide(b) => b.node_count(),
            Self::Binary(b) => b.node_count(),
            Self::Brute(_) => 0,
        }
    }

    pub fn memory_bytes(&self) -> usize {
        match self {
            Self::Wide(b) => b.memory_bytes(),
            Self::Binary(b) => b.memory_bytes(),
            Self::Brute(b) => b.memory_bytes(),
        }
    }
}
