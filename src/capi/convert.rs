//! Conversions between the C values a host passes and the kernel's Rust values, each
//! range-checked with a message naming the field.

use super::types::*;
use crate::accel::{Backend, BuildQuality};
use crate::error::*;
use crate::integrators::mlt::driver::MutationWeights;
use crate::params::ChoiceParameter;
use crate::render::{RenderSettings, RenderStats};
use crate::scene::{Camera, Material, PunctualLight, PunctualLightKind, SunDesc, TextureRef};
use crate::texture::{TextureEncoding, TextureFilter, WrapMode};
use glam::Vec3A;

/// The host's material `index`; its values are validated with the scene (`Material::validate`),
/// its choices, texture indices below -1 and `texcoord1_slots` here.
pub(super) fn material(m: &MltMaterial, index: usize) -> Result<Material> {
    let name = |field: &str| format!("desc.materials[{index}].{field}");
    macro_rules! from_c {
        ($($field:ident,)*) => {
            // The defaults fill in a parameter declared since the list was generated, so
            // that the crate builds to run the generator (`tests/parameters.rs`).
            {
                #[allow(clippy::needless_update)]
                let material = Material {
                    $($field: CField::from_c(m.$field, &name(stringify!($field)))?,)*
                    ..Material::default()
                };
                material
            }
        };
    }
    let mut material = from_c! {
        // BEGIN GENERATED material from C: tests/parameters.rs writes these lines from src/scene/material.rs
        kind,
        color,
        emission,
        ior,
        metallic,
        roughness,
        transmission,
        alpha,
        alpha_mode,
        alpha_cutoff,
        base_color_texture,
        metallic_roughness_texture,
        normal_texture,
        emission_texture,
        normal_scale,
        energy_compensation,
        abbe_number,
        transmission_texture,
        clearcoat,
        clearcoat_roughness,
        clearcoat_texture,
        clearcoat_roughness_texture,
        clearcoat_normal_texture,
        clearcoat_normal_scale,
        thickness,
        attenuation_color,
        attenuation_distance,
        specular,
        specular_color,
        specular_texture,
        specular_color_texture,
        sheen_color,
        sheen_roughness,
        sheen_color_texture,
        sheen_roughness_texture,
        anisotropy,
        anisotropy_rotation,
        anisotropy_texture,
        iridescence,
        iridescence_texture,
        iridescence_ior,
        iridescence_thickness_minimum,
        iridescence_thickness_maximum,
        iridescence_thickness_texture,
        // END GENERATED material from C
    };
    set_texcoord1_slots(&mut material, m.texcoord1_slots, &name("texcoord1_slots"))?;
    Ok(material)
}

/// Gives the texture slots whose bits of `bits` are set (bit i: the i-th slot in declaration
/// order, `MLT_TEXCOORD1_*`) texture coordinate set 1; a bit past the last slot is refused.
fn set_texcoord1_slots(material: &mut Material, bits: u32, name: &str) -> Result<()> {
    let mut slots = 0;
    for (i, (_, slot)) in material.texture_slots_mut().enumerate() {
        if bits.checked_shr(i as u32).unwrap_or(0) & 1 == 1
            && let Some(texture) = slot
        {
            texture.texcoord = 1;
        }
        slots = i as u32 + 1;
    }
    let beyond = bits.checked_shr(slots).unwrap_or(0);
    if beyond != 0 {
        let names: Vec<&str> = Material::default()
            .texture_slots()
            .map(|(slot, _)| slot)
            .collect();
        return Err(Error::invalid(format!(
            "{name} is {bits:#x}; bit {} names no texture slot: bits 0 ({}) to {} ({}) are the {slots} slots",
            slots + beyond.trailing_zeros(),
            names[0],
            slots - 1,
            names[names.len() - 1],
        )));
    }
    Ok(())
}

/// The C material's `texcoord1_slots` of `material`: a bit for each slot whose texture reads
/// texture coordinate set 1.
pub(super) fn texcoord1_slots(material: &Material) -> u32 {
    material
        .texture_slots()
        .enumerate()
        .filter(|(_, (_, slot))| slot.is_some_and(|t| t.texcoord == 1))
        .fold(0, |bits, (i, _)| bits | 1 << i)
}

