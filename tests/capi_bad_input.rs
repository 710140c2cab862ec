//! Every C entry point fed bad input exactly as a C host would: the call must return the
//! documented status, `mlt_last_error_message()` must name the offending field, index or value,
//! and out-parameters must be left untouched on failure. Plus the behaviours the header
//! promises around them: degenerate triangles, cancellation, time limits, thread safety and
//! the last-error life cycle.
//!
//! The bad values are table-driven: `cases!` writes a table one case a line, each case a
//! valid input with one change, labelled with that change's source text, and the needles the
//! message must contain; `non_finite_cases!` gives NaN, +inf and -inf to every float field
//! listed. `assert_cases` checks every case of a table (status, message, outputs untouched)
//! and then fails listing each failing case by its label, so a broken validation shows as
//! the cases it breaks. Behaviours that are not one bad value (cancellation, time limits,
//! concurrency, the last error's life cycle) are tests of their own.

mod common;

use mlt::MLT_MAX_TEXTURE_SIDE;
use mlt::capi::*;
use mlt::error::*;
use mlt::render::{
    MLT_MAX_DEPTH_LIMIT, MLT_MAX_ERPT_CHAIN_LENGTH, MLT_MAX_IMAGE_SIDE, MLT_MAX_SAMPLES_PER_PIXEL,
    MLT_MAX_THREADS, MLT_MAX_TIME_LIMIT_SECONDS,
};
use mlt::scene::{MLT_MAX_ENVIRONMENT_SIDE, MLT_MAX_PUNCTUAL_LIGHTS};
use std::ffi::{CStr, c_void};
use std::ptr::{null, null_mut};

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

fn last_error() -> String {
    // SAFETY: mlt returns a NUL-terminated string valid until the next call on this thread.
    unsafe { CStr::from_ptr(mlt_last_error_message()) }
        .to_str()
        .unwrap()
        .to_owned()
}

fn status_string(status: i32) -> String {
    // SAFETY: static NUL-terminated strings.
    unsafe { CStr::from_ptr(mlt_status_string(status)) }
        .to_str()
        .unwrap()
        .to_owned()
}

/// The outcome of checking one case: `Err` says what is wrong.
type Check = std::result::Result<(), String>;

/// Whether a call returned `expected` and left a last error message containing every one of
/// `needles`; the error says what differs.
fn check_error(status: MltStatus, expected: MltStatus, needles: &[impl AsRef<str>]) -> Check {
    let message = last_error();
    if status != expected {
        return Err(format!(
            "{status:?} instead of {expected:?}; message {message:?}"
        ));
    }
    let missing: Vec<&str> = needles
        .iter()
        .map(AsRef::as_ref)
        .filter(|needle| !message.contains(needle))
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "the message {message:?} should mention {missing:?}"
        ));
    }
    Ok(())
}

/// `Err(what)` unless `condition`: the "untouched on failure" checks of a case.
fn ensure(condition: bool, what: &str) -> Check {
    if condition {
        Ok(())
    } else {
        Err(what.to_owned())
    }
}

#[track_caller]
fn pass(result: Check) {
    if let Err(error) = result {
        panic!("{error}");
    }
}

/// Asserts `status` and that the last error message contains every one of `needles`.
#[track_caller]
fn assert_error(status: MltStatus, expected: MltStatus, needles: &[&str]) {
    pass(check_error(status, expected, needles));
}

#[track_caller]
fn assert_invalid(status: MltStatus, needles: &[&str]) {
    assert_error(status, MLT_STATUS_INVALID_ARGUMENT, needles);
}

/// Whether a call succeeded and cleared the last error.
fn check_ok(status: MltStatus) -> Check {
    let message = last_error();
    ensure(
        status == MLT_STATUS_OK,
        &format!("{status:?}; message {message:?}"),
    )?;
    ensure(message.is_empty(), "a success clears the last error")
}

#[track_caller]
fn assert_ok(status: MltStatus) {
    pass(check_ok(status));
}

/// One bad input of a table: the label that names it in failure messages, the input, and
/// what the last error message must contain.
struct Case<T> {
    label: String,
    input: T,
    needles: Vec<String>,
}

/// A table of cases, one a line: `cases![x = base; change => [needles], ...]` gives each
/// case the input `base` (evaluated anew for each) with `change` applied to it as `x` (an
/// assignment, or a block of them), labelled with the change's source text.
macro_rules! cases {
    ($x:ident = $base:expr; $($change:expr => [$($needle:expr),* $(,)?]),+ $(,)?) => {
        vec![$({
            let mut $x = $base;
            $change;
            Case {
                label: stringify!($change).to_owned(),
                input: $x,
                needles: vec![$($needle.to_string()),*],
            }
        }),+]
    };
}

/// NaN and both infinities: no float a host passes may be one (unless the header says so).
const NON_FINITE: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// `non_finite_cases![x = base; place => "name" + "rule", ...]`: for each float `place` of
/// `x`, a case for each of NaN, +inf and -inf put there, whose message must say
/// "<name> is <value>" and contain each `rule` (what the valid values are).
macro_rules! non_finite_cases {
    ($x:ident = $base:expr; $($place:expr => $name:literal $(+ $rule:literal)*),+ $(,)?) => {{
        let mut cases = Vec::new();
        $(for value in NON_FINITE {
            let mut $x = $base;
            $place = value;
            cases.push(Case {
                label: format!("{} = {value}", stringify!($place)),
                input: $x,
                needles: vec![format!("{} is {value}", $name) $(, $rule.to_string())*],
            });
        })+
        cases
    }};
}

/// Checks every case with `check` (given its input and needles), then fails listing each case
/// that failed by its label, with why.
#[track_caller]
fn assert_cases<T>(table: &str, cases: &[Case<T>], check: impl Fn(&T, &[String]) -> Check) {
    assert_all(
        table,
        cases
            .iter()
            .map(|case| (case.label.clone(), check(&case.input, &case.needles))),
    );
}

/// Fails listing every `(label, result)` that is an error, after looking at all of them.
#[track_caller]
fn assert_all(table: &str, results: impl IntoIterator<Item = (String, Check)>) {
    let results: Vec<_> = results.into_iter().collect();
    assert!(!results.is_empty(), "{table}: the table is empty");
    let failures: Vec<String> = results
        .iter()
        .filter_map(|(label, result)| result.as_ref().err().map(|e| format!("  {label}: {e}")))
        .collect();
    assert!(
        failures.is_empty(),
        "{table}: {} of {} cases failed:\n{}",
        failures.len(),
        results.len(),
        failures.join("\n")
    );
}

/// An aligned, non-null pointer value no allocation will ever have: the "untouched" marker
/// for out-parameters that are pointers.
fn sentinel_scene() -> *mut MltScene {
    std::ptr::dangling_mut::<u64>().wrapping_add(0x1000).cast()
}

const SENTINEL_F32: f32 = -12345.0;

/// An `MltBytes` holding nothing, as a host declares one before a call fills it.
fn empty_bytes() -> MltBytes {
    MltBytes {
        data: null_mut(),
        size: 0,
    }
}

fn default_material() -> MltMaterial {
    let mut m = std::mem::MaybeUninit::<MltMaterial>::uninit();
    // SAFETY: writable memory for an MltMaterial.
    assert_ok(unsafe { mlt_material_init(m.as_mut_ptr(), size_of::<MltMaterial>()) });
    // SAFETY: initialized on success.
    unsafe { m.assume_init() }
}

fn default_camera() -> MltCamera {
    let mut c = std::mem::MaybeUninit::<MltCamera>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_camera_init(c.as_mut_ptr(), size_of::<MltCamera>()) });
    unsafe { c.assume_init() }
}

fn default_settings() -> MltRenderSettings {
    let mut s = std::mem::MaybeUninit::<MltRenderSettings>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_render_settings_init(s.as_mut_ptr(), size_of::<MltRenderSettings>()) });
    unsafe { s.assume_init() }
}

fn default_desc() -> MltSceneDesc {
    let mut d = std::mem::MaybeUninit::<MltSceneDesc>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_scene_desc_init(d.as_mut_ptr(), size_of::<MltSceneDesc>()) });
    unsafe { d.assume_init() }
}

fn render_stats_default() -> MltRenderStats {
    let mut s = MltRenderStats::default();
    // SAFETY: writable memory of this size.
    assert_ok(unsafe { mlt_render_stats_init(&mut s, size_of::<MltRenderStats>()) });
    s
}

fn scene_info_default() -> MltSceneInfo {
    let mut i = MltSceneInfo::default();
    // SAFETY: writable memory of this size.
    assert_ok(unsafe { mlt_scene_info_init(&mut i, size_of::<MltSceneInfo>()) });
    i
}

fn small_settings(width: u32, height: u32, spp: u32) -> MltRenderSettings {
    MltRenderSettings {
        width,
        height,
        algorithm: MLT_ALGORITHM_PATH,
        samples_per_pixel: spp,
        ..default_settings()
    }
}

/// Host-owned arrays of a scene; `desc()` points into them like a C host's struct would.
#[derive(Clone)]
struct HostScene {
    positions: Vec<f32>,
    indices: Vec<u32>,
    material_ids: Vec<u32>,
    materials: Vec<MltMaterial>,
    backend: i32,
}

impl HostScene {
    /// A floor quad (y = 0, facing +y, material 0) under a light quad (y = 2, facing -y,
    /// material 1): 8 vertices, 4 triangles, 2 materials.
    fn floor_and_light() -> Self {
        let floor = default_material();
        let light = MltMaterial {
            color: [0.0; 3],
            emission: [1.0, 1.0, 1.0],
            ..default_material()
        };
        HostScene {
            positions: vec![
                -1.0, 0.0, -1.0, -1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, -1.0, // floor
                -1.0, 2.0, -1.0, 1.0, 2.0, -1.0, 1.0, 2.0, 1.0, -1.0, 2.0, 1.0, // light
            ],
            indices: vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7],
            material_ids: vec![0, 0, 1, 1],
            materials: vec![floor, light],
            backend: MLT_BACKEND_BVH,
        }
    }

    fn cornell_box() -> Self {
        let mesh = common::cornell_box();
        HostScene {
            materials: mesh.c_materials(),
            positions: mesh.positions,
            indices: mesh.indices,
            material_ids: mesh.material_ids,
            backend: MLT_BACKEND_BVH,
        }
    }

    fn desc(&self) -> MltSceneDesc {
        MltSceneDesc {
            positions: self.positions.as_ptr(),
            positions_len: self.positions.len(),
            indices: self.indices.as_ptr(),
            indices_len: self.indices.len(),
            material_ids: self.material_ids.as_ptr(),
            material_ids_len: self.material_ids.len(),
            materials: self.materials.as_ptr(),
            materials_len: self.materials.len(),
            backend: self.backend,
            ..default_desc()
        }
    }

    /// `mlt_scene_create`, expecting success.
    fn create(&self) -> Handle {
        let mut out = null_mut();
        // SAFETY: the desc points into live vectors of the stated lengths.
        assert_ok(unsafe { mlt_scene_create(&self.desc(), &mut out) });
        assert!(!out.is_null());
        Handle(out)
    }
}

/// `mlt_scene_create` of a bad description: the status, the message, and `*out` untouched.
fn check_create_refused(
    desc: &MltSceneDesc,
    expected: MltStatus,
    needles: &[impl AsRef<str>],
) -> Check {
    let mut out = sentinel_scene();
    // SAFETY: every pointer in `desc` references an array of its length, or is one mlt must
    // refuse before reading (NULL, misaligned, or with a length no memory holds).
    let status = unsafe { mlt_scene_create(desc, &mut out) };
    if status == MLT_STATUS_OK {
        // SAFETY: a scene mlt created (wrongly), released once.
        unsafe { mlt_scene_release(out) };
    }
    check_error(status, expected, needles)?;
    ensure(out == sentinel_scene(), "*out must be untouched on failure")
}

/// Every case's description (`desc` of its input) is refused as invalid (`check_create_refused`).
#[track_caller]
fn assert_create_refuses<T>(table: &str, cases: &[Case<T>], desc: impl Fn(&T) -> MltSceneDesc) {
    assert_cases(table, cases, |input, needles| {
        check_create_refused(&desc(input), MLT_STATUS_INVALID_ARGUMENT, needles)
    });
}

/// Owns a scene, as a C++ host's RAII wrapper would.
struct Handle(*mut MltScene);

// SAFETY: the header promises that scenes are thread safe for rendering and queries.
unsafe impl Send for Handle {}
unsafe impl Sync for Handle {}

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: created by mlt_scene_create, released once.
        unsafe { mlt_scene_release(self.0) };
    }
}

impl Handle {
    fn info(&self) -> MltSceneInfo {
        let mut info = scene_info_default();
        // SAFETY: live scene, writable out.
        assert_ok(unsafe { mlt_scene_get_info(self.0, &mut info) });
        info
    }

    /// Renders into a buffer pre-filled with the sentinel; returns the status and buffer.
    fn render(
        &self,
        camera: &MltCamera,
        settings: &MltRenderSettings,
        out_len: usize,
    ) -> (MltStatus, Vec<f32>) {
        let mut image = vec![SENTINEL_F32; out_len];
        // SAFETY: valid pointers; the buffer holds out_len floats.
        let status = unsafe {
            mlt_render(
                self.0,
                camera,
                settings,
                image.as_mut_ptr(),
                out_len,
                None,
                null_mut(),
            )
        };
        (status, image)
    }

    /// A render of 4 × 4 pixels that must succeed: the image and the stats.
    #[track_caller]
    fn render_4x4_with_stats(
        &self,
        camera: &MltCamera,
        settings: &MltRenderSettings,
    ) -> (Vec<f32>, MltRenderStats) {
        let mut rgb = vec![0.0f32; 4 * 4 * 3];
        let mut stats = render_stats_default();
        // SAFETY: valid pointers; `rgb` holds the 48 floats passed.
        let status = unsafe {
            mlt_render_ex(
                self.0,
                camera,
                settings,
                rgb.as_mut_ptr(),
                rgb.len(),
                None,
                null_mut(),
                &mut stats,
            )
        };
        assert_eq!(status, MLT_STATUS_OK, "algorithm {}", settings.algorithm);
        (rgb, stats)
    }

    /// A render mlt must refuse as invalid: the needles in the message, and neither the
    /// image nor the stats written.
    fn check_render_refused(
        &self,
        camera: &MltCamera,
        settings: &MltRenderSettings,
        needles: &[impl AsRef<str>],
    ) -> Check {
        let len = 16 * 16 * 3;
        let mut image = vec![SENTINEL_F32; len];
        let mut stats = MltRenderStats {
            samples: 77,
            ..render_stats_default()
        };
        // SAFETY: valid pointers; `len` floats.
        let status = unsafe {
            mlt_render_ex(
                self.0,
                camera,
                settings,
                image.as_mut_ptr(),
                len,
                None,
                null_mut(),
                &mut stats,
            )
        };
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)?;
        ensure(
            image.iter().all(|&v| v == SENTINEL_F32),
            "rgb_out must be untouched on failure",
        )?;
        ensure(
            stats.samples == 77,
            "stats_out must be untouched on failure",
        )
    }

    /// Every case's settings, rendered with `camera`, are refused (`check_render_refused`).
    #[track_caller]
    fn assert_refuses_settings(
        &self,
        table: &str,
        camera: &MltCamera,
        cases: &[Case<MltRenderSettings>],
    ) {
        assert_cases(table, cases, |settings, needles| {
            self.check_render_refused(camera, settings, needles)
        });
    }

    fn intersect(&self, rays: &[MltRay]) -> (MltStatus, Vec<MltHit>) {
        let mut hits = vec![SENTINEL_HIT; rays.len()];
        // SAFETY: both arrays hold rays.len() elements.
        let status = unsafe { mlt_intersect(self.0, rays.as_ptr(), rays.len(), hits.as_mut_ptr()) };
        (status, hits)
    }

    fn occluded(&self, rays: &[MltRay]) -> (MltStatus, Vec<u8>) {
        let mut flags = vec![0xAB; rays.len()];
        // SAFETY: both arrays hold rays.len() elements.
        let status = unsafe { mlt_occluded(self.0, rays.as_ptr(), rays.len(), flags.as_mut_ptr()) };
        (status, flags)
    }
}

const SENTINEL_HIT: MltHit = MltHit {
    triangle_id: 0xDEAD,
    t: SENTINEL_F32,
    u: SENTINEL_F32,
    v: SENTINEL_F32,
};

fn ray(origin: [f32; 3], direction: [f32; 3]) -> MltRay {
    MltRay {
        origin,
        tmin: 0.0,
        direction,
        tmax: f32::INFINITY,
    }
}

