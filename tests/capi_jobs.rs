//! A render split into jobs through the C ABI (`mlt_render_plan`, `mlt_render_job`,
//! `mlt_render_combine`, `mlt_render_merge`, `mlt_bytes_release`), called exactly as a C host calls them: the
//! merged image has the bits of `mlt_render_ex`'s for any number of jobs, thread counts and
//! order of the partial results; every bad argument is `MLT_STATUS_INVALID_ARGUMENT` with a
//! message naming it and leaves the outputs untouched; byte buffers are freed once, and a
//! buffer mlt did not give is never freed.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_jobs`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::{
    SENTINEL_F32, assert_invalid, assert_ok, default_camera, default_settings, last_error,
    render_stats_default,
};
use mlt::capi::*;
use mlt::error::*;
use mlt::jobs::MLT_MAX_JOBS;
use mlt::{MLT_MAX_SAMPLES_PER_PIXEL, MLT_MAX_THREADS};
use std::ffi::c_void;
use std::ptr::{null, null_mut};

// ---------------------------------------------------------------------------------------
// A C host's calls
// ---------------------------------------------------------------------------------------

/// Asserts `status` and that the last error message contains every one of `needles`.
#[track_caller]
fn assert_status(status: MltStatus, expected: MltStatus, needles: &[&str]) {
    assert_outcome((status, last_error()), expected, needles);
}

/// Asserts a call's status and the message it left (read before any other mlt call,
/// `mlt_bytes_release` included, replaced it) contains every one of `needles`.
#[track_caller]
fn assert_outcome((status, message): (MltStatus, String), expected: MltStatus, needles: &[&str]) {
    assert_eq!(status, expected, "message {message:?}");
    if expected == MLT_STATUS_OK {
        assert_eq!(message, "", "a success clears the last error");
    }
    for needle in needles {
        assert!(
            message.contains(needle),
            "the message {message:?} should mention {needle:?}"
        );
    }
}

/// Stats a failing call must leave as they are.
fn sentinel_stats() -> MltRenderStats {
    MltRenderStats {
        samples: 77,
        ..render_stats_default()
    }
}

/// An `MltBytes` a failing call must leave as it is: a pointer no allocation has.
fn sentinel_bytes() -> MltBytes {
    MltBytes {
        data: std::ptr::dangling_mut::<u64>().wrapping_add(0x1000).cast(),
        size: 4321,
    }
}

fn is_sentinel(bytes: &MltBytes) -> bool {
    let sentinel = sentinel_bytes();
    bytes.data == sentinel.data && bytes.size == sentinel.size
}

/// Owns a scene, as a C++ host's RAII wrapper would.
struct Scene(*mut MltScene);

// SAFETY: the header promises that scenes are thread safe for rendering and queries.
unsafe impl Sync for Scene {}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: created by mlt_scene_create, released once.
        unsafe { mlt_scene_release(self.0) };
    }
}

/// A scene through `mlt_scene_create` from a mesh's arrays.
fn create(mesh: &common::scenes::Mesh) -> Scene {
    let materials = mesh.c_materials();
    let mut desc = std::mem::MaybeUninit::<MltSceneDesc>::uninit();
    // SAFETY: writable memory for an MltSceneDesc.
    assert_ok(unsafe { mlt_scene_desc_init(desc.as_mut_ptr(), size_of::<MltSceneDesc>()) });
    // SAFETY: initialized on success.
    let desc = MltSceneDesc {
        positions: mesh.positions.as_ptr(),
        positions_len: mesh.positions.len(),
        indices: mesh.indices.as_ptr(),
        indices_len: mesh.indices.len(),
        material_ids: mesh.material_ids.as_ptr(),
        material_ids_len: mesh.material_ids.len(),
        materials: materials.as_ptr(),
        materials_len: materials.len(),
        ..unsafe { desc.assume_init() }
    };
    let mut scene = null_mut();
    // SAFETY: the description points into live vectors of the stated lengths.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut scene) });
    Scene(scene)
}

/// tests/scenes/cornell-box.obj through the C ABI, and its camera.
fn cornell() -> (Scene, MltCamera) {
    let camera = common::scenes::cornell_camera();
    let c = MltCamera {
        eye: camera.eye,
        target: camera.target,
        up: camera.up,
        fov_y_deg: camera.fov_y_deg,
        lens_radius: camera.lens_radius,
        focus_distance: camera.focus_distance,
        ..default_camera()
    };
    (create(&common::scenes::cornell_box()), c)
}

fn settings(algorithm: i32) -> MltRenderSettings {
    MltRenderSettings {
        // 11 bands of 4 rows, the last one short.
        width: 24,
        height: 42,
        algorithm,
        samples_per_pixel: 3,
        seed: 5,
        threads: 2,
        ..default_settings()
    }
}

/// A 12 × 10 render of `algorithm` with few samples, mutations and chains: every algorithm
/// splits in well under a second.
fn small_settings(algorithm: i32) -> MltRenderSettings {
    MltRenderSettings {
        width: 12,
        height: 10,
        samples_per_pixel: 2,
        mutations_per_pixel: 2,
        bootstrap_samples: 4096,
        chains: 16,
        ..settings(algorithm)
    }
}

fn image_len(settings: &MltRenderSettings) -> usize {
    settings.width as usize * settings.height as usize * 3
}

/// Bytes mlt gave, released when dropped, as a C++ host's RAII wrapper would.
struct Bytes(MltBytes);

impl Bytes {
    fn new() -> Self {
        Bytes(MltBytes {
            data: null_mut(),
            size: 0,
        })
    }

    fn as_slice(&self) -> &[u8] {
        assert!(!self.0.data.is_null(), "bytes were given");
        // SAFETY: mlt gave `size` bytes at `data`, live until released.
        unsafe { std::slice::from_raw_parts(self.0.data, self.0.size) }
    }
}

