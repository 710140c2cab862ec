//! Surface materials: what a triangle does with light.

use crate::error::{Error, Result, check_finite, check_finite3};

/// The scattering model of a material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialKind {
    /// Lambertian reflection with albedo `color`; scatters from both sides.
    Diffuse,
    /// A perfect mirror reflecting `color`; both sides.
    Mirror,
    /// A smooth dielectric interface (glass): Fresnel-weighted specular reflection and
    /// refraction with index of refraction `ior` on the front side, `color` tinting both.
    Dielectric,
}

/// A material. Any material may also emit: `emission` is the radiance leaving the
/// triangle's front side (counter-clockwise winding); emissive triangles are area lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub kind: MaterialKind,
    pub color: [f32; 3],
    pub emission: [f32; 3],
    pub ior: f32,
}

impl Material {
    pub fn diffuse(albedo: [f32; 3]) -> Self {
        Material {
            kind: MaterialKind::Diffuse,
            color: albedo,
            emission: [0.0; 3],
            ior: 1.5,
        }
    }

    pub fn mirror(reflectance: [f32; 3]) -> Self {
        Material {
            kind: MaterialKind::Mirror,
            ..Material::diffuse(reflectance)
        }
    }

    pub fn dielectric(ior: f32) -> Self {
        Material {
            kind: MaterialKind::Dielectric,
            ior,
            ..Material::diffuse([1.0; 3])
        }
    }

    pub fn with_emission(self, radiance: [f32; 3]) -> Self {
        Material {
            emission: radiance,
            ..self
        }
    }

    pub fn is_emissive(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }

    /// Checks every field, naming `materials[index]` in the message.
    pub fn validate(&self, index: usize) -> Result<()> {
        let name = format!("desc.materials[{index}]");
        check_finite3(&format!("{name}.color"), self.color)?;
        check_finite3(&format!("{name}.emission"), self.emission)?;
        check_finite(&format_args!("{name}.ior"), self.ior)?;
        for (axis, c) in ["x", "y", "z"].iter().zip(self.color) {
            if c < 0.0 {
                return Err(Error::invalid(format!(
                    "{name}.color.{axis} is {c}; colors must not be negative"
                )));
            }
            if c > 1.0 {
                return Err(Error::invalid(format!(
                    "{name}.color.{axis} is {c}; a reflectance above 1 would create energy"
                )));
            }
        }
        for (axis, e) in ["x", "y", "z"].iter().zip(self.emission) {
            if e < 0.0 {
                return Err(Error::invalid(format!(
                    "{name}.emission.{axis} is {e}; emission must not be negative"
                )));
            }
        }
        if self.kind == MaterialKind::Dielectric && self.ior <= 0.0 {
            return Err(Error::invalid(format!(
                "{name}.ior is {}; a dielectric's index of refraction must be greater than 0",
                self.ior
            )));
        }
        Ok(())
    }
}