/// The enums of the host's texture `index`, and the pairing of sRGB with 8-bit texels,
/// checked before its texels are read.
pub(super) fn texture_modes(
    t: &MltTexture,
    index: usize,
) -> Result<(TextureEncoding, WrapMode, WrapMode, TextureFilter)> {
    let name = format!("desc.textures[{index}]");
    if !matches!(t.texel_type, MLT_TEXEL_U8 | MLT_TEXEL_F32) {
        return Err(Error::invalid(format!(
            "{name}.texel_type is {}; use MLT_TEXEL_U8 (0) or MLT_TEXEL_F32 (1)",
            t.texel_type
        )));
    }
    let encoding = match t.encoding {
        MLT_TEXTURE_SRGB if t.texel_type == MLT_TEXEL_F32 => {
            return Err(Error::invalid(format!(
                "{name}.encoding is MLT_TEXTURE_SRGB (0) but texel_type is MLT_TEXEL_F32; sRGB applies to 8-bit texels only (float texels are linear: use MLT_TEXTURE_LINEAR)"
            )));
        }
        MLT_TEXTURE_SRGB => TextureEncoding::Srgb,
        MLT_TEXTURE_LINEAR => TextureEncoding::Linear,
        other => {
            return Err(Error::invalid(format!(
                "{name}.encoding is {other}; use MLT_TEXTURE_SRGB (0) or MLT_TEXTURE_LINEAR (1)"
            )));
        }
    };
    let wrap = |value: i32, field: &str| match value {
        MLT_WRAP_REPEAT => Ok(WrapMode::Repeat),
        MLT_WRAP_CLAMP_TO_EDGE => Ok(WrapMode::ClampToEdge),
        MLT_WRAP_MIRRORED_REPEAT => Ok(WrapMode::MirroredRepeat),
        other => Err(Error::invalid(format!(
            "{name}.{field} is {other}; use MLT_WRAP_REPEAT (0), MLT_WRAP_CLAMP_TO_EDGE (1) or MLT_WRAP_MIRRORED_REPEAT (2)"
        ))),
    };
    let filter = match t.filter {
        MLT_FILTER_NEAREST => TextureFilter::Nearest,
        MLT_FILTER_BILINEAR => TextureFilter::Bilinear,
        other => {
            return Err(Error::invalid(format!(
                "{name}.filter is {other}; use MLT_FILTER_NEAREST (0) or MLT_FILTER_BILINEAR (1)"
            )));
        }
    };
    Ok((
        encoding,
        wrap(t.wrap_u, "wrap_u")?,
        wrap(t.wrap_v, "wrap_v")?,
        filter,
    ))
}

/// Float texels must be finite and >= 0; named by the C field (`texels`), with the texel's
/// row, column and channel.
pub(super) fn check_float_texels(values: &[f32], t: &MltTexture, index: usize) -> Result<()> {
    if let Some(i) = values.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
        let channels = t.channels as usize;
        let texel = i / channels;
        return Err(Error::invalid(format!(
            "desc.textures[{index}].texels[{i}] (row {}, column {}, channel {}) is {}; float texels must be finite and >= 0",
            texel / t.width as usize,
            texel % t.width as usize,
            i % channels,
            values[i]
        )));
    }
    Ok(())
}

pub(super) fn punctual_light(light: &MltPunctualLight, index: usize) -> Result<PunctualLight> {
    let kind = match light.kind {
        MLT_LIGHT_POINT => PunctualLightKind::Point,
        MLT_LIGHT_SPOT => PunctualLightKind::Spot,
        MLT_LIGHT_DIRECTIONAL => PunctualLightKind::Directional,
        other => {
            return Err(Error::invalid(format!(
                "desc.punctual_lights[{index}].kind is {other}; use MLT_LIGHT_POINT (0), MLT_LIGHT_SPOT (1) or MLT_LIGHT_DIRECTIONAL (2)"
            )));
        }
    };
    Ok(PunctualLight {
        kind,
        position: light.position,
        direction: light.direction,
        intensity: light.intensity,
        inner_cone_degrees: light.inner_cone_degrees,
        outer_cone_degrees: light.outer_cone_degrees,
    })
}

impl From<&MltSun> for SunDesc {
    fn from(s: &MltSun) -> Self {
        SunDesc {
            direction: s.direction,
            angular_radius_degrees: s.angular_radius_degrees,
            irradiance: s.irradiance,
        }
    }
}