impl Drop for Bytes {
    fn drop(&mut self) {
        // SAFETY: an MltBytes mlt filled (or empty).
        unsafe { mlt_bytes_release(&mut self.0) };
    }
}

/// `mlt_render_ex`, which must complete: the image and the stats.
fn render(
    scene: &Scene,
    camera: &MltCamera,
    settings: &MltRenderSettings,
) -> (Vec<f32>, MltRenderStats) {
    let mut image = vec![SENTINEL_F32; image_len(settings)];
    let mut stats = render_stats_default();
    // SAFETY: valid pointers; `image` holds the floats passed.
    let status = unsafe {
        mlt_render_ex(
            scene.0,
            camera,
            settings,
            image.as_mut_ptr(),
            image.len(),
            None,
            null_mut(),
            &mut stats,
        )
    };
    assert_ok(status);
    (image, stats)
}

/// `mlt_render_plan`, which must succeed: the plan's bytes, copied (as a host sends them).
fn plan(scene: &Scene, camera: &MltCamera, settings: &MltRenderSettings) -> Vec<u8> {
    let mut bytes = Bytes(sentinel_bytes());
    // SAFETY: valid pointers.
    assert_ok(unsafe { mlt_render_plan(scene.0, camera, settings, &mut bytes.0) });
    bytes.as_slice().to_vec()
}

/// `mlt_render_job`: the status and the message it left, the partial result (if written)
/// copied, and the stats.
fn job(
    scene: &Scene,
    plan: &[u8],
    job: u32,
    jobs: u32,
    threads: u32,
) -> ((MltStatus, String), Option<Vec<u8>>, MltRenderStats) {
    let mut partial = Bytes(sentinel_bytes());
    let mut stats = sentinel_stats();
    // SAFETY: valid pointers; `plan` holds plan.len() bytes.
    let status = unsafe {
        mlt_render_job(
            scene.0,
            plan.as_ptr(),
            plan.len(),
            job,
            jobs,
            threads,
            None,
            null_mut(),
            &mut partial.0,
            &mut stats,
        )
    };
    let outcome = (status, last_error());
    if is_sentinel(&partial.0) {
        std::mem::forget(partial);
        (outcome, None, stats)
    } else {
        // Released when `partial` drops, which clears the last error: `outcome` keeps it.
        (outcome, Some(partial.as_slice().to_vec()), stats)
    }
}

/// A job that must complete.
#[track_caller]
fn job_ok(scene: &Scene, plan: &[u8], k: u32, n: u32) -> Vec<u8> {
    let (outcome, partial, _) = job(scene, plan, k, n, 1);
    assert_outcome(outcome, MLT_STATUS_OK, &[]);
    partial.expect("partial_out written")
}

/// `mlt_render_merge` of `partials` into `out_len` floats pre-filled with the sentinel.
fn merge(plan: &[u8], partials: &[&[u8]], out_len: usize) -> (MltStatus, Vec<f32>, MltRenderStats) {
    let pointers: Vec<*const u8> = partials.iter().map(|p| p.as_ptr()).collect();
    let sizes: Vec<usize> = partials.iter().map(|p| p.len()).collect();
    let mut image = vec![SENTINEL_F32; out_len];
    let mut stats = sentinel_stats();
    // SAFETY: valid pointers of the stated lengths.
    let status = unsafe {
        mlt_render_merge(
            plan.as_ptr(),
            plan.len(),
            pointers.as_ptr(),
            sizes.as_ptr(),
            partials.len(),
            image.as_mut_ptr(),
            out_len,
            &mut stats,
        )
    };
    (status, image, stats)
}

/// Asserts a merge is refused as invalid, naming `needles`, with the image and stats
/// untouched.
#[track_caller]
fn assert_merge_refused(plan: &[u8], partials: &[&[u8]], out_len: usize, needles: &[&str]) {
    let (status, image, stats) = merge(plan, partials, out_len);
    assert_invalid(status, needles);
    assert!(
        image.iter().all(|&v| v == SENTINEL_F32),
        "rgb_out written on failure"
    );
    assert_eq!(stats.samples, 77, "stats_out written on failure");
}

/// `mlt_render_combine` of `partials`: the status and the message it left, and the combined
/// partial result (if written) copied.
fn combine(plan: &[u8], partials: &[&[u8]]) -> ((MltStatus, String), Option<Vec<u8>>) {
    let pointers: Vec<*const u8> = partials.iter().map(|p| p.as_ptr()).collect();
    let sizes: Vec<usize> = partials.iter().map(|p| p.len()).collect();
    let mut combined = Bytes(sentinel_bytes());
    // SAFETY: valid pointers of the stated lengths.
    let status = unsafe {
        mlt_render_combine(
            plan.as_ptr(),
            plan.len(),
            pointers.as_ptr(),
            sizes.as_ptr(),
            partials.len(),
            &mut combined.0,
        )
    };
    let outcome = (status, last_error());
    if is_sentinel(&combined.0) {
        std::mem::forget(combined);
        (outcome, None)
    } else {
        (outcome, Some(combined.as_slice().to_vec()))
    }
}

/// A combine that must succeed.
#[track_caller]
fn combine_ok(plan: &[u8], partials: &[&[u8]]) -> Vec<u8> {
    let (outcome, combined) = combine(plan, partials);
    assert_outcome(outcome, MLT_STATUS_OK, &[]);
    combined.expect("combined_out written")
}

