//! The scene's lights, and light sampling written once: area lights (emissive triangles),
//! point and spot lights, directional lights, and the lights at infinity (environment and
//! sun disc, one light), picked in proportion to their power.
//!
//! Every light answers the same questions, in the shape of pbrt's light interface:
//! `sample_li` (a light seen from a shading point, for next-event estimation and BDPT's
//! connections), `sample_emission` and `sample_le_ray` (where a light subpath starts and
//! its first ray), `le` (what a ray that found a light at infinity carries), `emitted`,
//! `pdf_origin` and `pdf_le_direction` (a light vertex's emission and densities, for MIS
//! and the Metropolis targets). A light vertex names its light by an [`Emitter`], which the
//! integrators only hand back and ask for its type (area, delta position, at infinity,
//! delta): they never match on the kind of light, so another kind changes this module,
//! not theirs. The `Scene` forwards the questions and answers the lights' own
//! ([`EmissiveSurfaces`]: an area light's textured or spectral emission).
//!
//! Power is measured as Φ/π (luminance times area for an area light), so that a scene of
//! area lights picks them exactly as before the other kinds existed.

mod environment;

pub(crate) use environment::{EnvironmentMap, InfiniteLight, SunDisc, uniform_sphere};

use super::light_desc::{LightsDesc, PunctualLightKind};
use crate::error::{Error, Result};
use crate::sampling::{OrthonormalBasis, uniform_disk, uniform_triangle};
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, PI};

/// What light sampling needs about one area light.
#[derive(Clone, Copy, Debug)]
pub struct AreaLight {
    pub v0: Vec3A,
    pub edge1: Vec3A,
    pub edge2: Vec3A,
    pub normal: Vec3A,
    /// The material's emission factor (an emission texture multiplies it point by point).
    pub emission: Spectrum,
    /// The mean of the emission texture over the triangle relative to 1 (1 without a
    /// texture): scales the power the light is picked by.
    pub power_scale: f32,
    /// Selection probability / area: the area density of light sampling on this light.
    pub area_pdf: f32,
    /// Internal index of the light's triangle.
    pub triangle: u32,
}

/// A spot light's cone, with glTF's smooth falloff.
#[derive(Clone, Copy, Debug)]
struct SpotCone {
    /// Unit axis the light shines along.
    pub axis: Vec3A,
    /// cos of the inner angle: full intensity within it.
    pub cos_inner: f32,
    /// cos of the outer angle: no light beyond it.
    pub cos_outer: f32,
    /// The falloff is `clamp(cos · scale + offset, 0, 1)²` (glTF's recommendation).
    scale: f32,
    offset: f32,
}

impl SpotCone {
    #[inline]
    fn falloff(&self, w: Vec3A) -> f32 {
        let t = (w.dot(self.axis) * self.scale + self.offset).clamp(0.0, 1.0);
        t * t
    }

    /// 1 − cos of the outer angle.
    #[inline]
    fn one_minus_cos_outer(&self) -> f32 {
        1.0 - self.cos_outer
    }
}

/// A point or spot light: a delta position.
#[derive(Clone, Copy, Debug)]
struct PointLight {
    pub position: Vec3A,
    /// Radiant intensity (on the axis, for a spot).
    pub intensity: Spectrum,
    pub cone: Option<SpotCone>,
}

impl PointLight {
    /// Radiant intensity towards unit direction `w` (leaving the light), in `channels`.
    #[inline]
    pub fn intensity(&self, w: Vec3A, channels: &Channels) -> Spectrum {
        let rgb = match &self.cone {
            None => self.intensity,
            Some(cone) => self.intensity * cone.falloff(w),
        };
        channels.illuminant(rgb.to_array())
    }

    /// Density in solid angle with which light subpaths leave in `w`: uniform over the
    /// sphere, or over the spot's outer cone.
    #[inline]
    pub fn direction_pdf(&self, w: Vec3A) -> f32 {
        match &self.cone {
            None => 1.0 / (4.0 * PI),
            Some(cone) if w.dot(cone.axis) >= cone.cos_outer => {
                1.0 / (2.0 * PI * cone.one_minus_cos_outer())
            }
            Some(_) => 0.0,
        }
    }

    #[inline]
    fn sample_direction(&self, u: [f32; 2]) -> Vec3A {
        match &self.cone {
            None => uniform_sphere(u),
            Some(cone) => {
                let cos_theta = 1.0 - u[0] * cone.one_minus_cos_outer();
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
                OrthonormalBasis::from_normal(cone.axis).to_world(Vec3A::new(
                    cos_phi * sin_theta,
                    sin_phi * sin_theta,
                    cos_theta,
                ))
            }
        }
    }

