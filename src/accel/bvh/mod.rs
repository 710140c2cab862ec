//! The default backend: a wide BVH whose triangles are packed four to a leaf block, nodes and
//! blocks both in structure-of-arrays layout, so one vector instruction tests a ray against
//! several boxes or four triangles. obvhs builds the binary tree (PLOC with reinsertion and
//! leaf collapsing); we collapse it to a wide tree, choosing each wide node's children by the
//! surface area heuristic (a dynamic programme over the binary tree), and traverse it
//! ourselves, nearest child first. A leaf is one block, or two consecutive ones in the 8-wide tree.
//!
//! The width is picked at build time from the CPU: on x86-64 with AVX2 and FMA, eight children
//! per node, whose boxes are tested with one AVX instruction per slab (`mod avx2`); elsewhere
//! four, tested with SSE (or NEON) through glam's `Vec4`. Leaf blocks are tested with `Vec4`
//! in both. Tests and benches can force the 4-wide tree with [`with_bvh_width`]. On the
//! traversal bench (1 thread, closest hit) the 8-wide tree traces 1.3-1.6x the 4-wide's rays,
//! 0.78-0.99x Embree 3's; its build takes the same time.
//!
//! Triangles are numbered in leaf order, so a hit needs no indirection; the unused lanes of a
//! block hold a zero triangle, whose test yields NaN and fails every comparison.

mod huge_pages;
mod stack;

use super::ray::{Hit, Ray};
use crate::error::{Error, MLT_STATUS_INTERNAL_ERROR, Result};
use glam::{BVec4A, Vec3A, Vec4};
use huge_pages::in_huge_pages;
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, builder::build_bvh2_from_tris},
    triangle::Triangle,
};
use stack::{STACK_SIZE, TraversalStack};
use std::cell::Cell;
use std::time::Duration;

/// Triangles of a leaf block, and children of a 4-wide node.
const WIDTH: usize = 4;
/// A child reference with this bit set is a leaf block index; otherwise a node index.
const LEAF_BIT: u32 = 1 << 31;
/// Set in a leaf reference whose triangles fill two consecutive blocks.
const TWO_BLOCKS_BIT: u32 = 1 << 30;
/// The reference of an empty child slot (its box is empty, so it is never entered).
const EMPTY: u32 = u32::MAX;

/// Children per node of the BVH.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhWidth {
    /// Tested with SSE (or NEON): any CPU.
    Four,
    /// Tested with AVX2 and FMA: x86-64 CPUs that have them.
    Eight,
}

impl BvhWidth {
    /// The widest this CPU supports.
    pub fn best() -> BvhWidth {
        if BvhWidth::Eight.is_supported() {
            BvhWidth::Eight
        } else {
            BvhWidth::Four
        }
    }

    pub fn is_supported(self) -> bool {
        match self {
            BvhWidth::Four => true,
            #[cfg(target_arch = "x86_64")]
            BvhWidth::Eight => is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"),
            #[cfg(not(target_arch = "x86_64"))]
            BvhWidth::Eight => false,
        }
    }
}

thread_local! {
    static FORCED_WIDTH: Cell<Option<BvhWidth>> = const { Cell::new(None) };
}

/// Runs `f` with the BVHs built on this thread `width` wide (if the CPU supports it) instead
/// of the widest it supports: for tests and benches of the fallback.
#[doc(hidden)]
pub fn with_bvh_width<R>(width: BvhWidth, f: impl FnOnce() -> R) -> R {
    struct Restore(Option<BvhWidth>);
    impl Drop for Restore {
        fn drop(&mut self) {
            FORCED_WIDTH.set(self.0);
        }
    }
    let _restore = Restore(FORCED_WIDTH.replace(Some(width)));
    f()
}

/// Four child boxes: `bounds[2 * axis]` their minima along the axis, `bounds[2 * axis + 1]`
/// their maxima. Empty slots have min = +inf, max = -inf. Aligned to cache lines, for
/// `BvhAccel::prefetch`.
#[repr(align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
struct Node4 {
    bounds: [Vec4; 6],
    children: [u32; WIDTH],
}

/// A node of the wide tree, as `Builder::collapse` fills it.
trait WideNode {
    const WIDTH: usize;
    /// Every slot empty.
    fn empty() -> Self;
    fn set_child(&mut self, slot: usize, aabb: &Aabb, reference: u32);
}

impl WideNode for Node4 {
    const WIDTH: usize = WIDTH;

    fn empty() -> Self {
        let (min, max) = (Vec4::INFINITY, Vec4::NEG_INFINITY);
        Node4 {
            bounds: [min, max, min, max, min, max],
            children: [EMPTY; WIDTH],
        }
    }

    fn set_child(&mut self, slot: usize, aabb: &Aabb, reference: u32) {
        for axis in 0..3 {
            self.bounds[2 * axis][slot] = aabb.min[axis];
            self.bounds[2 * axis + 1][slot] = aabb.max[axis];
        }
        self.children[slot] = reference;
    }
}

/// Four triangles for the Möller–Trumbore test with the normal precomputed: v0, e1 = v0 - v1,
/// e2 = v2 - v0 and ng = e1 × e2, each as x, y, z lanes. Exactly three cache lines: the
/// triangles' numbers are kept apart (`BvhAccel::block_first`), since only hits need them.
#[repr(align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
struct TriangleBlock {
    v0: [Vec4; 3],
    e1: [Vec4; 3],
    e2: [Vec4; 3],
    ng: [Vec4; 3],
}