/// Asserts a combine is refused as invalid, naming `needles`, with `combined_out` untouched.
#[track_caller]
fn assert_combine_refused(plan: &[u8], partials: &[&[u8]], needles: &[&str]) {
    let (outcome, combined) = combine(plan, partials);
    assert_outcome(outcome, MLT_STATUS_INVALID_ARGUMENT, needles);
    assert!(combined.is_none(), "combined_out written on failure");
}

fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The order in which the partial results of `n` jobs are merged: not 0, 1, 2, … (for n > 2).
fn shuffled(n: u32) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n as usize).rev().collect();
    order.rotate_left(n as usize / 2);
    order
}

// ---------------------------------------------------------------------------------------
// Split renders
// ---------------------------------------------------------------------------------------

/// The path tracer and BDPT in 1, 2 and 3 jobs (each on 0, 1 or 2 threads), the bytes
/// copied as a host would send them, merged in shuffled order: `mlt_render_ex`'s image and
/// counts, bit for bit.
#[test]
fn split_renders_merge_into_the_bits_of_mlt_render() {
    let (scene, camera) = cornell();
    for algorithm in [MLT_ALGORITHM_PATH, MLT_ALGORITHM_BDPT] {
        let settings = settings(algorithm);
        let (whole, whole_stats) = render(&scene, &camera, &settings);
        assert!(whole.iter().any(|&v| v > 0.0));
        let plan = plan(&scene, &camera, &settings);
        for jobs in 1..=3u32 {
            let partials: Vec<Vec<u8>> = (0..jobs)
                .map(|k| {
                    let (outcome, partial, stats) = job(&scene, &plan, k, jobs, k % 3);
                    assert_outcome(outcome, MLT_STATUS_OK, &[]);
                    assert!(stats.samples > 0, "job {k} of {jobs} rendered");
                    assert_eq!(stats.filter_changed_fraction, 0.0);
                    partial.expect("partial_out written")
                })
                .collect();
            let order = shuffled(jobs);
            let given: Vec<&[u8]> = order.iter().map(|&k| &partials[k][..]).collect();
            let (status, merged, stats) = merge(&plan, &given, image_len(&settings));
            assert_ok(status);
            assert!(
                same_bits(&whole, &merged),
                "algorithm {algorithm} in {jobs} jobs (merged in the order {order:?}) differs from mlt_render"
            );
            assert_eq!(
                (stats.samples, stats.rays, stats.invalid_samples),
                (
                    whole_stats.samples,
                    whole_stats.rays,
                    whole_stats.invalid_samples
                ),
                "algorithm {algorithm} in {jobs} jobs"
            );
            assert!(stats.threads >= 1 && stats.seconds > 0.0);
        }
    }
}

/// A larger buffer is fine: the image goes at its start, the tail is untouched. Stats are
/// optional.
#[test]
fn merge_into_a_larger_buffer_without_stats() {
    let (scene, camera) = cornell();
    let settings = settings(MLT_ALGORITHM_PATH);
    let (whole, _) = render(&scene, &camera, &settings);
    let plan = plan(&scene, &camera, &settings);
    let partials = [job_ok(&scene, &plan, 1, 2), job_ok(&scene, &plan, 0, 2)];
    let pointers = [partials[0].as_ptr(), partials[1].as_ptr()];
    let sizes = [partials[0].len(), partials[1].len()];
    let len = image_len(&settings);
    let mut image = vec![SENTINEL_F32; len + 5];
    // SAFETY: valid pointers of the stated lengths; no stats.
    let status = unsafe {
        mlt_render_merge(
            plan.as_ptr(),
            plan.len(),
            pointers.as_ptr(),
            sizes.as_ptr(),
            2,
            image.as_mut_ptr(),
            len + 5,
            null_mut(),
        )
    };
    assert_ok(status);
    assert!(same_bits(&image[..len], &whole));
    assert!(image[len..].iter().all(|&v| v == SENTINEL_F32));
}

/// Every algorithm splits: two jobs merge into `mlt_render_ex`'s image, bit for bit.
#[test]
fn every_algorithm_splits_exactly() {
    let (scene, camera) = cornell();
    for algorithm in [
        MLT_ALGORITHM_PATH,
        MLT_ALGORITHM_BDPT,
        MLT_ALGORITHM_PSSMLT,
        MLT_ALGORITHM_MMLT,
        MLT_ALGORITHM_PSSMLT_BDPT,
        MLT_ALGORITHM_PATH_SPACE_MLT,
        MLT_ALGORITHM_ERPT,
    ] {
        let settings = small_settings(algorithm);
        let plan = plan(&scene, &camera, &settings);
        let ((status, message), partial, _) = job(&scene, &plan, 0, 2, 1);
        assert_outcome((status, message), MLT_STATUS_OK, &[]);
        let partials = [
            job_ok(&scene, &plan, 1, 2),
            partial.expect("partial_out written"),
        ];
        let (status, merged, _) = merge(&plan, &[&partials[0], &partials[1]], image_len(&settings));
        assert_ok(status);
        let (whole, _) = render(&scene, &camera, &settings);
        assert!(
            same_bits(&whole, &merged),
            "algorithm {algorithm} in 2 jobs differs from mlt_render"
        );
    }
}

/// Partial results combined in a tree (two jobs, then that with a third), merged with the
/// rest: `mlt_render_ex`'s image, bit for bit, for the path tracer and MMLT.
#[test]
fn combined_partial_results_merge_exactly() {
    let (scene, camera) = cornell();
    for algorithm in [MLT_ALGORITHM_PATH, MLT_ALGORITHM_MMLT] {
        let settings = small_settings(algorithm);
        let plan = plan(&scene, &camera, &settings);
        let five: Vec<Vec<u8>> = (0..5).map(|k| job_ok(&scene, &plan, k, 5)).collect();
        let pair = combine_ok(&plan, &[&five[3], &five[0]]);
        let three = combine_ok(&plan, &[&five[4], &pair]);
        let (status, merged, stats) =
            merge(&plan, &[&five[2], &three, &five[1]], image_len(&settings));
        assert_ok(status);
        let (whole, whole_stats) = render(&scene, &camera, &settings);
        assert!(
            same_bits(&whole, &merged),
            "algorithm {algorithm}: combined jobs differ from mlt_render"
        );
        assert_eq!(stats.samples, whole_stats.samples);
        assert_eq!(stats.mutations, whole_stats.mutations);
    }
}