    /// Φ/π.
    fn power(&self) -> f32 {
        let luminance = self.intensity.luminance();
        match &self.cone {
            None => 4.0 * luminance,
            // The cone's solid angle with the falloff averaged to ½ between the angles.
            Some(cone) => 2.0 * luminance * (1.0 - 0.5 * (cone.cos_inner + cone.cos_outer)),
        }
    }
}

/// One light the scene picks among.
#[derive(Clone, Copy, Debug)]
enum Light {
    Area(AreaLight),
    Point(PointLight),
    /// A delta direction: `toward` (unit) points from the scene to the light.
    Directional {
        toward: Vec3A,
        irradiance: Spectrum,
    },
    /// The scene's `InfiniteLight` (environment and sun disc).
    Infinite,
}

/// Which light a light vertex is on: a handle the integrators hand back to the lights'
/// questions and ask for the light's type (the flags below), never taken apart outside this
/// module.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Emitter(EmitterKind);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum EmitterKind {
    /// An emissive triangle (internal index).
    Area(u32),
    /// A point or spot light (index into the scene's lights).
    Point(u32),
    /// A directional light (index into the scene's lights).
    Directional(u32),
    /// The environment and sun disc.
    Infinite,
}

/// The type of a light, as pbrt's light types: what the integrators may ask of its vertex.
impl Emitter {
    /// The light of emissive internal triangle `triangle` (a surface vertex on a light is
    /// told by its triangle).
    #[inline]
    pub fn triangle(triangle: u32) -> Emitter {
        Emitter(EmitterKind::Area(triangle))
    }

    /// A point on an emissive surface: rays leave it offset along its normal, rays hit it.
    #[inline]
    pub fn is_area(self) -> bool {
        matches!(self.0, EmitterKind::Area(_))
    }

    /// A delta position (point, spot): a point without a surface, that no ray hits.
    #[inline]
    pub fn is_delta_position(self) -> bool {
        matches!(self.0, EmitterKind::Point(_))
    }

    /// Whether the light sits at infinity: its vertex is a direction, not a point.
    #[inline]
    pub fn at_infinity(self) -> bool {
        matches!(self.0, EmitterKind::Directional(_) | EmitterKind::Infinite)
    }

    /// Whether the light is a delta in position or direction: no ray can hit it.
    #[inline]
    pub fn is_delta(self) -> bool {
        matches!(self.0, EmitterKind::Point(_) | EmitterKind::Directional(_))
    }
}

/// What the lights ask of the scene's surfaces about an emissive triangle (`Scene`
/// answers): textures and spectra stay with the materials.
pub(crate) trait EmissiveSurfaces {
    /// Radiance internal triangle `triangle` emits at `barycentrics`, in `channels`.
    fn surface_emission(
        &self,
        triangle: u32,
        barycentrics: [f32; 2],
        channels: &Channels,
    ) -> Spectrum;
    /// Whether the triangle's emission varies over it (an emission texture, or alpha that
    /// removes parts of it): light samples then ask `surface_emission` at their point
    /// rather than take the light's own RGB emission.
    fn emission_varies(&self, triangle: u32) -> bool;
    /// The density with which light sampling picks a point on the triangle, per unit area
    /// (0: not a light).
    fn triangle_light_pdf(&self, triangle: u32) -> f32;
}

/// A point or direction on a light picked by power (`SceneLights::sample_vertex`), before
/// anything is known of where it is seen from.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightVertex {
    pub light: Emitter,
    /// The point on an area or point light (zero at infinity).
    pub point: Vec3A,
    /// An area light's front normal, the unit direction from the scene to a light at
    /// infinity (zero for a point light).
    pub normal: Vec3A,
    /// Density of the vertex: selection × area density (area), selection (point,
    /// directional), selection × density in solid angle (infinite).
    pub pdf: f32,
    /// An area light's internal triangle and the point's barycentrics on it (zero for the
    /// other lights).
    pub triangle: u32,
    pub barycentrics: [f32; 2],
    /// In RGB: the area light's emission factor, a directional light's irradiance, the
    /// radiance from the infinite light (a point light's comes with its direction).
    emission: Spectrum,
}

/// A light sampled for shading point `p` (pbrt's `SampleLi`): the direction to it, what
/// arrives along it, and the light vertex, for next-event estimation and BDPT's connection
/// to a new light vertex.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightLiSample {
    pub light: Emitter,
    /// Unit direction from `p` towards the light.
    pub wi: Vec3A,
    /// What the light sends towards `p`, before the falloff with distance: radiance (area,
    /// infinite), intensity (point, spot), irradiance (directional).
    pub radiance: Spectrum,
    /// Density of the light vertex (`LightVertex::pdf`).
    pub pdf: f32,
    /// Squared distance to the light vertex (1 at infinity: no falloff).
    pub distance2: f32,
    /// Cosine between the light's normal and −`wi` (1 for a light without a surface).
    pub cos_light: f32,
    /// The light vertex: the point on the light, or `p` itself for a light at infinity.
    pub point: Vec3A,
    /// Its normal: an area light's front normal, −`wi` for a point light, `wi` at infinity.
    pub normal: Vec3A,
    /// An area light's internal triangle and the point's barycentrics on it.
    pub triangle: u32,
    pub barycentrics: [f32; 2],
}

