//! Every C entry point fed bad input exactly as a C host would: the call must return the
//! documented status, `mlt_last_error_message()` must name the offending field, index or value,
//! and out-parameters must be left untouched on failure. Plus the behaviours the header
//! promises around them: degenerate triangles, cancellation, time limits, thread safety and
//! the last-error life cycle.

mod common;

use mlt::capi::*;
use mlt::error::*;
use mlt::render::{
    MLT_MAX_DEPTH_LIMIT, MLT_MAX_ERPT_CHAIN_LENGTH, MLT_MAX_IMAGE_SIDE, MLT_MAX_SAMPLES_PER_PIXEL,
    MLT_MAX_THREADS, MLT_MAX_TIME_LIMIT_SECONDS,
};
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

/// Asserts `status` and that the last error message contains every one of `needles`.
#[track_caller]
fn assert_error(status: MltStatus, expected: MltStatus, needles: &[&str]) {
    let message = last_error();
    assert_eq!(status, expected, "message: {message:?}");
    for needle in needles {
        assert!(
            message.contains(needle),
            "the message {message:?} should mention {needle:?}"
        );
    }
}

#[track_caller]
fn assert_invalid(status: MltStatus, needles: &[&str]) {
    assert_error(status, MLT_STATUS_INVALID_ARGUMENT, needles);
}

#[track_caller]
fn assert_ok(status: MltStatus) {
    assert_eq!(status, MLT_STATUS_OK, "message: {:?}", last_error());
    assert_eq!(last_error(), "", "a success clears the last error");
}

/// An aligned, non-null pointer value no allocation will ever have: the "untouched" marker
/// for out-parameters that are pointers.
fn sentinel_scene() -> *mut MltScene {
    std::ptr::dangling_mut::<u64>().wrapping_add(0x1000).cast()
}

const SENTINEL_F32: f32 = -12345.0;

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

    /// `mlt_scene_create` of a modified description, expecting failure: checks the status,
    /// the message and that `*out` was not written.
    #[track_caller]
    fn create_fails(&self, desc: &MltSceneDesc, expected: MltStatus, needles: &[&str]) {
        let _ = self;
        let mut out = sentinel_scene();
        // SAFETY: every non-null pointer in `desc` references an array of its length.
        let status = unsafe { mlt_scene_create(desc, &mut out) };
        assert_error(status, expected, needles);
        assert_eq!(out, sentinel_scene(), "*out must be untouched on failure");
    }
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

    /// A render that must fail: status, message, and the image buffer untouched.
    #[track_caller]
    fn render_fails(&self, camera: &MltCamera, settings: &MltRenderSettings, needles: &[&str]) {
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
        assert_invalid(status, needles);
        assert!(
            image.iter().all(|&v| v == SENTINEL_F32),
            "rgb_out must be untouched on failure"
        );
        assert_eq!(stats.samples, 77, "stats_out must be untouched on failure");
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

#[test]
fn default_initializers_reject_null() {
    // SAFETY: NULL is an accepted input (documented: returns an error).
    unsafe {
        assert_invalid(
            mlt_material_init(null_mut(), size_of::<MltMaterial>()),
            &["out", "NULL"],
        );
        assert_invalid(
            mlt_scene_desc_init(null_mut(), size_of::<MltSceneDesc>()),
            &["out", "NULL"],
        );
        assert_invalid(
            mlt_camera_init(null_mut(), size_of::<MltCamera>()),
            &["out", "NULL"],
        );
        assert_invalid(
            mlt_render_settings_init(null_mut(), size_of::<MltRenderSettings>()),
            &["out", "NULL"],
        );
    }
}

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

/// Sizes no header ever had: never initialized, too small, between layouts, from the future.
fn unknown_sizes<T>() -> [usize; 4] {
    [0, 3, size_of::<T>() - align_of::<T>(), size_of::<T>() + 8]
}

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
    for (name, size, init) in initializers {
        let mut storage = [0xABu8; 512];
        let aligned = storage
            .as_mut_ptr()
            .wrapping_add(storage.as_ptr().align_offset(8));
        // The storage holds any size tried (< 512 - 8).
        assert_invalid(init(null_mut(), size), &["out", "NULL"]);
        for bad in [0, 3, size - 8, size + 8] {
            assert_invalid(
                init(aligned, bad),
                &["out.struct_size", &bad.to_string(), name],
            );
            assert!(
                storage.iter().all(|&b| b == 0xAB),
                "{name}: out untouched on failure"
            );
        }
        assert_ok(init(aligned, size));
        // SAFETY: 4 initialized, aligned bytes of `storage`.
        let written = unsafe { aligned.cast::<u32>().read() };
        assert_eq!(written as usize, size, "{name} sets struct_size");
    }
}

