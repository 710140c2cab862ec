//! The default backend: a 4-wide BVH with its triangles packed four to a leaf block, both in
//! structure-of-arrays layout, so one SSE instruction tests a ray against four boxes or four
//! triangles (glam's `Vec4` is an SSE register on x86-64). obvhs builds the binary tree (PLOC
//! with reinsertion and leaf collapsing, leaves of at most four triangles); we collapse it to
//! four children per node and traverse it ourselves, nearest child first.
//!
//! Triangles are numbered in leaf order, so a hit needs no indirection; the unused lanes of a
//! block hold a zero triangle, whose test yields NaN and fails every comparison.

use super::{Hit, Ray};
use crate::error::{Error, MLT_STATUS_INTERNAL_ERROR, Result};
use glam::{BVec4A, Vec3A, Vec4};
use obvhs::{
    BvhBuildParams,
    bvh2::{Bvh2, builder::build_bvh2_from_tris},
    triangle::Triangle,
};
use std::mem::MaybeUninit;
use std::time::Duration;

/// Children of a node, and triangles of a leaf block.
const WIDTH: usize = 4;
/// A child reference with this bit set is a leaf block index; otherwise a node index.
const LEAF_BIT: u32 = 1 << 31;
/// The reference of an empty child slot (its box is empty, so it is never entered).
const EMPTY: u32 = u32::MAX;
/// Entries of the traversal stack: each level of the tree adds at most WIDTH - 1, so trees
/// up to 85 levels deep fit (PLOC trees over real scenes are a few dozen levels deep).
const STACK_SIZE: usize = 256;
/// Deepest tree the stack can traverse.
const MAX_DEPTH: usize = (STACK_SIZE - 1) / (WIDTH - 1);

/// Four child boxes: `bounds[2 * axis]` their minima along the axis, `bounds[2 * axis + 1]`
/// their maxima. Empty slots have min = +inf, max = -inf.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: [Vec4; 6],
    children: [u32; WIDTH],
}