#[test]
fn combine_bad_input() {
    let (scene, camera) = cornell();
    let settings = settings(MLT_ALGORITHM_PATH);
    let plan = plan(&scene, &camera, &settings);
    let three: Vec<Vec<u8>> = (0..3).map(|k| job_ok(&scene, &plan, k, 3)).collect();
    let [p0, p1, p2] = [&three[0][..], &three[1][..], &three[2][..]];
    let pair = combine_ok(&plan, &[p0, p1]);

    // Pointers, counts and sizes.
    let pointers = [p0.as_ptr()];
    let sizes = [p0.len()];
    let mut out = Bytes(sentinel_bytes());
    type Call<'a> = Box<dyn Fn(&mut MltBytes) -> MltStatus + 'a>;
    let cases: [(&str, Call); 7] = [
        (
            "plan is NULL",
            // SAFETY (each case): valid pointers but the one named.
            Box::new(|out| unsafe {
                mlt_render_combine(null(), 9, pointers.as_ptr(), sizes.as_ptr(), 1, out)
            }),
        ),
        (
            "plan_size is 0",
            Box::new(|out| unsafe {
                mlt_render_combine(plan.as_ptr(), 0, pointers.as_ptr(), sizes.as_ptr(), 1, out)
            }),
        ),
        (
            "partial_count is 0",
            Box::new(|out| unsafe {
                mlt_render_combine(
                    plan.as_ptr(),
                    plan.len(),
                    pointers.as_ptr(),
                    sizes.as_ptr(),
                    0,
                    out,
                )
            }),
        ),
        (
            "MLT_MAX_JOBS",
            Box::new(|out| unsafe {
                mlt_render_combine(
                    plan.as_ptr(),
                    plan.len(),
                    pointers.as_ptr(),
                    sizes.as_ptr(),
                    MLT_MAX_JOBS as usize + 1,
                    out,
                )
            }),
        ),
        (
            "partials",
            Box::new(|out| unsafe {
                mlt_render_combine(plan.as_ptr(), plan.len(), null(), sizes.as_ptr(), 1, out)
            }),
        ),
        (
            "partial_sizes",
            Box::new(|out| unsafe {
                mlt_render_combine(plan.as_ptr(), plan.len(), pointers.as_ptr(), null(), 1, out)
            }),
        ),
        (
            "partial_sizes[0] is 0",
            Box::new(|out| unsafe {
                mlt_render_combine(
                    plan.as_ptr(),
                    plan.len(),
                    pointers.as_ptr(),
                    [0usize].as_ptr(),
                    1,
                    out,
                )
            }),
        ),
    ];
    for (needle, call) in &cases {
        let status = call(&mut out.0);
        assert_invalid(status, &[needle]);
        assert!(is_sentinel(&out.0), "combined_out written on failure");
    }
    std::mem::forget(out);
    // SAFETY: valid pointers but the NULL output.
    let status = unsafe {
        mlt_render_combine(
            plan.as_ptr(),
            plan.len(),
            pointers.as_ptr(),
            sizes.as_ptr(),
            1,
            null_mut(),
        )
    };
    assert_invalid(status, &["combined_out"]);

    // The buffers and the set of jobs.
    let mut corrupted = p1.to_vec();
    corrupted[p1.len() / 2] ^= 0x10;
    assert_combine_refused(&plan, &[p0, &corrupted], &["partials[1]", "corrupted"]);
    assert_combine_refused(
        &plan,
        &[p0, &p2[..p2.len() - 1]],
        &["partials[1]", "truncated"],
    );
    assert_combine_refused(&plan, &[&pair, p1], &["job 1 of 3 is given twice"]);
    assert_combine_refused(
        &plan,
        &[&pair, p2, p0, p1],
        &["partial_count is 4", "3 jobs"],
    );
    let other_plan = self::plan(
        &scene,
        &camera,
        &MltRenderSettings {
            seed: 99,
            ..settings
        },
    );
    assert_combine_refused(&other_plan, &[p0], &["another plan"]);
    // A merge whose first partial result holds every job, then a corrupted one: refused,
    // the image unwritten.
    let all = combine_ok(&plan, &[&pair, p2]);
    assert_merge_refused(
        &plan,
        &[&all, &corrupted],
        image_len(&settings),
        &["partials[1]"],
    );
    let (status, _, _) = merge(&plan, &[&all], image_len(&settings));
    assert_ok(status);
}

// ---------------------------------------------------------------------------------------
// Cancel and time limit: the partial result is still written
// ---------------------------------------------------------------------------------------

unsafe extern "C" fn cancel(_fraction: f32, user_data: *mut c_void) -> bool {
    // SAFETY: the tests pass a &mut u32 call count.
    unsafe { *user_data.cast::<u32>() += 1 };
    false
}