#[test]
fn unknown_struct_sizes_are_refused_where_each_struct_is_read() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    for size in unknown_sizes::<MltRenderSettings>() {
        let settings = MltRenderSettings {
            struct_size: size as u32,
            ..small_settings(4, 4, 1)
        };
        scene.render_fails(
            &floor_camera(),
            &settings,
            &["settings.struct_size", &size.to_string()],
        );
    }
    for size in unknown_sizes::<MltCamera>() {
        let camera = MltCamera {
            struct_size: size as u32,
            ..floor_camera()
        };
        scene.render_fails(&camera, &small_settings(4, 4, 1), &["camera.struct_size"]);
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
                &floor_camera(),
                &small_settings(4, 4, 1),
                image.as_mut_ptr(),
                48,
                None,
                null_mut(),
                &mut stats,
            )
        };
        assert_invalid(
            status,
            &["stats_out.struct_size", "mlt_render_stats_default"],
        );
        assert!(image.iter().all(|&v| v == SENTINEL_F32) && stats.samples == 77);
    }
    for size in unknown_sizes::<MltSceneInfo>() {
        let mut info = MltSceneInfo {
            struct_size: size as u32,
            triangle_count: 99,
            ..scene_info_default()
        };
        // SAFETY: live scene, writable out.
        assert_invalid(
            unsafe { mlt_scene_get_info(scene.0, &mut info) },
            &["out.struct_size"],
        );
        assert_eq!(info.triangle_count, 99);
    }
    for size in unknown_sizes::<MltSceneDesc>() {
        let desc = MltSceneDesc {
            struct_size: size as u32,
            ..host.desc()
        };
        host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["desc.struct_size"]);
    }
    for size in unknown_sizes::<MltMaterial>() {
        let mut materials = host.clone();
        materials.materials[0].struct_size = size as u32;
        materials.create_fails(
            &materials.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["desc.materials[0].struct_size"],
        );
    }
    // An array's stride is its first element's size: every element must carry the same.
    let mut mixed = host.clone();
    mixed.materials[1].struct_size += 8;
    mixed.create_fails(
        &mixed.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["desc.materials[1].struct_size", "desc.materials[0]'s"],
    );
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
fn scene_create_null_desc() {
    let mut out = sentinel_scene();
    // SAFETY: NULL desc must be rejected.
    let status = unsafe { mlt_scene_create(null(), &mut out) };
    assert_invalid(status, &["desc", "NULL"]);
    assert_eq!(out, sentinel_scene());
}

#[test]
fn scene_create_null_out() {
    let host = HostScene::floor_and_light();
    // SAFETY: NULL out must be rejected.
    let status = unsafe { mlt_scene_create(&host.desc(), null_mut()) };
    assert_invalid(status, &["out", "NULL"]);
}

#[test]
fn scene_create_null_positions_with_length() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        positions: null(),
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["positions", "NULL"]);
}

#[test]
fn scene_create_null_indices_with_length() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        indices: null(),
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["indices", "NULL"]);
}

#[test]
fn scene_create_null_materials_with_length() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        materials: null(),
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["materials", "NULL"]);
}

#[test]
fn scene_create_null_material_ids_with_length() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        material_ids: null(),
        ..host.desc()
    };
    host.create_fails(
        &desc,
        MLT_STATUS_INVALID_ARGUMENT,
        &["material_ids", "NULL"],
    );
}

#[test]
fn scene_create_misaligned_arrays() {
    let host = HostScene::floor_and_light();
    // u64 storage: one byte past its start is misaligned for every multi-byte type.
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let desc = MltSceneDesc {
        positions: odd.cast(),
        ..host.desc()
    };
    host.create_fails(
        &desc,
        MLT_STATUS_INVALID_ARGUMENT,
        &["positions", "aligned"],
    );
    let desc = MltSceneDesc {
        indices: odd.cast(),
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["indices", "aligned"]);
}

#[test]
fn scene_create_length_larger_than_memory() {
    // A length whose byte size overflows must be refused before anything is read.
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        positions_len: usize::MAX / 2,
        ..host.desc()
    };
    host.create_fails(
        &desc,
        MLT_STATUS_INVALID_ARGUMENT,
        &["positions", "address space"],
    );
    let desc = MltSceneDesc {
        indices_len: usize::MAX,
        ..host.desc()
    };
    host.create_fails(
        &desc,
        MLT_STATUS_INVALID_ARGUMENT,
        &["indices", "address space"],
    );
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
fn positions_len_not_a_multiple_of_3() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        positions_len: 23,
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["positions", "23"]);
}

