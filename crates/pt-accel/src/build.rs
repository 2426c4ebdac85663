//! BVH2 construction: a top-down binned-SAH builder, and obvhs' builders guarded against
//! degenerate input.
//!
//! The medium and high presets build top-down by binned SAH ([`build_sah`]); on the meshes
//! measured its trees trace faster than obvhs' PLOC trees (docs/performance-log.md, "A binned SAH
//! build"). The faster presets keep obvhs' PLOC, whose passes run on all threads.
//!
//! obvhs builds by PLOC: primitives sorted by Morton code are merged with their nearest
//! neighbour in the sorted order, pairs that choose each other merging in each pass. When the
//! merge costs of neighbouring pairs are equal (coincident triangles, identical instances) or
//! change monotonically along the order (the slivers of a fan around one vertex, the triangles
//! of one huge polygon), almost no pair chooses each other, each pass merges one pair, and the
//! build takes quadratic time: 10,000 copies of one triangle took 17 s, a fan of 60,000 32 s.
//!
//! So for the PLOC presets the first pass is simulated here, in linear time after the sort:
//! when fewer than one primitive in [`MIN_MERGE_FRACTION`] would merge, the tree is built
//! top-down instead, then its leaves collapsed like a PLOC tree's. Ordinary meshes merge about a
//! third of their primitives in PLOC's first pass and keep obvhs' trees.

use std::time::Duration;

use glam::{Vec3, Vec3A};

use crate::BuildQuality;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::leaf_collapser::collapse;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::triangle::Triangle;

/// A merge pass that merges fewer than one node in this many means the build would degenerate
/// (ordinary meshes: about one in three).
pub(crate) const MIN_MERGE_FRACTION: usize = 16;

/// Below this many primitives PLOC cannot take long, whatever the input.
const SMALL: usize = 2048;

/// Whether PLOC's first pass over these boxes would merge too few pairs (see the module docs).
pub(crate) fn ploc_would_degenerate(boxes: &[Aabb], params: &BvhBuildParams) -> bool {
    use obvhs::ploc::PlocSearchDistance as D;
    let radius = match params.ploc_search_distance {
        D::Minimum => 1,
        D::VeryLow => 2,
        D::Low => 6,
        D::Medium => 14,
        D::High => 24,
        D::VeryHigh => 32,
    };
    let threshold = params.search_depth_threshold;
    let n = boxes.len();
    if n < SMALL {
        return false;
    }
    let mut bounds = Aabb::empty();
    for b in boxes {
        bounds.extend(b.center());
    }
    let scale = (bounds.max - bounds.min)
        .max(Vec3A::splat(f32::MIN_POSITIVE))
        .recip();
    let spread = |v: f32| -> u64 {
        let mut x = ((v.clamp(0.0, 1.0) * 2_097_151.0) as u64) & 0x1f_ffff;
        x = (x | (x << 32)) & 0x1f_0000_0000_ffff;
        x = (x | (x << 16)) & 0x1f_0000_ff00_00ff;
        x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
        x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
        (x | (x << 2)) & 0x1249_2492_4924_9249
    };
    let mut order: Vec<(u64, u32)> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let c = (b.center() - bounds.min) * scale;
            (spread(c.x) | spread(c.y) << 1 | spread(c.z) << 2, i as u32)
        })
        .collect();
    order.sort_unstable();
    // PLOC's passes, on the sorted boxes, with obvhs' rules: for the first `threshold` passes a
    // node prefers its right neighbour unless the pair on its left is cheaper; later, the
    // neighbour within `radius` whose union with it has the least area (ties: the last). Pairs
    // that prefer each other merge. Healthy input merges about a third of its nodes per pass
    // and shrinks geometrically, so this costs O(n radius); a pass that merges too few means
    // PLOC would crawl.
    let mut nodes: Vec<Aabb> = order.iter().map(|&(_, i)| boxes[i as usize]).collect();
    let mut next = Vec::with_capacity(nodes.len());
    let mut best = vec![0usize; nodes.len()];
    let mut depth = 0;
    while nodes.len() >= SMALL {
        let count = nodes.len();
        let area = |a: usize, b: usize| nodes[a].union(&nodes[b]).half_area();
        if radius == 1 || depth < threshold {
            let mut last = f32::INFINITY;
            for i in 0..count - 1 {
                let cost = area(i, i + 1);
                best[i] = if last < cost { i - 1 } else { i + 1 };
                last = cost;
            }
            best[count - 1] = count - 2;
        } else {
            for i in 0..count {
                let (mut b, mut b_cost) = (i, f32::INFINITY);
                for j in i.saturating_sub(radius)..(i + radius + 1).min(count) {
                    if j != i {
                        let c = area(i, j);
                        if c <= b_cost {
                            (b, b_cost) = (j, c);
                        }
                    }
                }
                best[i] = b;
            }
        }
        next.clear();
        let mut merges = 0usize;
        for i in 0..count {
            let b = best[i];
            if best[b] != i {
                next.push(nodes[i]);
            } else if b < i {
                next.push(nodes[i].union(&nodes[b]));
                merges += 1;
            }
        }
        if merges * MIN_MERGE_FRACTION < count {
            return true;
        }
        std::mem::swap(&mut nodes, &mut next);
        depth += 1;
    }
    false
}

