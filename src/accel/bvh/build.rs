//! The build: obvhs builds a binary tree (PLOC with reinsertion and leaf collapsing), which we
//! collapse to a wide one, choosing each wide node's children by the surface area heuristic
//! (a dynamic programme over the binary tree), and pack each binary leaf's triangles into one
//! leaf block, or two consecutive ones in the 8-wide tree. The collapse runs on rayon's
//! threads: the top wide levels are laid out first, the subtrees below them collapse in
//! parallel, each into arrays of its own, and are stitched in depth-first order, so the tree
//! is the same whatever the thread count.

use super::huge_pages::in_huge_pages;
use super::layout::{EMPTY, LEAF_BIT, TWO_BLOCKS_BIT, TriangleBlock, WIDTH, WideNode, WideTree};
use super::stack::STACK_SIZE;
use crate::accel::BuildQuality;
use crate::error::{Error, MLT_STATUS_INTERNAL_ERROR, Result};
use glam::{Vec3A, Vec4};
use obvhs::{
    BvhBuildParams,
    bvh2::{Bvh2, builder::build_bvh2_from_tris},
    triangle::Triangle,
};
use rayon::prelude::*;
use std::time::Duration;

/// What the collapse reads: the binary tree, its plans and the triangles.
struct Builder<'a> {
    bvh2: &'a Bvh2,
    /// Per binary node, `plan_slots`'s answer for 1..=width slots.
    plans: Vec<[SlotPlan; 8]>,
    vertices: &'a [[Vec3A; 3]],
}

/// What the collapse writes, in depth-first order: the wide tree's arrays, and for each
/// leaf-order triangle its index in the vertices.
struct Collapsed<N> {
    nodes: Vec<N>,
    blocks: Vec<TriangleBlock>,
    block_first: Vec<u32>,
    build_order: Vec<u32>,
}

impl<N> Collapsed<N> {
    fn new() -> Self {
        Collapsed {
            nodes: Vec::new(),
            blocks: Vec::new(),
            block_first: Vec::new(),
            build_order: Vec::new(),
        }
    }

    /// Appends `part`, collapsed on its own, moving its references past what is already
    /// here; returns `part`'s root reference moved the same way.
    fn append<const W: usize>(&mut self, part: Collapsed<N>, root: u32) -> u32
    where
        N: WideNode<W>,
    {
        let (node_offset, block_offset) = (self.nodes.len() as u32, self.blocks.len() as u32);
        let relocate = |reference: u32| match reference {
            EMPTY => EMPTY,
            leaf if leaf & LEAF_BIT != 0 => leaf + block_offset,
            node => node + node_offset,
        };
        let order_offset = self.build_order.len() as u32;
        self.nodes.extend(part.nodes.into_iter().map(|mut node| {
            for child in node.children_mut() {
                *child = relocate(*child);
            }
            node
        }));
        self.blocks.extend(part.blocks);
        self.block_first
            .extend(part.block_first.iter().map(|first| first + order_offset));
        self.build_order.extend(part.build_order);
        relocate(root)
    }
}

