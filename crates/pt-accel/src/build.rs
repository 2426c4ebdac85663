//! BVH2 construction robust to degenerate input, around obvhs' builders.
//!
//! obvhs builds by PLOC: primitives sorted by Morton code are merged with their nearest
//! neighbour in the sorted order, pairs that choose each other merging in each pass. When the
//! merge costs of neighbouring pairs are equal (coincident triangles, identical instances) or
//! change monotonically along the order (the slivers of a fan around one vertex, the triangles
//! of one huge polygon), almost no pair chooses each other, each pass merges one pair, and the
//! build takes quadratic time: 10,000 copies of one triangle took 17 s, a fan of 60,000 32 s.
//!
//! So the first pass is simulated here, in linear time after the sort: when fewer than one
//! primitive in [`MIN_MERGE_FRACTION`] would merge, the tree is built top-down instead, by
//! binned SAH over the centroids (falling back to an even split of the primitives when their
//! centroids coincide), then refined by obvhs' reinsertion and leaf collapse like a PLOC tree.
//! Ordinary meshes merge about a third of their primitives in PLOC's first pass and keep
//! obvhs' trees unchanged.

use std::time::Duration;

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::leaf_collapser::collapse;
use obvhs::bvh2::node::Bvh2Node;
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

/// A BVH2 over `boxes` with one primitive per leaf, built top-down by binned SAH on the
/// centroids (16 bins along the widest centroid axis; an even split when the centroids
/// coincide or no split is better). Iterative: no recursion depth to worry about.
pub(crate) fn build_top_down(boxes: &[Aabb]) -> Bvh2 {
    const BINS: usize = 16;
    let n = boxes.len();
    let mut indices: Vec<u32> = (0..n as u32).collect();
    let mut nodes = vec![Bvh2Node::default(); 2 * n - 1];
    let mut next = 1usize;
    // (node, first, end) ranges of `indices` still to split.
    let mut todo = vec![(0usize, 0usize, n)];
    while let Some((node, first, end)) = todo.pop() {
        let mut aabb = Aabb::empty();
        let mut centroids = Aabb::empty();
        for &i in &indices[first..end] {
            aabb = aabb.union(&boxes[i as usize]);
            centroids.extend(boxes[i as usize].center());
        }
        if end - first == 1 {
            nodes[node] = Bvh2Node {
                aabb,
                prim_count: 1,
                first_index: first as u32,
                ..Bvh2Node::default()
            };
            continue;
        }
        let extent = centroids.max - centroids.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mut mid = first + (end - first) / 2;
        if extent[axis] > 0.0 {
            // Bin the centroids, then choose the boundary of least SAH cost.
            let lo = centroids.min[axis];
            let k = BINS as f32 / extent[axis];
            let bin =
                |i: u32| (((boxes[i as usize].center()[axis] - lo) * k) as usize).min(BINS - 1);
            let mut counts = [0usize; BINS];
            let mut bin_boxes = [Aabb::empty(); BINS];
            for &i in &indices[first..end] {
                let b = bin(i);
                counts[b] += 1;
                bin_boxes[b] = bin_boxes[b].union(&boxes[i as usize]);
            }
            let mut right_area = [0.0f32; BINS];
            let mut acc = Aabb::empty();
            let mut right_count = [0usize; BINS];
            let mut c = 0;
            for b in (1..BINS).rev() {
                acc = acc.union(&bin_boxes[b]);
                c += counts[b];
                right_area[b] = acc.half_area();
                right_count[b] = c;
            }
            let (mut best, mut best_cost) = (0usize, f32::INFINITY);
            let mut left = Aabb::empty();
            let mut left_count = 0;
            for b in 1..BINS {
                left = left.union(&bin_boxes[b - 1]);
                left_count += counts[b - 1];
                if left_count == 0 || right_count[b] == 0 {
                    continue;
                }
                let cost =
                    left.half_area() * left_count as f32 + right_area[b] * right_count[b] as f32;
                if cost < best_cost {
                    (best, best_cost) = (b, cost);
                }
            }
            if best > 0 {
                let part = &mut indices[first..end];
                let mut l = 0;
                for j in 0..part.len() {
                    if bin(part[j]) < best {
                        part.swap(l, j);
                        l += 1;
                    }
                }
                mid = first + l;
            }
        }
        let (left, right) = (next, next + 1);
        next += 2;
        nodes[node] = Bvh2Node {
            aabb,
            prim_count: 0,
            first_index: left as u32,
            ..Bvh2Node::default()
        };
        todo.push((left, first, mid));
        todo.push((right, mid, end));
    }
    Bvh2 {
        nodes,
        primitive_indices: indices,
        ..Bvh2::default()
    }
}

/// A BVH2 over triangles: obvhs' `build_bvh2_from_tris`, or, for input that would make PLOC
/// degenerate, the top-down build with obvhs' leaf collapse.
pub(crate) fn bvh2_from_tris(tris: &[Triangle], params: BvhBuildParams) -> Bvh2 {
    let boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
    if ploc_would_degenerate(&boxes, &params) {
        let mut bvh = build_top_down(&boxes);
        collapse(
            &mut bvh,
            params.max_prims_per_leaf.clamp(1, 255),
            params.collapse_traversal_cost,
        );
        return bvh;
    }
    drop(boxes);
    obvhs::bvh2::builder::build_bvh2_from_tris(tris, params, &mut Duration::default())
}

/// A CWBVH over boxes (triangles' or instances'): obvhs' builder, or, for input that would make
/// PLOC degenerate, the top-down build, converted as obvhs converts.
pub(crate) fn cwbvh_from_boxes(
    boxes: &[Aabb],
    params: BvhBuildParams,
    build: impl FnOnce() -> obvhs::cwbvh::CwBvh,
) -> obvhs::cwbvh::CwBvh {
    if ploc_would_degenerate(boxes, &params) {
        let bvh = build_top_down(boxes);
        return obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
            &bvh,
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

    #[test]
    fn top_down_trees_hold_every_primitive_once_in_bounding_nodes() {
        for tris in [
            fan(5_000),
            vec![tri([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]); 3_000],
        ] {
            let boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
            let bvh = build_top_down(&boxes);
            let mut seen = vec![false; tris.len()];
            let mut stack = vec![(0usize, 0usize)];
            let mut depth = 0;
            while let Some((i, d)) = stack.pop() {
                depth = depth.max(d);
                let node = &bvh.nodes[i];
                if node.prim_count > 0 {
                    let p = bvh.primitive_indices[node.first_index as usize] as usize;
                    assert!(!seen[p]);
                    seen[p] = true;
                    assert!(
                        node.aabb.contains_point(boxes[p].min)
                            && node.aabb.contains_point(boxes[p].max)
                    );
                } else {
                    for c in [node.first_index as usize, node.first_index as usize + 1] {
                        let child = &bvh.nodes[c].aabb;
                        assert!(
                            node.aabb.contains_point(child.min)
                                && node.aabb.contains_point(child.max)
                        );
                        stack.push((c, d + 1));
                    }
                }
            }
            assert!(seen.iter().all(|&s| s));
            assert!(depth < 64, "depth {depth}");
        }
    }
}
