//! The scene's lights, and light sampling written once: area lights (emissive triangles),
//! point and spot lights, directional lights, and the lights at infinity (environment and
//! sun disc, one light), picked in proportion to their power.
//!
//! Every integrator that samples a light (next-event estimation, light subpaths, the
//! bidirectional mutation's new light vertex) calls `sample_light` or `sample_emission`,
//! and every ray that leaves the scene asks `infinite_radiance` (the `Scene` forwards them
//! to its [`SceneLights`]), so another kind of light changes this module, not theirs.
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
pub(crate) struct SpotCone {
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
pub(crate) struct PointLight {
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
pub(crate) enum Light {
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

/// Which light a light vertex is on, for the densities of bidirectional strategies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Emitter {
    /// An emissive triangle (internal index).
    Area(u32),
    /// A point or spot light (index into the scene's lights).
    Point(u32),
    /// A directional light (index into the scene's lights): a delta direction.
    Directional(u32),
    /// The environment and sun disc: a direction at infinity.
    Infinite,
}

impl Emitter {
    /// Whether the light sits at infinity: its vertex is a direction, not a point.
    #[inline]
    pub fn at_infinity(self) -> bool {
        matches!(self, Emitter::Directional(_) | Emitter::Infinite)
    }

    /// Whether the light is a delta in position or direction: no ray can hit it.
    #[inline]
    pub fn is_delta(self) -> bool {
        matches!(self, Emitter::Point(_) | Emitter::Directional(_))
    }
}

/// A light sampled from the scene's lights, as next-event estimation sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LightSample {
    /// A point on an area light.
    Area {
        point: Vec3A,
        /// The light's front normal: it emits into that hemisphere.
        normal: Vec3A,
        /// Radiance leaving the front side.
        emission: Spectrum,
        /// Density of `point` per unit area, the light's selection probability included.
        area_pdf: f32,
        /// Internal index of the light's triangle.
        triangle: u32,
        /// The point's barycentrics on that triangle.
        barycentrics: [f32; 2],
    },
    /// A point or spot light.
    Point {
        light: u32,
        position: Vec3A,
        /// The light's selection probability.
        pdf: f32,
    },
    /// A direction towards a light at infinity.
    Direction {
        emitter: Emitter,
        /// Unit, from the scene towards the light.
        toward: Vec3A,
        /// Radiance arriving from `toward` (infinite light), or irradiance (directional).
        radiance: Spectrum,
        /// Selection probability times the density of `toward` in solid angle; for a
        /// directional light, the selection probability alone.
        pdf: f32,
    },
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
    /// An area light's point's barycentrics on its triangle (zero for other lights).
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

    /// Picks a light by power with `u_select` and a point or direction on it with
    /// `u_point`; `None` if the scene has no lights or the sample has zero density. The
    /// caller draws both numbers (always, whether or not there are lights, where its
    /// sampler's coordinates must stay in place).
    #[inline]
    pub(crate) fn sample_light(&self, u_select: f32, u_point: [f32; 2]) -> Option<LightSample> {
        if self.lights.is_empty() {
            return None;
        }
        let (index, select_pdf, _) = self.distribution.sample_discrete(u_select);
        match &self.lights[index] {
            Light::Area(light) => {
                let [b1, b2] = uniform_triangle(u_point);
                Some(LightSample::Area {
                    point: light.v0 + light.edge1 * b1 + light.edge2 * b2,
                    normal: light.normal,
                    emission: light.emission,
                    area_pdf: light.area_pdf,
                    triangle: light.triangle,
                    barycentrics: [b1, b2],
                })
            }
            Light::Point(light) => Some(LightSample::Point {
                light: index as u32,
                position: light.position,
                pdf: select_pdf,
            }),
            Light::Directional { toward, irradiance } => Some(LightSample::Direction {
                emitter: Emitter::Directional(index as u32),
                toward: *toward,
                radiance: *irradiance,
                pdf: select_pdf,
            }),
            Light::Infinite => {
                let (toward, radiance, pdf) = self.infinite.as_ref()?.sample(u_point)?;
                Some(LightSample::Direction {
                    emitter: Emitter::Infinite,
                    toward,
                    radiance,
                    pdf: select_pdf * pdf,
                })
            }
        }
    }

