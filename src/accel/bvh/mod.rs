//! The default backend: a wide BVH whose triangles are packed four to a leaf block, nodes and
//! blocks both in structure-of-arrays layout, so one vector instruction tests a ray against
//! several boxes or four triangles. obvhs builds the binary tree (PLOC with reinsertion and
//! leaf collapsing); we collapse it to a wide tree, choosing each wide node's children by the
//! surface area heuristic (a dynamic programme over the binary tree), and traverse it
//! ourselves, nearest child first. A leaf is one block, or two consecutive ones in the 8-wide tree.
//!
//! The width is picked at build time from the CPU: on x86-64 with AVX2 and FMA (and the bit
//! instructions BMI1, BMI2, LZCNT and POPCNT, which every such CPU has: the traversal's masks
//! then take one instruction per step, 2-3% fewer per ray by callgrind), eight children
//! per node, whose boxes are tested with one AVX instruction per slab; elsewhere four, tested
//! with SSE (or NEON) through glam's `Vec4`. Leaf blocks are tested with `Vec4` in both. Tests
//! and benches can force the 4-wide tree with [`with_bvh_width`]. On the traversal bench
//! (closest hit, 1 and 2 threads) the 8-wide tree traces 1.25-1.4x the 4-wide's rays,
//! 0.95-1.11x Embree 3's on the room and 0.77-0.93x on the terrain (README, "Benchmarks");
//! its build takes the same time.
//!
//! Triangles are numbered in leaf order, so a hit needs no indirection; the unused lanes of a
//! block hold a zero triangle, whose test yields NaN and fails every comparison.
//!
//! The files, each depending only on those listed after it:
//! - `mod.rs`: [`BvhAccel`], the choice of width and the dispatch of each query to the tree's;
//! - `build.rs`: obvhs's binary tree collapsed to a wide one, generic over the width;
//! - `traversal.rs`: the closest-hit and occlusion traversals, one body each for both widths,
//!   and their entry points per width (the 8-wide ones compiled with AVX2 and FMA);
//! - `simd4.rs`, `avx2.rs`: the box tests of a 4-wide node (`Vec4`) and an 8-wide node (AVX2);
//! - `layout.rs`: nodes, leaf blocks, the references between them and the tree's arrays;
//! - `stack.rs`: the traversal stack;
//! - `huge_pages.rs`: large arrays in 2 MiB pages.

#[cfg(target_arch = "x86_64")]
mod avx2;
mod build;
mod huge_pages;
mod layout;
mod simd4;
mod stack;
mod traversal;

use super::BuildQuality;
use super::ray::{Hit, Ray};
use crate::error::Result;
use glam::Vec3A;
#[cfg(target_arch = "x86_64")]
use layout::Node8;
use layout::{EMPTY, Node4, WideTree};
use std::cell::Cell;

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
            BvhWidth::Eight => {
                is_x86_feature_detected!("avx2")
                    && is_x86_feature_detected!("fma")
                    && is_x86_feature_detected!("bmi1")
                    && is_x86_feature_detected!("bmi2")
                    && is_x86_feature_detected!("lzcnt")
                    && is_x86_feature_detected!("popcnt")
            }
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
#[cfg(any(test, feature = "internals"))]
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

/// The tree, at the width it was built.
#[derive(PartialEq)]
enum Tree {
    Four(WideTree<Node4>),
    /// Only built on CPUs with AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    Eight(WideTree<Node8>),
}

pub struct BvhAccel {
    tree: Tree,
    /// For each leaf-order triangle, its index in the list the BVH was built from.
    build_order: Vec<u32>,
}

impl BvhAccel {
    /// Builds at `quality` over triangles given as vertex triples, none of them degenerate, as
    /// wide as the CPU supports (or as [`with_bvh_width`] asks).
    pub fn build(vertices: &[[Vec3A; 3]], quality: BuildQuality) -> Result<Self> {
        let width = FORCED_WIDTH.get().unwrap_or_else(BvhWidth::best);
        Self::build_with_width(vertices, width, quality)
    }

    /// Builds `width` wide, or 4-wide if the CPU does not support `width`.
    pub(crate) fn build_with_width(
        vertices: &[[Vec3A; 3]],
        width: BvhWidth,
        quality: BuildQuality,
    ) -> Result<Self> {
        let width = if width.is_supported() {
            width
        } else {
            BvhWidth::Four
        };
        if vertices.is_empty() {
            return Ok(BvhAccel {
                tree: Tree::Four(WideTree {
                    nodes: Vec::new(),
                    blocks: Vec::new(),
                    block_first: Vec::new(),
                    root: EMPTY,
                }),
                build_order: Vec::new(),
            });
        }
        let (tree, build_order) = match width {
            BvhWidth::Four => {
                let (tree, build_order) = build::build(vertices, quality)?;
                (Tree::Four(tree), build_order)
            }
            #[cfg(target_arch = "x86_64")]
            BvhWidth::Eight => {
                let (tree, build_order) = build::build(vertices, quality)?;
                (Tree::Eight(tree), build_order)
            }
            #[cfg(not(target_arch = "x86_64"))]
            BvhWidth::Eight => unreachable!("8-wide needs x86-64"),
        };
        Ok(BvhAccel { tree, build_order })
    }

