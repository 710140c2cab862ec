//! Surface materials: what a triangle does with light.

use crate::bsdf::{BsdfModel, Clearcoat, MetallicRoughness, Sheen, ThinFilm};
use crate::error::{Error, Result};
use crate::params::{ChoiceParameter, Range, declare_parameters, in_unit_interval};
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
pub use crate::texture::TextureRef;

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
    /// Stochastic coverage (glTF `BLEND`): a fraction alpha of the light meets the surface
    /// and the rest passes straight on. A cut-out whose cutoff is a fixed pseudo-random
    /// threshold per surface point (`Scene::is_solid`), so every ray that reaches a point
    /// finds the same surface there; `alpha_cutoff` is unused.
    Blend,
}

// Each material parameter is declared once: the C, C++ and Python fields, the command line's
// `--material NAME=VALUE`, the checks of `validate` and `docs/settings.md` follow from this
// table. The order is the C struct's: append new parameters at the end.
declare_parameters! {
    /// A material. Any material may also emit: `emission` (times `emission_texture`) is the
    /// radiance leaving the triangle's front side (counter-clockwise winding); emissive
    /// triangles are area lights.
    ///
    /// Textures (`SceneDesc::textures`, looked up at the surface's texture coordinates):
    /// `base_color_texture` multiplies `color` and `alpha` for every kind;
    /// `metallic_roughness_texture` multiplies `roughness` (its green channel) and `metallic`
    /// (blue) as glTF defines; `normal_texture` is a tangent-space normal map (glTF's
    /// convention, +Y up in the texture) whose x and y are scaled by `normal_scale`;
    /// `emission_texture` multiplies `emission`; `transmission_texture`'s red channel
    /// multiplies `transmission`; `clearcoat_texture`'s red and
    /// `clearcoat_roughness_texture`'s green multiply the clear coat's factor and roughness,
    /// and `clearcoat_normal_texture` is the coat's own normal map (scaled by
    /// `clearcoat_normal_scale`); `specular_texture`'s alpha and `specular_color_texture`'s
    /// RGB multiply `specular` and `specular_color`, `sheen_color_texture`'s RGB and
    /// `sheen_roughness_texture`'s alpha `sheen_color` and `sheen_roughness`;
    /// `anisotropy_texture`'s red and green give the anisotropy's direction in the tangent
    /// plane and its blue multiplies `anisotropy`; `iridescence_texture`'s red multiplies
    /// `iridescence`, and `iridescence_thickness_texture`'s green interpolates the film's
    /// thickness from `iridescence_thickness_minimum` to `iridescence_thickness_maximum`.
    /// Per-vertex colours multiply `color` and `alpha` too.
    ///
    /// The default is a light grey (0.8) diffuse surface, the C API's and Python's.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Material in "material" {
        kind: MaterialKind = MaterialKind::Diffuse => {
            doc: "The scattering model: diffuse (Lambertian), mirror, dielectric (smooth glass) or metallic-roughness (glTF 2.0's).",
        },
        /// Diffuse albedo, mirror reflectance, glass tint or base colour; linear RGB in [0, 1].
        color: [f32; 3] = [0.8; 3] => {
            doc: "Diffuse albedo, mirror reflectance, glass tint or metallic-roughness base colour, linear RGB.",
            range: Range::closed(0.0, 1.0),
            rule: |_| "a reflectance must be in [0, 1]; above 1 would create energy".into(),
        },
        emission: [f32; 3] = [0.0; 3] => {
            doc: "Radiance emitted from the front (counter-clockwise) side, linear RGB; emissive triangles are area lights.",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "emission must not be negative".into(),
        },
        /// Index of refraction (> 0 where used; the outside is vacuum).
        ior: f32 = 1.5 => {
            doc: "Index of refraction of a dielectric and of the metallic-roughness model's dielectric part (there > 0).",
        },
        /// Metalness in [0, 1] (metallic-roughness only).
        metallic: f32 = 0.0 => {
            doc: "Metallic-roughness: metalness, 0 a dielectric, 1 a metal whose reflectance is the colour.",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// Perceptual roughness in [0, 1] (metallic-roughness only).
        roughness: f32 = 1.0 => {
            doc: "Metallic-roughness: perceptual roughness (GGX alpha = roughness squared; 0 is the exact specular lobe).",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// The fraction of the non-metallic base that is transmission, in [0, 1]
        /// (metallic-roughness only).
        transmission: f32 = 0.0 => {
            doc: "Metallic-roughness: the fraction of the non-metallic base transmitted, not diffusely reflected (KHR_materials_transmission).",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// Coverage in [0, 1], used by `AlphaMode::Mask` and `AlphaMode::Blend`.
        alpha: f32 = 1.0 => {
            doc: "Coverage, times the base colour texture's alpha and the vertex colour's; used by the mask and blend alpha modes.",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        alpha_mode: AlphaMode = AlphaMode::Opaque => {
            doc: "What alpha does: opaque ignores it, mask cuts the surface out where alpha < alpha_cutoff (glTF's MASK), blend lets a fraction 1 - alpha of the light pass straight through (glTF's BLEND, as stochastic coverage).",
        },
        /// `AlphaMode::Mask` cuts out where alpha < `alpha_cutoff`; finite, >= 0.
        alpha_cutoff: f32 = 0.5 => {
            doc: "The mask alpha mode's threshold (glTF's alphaCutoff).",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "it must not be negative".into(),
        },
        base_color_texture: Option<TextureRef> = None => {
            doc: "Multiplies the colour (RGB) and alpha (A), for every kind; usually 8-bit sRGB.",
        },
        metallic_roughness_texture: Option<TextureRef> = None => {
            doc: "Green multiplies the roughness, blue the metalness (glTF's packing); usually linear.",
        },
        normal_texture: Option<TextureRef> = None => {
            doc: "A tangent-space normal map (glTF's convention: +Y up in the image); usually linear.",
        },
        emission_texture: Option<TextureRef> = None => {
            doc: "Multiplies the emission; usually 8-bit sRGB.",
        },
        /// Scales the normal map's x and y; finite.
        normal_scale: f32 = 1.0 => {
            doc: "Scales the normal map's x and y (glTF's normalTexture.scale).",
        },
        /// Metallic-roughness only: compensate the metal's reflection for the light that
        /// bounces between microfacets more than once (Kulla and Conty 2017), which glTF's
        /// single-scattering model loses: a white metal then reflects all the light at every
        /// roughness instead of 92% at roughness 0.5 and 31% at 1 (normal incidence). Off by
        /// default, as glTF defines the model; the dielectric's reflection is not compensated.
        energy_compensation: bool = false => {
            doc: "Metallic-roughness: give rough metals the light glTF's single-scattering model loses (Kulla and Conty 2017).",
        },
        /// Dispersion of a dielectric (and of the metallic-roughness model's dielectric part),
        /// as the Abbe number V_d: the index of refraction `ior` holds at 587.56 nm (the
        /// helium d line) and varies with the wavelength λ by the Cauchy form that glTF's
        /// `KHR_materials_dispersion` defines (whose `dispersion` is 20 / V_d),
        /// n(λ) = n_d + (n_d − 1) / V_d · (523655 nm² / λ² − 1.5168),
        /// so that n(486.13 nm) − n(656.27 nm) = (n_d − 1) / V_d. 0 means no dispersion;
        /// otherwise finite and positive (crown glass ≈ 60, flint ≈ 36, diamond ≈ 55 at a
        /// higher index). Only spectral renders disperse light; RGB renders use n_d.
        abbe_number: f32 = 0.0 => {
            doc: "Dispersion as the Abbe number V_d (0: none; KHR_materials_dispersion's dispersion is 20 / V_d); spectral renders only.",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "an Abbe number must be positive (0: no dispersion)".into(),
        },
        transmission_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: red multiplies the transmission (KHR_materials_transmission's transmissionTexture); usually linear.",
        },
        /// Metallic-roughness only: a clear coat over the whole material, in [0, 1] (0: none).
        clearcoat: f32 = 0.0 => {
            doc: "Metallic-roughness: a clear coat over the material, a white GGX reflection of index 1.5 with its own roughness and normal (KHR_materials_clearcoat's clearcoatFactor); 0 is none.",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// The clear coat's perceptual roughness in [0, 1].
        clearcoat_roughness: f32 = 0.0 => {
            doc: "Metallic-roughness: the clear coat's perceptual roughness (GGX alpha = its square; 0 is an exact mirror).",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        clearcoat_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: red multiplies the clear coat (KHR_materials_clearcoat's clearcoatTexture); usually linear.",
        },
        clearcoat_roughness_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: green multiplies the clear coat's roughness (clearcoatRoughnessTexture); usually linear.",
        },
        clearcoat_normal_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: the clear coat's own tangent-space normal map (clearcoatNormalTexture); without it the coat follows the interpolated normal, not normal_texture.",
        },
        /// Scales the clear coat's normal map's x and y; finite.
        clearcoat_normal_scale: f32 = 1.0 => {
            doc: "Scales the clear coat's normal map's x and y (clearcoatNormalTexture.scale).",
        },
        /// The volume behind the surface (`KHR_materials_volume`), for a dielectric and a
        /// metallic-roughness material with transmission, on closed meshes: 0 is a thin wall
        /// (no volume, no absorption); otherwise the light travelling inside is absorbed by
        /// Beer–Lambert's law (see `attenuation_color`). The thickness is not used as a
        /// length: a path tracer measures the real distances through the mesh.
        thickness: f32 = 0.0 => {
            doc: "Dielectric and transmissive metallic-roughness: 0 is thin-walled, above 0 the mesh encloses an absorbing volume (KHR_materials_volume's thicknessFactor).",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "a thickness must not be negative (0: thin-walled)".into(),
        },
        /// The colour white light becomes after travelling `attenuation_distance` inside the
        /// volume: the absorption coefficient is −ln(colour) / distance per channel (per
        /// wavelength in spectral renders, the colour upsampled as a reflectance).
        attenuation_color: [f32; 3] = [1.0; 3] => {
            doc: "The volume's colour after attenuation_distance of travel inside it, linear RGB (KHR_materials_volume's attenuationColor).",
            range: Range::UNIT,
            rule: |_| "an attenuation colour is a transmittance, in [0, 1]".into(),
        },
        /// The distance at which the light inside has the attenuation colour; the largest
        /// float (`f32::MAX`, C's `FLT_MAX`) stands for glTF's default, infinity: no
        /// absorption.
        attenuation_distance: f32 = f32::MAX => {
            doc: "The distance inside the volume after which white light has the attenuation colour; the largest float (FLT_MAX) is infinity, no absorption (KHR_materials_volume's attenuationDistance).",
            range: Range::above(0.0, f32::MAX as f64),
            rule: |_| "an attenuation distance must be greater than 0 (the largest float: no absorption)".into(),
        },
        /// Metallic-roughness: the strength of the dielectric's specular reflection
        /// (`KHR_materials_specular`'s `specularFactor`), in [0, 1]; 0 leaves the diffuse
        /// base alone, and the base gains what the reflection gives up.
        specular: f32 = 1.0 => {
            doc: "Metallic-roughness: strength of the dielectric's specular reflection, 0 a pure diffuse base (KHR_materials_specular's specularFactor).",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// Metallic-roughness: scales the dielectric's normal reflectance F0 per channel
        /// (`KHR_materials_specular`'s `specularColorFactor`), linear RGB, not negative; may
        /// exceed 1 (F0 times it is clamped to 1).
        specular_color: [f32; 3] = [1.0; 3] => {
            doc: "Metallic-roughness: scales the dielectric's F0 per channel, linear RGB, may exceed 1 (F0 times it is clamped to 1; KHR_materials_specular's specularColorFactor).",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "a specular colour must not be negative".into(),
        },
        specular_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: alpha multiplies the specular strength (KHR_materials_specular's specularTexture); usually linear.",
        },
        specular_color_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: RGB multiplies the specular colour (KHR_materials_specular's specularColorTexture); usually 8-bit sRGB.",
        },
        /// Metallic-roughness: the colour of a sheen layer over the material
        /// (`KHR_materials_sheen`'s `sheenColorFactor`), linear RGB in [0, 1]; black, the
        /// default, is no sheen.
        sheen_color: [f32; 3] = [0.0; 3] => {
            doc: "Metallic-roughness: colour of a sheen layer over the material (velvet, cloth), linear RGB; black is none (KHR_materials_sheen's sheenColorFactor).",
            range: Range::closed(0.0, 1.0),
            rule: |_| "a reflectance must be in [0, 1]; above 1 would create energy".into(),
        },
        /// Metallic-roughness: the sheen's perceptual roughness (`KHR_materials_sheen`'s
        /// `sheenRoughnessFactor`) in [0, 1]; the Charlie distribution's α is its square, at
        /// least 0.07².
        sheen_roughness: f32 = 0.0 => {
            doc: "Metallic-roughness: the sheen's roughness (Charlie distribution, alpha = roughness squared, at least 0.07 squared; KHR_materials_sheen's sheenRoughnessFactor).",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        sheen_color_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: RGB multiplies the sheen colour (KHR_materials_sheen's sheenColorTexture); usually 8-bit sRGB.",
        },
        sheen_roughness_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: alpha multiplies the sheen roughness (KHR_materials_sheen's sheenRoughnessTexture); usually linear.",
        },
        /// Metallic-roughness: the anisotropy of the microfacets (`KHR_materials_anisotropy`'s
        /// `anisotropyStrength`), in [0, 1]: GGX's α along the anisotropy's direction is
        /// mix(α, 1, strength²), across it α; 0, the default, is isotropic.
        anisotropy: f32 = 0.0 => {
            doc: "Metallic-roughness: anisotropy of the microfacets (brushed metal), alpha along its direction = mix(alpha, 1, strength squared); 0 is isotropic (KHR_materials_anisotropy's anisotropyStrength).",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// Metallic-roughness: the anisotropy's direction, in radians counter-clockwise from
        /// the mesh's tangent towards its bitangent (`anisotropyRotation`); finite.
        anisotropy_rotation: f32 = 0.0 => {
            doc: "Metallic-roughness: the anisotropy's direction in radians, counter-clockwise from the mesh's tangent towards its bitangent (KHR_materials_anisotropy's anisotropyRotation).",
        },
        anisotropy_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: red and green are the anisotropy's direction in the tangent plane mapped from [-1, 1] to [0, 1] (then rotated by anisotropy_rotation), blue multiplies its strength (KHR_materials_anisotropy's anisotropyTexture); linear.",
        },
        /// Metallic-roughness: the strength of a thin film over the material
        /// (`KHR_materials_iridescence`'s `iridescenceFactor`), in [0, 1]; 0, the default, is
        /// none. The specular reflection's Fresnel term becomes the film's by this share.
        iridescence: f32 = 0.0 => {
            doc: "Metallic-roughness: strength of a thin film over the material, its interference colours (soap bubbles, oil); 0 is none (KHR_materials_iridescence's iridescenceFactor). Exact per wavelength in spectral renders, integrated over each RGB channel otherwise.",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        iridescence_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: red multiplies the thin film's strength (KHR_materials_iridescence's iridescenceTexture); usually linear.",
        },
        /// Metallic-roughness: the thin film's index of refraction, > 0 (glTF's default
        /// 1.3).
        iridescence_ior: f32 = 1.3 => {
            doc: "Metallic-roughness: the thin film's index of refraction (KHR_materials_iridescence's iridescenceIor).",
            range: Range::above(0.0, f32::MAX as f64),
            rule: |_| "an index of refraction must be greater than 0".into(),
        },
        /// Metallic-roughness: the thin film's thickness in nanometres where
        /// `iridescence_thickness_texture`'s green is 0; not negative.
        iridescence_thickness_minimum: f32 = 100.0 => {
            doc: "Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's green is 0 (KHR_materials_iridescence's iridescenceThicknessMinimum).",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "a thickness must not be negative".into(),
        },
        /// Metallic-roughness: the thin film's thickness in nanometres where
        /// `iridescence_thickness_texture`'s green is 1, and everywhere without the texture;
        /// not negative. A film of thickness 0 is none.
        iridescence_thickness_maximum: f32 = 400.0 => {
            doc: "Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's green is 1, and everywhere without it; 0 is no film (KHR_materials_iridescence's iridescenceThicknessMaximum).",
            range: Range::closed(0.0, f32::MAX as f64),
            rule: |_| "a thickness must not be negative".into(),
        },
        iridescence_thickness_texture: Option<TextureRef> = None => {
            doc: "Metallic-roughness: green interpolates the thin film's thickness from the minimum (0) to the maximum (1) (KHR_materials_iridescence's iridescenceThicknessTexture); usually linear.",
        },
    }
}

impl ChoiceParameter for MaterialKind {
    const NAMES: &'static [&'static str] =
        &["diffuse", "mirror", "dielectric", "metallic-roughness"];
    const ALL: &'static [MaterialKind] = &[
        MaterialKind::Diffuse,
        MaterialKind::Mirror,
        MaterialKind::Dielectric,
        MaterialKind::MetallicRoughness,
    ];
    const TYPE_NAME: &'static str = "MaterialKind";
    const C_PREFIX: &'static str = "MLT_MATERIAL";
}

impl ChoiceParameter for AlphaMode {
    const NAMES: &'static [&'static str] = &["opaque", "mask", "blend"];
    const ALL: &'static [AlphaMode] = &[AlphaMode::Opaque, AlphaMode::Mask, AlphaMode::Blend];
    const TYPE_NAME: &'static str = "AlphaMode";
    const C_PREFIX: &'static str = "MLT_ALPHA";
}

