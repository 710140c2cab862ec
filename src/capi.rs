//! The C ABI. Every export validates what the host passed, catches panics, and reports
//! failures as an [`MltStatus`] plus a thread-local message. Conventions:
//! - out-parameters are written only on success (renders also on cancel / time limit);
//! - `*_release(NULL)` is a no-op;
//! - enums coming from C are `int32_t` and range-checked (an invalid value in a Rust enum
//!   would be undefined behaviour);
//! - a null pointer is accepted only where a count of 0 makes it unused, or where the header
//!   says it is optional.

use crate::accel::Backend;
use crate::error::*;
use crate::integrators::mlt::driver::MutationWeights;
use crate::render::{self, Algorithm, RenderSettings, StopReason};
use crate::scene::{Camera, Material, MaterialKind, Scene, SceneDesc};
use glam::Vec3A;
use std::cell::RefCell;
use std::ffi::{CString, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Major version of the mlt library this header belongs to.
pub const MLT_VERSION_MAJOR: u32 = 0;
/// Minor version.
pub const MLT_VERSION_MINOR: u32 = 1;
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

/// `MltSceneDesc.backend`: mlt's own SIMD BVH (8-wide with AVX2, else 4-wide; built with
/// obvhs), always available.
pub const MLT_BACKEND_BVH: i32 = 0;
/// `MltSceneDesc.backend`: Intel Embree 3, only when mlt was built with the `embree` feature.
pub const MLT_BACKEND_EMBREE: i32 = 1;

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

/// A material. Initialize with `mlt_material_default`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltMaterial {
    /// One of `MLT_MATERIAL_*`.
    pub kind: i32,
    /// Diffuse albedo, mirror reflectance or glass tint; linear RGB, each in [0, 1].
    pub color: [f32; 3],
    /// Radiance emitted from the front (counter-clockwise) side; linear RGB, each >= 0.
    /// Any material may emit: its triangles become area lights.
    pub emission: [f32; 3],
    /// Index of refraction of a dielectric (> 0; the outside is vacuum). Must be finite for
    /// every kind; only dielectrics use it.
    pub ior: f32,
}

/// Everything `mlt_scene_create` needs, as plain arrays the host keeps ownership of (they are
/// copied; the host may free them once the call returns). Initialize with
/// `mlt_scene_desc_default`.
///
/// Degenerate triangles (zero area, e.g. repeated or collinear vertices) are accepted: they
/// keep their id but are never hit and never emit. `mlt_scene_get_info` counts them.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltSceneDesc {
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
}

/// A perspective camera. Image right is normalize(cross(target - eye, up)). Initialize with
/// `mlt_camera_default` (the Cornell box's camera).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltCamera {
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