/// Four triangles for the Möller–Trumbore test with the normal precomputed: v0, e1 = v0 - v1,
/// e2 = v2 - v0 and ng = e1 × e2, each as x, y, z lanes.
#[derive(Clone, Copy, Debug)]
struct TriangleBlock {
    v0: [Vec4; 3],
    e1: [Vec4; 3],
    e2: [Vec4; 3],
    ng: [Vec4; 3],
    /// Leaf-order index of lane 0; lane i is `first + i`.
    first: u32,
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
        // The sign bit, so -0 (inv = -inf) counts as negative.
        let near = |axis: usize| 2 * axis + inv[axis].is_sign_negative() as usize;
        BoxRay {
            near: [near(0), near(1), near(2)],
            far: [near(0) ^ 1, near(1) ^ 1, near(2) ^ 1],
            origin: splat3(ray.origin),
            inv_direction: splat3(inv),
        }
    }

    /// Entry distances of the four children and which of them the ray enters in [tmin, tmax].
    #[inline(always)]
    fn intersect(&self, node: &Node, tmin: f32, tmax: f32) -> (Vec4, u32) {
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

fn splat3(v: Vec3A) -> [Vec4; 3] {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

pub struct BvhAccel {
    nodes: Vec<Node>,
    blocks: Vec<TriangleBlock>,
    /// The root: a node index, a leaf block (`LEAF_BIT`) or `EMPTY`.
    root: u32,
    /// For each leaf-order triangle, its index in the list the BVH was built from.
    build_order: Vec<u32>,
}

impl BvhAccel {
    /// Builds over triangles given as vertex triples. None of them may be degenerate.
    pub fn build(vertices: &[[Vec3A; 3]]) -> Result<Self> {
        let mut accel = BvhAccel {
            nodes: Vec::new(),
            blocks: Vec::new(),
            root: EMPTY,
            build_order: Vec::with_capacity(vertices.len()),
        };
        if vertices.is_empty() {
            return Ok(accel);
        }
        let tris: Vec<Triangle> = vertices
            .iter()
            .map(|&[v0, v1, v2]| Triangle { v0, v1, v2 })
            .collect();
        // Reinsertion over every node (ratio 1 instead of the preset's 0.05) makes the tree
        // fit cluttered scenes far better: on the traversal bench's 70k-triangle room, 3.0x
        // the camera-ray rate and 2.4x on bounce and random rays, for 7x the build time
        // (0.03 -> 0.22 s; the 1.2M-triangle terrain: 0.55 -> 3.8 s, single-threaded).
        let params = BvhBuildParams {
            max_prims_per_leaf: WIDTH as u32,
            reinsertion_batch_ratio: 1.0,
            ..BvhBuildParams::medium_build()
        };
        let bvh2 = build_bvh2_from_tris(&tris, params, &mut Duration::default());
        let mut depth = 0;
        accel.root = accel.collapse(&bvh2, 0, vertices, 1, &mut depth);
        if depth > MAX_DEPTH {
            return Err(Error::new(
                MLT_STATUS_INTERNAL_ERROR,
                format!(
                    "the BVH over these {} triangles is {depth} levels deep; at most {MAX_DEPTH} are supported",
                    vertices.len()
                ),
            ));
        }
        Ok(accel)
    }

    /// The wide subtree of binary node `index` at `level` (the root's is 1); returns its
    /// reference and raises `depth` to the deepest level it reaches.
    fn collapse(
        &mut self,
        bvh2: &Bvh2,
        index: usize,
        vertices: &[[Vec3A; 3]],
        level: usize,
        depth: &mut usize,
    ) -> u32 {
        *depth = (*depth).max(level);
        let node = &bvh2.nodes[index];
        if node.prim_count > 0 {
            return self.leaf_block(bvh2, index, vertices);
        }
        // Open the binary children with the largest surface area until there are WIDTH.
        let mut open = vec![node.first_index as usize, node.first_index as usize + 1];
        while open.len() < WIDTH {
            let widest = open
                .iter()
                .enumerate()
                .filter(|&(_, &i)| bvh2.nodes[i].prim_count == 0)
                .max_by(|&(_, &a), &(_, &b)| {
                    let area = |i: usize| bvh2.nodes[i].aabb.half_area();
                    area(a).total_cmp(&area(b))
                })
                .map(|(slot, _)| slot);
            let Some(slot) = widest else { break };
            let first = bvh2.nodes[open[slot]].first_index as usize;
            open[slot] = first;
            open.push(first + 1);
        }
        let me = self.nodes.len();
        self.nodes.push(Node {
            bounds: [
                Vec4::INFINITY,
                Vec4::NEG_INFINITY,
                Vec4::INFINITY,
                Vec4::NEG_INFINITY,
                Vec4::INFINITY,
                Vec4::NEG_INFINITY,
            ],
            children: [EMPTY; WIDTH],
        });
        for (slot, &child) in open.iter().enumerate() {
            let reference = self.collapse(bvh2, child, vertices, level + 1, depth);
            let aabb = bvh2.nodes[child].aabb;
            let node = &mut self.nodes[me];
            for axis in 0..3 {
                node.bounds[2 * axis][slot] = aabb.min[axis];
                node.bounds[2 * axis + 1][slot] = aabb.max[axis];
            }
            node.children[slot] = reference;
        }
        me as u32
    }

    /// Packs the triangles of binary leaf `index` into a block; returns its reference.
    fn leaf_block(&mut self, bvh2: &Bvh2, index: usize, vertices: &[[Vec3A; 3]]) -> u32 {
        let node = &bvh2.nodes[index];
        let first = node.first_index as usize;
        let ids = &bvh2.primitive_indices[first..first + node.prim_count as usize];
        assert!(ids.len() <= WIDTH, "obvhs made a leaf larger than asked");
        let mut block = TriangleBlock {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            ng: [Vec4::ZERO; 3],
            first: self.build_order.len() as u32,
        };
        for (lane, &id) in ids.iter().enumerate() {
            let [v0, v1, v2] = vertices[id as usize];
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
        (self.blocks.len() - 1) as u32 | LEAF_BIT
    }

    pub fn internal_to_build_order(&self) -> &[u32] {
        &self.build_order
    }

    /// Bytes of the structure: nodes, triangle blocks and the index map.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node>()
            + self.blocks.len() * size_of::<TriangleBlock>()
            + self.build_order.len() * size_of::<u32>()
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
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
                let node = &self.nodes[current as usize];
                let (t_near, mut mask) = box_ray.intersect(node, ray.tmin, tmax);
                if mask != 0 {
                    // Go on with the nearest child; push the others, farthest first.
                    let mut hits = [(0u32, 0f32); WIDTH];
                    let mut count = 0;
                    while mask != 0 {
                        let slot = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let entry = (node.children[slot], t_near[slot]);
                        // Insertion sort, nearest last.
                        let mut at = count;
                        while at > 0 && hits[at - 1].1 < entry.1 {
                            hits[at] = hits[at - 1];
                            at -= 1;
                        }
                        hits[at] = entry;
                        count += 1;
                    }
                    for &entry in &hits[..count - 1] {
                        stack.push(entry);
                    }
                    current = hits[count - 1].0;
                    continue;
                }
            } else {
                let block = &self.blocks[(current & !LEAF_BIT) as usize];
                let (t, u, v, hit) = intersect_block(block, &origin, &direction, ray.tmin, tmax);
                let mut mask = hit.bitmask();
                while mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if t[lane] <= tmax {
                        tmax = t[lane];
                        best = Some(Hit {
                            triangle: block.first + lane as u32,
                            t: t[lane],
                            u: u[lane],
                            v: v[lane],
                        });
                    }
                }
            }
            // Next: the nearest pushed entry the ray can still reach.
            loop {
                let Some((reference, t_near)) = stack.pop() else {
                    return best;
                };
                if t_near <= tmax {
                    current = reference;
                    break;
                }
            }
        }
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
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
                let node = &self.nodes[current as usize];
                let (_, mut mask) = box_ray.intersect(node, ray.tmin, ray.tmax);
                while mask != 0 {
                    let slot = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack.push(node.children[slot]);
                }
            } else {
                let block = &self.blocks[(current & !LEAF_BIT) as usize];
                let (_, _, _, hit) =
                    intersect_block(block, &origin, &direction, ray.tmin, ray.tmax);
                if hit.any() {
                    return true;
                }
            }
        }
        false
    }
}