impl Material {
    pub fn diffuse(albedo: [f32; 3]) -> Self {
        Material {
            kind: MaterialKind::Diffuse,
            color: albedo,
            ..Material::default()
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
    #[inline]
    pub fn has_textures(&self) -> bool {
        self.any_texture()
    }

    /// Checks every field, naming `desc.materials[index]` in the message: the declared
    /// ranges, then what depends on the kind and the scene (texture references must be
    /// below `texture_count`).
    pub fn validate(&self, index: usize, texture_count: usize) -> Result<()> {
        let name = format!("desc.materials[{index}]");
        self.check_ranges(&name)?;
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
        for (field, texture) in self.textures() {
            texture.validate(&format!("{name}.{field}"), texture_count)?;
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
            self.transmission,
            self.ior_in(channels),
            &self.untextured_layers(),
            channels,
        )
    }

    /// The specular, sheen and thin film parameters without their textures.
    #[inline]
    pub(crate) fn untextured_layers(&self) -> SpecularAndSheen {
        SpecularAndSheen {
            specular: self.specular,
            specular_color: self.specular_color,
            sheen_color: self.sheen_color,
            sheen_roughness: self.sheen_roughness,
            iridescence: self.iridescence,
            iridescence_thickness: self.iridescence_thickness_maximum,
        }
    }

    /// The scattering model with the colour replaced by `color` and, for the
    /// metallic-roughness model, its metalness, roughness and transmission by `metallic`,
    /// `roughness` and `transmission`, its specular and sheen parameters by `layers`
    /// (textured; their colours turned into `channels`).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn textured_bsdf_model(
        &self,
        color: Spectrum,
        metallic: f32,
        roughness: f32,
        transmission: f32,
        ior: f32,
        layers: &SpecularAndSheen,
        channels: &Channels,
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
                transmission,
                energy_compensation: self.energy_compensation,
                clearcoat: Clearcoat {
                    factor: self.clearcoat,
                    roughness: self.clearcoat_roughness,
                    normal: None,
                },
                specular: layers.specular,
                specular_color: layers.specular_color(channels),
                specular_color_max: max3(layers.specular_color),
                sheen: layers.sheen(channels),
                // Its direction needs the surface's tangent frame: the surface sets it.
                anisotropy: None,
                film: layers.film(self.iridescence_ior, channels),
            }),
        }
    }
}