/// Camera for the floor-and-light scene: from the front, slightly above the floor.
fn floor_camera() -> MltCamera {
    MltCamera {
        eye: [0.0, 1.0, -4.0],
        target: [0.0, 1.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 60.0,
        ..default_camera()
    }
}

fn assert_valid_image(image: &[f32], what: &str) {
    assert!(
        image.iter().all(|v| v.is_finite() && *v >= 0.0),
        "{what}: every value must be finite and non-negative"
    );
}

// ---------------------------------------------------------------------------------------
// Initializers, versions, status strings, release
// ---------------------------------------------------------------------------------------

// Each initializer refusing NULL: `initializers_refuse_null_and_unknown_sizes` (struct_size).

#[test]
fn defaults_are_valid_and_documented() {
    let m = default_material();
    assert_eq!(m.kind, MLT_MATERIAL_DIFFUSE);
    assert_eq!(m.emission, [0.0; 3]);
    assert_eq!(m.ior, 1.5);
    let d = default_desc();
    assert!(d.positions.is_null() && d.positions_len == 0 && d.backend == MLT_BACKEND_BVH);
    let c = default_camera();
    assert_eq!(c.eye, [278.0, 273.0, -800.0]);
    assert_eq!(c.target, [278.0, 273.0, -799.0]);
    assert!((c.fov_y_deg - 39.3076).abs() < 1e-3);
    let s = default_settings();
    assert_eq!((s.width, s.height, s.samples_per_pixel), (256, 256, 64));
    assert_eq!((s.max_depth, s.seed, s.threads), (5, 0, 0));
    assert_eq!(
        (s.algorithm, s.time_limit_seconds),
        (MLT_ALGORITHM_MMLT, 0.0)
    );
    assert_eq!(
        (s.mutations_per_pixel, s.bootstrap_samples, s.chains),
        (32, 0, 1024)
    );
    assert_eq!(s.normalization_work_fraction, 0.05);
    assert_eq!(
        (
            s.large_step_probability,
            s.small_step_sigma,
            s.direct_samples_per_mutation
        ),
        (0.3, 0.01, 1)
    );
    assert_eq!((s.erpt_chain_length, s.erpt_deposit_energy), (10, 0.0));
    assert_eq!(
        (s.adapt_mutation_weights, s.perturb_in_sample_space),
        (0, 0)
    );
    assert_eq!(
        (s.filter_buffers, s.filter_strength, s.filter_radius),
        (0, 0.45, 7)
    );
}

#[test]
fn version_function_matches_the_macros() {
    assert_eq!(
        mlt_version(),
        MLT_VERSION_MAJOR * 10000 + MLT_VERSION_MINOR * 100 + MLT_VERSION_PATCH
    );
    assert_eq!(mlt_version(), MLT_VERSION);
    // SAFETY: static string.
    let s = unsafe { CStr::from_ptr(mlt_version_string()) };
    assert_eq!(s.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
}

#[test]
fn status_string_of_every_value() {
    assert_eq!(status_string(0), "success");
    assert_eq!(status_string(1), "invalid argument");
    assert_eq!(status_string(2), "unsupported");
    assert_eq!(status_string(3), "out of memory");
    assert!(status_string(4).contains("cancelled"));
    assert_eq!(status_string(5), "time limit reached");
    assert_eq!(status_string(6), "internal error");
    for unknown in [7, 100, -1, i32::MIN, i32::MAX] {
        assert_eq!(status_string(unknown), "unknown status", "status {unknown}");
    }
}

/// Releasing NULL touches nothing: the thread's last error stays as it was, and scenes are
/// created and released as before.
#[test]
fn release_null_leaves_the_last_error_and_the_library_as_they_were() {
    let mut out = sentinel_scene();
    // SAFETY: NULL desc must be rejected.
    let status = unsafe { mlt_scene_create(null(), &mut out) };
    assert_invalid(status, &["desc", "NULL"]);
    let error = last_error();
    // SAFETY: NULL is documented as a no-op.
    unsafe {
        mlt_scene_release(null_mut());
        mlt_scene_release(null_mut());
    }
    assert_eq!(last_error(), error);
    drop(HostScene::floor_and_light().create());
}

/// Pointers that are not live scenes (released, never created, misaligned, NULL) are
/// refused by every call that takes a scene, never dereferenced; retain adds a reference
/// that one more release drops.
#[test]
fn released_and_foreign_scene_pointers_are_refused() {
    let floor = HostScene::floor_and_light();
    let mut out = sentinel_scene();
    // SAFETY: a valid description and out-parameter.
    assert_ok(unsafe { mlt_scene_create(&floor.desc(), &mut out) });
    let released = out;
    // SAFETY: pointers are looked up, not dereferenced.
    unsafe {
        assert_ok(mlt_scene_retain(released));
        mlt_scene_release(released);
    }
    let retained = Handle(released);
    assert_eq!(
        retained.info().triangle_count,
        4,
        "retained scene still live"
    );
    drop(retained);

    let mut word = 0u64;
    let stack = (&raw mut word).cast::<MltScene>();
    let odd = stack.cast::<u8>().wrapping_add(1).cast::<MltScene>();
    let camera = floor_camera();
    let settings = small_settings(4, 4, 1);
    let rays = [ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])];
    let plan = {
        let live = floor.create();
        let mut bytes = empty_bytes();
        // SAFETY: a live scene and valid pointers.
        assert_ok(unsafe { mlt_render_plan(live.0, &camera, &settings, &mut bytes) });
        // SAFETY: the bytes mlt gave, read before they are released.
        let plan = unsafe { std::slice::from_raw_parts(bytes.data, bytes.size) }.to_vec();
        // SAFETY: filled by mlt_render_plan, released once.
        unsafe { mlt_bytes_release(&mut bytes) };
        plan
    };
    for (what, scene) in [
        ("released", released),
        ("foreign", stack),
        ("misaligned", odd),
        ("sentinel", sentinel_scene()),
    ] {
        let mut image = vec![SENTINEL_F32; 48];
        let mut hits = [SENTINEL_HIT];
        let mut flags = [0xABu8];
        let mut info = scene_info_default();
        let (mut plan_out, mut partial_out) = (empty_bytes(), empty_bytes());
        // SAFETY: every other pointer is valid; `scene` must be refused before use.
        let statuses = unsafe {
            [
                mlt_render_plan(scene, &camera, &settings, &mut plan_out),
                mlt_render_job(
                    scene,
                    plan.as_ptr(),
                    plan.len(),
                    0,
                    1,
                    1,
                    None,
                    null_mut(),
                    &mut partial_out,
                    null_mut(),
                ),
                mlt_scene_get_info(scene, &mut info),
                mlt_render(
                    scene,
                    &camera,
                    &settings,
                    image.as_mut_ptr(),
                    image.len(),
                    None,
                    null_mut(),
                ),
                mlt_intersect(scene, rays.as_ptr(), 1, hits.as_mut_ptr()),
                mlt_occluded(scene, rays.as_ptr(), 1, flags.as_mut_ptr()),
                mlt_scene_retain(scene),
            ]
        };
        for status in statuses {
            assert_invalid(status, &["scene", "not a live scene"]);
        }
        assert!(
            image.iter().all(|&v| v == SENTINEL_F32),
            "{what}: image written"
        );
        assert_eq!(hits[0].triangle_id, SENTINEL_HIT.triangle_id, "{what}");
        assert_eq!((flags[0], info.triangle_count), (0xAB, 0), "{what}");
        assert!(
            plan_out.data.is_null() && partial_out.data.is_null(),
            "{what}: bytes written"
        );
        // SAFETY: looked up, not dereferenced; ignored with a message.
        unsafe { mlt_scene_release(scene) };
        assert!(
            last_error().contains("not a live scene"),
            "{what}: {}",
            last_error()
        );
    }
    assert_eq!(word, 0, "a foreign pointer's memory was written");
    // SAFETY: NULL is refused by retain.
    assert_invalid(unsafe { mlt_scene_retain(null_mut()) }, &["scene", "NULL"]);
}

/// A scene released while renders and queries on other threads are running stays alive
/// until they return: each image equals the same render on a scene nobody releases.
#[test]
fn a_scene_released_during_renders_stays_alive_until_they_return() {
    let floor = HostScene::floor_and_light();
    let camera = floor_camera();
    let settings = MltRenderSettings {
        threads: 1,
        // Long enough (about half a second unloaded) that the renders are still tracing
        // rays when the progress callback's first call, after 50 ms, lets the release
        // happen.
        ..small_settings(16, 16, 16384)
    };
    let reference = floor.create().render(&camera, &settings, 16 * 16 * 3);
    assert_ok(reference.0);

    const RENDERS: usize = 3;
    let doomed = floor.create();
    let started = std::sync::Barrier::new(RENDERS + 1);
    let images = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..RENDERS)
            .map(|_| {
                // The address crosses threads as a number: the threads must not borrow the
                // handle that is dropped under them.
                let (scene, started, camera, settings) =
                    (doomed.0 as usize, &started, &camera, &settings);
                scope.spawn(move || {
                    let mut image = vec![0.0f32; 16 * 16 * 3];
                    // The first progress call (while the render's workers trace) waits
                    // until every render is under way; then the scene is released.
                    let mut first = Some(started);
                    let mut released_at = None;
                    let mut on_progress = |fraction: f32| {
                        if let Some(barrier) = first.take() {
                            released_at = Some(fraction);
                            barrier.wait();
                        }
                        true
                    };
                    let status = render_with_progress(
                        scene as *const MltScene,
                        camera,
                        settings,
                        &mut image,
                        &mut on_progress,
                    );
                    (status, image, released_at)
                })
            })
            .collect();
        started.wait();
        // Every render is running: drop the only host reference under them.
        drop(doomed);
        workers
            .into_iter()
            .map(|w| w.join().expect("render thread"))
            .collect::<Vec<_>>()
    });
    for (status, image, released_at) in images {
        assert_ok(status);
        let released_at = released_at.expect("the callback was called");
        assert!(
            released_at < 0.75,
            "the release came at {released_at} of a render, not well before its end"
        );
        assert!(
            image == reference.1,
            "a render lost its scene while running"
        );
    }
}

/// `mlt_render` with a Rust closure as the progress callback.
fn render_with_progress(
    scene: *const MltScene,
    camera: &MltCamera,
    settings: &MltRenderSettings,
    image: &mut [f32],
    on_progress: &mut dyn FnMut(f32) -> bool,
) -> MltStatus {
    unsafe extern "C" fn trampoline(fraction: f32, user_data: *mut std::ffi::c_void) -> bool {
        // SAFETY: `user_data` is the `&mut dyn FnMut` below, alive for the render.
        let callback = unsafe { &mut *user_data.cast::<&mut dyn FnMut(f32) -> bool>() };
        callback(fraction)
    }
    let mut callback = on_progress;
    // SAFETY: valid pointers; `image` holds the floats passed; the callback's user data
    // outlives the call.
    unsafe {
        mlt_render(
            scene,
            camera,
            settings,
            image.as_mut_ptr(),
            image.len(),
            Some(trampoline),
            (&raw mut callback).cast(),
        )
    }
}

#[test]
fn backend_supported() {
    assert!(mlt_backend_supported(MLT_BACKEND_BVH));
    assert_eq!(
        mlt_backend_supported(MLT_BACKEND_EMBREE),
        cfg!(feature = "embree")
    );
    assert!(!mlt_backend_supported(2));
    assert!(!mlt_backend_supported(7));
    assert!(!mlt_backend_supported(-1));
    assert!(!mlt_backend_supported(i32::MIN));
    for (c, rust) in [
        (MLT_BACKEND_BVH, mlt::Backend::Bvh),
        (MLT_BACKEND_EMBREE, mlt::Backend::Embree),
    ] {
        assert_eq!(mlt_backend_supported(c), rust.is_available());
    }
}

/// The backends `mlt_backend_supported` says this build has.
fn supported_backends() -> Vec<i32> {
    [MLT_BACKEND_BVH, MLT_BACKEND_EMBREE]
        .into_iter()
        .filter(|&b| mlt_backend_supported(b))
        .collect()
}

// ---------------------------------------------------------------------------------------
// struct_size: hosts built against an older (or newer) header
// ---------------------------------------------------------------------------------------

/// The size of a layout whose fields end where `first_missing` starts, padded as C pads it.
fn earlier_size<T>(first_missing: usize) -> u32 {
    first_missing.next_multiple_of(align_of::<T>()) as u32
}

/// Sizes no header ever had: never initialized, too small, between layouts (4 short of
/// today's: a layout ends at a multiple of the alignment, and the last two may be only 8
/// apart), from the future.
fn unknown_sizes<T>() -> [usize; 4] {
    [0, 3, size_of::<T>() - 4, size_of::<T>() + 8]
}

/// NULL and every unknown size, for each of the six initializers: refused, naming the
/// initializer, with `out` untouched; the struct's own size is taken and written.
#[test]
fn initializers_refuse_null_and_unknown_sizes() {
    type Init = fn(*mut u8, usize) -> MltStatus;
    // Each takes its own struct; `storage` below is large and aligned enough for any.
    // SAFETY (each closure): forwards the pointer and size to the initializer under test.
    let initializers: [(&str, usize, Init); 6] = [
        (
            "mlt_material_default",
            size_of::<MltMaterial>(),
            |p, n| unsafe { mlt_material_init(p.cast(), n) },
        ),
        (
            "mlt_scene_desc_default",
            size_of::<MltSceneDesc>(),
            |p, n| unsafe { mlt_scene_desc_init(p.cast(), n) },
        ),
        (
            "mlt_camera_default",
            size_of::<MltCamera>(),
            |p, n| unsafe { mlt_camera_init(p.cast(), n) },
        ),
        (
            "mlt_render_settings_default",
            size_of::<MltRenderSettings>(),
            |p, n| unsafe { mlt_render_settings_init(p.cast(), n) },
        ),
        (
            "mlt_render_stats_default",
            size_of::<MltRenderStats>(),
            |p, n| unsafe { mlt_render_stats_init(p.cast(), n) },
        ),
        (
            "mlt_scene_info_default",
            size_of::<MltSceneInfo>(),
            |p, n| unsafe { mlt_scene_info_init(p.cast(), n) },
        ),
    ];
    let mut results = Vec::new();
    for (name, size, init) in initializers {
        let mut storage = [0xABu8; 512];
        let aligned = storage
            .as_mut_ptr()
            .wrapping_add(storage.as_ptr().align_offset(8));
        let status = init(null_mut(), size);
        results.push((
            format!("{name}: out NULL"),
            check_error(status, MLT_STATUS_INVALID_ARGUMENT, &["out", "NULL"]),
        ));
        // The storage holds any size tried (< 512 - 8); as `unknown_sizes`.
        for bad in [0, 3, size - 4, size + 8] {
            let status = init(aligned, bad);
            let needles = ["out.struct_size", &bad.to_string(), name];
            let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &needles)
                .and_then(|()| ensure(storage.iter().all(|&b| b == 0xAB), "out written"));
            results.push((format!("{name}: struct_size {bad}"), result));
        }
        let status = init(aligned, size);
        // SAFETY: 4 aligned bytes of `storage`, initialized.
        let written = unsafe { aligned.cast::<u32>().read() };
        let result =
            check_ok(status).and_then(|()| ensure(written as usize == size, "struct_size not set"));
        results.push((format!("{name}: its own size {size}"), result));
    }
    assert_all("initializers", results);
}

/// Each struct mlt reads or writes, with each size no header had, where the call reads it.
#[test]
fn unknown_struct_sizes_are_refused_where_each_struct_is_read() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    let (camera, settings) = (floor_camera(), small_settings(4, 4, 1));
    let mut results = Vec::new();
    for size in unknown_sizes::<MltRenderSettings>() {
        let bad = MltRenderSettings {
            struct_size: size as u32,
            ..settings
        };
        let needles = ["settings.struct_size", &size.to_string()];
        let result = scene.check_render_refused(&camera, &bad, &needles);
        results.push((format!("settings.struct_size = {size}"), result));
    }
    for size in unknown_sizes::<MltCamera>() {
        let bad = MltCamera {
            struct_size: size as u32,
            ..camera
        };
        let result = scene.check_render_refused(&bad, &settings, &["camera.struct_size"]);
        results.push((format!("camera.struct_size = {size}"), result));
    }
    for size in unknown_sizes::<MltRenderStats>() {
        let mut stats = MltRenderStats {
            struct_size: size as u32,
            samples: 77,
            ..render_stats_default()
        };
        let mut image = vec![SENTINEL_F32; 48];
        // SAFETY: valid pointers; 48 floats.
        let status = unsafe {
            mlt_render_ex(
                scene.0,
                &camera,
                &settings,
                image.as_mut_ptr(),
                48,
                None,
                null_mut(),
                &mut stats,
            )
        };
        let needles = ["stats_out.struct_size", "mlt_render_stats_default"];
        let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &needles).and_then(|()| {
            ensure(
                image.iter().all(|&v| v == SENTINEL_F32) && stats.samples == 77,
                "rgb_out or stats_out written",
            )
        });
        results.push((format!("stats_out.struct_size = {size}"), result));
    }
    // mlt_render_plan reads the camera and the settings too.
    for size in unknown_sizes::<MltRenderSettings>() {
        let bad = MltRenderSettings {
            struct_size: size as u32,
            ..settings
        };
        let mut plan = empty_bytes();
        // SAFETY: valid pointers.
        let status = unsafe { mlt_render_plan(scene.0, &camera, &bad, &mut plan) };
        let result = check_error(
            status,
            MLT_STATUS_INVALID_ARGUMENT,
            &["settings.struct_size"],
        )
        .and_then(|()| ensure(plan.data.is_null(), "plan_out written"));
        results.push((
            format!("mlt_render_plan settings.struct_size = {size}"),
            result,
        ));
    }
    for size in unknown_sizes::<MltCamera>() {
        let bad = MltCamera {
            struct_size: size as u32,
            ..camera
        };
        let mut plan = empty_bytes();
        // SAFETY: valid pointers.
        let status = unsafe { mlt_render_plan(scene.0, &bad, &settings, &mut plan) };
        let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &["camera.struct_size"])
            .and_then(|()| ensure(plan.data.is_null(), "plan_out written"));
        results.push((
            format!("mlt_render_plan camera.struct_size = {size}"),
            result,
        ));
    }
    for size in unknown_sizes::<MltSceneInfo>() {
        let mut info = MltSceneInfo {
            struct_size: size as u32,
            triangle_count: 99,
            ..scene_info_default()
        };
        // SAFETY: live scene, writable out.
        let status = unsafe { mlt_scene_get_info(scene.0, &mut info) };
        let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &["out.struct_size"])
            .and_then(|()| ensure(info.triangle_count == 99, "out written"));
        results.push((
            format!("mlt_scene_get_info out.struct_size = {size}"),
            result,
        ));
    }
    for size in unknown_sizes::<MltSceneDesc>() {
        let desc = MltSceneDesc {
            struct_size: size as u32,
            ..host.desc()
        };
        let result =
            check_create_refused(&desc, MLT_STATUS_INVALID_ARGUMENT, &["desc.struct_size"]);
        results.push((format!("desc.struct_size = {size}"), result));
    }
    for size in unknown_sizes::<MltMaterial>() {
        let mut bad = host.clone();
        bad.materials[0].struct_size = size as u32;
        let needles = ["desc.materials[0].struct_size"];
        let result = check_create_refused(&bad.desc(), MLT_STATUS_INVALID_ARGUMENT, &needles);
        results.push((format!("materials[0].struct_size = {size}"), result));
    }
    // An array's stride is its first element's size: every element must carry the same.
    let mut mixed = host.clone();
    mixed.materials[1].struct_size += 8;
    let needles = ["desc.materials[1].struct_size", "desc.materials[0]'s"];
    let result = check_create_refused(&mixed.desc(), MLT_STATUS_INVALID_ARGUMENT, &needles);
    results.push((
        "materials[1].struct_size = materials[0]'s + 8".into(),
        result,
    ));
    assert_all("struct_size", results);
}