/// A ray prepared for the box test: which bound is near on each axis, the origin and the
/// reciprocal direction.
///
/// A zero direction component gives an infinite reciprocal, and the slab (bound − o) · inv is
/// then ±inf (the ray is inside or outside the slab forever) or, for an origin exactly on the
/// bound, NaN. The slabs are combined with the running value as the *second* operand of
/// `max`/`min`, which SSE's maxps/minps (and `f32::max`) return when the first is NaN: a NaN
/// slab then leaves the interval unconstrained, as a ray lying in the slab's plane should.
struct BoxRay {
    near: [usize; 3],
    far: [usize; 3],
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
}

impl BoxRay {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let inv = Vec3A::ONE / ray.direction;
        let (near, far) = near_and_far_bounds(inv);
        BoxRay {
            near,
            far,
            origin: splat3(ray.origin),
            inv_direction: splat3(inv),
        }
    }

    /// Entry distances of the four children and which of them the ray enters in [tmin, tmax].
    #[inline(always)]
    fn intersect(&self, node: &Node4, tmin: f32, tmax: f32) -> (Vec4, u32) {
        let slab = |bound: usize, axis: usize| {
            (node.bounds[bound] - self.origin[axis]) * self.inv_direction[axis]
        };
        let t_near = slab(self.near[2], 2)
            .max(slab(self.near[1], 1).max(slab(self.near[0], 0).max(Vec4::splat(tmin))));
        let t_far = slab(self.far[2], 2)
            .min(slab(self.far[1], 1).min(slab(self.far[0], 0).min(Vec4::splat(tmax))));
        (t_near, t_near.cmple(t_far).bitmask())
    }
}

/// For a ray with reciprocal direction `inv`, the rows of a node's bounds (`2 * axis` minima,
/// `2 * axis + 1` maxima) it meets first and last on each axis.
#[inline(always)]
fn near_and_far_bounds(inv: Vec3A) -> ([usize; 3], [usize; 3]) {
    // The sign bit, so -0 (inv = -inf) counts as negative.
    let near = |axis: usize| 2 * axis + inv[axis].is_sign_negative() as usize;
    (
        [near(0), near(1), near(2)],
        [near(0) ^ 1, near(1) ^ 1, near(2) ^ 1],
    )
}