pub(super) fn backend(value: i32) -> Result<Backend> {
    match value {
        MLT_BACKEND_BVH => Ok(Backend::Bvh),
        MLT_BACKEND_EMBREE => Ok(Backend::Embree),
        other => Err(Error::invalid(format!(
            "desc.backend is {other}; use MLT_BACKEND_BVH (0) or MLT_BACKEND_EMBREE (1)"
        ))),
    }
}

pub(super) fn build_quality(value: i32) -> Result<BuildQuality> {
    match value {
        MLT_BUILD_QUALITY_HIGH => Ok(BuildQuality::High),
        MLT_BUILD_QUALITY_MEDIUM => Ok(BuildQuality::Medium),
        MLT_BUILD_QUALITY_FAST => Ok(BuildQuality::Fast),
        other => Err(Error::invalid(format!(
            "desc.build_quality is {other}; use MLT_BUILD_QUALITY_HIGH (0), MLT_BUILD_QUALITY_MEDIUM (1) or MLT_BUILD_QUALITY_FAST (2)"
        ))),
    }
}

/// The `MLT_BUILD_QUALITY_*` of `quality`.
pub(super) fn build_quality_code(quality: BuildQuality) -> i32 {
    match quality {
        BuildQuality::High => MLT_BUILD_QUALITY_HIGH,
        BuildQuality::Medium => MLT_BUILD_QUALITY_MEDIUM,
        BuildQuality::Fast => MLT_BUILD_QUALITY_FAST,
    }
}

impl From<&MltCamera> for Camera {
    fn from(c: &MltCamera) -> Self {
        Camera {
            eye: c.eye,
            target: c.target,
            up: c.up,
            fov_y_deg: c.fov_y_deg,
            lens_radius: c.lens_radius,
            focus_distance: c.focus_distance,
        }
    }
}

/// The host's settings as Rust's; every field a setting (see `CField`).
pub(super) fn render_settings(s: &MltRenderSettings) -> Result<RenderSettings> {
    macro_rules! from_c {
        ($($name:ident,)*) => {
            // The defaults fill in a setting declared since the list was generated, so that
            // the crate builds to run the generator (`tests/parameters.rs`).
            #[allow(clippy::needless_update)]
            Ok(RenderSettings {
                $($name: CField::from_c(s.$name, concat!("settings.", stringify!($name)))?,)*
                ..RenderSettings::default()
            })
        };
    }
    from_c! {
        // BEGIN GENERATED settings from C: tests/parameters.rs writes these lines from src/render/settings.rs
        width,
        height,
        algorithm,
        samples_per_pixel,
        max_depth,
        threads,
        seed,
        time_limit_seconds,
        mutations_per_pixel,
        bootstrap_samples,
        chains,
        large_step_probability,
        small_step_sigma,
        direct_samples_per_mutation,
        mutation_weights,
        erpt_chain_length,
        erpt_deposit_energy,
        adapt_mutation_weights,
        perturb_in_sample_space,
        filter_buffers,
        filter_strength,
        filter_radius,
        normalization_work_fraction,
        spectral,
        roulette_start_depth,
        roulette_max_survival,
        full_resolution_textures,
        // END GENERATED settings from C
    }
}

/// A setting's type in the C struct, and the conversions between the two (a C value Rust's
/// type does not hold is refused with a message naming the field).
pub(super) trait CField: Sized {
    type C: Copy;
    fn to_c(self) -> Self::C;
    fn from_c(value: Self::C, name: &str) -> Result<Self>;
}

macro_rules! same_in_c {
    ($($ty:ty),*) => {$(
        impl CField for $ty {
            type C = $ty;
            fn to_c(self) -> $ty {
                self
            }
            fn from_c(value: $ty, _: &str) -> Result<$ty> {
                Ok(value)
            }
        }
    )*};
}
same_in_c!(u32, u64, f32, f64, [f32; 3]);

impl CField for bool {
    type C = u32;
    fn to_c(self) -> u32 {
        self as u32
    }
    fn from_c(value: u32, name: &str) -> Result<bool> {
        flag(value, name)
    }
}

