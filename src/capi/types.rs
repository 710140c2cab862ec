//! The C types and constants: what include/mlt.h declares (cbindgen reads them here).

use crate::scene::Scene;
use std::ffi::c_void;

/// Major version of the mlt library this header belongs to.
pub const MLT_VERSION_MAJOR: u32 = 0;
/// Minor version.
pub const MLT_VERSION_MINOR: u32 = 7;
/// Patch version.
pub const MLT_VERSION_PATCH: u32 = 0;
/// The version as one number, MAJOR * 10000 + MINOR * 100 + PATCH, for `#if MLT_VERSION >= …`
/// checks; `mlt_version()` returns the linked library's.
pub const MLT_VERSION: u32 =
    MLT_VERSION_MAJOR * 10000 + MLT_VERSION_MINOR * 100 + MLT_VERSION_PATCH;

/// `MltMaterial.kind`: Lambertian diffuse with albedo `color` (two-sided).
pub const MLT_MATERIAL_DIFFUSE: i32 = 0;
/// `MltMaterial.kind`: perfect mirror reflecting `color` (two-sided).
pub const MLT_MATERIAL_MIRROR: i32 = 1;
/// `MltMaterial.kind`: smooth dielectric (glass) with index of refraction `ior`, tinted by `color`.
pub const MLT_MATERIAL_DIELECTRIC: i32 = 2;
/// `MltMaterial.kind`: glTF 2.0's metallic-roughness model (its specification's appendix
/// B): base colour `color`, `metallic`, `roughness` (GGX with alpha = roughness^2; 0 is a
/// perfectly smooth surface), dielectric Fresnel from `ior` (1.5 is glTF's), and
/// `transmission` (`KHR_materials_transmission`) through the back side.
pub const MLT_MATERIAL_METALLIC_ROUGHNESS: i32 = 3;

/// `MltMaterial.alpha_mode`: alpha is ignored, the surface is solid (glTF `OPAQUE`).
pub const MLT_ALPHA_OPAQUE: i32 = 0;
/// `MltMaterial.alpha_mode`: a cut-out (glTF `MASK`): where alpha (`alpha` × the base
/// colour texture's alpha × the vertex colour's alpha) is below `alpha_cutoff` there is no
/// surface, and every ray passes through.
pub const MLT_ALPHA_MASK: i32 = 1;
/// `MltMaterial.alpha_mode`: stochastic coverage (glTF `BLEND`): a fraction alpha of the light
/// meets the surface and 1 − alpha passes straight through, decided by a fixed pseudo-random
/// threshold per surface point; `alpha_cutoff` is unused.
pub const MLT_ALPHA_BLEND: i32 = 2;

/// `MltTextureRef.texture` of a material slot without a texture.
pub const MLT_NO_TEXTURE: i32 = -1;

// The bits of `MltMaterial.texcoord1_slots`, one per texture slot in field order.
// BEGIN GENERATED texcoord1 slots: tests/parameters.rs writes these lines from src/scene/material.rs
/// `MltMaterial.texcoord1_slots`: `base_color_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_BASE_COLOR: u32 = 1 << 0;
/// `MltMaterial.texcoord1_slots`: `metallic_roughness_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_METALLIC_ROUGHNESS: u32 = 1 << 1;
/// `MltMaterial.texcoord1_slots`: `normal_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_NORMAL: u32 = 1 << 2;
/// `MltMaterial.texcoord1_slots`: `emission_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_EMISSION: u32 = 1 << 3;
/// `MltMaterial.texcoord1_slots`: `transmission_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_TRANSMISSION: u32 = 1 << 4;
/// `MltMaterial.texcoord1_slots`: `clearcoat_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_CLEARCOAT: u32 = 1 << 5;
/// `MltMaterial.texcoord1_slots`: `clearcoat_roughness_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_CLEARCOAT_ROUGHNESS: u32 = 1 << 6;
/// `MltMaterial.texcoord1_slots`: `clearcoat_normal_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_CLEARCOAT_NORMAL: u32 = 1 << 7;
/// `MltMaterial.texcoord1_slots`: `specular_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_SPECULAR: u32 = 1 << 8;
/// `MltMaterial.texcoord1_slots`: `specular_color_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_SPECULAR_COLOR: u32 = 1 << 9;
/// `MltMaterial.texcoord1_slots`: `sheen_color_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_SHEEN_COLOR: u32 = 1 << 10;
/// `MltMaterial.texcoord1_slots`: `sheen_roughness_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_SHEEN_ROUGHNESS: u32 = 1 << 11;
/// `MltMaterial.texcoord1_slots`: `anisotropy_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_ANISOTROPY: u32 = 1 << 12;
/// `MltMaterial.texcoord1_slots`: `iridescence_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_IRIDESCENCE: u32 = 1 << 13;
/// `MltMaterial.texcoord1_slots`: `iridescence_thickness_texture` reads texture coordinate set 1.
pub const MLT_TEXCOORD1_IRIDESCENCE_THICKNESS: u32 = 1 << 14;
// END GENERATED texcoord1 slots

/// `MltTexture.texel_type`: 8-bit values (`uint8_t`), 255 meaning 1, decoded by `encoding`.
pub const MLT_TEXEL_U8: i32 = 0;
/// `MltTexture.texel_type`: linear `float` values, each finite and >= 0 (above 1 is
/// allowed: emission may be HDR).
pub const MLT_TEXEL_F32: i32 = 1;

/// `MltTexture.encoding`: the colour channels of 8-bit texels use the sRGB transfer function
/// (IEC 61966-2-1), as glTF base colour and emissive images do; alpha stays linear. Only
/// with `MLT_TEXEL_U8`. The default.
pub const MLT_TEXTURE_SRGB: i32 = 0;
/// `MltTexture.encoding`: values are linear (value / 255 for 8-bit texels), as glTF
/// normal and metallic-roughness images are; the only encoding of `MLT_TEXEL_F32`.
pub const MLT_TEXTURE_LINEAR: i32 = 1;

