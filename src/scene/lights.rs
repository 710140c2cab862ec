//! The scene's lights, and light sampling written once: today area lights (emissive
//! triangles), picked in proportion to their emitted power. Every integrator that samples a
//! point on a light (next-event estimation, light subpaths, the bidirectional mutation's new
//! light vertex) calls [`Scene::sample_light`], so another kind of light changes this file,
//! not theirs.

use super::Scene;
use crate::sampling::uniform_triangle;
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// What light sampling needs about one area light.
#[derive(Clone, Copy, Debug)]
pub struct AreaLight {
    pub v0: Vec3A,
    pub edge1: Vec3A,
    pub edge2: Vec3A,
    pub normal: Vec3A,
    pub emission: Spectrum,
    /// Selection probability / area: the area density of light sampling on this light.
    pub area_pdf: f32,
    /// Internal index of the light's triangle.
    pub triangle: u32,
}

/// A point sampled on a light.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightSample {
    pub point: Vec3A,
    /// The light's front normal: it emits into that hemisphere.
    pub normal: Vec3A,
    /// Radiance leaving the front side.
    pub emission: Spectrum,
    /// Density of `point` per unit area, the light's selection probability included.
    pub area_pdf: f32,
    /// Internal index of the light's triangle.
    pub triangle: u32,
}

impl Scene {
    /// Picks a light by power with `u_select` and a uniform point on it with `u_point`;
    /// `None` if the scene has no lights. The caller draws both numbers (always, whether or
    /// not there are lights, where its sampler's coordinates must stay in place).
    #[inline]
    pub(crate) fn sample_light(&self, u_select: f32, u_point: [f32; 2]) -> Option<LightSample> {
        if self.lights.is_empty() {
            return None;
        }
        let (index, _, _) = self.light_distribution.sample_discrete(u_select);
        let light = &self.lights[index];
        let [b1, b2] = uniform_triangle(u_point);
        Some(LightSample {
            point: light.v0 + light.edge1 * b1 + light.edge2 * b2,
            normal: light.normal,
            emission: light.emission,
            area_pdf: light.area_pdf,
            triangle: light.triangle,
        })
    }

    /// Whether the scene has a light to sample.
    #[inline]
    pub(crate) fn has_lights(&self) -> bool {
        !self.lights.is_empty()
    }

    /// The area density with which `sample_light` picks a point on internal triangle
    /// `triangle` (0 for triangles that do not emit).
    #[inline]
    pub(crate) fn light_area_pdf(&self, triangle: u32) -> f32 {
        self.shading[triangle as usize].light_area_pdf
    }

    /// Radiance the front side of internal triangle `triangle` emits, if it is a light
    /// (`light_area_pdf` > 0: the integrators ask that first).
    #[inline]
    pub(crate) fn emission(&self, triangle: u32) -> Spectrum {
        let material = self.shading[triangle as usize].material;
        Spectrum::from(self.materials[material as usize].emission)
    }
}