/// Bins per axis of the top-down SAH build (Embree's binned builder uses 32 as well).
const SAH_BINS: usize = 32;

/// Below this depth the top-down build splits where the surface-area heuristic says; deeper, at
/// the median centroid of the widest axis, so that no input (centroids spaced geometrically, say)
/// makes the tree deeper than this plus `log2(n)`.
pub(crate) const SAH_MAX_DEPTH: u32 = 48;

/// Subtrees of more primitives than this are built on two threads (feature `parallel`).
#[cfg(feature = "parallel")]
const PARALLEL_MIN: usize = 8192;

/// A primitive's box and its index in the input, as the top-down build reorders them.
#[derive(Clone, Copy)]
struct Prim {
    lo: Vec3,
    index: u32,
    hi: Vec3,
}

impl Prim {
    #[inline(always)]
    fn aabb(&self) -> Aabb {
        Aabb::new(self.lo.into(), self.hi.into())
    }

    /// Twice the centroid (the halving cancels out of every comparison and bin).
    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        Vec3A::from(self.lo) + Vec3A::from(self.hi)
    }
}

/// A BVH2 over `boxes` with one primitive per leaf, built top-down by binned SAH: at each node,
/// [`SAH_BINS`] bins of the centroids along each axis whose centroids spread, and the boundary
/// of least `area(left) count(left) + area(right) count(right)` over the three axes (Wald,
/// "On fast construction of SAH-based bounding volume hierarchies", 2007), or, where it costs
/// less, the node's large primitives apart from its small ones ([`LARGE_FRACTIONS`]).
/// Coincident centroids split in the middle of the range, and splits below [`SAH_MAX_DEPTH`] at
/// the median.
///
/// On the bunny and the 202k-triangle dragon this tree, collapsed to eight-wide nodes, traces
/// incoherent closest-hit rays 7-14% faster than obvhs' PLOC tree at its medium preset, and
/// builds in the same time or less (docs/performance-log.md, "A binned SAH build").
///
/// Every subtree of `m` primitives owns `2 m - 1` consecutive nodes, so the two halves of a
/// split are built independently (on two threads for large ones) and the tree is the same
/// whatever the thread count.
pub(crate) fn build_sah(boxes: &[Aabb]) -> Bvh2 {
    build_sah_to(boxes, SAH_MAX_DEPTH)
}

