//! What the tree is made of: wide nodes (`Node4`, and on x86-64 `Node8`), leaf blocks of four
//! triangles, the references that link them, and `WideTree`, the arrays a traversal reads.
//! Nodes and blocks are in structure-of-arrays layout, so one vector instruction tests a ray
//! against all of a node's boxes or a block's four triangles.

use glam::{Vec3A, Vec4};
use obvhs::aabb::Aabb;

/// Triangles per leaf block, and children of a 4-wide node.
pub(super) const WIDTH: usize = 4;
/// A child reference with this bit set is a leaf block index; otherwise a node index.
pub(super) const LEAF_BIT: u32 = 1 << 31;
/// Set in a leaf reference whose triangles fill two consecutive blocks.
pub(super) const TWO_BLOCKS_BIT: u32 = 1 << 30;
/// The reference of an empty child slot (its box is empty, so it is never entered).
pub(super) const EMPTY: u32 = u32::MAX;

/// A tree with nodes `N`, as the build leaves it and the traversal reads it.
#[derive(PartialEq)]
pub(super) struct WideTree<N> {
    pub(super) nodes: Vec<N>,
    pub(super) blocks: Vec<TriangleBlock>,
    /// Per block, the leaf-order index of its lane 0; lane i is `first + i`.
    pub(super) block_first: Vec<u32>,
    /// The root: a node index, a leaf block (`LEAF_BIT`) or `EMPTY`.
    pub(super) root: u32,
}

/// A node of the wide tree, with `W` child slots.
pub(super) trait WideNode<const W: usize> {
    /// Every slot empty.
    fn empty() -> Self;
    fn set_child(&mut self, slot: usize, aabb: &Aabb, reference: u32);
    /// The slots' references: nodes, leaves or `EMPTY`.
    fn children(&self) -> &[u32; W];
    fn children_mut(&mut self) -> &mut [u32; W];
}

/// Four child boxes: `bounds[2 * axis]` their minima along the axis, `bounds[2 * axis + 1]`
/// their maxima. Empty slots have min = +inf, max = -inf. Aligned to cache lines, for
/// `prefetch` in the traversal.
#[repr(align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Node4 {
    pub(super) bounds: [Vec4; 6],
    pub(super) children: [u32; WIDTH],
}

impl WideNode<WIDTH> for Node4 {
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

    #[inline(always)]
    fn children(&self) -> &[u32; WIDTH] {
        &self.children
    }

    fn children_mut(&mut self) -> &mut [u32; WIDTH] {
        &mut self.children
    }
}

/// Eight child boxes, as in `Node4`: `bounds[2 * axis]` their minima along the axis,
/// `bounds[2 * axis + 1]` their maxima; empty slots have min = +inf, max = -inf. Aligned to
/// cache lines (for `prefetch` in the traversal), so each row is one aligned 32-byte load.
/// Only x86-64 CPUs with AVX2 and FMA get 8-wide trees.
#[cfg(target_arch = "x86_64")]
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Node8 {
    pub(super) bounds: [[f32; 8]; 6],
    pub(super) children: [u32; 8],
}

#[cfg(target_arch = "x86_64")]
impl WideNode<8> for Node8 {
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

    #[inline(always)]
    fn children(&self) -> &[u32; 8] {
        &self.children
    }

    fn children_mut(&mut self) -> &mut [u32; 8] {
        &mut self.children
    }
}

/// Four triangles for the Möller–Trumbore test with the normal precomputed: v0, e1 = v0 - v1,
/// e2 = v2 - v0 and ng = e1 × e2, each as x, y, z lanes. Exactly three cache lines: the
/// triangles' numbers are kept apart (`WideTree::block_first`), since only hits need them.
#[repr(align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TriangleBlock {
    pub(super) v0: [Vec4; 3],
    pub(super) e1: [Vec4; 3],
    pub(super) e2: [Vec4; 3],
    pub(super) ng: [Vec4; 3],
}

// What `prefetch` in the traversal relies on: whole cache lines.
const _: () = assert!(align_of::<Node4>() == 64 && size_of::<Node4>().is_multiple_of(64));
#[cfg(target_arch = "x86_64")]
const _: () = assert!(align_of::<Node8>() == 64 && size_of::<Node8>().is_multiple_of(64));
const _: () =
    assert!(align_of::<TriangleBlock>() == 64 && size_of::<TriangleBlock>().is_multiple_of(64));

/// The first block of leaf `reference` and how many it has.
#[inline(always)]
pub(super) fn leaf_span(reference: u32) -> (usize, usize) {
    let first = (reference & !(LEAF_BIT | TWO_BLOCKS_BIT)) as usize;
    (first, 1 + (reference & TWO_BLOCKS_BIT != 0) as usize)
}

/// For a ray with reciprocal direction `inv`, the rows of a node's bounds (`2 * axis` minima,
/// `2 * axis + 1` maxima) it meets first and last on each axis.
#[inline(always)]
pub(super) fn near_and_far_bounds(inv: Vec3A) -> ([usize; 3], [usize; 3]) {
    // The sign bit, so -0 (inv = -inf) counts as negative.
    let near = |axis: usize| 2 * axis + inv[axis].is_sign_negative() as usize;
    (
        [near(0), near(1), near(2)],
        [near(0) ^ 1, near(1) ^ 1, near(2) ^ 1],
    )
}
