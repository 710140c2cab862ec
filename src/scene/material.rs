//! Surface materials: what a triangle does with light.

use crate::bsdf::{BsdfModel, MetallicRoughness};
use crate::error::{Error, Result, check_finite, check_finite3};
use crate::spectral::Channels;
use crate::spectrum::Spectrum;

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
    /// glTF 2.0's metallic-roughness model (its specification's appendix B): base colour
    /// `color`, `metallic`, `roughness` (GGX with α = roughness²; 0 is the exact specular
    /// lobe), dielectric Fresnel from `ior`, and `transmission`
    /// (`KHR_materials_transmission`) through the back side.
    MetallicRoughness,
}

/// How a material's alpha (`alpha` × the base colour texture's alpha × the vertex colour's)
/// shapes its surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is solid (glTF `OPAQUE`).
    #[default]
    Opaque,
    /// A cut-out: where alpha < `alpha_cutoff` there is no surface, and rays (camera,
    /// light and shadow rays alike) pass through (glTF `MASK`).
    Mask,
}

/// A material's use of a texture: which one, and the affine map applied to the surface's
/// texture coordinates before the lookup (glTF `KHR_texture_transform`: scale, then
/// rotate, then offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `SceneDesc::textures`.
    pub texture: u32,
    pub offset: [f32; 2],
    /// Radians, counter-clockwise in uv space as `KHR_texture_transform` defines it.
    pub rotation: f32,
    pub scale: [f32; 2],
}

impl TextureRef {
    /// Texture `texture` at the surface's own coordinates.
    pub const fn new(texture: u32) -> Self {
        TextureRef {
            texture,
            offset: [0.0; 2],
            rotation: 0.0,
            scale: [1.0; 2],
        }
    }

    /// The transform as the rows of a 2×3 matrix applied to (u, v, 1).
    #[allow(dead_code)] // Until textures are looked up.
    pub(crate) fn matrix(&self) -> [[f32; 3]; 2] {
        let (sin, cos) = self.rotation.sin_cos();
        let [sx, sy] = self.scale;
        [
            [cos * sx, sin * sy, self.offset[0]],
            [-sin * sx, cos * sy, self.offset[1]],
        ]
    }

    fn validate(&self, name: &str, texture_count: usize) -> Result<()> {
        if self.texture as usize >= texture_count {
            return Err(Error::invalid(format!(
                "{name}.texture is {}, but there are only {texture_count} textures",
                self.texture
            )));
        }
        check_finite(&format_args!("{name}.rotation"), self.rotation)?;
        for (field, value) in [("offset", self.offset), ("scale", self.scale)] {
            for (axis, v) in ["u", "v"].iter().zip(value) {
                check_finite(&format_args!("{name}.{field}.{axis}"), v)?;
            }
        }
        Ok(())
    }
}