/// How to render. Initialize with `mlt_render_settings_default`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct MltRenderSettings {
    /// Image size in pixels, each in [1, 65536].
    pub width: u32,
    pub height: u32,
    /// One of `MLT_ALGORITHM_*`; the default is `MLT_ALGORITHM_MMLT`.
    pub algorithm: i32,
    /// Path tracing and BDPT: samples per pixel, at most 2^24. 0 renders until
    /// `time_limit_seconds`. The Metropolis algorithms use `mutations_per_pixel` instead.
    pub samples_per_pixel: u32,
    /// Most scattering vertices between camera and light (0: only directly visible
    /// emitters), at most 1024.
    pub max_depth: u32,
    /// Worker threads; 0 runs on one pool of one thread per core that every such render in
    /// the process shares (renders from several host threads at once then share the cores
    /// instead of oversubscribing them); a count gives the render a pool of its own. The
    /// image does not depend on it.
    pub threads: u32,
    /// Seed of every random number; equal seeds and settings give bitwise equal images.
    pub seed: u64,
    /// Stop after this many seconds (0: no limit). Finite, at most 1e7.
    pub time_limit_seconds: f64,
    /// Metropolis: mutations per pixel, at most 2^24; 0 renders until `time_limit_seconds`.
    pub mutations_per_pixel: u32,
    /// Metropolis: independent samples that seed the chains and start the estimate of the
    /// image normalization, at most 2^28. 0 (the default) sizes it to the render: one
    /// sample per 8 planned mutations, at least 2^16 (2^18 for a render planned by its time
    /// limit alone).
    pub bootstrap_samples: u32,
    /// Metropolis: number of Markov chains, from 1 to the bootstrap samples. The image does
    /// not depend on the thread count.
    pub chains: u32,
    /// PSSMLT: probability of a large (independent) step, in [0, 1].
    pub large_step_probability: f32,
    /// PSSMLT: standard deviation of a small step in primary sample space, in (0, 1].
    pub small_step_sigma: f32,
    /// Metropolis: camera samples of the direct pass per chain mutation (both per pixel);
    /// mutations_per_pixel × this is at most 2^24. The direct pass path-traces the paths of
    /// depth 0 and 1 (emitters seen directly, direct lighting) and leaves the longer ones to
    /// the chains; the two alternate, so a render stopped early keeps the ratio. 0: no direct
    /// pass, the chains render every depth.
    pub direct_samples_per_mutation: u32,
    /// `MLT_ALGORITHM_PATH_SPACE_MLT`: relative probabilities of the mutations, indexed by
    /// `MLT_MUTATION_*` (bidirectional, lens, caustic, multi-chain). Each step picks among
    /// those the current path admits. Finite, in [0, 1e6]; the bidirectional weight must be
    /// positive.
    pub mutation_weights: [f32; 4],
    /// `MLT_ALGORITHM_ERPT`: perturbations per chain (L), in [1, 2^20]; default 10.
    pub erpt_chain_length: u32,
    /// `MLT_ALGORITHM_ERPT`: the energy (luminance) each chain step deposits, e_d; a camera
    /// sample's energy e starts floor(e / (L e_d) + uniform) chains. 0 (the default) picks
    /// e_d so that a camera sample starts one chain on average. Finite, in [0, 1e30].
    pub erpt_deposit_energy: f32,
    /// `MLT_ALGORITHM_PATH_SPACE_MLT`, 0 or 1: run a warm-up of about one mutation per pixel
    /// with `mutation_weights`, then weight each mutation by its acceptance rate there
    /// (within a factor of 8) for the rest of the render, on chains seeded anew. The weights
    /// used are reported in `MltRenderStats::mutation_weights`. Default 0.
    pub adapt_mutation_weights: u32,
    /// `MLT_ALGORITHM_PATH_SPACE_MLT` and `MLT_ALGORITHM_ERPT`, 0 or 1: perturb directions at
    /// diffuse vertices and lights by small steps in their cosine-weighted sample space
    /// instead of within a cone. Default 0.
    pub perturb_in_sample_space: u32,
    /// Metropolis algorithms and `MLT_ALGORITHM_ERPT`: the post-process filter for blotchy
    /// noise, non-local means guided by per-pixel variances measured from partial images.
    /// 0 (the default) turns it off; otherwise the number of partial images the deposits are
    /// split into, from `MLT_MIN_FILTER_BUFFERS` to `MLT_MAX_FILTER_BUFFERS` (8 is a good
    /// start; each costs 12 bytes per pixel). The image keeps its total: the filter moves
    /// energy between pixels (a local bias) to lower the error. `MltRenderStats` reports
    /// what it did.
    pub filter_buffers: u32,
    /// The filter's strength, in (0, `MLT_MAX_FILTER_STRENGTH`]; default 0.45. Higher
    /// smooths more.
    pub filter_strength: f32,
    /// The filter's search radius in pixels, in [1, `MLT_MAX_FILTER_RADIUS`]; default 7.
    pub filter_radius: u32,
    /// Metropolis: the share of the rays spent on independent samples of the chains' target,
    /// drawn alongside the chains to go on estimating the normalization b, which sets the
    /// image's brightness; in [0, 0.9], default 0.05. The image is scaled by the final
    /// estimate (over the bootstrap, these samples and, for PSSMLT and PSSMLT over BDPT, the
    /// large steps), so its brightness error shrinks as the render goes on. 0: no such
    /// samples.
    pub normalization_work_fraction: f32,
}

