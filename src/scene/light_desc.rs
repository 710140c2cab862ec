//! Host-side descriptions of the lights that are not emissive triangles: an environment
//! (an HDR map or a constant colour), the sun, and punctual lights (`KHR_lights_punctual`).
//!
//! Units are radiometric and linear RGB, like a material's `emission` (radiance): radiance
//! for the environment, irradiance for the sun and directional lights, radiant intensity
//! for point and spot lights. The glTF loader converts glTF's photometric units (candela,
//! lux) with 683 lm/W (see `io`).

use crate::error::{Error, Result, check_finite, check_finite3};

/// Largest width or height of an environment map, in texels.
pub const MLT_MAX_ENVIRONMENT_SIDE: u32 = 1 << 16;
/// Most texels of an environment map (width × height): 2^28, 3 GiB of RGB floats.
pub const MLT_MAX_ENVIRONMENT_TEXELS: u64 = 1 << 28;
/// Most punctual lights of a scene.
pub const MLT_MAX_PUNCTUAL_LIGHTS: usize = 1 << 20;

/// An environment: radiance arriving from infinitely far away, seen by every ray that
/// leaves the scene and sampled by every algorithm as a light.
///
/// The map is equirectangular (latitude-longitude) with +Y up: texel column `u ∈ [0, 1)`
/// (left to right) is the azimuth φ = 2πu and row `v ∈ [0, 1)` (top to bottom) the polar
/// angle θ = πv from +Y, the direction being `(sin φ sin θ, cos θ, −cos φ sin θ)`, so the
/// map's centre looks along +Z and its left and right edges along −Z. (Mitsuba 3's
/// convention, so the same file lights both renderers alike.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentDesc<'a> {
    /// Linear RGB radiance, 3 floats per texel, rows from the top: `width · height · 3`.
    pub pixels: &'a [f32],
    pub width: u32,
    pub height: u32,
    /// Turns the environment about +Y by this many degrees (counter-clockwise seen from
    /// above): what the unrotated map shows along `d` then arrives from `R_y(rotation) d`.
    pub rotation_degrees: f32,
    /// Multiplies every texel.
    pub scale: f32,
}

impl<'a> EnvironmentDesc<'a> {
    /// A constant environment of the given radiance (a 1 × 1 map).
    pub fn constant(radiance: &'a [f32; 3]) -> Self {
        EnvironmentDesc {
            pixels: radiance,
            width: 1,
            height: 1,
            rotation_degrees: 0.0,
            scale: 1.0,
        }
    }

    /// Checks the size alone (before the pixels are looked at): at least 1 × 1, each side
    /// at most [`MLT_MAX_ENVIRONMENT_SIDE`], at most [`MLT_MAX_ENVIRONMENT_TEXELS`] texels.
    pub(crate) fn validate_size(width: u32, height: u32) -> Result<()> {
        if width == 0 || height == 0 {
            return Err(Error::invalid(format!(
                "desc.environment is {width} x {height} texels; it needs at least 1 x 1"
            )));
        }
        if width > MLT_MAX_ENVIRONMENT_SIDE
            || height > MLT_MAX_ENVIRONMENT_SIDE
            || width as u64 * height as u64 > MLT_MAX_ENVIRONMENT_TEXELS
        {
            return Err(Error::invalid(format!(
                "desc.environment is {width} x {height} texels; each side may be at most {MLT_MAX_ENVIRONMENT_SIDE} and the map at most {MLT_MAX_ENVIRONMENT_TEXELS} texels"
            )));
        }
        Ok(())
    }

    pub(crate) fn validate(&self) -> Result<()> {
        Self::validate_size(self.width, self.height)?;
        let expected = self.width as u64 * self.height as u64 * 3;
        if self.pixels.len() as u64 != expected {
            return Err(Error::invalid(format!(
                "desc.environment.pixels has {} floats, but {} x {} RGB texels need {expected}",
                self.pixels.len(),
                self.width,
                self.height
            )));
        }
        check_finite(&"desc.environment.rotation_degrees", self.rotation_degrees)?;
        if !(self.scale >= 0.0 && self.scale.is_finite()) {
            return Err(Error::invalid(format!(
                "desc.environment.scale is {}; it must be a finite number >= 0",
                self.scale
            )));
        }
        for (i, &value) in self.pixels.iter().enumerate() {
            if !(value >= 0.0 && value.is_finite()) {
                return Err(Error::invalid(format!(
                    "desc.environment.pixels[{i}] (texel {}, row {}, column {}, {}) is {value}; radiance must be finite and >= 0",
                    i / 3,
                    i / 3 / self.width as usize,
                    i / 3 % self.width as usize,
                    ["R", "G", "B"][i % 3]
                )));
            }
        }
        // The map is sampled by its texels' luminance, summed in single precision: every
        // scaled value, and their sum, must stay a float.
        let total = self.pixels.iter().map(|&v| v as f64).sum::<f64>() * self.scale as f64;
        if total > MLT_MAX_LIGHT_SUM {
            return Err(Error::invalid(format!(
                "desc.environment.pixels times its scale ({}) sum to {total:e}; at most {MLT_MAX_LIGHT_SUM:e} is supported (lower the scale)",
                self.scale
            )));
        }
        Ok(())
    }
}