/// The ray against four triangles: (t, u, v) per lane and the lanes hit within [tmin, tmax].
#[inline(always)]
fn intersect_block(
    block: &TriangleBlock,
    origin: &[Vec4; 3],
    direction: &[Vec4; 3],
    tmin: f32,
    tmax: f32,
) -> (Vec4, Vec4, Vec4, BVec4A) {
    let dot = |a: &[Vec4; 3], b: &[Vec4; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let c = [
        block.v0[0] - origin[0],
        block.v0[1] - origin[1],
        block.v0[2] - origin[2],
    ];
    let r = [
        direction[1] * c[2] - direction[2] * c[1],
        direction[2] * c[0] - direction[0] * c[2],
        direction[0] * c[1] - direction[1] * c[0],
    ];
    let inv_det = Vec4::ONE / dot(&block.ng, direction);
    let u = dot(&r, &block.e2) * inv_det;
    let v = dot(&r, &block.e1) * inv_det;
    let t = dot(&block.ng, &c) * inv_det;
    // Comparisons written so NaN (a zero lane, or det = 0) fails them all.
    let hit = u.cmpge(Vec4::ZERO)
        & v.cmpge(Vec4::ZERO)
        & (u + v).cmple(Vec4::ONE)
        & t.cmpge(Vec4::splat(tmin))
        & t.cmple(Vec4::splat(tmax));
    (t, u, v, hit)
}

// What `BvhAccel::prefetch` relies on.
const _: () = assert!(align_of::<Node4>() == 64 && size_of::<Node4>().is_multiple_of(64));
const _: () =
    assert!(align_of::<TriangleBlock>() == 64 && size_of::<TriangleBlock>().is_multiple_of(64));

/// The first block of leaf `reference` and how many it has.
#[inline(always)]
fn leaf_span(reference: u32) -> (usize, usize) {
    let first = (reference & !(LEAF_BIT | TWO_BLOCKS_BIT)) as usize;
    (first, 1 + (reference & TWO_BLOCKS_BIT != 0) as usize)
}

fn splat3(v: Vec3A) -> [Vec4; 3] {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

#[derive(PartialEq)]
enum Nodes {
    Four(Vec<Node4>),
    /// Only built on CPUs with AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    Eight(Vec<avx2::Node8>),
}

pub struct BvhAccel {
    nodes: Nodes,
    blocks: Vec<TriangleBlock>,
    /// Per block, the leaf-order index of its lane 0; lane i is `first + i`.
    block_first: Vec<u32>,
    /// The root: a node index, a leaf block (`LEAF_BIT`) or `EMPTY`.
    root: u32,
    /// For each leaf-order triangle, its index in the list the BVH was built from.
    build_order: Vec<u32>,
}

/// The state of the collapse from the binary tree.
struct Builder<'a> {
    bvh2: &'a Bvh2,
    /// Per binary node, `plan_slots`'s answer for 1..=width slots.
    plans: Vec<[SlotPlan; 8]>,
    vertices: &'a [[Vec3A; 3]],
    blocks: Vec<TriangleBlock>,
    block_first: Vec<u32>,
    build_order: Vec<u32>,
}

/// How a binary subtree fills at most i slots of a wide node, at the least surface area
/// heuristic cost: as one slot (a leaf, or a wide node of its own: `split` 0), or split
/// between its children, `split` slots to the left one and the rest to the right one.
#[derive(Clone, Copy, Debug, Default)]
struct SlotPlan {
    cost: f32,
    split: u8,
}

/// SAH cost of a wide node's box test, relative to a block's triangle test. (Every binary
/// leaf becomes one leaf of the wide tree, so only the node cost steers the plan.)
const NODE_COST: f32 = 1.0;
const BLOCK_COST: f32 = 1.0;

impl Builder<'_> {
    /// Fills `plans` for the subtree of binary node `index` (Ylitie et al. 2017's dynamic
    /// programme for wide BVHs, with the binary leaves kept as they are).
    fn plan_slots(&mut self, index: usize, width: usize) {
        let node = &self.bvh2.nodes[index];
        let area = node.aabb.half_area();
        if node.prim_count > 0 {
            let blocks = (node.prim_count as usize).div_ceil(WIDTH) as f32;
            self.plans[index] = [SlotPlan {
                cost: area * BLOCK_COST * blocks,
                split: 0,
            }; 8];
            return;
        }
        let (left, right) = (node.first_index as usize, node.first_index as usize + 1);
        self.plan_slots(left, width);
        self.plan_slots(right, width);
        // The best split of i slots between the children, for i = 2..=width.
        let mut split_plans = [SlotPlan {
            cost: f32::INFINITY,
            split: 0,
        }; 8];
        for slots in 2..=width {
            for to_left in 1..slots {
                let cost = self.plans[left][to_left - 1].cost
                    + self.plans[right][slots - to_left - 1].cost;
                if cost < split_plans[slots - 1].cost {
                    split_plans[slots - 1] = SlotPlan {
                        cost,
                        split: to_left as u8,
                    };
                }
            }
        }
        let whole = SlotPlan {
            cost: area * NODE_COST + split_plans[width - 1].cost,
            split: 0,
        };
        let plans = &mut self.plans[index];
        plans[0] = whole;
        for slots in 2..=width {
            let split = split_plans[slots - 1];
            // Ties split: at the full width the split always wins (whole adds a node), so a
            // wide node always has a split to follow, even over boxes of zero area.
            plans[slots - 1] = if split.cost <= whole.cost {
                split
            } else {
                whole
            };
        }
    }

    /// Appends the binary nodes that fill `slots` slots for the subtree of `index`.
    fn gather(&self, index: usize, slots: usize, out: &mut Vec<usize>) {
        let plan = self.plans[index][slots - 1];
        if plan.split == 0 {
            out.push(index);
        } else {
            let left = self.bvh2.nodes[index].first_index as usize;
            self.gather(left, plan.split as usize, out);
            self.gather(left + 1, slots - plan.split as usize, out);
        }
    }

    /// The wide subtree of binary node `index`, appended to `nodes`: its reference, and the
    /// traversal stack entries a closest-hit query in it needs at most.
    fn collapse<N: WideNode>(&mut self, nodes: &mut Vec<N>, index: usize) -> (u32, usize) {
        let bvh2 = self.bvh2;
        let node = &bvh2.nodes[index];
        if node.prim_count > 0 {
            return (self.leaf_block(index), 0);
        }
        let mut open = Vec::with_capacity(N::WIDTH);
        // The children the cost-based plan gives this wide node.
        self.gather(index, N::WIDTH, &mut open);
        let me = nodes.len();
        nodes.push(N::empty());
        let mut deepest_need = 0;
        for (slot, &child) in open.iter().enumerate() {
            let (reference, need) = self.collapse(nodes, child);
            deepest_need = deepest_need.max(need);
            nodes[me].set_child(slot, &bvh2.nodes[child].aabb, reference);
        }
        // The query goes on with one child and pushes the others.
        (me as u32, deepest_need + open.len() - 1)
    }

    /// Packs the triangles of binary leaf `index` into one block, or two of about equal
    /// size; returns its reference.
    fn leaf_block(&mut self, index: usize) -> u32 {
        let node = &self.bvh2.nodes[index];
        let first = node.first_index as usize;
        let ids = &self.bvh2.primitive_indices[first..first + node.prim_count as usize];
        assert!(
            ids.len() <= 2 * WIDTH,
            "obvhs made a leaf larger than asked"
        );
        let reference = self.blocks.len() as u32 | LEAF_BIT;
        assert!(reference & TWO_BLOCKS_BIT == 0, "too many leaf blocks");
        if ids.len() <= WIDTH {
            self.push_block(ids);
            reference
        } else {
            let (a, b) = ids.split_at(ids.len().div_ceil(2));
            self.push_block(a);
            self.push_block(b);
            reference | TWO_BLOCKS_BIT
        }
    }

    fn push_block(&mut self, ids: &[u32]) {
        let mut block = TriangleBlock {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            ng: [Vec4::ZERO; 3],
        };
        self.block_first.push(self.build_order.len() as u32);
        for (lane, &id) in ids.iter().enumerate() {
            let [v0, v1, v2] = self.vertices[id as usize];
            let e1 = v0 - v1;
            let e2 = v2 - v0;
            let ng = e1.cross(e2);
            for axis in 0..3 {
                block.v0[axis][lane] = v0[axis];
                block.e1[axis][lane] = e1[axis];
                block.e2[axis][lane] = e2[axis];
                block.ng[axis][lane] = ng[axis];
            }
            self.build_order.push(id);
        }
        self.blocks.push(block);
    }
}

