//! The C ABI. Every export validates what the host passed, catches panics, and reports
//! failures as an [`MltStatus`] plus a thread-local message. Conventions:
//! - out-parameters are written only on success (renders also on cancel / time limit);
//! - `*_release(NULL)` is a no-op;
//! - enums coming from C are `int32_t` and range-checked (an invalid value in a Rust enum
//!   would be undefined behaviour);
//! - a null pointer is accepted only where a count of 0 makes it unused, or where the header
//!   says it is optional.
//!
//! - every struct the host fills or receives starts with `struct_size`, so a host built
//!   against an older header keeps working (`extensible`).
//!
//! The C types and constants are in `types` (what include/mlt.h declares), the checks of
//! host pointers and the panic guard in `marshal`, the conversions between C and Rust values
//! in `convert`, the reading and writing of growing structs in `extensible`, the live scene
//! handles in `handles` and the byte buffers mlt gives the host in `buffers`; this file holds
//! the exports, but for those of a render split into jobs, in `jobs`.

mod buffers;
mod convert;
mod extensible;
mod handles;
mod jobs;
mod marshal;
mod types;

pub use jobs::*;
pub use types::*;

use crate::accel::Backend;
use crate::error::*;
use crate::render::{self, StopReason, ValidSettings};
use crate::scene::{
    Camera, EnvironmentDesc, LightsDesc, MLT_MAX_PUNCTUAL_LIGHTS, Scene, SceneDesc, SunDesc,
};
use crate::texture::{TexelData, TextureDesc};
use convert::*;
use extensible::*;
use marshal::*;
use std::borrow::Cow;
use std::ffi::{c_char, c_void};

/// The library version as MAJOR * 10000 + MINOR * 100 + PATCH.
#[unsafe(no_mangle)]
pub extern "C" fn mlt_version() -> u32 {
    MLT_VERSION
}

/// The library version as "MAJOR.MINOR.PATCH" (static storage).
#[unsafe(no_mangle)]
pub extern "C" fn mlt_version_string() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// A static description of a status (any integer is accepted).
#[unsafe(no_mangle)]
pub extern "C" fn mlt_status_string(status: i32) -> *const c_char {
    let text: &'static std::ffi::CStr = match status {
        0 => c"success",
        1 => c"invalid argument",
        2 => c"unsupported",
        3 => c"out of memory",
        4 => c"cancelled by the progress callback",
        5 => c"time limit reached",
        6 => c"internal error",
        _ => c"unknown status",
    };
    text.as_ptr()
}

/// The message of the last failed mlt call on this thread ("" after a success). The pointer
/// stays valid until the next mlt call on this thread.
#[unsafe(no_mangle)]
pub extern "C" fn mlt_last_error_message() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Whether `mlt_scene_create` can build scenes with `backend` (one of `MLT_BACKEND_*`) in
/// this build of the library: true for `MLT_BACKEND_BVH`; for `MLT_BACKEND_EMBREE` only if
/// mlt was compiled with the `embree` feature (otherwise scene creation with it returns
/// `MLT_STATUS_UNSUPPORTED`); false for any other value.
#[unsafe(no_mangle)]
pub extern "C" fn mlt_backend_supported(backend: i32) -> bool {
    self::backend(backend).is_ok_and(Backend::is_available)
}

