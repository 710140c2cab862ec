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
#[doc(hidden)]
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

/// The backends. An enum, not a trait object, so the hot path dispatches without a vtable.
pub enum Accel {
    Bvh(BvhAccel),
    #[cfg(feature = "embree")]
    Embree(EmbreeAccel),
}

impl Accel {
    /// Builds `backend`'s structure over triangles given as vertex triples, none degenerate.
    /// Fails with `MLT_STATUS_UNSUPPORTED` for a backend this build lacks (see
    /// [`Backend::is_available`]), and with Embree's error if Embree fails.
    pub fn build(backend: Backend, triangles: &[[Vec3A; 3]]) -> Result<Accel> {
        match backend {
            Backend::Bvh => Ok(Accel::Bvh(BvhAccel::build(triangles)?)),
            #[cfg(feature = "embree")]
            Backend::Embree => Ok(Accel::Embree(EmbreeAccel::build(triangles)?)),
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

    /// The bytes the structure holds: for the BVH computed from its arrays' lengths, for
    /// Embree the balance of what Embree allocated (counted by its memory monitor) plus our
    /// own arrays. For comparing backends and sizing scenes; allocator overhead is not counted.
    /// The closest hit that `accept(triangle, u, v)` keeps (alpha cut-outs): candidates it
    /// rejects are passed through.
    // A first version on top of `intersect`: it re-traces past each rejected hit.
    #[inline]
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        accept: &impl Fn(u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        let mut ray = *ray;
        loop {
            let hit = self.intersect(&ray)?;
            if accept(hit.triangle, hit.u, hit.v) {
                return Some(hit);
            }
            ray.tmin = hit.t.next_up();
        }
    }

    /// Whether a hit `accept(triangle, u, v)` keeps lies on the ray.
    #[inline]
    pub fn occluded_filtered(&self, ray: &Ray, accept: &impl Fn(u32, f32, f32) -> bool) -> bool {
        self.intersect_filtered(ray, accept).is_some()
    }

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
                &[[
                    Vec3A::new(-1.0, -1.0, 1.0),
                    Vec3A::new(1.0, -1.0, 1.0),
                    Vec3A::new(0.0, 1.0, 1.0),
                ]],
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

    #[test]
    fn unavailable_backend_is_unsupported() {
        for backend in [Backend::Bvh, Backend::Embree] {
            match Accel::build(backend, &[]) {
                Ok(_) => assert!(backend.is_available()),
                Err(e) => {
                    assert!(!backend.is_available());
                    assert_eq!(e.status, crate::error::MLT_STATUS_UNSUPPORTED);
                }
            }
        }
    }
}
