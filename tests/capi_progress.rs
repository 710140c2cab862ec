//! Progress, cancellation and time limits through the C ABI: the progress callback is called
//! on the calling thread and ends at 1; a render cancelled from it or stopped by its time
//! limit returns the documented status with an image of whole passes, every pixel
//! bit-identical to the complete render of its own sample count.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_progress`).

mod common {
    pub mod capi;
    pub mod scenes;
    pub mod stats;
}

use common::capi::*;
use mlt::MLT_MAX_SAMPLES_PER_PIXEL;
use mlt::capi::*;
use mlt::error::*;
use std::ffi::c_void;
use std::ptr::null_mut;

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
    assert!(common::stats::mean(&image)[0] > 0.0);
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