/// `MltTexture.wrap_u` / `wrap_v`: the image tiles the plane (glTF's default, the default).
pub const MLT_WRAP_REPEAT: i32 = 0;
/// `MltTexture.wrap_u` / `wrap_v`: the edge texels extend outwards.
pub const MLT_WRAP_CLAMP_TO_EDGE: i32 = 1;
/// `MltTexture.wrap_u` / `wrap_v`: the image tiles with period 2, mirrored on every odd tile.
pub const MLT_WRAP_MIRRORED_REPEAT: i32 = 2;

/// `MltTexture.filter`: the texel containing the point.
pub const MLT_FILTER_NEAREST: i32 = 0;
/// `MltTexture.filter`: the four texels around the point, weighted by distance, on linear
/// values (the default).
pub const MLT_FILTER_BILINEAR: i32 = 1;

/// `MltPunctualLight.kind`: radiates `intensity` equally in every direction from `position`.
pub const MLT_LIGHT_POINT: i32 = 0;
/// `MltPunctualLight.kind`: radiates from `position` into a cone about `direction`, full
/// `intensity` within `inner_cone_degrees` of the axis, none beyond `outer_cone_degrees`,
/// with glTF's smooth falloff between.
pub const MLT_LIGHT_SPOT: i32 = 1;
/// `MltPunctualLight.kind`: light travelling along `direction` from infinitely far away,
/// with irradiance `intensity` on a plane facing it.
pub const MLT_LIGHT_DIRECTIONAL: i32 = 2;

/// `MltSceneDesc.backend`: mlt's own SIMD BVH (8-wide with AVX2, else 4-wide; built with
/// obvhs), always available.
pub const MLT_BACKEND_BVH: i32 = 0;
/// `MltSceneDesc.backend`: Intel Embree 3, only when mlt was built with the `embree` feature.
pub const MLT_BACKEND_EMBREE: i32 = 1;

/// `MltSceneDesc.build_quality` (0, the default): the acceleration structure that renders
/// fastest, for scenes built once and rendered long (Embree: `RTC_BUILD_QUALITY_HIGH`).
pub const MLT_BUILD_QUALITY_HIGH: i32 = 0;
/// `MltSceneDesc.build_quality`: a quicker build, slower rays (Embree:
/// `RTC_BUILD_QUALITY_MEDIUM`).
pub const MLT_BUILD_QUALITY_MEDIUM: i32 = 1;
/// `MltSceneDesc.build_quality`: the quickest build, for scenes rebuilt often (an editor's
/// preview, a baking tool's iterations); rays are slower still (Embree:
/// `RTC_BUILD_QUALITY_LOW`). Every quality gives the same images up to rounding.
pub const MLT_BUILD_QUALITY_FAST: i32 = 2;

/// `MltRenderSettings.algorithm`: path tracing with next-event estimation and MIS.
pub const MLT_ALGORITHM_PATH: i32 = 0;
/// `MltRenderSettings.algorithm`: bidirectional path tracing, all strategies combined by MIS
/// (including light tracing onto the film).
pub const MLT_ALGORITHM_BDPT: i32 = 1;
/// `MltRenderSettings.algorithm`: primary-sample-space Metropolis light transport (Kelemen
/// et al. 2002) over the path tracer; uses the `mutations_per_pixel`, `bootstrap_samples`,
/// `chains`, `large_step_probability` and `small_step_sigma` settings.
pub const MLT_ALGORITHM_PSSMLT: i32 = 2;
/// `MltRenderSettings.algorithm`: multiplexed Metropolis light transport (Hachisuka et al. 2014): primary-sample-space
/// chains over bidirectional path tracing that also pick the path depth and one connection
/// strategy; one group of chains per depth, each normalized by its own bootstrap estimate.
pub const MLT_ALGORITHM_MMLT: i32 = 3;
/// `MltRenderSettings.algorithm`: primary-sample-space MLT over bidirectional path tracing,
/// all strategies of a sample summed.
pub const MLT_ALGORITHM_PSSMLT_BDPT: i32 = 4;
/// `MltRenderSettings.algorithm`: path-space Metropolis light transport (Veach & Guibas
/// 1997): the chains' states are light paths, changed by Veach's mutations; seeded and
/// normalized by a bidirectional bootstrap. Uses `mutations_per_pixel`, `bootstrap_samples`
/// and `chains`.
pub const MLT_ALGORITHM_PATH_SPACE_MLT: i32 = 5;
/// `MltRenderSettings.algorithm`: energy redistribution path tracing (Cline, Talbot & Egbert
/// 2005): each of `samples_per_pixel` BDPT camera samples per pixel starts short chains of
/// lens, caustic and multi-chain perturbations that spread its energy over nearby paths.
/// Unbiased. Uses `erpt_chain_length`, `erpt_deposit_energy` and the perturbation weights
/// of `mutation_weights`.
pub const MLT_ALGORITHM_ERPT: i32 = 6;

/// Index of the bidirectional mutation in `MltRenderSettings.mutation_weights` and the
/// per-mutation counts of `MltRenderStats`.
pub const MLT_MUTATION_BIDIRECTIONAL: i32 = 0;
/// Index of the lens perturbation.
pub const MLT_MUTATION_LENS: i32 = 1;
/// Index of the caustic perturbation.
pub const MLT_MUTATION_CAUSTIC: i32 = 2;
/// Index of the multi-chain perturbation.
pub const MLT_MUTATION_MULTI_CHAIN: i32 = 3;

/// `MltHit.triangle_id` of a ray that hit nothing.
pub const MLT_INVALID_ID: u32 = u32::MAX;

/// A material's use of a texture: which one, and glTF's `KHR_texture_transform` applied to
/// the surface's texture coordinates before the lookup (scale, then rotate, then offset).
/// Plain data inside `MltMaterial` (it has no `struct_size` of its own); the material's
/// initializer sets every slot to no texture with the identity transform.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltTextureRef {
    /// Index into `MltSceneDesc.textures`, below `textures_len`; `MLT_NO_TEXTURE` (-1, the
    /// default) for none (the transform is then ignored).
    pub texture: i32,
    /// Added to the (scaled, rotated) coordinates, u then v; finite. Default 0.
    pub offset: [f32; 2],
    /// Radians, counter-clockwise in uv space as `KHR_texture_transform` defines it;
    /// finite. Default 0.
    pub rotation: f32,
    /// Multiplies u and v first; finite. Default 1.
    pub scale: [f32; 2],
}

