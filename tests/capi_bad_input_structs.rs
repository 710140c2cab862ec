//! The C ABI's structs as hosts built against any header version pass them: the initializers
//! (`mlt_*_default`) fill the documented defaults and refuse NULL and sizes no header had;
//! every call refuses an unknown `struct_size` where it reads the struct; a host built
//! against an older header renders as a current one with the defaults. Also the version
//! functions, the status strings and `mlt_backend_supported`.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_bad_input_structs`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;
use mlt::error::*;
use std::ffi::CStr;
use std::ptr::null_mut;

fn status_string(status: i32) -> String {
    // SAFETY: static NUL-terminated strings.
    unsafe { CStr::from_ptr(mlt_status_string(status)) }
        .to_str()
        .unwrap()
        .to_owned()
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

/// NULL and every unknown size, for each of the six initializers: refused, naming the
/// initializer, with `out` untouched; the struct's own size is taken and written.
#[test]
fn initializers_refuse_null_and_unknown_sizes() {
    // Each takes its own struct; `storage` below is large and aligned enough for any.
    // SAFETY (each closure): forwards the pointer and size to the initializer under test.
    let initializers: [(&str, usize, Initializer); 6] = [
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
    assert_initializers_refuse_null_and_unknown_sizes("initializers", &initializers);
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