/// Fills `out` with a light grey (0.8) diffuse, non-emissive material (ior 1.5; metallic 0,
/// roughness 1, transmission 0, alpha 1, `MLT_ALPHA_OPAQUE` with cutoff 0.5, no textures
/// (`MLT_NO_TEXTURE` with the identity transform), normal scale 1) and `struct_size`. Call it through the header's inline `mlt_material_default(out)`, which
/// passes the host's `sizeof(MltMaterial)`; the other `*_init` functions likewise.
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_material_init(out: *mut MltMaterial, struct_size: usize) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with an empty texture: no texels (set `width`, `height` and `texels`), 4
/// channels of `MLT_TEXEL_U8` in `MLT_TEXTURE_SRGB`, `MLT_WRAP_REPEAT` both ways,
/// `MLT_FILTER_BILINEAR`.
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_texture_init(out: *mut MltTexture, struct_size: usize) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with an empty description (no arrays, no lights, no surface attributes or
/// textures, BVH backend).
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_desc_init(
    out: *mut MltSceneDesc,
    struct_size: usize,
) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with an empty environment (no pixels, rotation 0, scale 1): set `pixels`,
/// `width` and `height` before passing it.
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_environment_init(
    out: *mut MltEnvironment,
    struct_size: usize,
) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with a white sun of irradiance 1 straight above (+Y), of the real sun's
/// angular radius (0.27 degrees).
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_sun_init(out: *mut MltSun, struct_size: usize) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with a point light of intensity 1 at the origin (for a spot: axis -Z, cone
/// 0 to 45 degrees).
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_punctual_light_init(
    out: *mut MltPunctualLight,
    struct_size: usize,
) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with the Cornell box's pinhole camera.
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_camera_init(out: *mut MltCamera, struct_size: usize) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Fills `out` with the default settings: 256 x 256, multiplexed MLT with the direct pass
/// (32 mutations per pixel and one direct sample per mutation, an automatic bootstrap
/// (2^18 samples at this size), 5% of the rays for the normalization pass,
/// 1024 chains, large steps 0.3, small steps 0.01), 64 samples per pixel for path tracing and
/// BDPT, max depth 5, seed 0, all cores, no time limit, no post-process filter (strength
/// 0.45 and radius 7 when `filter_buffers` turns it on).
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_render_settings_init(
    out: *mut MltRenderSettings,
    struct_size: usize,
) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Prepares `out` to receive a render's statistics: zeros and `struct_size`.
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_render_stats_init(
    out: *mut MltRenderStats,
    struct_size: usize,
) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Prepares `out` to receive a scene's facts: zeros and `struct_size`.
///
/// # Safety
/// `out` must be NULL or point to `struct_size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_info_init(
    out: *mut MltSceneInfo,
    struct_size: usize,
) -> MltStatus {
    // SAFETY: forwarded contract.
    guard(|| unsafe { init_host(out, struct_size) }.map(|()| MLT_STATUS_OK))
}

/// Validates `desc`, copies its arrays and builds the acceleration structure. On success
/// `*out` receives a scene to release with `mlt_scene_release`; on failure `*out` is untouched.
///
/// # Safety
/// `desc` must point to an `MltSceneDesc` whose pointers reference arrays of at least the
/// given lengths; `out` must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_create(
    desc: *const MltSceneDesc,
    out: *mut *mut MltScene,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract for every pointer below.
        let desc = unsafe { read_host(desc, "desc") }?;
        check_pointer(out, "out")?;
        let positions =
            unsafe { host_slice(desc.positions, desc.positions_len, "desc.positions") }?;
        let indices = unsafe { host_slice(desc.indices, desc.indices_len, "desc.indices") }?;
        let material_ids = unsafe {
            host_slice(
                desc.material_ids,
                desc.material_ids_len,
                "desc.material_ids",
            )
        }?;
        let host_materials =
            unsafe { read_host_array(desc.materials, desc.materials_len, "desc.materials") }?;
        let materials = host_materials
            .iter()
            .enumerate()
            .map(|(i, m)| material(m, i))
            .collect::<Result<Vec<_>>>()?;
        let environment = unsafe { read_environment(desc.environment) }?;
        let sun = if desc.sun.is_null() {
            None
        } else {
            Some(SunDesc::from(&unsafe { read_host(desc.sun, "desc.sun") }?))
        };
        if desc.punctual_lights_len > MLT_MAX_PUNCTUAL_LIGHTS {
            return Err(Error::invalid(format!(
                "desc.punctual_lights_len is {}; at most {MLT_MAX_PUNCTUAL_LIGHTS} punctual lights are allowed",
                desc.punctual_lights_len
            )));
        }
        let punctual = unsafe {
            read_host_array(
                desc.punctual_lights,
                desc.punctual_lights_len,
                "desc.punctual_lights",
            )
        }?
        .iter()
        .enumerate()
        .map(|(i, light)| punctual_light(light, i))
        .collect::<Result<Vec<_>>>()?;
        let normals = unsafe { host_slice(desc.normals, desc.normals_len, "desc.normals") }?;
        let texcoords =
            unsafe { host_slice(desc.texcoords, desc.texcoords_len, "desc.texcoords") }?;
        let texcoords1 =
            unsafe { host_slice(desc.texcoords1, desc.texcoords1_len, "desc.texcoords1") }?;
        let tangents = unsafe { host_slice(desc.tangents, desc.tangents_len, "desc.tangents") }?;
        let colors = unsafe { host_slice(desc.colors, desc.colors_len, "desc.colors") }?;
        let textures = unsafe { read_textures(desc.textures, desc.textures_len) }?;
        // The BVH build is parallel: on the pool renders use, rather than start rayon's
        // global pool as a second set of threads for the process.
        let build = || {
            Scene::new(&SceneDesc {
                positions,
                indices,
                material_ids,
                materials: &materials,
                lights: LightsDesc {
                    environment,
                    sun,
                    punctual: &punctual,
                },
                backend: backend(desc.backend)?,
                build_quality: build_quality(desc.build_quality)?,
                normals,
                texcoords,
                texcoords1,
                tangents,
                colors,
                textures: &textures,
            })
        };
        let scene = render::shared_pool()?.install(build)?;
        let handle = handles::register(MltScene {
            scene,
            backend: desc.backend,
        });
        // SAFETY: `out` checked non-null and aligned above.
        unsafe { out.write(handle) };
        Ok(MLT_STATUS_OK)
    })
}