/// [`build_sah`] with SAH splits down to depth `sah_depth` (tests lower it).
fn build_sah_to(boxes: &[Aabb], sah_depth: u32) -> Bvh2 {
    let n = boxes.len();
    if n == 0 {
        return Bvh2::default();
    }
    let mut prims: Vec<Prim> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| Prim {
            lo: b.min.into(),
            index: i as u32,
            hi: b.max.into(),
        })
        .collect();
    let mut nodes = vec![Bvh2Node::default(); 2 * n - 1];
    let (root, rest) = nodes.split_at_mut(1);
    sah_subtree(&mut root[0], rest, 1, &mut prims, 0, sah_depth);
    Bvh2 {
        nodes,
        primitive_indices: prims.iter().map(|p| p.index).collect(),
        ..Bvh2::default()
    }
}

/// Build the subtree of `prims` (the first is primitive `first` of the final order) into `node`
/// and its descendants `below`, whose first is node `below_index` of the tree; SAH splits for
/// `sah_levels` more levels, median splits below.
fn sah_subtree(
    node: &mut Bvh2Node,
    below: &mut [Bvh2Node],
    below_index: usize,
    prims: &mut [Prim],
    first: usize,
    sah_levels: u32,
) {
    let mut aabb = Aabb::empty();
    let mut centroids = Aabb::empty();
    let mut largest = 0.0f32;
    for p in prims.iter() {
        let b = p.aabb();
        aabb = aabb.union(&b);
        centroids.extend(p.centroid2());
        largest = largest.max(b.half_area());
    }
    if prims.len() == 1 {
        *node = Bvh2Node {
            aabb,
            prim_count: 1,
            first_index: first as u32,
            ..Bvh2Node::default()
        };
        return;
    }
    *node = Bvh2Node {
        aabb,
        prim_count: 0,
        first_index: below_index as u32,
        ..Bvh2Node::default()
    };
    #[cfg(feature = "parallel")]
    let count = prims.len();
    let large = largest >= aabb.half_area() * LARGE_FRACTIONS[2];
    let mid = sah_partition(prims, &aabb, &centroids, large, sah_levels == 0);
    // The two children, then the left subtree's `2 mid - 2` descendants, then the right's.
    let (children, rest) = below.split_at_mut(2);
    let (left, right) = children.split_at_mut(1);
    let (left_below, right_below) = rest.split_at_mut(2 * mid - 2);
    let (left_prims, right_prims) = prims.split_at_mut(mid);
    let mut build_left = move || {
        sah_subtree(
            &mut left[0],
            left_below,
            below_index + 2,
            left_prims,
            first,
            sah_levels.saturating_sub(1),
        );
    };
    let mut build_right = move || {
        sah_subtree(
            &mut right[0],
            right_below,
            below_index + 2 * mid,
            right_prims,
            first + mid,
            sah_levels.saturating_sub(1),
        );
    };
    #[cfg(feature = "parallel")]
    if count > PARALLEL_MIN {
        rayon::join(build_left, build_right);
        return;
    }
    build_left();
    build_right();
}