/// What a render did (filled by `mlt_render_ex`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct MltRenderStats {
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

/// Facts about a created scene.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct MltSceneInfo {
    pub triangle_count: u64,
    /// Triangles with zero area: never hit, never emit.
    pub degenerate_triangle_count: u64,
    /// Emissive triangles (area lights).
    pub emitter_count: u64,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    /// The `MLT_BACKEND_*` the scene was built with.
    pub backend: i32,
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

/// An immutable scene: triangles, materials, lights and the acceleration structure. Thread
/// safe: any number of threads may render and query one scene at the same time.
pub struct MltScene {
    scene: Scene,
    backend: i32,
}

/// Progress callback: called on the thread that called `mlt_render` (never from a worker),
/// about 20 times a second and once with 1.0 at the end, with the fraction done in [0, 1].
/// Return `true` to continue and `false` to cancel. It must return normally: a C++
/// exception thrown through it, or a `longjmp` out of it, skips mlt's cleanup (worker
/// threads keep running on freed memory) and is undefined behavior; catch inside the
/// callback and return `false` instead.
pub type MltProgressCallback =
    Option<unsafe extern "C" fn(fraction: f32, user_data: *mut c_void) -> bool>;

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs an export: converts errors and panics to a status and the thread's last message.
fn guard(f: impl FnOnce() -> Result<MltStatus>) -> MltStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(status)) => {
            if status == MLT_STATUS_OK {
                set_last_error("");
            }
            status
        }
        Ok(Err(error)) => {
            set_last_error(&error.message);
            error.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("internal error (please report): {what}"));
            MLT_STATUS_INTERNAL_ERROR
        }
    }
}

fn check_pointer<T>(pointer: *const T, name: &str) -> Result<()> {
    if pointer.is_null() {
        return Err(Error::invalid(format!("{name} is NULL")));
    }
    if !pointer.is_aligned() {
        return Err(Error::invalid(format!(
            "{name} ({pointer:p}) is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    Ok(())
}

/// A reference from a host pointer, after checking it is non-null and aligned.
///
/// # Safety
/// If non-null, `pointer` must point to a valid `T` for the returned lifetime.
unsafe fn host_ref<'a, T>(pointer: *const T, name: &str) -> Result<&'a T> {
    check_pointer(pointer, name)?;
    // SAFETY: non-null and aligned (checked above); validity is the caller's contract.
    Ok(unsafe { &*pointer })
}

/// A slice from a host pointer and element count; NULL is allowed only with a count of 0.
///
/// # Safety
/// If `len > 0`, `pointer` must point to `len` valid, initialized `T`s.
unsafe fn host_slice<'a, T>(pointer: *const T, len: usize, name: &str) -> Result<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    check_pointer(pointer, name)?;
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Error::invalid(format!(
            "{name} claims {len} elements, more than the address space holds"
        )));
    }
    // SAFETY: non-null, aligned, size within isize::MAX (checked); the host guarantees
    // `len` initialized elements.
    Ok(unsafe { std::slice::from_raw_parts(pointer, len) })
}

/// A mutable slice from a host pointer and element count.
///
/// # Safety
/// `pointer` must point to `len` writable `T`s not aliased during the call.
unsafe fn host_slice_mut<'a, T>(pointer: *mut T, len: usize, name: &str) -> Result<&'a mut [T]> {
    check_pointer(pointer, name)?;
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Error::invalid(format!(
            "{name} claims {len} elements, more than the address space holds"
        )));
    }
    // SAFETY: as host_slice, and the host guarantees exclusive access for the call.
    Ok(unsafe { std::slice::from_raw_parts_mut(pointer, len) })
}