/// The host's environment, if `environment` is not NULL: its size checked before its pixels
/// are looked at (the rest is validated with the scene).
///
/// # Safety
/// If non-null, `environment` must point to an `MltEnvironment` of the layout its
/// `struct_size` names, whose `pixels` point to width × height × 3 floats.
unsafe fn read_environment<'a>(
    environment: *const MltEnvironment,
) -> Result<Option<EnvironmentDesc<'a>>> {
    if environment.is_null() {
        return Ok(None);
    }
    // SAFETY: forwarded contract.
    let e = unsafe { read_host(environment, "desc.environment") }?;
    EnvironmentDesc::validate_size(e.width, e.height)?;
    let len = e.width as usize * e.height as usize * 3;
    // SAFETY: forwarded contract; the size is checked above, so `len` does not overflow.
    let pixels = unsafe { host_slice(e.pixels, len, "desc.environment.pixels") }?;
    Ok(Some(EnvironmentDesc {
        pixels,
        width: e.width,
        height: e.height,
        rotation_degrees: e.rotation_degrees,
        scale: e.scale,
    }))
}

/// The host's textures, borrowing their texels (the scene copies them): each one's enums
/// and size checked before its texels are looked at.
///
/// # Safety
/// If `len > 0`, `textures` must point to `len` `MltTexture`s of the layout the first one's
/// `struct_size` names, each of whose `texels` points to width × height × channels values of
/// its `texel_type`.
unsafe fn read_textures<'a>(
    textures: *const MltTexture,
    len: usize,
) -> Result<Vec<TextureDesc<'a>>> {
    // SAFETY: forwarded contract.
    let host = unsafe { read_host_array(textures, len, "desc.textures") }?;
    host.iter()
        .enumerate()
        .map(|(i, t)| {
            let (encoding, wrap_u, wrap_v, filter) = texture_modes(t, i)?;
            let count = TextureDesc::value_count(t.width, t.height, t.channels, i)?;
            let name = format!("desc.textures[{i}].texels");
            let data = if t.texel_type == MLT_TEXEL_F32 {
                // SAFETY: forwarded contract; `count` is checked small (at most 2^30).
                let values = unsafe { host_slice(t.texels.cast::<f32>(), count, &name) }?;
                check_float_texels(values, t, i)?;
                TexelData::F32(Cow::Borrowed(values))
            } else {
                // SAFETY: as above.
                let values = unsafe { host_slice(t.texels.cast::<u8>(), count, &name) }?;
                TexelData::U8(Cow::Borrowed(values))
            };
            Ok(TextureDesc {
                width: t.width,
                height: t.height,
                channels: t.channels,
                data,
                encoding,
                wrap_u,
                wrap_v,
                filter,
            })
        })
        .collect()
}

/// Adds a reference to a live scene, to be dropped by one more `mlt_scene_release`: a host
/// that shares a scene between owners (threads, documents) retains it for each.
///
/// # Safety
/// None beyond passing a pointer: `scene` is looked up among the live scenes, never
/// dereferenced, so NULL, released or foreign pointers are refused with
/// `MLT_STATUS_INVALID_ARGUMENT`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_retain(scene: *mut MltScene) -> MltStatus {
    guard(|| handles::retain(scene).map(|()| MLT_STATUS_OK))
}

/// Drops a reference to a scene (the one `mlt_scene_create` gave, or one added by
/// `mlt_scene_retain`). NULL is a no-op. When the last reference is dropped, the handle is
/// no longer valid; renders and queries still running on the scene in other threads
/// finish normally, and the scene is freed when the last of them returns. A pointer that is
/// not a live scene (released already, or not from `mlt_scene_create`) is ignored, and
/// `mlt_last_error_message` says so. (A freed scene's address may be given to a scene
/// created later, so a stale pointer may then name that one: a host bug, but never a
/// use-after-free.)
///
/// # Safety
/// None beyond passing a pointer: it is looked up, never dereferenced.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_release(scene: *mut MltScene) {
    if scene.is_null() {
        return;
    }
    let _ = guard(|| handles::release(scene).map(|()| MLT_STATUS_OK));
}

