//! Unidirectional path tracing: BSDF importance sampling, next-event estimation to every
//! kind of light, multiple importance sampling (power heuristic) against BSDF sampling for
//! the lights rays can hit (area lights, the environment, the sun's disc), and Russian
//! roulette. Camera paths may carry a ray cone, the pixel's footprint, over which the
//! textures of the surfaces they meet are filtered (mip-mapped) up to their first diffuse or
//! glossy bounce.

use super::{PixelEstimator, SampleCounters, light_shadow_ray, spawn_ray};
use crate::bsdf::{Bsdf, TransportMode};
use crate::film::Splat;
use crate::interaction::SurfaceInteraction;
use crate::sampling::{PixelSampler, Sampler, power_heuristic};
use crate::scene::{CameraModel, Scene};
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// When Russian roulette may end a path, and how likely it lets one go on at most.
#[derive(Clone, Copy, Debug)]
pub struct Roulette {
    /// Bounces after which it may end a path.
    pub start_depth: u32,
    /// Highest survival probability: below 1, paths always carry some chance of ending.
    pub max_survival: f32,
}

/// A ray cone (after Akenine-Möller et al., "Texture Level of Detail Strategies for
/// Real-Time Ray Tracing"): a camera ray with the spread of its pixel, whose width at a hit
/// is the footprint textures are filtered over there. A specular bounce keeps the cone
/// (growing on from its width there with its spread: exact for flat mirrors, an
/// approximation through refraction, which narrows or widens a cone, and off curved
/// surfaces, which bend it); the first diffuse or glossy
/// bounce ends it, and later vertices read textures at full resolution, as every other
/// strategy does there (a wide lobe averages the texture itself).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCone {
    /// Width at the ray's origin.
    pub width: f32,
    /// Growth of the width per unit of distance (the spread angle, small).
    pub spread: f32,
}

impl RayCone {
    /// No cone: textures at full resolution.
    pub const NONE: RayCone = RayCone {
        width: 0.0,
        spread: 0.0,
    };

    /// The cone of a camera ray through one pixel of `camera`.
    #[inline]
    pub fn through_pixel(camera: &CameraModel) -> RayCone {
        RayCone {
            width: 0.0,
            spread: camera.pixel_spread_angle(),
        }
    }

    /// The width `distance` along the ray.
    #[inline]
    pub fn width_at(&self, distance: f32) -> f32 {
        self.width + self.spread * distance
    }
}

pub struct PathTracer<'a> {
    pub scene: &'a Scene,
    /// At most this many scattering vertices between camera and light.
    pub max_depth: u32,
    /// Paths with fewer scattering vertices contribute nothing (another pass renders them).
    pub min_depth: u32,
    /// Whether paths carry wavelengths (one more sampler coordinate, read first) instead
    /// of RGB.
    pub spectral: bool,
    pub roulette: Roulette,
    /// Whether camera samples carry ray cones (`RayCone`): textures filtered over the
    /// pixel's footprint. Off, camera paths read textures at full resolution as the other
    /// algorithms do.
    pub texture_filtering: bool,
}

