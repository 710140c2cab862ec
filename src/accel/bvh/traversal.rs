//! How a ray walks the tree, nearest child first: one body for closest-hit queries and one for
//! occlusion, each generic over the node width, and per width the entry points that answer the
//! rays needing no traversal and run the bodies with that width's box test (`simd4`'s for
//! 4-wide nodes, `avx2`'s for 8-wide ones). Leaf blocks are tested four triangles at a time
//! with `Vec4` at both widths.
//!
//! Both bodies also take `accept(triangle, u, v)`, which says whether a candidate hit counts
//! (alpha cut-outs): the unfiltered queries pass a constant `true`, which compiles away.
//!
//! A body gets the box test as a closure rather than through a trait: a trait method cannot be
//! `#[target_feature]` unless it is `unsafe` to call, whereas a closure written in `intersect8`
//! or `occluded8` inherits their target features. The bodies are `#[inline(always)]`, so each
//! entry point gets its own copy, compiled with its features.

#[cfg(target_arch = "x86_64")]
use super::avx2::BoxRay8;
#[cfg(target_arch = "x86_64")]
use super::layout::Node8;
use super::layout::{EMPTY, LEAF_BIT, Node4, TriangleBlock, WideNode, WideTree, leaf_span};
use super::simd4::{BoxRay4, splat3};
use super::stack::{Lanes, TraversalStack};
use crate::accel::ray::{Hit, Ray};
#[cfg(target_arch = "x86_64")]
use glam::Vec3A;
use glam::{BVec4A, Vec4};

/// The closest hit in a 4-wide tree that `accept` keeps.
#[inline(always)]
pub(super) fn intersect4(
    tree: &WideTree<Node4>,
    ray: &Ray,
    accept: &impl Fn(u32, f32, f32) -> bool,
) -> Option<Hit> {
    if tree.root == EMPTY {
        return None;
    }
    let boxes = BoxRay4::new(ray);
    intersect(
        tree,
        ray,
        |node, tmin, tmax| boxes.intersect(node, tmin, tmax),
        accept,
    )
}

/// Whether a hit `accept` keeps in a 4-wide tree blocks the ray.
#[inline(always)]
pub(super) fn occluded4(
    tree: &WideTree<Node4>,
    ray: &Ray,
    accept: &impl Fn(u32, f32, f32) -> bool,
) -> bool {
    if tree.root == EMPTY {
        return false;
    }
    let boxes = BoxRay4::new(ray);
    occluded(
        tree,
        ray,
        |node, tmin, tmax| boxes.intersect(node, tmin, tmax),
        accept,
    )
}

/// The closest hit in an 8-wide tree that `accept` keeps; for CPUs with AVX2, FMA and the bit
/// instructions (`BvhWidth::is_supported`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
pub(super) fn intersect8(
    tree: &WideTree<Node8>,
    ray: &Ray,
    accept: &impl Fn(u32, f32, f32) -> bool,
) -> Option<Hit> {
    // A ray with no direction hits nothing, and `BoxRay8` would not cull empty slots for it.
    if tree.root == EMPTY || ray.direction == Vec3A::ZERO {
        return None;
    }
    let boxes = BoxRay8::new(ray);
    intersect(
        tree,
        ray,
        |node, tmin, tmax| boxes.intersect(node, tmin, tmax),
        accept,
    )
}

/// Whether a hit `accept` keeps in an 8-wide tree blocks the ray; for CPUs with AVX2, FMA and
/// the bit instructions (`BvhWidth::is_supported`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
pub(super) fn occluded8(
    tree: &WideTree<Node8>,
    ray: &Ray,
    accept: &impl Fn(u32, f32, f32) -> bool,
) -> bool {
    if tree.root == EMPTY || ray.direction == Vec3A::ZERO {
        return false;
    }
    let boxes = BoxRay8::new(ray);
    occluded(
        tree,
        ray,
        |node, tmin, tmax| boxes.intersect(node, tmin, tmax),
        accept,
    )
}

/// The closest hit with t in [tmin, tmax] that `accept` keeps, in a tree with a root.
/// `boxes(node, tmin, tmax)` tests the ray against the node's child boxes: their entry
/// distances, and the mask of those it enters within [tmin, tmax].
#[inline(always)]
fn intersect<const W: usize, N: WideNode<W>, D: Lanes<W>>(
    tree: &WideTree<N>,
    ray: &Ray,
    boxes: impl Fn(&N, f32, f32) -> (D, u32),
    accept: &impl Fn(u32, f32, f32) -> bool,
) -> Option<Hit> {
    let block_ray = BlockRay::new(ray);
    let mut tmax = ray.tmax;
    let mut best: Option<Hit> = None;
    let mut stack = TraversalStack::<(u32, f32)>::new();
    let mut current = tree.root;
    loop {
        if current & LEAF_BIT == 0 {
            let node = &tree.nodes[current as usize];
            let (t_near, mask) = boxes(node, ray.tmin, tmax);
            if mask != 0 {
                current =
                    stack.descend(mask, node.children(), t_near, |child| tree.prefetch(child));
                if current != EMPTY {
                    continue;
                }
            }
        } else {
            tree.intersect_leaf(current, &block_ray, &mut tmax, &mut best, accept);
        }
        match stack.pop_within(tmax) {
            Some(next) => current = next,
            None => return best,
        }
    }
}