/// Writes an out-parameter after checking it.
///
/// # Safety
/// If non-null, `pointer` must be valid for a write of `T`.
unsafe fn write_out<T>(pointer: *mut T, name: &str, value: T) -> Result<()> {
    check_pointer(pointer, name)?;
    // SAFETY: non-null and aligned; writable by the caller's contract.
    unsafe { pointer.write(value) };
    Ok(())
}

fn material_kind(kind: i32, index: usize) -> Result<MaterialKind> {
    match kind {
        MLT_MATERIAL_DIFFUSE => Ok(MaterialKind::Diffuse),
        MLT_MATERIAL_MIRROR => Ok(MaterialKind::Mirror),
        MLT_MATERIAL_DIELECTRIC => Ok(MaterialKind::Dielectric),
        other => Err(Error::invalid(format!(
            "desc.materials[{index}].kind is {other}; use MLT_MATERIAL_DIFFUSE (0), MLT_MATERIAL_MIRROR (1) or MLT_MATERIAL_DIELECTRIC (2)"
        ))),
    }
}

fn backend(value: i32) -> Result<Backend> {
    match value {
        MLT_BACKEND_BVH => Ok(Backend::Bvh),
        MLT_BACKEND_EMBREE => Ok(Backend::Embree),
        other => Err(Error::invalid(format!(
            "desc.backend is {other}; use MLT_BACKEND_BVH (0) or MLT_BACKEND_EMBREE (1)"
        ))),
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

fn algorithm_to_c(algorithm: Algorithm) -> i32 {
    match algorithm {
        Algorithm::Path => MLT_ALGORITHM_PATH,
        Algorithm::Bdpt => MLT_ALGORITHM_BDPT,
        Algorithm::Pssmlt => MLT_ALGORITHM_PSSMLT,
        Algorithm::Mmlt => MLT_ALGORITHM_MMLT,
        Algorithm::PssmltBdpt => MLT_ALGORITHM_PSSMLT_BDPT,
        Algorithm::PathSpaceMlt => MLT_ALGORITHM_PATH_SPACE_MLT,
        Algorithm::Erpt => MLT_ALGORITHM_ERPT,
    }
}

fn render_settings(s: &MltRenderSettings) -> Result<RenderSettings> {
    let algorithm = match s.algorithm {
        MLT_ALGORITHM_PATH => Algorithm::Path,
        MLT_ALGORITHM_BDPT => Algorithm::Bdpt,
        MLT_ALGORITHM_PSSMLT => Algorithm::Pssmlt,
        MLT_ALGORITHM_MMLT => Algorithm::Mmlt,
        MLT_ALGORITHM_PSSMLT_BDPT => Algorithm::PssmltBdpt,
        MLT_ALGORITHM_PATH_SPACE_MLT => Algorithm::PathSpaceMlt,
        MLT_ALGORITHM_ERPT => Algorithm::Erpt,
        other => {
            return Err(Error::invalid(format!(
                "settings.algorithm is {other}; use MLT_ALGORITHM_PATH (0), MLT_ALGORITHM_BDPT (1), MLT_ALGORITHM_PSSMLT (2), MLT_ALGORITHM_MMLT (3), MLT_ALGORITHM_PSSMLT_BDPT (4), MLT_ALGORITHM_PATH_SPACE_MLT (5) or MLT_ALGORITHM_ERPT (6)"
            )));
        }
    };
    Ok(RenderSettings {
        width: s.width,
        height: s.height,
        algorithm,
        samples_per_pixel: s.samples_per_pixel,
        max_depth: s.max_depth,
        seed: s.seed,
        threads: s.threads,
        time_limit_seconds: s.time_limit_seconds,
        mutations_per_pixel: s.mutations_per_pixel,
        bootstrap_samples: s.bootstrap_samples,
        chains: s.chains,
        large_step_probability: s.large_step_probability,
        small_step_sigma: s.small_step_sigma,
        direct_samples_per_mutation: s.direct_samples_per_mutation,
        mutation_weights: MutationWeights(s.mutation_weights),
        erpt_chain_length: s.erpt_chain_length,
        erpt_deposit_energy: s.erpt_deposit_energy,
        adapt_mutation_weights: flag(s.adapt_mutation_weights, "adapt_mutation_weights")?,
        perturb_in_sample_space: flag(s.perturb_in_sample_space, "perturb_in_sample_space")?,
        filter_buffers: s.filter_buffers,
        filter_strength: s.filter_strength,
        filter_radius: s.filter_radius,
        normalization_work_fraction: s.normalization_work_fraction,
    })
}

/// A C boolean setting: 0 or 1, anything else is a mistake.
fn flag(value: u32, name: &str) -> Result<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(Error::invalid(format!(
            "settings.{name} is {other}; it must be 0 or 1"
        ))),
    }
}

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