impl CField for MutationWeights {
    type C = [f32; 4];
    fn to_c(self) -> [f32; 4] {
        self.0
    }
    fn from_c(value: [f32; 4], _: &str) -> Result<Self> {
        Ok(MutationWeights(value))
    }
}

/// A choice is its index in C: the constants `MLT_<PREFIX>_<NAME>` are 0, 1, … in the
/// declared order (`c_examples/parameters.cpp` checks the header's against it).
impl<T: ChoiceParameter> CField for T {
    type C = i32;
    fn to_c(self) -> i32 {
        T::ALL
            .iter()
            .position(|&v| v == self)
            .expect("ALL holds every value") as i32
    }
    fn from_c(value: i32, name: &str) -> Result<T> {
        usize::try_from(value)
            .ok()
            .and_then(|i| T::ALL.get(i))
            .copied()
            .ok_or_else(|| {
                let constants: Vec<String> = T::NAMES
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{} ({i})", T::CHOICES.c_constant(n)))
                    .collect();
                let (last, rest) = constants.split_last().expect("a choice has names");
                Error::invalid(format!(
                    "{name} is {value}; use {} or {last}",
                    rest.join(", ")
                ))
            })
    }
}

/// A material's texture slot: `MLT_NO_TEXTURE` is none; an index at or past the texture
/// count is refused by the scene's validation (`TextureRef::validate`), one below -1 here.
impl CField for Option<TextureRef> {
    type C = MltTextureRef;
    fn to_c(self) -> MltTextureRef {
        match self {
            None => NO_TEXTURE,
            Some(r) => MltTextureRef {
                texture: r.texture as i32,
                offset: r.offset,
                rotation: r.rotation,
                scale: r.scale,
            },
        }
    }
    fn from_c(r: MltTextureRef, name: &str) -> Result<Self> {
        match r.texture {
            MLT_NO_TEXTURE => Ok(None),
            index if index < 0 => Err(Error::invalid(format!(
                "{name}.texture is {index}; use an index into desc.textures, or MLT_NO_TEXTURE (-1) for none"
            ))),
            // The set is `MltMaterial.texcoord1_slots`' (`MltTextureRef` cannot grow without
            // moving the material's later fields): `material` sets it.
            index => Ok(Some(TextureRef {
                texture: index as u32,
                texcoord: 0,
                offset: r.offset,
                rotation: r.rotation,
                scale: r.scale,
            })),
        }
    }
}

/// A material's texture slot without a texture: index -1, the identity transform.
pub(super) const NO_TEXTURE: MltTextureRef = MltTextureRef {
    texture: MLT_NO_TEXTURE,
    offset: [0.0; 2],
    rotation: 0.0,
    scale: [1.0; 2],
};

/// What a render, a job or a merge did, as the host receives it (`struct_size` 0: the
/// host's stays, `write_host` skips it).
pub(super) fn stats_to_c(stats: &RenderStats) -> MltRenderStats {
    MltRenderStats {
        struct_size: 0,
        samples: stats.samples,
        rays: stats.rays,
        invalid_samples: stats.invalid_samples,
        seconds: stats.seconds,
        threads: stats.threads,
        accepted_mutations: stats.accepted_mutations,
        normalization: stats.normalization.value,
        mutations: stats.mutations,
        mutations_proposed: stats.mutation_counts.proposed,
        mutations_accepted: stats.mutation_counts.accepted,
        mutation_weights: stats.mutation_weights.0,
        filter_changed_fraction: stats.filter.changed_fraction,
        filter_mean_neighbours: stats.filter.mean_neighbours,
        normalization_samples: stats.normalization.samples,
        normalization_relative_error: stats.normalization.relative_error,
        normalization_largest_share: stats.normalization.largest_share,
    }
}

/// A C boolean field `name`: 0 or 1, anything else is a mistake.
pub(super) fn flag(value: u32, name: &str) -> Result<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(Error::invalid(format!(
            "{name} is {other}; it must be 0 or 1"
        ))),
    }
}

