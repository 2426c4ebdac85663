//! The binary tree collapsed into eight-wide nodes at least surface-area-heuristic cost.
//!
//! Ylitie, Karras and Laine, "Efficient incoherent ray traversal on GPUs through compressed wide
//! BVHs" (HPG 2017), section 4.1: a dynamic programme over the binary tree finds, for every
//! binary node `n` and every `i` in 1..=8, the cheapest way to represent `n`'s subtree as at
//! most `i` children of a wide node:
//!
//! - `C(n, 1) = min(leaf(n), A(n) c_node + D(n, 8))`, where `leaf(n)` is `A(n) c_packet`
//!   times the leaf's test cost in packets when the subtree's `p(n)` triangles fit in one leaf,
//!   else infinite;
//! - `C(n, i) = min(D(n, i), C(n, i - 1))` for `i > 1`;
//! - `D(n, j) = min over 0 < k < j of C(left, k) + C(right, j - k)`.
//!
//! Leaves are priced by how they are tested ([`Pricing`]). One ray at a time, a packet of four
//! triangles costs 1, a full leaf's two packets, tested in one eight-lane pass, `C_PAIR`; so the
//! programme prefers leaves of four or eight triangles and nodes with all eight slots used,
//! where the greedy collapse (open the largest child until there are eight) leaves half of the
//! slots empty near the leaves. The packet kernels (`packet.rs`), which every query of a small
//! tree takes, test a leaf one triangle at a time against eight rays and a node one child at a
//! time: there a leaf costs more against a node, and leaves hold at most four triangles. The
//! binary tree comes from `crate::build` with one triangle per leaf, so leaf sizes are the
//! programme's choice alone; a binary leaf that holds several triangles (should a builder make
//! one) stays one leaf.

use obvhs::bvh2::Bvh2;

/// Relative cost of testing one eight-wide node.
const C_NODE: f32 = 1.0;
/// Relative cost of testing one packet of four triangles, one ray at a time.
const C_PACKET: f32 = 1.5;
/// Relative cost of a leaf of up to four triangles in the packet kernels. Measured on Mitsuba's
/// Cornell box (36 triangles, every query a packet; docs/performance-log.md, thirteenth
/// session): 2.5 +1.3%, 5 +1.8% against the one-ray pricing, the same image bytes.
const C_PACKET_LEAF: f32 = 5.0;
/// Relative cost of testing two packets in one eight-lane pass, in packets. At 2 (the cost of
/// two separate packets, the pricing before the eight-lane pass) the bunny's tree had 4,590
/// nodes; at 1.5, 3,707: incoherent queries ran up to 20% faster and camera rays' closest hits
/// 5% slower (interleaved runs, docs/PERFORMANCE.md); at 1 the instructions per query rose by
/// 2-3%.
const C_PAIR: f32 = 1.5;

/// Cost of a leaf of `triangles`, relative to one packet's: pairs of packets in eight-lane
/// passes, a last odd packet alone.
fn leaf_packets_cost(triangles: u32) -> f32 {
    let packets = triangles.div_ceil(4);
    (packets / 2) as f32 * C_PAIR + (packets % 2) as f32
}

/// How the programme prices leaves: for the kernels that will traverse the tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pricing {
    /// One ray at a time (`traverse.rs`): leaves of up to eight triangles.
    OneRay,
    /// Eight rays at a time (`packet.rs`), as every query of a small tree: leaves of up to four.
    Packets,
}

impl Pricing {
    /// Most triangles the programme puts in one leaf.
    fn max_leaf_triangles(self) -> u32 {
        match self {
            Self::OneRay => 8,
            Self::Packets => 4,
        }
    }

    /// The cost of a leaf of `triangles` (at most [`Self::max_leaf_triangles`]) per unit of
    /// surface area, relative to a node's.
    fn leaf(self, triangles: u32) -> f32 {
        match self {
            Self::OneRay => C_PACKET * leaf_packets_cost(triangles),
            Self::Packets => C_PACKET_LEAF,
        }
    }
}

/// What the programme decided for one binary node.
#[derive(Clone, Copy)]
struct Choice {
    /// `cost[i - 1]` is `C(n, i)`.
    cost: [f32; 8],
    /// For `i > 1`: 0 when `C(n, i) = C(n, i - 1)`, else the `k` of the best split of `D(n, i)`.
    /// For `i = 1`: 0 for a leaf, else the `k` of `D(n, 8)` of the inner node.
    split: [u8; 8],
}

/// One child of a wide node: a binary node to be made a leaf, or to be expanded into a wide node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Slot {
    Leaf(usize),
    Inner(usize),
}