impl BvhAccel {
    /// Builds over triangles given as vertex triples, none of them degenerate, as wide as the
    /// CPU supports (or as [`with_bvh_width`] asks).
    pub fn build(vertices: &[[Vec3A; 3]]) -> Result<Self> {
        let width = FORCED_WIDTH.get().unwrap_or_else(BvhWidth::best);
        Self::build_with_width(vertices, width)
    }

    /// Builds `width` wide, or 4-wide if the CPU does not support `width`.
    pub(crate) fn build_with_width(vertices: &[[Vec3A; 3]], width: BvhWidth) -> Result<Self> {
        let width = if width.is_supported() {
            width
        } else {
            BvhWidth::Four
        };
        if vertices.is_empty() {
            return Ok(BvhAccel {
                nodes: Nodes::Four(Vec::new()),
                blocks: Vec::new(),
                block_first: Vec::new(),
                root: EMPTY,
                build_order: Vec::new(),
            });
        }
        let tris: Vec<Triangle> = vertices
            .iter()
            .map(|&[v0, v1, v2]| Triangle { v0, v1, v2 })
            .collect();
        // Reinsertion over every node (ratio 1 instead of the preset's 0.05) makes the tree
        // fit cluttered scenes far better: on the traversal bench's 70k-triangle room, 3.0x
        // the camera-ray rate and 2.4x on bounce and random rays, for 7x the build time
        // (0.03 -> 0.22 s; the 1.2M-triangle terrain: 0.55 -> 3.8 s, single-threaded; obvhs
        // now builds on rayon's threads, 2 cores halve it).
        // The 8-wide tree takes leaves of up to two blocks: on the terrain, 30% fewer nodes
        // (they average only ~4.3 children: the bottom nodes hold few leaves) and ~7% more
        // random rays per second; the room is unchanged.
        let params = BvhBuildParams {
            max_prims_per_leaf: match width {
                BvhWidth::Four => WIDTH as u32,
                BvhWidth::Eight => 2 * WIDTH as u32,
            },
            reinsertion_batch_ratio: 1.0,
            ..BvhBuildParams::medium_build()
        };
        let bvh2 = build_bvh2_from_tris(&tris, params, &mut Duration::default());
        let mut builder = Builder {
            bvh2: &bvh2,
            plans: vec![[SlotPlan::default(); 8]; bvh2.nodes.len()],
            vertices,
            blocks: Vec::new(),
            block_first: Vec::new(),
            build_order: Vec::with_capacity(vertices.len()),
        };
        let (nodes, (root, stack_need)) = match width {
            BvhWidth::Four => {
                let mut nodes = Vec::new();
                builder.plan_slots(0, 4);
                let root = builder.collapse(&mut nodes, 0);
                (Nodes::Four(in_huge_pages(nodes)), root)
            }
            #[cfg(target_arch = "x86_64")]
            BvhWidth::Eight => {
                let mut nodes = Vec::new();
                builder.plan_slots(0, 8);
                let root = builder.collapse(&mut nodes, 0);
                (Nodes::Eight(in_huge_pages(nodes)), root)
            }
            #[cfg(not(target_arch = "x86_64"))]
            BvhWidth::Eight => unreachable!("8-wide needs x86-64"),
        };
        // Occlusion queries push the root too.
        if stack_need + 1 > STACK_SIZE {
            return Err(Error::new(
                MLT_STATUS_INTERNAL_ERROR,
                format!(
                    "the BVH over these {} triangles needs a traversal stack of {} entries; at most {STACK_SIZE} are supported",
                    vertices.len(),
                    stack_need + 1
                ),
            ));
        }
        Ok(BvhAccel {
            nodes,
            blocks: in_huge_pages(builder.blocks),
            block_first: in_huge_pages(builder.block_first),
            root,
            build_order: in_huge_pages(builder.build_order),
        })
    }

    /// Children per node.
    #[doc(hidden)]
    pub fn width(&self) -> BvhWidth {
        match self.nodes {
            Nodes::Four(_) => BvhWidth::Four,
            #[cfg(target_arch = "x86_64")]
            Nodes::Eight(_) => BvhWidth::Eight,
        }
    }

    pub fn internal_to_build_order(&self) -> &[u32] {
        &self.build_order
    }

    /// Bytes allocated for the structure: nodes, triangle blocks and the index maps.
    pub fn memory_bytes(&self) -> usize {
        fn allocated<T>(items: &Vec<T>) -> usize {
            items.capacity() * size_of::<T>()
        }
        let nodes = match &self.nodes {
            Nodes::Four(nodes) => allocated(nodes),
            #[cfg(target_arch = "x86_64")]
            Nodes::Eight(nodes) => allocated(nodes),
        };
        nodes
            + allocated(&self.blocks)
            + allocated(&self.block_first)
            + allocated(&self.build_order)
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match &self.nodes {
            Nodes::Four(nodes) => self.intersect4(nodes, ray),
            // SAFETY: `Nodes::Eight` is only built on CPUs with AVX2 and FMA
            // (`build_with_width`), which `intersect8` needs.
            #[cfg(target_arch = "x86_64")]
            Nodes::Eight(nodes) => unsafe { self.intersect8(nodes, ray) },
        }
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match &self.nodes {
            Nodes::Four(nodes) => self.occluded4(nodes, ray),
            // SAFETY: as in `intersect`.
            #[cfg(target_arch = "x86_64")]
            Nodes::Eight(nodes) => unsafe { self.occluded8(nodes, ray) },
        }
    }