/// A material. Initialize with `mlt_material_default`.
///
/// Textures are looked up at the surface's texture coordinates (`MltSceneDesc.texcoords`,
/// which a scene with a textured material must have, or `MltSceneDesc.texcoords1` for the
/// slots whose bit of `texcoord1_slots` is set), each through its `MltTextureRef`:
/// `base_color_texture` multiplies `color` (RGB) and `alpha` (A) for every kind;
/// `metallic_roughness_texture` multiplies `roughness` by its green channel and `metallic`
/// by its blue one (glTF's packing; red is unused); `normal_texture` is a tangent-space
/// normal map; `emission_texture` multiplies `emission`; `transmission_texture`'s red
/// channel multiplies `transmission`; `clearcoat_texture` (red) and
/// `clearcoat_roughness_texture` (green) multiply the clear coat's factor and roughness, and
/// `clearcoat_normal_texture` is the coat's own normal map. Per-vertex colours
/// (`MltSceneDesc.colors`) multiply `color` and `alpha` too.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltMaterial {
    /// sizeof(MltMaterial) of the header the host was built with: set by `mlt_material_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    // BEGIN GENERATED material: tests/parameters.rs writes these lines from src/scene/material.rs
    /// The scattering model: diffuse (Lambertian), mirror, dielectric (smooth glass) or
    /// metallic-roughness (glTF 2.0's). One of `MLT_MATERIAL_*`. Default `MLT_MATERIAL_DIFFUSE`.
    pub kind: i32,
    /// Diffuse albedo, mirror reflectance, glass tint or metallic-roughness base colour, linear
    /// RGB. A reflectance must be in [0, 1]; above 1 would create energy. Default 0.8, 0.8, 0.8.
    pub color: [f32; 3],
    /// Radiance emitted from the front (counter-clockwise) side, linear RGB; emissive triangles are
    /// area lights. Emission must not be negative. Default 0.0, 0.0, 0.0.
    pub emission: [f32; 3],
    /// Index of refraction of a dielectric and of the metallic-roughness model's dielectric part
    /// (there > 0). Any finite number. Default 1.5.
    pub ior: f32,
    /// Metallic-roughness: metalness, 0 a dielectric, 1 a metal whose reflectance is the colour. It
    /// must be in [0, 1]. Default 0.0.
    pub metallic: f32,
    /// Metallic-roughness: perceptual roughness (GGX alpha = roughness squared; 0 is the exact
    /// specular lobe). It must be in [0, 1]. Default 1.0.
    pub roughness: f32,
    /// Metallic-roughness: the fraction of the non-metallic base transmitted, not diffusely
    /// reflected (KHR_materials_transmission). It must be in [0, 1]. Default 0.0.
    pub transmission: f32,
    /// Coverage, times the base colour texture's alpha and the vertex colour's; used by the mask
    /// and blend alpha modes. It must be in [0, 1]. Default 1.0.
    pub alpha: f32,
    /// What alpha does: opaque ignores it, mask cuts the surface out where alpha < alpha_cutoff
    /// (glTF's MASK), blend lets a fraction 1 - alpha of the light pass straight through (glTF's
    /// BLEND, as stochastic coverage). One of `MLT_ALPHA_*`. Default `MLT_ALPHA_OPAQUE`.
    pub alpha_mode: i32,
    /// The mask alpha mode's threshold (glTF's alphaCutoff). It must not be negative. Default 0.5.
    pub alpha_cutoff: f32,
    /// Multiplies the colour (RGB) and alpha (A), for every kind; usually 8-bit sRGB. An index into
    /// `MltSceneDesc.textures` and its transform. Default `MLT_NO_TEXTURE` (-1).
    pub base_color_texture: MltTextureRef,
    /// Green multiplies the roughness, blue the metalness (glTF's packing); usually linear. An
    /// index into `MltSceneDesc.textures` and its transform. Default `MLT_NO_TEXTURE` (-1).
    pub metallic_roughness_texture: MltTextureRef,
    /// A tangent-space normal map (glTF's convention: +Y up in the image); usually linear. An index
    /// into `MltSceneDesc.textures` and its transform. Default `MLT_NO_TEXTURE` (-1).
    pub normal_texture: MltTextureRef,
    /// Multiplies the emission; usually 8-bit sRGB. An index into `MltSceneDesc.textures` and its
    /// transform. Default `MLT_NO_TEXTURE` (-1).
    pub emission_texture: MltTextureRef,
    /// Scales the normal map's x and y (glTF's normalTexture.scale). Any finite number. Default
    /// 1.0.
    pub normal_scale: f32,
    /// Metallic-roughness: give rough metals the light glTF's single-scattering model loses (Kulla
    /// and Conty 2017). 0 or 1. Default 0.
    pub energy_compensation: u32,
    /// Dispersion as the Abbe number V_d (0: none; KHR_materials_dispersion's dispersion is 20 /
    /// V_d); spectral renders only. An Abbe number must be positive (0: no dispersion). Default
    /// 0.0.
    pub abbe_number: f32,
    /// Metallic-roughness: red multiplies the transmission (KHR_materials_transmission's
    /// transmissionTexture); usually linear. An index into `MltSceneDesc.textures` and its
    /// transform. Default `MLT_NO_TEXTURE` (-1).
    pub transmission_texture: MltTextureRef,
    /// Metallic-roughness: a clear coat over the material, a white GGX reflection of index 1.5 with
    /// its own roughness and normal (KHR_materials_clearcoat's clearcoatFactor); 0 is none. It must
    /// be in [0, 1]. Default 0.0.
    pub clearcoat: f32,
    /// Metallic-roughness: the clear coat's perceptual roughness (GGX alpha = its square; 0 is an
    /// exact mirror). It must be in [0, 1]. Default 0.0.
    pub clearcoat_roughness: f32,
    /// Metallic-roughness: red multiplies the clear coat (KHR_materials_clearcoat's
    /// clearcoatTexture); usually linear. An index into `MltSceneDesc.textures` and its transform.
    /// Default `MLT_NO_TEXTURE` (-1).
    pub clearcoat_texture: MltTextureRef,
    /// Metallic-roughness: green multiplies the clear coat's roughness (clearcoatRoughnessTexture);
    /// usually linear. An index into `MltSceneDesc.textures` and its transform. Default
    /// `MLT_NO_TEXTURE` (-1).
    pub clearcoat_roughness_texture: MltTextureRef,
    /// Metallic-roughness: the clear coat's own tangent-space normal map (clearcoatNormalTexture);
    /// without it the coat follows the interpolated normal, not normal_texture. An index into
    /// `MltSceneDesc.textures` and its transform. Default `MLT_NO_TEXTURE` (-1).
    pub clearcoat_normal_texture: MltTextureRef,
    /// Scales the clear coat's normal map's x and y (clearcoatNormalTexture.scale). Any finite
    /// number. Default 1.0.
    pub clearcoat_normal_scale: f32,
    /// Dielectric and transmissive metallic-roughness: 0 is thin-walled, above 0 the mesh encloses
    /// an absorbing volume (KHR_materials_volume's thicknessFactor). A thickness must not be
    /// negative (0: thin-walled). Default 0.0.
    pub thickness: f32,
    /// The volume's colour after attenuation_distance of travel inside it, linear RGB
    /// (KHR_materials_volume's attenuationColor). An attenuation colour is a transmittance, in [0,
    /// 1]. Default 1.0, 1.0, 1.0.
    pub attenuation_color: [f32; 3],
    /// The distance inside the volume after which white light has the attenuation colour; the
    /// largest float (FLT_MAX) is infinity, no absorption (KHR_materials_volume's
    /// attenuationDistance). An attenuation distance must be greater than 0 (the largest float: no
    /// absorption). Default 3.4028235e38.
    pub attenuation_distance: f32,
    /// Metallic-roughness: strength of the dielectric's specular reflection, 0 a pure diffuse base
    /// (KHR_materials_specular's specularFactor). It must be in [0, 1]. Default 1.0.
    pub specular: f32,
    /// Metallic-roughness: scales the dielectric's F0 per channel, linear RGB, may exceed 1 (F0
    /// times it is clamped to 1; KHR_materials_specular's specularColorFactor). A specular colour
    /// must not be negative. Default 1.0, 1.0, 1.0.
    pub specular_color: [f32; 3],
    /// Metallic-roughness: alpha multiplies the specular strength (KHR_materials_specular's
    /// specularTexture); usually linear. An index into `MltSceneDesc.textures` and its transform.
    /// Default `MLT_NO_TEXTURE` (-1).
    pub specular_texture: MltTextureRef,
    /// Metallic-roughness: RGB multiplies the specular colour (KHR_materials_specular's
    /// specularColorTexture); usually 8-bit sRGB. An index into `MltSceneDesc.textures` and its
    /// transform. Default `MLT_NO_TEXTURE` (-1).
    pub specular_color_texture: MltTextureRef,
    /// Metallic-roughness: colour of a sheen layer over the material (velvet, cloth), linear RGB;
    /// black is none (KHR_materials_sheen's sheenColorFactor). A reflectance must be in [0, 1];
    /// above 1 would create energy. Default 0.0, 0.0, 0.0.
    pub sheen_color: [f32; 3],
    /// Metallic-roughness: the sheen's roughness (Charlie distribution, alpha = roughness squared,
    /// at least 0.07 squared; KHR_materials_sheen's sheenRoughnessFactor). It must be in [0, 1].
    /// Default 0.0.
    pub sheen_roughness: f32,
    /// Metallic-roughness: RGB multiplies the sheen colour (KHR_materials_sheen's
    /// sheenColorTexture); usually 8-bit sRGB. An index into `MltSceneDesc.textures` and its
    /// transform. Default `MLT_NO_TEXTURE` (-1).
    pub sheen_color_texture: MltTextureRef,
    /// Metallic-roughness: alpha multiplies the sheen roughness (KHR_materials_sheen's
    /// sheenRoughnessTexture); usually linear. An index into `MltSceneDesc.textures` and its
    /// transform. Default `MLT_NO_TEXTURE` (-1).
    pub sheen_roughness_texture: MltTextureRef,
    /// Metallic-roughness: anisotropy of the microfacets (brushed metal), alpha along its direction
    /// = mix(alpha, 1, strength squared); 0 is isotropic (KHR_materials_anisotropy's
    /// anisotropyStrength). It must be in [0, 1]. Default 0.0.
    pub anisotropy: f32,
    /// Metallic-roughness: the anisotropy's direction in radians, counter-clockwise from the mesh's
    /// tangent towards its bitangent (KHR_materials_anisotropy's anisotropyRotation). Any finite
    /// number. Default 0.0.
    pub anisotropy_rotation: f32,
    /// Metallic-roughness: red and green are the anisotropy's direction in the tangent plane mapped
    /// from [-1, 1] to [0, 1] (then rotated by anisotropy_rotation), blue multiplies its strength
    /// (KHR_materials_anisotropy's anisotropyTexture); linear. An index into
    /// `MltSceneDesc.textures` and its transform. Default `MLT_NO_TEXTURE` (-1).
    pub anisotropy_texture: MltTextureRef,
    /// Metallic-roughness: strength of a thin film over the material, its interference colours
    /// (soap bubbles, oil); 0 is none (KHR_materials_iridescence's iridescenceFactor). Exact per
    /// wavelength in spectral renders, integrated over each RGB channel otherwise. It must be in
    /// [0, 1]. Default 0.0.
    pub iridescence: f32,
    /// Metallic-roughness: red multiplies the thin film's strength (KHR_materials_iridescence's
    /// iridescenceTexture); usually linear. An index into `MltSceneDesc.textures` and its
    /// transform. Default `MLT_NO_TEXTURE` (-1).
    pub iridescence_texture: MltTextureRef,
    /// Metallic-roughness: the thin film's index of refraction (KHR_materials_iridescence's
    /// iridescenceIor). An index of refraction must be greater than 0. Default 1.3.
    pub iridescence_ior: f32,
    /// Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's
    /// green is 0 (KHR_materials_iridescence's iridescenceThicknessMinimum). A thickness must not
    /// be negative. Default 100.0.
    pub iridescence_thickness_minimum: f32,
    /// Metallic-roughness: the thin film's thickness in nanometres where the thickness texture's
    /// green is 1, and everywhere without it; 0 is no film (KHR_materials_iridescence's
    /// iridescenceThicknessMaximum). A thickness must not be negative. Default 400.0.
    pub iridescence_thickness_maximum: f32,
    /// Metallic-roughness: green interpolates the thin film's thickness from the minimum (0) to the
    /// maximum (1) (KHR_materials_iridescence's iridescenceThicknessTexture); usually linear. An
    /// index into `MltSceneDesc.textures` and its transform. Default `MLT_NO_TEXTURE` (-1).
    pub iridescence_thickness_texture: MltTextureRef,
    /// The texture slots that read texture coordinate set 1 (`MltSceneDesc.texcoords1`, glTF's
    /// texCoord 1) instead of set 0: bit i is the i-th texture slot in field order,
    /// `MLT_TEXCOORD1_<SLOT>` (`MLT_TEXCOORD1_BASE_COLOR` is bit 0). A bit past the last slot is
    /// refused; a bit of a slot without a texture is ignored. Default 0: every slot reads set 0.
    pub texcoord1_slots: u32,
    // END GENERATED material
}

