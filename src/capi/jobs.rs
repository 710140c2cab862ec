//! The exports of a render split into jobs (`mlt::jobs`): plan, job k of N, combine, merge. Plans and
//! partial results cross the boundary as bytes: mlt gives them as `MltBytes` (`buffers`),
//! and the host passes them back as a pointer and a size, from wherever it kept or
//! received them.

use super::buffers;
use super::convert::*;
use super::extensible::*;
use super::handles;
use super::marshal::*;
use super::types::*;
use crate::error::*;
use crate::render::jobs::{self, MLT_MAX_JOBS, PartialRender, RenderPlan};
use crate::render::{MLT_MAX_THREADS, StopReason};
use crate::scene::Camera;
use std::ffi::c_void;

/// `error` with `what` (the argument it is about) before its message.
fn about(what: &str, error: Error) -> Error {
    Error::new(error.status, format!("{what}: {}", error.message))
}

/// The plan the host passes back, checked and decoded.
///
/// # Safety
/// If non-null, `plan` must point to `plan_size` readable bytes.
unsafe fn read_plan(plan: *const u8, plan_size: usize) -> Result<RenderPlan> {
    if plan.is_null() {
        return Err(Error::invalid(
            "plan is NULL: pass the bytes mlt_render_plan gave (MltBytes.data)",
        ));
    }
    if plan_size == 0 {
        return Err(Error::invalid(
            "plan_size is 0: pass the size of the bytes mlt_render_plan gave (MltBytes.size)",
        ));
    }
    // SAFETY: forwarded contract.
    let bytes = unsafe { host_slice(plan, plan_size, "plan") }?;
    RenderPlan::from_bytes(bytes).map_err(|e| about("plan", e))
}

/// The partial results the host passes back (`partials[i]`, `partial_sizes[i]` bytes each),
/// checked but not decoded.
///
/// # Safety
/// If non-null, `partials` and `partial_sizes` must point to `partial_count` elements, each
/// `partials[i]` to `partial_sizes[i]` readable bytes.
unsafe fn host_partials<'a>(
    partials: *const *const u8,
    partial_sizes: *const usize,
    partial_count: usize,
    call: &str,
) -> Result<Vec<&'a [u8]>> {
    if partial_count == 0 {
        return Err(Error::invalid(format!(
            "partial_count is 0: {call} needs at least one partial result"
        )));
    }
    if partial_count > MLT_MAX_JOBS as usize {
        return Err(Error::invalid(format!(
            "partial_count is {partial_count}; a render has at most MLT_MAX_JOBS ({MLT_MAX_JOBS}) jobs"
        )));
    }
    // SAFETY: forwarded contract for every pointer below.
    let pointers = unsafe { host_slice(partials, partial_count, "partials") }?;
    let sizes = unsafe { host_slice(partial_sizes, partial_count, "partial_sizes") }?;
    pointers
        .iter()
        .zip(sizes)
        .enumerate()
        .map(|(i, (&pointer, &size))| {
            if pointer.is_null() {
                return Err(Error::invalid(format!("partials[{i}] is NULL")));
            }
            if size == 0 {
                return Err(Error::invalid(format!(
                    "partial_sizes[{i}] is 0: pass the size of the bytes mlt_render_job or mlt_render_combine gave"
                )));
            }
            unsafe { host_slice(pointer, size, &format!("partials[{i}]")) }
        })
        .collect()
}

/// Decodes `buffers` one at a time for `fold`, so it holds one decoded partial result
/// besides its sums, and returns the first decoding error instead of `fold`'s result, which
/// then saw only the partial results before it.
fn decode_each<T>(
    plan: &RenderPlan,
    buffers: &[&[u8]],
    fold: impl FnOnce(&mut dyn Iterator<Item = PartialRender>) -> Result<T>,
) -> Result<T> {
    let decode = |i: usize| {
        PartialRender::from_bytes(buffers[i]).map_err(|e| about(&format!("partials[{i}]"), e))
    };
    let first = decode(0)?;
    // Each partial result holds at least one job of its own.
    if first.plan_id() == plan.id() && buffers.len() > first.jobs() as usize {
        return Err(Error::invalid(format!(
            "partial_count is {} but the render was split into {} jobs: give each job's partial result once",
            buffers.len(),
            first.jobs()
        )));
    }
    let mut undecodable = None;
    let rest = (1..buffers.len()).map_while(|i| match decode(i) {
        Ok(partial) => Some(partial),
        Err(error) => {
            undecodable = Some(error);
            None
        }
    });
    let folded = fold(&mut std::iter::once(first).chain(rest));
    match undecodable {
        Some(error) => Err(error),
        None => folded,
    }
}