    /// Tests leaf block `reference` and narrows `tmax` to its closest hit in [tmin, tmax].
    #[inline(always)]
    fn intersect_leaf(
        &self,
        reference: u32,
        origin: &[Vec4; 3],
        direction: &[Vec4; 3],
        tmin: f32,
        tmax: &mut f32,
        best: &mut Option<Hit>,
    ) {
        let (index, blocks) = self.leaf_blocks(reference);
        for (block, &first) in blocks.iter().zip(&self.block_first[index..]) {
            let (t, u, v, hit) = intersect_block(block, origin, direction, tmin, *tmax);
            let mut mask = hit.bitmask();
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if t[lane] <= *tmax {
                    *tmax = t[lane];
                    *best = Some(Hit {
                        triangle: first + lane as u32,
                        t: t[lane],
                        u: u[lane],
                        v: v[lane],
                    });
                }
            }
        }
    }

    /// The blocks of leaf `reference`, and the index of the first.
    #[inline(always)]
    fn leaf_blocks(&self, reference: u32) -> (usize, &[TriangleBlock]) {
        let (first, count) = leaf_span(reference);
        (first, &self.blocks[first..first + count])
    }

    /// Starts loading child `reference` of a node (a node or a leaf's blocks) from memory.
    ///
    /// Traversals call it for every child a ray enters, as they sort or push them: the ray
    /// goes on with one, and the siblings it visits afterwards are then already on their way
    /// instead of each waiting for memory in turn. On the 1.2M-triangle terrain of the
    /// traversal bench (87 MB, beyond the caches) random rays spent about half their time
    /// stalled on the first load of a node or block; this bought +15% on closest-hit and
    /// +20% on occlusion rays there. Scenes that fit in cache lose nothing measurable.
    #[inline(always)]
    fn prefetch<N>(&self, nodes: &[N], reference: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            // Pointer arithmetic that cannot fault: a prefetch of any address is harmless,
            // and the build only stores references inside the arrays.
            let (start, bytes) = if reference & LEAF_BIT == 0 {
                let node = nodes.as_ptr().wrapping_add(reference as usize);
                (node.cast::<i8>(), size_of::<N>())
            } else {
                let (first, count) = leaf_span(reference);
                let block = self.blocks.as_ptr().wrapping_add(first);
                (block.cast::<i8>(), count * size_of::<TriangleBlock>())
            };
            // Nodes and blocks are 64-byte aligned and sized (asserted at compile time), so these are
            // their lines.
            for offset in (0..bytes).step_by(64) {
                // SAFETY: a prefetch is a hint that never faults or changes memory; SSE,
                // which it needs, is part of x86-64.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (nodes, reference);
    }

    #[inline(always)]
    fn intersect4(&self, nodes: &[Node4], ray: &Ray) -> Option<Hit> {
        if self.root == EMPTY {
            return None;
        }
        let box_ray = BoxRay::new(ray);
        let origin = splat3(ray.origin);
        let direction = splat3(ray.direction);
        let mut tmax = ray.tmax;
        let mut best: Option<Hit> = None;
        let mut stack = TraversalStack::<(u32, f32)>::new();
        let mut current = self.root;
        loop {
            if current & LEAF_BIT == 0 {
                let node = &nodes[current as usize];
                let (t_near, mask) = box_ray.intersect(node, ray.tmin, tmax);
                if mask != 0 {
                    current = stack.descend(mask, &node.children, &t_near.to_array(), |child| {
                        self.prefetch(nodes, child)
                    });
                    continue;
                }
            } else {
                self.intersect_leaf(current, &origin, &direction, ray.tmin, &mut tmax, &mut best);
            }
            match stack.pop_within(tmax) {
                Some(next) => current = next,
                None => return best,
            }
        }
    }

    #[inline(always)]
    fn occluded4(&self, nodes: &[Node4], ray: &Ray) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let box_ray = BoxRay::new(ray);
        let origin = splat3(ray.origin);
        let direction = splat3(ray.direction);
        let mut stack = TraversalStack::<u32>::new();
        stack.push(self.root);
        while let Some(current) = stack.pop() {
            if current & LEAF_BIT == 0 {
                let node = &nodes[current as usize];
                let (_, mut mask) = box_ray.intersect(node, ray.tmin, ray.tmax);
                while mask != 0 {
                    let slot = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    self.prefetch(nodes, node.children[slot]);
                    stack.push(node.children[slot]);
                }
            } else if self.leaf_blocked(current, &origin, &direction, ray.tmin, ray.tmax) {
                return true;
            }
        }
        false
    }

    /// Whether leaf block `reference` has a hit in [tmin, tmax].
    #[inline(always)]
    fn leaf_blocked(
        &self,
        reference: u32,
        origin: &[Vec4; 3],
        direction: &[Vec4; 3],
        tmin: f32,
        tmax: f32,
    ) -> bool {
        self.leaf_blocks(reference).1.iter().any(|block| {
            intersect_block(block, origin, direction, tmin, tmax)
                .3
                .any()
        })
    }
}