#[test]
fn a_cancelled_job_still_gives_its_partial_result_and_the_merge_says_so() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        samples_per_pixel: MLT_MAX_SAMPLES_PER_PIXEL,
        ..settings(MLT_ALGORITHM_PATH)
    };
    let plan = plan(&scene, &camera, &settings);
    let mut calls = 0u32;
    let mut partial = Bytes(sentinel_bytes());
    let mut stats = sentinel_stats();
    // SAFETY: valid pointers; `calls` outlives the call.
    let status = unsafe {
        mlt_render_job(
            scene.0,
            plan.as_ptr(),
            plan.len(),
            0,
            2,
            2,
            Some(cancel),
            (&raw mut calls).cast(),
            &mut partial.0,
            &mut stats,
        )
    };
    assert_status(
        status,
        MLT_STATUS_CANCELLED,
        &["cancelled job 0 of 2", "partial_out"],
    );
    assert!(calls >= 1, "the callback was called");
    assert!(!is_sentinel(&partial.0), "partial_out written");
    assert!(stats.samples > 0 && stats.samples != 77);
    let cancelled = partial.as_slice().to_vec();
    drop(partial);

    // Job 1, cancelled too: its partial result merges with job 0's into a stopped render's
    // image.
    let (status, image, merged) = {
        let mut calls = 0u32;
        let mut other = Bytes::new();
        let mut job_stats = render_stats_default();
        // SAFETY: as above.
        let status = unsafe {
            mlt_render_job(
                scene.0,
                plan.as_ptr(),
                plan.len(),
                1,
                2,
                1,
                Some(cancel),
                (&raw mut calls).cast(),
                &mut other.0,
                &mut job_stats,
            )
        };
        assert_status(status, MLT_STATUS_CANCELLED, &["job 1 of 2"]);
        let (status, image, stats) =
            merge(&plan, &[other.as_slice(), &cancelled], image_len(&settings));
        ((status, last_error()), image, stats)
    };
    assert_outcome(status, MLT_STATUS_CANCELLED, &["cancelled", "samples"]);
    assert!(
        image.iter().all(|v| v.is_finite() && *v >= 0.0),
        "a valid image"
    );
    assert!(image.iter().any(|&v| v > 0.0));
    assert!(merged.samples >= stats.samples);
}

#[test]
fn jobs_that_reach_the_time_limit_give_their_partial_results() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        samples_per_pixel: MLT_MAX_SAMPLES_PER_PIXEL,
        time_limit_seconds: 0.1,
        ..settings(MLT_ALGORITHM_PATH)
    };
    let plan = plan(&scene, &camera, &settings);
    let partials: Vec<Vec<u8>> = (0..2)
        .map(|k| {
            let (outcome, partial, stats) = job(&scene, &plan, k, 2, 1);
            assert_outcome(
                outcome,
                MLT_STATUS_TIME_LIMIT_REACHED,
                &["time limit of 0.1 s", &format!("job {k} of 2")],
            );
            assert!(stats.samples > 0 && stats.samples != 77);
            partial.expect("partial_out written")
        })
        .collect();
    let (status, image, stats) = merge(&plan, &[&partials[0], &partials[1]], image_len(&settings));
    assert_status(status, MLT_STATUS_TIME_LIMIT_REACHED, &["time limit"]);
    assert!(image.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(stats.samples > 0 && stats.samples != 77);
}

// ---------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------

#[test]
fn plan_bad_input() {
    let (scene, camera) = cornell();
    let good = settings(MLT_ALGORITHM_PATH);
    let call = |scene: *const MltScene,
                camera: *const MltCamera,
                settings: *const MltRenderSettings,
                with_out: bool,
                needles: &[&str]| {
        let mut out = sentinel_bytes();
        let out_ptr = if with_out { &raw mut out } else { null_mut() };
        // SAFETY: every pointer is valid or one mlt must refuse before using it.
        let status = unsafe { mlt_render_plan(scene, camera, settings, out_ptr) };
        assert_invalid(status, needles);
        assert!(is_sentinel(&out), "plan_out written on failure");
    };
    call(null(), &camera, &good, true, &["scene", "NULL"]);
    let mut word = 0u64;
    call(
        (&raw mut word).cast(),
        &camera,
        &good,
        true,
        &["scene", "not a live scene"],
    );
    call(scene.0, null(), &good, true, &["camera", "NULL"]);
    call(scene.0, &camera, null(), true, &["settings", "NULL"]);
    call(scene.0, &camera, &good, false, &["plan_out", "NULL"]);
    let zero_width = MltRenderSettings { width: 0, ..good };
    call(scene.0, &camera, &zero_width, true, &["width is 0"]);
    let never_initialized = MltRenderSettings {
        struct_size: 0,
        ..good
    };
    call(
        scene.0,
        &camera,
        &never_initialized,
        true,
        &["settings.struct_size", "mlt_render_settings_default"],
    );
    let bad_camera = MltCamera {
        target: camera.eye,
        ..camera
    };
    call(scene.0, &bad_camera, &good, true, &["camera"]);
    let bad_algorithm = MltRenderSettings {
        algorithm: 99,
        ..good
    };
    call(
        scene.0,
        &camera,
        &bad_algorithm,
        true,
        &["settings.algorithm is 99"],
    );
    let odd = (&raw mut word)
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<MltBytes>();
    // SAFETY: a misaligned pointer mlt must refuse before writing.
    let status = unsafe { mlt_render_plan(scene.0, &camera, &good, odd) };
    assert_invalid(status, &["plan_out", "aligned"]);
    assert_eq!(word, 0, "nothing written through a foreign pointer");
}

