//! An eight-wide BVH with full-precision child boxes, traced with one 256-bit register per plane.
//!
//! The layout of Embree's BVH8 and tinybvh's `BVH8_CPU`: a node holds its eight children's boxes
//! as six planes of eight floats (min x of all eight children, max x, min y, ...), so one ray meets
//! all eight boxes in six fused multiply-subtracts, three maxima, three minima and a comparison;
//! leaves hold packets of four triangles side by side ([`PackedTriangles4`]), 144 bytes each;
//! the ids of their triangles are kept apart, since only a query's closest hit needs them.
//!
//! The binary tree, with one triangle per leaf, comes from `crate::build` (binned SAH from the
//! medium preset up, obvhs' PLOC for the faster ones); a dynamic programme over it chooses the
//! eight-wide nodes and the leaves at least SAH cost (`collapse.rs`).
//!
//! Traversal (`traverse.rs`) is front to back for closest hits, the entered children ordered by
//! entry distance, and skips stack entries that lie beyond the closest hit found so far; shadow
//! rays stop at the first hit. The node test is conservative at every scale (see
//! `traverse.rs`). The kernels are chosen per query by the CPU: AVX2 with FMA where the CPU has
//! them, two four-lane halves elsewhere ([`crate::simd`]).

mod collapse;
mod packet;
mod traverse;

use glam::Vec3A;
use obvhs::bvh2::Bvh2;

use crate::BuildQuality;
use crate::simd::Lanes8;
use crate::store::{PrimRef, TriangleStore};
use crate::triangle::{PackedTriangle, PackedTriangles4, Triangles4};
use collapse::{Plan, Pricing, Slot};

/// Set in a child reference when the child is a leaf.
const LEAF: u32 = 1 << 31;
/// Bits of a leaf reference that hold its packet count minus one.
pub(super) const COUNT_BITS: u32 = 5;
/// Most packets in one leaf.
const MAX_LEAF_PACKETS: usize = 1 << COUNT_BITS;
/// Most packets in a tree (the rest of a leaf reference).
const MAX_PACKETS: usize = 1 << (31 - COUNT_BITS);
/// Most nodes in a tree: a node reference is the node's byte offset in `nodes`, below `LEAF`
/// (8,388,608 nodes, room for about 58 million leaves; a tree that needs more is refused, and
/// the accelerator falls back to another layout, as at the other limits).
const MAX_NODES: usize = LEAF as usize / size_of::<Node8>();
/// Trees over at most this many triangles that answer lane queries are priced for the packet
/// kernels ([`collapse::Pricing::Packets`]) when they come out small enough to take them for
/// every such query (at most `packet::MAX_NODES` nodes; leaves of at most four triangles make about one
/// node per 32 triangles).
const PACKET_PRICED_TRIANGLES: usize = 256;
/// Largest traversal stack (entries); a tree that could need more is refused.
pub(crate) const MAX_STACK: usize = 256;

/// Eight children: their boxes as planes (lane `i` is child `i`) and references. Four cache
/// lines: the planes in three, the references in the fourth.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node8 {
    /// min x, max x, min y, max y, min z, max z of the eight children.
    planes: [Lanes8; 6],
    /// Per child: a node's byte offset in the tree's nodes (so that the walks address it without
    /// a multiplication), or `LEAF | first_packet << COUNT_BITS | (packets - 1)`. Empty slots
    /// hold 0 and an inverted infinite box, whose entry distance is `+inf` for every ray.
    child: [u32; 8],
}

impl Node8 {
    const EMPTY: Self = Self {
        planes: [
            Lanes8([f32::INFINITY; 8]),
            Lanes8([f32::NEG_INFINITY; 8]),
            Lanes8([f32::INFINITY; 8]),
            Lanes8([f32::NEG_INFINITY; 8]),
            Lanes8([f32::INFINITY; 8]),
            Lanes8([f32::NEG_INFINITY; 8]),
        ],
        child: [0; 8],
    };
}