/// The 8-wide tree, tested with AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::*;
    use std::arch::x86_64::*;

    /// Eight child boxes, as in `Node4`: `bounds[2 * axis]` their minima along the axis,
    /// `bounds[2 * axis + 1]` their maxima; empty slots have min = +inf, max = -inf. Aligned
    /// to cache lines (for `BvhAccel::prefetch`), so each row is one aligned 32-byte load.
    #[repr(C, align(64))]
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub(super) struct Node8 {
        bounds: [[f32; 8]; 6],
        children: [u32; 8],
    }

    #[cfg(test)]
    impl Node8 {
        pub(super) fn children(&self) -> &[u32; 8] {
            &self.children
        }
    }

    // What `BvhAccel::prefetch` relies on.
    const _: () = assert!(align_of::<Node8>() == 64 && size_of::<Node8>().is_multiple_of(64));

    impl WideNode for Node8 {
        const WIDTH: usize = 8;

        fn empty() -> Self {
            let (min, max) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
            Node8 {
                bounds: [min, max, min, max, min, max],
                children: [EMPTY; 8],
            }
        }

        fn set_child(&mut self, slot: usize, aabb: &Aabb, reference: u32) {
            for axis in 0..3 {
                self.bounds[2 * axis][slot] = aabb.min[axis];
                self.bounds[2 * axis + 1][slot] = aabb.max[axis];
            }
            self.children[slot] = reference;
        }
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn load(row: &[f32; 8]) -> __m256 {
        // SAFETY: reads the eight floats `row` refers to (unaligned load, no alignment needed).
        unsafe { _mm256_loadu_ps(row.as_ptr()) }
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn lanes(v: __m256) -> [f32; 8] {
        // SAFETY: both are 32 bytes of eight f32, and every bit pattern is a valid f32.
        unsafe { std::mem::transmute::<__m256, [f32; 8]>(v) }
    }

    /// `BoxRay` for eight boxes, with each slab computed as one fused bound · inv − origin · inv.
    ///
    /// For a zero direction component (inv = ±inf) the fused form gives the slab's ±inf only
    /// when the bound and the origin have opposite signs, and NaN otherwise (inf − inf, or
    /// 0 · inf). NaN slabs leave the interval unconstrained, as in `BoxRay`: such a ray is
    /// culled by the other two axes only, never wrongly. A direction of all zeros would leave
    /// empty slots unculled, so such rays are answered before the traversal.
    struct BoxRay8 {
        near: [usize; 3],
        far: [usize; 3],
        inv_direction: [__m256; 3],
        origin_inv: [__m256; 3],
    }

    impl BoxRay8 {
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn new(ray: &Ray) -> Self {
            let inv = Vec3A::ONE / ray.direction;
            let origin_inv = ray.origin * inv;
            let (near, far) = near_and_far_bounds(inv);
            BoxRay8 {
                near,
                far,
                inv_direction: inv.to_array().map(|v| _mm256_set1_ps(v)),
                origin_inv: origin_inv.to_array().map(|v| _mm256_set1_ps(v)),
            }
        }

        /// Entry distances of the eight children and which of them the ray enters in
        /// [tmin, tmax]. The running value is the second operand of max/min, which vmaxps and
        /// vminps return when the first is NaN.
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn intersect(&self, node: &Node8, tmin: __m256, tmax: __m256) -> (__m256, u32) {
            let slab = |bound: usize, axis: usize| {
                _mm256_fmsub_ps(
                    load(&node.bounds[bound]),
                    self.inv_direction[axis],
                    self.origin_inv[axis],
                )
            };
            let t_near = _mm256_max_ps(
                slab(self.near[2], 2),
                _mm256_max_ps(
                    slab(self.near[1], 1),
                    _mm256_max_ps(slab(self.near[0], 0), tmin),
                ),
            );
            let t_far = _mm256_min_ps(
                slab(self.far[2], 2),
                _mm256_min_ps(
                    slab(self.far[1], 1),
                    _mm256_min_ps(slab(self.far[0], 0), tmax),
                ),
            );
            let entered = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far);
            (t_near, _mm256_movemask_ps(entered) as u32)
        }
    }

    impl BvhAccel {
        #[target_feature(enable = "avx2,fma")]
        pub(super) fn intersect8(&self, nodes: &[Node8], ray: &Ray) -> Option<Hit> {
            if self.root == EMPTY || ray.direction == Vec3A::ZERO {
                return None;
            }
            let box_ray = BoxRay8::new(ray);
            let tmin = _mm256_set1_ps(ray.tmin);
            let origin = splat3(ray.origin);
            let direction = splat3(ray.direction);
            let mut tmax = ray.tmax;
            let mut best: Option<Hit> = None;
            let mut stack = TraversalStack::<(u32, f32)>::new();
            let mut current = self.root;
            loop {
                if current & LEAF_BIT == 0 {
                    let node = &nodes[current as usize];
                    let (t_near, mask) = box_ray.intersect(node, tmin, _mm256_set1_ps(tmax));
                    if mask != 0 {
                        current = stack.descend(mask, &node.children, &lanes(t_near), |child| {
                            self.prefetch(nodes, child)
                        });
                        continue;
                    }
                } else {
                    self.intersect_leaf(
                        current, &origin, &direction, ray.tmin, &mut tmax, &mut best,
                    );
                }
                match stack.pop_within(tmax) {
                    Some(next) => current = next,
                    None => return best,
                }
            }
        }

        #[target_feature(enable = "avx2,fma")]
        pub(super) fn occluded8(&self, nodes: &[Node8], ray: &Ray) -> bool {
            if self.root == EMPTY || ray.direction == Vec3A::ZERO {
                return false;
            }
            let box_ray = BoxRay8::new(ray);
            let (tmin, tmax) = (_mm256_set1_ps(ray.tmin), _mm256_set1_ps(ray.tmax));
            let origin = splat3(ray.origin);
            let direction = splat3(ray.direction);
            let mut stack = TraversalStack::<u32>::new();
            stack.push(self.root);
            while let Some(current) = stack.pop() {
                if current & LEAF_BIT == 0 {
                    let node = &nodes[current as usize];
                    let (_, mut mask) = box_ray.intersect(node, tmin, tmax);
                    while mask != 0 {
                        let slot = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        self.prefetch(nodes, node.children[slot]);
                        stack.push(node.children[slot]);
                    }
                } else if self.leaf_blocked(current, &origin, &direction, ray.tmin, ray.tmax) {
                    return true;
                }
            }
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn random_point(rng: &mut Rng) -> Vec3A {
        Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0 - 5.0
    }

    /// The scalar form of the block test, for the brute-force reference.
    fn intersect_one(tri: &[Vec3A; 3], o: Vec3A, d: Vec3A, tmin: f32, tmax: f32) -> Option<f32> {
        let [v0, v1, v2] = *tri;
        let (e1, e2) = (v0 - v1, v2 - v0);
        let ng = e1.cross(e2);
        let c = v0 - o;
        let r = d.cross(c);
        let inv_det = 1.0 / ng.dot(d);
        let (u, v, t) = (
            r.dot(e2) * inv_det,
            r.dot(e1) * inv_det,
            ng.dot(c) * inv_det,
        );
        (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= tmin && t <= tmax).then_some(t)
    }

    fn two_block_leaves(accel: &BvhAccel) -> usize {
        let two_blocks = |&&c: &&u32| c != EMPTY && c & LEAF_BIT != 0 && c & TWO_BLOCKS_BIT != 0;
        match &accel.nodes {
            Nodes::Four(nodes) => nodes
                .iter()
                .flat_map(|n| &n.children)
                .filter(two_blocks)
                .count(),
            #[cfg(target_arch = "x86_64")]
            Nodes::Eight(nodes) => nodes
                .iter()
                .flat_map(|n| n.children())
                .filter(two_blocks)
                .count(),
        }
    }

    /// The widths this CPU can build: both on x86-64 with AVX2 and FMA.
    fn widths() -> Vec<BvhWidth> {
        [BvhWidth::Four, BvhWidth::Eight]
            .into_iter()
            .filter(|w| w.is_supported())
            .collect()
    }

    /// obvhs builds in parallel (rayon); the tree, and so which of two equally near
    /// triangles a ray reports, must not depend on the threads. (150k triangles: obvhs
    /// switches to its parallel Morton sort above 100k.)
    #[test]
    fn builds_the_same_tree_on_any_thread_count() {
        let mut rng = Rng::new(5, 0);
        let triangles: Vec<[Vec3A; 3]> = (0..150_000)
            .map(|_| {
                let p = random_point(&mut rng);
                [0; 3].map(|_| p + (random_point(&mut rng) * 0.02))
            })
            .collect();
        for width in widths() {
            let build_on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                pool.install(|| BvhAccel::build_with_width(&triangles, width).unwrap())
            };
            let one = build_on(1);
            for threads in [2, 3, 8] {
                let many = build_on(threads);
                assert!(
                    one.nodes == many.nodes,
                    "{width:?}, {threads} threads: nodes"
                );
                assert!(
                    one.blocks == many.blocks,
                    "{width:?}, {threads} threads: blocks"
                );
                assert_eq!(
                    one.build_order, many.build_order,
                    "{width:?}, {threads} threads"
                );
                assert_eq!(one.root, many.root);
            }
        }
    }

    #[test]
    fn builds_the_widest_supported_unless_forced() {
        let tris = [[Vec3A::ZERO, Vec3A::X, Vec3A::Y]; 40];
        assert_eq!(BvhAccel::build(&tris).unwrap().width(), BvhWidth::best());
        let forced = with_bvh_width(BvhWidth::Four, || BvhAccel::build(&tris).unwrap());
        assert_eq!(forced.width(), BvhWidth::Four);
        assert_eq!(BvhAccel::build(&tris).unwrap().width(), BvhWidth::best());
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            assert_eq!(BvhWidth::best(), BvhWidth::Eight);
        }
    }

    /// The BVH must return what testing every triangle returns, for scenes of every size
    /// (a lone leaf as root, partly filled nodes and blocks, deep trees), at every width.
    #[test]
    fn matches_brute_force() {
        for width in widths() {
            matches_brute_force_at(width);
        }
    }

    fn matches_brute_force_at(width: BvhWidth) {
        let mut rng = Rng::new(5, 5);
        for count in [1, 3, 5, 9, 17, 40, 500, 5000] {
            let tris: Vec<[Vec3A; 3]> = (0..count)
                .map(|_| {
                    let c = random_point(&mut rng);
                    [
                        c,
                        c + random_point(&mut rng) * 0.2,
                        c + random_point(&mut rng) * 0.2,
                    ]
                })
                .collect();
            let accel = BvhAccel::build_with_width(&tris, width).unwrap();
            assert_eq!(accel.width(), width);
            let mut sorted = accel.build_order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..count as u32).collect::<Vec<_>>());
            let mut hits = 0;
            for _ in 0..20_000 {
                let o = random_point(&mut rng) * 1.5;
                let d = (random_point(&mut rng)).normalize();
                let ray = Ray::new(o, d, 1e-3, f32::INFINITY);
                let mut best: Option<(f32, usize)> = None;
                for (i, tri) in tris.iter().enumerate() {
                    if let Some(t) = intersect_one(tri, o, d, 1e-3, f32::INFINITY)
                        && best.is_none_or(|(bt, _)| t < bt)
                    {
                        best = Some((t, i));
                    }
                }
                let hit = accel.intersect(&ray);
                match (best, hit) {
                    (None, None) => {}
                    (Some((t, i)), Some(h)) => {
                        hits += 1;
                        assert_eq!(accel.build_order[h.triangle as usize] as usize, i);
                        assert!((h.t - t).abs() <= 1e-4 * t.max(1.0));
                        let [a, b, c] = tris[i];
                        let p = a * (1.0 - h.u - h.v) + b * h.u + c * h.v;
                        assert!((p - (o + d * h.t)).length() < 1e-3);
                    }
                    other => panic!("{width:?}, {count} triangles: mismatch {other:?}"),
                }
                assert_eq!(accel.occluded(&ray), best.is_some());
                // A segment that ends before the closest hit is not blocked by it.
                if let Some((t, _)) = best {
                    let short = Ray::new(o, d, 1e-3, t * 0.999);
                    let blocked = accel.occluded(&short);
                    let expected = tris
                        .iter()
                        .any(|tri| intersect_one(tri, o, d, 1e-3, t * 0.999).is_some());
                    assert_eq!(blocked, expected);
                }
            }
            if count >= 500 {
                assert!(hits > 1000, "{width:?}, {count} triangles: {hits} hits");
            }
            if width == BvhWidth::Eight && count == 5000 {
                assert!(two_block_leaves(&accel) > 0, "two-block leaves are tested");
            }
        }
    }

    /// Rays along the axes (zero direction components) from origins on box planes, at every
    /// width; and rays with no direction at all, which hit nothing.
    #[test]
    fn axis_aligned_rays_from_box_planes() {
        let square = |z: f32| {
            [
                [
                    Vec3A::new(0.0, 0.0, z),
                    Vec3A::new(1.0, 0.0, z),
                    Vec3A::new(1.0, 1.0, z),
                ],
                [
                    Vec3A::new(0.0, 0.0, z),
                    Vec3A::new(1.0, 1.0, z),
                    Vec3A::new(0.0, 1.0, z),
                ],
            ]
        };
        // 8 squares: one 8-wide node over leaves; 40: two levels, partly filled.
        for squares in [8, 40] {
            let tris: Vec<[Vec3A; 3]> = (0..squares).flat_map(|i| square(i as f32)).collect();
            for width in widths() {
                let accel = BvhAccel::build_with_width(&tris, width).unwrap();
                // From x = 0 and y = 0 (the boxes' own planes), straight along +z.
                let ray = Ray::new(Vec3A::new(0.0, 0.25, -1.0), Vec3A::Z, 0.0, f32::INFINITY);
                let hit = accel.intersect(&ray).expect("the first square");
                assert_eq!(hit.t, 1.0, "{width:?}");
                let ray = Ray::new(Vec3A::new(0.5, 0.0, 2.5), -Vec3A::Z, 0.0, f32::INFINITY);
                assert_eq!(accel.intersect(&ray).map(|h| h.t), Some(0.5), "{width:?}");
                // From the far corner's planes (x = 1, y = 1), along -z.
                let far_corner = Vec3A::new(1.0, 1.0, squares as f32 + 0.5);
                let ray = Ray::new(far_corner, -Vec3A::Z, 0.0, f32::INFINITY);
                assert_eq!(accel.intersect(&ray).map(|h| h.t), Some(1.5), "{width:?}");
                let ray = Ray::new(Vec3A::new(0.5, 0.5, 2.5), -Vec3A::Z, 0.0, 0.4);
                assert!(!accel.occluded(&ray), "{width:?}");
                let ray = Ray::new(Vec3A::new(0.5, 0.5, 2.5), -Vec3A::Z, 0.0, 0.5);
                assert!(accel.occluded(&ray), "{width:?}");
                // Along x and y inside the squares' planes: grazing, so no hit.
                let ray = Ray::new(Vec3A::new(-1.0, 0.5, 3.0), Vec3A::X, 0.0, f32::INFINITY);
                assert_eq!(accel.intersect(&ray), None, "{width:?}");
                let ray = Ray::new(Vec3A::new(0.5, 0.5, 3.0), Vec3A::ZERO, 0.0, f32::INFINITY);
                assert_eq!(accel.intersect(&ray), None, "{width:?}");
                assert!(!accel.occluded(&ray), "{width:?}");
            }
        }
    }
}