/// Reorder `prims` (whose union is `aabb`) into the two halves of the split and return the size
/// of the first, which is at least 1 and less than `prims.len()`: at the median with `median`,
/// else the split of least SAH cost among the centroid bins' and, with `large` (some primitive's
/// box is large against the node's), the large primitives' (see [`LARGE_FRACTIONS`]).
///
/// Not inlined: its bins (about 4 KB) stay out of the recursion's frames, which number up to
/// `SAH_MAX_DEPTH + log2(n)` on the calling thread's stack.
#[inline(never)]
fn sah_partition(
    prims: &mut [Prim],
    aabb: &Aabb,
    centroids: &Aabb,
    large: bool,
    median: bool,
) -> usize {
    let m = prims.len();
    let extent = centroids.max - centroids.min;
    let widest = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let spread = extent[widest] > 0.0;
    if !spread {
        // Every centroid the same: large boxes apart from small ones, else any split.
        if large && let Some((limit, _)) = large_split(prims, aabb.half_area()) {
            return partition(prims, |p| p.aabb().half_area() >= limit);
        }
        return m / 2;
    }
    if median {
        prims.select_nth_unstable_by(m / 2, |a, b| {
            a.centroid2()[widest].total_cmp(&b.centroid2()[widest])
        });
        return m / 2;
    }
    let lo = centroids.min;
    // Bin scale per axis; 0 for axes whose centroids coincide (they are skipped).
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(SAH_BINS as f32) / extent,
        Vec3A::ZERO,
    );
    let bin =
        |c: Vec3A, axis: usize| (((c[axis] - lo[axis]) * scale[axis]) as usize).min(SAH_BINS - 1);
    let mut counts = [[0u32; SAH_BINS]; 3];
    let mut boxes = [[Aabb::empty(); SAH_BINS]; 3];
    for p in prims.iter() {
        let (c, b) = (p.centroid2(), p.aabb());
        for axis in 0..3 {
            let k = bin(c, axis);
            counts[axis][k] += 1;
            boxes[axis][k] = boxes[axis][k].union(&b);
        }
    }
    let (mut best_axis, mut best_bin, mut best_cost) = (widest, 0, f32::INFINITY);
    for axis in 0..3 {
        if scale[axis] == 0.0 {
            continue;
        }
        // Sweep from the right for the right sides' areas and counts, then from the left.
        let mut right_area = [0.0f32; SAH_BINS];
        let mut right_count = [0u32; SAH_BINS];
        let (mut acc, mut count) = (Aabb::empty(), 0);
        for k in (1..SAH_BINS).rev() {
            acc = acc.union(&boxes[axis][k]);
            count += counts[axis][k];
            right_area[k] = acc.half_area();
            right_count[k] = count;
        }
        let (mut acc, mut count) = (Aabb::empty(), 0);
        for k in 1..SAH_BINS {
            acc = acc.union(&boxes[axis][k - 1]);
            count += counts[axis][k - 1];
            if count == 0 || right_count[k] == 0 {
                continue;
            }
            let cost = acc.half_area() * count as f32 + right_area[k] * right_count[k] as f32;
            if cost < best_cost {
                (best_axis, best_bin, best_cost) = (axis, k, cost);
            }
        }
    }
    if large
        && let Some((limit, cost)) = large_split(prims, aabb.half_area())
        && cost < best_cost
    {
        return partition(prims, |p| p.aabb().half_area() >= limit);
    }
    if best_bin == 0 {
        return m / 2;
    }
    partition(prims, |p| bin(p.centroid2(), best_axis) < best_bin)
}

/// Split candidates that set a node's large primitives apart: those whose box has at least
/// these fractions of the node's surface area. Binning by centroid mixes such a primitive (a
/// wall, a floor) with the small ones whose centroids lie near its own, and every node above
/// them down to where it is split off then has about the large one's box: a bunny on the floor
/// of a box gave nodes as big as the room all the way down. (PLOC merges such primitives last,
/// near the root, and had no such problem; spatial splits are the other cure.)
const LARGE_FRACTIONS: [f32; 3] = [0.5, 0.125, 1.0 / 32.0];

/// The best of the splits into the primitives whose box's half area is at least `fraction x
/// area` (one of [`LARGE_FRACTIONS`]) and the others: the half-area limit and the SAH cost, or
/// `None` when every such split leaves a side empty.
fn large_split(prims: &[Prim], area: f32) -> Option<(f32, f32)> {
    let limits = LARGE_FRACTIONS.map(|f| f * area);
    // Buckets: at least the first limit, at least the second, at least the third, the rest.
    let mut boxes = [Aabb::empty(); 4];
    let mut counts = [0u32; 4];
    for p in prims {
        let b = p.aabb();
        let a = b.half_area();
        let k = limits.iter().take_while(|&&l| a < l).count();
        boxes[k] = boxes[k].union(&b);
        counts[k] += 1;
    }
    let mut best = None;
    for k in 0..3 {
        let (mut big, mut small) = (Aabb::empty(), Aabb::empty());
        let (mut n_big, mut n_small) = (0, 0);
        for j in 0..4 {
            if j <= k {
                big = big.union(&boxes[j]);
                n_big += counts[j];
            } else {
                small = small.union(&boxes[j]);
                n_small += counts[j];
            }
        }
        if n_big == 0 || n_small == 0 {
            continue;
        }
        let cost = big.half_area() * n_big as f32 + small.half_area() * n_small as f32;
        if best.is_none_or(|(_, c)| cost < c) {
            best = Some((limits[k], cost));
        }
    }
    best
}