impl PathTracer<'_> {
    /// Radiance arriving at `origin` from `direction` (unit length), as linear RGB, the
    /// textures met filtered over `cone` (`RayCone::NONE`: full resolution). `rays` counts
    /// traced rays.
    #[inline]
    pub fn radiance<S: Sampler>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        cone: RayCone,
        rng: &mut S,
        rays: &mut u64,
    ) -> Spectrum {
        // Two copies of the loop: paths without a cone pay nothing for cones.
        if cone == RayCone::NONE {
            self.trace::<S, false>(origin, direction, cone, rng, rays)
        } else {
            self.trace::<S, true>(origin, direction, cone, rng, rays)
        }
    }

    /// `radiance`, `CONE` saying whether `cone` is not `RayCone::NONE`.
    #[inline(always)]
    fn trace<S: Sampler, const CONE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        mut cone: RayCone,
        rng: &mut S,
        rays: &mut u64,
    ) -> Spectrum {
        let scene = self.scene;
        let mut channels = Channels::new(self.spectral, || rng.uniform());
        let mut radiance = Spectrum::ZERO;
        let mut throughput = Spectrum::ONE;
        let mut ray = crate::accel::Ray::new(origin, direction, 0.0, f32::INFINITY);
        // The previous vertex's scattering density, for MIS against light sampling.
        let mut previous_pdf = 0.0f32;
        let mut previous_specular = true;
        // The product of the refractions' radiance scalings so far, which Russian roulette
        // divides out of the throughput (as pbrt-v4 and Mitsuba do): a path inside glass
        // carries (1/η)² the throughput with no less to contribute.
        let mut radiance_scale = 1.0f32;
        // The point the current ray leaves and its triangle (`None`: the lens), which with
        // the one it reaches tell the volume it travels through and how far (the ray's
        // origin is moved off the surface, so its `t` is not the distance).
        let mut leaving: (Option<u32>, Vec3A) = (None, origin);

        // `depth` = scattering vertices before the surface this iteration hits.
        let mut depth = 0;
        loop {
            *rays += 1;
            let Some(hit) = scene.closest_hit(&ray) else {
                // The ray left the scene: the environment and the sun's disc.
                if depth >= self.min_depth && scene.lights.has_infinite_light() {
                    if scene.has_media() {
                        throughput *= scene.transmittance(
                            leaving.0,
                            None,
                            ray.direction,
                            f32::INFINITY,
                            &channels,
                        );
                    }
                    let emission = scene.lights.infinite_radiance(ray.direction, &channels);
                    let weight = if previous_specular {
                        1.0
                    } else {
                        power_heuristic(previous_pdf, scene.lights.infinite_pdf(ray.direction))
                    };
                    radiance += throughput * emission * weight;
                }
                break;
            };
            let si = SurfaceInteraction::new(scene, &ray, &hit);
            let normal = si.geometric_normal;
            let wo = -ray.direction;
            let cos_o = wo.dot(normal);
            // The cone's footprint on the surface: its width over the incidence cosine (the
            // long axis of the ellipse it cuts). 0 without a cone (and 0/0 = NaN, grazing
            // without a cone, reads full resolution too).
            let cone_width = cone.width_at(hit.t);
            let bsdf = if CONE {
                si.filtered_bsdf(scene, cone_width / cos_o.abs(), &channels)
            } else {
                si.bsdf(scene, &channels)
            };
            if bsdf.is_dispersive() {
                channels.keep_hero_only();
            }
            if scene.has_media() {
                throughput *= scene.transmittance_between(
                    leaving.0,
                    Some(hit.triangle),
                    leaving.1,
                    si.p,
                    &channels,
                );
            }
            let p = si.p;

            // Emission from the front side.
            if si.light_area_pdf > 0.0 && cos_o > 0.0 && depth >= self.min_depth {
                let emission = si.emission(scene, &channels);
                let weight = if previous_specular {
                    1.0
                } else {
                    let light_pdf = si.light_area_pdf * hit.t * hit.t / cos_o;
                    power_heuristic(previous_pdf, light_pdf)
                };
                radiance += throughput * emission * weight;
            }
            if depth >= self.max_depth {
                break;
            }

            // A light sample here ends a path of depth + 1 scattering vertices. It is
            // weighted by MIS against the BSDF-sampled ray even at the last vertex, where that
            // ray only looks for emission: light sampling alone has unbounded variance near
            // concave edges (the geometry term's 1/d² where two surfaces meet).
            // Every vertex reads the same coordinates (light sample, BSDF sample, roulette)
            // whether or not it uses them, so a Metropolis chain's small step that changes a
            // vertex from specular to diffuse leaves the later vertices' numbers in place.
            // The light's choice one number, its point a pair (a 2D low-discrepancy slot).
            let u_select = rng.uniform();
            let [u_point_x, u_point_y] = rng.uniform2();
            let u_light = [u_select, u_point_x, u_point_y];
            let u_bsdf = rng.uniform2();
            let u_lobe = rng.uniform();
            let u_roulette = rng.uniform();
            // Only a lobe with a density (diffuse, glossy) can meet a light sample.
            if bsdf.lobes().has_non_specular() && depth + 1 >= self.min_depth {
                radiance +=
                    throughput * self.sample_light(&si, wo, &bsdf, u_light, &channels, rays);
            }

            let Some(sample) = bsdf.sample(wo, u_bsdf, u_lobe, TransportMode::Radiance) else {
                break;
            };
            throughput *= sample.weight;
            previous_pdf = sample.pdf;
            previous_specular = sample.specular;
            cone = if !CONE {
                RayCone::NONE
            } else if sample.specular {
                RayCone {
                    width: cone_width,
                    ..cone
                }
            } else {
                RayCone::NONE
            };
            radiance_scale *= sample.radiance_scale;
            depth += 1;

            if depth >= self.roulette.start_depth {
                let survival =
                    (throughput.max_component() / radiance_scale).min(self.roulette.max_survival);
                if u_roulette >= survival {
                    break;
                }
                throughput /= survival;
            }
            if throughput.is_black() {
                break;
            }
            ray = spawn_ray(scene, p, normal, sample.wi);
            leaving = (Some(si.triangle), p);
        }
        channels.rgb_of(radiance)
    }

    /// Next-event estimation: one light (chosen by power) and a point or direction on it,
    /// weighted by MIS against BSDF sampling where BSDF sampling could find it too. Returns
    /// the contribution before the path throughput.
    // Always inlined: called once per vertex, and as a call it costs ~1.5% more
    // instructions (the compiler stopped inlining it once it took a `Bsdf`).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn sample_light(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3A,
        bsdf: &Bsdf,
        [u_select, u_point @ ..]: [f32; 3],
        channels: &Channels,
        rays: &mut u64,
    ) -> Spectrum {
        let scene = self.scene;
        let (p, normal) = (si.p, si.geometric_normal);
        let Some(light) = scene.sample_li(p, u_select, u_point, channels) else {
            return Spectrum::ZERO;
        };
        let wi = light.wi;
        let f = bsdf.eval(wo, wi, TransportMode::Radiance);
        if f.is_black() || light.radiance.is_black() || light.pdf <= 0.0 {
            return Spectrum::ZERO;
        }
        let Some(ray) = light_shadow_ray(scene, p, normal, &light) else {
            return Spectrum::ZERO;
        };
        *rays += 1;
        if scene.blocked(&ray) {
            return Spectrum::ZERO;
        }
        let light_pdf = light.solid_angle_pdf();
        // A delta light: no other strategy finds it, so no MIS.
        let weight = if light.light.is_delta() {
            1.0
        } else {
            power_heuristic(light_pdf, bsdf.pdf(wo, wi))
        };
        let mut arriving = f * light.radiance;
        if scene.has_media() {
            arriving *= scene.light_transmittance(si.triangle, &light, channels);
        }
        arriving * (wi.dot(normal).abs() * weight / light_pdf)
    }
}