/// Largest luminance an environment's texels (times its scale) may sum to, and largest
/// radiance a sun disc may have: light values that sums and products in single precision
/// still hold.
pub(crate) const MLT_MAX_LIGHT_SUM: f64 = 1e38;

/// The sun: a distant disc of uniform radiance, or a delta direction when its angular
/// radius is 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunDesc {
    /// From the scene towards the sun; any length but zero.
    pub direction: [f32; 3],
    /// Half the angle the disc subtends, in degrees, in [0, 45]: 0 is a delta direction
    /// (hard shadows, reached only by connections); the real sun is about 0.27.
    pub angular_radius_degrees: f32,
    /// Linear RGB irradiance on a plane facing the sun. The disc's radiance is this over
    /// π sin² of the angular radius (see [`SunDesc::from_radiance`]).
    pub irradiance: [f32; 3],
}

/// Largest angular radius of the sun, in degrees: a wider disc is an environment.
pub(crate) const SUN_MAX_ANGULAR_RADIUS_DEGREES: f32 = 45.0;

impl SunDesc {
    /// A sun disc of the given radiance (angular radius > 0).
    pub fn from_radiance(
        direction: [f32; 3],
        angular_radius_degrees: f32,
        radiance: [f32; 3],
    ) -> Self {
        let sin = angular_radius_degrees.to_radians().sin();
        let solid = std::f32::consts::PI * sin * sin;
        SunDesc {
            direction,
            angular_radius_degrees,
            irradiance: radiance.map(|l| l * solid),
        }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        check_direction("desc.sun.direction", self.direction)?;
        let radius = self.angular_radius_degrees;
        if !(0.0..=SUN_MAX_ANGULAR_RADIUS_DEGREES).contains(&radius) {
            return Err(Error::invalid(format!(
                "desc.sun.angular_radius_degrees is {radius}; it must be in [0, {SUN_MAX_ANGULAR_RADIUS_DEGREES}] (0: a delta direction)"
            )));
        }
        check_non_negative3("desc.sun.irradiance", self.irradiance)?;
        if radius > 0.0 {
            let radiance = self.disc_radiance();
            if radiance
                .iter()
                .any(|&l| l.is_nan() || l > MLT_MAX_LIGHT_SUM)
            {
                return Err(Error::invalid(format!(
                    "desc.sun.irradiance {:?} over a disc of angular radius {radius} degrees is a radiance of {radiance:?}; at most {MLT_MAX_LIGHT_SUM:e} is supported (widen the disc or lower the irradiance)",
                    self.irradiance
                )));
            }
        }
        Ok(())
    }

    /// The radiance of the disc of a sun with a positive angular radius: the irradiance
    /// over π sin² of the radius.
    pub(crate) fn disc_radiance(&self) -> [f64; 3] {
        let sin = (self.angular_radius_degrees as f64).to_radians().sin();
        let solid_for_irradiance = std::f64::consts::PI * sin * sin;
        self.irradiance.map(|e| e as f64 / solid_for_irradiance)
    }
}

/// The kind of a punctual light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PunctualLightKind {
    /// Radiates `intensity` equally in every direction from `position`.
    Point,
    /// Radiates from `position` into a cone about `direction`, with glTF's smooth falloff
    /// between the inner and the outer cone angle.
    Spot,
    /// Light arriving along `direction` from infinitely far away, with irradiance
    /// `intensity` on a plane facing it.
    Directional,
}

