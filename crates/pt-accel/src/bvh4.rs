//! A four-wide BVH with full-precision child boxes and leaves tested four triangles at a time.
//!
//! `crate::build` makes a binary BVH (binned SAH, or obvhs' PLOC for the faster presets, then
//! obvhs' SAH leaf collapsing); it is collapsed here into
//! nodes of up to four children by repeatedly opening the child with the largest surface area
//! (the usual BVH2-to-BVH4 collapse, as in Embree's and pbrt's wide trees). A node stores its
//! children's boxes as six four-lane planes (min x, max x, min y, ...), so one ray meets all four
//! boxes in a dozen SIMD operations, with no decompression; a leaf's triangles are stored as
//! packets of four ([`PackedTriangles4`]) and tested together.
//!
//! The box test is the conservative slab test of *Physically Based Rendering* (4th ed., section
//! 6.8.2): each slab distance is within `gamma(3)` of its real value relative to itself, so the
//! exit distance is widened by `1 + 2 gamma(3)`. Direction components below `MIN_DIR` are clamped
//! (see `node_ray`), which keeps every distance finite; an empty child slot has an inverted
//! infinite box, whose entry distance is `+inf`, so it is never entered.
//!
//! Traversal is front to back for closest hits (children sorted by entry distance; stack entries
//! keep their distance and are dropped once a nearer hit is known) and in any order for shadow
//! rays. The stack is a fixed array; a tree too deep for it is refused at build time and the
//! caller falls back to another layout.

use glam::{Vec3A, Vec4};
use obvhs::bvh2::Bvh2;

use crate::BuildQuality;
use crate::float::gamma;
use crate::node_ray::{MIN_DIR, NodeRay};
use crate::ray::Ray;
use crate::store::{PrimRef, TriangleStore};
use crate::triangle::{PackedTriangle, PackedTriangles4, RayTriangleTest, TriangleHit};

/// Entries of the traversal stack. Each node on the way down leaves at most three children on the
/// stack and briefly holds a fourth while sorting, so a tree of depth `d` needs `3 (d - 1) + 4`
/// entries; deeper trees are refused.
const STACK_SIZE: usize = 64;

/// The deepest tree (in nodes) a stack of `entries` can hold.
const fn max_depth(entries: usize) -> usize {
    (entries - 4) / 3 + 1
}

/// The deepest tree (in nodes) the traversal stack can hold.
pub(crate) const MAX_BVH4_DEPTH: usize = max_depth(STACK_SIZE);

/// Trees this shallow are traversed with a stack of [`SMALL_STACK_SIZE`] entries, which is
/// cheaper to set up (the stack is zeroed per query).
const SMALL_STACK_SIZE: usize = 19;

/// Set in a child reference when the child is a leaf.
const LEAF: u32 = 1 << 31;
/// Bits of a leaf reference that hold its packet count minus one.
const COUNT_BITS: u32 = 5;
/// Most packets in one leaf.
const MAX_LEAF_PACKETS: usize = 1 << COUNT_BITS;
/// Most packets in a tree (the rest of a leaf reference).
const MAX_PACKETS: usize = 1 << (31 - COUNT_BITS);

/// Widening of a box's exit distance for the conservative slab test.
const BOX_EXIT_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// Four children: their boxes as planes (lane `i` is child `i`) and references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    /// min x, max x, min y, max y, min z, max z of the four children.
    planes: [Vec4; 6],
    /// Per child: a node index, or `LEAF | first_packet << COUNT_BITS | (packets - 1)`. Empty
    /// slots hold 0 and an inverted box.
    child: [u32; 4],
}

impl Node4 {
    const EMPTY: Self = Self {
        planes: [
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
        ],
        child: [0; 4],
    };
}

/// A leaf's triangles, four at a time, with where each came from (so that a hit needs no
/// access to the triangle store). Three cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct LeafPacket {
    tris: PackedTriangles4,
    refs: [PrimRef; 4],
}

