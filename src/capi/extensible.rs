//! Structs that grow between versions. Every struct a host fills or receives begins with
//! `struct_size`, which its `mlt_*_default` initializer sets: the initializer is inline in
//! the header, so the size is the `sizeof` of the header the host was compiled with. Later
//! versions only append fields, so a host built against an older header passes a prefix of
//! today's struct: mlt reads the fields it has, gives the rest their defaults, and writes
//! back only the fields it has. A size mlt does not know (0: never initialized; larger than
//! today's: a newer header than the library) is refused with a message.
//!
//! Growth rule, for whoever appends a field: a new layout must change the struct's size (a
//! lone 4-byte field may fit the old tail padding: add the next field in the same release, or
//! an explicit `_reserved` one), and its end goes into `EARLIER_LAYOUTS` of the previous
//! layout. The unit tests check the sizes stay distinct.

use super::convert::CField;
use super::marshal::check_pointer;
use super::types::*;
use crate::error::*;
use crate::render::RenderSettings;
use crate::scene::{Camera, Material, PunctualLight};
use std::mem::{align_of, offset_of, size_of};

/// A C struct that begins with `struct_size: u32` and only grows by appending fields, all
/// plain data (any bit pattern of the host's bytes is a value; the conversions validate).
pub(super) trait Extensible: Copy {
    /// The C type's name, for messages.
    const TYPE_NAME: &'static str;
    /// The initializer that sets `struct_size`, for messages.
    const INITIALIZER: &'static str;
    /// Where the fields of each earlier layout a host may pass end (the offset of the first
    /// field it lacks), oldest first.
    const EARLIER_LAYOUTS: &'static [usize];
    /// The value the initializer gives, also what the fields a shorter layout lacks get.
    fn defaults() -> Self;
}

/// The size of a layout whose fields end at `end`: rounded up to the struct's alignment, as
/// a C compiler pads it.
const fn padded<T>(end: usize) -> usize {
    end.next_multiple_of(align_of::<T>())
}

/// The bytes of fields in a host struct of `struct_size` bytes, if it is a layout mlt knows.
fn known_fields<T: Extensible>(struct_size: usize) -> Option<usize> {
    if struct_size == size_of::<T>() {
        return Some(size_of::<T>());
    }
    T::EARLIER_LAYOUTS
        .iter()
        .copied()
        .find(|&end| padded::<T>(end) == struct_size)
}

/// [`known_fields`], or the error a host gets for a size mlt does not know.
pub(super) fn fields_of_size<T: Extensible>(struct_size: usize, name: &str) -> Result<usize> {
    known_fields::<T>(struct_size).ok_or_else(|| {
        let known: Vec<String> = T::EARLIER_LAYOUTS
            .iter()
            .map(|&end| padded::<T>(end))
            .chain([size_of::<T>()])
            .map(|size| size.to_string())
            .collect();
        let hint = if struct_size == 0 {
            format!("initialize it with {} first", T::INITIALIZER)
        } else if struct_size > size_of::<T>() {
            format!(
                "the host was built against a newer mlt header than this library ({}), or did not initialize it with {}",
                env!("CARGO_PKG_VERSION"),
                T::INITIALIZER
            )
        } else {
            format!("initialize it with {}", T::INITIALIZER)
        };
        Error::invalid(format!(
            "{name}.struct_size is {struct_size}, not a size of {} this library knows ({}); {hint}",
            T::TYPE_NAME,
            known.join(", ")
        ))
    })
}

/// The bytes of fields of the host's struct at `pointer`, from its `struct_size`.
///
/// # Safety
/// If non-null and aligned, `pointer` must point to at least 4 readable bytes.
pub(super) unsafe fn host_fields<T: Extensible>(pointer: *const T, name: &str) -> Result<usize> {
    check_pointer(pointer, name)?;
    // SAFETY: non-null and aligned (checked); `struct_size` is the first field of every
    // layout, so any host struct has these 4 bytes.
    let struct_size = unsafe { pointer.cast::<u32>().read() };
    fields_of_size::<T>(struct_size as usize, name)
}