impl PixelEstimator for PathTracer<'_> {
    type Scratch = ();

    fn scratch(&self) {}

    fn splats(&self) -> bool {
        false
    }

    #[inline]
    fn sample(
        &self,
        camera: &CameraModel,
        x: f32,
        y: f32,
        sampler: &mut PixelSampler,
        counters: &mut SampleCounters,
        _scratch: &mut (),
        _splats: &mut Vec<Splat>,
    ) -> Spectrum {
        let lens = sampler.uniform2();
        let (origin, direction) = camera.generate_ray(x, y, lens);
        let cone = if self.texture_filtering && self.scene.has_textures() {
            RayCone::through_pixel(camera)
        } else {
            RayCone::NONE
        };
        self.radiance(origin, direction, cone, sampler, &mut counters.rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Backend, Ray};
    use crate::scene::{Camera, Material, SceneDesc};
    use crate::texture::{TexelData, TextureDesc, TextureEncoding, TextureRef};
    use std::borrow::Cow;

    /// The level of detail a camera ray's cone gives a textured plane equals the analytic
    /// one. A pinhole h = 1 above a 2 × 2 quad in y = 0 whose texture coordinates run over
    /// it once (0.5 units of texture coordinate per unit of length) and a 1024 × 1024
    /// texture stretched by `KHR_texture_transform`'s scale (4, 1): a ray meeting the plane
    /// at angle θ from its normal travels t = h / cos θ, its cone is spread · t wide there
    /// and its footprint on the plane spread · h / cos² θ, which is
    /// spread · h / cos² θ · 0.5 · √(4 · 1) · 1024 texels wide.
    #[test]
    fn a_plane_at_a_known_distance_and_angle_gets_the_analytic_level_of_detail() {
        let positions = [
            -1.0, 0.0, -1.0, 1.0, 0.0, -1.0, 1.0, 0.0, 1.0, -1.0, 0.0, 1.0,
        ];
        let texcoords = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
        let texels = vec![0u8; 1024 * 1024];
        let texture = TextureDesc {
            width: 1024,
            height: 1024,
            channels: 1,
            data: TexelData::U8(Cow::Owned(texels)),
            encoding: TextureEncoding::Linear,
            wrap_u: Default::default(),
            wrap_v: Default::default(),
            filter: Default::default(),
        };
        let reference = TextureRef {
            scale: [4.0, 1.0],
            ..TextureRef::new(0)
        };
        let materials = [Material {
            base_color_texture: Some(reference),
            ..Material::diffuse([0.5; 3])
        }];
        let scene = Scene::new(&SceneDesc {
            positions: &positions,
            indices: &[0, 2, 1, 0, 3, 2],
            materials: &materials,
            texcoords: &texcoords,
            textures: std::slice::from_ref(&texture),
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap();
        let (height, size) = (1.0f32, 64);
        let camera = Camera {
            eye: [0.0, height, 0.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 0.0, -1.0],
            fov_y_deg: 60.0,
            ..Default::default()
        }
        .model(size, size);
        let spread = 2.0 * (30.0f32).to_radians().tan() / size as f32;
        let cone = RayCone::through_pixel(&camera);
        assert!((cone.spread - spread).abs() < 1e-7);
        for theta_degrees in [0.0f32, 10.0, 20.0] {
            let theta = theta_degrees.to_radians();
            let direction = Vec3A::new(theta.sin(), -theta.cos(), 0.0);
            let ray = Ray::new(camera.eye, direction, 0.0, f32::INFINITY);
            let hit = scene.closest_hit(&ray).unwrap();
            let si = SurfaceInteraction::new(&scene, &ray, &hit);
            // As the path tracer measures it.
            let footprint = cone.width_at(hit.t) / (-direction).dot(si.geometric_normal).abs();
            let point = crate::scene::surface::SurfacePoint {
                footprint,
                ..scene.surface_point(hit.triangle, si.uv)
            };
            let analytic =
                (spread * height / theta.cos().powi(2) * 0.5 * 4.0f32.sqrt() * 1024.0).log2();
            let level = point.level_of_detail(&reference);
            assert!(
                (level - analytic).abs() < 1e-4,
                "θ = {theta_degrees}°: level {level}, analytic {analytic}"
            );
        }
        // Without a cone, the image itself.
        let point = scene.surface_point(0, [0.2, 0.3]);
        assert_eq!(point.level_of_detail(&reference), f32::NEG_INFINITY);
    }
}