    /// Picks a light by power and samples where a light subpath starts and its first
    /// direction (5 numbers, always all read by the caller).
    #[inline]
    pub(crate) fn sample_emission(
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
                    emitter: Emitter::Area(light.triangle),
                    point: light.v0 + light.edge1 * b1 + light.edge2 * b2,
                    normal: light.normal,
                    direction: OrthonormalBasis::from_normal(light.normal).to_world(local),
                    emission: light.emission,
                    pdf_origin: light.area_pdf,
                    pdf_direction,
                    // Le·cos / (p_position · p_direction).
                    beta: light.emission * (local.z / (light.area_pdf * pdf_direction)),
                    barycentrics: [b1, b2],
                })
            }
            Light::Point(light) => {
                let direction = light.sample_direction(u_direction);
                let pdf_direction = light.direction_pdf(direction);
                let emission = light.intensity(direction, &Channels::Rgb);
                Some(EmissionSample {
                    emitter: Emitter::Point(index as u32),
                    point: light.position,
                    normal: direction,
                    direction,
                    emission,
                    pdf_origin: select_pdf,
                    pdf_direction,
                    beta: emission / (select_pdf * pdf_direction),
                    barycentrics: [0.0; 2],
                })
            }
            Light::Directional { toward, irradiance } => self.emission_from_infinity(
                Emitter::Directional(index as u32),
                *toward,
                *irradiance,
                select_pdf,
                u_point,
            ),
            Light::Infinite => {
                let (toward, radiance, pdf) = self.infinite.as_ref()?.sample(u_direction)?;
                self.emission_from_infinity(
                    Emitter::Infinite,
                    toward,
                    radiance,
                    select_pdf * pdf,
                    u_point,
                )
            }
        }
    }

    /// A light subpath from infinity along −`toward`: it starts on the disc facing
    /// `toward` that covers the scene's bounding sphere (pbrt's construction), so every
    /// point of the scene can be reached with an area density of |cos| / (π R²).
    #[inline]
    fn emission_from_infinity(
        &self,
        emitter: Emitter,
        toward: Vec3A,
        emission: Spectrum,
        pdf_origin: f32,
        u_point: [f32; 2],
    ) -> Option<EmissionSample> {
        let (center, radius) = self.bounding_sphere;
        let [dx, dy] = uniform_disk(u_point);
        let basis = OrthonormalBasis::from_normal(toward);
        let point = center + toward * radius + basis.to_world(Vec3A::new(dx, dy, 0.0)) * radius;
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
            barycentrics: [0.0; 2],
        })
    }

    /// Area density of a light subpath's start on the disc of lights at infinity.
    #[inline]
    pub(crate) fn disc_pdf(&self) -> f32 {
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

    /// Radiance arriving from direction `w` (unit) along a ray that left the scene, in
    /// `channels`.
    #[inline]
    pub(crate) fn infinite_radiance(&self, w: Vec3A, channels: &Channels) -> Spectrum {
        match &self.infinite {
            Some(light) => channels.illuminant(light.radiance(w).to_array()),
            None => Spectrum::ZERO,
        }
    }

    /// Density in solid angle with which `sample_light` (and `sample_emission`) choose
    /// direction `w` on the lights at infinity, the selection probability included.
    #[inline]
    pub(crate) fn infinite_pdf(&self, w: Vec3A) -> f32 {
        match &self.infinite {
            Some(light) => self.infinite_select_pdf * light.pdf(w),
            None => 0.0,
        }
    }

    /// Point or spot light number `index` of the scene's lights.
    #[inline]
    pub(crate) fn point_light(&self, index: u32) -> &PointLight {
        match &self.lights[index as usize] {
            Light::Point(light) => light,
            _ => unreachable!("light {index} is not a point light"),
        }
    }

    /// Selection probability of light number `index`.
    #[inline]
    pub(crate) fn light_select_pdf(&self, index: u32) -> f32 {
        self.distribution.discrete_pdf(index as usize)
    }

    /// Density in solid angle with which a light subpath leaves light vertex `emitter`
    /// (at `point`, front normal `normal`) in direction `w`; for lights at infinity, the
    /// disc's area density (times |cos| at the next vertex, which the caller applies).
    #[inline]
    pub(crate) fn emission_direction_pdf(&self, emitter: Emitter, normal: Vec3A, w: Vec3A) -> f32 {
        match emitter {
            Emitter::Area(_) => {
                let cos = w.dot(normal);
                if cos > 0.0 { cos * FRAC_1_PI } else { 0.0 }
            }
            Emitter::Point(index) => self.point_light(index).direction_pdf(w),
            Emitter::Directional(_) | Emitter::Infinite => self.disc_pdf(),
        }
    }
}

/// The scene's lights in selection order, their selection distribution and the lights at
/// infinity: built by `Scene::new` after the area lights.
pub(crate) struct SceneLights {
    pub lights: Vec<Light>,
    pub distribution: crate::sampling::Distribution1D,
    /// The environment and sun disc, if any.
    pub infinite: Option<InfiniteLight>,
    /// Selection probability of the lights at infinity (0: none, or black).
    pub infinite_select_pdf: f32,
    /// Centre and radius of a sphere around the geometry: light subpaths from infinity
    /// start on a disc of this radius.
    pub bounding_sphere: (Vec3A, f32),
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