/// Reads the host's struct at `pointer`: the fields its layout has, the defaults for the rest.
///
/// # Safety
/// If non-null and aligned, `pointer` must point to a struct of the layout its
/// `struct_size` names.
pub(super) unsafe fn read_host<T: Extensible>(pointer: *const T, name: &str) -> Result<T> {
    // SAFETY: forwarded contract.
    let fields = unsafe { host_fields(pointer, name) }?;
    let mut value = T::defaults();
    // SAFETY: the host's struct holds `fields` bytes of fields (its layout, checked), which
    // are a prefix of T's; T is plain data, so any bytes make a value.
    unsafe {
        std::ptr::copy_nonoverlapping(pointer.cast::<u8>(), (&raw mut value).cast::<u8>(), fields)
    };
    Ok(value)
}

/// Reads an array of host structs. Its stride is the first element's `struct_size` (the
/// host's `sizeof`), and every element must carry the same size.
///
/// # Safety
/// If `len > 0`, `pointer` must point to `len` structs of the layout the first one's
/// `struct_size` names.
pub(super) unsafe fn read_host_array<T: Extensible>(
    pointer: *const T,
    len: usize,
    name: &str,
) -> Result<Vec<T>> {
    if len == 0 {
        return Ok(Vec::new());
    }
    let first = format!("{name}[0]");
    // SAFETY: forwarded contract.
    let fields = unsafe { host_fields(pointer, &first) }?;
    // SAFETY: checked by host_fields.
    let stride = unsafe { pointer.cast::<u32>().read() } as usize;
    if len
        .checked_mul(stride)
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Error::invalid(format!(
            "{name} claims {len} elements, more than the address space holds"
        )));
    }
    (0..len)
        .map(|i| {
            // SAFETY: within the host's array of `len` elements of `stride` bytes (contract;
            // the byte count fits isize, checked); aligned as the first, since the stride
            // is a padded size.
            let element = unsafe { pointer.cast::<u8>().add(i * stride) }.cast::<T>();
            let size = unsafe { element.cast::<u32>().read() } as usize;
            if size != stride {
                return Err(Error::invalid(format!(
                    "{name}[{i}].struct_size is {size} but {first}'s is {stride}; initialize every element with {}",
                    T::INITIALIZER
                )));
            }
            let mut value = T::defaults();
            // SAFETY: as in read_host.
            unsafe {
                std::ptr::copy_nonoverlapping(
                    element.cast::<u8>(),
                    (&raw mut value).cast::<u8>(),
                    fields,
                )
            };
            Ok(value)
        })
        .collect()
}

/// Writes the fields of `value` the host's struct has (`fields` bytes, from
/// [`host_fields`]), keeping its `struct_size`.
///
/// # Safety
/// `pointer` must be checked by [`host_fields`] and writable for `fields` bytes.
pub(super) unsafe fn write_host<T: Extensible>(pointer: *mut T, fields: usize, value: &T) {
    let skip = size_of::<u32>();
    // SAFETY: `fields` bytes of the host's struct are writable (contract) and `value` has at
    // least as many; the first 4 (struct_size) stay the host's.
    unsafe {
        std::ptr::copy_nonoverlapping(
            (value as *const T).cast::<u8>().add(skip),
            pointer.cast::<u8>().add(skip),
            fields - skip,
        )
    };
}

/// Fills the host's `out` with the defaults for a struct of `struct_size` bytes.
///
/// # Safety
/// If non-null and aligned, `out` must be writable for `struct_size` bytes.
pub(super) unsafe fn init_host<T: Extensible>(out: *mut T, struct_size: usize) -> Result<()> {
    check_pointer(out, "out")?;
    let fields = fields_of_size::<T>(struct_size, "out")?;
    let size = u32::try_from(struct_size).expect("known sizes are small");
    // SAFETY: writable for struct_size >= 4 bytes (contract; known sizes are).
    unsafe { out.cast::<u32>().write(size) };
    // SAFETY: as above, `fields` <= struct_size.
    unsafe { write_host(out, fields, &T::defaults()) };
    Ok(())
}

impl Extensible for MltMaterial {
    const TYPE_NAME: &'static str = "MltMaterial";
    const INITIALIZER: &'static str = "mlt_material_default";
    /// Before the metallic-roughness model and textures (mlt 0.2's header): 36 bytes; before
    /// the transmission texture (0.3's): 168; before the clear coat, the volume, specular and sheen (0.4's): 192;
    /// before the anisotropy: 424; before the texture coordinate set 1 (0.6's): 520.
    const EARLIER_LAYOUTS: &'static [usize] = &[
        offset_of!(MltMaterial, metallic),
        offset_of!(MltMaterial, transmission_texture),
        offset_of!(MltMaterial, clearcoat),
        offset_of!(MltMaterial, anisotropy),
        offset_of!(MltMaterial, texcoord1_slots),
    ];
    fn defaults() -> Self {
        (&Material::default()).into()
    }
}