impl LightLiSample {
    /// Density of `wi` in solid angle, the selection included; for a delta light, what
    /// `radiance` is divided by to give the light arriving at `p` (selection × distance²
    /// for a point light, the selection alone for a directional one).
    #[inline]
    pub fn solid_angle_pdf(&self) -> f32 {
        self.pdf * self.distance2 / self.cos_light
    }

    /// The geometry factor between `p` (normal `normal`) and the light vertex: |cos| at
    /// `p` × the light's cosine / distance².
    #[inline]
    pub fn geometry(&self, normal: Vec3A) -> f32 {
        self.wi.dot(normal).abs() * self.cos_light / self.distance2
    }

    /// The normal a shadow ray's end at the light vertex is offset along (none for a point
    /// light, which has no surface).
    #[inline]
    pub fn offset_normal(&self) -> Vec3A {
        if self.light.is_delta_position() {
            Vec3A::ZERO
        } else {
            self.normal
        }
    }
}

/// The start of a light subpath: the light vertex and the first ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct EmissionSample {
    pub emitter: Emitter,
    /// The light vertex: a point (area, point lights), or for lights at infinity the
    /// point on the disc facing the scene that the ray starts from.
    pub point: Vec3A,
    /// Area light: its front normal. Lights at infinity: `toward`, from the scene to the
    /// light. Point lights: the ray's direction.
    pub normal: Vec3A,
    /// The first ray's direction.
    pub direction: Vec3A,
    /// Radiance (area), intensity (point) or radiance/irradiance (at infinity) carried by
    /// the ray: what a connection to the light vertex itself carries, before densities.
    pub emission: Spectrum,
    /// The light vertex's density: selection × area density (area), selection (point,
    /// directional), selection × solid-angle density of `normal` (infinite).
    pub pdf_origin: f32,
    /// The first ray's density: in solid angle for area and point lights, per unit area of
    /// the disc for lights at infinity (the next vertex's area density is this times its
    /// |cos|).
    pub pdf_direction: f32,
    /// The first ray's throughput: emission·|cos| / (pdf_origin · pdf_direction).
    pub beta: Spectrum,
    /// An area light's internal triangle and the point's barycentrics on it (zero for
    /// other lights).
    pub triangle: u32,
    pub barycentrics: [f32; 2],
}

impl SceneLights {
    /// The largest of the lights' emitted radiance, intensity and irradiance (per channel),
    /// and of the lights at infinity their luminance integral: the scale of the scene's
    /// units, which the film's fixed-point sums are set to (`crate::film::FixedPoint`).
    pub fn brightest(&self) -> f32 {
        let max = |s: Spectrum| s.to_array().into_iter().fold(0.0f32, f32::max);
        let mut brightest = self
            .infinite
            .as_ref()
            .map_or(0.0, |light| light.luminance_integral());
        for light in &self.lights {
            let value = match light {
                Light::Area(area) => max(area.emission),
                Light::Point(point) => max(point.intensity),
                Light::Directional { irradiance, .. } => max(*irradiance),
                Light::Infinite => 0.0,
            };
            brightest = brightest.max(value);
        }
        brightest
    }

