//! Ray queries: closest hit and occlusion, behind one interface for every backend.
//!
//! Triangles are addressed by their *internal* index, the order the backend stores them in
//! (for the BVH: leaf order, so a hit needs no indirection). The scene maps internal indices
//! back to the host's triangle ids.
//!
//! Every backend answers the same queries the same way, up to floating-point rounding: the
//! same closest triangle and t, the same occlusion, except for rays that pass within rounding
//! of an edge, graze a triangle or hit two triangles at (nearly) the same t;
//! `tests/backends.rs` measures how rare those are. One difference by definition: the BVH
//! accepts hits with t in [tmin, tmax], Embree in (tmin, tmax] (tmin is passed as is, so they
//! differ only for a hit at exactly t = tmin; the integrators use tmin = 0 from origins moved
//! off the surface).

mod bvh;
/// cbindgen:ignore
#[cfg(feature = "embree")]
pub mod embree;
mod ray;

pub use bvh::BvhAccel;
#[cfg(any(test, feature = "internals"))]
pub use bvh::{BvhWidth, with_bvh_width};
#[cfg(feature = "embree")]
pub use embree::EmbreeAccel;
pub use ray::{Hit, Ray};

use crate::error::Result;
use glam::Vec3A;

/// Which ray-intersection backend a scene is built with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backend {
    /// mlt's own SIMD BVH, 8-wide on x86-64 CPUs with AVX2 and FMA, else 4-wide; built with
    /// obvhs (always available).
    #[default]
    Bvh,
    /// Intel Embree 3 (only with the `embree` cargo feature).
    Embree,
}

impl Backend {
    /// Whether scenes can be built with this backend in this build of mlt.
    pub const fn is_available(self) -> bool {
        match self {
            Backend::Bvh => true,
            Backend::Embree => cfg!(feature = "embree"),
        }
    }
}

/// How much work the build spends for faster rays, as Embree's build qualities. Every quality
/// answers the same queries (the agreement of `Accel`'s contract); only the speeds and the
/// memory differ. The traversal bench (`benches/traversal.rs`) reports build time, memory and
/// ray rates per quality; docs/benchmarks.md has the figures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildQuality {
    /// The quickest build, for scenes rebuilt often (an editor's preview, a baking tool's
    /// iterations); rays are slower. Embree: `RTC_BUILD_QUALITY_LOW`.
    Fast,
    /// Between the two. Embree: `RTC_BUILD_QUALITY_MEDIUM`.
    Medium,
    /// The tree that renders fastest, for scenes built once and rendered long (the
    /// default). Embree: `RTC_BUILD_QUALITY_HIGH`.
    #[default]
    High,
}

/// Whether a structure will also answer filtered queries ([`Accel::intersect_filtered`],
/// [`Accel::occluded_filtered`]). The BVH answers them either way; Embree only runs filters
/// in scenes built for them, which makes its unfiltered queries slower too (see
/// [`EmbreeAccel`]), so scenes ask for this only when they have alpha cut-outs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filtering {
    /// Only unfiltered queries.
    #[default]
    Unfiltered,
    /// Filtered queries too.
    Filtered,
}

/// The backends. An enum, not a trait object, so the hot path dispatches without a vtable.
pub enum Accel {
    Bvh(BvhAccel),
    #[cfg(feature = "embree")]
    Embree(EmbreeAccel),
}

impl Accel {
    /// Builds `backend`'s structure at `quality` over triangles given as vertex triples, none degenerate;
    /// `filtering` says whether it will answer filtered queries (a filtered query on an
    /// Embree structure built `Unfiltered` panics). Fails with `MLT_STATUS_UNSUPPORTED` for
    /// a backend this build lacks (see [`Backend::is_available`]), and with Embree's error if
    /// Embree fails.
    pub fn build(
        backend: Backend,
        quality: BuildQuality,
        triangles: &[[Vec3A; 3]],
        filtering: Filtering,
    ) -> Result<Accel> {
        match backend {
            Backend::Bvh => {
                // The BVH answers filtered queries whatever it was built for.
                let _ = filtering;
                Ok(Accel::Bvh(BvhAccel::build(triangles, quality)?))
            }
            #[cfg(feature = "embree")]
            Backend::Embree => Ok(Accel::Embree(EmbreeAccel::build(
                triangles, quality, filtering,
            )?)),
            #[cfg(not(feature = "embree"))]
            Backend::Embree => Err(crate::error::Error::new(
                crate::error::MLT_STATUS_UNSUPPORTED,
                "backend Embree was requested but this build of mlt was compiled without the `embree` feature",
            )),
        }
    }