#[test]
fn indices_len_not_a_multiple_of_3() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        indices_len: 11,
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["indices", "11"]);
}

#[test]
fn material_ids_len_differs_from_triangle_count() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        material_ids_len: 3,
        ..host.desc()
    };
    host.create_fails(
        &desc,
        MLT_STATUS_INVALID_ARGUMENT,
        &["material_ids", "3", "4 triangles"],
    );
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

#[test]
fn triangles_without_materials() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        materials: null(),
        materials_len: 0,
        material_ids: null(),
        material_ids_len: 0,
        ..host.desc()
    };
    host.create_fails(&desc, MLT_STATUS_INVALID_ARGUMENT, &["materials", "empty"]);
}

#[test]
fn vertex_index_out_of_range() {
    let mut host = HostScene::floor_and_light();
    host.indices[7] = 8;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["indices[7]", "8", "8 vertices"],
    );
    host.indices[7] = u32::MAX;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["indices[7]", "4294967295"],
    );
}

#[test]
fn material_id_out_of_range() {
    let mut host = HostScene::floor_and_light();
    host.material_ids[3] = 2;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["material_ids[3]", "2", "2 materials"],
    );
}

// ---------------------------------------------------------------------------------------
// mlt_scene_create: float values and enums
// ---------------------------------------------------------------------------------------

#[test]
fn non_finite_positions() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut host = HostScene::floor_and_light();
        host.positions[13] = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["positions[13]", "vertex 4", "y", &bad.to_string()],
        );
    }
}

#[test]
fn non_finite_colors() {
    for bad in [f32::NAN, f32::INFINITY] {
        let mut host = HostScene::floor_and_light();
        host.materials[0].color[1] = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["materials[0].color.y", &bad.to_string()],
        );
    }
}

#[test]
fn colors_outside_0_1() {
    let mut host = HostScene::floor_and_light();
    host.materials[0].color[2] = -0.5;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["materials[0].color.z", "-0.5"],
    );
    let mut host = HostScene::floor_and_light();
    host.materials[1].color[0] = 1.5;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["materials[1].color.x", "1.5"],
    );
}

#[test]
fn non_finite_emission() {
    for bad in [f32::NAN, f32::INFINITY] {
        let mut host = HostScene::floor_and_light();
        host.materials[1].emission[0] = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["materials[1].emission.x", &bad.to_string()],
        );
    }
}

#[test]
fn negative_emission() {
    let mut host = HostScene::floor_and_light();
    host.materials[1].emission[2] = -1.0;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["materials[1].emission.z", "-1", "negative"],
    );
}

#[test]
fn non_finite_ior() {
    for bad in [f32::NAN, f32::INFINITY] {
        let mut host = HostScene::floor_and_light();
        host.materials[0].kind = MLT_MATERIAL_DIELECTRIC;
        host.materials[0].ior = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["materials[0].ior", &bad.to_string()],
        );
    }
}

#[test]
fn ior_not_positive() {
    for bad in [0.0, -0.0, -1.5] {
        let mut host = HostScene::floor_and_light();
        host.materials[0].kind = MLT_MATERIAL_DIELECTRIC;
        host.materials[0].ior = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["materials[0].ior", "greater than 0"],
        );
    }
}

#[test]
fn ior_is_ignored_for_non_dielectrics_but_must_be_finite() {
    // The header: "Ignored otherwise". Zero or negative is accepted for diffuse and mirror...
    for kind in [MLT_MATERIAL_DIFFUSE, MLT_MATERIAL_MIRROR] {
        let mut host = HostScene::floor_and_light();
        host.materials[0].kind = kind;
        host.materials[0].ior = -1.0;
        drop(host.create());
    }
    // ...but a NaN is still reported (every float the host passes must be finite).
    let mut host = HostScene::floor_and_light();
    host.materials[0].ior = f32::NAN;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_INVALID_ARGUMENT,
        &["materials[0].ior", "NaN"],
    );
}

#[test]
fn unknown_material_kind() {
    for bad in [3, -1, i32::MAX] {
        let mut host = HostScene::floor_and_light();
        host.materials[1].kind = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &[
                "materials[1].kind",
                &bad.to_string(),
                "MLT_MATERIAL_DIFFUSE",
            ],
        );
    }
}