/// A host built against the header before the post-process filter (its settings end at
/// `perturb_in_sample_space`, its stats at `mutation_weights`) renders the image a current
/// host gets with the filter off, and mlt writes none of the stats it does not have. The C
/// version of this host is `tests/c_hosts.rs`'s `a_host_built_against_the_previous_header_renders`.
#[test]
fn an_older_layout_reads_what_it_has_and_defaults_the_rest() {
    let scene = HostScene::floor_and_light().create();
    let current = MltRenderSettings {
        algorithm: MLT_ALGORITHM_PSSMLT,
        mutations_per_pixel: 2,
        ..small_settings(4, 4, 1)
    };
    let (expected, expected_stats) = scene.render_4x4_with_stats(&floor_camera(), &current);
    // Past an older host's struct lies memory of its own: mlt must not read it.
    let older = MltRenderSettings {
        struct_size: earlier_size::<MltRenderSettings>(std::mem::offset_of!(
            MltRenderSettings,
            filter_buffers
        )),
        filter_buffers: 999,
        filter_strength: f32::NAN,
        filter_radius: 0,
        normalization_work_fraction: -1.0,
        ..current
    };
    let first_missing_stat = std::mem::offset_of!(MltRenderStats, filter_changed_fraction);
    let mut stats = MltRenderStats {
        struct_size: earlier_size::<MltRenderStats>(first_missing_stat),
        filter_changed_fraction: -7.0,
        normalization_samples: 77,
        normalization_largest_share: -7.0,
        ..render_stats_default()
    };
    let mut rgb = vec![0.0f32; 48];
    // SAFETY: valid pointers; 48 floats.
    let status = unsafe {
        mlt_render_ex(
            scene.0,
            &floor_camera(),
            &older,
            rgb.as_mut_ptr(),
            48,
            None,
            null_mut(),
            &mut stats,
        )
    };
    assert_ok(status);
    assert_eq!(
        rgb, expected,
        "the same image as with today's defaults for the missing fields"
    );
    assert_eq!(
        (stats.samples, stats.mutations),
        (expected_stats.samples, expected_stats.mutations)
    );
    assert_eq!(stats.normalization, expected_stats.normalization);
    assert_eq!(
        (
            stats.filter_changed_fraction,
            stats.normalization_samples,
            stats.normalization_largest_share
        ),
        (-7.0, 77, -7.0),
        "fields past the host's struct are not written"
    );
    assert_eq!(
        stats.struct_size,
        earlier_size::<MltRenderStats>(first_missing_stat)
    );
}

// ---------------------------------------------------------------------------------------
// mlt_scene_create: pointers
// ---------------------------------------------------------------------------------------

#[test]
fn scene_create_null_desc_or_out() {
    let mut out = sentinel_scene();
    // SAFETY: NULL desc must be rejected.
    let status = unsafe { mlt_scene_create(null(), &mut out) };
    assert_invalid(status, &["desc", "NULL"]);
    assert_eq!(out, sentinel_scene());
    let host = HostScene::floor_and_light();
    // SAFETY: NULL out must be rejected.
    let status = unsafe { mlt_scene_create(&host.desc(), null_mut()) };
    assert_invalid(status, &["out", "NULL"]);
}

/// Array pointers mlt must refuse before reading them: NULL with a length, misaligned, and
/// lengths whose byte size overflows.
#[test]
fn scene_create_bad_arrays() {
    let host = HostScene::floor_and_light();
    // u64 storage: one byte past its start is misaligned for every multi-byte type.
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let cases = cases![d = host.desc();
        d.positions = null() => ["positions", "NULL"],
        d.indices = null() => ["indices", "NULL"],
        d.materials = null() => ["materials", "NULL"],
        d.material_ids = null() => ["material_ids", "NULL"],
        d.positions = odd.cast() => ["positions", "aligned"],
        d.indices = odd.cast() => ["indices", "aligned"],
        d.positions_len = usize::MAX / 2 => ["positions", "address space"],
        d.indices_len = usize::MAX => ["indices", "address space"],
    ];
    assert_create_refuses("scene arrays", &cases, |d| *d);
}

#[test]
fn scene_create_null_arrays_with_zero_length_are_an_empty_scene() {
    let desc = default_desc();
    let mut out = null_mut();
    // SAFETY: NULL arrays with length 0 are documented as fine.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let scene = Handle(out);
    let info = scene.info();
    assert_eq!(info.triangle_count, 0);
    assert_eq!(info.emitter_count, 0);
    let (status, image) = scene.render(&default_camera(), &small_settings(4, 4, 2), 48);
    assert_ok(status);
    assert!(
        image.iter().all(|&v| v == 0.0),
        "an empty scene renders black"
    );
}

// ---------------------------------------------------------------------------------------
// mlt_scene_create: counts and indices
// ---------------------------------------------------------------------------------------

#[test]
fn scene_create_bad_counts() {
    let host = HostScene::floor_and_light();
    let cases = cases![d = host.desc();
        d.positions_len = 23 => ["positions", "23"],
        d.indices_len = 11 => ["indices", "11"],
        d.material_ids_len = 3 => ["material_ids", "3", "4 triangles"],
        {
            (d.materials, d.materials_len) = (null(), 0);
            (d.material_ids, d.material_ids_len) = (null(), 0);
        } => ["materials", "empty"],
    ];
    assert_create_refuses("scene counts", &cases, |d| *d);
}

#[test]
fn scene_create_indices_out_of_range() {
    let host = HostScene::floor_and_light();
    let cases = cases![h = host.clone();
        h.indices[7] = 8 => ["indices[7]", "8", "8 vertices"],
        h.indices[7] = u32::MAX => ["indices[7]", "4294967295"],
        h.material_ids[3] = 2 => ["material_ids[3]", "2", "2 materials"],
    ];
    assert_create_refuses("scene indices", &cases, HostScene::desc);
}

#[test]
fn missing_material_ids_mean_material_0() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        material_ids: null(),
        material_ids_len: 0,
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: valid desc.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let scene = Handle(out);
    assert_eq!(scene.info().emitter_count, 0, "material 0 does not emit");
}

// ---------------------------------------------------------------------------------------
// mlt_scene_create: float values and enums
// ---------------------------------------------------------------------------------------

/// Every float of the vertices and materials must be finite (`ior` too where it is ignored,
/// on a diffuse material), colors within [0, 1] and emission not negative.
#[test]
fn scene_create_bad_floats() {
    let host = HostScene::floor_and_light();
    let mut cases = cases![h = host.clone();
        h.positions[13] = f32::NAN => ["positions[13]", "vertex 4", "y", "NaN"],
        h.positions[13] = f32::INFINITY => ["positions[13]", "vertex 4", "y", "inf"],
        h.positions[13] = f32::NEG_INFINITY => ["positions[13]", "vertex 4", "y", "-inf"],
        h.materials[0].color[2] = -0.5 => ["materials[0].color.z", "-0.5"],
        h.materials[1].color[0] = 1.5 => ["materials[1].color.x", "1.5"],
        h.materials[1].emission[2] = -1.0 => ["materials[1].emission.z", "-1", "negative"],
    ];
    cases.extend(non_finite_cases![h = host.clone();
        h.materials[0].color[0] => "desc.materials[0].color.x" + "finite",
        h.materials[0].color[1] => "desc.materials[0].color.y" + "finite",
        h.materials[0].color[2] => "desc.materials[0].color.z" + "finite",
        h.materials[1].emission[0] => "desc.materials[1].emission.x" + "finite",
        h.materials[1].emission[1] => "desc.materials[1].emission.y" + "finite",
        h.materials[1].emission[2] => "desc.materials[1].emission.z" + "finite",
        h.materials[0].ior => "desc.materials[0].ior" + "finite",
    ]);
    assert_create_refuses("scene floats", &cases, HostScene::desc);
}

#[test]
fn scene_create_bad_dielectric_ior() {
    let mut dielectric = HostScene::floor_and_light();
    dielectric.materials[0].kind = MLT_MATERIAL_DIELECTRIC;
    let mut cases = cases![h = dielectric.clone();
        h.materials[0].ior = 0.0 => ["materials[0].ior", "greater than 0"],
        h.materials[0].ior = -0.0 => ["materials[0].ior", "greater than 0"],
        h.materials[0].ior = -1.5 => ["materials[0].ior", "greater than 0"],
    ];
    cases.extend(non_finite_cases![h = dielectric.clone();
        h.materials[0].ior => "desc.materials[0].ior" + "finite",
    ]);
    assert_create_refuses("dielectric ior", &cases, HostScene::desc);
}

#[test]
fn ior_is_ignored_for_non_dielectrics() {
    // The header: "Ignored otherwise". Zero or negative is accepted for diffuse and mirror
    // (a non-finite one is not: `scene_create_bad_floats`).
    for kind in [MLT_MATERIAL_DIFFUSE, MLT_MATERIAL_MIRROR] {
        let mut host = HostScene::floor_and_light();
        host.materials[0].kind = kind;
        host.materials[0].ior = -1.0;
        drop(host.create());
    }
}

#[test]
fn scene_create_unknown_enums() {
    let host = HostScene::floor_and_light();
    let cases = cases![h = host.clone();
        h.materials[1].kind = 4
            => ["materials[1].kind is 4", "MLT_MATERIAL_DIFFUSE", "MLT_MATERIAL_METALLIC_ROUGHNESS"],
        h.materials[1].kind = -1 => ["materials[1].kind is -1", "MLT_MATERIAL_DIFFUSE"],
        h.materials[1].kind = i32::MAX
            => ["materials[1].kind is 2147483647", "MLT_MATERIAL_DIFFUSE"],
        h.backend = 2 => ["backend", "2"],
        h.backend = -1 => ["backend", "-1"],
        h.backend = i32::MIN => ["backend", "-2147483648"],
    ];
    assert_create_refuses("scene enums", &cases, HostScene::desc);
}

#[test]
#[cfg(not(feature = "embree"))]
fn embree_backend_is_unsupported_without_the_feature() {
    let mut host = HostScene::floor_and_light();
    host.backend = MLT_BACKEND_EMBREE;
    let needles = ["Embree", "`embree` feature"];
    pass(check_create_refused(
        &host.desc(),
        MLT_STATUS_UNSUPPORTED,
        &needles,
    ));
}

#[test]
#[cfg(feature = "embree")]
fn embree_backend_builds_with_the_feature() {
    let mut host = HostScene::floor_and_light();
    host.backend = MLT_BACKEND_EMBREE;
    let scene = host.create();
    let info = scene.info();
    assert_eq!(info.backend, MLT_BACKEND_EMBREE);
    assert_eq!((info.triangle_count, info.emitter_count), (4, 2));
    let (status, hits) = scene.intersect(&[ray([0.5, 1.0, 0.25], [0.0, 2.0, 0.0])]);
    assert_ok(status);
    assert!(hits[0].triangle_id >= 2, "the upward ray hits the light");
    // Embree's t may be an ulp off (3.13.5 reports 0.49999997 on some CPUs).
    assert!(
        (hits[0].t - 0.5).abs() <= 2.0 * f32::EPSILON,
        "t in multiples of the direction: {}",
        hits[0].t
    );
}

// ---------------------------------------------------------------------------------------
// Degenerate triangles: accepted, counted, never hit, never emit
// ---------------------------------------------------------------------------------------

/// The floor-and-light scene plus, floating at y = 1, a triangle with a repeated vertex and a
/// triangle with collinear vertices, both emissive.
fn with_degenerates() -> HostScene {
    let mut host = HostScene::floor_and_light();
    host.positions.extend([
        -0.5, 1.0, 0.0, // 8
        0.5, 1.0, 0.0, // 9
        0.0, 1.0, 0.0, // 10: midpoint of 8-9
    ]);
    host.indices.extend([8, 9, 9, 8, 10, 9]);
    host.material_ids.extend([1, 1]);
    host
}

#[test]
fn degenerate_triangles_are_accepted_and_counted() {
    let scene = with_degenerates().create();
    let info = scene.info();
    assert_eq!(info.triangle_count, 6);
    assert_eq!(info.degenerate_triangle_count, 2);
    assert_eq!(info.emitter_count, 2, "degenerate triangles never emit");
    assert_eq!(info.bounds_min, [-1.0, 0.0, -1.0]);
    assert_eq!(info.bounds_max, [1.0, 2.0, 1.0]);
    assert_eq!(info.backend, MLT_BACKEND_BVH);
}

#[test]
fn degenerate_triangles_are_never_hit() {
    for backend in supported_backends() {
        let mut host = with_degenerates();
        host.backend = backend;
        degenerate_triangles_are_never_hit_with(host.create());
    }
}

fn degenerate_triangles_are_never_hit_with(scene: Handle) {
    // Rays through the degenerate triangles' line, from several directions.
    let rays = [
        ray([0.0, 1.0, -3.0], [0.0, 0.0, 1.0]), // along z, through the midpoint
        ray([0.25, 1.0, -3.0], [0.0, 0.0, 1.0]),
        ray([-3.0, 1.0, 0.0], [1.0, 0.0, 0.0]), // along the line itself
        ray([0.0, 1.5, 0.0], [0.0, -1.0, 0.0]), // down through it onto the floor
    ];
    let (status, hits) = scene.intersect(&rays);
    assert_ok(status);
    for (i, hit) in hits.iter().enumerate() {
        assert!(
            hit.triangle_id != 4 && hit.triangle_id != 5,
            "ray {i} hit degenerate triangle {}",
            hit.triangle_id
        );
    }
    assert_eq!(hits[0].triangle_id, MLT_INVALID_ID);
    assert_eq!(hits[0].t, f32::INFINITY);
    assert!(
        hits[3].triangle_id < 2,
        "the downward ray reaches the floor"
    );
    assert!((hits[3].t - 1.5).abs() < 1e-5);
    let (status, flags) = scene.occluded(&rays[..3]);
    assert_ok(status);
    assert_eq!(flags, [0, 0, 0]);
}

#[test]
fn a_scene_of_only_degenerate_triangles_renders_black() {
    let host = HostScene {
        positions: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0],
        indices: vec![0, 1, 2, 0, 0, 1, 2, 2, 2],
        material_ids: vec![0, 1, 1],
        materials: vec![
            default_material(),
            MltMaterial {
                emission: [5.0; 3],
                ..default_material()
            },
        ],
        backend: MLT_BACKEND_BVH,
    };
    let scene = host.create();
    let info = scene.info();
    assert_eq!(
        (
            info.triangle_count,
            info.degenerate_triangle_count,
            info.emitter_count
        ),
        (3, 3, 0)
    );
    let camera = MltCamera {
        eye: [1.0, 1.0, -5.0],
        target: [1.0, 1.0, 1.0],
        ..default_camera()
    };
    let (status, image) = scene.render(&camera, &small_settings(8, 8, 4), 8 * 8 * 3);
    assert_ok(status);
    assert!(image.iter().all(|&v| v == 0.0));
    let (status, hits) = scene.intersect(&[ray([1.0, 1.0, -5.0], [0.0, 0.0, 1.0])]);
    assert_ok(status);
    assert_eq!(hits[0].triangle_id, MLT_INVALID_ID);
}

// ---------------------------------------------------------------------------------------
// mlt_scene_get_info
// ---------------------------------------------------------------------------------------

#[test]
fn get_info_null_pointers() {
    let mut info = MltSceneInfo {
        triangle_count: 99,
        ..scene_info_default()
    };
    // SAFETY: NULL must be rejected.
    let status = unsafe { mlt_scene_get_info(null(), &mut info) };
    assert_invalid(status, &["scene", "NULL"]);
    assert_eq!(info.triangle_count, 99);
    let scene = HostScene::floor_and_light().create();
    // SAFETY: NULL out must be rejected.
    let status = unsafe { mlt_scene_get_info(scene.0, null_mut()) };
    assert_invalid(status, &["out", "NULL"]);
}