/// Facts about a scene: triangle, degenerate and emitter counts, bounds, backend, and its
/// acceleration structure's build quality, memory and build time.
///
/// # Safety
/// `out` must be writable. (`scene` is looked up among the live scenes: any other pointer
/// is refused.)
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_get_info(
    scene: *const MltScene,
    out: *mut MltSceneInfo,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract.
        let handle = handles::acquire(scene, "scene")?;
        let fields = unsafe { host_fields(out, "out") }?;
        let info = handle.scene.info();
        let value = MltSceneInfo {
            struct_size: 0, // the host's stays
            triangle_count: info.triangle_count as u64,
            degenerate_triangle_count: info.degenerate_triangle_count as u64,
            emitter_count: info.emitter_count as u64,
            bounds_min: info.bounds_min,
            bounds_max: info.bounds_max,
            backend: handle.backend,
            build_quality: build_quality_code(info.build_quality),
            accel_memory_bytes: info.accel_memory_bytes as u64,
            accel_build_seconds: info.accel_build_seconds,
        };
        // SAFETY: checked by host_fields; writable by the contract.
        unsafe { write_host(out, fields, &value) };
        Ok(MLT_STATUS_OK)
    })
}

/// Renders `scene` seen by `camera` into `rgb_out`: width × height × 3 floats, linear RGB
/// radiance, rows from top to bottom, left to right. `out_len` is the number of floats
/// `rgb_out` holds (at least width·height·3). `progress` may be NULL.
///
/// Returns `MLT_STATUS_OK` when every sample was taken. `MLT_STATUS_CANCELLED` or
/// `MLT_STATUS_TIME_LIMIT_REACHED` also leave a valid image in `rgb_out`, each pixel
/// normalized by the samples it actually received. A cancel or time limit takes effect once
/// every pixel has at least one sample (the first pass is never interrupted). On any other status `rgb_out` is untouched.
///
/// The render holds its own reference to the scene: another thread may release the scene
/// meanwhile, and it is freed when the render returns. A `scene` that is not live (released,
/// or not from `mlt_scene_create`) is refused with `MLT_STATUS_INVALID_ARGUMENT`.
///
/// # Safety
/// Pointers must be valid as described; `rgb_out` must not be accessed by the host until
/// the call returns.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_render(
    scene: *const MltScene,
    camera: *const MltCamera,
    settings: *const MltRenderSettings,
    rgb_out: *mut f32,
    out_len: usize,
    progress: MltProgressCallback,
    user_data: *mut c_void,
) -> MltStatus {
    // SAFETY: forwarded contract; no stats requested.
    unsafe {
        mlt_render_ex(
            scene,
            camera,
            settings,
            rgb_out,
            out_len,
            progress,
            user_data,
            std::ptr::null_mut(),
        )
    }
}

/// `mlt_render` that also fills `stats_out` (may be NULL) whenever it writes the image.
///
/// # Safety
/// As `mlt_render`; `stats_out` NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mlt_render_ex(
    scene: *const MltScene,
    camera: *const MltCamera,
    settings: *const MltRenderSettings,
    rgb_out: *mut f32,
    out_len: usize,
    progress: MltProgressCallback,
    user_data: *mut c_void,
    stats_out: *mut MltRenderStats,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract for every pointer below.
        let handle = handles::acquire(scene, "scene")?;
        let camera: Camera = (&unsafe { read_host(camera, "camera") }?).into();
        let settings = render_settings(&unsafe { read_host(settings, "settings") }?)?;
        let stats_fields = if stats_out.is_null() {
            None
        } else {
            Some(unsafe { host_fields(stats_out, "stats_out") }?)
        };
        let request = ValidSettings::new(&settings)?.with_camera(&camera)?;
        let settings = request.settings();
        let needed = settings.output_len()?;
        if out_len < needed {
            return Err(Error::invalid(format!(
                "out_len is {out_len} floats but a {} x {} RGB image needs {needed}",
                settings.width, settings.height
            )));
        }
        let image = unsafe { host_slice_mut(rgb_out, needed, "rgb_out") }?;
        let mut forward = |fraction: f32| match progress {
            // SAFETY: the host's callback with the host's user data, on the host's thread.
            Some(callback) => unsafe { callback(fraction, user_data) },
            None => true,
        };
        let stats =
            render::render_request(&handle.scene, &request, image, None, Some(&mut forward))?;
        if let Some(fields) = stats_fields {
            // SAFETY: checked by host_fields above; writable by the contract.
            unsafe { write_host(stats_out, fields, &stats_to_c(&stats)) };
        }
        Ok(match stats.stop {
            StopReason::Completed => MLT_STATUS_OK,
            StopReason::Cancelled => {
                set_last_error(&format!(
                    "the progress callback cancelled the render after {} samples and {} mutations",
                    stats.samples, stats.mutations
                ));
                MLT_STATUS_CANCELLED
            }
            StopReason::TimeLimitReached => {
                set_last_error(&format!(
                    "the time limit of {} s was reached after {} samples and {} mutations",
                    settings.time_limit_seconds, stats.samples, stats.mutations
                ));
                MLT_STATUS_TIME_LIMIT_REACHED
            }
        })
    })
}