#[test]
fn unknown_backend() {
    for bad in [2, -1, i32::MIN] {
        let mut host = HostScene::floor_and_light();
        host.backend = bad;
        host.create_fails(
            &host.desc(),
            MLT_STATUS_INVALID_ARGUMENT,
            &["backend", &bad.to_string()],
        );
    }
}

#[test]
#[cfg(not(feature = "embree"))]
fn embree_backend_is_unsupported_without_the_feature() {
    let mut host = HostScene::floor_and_light();
    host.backend = MLT_BACKEND_EMBREE;
    host.create_fails(
        &host.desc(),
        MLT_STATUS_UNSUPPORTED,
        &["Embree", "`embree` feature"],
    );
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
    assert_eq!(hits[0].t, 0.5, "t in multiples of the direction");
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
fn render_null_pointers() {
    let scene = HostScene::floor_and_light().create();
    let camera = floor_camera();
    let settings = small_settings(4, 4, 1);
    let mut image = vec![SENTINEL_F32; 48];
    let p = image.as_mut_ptr();
    // SAFETY: each call passes one NULL that must be rejected; the rest is valid.
    unsafe {
        let s = mlt_render(null(), &camera, &settings, p, 48, None, null_mut());
        assert_invalid(s, &["scene", "NULL"]);
        let s = mlt_render(scene.0, null(), &settings, p, 48, None, null_mut());
        assert_invalid(s, &["camera", "NULL"]);
        let s = mlt_render(scene.0, &camera, null(), p, 48, None, null_mut());
        assert_invalid(s, &["settings", "NULL"]);
        let s = mlt_render(
            scene.0,
            &camera,
            &settings,
            null_mut(),
            48,
            None,
            null_mut(),
        );
        assert_invalid(s, &["rgb_out", "NULL"]);
    }
    assert!(image.iter().all(|&v| v == SENTINEL_F32));
}

#[test]
fn render_misaligned_output() {
    let scene = HostScene::floor_and_light().create();
    let mut storage = vec![0u64; 32];
    let odd = storage
        .as_mut_ptr()
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<f32>();
    // SAFETY: a misaligned pointer must be rejected before any write.
    let s = unsafe {
        mlt_render(
            scene.0,
            &floor_camera(),
            &small_settings(4, 4, 1),
            odd,
            48,
            None,
            null_mut(),
        )
    };
    assert_invalid(s, &["rgb_out", "aligned"]);
    assert!(storage.iter().all(|&b| b == 0));
}

#[test]
fn render_output_buffer_too_small() {
    let scene = HostScene::floor_and_light().create();
    let settings = small_settings(4, 4, 1);
    let (status, image) = scene.render(&floor_camera(), &settings, 47);
    assert_invalid(status, &["out_len", "47", "48"]);
    assert!(image.iter().all(|&v| v == SENTINEL_F32));
    let (status, _) = scene.render(&floor_camera(), &settings, 0);
    assert_invalid(status, &["out_len", "0"]);
}

#[test]
fn render_larger_buffer_is_fine_and_the_tail_untouched() {
    let scene = HostScene::floor_and_light().create();
    let (status, image) = scene.render(&floor_camera(), &small_settings(4, 4, 1), 60);
    assert_ok(status);
    assert_valid_image(&image[..48], "image");
    assert!(image[48..].iter().all(|&v| v == SENTINEL_F32));
}

#[test]
fn stats_out_misaligned() {
    let scene = HostScene::floor_and_light().create();
    let mut image = vec![SENTINEL_F32; 48];
    let mut storage = [0u64; 16];
    let odd = storage
        .as_mut_ptr()
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<MltRenderStats>();
    // SAFETY: the misaligned stats pointer must be rejected before rendering.
    let s = unsafe {
        mlt_render_ex(
            scene.0,
            &floor_camera(),
            &small_settings(4, 4, 1),
            image.as_mut_ptr(),
            48,
            None,
            null_mut(),
            odd,
        )
    };
    assert_invalid(s, &["stats_out", "aligned"]);
    assert!(image.iter().all(|&v| v == SENTINEL_F32));
}

// ---------------------------------------------------------------------------------------
// mlt_render: settings
// ---------------------------------------------------------------------------------------

#[test]
fn zero_or_huge_image_size() {
    let scene = HostScene::floor_and_light().create();
    let camera = floor_camera();
    for (w, h, field, value) in [
        (0, 4, "width", "0"),
        (4, 0, "height", "0"),
        (MLT_MAX_IMAGE_SIDE + 1, 4, "width", "65537"),
        (4, u32::MAX, "height", "4294967295"),
    ] {
        scene.render_fails(&camera, &small_settings(w, h, 1), &[field, value, "65536"]);
    }
}

#[test]
fn absurd_samples_depth_threads() {
    let scene = HostScene::floor_and_light().create();
    let camera = floor_camera();
    let base = small_settings(4, 4, 1);
    let s = MltRenderSettings {
        samples_per_pixel: MLT_MAX_SAMPLES_PER_PIXEL + 1,
        ..base
    };
    scene.render_fails(&camera, &s, &["samples_per_pixel", "16777217"]);
    let s = MltRenderSettings {
        max_depth: MLT_MAX_DEPTH_LIMIT + 1,
        ..base
    };
    scene.render_fails(&camera, &s, &["max_depth", "1025"]);
    let s = MltRenderSettings {
        threads: MLT_MAX_THREADS + 1,
        ..base
    };
    scene.render_fails(&camera, &s, &["threads", "4097"]);
    let s = MltRenderSettings {
        threads: u32::MAX,
        ..base
    };
    scene.render_fails(&camera, &s, &["threads", "4294967295"]);
}

#[test]
fn bad_time_limits() {
    let scene = HostScene::floor_and_light().create();
    let camera = floor_camera();
    for (bad, text) in [
        (-1.0, "-1"),
        (-0.001, "-0.001"),
        (f64::NAN, "NaN"),
        (f64::INFINITY, "inf"),
        (1.0e8, "100000000"),
    ] {
        let s = MltRenderSettings {
            time_limit_seconds: bad,
            ..small_settings(4, 4, 1)
        };
        scene.render_fails(&camera, &s, &["time_limit_seconds", text]);
    }
}

#[test]
fn zero_samples_without_time_limit() {
    let scene = HostScene::floor_and_light().create();
    scene.render_fails(
        &floor_camera(),
        &small_settings(4, 4, 0),
        &["samples_per_pixel is 0", "time limit"],
    );
}

#[test]
fn unknown_algorithm() {
    let scene = HostScene::floor_and_light().create();
    for bad in [7, -1, i32::MAX] {
        let s = MltRenderSettings {
            algorithm: bad,
            ..small_settings(4, 4, 1)
        };
        scene.render_fails(
            &floor_camera(),
            &s,
            &["algorithm", &bad.to_string(), "MLT_ALGORITHM_PATH"],
        );
    }
}

#[test]
fn erpt_settings_out_of_range() {
    let scene = HostScene::floor_and_light().create();
    let erpt = MltRenderSettings {
        algorithm: MLT_ALGORITHM_ERPT,
        ..small_settings(4, 4, 1)
    };
    let cases: [(MltRenderSettings, &[&str]); 8] = [
        (
            MltRenderSettings {
                erpt_chain_length: 0,
                ..erpt
            },
            &["erpt_chain_length is 0", "between 1 and 1048576"],
        ),
        (
            MltRenderSettings {
                erpt_chain_length: MLT_MAX_ERPT_CHAIN_LENGTH + 1,
                ..erpt
            },
            &["erpt_chain_length is 1048577"],
        ),
        (
            MltRenderSettings {
                erpt_chain_length: u32::MAX,
                ..erpt
            },
            &["erpt_chain_length is 4294967295"],
        ),
        (
            MltRenderSettings {
                erpt_deposit_energy: -1.0,
                ..erpt
            },
            &["erpt_deposit_energy is -1"],
        ),
        (
            MltRenderSettings {
                erpt_deposit_energy: f32::NAN,
                ..erpt
            },
            &["erpt_deposit_energy is NaN"],
        ),
        (
            MltRenderSettings {
                erpt_deposit_energy: f32::INFINITY,
                ..erpt
            },
            &["erpt_deposit_energy is inf"],
        ),
        (
            MltRenderSettings {
                erpt_deposit_energy: 1e31,
                ..erpt
            },
            &["erpt_deposit_energy", "1e30"],
        ),
        (
            MltRenderSettings {
                samples_per_pixel: 0,
                ..erpt
            },
            &["samples_per_pixel is 0", "time limit"],
        ),
    ];
    for (settings, needles) in &cases {
        scene.render_fails(&floor_camera(), settings, needles);
    }
    // In range, with an explicit deposit energy and the shortest chains, it renders.
    for (erpt_chain_length, erpt_deposit_energy) in [(1, 0.0), (100, 1e-3), (1, 1e30)] {
        let settings = MltRenderSettings {
            erpt_chain_length,
            erpt_deposit_energy,
            ..erpt
        };
        let mut rgb = vec![0.0f32; 4 * 4 * 3];
        let mut stats = render_stats_default();
        // SAFETY: valid pointers; `rgb` holds the 48 floats passed.
        let status = unsafe {
            mlt_render_ex(
                scene.0,
                &floor_camera(),
                &settings,
                rgb.as_mut_ptr(),
                rgb.len(),
                None,
                null_mut(),
                &mut stats,
            )
        };
        assert_eq!(
            status, MLT_STATUS_OK,
            "{erpt_chain_length}, {erpt_deposit_energy}"
        );
        assert_eq!(stats.samples, 16);
        assert!(rgb.iter().all(|v| v.is_finite()));
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
    let cases: [(MltRenderSettings, &[&str]); 9] = [
        (
            MltRenderSettings {
                filter_buffers: 1,
                ..metropolis
            },
            &["filter_buffers is 1", "0 (no filter) or from 2 to 32"],
        ),
        (
            MltRenderSettings {
                filter_buffers: 33,
                ..metropolis
            },
            &["filter_buffers is 33"],
        ),
        (
            MltRenderSettings {
                filter_strength: f32::NAN,
                ..metropolis
            },
            &["filter_strength is NaN"],
        ),
        (
            MltRenderSettings {
                filter_strength: 0.0,
                ..metropolis
            },
            &["filter_strength is 0", "positive"],
        ),
        (
            MltRenderSettings {
                filter_strength: -1.0,
                ..metropolis
            },
            &["filter_strength is -1"],
        ),
        (
            MltRenderSettings {
                filter_strength: 1e9,
                ..metropolis
            },
            &["filter_strength is 1000000000", "up to 100"],
        ),
        (
            MltRenderSettings {
                filter_radius: 0,
                ..metropolis
            },
            &["filter_radius is 0", "from 1 to 32"],
        ),
        (
            MltRenderSettings {
                filter_radius: u32::MAX,
                ..metropolis
            },
            &["filter_radius is 4294967295"],
        ),
        (
            MltRenderSettings {
                algorithm: MLT_ALGORITHM_PATH,
                ..metropolis
            },
            &["filter_buffers is 8", "Path", "Metropolis and ERPT"],
        ),
    ];
    for (settings, needles) in &cases {
        scene.render_fails(&floor_camera(), settings, needles);
    }
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
    let cases: [(MltRenderSettings, &[&str]); 19] = [
        (
            MltRenderSettings {
                mutations_per_pixel: 0,
                ..metropolis
            },
            &["mutations_per_pixel is 0", "time limit"],
        ),
        (
            MltRenderSettings {
                mutations_per_pixel: MLT_MAX_SAMPLES_PER_PIXEL + 1,
                direct_samples_per_mutation: 0,
                ..metropolis
            },
            &["mutations_per_pixel", "16777217"],
        ),
        (
            MltRenderSettings {
                mutations_per_pixel: 1 << 20,
                direct_samples_per_mutation: 17,
                ..metropolis
            },
            &["direct_samples_per_mutation is 17", "mutations_per_pixel"],
        ),
        (
            MltRenderSettings {
                bootstrap_samples: (1 << 28) + 1,
                ..metropolis
            },
            &["bootstrap_samples is 268435457", "0 (automatic)"],
        ),
        (
            MltRenderSettings {
                bootstrap_samples: 0,
                chains: 1 << 20,
                ..metropolis
            },
            &["chains is 1048576", "bootstrap samples (65536)"],
        ),
        (
            MltRenderSettings {
                normalization_work_fraction: f32::NAN,
                ..metropolis
            },
            &["normalization_work_fraction is NaN", "0 to 0.9"],
        ),
        (
            MltRenderSettings {
                normalization_work_fraction: -0.1,
                ..metropolis
            },
            &["normalization_work_fraction is -0.1"],
        ),
        (
            MltRenderSettings {
                normalization_work_fraction: 0.95,
                ..metropolis
            },
            &["normalization_work_fraction is 0.95"],
        ),
        (
            MltRenderSettings {
                chains: 0,
                ..metropolis
            },
            &["chains is 0"],
        ),
        (
            MltRenderSettings {
                chains: 65,
                ..metropolis
            },
            &["chains is 65", "bootstrap samples (64)"],
        ),
        (
            MltRenderSettings {
                large_step_probability: f32::NAN,
                ..metropolis
            },
            &["large_step_probability is NaN"],
        ),
        (
            MltRenderSettings {
                large_step_probability: 1.5,
                ..metropolis
            },
            &["large_step_probability is 1.5"],
        ),
        (
            MltRenderSettings {
                small_step_sigma: 0.0,
                ..metropolis
            },
            &["small_step_sigma is 0"],
        ),
        (
            MltRenderSettings {
                small_step_sigma: f32::INFINITY,
                ..metropolis
            },
            &["small_step_sigma is inf"],
        ),
        (
            MltRenderSettings {
                mutation_weights: [0.5, f32::NAN, 0.25, 0.25],
                ..metropolis
            },
            &["mutation_weights[1] is NaN"],
        ),
        (
            MltRenderSettings {
                mutation_weights: [0.5, 0.25, -1.0, 0.25],
                ..metropolis
            },
            &["mutation_weights[2] is -1"],
        ),
        (
            MltRenderSettings {
                mutation_weights: [0.0, 1.0, 1.0, 1.0],
                ..metropolis
            },
            &["mutation_weights[0]", "bidirectional", "positive"],
        ),
        (
            MltRenderSettings {
                adapt_mutation_weights: 2,
                ..metropolis
            },
            &["adapt_mutation_weights is 2", "0 or 1"],
        ),
        (
            MltRenderSettings {
                perturb_in_sample_space: u32::MAX,
                ..metropolis
            },
            &["perturb_in_sample_space is 4294967295", "0 or 1"],
        ),
    ];
    for (settings, needles) in &cases {
        scene.render_fails(&floor_camera(), settings, needles);
    }
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
fn non_finite_camera_values() {
    let scene = HostScene::floor_and_light().create();
    let settings = small_settings(4, 4, 1);
    let base = floor_camera();
    let cases: [(MltCamera, &str); 6] = [
        (
            MltCamera {
                eye: [f32::NAN, 1.0, -4.0],
                ..base
            },
            "camera.eye.x",
        ),
        (
            MltCamera {
                target: [0.0, f32::INFINITY, 0.0],
                ..base
            },
            "camera.target.y",
        ),
        (
            MltCamera {
                up: [0.0, 1.0, f32::NAN],
                ..base
            },
            "camera.up.z",
        ),
        (
            MltCamera {
                fov_y_deg: f32::INFINITY,
                ..base
            },
            "camera.fov_y_deg",
        ),
        (
            MltCamera {
                lens_radius: f32::NAN,
                ..base
            },
            "camera.lens_radius",
        ),
        (
            MltCamera {
                focus_distance: f32::NEG_INFINITY,
                ..base
            },
            "camera.focus_distance",
        ),
    ];
    for (camera, field) in cases {
        scene.render_fails(&camera, &settings, &[field, "finite"]);
    }
}

#[test]
fn eye_equals_target() {
    let scene = HostScene::floor_and_light().create();
    let camera = MltCamera {
        target: [0.0, 1.0, -4.0],
        ..floor_camera()
    };
    scene.render_fails(
        &camera,
        &small_settings(4, 4, 1),
        &["camera.eye", "camera.target", "coincide"],
    );
}

#[test]
fn up_parallel_to_view_or_zero() {
    let scene = HostScene::floor_and_light().create();
    let settings = small_settings(4, 4, 1);
    for up in [[0.0, 0.0, 1.0], [0.0, 0.0, -3.0]] {
        let camera = MltCamera {
            up,
            ..floor_camera()
        };
        scene.render_fails(&camera, &settings, &["camera.up", "parallel"]);
    }
    let camera = MltCamera {
        up: [0.0; 3],
        ..floor_camera()
    };
    scene.render_fails(&camera, &settings, &["camera.up", "zero"]);
}

#[test]
fn bad_field_of_view() {
    let scene = HostScene::floor_and_light().create();
    let settings = small_settings(4, 4, 1);
    for fov in [0.0, -0.0, 180.0, 200.0, -30.0, f32::NAN] {
        let camera = MltCamera {
            fov_y_deg: fov,
            ..floor_camera()
        };
        scene.render_fails(&camera, &settings, &["camera.fov_y_deg", &fov.to_string()]);
    }
}

#[test]
fn negative_lens_values() {
    let scene = HostScene::floor_and_light().create();
    let settings = small_settings(4, 4, 1);
    let camera = MltCamera {
        lens_radius: -1.0,
        ..floor_camera()
    };
    scene.render_fails(&camera, &settings, &["camera.lens_radius", "-1"]);
    let camera = MltCamera {
        focus_distance: -2.0,
        ..floor_camera()
    };
    scene.render_fails(&camera, &settings, &["camera.focus_distance", "-2"]);
}

#[test]
fn camera_whose_view_vector_overflows() {
    // Finite eye and target whose difference overflows f32: the view direction is undefined.
    let scene = HostScene::floor_and_light().create();
    let camera = MltCamera {
        eye: [3.0e38, 0.0, 0.0],
        target: [-3.0e38, 0.0, 0.0],
        ..floor_camera()
    };
    scene.render_fails(&camera, &small_settings(4, 4, 1), &["camera"]);
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
    let cases: Vec<(MltRay, Vec<&str>)> = vec![
        (
            MltRay {
                origin: [f32::NAN, 0.0, 0.0],
                ..good
            },
            vec!["rays[1].origin.x", "NaN"],
        ),
        (
            MltRay {
                origin: [0.0, f32::INFINITY, 0.0],
                ..good
            },
            vec!["rays[1].origin.y", "inf"],
        ),
        (
            MltRay {
                direction: [0.0, 0.0, f32::NAN],
                ..good
            },
            vec!["rays[1].direction.z", "NaN"],
        ),
        (
            MltRay {
                direction: [0.0; 3],
                ..good
            },
            vec!["rays[1].direction", "non-zero"],
        ),
        (
            MltRay { tmin: -1.0, ..good },
            vec!["rays[1].tmin", "-1", ">= 0"],
        ),
        (
            MltRay {
                tmin: f32::NAN,
                ..good
            },
            vec!["rays[1].tmin", "NaN"],
        ),
        (
            MltRay {
                tmin: f32::INFINITY,
                ..good
            },
            vec!["rays[1].tmin", "inf"],
        ),
        (
            MltRay {
                tmin: 2.0,
                tmax: 1.0,
                ..good
            },
            vec!["rays[1].tmax", "1", "tmin (2)"],
        ),
        (
            MltRay {
                tmax: f32::NAN,
                ..good
            },
            vec!["rays[1].tmax", "NaN"],
        ),
        (
            MltRay {
                tmax: f32::NEG_INFINITY,
                ..good
            },
            vec!["rays[1].tmax", "-inf"],
        ),
    ];
    for (bad, needles) in cases {
        let rays = [good, bad];
        let (status, hits) = scene.intersect(&rays);
        assert_invalid(status, &needles);
        assert!(
            hits.iter()
                .all(|h| h.triangle_id == SENTINEL_HIT.triangle_id),
            "hits_out written although rays[1] is bad: {bad:?}"
        );
        let (status, flags) = scene.occluded(&rays);
        assert_invalid(status, &needles);
        assert_eq!(
            flags,
            [0xAB, 0xAB],
            "occluded_out written although rays[1] is bad"
        );
    }
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

/// A well-converged mean of the 8 × 8 Cornell box.
fn cornell_reference_mean(scene: &Handle, camera: &MltCamera) -> [f64; 3] {
    let (status, image) = scene.render(camera, &small_settings(8, 8, 2048), 192);
    assert_ok(status);
    common::mean(&image)
}

#[track_caller]
fn assert_mean_close(image: &[f32], reference: [f64; 3], tolerance: f64) {
    let mean = common::mean(image);
    for c in 0..3 {
        assert!(
            (mean[c] - reference[c]).abs() <= tolerance * reference[c],
            "mean {mean:?} is not within {tolerance} of the full render's {reference:?}"
        );
    }
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
    let reference = cornell_reference_mean(&scene, &camera);
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
    // Normalized by the samples actually taken: the mean matches a complete render.
    assert_mean_close(&image, reference, 0.1);
}

#[test]
fn time_limit_with_huge_sample_count() {
    let (scene, camera) = cornell();
    let reference = cornell_reference_mean(&scene, &camera);
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
    assert_mean_close(&image, reference, 0.1);
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
    // (at least one sample per pixel), not an all-black buffer reported as "valid".
    let (scene, camera) = cornell();
    let reference = cornell_reference_mean(&scene, &camera);
    // The image mean does not depend on resolution: 32 x 32 pixels of one sample each are
    // compared with the 8 x 8 reference.
    let settings = MltRenderSettings {
        time_limit_seconds: 1e-6,
        ..small_settings(32, 32, MLT_MAX_SAMPLES_PER_PIXEL)
    };
    let (status, image) = scene.render(&camera, &settings, 32 * 32 * 3);
    assert_error(status, MLT_STATUS_TIME_LIMIT_REACHED, &["time limit"]);
    assert_valid_image(&image, "image");
    assert_mean_close(&image, reference, 0.5);
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