/// Every bad argument of `mlt_render_job`: refused, naming it, `partial_out` and
/// `stats_out` untouched.
#[test]
fn job_bad_input() {
    let (scene, camera) = cornell();
    let settings = settings(MLT_ALGORITHM_PATH);
    let plan = plan(&scene, &camera, &settings);
    let partial = job_ok(&scene, &plan, 0, 2);

    /// The arguments of `mlt_render_job` but the callback.
    #[derive(Clone, Copy)]
    struct Call {
        scene: *const MltScene,
        plan: *const u8,
        plan_size: usize,
        job: u32,
        jobs: u32,
        threads: u32,
        partial_out: bool,
        stats_out: bool,
    }
    let valid = Call {
        scene: scene.0,
        plan: plan.as_ptr(),
        plan_size: plan.len(),
        job: 0,
        jobs: 2,
        threads: 1,
        partial_out: true,
        stats_out: true,
    };
    let refuse = |label: &str, call: Call, needles: &[&str]| {
        let mut out = sentinel_bytes();
        let mut stats = sentinel_stats();
        // SAFETY: every pointer is valid for the call or one mlt must refuse before use.
        let status = unsafe {
            mlt_render_job(
                call.scene,
                call.plan,
                call.plan_size,
                call.job,
                call.jobs,
                call.threads,
                None,
                null_mut(),
                if call.partial_out {
                    &raw mut out
                } else {
                    null_mut()
                },
                if call.stats_out {
                    &raw mut stats
                } else {
                    null_mut()
                },
            )
        };
        let message = last_error();
        assert_eq!(status, MLT_STATUS_INVALID_ARGUMENT, "{label}: {message:?}");
        for needle in needles {
            assert!(
                message.contains(needle),
                "{label}: {message:?} lacks {needle:?}"
            );
        }
        assert!(is_sentinel(&out), "{label}: partial_out written");
        assert_eq!(stats.samples, 77, "{label}: stats_out written");
    };
    let mut flipped = plan.clone();
    flipped[plan.len() / 2] ^= 4;
    let mut word = 0u64;
    refuse(
        "scene NULL",
        Call {
            scene: null(),
            ..valid
        },
        &["scene", "NULL"],
    );
    refuse(
        "scene foreign",
        Call {
            scene: (&raw mut word).cast(),
            ..valid
        },
        &["scene", "not a live scene"],
    );
    refuse(
        "plan NULL",
        Call {
            plan: null(),
            ..valid
        },
        &["plan is NULL"],
    );
    refuse(
        "plan_size 0",
        Call {
            plan_size: 0,
            ..valid
        },
        &["plan_size is 0"],
    );
    refuse(
        "plan corrupted",
        Call {
            plan: flipped.as_ptr(),
            ..valid
        },
        &["plan:", "corrupted"],
    );
    refuse(
        "plan truncated",
        Call {
            plan_size: plan.len() - 1,
            ..valid
        },
        &["plan:", "truncated"],
    );
    refuse(
        "a partial result as the plan",
        Call {
            plan: partial.as_ptr(),
            plan_size: partial.len(),
            ..valid
        },
        &["plan:", "not an mlt render plan"],
    );
    refuse(
        "job 2 of 2",
        Call { job: 2, ..valid },
        &["job 2 does not exist", "0 to 1"],
    );
    refuse(
        "jobs 0",
        Call {
            job: 0,
            jobs: 0,
            ..valid
        },
        &["jobs is 0"],
    );
    refuse(
        "jobs MLT_MAX_JOBS + 1",
        Call {
            jobs: MLT_MAX_JOBS + 1,
            ..valid
        },
        &[&format!("jobs is {}", MLT_MAX_JOBS + 1)],
    );
    refuse(
        "threads MLT_MAX_THREADS + 1",
        Call {
            threads: MLT_MAX_THREADS + 1,
            ..valid
        },
        &[&format!("threads is {}", MLT_MAX_THREADS + 1)],
    );
    refuse(
        "partial_out NULL",
        Call {
            partial_out: false,
            ..valid
        },
        &["partial_out", "NULL"],
    );
    assert_eq!(word, 0, "nothing written through a foreign pointer");

    // stats_out of a size no header had.
    let mut out = sentinel_bytes();
    let mut stats = MltRenderStats {
        struct_size: 0,
        ..sentinel_stats()
    };
    // SAFETY: valid pointers.
    let status = unsafe {
        mlt_render_job(
            scene.0,
            plan.as_ptr(),
            plan.len(),
            0,
            2,
            1,
            None,
            null_mut(),
            &mut out,
            &mut stats,
        )
    };
    assert_invalid(
        status,
        &["stats_out.struct_size", "mlt_render_stats_default"],
    );
    assert!(is_sentinel(&out) && stats.samples == 77);

    // A scene built from other arrays (one vertex moved) is not the plan's.
    let mut moved = common::scenes::cornell_box();
    moved.positions[0] += 1e-3;
    let other = create(&moved);
    refuse(
        "another scene",
        Call {
            scene: other.0,
            ..valid
        },
        &["not the one the plan was made for"],
    );
}