/// Plans a render of `scene` seen by `camera` with `settings`, to be split into jobs that
/// other threads, processes or machines render (`mlt_render_job`) and one merges
/// (`mlt_render_merge`) into the image `mlt_render` gives, bit for bit. Validates what
/// `mlt_render` would. On success `*plan_out` receives the plan's bytes (a few hundred, and
/// a Metropolis plan's chain seeds), to release with `mlt_bytes_release`; it is written
/// without being read, so release what it held first. `settings.threads` is the plan
/// step's own: each job chooses its threads.
///
/// A plan names its scene by a fingerprint of the scene's description (arrays, materials,
/// lights, textures and backend): every job must build its scene from the same one.
/// Every algorithm splits. A Metropolis plan runs the bootstrap and fixes every chain's
/// group and seed; the others' plans are immediate.
///
/// # Safety
/// `camera` and `settings` must point to initialized structs; `plan_out` must be writable.
/// (`scene` is looked up among the live scenes: any other pointer is refused.)
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_render_plan(
    scene: *const MltScene,
    camera: *const MltCamera,
    settings: *const MltRenderSettings,
    plan_out: *mut MltBytes,
) -> MltStatus {
    guard(|| {
        let handle = handles::acquire(scene, "scene")?;
        // SAFETY: forwarded contract.
        let camera: Camera = (&unsafe { read_host(camera, "camera") }?).into();
        let settings = render_settings(&unsafe { read_host(settings, "settings") }?)?;
        check_pointer(plan_out, "plan_out")?;
        let plan = jobs::plan(&handle.scene, &camera, &settings)?;
        let bytes = buffers::give(plan.to_bytes());
        // SAFETY: `plan_out` checked non-null and aligned above; writable by the contract.
        unsafe { plan_out.write(bytes) };
        Ok(MLT_STATUS_OK)
    })
}

/// Renders job `job` of `jobs` (numbered from 0; `jobs` from 1 to `MLT_MAX_JOBS`) of the
/// plan in `plan` (`plan_size` bytes, as `mlt_render_plan` gave them) on `scene`, which
/// must be built from the same description as the plan's. `threads` is this job's (0: the
/// process-wide pool of one thread per core, as `MltRenderSettings.threads`), and so are
/// `progress` and `user_data` (may be NULL), called as for `mlt_render`. The plan's time
/// limit applies to each job.
///
/// On success `*partial_out` receives the job's partial result, to pass to
/// `mlt_render_merge` with the others and release with `mlt_bytes_release` (it is written
/// without being read: release what it held first), and `stats_out` (may be NULL; its
/// `filter_*` fields are 0, the filter runs at the merge) what the job did.
/// `MLT_STATUS_CANCELLED` and `MLT_STATUS_TIME_LIMIT_REACHED` also write both: the
/// partial result holds what the job rendered, and merges into the image of a render
/// stopped the same way. On any other status neither is written.
///
/// # Safety
/// If non-null, `plan` must point to `plan_size` readable bytes; `partial_out` must be
/// writable, `stats_out` NULL or writable. (`scene` is looked up among the live scenes.)
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mlt_render_job(
    scene: *const MltScene,
    plan: *const u8,
    plan_size: usize,
    job: u32,
    jobs: u32,
    threads: u32,
    progress: MltProgressCallback,
    user_data: *mut c_void,
    partial_out: *mut MltBytes,
    stats_out: *mut MltRenderStats,
) -> MltStatus {
    guard(|| {
        let handle = handles::acquire(scene, "scene")?;
        // SAFETY: forwarded contract for every pointer below.
        let plan = unsafe { read_plan(plan, plan_size) }?;
        if threads > MLT_MAX_THREADS {
            return Err(Error::invalid(format!(
                "threads is {threads}; use 0 for all cores or at most {MLT_MAX_THREADS}"
            )));
        }
        check_pointer(partial_out, "partial_out")?;
        let stats_fields = if stats_out.is_null() {
            None
        } else {
            Some(unsafe { host_fields(stats_out, "stats_out") }?)
        };
        let mut forward = |fraction: f32| match progress {
            // SAFETY: the host's callback with the host's user data, on the host's thread.
            Some(callback) => unsafe { callback(fraction, user_data) },
            None => true,
        };
        let partial =
            jobs::render_job(&handle.scene, &plan, job, jobs, threads, Some(&mut forward))?;
        let stats = *partial.stats();
        let bytes = buffers::give(partial.to_bytes());
        drop(partial);
        // SAFETY: `partial_out` checked non-null and aligned above; writable by the contract.
        unsafe { partial_out.write(bytes) };
        if let Some(fields) = stats_fields {
            // SAFETY: checked by host_fields above; writable by the contract.
            unsafe { write_host(stats_out, fields, &stats_to_c(&stats)) };
        }
        Ok(match stats.stop {
            StopReason::Completed => MLT_STATUS_OK,
            StopReason::Cancelled => {
                set_last_error(&format!(
                    "the progress callback cancelled job {job} of {jobs} after {} samples and {} mutations; partial_out holds what it rendered",
                    stats.samples, stats.mutations
                ));
                MLT_STATUS_CANCELLED
            }
            StopReason::TimeLimitReached => {
                set_last_error(&format!(
                    "the time limit of {} s was reached in job {job} of {jobs} after {} samples and {} mutations; partial_out holds what it rendered",
                    plan.settings().time_limit_seconds,
                    stats.samples,
                    stats.mutations
                ));
                MLT_STATUS_TIME_LIMIT_REACHED
            }
        })
    })
}