/// Whether a hit `accept` keeps lies on the ray with t in [tmin, tmax], in a tree with a
/// root; `boxes` as for `intersect`.
#[inline(always)]
fn occluded<const W: usize, N: WideNode<W>, D: Lanes<W>>(
    tree: &WideTree<N>,
    ray: &Ray,
    boxes: impl Fn(&N, f32, f32) -> (D, u32),
    accept: &impl Fn(u32, f32, f32) -> bool,
) -> bool {
    let block_ray = BlockRay::new(ray);
    let mut stack = TraversalStack::<u32>::new();
    stack.push(tree.root);
    while let Some(current) = stack.pop() {
        if current & LEAF_BIT == 0 {
            let node = &tree.nodes[current as usize];
            let (_, mut mask) = boxes(node, ray.tmin, ray.tmax);
            while mask != 0 {
                let slot = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                // Empty slots are entered only by rays with all-NaN slabs (`descend`).
                let child = node.children()[slot];
                if child != EMPTY {
                    tree.prefetch(child);
                    stack.push(child);
                }
            }
        } else if tree.leaf_blocked(current, &block_ray, ray.tmax, accept) {
            return true;
        }
    }
    false
}

impl<N> WideTree<N> {
    /// Tests leaf block `reference` and narrows `tmax` to its closest hit in [tmin, tmax]
    /// that `accept` keeps.
    #[inline(always)]
    fn intersect_leaf(
        &self,
        reference: u32,
        ray: &BlockRay,
        tmax: &mut f32,
        best: &mut Option<Hit>,
        accept: &impl Fn(u32, f32, f32) -> bool,
    ) {
        let (index, blocks) = self.leaf_blocks(reference);
        for (block, &first) in blocks.iter().zip(&self.block_first[index..]) {
            let (t, u, v, hit) = intersect_block(block, ray, *tmax);
            // As arrays: indexing a `Vec4` by a variable lane is a jump table, whose
            // indirect branch mispredicted about once per ray.
            let (t, u, v) = (t.to_array(), u.to_array(), v.to_array());
            let mut mask = hit.bitmask();
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                // Lanes come in lane order, not by t: `accept` is asked only about a lane
                // nearer than the best so far.
                if t[lane] <= *tmax && accept(first + lane as u32, u[lane], v[lane]) {
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
    fn prefetch(&self, reference: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            // Pointer arithmetic that cannot fault: a prefetch of any address is harmless,
            // and the build only stores references inside the arrays. Node or leaf is
            // chosen without a branch (a branch here mispredicted 1.4 times per ray): the
            // first four lines are fetched for both, which covers a node (at most four
            // lines) and a block (three, and the line after it); only a two-block leaf
            // needs more.
            let is_leaf = reference & LEAF_BIT != 0;
            let (first, count) = leaf_span(reference);
            let node = self.nodes.as_ptr().wrapping_add(reference as usize) as usize;
            let block = self.blocks.as_ptr().wrapping_add(first) as usize;
            let start = if is_leaf { block } else { node } as *const i8;
            for line in 0..4 {
                // SAFETY: a prefetch is a hint that never faults or changes memory; SSE,
                // which it needs, is part of x86-64.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(64 * line)) };
            }
            if count > 1 {
                for line in 4..2 * size_of::<TriangleBlock>() / 64 {
                    // SAFETY: as above.
                    unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(64 * line)) };
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = reference;
    }

    /// Whether leaf block `reference` has a hit in [tmin, tmax] that `accept` keeps.
    #[inline(always)]
    fn leaf_blocked(
        &self,
        reference: u32,
        ray: &BlockRay,
        tmax: f32,
        accept: &impl Fn(u32, f32, f32) -> bool,
    ) -> bool {
        let (index, blocks) = self.leaf_blocks(reference);
        for (offset, block) in blocks.iter().enumerate() {
            let (_, u, v, hit) = intersect_block(block, ray, tmax);
            let (u, v) = (u.to_array(), v.to_array());
            // Written so that with an `accept` that is constant true this is `hit.any()`:
            // the first hit lane answers, and nothing in the lane loop can panic (`get`, with
            // a default never used since every block has its entry; lanes masked to 0..4), so
            // the unused lookups compile away.
            let mut mask = hit.bitmask();
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize & 3;
                let first = self.block_first.get(index + offset).copied().unwrap_or(0);
                if accept(first + lane as u32, u[lane], v[lane]) {
                    return true;
                }
                mask &= mask - 1;
            }
        }
        false
    }
}

/// The ray as the leaf block test takes it: origin and direction splatted to four lanes.
struct BlockRay {
    origin: [Vec4; 3],
    direction: [Vec4; 3],
    tmin: f32,
}

impl BlockRay {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        BlockRay {
            origin: splat3(ray.origin),
            direction: splat3(ray.direction),
            tmin: ray.tmin,
        }
    }
}

/// The ray against four triangles: (t, u, v) per lane and the lanes hit within [tmin, tmax].
#[inline(always)]
fn intersect_block(block: &TriangleBlock, ray: &BlockRay, tmax: f32) -> (Vec4, Vec4, Vec4, BVec4A) {
    let (origin, direction, tmin) = (&ray.origin, &ray.direction, ray.tmin);
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