    /// Each area light's internal triangle and its `area_pdf`.
    pub(crate) fn area_light_pdfs(&self) -> impl Iterator<Item = (u32, f32)> + '_ {
        self.lights.iter().filter_map(|light| match light {
            Light::Area(light) => Some((light.triangle, light.area_pdf)),
            _ => None,
        })
    }

    /// Picks a light by power with `u_select` and a point or direction on it with
    /// `u_point`; `None` if the scene has no lights or the sample has zero density. The
    /// caller draws both numbers (always, whether or not there are lights, where its
    /// sampler's coordinates must stay in place).
    #[inline(always)]
    pub(crate) fn sample_vertex(&self, u_select: f32, u_point: [f32; 2]) -> Option<LightVertex> {
        if self.lights.is_empty() {
            return None;
        }
        let (index, select_pdf, _) = self.distribution.sample_discrete(u_select);
        let vertex = |light, point, normal, pdf, emission| LightVertex {
            light: Emitter(light),
            point,
            normal,
            pdf,
            triangle: 0,
            barycentrics: [0.0; 2],
            emission,
        };
        match &self.lights[index] {
            Light::Area(light) => {
                let [b1, b2] = uniform_triangle(u_point);
                Some(LightVertex {
                    triangle: light.triangle,
                    barycentrics: [b1, b2],
                    ..vertex(
                        EmitterKind::Area(light.triangle),
                        light.v0 + light.edge1 * b1 + light.edge2 * b2,
                        light.normal,
                        light.area_pdf,
                        light.emission,
                    )
                })
            }
            Light::Point(light) => Some(vertex(
                EmitterKind::Point(index as u32),
                light.position,
                Vec3A::ZERO,
                select_pdf,
                light.intensity,
            )),
            Light::Directional { toward, irradiance } => Some(vertex(
                EmitterKind::Directional(index as u32),
                Vec3A::ZERO,
                *toward,
                select_pdf,
                *irradiance,
            )),
            Light::Infinite => {
                let (toward, radiance, pdf) = self.infinite.as_ref()?.sample(u_point)?;
                Some(vertex(
                    EmitterKind::Infinite,
                    Vec3A::ZERO,
                    toward,
                    select_pdf * pdf,
                    radiance,
                ))
            }
        }
    }

    /// Picks a light by power and a point or direction on it (`sample_vertex`, the same
    /// numbers) and what it sends towards shading point `p`, in `channels`; `None` if there
    /// is none, `p` is on the light or behind it.
    // Always inlined, as the path tracer's own light sampling was (its callgrind count is
    // 3-5% higher as a call).
    #[inline(always)]
    pub(crate) fn sample_li(
        &self,
        surfaces: &impl EmissiveSurfaces,
        p: Vec3A,
        u_select: f32,
        u_point: [f32; 2],
        channels: &Channels,
    ) -> Option<LightLiSample> {
        let vertex = self.sample_vertex(u_select, u_point)?;
        let sample = |wi, radiance, distance2, cos_light, point, normal| LightLiSample {
            light: vertex.light,
            wi,
            radiance,
            pdf: vertex.pdf,
            distance2,
            cos_light,
            point,
            normal,
            triangle: vertex.triangle,
            barycentrics: vertex.barycentrics,
        };
        match vertex.light.0 {
            EmitterKind::Area(triangle) => {
                // In RGB the light's own emission, unless it varies over the triangle;
                // spectra from the material's fit.
                let emission = if surfaces.emission_varies(triangle) || *channels != Channels::Rgb {
                    surfaces.surface_emission(triangle, vertex.barycentrics, channels)
                } else {
                    vertex.emission
                };
                let to_light = vertex.point - p;
                let distance2 = to_light.length_squared();
                if distance2 <= 0.0 {
                    return None;
                }
                let wi = to_light / distance2.sqrt();
                let cos_light = -wi.dot(vertex.normal);
                if cos_light <= 0.0 {
                    return None;
                }
                Some(sample(
                    wi,
                    emission,
                    distance2,
                    cos_light,
                    vertex.point,
                    vertex.normal,
                ))
            }
            EmitterKind::Point(index) => {
                let to_light = vertex.point - p;
                let distance2 = to_light.length_squared();
                if distance2 <= 0.0 {
                    return None;
                }
                let wi = to_light / distance2.sqrt();
                let intensity = self.point_light(index).intensity(-wi, channels);
                Some(sample(wi, intensity, distance2, 1.0, vertex.point, -wi))
            }
            EmitterKind::Directional(_) | EmitterKind::Infinite => {
                let radiance = channels.illuminant(vertex.emission.to_array());
                Some(sample(vertex.normal, radiance, 1.0, 1.0, p, vertex.normal))
            }
        }
    }

    /// Picks a light by power and samples where a light subpath starts and its first
    /// direction (5 numbers, always all read by the caller), its emission and weight in
    /// `channels`.
    #[inline]
    pub(crate) fn sample_emission(
        &self,
        surfaces: &impl EmissiveSurfaces,
        u_select: f32,
        u_point: [f32; 2],
        u_direction: [f32; 2],
        channels: &Channels,
    ) -> Option<EmissionSample> {
        let mut sample = self.sample_emission_rgb(u_select, u_point, u_direction)?;
        if let EmitterKind::Area(triangle) = sample.emitter.0
            && (surfaces.emission_varies(triangle) || *channels != Channels::Rgb)
        {
            sample.emission = surfaces.surface_emission(triangle, sample.barycentrics, channels);
            let cos = sample.direction.dot(sample.normal);
            sample.beta = sample.emission * (cos / (sample.pdf_origin * sample.pdf_direction));
        } else {
            // The weight is the emission times a number, and the upsampling scales with
            // its argument, so it converts as the emission does.
            sample.emission = channels.illuminant(sample.emission.to_array());
            sample.beta = channels.illuminant(sample.beta.to_array());
        }
        Some(sample)
    }

    /// `sample_emission` with the lights' own RGB emission.
    #[inline]
    fn sample_emission_rgb(
        &self,
        u_select: f32,
        u_point: [f32; 2],
        u_direction: [f32; 2],
    ) -> Option<EmissionSample> {
        if self.lights.is_empty() {
            return None;
        }
        let (index, select_pdf, _) = self.distribution.sample_discrete(u_select);
        match &self.lights[index] {
            Light::Area(light) => {
                let [b1, b2] = uniform_triangle(u_point);
                let local = crate::sampling::cosine_hemisphere(u_direction);
                let pdf_direction = local.z * FRAC_1_PI;
                Some(EmissionSample {
                    emitter: Emitter(EmitterKind::Area(light.triangle)),
                    point: light.v0 + light.edge1 * b1 + light.edge2 * b2,
                    normal: light.normal,
                    direction: OrthonormalBasis::from_normal(light.normal).to_world(local),
                    emission: light.emission,
                    pdf_origin: light.area_pdf,
                    pdf_direction,
                    // Le·cos / (p_position · p_direction).
                    beta: light.emission * (local.z / (light.area_pdf * pdf_direction)),
                    triangle: light.triangle,
                    barycentrics: [b1, b2],
                })
            }
            Light::Point(light) => {
                let direction = light.sample_direction(u_direction);
                let pdf_direction = light.direction_pdf(direction);
                let emission = light.intensity(direction, &Channels::Rgb);
                Some(EmissionSample {
                    emitter: Emitter(EmitterKind::Point(index as u32)),
                    point: light.position,
                    normal: direction,
                    direction,
                    emission,
                    pdf_origin: select_pdf,
                    pdf_direction,
                    beta: emission / (select_pdf * pdf_direction),
                    triangle: 0,
                    barycentrics: [0.0; 2],
                })
            }
            Light::Directional { toward, irradiance } => self.emission_from_infinity(
                Emitter(EmitterKind::Directional(index as u32)),
                *toward,
                *irradiance,
                select_pdf,
                u_point,
            ),
            Light::Infinite => {
                let (toward, radiance, pdf) = self.infinite.as_ref()?.sample(u_direction)?;
                self.emission_from_infinity(
                    Emitter(EmitterKind::Infinite),
                    toward,
                    radiance,
                    select_pdf * pdf,
                    u_point,
                )
            }
        }
    }

    /// The point a light subpath from infinity along −`toward` starts from: uniform on
    /// the disc facing `toward` that covers the scene's bounding sphere (pbrt's
    /// construction), so every point of the scene can be reached with an area density of
    /// |cos| / (π R²).
    #[inline]
    fn disc_point(&self, toward: Vec3A, u_point: [f32; 2]) -> Vec3A {
        let (center, radius) = self.bounding_sphere;
        let [dx, dy] = uniform_disk(u_point);
        let basis = OrthonormalBasis::from_normal(toward);
        center + toward * radius + basis.to_world(Vec3A::new(dx, dy, 0.0)) * radius
    }

    /// A light subpath from infinity along −`toward`, from `disc_point`.
    #[inline]
    fn emission_from_infinity(
        &self,
        emitter: Emitter,
        toward: Vec3A,
        emission: Spectrum,
        pdf_origin: f32,
        u_point: [f32; 2],
    ) -> Option<EmissionSample> {
        let point = self.disc_point(toward, u_point);
        let pdf_direction = self.disc_pdf();
        Some(EmissionSample {
            emitter,
            point,
            normal: toward,
            direction: -toward,
            emission,
            pdf_origin,
            pdf_direction,
            beta: emission / (pdf_origin * pdf_direction),
            triangle: 0,
            barycentrics: [0.0; 2],
        })
    }

    /// The first ray of a light subpath from light vertex `light` (at `point`, normal
    /// `normal`, as `LightVertex` has them), with the direction density
    /// `pdf_le_direction` gives it: cosine-weighted from an area light, uniform over the
    /// sphere or the spot's outer cone from a point light, from `disc_point` along the
    /// light at infinity. Returns the origin and direction; `None` if the direction has no
    /// density.
    #[inline]
    pub(crate) fn sample_le_ray(
        &self,
        light: Emitter,
        point: Vec3A,
        normal: Vec3A,
        u: [f32; 2],
    ) -> Option<(Vec3A, Vec3A)> {
        match light.0 {
            EmitterKind::Area(_) => {
                let local = crate::sampling::cosine_hemisphere(u);
                if local.z <= 0.0 {
                    return None;
                }
                Some((point, OrthonormalBasis::from_normal(normal).to_world(local)))
            }
            EmitterKind::Point(index) => {
                let light = self.point_light(index);
                let direction = light.sample_direction(u);
                (light.direction_pdf(direction) > 0.0).then_some((point, direction))
            }
            EmitterKind::Directional(_) | EmitterKind::Infinite => {
                Some((self.disc_point(normal, u), -normal))
            }
        }
    }

    /// Area density of a light subpath's start on the disc of lights at infinity.
    #[inline]
    fn disc_pdf(&self) -> f32 {
        let radius = self.bounding_sphere.1;
        1.0 / (PI * radius * radius)
    }

    /// Whether the scene has a light to sample.
    #[inline]
    pub(crate) fn has_lights(&self) -> bool {
        !self.lights.is_empty()
    }

    /// Whether rays that leave the scene can find light (an environment or a sun disc).
    #[inline]
    pub(crate) fn has_infinite_light(&self) -> bool {
        self.infinite_select_pdf > 0.0
    }

    /// The light a ray that leaves the scene ends on (`None` if it finds no light).
    #[inline]
    pub(crate) fn infinite_emitter(&self) -> Option<Emitter> {
        self.has_infinite_light()
            .then_some(Emitter(EmitterKind::Infinite))
    }

    /// Radiance arriving from direction `w` (unit) along a ray that left the scene, in
    /// `channels`.
    #[inline]
    pub(crate) fn infinite_radiance(&self, w: Vec3A, channels: &Channels) -> Spectrum {
        match &self.infinite {
            Some(light) => channels.illuminant(light.radiance(w).to_array()),
            None => Spectrum::ZERO,
        }
    }

    /// Density in solid angle with which `sample_vertex` (and `sample_emission`) choose
    /// direction `w` on the lights at infinity, the selection probability included.
    #[inline]
    pub(crate) fn infinite_pdf(&self, w: Vec3A) -> f32 {
        match &self.infinite {
            Some(light) => self.infinite_select_pdf * light.pdf(w),
            None => 0.0,
        }
    }

    /// Radiance light vertex `light` sends along a ray that found it, arriving from
    /// `toward` (pbrt's `Le`): the lights at infinity that rays can hit; zero for the others
    /// (an area light is found as its triangle, by the surface hit).
    #[inline]
    pub(crate) fn le(&self, light: Emitter, toward: Vec3A, channels: &Channels) -> Spectrum {
        match light.0 {
            EmitterKind::Infinite => self.infinite_radiance(toward, channels),
            _ => Spectrum::ZERO,
        }
    }

    /// Point or spot light number `index` of the scene's lights.
    #[inline]
    fn point_light(&self, index: u32) -> &PointLight {
        match &self.lights[index as usize] {
            Light::Point(light) => light,
            _ => unreachable!("light {index} is not a point light"),
        }
    }

    /// Selection probability of light number `index`.
    #[inline]
    fn light_select_pdf(&self, index: u32) -> f32 {
        self.distribution.discrete_pdf(index as usize)
    }

    /// Density of light vertex `light` as the start of a light subpath (see
    /// `EmissionSample::pdf_origin`); `toward` is the direction of a light at infinity.
    #[inline]
    pub(crate) fn pdf_origin(
        &self,
        surfaces: &impl EmissiveSurfaces,
        light: Emitter,
        toward: Vec3A,
    ) -> f32 {
        match light.0 {
            EmitterKind::Area(triangle) => surfaces.triangle_light_pdf(triangle),
            EmitterKind::Point(index) | EmitterKind::Directional(index) => {
                self.light_select_pdf(index)
            }
            EmitterKind::Infinite => self.infinite_pdf(toward),
        }
    }

    /// Density with which a light subpath leaves light vertex `light` (at `from`, normal
    /// `normal` as `LightVertex` has them) towards point `to` (pbrt's `PDF_Le`'s
    /// direction part): in solid angle from area and point lights; for lights at infinity
    /// the disc's area density (times |cos| at `to`, which the caller applies).
    #[inline]
    pub(crate) fn pdf_le_direction(
        &self,
        light: Emitter,
        from: Vec3A,
        normal: Vec3A,
        to: Vec3A,
    ) -> f32 {
        match light.0 {
            EmitterKind::Area(_) => {
                let w = (to - from).normalize();
                let cos = w.dot(normal);
                if cos > 0.0 { cos * FRAC_1_PI } else { 0.0 }
            }
            EmitterKind::Point(index) => {
                let d = to - from;
                let distance2 = d.length_squared();
                if distance2 <= 0.0 || distance2.is_nan() {
                    return 0.0;
                }
                self.point_light(index).direction_pdf(d / distance2.sqrt())
            }
            EmitterKind::Directional(_) | EmitterKind::Infinite => self.disc_pdf(),
        }
    }

    /// What light vertex `light` (normal `normal`; an area light's point at `barycentrics`)
    /// emits towards unit direction `w`, in `channels`, and the vertex's density as a light
    /// sample (`LightVertex::pdf`); `None` for a triangle that is not a light or a
    /// direction behind an area light.
    #[inline]
    pub(crate) fn emitted(
        &self,
        surfaces: &impl EmissiveSurfaces,
        light: Emitter,
        normal: Vec3A,
        barycentrics: [f32; 2],
        w: Vec3A,
        channels: &Channels,
    ) -> Option<(Spectrum, f32)> {
        match light.0 {
            EmitterKind::Area(triangle) => {
                let area_pdf = surfaces.triangle_light_pdf(triangle);
                if area_pdf <= 0.0 {
                    return None;
                }
                let emission = surfaces.surface_emission(triangle, barycentrics, channels);
                // The light leaves its front side only.
                if w.dot(normal) <= 0.0 {
                    return None;
                }
                Some((emission, area_pdf))
            }
            EmitterKind::Point(index) => Some((
                self.point_light(index).intensity(w, channels),
                self.light_select_pdf(index),
            )),
            EmitterKind::Directional(index) => match &self.lights[index as usize] {
                Light::Directional { irradiance, .. } => Some((
                    channels.illuminant(irradiance.to_array()),
                    self.light_select_pdf(index),
                )),
                _ => None,
            },
            EmitterKind::Infinite => Some((
                self.infinite_radiance(normal, channels),
                self.infinite_pdf(normal),
            )),
        }
    }

    /// A light subpath's throughput `beta` (emission over the origin's density) after its
    /// first direction `w` from light vertex `light`: times the cosine at the light over
    /// the direction's density (`pdf_le_direction`). From an area light the cosine cancels
    /// (π); from the disc of a light at infinity the cosine at the next vertex is in both
    /// the geometry term and its area density, and is left out. `None` where the
    /// direction has no density.
    #[inline]
    pub(crate) fn weight_first_direction(
        &self,
        light: Emitter,
        w: Vec3A,
        beta: Spectrum,
    ) -> Option<Spectrum> {
        match light.0 {
            EmitterKind::Area(_) => Some(beta * PI),
            EmitterKind::Point(index) => {
                let pdf = self.point_light(index).direction_pdf(w);
                (pdf > 0.0).then(|| beta / pdf)
            }
            EmitterKind::Directional(_) | EmitterKind::Infinite => Some(beta / self.disc_pdf()),
        }
    }
}