/// A texture the materials refer to by index (`MltSceneDesc.textures`). Initialize with
/// `mlt_texture_default` (8-bit sRGB, repeat, bilinear, no texels), then set `width`,
/// `height`, `channels` and `texels`.
///
/// Coordinates follow glTF: uv (0, 0) is the top-left corner of the image (the first texel
/// of the first row), u grows to the right and v downwards; texel (column i, row j) covers
/// [i/w, (i+1)/w] × [j/h, (j+1)/h]. One channel is grey (read as RGB = g, A = 1), two grey
/// and alpha, three RGB (A = 1), four RGBA.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltTexture {
    /// sizeof(MltTexture) of the header the host was built with: set by `mlt_texture_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    /// Texels per row and rows, each in [1, `MLT_MAX_TEXTURE_SIDE`], at most
    /// `MLT_MAX_TEXTURE_TEXELS` together.
    pub width: u32,
    pub height: u32,
    /// Values per texel: 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA). Default 4.
    pub channels: u32,
    /// One of `MLT_TEXEL_*`: what `texels` points to. Default `MLT_TEXEL_U8`.
    pub texel_type: i32,
    /// width × height × channels values of `texel_type` (`uint8_t` or `float`, aligned
    /// for it), rows from the top of the image down, channels interleaved. Copied by
    /// `mlt_scene_create`; the host may free them once it returns.
    pub texels: *const c_void,
    /// One of `MLT_TEXTURE_*`: how 8-bit colour channels encode linear values.
    /// `MLT_TEXTURE_SRGB` (the default) only with `MLT_TEXEL_U8`; `MLT_TEXEL_F32` texels
    /// must be `MLT_TEXTURE_LINEAR`.
    pub encoding: i32,
    /// One of `MLT_WRAP_*`: what a coordinate outside [0, 1] reads, along u (glTF
    /// `wrapS`) and along v (`wrapT`). Default `MLT_WRAP_REPEAT`.
    pub wrap_u: i32,
    pub wrap_v: i32,
    /// One of `MLT_FILTER_*`: how a point between texel centres is read. Default
    /// `MLT_FILTER_BILINEAR`.
    pub filter: i32,
}