/// Move the primitives for which `first` holds to the front; return how many, or half of them
/// when that leaves a side empty.
fn partition(prims: &mut [Prim], first: impl Fn(&Prim) -> bool) -> usize {
    let m = prims.len();
    let mut l = 0;
    for j in 0..m {
        if first(&prims[j]) {
            prims.swap(l, j);
            l += 1;
        }
    }
    if l == 0 || l == m { m / 2 } else { l }
}

/// A BVH2 over triangles for `quality` (with `params`, its obvhs parameters as the caller
/// adjusted them): the top-down SAH build for [`BuildQuality::Medium`] and
/// [`BuildQuality::High`] (High then refines it by obvhs' reinsertion), obvhs' PLOC for the
/// faster presets unless the input would make PLOC degenerate; leaves collapsed by obvhs.
pub(crate) fn bvh2_from_tris(
    tris: &[Triangle],
    quality: BuildQuality,
    params: BvhBuildParams,
) -> Bvh2 {
    let boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
    if quality.top_down() || ploc_would_degenerate(&boxes, &params) {
        return collapsed(top_down(&boxes, quality, &params), &params);
    }
    drop(boxes);
    obvhs::bvh2::builder::build_bvh2_from_tris(tris, params, &mut Duration::default())
}

/// The top-down SAH tree over `boxes`, refined by obvhs' reinsertion at
/// [`BuildQuality::High`] unless the input is of the kind that makes PLOC degenerate (there
/// reinsertion took 91% of a 32 s build: docs/performance-log.md, "Degenerate geometry").
fn top_down(boxes: &[Aabb], quality: BuildQuality, params: &BvhBuildParams) -> Bvh2 {
    let mut bvh = build_sah(boxes);
    if quality == BuildQuality::High && !ploc_would_degenerate(boxes, params) {
        ReinsertionOptimizer::default().run(&mut bvh, params.reinsertion_batch_ratio, None);
    }
    bvh
}

/// `bvh` with its leaves merged as `params` ask (obvhs' collapse; nothing for one per leaf).
fn collapsed(mut bvh: Bvh2, params: &BvhBuildParams) -> Bvh2 {
    collapse(
        &mut bvh,
        params.max_prims_per_leaf.clamp(1, 255),
        params.collapse_traversal_cost,
    );
    bvh
}

