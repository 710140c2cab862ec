//! The surface interaction: what a ray hit means at the surface, built once from the hit.
//!
//! Every integrator and mutation that turns a hit into a path vertex starts from a
//! [`SurfaceInteraction`] and asks it for the surface's [`Bsdf`], so nothing above this
//! module reads the scene's per-triangle shading data or material array. Textures, shading
//! normals and new materials change what is built here, not the integrators.
//!
//! Sits between the integrators (above) and the scene, BSDFs and ray queries (below).

use crate::accel::{Hit, Ray};
use crate::bsdf::Bsdf;
use crate::scene::Scene;
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// A point where a ray met a surface. Small and `Copy`: hot paths build one per hit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfaceInteraction {
    pub p: Vec3A,
    /// Unit geometric normal of the triangle's front (counter-clockwise) side: for cosines
    /// in geometry terms and for moving ray origins off the surface. (The BSDF's shading
    /// frame may differ: interpolated or mapped normals.)
    pub geometric_normal: Vec3A,
    /// Barycentrics of the hit: the point is `(1-u-v)·v0 + u·v1 + v·v2`. Where the vertex
    /// attributes (shading normals, texture coordinates) are interpolated.
    pub uv: [f32; 2],
    /// Internal triangle index.
    pub triangle: u32,
    /// Area density with which light sampling picks this point (0: not on a light); what
    /// MIS weighs an emitter found by BSDF sampling with.
    pub light_area_pdf: f32,
}

impl SurfaceInteraction {
    /// The interaction at `hit`, the closest hit of `ray` in `scene`.
    #[inline]
    pub fn new(scene: &Scene, ray: &Ray, hit: &Hit) -> Self {
        let shading = &scene.shading[hit.triangle as usize];
        SurfaceInteraction {
            p: ray.origin + ray.direction * hit.t,
            geometric_normal: shading.normal,
            uv: [hit.u, hit.v],
            triangle: hit.triangle,
            light_area_pdf: shading.light_area_pdf,
        }
    }

    /// The surface's BSDF here, its colours in `channels`, its textures at full resolution.
    #[inline]
    pub fn bsdf(&self, scene: &Scene, channels: &Channels) -> Bsdf {
        scene.bsdf_at(self.triangle, self.uv, 0.0, channels)
    }

    /// The surface's BSDF here with its textures filtered over a ray footprint `footprint`
    /// wide in space (0: full resolution, as `bsdf`).
    #[inline]
    pub fn filtered_bsdf(&self, scene: &Scene, footprint: f32, channels: &Channels) -> Bsdf {
        scene.bsdf_at(self.triangle, self.uv, footprint, channels)
    }

    /// Radiance the surface emits from its front side (its material's emission; only
    /// surfaces with `light_area_pdf` > 0 are lights), in `channels`.
    #[inline]
    pub fn emission(&self, scene: &Scene, channels: &Channels) -> Spectrum {
        scene.emission(self.triangle, self.uv, channels)
    }
}

/// The BSDF at a path vertex stored without its interaction (BDPT and path-space vertices
/// keep only the point, the geometric normal, the triangle and the barycentrics, to stay
/// small): the same BSDF the interaction gave.
#[inline]
pub(crate) fn vertex_bsdf(
    scene: &Scene,
    triangle: u32,
    barycentrics: [f32; 2],
    channels: &Channels,
) -> Bsdf {
    scene.bsdf_at(triangle, barycentrics, 0.0, channels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Backend;
    use crate::bsdf::BsdfLobes;
    use crate::scene::{Material, SceneDesc};

    /// One emissive mirror triangle facing -z: the interaction of a hit carries the hit's
    /// point, barycentrics and triangle, and the surface's normal, material and light.
    #[test]
    fn interaction_of_a_hit() {
        let positions = [-1.0, -1.0, 1.0, 1.0, -1.0, 1.0, 0.0, 1.0, 1.0];
        let materials = [Material::mirror([0.5; 3]).with_emission([2.0; 3])];
        let scene = Scene::new(&SceneDesc {
            positions: &positions,
            indices: &[0, 2, 1],
            material_ids: &[],
            materials: &materials,
            lights: Default::default(),
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY);
        let hit = scene.accel.intersect(&ray).unwrap();
        let si = SurfaceInteraction::new(&scene, &ray, &hit);
        assert_eq!(si.p, Vec3A::new(0.0, 0.0, 1.0));
        assert_eq!(si.geometric_normal, Vec3A::new(0.0, 0.0, -1.0));
        assert_eq!(
            si.bsdf(&scene, &Channels::Rgb).shading_normal(),
            si.geometric_normal
        );
        assert_eq!(si.uv, [hit.u, hit.v]);
        assert_eq!(si.triangle, hit.triangle);
        // The only light: picked with probability 1 over its area 2.
        assert_eq!(si.light_area_pdf, 0.5);
        assert_eq!(si.emission(&scene, &Channels::Rgb), Spectrum::splat(2.0));
        assert!(
            si.bsdf(&scene, &Channels::Rgb)
                .lobes()
                .contains(BsdfLobes::SPECULAR)
        );
        let light = scene.lights.sample_vertex(0.3, [0.2, 0.7]).unwrap();
        assert!(light.light.is_area(), "the only light is an area light");
        assert_eq!((light.triangle, light.pdf), (si.triangle, 0.5));
        assert_eq!(light.normal, si.geometric_normal);
    }
}