/// Merges the partial results of every job of the plan in `plan` (`plan_size` bytes) and
/// writes the image into `rgb_out` (`out_len` floats, at least width × height × 3) as
/// `mlt_render` would: bit for bit the image one `mlt_render` of the plan gives, whatever
/// the number of jobs, their threads and the order of the partial results.
///
/// `partials[i]` points to the `partial_sizes[i]` bytes of a partial result, as
/// `mlt_render_job` (one job) or `mlt_render_combine` (several) gave them; together they
/// hold every job once, in any order. They are decoded one at a time, so the merge holds one
/// decoded partial result besides the image's sums. A partial result that is corrupted, cut short, from
/// another plan or split, a job missing or given twice, is `MLT_STATUS_INVALID_ARGUMENT`
/// naming it. `stats_out` (may be NULL) receives the jobs' counts added up (`seconds` is
/// the sum of the jobs' times, `threads` the most any job used).
///
/// Returns `MLT_STATUS_OK` when every job completed; `MLT_STATUS_CANCELLED` (some job was
/// cancelled) or `MLT_STATUS_TIME_LIMIT_REACHED` (some job reached the time limit) also
/// write a valid image, normalized by the samples the jobs took. On any other status
/// neither `rgb_out` nor `stats_out` is written.
///
/// # Safety
/// If non-null, `plan` must point to `plan_size` readable bytes; `partials` and
/// `partial_sizes` to `partial_count` elements, each `partials[i]` to `partial_sizes[i]`
/// readable bytes; `rgb_out` to `out_len` writable floats, not accessed by the host until
/// the call returns; `stats_out` NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mlt_render_merge(
    plan: *const u8,
    plan_size: usize,
    partials: *const *const u8,
    partial_sizes: *const usize,
    partial_count: usize,
    rgb_out: *mut f32,
    out_len: usize,
    stats_out: *mut MltRenderStats,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract for every pointer below.
        let plan = unsafe { read_plan(plan, plan_size) }?;
        let buffers =
            unsafe { host_partials(partials, partial_sizes, partial_count, "the merge") }?;
        let settings = plan.settings();
        let needed = settings.output_len()?;
        if out_len < needed {
            return Err(Error::invalid(format!(
                "out_len is {out_len} floats but a {} x {} RGB image needs {needed}",
                settings.width, settings.height
            )));
        }
        let image = unsafe { host_slice_mut(rgb_out, needed, "rgb_out") }?;
        let stats_fields = if stats_out.is_null() {
            None
        } else {
            Some(unsafe { host_fields(stats_out, "stats_out") }?)
        };

        // Merged into an image of mlt's, copied out on success: a partial result that fails
        // to decode after the others held every job must leave `rgb_out` unwritten.
        let mut merged = Vec::new();
        merged.try_reserve_exact(needed).map_err(|_| {
            Error::new(
                MLT_STATUS_OUT_OF_MEMORY,
                format!("no memory for the merged image ({needed} floats)"),
            )
        })?;
        merged.resize(needed, 0.0f32);
        let stats = decode_each(&plan, &buffers, |partials| {
            jobs::merge(&plan, partials, &mut merged)
        })?;
        image.copy_from_slice(&merged);
        if let Some(fields) = stats_fields {
            // SAFETY: checked by host_fields above; writable by the contract.
            unsafe { write_host(stats_out, fields, &stats_to_c(&stats)) };
        }
        Ok(match stats.stop {
            StopReason::Completed => MLT_STATUS_OK,
            StopReason::Cancelled => {
                set_last_error(&format!(
                    "a job was cancelled by its progress callback: the image holds the {} samples and {} mutations the jobs took",
                    stats.samples, stats.mutations
                ));
                MLT_STATUS_CANCELLED
            }
            StopReason::TimeLimitReached => {
                set_last_error(&format!(
                    "a job reached the time limit of {} s: the image holds the {} samples and {} mutations the jobs took",
                    settings.time_limit_seconds, stats.samples, stats.mutations
                ));
                MLT_STATUS_TIME_LIMIT_REACHED
            }
        })
    })
}