/// A CWBVH over boxes (triangles' or instances'): the top-down build converted as obvhs
/// converts for [`BuildQuality::Medium`] and [`BuildQuality::High`] and for input that would
/// make PLOC degenerate, else obvhs' builder.
pub(crate) fn cwbvh_from_boxes(
    boxes: &[Aabb],
    quality: BuildQuality,
    build: impl FnOnce() -> obvhs::cwbvh::CwBvh,
) -> obvhs::cwbvh::CwBvh {
    let params = quality.params();
    if quality.top_down() || ploc_would_degenerate(boxes, &params) {
        return obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
            &top_down(boxes, quality, &params),
            params.max_prims_per_leaf.clamp(1, 3),
            true,
            false,
        );
    }
    build()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle {
            v0: a.into(),
            v1: b.into(),
            v2: c.into(),
        }
    }

    fn fan(n: usize) -> Vec<Triangle> {
        (0..n)
            .map(|i| {
                let (a, b) = (
                    i as f32 / n as f32 * std::f32::consts::TAU,
                    (i + 1) as f32 / n as f32 * std::f32::consts::TAU,
                );
                tri([0.0; 3], [a.cos(), a.sin(), 0.0], [b.cos(), b.sin(), 0.0])
            })
            .collect()
    }

    #[test]
    fn degenerate_inputs_are_detected_and_ordinary_ones_are_not() {
        let boxes = |t: &[Triangle]| t.iter().map(Triangle::aabb).collect::<Vec<_>>();
        let p = BvhBuildParams::medium_build();
        let ploc_would_degenerate = |b: &[Aabb]| ploc_would_degenerate(b, &p);
        let same = vec![tri([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]); 10_000];
        assert!(ploc_would_degenerate(&boxes(&same)));
        assert!(ploc_would_degenerate(&boxes(&fan(30_000))));
        // One polygon of 100,000 corners triangulated as a fan from a corner.
        let polygon: Vec<Triangle> = (0..100_000)
            .map(|i| {
                let (a, b) = (
                    (i + 1) as f32 * (std::f32::consts::TAU / 100_000.0),
                    (i + 2) as f32 * (std::f32::consts::TAU / 100_000.0),
                );
                tri(
                    [1.0, 0.0, 0.0],
                    [a.cos(), a.sin(), 0.0],
                    [b.cos(), b.sin(), 0.0],
                )
            })
            .collect();
        assert!(ploc_would_degenerate(&boxes(&polygon)));
        // A grid of small triangles (an ordinary mesh).
        let grid: Vec<Triangle> = (0..10_000)
            .map(|i| {
                let (x, y) = ((i % 100) as f32, (i / 100) as f32);
                tri([x, y, 0.0], [x + 1.0, y, 0.0], [x, y + 1.0, 0.0])
            })
            .collect();
        assert!(!ploc_would_degenerate(&boxes(&grid)));
    }

    /// Check that `bvh` holds every one of `boxes` once, in a leaf of one primitive, each node's
    /// box the union of its children's; return the depth (the root alone is 0).
    fn check_tree(bvh: &Bvh2, boxes: &[Aabb]) -> usize {
        assert_eq!(bvh.nodes.len(), 2 * boxes.len() - 1);
        let mut seen = vec![false; boxes.len()];
        let mut stack = vec![(0usize, 0usize)];
        let mut depth = 0;
        while let Some((i, d)) = stack.pop() {
            depth = depth.max(d);
            let node = &bvh.nodes[i];
            if node.prim_count > 0 {
                assert_eq!(node.prim_count, 1);
                let p = bvh.primitive_indices[node.first_index as usize] as usize;
                assert!(!seen[p]);
                seen[p] = true;
                assert_eq!((node.aabb.min, node.aabb.max), (boxes[p].min, boxes[p].max));
            } else {
                let c = node.first_index as usize;
                let union = bvh.nodes[c].aabb.union(&bvh.nodes[c + 1].aabb);
                assert_eq!((node.aabb.min, node.aabb.max), (union.min, union.max));
                stack.extend([(c, d + 1), (c + 1, d + 1)]);
            }
        }
        assert!(seen.iter().all(|&s| s));
        depth
    }

    #[test]
    fn top_down_trees_hold_every_primitive_once_in_bounding_nodes() {
        for tris in [
            fan(5_000),
            vec![tri([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]); 3_000],
        ] {
            let boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
            let depth = check_tree(&build_sah(&boxes), &boxes);
            assert!(depth < 64, "depth {depth}");
        }
    }

    /// Below the depth where SAH splits stop, splits are at the median, so the depth is bounded
    /// whatever the input: with none at all, a tree of `n` primitives is `ceil(log2 n)` deep,
    /// where SAH splits of centroids spaced geometrically (each cutting off a few primitives)
    /// make it deeper.
    #[test]
    fn top_down_depth_is_bounded() {
        let n = 120;
        let boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let x = 1.5f32.powi(i - 60);
                Aabb::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x * 1.01, 1.0, 1.0))
            })
            .collect();
        let sah = check_tree(&build_sah(&boxes), &boxes);
        assert!(sah > 8, "SAH depth {sah}");
        let median = check_tree(&build_sah_to(&boxes, 0), &boxes);
        assert_eq!(median, 7);
        let capped = check_tree(&build_sah_to(&boxes, 3), &boxes);
        assert!(capped <= 3 + 7, "depth {capped}");
    }

    /// The split is chosen over all three axes: two clusters apart along y, each wider along x
    /// than the gap between them, are the root's two children.
    #[test]
    fn top_down_splits_along_the_best_axis() {
        let boxes: Vec<Aabb> = (0..200)
            .map(|i| {
                let (x, y) = ((i % 100) as f32, if i < 100 { 0.0 } else { 10.0 });
                Aabb::new(Vec3A::new(x, y, 0.0), Vec3A::new(x + 0.5, y + 0.5, 0.5))
            })
            .collect();
        let bvh = build_sah(&boxes);
        check_tree(&bvh, &boxes);
        let c = bvh.nodes[0].first_index as usize;
        for child in [&bvh.nodes[c], &bvh.nodes[c + 1]] {
            assert_eq!(child.aabb.max.y - child.aabb.min.y, 0.5, "{child:?}");
        }
    }

    /// Large primitives are set apart from small ones whose centroids lie among theirs: the
    /// six faces of a room (two triangles' boxes each, as a floor or a wall) around a cloud of
    /// small boxes in its middle, low down as a bunny on the floor, are one child of the root
    /// and the cloud the other.
    #[test]
    fn top_down_sets_large_primitives_apart() {
        let mut boxes = Vec::new();
        for axis in 0..3 {
            for side in [0.0, 10.0] {
                let (mut lo, mut hi) = (Vec3A::ZERO, Vec3A::splat(10.0));
                lo[axis] = side;
                hi[axis] = side;
                boxes.extend([Aabb::new(lo, hi), Aabb::new(lo, hi)]);
            }
        }
        for i in 0..1000 {
            let p = Vec3A::new((i % 10) as f32, ((i / 10) % 10) as f32, (i / 100) as f32);
            let lo = Vec3A::new(3.0, 0.0, 3.0) + p * 0.4;
            boxes.push(Aabb::new(lo, lo + 0.3));
        }
        let bvh = build_sah(&boxes);
        check_tree(&bvh, &boxes);
        let c = bvh.nodes[0].first_index as usize;
        let small = [&bvh.nodes[c], &bvh.nodes[c + 1]]
            .into_iter()
            .filter(|n| n.aabb.max.x - n.aabb.min.x < 5.0)
            .count();
        assert_eq!(small, 1, "{:?}", &bvh.nodes[c..c + 2]);
    }

    /// The tree does not depend on how many threads build it.
    #[test]
    fn top_down_trees_are_the_same_on_any_thread_count() {
        let boxes: Vec<Aabb> = (0..40_000)
            .map(|i| {
                let (x, y, z) = ((i % 40) as f32, ((i / 40) % 40) as f32, (i / 1600) as f32);
                let w = 0.1 + ((i * 7919) % 13) as f32 * 0.1;
                Aabb::new(Vec3A::new(x, y, z), Vec3A::new(x + w, y + 0.3, z + w * 0.5))
            })
            .collect();
        let build = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            pool.install(|| build_sah(&boxes))
        };
        let (one, two) = (build(1), build(2));
        check_tree(&one, &boxes);
        assert_eq!(one.primitive_indices, two.primitive_indices);
        for (a, b) in one.nodes.iter().zip(&two.nodes) {
            assert_eq!(
                (a.aabb.min, a.aabb.max, a.first_index, a.prim_count),
                (b.aabb.min, b.aabb.max, b.first_index, b.prim_count)
            );
        }
    }
}