/// The ray prepared for [`Node4`] tests: splatted origin and reciprocal direction, and which plane
/// is the near one on each axis.
///
/// On an axis where the direction is (nearly) zero the ray runs parallel to the slabs: it is inside
/// a slab exactly when `lo <= o <= hi`, which the clamped reciprocal decides correctly except when
/// the origin lies exactly on a plane (the distance is then `0 * 1e20 = 0`, and the box would be
/// left at `t = 0`). There the origin is moved outward by a few ulps, backward for the far plane
/// and forward for the near one, so a ray running along a box face counts as inside the box.
struct Ray4 {
    origin_near: [Vec4; 3],
    origin_far: [Vec4; 3],
    inv_dir: [Vec4; 3],
    neg: [bool; 3],
    t_min: Vec4,
}

impl Ray4 {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let r = NodeRay::new(ray);
        let d = Vec3A::from(ray.dir);
        let flat = d.abs().cmplt(Vec3A::splat(MIN_DIR));
        let o = r.origin;
        let shift = Vec3A::select(
            flat,
            (o.abs() * (2.0 * f32::EPSILON) + f32::MIN_POSITIVE) * r.inv_dir.signum(),
            Vec3A::ZERO,
        );
        let (o_near, o_far) = (o + shift, o - shift);
        Self {
            origin_near: [0, 1, 2].map(|a| Vec4::splat(o_near[a])),
            origin_far: [0, 1, 2].map(|a| Vec4::splat(o_far[a])),
            inv_dir: [0, 1, 2].map(|a| Vec4::splat(r.inv_dir[a])),
            neg: r.neg,
            t_min: Vec4::splat(r.t_min),
        }
    }

    /// Which of the node's four children the ray enters within `[t_min, t_max]` (bit `i` for
    /// child `i`), and their entry distances.
    #[inline(always)]
    fn hit_children(&self, node: &Node4, t_max: f32) -> (u32, Vec4) {
        let p = &node.planes;
        let [nx, ny, nz] = self.neg.map(usize::from);
        let near_slab = |plane: Vec4, a: usize| (plane - self.origin_near[a]) * self.inv_dir[a];
        let far_slab = |plane: Vec4, a: usize| (plane - self.origin_far[a]) * self.inv_dir[a];
        let near = near_slab(p[nx], 0)
            .max(near_slab(p[2 + ny], 1))
            .max(near_slab(p[4 + nz], 2))
            .max(self.t_min);
        let far = far_slab(p[1 - nx], 0)
            .min(far_slab(p[3 - ny], 1))
            .min(far_slab(p[5 - nz], 2))
            * BOX_EXIT_SCALE;
        let far = far.min(Vec4::splat(t_max));
        (near.cmple(far).bitmask(), near)
    }
}

/// A traversal stack entry: a child reference and its entry distance.
#[derive(Clone, Copy, Default)]
struct Entry {
    child: u32,
    t: f32,
}

/// A four-wide BVH over a triangle store whose triangles are kept in BVH leaf order.
#[derive(Clone, Debug)]
pub(crate) struct Bvh4 {
    nodes: Vec<Node4>,
    packets: Vec<LeafPacket>,
    /// Reference to the root: node 0, or a leaf when the whole tree is one, or `None` when empty.
    root: Option<u32>,
    /// Depth in nodes (0 when empty or a single leaf).
    depth: usize,
    pub store: TriangleStore,
}

/// Why a [`Bvh4`] was not built: the store comes back for another layout to use.
pub(crate) struct TooDeep(pub TriangleStore);