/// The programme's result for a binary tree.
pub(crate) struct Plan {
    choices: Vec<Choice>,
}

impl Plan {
    /// Solve the programme for `bvh` (whose root is node 0 and is not a leaf), leaves priced
    /// by `pricing`.
    pub fn new(bvh: &Bvh2, pricing: Pricing) -> Self {
        let nodes = &bvh.nodes;
        let mut choices = vec![
            Choice {
                cost: [0.0; 8],
                split: [0; 8],
            };
            nodes.len()
        ];
        let mut count = vec![0u32; nodes.len()];
        // Children before parents: an explicit post-order walk.
        let mut stack = vec![(0usize, false)];
        while let Some((n, expanded)) = stack.pop() {
            let node = &nodes[n];
            let area = node.aabb.half_area().max(0.0);
            if node.prim_count > 0 {
                count[n] = node.prim_count;
                let leaf = area * pricing.leaf(node.prim_count);
                choices[n] = Choice {
                    cost: [leaf; 8],
                    split: [0; 8],
                };
                continue;
            }
            let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
            if !expanded {
                stack.push((n, true));
                stack.push((l, false));
                stack.push((r, false));
                continue;
            }
            count[n] = count[l].saturating_add(count[r]);
            let (cl, cr) = (&choices[l].cost, &choices[r].cost);
            // D(n, j) for j = 2..=8 and its best k.
            let mut dist = [(f32::INFINITY, 0u8); 9];
            for (j, d) in dist.iter_mut().enumerate().skip(2) {
                for k in 1..j {
                    let c = cl[k - 1] + cr[j - k - 1];
                    if c < d.0 {
                        *d = (c, k as u8);
                    }
                }
            }
            let inner = area * C_NODE + dist[8].0;
            let leaf = if count[n] <= pricing.max_leaf_triangles() {
                area * pricing.leaf(count[n])
            } else {
                f32::INFINITY
            };
            let mut c = Choice {
                cost: [0.0; 8],
                split: [0; 8],
            };
            (c.cost[0], c.split[0]) = if leaf <= inner {
                (leaf, 0)
            } else {
                (inner, dist[8].1)
            };
            for i in 2..=8 {
                (c.cost[i - 1], c.split[i - 1]) = if dist[i].0 < c.cost[i - 2] {
                    dist[i]
                } else {
                    (c.cost[i - 2], 0)
                };
            }
            choices[n] = c;
        }
        Self { choices }
    }

    /// The children of the wide node made from inner binary node `n` (at most eight).
    pub fn children(&self, bvh: &Bvh2, n: usize, out: &mut Vec<Slot>) {
        out.clear();
        let k = self.choices[n].split[0] as usize;
        debug_assert!(k > 0, "node {n} is a leaf");
        let l = bvh.nodes[n].first_index as usize;
        self.roots(bvh, l, k, out);
        self.roots(bvh, l + 1, 8 - k, out);
    }

    /// Append the at most `i` roots that represent `n`'s subtree.
    fn roots(&self, bvh: &Bvh2, n: usize, i: usize, out: &mut Vec<Slot>) {
        let mut work = vec![(n, i)];
        while let Some((n, mut i)) = work.pop() {
            // Step down to the largest i' <= i that splits.
            while i > 1 && self.choices[n].split[i - 1] == 0 {
                i -= 1;
            }
            if i == 1 {
                let leaf = bvh.nodes[n].prim_count > 0 || self.choices[n].split[0] == 0;
                out.push(if leaf { Slot::Leaf(n) } else { Slot::Inner(n) });
                continue;
            }
            let k = self.choices[n].split[i - 1] as usize;
            let l = bvh.nodes[n].first_index as usize;
            // Right pushed first so that the left subtree's roots come first.
            work.push((l + 1, i - k));
            work.push((l, k));
        }
    }

    /// Whether the whole tree is best one leaf.
    pub fn root_is_leaf(&self) -> bool {
        self.choices[0].split[0] == 0
    }
}

/// The triangles (store slots) under binary node `n`, in the binary tree's order.
pub(crate) fn leaf_slots(bvh: &Bvh2, n: usize, out: &mut Vec<u32>) {
    out.clear();
    let mut stack = vec![n];
    while let Some(n) = stack.pop() {
        let node = &bvh.nodes[n];
        if node.prim_count > 0 {
            out.extend(node.first_index..node.first_index + node.prim_count);
        } else {
            stack.push(node.first_index as usize + 1);
            stack.push(node.first_index as usize);
        }
    }
}