/// An environment: radiance arriving from infinitely far away, seen by every ray that
/// leaves the scene and sampled as a light by every algorithm. Initialize with
/// `mlt_environment_default`; for a constant colour, `mlt_environment_constant`.
///
/// The map is equirectangular (latitude-longitude) with +Y up: column u in [0, 1) (left to
/// right) is the azimuth phi = 2 pi u, row v in [0, 1) (top to bottom) the polar angle
/// theta = pi v from +Y, and the direction is (sin phi sin theta, cos theta, -cos phi sin
/// theta): the map's centre looks along +Z, its left and right edges along -Z (Mitsuba 3's
/// convention).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltEnvironment {
    /// sizeof(MltEnvironment) of the header the host was built with: set by `mlt_environment_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    /// Linear RGB radiance, 3 floats per texel, rows from the top: width × height × 3
    /// floats, each finite and >= 0. Copied by `mlt_scene_create`.
    pub pixels: *const f32,
    /// Texels per row and rows, each in [1, `MLT_MAX_ENVIRONMENT_SIDE`], at most
    /// `MLT_MAX_ENVIRONMENT_TEXELS` together. A 1 × 1 map is a constant environment.
    pub width: u32,
    pub height: u32,
    /// Turns the environment about +Y by this many degrees (counter-clockwise seen from
    /// above); finite.
    pub rotation_degrees: f32,
    /// Multiplies every texel; finite and >= 0. Default 1.
    pub scale: f32,
}

/// The sun: a distant disc of uniform radiance (or a delta direction, with an angular
/// radius of 0). Initialize with `mlt_sun_default`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltSun {
    /// sizeof(MltSun) of the header the host was built with: set by `mlt_sun_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    /// From the scene towards the sun; any finite length but zero. Default +Y (noon).
    pub direction: [f32; 3],
    /// Half the angle the disc subtends, in degrees, in [0, 45]: 0 is a delta direction
    /// (hard shadows); the real sun is about 0.27 (the default).
    pub angular_radius_degrees: f32,
    /// Linear RGB irradiance on a plane facing the sun, each finite and >= 0 (the disc's
    /// radiance is this over pi sin^2 of the angular radius). Default 1.
    pub irradiance: [f32; 3],
}

