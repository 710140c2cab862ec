//! Ray queries: closest hit and occlusion, behind one interface for every backend.
//!
//! Triangles are addressed by their *internal* index, the order the backend stores them in
//! (for the BVH: leaf order, so a hit needs no indirection). The scene maps internal indices
//! back to the host's triangle ids.

mod bvh;

pub use bvh::BvhAccel;
use glam::Vec3A;

/// A ray with a parametric interval: points `origin + t * direction` for t in [tmin, tmax].
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3A,
    pub direction: Vec3A,
    pub tmin: f32,
    pub tmax: f32,
}

impl Ray {
    #[inline]
    pub fn new(origin: Vec3A, direction: Vec3A, tmin: f32, tmax: f32) -> Self {
        Ray {
            origin,
            direction,
            tmin,
            tmax,
        }
    }
}

/// The closest intersection: internal triangle index, distance and barycentrics
/// (the hit point is `(1-u-v)·v0 + u·v1 + v·v2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub triangle: u32,
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// The backends. An enum, not a trait object, so the hot path dispatches without a vtable.
pub enum Accel {
    Bvh(BvhAccel),
}

impl Accel {
    /// The closest hit with t in [tmin, tmax], if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match self {
            Accel::Bvh(bvh) => bvh.intersect(ray),
        }
    }

    /// Whether anything lies on the ray with t in [tmin, tmax].
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match self {
            Accel::Bvh(bvh) => bvh.occluded(ray),
        }
    }

    /// For each internal triangle index, the index into the triangle list the backend was
    /// built from.
    pub fn internal_to_build_order(&self) -> &[u32] {
        match self {
            Accel::Bvh(bvh) => bvh.internal_to_build_order(),
        }
    }
}