/// Wide levels laid out before the subtrees below them collapse in parallel: up to 64
/// subtrees at either width, enough to keep the threads busy however unequal they are.
const fn parallel_levels(width: usize) -> u32 {
    if width >= 8 { 2 } else { 3 }
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
        // The best split of i slots between the children, for i = 2..=width. Each starts
        // from one slot to the left, so it is a split even when costs are infinite or NaN
        // (boxes whose area overflows): a "split" of 0 would collapse the node into itself.
        let mut split_plans = [SlotPlan {
            cost: f32::INFINITY,
            split: 1,
        }; 8];
        for slots in 2..=width {
            split_plans[slots - 1].cost =
                self.plans[left][0].cost + self.plans[right][slots - 2].cost;
            for to_left in 2..slots {
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
            // wide node always has a split to follow, even over boxes of zero area, or of
            // an area that overflows (NaN costs split too).
            plans[slots - 1] = if whole.cost < split.cost {
                whole
            } else {
                split
            };
        }
    }

    /// The binary nodes the cost-based plan gives the wide node of binary node `index`
    /// (internal), in slot order, and their count.
    fn wide_children(&self, index: usize, width: usize) -> ([usize; 8], usize) {
        let mut children = [0; 8];
        let mut count = 0;
        self.gather(index, width, &mut children, &mut count);
        (children, count)
    }

    /// Appends the binary nodes that fill `slots` slots for the subtree of `index`.
    fn gather(&self, index: usize, slots: usize, out: &mut [usize; 8], count: &mut usize) {
        let plan = self.plans[index][slots - 1];
        if plan.split == 0 {
            out[*count] = index;
            *count += 1;
        } else {
            let left = self.bvh2.nodes[index].first_index as usize;
            self.gather(left, plan.split as usize, out, count);
            self.gather(left + 1, slots - plan.split as usize, out, count);
        }
    }

    fn is_leaf(&self, index: usize) -> bool {
        self.bvh2.nodes[index].prim_count > 0
    }

    /// The binary nodes whose wide subtrees sit `levels` wide levels below `index`, in
    /// depth-first order: the subtrees `collapse_top` leaves to `parts`.
    fn frontier<const W: usize>(&self, index: usize, levels: u32, out: &mut Vec<usize>) {
        if self.is_leaf(index) {
            return;
        }
        if levels == 0 {
            out.push(index);
            return;
        }
        let (children, count) = self.wide_children(index, W);
        for &child in &children[..count] {
            self.frontier::<W>(child, levels - 1, out);
        }
    }

    /// The wide tree of binary node `index`: its top `levels` wide levels laid out here, the
    /// subtrees below them taken in order from `parts` (each collapsed on its own from the
    /// `frontier`, with its root reference and stack need). Returns the tree's reference and
    /// stack need, as `collapse`.
    fn collapse_top<const W: usize, N: WideNode<W>>(
        &self,
        out: &mut Collapsed<N>,
        index: usize,
        levels: u32,
        parts: &mut impl Iterator<Item = (Collapsed<N>, u32, usize)>,
    ) -> (u32, usize) {
        if self.is_leaf(index) {
            return (self.leaf_block(out, index), 0);
        }
        if levels == 0 {
            let (part, root, need) = parts.next().expect("a part per frontier node");
            return (out.append::<W>(part, root), need);
        }
        self.wide_node::<W, N>(out, index, |out, child| {
            self.collapse_top::<W, N>(out, child, levels - 1, parts)
        })
    }

    /// The wide subtree of binary node `index`, appended to `out`: its reference, and the
    /// traversal stack entries a closest-hit query in it needs at most.
    fn collapse<const W: usize, N: WideNode<W>>(
        &self,
        out: &mut Collapsed<N>,
        index: usize,
    ) -> (u32, usize) {
        if self.is_leaf(index) {
            return (self.leaf_block(out, index), 0);
        }
        self.wide_node::<W, N>(out, index, |out, child| self.collapse::<W, N>(out, child))
    }

    /// The wide node of binary node `index` (internal), its children's subtrees appended
    /// after it by `subtree`; its reference and stack need.
    fn wide_node<const W: usize, N: WideNode<W>>(
        &self,
        out: &mut Collapsed<N>,
        index: usize,
        mut subtree: impl FnMut(&mut Collapsed<N>, usize) -> (u32, usize),
    ) -> (u32, usize) {
        let (children, count) = self.wide_children(index, W);
        let me = out.nodes.len();
        out.nodes.push(N::empty());
        let mut deepest_need = 0;
        for (slot, &child) in children[..count].iter().enumerate() {
            let (reference, need) = subtree(out, child);
            deepest_need = deepest_need.max(need);
            out.nodes[me].set_child(slot, &self.bvh2.nodes[child].aabb, reference);
        }
        // The query goes on with one child and pushes the others.
        (me as u32, deepest_need + count - 1)
    }

    /// Packs the triangles of binary leaf `index` into one block, or two of about equal
    /// size, appended to `out`; returns its reference.
    fn leaf_block<N>(&self, out: &mut Collapsed<N>, index: usize) -> u32 {
        let node = &self.bvh2.nodes[index];
        let first = node.first_index as usize;
        let ids = &self.bvh2.primitive_indices[first..first + node.prim_count as usize];
        assert!(
            ids.len() <= 2 * WIDTH,
            "obvhs made a leaf larger than asked"
        );
        let reference = out.blocks.len() as u32 | LEAF_BIT;
        if ids.len() <= WIDTH {
            self.push_block(out, ids);
            reference
        } else {
            let (a, b) = ids.split_at(ids.len().div_ceil(2));
            self.push_block(out, a);
            self.push_block(out, b);
            reference | TWO_BLOCKS_BIT
        }
    }

    fn push_block<N>(&self, out: &mut Collapsed<N>, ids: &[u32]) {
        let mut block = TriangleBlock {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            ng: [Vec4::ZERO; 3],
        };
        out.block_first.push(out.build_order.len() as u32);
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
            out.build_order.push(id);
        }
        out.blocks.push(block);
    }
}