/// What the path-space tests need to build light vertices of each kind.
#[cfg(test)]
impl SceneLights {
    /// Light number `index` in selection order (area lights first, then the punctual
    /// lights, the delta sun, the infinite light).
    pub(crate) fn emitter(&self, index: usize) -> Emitter {
        Emitter(match &self.lights[index] {
            Light::Area(light) => EmitterKind::Area(light.triangle),
            Light::Point(_) => EmitterKind::Point(index as u32),
            Light::Directional { .. } => EmitterKind::Directional(index as u32),
            Light::Infinite => EmitterKind::Infinite,
        })
    }

    /// The number of area lights.
    pub(crate) fn area_light_count(&self) -> usize {
        self.area_light_pdfs().count()
    }

    /// A point or spot light's cone: its axis and cos of its outer angle.
    pub(crate) fn cone(&self, light: Emitter) -> Option<(Vec3A, f32)> {
        match light.0 {
            EmitterKind::Point(index) => {
                self.point_light(index).cone.map(|c| (c.axis, c.cos_outer))
            }
            _ => None,
        }
    }

    /// The centre and radius of the sphere around the scene.
    pub(crate) fn bounding_sphere(&self) -> (Vec3A, f32) {
        self.bounding_sphere
    }
}

/// The scene's lights in selection order, their selection distribution and the lights at
/// infinity: built by `Scene::new` after the area lights.
pub(crate) struct SceneLights {
    lights: Vec<Light>,
    distribution: crate::sampling::Distribution1D,
    /// The environment and sun disc, if any.
    infinite: Option<InfiniteLight>,
    /// Selection probability of the lights at infinity (0: none, or black).
    infinite_select_pdf: f32,
    /// Centre and radius of a sphere around the geometry: light subpaths from infinity
    /// start on a disc of this radius.
    bounding_sphere: (Vec3A, f32),
}