/// The C struct of a Rust material, with today's `struct_size`.
impl From<&Material> for MltMaterial {
    fn from(d: &Material) -> Self {
        macro_rules! to_c {
            ($($name:ident,)*) => {
                MltMaterial {
                    struct_size: size_of::<Self>() as u32,
                    $($name: d.$name.to_c(),)*
                    texcoord1_slots: super::convert::texcoord1_slots(d),
                }
            };
        }
        to_c! {
            // BEGIN GENERATED material to C: tests/parameters.rs writes these lines from src/scene/material.rs
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
            // END GENERATED material to C
        }
    }
}

impl Extensible for MltTexture {
    const TYPE_NAME: &'static str = "MltTexture";
    const INITIALIZER: &'static str = "mlt_texture_default";
    const EARLIER_LAYOUTS: &'static [usize] = &[];
    fn defaults() -> Self {
        MltTexture {
            struct_size: size_of::<Self>() as u32,
            width: 0,
            height: 0,
            channels: 4,
            texel_type: MLT_TEXEL_U8,
            texels: std::ptr::null(),
            encoding: MLT_TEXTURE_SRGB,
            wrap_u: MLT_WRAP_REPEAT,
            wrap_v: MLT_WRAP_REPEAT,
            filter: MLT_FILTER_BILINEAR,
        }
    }
}

impl Extensible for MltSceneDesc {
    const TYPE_NAME: &'static str = "MltSceneDesc";
    const INITIALIZER: &'static str = "mlt_scene_desc_default";
    /// Before the lights besides emissive triangles (mlt 0.2's header, 80 bytes): no
    /// lights; before the surface attributes and textures (112 bytes): flat triangles, no
    /// textures; before the build quality (192 bytes): the default quality; before the
    /// texture coordinate set 1 (200 bytes, 0.6's): none.
    const EARLIER_LAYOUTS: &'static [usize] = &[
        offset_of!(MltSceneDesc, environment),
        offset_of!(MltSceneDesc, normals),
        offset_of!(MltSceneDesc, build_quality),
        offset_of!(MltSceneDesc, texcoords1),
    ];
    fn defaults() -> Self {
        MltSceneDesc {
            struct_size: size_of::<Self>() as u32,
            positions: std::ptr::null(),
            positions_len: 0,
            indices: std::ptr::null(),
            indices_len: 0,
            material_ids: std::ptr::null(),
            material_ids_len: 0,
            materials: std::ptr::null(),
            materials_len: 0,
            backend: MLT_BACKEND_BVH,
            environment: std::ptr::null(),
            sun: std::ptr::null(),
            punctual_lights: std::ptr::null(),
            punctual_lights_len: 0,
            normals: std::ptr::null(),
            normals_len: 0,
            texcoords: std::ptr::null(),
            texcoords_len: 0,
            tangents: std::ptr::null(),
            tangents_len: 0,
            colors: std::ptr::null(),
            colors_len: 0,
            textures: std::ptr::null(),
            textures_len: 0,
            build_quality: MLT_BUILD_QUALITY_HIGH,
            texcoords1: std::ptr::null(),
            texcoords1_len: 0,
        }
    }
}

impl Extensible for MltEnvironment {
    const TYPE_NAME: &'static str = "MltEnvironment";
    const INITIALIZER: &'static str = "mlt_environment_default";
    const EARLIER_LAYOUTS: &'static [usize] = &[];
    fn defaults() -> Self {
        MltEnvironment {
            struct_size: size_of::<Self>() as u32,
            pixels: std::ptr::null(),
            width: 0,
            height: 0,
            rotation_degrees: 0.0,
            scale: 1.0,
        }
    }
}

impl Extensible for MltSun {
    const TYPE_NAME: &'static str = "MltSun";
    const INITIALIZER: &'static str = "mlt_sun_default";
    const EARLIER_LAYOUTS: &'static [usize] = &[];
    fn defaults() -> Self {
        MltSun {
            struct_size: size_of::<Self>() as u32,
            direction: [0.0, 1.0, 0.0],
            angular_radius_degrees: 0.27,
            irradiance: [1.0; 3],
        }
    }
}