impl Bvh4 {
    /// Build over `store` (reordering its triangles into BVH order), or give the store back when
    /// the tree is too deep for the traversal stack or too big for the leaf references.
    pub fn build(store: TriangleStore, quality: BuildQuality) -> Result<Self, TooDeep> {
        if store.tris.is_empty() {
            return Ok(Self {
                nodes: Vec::new(),
                packets: Vec::new(),
                root: None,
                depth: 0,
                store,
            });
        }
        let tris = store.obvhs_triangles();
        // obvhs' presets allow leaves of up to 8 triangles (two packets). Limiting them to one
        // packet saved 2% of the instructions on the Cornell box but cost 7% of the speed of
        // incoherent rays on the bunny (more nodes, more cache misses). The fastest preset makes
        // leaves of one triangle, which fills three lanes of every packet with copies (1.5x
        // slower for incoherent rays than the CWBVH built with it); it gets leaves of up to 8
        // too (then 10-25% slower than that CWBVH, whose leaves obvhs assigns by SAH).
        let mut params = quality.params();
        params.max_prims_per_leaf = params.max_prims_per_leaf.max(8);
        let bvh2 = crate::build::bvh2_from_tris(&tris, quality, params);
        drop(tris);
        let store = store.reordered(&bvh2.primitive_indices);
        let mut out = Self {
            nodes: Vec::new(),
            packets: Vec::new(),
            root: None,
            depth: 0,
            store,
        };
        match out.collapse(&bvh2) {
            Some(()) => Ok(out),
            None => Err(TooDeep(out.store)),
        }
    }

