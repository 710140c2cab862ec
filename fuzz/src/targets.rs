//! The bodies of mlt's fuzz targets: each takes the fuzzer's bytes and feeds what a host or
//! a user could pass to the library, then checks what it got back. A target panics on a
//! finding (libFuzzer reports a panic as a crash): an internal error from the C ABI (a panic
//! it caught), a result breaking the API's promises, or a panic in a loader.
//!
//! This file is shared: the fuzz crate (`fuzz/src/lib.rs`) builds the libFuzzer binaries from
//! it, and the main crate's `tests/fuzz_corpus.rs` includes it (`#[path]`) to replay the
//! committed corpora and regression inputs under `cargo test`. So it uses only what both
//! crates have: `mlt` and `arbitrary`.
//!
//! Structured inputs are read with `arbitrary::Unstructured`. Once the bytes run out its
//! readers give the low end of each range, so every choice below puts the ordinary case at 0
//! and the unusual ones after it: a short input is a plain, valid request.

use arbitrary::Unstructured;
use mlt::MltStatus::{self, *};
use mlt::RenderSettings;
use mlt::capi::*;
use mlt::params::{Kind, Parameter, Parameters, Value};
use std::cell::Cell;
use std::ffi::{CStr, c_void};
use std::mem::{MaybeUninit, offset_of, size_of};
use std::path::{Path, PathBuf};
use std::ptr::{null, null_mut};

type Result<T> = arbitrary::Result<T>;

// ---------------------------------------------------------------------------------------
// Reading values
// ---------------------------------------------------------------------------------------

/// A float for a field whose sensible values lie in `[lo, hi]`: usually one of those, often
/// a small integer, sometimes a value that breaks something (NaN, ±∞, the extremes, a
/// subnormal, -0) or any bit pattern.
fn float(u: &mut Unstructured, lo: f32, hi: f32) -> Result<f32> {
    Ok(match u.arbitrary::<u8>()? {
        0..=191 => lo + (hi - lo) * (u.arbitrary::<u16>()? as f32 / u16::MAX as f32),
        192..=215 => u.int_in_range(-4i8..=4)? as f32,
        216 => f32::NAN,
        217 => f32::INFINITY,
        218 => f32::NEG_INFINITY,
        219 => f32::MAX,
        220 => -f32::MAX,
        221 => f32::MIN_POSITIVE,
        222 => 1e-40,
        223 => -0.0,
        224 => 1e20,
        225 => -1e20,
        226 => 1e-20,
        227 => f32::EPSILON,
        _ => f32::from_bits(u.arbitrary()?),
    })
}

fn float3(u: &mut Unstructured, lo: f32, hi: f32) -> Result<[f32; 3]> {
    Ok([float(u, lo, hi)?, float(u, lo, hi)?, float(u, lo, hi)?])
}

/// An enum value from C: usually one of `0..count`, sometimes anything.
fn enum_int(u: &mut Unstructured, count: i32) -> Result<i32> {
    Ok(match u.int_in_range(0u8..=15)? {
        0..=13 => u.int_in_range(0..=count - 1)?,
        14 => -1,
        _ => u.arbitrary()?,
    })
}

/// A C boolean: usually 0 or 1, sometimes another value (refused).
fn flag(u: &mut Unstructured) -> Result<u32> {
    Ok(match u.int_in_range(0u8..=15)? {
        0..=6 => 0,
        7..=14 => 1,
        _ => u.arbitrary()?,
    })
}

/// A count in `0..=max`, sometimes one past it.
fn count(u: &mut Unstructured, max: u32) -> Result<u32> {
    Ok(if u.ratio(1, 16)? {
        max + 1
    } else {
        u.int_in_range(0..=max)?
    })
}

/// The `struct_size` a host puts in a `T`: usually `sizeof(T)`, sometimes the size of an
/// earlier layout (`earlier`: where its fields end), 0 (never initialized), a newer size
/// or anything. Memory-safe whatever it says: mlt reads only layouts it knows, and those
/// are at most `sizeof(T)`, which is what each buffer here holds.
fn struct_size<T>(u: &mut Unstructured, earlier: &[usize]) -> Result<u32> {
    let size = size_of::<T>();
    let padded = |end: usize| end.next_multiple_of(std::mem::align_of::<T>()) as u32;
    Ok(match u.int_in_range(0u8..=63)? {
        0..=57 => size as u32,
        58 => 0,
        59 => size as u32 + 8,
        60 => size as u32 - 4,
        61 | 62 if !earlier.is_empty() => padded(earlier[u.choose_index(earlier.len())?]),
        _ => u.arbitrary()?,
    })
}

/// A C struct as its `mlt_*_init` leaves it (what a host's `mlt_*_default` does).
fn initialized<T>(init: unsafe extern "C" fn(*mut T, usize) -> MltStatus) -> T {
    let mut value = MaybeUninit::<T>::uninit();
    // SAFETY: the buffer holds size_of::<T>() writable bytes.
    let status = unsafe { init(value.as_mut_ptr(), size_of::<T>()) };
    assert_eq!(status, MLT_STATUS_OK, "{}", last_error());
    // SAFETY: the initializer wrote every field (checked above).
    unsafe { value.assume_init() }
}

