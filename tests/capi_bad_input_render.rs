//! `mlt_render` and `mlt_render_ex` fed bad input as a C host would: each bad pointer, buffer
//! length, setting (of every algorithm) or camera is refused with a message naming it and
//! neither the image nor the stats written; the limits themselves and extreme but finite
//! cameras render.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_bad_input_render`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;
use mlt::error::*;
use mlt::{
    MLT_MAX_DEPTH_LIMIT, MLT_MAX_ERPT_CHAIN_LENGTH, MLT_MAX_IMAGE_SIDE, MLT_MAX_SAMPLES_PER_PIXEL,
    MLT_MAX_THREADS, MLT_MAX_TIME_LIMIT_SECONDS,
};
use std::ptr::{null, null_mut};

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
        s.erpt_deposit_energy => "settings.erpt_deposit_energy" + "must be a finite number",
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
        s.filter_strength => "settings.filter_strength" + "must be a finite number",
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
        s.normalization_work_fraction => "settings.normalization_work_fraction" + "must be a finite number",
        s.large_step_probability => "settings.large_step_probability" + "must be a finite number",
        s.small_step_sigma => "settings.small_step_sigma" + "must be a finite number",
        s.mutation_weights[0] => "settings.mutation_weights[0]" + "must be a finite number",
        s.mutation_weights[1] => "settings.mutation_weights[1]" + "must be a finite number",
        s.mutation_weights[2] => "settings.mutation_weights[2]" + "must be a finite number",
        s.mutation_weights[3] => "settings.mutation_weights[3]" + "must be a finite number",
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