    /// Built 8-wide (or as wide as the CPU supports) over Embree's own binary SAH tree
    /// instead of obvhs's: the traversal bench's diagnostic of tree against traversal.
    #[cfg(all(feature = "embree", any(test, feature = "internals")))]
    pub fn build_over_embree_tree(vertices: &[[Vec3A; 3]]) -> Result<Self> {
        fn over<const W: usize, N: layout::WideNode<W> + Copy + Send>(
            vertices: &[[Vec3A; 3]],
        ) -> Result<(WideTree<N>, Vec<u32>)> {
            let bvh2 = super::embree::tree::binary_tree(vertices, build::max_leaf::<W>())?;
            build::build_over(&bvh2, vertices)
        }
        if vertices.is_empty() {
            return Self::build_with_width(vertices, BvhWidth::best(), BuildQuality::default());
        }
        let (tree, build_order) = match BvhWidth::best() {
            BvhWidth::Four => over(vertices).map(|(tree, order)| (Tree::Four(tree), order))?,
            #[cfg(target_arch = "x86_64")]
            BvhWidth::Eight => over(vertices).map(|(tree, order)| (Tree::Eight(tree), order))?,
            #[cfg(not(target_arch = "x86_64"))]
            BvhWidth::Eight => unreachable!("8-wide needs x86-64"),
        };
        Ok(BvhAccel { tree, build_order })
    }

