//! Bidirectional path tracing against ground truth and against the path tracer: the white
//! furnace, the analytic area light, and the Cornell and door-ajar scenes (image mean and
//! per-region means within 5 and 6 combined standard errors from 16 renders, a 2% bias
//! resolvable). Light tracing splats land on arbitrary pixels; the image must still be
//! identical for any thread count.
//!
//! Runs in about 20 s on 2 cores (`cargo test --test bdpt`).

mod common {
    pub mod scenes;
    pub mod stats;
}

use common::scenes::{furnace_camera, furnace_scene, furnace_truth, load_canonical};
use common::stats::{
    Estimate, assert_estimates_agree, assert_within_and_sharp, mean_and_standard_error,
};

use mlt::{Algorithm, Camera, RenderSettings, Scene, render};

#[allow(clippy::too_many_arguments)]
fn render_with(
    scene: &Scene,
    camera: &Camera,
    algorithm: Algorithm,
    size: u32,
    spp: u32,
    max_depth: u32,
    seed: u64,
    threads: u32,
) -> Vec<f32> {
    let settings = RenderSettings {
        width: size,
        height: size,
        algorithm,
        samples_per_pixel: spp,
        max_depth,
        seed,
        threads,
        ..Default::default()
    };
    let mut image = vec![0.0; (size * size * 3) as usize];
    let stats = render(scene, camera, &settings, &mut image, None).unwrap();
    assert_eq!(stats.invalid_samples, 0);
    image
}

fn estimate(
    scene: &Scene,
    camera: &Camera,
    algorithm: Algorithm,
    size: u32,
    spp: u32,
    seeds: std::ops::Range<u64>,
) -> Estimate {
    let renders: Vec<Vec<f32>> = seeds
        .map(|seed| render_with(scene, camera, algorithm, size, spp, 5, seed, 0))
        .collect();
    if algorithm == Algorithm::Bdpt {
        // Light-tracing splats correlate the pixels of one render: region variances come
        // from the spread between renders.
        Estimate::from_correlated_renders(size as usize, size as usize, &renders)
    } else {
        Estimate::from_renders(size as usize, size as usize, &renders)
    }
}

#[test]
fn bdpt_furnace_matches_the_geometric_series() {
    let albedo = [0.5, 0.7, 0.9];
    let emission = [1.0, 0.5, 2.0];
    let scene = furnace_scene(albedo, emission);
    for depth in [1, 4] {
        let image = render_with(
            &scene,
            &furnace_camera(),
            Algorithm::Bdpt,
            32,
            8,
            depth,
            5,
            0,
        );
        let (mean, error) = mean_and_standard_error(&image);
        let truth = furnace_truth(albedo, emission, depth);
        for c in 0..3 {
            // Splats make neighbouring pixels slightly correlated; 5 standard errors.
            let label = format!("depth {depth} channel {c}");
            assert_within_and_sharp(&label, mean[c], truth[c], error[c], 5.0);
        }
    }
}

#[test]
fn bdpt_agrees_with_the_path_tracer_on_the_cornell_box() {
    let (scene, camera) = load_canonical("cornell-box");
    let reference = estimate(&scene, &camera, Algorithm::Path, 64, 256, 1000..1004);
    let test = estimate(&scene, &camera, Algorithm::Bdpt, 64, 32, 0..16);
    // 16 renders: variances with 15 degrees of freedom (see `assert_estimates_agree`).
    assert_estimates_agree("cornell-box bdpt", &test, &reference, 4, 5.0, 6.0);
}

#[test]
fn bdpt_agrees_with_the_path_tracer_on_cornell_glass() {
    let (scene, camera) = load_canonical("cornell-glass");
    let reference = estimate(&scene, &camera, Algorithm::Path, 64, 256, 1000..1004);
    let test = estimate(&scene, &camera, Algorithm::Bdpt, 64, 32, 0..16);
    assert_estimates_agree("cornell-glass bdpt", &test, &reference, 4, 5.0, 6.0);
}

/// The door-ajar scene: the near room is lit only through the crack of a door. The path
/// tracer needs many samples here; the Metropolis tests use BDPT as their reference on it.
#[test]
fn bdpt_agrees_with_the_path_tracer_on_the_door_ajar_scene() {
    let (scene, camera) = load_canonical("door-ajar");
    let reference = estimate(&scene, &camera, Algorithm::Path, 64, 1024, 1000..1004);
    let test = estimate(&scene, &camera, Algorithm::Bdpt, 64, 32, 0..16);
    assert_estimates_agree("door-ajar bdpt", &test, &reference, 4, 5.0, 6.0);
}

#[test]
fn bdpt_image_is_identical_for_any_thread_count() {
    let (scene, camera) = load_canonical("cornell-glass");
    let bits = |threads| {
        render_with(&scene, &camera, Algorithm::Bdpt, 40, 3, 5, 9, threads)
            .iter()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    let one = bits(1);
    assert_eq!(one, bits(2));
    assert_eq!(one, bits(3));
}
