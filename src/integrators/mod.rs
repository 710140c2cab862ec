//! Light-transport estimators.

pub mod bdpt;
pub(crate) mod camera_samples;
pub mod mlt;
pub mod path;

use crate::accel::Ray;
use crate::film::Splat;
use crate::interaction::SurfaceInteraction;
use crate::sampling::PixelSampler;
use crate::scene::lights::{Emitter, LightLiSample};
use crate::scene::{CameraModel, Scene};
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// A vertex of a light path: a point on a light (the first), on a surface, or on the lens
/// (the last).
///
/// The first vertex may be a light that is not an emissive triangle (`light`): a point or
/// spot light (`p` its position, `normal` zero), or a light at infinity (the environment
/// and sun disc, or a directional light), which is a direction, not a point: `normal` is
/// the unit direction from the scene towards the light and `p` is zero (meaningless).
/// Densities towards and from such a vertex are in solid angle, as in BDPT.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PathVertex {
    pub p: Vec3A,
    /// The triangle's front geometric normal; the camera's view direction for the lens;
    /// see above for lights that are not triangles.
    pub normal: Vec3A,
    /// Internal triangle index (unused for the lens and for `light` vertices).
    pub triangle: u32,
    /// The point's barycentrics on `triangle`: where its BSDF (shading normal, textures)
    /// is evaluated.
    pub barycentrics: [f32; 2],
    /// `Some` for a first vertex on a light that is not an emissive triangle (a point on an
    /// emissive triangle is `None`, told by its triangle, as any surface vertex).
    pub light: Option<Emitter>,
    /// Which lobe scatters the path here where the BSDF has a Dirac lobe beside one with a
    /// density (a smooth coat over a diffuse base, a smooth clear coat): the Dirac one
    /// (true) or the other. Which Dirac lobe follows from the directions: the sides say
    /// reflection or refraction, and the nearer mirror which of two (`Bsdf::specular_lobe`). Read only at such BSDFs: elsewhere the BSDF alone says which (see
    /// `PathSpace::is_specular`). False at the path's ends.
    pub dirac: bool,
}

impl PathVertex {
    /// The vertex at a surface interaction. It keeps the geometric normal and the
    /// barycentrics the BSDF is rebuilt from (see `interaction::vertex_bsdf`).
    #[inline]
    pub fn surface(si: &SurfaceInteraction) -> PathVertex {
        PathVertex::on_triangle(si.p, si.geometric_normal, si.triangle, si.uv)
    }

    /// The vertex at barycentrics `barycentrics` of internal triangle `triangle`, point `p`
    /// with front geometric normal `normal`.
    #[inline]
    pub fn on_triangle(p: Vec3A, normal: Vec3A, triangle: u32, barycentrics: [f32; 2]) -> Self {
        PathVertex {
            p,
            normal,
            triangle,
            barycentrics,
            light: None,
            dirac: false,
        }
    }

    /// A vertex on the lens (or any point that is not on a surface or a light).
    #[inline]
    pub fn point(p: Vec3A, normal: Vec3A) -> PathVertex {
        PathVertex {
            p,
            normal,
            triangle: 0,
            barycentrics: [0.0; 2],
            light: None,
            dirac: false,
        }
    }

    /// The light at infinity `emitter` seen towards unit direction `toward`.
    #[inline]
    pub fn at_infinity(emitter: Emitter, toward: Vec3A) -> PathVertex {
        PathVertex {
            p: Vec3A::ZERO,
            normal: toward,
            triangle: 0,
            barycentrics: [0.0; 2],
            light: Some(emitter),
            dirac: false,
        }
    }

    /// The vertex on light `emitter` at `p` with normal `normal` (a triangle's and the
    /// barycentrics for an area light): a point on a triangle, a point without a surface
    /// (a delta position), or a direction at infinity (`normal`).
    #[inline]
    pub fn on_light(
        emitter: Emitter,
        p: Vec3A,
        normal: Vec3A,
        triangle: u32,
        barycentrics: [f32; 2],
    ) -> PathVertex {
        if emitter.is_area() {
            PathVertex::on_triangle(p, normal, triangle, barycentrics)
        } else if emitter.at_infinity() {
            PathVertex::at_infinity(emitter, normal)
        } else {
            PathVertex {
                p,
                normal: Vec3A::ZERO,
                triangle: 0,
                barycentrics: [0.0; 2],
                light: Some(emitter),
                dirac: false,
            }
        }
    }

    /// The light of a path's first vertex (a surface vertex's is its triangle's).
    #[inline]
    pub fn emitter(&self) -> Emitter {
        self.light.unwrap_or(Emitter::triangle(self.triangle))
    }

    /// Whether the vertex is a direction at infinity.
    #[inline]
    pub fn is_at_infinity(&self) -> bool {
        matches!(self.light, Some(e) if e.at_infinity())
    }

    /// Whether the vertex is a point light without a surface (a delta position).
    #[inline]
    pub fn is_delta_position(&self) -> bool {
        matches!(self.light, Some(e) if e.is_delta_position())
    }
}

/// Counters a sample updates; summed per work unit.
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleCounters {
    pub rays: u64,
}

/// An estimator of pixel values from camera samples, run by the render driver.
pub trait PixelEstimator: Sync {
    /// Per-work-unit memory reused by every sample (path vertices...): allocated once per
    /// render, so sampling never allocates.
    type Scratch: Send;
    fn scratch(&self) -> Self::Scratch;
    /// Whether samples add splats (then the film keeps a splat image).
    fn splats(&self) -> bool;
    /// One sample through film position (x, y) in pixels. Returns the contribution to that
    /// pixel; contributions to other pixels go to `splats`.
    #[allow(clippy::too_many_arguments)]
    fn sample(
        &self,
        camera: &CameraModel,
        x: f32,
        y: f32,
        sampler: &mut PixelSampler,
        counters: &mut SampleCounters,
        scratch: &mut Self::Scratch,
        splats: &mut Vec<Splat>,
    ) -> Spectrum;
}

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

/// The first ray of a light subpath from light vertex `emitter` at `origin`: off an area
/// light's surface (normal `normal`), from the point itself for the other lights.
#[inline]
pub(crate) fn emission_ray(
    scene: &Scene,
    emitter: Emitter,
    origin: Vec3A,
    normal: Vec3A,
    direction: Vec3A,
) -> Ray {
    if emitter.is_area() {
        spawn_ray(scene, origin, normal, direction)
    } else {
        Ray::new(origin, direction, 0.0, f32::INFINITY)
    }
}

/// A shadow ray from surface point `p` (geometric normal `normal`) towards the light vertex
/// of `light`: to its point, or along `wi` to a light at infinity; `None` when the points
/// are too close to tell apart.
#[inline]
pub(crate) fn light_shadow_ray(
    scene: &Scene,
    p: Vec3A,
    normal: Vec3A,
    light: &LightLiSample,
) -> Option<Ray> {
    if light.light.at_infinity() {
        Some(spawn_ray(scene, p, normal, light.wi))
    } else {
        shadow_ray(scene, p, normal, light.point, light.offset_normal())
    }
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