    /// Children per node.
    #[cfg(any(test, feature = "internals"))]
    pub fn width(&self) -> BvhWidth {
        match self.tree {
            Tree::Four(_) => BvhWidth::Four,
            #[cfg(target_arch = "x86_64")]
            Tree::Eight(_) => BvhWidth::Eight,
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
        fn tree<N>(tree: &WideTree<N>) -> usize {
            allocated(&tree.nodes) + allocated(&tree.blocks) + allocated(&tree.block_first)
        }
        let tree = match &self.tree {
            Tree::Four(four) => tree(four),
            #[cfg(target_arch = "x86_64")]
            Tree::Eight(eight) => tree(eight),
        };
        tree + allocated(&self.build_order)
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_filtered(ray, &|_, _, _| true)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_filtered(ray, &|_, _, _| true)
    }

    /// The closest hit that `accept(triangle, u, v)` keeps.
    #[inline]
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        accept: &impl Fn(u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        match &self.tree {
            Tree::Four(tree) => traversal::intersect4(tree, ray, accept),
            // SAFETY: `Tree::Eight` is only built on CPUs with the features `intersect8`
            // enables (`build_with_width` checks `BvhWidth::is_supported`).
            #[cfg(target_arch = "x86_64")]
            Tree::Eight(tree) => unsafe { traversal::intersect8(tree, ray, accept) },
        }
    }

    /// Whether a hit that `accept(triangle, u, v)` keeps lies on the ray.
    #[inline]
    pub fn occluded_filtered(&self, ray: &Ray, accept: &impl Fn(u32, f32, f32) -> bool) -> bool {
        match &self.tree {
            Tree::Four(tree) => traversal::occluded4(tree, ray, accept),
            // SAFETY: as in `intersect_filtered`.
            #[cfg(target_arch = "x86_64")]
            Tree::Eight(tree) => unsafe { traversal::occluded8(tree, ray, accept) },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use layout::{LEAF_BIT, TWO_BLOCKS_BIT, WideNode};

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
        fn count<const W: usize, N: WideNode<W>>(tree: &WideTree<N>) -> usize {
            let two_blocks =
                |&&c: &&u32| c != EMPTY && c & LEAF_BIT != 0 && c & TWO_BLOCKS_BIT != 0;
            tree.nodes
                .iter()
                .flat_map(|n| n.children())
                .filter(two_blocks)
                .count()
        }
        match &accel.tree {
            Tree::Four(tree) => count(tree),
            #[cfg(target_arch = "x86_64")]
            Tree::Eight(tree) => count(tree),
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
                pool.install(|| {
                    BvhAccel::build_with_width(&triangles, width, BuildQuality::default()).unwrap()
                })
            };
            let one = build_on(1);
            for threads in [2, 3, 8] {
                let many = build_on(threads);
                // Nodes, blocks and root.
                assert!(one.tree == many.tree, "{width:?}, {threads} threads: tree");
                assert_eq!(
                    one.build_order, many.build_order,
                    "{width:?}, {threads} threads"
                );
            }
        }
    }

    #[test]
    fn builds_the_widest_supported_unless_forced() {
        let tris = [[Vec3A::ZERO, Vec3A::X, Vec3A::Y]; 40];
        assert_eq!(
            BvhAccel::build(&tris, BuildQuality::default())
                .unwrap()
                .width(),
            BvhWidth::best()
        );
        let forced = with_bvh_width(BvhWidth::Four, || {
            BvhAccel::build(&tris, BuildQuality::default()).unwrap()
        });
        assert_eq!(forced.width(), BvhWidth::Four);
        assert_eq!(
            BvhAccel::build(&tris, BuildQuality::default())
                .unwrap()
                .width(),
            BvhWidth::best()
        );
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // Every CPU with these has the bit instructions the 8-wide traversal also enables.
            assert!(BvhWidth::Eight.is_supported());
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
        matches_brute_force_of(&format!("{width:?}"), |tris| {
            let accel = BvhAccel::build_with_width(tris, width, BuildQuality::default()).unwrap();
            assert_eq!(accel.width(), width);
            accel
        });
    }

    /// The traversal bench's diagnostic build over Embree's own binary tree answers as
    /// testing every triangle does, as the default build does.
    #[cfg(feature = "embree")]
    #[test]
    fn over_embrees_tree_matches_brute_force() {
        matches_brute_force_of("over Embree's tree", |tris| {
            BvhAccel::build_over_embree_tree(tris).unwrap()
        });
        let empty = BvhAccel::build_over_embree_tree(&[]).unwrap();
        assert_eq!(
            empty.intersect(&Ray::new(Vec3A::ZERO, Vec3A::X, 0.0, 1.0)),
            None
        );
    }

    /// `build` (over triangles) answers every query as testing every triangle does.
    fn matches_brute_force_of(label: &str, build: impl Fn(&[[Vec3A; 3]]) -> BvhAccel) {
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
            let accel = build(&tris);
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
                    other => panic!("{label}, {count} triangles: mismatch {other:?}"),
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
                assert!(hits > 1000, "{label}, {count} triangles: {hits} hits");
            }
            if accel.width() == BvhWidth::Eight && count == 5000 {
                assert!(two_block_leaves(&accel) > 0, "two-block leaves are tested");
            }
        }
    }

    /// Rays from origins so far out that origin / direction overflows on every axis make
    /// every slab of the box test NaN, which enters the empty slots of partly filled nodes
    /// too (found by the ray_queries fuzzer: the traversal then indexed past the leaf
    /// blocks). The traversal skips them: such rays get an answer, the same from both
    /// queries, at every width.
    #[test]
    fn rays_from_far_origins_skip_empty_slots() {
        let tris: Vec<[Vec3A; 3]> = (0..40)
            .map(|i| {
                let c = Vec3A::new(i as f32, (i % 3) as f32, (i % 7) as f32);
                [c, c + Vec3A::X, c + Vec3A::Y]
            })
            .collect();
        for width in widths() {
            let accel = BvhAccel::build_with_width(&tris, width, BuildQuality::default()).unwrap();
            for origin in [Vec3A::splat(3e38), Vec3A::new(-3e38, 3e38, -3e38)] {
                for direction in [Vec3A::ONE, -Vec3A::ONE, Vec3A::new(1.0, -1.0, 1.0)] {
                    let ray = Ray::new(origin, direction.normalize(), 0.0, f32::INFINITY);
                    let hit = accel.intersect(&ray);
                    assert_eq!(accel.occluded(&ray), hit.is_some(), "{width:?} {ray:?}");
                }
            }
        }
    }

    /// A ray with a direction component so small that origin / direction overflows on its
    /// axis still enters the boxes it crosses (found by the ray_queries fuzzer: the 8-wide
    /// box test's fused form made their far bound -inf and missed the triangle), at every
    /// width, here among partly filled nodes of 40 small triangles.
    #[test]
    fn rays_with_tiny_direction_components_find_their_hit() {
        let mut tris: Vec<[Vec3A; 3]> = (0..40)
            .map(|i| {
                let c = Vec3A::new(i as f32, -5.0, (i % 7) as f32);
                [c, c + Vec3A::X, c + Vec3A::Y]
            })
            .collect();
        tris.push([
            Vec3A::new(-1e9, 1e8, 1e9),
            Vec3A::new(1e9, 1e8, 1e9),
            Vec3A::new(0.0, 1e8, -1e9),
        ]);
        let origin = Vec3A::new(3.0, -1.0, 0.0);
        for tiny in [f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-37] {
            let direction = Vec3A::new(tiny, 3.0, 1.0).normalize();
            let expected = (1e8 + 1.0) / direction.y;
            for width in widths() {
                let accel =
                    BvhAccel::build_with_width(&tris, width, BuildQuality::default()).unwrap();
                let ray = Ray::new(origin, direction, 0.0, f32::INFINITY);
                let hit = accel.intersect(&ray);
                let what = format!("{width:?}, direction {direction}: {hit:?}");
                let hit = hit.expect(&what);
                assert_eq!(accel.build_order[hit.triangle as usize], 40, "{what}");
                assert!((hit.t / expected - 1.0).abs() < 1e-3, "{what}");
                assert!(accel.occluded(&ray), "{what}");
            }
        }
    }

    /// Small triangles far apart, whose boxes' areas overflow: the wide tree's planning
    /// costs are infinite or NaN, and it must still split every node (found by the
    /// ray_queries fuzzer: a node "split" into itself recursed until the stack overflowed,
    /// aborting the process). The tree is built and finds each triangle, at every width.
    #[test]
    fn builds_over_boxes_whose_area_overflows() {
        // Spread along y and z, so the root's box has an area beyond f32 (1e43).
        let tris: Vec<[Vec3A; 3]> = (0..20)
            .map(|i| {
                let far = 1e20 * (i + 1) as f32;
                let c = Vec3A::new(0.0, if i % 2 == 0 { far } else { -far }, far);
                [c, c + Vec3A::Y * 1e15, c + Vec3A::Z * 1e15]
            })
            .collect();
        for width in widths() {
            let accel = BvhAccel::build_with_width(&tris, width, BuildQuality::default()).unwrap();
            for (i, [a, ..]) in tris.iter().enumerate() {
                let origin = *a + Vec3A::new(-1.0, 1e14, 1e14);
                let ray = Ray::new(origin, Vec3A::X, 0.0, 2.0);
                let hit = accel.intersect(&ray).expect("the triangle in front");
                assert_eq!(
                    accel.build_order[hit.triangle as usize] as usize, i,
                    "{width:?}"
                );
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
                let accel =
                    BvhAccel::build_with_width(&tris, width, BuildQuality::default()).unwrap();
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

#[cfg(test)]
mod ordering_tests {
    use super::stack::Lanes;
    use crate::sampling::Rng;

    /// `places` against a sort: the entered lanes, farthest first (ties by lane, the lower
    /// lane taken as farther only if its key says so), then the last place for the others.
    fn check_places<const N: usize>(distances: [f32; N], mask: u32, places: [u32; N]) {
        let mut entered: Vec<usize> = (0..N).filter(|lane| mask >> lane & 1 != 0).collect();
        let key = |lane: usize| super::stack::distance_key(distances[lane], lane as u32);
        entered.sort_by_key(|&lane| std::cmp::Reverse(key(lane)));
        for (place, &lane) in entered.iter().enumerate() {
            assert_eq!(
                places[lane] as usize, place,
                "{distances:?} {mask:#b} {places:?}"
            );
        }
        for lane in (0..N).filter(|lane| mask >> lane & 1 == 0) {
            assert_eq!(
                places[lane] as usize,
                N - 1,
                "{distances:?} {mask:#b} {places:?}"
            );
        }
    }

    /// Distances with ties and zeros, as entry distances are (at least tmin = 0).
    fn distances<const N: usize>(rng: &mut Rng) -> [f32; N] {
        std::array::from_fn(|_| match (rng.uniform() * 4.0) as u32 {
            0 => 0.0,
            1 => 1.5,
            _ => rng.uniform() * 100.0,
        })
    }

    #[test]
    fn places_order_entered_children_farthest_first() {
        let mut rng = Rng::new(11, 0);
        for _ in 0..2000 {
            let mask = (rng.uniform() * 16.0) as u32;
            let t = distances::<4>(&mut rng);
            check_places(t, mask, glam::Vec4::from_array(t).places(mask));
        }
        #[cfg(target_arch = "x86_64")]
        if super::BvhWidth::Eight.is_supported() {
            for _ in 0..2000 {
                let mask = (rng.uniform() * 256.0) as u32;
                let t = distances::<8>(&mut rng);
                // SAFETY: both are 32 bytes of eight f32.
                let lanes =
                    unsafe { std::mem::transmute::<[f32; 8], std::arch::x86_64::__m256>(t) };
                check_places(t, mask, lanes.places(mask));
            }
        }
    }
}
