//! The 4-wide node's box test, with glam's `Vec4` (SSE on x86-64, NEON on aarch64): each slab
//! of the four children's boxes in one vector operation.

use super::layout::{Node4, near_and_far_bounds};
use super::stack::{Lanes, distance_key};
use crate::accel::ray::Ray;
use glam::{Vec3A, Vec4};

/// A ray prepared for the box test: which bound is near on each axis, the origin and the
/// reciprocal direction.
///
/// A zero direction component gives an infinite reciprocal, and the slab (bound − o) · inv is
/// then ±inf (the ray is inside or outside the slab forever) or, for an origin exactly on the
/// bound, NaN. The slabs are combined with the running value as the *second* operand of
/// `max`/`min`, which SSE's maxps/minps (and `f32::max`) return when the first is NaN: a NaN
/// slab then leaves the interval unconstrained, as a ray lying in the slab's plane should.
pub(super) struct BoxRay4 {
    near: [usize; 3],
    far: [usize; 3],
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
}

impl BoxRay4 {
    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> Self {
        let inv = Vec3A::ONE / ray.direction;
        let (near, far) = near_and_far_bounds(inv);
        BoxRay4 {
            near,
            far,
            origin: splat3(ray.origin),
            inv_direction: splat3(inv),
        }
    }

    /// Entry distances of the four children and which of them the ray enters in [tmin, tmax].
    #[inline(always)]
    pub(super) fn intersect(&self, node: &Node4, tmin: f32, tmax: f32) -> (Vec4, u32) {
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

impl Lanes<4> for Vec4 {
    #[inline(always)]
    fn lanes(self) -> [f32; 4] {
        self.to_array()
    }

    #[inline(always)]
    fn places(self, mask: u32) -> [u32; 4] {
        let t = self.to_array();
        let keys: [i32; 4] = std::array::from_fn(|lane| distance_key(t[lane], lane as u32));
        let mut farther = [0; 4];
        for (other, &key) in keys.iter().enumerate() {
            let entered = (mask >> other) & 1;
            for (count, &lane_key) in farther.iter_mut().zip(&keys) {
                *count += entered & (key > lane_key) as u32;
            }
        }
        // Arithmetic rather than a branch on each lane.
        std::array::from_fn(|lane| {
            let outside = ((mask >> lane) & 1).wrapping_sub(1);
            (farther[lane] & !outside) | (3 & outside)
        })
    }
}

/// `v`'s x, y and z, each in all four lanes.
pub(super) fn splat3(v: Vec3A) -> [Vec4; 3] {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}