/// Checks every ray of a batch query, naming the first bad one.
pub(super) fn checked_rays(rays: &[MltRay]) -> Result<()> {
    for (i, ray) in rays.iter().enumerate() {
        check_finite3(&format!("rays[{i}].origin"), ray.origin)?;
        check_finite3(&format!("rays[{i}].direction"), ray.direction)?;
        let length = direction_length(ray.direction);
        if length == 0.0 {
            return Err(Error::invalid(format!(
                "rays[{i}].direction is {:?}; it must be non-zero",
                ray.direction
            )));
        }
        if !(ray.tmin.is_finite() && ray.tmin >= 0.0) {
            return Err(Error::invalid(format!(
                "rays[{i}].tmin is {}; it must be finite and >= 0",
                ray.tmin
            )));
        }
        if ray.tmax.is_nan() || ray.tmax < ray.tmin {
            return Err(Error::invalid(format!(
                "rays[{i}].tmax is {}; it must be >= tmin ({})",
                ray.tmax, ray.tmin
            )));
        }
    }
    Ok(())
}

/// |direction| in f64: exact enough, and neither underflows nor overflows for finite floats.
pub(super) fn direction_length(direction: [f32; 3]) -> f64 {
    glam::DVec3::from(direction.map(f64::from)).length()
}

/// The ray with a unit direction and t scaled to match, plus the scale to map t back.
pub(super) fn unit_ray(ray: &MltRay) -> (crate::accel::Ray, f64) {
    let direction = glam::DVec3::from(ray.direction.map(f64::from));
    let length = direction.length();
    (
        crate::accel::Ray::new(
            Vec3A::from(ray.origin),
            (direction / length).as_vec3a(),
            (ray.tmin as f64 * length) as f32,
            (ray.tmax as f64 * length) as f32,
        ),
        length,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `texcoord1_slots` has a bit per texture slot in declaration order, the header's
    /// `MLT_TEXCOORD1_*`: a Rust material's sets survive the trip through C, and a bit past
    /// the last slot is refused.
    #[test]
    fn texcoord1_slots_are_the_texture_slots_in_order() {
        let slots: Vec<&str> = Material::default()
            .texture_slots()
            .map(|(slot, _)| slot)
            .collect();
        assert!(
            slots.len() < 32,
            "a u32 has a bit for 31 slots and one past them"
        );
        assert_eq!(slots[0], "base_color_texture");
        assert_eq!(slots[2], "normal_texture");
        assert_eq!(slots[14], "iridescence_thickness_texture");
        assert_eq!(
            (
                MLT_TEXCOORD1_BASE_COLOR,
                MLT_TEXCOORD1_NORMAL,
                MLT_TEXCOORD1_IRIDESCENCE_THICKNESS
            ),
            (1, 1 << 2, 1 << 14)
        );

        let texture = |texture, texcoord| {
            Some(TextureRef {
                texcoord,
                ..TextureRef::new(texture)
            })
        };
        let rust = Material {
            base_color_texture: texture(0, 0),
            normal_texture: texture(1, 1),
            iridescence_thickness_texture: texture(2, 1),
            ..Material::default()
        };
        let c = MltMaterial::from(&rust);
        assert_eq!(
            c.texcoord1_slots,
            MLT_TEXCOORD1_NORMAL | MLT_TEXCOORD1_IRIDESCENCE_THICKNESS
        );
        assert_eq!(material(&c, 0).unwrap(), rust);

        // A bit of a slot without a texture is ignored, as its transform is.
        let empty_slot = MltMaterial {
            texcoord1_slots: c.texcoord1_slots | MLT_TEXCOORD1_EMISSION,
            ..c
        };
        assert_eq!(material(&empty_slot, 0).unwrap(), rust);

        // Bits past the last slot (the slots may grow to 30 before these are any).
        let beyond = MltMaterial {
            texcoord1_slots: MLT_TEXCOORD1_BASE_COLOR | 1 << 30 | 1 << 31,
            ..c
        };
        assert_eq!(
            material(&beyond, 3).unwrap_err().message,
            format!(
                "desc.materials[3].texcoord1_slots is 0xc0000001; bit 30 names no texture slot: \
                 bits 0 (base_color_texture) to {} ({}) are the {} slots",
                slots.len() - 1,
                slots[slots.len() - 1],
                slots.len()
            )
        );
        let next = MltMaterial {
            texcoord1_slots: 1 << slots.len(),
            ..c
        };
        let message = material(&next, 0).unwrap_err().message;
        assert!(
            message.contains(&format!("bit {} names no texture slot", slots.len())),
            "{message}"
        );
    }
}