// ---------------------------------------------------------------------------------------
// mlt_render: pointers and buffer
// ---------------------------------------------------------------------------------------

#[test]
fn render_bad_pointers_and_buffers() {
    let scene = HostScene::floor_and_light().create();
    let (camera, settings) = (floor_camera(), small_settings(4, 4, 1));
    // Every case could write (wrongly) only into `buffer`: rgb_out at its start or one byte
    // past it (misaligned), stats_out one byte past its middle (misaligned).
    let mut buffer = vec![SENTINEL_F32; 128];
    let rgb = buffer.as_mut_ptr();
    let odd_rgb = rgb.cast::<u8>().wrapping_add(1);
    let odd_stats = rgb.wrapping_add(64).cast::<u8>().wrapping_add(1);
    assert!(
        size_of::<MltRenderStats>() < 63 * size_of::<f32>(),
        "stats fit the buffer"
    );
    let valid = RenderCall {
        scene: scene.0,
        camera: &camera,
        settings: &settings,
        rgb_out: rgb,
        out_len: 48,
        stats_out: null_mut(),
    };
    let cases = cases![c = valid;
        c.scene = null() => ["scene", "NULL"],
        c.camera = null() => ["camera", "NULL"],
        c.settings = null() => ["settings", "NULL"],
        c.rgb_out = null_mut() => ["rgb_out", "NULL"],
        c.rgb_out = odd_rgb.cast() => ["rgb_out", "aligned"],
        c.out_len = 47 => ["out_len", "47", "48"],
        c.out_len = 0 => ["out_len", "0"],
        c.stats_out = odd_stats.cast() => ["stats_out", "aligned"],
    ];
    assert_cases("render arguments", &cases, |call, needles| {
        // SAFETY: every pointer is valid for the call or one mlt must refuse before using it.
        let status = unsafe { call.run() };
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)?;
        // SAFETY: `buffer`'s memory, only read here.
        let untouched = unsafe { std::slice::from_raw_parts(rgb, 128) };
        ensure(
            untouched.iter().all(|&v| v == SENTINEL_F32),
            "rgb_out or stats_out written",
        )
    });
}

/// The arguments of a render, as a host passes them.
#[derive(Clone, Copy)]
struct RenderCall {
    scene: *const MltScene,
    camera: *const MltCamera,
    settings: *const MltRenderSettings,
    rgb_out: *mut f32,
    out_len: usize,
    stats_out: *mut MltRenderStats,
}

impl RenderCall {
    /// `mlt_render_ex`, or `mlt_render` when `stats_out` is NULL (a host that wants no stats).
    ///
    /// # Safety
    /// As `mlt_render_ex`.
    unsafe fn run(&self) -> MltStatus {
        let &RenderCall {
            scene,
            camera,
            settings,
            rgb_out,
            out_len,
            stats_out,
        } = self;
        // SAFETY: forwarded contract.
        unsafe {
            if stats_out.is_null() {
                mlt_render(scene, camera, settings, rgb_out, out_len, None, null_mut())
            } else {
                mlt_render_ex(
                    scene,
                    camera,
                    settings,
                    rgb_out,
                    out_len,
                    None,
                    null_mut(),
                    stats_out,
                )
            }
        }
    }
}

#[test]
fn render_larger_buffer_is_fine_and_the_tail_untouched() {
    let scene = HostScene::floor_and_light().create();
    let (status, image) = scene.render(&floor_camera(), &small_settings(4, 4, 1), 60);
    assert_ok(status);
    assert_valid_image(&image[..48], "image");
    assert!(image[48..].iter().all(|&v| v == SENTINEL_F32));
}

// ---------------------------------------------------------------------------------------
// mlt_render: settings
// ---------------------------------------------------------------------------------------

/// The settings every algorithm checks, on a path-traced render.
#[test]
fn bad_settings() {
    let scene = HostScene::floor_and_light().create();
    let cases = cases![s = small_settings(4, 4, 1);
        s.width = 0 => ["settings.width is 0", "65536"],
        s.height = 0 => ["settings.height is 0", "65536"],
        s.width = MLT_MAX_IMAGE_SIDE + 1 => ["settings.width is 65537", "65536"],
        s.height = u32::MAX => ["settings.height is 4294967295", "65536"],
        s.samples_per_pixel = MLT_MAX_SAMPLES_PER_PIXEL + 1 => ["samples_per_pixel is 16777217"],
        s.samples_per_pixel = 0 => ["samples_per_pixel is 0", "time limit"],
        s.max_depth = MLT_MAX_DEPTH_LIMIT + 1 => ["settings.max_depth is 1025"],
        s.threads = MLT_MAX_THREADS + 1 => ["settings.threads is 4097"],
        s.threads = u32::MAX => ["settings.threads is 4294967295"],
        s.time_limit_seconds = -1.0 => ["time_limit_seconds is -1"],
        s.time_limit_seconds = -0.001 => ["time_limit_seconds is -0.001"],
        s.time_limit_seconds = f64::NAN => ["time_limit_seconds is NaN"],
        s.time_limit_seconds = f64::INFINITY => ["time_limit_seconds is inf"],
        s.time_limit_seconds = f64::NEG_INFINITY => ["time_limit_seconds is -inf"],
        s.time_limit_seconds = 1.0e8 => ["time_limit_seconds is 100000000", "up to 10000000"],
        s.algorithm = 7 => ["settings.algorithm is 7", "MLT_ALGORITHM_PATH"],
        s.algorithm = -1 => ["settings.algorithm is -1", "MLT_ALGORITHM_PATH"],
        s.algorithm = i32::MAX => ["settings.algorithm is 2147483647", "MLT_ALGORITHM_PATH"],
    ];
    scene.assert_refuses_settings("settings", &floor_camera(), &cases);
}

#[test]
fn erpt_settings_out_of_range() {
    let scene = HostScene::floor_and_light().create();
    let erpt = MltRenderSettings {
        algorithm: MLT_ALGORITHM_ERPT,
        ..small_settings(4, 4, 1)
    };
    let mut cases = cases![s = erpt;
        s.erpt_chain_length = 0 => ["erpt_chain_length is 0", "between 1 and 1048576"],
        s.erpt_chain_length = MLT_MAX_ERPT_CHAIN_LENGTH + 1 => ["erpt_chain_length is 1048577"],
        s.erpt_chain_length = u32::MAX => ["erpt_chain_length is 4294967295"],
        s.erpt_deposit_energy = -1.0 => ["erpt_deposit_energy is -1"],
        s.erpt_deposit_energy = 1e31 => ["erpt_deposit_energy", "1e30"],
        s.samples_per_pixel = 0 => ["samples_per_pixel is 0", "time limit"],
    ];
    cases.extend(non_finite_cases![s = erpt;
        s.erpt_deposit_energy => "settings.erpt_deposit_energy" + "up to 1e30",
    ]);
    scene.assert_refuses_settings("ERPT settings", &floor_camera(), &cases);
    // In range, with an explicit deposit energy and the shortest chains, it renders.
    for (erpt_chain_length, erpt_deposit_energy) in [(1, 0.0), (100, 1e-3), (1, 1e30)] {
        let settings = MltRenderSettings {
            erpt_chain_length,
            erpt_deposit_energy,
            ..erpt
        };
        let (rgb, stats) = scene.render_4x4_with_stats(&floor_camera(), &settings);
        let case = format!("{erpt_chain_length}, {erpt_deposit_energy}");
        assert_eq!(stats.samples, 16, "{case}");
        assert!(rgb.iter().all(|v| v.is_finite()), "{case}");
    }
}

#[test]
fn filter_settings_out_of_range() {
    let scene = HostScene::floor_and_light().create();
    let metropolis = MltRenderSettings {
        algorithm: MLT_ALGORITHM_PSSMLT,
        mutations_per_pixel: 1,
        bootstrap_samples: 64,
        chains: 4,
        filter_buffers: 8,
        ..small_settings(4, 4, 1)
    };
    let mut cases = cases![s = metropolis;
        s.filter_buffers = 1 => ["filter_buffers is 1", "0 (no filter) or from 2 to 32"],
        s.filter_buffers = 33 => ["filter_buffers is 33"],
        s.filter_strength = 0.0 => ["filter_strength is 0", "positive"],
        s.filter_strength = -1.0 => ["filter_strength is -1"],
        s.filter_strength = 1e9 => ["filter_strength is 1000000000", "up to 100"],
        s.filter_radius = 0 => ["filter_radius is 0", "from 1 to 32"],
        s.filter_radius = u32::MAX => ["filter_radius is 4294967295"],
        s.algorithm = MLT_ALGORITHM_PATH => ["filter_buffers is 8", "Path", "Metropolis and ERPT"],
    ];
    cases.extend(non_finite_cases![s = metropolis;
        s.filter_strength => "settings.filter_strength" + "positive, up to 100",
    ]);
    scene.assert_refuses_settings("filter settings", &floor_camera(), &cases);
    // In range, every algorithm the filter applies to renders and reports it.
    for algorithm in [
        MLT_ALGORITHM_PSSMLT,
        MLT_ALGORITHM_MMLT,
        MLT_ALGORITHM_PSSMLT_BDPT,
        MLT_ALGORITHM_PATH_SPACE_MLT,
        MLT_ALGORITHM_ERPT,
    ] {
        let settings = MltRenderSettings {
            algorithm,
            filter_buffers: 2,
            filter_strength: 100.0,
            filter_radius: 32,
            ..metropolis
        };
        let (rgb, stats) = scene.render_4x4_with_stats(&floor_camera(), &settings);
        assert!(rgb.iter().all(|v| v.is_finite()), "algorithm {algorithm}");
        assert!(stats.filter_changed_fraction.is_finite() && stats.filter_mean_neighbours >= 0.0);
    }
}

#[test]
fn metropolis_settings_out_of_range() {
    let scene = HostScene::floor_and_light().create();
    let metropolis = MltRenderSettings {
        algorithm: MLT_ALGORITHM_MMLT,
        mutations_per_pixel: 1,
        bootstrap_samples: 64,
        chains: 4,
        ..small_settings(4, 4, 1)
    };
    let mut cases = cases![s = metropolis;
        s.mutations_per_pixel = 0 => ["mutations_per_pixel is 0", "time limit"],
        { s.mutations_per_pixel = MLT_MAX_SAMPLES_PER_PIXEL + 1; s.direct_samples_per_mutation = 0 }
            => ["mutations_per_pixel is 16777217"],
        { s.mutations_per_pixel = 1 << 20; s.direct_samples_per_mutation = 17 }
            => ["direct_samples_per_mutation is 17", "mutations_per_pixel"],
        s.bootstrap_samples = (1 << 28) + 1 => ["bootstrap_samples is 268435457", "0 (automatic)"],
        { s.bootstrap_samples = 0; s.chains = 1 << 20 }
            => ["chains is 1048576", "bootstrap samples (65536)"],
        s.chains = 0 => ["chains is 0"],
        s.chains = 65 => ["chains is 65", "bootstrap samples (64)"],
        s.normalization_work_fraction = -0.1 => ["normalization_work_fraction is -0.1"],
        s.normalization_work_fraction = 0.95 => ["normalization_work_fraction is 0.95"],
        s.large_step_probability = 1.5 => ["large_step_probability is 1.5"],
        s.small_step_sigma = 0.0 => ["small_step_sigma is 0"],
        s.mutation_weights = [0.5, 0.25, -1.0, 0.25] => ["mutation_weights[2] is -1"],
        s.mutation_weights = [0.0, 1.0, 1.0, 1.0]
            => ["mutation_weights[0]", "bidirectional", "positive"],
        s.adapt_mutation_weights = 2 => ["adapt_mutation_weights is 2", "0 or 1"],
        s.perturb_in_sample_space = u32::MAX => ["perturb_in_sample_space is 4294967295", "0 or 1"],
        s.spectral = 2 => ["settings.spectral is 2", "0 or 1"],
    ];
    cases.extend(non_finite_cases![s = metropolis;
        s.normalization_work_fraction => "settings.normalization_work_fraction" + "0 to 0.9",
        s.large_step_probability => "settings.large_step_probability" + "in [0, 1]",
        s.small_step_sigma => "settings.small_step_sigma" + "in (0, 1]",
        s.mutation_weights[0] => "settings.mutation_weights[0]" + "finite, from 0 to 1e6",
        s.mutation_weights[1] => "settings.mutation_weights[1]" + "finite, from 0 to 1e6",
        s.mutation_weights[2] => "settings.mutation_weights[2]" + "finite, from 0 to 1e6",
        s.mutation_weights[3] => "settings.mutation_weights[3]" + "finite, from 0 to 1e6",
    ]);
    scene.assert_refuses_settings("Metropolis settings", &floor_camera(), &cases);
    // The same settings in range render, with every Metropolis algorithm.
    for algorithm in [
        MLT_ALGORITHM_PSSMLT,
        MLT_ALGORITHM_MMLT,
        MLT_ALGORITHM_PSSMLT_BDPT,
        MLT_ALGORITHM_PATH_SPACE_MLT,
    ] {
        let settings = MltRenderSettings {
            algorithm,
            ..metropolis
        };
        let (rgb, stats) = scene.render_4x4_with_stats(&floor_camera(), &settings);
        // One mutation per pixel by the chains, one direct-pass camera sample per mutation.
        assert_eq!(stats.mutations, 16, "algorithm {algorithm}");
        assert_eq!(stats.samples, 16, "algorithm {algorithm}");
        // Nothing reaches the camera after two bounces here: the chains' b is 0 and the
        // direct pass alone makes the image.
        assert_eq!(
            (stats.accepted_mutations, stats.normalization),
            (0, 0.0),
            "algorithm {algorithm}"
        );
        assert!(rgb.iter().any(|&v| v > 0.0), "algorithm {algorithm}");
    }
}

#[test]
fn limits_themselves_are_accepted() {
    // The largest accepted depth and thread count, and the longest time limit, are valid.
    let scene = HostScene::floor_and_light().create();
    let s = MltRenderSettings {
        max_depth: MLT_MAX_DEPTH_LIMIT,
        threads: 3,
        time_limit_seconds: MLT_MAX_TIME_LIMIT_SECONDS,
        ..small_settings(4, 4, 1)
    };
    let (status, image) = scene.render(&floor_camera(), &s, 48);
    assert_ok(status);
    assert_valid_image(&image, "image");
}

// ---------------------------------------------------------------------------------------
// mlt_render: camera
// ---------------------------------------------------------------------------------------

#[test]
fn bad_cameras() {
    let scene = HostScene::floor_and_light().create();
    let mut cases = cases![c = floor_camera();
        c.target = [0.0, 1.0, -4.0] => ["camera.eye", "camera.target", "coincide"],
        c.up = [0.0, 0.0, 1.0] => ["camera.up", "parallel"],
        c.up = [0.0, 0.0, -3.0] => ["camera.up", "parallel"],
        c.up = [0.0; 3] => ["camera.up", "zero"],
        c.up = [0.0, 1e-30, 0.0] => ["camera.up", "too short or too long"],
        c.up = [0.0, 3e38, 3e38] => ["camera.up", "too short or too long"],
        c.fov_y_deg = 0.0 => ["camera.fov_y_deg is 0", "(0, 180)"],
        c.fov_y_deg = -0.0 => ["camera.fov_y_deg is -0"],
        c.fov_y_deg = 180.0 => ["camera.fov_y_deg is 180"],
        c.fov_y_deg = 200.0 => ["camera.fov_y_deg is 200"],
        c.fov_y_deg = -30.0 => ["camera.fov_y_deg is -30"],
        c.lens_radius = -1.0 => ["camera.lens_radius is -1"],
        c.focus_distance = -2.0 => ["camera.focus_distance is -2"],
        // Finite eye and target whose difference overflows f32: no view direction.
        { c.eye = [3.0e38, 0.0, 0.0]; c.target = [-3.0e38, 0.0, 0.0] } => ["camera", "overflows"],
    ];
    cases.extend(non_finite_cases![c = floor_camera();
        c.eye[0] => "camera.eye.x" + "finite",
        c.eye[1] => "camera.eye.y" + "finite",
        c.eye[2] => "camera.eye.z" + "finite",
        c.target[0] => "camera.target.x" + "finite",
        c.target[1] => "camera.target.y" + "finite",
        c.target[2] => "camera.target.z" + "finite",
        c.up[0] => "camera.up.x" + "finite",
        c.up[1] => "camera.up.y" + "finite",
        c.up[2] => "camera.up.z" + "finite",
        c.fov_y_deg => "camera.fov_y_deg" + "finite",
        c.lens_radius => "camera.lens_radius" + "finite",
        c.focus_distance => "camera.focus_distance" + "finite",
    ]);
    let settings = small_settings(4, 4, 1);
    assert_cases("cameras", &cases, |camera, needles| {
        scene.check_render_refused(camera, &settings, needles)
    });
}

// ---------------------------------------------------------------------------------------
// mlt_intersect / mlt_occluded
// ---------------------------------------------------------------------------------------