/// A point, spot or directional light (glTF's `KHR_lights_punctual`): a delta light, hit by
/// no ray, reached by connections only. Initialize with `mlt_punctual_light_default` (a
/// white point light at the origin).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltPunctualLight {
    /// sizeof(MltPunctualLight) of the header the host was built with: set by `mlt_punctual_light_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    /// One of `MLT_LIGHT_*`.
    pub kind: i32,
    /// Point and spot lights: where the light is; finite (ignored for directional lights).
    pub position: [f32; 3],
    /// Spot: the cone's axis; directional: the direction the light travels. Any finite
    /// length but zero (ignored for point lights).
    pub direction: [f32; 3],
    /// Linear RGB, each finite and >= 0: radiant intensity (W/sr) of a point light and of a
    /// spot on its axis, irradiance (W/m^2) on a plane facing a directional light.
    pub intensity: [f32; 3],
    /// Spot: full intensity within this angle from the axis, in degrees (default 0).
    pub inner_cone_degrees: f32,
    /// Spot: no light beyond this angle from the axis, in degrees; 0 <= inner < outer <= 90
    /// (default 45).
    pub outer_cone_degrees: f32,
}

/// Everything `mlt_scene_create` needs, as plain arrays the host keeps ownership of (they are
/// copied; the host may free them once the call returns). Initialize with
/// `mlt_scene_desc_default`.
///
/// Degenerate triangles (zero area, e.g. repeated or collinear vertices) are accepted: they
/// keep their id but are never hit and never emit. `mlt_scene_get_info` counts them.
///
/// Light comes from emissive triangles and from an environment, a sun and punctual lights
/// (the fields after `backend`; a host built against a header from before them, whose
/// struct ends at `backend`, gets none of those).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltSceneDesc {
    /// sizeof(MltSceneDesc) of the header the host was built with: set by `mlt_scene_desc_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    /// Vertex positions, x y z per vertex; all finite.
    pub positions: *const f32,
    /// Number of floats in `positions` (3 per vertex).
    pub positions_len: usize,
    /// Vertex indices, 3 per triangle, each < vertex count. Counter-clockwise is the front.
    pub indices: *const u32,
    /// Number of entries in `indices` (3 per triangle).
    pub indices_len: usize,
    /// One material index per triangle, each < `materials_len`. May be NULL (with length 0):
    /// every triangle then uses material 0.
    pub material_ids: *const u32,
    /// Number of entries in `material_ids`: 0 or the triangle count.
    pub material_ids_len: usize,
    pub materials: *const MltMaterial,
    pub materials_len: usize,
    /// One of `MLT_BACKEND_*`.
    pub backend: i32,
    /// An environment lighting the scene from infinitely far away, or NULL (the default)
    /// for none (black).
    pub environment: *const MltEnvironment,
    /// The sun, or NULL (the default) for none.
    pub sun: *const MltSun,
    /// Point, spot and directional lights, each initialized by `mlt_punctual_light_default`;
    /// may be NULL with a length of 0 (the default).
    pub punctual_lights: *const MltPunctualLight,
    /// Number of entries in `punctual_lights`, at most `MLT_MAX_PUNCTUAL_LIGHTS`.
    pub punctual_lights_len: usize,
    // A header before the surface attributes below ends the struct here: such a host's
    // scenes have flat triangles and no textures.
    /// Per-vertex shading normals, x y z per vertex, or NULL with a length of 0 (the default)
    /// for flat triangles. Each finite, of any nonzero length (normalized on use);
    /// interpolated across each triangle. A normal on the back side of its triangle is
    /// turned to the front.
    pub normals: *const f32,
    /// Number of floats in `normals`: 0 or 3 × the vertex count.
    pub normals_len: usize,
    /// Per-vertex texture coordinates, u v per vertex, or NULL with 0. Each finite. glTF's
    /// convention: (0, 0) is the top-left corner of a texture, u grows to the right and v
    /// downwards (a texture repeats outside [0, 1] unless its wrap modes say otherwise).
    /// Needed by every textured material.
    pub texcoords: *const f32,
    /// Number of floats in `texcoords`: 0 or 2 × the vertex count.
    pub texcoords_len: usize,
    /// Per-vertex tangents for normal maps, x y z w per vertex, or NULL with 0: then mlt
    /// computes them with MikkTSpace (as glTF asks) where a material has a normal map.
    /// x y z (finite, nonzero) point along +u on the surface; w = +1 or -1 is the
    /// bitangent's sign: bitangent = w × cross(normal, tangent) (glTF's convention), which
    /// must point up the image (towards decreasing v), where a normal map's +Y points.
    pub tangents: *const f32,
    /// Number of floats in `tangents`: 0 or 4 × the vertex count.
    pub tangents_len: usize,
    /// Per-vertex linear RGBA colours, each in [0, 1], multiplying the material's `color`
    /// and `alpha` (glTF `COLOR_0`), or NULL with 0.
    pub colors: *const f32,
    /// Number of floats in `colors`: 0 or 4 × the vertex count.
    pub colors_len: usize,
    /// The textures the materials' `MltTextureRef`s index, each initialized by
    /// `mlt_texture_default`; may be NULL with a length of 0 (the default).
    pub textures: *const MltTexture,
    /// Number of entries in `textures`.
    pub textures_len: usize,
    // A header before the build quality ends the struct here: such a host's scenes are
    // built at the default quality.
    /// One of `MLT_BUILD_QUALITY_*` (the default, 0, is `MLT_BUILD_QUALITY_HIGH`): how much
    /// work the acceleration structure's build spends for faster rays.
    pub build_quality: i32,
    // A header before the texture coordinate set 1 ends the struct here: such a host's
    // textures read set 0.
    /// Per-vertex texture coordinate set 1 (glTF's `TEXCOORD_1`), u v per vertex as
    /// `texcoords`, or NULL with 0 (the default). Read by the texture slots whose bit of
    /// `MltMaterial.texcoord1_slots` is set, which need it.
    pub texcoords1: *const f32,
    /// Number of floats in `texcoords1`: 0 or 2 × the vertex count.
    pub texcoords1_len: usize,
}