    /// Fill `nodes` and `packets` from the binary tree; `None` when a limit is exceeded.
    fn collapse(&mut self, bvh2: &Bvh2) -> Option<()> {
        let b = &bvh2.nodes;
        let root = &b[0];
        if root.prim_count > 0 {
            self.root = Some(self.leaf(root.first_index, root.prim_count)?);
            return Some(());
        }
        // Work list of (binary node, wide node to fill, its depth).
        self.nodes.push(Node4::EMPTY);
        self.root = Some(0);
        let mut work = vec![(0usize, 0usize, 1usize)];
        while let Some((bi, ni, depth)) = work.pop() {
            self.depth = self.depth.max(depth);
            if depth > MAX_BVH4_DEPTH {
                return None;
            }
            // Open the largest inner child until there are four children or only leaves.
            let first = b[bi].first_index as usize;
            let mut kids = vec![first, first + 1];
            while kids.len() < 4 {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|(_, k)| b[**k].prim_count == 0)
                    .max_by(|x, y| {
                        b[*x.1]
                            .aabb
                            .half_area()
                            .total_cmp(&b[*y.1].aabb.half_area())
                    });
                let Some((i, &k)) = open else { break };
                let f = b[k].first_index as usize;
                kids.splice(i..=i, [f, f + 1]);
            }
            let mut node = Node4::EMPTY;
            for (lane, &k) in kids.iter().enumerate() {
                let (lo, hi) = (b[k].aabb.min, b[k].aabb.max);
                for axis in 0..3 {
                    node.planes[2 * axis][lane] = lo[axis];
                    node.planes[2 * axis + 1][lane] = hi[axis];
                }
                node.child[lane] = if b[k].prim_count > 0 {
                    self.leaf(b[k].first_index, b[k].prim_count)?
                } else {
                    let index = self.nodes.len();
                    self.nodes.push(Node4::EMPTY);
                    work.push((k, index, depth + 1));
                    index as u32
                };
            }
            self.nodes[ni] = node;
        }
        Some(())
    }

    /// Pack the triangles in store slots `first..first + count` and return the leaf reference.
    fn leaf(&mut self, first: u32, count: u32) -> Option<u32> {
        let start = self.packets.len();
        let slots: Vec<u32> = (first..first + count).collect();
        for chunk in slots.chunks(4) {
            let tris: Vec<PackedTriangle> = chunk
                .iter()
                .map(|&s| self.store.tris[s as usize].tri)
                .collect();
            let last = *chunk.last().expect("chunks are not empty");
            let slot = |i: usize| chunk.get(i).copied().unwrap_or(last) as usize;
            self.packets.push(LeafPacket {
                tris: PackedTriangles4::padded(&tris),
                refs: std::array::from_fn(|i| self.store.tris[slot(i)].r),
            });
        }
        let n = self.packets.len() - start;
        if n > MAX_LEAF_PACKETS || self.packets.len() > MAX_PACKETS {
            return None;
        }
        Some(LEAF | (start as u32) << COUNT_BITS | (n as u32 - 1))
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node4>()
            + self.packets.capacity() * size_of::<LeafPacket>()
            + self.store.memory_bytes()
    }

    /// The packets of a leaf reference.
    #[inline(always)]
    fn leaf_packets(&self, r: u32) -> &[LeafPacket] {
        let first = ((r & !LEAF) >> COUNT_BITS) as usize;
        let n = (r & (MAX_LEAF_PACKETS as u32 - 1)) as usize + 1;
        &self.packets[first..first + n]
    }

    /// The closest triangle hit in `[t_min, t_max]`: where the triangle came from and the hit.
    #[inline]
    pub fn closest(&self, ray: &Ray) -> Option<(PrimRef, TriangleHit)> {
        if self.depth <= max_depth(SMALL_STACK_SIZE) {
            self.closest_with::<SMALL_STACK_SIZE>(ray)
        } else {
            self.closest_with::<STACK_SIZE>(ray)
        }
    }

    /// True when any triangle is hit in `[t_min, t_max]`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.depth <= max_depth(SMALL_STACK_SIZE) {
            self.occluded_with::<SMALL_STACK_SIZE>(ray)
        } else {
            self.occluded_with::<STACK_SIZE>(ray)
        }
    }

    /// [`Self::closest`] with a stack of `N` entries.
    #[inline(always)]
    fn closest_with<const N: usize>(&self, ray: &Ray) -> Option<(PrimRef, TriangleHit)> {
        let mut cur = self.root?;
        let test = RayTriangleTest::new(ray);
        let r = Ray4::new(ray);
        let mut t_max = ray.t_max;
        let mut best = None;
        let mut stack = [Entry::default(); N];
        let mut len = 0usize;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let (mut mask, near) = r.hit_children(node, t_max);
                if mask != 0 {
                    let first = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        cur = node.child[first];
                        continue;
                    }
                    // Push every entered child, keeping the entries of this node sorted so that
                    // the nearest ends on top; then continue with it.
                    let near = near.to_array();
                    let base = len;
                    let mut push = |child: u32, t: f32| {
                        let mut j = len;
                        while j > base && stack[j - 1].t < t {
                            stack[j] = stack[j - 1];
                            j -= 1;
                        }
                        stack[j] = Entry { child, t };
                        len += 1;
                    };
                    push(node.child[first], near[first]);
                    while mask != 0 {
                        let i = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        push(node.child[i], near[i]);
                    }
                    len -= 1;
                    cur = stack[len].child;
                    continue;
                }
            } else {
                for p in self.leaf_packets(cur) {
                    let bound = crate::triangle::tie_bound(ray.t_max, t_max);
                    if let Some((lane, h)) = test.closest4_bounded(&p.tris, bound, t_max) {
                        t_max = h.t;
                        best = Some((p.refs[lane], h));
                    }
                }
            }
            // Next: the nearest pushed child not beyond the closest hit so far.
            loop {
                if len == 0 {
                    return best;
                }
                len -= 1;
                if stack[len].t <= t_max {
                    cur = stack[len].child;
                    break;
                }
            }
        }
    }

    /// [`Self::occluded`] with a stack of `N` entries.
    #[inline(always)]
    fn occluded_with<const N: usize>(&self, ray: &Ray) -> bool {
        let Some(mut cur) = self.root else {
            return false;
        };
        let test = RayTriangleTest::new(ray);
        let r = Ray4::new(ray);
        let mut stack = [0u32; N];
        let mut len = 0usize;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let (mut mask, _) = r.hit_children(node, ray.t_max);
                if mask != 0 {
                    cur = node.child[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    while mask != 0 {
                        stack[len] = node.child[mask.trailing_zeros() as usize];
                        len += 1;
                        mask &= mask - 1;
                    }
                    continue;
                }
            } else if self
                .leaf_packets(cur)
                .iter()
                .any(|p| test.any4(&p.tris, ray.t_max))
            {
                return true;
            }
            if len == 0 {
                return false;
            }
            len -= 1;
            cur = stack[len];
        }
    }
}

// The binary node's box must be the Vec3A pair this file reads.
const _: fn(&obvhs::bvh2::node::Bvh2Node) -> (Vec3A, Vec3A) = |n| (n.aabb.min, n.aabb.max);