#[test]
fn ray_queries_null_pointers() {
    let scene = HostScene::floor_and_light().create();
    let rays = [ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])];
    let mut hits = [SENTINEL_HIT];
    let mut flags = [0xABu8];
    // SAFETY: each call passes one NULL that must be rejected.
    unsafe {
        assert_invalid(
            mlt_intersect(null(), rays.as_ptr(), 1, hits.as_mut_ptr()),
            &["scene", "NULL"],
        );
        assert_invalid(
            mlt_intersect(scene.0, null(), 1, hits.as_mut_ptr()),
            &["rays", "NULL"],
        );
        assert_invalid(
            mlt_intersect(scene.0, rays.as_ptr(), 1, null_mut()),
            &["hits_out", "NULL"],
        );
        assert_invalid(
            mlt_occluded(null(), rays.as_ptr(), 1, flags.as_mut_ptr()),
            &["scene", "NULL"],
        );
        assert_invalid(
            mlt_occluded(scene.0, null(), 1, flags.as_mut_ptr()),
            &["rays", "NULL"],
        );
        assert_invalid(
            mlt_occluded(scene.0, rays.as_ptr(), 1, null_mut()),
            &["occluded_out", "NULL"],
        );
    }
    assert_eq!(hits[0].triangle_id, SENTINEL_HIT.triangle_id);
    assert_eq!(flags[0], 0xAB);
}

#[test]
fn ray_queries_with_zero_rays_accept_null() {
    let scene = HostScene::floor_and_light().create();
    // SAFETY: count 0 makes both arrays unused.
    unsafe {
        assert_ok(mlt_intersect(scene.0, null(), 0, null_mut()));
        assert_ok(mlt_occluded(scene.0, null(), 0, null_mut()));
    }
}

#[test]
fn ray_queries_with_impossible_counts() {
    let scene = HostScene::floor_and_light().create();
    let rays = [ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])];
    let mut hits = [SENTINEL_HIT];
    // SAFETY: the count overflows the address space and must be rejected before any access.
    let s = unsafe { mlt_intersect(scene.0, rays.as_ptr(), usize::MAX, hits.as_mut_ptr()) };
    assert_invalid(s, &["rays", "address space"]);
    assert_eq!(hits[0].triangle_id, SENTINEL_HIT.triangle_id);
}

/// Every bad ray, each at index 1 behind a good ray 0: the message names rays[1] and the
/// outputs stay untouched (all rays are validated before any result is written).
#[test]
fn bad_rays() {
    let scene = HostScene::floor_and_light().create();
    let good = ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]);
    let mut cases = cases![r = good;
        r.direction = [0.0; 3] => ["rays[1].direction", "non-zero"],
        r.tmin = -1.0 => ["rays[1].tmin is -1", ">= 0"],
        { r.tmin = 2.0; r.tmax = 1.0 } => ["rays[1].tmax is 1", "tmin (2)"],
        // tmax may be +inf (no limit), not NaN or -inf.
        r.tmax = f32::NAN => ["rays[1].tmax is NaN"],
        r.tmax = f32::NEG_INFINITY => ["rays[1].tmax is -inf"],
    ];
    cases.extend(non_finite_cases![r = good;
        r.origin[0] => "rays[1].origin.x" + "finite",
        r.origin[1] => "rays[1].origin.y" + "finite",
        r.origin[2] => "rays[1].origin.z" + "finite",
        r.direction[0] => "rays[1].direction.x" + "finite",
        r.direction[1] => "rays[1].direction.y" + "finite",
        r.direction[2] => "rays[1].direction.z" + "finite",
        r.tmin => "rays[1].tmin" + "finite and >= 0",
    ]);
    assert_cases("rays", &cases, |&bad, needles| {
        let rays = [good, bad];
        let (status, hits) = scene.intersect(&rays);
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)
            .and_then(|()| {
                ensure(
                    hits.iter()
                        .all(|h| h.triangle_id == SENTINEL_HIT.triangle_id),
                    "hits_out written although rays[1] is bad",
                )
            })
            .map_err(|e| format!("mlt_intersect: {e}"))?;
        let (status, flags) = scene.occluded(&rays);
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)
            .and_then(|()| {
                ensure(
                    flags == [0xAB, 0xAB],
                    "occluded_out written although rays[1] is bad",
                )
            })
            .map_err(|e| format!("mlt_occluded: {e}"))
    });
}

#[test]
fn ray_query_results_follow_the_host_conventions() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    // Non-unit direction: t is in multiples of it. Origin 1 above the floor at (0.3, 0.2).
    let rays = [
        ray([0.3, 1.0, 0.2], [0.0, -2.0, 0.0]),
        MltRay {
            tmax: 0.4,
            ..ray([0.3, 1.0, 0.2], [0.0, -2.0, 0.0])
        },
        MltRay {
            tmax: 0.5,
            ..ray([0.3, 1.0, 0.2], [0.0, -2.0, 0.0])
        },
        // The light quad is one-sided for emission but a surface from both sides.
        ray([0.3, 1.0, 0.2], [0.0, 1.0, 0.0]),
        ray([0.3, 1.0, 0.2], [0.0, 0.0, 1.0]),
    ];
    let (status, hits) = scene.intersect(&rays);
    assert_ok(status);
    let h = hits[0];
    assert!(h.triangle_id < 2, "the floor is triangles 0 and 1");
    assert!((h.t - 0.5).abs() < 1e-6, "t = {}", h.t);
    // The hit point from the barycentrics of the host's vertex order.
    let tri = &host.indices[h.triangle_id as usize * 3..][..3];
    let vertex = |i: u32| &host.positions[i as usize * 3..][..3];
    let point: Vec<f32> = (0..3)
        .map(|c| {
            (1.0 - h.u - h.v) * vertex(tri[0])[c]
                + h.u * vertex(tri[1])[c]
                + h.v * vertex(tri[2])[c]
        })
        .collect();
    for (p, expected) in point.iter().zip([0.3, 0.0, 0.2]) {
        assert!((p - expected).abs() < 1e-5, "hit point {point:?}");
    }
    assert_eq!(hits[1].triangle_id, MLT_INVALID_ID, "tmax before the floor");
    assert!(
        hits[2].triangle_id < 2,
        "tmax exactly at the floor still hits"
    );
    assert!(hits[3].triangle_id == 2 || hits[3].triangle_id == 3);
    assert!((hits[3].t - 1.0).abs() < 1e-6);
    assert_eq!(hits[4].triangle_id, MLT_INVALID_ID);
    let (status, flags) = scene.occluded(&rays);
    assert_ok(status);
    assert_eq!(flags, [1, 0, 1, 1, 0]);
}

// ---------------------------------------------------------------------------------------
// The last error message
// ---------------------------------------------------------------------------------------

#[test]
fn last_error_is_cleared_by_each_kind_of_success() {
    let scene = HostScene::floor_and_light().create();
    let fail = || {
        // SAFETY: NULL must be rejected.
        let s = unsafe { mlt_camera_init(null_mut(), size_of::<MltCamera>()) };
        assert_invalid(s, &["out"]);
        assert!(!last_error().is_empty());
    };
    fail();
    let _ = scene.info(); // asserts the message is "" afterwards
    fail();
    let (status, _) = scene.render(&floor_camera(), &small_settings(4, 4, 1), 48);
    assert_ok(status);
    fail();
    let (status, _) = scene.intersect(&[ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])]);
    assert_ok(status);
    fail();
    let (status, _) = scene.occluded(&[ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])]);
    assert_ok(status);
    fail();
    let _ = HostScene::floor_and_light().create();
    fail();
    let _ = default_settings();
    fail();
    let mut plan = empty_bytes();
    // SAFETY: valid pointers.
    assert_ok(unsafe {
        mlt_render_plan(
            scene.0,
            &floor_camera(),
            &small_settings(4, 4, 1),
            &mut plan,
        )
    });
    fail();
    let mut partial = empty_bytes();
    // SAFETY: the plan's bytes as mlt gave them.
    assert_ok(unsafe {
        mlt_render_job(
            scene.0,
            plan.data,
            plan.size,
            0,
            1,
            1,
            None,
            null_mut(),
            &mut partial,
            null_mut(),
        )
    });
    fail();
    let mut image = [0.0f32; 48];
    let partials = [partial.data.cast_const()];
    // SAFETY: one partial result of `partial.size` bytes; 48 floats.
    assert_ok(unsafe {
        mlt_render_merge(
            plan.data,
            plan.size,
            partials.as_ptr(),
            &partial.size,
            1,
            image.as_mut_ptr(),
            48,
            null_mut(),
        )
    });
    fail();
    let mut combined = empty_bytes();
    // SAFETY: one partial result of `partial.size` bytes.
    assert_ok(unsafe {
        mlt_render_combine(
            plan.data,
            plan.size,
            partials.as_ptr(),
            &partial.size,
            1,
            &mut combined,
        )
    });
    fail();
    // SAFETY: filled by mlt, released once each.
    unsafe { mlt_bytes_release(&mut combined) };
    // SAFETY: as above.
    unsafe { mlt_bytes_release(&mut partial) };
    assert_eq!(last_error(), "", "a release clears the last error");
    // SAFETY: as above.
    unsafe { mlt_bytes_release(&mut plan) };
}

#[test]
fn last_error_belongs_to_the_failing_thread() {
    // SAFETY: NULL must be rejected.
    let s = unsafe { mlt_scene_create(null(), null_mut()) };
    assert_invalid(s, &["desc"]);
    let other = std::thread::spawn(last_error).join().unwrap();
    assert_eq!(other, "", "another thread has no error");
    assert!(
        last_error().contains("desc"),
        "this thread's message survives"
    );
}

// ---------------------------------------------------------------------------------------
// Progress, cancellation, time limit
// ---------------------------------------------------------------------------------------

struct ProgressLog {
    fractions: Vec<f32>,
    threads: Vec<std::thread::ThreadId>,
    /// Return false once a fraction above this is reported.
    cancel_after: f32,
}

unsafe extern "C" fn log_progress(fraction: f32, user_data: *mut c_void) -> bool {
    // SAFETY: the tests pass a &mut ProgressLog as user_data.
    let log = unsafe { &mut *user_data.cast::<ProgressLog>() };
    log.fractions.push(fraction);
    log.threads.push(std::thread::current().id());
    fraction <= log.cancel_after
}

/// The Cornell box at 8 × 8: every pixel sees a lit surface.
fn cornell() -> (Handle, MltCamera) {
    (HostScene::cornell_box().create(), default_camera())
}

/// Samples per pixel of a camera pass after the first on a small image (the schedule's
/// maximum batch).
const PASS_BATCH: u64 = 64;

/// A render stopped early (cancelled or out of time) keeps whole passes: every pixel has
/// 1 + k·64 samples, and a band of rows whose pass had not begun when the stop came has one
/// pass fewer than those before it. Each sample depends only on its pixel and index, so every
/// pixel is bit-identical to the same pixel of a complete render of its own sample count,
/// and the counts add up to the samples reported. (A mean compared with a converged
/// reference would be a weak test: under load the stopped render may hold one pass.)
#[track_caller]
fn assert_equals_the_complete_renders_of_its_samples(
    scene: &Handle,
    camera: &MltCamera,
    stopped: &MltRenderSettings,
    image: &[f32],
    samples: u64,
) {
    let pixels = stopped.width as u64 * stopped.height as u64;
    assert!(samples >= pixels, "{samples} samples over {pixels} pixels");
    // The fewest samples a pixel can have: the last whole pass all pixels took.
    let fewest = 1 + (samples / pixels - 1) / PASS_BATCH * PASS_BATCH;
    let complete = |spp: u64| {
        let settings = MltRenderSettings {
            time_limit_seconds: 0.0,
            samples_per_pixel: spp as u32,
            ..*stopped
        };
        let (status, reference) = scene.render(camera, &settings, image.len());
        assert_ok(status);
        reference
    };
    let (fewer, more) = (complete(fewest), complete(fewest + PASS_BATCH));
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let mut counted = 0;
    for (i, pixel) in image.chunks_exact(3).enumerate() {
        let range = 3 * i..3 * i + 3;
        counted += if same(pixel, &fewer[range.clone()]) {
            fewest
        } else if same(pixel, &more[range]) {
            fewest + PASS_BATCH
        } else {
            panic!(
                "pixel {i} is neither the complete render of {fewest} nor of {} samples",
                fewest + PASS_BATCH
            )
        };
    }
    assert_eq!(
        counted, samples,
        "the pixels' samples add up to the reported count"
    );
}

#[test]
fn progress_is_reported_on_the_calling_thread_and_ends_at_1() {
    let (scene, camera) = cornell();
    let mut log = ProgressLog {
        fractions: Vec::new(),
        threads: Vec::new(),
        cancel_after: f32::INFINITY,
    };
    let settings = MltRenderSettings {
        threads: 2,
        ..small_settings(16, 16, 4096)
    };
    let mut image = vec![0.0f32; 16 * 16 * 3];
    // SAFETY: valid pointers; `log` outlives the call.
    let status = unsafe {
        mlt_render(
            scene.0,
            &camera,
            &settings,
            image.as_mut_ptr(),
            image.len(),
            Some(log_progress),
            (&mut log as *mut ProgressLog).cast(),
        )
    };
    assert_ok(status);
    assert_eq!(log.fractions.last(), Some(&1.0), "the last report is 1.0");
    assert!(log.fractions.iter().all(|f| (0.0..=1.0).contains(f)));
    assert!(
        log.fractions.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        log.fractions
    );
    let me = std::thread::current().id();
    assert!(
        log.threads.iter().all(|&t| t == me),
        "called from a worker thread"
    );
}

#[test]
fn cancelling_from_the_progress_callback() {
    let (scene, camera) = cornell();
    let mut log = ProgressLog {
        fractions: Vec::new(),
        threads: Vec::new(),
        cancel_after: 0.0, // cancel as soon as any sample is done
    };
    let settings = small_settings(8, 8, MLT_MAX_SAMPLES_PER_PIXEL);
    let mut image = vec![SENTINEL_F32; 192];
    let mut stats = render_stats_default();
    // SAFETY: valid pointers; `log` outlives the call.
    let status = unsafe {
        mlt_render_ex(
            scene.0,
            &camera,
            &settings,
            image.as_mut_ptr(),
            image.len(),
            Some(log_progress),
            (&mut log as *mut ProgressLog).cast(),
            &mut stats,
        )
    };
    assert_error(
        status,
        MLT_STATUS_CANCELLED,
        &["cancelled", &stats.samples.to_string()],
    );
    assert!(stats.samples > 0);
    assert!(stats.samples < 64 * MLT_MAX_SAMPLES_PER_PIXEL as u64);
    assert_valid_image(&image, "cancelled image");
    // Normalized by the samples actually taken.
    assert_equals_the_complete_renders_of_its_samples(
        &scene,
        &camera,
        &settings,
        &image,
        stats.samples,
    );
}

#[test]
fn time_limit_with_huge_sample_count() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        time_limit_seconds: 0.2,
        ..small_settings(8, 8, MLT_MAX_SAMPLES_PER_PIXEL)
    };
    let mut image = vec![SENTINEL_F32; 192];
    let mut stats = render_stats_default();
    let start = std::time::Instant::now();
    // SAFETY: valid pointers.
    let status = unsafe {
        mlt_render_ex(
            scene.0,
            &camera,
            &settings,
            image.as_mut_ptr(),
            192,
            None,
            null_mut(),
            &mut stats,
        )
    };
    let elapsed = start.elapsed().as_secs_f64();
    assert_error(
        status,
        MLT_STATUS_TIME_LIMIT_REACHED,
        &["time limit", "0.2"],
    );
    assert!(elapsed < 5.0, "a 0.2 s limit took {elapsed} s");
    assert!(stats.samples > 0);
    assert_valid_image(&image, "time-limited image");
    assert_equals_the_complete_renders_of_its_samples(
        &scene,
        &camera,
        &settings,
        &image,
        stats.samples,
    );
}

#[test]
fn time_limit_with_zero_samples_means_render_until_the_limit() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        time_limit_seconds: 0.1,
        ..small_settings(8, 8, 0)
    };
    let (status, image) = scene.render(&camera, &settings, 192);
    assert_error(status, MLT_STATUS_TIME_LIMIT_REACHED, &["time limit"]);
    assert_valid_image(&image, "image");
    assert!(common::mean(&image)[0] > 0.0);
}

#[test]
fn a_tiny_time_limit_still_gives_a_usable_image() {
    // Even a limit shorter than starting the workers should leave an estimate of the image
    // (the first pass always completes: one sample in every pixel), not an all-black buffer
    // reported as "valid".
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        time_limit_seconds: 1e-6,
        ..small_settings(32, 32, MLT_MAX_SAMPLES_PER_PIXEL)
    };
    let (status, image) = scene.render(&camera, &settings, 32 * 32 * 3);
    assert_error(status, MLT_STATUS_TIME_LIMIT_REACHED, &["time limit"]);
    assert_valid_image(&image, "image");
    assert_equals_the_complete_renders_of_its_samples(&scene, &camera, &settings, &image, 32 * 32);
}

// ---------------------------------------------------------------------------------------
// Concurrency and determinism
// ---------------------------------------------------------------------------------------

#[test]
fn several_host_threads_render_one_scene_at_once() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        seed: 42,
        threads: 1,
        ..small_settings(16, 16, 16)
    };
    let (status, expected) = scene.render(&camera, &settings, 16 * 16 * 3);
    assert_ok(status);
    let images: Vec<Vec<f32>> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..4)
            .map(|i| {
                let scene = &scene;
                s.spawn(move || {
                    let settings = MltRenderSettings {
                        threads: (i % 2) + 1,
                        ..settings
                    };
                    let (status, image) = scene.render(&camera, &settings, 16 * 16 * 3);
                    assert_ok(status);
                    // Queries on the same scene at the same time.
                    let (status, hits) = scene.intersect(&[ray(camera.eye, [0.0, 0.0, 1.0])]);
                    assert_ok(status);
                    assert_ne!(hits[0].triangle_id, MLT_INVALID_ID);
                    image
                })
            })
            .collect();
        workers.into_iter().map(|w| w.join().unwrap()).collect()
    });
    for image in images {
        assert!(
            image
                .iter()
                .zip(&expected)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "same seed and settings must give bitwise equal images"
        );
    }
}

