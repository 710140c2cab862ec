//! What every backend answers: a ray with its interval, and the closest hit.

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