/// A material. Any material may also emit: `emission` (times `emission_texture`) is the
/// radiance leaving the triangle's front side (counter-clockwise winding); emissive
/// triangles are area lights.
///
/// Textures (`SceneDesc::textures`, looked up at the surface's texture coordinates):
/// `base_color_texture` multiplies `color` and `alpha` for every kind;
/// `metallic_roughness_texture` multiplies `roughness` (its green channel) and `metallic`
/// (blue) as glTF defines; `normal_texture` is a tangent-space normal map (glTF's
/// convention, +Y up in the texture) whose x and y are scaled by `normal_scale`;
/// `emission_texture` multiplies `emission`. Per-vertex colours multiply `color` and
/// `alpha` too.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub kind: MaterialKind,
    /// Diffuse albedo, mirror reflectance, glass tint or base colour; linear RGB in [0, 1].
    pub color: [f32; 3],
    pub emission: [f32; 3],
    pub ior: f32,
    /// Metalness in [0, 1] (metallic-roughness only).
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (metallic-roughness only).
    pub roughness: f32,
    /// The fraction of the non-metallic base that is transmission, in [0, 1]
    /// (metallic-roughness only).
    pub transmission: f32,
    /// Coverage in [0, 1], used by `AlphaMode::Mask`.
    pub alpha: f32,
    pub alpha_mode: AlphaMode,
    /// `AlphaMode::Mask` cuts out where alpha < `alpha_cutoff`; finite, >= 0.
    pub alpha_cutoff: f32,
    pub base_color_texture: Option<TextureRef>,
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    /// Scales the normal map's x and y; finite.
    pub normal_scale: f32,
    pub emission_texture: Option<TextureRef>,
    /// Metallic-roughness only: compensate the metal's reflection for the light that
    /// bounces between microfacets more than once (Kulla and Conty 2017), which glTF's
    /// single-scattering model loses: a white metal then reflects all the light at every
    /// roughness instead of 92% at roughness 0.5 and 31% at 1 (normal incidence). Off by
    /// default, as glTF defines the model; the dielectric's reflection is not compensated.
    pub energy_compensation: bool,
    /// Dispersion of a dielectric (and of the metallic-roughness model's dielectric part),
    /// as the Abbe number V_d: the index of refraction `ior` holds at 587.56 nm (the
    /// helium d line) and varies with the wavelength λ by the Cauchy form that glTF's
    /// `KHR_materials_dispersion` defines (whose `dispersion` is 20 / V_d),
    /// n(λ) = n_d + (n_d − 1) / V_d · (523655 nm² / λ² − 1.5168),
    /// so that n(486.13 nm) − n(656.27 nm) = (n_d − 1) / V_d. 0 means no dispersion;
    /// otherwise finite and positive (crown glass ≈ 60, flint ≈ 36, diamond ≈ 55 at a
    /// higher index). Only spectral renders disperse light; RGB renders use n_d.
    pub abbe_number: f32,
}