/// A perspective camera. Image right is normalize(cross(target - eye, up)). Initialize with
/// `mlt_camera_default` (the Cornell box's camera).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltCamera {
    /// sizeof(MltCamera) of the header the host was built with: set by `mlt_camera_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    pub eye: [f32; 3],
    /// Must differ from `eye`.
    pub target: [f32; 3],
    /// Must not be parallel to target - eye.
    pub up: [f32; 3],
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Thin-lens aperture radius; 0 for a pinhole.
    pub lens_radius: f32,
    /// Distance of the plane in focus; 0 means |target - eye|.
    pub focus_distance: f32,
}

/// How to render. Initialize with `mlt_render_settings_default`. Each field is a setting
/// declared in mlt's `src/render/settings.rs`; `docs/settings.md` lists them with their
/// defaults, valid values and command-line flags. Booleans are 0 or 1.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltRenderSettings {
    /// sizeof(MltRenderSettings) of the header the host was built with: set by `mlt_render_settings_default`, do not change
    /// it. An older header's smaller struct is read as far as it goes (the rest defaults).
    pub struct_size: u32,
    // BEGIN GENERATED render settings: tests/parameters.rs writes these lines from src/render/settings.rs
    /// Image width in pixels. It must be between 1 and 65536. Default 256.
    pub width: u32,
    /// Image height in pixels. It must be between 1 and 65536. Default 256.
    pub height: u32,
    /// The light-transport algorithm. One of `MLT_ALGORITHM_*`. Default `MLT_ALGORITHM_MMLT`.
    pub algorithm: i32,
    /// Path tracing, BDPT and ERPT: samples per pixel (0: until the time limit). At most 16777216
    /// are supported. Default 64.
    pub samples_per_pixel: u32,
    /// Most scattering vertices between camera and light (0: emitters seen directly). At most 1024
    /// is supported. Default 5.
    pub max_depth: u32,
    /// Worker threads (0: a pool of one per core shared by such renders); the image does not depend
    /// on it. Use 0 for all cores or at most 4096. Default 0.
    pub threads: u32,
    /// Seed of every random number: equal seeds and settings give equal images. Any value of its
    /// type. Default 0.
    pub seed: u64,
    /// Stop after this many seconds (0: no limit). It must be 0 (no limit) or a positive number of
    /// seconds up to 10000000. Default 0.0.
    pub time_limit_seconds: f64,
    /// Metropolis: mutations per pixel (0: until the time limit). At most 16777216 are supported.
    /// Default 32.
    pub mutations_per_pixel: u32,
    /// Metropolis: samples seeding the chains and the brightness estimate (0: one per 8 planned
    /// mutations, at least 65536; 262144 for a render planned by time alone). It must be 0
    /// (automatic) or at most 268435456. Default 0.
    pub bootstrap_samples: u32,
    /// Metropolis: number of Markov chains, at most the bootstrap samples. It must be between 1 and
    /// the bootstrap samples (262144). Default 1024.
    pub chains: u32,
    /// PSSMLT: probability of a large (independent) step. It must be in [0, 1]. Default 0.3.
    pub large_step_probability: f32,
    /// PSSMLT: standard deviation of a small step in primary sample space. It must be in (0, 1].
    /// Default 0.01.
    pub small_step_sigma: f32,
    /// Metropolis: path-traced samples of depths 0 and 1 per chain mutation (0: the chains render
    /// every depth). Any value of its type. Default 1.
    pub direct_samples_per_mutation: u32,
    /// Path-space MLT: relative probabilities of the bidirectional mutation and the lens, caustic
    /// and multi-chain perturbations (the first positive). Weights must be finite, from 0 to 1e6.
    /// Default 0.5, 0.25, 0.25, 0.25.
    pub mutation_weights: [f32; 4],
    /// ERPT: perturbations per chain. It must be between 1 and 1048576. Default 10.
    pub erpt_chain_length: u32,
    /// ERPT: energy (luminance) each chain step deposits (0: one chain per camera sample on
    /// average). It must be 0 (automatic) or a positive number up to 1e30. Default 0.0.
    pub erpt_deposit_energy: f32,
    /// Path-space MLT: after a warm-up, weight each mutation by its acceptance rate there. 0 or 1.
    /// Default 0.
    pub adapt_mutation_weights: u32,
    /// Path-space MLT and ERPT: perturb directions in the BSDF's sample space instead of within a
    /// cone. 0 or 1. Default 0.
    pub perturb_in_sample_space: u32,
    /// Metropolis and ERPT: partial images of the post-process noise filter (0: no filter; 8 is a
    /// good start). It must be 0 (no filter) or from 2 to 32. Default 0.
    pub filter_buffers: u32,
    /// The filter's strength (higher smooths more). It must be positive, up to 100. Default 0.45.
    pub filter_strength: f32,
    /// The filter's search radius in pixels. It must be from 1 to 32 pixels. Default 7.
    pub filter_radius: u32,
    /// Metropolis: share of the rays spent on samples that go on estimating the brightness (0: the
    /// bootstrap and large steps alone). It must be from 0 to 0.9. Default 0.05.
    pub normalization_work_fraction: f32,
    /// Spectral transport: four wavelengths per path instead of RGB; dispersive glass splits light.
    /// 0 or 1. Default 0.
    pub spectral: u32,
    /// Path tracing and PSSMLT: scattering vertices after which Russian roulette may end a path. It
    /// must be at most 1024. Default 3.
    pub roulette_start_depth: u32,
    /// Path tracing and PSSMLT: the highest probability with which Russian roulette lets a path go
    /// on. It must be in (0, 1]. Default 0.95.
    pub roulette_max_survival: f32,
    /// Path tracing: read textures at full resolution, as the other algorithms do (by default
    /// camera paths filter them over the pixel's footprint, mip-mapped, until their first diffuse
    /// or glossy bounce). 0 or 1. Default 0.
    pub full_resolution_textures: u32,
    // END GENERATED render settings
    /// Unused (0): keeps this layout's size apart from the one before
    /// `full_resolution_textures`, which fills that one's tail padding.
    pub _reserved: u32,
}