/// Every bad argument of `mlt_render_merge`, and every bad set of partial results:
/// refused, naming it, with the image and the stats untouched.
#[test]
fn merge_bad_input() {
    let (scene, camera) = cornell();
    let settings = settings(MLT_ALGORITHM_PATH);
    let len = image_len(&settings);
    let plan = plan(&scene, &camera, &settings);
    let three: Vec<Vec<u8>> = (0..3).map(|k| job_ok(&scene, &plan, k, 3)).collect();
    let [p0, p1, p2] = [&three[0][..], &three[1][..], &three[2][..]];

    // The plan.
    let mut flipped_plan = plan.clone();
    flipped_plan[plan.len() / 2] ^= 1;
    assert_merge_refused(&flipped_plan, &[p0, p1, p2], len, &["plan:", "corrupted"]);
    assert_merge_refused(
        &plan[..plan.len() - 3],
        &[p0, p1, p2],
        len,
        &["plan:", "truncated"],
    );
    assert_merge_refused(p0, &[p0, p1, p2], len, &["plan:", "not an mlt render plan"]);

    // The partial results, one by one.
    let mut corrupted = p1.to_vec();
    corrupted[p1.len() / 2] ^= 0x10;
    assert_merge_refused(
        &plan,
        &[p0, &corrupted, p2],
        len,
        &["partials[1]", "corrupted"],
    );
    assert_merge_refused(
        &plan,
        &[p0, p1, &p2[..p2.len() - 1]],
        len,
        &["partials[2]", "truncated"],
    );
    assert_merge_refused(
        &plan,
        &[&corrupted, p1, p2],
        len,
        &["partials[0]", "corrupted"],
    );
    assert_merge_refused(
        &plan,
        &[p0, &plan, p2],
        len,
        &["partials[1]", "not an mlt partial render"],
    );

    // The set of partial results.
    assert_merge_refused(&plan, &[p2, p0], len, &["jobs [1] of 3 are missing"]);
    assert_merge_refused(&plan, &[p0, p2, p0], len, &["job 0 of 3 is given twice"]);
    assert_merge_refused(
        &plan,
        &[p0, p1, p2, p1],
        len,
        &["partial_count is 4", "3 jobs"],
    );
    // All the jobs, then a corrupted buffer: refused, never an image without a word.
    assert_merge_refused(
        &plan,
        &[p0, p1, p2, &corrupted],
        len,
        &["partial_count is 4"],
    );
    let two: Vec<Vec<u8>> = (0..2).map(|k| job_ok(&scene, &plan, k, 2)).collect();
    assert_merge_refused(&plan, &[p0, &two[1], p2], len, &["split one way"]);
    let other_plan = self::plan(
        &scene,
        &camera,
        &MltRenderSettings {
            seed: 6,
            ..settings
        },
    );
    let other = job_ok(&scene, &other_plan, 0, 1);
    assert_merge_refused(&plan, &[&other], len, &["another plan"]);
    assert_merge_refused(&plan, &[p0, p1, &other], len, &["another plan"]);
    assert_merge_refused(&other_plan, &[p0, p1, p2], len, &["another plan"]);

    // The image.
    assert_merge_refused(
        &plan,
        &[p0, p1, p2],
        len - 1,
        &[&format!("out_len is {}", len - 1), &len.to_string()],
    );
    assert_merge_refused(&plan, &[p0, p1, p2], 0, &["out_len is 0"]);

    // Pointers and counts.
    let pointers = [p0.as_ptr(), p1.as_ptr(), p2.as_ptr()];
    let sizes = [p0.len(), p1.len(), p2.len()];
    let null_second = [p0.as_ptr(), null(), p2.as_ptr()];
    let zero_second = [p0.len(), 0, p2.len()];
    let mut image = vec![SENTINEL_F32; len + 1];
    let rgb = image.as_mut_ptr();
    let odd_rgb = rgb.cast::<u8>().wrapping_add(1).cast::<f32>();
    #[derive(Clone, Copy)]
    struct Call {
        plan: *const u8,
        plan_size: usize,
        partials: *const *const u8,
        partial_sizes: *const usize,
        partial_count: usize,
        rgb_out: *mut f32,
        out_len: usize,
        stats_out: bool,
    }
    let valid = Call {
        plan: plan.as_ptr(),
        plan_size: plan.len(),
        partials: pointers.as_ptr(),
        partial_sizes: sizes.as_ptr(),
        partial_count: 3,
        rgb_out: rgb,
        out_len: len,
        stats_out: true,
    };
    let cases: Vec<(&str, Call, Vec<String>)> = vec![
        (
            "plan NULL",
            Call {
                plan: null(),
                ..valid
            },
            vec!["plan is NULL".into()],
        ),
        (
            "plan_size 0",
            Call {
                plan_size: 0,
                ..valid
            },
            vec!["plan_size is 0".into()],
        ),
        (
            "partials NULL",
            Call {
                partials: null(),
                ..valid
            },
            vec!["partials is NULL".into()],
        ),
        (
            "partial_sizes NULL",
            Call {
                partial_sizes: null(),
                ..valid
            },
            vec!["partial_sizes is NULL".into()],
        ),
        (
            "partial_count 0",
            Call {
                partial_count: 0,
                ..valid
            },
            vec!["partial_count is 0".into()],
        ),
        (
            "partial_count huge",
            Call {
                partial_count: MLT_MAX_JOBS as usize + 1,
                ..valid
            },
            vec![
                format!("partial_count is {}", MLT_MAX_JOBS + 1),
                "MLT_MAX_JOBS".into(),
            ],
        ),
        (
            "partial_count usize::MAX",
            Call {
                partial_count: usize::MAX,
                ..valid
            },
            vec!["partial_count is".into(), "MLT_MAX_JOBS".into()],
        ),
        (
            "partials[1] NULL",
            Call {
                partials: null_second.as_ptr(),
                ..valid
            },
            vec!["partials[1] is NULL".into()],
        ),
        (
            "partial_sizes[1] 0",
            Call {
                partial_sizes: zero_second.as_ptr(),
                ..valid
            },
            vec!["partial_sizes[1] is 0".into()],
        ),
        (
            "rgb_out NULL",
            Call {
                rgb_out: null_mut(),
                ..valid
            },
            vec!["rgb_out".into(), "NULL".into()],
        ),
        (
            "rgb_out misaligned",
            Call {
                rgb_out: odd_rgb,
                ..valid
            },
            vec!["rgb_out".into(), "aligned".into()],
        ),
        (
            "partials misaligned",
            Call {
                partials: pointers.as_ptr().cast::<u8>().wrapping_add(1).cast(),
                ..valid
            },
            vec!["partials".into(), "aligned".into()],
        ),
    ];
    for (label, call, needles) in cases {
        let mut stats = sentinel_stats();
        // SAFETY: every pointer is valid for the call or one mlt must refuse before use;
        // `rgb` holds len + 1 floats, so even the misaligned one has `len` behind it.
        let status = unsafe {
            mlt_render_merge(
                call.plan,
                call.plan_size,
                call.partials,
                call.partial_sizes,
                call.partial_count,
                call.rgb_out,
                call.out_len,
                if call.stats_out {
                    &raw mut stats
                } else {
                    null_mut()
                },
            )
        };
        let message = last_error();
        assert_eq!(status, MLT_STATUS_INVALID_ARGUMENT, "{label}: {message:?}");
        for needle in &needles {
            assert!(
                message.contains(needle.as_str()),
                "{label}: {message:?} lacks {needle:?}"
            );
        }
        // SAFETY: `image`'s memory, only read here.
        let untouched = unsafe { std::slice::from_raw_parts(rgb, len + 1) };
        assert!(
            untouched.iter().all(|&v| v == SENTINEL_F32),
            "{label}: rgb_out written"
        );
        assert_eq!(stats.samples, 77, "{label}: stats_out written");
    }
    // stats_out of a size no header had.
    let mut stats = MltRenderStats {
        struct_size: 3,
        ..sentinel_stats()
    };
    // SAFETY: valid pointers.
    let status = unsafe {
        mlt_render_merge(
            plan.as_ptr(),
            plan.len(),
            pointers.as_ptr(),
            sizes.as_ptr(),
            3,
            rgb,
            len,
            &mut stats,
        )
    };
    assert_invalid(status, &["stats_out.struct_size is 3"]);
    // SAFETY: as above.
    let untouched = unsafe { std::slice::from_raw_parts(rgb, len + 1) };
    assert!(untouched.iter().all(|&v| v == SENTINEL_F32) && stats.samples == 77);

    // And the valid call merges.
    let (status, _, _) = merge(&plan, &[p1, p2, p0], len);
    assert_ok(status);
}