impl Material {
    pub fn diffuse(albedo: [f32; 3]) -> Self {
        Material {
            kind: MaterialKind::Diffuse,
            color: albedo,
            emission: [0.0; 3],
            ior: 1.5,
            metallic: 0.0,
            roughness: 1.0,
            transmission: 0.0,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            base_color_texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emission_texture: None,
            energy_compensation: false,
            abbe_number: 0.0,
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

    /// glTF's metallic-roughness material with index of refraction 1.5 and no transmission
    /// (glTF's defaults are base colour 1, metallic 1, roughness 1).
    pub fn metallic_roughness(base_color: [f32; 3], metallic: f32, roughness: f32) -> Self {
        Material {
            kind: MaterialKind::MetallicRoughness,
            metallic,
            roughness,
            ..Material::diffuse(base_color)
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

    /// Whether any texture is looked up at the surface's texture coordinates.
    pub fn has_textures(&self) -> bool {
        self.base_color_texture.is_some()
            || self.metallic_roughness_texture.is_some()
            || self.normal_texture.is_some()
            || self.emission_texture.is_some()
    }

    /// The texture references with their field names, for validation.
    fn texture_refs(&self) -> [(&'static str, Option<TextureRef>); 4] {
        [
            ("base_color_texture", self.base_color_texture),
            (
                "metallic_roughness_texture",
                self.metallic_roughness_texture,
            ),
            ("normal_texture", self.normal_texture),
            ("emission_texture", self.emission_texture),
        ]
    }

    /// Checks every field, naming `materials[index]` in the message; texture references
    /// must be below `texture_count`.
    pub fn validate(&self, index: usize, texture_count: usize) -> Result<()> {
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
        if matches!(
            self.kind,
            MaterialKind::Dielectric | MaterialKind::MetallicRoughness
        ) && self.ior <= 0.0
        {
            return Err(Error::invalid(format!(
                "{name}.ior is {}; a dielectric's index of refraction must be greater than 0",
                self.ior
            )));
        }
        for (field, value) in [
            ("metallic", self.metallic),
            ("roughness", self.roughness),
            ("transmission", self.transmission),
            ("alpha", self.alpha),
        ] {
            check_finite(&format_args!("{name}.{field}"), value)?;
            if !(0.0..=1.0).contains(&value) {
                return Err(Error::invalid(format!(
                    "{name}.{field} is {value}; it must be in [0, 1]"
                )));
            }
        }
        check_finite(&format_args!("{name}.alpha_cutoff"), self.alpha_cutoff)?;
        if self.alpha_cutoff < 0.0 {
            return Err(Error::invalid(format!(
                "{name}.alpha_cutoff is {}; it must not be negative",
                self.alpha_cutoff
            )));
        }
        check_finite(&format_args!("{name}.normal_scale"), self.normal_scale)?;
        check_finite(&format_args!("{name}.abbe_number"), self.abbe_number)?;
        if self.abbe_number < 0.0 {
            return Err(Error::invalid(format!(
                "{name}.abbe_number is {}; an Abbe number must be positive (0: no dispersion)",
                self.abbe_number
            )));
        }
        for (field, texture) in self.texture_refs() {
            if let Some(texture) = texture {
                texture.validate(&format!("{name}.{field}"), texture_count)?;
            }
        }
        Ok(())
    }
}

impl Material {
    /// Whether light of different wavelengths refracts differently at this material in a
    /// spectral render: a dispersion is set and the model has a dielectric interface.
    #[inline(always)]
    pub(crate) fn disperses(&self, channels: &Channels) -> bool {
        self.abbe_number > 0.0
            && matches!(
                self.kind,
                MaterialKind::Dielectric | MaterialKind::MetallicRoughness
            )
            && channels.hero().is_some()
    }

    /// The index of refraction for a path in `channels`: at the hero wavelength where the
    /// material disperses (Cauchy's form, see `abbe_number`, never below 1), else `ior`.
    #[inline(always)]
    pub(crate) fn ior_in(&self, channels: &Channels) -> f32 {
        match channels.hero() {
            Some(lambda) if self.abbe_number > 0.0 => {
                cauchy_index(self.ior, self.abbe_number, lambda)
            }
            _ => self.ior,
        }
    }

    /// The scattering model of the untextured material.
    #[cfg(test)]
    pub(crate) fn bsdf_model(&self, channels: &Channels) -> BsdfModel {
        self.textured_bsdf_model(
            channels.reflectance(self.color),
            self.metallic,
            self.roughness,
            self.ior_in(channels),
        )
    }

    /// The scattering model with the colour replaced by `color` and, for the
    /// metallic-roughness model, its metalness and roughness by `metallic` and `roughness`
    /// (textured).
    #[inline]
    pub(crate) fn textured_bsdf_model(
        &self,
        color: Spectrum,
        metallic: f32,
        roughness: f32,
        ior: f32,
    ) -> BsdfModel {
        match self.kind {
            MaterialKind::Diffuse => BsdfModel::Diffuse(color),
            MaterialKind::Mirror => BsdfModel::Mirror(color),
            MaterialKind::Dielectric => BsdfModel::Dielectric { ior, tint: color },
            MaterialKind::MetallicRoughness => BsdfModel::MetallicRoughness(MetallicRoughness {
                base_color: color,
                metallic,
                roughness,
                ior,
                transmission: self.transmission,
                energy_compensation: self.energy_compensation,
            }),
        }
    }
}

/// The index of refraction at `lambda` nm of a material with index `ior_d` at the d line
/// (587.56 nm) and Abbe number `abbe_number` > 0, by `KHR_materials_dispersion`'s Cauchy
/// form; at least 1 (a far-dispersing low index would otherwise fall below vacuum's).
#[inline]
pub(crate) fn cauchy_index(ior_d: f32, abbe_number: f32, lambda: f32) -> f32 {
    (ior_d + (ior_d - 1.0) / abbe_number * (523_655.0 / (lambda * lambda) - 1.5168)).max(1.0)
}