/// Closest hit for each of `count` rays, written to `hits_out[i]` (a miss has triangle_id
/// `MLT_INVALID_ID` and t = INFINITY). Runs on the calling thread. Every ray is validated
/// before any result is written.
///
/// # Safety
/// `rays` and `hits_out` must hold `count` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_intersect(
    scene: *const MltScene,
    rays: *const MltRay,
    count: usize,
    hits_out: *mut MltHit,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract.
        let handle = handles::acquire(scene, "scene")?;
        let rays = unsafe { host_slice(rays, count, "rays") }?;
        if count == 0 {
            return Ok(MLT_STATUS_OK);
        }
        let hits = unsafe { host_slice_mut(hits_out, count, "hits_out") }?;
        checked_rays(rays)?;
        for (ray, out) in rays.iter().zip(hits.iter_mut()) {
            let (unit, length) = unit_ray(ray);
            *out = match handle.scene.intersect(&unit) {
                Some(hit) => MltHit {
                    triangle_id: hit.triangle,
                    t: (hit.t as f64 / length) as f32,
                    u: hit.u,
                    v: hit.v,
                },
                None => MltHit {
                    triangle_id: MLT_INVALID_ID,
                    t: f32::INFINITY,
                    u: 0.0,
                    v: 0.0,
                },
            };
        }
        Ok(MLT_STATUS_OK)
    })
}

/// For each of `count` rays, `occluded_out[i]` = 1 if any triangle lies on it within
/// [tmin, tmax], else 0. Runs on the calling thread.
///
/// # Safety
/// `rays` and `occluded_out` must hold `count` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_occluded(
    scene: *const MltScene,
    rays: *const MltRay,
    count: usize,
    occluded_out: *mut u8,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract.
        let handle = handles::acquire(scene, "scene")?;
        let rays = unsafe { host_slice(rays, count, "rays") }?;
        if count == 0 {
            return Ok(MLT_STATUS_OK);
        }
        let out = unsafe { host_slice_mut(occluded_out, count, "occluded_out") }?;
        checked_rays(rays)?;
        for (ray, o) in rays.iter().zip(out.iter_mut()) {
            let (unit, _) = unit_ray(ray);
            *o = handle.scene.occluded(&unit) as u8;
        }
        Ok(MLT_STATUS_OK)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_constants_match_the_crate() {
        assert_eq!(
            env!("CARGO_PKG_VERSION"),
            format!("{MLT_VERSION_MAJOR}.{MLT_VERSION_MINOR}.{MLT_VERSION_PATCH}")
        );
    }

    /// The committed header is what hosts compile against: its version macros must name this
    /// crate's version, which is bumped whenever the C ABI grows.
    #[test]
    fn header_version_macros_match_the_crate() {
        let header = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/mlt.h"))
            .expect("include/mlt.h is readable");
        let define = |name: &str| -> String {
            let prefix = format!("#define {name} ");
            let line = header
                .lines()
                .find(|line| line.starts_with(&prefix))
                .unwrap_or_else(|| panic!("include/mlt.h defines {name}"));
            line[prefix.len()..].trim().to_string()
        };
        let version = [
            define("MLT_VERSION_MAJOR"),
            define("MLT_VERSION_MINOR"),
            define("MLT_VERSION_PATCH"),
        ]
        .join(".");
        assert_eq!(version, env!("CARGO_PKG_VERSION"));
    }

    #[test]
    fn status_strings_match_descriptions() {
        for status in [
            MLT_STATUS_OK,
            MLT_STATUS_INVALID_ARGUMENT,
            MLT_STATUS_UNSUPPORTED,
            MLT_STATUS_OUT_OF_MEMORY,
            MLT_STATUS_CANCELLED,
            MLT_STATUS_TIME_LIMIT_REACHED,
            MLT_STATUS_INTERNAL_ERROR,
        ] {
            // SAFETY: static NUL-terminated strings.
            let s = unsafe { std::ffi::CStr::from_ptr(mlt_status_string(status as i32)) };
            assert_eq!(s.to_str().unwrap(), status.description());
        }
    }
}