/// The traversal stack. Its storage is left uninitialized: zeroing all `STACK_SIZE` entries
/// for every ray cost about a tenth of a render's time on small scenes.
struct TraversalStack<T: Copy> {
    entries: [MaybeUninit<T>; STACK_SIZE],
    len: usize,
}

impl<T: Copy> TraversalStack<T> {
    #[inline(always)]
    fn new() -> Self {
        TraversalStack {
            entries: [const { MaybeUninit::uninit() }; STACK_SIZE],
            len: 0,
        }
    }

    /// Panics (bounds check) past `STACK_SIZE`, which the build's depth limit rules out.
    #[inline(always)]
    fn push(&mut self, value: T) {
        self.entries[self.len].write(value);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: every entry below the old `len` was written by `push`, and entries are
        // only ever read below `len`.
        Some(unsafe { self.entries[self.len].assume_init() })
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

    /// The BVH must return what testing every triangle returns, for scenes of every size
    /// (a lone leaf as root, partly filled nodes and blocks, deep trees).
    #[test]
    fn matches_brute_force() {
        let mut rng = Rng::new(5, 5);
        for count in [1, 3, 5, 17, 500, 5000] {
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
            let accel = BvhAccel::build(&tris).unwrap();
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
                    other => panic!("{count} triangles: mismatch {other:?}"),
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
                assert!(hits > 1000, "{count} triangles: {hits} hits");
            }
        }
    }

    /// Rays along the axes (zero direction components) from origins on box planes.
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
        let tris: Vec<[Vec3A; 3]> = (0..8).flat_map(|i| square(i as f32)).collect();
        let accel = BvhAccel::build(&tris).unwrap();
        // From x = 0 and y = 0 (the boxes' own planes), straight along +z.
        let ray = Ray::new(Vec3A::new(0.0, 0.25, -1.0), Vec3A::Z, 0.0, f32::INFINITY);
        let hit = accel.intersect(&ray).expect("the first square");
        assert_eq!(hit.t, 1.0);
        let ray = Ray::new(Vec3A::new(0.5, 0.0, 2.5), -Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!(accel.intersect(&ray).map(|h| h.t), Some(0.5));
        let ray = Ray::new(Vec3A::new(0.5, 0.5, 2.5), -Vec3A::Z, 0.0, 0.4);
        assert!(!accel.occluded(&ray));
    }
}