#[test]
fn different_seeds_give_different_images() {
    let (scene, camera) = cornell();
    let a = scene.render(&camera, &small_settings(8, 8, 2), 192).1;
    let b = scene
        .render(
            &camera,
            &MltRenderSettings {
                seed: 1,
                ..small_settings(8, 8, 2)
            },
            192,
        )
        .1;
    assert_ne!(a, b);
}

#[test]
fn tiny_or_huge_but_finite_ray_directions_are_accepted() {
    // The header: direction "Finite and non-zero", t in multiples of it. Both of these are.
    let scene = HostScene::floor_and_light().create();
    let rays = [
        ray([0.3, 1.0, 0.2], [0.0, -1e-30, 0.0]),
        ray([0.3, 1.0, 0.2], [1e-30, -3e38, 1e-30]),
    ];
    let (status, hits) = scene.intersect(&rays);
    assert_ok(status);
    assert!(hits.iter().all(|h| h.triangle_id < 2), "{hits:?}");
    assert!((hits[0].t / 1e30 - 1.0).abs() < 1e-5, "t = {}", hits[0].t);
    assert!((hits[1].t * 3e38 - 1.0).abs() < 1e-5, "t = {}", hits[1].t);
    let (status, flags) = scene.occluded(&rays);
    assert_ok(status);
    assert_eq!(flags, [1, 1]);
}

/// Extreme but finite camera values must give an error naming the camera or a finite image,
/// never an internal error (a panic inside the renderer).
#[test]
fn extreme_camera_values_are_rejected_or_rendered() {
    let scene = HostScene::floor_and_light().create();
    let settings = small_settings(4, 4, 2);
    let mut failures = Vec::new();
    for camera in [
        MltCamera {
            lens_radius: 3e38,
            ..floor_camera()
        },
        MltCamera {
            lens_radius: 1.0,
            focus_distance: 3e38,
            fov_y_deg: 170.0,
            ..floor_camera()
        },
        MltCamera {
            lens_radius: 1.0,
            focus_distance: 3e38,
            ..floor_camera()
        },
        MltCamera {
            eye: [3e38, 1.0, -4.0],
            target: [3e38, 1.0, 0.0],
            ..floor_camera()
        },
        MltCamera {
            fov_y_deg: 179.99,
            ..floor_camera()
        },
        MltCamera {
            fov_y_deg: 1e-30,
            ..floor_camera()
        },
    ] {
        let (status, image) = scene.render(&camera, &settings, 48);
        let message = last_error();
        let fine = match status {
            MLT_STATUS_OK => image.iter().all(|v| v.is_finite() && *v >= 0.0),
            MLT_STATUS_INVALID_ARGUMENT => message.contains("camera"),
            _ => false,
        };
        if !fine {
            failures.push(format!("{camera:?}: {status:?} {message:?}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

// ---------------------------------------------------------------------------------------
// mlt_scene_create: lights besides emissive triangles
// ---------------------------------------------------------------------------------------

fn default_environment() -> MltEnvironment {
    let mut e = std::mem::MaybeUninit::<MltEnvironment>::uninit();
    // SAFETY: writable memory for an MltEnvironment.
    assert_ok(unsafe { mlt_environment_init(e.as_mut_ptr(), size_of::<MltEnvironment>()) });
    // SAFETY: initialized on success.
    unsafe { e.assume_init() }
}

fn default_sun() -> MltSun {
    let mut s = std::mem::MaybeUninit::<MltSun>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_sun_init(s.as_mut_ptr(), size_of::<MltSun>()) });
    unsafe { s.assume_init() }
}

fn default_punctual_light() -> MltPunctualLight {
    let mut l = std::mem::MaybeUninit::<MltPunctualLight>::uninit();
    // SAFETY: as above.
    assert_ok(unsafe { mlt_punctual_light_init(l.as_mut_ptr(), size_of::<MltPunctualLight>()) });
    unsafe { l.assume_init() }
}

/// A scene with every kind of light: `HostScene::floor_and_light` under a 2 × 1
/// environment, a sun, and a point, a spot and a directional light (in that order).
struct HostLights {
    host: HostScene,
    /// What `environment.pixels` points to (set at construction: the vector's buffer does
    /// not move with the struct).
    pixels: Vec<f32>,
    environment: MltEnvironment,
    sun: MltSun,
    punctual: Vec<MltPunctualLight>,
}

impl HostLights {
    fn new() -> Self {
        let pixels = vec![0.5, 0.6, 0.7, 1.0, 1.0, 1.0];
        let environment = MltEnvironment {
            pixels: pixels.as_ptr(),
            width: 2,
            height: 1,
            rotation_degrees: 30.0,
            scale: 2.0,
            ..default_environment()
        };
        let sun = MltSun {
            direction: [1.0, 2.0, 0.5],
            angular_radius_degrees: 1.0,
            irradiance: [3.0, 2.0, 1.0],
            ..default_sun()
        };
        let point = MltPunctualLight {
            position: [0.0, 1.0, 0.0],
            intensity: [1.0, 2.0, 3.0],
            ..default_punctual_light()
        };
        let spot = MltPunctualLight {
            kind: MLT_LIGHT_SPOT,
            position: [0.5, 1.5, 0.0],
            direction: [0.0, -1.0, 0.0],
            inner_cone_degrees: 10.0,
            outer_cone_degrees: 20.0,
            ..default_punctual_light()
        };
        let directional = MltPunctualLight {
            kind: MLT_LIGHT_DIRECTIONAL,
            direction: [0.3, -1.0, 0.0],
            ..default_punctual_light()
        };
        HostLights {
            host: HostScene::floor_and_light(),
            pixels,
            environment,
            sun,
            punctual: vec![point, spot, directional],
        }
    }

    fn desc(&self) -> MltSceneDesc {
        MltSceneDesc {
            environment: &self.environment,
            sun: &self.sun,
            punctual_lights: self.punctual.as_ptr(),
            punctual_lights_len: self.punctual.len(),
            ..self.host.desc()
        }
    }
}

#[test]
fn light_defaults_are_valid_and_documented() {
    let d = default_desc();
    assert!(d.environment.is_null() && d.sun.is_null());
    assert!(d.punctual_lights.is_null() && d.punctual_lights_len == 0);
    let e = default_environment();
    assert!(e.pixels.is_null());
    assert_eq!(
        (e.width, e.height, e.rotation_degrees, e.scale),
        (0, 0, 0.0, 1.0)
    );
    let s = default_sun();
    assert_eq!(
        (s.direction, s.angular_radius_degrees, s.irradiance),
        ([0.0, 1.0, 0.0], 0.27, [1.0; 3])
    );
    let l = default_punctual_light();
    assert_eq!(
        (l.kind, l.position, l.intensity),
        (MLT_LIGHT_POINT, [0.0; 3], [1.0; 3])
    );
    assert_eq!(
        (l.direction, l.inner_cone_degrees, l.outer_cone_degrees),
        ([0.0, 0.0, -1.0], 0.0, 45.0)
    );
    // Every kind of light together, valid.
    let lights = HostLights::new();
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(&lights.desc(), &mut out) });
    drop(Handle(out));
}

#[test]
fn light_initializers_refuse_null_and_unknown_sizes() {
    type Init = fn(*mut u8, usize) -> MltStatus;
    // SAFETY (each closure): forwards the pointer and size to the initializer under test.
    let initializers: [(&str, usize, Init); 3] = [
        (
            "mlt_environment_default",
            size_of::<MltEnvironment>(),
            |p, n| unsafe { mlt_environment_init(p.cast(), n) },
        ),
        ("mlt_sun_default", size_of::<MltSun>(), |p, n| unsafe {
            mlt_sun_init(p.cast(), n)
        }),
        (
            "mlt_punctual_light_default",
            size_of::<MltPunctualLight>(),
            |p, n| unsafe { mlt_punctual_light_init(p.cast(), n) },
        ),
    ];
    let mut results = Vec::new();
    for (name, size, init) in initializers {
        let mut storage = [0xABu8; 256];
        let aligned = storage
            .as_mut_ptr()
            .wrapping_add(storage.as_ptr().align_offset(8));
        let status = init(null_mut(), size);
        results.push((
            format!("{name}: out NULL"),
            check_error(status, MLT_STATUS_INVALID_ARGUMENT, &["out", "NULL"]),
        ));
        for bad in [0, 3, size - 4, size + 8] {
            let status = init(aligned, bad);
            let needles = ["out.struct_size", &bad.to_string(), name];
            let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &needles)
                .and_then(|()| ensure(storage.iter().all(|&b| b == 0xAB), "out written"));
            results.push((format!("{name}: struct_size {bad}"), result));
        }
        let status = init(aligned, size);
        // SAFETY: 4 aligned bytes of `storage`, initialized.
        let written = unsafe { aligned.cast::<u32>().read() };
        let result =
            check_ok(status).and_then(|()| ensure(written as usize == size, "struct_size not set"));
        results.push((format!("{name}: its own size {size}"), result));
    }
    assert_all("light initializers", results);
}

/// Every bad value of the environment, the sun and the punctual lights, and bad pointers
/// and counts, each refused with a message naming it.
#[test]
fn scene_create_bad_lights() {
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let mut cases = cases![h = HostLights::new();
        h.environment.pixels = null() => ["desc.environment.pixels", "NULL"],
        h.environment.pixels = odd.cast() => ["desc.environment.pixels", "aligned"],
        h.environment.width = 0 => ["desc.environment is 0 x 1", "at least 1 x 1"],
        h.environment.height = 0 => ["desc.environment is 2 x 0", "at least 1 x 1"],
        h.environment.width = MLT_MAX_ENVIRONMENT_SIDE + 1
            => ["desc.environment is 65537 x 1", "at most 65536"],
        (h.environment.width, h.environment.height) = (1 << 15, 1 << 14)
            => ["desc.environment is 32768 x 16384", "at most 268435456 texels"],
        h.environment.struct_size = 0
            => ["desc.environment.struct_size is 0", "mlt_environment_default"],
        h.environment.struct_size = size_of::<MltEnvironment>() as u32 + 8
            => ["desc.environment.struct_size", "newer mlt header"],
        h.pixels[4] = -1.0
            => ["desc.environment.pixels[4]", "texel 1", "column 1", "G", "is -1", ">= 0"],
        h.pixels[5] = f32::NAN => ["desc.environment.pixels[5]", "B", "is NaN"],
        h.pixels[0] = f32::INFINITY => ["desc.environment.pixels[0]", "R", "is inf"],
        h.environment.scale = -1.0 => ["desc.environment.scale is -1", ">= 0"],
        h.sun.struct_size = 0 => ["desc.sun.struct_size is 0", "mlt_sun_default"],
        h.sun.direction = [0.0; 3] => ["desc.sun.direction", "non-zero"],
        h.sun.direction = [1e30, 1e30, 0.0] => ["desc.sun.direction", "finite length"],
        h.sun.angular_radius_degrees = 46.0
            => ["desc.sun.angular_radius_degrees is 46", "[0, 45]"],
        h.sun.angular_radius_degrees = -1.0
            => ["desc.sun.angular_radius_degrees is -1", "[0, 45]"],
        h.sun.irradiance[0] = -1.0 => ["desc.sun.irradiance (R) is -1", ">= 0"],
        h.punctual[0].kind = 3
            => ["desc.punctual_lights[0].kind is 3", "MLT_LIGHT_POINT", "MLT_LIGHT_DIRECTIONAL"],
        h.punctual[2].kind = -1 => ["desc.punctual_lights[2].kind is -1", "MLT_LIGHT_SPOT"],
        h.punctual[0].intensity[1] = -2.0
            => ["desc.punctual_lights[0].intensity (G) is -2", ">= 0"],
        (h.punctual[1].inner_cone_degrees, h.punctual[1].outer_cone_degrees) = (30.0, 20.0)
            => ["desc.punctual_lights[1].inner_cone_degrees is 30", "outer_cone_degrees is 20"],
        h.punctual[1].outer_cone_degrees = 10.0
            => ["desc.punctual_lights[1].inner_cone_degrees is 10", "inner < outer"],
        h.punctual[1].outer_cone_degrees = 91.0
            => ["desc.punctual_lights[1]", "outer_cone_degrees is 91", "<= 90"],
        h.punctual[1].inner_cone_degrees = -1.0
            => ["desc.punctual_lights[1].inner_cone_degrees is -1", "0 <= inner"],
        h.punctual[1].direction = [0.0; 3] => ["desc.punctual_lights[1].direction", "non-zero"],
        h.punctual[2].direction = [0.0; 3] => ["desc.punctual_lights[2].direction", "non-zero"],
        h.punctual[1].struct_size = 0
            => ["desc.punctual_lights[1].struct_size is 0", "desc.punctual_lights[0]'s"],
        h.punctual[0].struct_size = 0
            => ["desc.punctual_lights[0].struct_size is 0", "mlt_punctual_light_default"],
    ];
    cases.extend(non_finite_cases![h = HostLights::new();
        h.environment.scale => "desc.environment.scale" + ">= 0",
        h.environment.rotation_degrees => "desc.environment.rotation_degrees" + "finite",
        h.sun.direction[1] => "desc.sun.direction.y" + "finite",
        h.sun.angular_radius_degrees => "desc.sun.angular_radius_degrees" + "[0, 45]",
        h.sun.irradiance[2] => "desc.sun.irradiance (B)" + ">= 0",
        h.punctual[0].position[2] => "desc.punctual_lights[0].position.z" + "finite",
        h.punctual[1].position[0] => "desc.punctual_lights[1].position.x" + "finite",
        h.punctual[0].intensity[0] => "desc.punctual_lights[0].intensity (R)" + ">= 0",
        h.punctual[1].direction[2] => "desc.punctual_lights[1].direction.z" + "finite",
        h.punctual[2].direction[0] => "desc.punctual_lights[2].direction.x" + "finite",
        h.punctual[1].inner_cone_degrees
            => "desc.punctual_lights[1].inner_cone_degrees" + "0 <= inner < outer <= 90",
        h.punctual[1].outer_cone_degrees
            => "desc.punctual_lights[1].outer_cone_degrees" + "0 <= inner < outer <= 90",
    ]);
    assert_create_refuses("lights", &cases, HostLights::desc);

    // Pointers and counts of the description itself.
    let lights = HostLights::new();
    let cases = cases![d = lights.desc();
        d.punctual_lights = null() => ["desc.punctual_lights", "NULL"],
        d.punctual_lights = odd.cast() => ["desc.punctual_lights[0]", "aligned"],
        d.environment = odd.cast() => ["desc.environment", "aligned"],
        d.sun = odd.cast() => ["desc.sun", "aligned"],
        d.punctual_lights_len = MLT_MAX_PUNCTUAL_LIGHTS + 1
            => ["desc.punctual_lights_len is 1048577", "at most 1048576"],
        d.punctual_lights_len = usize::MAX
            => ["desc.punctual_lights_len", "at most 1048576"],
    ];
    assert_create_refuses("light pointers", &cases, |d| *d);
}

/// Lights that are valid but unused are not checked: a point light's direction and cone,
/// a directional light's position and cone.
#[test]
fn unused_light_fields_are_ignored() {
    let mut lights = HostLights::new();
    lights.punctual[0].direction = [0.0; 3];
    lights.punctual[0].outer_cone_degrees = -5.0;
    lights.punctual[2].position = [f32::NAN; 3];
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(&lights.desc(), &mut out) });
    drop(Handle(out));
}

/// A host built against the header before the lights (its `MltSceneDesc` ends at
/// `backend`) gets no lights, whatever its memory holds past its struct.
#[test]
fn an_older_scene_desc_has_no_lights() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    let settings = small_settings(4, 4, 4);
    let (status, expected) = scene.render(&floor_camera(), &settings, 48);
    assert_ok(status);
    let older = MltSceneDesc {
        struct_size: earlier_size::<MltSceneDesc>(std::mem::offset_of!(MltSceneDesc, environment)),
        // Garbage an older host's memory may hold: mlt must not read it.
        environment: std::ptr::dangling(),
        sun: std::ptr::dangling(),
        punctual_lights: std::ptr::dangling(),
        punctual_lights_len: usize::MAX,
        ..host.desc()
    };
    assert_eq!(older.struct_size, 80, "mlt 0.2's sizeof(MltSceneDesc)");
    let mut out = null_mut();
    // SAFETY: an older layout's struct; mlt reads only its first 80 bytes.
    assert_ok(unsafe { mlt_scene_create(&older, &mut out) });
    let older_scene = Handle(out);
    let (status, image) = older_scene.render(&floor_camera(), &settings, 48);
    assert_ok(status);
    assert_eq!(image, expected, "the same scene, without lights");
}

