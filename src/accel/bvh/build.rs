//! The build: obvhs builds a binary tree (PLOC with reinsertion and leaf collapsing), which we
//! collapse to a wide one, choosing each wide node's children by the surface area heuristic
//! (a dynamic programme over the binary tree), and pack each binary leaf's triangles into one
//! leaf block, or two consecutive ones in the 8-wide tree.

use super::huge_pages::in_huge_pages;
use super::layout::{LEAF_BIT, TWO_BLOCKS_BIT, TriangleBlock, WIDTH, WideNode, WideTree};
use super::stack::STACK_SIZE;
use crate::error::{Error, MLT_STATUS_INTERNAL_ERROR, Result};
use glam::{Vec3A, Vec4};
use obvhs::{
    BvhBuildParams,
    bvh2::{Bvh2, builder::build_bvh2_from_tris},
    triangle::Triangle,
};
use std::time::Duration;

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
    fn collapse<const W: usize, N: WideNode<W>>(
        &mut self,
        nodes: &mut Vec<N>,
        index: usize,
    ) -> (u32, usize) {
        let bvh2 = self.bvh2;
        let node = &bvh2.nodes[index];
        if node.prim_count > 0 {
            return (self.leaf_block(index), 0);
        }
        let mut open = Vec::with_capacity(W);
        // The children the cost-based plan gives this wide node.
        self.gather(index, W, &mut open);
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

/// Builds the `W`-wide tree over triangles given as vertex triples, at least one and none of
/// them degenerate; returns it and, for each leaf-order triangle, its index in `vertices`.
pub(super) fn build<const W: usize, N: WideNode<W> + Copy>(
    vertices: &[[Vec3A; 3]],
) -> Result<(WideTree<N>, Vec<u32>)> {
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
    let leaf_blocks = if W == 8 { 2 } else { 1 };
    let params = BvhBuildParams {
        max_prims_per_leaf: (leaf_blocks * WIDTH) as u32,
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
    let mut nodes = Vec::new();
    builder.plan_slots(0, W);
    let (root, stack_need) = builder.collapse(&mut nodes, 0);
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
    let tree = WideTree {
        nodes: in_huge_pages(nodes),
        blocks: in_huge_pages(builder.blocks),
        block_first: in_huge_pages(builder.block_first),
        root,
    };
    Ok((tree, in_huge_pages(builder.build_order)))
}