/// The `KHR_materials_specular`, `KHR_materials_sheen` and `KHR_materials_iridescence`
/// parameters at a surface point.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpecularAndSheen {
    pub specular: f32,
    pub specular_color: [f32; 3],
    pub sheen_color: [f32; 3],
    pub sheen_roughness: f32,
    /// The thin film's strength.
    pub iridescence: f32,
    /// The thin film's thickness in nanometres.
    pub iridescence_thickness: f32,
}

#[inline]
fn max3(c: [f32; 3]) -> f32 {
    c[0].max(c[1]).max(c[2])
}

impl SpecularAndSheen {
    /// The specular colour in `channels` (white, the default, exactly: no spectral fit).
    #[inline]
    fn specular_color(&self, channels: &Channels) -> Spectrum {
        if self.specular_color == [1.0; 3] {
            Spectrum::ONE
        } else {
            // A spectral fit may rise above the RGB's largest channel, which weights the base.
            channels
                .reflectance(self.specular_color)
                .min(Spectrum::splat(max3(self.specular_color)))
        }
    }

    /// The thin film of index `ior`, `None` where its strength or its thickness is 0 (as
    /// `KHR_materials_iridescence` defines: no film, the plain Fresnel term exactly).
    #[inline]
    fn film(&self, ior: f32, channels: &Channels) -> Option<ThinFilm> {
        (self.iridescence > 0.0 && self.iridescence_thickness > 0.0).then(|| ThinFilm {
            factor: self.iridescence,
            ior,
            thickness: self.iridescence_thickness,
            wavelengths: channels.wavelengths(),
        })
    }

    /// The sheen layer, `None` for a black sheen colour (the default) without a look at
    /// the rest.
    #[inline]
    fn sheen(&self, channels: &Channels) -> Option<Sheen> {
        let color_max = max3(self.sheen_color);
        if color_max <= 0.0 {
            return None;
        }
        Sheen::new(
            channels.reflectance(self.sheen_color),
            color_max,
            self.sheen_roughness,
        )
    }
}

/// The index of refraction at `lambda` nm of a material with index `ior_d` at the d line
/// (587.56 nm) and Abbe number `abbe_number` > 0, by `KHR_materials_dispersion`'s Cauchy
/// form; at least 1 (a far-dispersing low index would otherwise fall below vacuum's).
#[inline]
pub(crate) fn cauchy_index(ior_d: f32, abbe_number: f32, lambda: f32) -> f32 {
    (ior_d + (ior_d - 1.0) / abbe_number * (523_655.0 / (lambda * lambda) - 1.5168)).max(1.0)
}