impl SceneLights {
    /// `area` in the host's triangle order (their `area_pdf` is filled here);
    /// `bounding_sphere` is the scene's (the environment's power is estimated through it);
    /// `input_triangle` maps an internal triangle index to the host's, for messages. Fails
    /// when a light's power, or the lights' total, overflows a float: the selection
    /// probabilities would be 0 or NaN.
    pub fn new(
        area: Vec<AreaLight>,
        desc: &LightsDesc,
        bounding_sphere: (Vec3A, f32),
        input_triangle: impl Fn(u32) -> u32,
    ) -> Result<SceneLights> {
        let bounds_radius = bounding_sphere.1;
        let area_of = |light: &AreaLight| 0.5 * light.edge1.cross(light.edge2).length();
        let mut lights: Vec<Light> = Vec::with_capacity(area.len() + desc.punctual.len() + 2);
        let mut power: Vec<f32> = Vec::with_capacity(lights.capacity());
        let area_count = area.len();
        for light in area {
            power.push(light.emission.luminance() * light.power_scale * area_of(&light));
            lights.push(Light::Area(light));
        }
        let r2 = bounds_radius * bounds_radius;
        for punctual in desc.punctual {
            use PunctualLightKind as Kind;
            let intensity = Spectrum::from(punctual.intensity);
            let light = match punctual.kind {
                Kind::Point | Kind::Spot => {
                    let cone = (punctual.kind == Kind::Spot).then(|| {
                        let cos_inner = punctual.inner_cone_degrees.to_radians().cos();
                        let cos_outer = punctual.outer_cone_degrees.to_radians().cos();
                        let scale = 1.0 / (cos_inner - cos_outer).max(1e-3);
                        SpotCone {
                            axis: Vec3A::from(punctual.direction).normalize(),
                            cos_inner,
                            cos_outer,
                            scale,
                            offset: -cos_outer * scale,
                        }
                    });
                    Light::Point(PointLight {
                        position: Vec3A::from(punctual.position),
                        intensity,
                        cone,
                    })
                }
                Kind::Directional => Light::Directional {
                    toward: -Vec3A::from(punctual.direction).normalize(),
                    irradiance: intensity,
                },
            };
            power.push(match &light {
                Light::Point(point) => point.power(),
                _ => intensity.luminance() * r2,
            });
            lights.push(light);
        }
        let mut sun_disc = None;
        if let Some(sun) = &desc.sun {
            if sun.angular_radius_degrees > 0.0 {
                sun_disc = Some(SunDisc::new(sun));
            } else {
                let irradiance = Spectrum::from(sun.irradiance);
                power.push(irradiance.luminance() * r2);
                lights.push(Light::Directional {
                    toward: Vec3A::from(sun.direction).normalize(),
                    irradiance,
                });
            }
        }
        let environment = desc.environment.as_ref().map(EnvironmentMap::new);
        let infinite = (environment.is_some() || sun_disc.is_some())
            .then(|| InfiniteLight::new(environment, sun_disc));
        let mut infinite_index = None;
        if let Some(light) = &infinite {
            let integral = light.luminance_integral();
            if integral > 0.0 {
                infinite_index = Some(lights.len());
                power.push(integral * r2);
                lights.push(Light::Infinite);
            }
        }
        let mut total = 0.0f64;
        for (index, &p) in power.iter().enumerate() {
            total += p as f64;
            if !(p.is_finite() && total <= f32::MAX as f64) {
                let light = match &lights[index] {
                    Light::Area(light) => format!(
                        "emissive triangle {} (emission {:?}, area {:e})",
                        input_triangle(light.triangle),
                        light.emission.to_array(),
                        area_of(light)
                    ),
                    Light::Point(_) => format!(
                        "desc.punctual_lights[{}] (intensity {:?})",
                        index - area_count,
                        desc.punctual[index - area_count].intensity
                    ),
                    Light::Directional { .. } if index - area_count < desc.punctual.len() => {
                        format!(
                            "desc.punctual_lights[{}] (irradiance {:?} over the scene's bounding sphere of radius {bounds_radius:e})",
                            index - area_count,
                            desc.punctual[index - area_count].intensity
                        )
                    }
                    Light::Directional { .. } | Light::Infinite => format!(
                        "the sun and environment (over the scene's bounding sphere of radius {bounds_radius:e})"
                    ),
                };
                return Err(Error::invalid(format!(
                    "the power of {light} overflows a float (the lights' total up to it is {total:e}); scale the scene's light or its size down"
                )));
            }
        }
        // Lights that emit nothing are never picked (zero weight) but keep their index.
        let distribution = crate::sampling::Distribution1D::new(&power);
        let infinite_select_pdf = infinite_index.map_or(0.0, |i| distribution.discrete_pdf(i));
        for (index, light) in lights.iter_mut().enumerate() {
            if let Light::Area(light) = light {
                light.area_pdf = distribution.discrete_pdf(index) / area_of(light);
            }
        }
        Ok(SceneLights {
            lights,
            distribution,
            infinite,
            infinite_select_pdf,
            bounding_sphere,
        })
    }
}