/// An eight-wide BVH over a triangle store whose triangles are kept in BVH leaf order.
#[derive(Clone, Debug)]
pub(crate) struct Bvh8 {
    nodes: Vec<Node8>,
    /// Leaves' triangles, four at a time, every lane live (a leaf's last packet repeats its
    /// last triangle): 144 bytes each, three cache lines wherever they start.
    packets: Vec<Triangles4>,
    /// Where each packet's triangles came from, apart from the coordinates: only the closest
    /// hit of a query needs them, once.
    refs: Vec<[PrimRef; 4]>,
    /// The packets' triangles again, corner by corner as `[x, y, z, 0]`, for trees the packet
    /// kernels take for every lane query (at most `packet::MAX_NODES` nodes, a few hundred
    /// triangles): each corner's coordinates are then permuted into a ray's axes by one
    /// in-register pick per coordinate ([`crate::lanes::Simd::pick`]). Empty for other trees.
    corners: Vec<PacketCorners>,
    /// Reference to the root: node 0, or a leaf when the whole tree is one, or `None` when empty.
    root: Option<u32>,
    /// The most entries the traversal stack can hold at once for this tree.
    stack_need: usize,
    /// The kernels this CPU runs, detected at build time.
    isa: traverse::Isa,
    /// The lanes the packet kernels run with, detected at build time.
    lanes: crate::lanes::Found,
    pub store: TriangleStore,
}

/// A packet's four triangles (index `i`), each's three corners (index `c`) as `[x, y, z, 0]`.
type PacketCorners = [[[f32; 4]; 3]; 4];

/// Why a [`Bvh8`] was not built: the store comes back for another layout to use.
pub(crate) struct TooDeep(pub TriangleStore);

impl Bvh8 {
    /// Build over `store` (reordering its triangles into BVH order), or give the store back when
    /// the tree could overflow the largest traversal stack or the leaf references.
    /// `lane_queries`: whether the tree will answer eight-ray lane queries (a flat accelerator;
    /// a two-level one's bottom trees answer one ray at a time), which decides how a small
    /// tree's leaves are priced.
    pub fn build(
        store: TriangleStore,
        quality: BuildQuality,
        lane_queries: bool,
    ) -> Result<Self, TooDeep> {
        let mut out = Self {
            nodes: Vec::new(),
            packets: Vec::new(),
            refs: Vec::new(),
            corners: Vec::new(),
            root: None,
            stack_need: 0,
            isa: traverse::Isa::detect(),
            lanes: crate::lanes::Found::detect(),
            store,
        };
        if out.store.tris.is_empty() {
            return Ok(out);
        }
        let tris = out.store.obvhs_triangles();
        // One triangle per binary leaf: the collapse chooses the leaves.
        let mut params = quality.params();
        params.max_prims_per_leaf = 1;
        let bvh2 = crate::build::bvh2_from_tris(&tris, quality, params);
        drop(tris);
        out.store = std::mem::take(&mut out.store).reordered(&bvh2.primitive_indices);
        // A small tree takes the packet kernels for every lane query: its leaves are priced for
        // them, unless the tree then comes out too big to count as small.
        if lane_queries && out.store.tris.len() <= PACKET_PRICED_TRIANGLES {
            if out.collapse(&bvh2, Pricing::Packets).is_some()
                && out.nodes.len() <= packet::MAX_NODES
            {
                out.corners = packet::corners(&out);
                return Ok(out);
            }
            out.nodes.clear();
            out.packets.clear();
            out.refs.clear();
            (out.root, out.stack_need) = (None, 0);
        }
        match out.collapse(&bvh2, Pricing::OneRay) {
            Some(()) => {
                out.corners = packet::corners(&out);
                Ok(out)
            }
            None => Err(TooDeep(out.store)),
        }
    }

    /// Fill `nodes` and `packets` from the binary tree as the cost programme says, leaves
    /// priced by `pricing`; `None` when a limit is exceeded.
    fn collapse(&mut self, bvh2: &Bvh2, pricing: Pricing) -> Option<()> {
        let b = &bvh2.nodes;
        let mut slots = Vec::new();
        if b[0].prim_count > 0 {
            collapse::leaf_slots(bvh2, 0, &mut slots);
            self.root = Some(self.leaf(&slots)?);
            return Some(());
        }
        let plan = Plan::new(bvh2, pricing);
        if plan.root_is_leaf() {
            collapse::leaf_slots(bvh2, 0, &mut slots);
            self.root = Some(self.leaf(&slots)?);
            return Some(());
        }
        self.nodes.push(Node8::EMPTY);
        self.root = Some(0);
        // Work list of (binary node, wide node to fill, stack entries its ancestors may leave).
        let mut work = vec![(0usize, 0usize, 0usize)];
        let mut kids = Vec::with_capacity(8);
        while let Some((bi, ni, below)) = work.pop() {
            plan.children(bvh2, bi, &mut kids);
            // Visiting this node pushes all its entered children, then pops one.
            self.stack_need = self.stack_need.max(below + kids.len());
            if self.stack_need > MAX_STACK {
                return None;
            }
            let mut node = Node8::EMPTY;
            for (lane, &kid) in kids.iter().enumerate() {
                let k = match kid {
                    Slot::Leaf(k) | Slot::Inner(k) => k,
                };
                let (lo, hi) = (b[k].aabb.min, b[k].aabb.max);
                for axis in 0..3 {
                    node.planes[2 * axis].0[lane] = lo[axis];
                    node.planes[2 * axis + 1].0[lane] = hi[axis];
                }
                node.child[lane] = match kid {
                    Slot::Leaf(k) => {
                        collapse::leaf_slots(bvh2, k, &mut slots);
                        self.leaf(&slots)?
                    }
                    Slot::Inner(k) => {
                        let index = self.nodes.len();
                        if index >= MAX_NODES {
                            return None;
                        }
                        self.nodes.push(Node8::EMPTY);
                        work.push((k, index, below + kids.len() - 1));
                        (index * size_of::<Node8>()) as u32
                    }
                };
            }
            self.nodes[ni] = node;
        }
        Some(())
    }