/// Fills `out` with a white diffuse, non-emissive material (ior 1.5 for dielectrics).
///
/// # Safety
/// `out` must be NULL or point to writable memory for an `MltMaterial`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_material_default(out: *mut MltMaterial) -> MltStatus {
    guard(|| {
        let value = MltMaterial {
            kind: MLT_MATERIAL_DIFFUSE,
            color: [0.8; 3],
            emission: [0.0; 3],
            ior: 1.5,
        };
        // SAFETY: forwarded contract.
        unsafe { write_out(out, "out", value) }?;
        Ok(MLT_STATUS_OK)
    })
}

/// Fills `out` with an empty description (no arrays, BVH backend).
///
/// # Safety
/// `out` must be NULL or point to writable memory for an `MltSceneDesc`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_desc_default(out: *mut MltSceneDesc) -> MltStatus {
    guard(|| {
        let value = MltSceneDesc {
            positions: std::ptr::null(),
            positions_len: 0,
            indices: std::ptr::null(),
            indices_len: 0,
            material_ids: std::ptr::null(),
            material_ids_len: 0,
            materials: std::ptr::null(),
            materials_len: 0,
            backend: MLT_BACKEND_BVH,
        };
        // SAFETY: forwarded contract.
        unsafe { write_out(out, "out", value) }?;
        Ok(MLT_STATUS_OK)
    })
}

/// Fills `out` with the Cornell box's pinhole camera.
///
/// # Safety
/// `out` must be NULL or point to writable memory for an `MltCamera`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_camera_default(out: *mut MltCamera) -> MltStatus {
    guard(|| {
        let c = Camera::default();
        let value = MltCamera {
            eye: c.eye,
            target: c.target,
            up: c.up,
            fov_y_deg: c.fov_y_deg,
            lens_radius: c.lens_radius,
            focus_distance: c.focus_distance,
        };
        // SAFETY: forwarded contract.
        unsafe { write_out(out, "out", value) }?;
        Ok(MLT_STATUS_OK)
    })
}