/// obvhs's build parameters for `quality`, with leaves of up to `max_leaf` triangles.
///
/// - High: obvhs's medium preset with reinsertion over every node (ratio 1 instead of
///   0.05), which makes the tree fit cluttered scenes far better: on the traversal bench's
///   70k-triangle room 3.0x the camera-ray rate and 2.4x on bounce and random rays, for 7x
///   the build time.
/// - Medium: obvhs's medium preset with reinsertion over a quarter of the nodes.
/// - Fast: obvhs's fast preset (a narrower PLOC search, reinsertion over 2% of the nodes).
///
/// README "Benchmarks" has the build times and ray rates of each.
fn build_params(quality: BuildQuality, max_leaf: u32) -> BvhBuildParams {
    let preset = match quality {
        BuildQuality::Fast => BvhBuildParams::fast_build(),
        BuildQuality::Medium => BvhBuildParams {
            reinsertion_batch_ratio: 0.25,
            ..BvhBuildParams::medium_build()
        },
        BuildQuality::High => BvhBuildParams {
            reinsertion_batch_ratio: 1.0,
            ..BvhBuildParams::medium_build()
        },
    };
    BvhBuildParams {
        max_prims_per_leaf: max_leaf,
        ..preset
    }
}

/// Builds the `W`-wide tree at `quality` over triangles given as vertex triples, at least one
/// and none of them degenerate; returns it and, for each leaf-order triangle, its index in
/// `vertices`.
pub(super) fn build<const W: usize, N: WideNode<W> + Copy + Send>(
    vertices: &[[Vec3A; 3]],
    quality: BuildQuality,
) -> Result<(WideTree<N>, Vec<u32>)> {
    let tris: Vec<Triangle> = vertices
        .iter()
        .map(|&[v0, v1, v2]| Triangle { v0, v1, v2 })
        .collect();
    // The 8-wide tree takes leaves of up to two blocks: on the terrain, 30% fewer nodes
    // (they average only ~4.3 children: the bottom nodes hold few leaves) and ~7% more
    // random rays per second; the room is unchanged.
    let params = build_params(quality, max_leaf::<W>());
    let bvh2 = build_bvh2_from_tris(&tris, params, &mut Duration::default());
    build_over(&bvh2, vertices)
}

/// Triangles per leaf of the `W`-wide tree.
pub(super) const fn max_leaf<const W: usize>() -> u32 {
    let leaf_blocks = if W == 8 { 2 } else { 1 };
    (leaf_blocks * WIDTH) as u32
}

/// The `W`-wide tree over the binary tree `bvh2` of `vertices`, as `build`.
pub(super) fn build_over<const W: usize, N: WideNode<W> + Copy + Send>(
    bvh2: &Bvh2,
    vertices: &[[Vec3A; 3]],
) -> Result<(WideTree<N>, Vec<u32>)> {
    let mut builder = Builder {
        bvh2,
        plans: vec![[SlotPlan::default(); 8]; bvh2.nodes.len()],
        vertices,
    };
    builder.plan_slots(0, W);
    let builder = &builder;
    let levels = parallel_levels(W);
    let mut frontier = Vec::new();
    builder.frontier::<W>(0, levels, &mut frontier);
    let parts: Vec<(Collapsed<N>, u32, usize)> = frontier
        .par_iter()
        .map(|&index| {
            let mut part = Collapsed::new();
            let (root, need) = builder.collapse::<W, N>(&mut part, index);
            (part, root, need)
        })
        .collect();
    let mut out = Collapsed {
        nodes: Vec::new(),
        blocks: Vec::new(),
        block_first: Vec::new(),
        build_order: Vec::with_capacity(vertices.len()),
    };
    let (root, stack_need) =
        builder.collapse_top::<W, N>(&mut out, 0, levels, &mut parts.into_iter());
    // References hold a block index below the flag bits, a node index below `LEAF_BIT`.
    assert!(
        out.blocks.len() < TWO_BLOCKS_BIT as usize && out.nodes.len() < LEAF_BIT as usize,
        "too many nodes or leaf blocks"
    );
    // Occlusion queries push the root too, and a closest-hit query's `descend` writes a
    // whole node's children above the entries it keeps.
    if stack_need + W > STACK_SIZE {
        return Err(Error::new(
            MLT_STATUS_INTERNAL_ERROR,
            format!(
                "the BVH over these {} triangles needs a traversal stack of {} entries; at most {STACK_SIZE} are supported",
                vertices.len(),
                stack_need + W
            ),
        ));
    }
    let tree = WideTree {
        nodes: in_huge_pages(out.nodes),
        blocks: in_huge_pages(out.blocks),
        block_first: in_huge_pages(out.block_first),
        root,
    };
    Ok((tree, in_huge_pages(out.build_order)))
}