impl Extensible for MltPunctualLight {
    const TYPE_NAME: &'static str = "MltPunctualLight";
    const INITIALIZER: &'static str = "mlt_punctual_light_default";
    const EARLIER_LAYOUTS: &'static [usize] = &[];
    fn defaults() -> Self {
        let d = PunctualLight::point([0.0; 3], [1.0; 3]);
        MltPunctualLight {
            struct_size: size_of::<Self>() as u32,
            kind: MLT_LIGHT_POINT,
            position: d.position,
            direction: d.direction,
            intensity: d.intensity,
            inner_cone_degrees: d.inner_cone_degrees,
            outer_cone_degrees: d.outer_cone_degrees,
        }
    }
}

impl Extensible for MltCamera {
    const TYPE_NAME: &'static str = "MltCamera";
    const INITIALIZER: &'static str = "mlt_camera_default";
    const EARLIER_LAYOUTS: &'static [usize] = &[];
    fn defaults() -> Self {
        let c = Camera::default();
        MltCamera {
            struct_size: size_of::<Self>() as u32,
            eye: c.eye,
            target: c.target,
            up: c.up,
            fov_y_deg: c.fov_y_deg,
            lens_radius: c.lens_radius,
            focus_distance: c.focus_distance,
        }
    }
}

impl Extensible for MltRenderSettings {
    const TYPE_NAME: &'static str = "MltRenderSettings";
    const INITIALIZER: &'static str = "mlt_render_settings_default";
    /// The settings before the post-process filter's fields (mlt 0.1 had them without
    /// `struct_size`). `normalization_work_fraction`, added after the filter, fits the
    /// filter layout's tail padding, so that intermediate layout has today's size and is
    /// not told apart: a host passes the filter fields with it or not at all. Then the
    /// settings before Russian roulette's, and before `full_resolution_textures` (which fills
    /// the roulette layout's tail padding: `_reserved` makes today's size differ).
    const EARLIER_LAYOUTS: &'static [usize] = &[
        offset_of!(MltRenderSettings, filter_buffers),
        offset_of!(MltRenderSettings, roulette_start_depth),
        offset_of!(MltRenderSettings, full_resolution_textures),
    ];
    fn defaults() -> Self {
        (&RenderSettings::default()).into()
    }
}

/// The C struct of Rust's settings, with today's `struct_size`.
impl From<&RenderSettings> for MltRenderSettings {
    fn from(d: &RenderSettings) -> Self {
        macro_rules! to_c {
            ($($name:ident,)*) => {
                MltRenderSettings {
                    struct_size: size_of::<Self>() as u32,
                    $($name: d.$name.to_c(),)*
                    _reserved: 0,
                }
            };
        }
        to_c! {
            // BEGIN GENERATED settings to C: tests/parameters.rs writes these lines from src/render/settings.rs
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
            // END GENERATED settings to C
        }
    }
}

impl Extensible for MltRenderStats {
    const TYPE_NAME: &'static str = "MltRenderStats";
    const INITIALIZER: &'static str = "mlt_render_stats_default";
    /// Before the filter's report, and before the normalization's error report.
    const EARLIER_LAYOUTS: &'static [usize] = &[
        offset_of!(MltRenderStats, filter_changed_fraction),
        offset_of!(MltRenderStats, normalization_samples),
    ];
    fn defaults() -> Self {
        MltRenderStats {
            struct_size: size_of::<Self>() as u32,
            ..Default::default()
        }
    }
}