// ---------------------------------------------------------------------------------------
// Releasing bytes
// ---------------------------------------------------------------------------------------

/// Release frees once and empties the `MltBytes`; releasing again, NULL or an empty one is a
/// no-op that keeps the last error; a copy of a released `MltBytes`, a changed size, and
/// memory mlt never gave are refused with a message and not freed.
#[test]
fn bytes_are_released_once_and_only_mlt_s() {
    let (scene, camera) = cornell();
    let settings = settings(MLT_ALGORITHM_PATH);
    let mut plan = MltBytes {
        data: null_mut(),
        size: 0,
    };
    // SAFETY: valid pointers.
    assert_ok(unsafe { mlt_render_plan(scene.0, &camera, &settings, &mut plan) });
    assert!(!plan.data.is_null() && plan.size > 0);
    let copy = plan;

    // A changed size is refused, and the buffer stays live.
    let mut resized = MltBytes {
        size: plan.size - 1,
        ..plan
    };
    // SAFETY: an MltBytes whose size does not match: looked up, not freed.
    unsafe { mlt_bytes_release(&mut resized) };
    assert!(last_error().contains("bytes.size is"), "{}", last_error());
    assert_eq!(resized.size, plan.size - 1, "left as it was");

    // SAFETY: the MltBytes mlt filled.
    unsafe { mlt_bytes_release(&mut plan) };
    assert_eq!(last_error(), "");
    assert!(plan.data.is_null() && plan.size == 0, "emptied");

    // Set a last error; the no-ops keep it.
    // SAFETY: NULL must be refused.
    assert_invalid(
        unsafe { mlt_render_plan(null(), &camera, &settings, &mut plan) },
        &["scene"],
    );
    let error = last_error();
    // SAFETY: NULL and an empty MltBytes are no-ops.
    unsafe {
        mlt_bytes_release(&mut plan);
        mlt_bytes_release(null_mut());
    }
    assert_eq!(last_error(), error);

    // The copy names a buffer freed already: refused, not freed twice.
    let mut stale = copy;
    // SAFETY: looked up, not dereferenced.
    unsafe { mlt_bytes_release(&mut stale) };
    assert!(
        last_error().contains("not a buffer mlt gave"),
        "{}",
        last_error()
    );

    // Memory mlt never gave is not freed.
    let mut host = vec![7u8; 16];
    let mut foreign = MltBytes {
        data: host.as_mut_ptr(),
        size: host.len(),
    };
    // SAFETY: looked up, not freed.
    unsafe { mlt_bytes_release(&mut foreign) };
    assert!(last_error().contains("not a buffer mlt gave"));
    assert_eq!(host, vec![7u8; 16]);
    let mut word = [0u64; 3];
    let odd = word
        .as_mut_ptr()
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<MltBytes>();
    // SAFETY: a misaligned pointer mlt must refuse before reading.
    unsafe { mlt_bytes_release(odd) };
    assert!(last_error().contains("aligned"), "{}", last_error());
    assert_eq!(word, [0; 3]);
}

/// Many threads plan, render jobs and release their bytes at once: every merge is the same
/// image.
#[test]
fn threads_split_renders_at_once() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        width: 8,
        height: 12,
        ..settings(MLT_ALGORITHM_BDPT)
    };
    let (whole, _) = render(&scene, &camera, &settings);
    let images: Vec<Vec<f32>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| {
                let (scene, camera, settings) = (&scene, &camera, &settings);
                s.spawn(move || {
                    let plan = plan(scene, camera, settings);
                    let partials: Vec<Vec<u8>> =
                        (0..3).map(|k| job_ok(scene, &plan, k, 3)).collect();
                    let given: Vec<&[u8]> = partials.iter().rev().map(|p| &p[..]).collect();
                    let (status, image, _) = merge(&plan, &given, image_len(settings));
                    assert_ok(status);
                    image
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for image in images {
        assert!(same_bits(&image, &whole));
    }
}
