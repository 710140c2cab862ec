//! Light-transport estimators.

pub mod path;

use crate::accel::Ray;
use crate::scene::Scene;
use glam::Vec3A;

/// A ray leaving surface point `p` (geometric normal `normal`) in `direction`, with its origin
/// moved off the surface to the side it leaves on, so it cannot hit its own triangle.
#[inline]
pub(crate) fn spawn_ray(scene: &Scene, p: Vec3A, normal: Vec3A, direction: Vec3A) -> Ray {
    let offset = if direction.dot(normal) >= 0.0 {
        normal * scene.ray_epsilon
    } else {
        -normal * scene.ray_epsilon
    };
    Ray::new(p + offset, direction, 0.0, f32::INFINITY)
}

/// A shadow ray from surface point `p` to surface point `target`, both offset off their
/// surfaces; `None` when the points are too close to tell apart.
#[inline]
pub(crate) fn shadow_ray(
    scene: &Scene,
    p: Vec3A,
    normal: Vec3A,
    target: Vec3A,
    target_normal: Vec3A,
) -> Option<Ray> {
    let toward = target - p;
    let origin = p + normal * scene.ray_epsilon.copysign(toward.dot(normal));
    let end = target + target_normal * scene.ray_epsilon.copysign(-toward.dot(target_normal));
    let d = end - origin;
    let length = d.length();
    if length <= scene.ray_epsilon {
        return None;
    }
    Some(Ray::new(origin, d / length, 0.0, length))
}