/// What a render did (filled by `mlt_render_ex`). Initialize with `mlt_render_stats_default`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct MltRenderStats {
    /// sizeof(MltRenderStats) of the header the host was built with: set by `mlt_render_stats_default` before the
    /// call. An older header's smaller struct receives the fields it has.
    pub struct_size: u32,
    /// Camera samples taken over the whole image (path tracing, BDPT, the direct pass of a
    /// Metropolis render).
    pub samples: u64,
    /// Rays traced, closest-hit and shadow.
    pub rays: u64,
    /// Samples with a non-finite value, dropped (they count as black samples).
    pub invalid_samples: u64,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// Worker threads used.
    pub threads: u32,
    /// Metropolis: accepted mutations, of `mutations`.
    pub accepted_mutations: u64,
    /// Metropolis: the normalization b (mean luminance of the path contribution) the image
    /// was scaled by, its final estimate. `MLT_ALGORITHM_ERPT`: the deposit energy used.
    pub normalization: f64,
    /// Metropolis: mutations made by all chains.
    pub mutations: u64,
    /// `MLT_ALGORITHM_PATH_SPACE_MLT`: proposals of each mutation, indexed by
    /// `MLT_MUTATION_*`.
    pub mutations_proposed: [u64; 4],
    /// `MLT_ALGORITHM_PATH_SPACE_MLT`: accepted proposals of each mutation.
    pub mutations_accepted: [u64; 4],
    /// `MLT_ALGORITHM_PATH_SPACE_MLT`: the mutation weights the chains ran with (after the
    /// warm-up, with `adapt_mutation_weights`). `MLT_ALGORITHM_ERPT`: its weights.
    pub mutation_weights: [f32; 4],
    /// With `filter_buffers`: the luminance the filter moved, Σ|change| / Σ luminance (the
    /// total is kept) …
    pub filter_changed_fraction: f64,
    /// … and about how many pixels each pixel was averaged over (the mean sum of weights).
    pub filter_mean_neighbours: f64,
    /// Metropolis: independent samples the normalization was estimated from …
    pub normalization_samples: u64,
    /// … the estimated standard error of `normalization` over it (from the samples'
    /// variance: the brightness uncertainty of the image) …
    pub normalization_relative_error: f64,
    /// … and the largest share of it a single sample carried (near 1 / samples when no rare
    /// bright path dominates).
    pub normalization_largest_share: f64,
}

/// Facts about a created scene (filled by `mlt_scene_get_info`). Initialize with
/// `mlt_scene_info_default`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct MltSceneInfo {
    /// sizeof(MltSceneInfo) of the header the host was built with: set by `mlt_scene_info_default` before the
    /// call. An older header's smaller struct receives the fields it has.
    pub struct_size: u32,
    pub triangle_count: u64,
    /// Triangles with zero area: never hit, never emit.
    pub degenerate_triangle_count: u64,
    /// Emissive triangles (area lights).
    pub emitter_count: u64,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    /// The `MLT_BACKEND_*` the scene was built with.
    pub backend: i32,
    /// The `MLT_BUILD_QUALITY_*` it was built at …
    pub build_quality: i32,
    /// … the bytes its acceleration structure holds (for Embree, what Embree allocated plus
    /// mlt's own arrays) …
    pub accel_memory_bytes: u64,
    /// … and the seconds the acceleration structure's build took.
    pub accel_build_seconds: f64,
}

/// A ray for the batch queries: points origin + t·direction with t in [tmin, tmax] (with
/// `MLT_BACKEND_EMBREE`: (tmin, tmax], which differs only for a hit at exactly t = tmin).
/// `direction` need not be unit length; t is measured in multiples of it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltRay {
    pub origin: [f32; 3],
    /// Finite, >= 0.
    pub tmin: f32,
    /// Finite and non-zero.
    pub direction: [f32; 3],
    /// >= tmin; may be INFINITY.
    pub tmax: f32,
}

/// A closest hit. The hit point is (1-u-v)·v0 + u·v1 + v·v2 of the triangle's vertices in
/// the order the host gave them.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltHit {
    /// The host's triangle index, or `MLT_INVALID_ID` for a miss (then t = INFINITY).
    pub triangle_id: u32,
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// Bytes mlt made for the host: a render plan (`mlt_render_plan`) or a job's partial result
/// (`mlt_render_job`), to keep, send to another machine and pass back to mlt as a pointer
/// and a size. The host owns them until `mlt_bytes_release` frees them. The bytes carry a
/// format version, mlt's version and a checksum: a buffer that is corrupted, cut short, from
/// another plan or from another version of mlt is refused with `MLT_STATUS_INVALID_ARGUMENT`.
///
/// A fixed pair (it has no `struct_size` and will not grow). The calls that fill one write
/// it without reading it: release the buffer it held first, or it leaks.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltBytes {
    /// The bytes; NULL when `size` is 0 (released).
    pub data: *mut u8,
    pub size: usize,
}

/// An immutable scene: triangles, materials, lights and the acceleration structure. Thread
/// safe: any number of threads may render and query one scene at the same time.
/// Reference-counted: `mlt_scene_retain` adds a reference, `mlt_scene_release` drops one,
/// and each running render or query holds one of its own, so releasing a scene while
/// other threads use it is safe. Calls given a pointer that is not a live scene fail with
/// `MLT_STATUS_INVALID_ARGUMENT` (it is never dereferenced).
pub struct MltScene {
    pub(super) scene: Scene,
    pub(super) backend: i32,
}

/// Progress callback: called on the thread that called `mlt_render` (never from a worker),
/// about 20 times a second and once with 1.0 at the end, with the fraction done in [0, 1].
/// Return `true` to continue and `false` to cancel. It must return normally: a C++
/// exception thrown through it, or a `longjmp` out of it, skips mlt's cleanup (worker
/// threads keep running on freed memory) and is undefined behavior; catch inside the
/// callback and return `false` instead.
pub type MltProgressCallback =
    Option<unsafe extern "C" fn(fraction: f32, user_data: *mut c_void) -> bool>;