/// Fills `out` with the default settings: 256 x 256, multiplexed MLT with the direct pass
/// (32 mutations per pixel and one direct sample per mutation, an automatic bootstrap
/// (2^18 samples at this size), 5% of the rays for the normalization pass,
/// 1024 chains, large steps 0.3, small steps 0.01), 64 samples per pixel for path tracing and
/// BDPT, max depth 5, seed 0, all cores, no time limit, no post-process filter (strength
/// 0.45 and radius 7 when `filter_buffers` turns it on).
///
/// # Safety
/// `out` must be NULL or point to writable memory for an `MltRenderSettings`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_render_settings_default(out: *mut MltRenderSettings) -> MltStatus {
    guard(|| {
        let d = RenderSettings::default();
        let value = MltRenderSettings {
            width: d.width,
            height: d.height,
            algorithm: algorithm_to_c(d.algorithm),
            samples_per_pixel: d.samples_per_pixel,
            max_depth: d.max_depth,
            threads: d.threads,
            seed: d.seed,
            time_limit_seconds: d.time_limit_seconds,
            mutations_per_pixel: d.mutations_per_pixel,
            bootstrap_samples: d.bootstrap_samples,
            chains: d.chains,
            large_step_probability: d.large_step_probability,
            small_step_sigma: d.small_step_sigma,
            direct_samples_per_mutation: d.direct_samples_per_mutation,
            mutation_weights: d.mutation_weights.0,
            erpt_chain_length: d.erpt_chain_length,
            erpt_deposit_energy: d.erpt_deposit_energy,
            adapt_mutation_weights: d.adapt_mutation_weights as u32,
            perturb_in_sample_space: d.perturb_in_sample_space as u32,
            filter_buffers: d.filter_buffers,
            filter_strength: d.filter_strength,
            filter_radius: d.filter_radius,
            normalization_work_fraction: d.normalization_work_fraction,
        };
        // SAFETY: forwarded contract.
        unsafe { write_out(out, "out", value) }?;
        Ok(MLT_STATUS_OK)
    })
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
        let desc = unsafe { host_ref(desc, "desc") }?;
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
            unsafe { host_slice(desc.materials, desc.materials_len, "desc.materials") }?;
        let materials = host_materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                Ok(Material {
                    kind: material_kind(m.kind, i)?,
                    color: m.color,
                    emission: m.emission,
                    ior: m.ior,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let scene = Scene::new(&SceneDesc {
            positions,
            indices,
            material_ids,
            materials: &materials,
            backend: backend(desc.backend)?,
        })?;
        let handle = Box::into_raw(Box::new(MltScene {
            scene,
            backend: desc.backend,
        }));
        // SAFETY: `out` checked non-null and aligned above.
        unsafe { out.write(handle) };
        Ok(MLT_STATUS_OK)
    })
}

/// Releases a scene. NULL is a no-op. The scene must not be in use by another thread.
///
/// # Safety
/// `scene` must be NULL or a pointer returned by `mlt_scene_create` not yet released.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_release(scene: *mut MltScene) {
    if scene.is_null() {
        return;
    }
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: created by Box::into_raw in mlt_scene_create, released once (contract).
        drop(unsafe { Box::from_raw(scene) });
    }));
}

/// Facts about a scene: triangle, degenerate and emitter counts, bounds, backend.
///
/// # Safety
/// `scene` must be a live scene; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_scene_get_info(
    scene: *const MltScene,
    out: *mut MltSceneInfo,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract.
        let handle = unsafe { host_ref(scene, "scene") }?;
        let info = handle.scene.info();
        let value = MltSceneInfo {
            triangle_count: info.triangle_count as u64,
            degenerate_triangle_count: info.degenerate_triangle_count as u64,
            emitter_count: info.emitter_count as u64,
            bounds_min: info.bounds_min,
            bounds_max: info.bounds_max,
            backend: handle.backend,
        };
        // SAFETY: forwarded contract.
        unsafe { write_out(out, "out", value) }?;
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
        let handle = unsafe { host_ref(scene, "scene") }?;
        let camera: Camera = unsafe { host_ref(camera, "camera") }?.into();
        let settings = render_settings(unsafe { host_ref(settings, "settings") }?)?;
        if !stats_out.is_null() {
            check_pointer(stats_out, "stats_out")?;
        }
        settings.validate()?;
        camera.validate()?;
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
        let stats = render::render(&handle.scene, &camera, &settings, image, Some(&mut forward))?;
        if !stats_out.is_null() {
            let value = MltRenderStats {
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
            };
            // SAFETY: checked non-null and aligned above.
            unsafe { stats_out.write(value) };
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

/// Checks every ray of a batch query, naming the first bad one.
fn checked_rays(rays: &[MltRay]) -> Result<()> {
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
fn direction_length(direction: [f32; 3]) -> f64 {
    glam::DVec3::from(direction.map(f64::from)).length()
}

/// The ray with a unit direction and t scaled to match, plus the scale to map t back.
fn unit_ray(ray: &MltRay) -> (crate::accel::Ray, f64) {
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
        let handle = unsafe { host_ref(scene, "scene") }?;
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
        let handle = unsafe { host_ref(scene, "scene") }?;
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