    /// The closest hit with t in [tmin, tmax] (Embree: (tmin, tmax]), if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match self {
            Accel::Bvh(bvh) => bvh.intersect(ray),
            #[cfg(feature = "embree")]
            Accel::Embree(embree) => embree.intersect(ray),
        }
    }

    /// Whether anything lies on the ray with t in [tmin, tmax] (Embree: (tmin, tmax]).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match self {
            Accel::Bvh(bvh) => bvh.occluded(ray),
            #[cfg(feature = "embree")]
            Accel::Embree(embree) => embree.occluded(ray),
        }
    }

    /// The closest hit that `accept(triangle, u, v)` keeps (alpha cut-outs), with t in the
    /// interval as for `intersect`: candidates it rejects are passed through. `triangle` is
    /// the internal index and (u, v) the barycentrics, as in [`Hit`]. `accept` may be asked
    /// about any candidate in the interval, in any order, more than once; the structure must
    /// have been built with [`Filtering::Filtered`].
    #[inline]
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        accept: &impl Fn(u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        match self {
            Accel::Bvh(bvh) => bvh.intersect_filtered(ray, accept),
            #[cfg(feature = "embree")]
            Accel::Embree(embree) => embree.intersect_filtered(ray, accept),
        }
    }

    /// Whether a hit that `accept(triangle, u, v)` keeps lies on the ray; `accept` as for
    /// `intersect_filtered`.
    #[inline]
    pub fn occluded_filtered(&self, ray: &Ray, accept: &impl Fn(u32, f32, f32) -> bool) -> bool {
        match self {
            Accel::Bvh(bvh) => bvh.occluded_filtered(ray, accept),
            #[cfg(feature = "embree")]
            Accel::Embree(embree) => embree.occluded_filtered(ray, accept),
        }
    }

    /// The bytes the structure holds: for the BVH computed from its arrays' lengths, for
    /// Embree the balance of what Embree allocated (counted by its memory monitor) plus our
    /// own arrays. For comparing backends and sizing scenes; allocator overhead is not counted.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Accel::Bvh(bvh) => bvh.memory_bytes(),
            #[cfg(feature = "embree")]
            Accel::Embree(embree) => embree.memory_bytes(),
        }
    }

    /// For each internal triangle index, the index into the triangle list the backend was
    /// built from.
    pub fn internal_to_build_order(&self) -> &[u32] {
        match self {
            Accel::Bvh(bvh) => bvh.internal_to_build_order(),
            #[cfg(feature = "embree")]
            Accel::Embree(embree) => embree.internal_to_build_order(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn available_backends() -> impl Iterator<Item = Backend> {
        [Backend::Bvh, Backend::Embree]
            .into_iter()
            .filter(|b| b.is_available())
    }

    /// Barycentrics and the ends of the t interval: the BVH's hit is exact here and both ends
    /// of its interval are included. Embree's may be off by an ulp (its arithmetic differs by
    /// CPU and version: 3.13.5 reports t = 1 − 2⁻²⁴ here and misses with tmax at that t), so
    /// its ends are checked a few ulps away.
    #[test]
    fn hit_barycentrics_and_interval_ends() {
        for backend in available_backends() {
            let accel = Accel::build(
                backend,
                BuildQuality::default(),
                &[[
                    Vec3A::new(-1.0, -1.0, 1.0),
                    Vec3A::new(1.0, -1.0, 1.0),
                    Vec3A::new(0.0, 1.0, 1.0),
                ]],
                Filtering::Unfiltered,
            )
            .unwrap();
            let ray = |tmin, tmax| Ray::new(Vec3A::ZERO, Vec3A::Z, tmin, tmax);
            // The origin's projection (0, 0) is 0.25·v0 + 0.25·v1 + 0.5·v2.
            let expected = Hit {
                triangle: 0,
                t: 1.0,
                u: 0.25,
                v: 0.5,
            };
            let hit = accel.intersect(&ray(0.0, f32::INFINITY)).expect("a hit");
            if backend == Backend::Bvh {
                assert_eq!(hit, expected);
            } else {
                assert_eq!(hit.triangle, 0);
                for (got, want) in [(hit.t, 1.0), (hit.u, 0.25), (hit.v, 0.5)] {
                    assert!((got - want).abs() <= 2.0 * f32::EPSILON, "{hit:?}");
                }
            }
            // The BVH at the exact ends; Embree compares against a t computed apart from the
            // one it reports, so its ends are checked a few ulps away.
            let t = hit.t;
            let cases = if backend == Backend::Bvh {
                vec![
                    (0.0, t, true),
                    (t.next_down(), 2.0, true),
                    (t, 2.0, true),
                    (t, t, true),
                    (0.0, t.next_down(), false),
                    (t.next_up(), 2.0, false),
                ]
            } else {
                let (below, above) = (t - 4.0 * f32::EPSILON, t + 4.0 * f32::EPSILON);
                vec![
                    (0.0, above, true),
                    (below, 2.0, true),
                    (0.0, below, false),
                    (above, 2.0, false),
                ]
            };
            for (tmin, tmax, hit) in cases {
                let what = format!("{backend:?}, t in [{tmin}, {tmax}]");
                assert_eq!(accel.intersect(&ray(tmin, tmax)).is_some(), hit, "{what}");
                assert_eq!(accel.occluded(&ray(tmin, tmax)), hit, "{what}");
            }
        }
    }

    /// Every structure filtered queries can run on: each available backend, the BVH at each
    /// width this CPU supports; named for messages.
    fn filterable_accels(triangles: &[[Vec3A; 3]]) -> Vec<(String, Accel)> {
        let mut accels = Vec::new();
        for backend in available_backends() {
            if backend == Backend::Bvh {
                for width in [BvhWidth::Four, BvhWidth::Eight] {
                    if width.is_supported() {
                        let accel = with_bvh_width(width, || {
                            Accel::build(
                                backend,
                                BuildQuality::default(),
                                triangles,
                                Filtering::Filtered,
                            )
                            .unwrap()
                        });
                        accels.push((format!("{backend:?} {width:?}"), accel));
                    }
                }
            } else {
                let accel = Accel::build(
                    backend,
                    BuildQuality::default(),
                    triangles,
                    Filtering::Filtered,
                )
                .unwrap();
                accels.push((format!("{backend:?}"), accel));
            }
        }
        accels
    }

    /// `accept` in terms of the build order's triangle indices, which do not depend on the
    /// backend.
    fn by_build_index<'a>(
        accel: &'a Accel,
        accept: impl Fn(u32, f32, f32) -> bool + 'a,
    ) -> impl Fn(u32, f32, f32) -> bool + 'a {
        let order = accel.internal_to_build_order();
        move |triangle, u, v| accept(order[triangle as usize], u, v)
    }

    /// A triangle in the plane z = `z` around the z axis (the one of
    /// `hit_barycentrics_and_interval_ends`, scaled by `size`).
    fn facing_triangle(z: f32, size: f32) -> [Vec3A; 3] {
        [
            Vec3A::new(-size, -size, z),
            Vec3A::new(size, -size, z),
            Vec3A::new(0.0, size, z),
        ]
    }

    #[test]
    fn filter_passes_rays_through_rejected_triangles() {
        let triangles = [facing_triangle(1.0, 1.0), facing_triangle(2.0, 1.0)];
        for (name, accel) in filterable_accels(&triangles) {
            let ray = |tmax| Ray::new(Vec3A::ZERO, Vec3A::Z, 0.0, tmax);
            // The hit's build-order triangle, checked against the expected t and barycentrics
            // (0.25, 0.5): exactly for the BVH, within a few ulps for Embree (see
            // `hit_barycentrics_and_interval_ends`).
            let expect = |hit: Option<Hit>, triangle: u32, t: f32| {
                let hit = hit.unwrap_or_else(|| panic!("{name}: no hit, expected {triangle}"));
                assert_eq!(
                    accel.internal_to_build_order()[hit.triangle as usize],
                    triangle,
                    "{name}: {hit:?}"
                );
                let ulps = if matches!(accel, Accel::Bvh(_)) {
                    0.0
                } else {
                    4.0
                };
                for (got, want) in [(hit.t, t), (hit.u, 0.25), (hit.v, 0.5)] {
                    assert!(
                        (got - want).abs() <= ulps * f32::EPSILON * want,
                        "{name}: {hit:?}"
                    );
                }
            };
            let not_near = by_build_index(&accel, |triangle, _, _| triangle != 0);
            let not_far = by_build_index(&accel, |triangle, _, _| triangle != 1);
            let everything = |_, _, _| true;
            let all = f32::INFINITY;
            expect(accel.intersect(&ray(all)), 0, 1.0);
            expect(accel.intersect_filtered(&ray(all), &everything), 0, 1.0);
            expect(accel.intersect_filtered(&ray(all), &not_near), 1, 2.0);
            expect(accel.intersect_filtered(&ray(all), &not_far), 0, 1.0);
            assert_eq!(
                accel.intersect_filtered(&ray(1.5), &not_near),
                None,
                "{name}"
            );
            assert!(accel.occluded(&ray(1.5)), "{name}");
            assert!(accel.occluded_filtered(&ray(1.5), &everything), "{name}");
            assert!(!accel.occluded_filtered(&ray(1.5), &not_near), "{name}");
            // Just past the far triangle (Embree's t may round above 2).
            assert!(accel.occluded_filtered(&ray(2.001), &not_near), "{name}");
            assert!(accel.occluded_filtered(&ray(1.5), &not_far), "{name}");
        }
    }

    #[test]
    fn filter_rejecting_everything_hits_nothing() {
        let mut rng = Rng::new(18, 1);
        let triangles = random_soup(&mut rng, 50);
        for (name, accel) in filterable_accels(&triangles) {
            let mut hits = 0;
            for _ in 0..500 {
                let ray = random_soup_ray(&mut rng);
                hits += accel.intersect(&ray).is_some() as u32;
                assert_eq!(accel.intersect_filtered(&ray, &|_, _, _| false), None);
                assert!(!accel.occluded_filtered(&ray, &|_, _, _| false), "{name}");
            }
            assert!(hits > 50, "{name}: {hits} hits");
        }
    }

    /// A filter on barycentrics keeps the half u < 1/2 of a triangle: rays through the other
    /// half go on to a larger triangle behind it.
    #[test]
    fn filter_on_barycentrics_cuts_a_triangle_in_half() {
        let triangles = [facing_triangle(1.0, 1.0), facing_triangle(3.0, 10.0)];
        for (name, accel) in filterable_accels(&triangles) {
            let front_half = by_build_index(&accel, |triangle, u, _| triangle == 1 || u < 0.5);
            // Rays along z through a grid of barycentrics (u, v) of the front triangle,
            // away from its edges and from u = 1/2. Its point there is
            // (-1 + 2u + v, -1 + 2v, 1), and the back triangle's barycentrics at the same x, y
            // are ((x + 10 - 10 v') / 20, v' = (y + 10) / 20).
            let steps = 20;
            let mut rays = [0; 2];
            for i in 0..steps {
                for j in 0..steps - i {
                    let (u, v) = (
                        (i as f32 + 0.3) / steps as f32,
                        (j as f32 + 0.3) / steps as f32,
                    );
                    if u + v > 0.97 {
                        continue;
                    }
                    let (x, y) = (-1.0 + 2.0 * u + v, -1.0 + 2.0 * v);
                    let ray = Ray::new(Vec3A::new(x, y, 0.0), Vec3A::Z, 0.0, f32::INFINITY);
                    let hit = accel.intersect_filtered(&ray, &front_half).expect(&name);
                    let triangle = accel.internal_to_build_order()[hit.triangle as usize];
                    let what = format!("{name}: u {u}, v {v}, {hit:?}");
                    let (t, expected_u, expected_v) = if u < 0.5 {
                        (1.0, u, v)
                    } else {
                        let back_v = (y + 10.0) / 20.0;
                        (3.0, (x + 10.0 - 10.0 * back_v) / 20.0, back_v)
                    };
                    assert_eq!(triangle, (u >= 0.5) as u32, "{what}");
                    assert!((hit.t - t).abs() < 1e-5, "{what}");
                    assert!((hit.u - expected_u).abs() < 1e-5, "{what}");
                    assert!((hit.v - expected_v).abs() < 1e-5, "{what}");
                    // A segment that ends between the two triangles is blocked only by the
                    // kept half.
                    let short = Ray { tmax: 2.0, ..ray };
                    assert_eq!(
                        accel.occluded_filtered(&short, &front_half),
                        u < 0.5,
                        "{what}"
                    );
                    assert!(accel.occluded(&short), "{what}");
                    rays[(u >= 0.5) as usize] += 1;
                }
            }
            assert!(rays[0] > 100 && rays[1] > 30, "{rays:?}");
        }
    }

    /// Triangles of random size and orientation in a box of side 10 around the origin.
    fn random_soup(rng: &mut Rng, count: usize) -> Vec<[Vec3A; 3]> {
        let mut point = || Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        (0..count)
            .map(|_| {
                let center = point() * 5.0;
                [
                    center + point() * 2.0,
                    center + point() * 2.0,
                    center + point() * 2.0,
                ]
            })
            .collect()
    }

    fn random_soup_ray(rng: &mut Rng) -> Ray {
        let mut point = || Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        let origin = point() * 6.0;
        let direction = point().normalize();
        Ray::new(origin, direction, 0.0, f32::INFINITY)
    }

    /// A checkerboard of 4×4 cells in barycentrics, shifted by a pseudo-random bit per
    /// triangle (of the build order).
    fn checkerboard(triangle: u32, u: f32, v: f32) -> bool {
        let flip = triangle.wrapping_mul(0x9e37_79b9) >> 31;
        ((u * 4.0).floor() as i32 + (v * 4.0).floor() as i32 + flip as i32) % 2 == 0
    }

    /// The closest hit `accept` keeps, found the slow way with unfiltered queries: re-traced
    /// from just past each rejected hit. Embree may report a t an ulp below the one it
    /// compares with tmin (t = 1 − 2⁻²⁴ for an exact 1), so tmin moves past both the reported
    /// t and itself, or a re-trace could find the same hit forever.
    fn retraced(accel: &Accel, ray: &Ray, accept: &impl Fn(u32, f32, f32) -> bool) -> Option<Hit> {
        let mut ray = *ray;
        loop {
            let hit = accel.intersect(&ray)?;
            if accept(hit.triangle, hit.u, hit.v) {
                return Some(hit);
            }
            ray.tmin = hit.t.max(ray.tmin).next_up();
        }
    }

    /// On a random soup with a checkerboard filter, every structure agrees with re-tracing
    /// its own unfiltered queries, and (in build-order triangles) with every other one.
    #[test]
    fn filtered_queries_agree_on_a_random_soup() {
        let mut rng = Rng::new(18, 2);
        let triangles = random_soup(&mut rng, 300);
        let rays: Vec<Ray> = (0..3000).map(|_| random_soup_ray(&mut rng)).collect();
        let accels = filterable_accels(&triangles);
        let mut answers = Vec::new();
        for (name, accel) in &accels {
            let accept = by_build_index(accel, checkerboard);
            let order = accel.internal_to_build_order();
            let mut changed_by_filter = 0;
            let mut list = Vec::new();
            for ray in &rays {
                let hit = accel.intersect_filtered(ray, &accept);
                assert_eq!(hit, retraced(accel, ray, &accept), "{name}: {ray:?}");
                changed_by_filter += (hit != accel.intersect(ray)) as u32;
                // Occlusion up to just past the filtered hit, and up to just before it.
                let end = hit.map_or(f32::INFINITY, |h| h.t);
                let blocked = Ray {
                    tmax: end * 1.0001,
                    ..*ray
                };
                assert_eq!(
                    accel.occluded_filtered(&blocked, &accept),
                    hit.is_some(),
                    "{name}: {ray:?}"
                );
                if hit.is_some() {
                    let short = Ray {
                        tmax: end * 0.9999,
                        ..*ray
                    };
                    assert!(!accel.occluded_filtered(&short, &accept), "{name}: {ray:?}");
                }
                list.push(hit.map(|h| (order[h.triangle as usize], h.t, h.u, h.v)));
            }
            assert!(changed_by_filter > 300, "{name}: {changed_by_filter}");
            answers.push(list);
        }
        for ((name, _), list) in accels.iter().zip(&answers).skip(1) {
            let differing = list
                .iter()
                .zip(&answers[0])
                .filter(|(a, b)| match (a, b) {
                    (None, None) => false,
                    (Some(a), Some(b)) => {
                        a.0 != b.0
                            || (a.1 - b.1).abs() > 1e-5 * a.1.max(1.0)
                            || (a.2 - b.2).abs() > 1e-5
                            || (a.3 - b.3).abs() > 1e-5
                    }
                    _ => true,
                })
                .count();
            assert_eq!(differing, 0, "{name} against {}", accels[0].0);
        }
    }

    #[test]
    fn unavailable_backend_is_unsupported() {
        for backend in [Backend::Bvh, Backend::Embree] {
            match Accel::build(backend, BuildQuality::default(), &[], Filtering::Unfiltered) {
                Ok(_) => assert!(backend.is_available()),
                Err(e) => {
                    assert!(!backend.is_available());
                    assert_eq!(e.status, crate::error::MLT_STATUS_UNSUPPORTED);
                }
            }
        }
    }
}