impl Extensible for MltSceneInfo {
    const TYPE_NAME: &'static str = "MltSceneInfo";
    const INITIALIZER: &'static str = "mlt_scene_info_default";
    /// Before the acceleration structure's facts (64 bytes).
    const EARLIER_LAYOUTS: &'static [usize] = &[offset_of!(MltSceneInfo, build_quality)];
    fn defaults() -> Self {
        MltSceneInfo {
            struct_size: size_of::<Self>() as u32,
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sizes<T: Extensible>() -> Vec<usize> {
        T::EARLIER_LAYOUTS
            .iter()
            .map(|&end| padded::<T>(end))
            .chain([size_of::<T>()])
            .collect()
    }

    /// Each layout a host may pass must be told apart by its size alone.
    fn assert_sizes_grow<T: Extensible>() {
        let sizes = sizes::<T>();
        assert!(
            sizes.windows(2).all(|w| w[0] < w[1]),
            "{}: layout sizes {sizes:?} must strictly grow",
            T::TYPE_NAME
        );
        assert_struct_size_comes_first::<T>();
        for size in sizes {
            assert_eq!(size % align_of::<T>(), 0);
            assert!(known_fields::<T>(size).is_some());
        }
    }

    /// The defaults' first 4 bytes are their `struct_size`, today's size.
    fn assert_struct_size_comes_first<T: Extensible>() {
        let value = T::defaults();
        // SAFETY: T is at least 4 bytes of plain data.
        let first = unsafe { (&raw const value).cast::<u32>().read() };
        assert_eq!(first as usize, size_of::<T>(), "{}", T::TYPE_NAME);
    }

    #[test]
    fn every_layout_has_its_own_size() {
        assert_sizes_grow::<MltMaterial>();
        assert_sizes_grow::<MltSceneDesc>();
        assert_sizes_grow::<MltCamera>();
        assert_sizes_grow::<MltRenderSettings>();
        assert_sizes_grow::<MltRenderStats>();
        assert_sizes_grow::<MltSceneInfo>();
        assert_sizes_grow::<MltEnvironment>();
        assert_sizes_grow::<MltSun>();
        assert_sizes_grow::<MltPunctualLight>();
        assert_sizes_grow::<MltTexture>();
    }

    /// The layouts older headers have: mlt 0.2's material ends at `ior` (0.3's at
    /// `abbe_number`, 0.4's at `transmission_texture`), its scene description at `backend`; the one with lights but no surface attributes is 112 bytes,
    /// the one without the build quality 192; the scene info without the acceleration
    /// structure's facts 64; the settings without the filter 104, without Russian roulette
    /// 128, without `full_resolution_textures` 136.
    #[test]
    #[cfg(target_pointer_width = "64")]
    fn earlier_layouts_have_the_sizes_of_the_older_headers() {
        assert_eq!(sizes::<MltMaterial>(), [36, 168, 192, 424, 520, 524]);
        assert_eq!(sizes::<MltSceneDesc>(), [80, 112, 192, 200, 216]);
        assert_eq!(sizes::<MltSceneInfo>(), [64, 80]);
        // Before the filter, before Russian roulette, before full_resolution_textures, today.
        assert_eq!(sizes::<MltRenderSettings>(), [104, 128, 136, 144]);
        assert_eq!(size_of::<MltTexture>(), 48);
        assert_eq!(size_of::<MltTextureRef>(), 24);
    }

    #[test]
    fn unknown_sizes_are_refused_with_a_hint() {
        let message = |size| {
            fields_of_size::<MltRenderSettings>(size, "settings")
                .unwrap_err()
                .message
        };
        assert!(message(0).contains("mlt_render_settings_default first"));
        assert!(message(size_of::<MltRenderSettings>() + 8).contains("newer mlt header"));
        assert!(message(12).contains("settings.struct_size is 12"));
    }

    #[test]
    fn a_shorter_layout_reads_its_fields_and_defaults_the_rest() {
        let end = MltRenderSettings::EARLIER_LAYOUTS[0];
        let mut host = MltRenderSettings {
            struct_size: padded::<MltRenderSettings>(end) as u32,
            width: 7,
            perturb_in_sample_space: 1,
            // What an older host's memory holds past its struct: garbage mlt must not read.
            filter_buffers: 999,
            filter_strength: f32::NAN,
            normalization_work_fraction: -1.0,
            ..MltRenderSettings::defaults()
        };
        // SAFETY: a valid struct.
        let read = unsafe { read_host(&raw const host, "settings") }.unwrap();
        let defaults = MltRenderSettings::defaults();
        assert_eq!((read.width, read.perturb_in_sample_space), (7, 1));
        assert_eq!(read.filter_buffers, defaults.filter_buffers);
        assert_eq!(read.filter_strength, defaults.filter_strength);
        assert_eq!(
            read.normalization_work_fraction,
            defaults.normalization_work_fraction
        );
        // Writing back touches only the fields the host has.
        let fields = unsafe { host_fields(&raw const host, "settings") }.unwrap();
        unsafe { write_host(&raw mut host, fields, &defaults) };
        assert_eq!(host.width, defaults.width);
        assert_eq!(host.filter_buffers, 999);
        assert_eq!(host.struct_size as usize, padded::<MltRenderSettings>(end));
    }
}