/// A point, spot or directional light (`KHR_lights_punctual`): a delta light, hit by no
/// ray, reached by connections only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PunctualLight {
    pub kind: PunctualLightKind,
    /// Point and spot lights: where the light is.
    pub position: [f32; 3],
    /// Spot: the cone's axis; directional: the direction the light travels (glTF's −Z of
    /// the light's node in both). Any length but zero; unused for point lights.
    pub direction: [f32; 3],
    /// Linear RGB: radiant intensity (W/sr) for point and spot lights (on the axis, for a
    /// spot), irradiance (W/m²) on a plane facing a directional light.
    pub intensity: [f32; 3],
    /// Spot: full intensity within this angle from the axis, in degrees.
    pub inner_cone_degrees: f32,
    /// Spot: no light beyond this angle from the axis, in degrees; in (inner, 90].
    pub outer_cone_degrees: f32,
}

impl PunctualLight {
    pub fn point(position: [f32; 3], intensity: [f32; 3]) -> Self {
        PunctualLight {
            kind: PunctualLightKind::Point,
            position,
            direction: [0.0, 0.0, -1.0],
            intensity,
            inner_cone_degrees: 0.0,
            outer_cone_degrees: 45.0,
        }
    }

    pub fn spot(
        position: [f32; 3],
        direction: [f32; 3],
        intensity: [f32; 3],
        inner_cone_degrees: f32,
        outer_cone_degrees: f32,
    ) -> Self {
        PunctualLight {
            kind: PunctualLightKind::Spot,
            direction,
            inner_cone_degrees,
            outer_cone_degrees,
            ..PunctualLight::point(position, intensity)
        }
    }

    pub fn directional(direction: [f32; 3], irradiance: [f32; 3]) -> Self {
        PunctualLight {
            kind: PunctualLightKind::Directional,
            direction,
            ..PunctualLight::point([0.0; 3], irradiance)
        }
    }

    pub(crate) fn validate(&self, index: usize) -> Result<()> {
        let name = |field: &str| format!("desc.punctual_lights[{index}].{field}");
        check_non_negative3(&name("intensity"), self.intensity)?;
        if self.kind != PunctualLightKind::Directional {
            check_finite3(&name("position"), self.position)?;
        }
        if self.kind != PunctualLightKind::Point {
            check_direction(&name("direction"), self.direction)?;
        }
        if self.kind == PunctualLightKind::Spot {
            let (inner, outer) = (self.inner_cone_degrees, self.outer_cone_degrees);
            if !(inner >= 0.0 && inner < outer && outer <= 90.0) {
                return Err(Error::invalid(format!(
                    "{} is {inner} and {} is {outer}; a spot light needs 0 <= inner < outer <= 90 degrees",
                    name("inner_cone_degrees"),
                    name("outer_cone_degrees")
                )));
            }
        }
        Ok(())
    }
}

/// The lights of a scene besides its emissive triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightsDesc<'a> {
    pub environment: Option<EnvironmentDesc<'a>>,
    pub sun: Option<SunDesc>,
    pub punctual: &'a [PunctualLight],
}

impl LightsDesc<'_> {
    pub(crate) fn validate(&self) -> Result<()> {
        if self.punctual.len() > MLT_MAX_PUNCTUAL_LIGHTS {
            return Err(Error::invalid(format!(
                "desc.punctual_lights has {} lights; at most {MLT_MAX_PUNCTUAL_LIGHTS} are allowed",
                self.punctual.len()
            )));
        }
        if let Some(environment) = &self.environment {
            environment.validate()?;
        }
        if let Some(sun) = &self.sun {
            sun.validate()?;
        }
        for (index, light) in self.punctual.iter().enumerate() {
            light.validate(index)?;
        }
        Ok(())
    }
}

fn check_direction(name: &str, direction: [f32; 3]) -> Result<()> {
    check_finite3(name, direction)?;
    let length2: f32 = direction.iter().map(|c| c * c).sum();
    if !(length2 > 0.0 && length2.is_finite()) {
        return Err(Error::invalid(format!(
            "{name} is {direction:?}; a direction must have a non-zero, finite length"
        )));
    }
    Ok(())
}

fn check_non_negative3(name: &str, value: [f32; 3]) -> Result<()> {
    for (channel, v) in ["R", "G", "B"].iter().zip(value) {
        if !(v >= 0.0 && v.is_finite()) {
            return Err(Error::invalid(format!(
                "{name} ({channel}) is {v}; light must be finite and >= 0"
            )));
        }
    }
    Ok(())
}
