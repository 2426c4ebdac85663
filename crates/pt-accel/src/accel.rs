//! One accelerator type over several strategies, chosen automatically or by the caller.

use std::fmt;
use std::time::{Duration, Instant};

use obvhs::BvhBuildParams;

use crate::bounds::Bounds3;
use crate::brute::BruteForce;
use crate::cwbvh::FlatBvh;
use crate::mesh::{Instance, TriangleMesh};
use crate::ray::{Hit, Ray};
use crate::store::TriangleStore;

/// Up to this many valid triangles, [`AccelKind::Auto`] tests every triangle instead of building a
/// BVH: a CWBVH query costs about as much as this many triangle tests.
pub const BRUTE_FORCE_MAX_TRIANGLES: usize = 8;

/// Which acceleration strategy to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum AccelKind {
    /// Pick from the scene: brute force for a handful of triangles, otherwise a BVH.
    #[default]
    Auto,
    /// Test every triangle. Slow for anything but tiny scenes; the reference in tests.
    BruteForce,
    /// One compressed wide BVH over all triangles in world space.
    Bvh,
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Auto => "auto",
            Self::BruteForce => "brute force",
            Self::Bvh => "bvh",
        })
    }
}

/// BVH build effort: faster builds give slower traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum BuildQuality {
    /// Minimal PLOC search, no reinsertion: for scenes rebuilt every frame.
    Fastest,
    /// Short PLOC search with a little reinsertion.
    Fast,
    /// Balanced (the default): about Embree's build time with faster traversal.
    #[default]
    Medium,
    /// Spatial pre-splits of large triangles and more reinsertion: for final renders of big
    /// static scenes.
    High,
}

impl BuildQuality {
    pub(crate) fn params(self) -> BvhBuildParams {
        match self {
            Self::Fastest => BvhBuildParams::fastest_build(),
            Self::Fast => BvhBuildParams::fast_build(),
            Self::Medium => BvhBuildParams::medium_build(),
            Self::High => BvhBuildParams::slow_build(),
        }
    }
}

/// What was built, for summaries and memory accounting.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct AccelStats {
    /// The strategy in use (never `Auto`).
    pub kind: AccelKind,
    /// Triangles over all instances, before validation.
    pub input_triangles: usize,
    /// Triangles skipped because they have zero area or a non-finite vertex.
    pub skipped_triangles: usize,
    /// BVH nodes (0 for brute force).
    pub nodes: usize,
    /// Bytes held by the accelerator (nodes and triangle copies).
    pub memory_bytes: usize,
    /// Wall time of the build.
    pub build_time: Duration,
}

#[derive(Clone, Debug)]
enum Imp {
    Brute(BruteForce),
    Bvh(FlatBvh),
}

/// Answers closest-hit and any-hit queries against a set of mesh instances.
///
/// Build it with [`Accel::build`]; degenerate and non-finite triangles are skipped and counted,
/// and an empty scene answers "no hit" to every query.
#[derive(Clone, Debug)]
pub struct Accel {
    imp: Imp,
    bounds: Bounds3,
    stats: AccelStats,
}

impl Accel {
    /// Build an accelerator over `instances` of `meshes` with the given strategy.
    ///
    /// # Panics
    /// If an instance refers to a mesh index outside `meshes`.
    pub fn build<T: AsRef<TriangleMesh>>(
        meshes: &[T],
        instances: &[Instance],
        kind: AccelKind,
        quality: BuildQuality,
    ) -> Self {
        let start = Instant::now();
        let store = TriangleStore::flatten(meshes, instances);
        let kind = match kind {
            AccelKind::Auto if store.verts.len() <= BRUTE_FORCE_MAX_TRIANGLES => {
                AccelKind::BruteForce
            }
            AccelKind::Auto => AccelKind::Bvh,
            k => k,
        };
        let (input, skipped, bounds) = (store.input, store.skipped, store.bounds);
        let (imp, nodes, memory_bytes) = match kind {
            AccelKind::Bvh => {
                let bvh = FlatBvh::build(store, quality);
                let (n, m) = (bvh.node_count(), bvh.memory_bytes());
                (Imp::Bvh(bvh), n, m)
            }
            _ => {
                let m = store.memory_bytes();
                (Imp::Brute(BruteForce { store }), 0, m)
            }
        };
        Self {
            imp,
            bounds,
            stats: AccelStats {
                kind,
                input_triangles: input,
                skipped_triangles: skipped,
                nodes,
                memory_bytes,
                build_time: start.elapsed(),
            },
        }
    }

    /// The closest hit with `t` in the ray's range, if any.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        match &self.imp {
            Imp::Brute(b) => b.intersect(ray),
            Imp::Bvh(b) => b.intersect(ray),
        }
    }

    /// True when anything is hit with `t` in the ray's range (shadow rays). Stops at the first hit.
    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if !ray.is_valid() {
            return false;
        }
        match &self.imp {
            Imp::Brute(b) => b.occluded(ray),
            Imp::Bvh(b) => b.occluded(ray),
        }
    }

    /// World-space bounds of all valid triangles (empty when there are none).
    #[inline]
    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// What was built.
    #[inline]
    #[must_use]
    pub fn stats(&self) -> &AccelStats {
        &self.stats
    }
}