/// Every build quality builds (the scene info says which, with the structure's memory and
/// build time) and renders the same image up to rounding; unknown values are refused; and a
/// host built against the header before the field gets the default, whatever its memory
/// holds past its struct.
#[test]
fn build_qualities() {
    let host = HostScene::floor_and_light();
    let settings = small_settings(4, 4, 4);
    let (status, expected) = host.create().render(&floor_camera(), &settings, 48);
    assert_ok(status);
    for backend in supported_backends() {
        for quality in [
            MLT_BUILD_QUALITY_HIGH,
            MLT_BUILD_QUALITY_MEDIUM,
            MLT_BUILD_QUALITY_FAST,
        ] {
            let desc = MltSceneDesc {
                backend,
                build_quality: quality,
                ..host.desc()
            };
            let mut out = null_mut();
            // SAFETY: a valid description.
            assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
            let scene = Handle(out);
            let info = scene.info();
            assert_eq!(info.build_quality, quality);
            assert!(info.accel_memory_bytes > 0, "{info:?}");
            assert!(info.accel_build_seconds >= 0.0, "{info:?}");
            let (status, image) = scene.render(&floor_camera(), &settings, 48);
            assert_ok(status);
            let difference: f32 = image
                .iter()
                .zip(&expected)
                .map(|(a, b)| (a - b).abs())
                .sum();
            let total: f32 = expected.iter().sum();
            assert!(
                difference <= 1e-4 * total,
                "backend {backend}, quality {quality}"
            );
        }
    }
    assert_eq!(default_desc().build_quality, MLT_BUILD_QUALITY_HIGH);
    for (value, text) in [(3, "3"), (-1, "-1"), (i32::MIN, "-2147483648")] {
        let desc = MltSceneDesc {
            build_quality: value,
            ..host.desc()
        };
        pass(check_create_refused(
            &desc,
            MLT_STATUS_INVALID_ARGUMENT,
            &["desc.build_quality", text, "MLT_BUILD_QUALITY_HIGH"],
        ));
    }
    let older = MltSceneDesc {
        struct_size: earlier_size::<MltSceneDesc>(std::mem::offset_of!(
            MltSceneDesc,
            build_quality
        )),
        // Garbage an older host's memory may hold past its struct.
        build_quality: 12345,
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: an older layout's struct; mlt reads only its first bytes.
    assert_ok(unsafe { mlt_scene_create(&older, &mut out) });
    assert_eq!(Handle(out).info().build_quality, MLT_BUILD_QUALITY_HIGH);
}

/// A 2 × 2 quad at y = 0 facing +y, diffuse with albedo `albedo`, no emitters.
fn lit_quad(albedo: f32) -> HostScene {
    HostScene {
        positions: vec![
            -1.0, 0.0, -1.0, -1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, -1.0,
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        material_ids: vec![0, 0],
        materials: vec![MltMaterial {
            color: [albedo; 3],
            ..default_material()
        }],
        backend: MLT_BACKEND_BVH,
    }
}

/// Looking straight down at the quad from `height`, so that it fills the image.
fn quad_camera(height: f32) -> MltCamera {
    MltCamera {
        eye: [0.0, height, 0.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 2.0 * (0.8 / height).atan().to_degrees(),
        ..default_camera()
    }
}

fn render_lit(desc: &MltSceneDesc, camera: &MltCamera, settings: &MltRenderSettings) -> Vec<f32> {
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(desc, &mut out) });
    let scene = Handle(out);
    let len = settings.width as usize * settings.height as usize * 3;
    let (status, image) = scene.render(camera, settings, len);
    assert_ok(status);
    image
}

/// A diffuse quad of albedo 0.5 under a constant environment of radiance 1, seen from
/// above: it receives π from the whole upper hemisphere and reflects 0.5 · π / π = 0.5 in
/// every direction, so every pixel is 0.5 within its noise (path tracing: BSDF sampling and
/// the environment's light sampling, combined by MIS).
#[test]
fn a_quad_under_a_constant_environment_reflects_its_albedo() {
    let host = lit_quad(0.5);
    let radiance = [1.0f32; 3];
    let environment = MltEnvironment {
        pixels: radiance.as_ptr(),
        width: 1,
        height: 1,
        ..default_environment()
    };
    let desc = MltSceneDesc {
        environment: &environment,
        ..host.desc()
    };
    let image = render_lit(&desc, &quad_camera(2.0), &small_settings(16, 16, 64));
    assert_valid_image(&image, "environment-lit quad");
    let (mean, error) = common::mean_and_standard_error(&image);
    for c in 0..3 {
        common::assert_within_and_sharp(&format!("channel {c}"), mean[c], 0.5, error[c], 4.0);
    }
    // Every pixel, against the spread of the pixels (all have the same expectation).
    let deviation = error[0] * ((image.len() / 3) as f64).sqrt();
    let worst = image
        .iter()
        .map(|&v| (v as f64 - 0.5).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= 5.0 * deviation,
        "a pixel is {worst} from 0.5, more than 5 standard deviations ({deviation})"
    );
}

/// The same quad lit only by a point light of intensity I at height h above its centre:
/// the irradiance at a point at distance d is I h / d³ and the radiance it reflects
/// albedo / π times that. Each pixel is compared with that radiance averaged over the
/// pixel's footprint; what remains is the noise of where in the pixel samples land.
#[test]
fn a_quad_under_a_point_light_follows_the_inverse_square_law() {
    let (albedo, intensity, h) = (0.5f32, 2.0f32, 1.0f32);
    let host = lit_quad(albedo);
    let light = MltPunctualLight {
        position: [0.0, h, 0.0],
        intensity: [intensity; 3],
        ..default_punctual_light()
    };
    let desc = MltSceneDesc {
        punctual_lights: &light,
        punctual_lights_len: 1,
        ..host.desc()
    };
    let camera = quad_camera(3.0);
    let (width, height) = (16u32, 16u32);
    let image = render_lit(&desc, &camera, &small_settings(width, height, 16));
    assert_valid_image(&image, "point-lit quad");

    let model = mlt::scene::Camera {
        eye: camera.eye,
        target: camera.target,
        up: camera.up,
        fov_y_deg: camera.fov_y_deg,
        ..mlt::scene::Camera::default()
    }
    .model(width, height);
    let radiance_at = |x: f32, y: f32| -> f64 {
        let (origin, direction) = model.generate_ray(x, y, [0.0, 0.0]);
        let t = -origin.y / direction.y;
        let p = origin + direction * t;
        let d2 = (p.x * p.x + (p.z * p.z) + h * h) as f64;
        albedo as f64 / std::f64::consts::PI * intensity as f64 * h as f64 / d2.powf(1.5)
    };
    const SUB: usize = 16;
    let mut residuals = Vec::new();
    let mut truth_sum = 0.0;
    for py in 0..height as usize {
        for px in 0..width as usize {
            let mut expected = 0.0;
            for sy in 0..SUB {
                for sx in 0..SUB {
                    let x = px as f32 + (sx as f32 + 0.5) / SUB as f32;
                    let y = py as f32 + (sy as f32 + 0.5) / SUB as f32;
                    expected += radiance_at(x, y);
                }
            }
            expected /= (SUB * SUB) as f64;
            truth_sum += expected;
            let i = (py * width as usize + px) * 3;
            for c in 0..3 {
                residuals.push(image[i + c] - expected as f32);
            }
        }
    }
    let pixels = (width * height) as f64;
    let truth = truth_sum / pixels;
    let (residual, error) = common::mean_and_standard_error(&residuals);
    for c in 0..3 {
        common::assert_within_and_sharp(
            &format!("channel {c} (mean {truth})"),
            truth + residual[c],
            truth,
            error[c],
            4.0,
        );
    }
}

// ---------------------------------------------------------------------------------------
// mlt_scene_create: surface attributes, textures and the metallic-roughness fields
// ---------------------------------------------------------------------------------------

fn default_texture() -> MltTexture {
    let mut t = std::mem::MaybeUninit::<MltTexture>::uninit();
    // SAFETY: writable memory for an MltTexture.
    assert_ok(unsafe { mlt_texture_init(t.as_mut_ptr(), size_of::<MltTexture>()) });
    // SAFETY: initialized on success.
    unsafe { t.assume_init() }
}

/// A texture slot of `texture` with the identity transform.
fn slot(texture: i32) -> MltTextureRef {
    MltTextureRef {
        texture,
        ..default_material().base_color_texture
    }
}

/// `HostScene::floor_and_light` with every surface attribute and three textures: texture 0
/// 2 × 2 8-bit sRGB RGBA, texture 1 2 × 2 float RGB (linear), texture 2 1 × 1 8-bit linear
/// RGB (a flat normal map). The floor (material 0, diffuse so that every build renders it)
/// uses textures 0, 1 and 2 as base colour, metallic-roughness and normal map, with a
/// texture transform and an alpha cut-out; the light (material 1) has texture 0 as its
/// emission texture.
struct HostSurfaces {
    host: HostScene,
    normals: Vec<f32>,
    texcoords: Vec<f32>,
    tangents: Vec<f32>,
    colors: Vec<f32>,
    /// What the textures' `texels` point to (set at construction: the vectors' buffers do
    /// not move with the struct), kept alive with it.
    #[allow(dead_code)]
    base_color_texels: Vec<u8>,
    metallic_roughness_texels: Vec<f32>,
    #[allow(dead_code)]
    normal_texels: Vec<u8>,
    textures: Vec<MltTexture>,
}

impl HostSurfaces {
    fn new() -> Self {
        let mut host = HostScene::floor_and_light();
        host.materials[0] = MltMaterial {
            metallic: 0.5,
            roughness: 0.25,
            transmission: 0.1,
            alpha: 0.9,
            alpha_mode: MLT_ALPHA_MASK,
            alpha_cutoff: 0.3,
            base_color_texture: MltTextureRef {
                texture: 0,
                offset: [0.25, -0.5],
                rotation: 0.3,
                scale: [2.0, 3.0],
            },
            metallic_roughness_texture: slot(1),
            normal_texture: slot(2),
            normal_scale: 0.8,
            energy_compensation: 1,
            ..host.materials[0]
        };
        host.materials[1].emission_texture = slot(0);
        let base_color_texels = vec![
            255, 128, 0, 255, 20, 40, 60, 200, 0, 0, 0, 0, 255, 255, 255, 255,
        ];
        let metallic_roughness_texels =
            vec![0.0, 1.0, 0.0, 0.0, 0.5, 1.0, 1.0, 0.2, 0.3, 0.0, 0.0, 0.0];
        let normal_texels = vec![128, 128, 255];
        let textures = vec![
            MltTexture {
                width: 2,
                height: 2,
                channels: 4,
                texels: base_color_texels.as_ptr().cast(),
                ..default_texture()
            },
            MltTexture {
                width: 2,
                height: 2,
                channels: 3,
                texel_type: MLT_TEXEL_F32,
                texels: metallic_roughness_texels.as_ptr().cast(),
                encoding: MLT_TEXTURE_LINEAR,
                wrap_u: MLT_WRAP_CLAMP_TO_EDGE,
                wrap_v: MLT_WRAP_MIRRORED_REPEAT,
                filter: MLT_FILTER_NEAREST,
                ..default_texture()
            },
            MltTexture {
                width: 1,
                height: 1,
                channels: 3,
                texels: normal_texels.as_ptr().cast(),
                encoding: MLT_TEXTURE_LINEAR,
                ..default_texture()
            },
        ];
        let up = [0.0, 1.0, 0.0];
        let down = [0.0, -1.0, 0.0];
        HostSurfaces {
            normals: [up, up, up, up, down, down, down, down].concat(),
            texcoords: vec![
                0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, // floor
                0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, // light
            ],
            tangents: [[1.0, 0.0, 0.0, -1.0]; 8].concat(),
            colors: [[0.9, 0.8, 0.7, 1.0]; 8].concat(),
            host,
            base_color_texels,
            metallic_roughness_texels,
            normal_texels,
            textures,
        }
    }

    fn desc(&self) -> MltSceneDesc {
        MltSceneDesc {
            normals: self.normals.as_ptr(),
            normals_len: self.normals.len(),
            texcoords: self.texcoords.as_ptr(),
            texcoords_len: self.texcoords.len(),
            tangents: self.tangents.as_ptr(),
            tangents_len: self.tangents.len(),
            colors: self.colors.as_ptr(),
            colors_len: self.colors.len(),
            textures: self.textures.as_ptr(),
            textures_len: self.textures.len(),
            ..self.host.desc()
        }
    }
}

#[test]
fn surface_defaults_are_valid_and_documented() {
    let m = default_material();
    assert_eq!(
        (m.metallic, m.roughness, m.transmission, m.alpha),
        (0.0, 1.0, 0.0, 1.0)
    );
    assert_eq!(
        (
            m.alpha_mode,
            m.alpha_cutoff,
            m.normal_scale,
            m.energy_compensation
        ),
        (MLT_ALPHA_OPAQUE, 0.5, 1.0, 0)
    );
    for r in [
        m.base_color_texture,
        m.metallic_roughness_texture,
        m.normal_texture,
        m.emission_texture,
    ] {
        assert_eq!(
            (r.texture, r.offset, r.rotation, r.scale),
            (MLT_NO_TEXTURE, [0.0; 2], 0.0, [1.0; 2])
        );
    }
    let d = default_desc();
    assert!(d.normals.is_null() && d.texcoords.is_null() && d.tangents.is_null());
    assert!(d.colors.is_null() && d.textures.is_null());
    assert_eq!(
        (
            d.normals_len,
            d.texcoords_len,
            d.tangents_len,
            d.colors_len,
            d.textures_len
        ),
        (0, 0, 0, 0, 0)
    );
    let t = default_texture();
    assert!(t.texels.is_null());
    assert_eq!((t.width, t.height, t.channels), (0, 0, 4));
    assert_eq!((t.texel_type, t.encoding), (MLT_TEXEL_U8, MLT_TEXTURE_SRGB));
    assert_eq!(
        (t.wrap_u, t.wrap_v, t.filter),
        (MLT_WRAP_REPEAT, MLT_WRAP_REPEAT, MLT_FILTER_BILINEAR)
    );
    // Every attribute and texture together, valid, and rendered.
    let surfaces = HostSurfaces::new();
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(&surfaces.desc(), &mut out) });
    let scene = Handle(out);
    let (status, image) = scene.render(&floor_camera(), &small_settings(4, 4, 2), 48);
    assert_ok(status);
    assert_valid_image(&image, "textured floor");
}

#[test]
fn texture_initializer_refuses_null_and_unknown_sizes() {
    let size = size_of::<MltTexture>();
    // SAFETY: NULL must be refused.
    let status = unsafe { mlt_texture_init(null_mut(), size) };
    assert_invalid(status, &["out", "NULL"]);
    for bad in [0, 3, size - 8, size + 8] {
        let mut storage = [0xABABABABu64; 16];
        // SAFETY: 128 writable bytes, more than any size tried.
        let status = unsafe { mlt_texture_init(storage.as_mut_ptr().cast(), bad) };
        assert_invalid(
            status,
            &["out.struct_size", &bad.to_string(), "mlt_texture_default"],
        );
        assert!(storage.iter().all(|&w| w == 0xABABABABu64), "out written");
    }
    assert_eq!(default_texture().struct_size as usize, size);
}