/// Adds partial results of the plan in `plan` (`plan_size` bytes) that hold disjoint sets of
/// jobs (`partials[i]`, `partial_sizes[i]` bytes each, as `mlt_render_job` or an earlier
/// `mlt_render_combine` gave them; any number from 1, in any order) into one partial result
/// that holds all their jobs, for `mlt_render_merge` or a further combine. Merging it gives
/// the bits merging its parts would: a cluster can add N jobs' results in a tree, each node
/// reading a few, instead of one node reading all N.
///
/// On success `*combined_out` receives the combined partial result, to release with
/// `mlt_bytes_release` (it is written without being read: release what it held first). A
/// partial result that is corrupted, cut short, from another plan or split, or a job held
/// twice, is `MLT_STATUS_INVALID_ARGUMENT` naming it, and nothing is written.
///
/// # Safety
/// If non-null, `plan` must point to `plan_size` readable bytes; `partials` and
/// `partial_sizes` to `partial_count` elements, each `partials[i]` to `partial_sizes[i]`
/// readable bytes; `combined_out` must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_render_combine(
    plan: *const u8,
    plan_size: usize,
    partials: *const *const u8,
    partial_sizes: *const usize,
    partial_count: usize,
    combined_out: *mut MltBytes,
) -> MltStatus {
    guard(|| {
        // SAFETY: forwarded contract for every pointer below.
        let plan = unsafe { read_plan(plan, plan_size) }?;
        let buffers =
            unsafe { host_partials(partials, partial_sizes, partial_count, "the combine") }?;
        check_pointer(combined_out, "combined_out")?;
        let combined = decode_each(&plan, &buffers, |partials| jobs::combine(&plan, partials))?;
        let bytes = buffers::give(combined.to_bytes());
        // SAFETY: `combined_out` checked non-null and aligned above; writable by the contract.
        unsafe { combined_out.write(bytes) };
        Ok(MLT_STATUS_OK)
    })
}

/// Frees bytes mlt gave (`mlt_render_plan`, `mlt_render_job`, `mlt_render_combine`) and sets `data` to NULL and
/// `size` to 0, so releasing twice is harmless. NULL, and an `MltBytes` whose `data` is
/// NULL, are no-ops. Bytes mlt did not give, or released already through a copy of the
/// `MltBytes`, are looked up, not freed: ignored, and `mlt_last_error_message` says so.
///
/// # Safety
/// `bytes` must be NULL or point to a readable and writable `MltBytes`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mlt_bytes_release(bytes: *mut MltBytes) {
    if bytes.is_null() {
        return;
    }
    if bytes.is_aligned() {
        // SAFETY: non-null and aligned; readable by the contract.
        if unsafe { bytes.read() }.data.is_null() {
            return;
        }
    }
    let _ = guard(|| {
        check_pointer(bytes, "bytes")?;
        // SAFETY: non-null and aligned (checked); readable by the contract.
        let value = unsafe { bytes.read() };
        buffers::take_back(value, "bytes")?;
        // SAFETY: as above; writable by the contract.
        unsafe {
            bytes.write(MltBytes {
                data: std::ptr::null_mut(),
                size: 0,
            })
        };
        Ok(MLT_STATUS_OK)
    });
}