    /// Pack the triangles in these store slots and return the leaf reference.
    fn leaf(&mut self, slots: &[u32]) -> Option<u32> {
        let start = self.packets.len();
        for chunk in slots.chunks(4) {
            let tris: Vec<PackedTriangle> = chunk
                .iter()
                .map(|&s| self.store.tris[s as usize].tri)
                .collect();
            let last = *chunk.last().expect("chunks are not empty");
            let slot = |i: usize| chunk.get(i).copied().unwrap_or(last) as usize;
            self.packets
                .push(Triangles4::from_full(&PackedTriangles4::padded(&tris)));
            self.refs
                .push(std::array::from_fn(|i| self.store.tris[slot(i)].r));
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
        self.nodes.capacity() * size_of::<Node8>()
            + self.packets.capacity() * size_of::<Triangles4>()
            + self.refs.capacity() * size_of::<[PrimRef; 4]>()
            + self.corners.capacity() * size_of::<PacketCorners>()
            + self.store.memory_bytes()
    }

    /// The node a node reference of this tree (the root's, or a child's: a byte offset) names,
    /// without a bounds check: the kernels' walks read one per visit.
    #[inline(always)]
    #[allow(unsafe_code)]
    fn node(&self, r: u32) -> &Node8 {
        let offset = r as usize;
        debug_assert!(
            offset.is_multiple_of(size_of::<Node8>())
                && offset / size_of::<Node8>() < self.nodes.len(),
            "node reference {r} out of range"
        );
        // SAFETY: `collapse` pushes a node before it writes the node's offset into its parent
        // (or `root`), and `nodes` is not changed after the tree is built; a failed collapse
        // clears the references with the nodes, or gives no tree. So every node reference the
        // walks read from this tree is the offset of an element of `nodes`.
        unsafe { &*self.nodes.as_ptr().cast::<u8>().add(offset).cast::<Node8>() }
    }

    /// The address of the node a node reference names, for a prefetch (any reference: the
    /// address need not be valid).
    #[inline(always)]
    fn node_address(&self, r: u32) -> *const Node8 {
        self.nodes
            .as_ptr()
            .cast::<u8>()
            .wrapping_add(r as usize)
            .cast()
    }

    /// The packets of a leaf reference of this tree: the index of the first and the packets
    /// (without a bounds check, for the same reason as [`Self::node`]).
    #[inline(always)]
    #[allow(unsafe_code)]
    fn leaf_packets(&self, r: u32) -> (usize, &[Triangles4]) {
        let first = ((r & !LEAF) >> COUNT_BITS) as usize;
        let n = (r & (MAX_LEAF_PACKETS as u32 - 1)) as usize + 1;
        debug_assert!(
            first + n <= self.packets.len(),
            "leaf reference {r:#x} out of range"
        );
        // SAFETY: `leaf` makes a reference from the packets it has just pushed, `first..first
        // + n` (its count checked to fit the reference's bits), and `packets` is not changed
        // after the tree is built (a failed collapse clears it with the references).
        unsafe { (first, self.packets.get_unchecked(first..first + n)) }
    }
}

// The binary node's box must be the Vec3A pair this file reads.
const _: fn(&obvhs::bvh2::node::Bvh2Node) -> (Vec3A, Vec3A) = |n| (n.aabb.min, n.aabb.max);
const _: () = assert!(size_of::<Node8>() == 256);
// A node reference (a byte offset) never reaches the leaf bit.
const _: () = assert!(MAX_NODES * size_of::<Node8>() <= LEAF as usize);