/// Every new field of a material, a texture and the scene description, each bad value
/// refused with a message naming it.
#[test]
fn scene_create_bad_surfaces() {
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let mut cases = cases![h = HostSurfaces::new();
        // Materials.
        h.host.materials[0].metallic = -0.1 => ["desc.materials[0].metallic is -0.1", "[0, 1]"],
        h.host.materials[0].metallic = 1.5 => ["desc.materials[0].metallic is 1.5", "[0, 1]"],
        h.host.materials[0].roughness = 2.0 => ["desc.materials[0].roughness is 2", "[0, 1]"],
        h.host.materials[1].roughness = -1.0 => ["desc.materials[1].roughness is -1", "[0, 1]"],
        h.host.materials[0].transmission = 1.01
            => ["desc.materials[0].transmission is 1.01", "[0, 1]"],
        h.host.materials[0].alpha = -0.5 => ["desc.materials[0].alpha is -0.5", "[0, 1]"],
        h.host.materials[0].alpha_cutoff = -0.25
            => ["desc.materials[0].alpha_cutoff is -0.25", "negative"],
        h.host.materials[0].alpha_mode = 2
            => ["desc.materials[0].alpha_mode is 2", "MLT_ALPHA_OPAQUE", "MLT_ALPHA_MASK"],
        h.host.materials[1].alpha_mode = -1 => ["desc.materials[1].alpha_mode is -1"],
        h.host.materials[0].energy_compensation = 2
            => ["desc.materials[0].energy_compensation is 2", "0 or 1"],
        h.host.materials[0].abbe_number = -20.0
            => ["desc.materials[0].abbe_number is -20", "positive", "0: no dispersion"],
        h.host.materials[1].abbe_number = f32::NAN => ["desc.materials[1].abbe_number", "NaN"],
        h.host.materials[1].abbe_number = f32::INFINITY
            => ["desc.materials[1].abbe_number", "inf"],
        h.host.materials[0].base_color_texture.texture = 3
            => ["desc.materials[0].base_color_texture.texture is 3", "3 textures"],
        h.host.materials[0].metallic_roughness_texture.texture = i32::MAX
            => ["desc.materials[0].metallic_roughness_texture.texture is 2147483647"],
        h.host.materials[0].normal_texture.texture = -2
            => ["desc.materials[0].normal_texture.texture is -2", "MLT_NO_TEXTURE (-1)"],
        h.host.materials[1].emission_texture.texture = i32::MIN
            => ["desc.materials[1].emission_texture.texture is -2147483648", "MLT_NO_TEXTURE"],
        h.host.materials[1].emission_texture.texture = 3
            => ["desc.materials[1].emission_texture.texture is 3", "3 textures"],
        h.host.materials[1].kind = 4 => ["desc.materials[1].kind is 4"],
        // Textures: enums.
        h.textures[0].texel_type = 2
            => ["desc.textures[0].texel_type is 2", "MLT_TEXEL_U8", "MLT_TEXEL_F32"],
        h.textures[2].texel_type = -1 => ["desc.textures[2].texel_type is -1"],
        h.textures[1].encoding = MLT_TEXTURE_SRGB
            => ["desc.textures[1].encoding is MLT_TEXTURE_SRGB", "MLT_TEXEL_F32", "8-bit"],
        h.textures[0].encoding = 2
            => ["desc.textures[0].encoding is 2", "MLT_TEXTURE_SRGB", "MLT_TEXTURE_LINEAR"],
        h.textures[0].wrap_u = 3
            => ["desc.textures[0].wrap_u is 3", "MLT_WRAP_REPEAT", "MLT_WRAP_MIRRORED_REPEAT"],
        h.textures[1].wrap_v = -1 => ["desc.textures[1].wrap_v is -1", "MLT_WRAP_CLAMP_TO_EDGE"],
        h.textures[2].filter = 2
            => ["desc.textures[2].filter is 2", "MLT_FILTER_NEAREST", "MLT_FILTER_BILINEAR"],
        // Textures: sizes (each refused before the texels are read).
        h.textures[0].width = 0 => ["desc.textures[0].width is 0", "at least 1 x 1"],
        h.textures[1].height = 0 => ["desc.textures[1].height is 0", "at least 1 x 1"],
        h.textures[0].width = MLT_MAX_TEXTURE_SIDE + 1
            => ["desc.textures[0].width is 32769", "at most 32768"],
        (h.textures[0].width, h.textures[0].height) = (1 << 15, 1 << 14)
            => ["desc.textures[0] is 32768 x 16384", "at most 268435456"],
        (h.textures[1].width, h.textures[1].height, h.textures[1].channels)
            = (u32::MAX, u32::MAX, u32::MAX)
            => ["desc.textures[1].width is 4294967295"],
        h.textures[0].channels = 0 => ["desc.textures[0].channels is 0", "1 (grey)"],
        h.textures[2].channels = 5 => ["desc.textures[2].channels is 5", "4 (RGBA)"],
        // Textures: texels.
        h.textures[2].texels = null() => ["desc.textures[2].texels is NULL"],
        h.textures[1].texels = odd.cast() => ["desc.textures[1].texels", "aligned"],
        h.metallic_roughness_texels[4] = -1.0
            => ["desc.textures[1].texels[4]", "row 0", "column 1", "channel 1", "is -1", ">= 0"],
        h.metallic_roughness_texels[9] = f32::NAN
            => ["desc.textures[1].texels[9]", "row 1", "column 1", "channel 0", "is NaN"],
        h.metallic_roughness_texels[11] = f32::INFINITY
            => ["desc.textures[1].texels[11]", "is inf"],
        h.textures[0].struct_size = 0
            => ["desc.textures[0].struct_size is 0", "mlt_texture_default"],
        h.textures[2].struct_size = 40
            => ["desc.textures[2].struct_size is 40", "desc.textures[0]'s"],
        // Vertex attributes: lengths.
        h.normals.pop() => ["desc.normals has 23 floats", "3 per vertex", "24 for 8 vertices"],
        h.texcoords.push(0.0) => ["desc.texcoords has 17 floats", "2 per vertex", "16"],
        h.tangents.truncate(28) => ["desc.tangents has 28 floats", "4 per vertex", "32"],
        h.colors.truncate(24) => ["desc.colors has 24 floats", "4 per vertex", "32"],
        // Vertex attributes: values.
        h.normals[3..6].copy_from_slice(&[0.0; 3])
            => ["desc.normals of vertex 1", "nonzero length"],
        h.tangents[7] = 0.0 => ["desc.tangents of vertex 1", "w = ±1"],
        h.tangents[12..15].copy_from_slice(&[0.0; 3])
            => ["desc.tangents of vertex 3", "nonzero length"],
        h.colors[5] = 1.5 => ["desc.colors[5]", "vertex 1", "g", "is 1.5", "[0, 1]"],
        h.colors[0] = -0.1 => ["desc.colors[0]", "vertex 0", "r", "is -0.1", "[0, 1]"],
        h.colors[31] = f32::NAN => ["desc.colors[31]", "vertex 7", "a", "is NaN"],
    ];
    cases.extend(non_finite_cases![h = HostSurfaces::new();
        h.host.materials[0].metallic => "desc.materials[0].metallic" + "finite",
        h.host.materials[0].roughness => "desc.materials[0].roughness" + "finite",
        h.host.materials[1].transmission => "desc.materials[1].transmission" + "finite",
        h.host.materials[0].alpha => "desc.materials[0].alpha" + "finite",
        h.host.materials[0].alpha_cutoff => "desc.materials[0].alpha_cutoff" + "finite",
        h.host.materials[0].normal_scale => "desc.materials[0].normal_scale" + "finite",
        h.host.materials[0].base_color_texture.rotation
            => "desc.materials[0].base_color_texture.rotation" + "finite",
        h.host.materials[0].base_color_texture.offset[1]
            => "desc.materials[0].base_color_texture.offset.v" + "finite",
        h.host.materials[0].normal_texture.scale[0]
            => "desc.materials[0].normal_texture.scale.u" + "finite",
        h.host.materials[1].emission_texture.scale[1]
            => "desc.materials[1].emission_texture.scale.v" + "finite",
        h.normals[4] => "desc.normals[4] (vertex 1, y)" + "finite",
        h.texcoords[3] => "desc.texcoords[3] (vertex 1, v)" + "finite",
        h.tangents[8] => "desc.tangents[8] (vertex 2, x)" + "finite",
        h.colors[2] => "desc.colors[2] (vertex 0, b)",
    ]);
    assert_create_refuses("surfaces", &cases, HostSurfaces::desc);

    // Pointers and counts of the description itself.
    let surfaces = HostSurfaces::new();
    let cases = cases![d = surfaces.desc();
        d.normals = null() => ["desc.normals is NULL"],
        d.texcoords = null() => ["desc.texcoords is NULL"],
        d.tangents = null() => ["desc.tangents is NULL"],
        d.colors = null() => ["desc.colors is NULL"],
        d.textures = null() => ["desc.textures[0] is NULL"],
        d.normals = odd.cast() => ["desc.normals", "aligned"],
        d.textures = odd.cast() => ["desc.textures[0]", "aligned"],
        d.colors_len = usize::MAX => ["desc.colors", "address space"],
        d.texcoords_len = 15 => ["desc.texcoords has 15 floats"],
        (d.texcoords, d.texcoords_len) = (null(), 0)
            => ["desc.materials[0] has textures", "desc.texcoords is empty"],
        d.textures_len = 2 => ["desc.materials[0].normal_texture.texture is 2", "2 textures"],
    ];
    assert_create_refuses("surface pointers", &cases, |d| *d);
}

/// The kind `MLT_MATERIAL_METALLIC_ROUGHNESS` passes the C ABI's checks: the scene is
/// created (and renders), or, in a build whose kernel cannot render the model yet, refused
/// as `MLT_STATUS_UNSUPPORTED` naming it, never as an invalid argument.
#[test]
fn metallic_roughness_materials_pass_the_c_abi() {
    let mut surfaces = HostSurfaces::new();
    surfaces.host.materials[0].kind = MLT_MATERIAL_METALLIC_ROUGHNESS;
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    let status = unsafe { mlt_scene_create(&surfaces.desc(), &mut out) };
    if status == MLT_STATUS_UNSUPPORTED {
        assert!(out.is_null());
        assert!(
            last_error().contains("desc.materials[0]"),
            "{}",
            last_error()
        );
        assert!(
            last_error().contains("metallic-roughness"),
            "{}",
            last_error()
        );
        return;
    }
    assert_ok(status);
    let scene = Handle(out);
    let (status, image) = scene.render(&floor_camera(), &small_settings(4, 4, 2), 48);
    assert_ok(status);
    assert_valid_image(&image, "metallic-roughness floor");
}

/// The textures' values reach the image: a white diffuse quad whose base colour texture
/// is a 1 × 1 float texel (0.5, 0.25, 1) and whose vertex colours are (1, 1, 0.5), under
/// a constant environment of radiance 1, reflects (0.5, 0.25, 0.5) (see
/// `a_quad_under_a_constant_environment_reflects_its_albedo`).
#[test]
fn a_texture_and_vertex_colours_set_the_albedo() {
    let mut host = lit_quad(1.0);
    host.materials[0].base_color_texture = slot(0);
    let texel = [0.5f32, 0.25, 1.0];
    let texture = MltTexture {
        width: 1,
        height: 1,
        channels: 3,
        texel_type: MLT_TEXEL_F32,
        texels: texel.as_ptr().cast(),
        encoding: MLT_TEXTURE_LINEAR,
        ..default_texture()
    };
    let texcoords = [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0];
    let colors = [[1.0f32, 1.0, 0.5, 1.0]; 4].concat();
    let radiance = [1.0f32; 3];
    let environment = MltEnvironment {
        pixels: radiance.as_ptr(),
        width: 1,
        height: 1,
        ..default_environment()
    };
    let desc = MltSceneDesc {
        environment: &environment,
        texcoords: texcoords.as_ptr(),
        texcoords_len: texcoords.len(),
        colors: colors.as_ptr(),
        colors_len: colors.len(),
        textures: &texture,
        textures_len: 1,
        ..host.desc()
    };
    let image = render_lit(&desc, &quad_camera(2.0), &small_settings(16, 16, 32));
    assert_valid_image(&image, "textured quad");
    let (mean, error) = common::mean_and_standard_error(&image);
    for (c, expected) in [0.5, 0.25, 0.5].into_iter().enumerate() {
        common::assert_within_and_sharp(&format!("channel {c}"), mean[c], expected, error[c], 4.0);
    }
}

/// Materials as a host built against mlt 0.2's header has them.
fn materials_of_02(materials: &[MltMaterial]) -> [MaterialOf02; 2] {
    std::array::from_fn(|i| {
        let m = materials[i];
        MaterialOf02 {
            struct_size: 36,
            kind: m.kind,
            color: m.color,
            emission: m.emission,
            ior: m.ior,
        }
    })
}

/// mlt 0.2's `MltMaterial`: the fields before `metallic`.
#[repr(C)]
#[derive(Clone, Copy)]
struct MaterialOf02 {
    struct_size: u32,
    kind: i32,
    color: [f32; 3],
    emission: [f32; 3],
    ior: f32,
}

/// Hosts built against older headers: a material array of mlt 0.2's 36-byte layout, and a
/// scene description of the 112-byte layout (lights, no surface attributes), whatever
/// their memory holds past their structs, give the scene a current host gets with the
/// defaults of the new fields: the same image.
#[test]
fn older_materials_and_scene_descs_default_the_surface_fields() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    let settings = small_settings(4, 4, 4);
    let (status, expected) = scene.render(&floor_camera(), &settings, 48);
    assert_ok(status);

    #[repr(C)]
    struct OlderMaterials {
        materials: [MaterialOf02; 2],
        /// What lies past an older host's array: NaN, never read.
        garbage: [u32; 64],
    }
    let older_materials = OlderMaterials {
        materials: materials_of_02(&host.materials),
        garbage: [0xFFFF_FFFF; 64],
    };
    let first_missing = std::mem::offset_of!(MltMaterial, metallic);
    assert_eq!(earlier_size::<MltMaterial>(first_missing), 36);
    assert_eq!(
        size_of::<MaterialOf02>(),
        36,
        "mlt 0.2's sizeof(MltMaterial)"
    );
    let desc = MltSceneDesc {
        materials: older_materials.materials.as_ptr().cast(),
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: an array of 2 materials of the older layout, as their struct_size says.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let (status, image) = Handle(out).render(&floor_camera(), &settings, 48);
    assert_ok(status);
    assert_eq!(image, expected, "0.2 materials: the same scene");

    let older_desc = MltSceneDesc {
        struct_size: earlier_size::<MltSceneDesc>(std::mem::offset_of!(MltSceneDesc, normals)),
        // Garbage an older host's memory may hold: mlt must not read it.
        normals: std::ptr::dangling(),
        normals_len: usize::MAX,
        texcoords: std::ptr::dangling(),
        texcoords_len: 3,
        tangents: null(),
        tangents_len: 5,
        colors: std::ptr::dangling(),
        colors_len: 7,
        textures: std::ptr::dangling(),
        textures_len: usize::MAX,
        ..host.desc()
    };
    assert_eq!(
        older_desc.struct_size, 112,
        "the lights' sizeof(MltSceneDesc)"
    );
    let mut out = null_mut();
    // SAFETY: an older layout's struct; mlt reads only its first 112 bytes.
    assert_ok(unsafe { mlt_scene_create(&older_desc, &mut out) });
    let (status, image) = Handle(out).render(&floor_camera(), &settings, 48);
    assert_ok(status);
    assert_eq!(image, expected, "a 112-byte desc: the same scene");
}

/// The surfaces scene (metallic-roughness materials, a checker base colour texture, a
/// textured lamp, per-vertex normals and texture coordinates) described through the C ABI
/// renders bit-identically to the same scene described in Rust: every new field of
/// `MltMaterial`, `MltTexture` and `MltSceneDesc` reaches the scene as the Rust API sets it.
#[test]
fn the_surfaces_scene_through_the_c_abi_renders_as_through_rust() {
    let surfaces = common::surfaces::surfaces_mesh();
    let textures: Vec<MltTexture> = surfaces
        .textures
        .iter()
        .map(|t| {
            let (texel_type, texels) = match &t.data {
                mlt::TexelData::U8(v) => (MLT_TEXEL_U8, v.as_ptr().cast::<c_void>()),
                mlt::TexelData::F32(v) => (MLT_TEXEL_F32, v.as_ptr().cast::<c_void>()),
            };
            let mut texture = std::mem::MaybeUninit::<MltTexture>::uninit();
            // SAFETY: writable memory of this size.
            assert_ok(unsafe { mlt_texture_init(texture.as_mut_ptr(), size_of::<MltTexture>()) });
            // SAFETY: initialized on success.
            let texture = unsafe { texture.assume_init() };
            MltTexture {
                width: t.width,
                height: t.height,
                channels: t.channels,
                texel_type,
                texels,
                encoding: match t.encoding {
                    mlt::TextureEncoding::Srgb => MLT_TEXTURE_SRGB,
                    mlt::TextureEncoding::Linear => MLT_TEXTURE_LINEAR,
                },
                wrap_u: wrap_mode(t.wrap_u),
                wrap_v: wrap_mode(t.wrap_v),
                filter: match t.filter {
                    mlt::TextureFilter::Nearest => MLT_FILTER_NEAREST,
                    mlt::TextureFilter::Bilinear => MLT_FILTER_BILINEAR,
                },
                ..texture
            }
        })
        .collect();
    let host = HostScene {
        materials: surfaces.mesh.c_materials(),
        positions: surfaces.mesh.positions.clone(),
        indices: surfaces.mesh.indices.clone(),
        material_ids: surfaces.mesh.material_ids.clone(),
        backend: MLT_BACKEND_BVH,
    };
    let desc = MltSceneDesc {
        normals: surfaces.normals.as_ptr(),
        normals_len: surfaces.normals.len(),
        texcoords: surfaces.texcoords.as_ptr(),
        texcoords_len: surfaces.texcoords.len(),
        textures: textures.as_ptr(),
        textures_len: textures.len(),
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: the desc points into live vectors of the stated lengths.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let c_scene = Handle(out);
    let rust_scene = surfaces.scene(mlt::Backend::Bvh);
    let camera = common::cornell_camera();
    let c_camera = MltCamera {
        eye: camera.eye,
        target: camera.target,
        up: camera.up,
        fov_y_deg: camera.fov_y_deg,
        lens_radius: camera.lens_radius,
        focus_distance: camera.focus_distance,
        ..default_camera()
    };
    for (algorithm, c_algorithm) in [
        (mlt::Algorithm::Path, MLT_ALGORITHM_PATH),
        (mlt::Algorithm::Bdpt, MLT_ALGORITHM_BDPT),
        (mlt::Algorithm::Mmlt, MLT_ALGORITHM_MMLT),
    ] {
        let settings = MltRenderSettings {
            algorithm: c_algorithm,
            ..small_settings(16, 16, 8)
        };
        let (status, c_image) = c_scene.render(&c_camera, &settings, 16 * 16 * 3);
        assert_ok(status);
        let rust_settings = mlt::RenderSettings {
            width: 16,
            height: 16,
            algorithm,
            samples_per_pixel: 8,
            ..Default::default()
        };
        let rust_image = common::render_image(&rust_scene, &camera, &rust_settings);
        assert!(
            c_image.iter().any(|&v| v > 0.0),
            "{algorithm:?}: a black image"
        );
        assert!(
            c_image
                .iter()
                .zip(&rust_image)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{algorithm:?}: the C ABI's render differs from the Rust API's"
        );
    }
}

fn wrap_mode(mode: mlt::WrapMode) -> i32 {
    match mode {
        mlt::WrapMode::Repeat => MLT_WRAP_REPEAT,
        mlt::WrapMode::ClampToEdge => MLT_WRAP_CLAMP_TO_EDGE,
        mlt::WrapMode::MirroredRepeat => MLT_WRAP_MIRRORED_REPEAT,
    }
}