fn last_error() -> String {
    // SAFETY: mlt returns a NUL-terminated string valid until its next call on this thread.
    unsafe { CStr::from_ptr(mlt_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// Whether to print what each input decodes to (`MLT_FUZZ_TRACE=1`), to triage a finding.
fn tracing() -> bool {
    static TRACE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *TRACE.get_or_init(|| std::env::var_os("MLT_FUZZ_TRACE").is_some_and(|v| v == "1"))
}

/// Checks a C call's status: an internal error is a finding (a panic the guard caught, or a
/// failure on bad input that should have been INVALID_ARGUMENT), and every failure must
/// come with a message.
fn check_status(status: MltStatus, call: &str) {
    let message = last_error();
    assert_ne!(
        status, MLT_STATUS_INTERNAL_ERROR,
        "{call} failed with an internal error: {message}"
    );
    if status != MLT_STATUS_OK {
        assert!(
            !message.is_empty(),
            "{call} returned {status:?} without a message"
        );
    }
}

/// A pointer to `values`, or NULL with one chance in 32 (refused when its count is not 0).
fn pointer<T>(u: &mut Unstructured, values: &[T]) -> Result<*const T> {
    Ok(if u.ratio(1, 32)? {
        null()
    } else {
        values.as_ptr()
    })
}

/// An attribute array of `per_vertex` floats per vertex: none, complete, or (sometimes) of
/// another length.
fn attribute(
    u: &mut Unstructured,
    vertices: usize,
    per_vertex: usize,
    lo: f32,
    hi: f32,
) -> Result<Vec<f32>> {
    let len = match u.int_in_range(0u8..=15)? {
        0..=9 => 0,
        10..=14 => vertices * per_vertex,
        _ => u.int_in_range(0..=vertices * per_vertex + per_vertex)?,
    };
    (0..len).map(|_| float(u, lo, hi)).collect()
}

// ---------------------------------------------------------------------------------------
// capi_scene: a scene description through the C ABI, then renders of it
// ---------------------------------------------------------------------------------------

/// Tiny sizes keep one execution to about a millisecond.
const MAX_VERTICES: usize = 9;
const MAX_TRIANGLES: usize = 6;
const MAX_MATERIALS: usize = 3;
const MAX_TEXTURES: usize = 2;
const MAX_TEXTURE_SIDE: u32 = 3;
const MAX_ENVIRONMENT_SIDE: u32 = 4;
const MAX_LIGHTS: usize = 3;

/// Texels as the host holds them: bytes or floats, of exactly the length mlt will read.
#[derive(Debug)]
enum Texels {
    U8(Vec<u8>),
    F32(Vec<f32>),
}

/// Every buffer an `MltSceneDesc` points into, kept alive for the call.
#[derive(Debug)]
struct HostScene {
    positions: Vec<f32>,
    indices: Vec<u32>,
    material_ids: Vec<u32>,
    materials: Vec<MltMaterial>,
    texels: Vec<Texels>,
    textures: Vec<MltTexture>,
    environment_pixels: Vec<f32>,
    environment: Option<MltEnvironment>,
    sun: Option<MltSun>,
    lights: Vec<MltPunctualLight>,
    normals: Vec<f32>,
    texcoords: Vec<f32>,
    tangents: Vec<f32>,
    colors: Vec<f32>,
}

/// The material parameters whose values are drawn from a range of their own rather than
/// their declared one (which for these is unbounded above): dim-to-bright emission, common
/// indices of refraction and Abbe numbers, normal scales of either sign.
const MATERIAL_LIMITS: &[(&str, f64, f64)] = &[
    ("emission", 0.0, 20.0),
    ("ior", 1.0, 3.0),
    ("alpha_cutoff", 0.0, 1.0),
    ("normal_scale", -2.0, 2.0),
    ("clearcoat_normal_scale", -2.0, 2.0),
    ("abbe_number", 0.0, 90.0),
    ("thickness", 0.0, 2.0),
    ("attenuation_distance", 0.01, 10.0),
];

/// A texture slot: mostly none; else a texture's index, or the index past the last (refused),
/// with a transform.
fn texture_slot(u: &mut Unstructured, textures: usize) -> Result<Value> {
    let may_have_one = textures > 0 || u.ratio(1, 8)?;
    if !may_have_one || u.ratio(5, 8)? {
        return Ok(Value::Texture(None));
    }
    Ok(Value::Texture(Some(mlt::TextureRef {
        texture: u.int_in_range(0..=textures as u32)?,
        offset: [float(u, -1.0, 1.0)?, float(u, -1.0, 1.0)?],
        rotation: float(u, -4.0, 4.0)?,
        scale: [float(u, -2.0, 4.0)?, float(u, -2.0, 4.0)?],
        // Set 1 without `texcoords1`, or 2, is refused.
        texcoord: u.int_in_range(0..=2)?,
    })))
}

/// A material, each declared parameter drawn by `parameter`, then as a C host may pass it:
/// an older layout's `struct_size`, or values of the C types that Rust's types do not hold
/// (an unknown kind or alpha mode, a boolean other than 0 and 1, a texture index below -1;
/// refused).
fn material(u: &mut Unstructured, textures: usize) -> Result<MltMaterial> {
    let mut rust = mlt::Material::default();
    for p in mlt::Material::parameters() {
        let value = match p.kind {
            Kind::Texture => texture_slot(u, textures)?,
            _ => parameter(u, p, MATERIAL_LIMITS)?,
        };
        rust.set(p.name, value)
            .expect("a value of the parameter's type");
    }
    let mut m = MltMaterial::from(&rust);
    m.struct_size = struct_size::<MltMaterial>(u, &[offset_of!(MltMaterial, metallic)])?;
    if u.ratio(1, 16)? {
        m.kind = enum_int(u, 4)?;
    }
    if u.ratio(1, 16)? {
        m.alpha_mode = enum_int(u, 2)?;
    }
    if u.ratio(1, 16)? {
        m.energy_compensation = flag(u)?;
    }
    if u.ratio(1, 16)? {
        m.normal_texture.texture = u.arbitrary()?;
    }
    Ok(m)
}

fn texture(u: &mut Unstructured) -> Result<(MltTexture, Texels)> {
    let mut t = initialized(mlt_texture_init);
    t.struct_size = struct_size::<MltTexture>(u, &[])?;
    t.width = count(u, MAX_TEXTURE_SIDE)?;
    t.height = count(u, MAX_TEXTURE_SIDE)?;
    t.channels = u.int_in_range(0..=5)?;
    t.texel_type = enum_int(u, 2)?;
    t.encoding = enum_int(u, 2)?;
    t.wrap_u = enum_int(u, 3)?;
    t.wrap_v = enum_int(u, 3)?;
    t.filter = enum_int(u, 2)?;
    // Exactly the values mlt reads (width × height × channels of the texel type).
    let len = (t.width * t.height * t.channels) as usize;
    let texels = if t.texel_type == MLT_TEXEL_F32 {
        Texels::F32(
            (0..len)
                .map(|_| float(u, 0.0, 4.0))
                .collect::<Result<_>>()?,
        )
    } else {
        Texels::U8((0..len).map(|_| u.arbitrary()).collect::<Result<_>>()?)
    };
    Ok((t, texels))
}

fn environment(u: &mut Unstructured) -> Result<(MltEnvironment, Vec<f32>)> {
    let mut e = initialized(mlt_environment_init);
    e.struct_size = struct_size::<MltEnvironment>(u, &[])?;
    e.width = u.int_in_range(1..=MAX_ENVIRONMENT_SIDE)?;
    e.height = u.int_in_range(1..=MAX_ENVIRONMENT_SIDE)?;
    if u.ratio(1, 16)? {
        e.width = 0;
    }
    e.rotation_degrees = float(u, -360.0, 360.0)?;
    e.scale = float(u, 0.0, 4.0)?;
    let len = (e.width * e.height * 3) as usize;
    let pixels = (0..len)
        .map(|_| float(u, 0.0, 4.0))
        .collect::<Result<_>>()?;
    Ok((e, pixels))
}

fn sun(u: &mut Unstructured) -> Result<MltSun> {
    let mut s = initialized(mlt_sun_init);
    s.struct_size = struct_size::<MltSun>(u, &[])?;
    s.direction = float3(u, -1.0, 1.0)?;
    s.angular_radius_degrees = float(u, 0.0, 10.0)?;
    s.irradiance = float3(u, 0.0, 4.0)?;
    Ok(s)
}

fn punctual_light(u: &mut Unstructured) -> Result<MltPunctualLight> {
    let mut l = initialized(mlt_punctual_light_init);
    l.struct_size = struct_size::<MltPunctualLight>(u, &[])?;
    l.kind = enum_int(u, 3)?;
    l.position = float3(u, -2.0, 2.0)?;
    l.direction = float3(u, -1.0, 1.0)?;
    l.intensity = float3(u, 0.0, 10.0)?;
    l.inner_cone_degrees = float(u, 0.0, 90.0)?;
    l.outer_cone_degrees = float(u, 0.0, 90.0)?;
    Ok(l)
}

fn host_scene(u: &mut Unstructured) -> Result<HostScene> {
    let vertices = u.int_in_range(3..=MAX_VERTICES)?;
    // Coordinates mostly in [-2, 2], often small integers, so triangles share corners.
    let positions = (0..vertices * 3)
        .map(|_| float(u, -2.0, 2.0))
        .collect::<Result<Vec<_>>>()?;
    let triangles = u.int_in_range(1..=MAX_TRIANGLES)?;
    let index_count = if u.ratio(1, 32)? {
        triangles * 3 + 1
    } else {
        triangles * 3
    };
    let indices = (0..index_count)
        .map(|_| {
            Ok(if u.ratio(1, 32)? {
                u.arbitrary()?
            } else {
                u.int_in_range(0..=vertices as u32 - 1)?
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let texture_count = u.int_in_range(0..=MAX_TEXTURES)?;
    let (textures, texels) = (0..texture_count)
        .map(|_| texture(u))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    let material_count = u.int_in_range(1..=MAX_MATERIALS)?;
    let materials = (0..material_count)
        .map(|_| material(u, texture_count))
        .collect::<Result<Vec<_>>>()?;
    let material_ids = match u.int_in_range(0u8..=15)? {
        0..=11 => (0..triangles)
            .map(|_| u.int_in_range(0..=material_count as u32 - 1))
            .collect::<Result<Vec<_>>>()?,
        12..=13 => Vec::new(),
        14 => vec![0; triangles + 1],
        _ => vec![material_count as u32; triangles],
    };
    let (environment, environment_pixels) = if u.ratio(1, 4)? {
        let (e, pixels) = environment(u)?;
        (Some(e), pixels)
    } else {
        (None, Vec::new())
    };
    let sun = if u.ratio(1, 5)? { Some(sun(u)?) } else { None };
    let lights = (0..u.int_in_range(0..=MAX_LIGHTS)?)
        .map(|_| punctual_light(u))
        .collect::<Result<Vec<_>>>()?;
    Ok(HostScene {
        normals: attribute(u, vertices, 3, -1.0, 1.0)?,
        texcoords: attribute(u, vertices, 2, -1.0, 2.0)?,
        tangents: attribute(u, vertices, 4, -1.0, 1.0)?,
        colors: attribute(u, vertices, 4, 0.0, 1.0)?,
        positions,
        indices,
        material_ids,
        materials,
        texels,
        textures,
        environment_pixels,
        environment,
        sun,
        lights,
    })
}

/// The description of `host`'s buffers, with a few pointers and sizes the fuzzer may break.
fn scene_desc(u: &mut Unstructured, host: &mut HostScene) -> Result<MltSceneDesc> {
    for (t, texels) in host.textures.iter_mut().zip(&host.texels) {
        t.texels = match texels {
            Texels::U8(v) => pointer(u, v)?.cast(),
            Texels::F32(v) => pointer(u, v)?.cast(),
        };
    }
    if let Some(e) = &mut host.environment {
        e.pixels = pointer(u, &host.environment_pixels)?;
    }
    let mut d = initialized(mlt_scene_desc_init);
    d.struct_size = struct_size::<MltSceneDesc>(
        u,
        &[
            offset_of!(MltSceneDesc, environment),
            offset_of!(MltSceneDesc, normals),
        ],
    )?;
    d.positions = pointer(u, &host.positions)?;
    d.positions_len = host.positions.len();
    d.indices = pointer(u, &host.indices)?;
    d.indices_len = host.indices.len();
    d.material_ids = pointer(u, &host.material_ids)?;
    d.material_ids_len = host.material_ids.len();
    d.materials = pointer(u, &host.materials)?;
    d.materials_len = host.materials.len();
    d.backend = enum_int(u, 2)?;
    d.environment = host.environment.as_ref().map_or(null(), |e| e as *const _);
    d.sun = host.sun.as_ref().map_or(null(), |s| s as *const _);
    d.punctual_lights = pointer(u, &host.lights)?;
    d.punctual_lights_len = host.lights.len();
    d.normals = pointer(u, &host.normals)?;
    d.normals_len = host.normals.len();
    d.texcoords = pointer(u, &host.texcoords)?;
    d.texcoords_len = host.texcoords.len();
    d.tangents = pointer(u, &host.tangents)?;
    d.tangents_len = host.tangents.len();
    d.colors = pointer(u, &host.colors)?;
    d.colors_len = host.colors.len();
    d.textures = pointer(u, &host.textures)?;
    d.textures_len = host.textures.len();
    Ok(d)
}

fn camera(u: &mut Unstructured) -> Result<MltCamera> {
    let mut c = initialized(mlt_camera_init);
    c.struct_size = struct_size::<MltCamera>(u, &[])?;
    if u.ratio(1, 2)? {
        c.eye = float3(u, -4.0, 4.0)?;
        c.target = float3(u, -2.0, 2.0)?;
        c.up = float3(u, -1.0, 1.0)?;
        c.fov_y_deg = float(u, 1.0, 179.0)?;
        c.lens_radius = float(u, 0.0, 0.5)?;
        c.focus_distance = float(u, 0.0, 8.0)?;
    }
    Ok(c)
}

/// The settings that scale a valid render's work, and the values drawn for them: an image of
/// at most 4 × 4, at most 3 samples or mutations per pixel, a bootstrap of at most 32
/// samples (0, the automatic size, is at least 2^16), short paths and ERPT chains, and
/// (mostly: each takes its default, when inside, half the time) the process's shared pool
/// and no time limit. Every other setting, a new one too, is drawn over its declared range.
const WORK_LIMITS: &[(&str, f64, f64)] = &[
    ("width", 1.0, 4.0),
    ("height", 1.0, 4.0),
    ("samples_per_pixel", 0.0, 3.0),
    ("mutations_per_pixel", 0.0, 3.0),
    ("max_depth", 0.0, 6.0),
    ("threads", 0.0, 1.0),
    ("time_limit_seconds", 0.0, 1e-3),
    ("bootstrap_samples", 1.0, 32.0),
    ("chains", 1.0, 16.0),
    ("direct_samples_per_mutation", 0.0, 2.0),
    ("erpt_chain_length", 1.0, 8.0),
    // 0 is the automatic deposit energy, whose pre-pass traces at least 1024 BDPT samples
    // (about 15 ms here; it was 2^14 until this target showed the cost): rare (one of the
    // float's edge values), to keep executions short. A small one starts many chains (see
    // `render`).
    ("erpt_deposit_energy", 0.01, 10.0),
    ("filter_buffers", 0.0, 8.0),
    ("filter_radius", 1.0, 4.0),
    ("mutation_weights", 0.0, 2.0),
];

/// A value of the declared parameter `p`: sometimes one outside its range (it must be
/// refused), else within its limit in `limits` or its declared range.
fn parameter<S>(
    u: &mut Unstructured,
    p: &Parameter<S>,
    limits: &[(&str, f64, f64)],
) -> Result<Value> {
    if let Some(bad) = p.outside_value()
        && u.ratio(1, 32)?
    {
        return Ok(bad);
    }
    let limit = limits
        .iter()
        .find(|&&(name, ..)| name == p.name)
        .map(|&(_, lo, hi)| (lo, hi));
    let (lo, hi) = limit
        .or(p.range.map(|r| (r.min, r.max)))
        .unwrap_or((0.0, 16.0));
    let default = (p.default)();
    let inside = match default {
        Value::Int(v) => (lo..=hi).contains(&(v as f64)),
        Value::Float(v) => (lo..=hi).contains(&v),
        _ => true,
    };
    if inside && u.ratio(1, 2)? {
        return Ok(default);
    }
    Ok(match p.kind {
        Kind::U32 if p.range.is_none() && limit.is_none() => {
            Value::Int(u.arbitrary::<u32>()?.into())
        }
        Kind::U64 if p.range.is_none() && limit.is_none() => {
            Value::Int(u.arbitrary::<u64>()?.into())
        }
        Kind::U32 | Kind::U64 => Value::Int(u.int_in_range(lo as u64..=hi as u64)?.into()),
        Kind::F32 | Kind::F64 => Value::Float(float(u, lo as f32, hi as f32)?.into()),
        Kind::Bool => Value::Bool(u.arbitrary()?),
        Kind::Choice(choices) => Value::Choice(choices.names[u.choose_index(choices.names.len())?]),
        Kind::F32x3 => Value::Vec3([
            float(u, lo as f32, hi as f32)?,
            float(u, lo as f32, hi as f32)?,
            float(u, lo as f32, hi as f32)?,
        ]),
        Kind::Texture => Value::Texture(None),
        Kind::F32x4 => Value::Floats([
            float(u, lo as f32, hi as f32)?,
            float(u, lo as f32, hi as f32)?,
            float(u, lo as f32, hi as f32)?,
            float(u, lo as f32, hi as f32)?,
        ]),
    })
}

/// Render settings, each declared setting drawn by `parameter`, then as a C host may pass
/// them: an older layout's `struct_size`, or values of the C types that Rust's types do not
/// hold (an unknown algorithm, a boolean other than 0 and 1; refused).
fn settings(u: &mut Unstructured) -> Result<MltRenderSettings> {
    let mut rust = RenderSettings::default();
    for p in RenderSettings::parameters() {
        let value = parameter(u, p, WORK_LIMITS)?;
        rust.set(p.name, value)
            .expect("a value of the setting's type");
    }
    let mut s = MltRenderSettings::from(&rust);
    s.struct_size =
        struct_size::<MltRenderSettings>(u, &[offset_of!(MltRenderSettings, filter_buffers)])?;
    if u.ratio(1, 16)? {
        s.algorithm = enum_int(u, 7)?;
    }
    if u.ratio(1, 16)? {
        s.spectral = flag(u)?;
    }
    Ok(s)
}

/// What the progress callback saw: it cancels the render when `cancel_after` reaches 0, and
/// records any fraction outside [0, 1] (a panic cannot unwind out of an `extern "C"` fn).
struct Progress {
    cancel_after: Cell<u32>,
    bad_fraction: Cell<Option<f32>>,
}

unsafe extern "C" fn progress(fraction: f32, user_data: *mut c_void) -> bool {
    // SAFETY: `user_data` is the `Progress` passed with this callback, alive for the call.
    let p = unsafe { &*user_data.cast::<Progress>() };
    if !(0.0..=1.0).contains(&fraction) {
        p.bad_fraction.set(Some(fraction));
    }
    let left = p.cancel_after.get();
    p.cancel_after.set(left.saturating_sub(1));
    left > 0
}

fn render(u: &mut Unstructured, scene: *const MltScene) -> Result<()> {
    let camera = camera(u)?;
    let settings = settings(u)?;
    let pixels = (settings.width * settings.height * 3) as usize;
    // The true length of the buffer: usually what the image needs, sometimes less.
    let mut image = vec![-7.0f32; if u.ratio(1, 32)? { pixels / 2 } else { pixels }];
    // The callback (called every 50 ms) cancels after a few calls: a render whose work the
    // settings do not bound, ERPT's with a deposit energy far below its paths' energies,
    // stops there, and one that does not stop is a hang. ERPT always gets it; the others
    // now and then run without one.
    let state = Progress {
        cancel_after: Cell::new(u.int_in_range(0..=3)?),
        bad_fraction: Cell::new(None),
    };
    let callback: MltProgressCallback =
        if settings.algorithm != MLT_ALGORITHM_ERPT && u.ratio(1, 8)? {
            None
        } else {
            Some(progress)
        };
    let mut stats = initialized(mlt_render_stats_init);
    stats.struct_size = struct_size::<MltRenderStats>(
        u,
        &[
            offset_of!(MltRenderStats, filter_changed_fraction),
            offset_of!(MltRenderStats, normalization_samples),
        ],
    )?;
    let stats_out: *mut MltRenderStats = if u.ratio(1, 2)? {
        &mut stats
    } else {
        null_mut()
    };
    // SAFETY: every pointer is valid for the length passed with it; `state` outlives the
    // call.
    let status = unsafe {
        mlt_render_ex(
            scene,
            &camera,
            &settings,
            image.as_mut_ptr(),
            image.len(),
            callback,
            (&raw const state).cast_mut().cast(),
            stats_out,
        )
    };
    if tracing() {
        eprintln!(
            "{camera:#?}\n{settings:#?}\nmlt_render_ex: {status:?} {}\n{image:?}",
            last_error()
        );
    }
    check_status(status, "mlt_render_ex");
    assert_eq!(
        state.bad_fraction.get(),
        None,
        "the progress callback got a fraction outside [0, 1]"
    );
    if matches!(
        status,
        MLT_STATUS_OK | MLT_STATUS_CANCELLED | MLT_STATUS_TIME_LIMIT_REACHED
    ) {
        // A spectral render's colour comes from a few wavelengths per sample, converted
        // from XYZ to sRGB: an unbiased estimate of a colour, which may be out of gamut
        // (negative) until it converges. RGB renders only add non-negative radiance.
        let bad = |v: f32| v.is_nan() || (settings.spectral == 0 && v < 0.0);
        if let Some((i, v)) = image.iter().enumerate().find(|(_, v)| bad(**v)) {
            panic!("mlt_render_ex returned {status:?} with pixel value {i} = {v}");
        }
    } else {
        assert!(
            image.iter().all(|&v| v == -7.0),
            "mlt_render_ex failed ({status:?}) but wrote the image"
        );
    }
    Ok(())
}

/// Bytes → an `MltSceneDesc` (a few triangles with any coordinates, indices and material
/// ids; materials, textures, environment, sun and punctual lights with any field values;
/// wrong enums, struct sizes and NULL pointers now and then) → `mlt_scene_create`; when it
/// succeeds, `mlt_scene_get_info` and one or two renders with fuzzed camera and settings
/// (see [`settings`]), then `mlt_scene_release`.
pub fn capi_scene(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let _ = capi_scene_inner(&mut u);
}

fn capi_scene_inner(u: &mut Unstructured) -> Result<()> {
    let mut host = host_scene(u)?;
    let desc = scene_desc(u, &mut host)?;
    let sentinel = 0x5eed as *mut MltScene;
    let mut scene = sentinel;
    // SAFETY: every pointer in `desc` is NULL or valid for the length passed with it (the
    // lengths are the buffers' own); `scene` is writable.
    let status = unsafe { mlt_scene_create(&desc, &mut scene) };
    if tracing() {
        eprintln!(
            "{host:#?}\n{desc:#?}\nmlt_scene_create: {status:?} {}",
            last_error()
        );
    }
    check_status(status, "mlt_scene_create");
    if status != MLT_STATUS_OK {
        assert_eq!(scene, sentinel, "a failed mlt_scene_create wrote *out");
        return Ok(());
    }
    let result = use_scene(u, scene, &host);
    // SAFETY: created above, released once.
    unsafe { mlt_scene_release(scene) };
    result
}

fn use_scene(u: &mut Unstructured, scene: *mut MltScene, host: &HostScene) -> Result<()> {
    let mut info = initialized(mlt_scene_info_init);
    // SAFETY: a live scene and a writable, initialized struct.
    let status = unsafe { mlt_scene_get_info(scene, &mut info) };
    check_status(status, "mlt_scene_get_info");
    assert_eq!(status, MLT_STATUS_OK);
    assert_eq!(info.triangle_count as usize, host.indices.len() / 3);
    assert!(info.degenerate_triangle_count <= info.triangle_count);
    assert!(info.emitter_count <= info.triangle_count);
    render(u, scene)?;
    if u.ratio(1, 4)? {
        render(u, scene)?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// ray_queries: mlt_intersect and mlt_occluded
// ---------------------------------------------------------------------------------------

/// A C scene handle shared by every execution (the scene is immutable and `Sync`).
struct SharedScene(*mut MltScene);
// SAFETY: an `MltScene` is immutable after creation and safe to query from any thread.
unsafe impl Send for SharedScene {}
// SAFETY: as above.
unsafe impl Sync for SharedScene {}

/// The fixed scene of the ray queries: the six faces of the box [-1, 1]³, a triangle in
/// its middle, a degenerate (zero-area) triangle and a huge one far away.
fn fixed_scene_triangles() -> (Vec<f32>, Vec<u32>) {
    let mut positions = Vec::new();
    for corner in 0..8 {
        for axis in 0..3 {
            positions.push(if corner >> axis & 1 == 1 { 1.0 } else { -1.0 });
        }
    }
    let mut indices = vec![
        0, 2, 1, 1, 2, 3, // -z
        4, 5, 6, 5, 7, 6, // +z
        0, 1, 4, 1, 5, 4, // -y
        2, 6, 3, 3, 6, 7, // +y
        0, 4, 2, 2, 4, 6, // -x
        1, 3, 5, 3, 7, 5, // +x
    ];
    let extra: [[f32; 3]; 9] = [
        [-0.5, -0.5, 0.0],
        [0.5, -0.5, 0.0],
        [0.0, 0.5, 0.0],
        [0.2, 0.2, 0.2],
        [0.4, 0.4, 0.4],
        [0.6, 0.6, 0.6],
        [-1e9, 1e8, 1e9],
        [1e9, 1e8, 1e9],
        [0.0, 1e8, -1e9],
    ];
    for p in extra {
        indices.push((positions.len() / 3) as u32);
        positions.extend_from_slice(&p);
    }
    (positions, indices)
}

fn create_scene(positions: &[f32], indices: &[u32]) -> (MltStatus, *mut MltScene) {
    let material = initialized(mlt_material_init);
    let mut desc = initialized(mlt_scene_desc_init);
    desc.positions = positions.as_ptr();
    desc.positions_len = positions.len();
    desc.indices = indices.as_ptr();
    desc.indices_len = indices.len();
    desc.materials = &material;
    desc.materials_len = 1;
    let mut scene = null_mut();
    // SAFETY: the arrays are valid for the lengths given; `scene` is writable.
    let status = unsafe { mlt_scene_create(&desc, &mut scene) };
    check_status(status, "mlt_scene_create");
    (status, scene)
}

fn fixed_scene() -> *const MltScene {
    static SCENE: std::sync::OnceLock<SharedScene> = std::sync::OnceLock::new();
    SCENE
        .get_or_init(|| {
            let (positions, indices) = fixed_scene_triangles();
            let (status, scene) = create_scene(&positions, &indices);
            assert_eq!(status, MLT_STATUS_OK, "{}", last_error());
            SharedScene(scene)
        })
        .0
}

fn ray(u: &mut Unstructured) -> Result<MltRay> {
    Ok(MltRay {
        origin: float3(u, -3.0, 3.0)?,
        tmin: if u.ratio(1, 2)? {
            0.0
        } else {
            float(u, 0.0, 2.0)?
        },
        direction: float3(u, -1.0, 1.0)?,
        tmax: if u.ratio(1, 2)? {
            f32::INFINITY
        } else {
            float(u, 0.0, 10.0)?
        },
    })
}

/// The ray's hit with triangle `[a, b, c]` in double precision (Möller–Trumbore), if it is
/// clearly inside the triangle and clearly within [tmin, tmax]: a hit the backend must not
/// miss whatever its rounding. Returns its t. Only for coordinates single precision can
/// work with (origin within 1e6, vertices within 1e9), and triangles the scene keeps: one
/// whose normal's length is 0 or overflows in single precision is degenerate.
fn clear_hit(ray: &MltRay, [a, b, c]: [[f64; 3]; 3]) -> Option<f64> {
    let far = |p: [f64; 3], limit: f64| p.iter().any(|x| x.is_nan() || x.abs() > limit);
    if far(ray.origin.map(f64::from), 1e6) || far(a, 1e9) || far(b, 1e9) || far(c, 1e9) {
        return None;
    }
    let single = |p: [f64; 3], q: [f64; 3]| [0, 1, 2].map(|k| (p[k] - q[k]) as f32);
    let (e1, e2) = (single(b, a), single(c, a));
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let sub = |p: [f64; 3], q: [f64; 3]| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let cross = |p: [f64; 3], q: [f64; 3]| {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let o = ray.origin.map(f64::from);
    let d = ray.direction.map(f64::from);
    let (e1, e2) = (sub(b, a), sub(c, a));
    let p = cross(d, e2);
    let det = dot(e1, p);
    let scale = dot(e1, e1).sqrt() * dot(e2, e2).sqrt() * dot(d, d).sqrt();
    // Away from grazing (the angle to the plane above 0.6°): single precision's t and
    // barycentrics are then within the tolerances below.
    if det.is_nan() || det.abs() <= 1e-2 * scale {
        return None;
    }
    let s = sub(o, a);
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let v = dot(d, q) / det;
    let t = dot(e2, q) / det;
    let margin = 1e-3;
    let (tmin, tmax) = (ray.tmin as f64, ray.tmax as f64);
    let inside = u > margin && v > margin && u + v < 1.0 - margin;
    let within = t > tmin + margin * (1.0 + tmin.abs()) && t < tmax - margin * (1.0 + t.abs());
    (inside && within).then_some(t)
}

/// Bytes → a batch of rays (any origins, directions and bounds, NaN and ∞ among them) →
/// `mlt_intersect` and `mlt_occluded` against the fixed scene or, for one input in four, a
/// fuzzed one (up to 6 triangles with any coordinates). Every hit must be on a triangle,
/// inside it and within the ray's bounds; a ray is occluded exactly when it hits; and no
/// clear hit (double precision, away from edges and bounds) may be missed.
pub fn ray_queries(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let _ = ray_queries_inner(&mut u);
}

fn ray_queries_inner(u: &mut Unstructured) -> Result<()> {
    let fuzzed = if u.ratio(1, 4)? {
        let triangles = u.int_in_range(1..=6)?;
        let positions = (0..triangles * 9)
            .map(|_| float(u, -2.0, 2.0))
            .collect::<Result<Vec<_>>>()?;
        let indices: Vec<u32> = (0..triangles as u32 * 3).collect();
        let (status, scene) = create_scene(&positions, &indices);
        if status != MLT_STATUS_OK {
            return Ok(());
        }
        Some((scene, positions, indices))
    } else {
        None
    };
    let result = match &fuzzed {
        Some((scene, positions, indices)) => query(u, *scene, positions, indices),
        None => {
            let (positions, indices) = fixed_scene_triangles();
            query(u, fixed_scene(), &positions, &indices)
        }
    };
    if let Some((scene, ..)) = fuzzed {
        // SAFETY: created above, released once.
        unsafe { mlt_scene_release(scene) };
    }
    result
}

fn query(
    u: &mut Unstructured,
    scene: *const MltScene,
    positions: &[f32],
    indices: &[u32],
) -> Result<()> {
    let rays = (0..u.int_in_range(0..=16)?)
        .map(|_| ray(u))
        .collect::<Result<Vec<_>>>()?;
    let miss = MltHit {
        triangle_id: 7,
        t: -7.0,
        u: -7.0,
        v: -7.0,
    };
    let mut hits = vec![miss; rays.len()];
    let mut occluded = vec![7u8; rays.len()];
    // SAFETY: each array holds `rays.len()` elements.
    let status = unsafe { mlt_intersect(scene, rays.as_ptr(), rays.len(), hits.as_mut_ptr()) };
    check_status(status, "mlt_intersect");
    // SAFETY: as above.
    let occluded_status =
        unsafe { mlt_occluded(scene, rays.as_ptr(), rays.len(), occluded.as_mut_ptr()) };
    check_status(occluded_status, "mlt_occluded");
    assert_eq!(status, occluded_status, "{}", last_error());
    if status != MLT_STATUS_OK {
        assert!(hits.iter().all(|h| h.triangle_id == 7 && h.t == -7.0));
        assert!(occluded.iter().all(|&o| o == 7));
        return Ok(());
    }
    let triangle = |i: usize| {
        [0, 1, 2].map(|k| {
            let v = indices[i * 3 + k] as usize * 3;
            [0, 1, 2].map(|axis| positions[v + axis] as f64)
        })
    };
    for ((ray, hit), &occluded) in rays.iter().zip(&hits).zip(&occluded) {
        let context = format!("{ray:?}: {hit:?}, occluded {occluded}");
        assert!(occluded <= 1, "{context}");
        if hit.triangle_id == MLT_INVALID_ID {
            assert_eq!(hit.t, f32::INFINITY, "{context}");
        } else {
            assert!((hit.triangle_id as usize) < indices.len() / 3, "{context}");
            // t is computed for the unit-length ray and scaled back: allow its rounding.
            let slack = 1e-4 * hit.t.abs().max(ray.tmin.abs()) + 1e-6;
            assert!(
                hit.t >= ray.tmin - slack && hit.t <= ray.tmax + slack,
                "{context}"
            );
            assert!(hit.u >= -1e-4 && hit.v >= -1e-4, "{context}");
            assert!(hit.u + hit.v <= 1.0 + 1e-4, "{context}");
        }
        assert_eq!(
            occluded == 1,
            hit.triangle_id != MLT_INVALID_ID,
            "{context}"
        );
        for i in 0..indices.len() / 3 {
            if let Some(t) = clear_hit(ray, triangle(i)) {
                // A t beyond single precision (a tiny direction) is reported as infinity.
                let nearer = hit.t as f64 <= t * (1.0 + 1e-2) + 1e-5
                    || (t >= f32::MAX as f64 && hit.t == f32::INFINITY);
                assert!(
                    hit.triangle_id != MLT_INVALID_ID && nearer,
                    "{context}: triangle {i} is clearly hit at t = {t}"
                );
            }
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Scene files: OBJ/MTL, glTF/GLB, camera JSON
// ---------------------------------------------------------------------------------------

/// A directory of this process and thread for the files the loaders read (they take
/// paths): in /dev/shm where there is one, so no execution touches a disk.
pub fn scratch_dir() -> PathBuf {
    thread_local! {
        static DIR: PathBuf = {
            let base = Path::new("/dev/shm");
            let base = if base.is_dir() { base.to_path_buf() } else { std::env::temp_dir() };
            let thread = format!("{:?}", std::thread::current().id());
            let thread: String = thread.chars().filter(char::is_ascii_digit).collect();
            let dir = base.join(format!("mlt-fuzz-{}-{thread}", std::process::id()));
            std::fs::create_dir_all(&dir).expect("the scratch directory can be made");
            dir
        };
    }
    DIR.with(Clone::clone)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("the scratch directory is writable");
    path
}

/// A loaded scene goes on to the kernel as `mlt-render` passes it: the scene is built
/// (which validates what the loader passed through) and, if valid, a 2 × 2 image with one
/// path-traced sample per pixel is rendered from its camera (or one framing it).
fn build_and_render(data: &mlt::io::SceneData) {
    let Ok(scene) = mlt::Scene::new(&data.desc(mlt::Backend::Bvh)) else {
        return;
    };
    let camera = data.camera.unwrap_or_else(|| {
        let (min, max) = data.bounds();
        mlt::io::CameraFile::framing(min, max)
    });
    let settings = mlt::RenderSettings {
        width: 2,
        height: 2,
        algorithm: mlt::Algorithm::Path,
        samples_per_pixel: 1,
        max_depth: 3,
        ..Default::default()
    };
    let mut image = [0.0f32; 12];
    if mlt::render(&scene, &camera.camera, &settings, &mut image, None).is_ok() {
        assert!(
            image.iter().all(|v| *v >= 0.0),
            "a loaded scene rendered {image:?}"
        );
    }
}

/// Bytes → `scene.obj`, `scene.mtl` and `texture.png` (the bytes split at their first two
/// NUL bytes; the OBJ names its library and the library its images) → `io::load_scene`,
/// then [`build_and_render`].
pub fn obj_mtl(data: &[u8]) {
    let mut parts = data.splitn(3, |&b| b == 0);
    let obj = parts.next().unwrap_or_default();
    let mtl = parts.next().unwrap_or_default();
    let image = parts.next().unwrap_or_default();
    let dir = scratch_dir();
    write(&dir, "scene.mtl", mtl);
    write(&dir, "texture.png", image);
    let path = write(&dir, "scene.obj", obj);
    load_build_and_render(&path);
}

fn load_build_and_render(path: &Path) {
    let loaded = mlt::io::load_scene(path);
    if tracing() {
        match &loaded {
            Ok(data) => eprintln!(
                "loaded {} triangles, {} materials, {} textures, {} lights",
                data.triangle_count(),
                data.materials.len(),
                data.textures.len(),
                data.punctual_lights.len()
            ),
            Err(e) => eprintln!("{e}"),
        }
    }
    if let Ok(data) = loaded {
        build_and_render(&data);
    }
}

/// Bytes → `scene.glb` (if they start with GLB's magic) or `scene.gltf` → `io::load_scene`,
/// then [`build_and_render`]. Buffers and images come as data URIs or in the GLB's binary
/// chunk.
pub fn gltf_glb(data: &[u8]) {
    let name = if data.starts_with(b"glTF") {
        "scene.glb"
    } else {
        "scene.gltf"
    };
    load_build_and_render(&write(&scratch_dir(), name, data));
}

/// Bytes → `scene.camera.json` → `io::load_camera_json`; a camera it accepts must be
/// valid, and written back with `CameraFile::to_json` it must read back the same.
pub fn camera_file(data: &[u8]) {
    let dir = scratch_dir();
    let path = write(&dir, "scene.camera.json", data);
    let Ok(camera) = mlt::io::load_camera_json(&path) else {
        return;
    };
    camera.camera.validate().expect("a loaded camera is valid");
    let again = write(&dir, "again.camera.json", camera.to_json().as_bytes());
    let reloaded = mlt::io::load_camera_json(&again).expect("a written camera loads");
    assert_eq!(
        reloaded, camera,
        "the camera changed in a round trip through JSON"
    );
}
