//! White furnace: inside a closed diffuse sphere of albedo a that emits Le everywhere, the
//! radiance along every ray is exactly Le·Σ_{k=0..d} aᵏ at max depth d. The tolerances come
//! from the estimator's own variance (4 standard errors of the image mean), and each test
//! also checks that a 2% brightness error would be outside them.
//!
//! Runs in under a second on 2 cores (`cargo test --test furnace`).

mod common {
    pub mod scenes;
    pub mod stats;
}

use common::scenes::{furnace_camera, furnace_scene, furnace_scene_of, furnace_truth};
use common::stats::{assert_within_and_sharp, mean_and_standard_error, rmse};

use mlt::{Algorithm, Camera, Material, RenderSettings, render};

const ALBEDO: [f32; 3] = [0.5, 0.7, 0.9];
const EMISSION: [f32; 3] = [1.0, 0.5, 2.0];

fn expected(depth: u32) -> [f64; 3] {
    furnace_truth(ALBEDO, EMISSION, depth)
}

fn render_furnace(depth: u32, spp: u32, seed: u64, size: u32) -> Vec<f32> {
    render_furnace_with(&furnace_camera(), depth, spp, seed, size)
}

fn render_furnace_with(camera: &Camera, depth: u32, spp: u32, seed: u64, size: u32) -> Vec<f32> {
    let scene = furnace_scene(ALBEDO, EMISSION);
    let settings = RenderSettings {
        width: size,
        height: size,
        algorithm: Algorithm::Path,
        samples_per_pixel: spp,
        max_depth: depth,
        seed,
        ..Default::default()
    };
    let mut image = vec![0.0; (size * size * 3) as usize];
    let stats = render(&scene, camera, &settings, &mut image, None).unwrap();
    assert_eq!(stats.samples, (size * size * spp) as u64);
    assert_eq!(stats.invalid_samples, 0);
    image
}

/// Russian roulette after the first bounce with at most 3 in 4 odds of going on
/// (`roulette_start_depth`, `roulette_max_survival`) still converges to the series: it
/// only trades time for noise. The default roulette renders another image.
#[test]
fn earlier_likelier_roulette_still_matches_the_geometric_series() {
    let scene = furnace_scene(ALBEDO, EMISSION);
    let depth = 5;
    let settings = RenderSettings {
        width: 64,
        height: 64,
        algorithm: Algorithm::Path,
        samples_per_pixel: 64,
        max_depth: depth,
        seed: 3,
        roulette_start_depth: 1,
        roulette_max_survival: 0.75,
        ..Default::default()
    };
    let mut image = vec![0.0; 64 * 64 * 3];
    render(&scene, &furnace_camera(), &settings, &mut image, None).unwrap();
    let (mean, error) = mean_and_standard_error(&image);
    let truth = expected(depth);
    for c in 0..3 {
        assert_within_and_sharp(&format!("channel {c}"), mean[c], truth[c], error[c], 4.0);
    }
    let mut default_roulette = vec![0.0; 64 * 64 * 3];
    let defaults = RenderSettings {
        roulette_start_depth: RenderSettings::default().roulette_start_depth,
        roulette_max_survival: RenderSettings::default().roulette_max_survival,
        ..settings
    };
    render(
        &scene,
        &furnace_camera(),
        &defaults,
        &mut default_roulette,
        None,
    )
    .unwrap();
    assert_ne!(image, default_roulette);
}

#[test]
fn depth_zero_sees_only_the_emission_exactly() {
    let image = render_furnace(0, 2, 1, 16);
    for pixel in image.chunks_exact(3) {
        assert_eq!(pixel, EMISSION);
    }
}

#[test]
fn furnace_matches_the_geometric_series() {
    for depth in [1, 2, 5, 12] {
        let image = render_furnace(depth, 16, 7 + depth as u64, 64);
        let (mean, error) = mean_and_standard_error(&image);
        let truth = expected(depth);
        for c in 0..3 {
            let label = format!("depth {depth} channel {c}");
            assert_within_and_sharp(&label, mean[c], truth[c], error[c], 4.0);
        }
    }
}

/// A furnace of rough white metal: with the multiple-scattering compensation every bounce
/// reflects all the light (up to the albedo table's error, a few tenths of a percent), so
/// the radiance at depth d is Le·(d + 1); glTF's single-scattering model alone reflects 31
/// to 88% depending on the angle at roughness 1 and falls far short (the companion check).
#[test]
fn compensated_rough_metal_furnace_reflects_everything() {
    let emission = [1.0; 3];
    let depth = 3;
    let mean_of = |energy_compensation: bool, seed: u64| {
        let material = Material {
            energy_compensation,
            ..Material::metallic_roughness([1.0; 3], 1.0, 1.0)
        };
        let scene = furnace_scene_of(material.with_emission(emission));
        let settings = RenderSettings {
            width: 64,
            height: 64,
            algorithm: Algorithm::Path,
            samples_per_pixel: 16,
            max_depth: depth,
            seed,
            ..Default::default()
        };
        let mut image = vec![0.0; 64 * 64 * 3];
        render(&scene, &furnace_camera(), &settings, &mut image, None).unwrap();
        mean_and_standard_error(&image)
    };
    let truth = furnace_truth([1.0; 3], emission, depth);
    let (mean, error) = mean_of(true, 21);
    for c in 0..3 {
        assert_within_and_sharp(&format!("channel {c}"), mean[c], truth[c], error[c], 4.0);
    }
    let (single, _) = mean_of(false, 21);
    println!(
        "rough white metal furnace, depth {depth}: {:.4} compensated, {:.4} single scattering, {:.4} exact",
        mean[0], single[0], truth[0]
    );
    assert!(single[0] < 0.8 * truth[0], "single scattering {single:?}");
}

#[test]
fn thin_lens_camera_sees_the_same_furnace() {
    // Every camera ray starts inside the sphere, so the lens must not change the radiance.
    let camera = Camera {
        lens_radius: 0.3,
        focus_distance: 0.7,
        ..furnace_camera()
    };
    let image = render_furnace_with(&camera, 2, 16, 11, 64);
    let (mean, error) = mean_and_standard_error(&image);
    let truth = expected(2);
    for c in 0..3 {
        assert!(
            (mean[c] - truth[c]).abs() <= 4.0 * error[c],
            "channel {c}: {} vs {}",
            mean[c],
            truth[c]
        );
    }
}

#[test]
fn error_falls_at_least_like_one_over_square_root_of_samples() {
    let truth = expected(5);
    let reference: Vec<f32> = (0..32 * 32).flat_map(|_| truth.map(|v| v as f32)).collect();
    let coarse = rmse(&render_furnace(5, 4, 100, 32), &reference);
    let fine = rmse(&render_furnace(5, 64, 200, 32), &reference);
    // 16× the samples: independent samples' error would shrink by √16 = 4 (the spread of an
    // RMSE over 3072 values is a few percent, so 3.4 is generous); the camera samples'
    // stratified (0, 2) points shrink it faster, at most by 16^1.5 = 64, the
    // best rate of randomized QMC on a smooth integrand. A biased estimator, whose
    // error stops shrinking, fails the lower bound.
    let ratio = coarse / fine;
    assert!(
        (3.4..=64.0).contains(&ratio),
        "ratio {ratio} ({coarse} / {fine})"
    );
}

#[test]
fn image_is_identical_for_any_thread_count() {
    let scene = furnace_scene(ALBEDO, EMISSION);
    let images: Vec<Vec<f32>> = [1, 2, 3]
        .iter()
        .map(|&threads| {
            let settings = RenderSettings {
                width: 48,
                height: 40,
                algorithm: Algorithm::Path,
                samples_per_pixel: 3,
                threads,
                seed: 42,
                ..Default::default()
            };
            let mut image = vec![0.0; 48 * 40 * 3];
            render(&scene, &furnace_camera(), &settings, &mut image, None).unwrap();
            image
        })
        .collect();
    let bits = |image: &[f32]| image.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&images[0]), bits(&images[1]));
    assert_eq!(bits(&images[0]), bits(&images[2]));
    // And the seed matters.
    let other = render_furnace(5, 3, 43, 16);
    assert_ne!(bits(&other), bits(&render_furnace(5, 3, 42, 16)));
}

/// With MIS every sample is bounded: at depth 1 a sample is the emission seen (Le), a light
/// sample (at most albedo·Le/2: f·Le·cosθ·p_light/(p_light² + p_bsdf²) peaks at
/// p_light = p_bsdf) and a BSDF-sampled emission hit (at most albedo·Le). Light sampling with
/// full weight would instead have the geometry term's 1/d² at the sphere's concave edges and
/// put fireflies of 20 times the mean in this image.
#[test]
fn mis_bounds_every_sample_near_concave_edges() {
    for seed in 0..4 {
        let image = render_furnace(1, 1, 100 + seed, 128);
        for (i, pixel) in image.chunks_exact(3).enumerate() {
            for c in 0..3 {
                let bound = EMISSION[c] * (1.0 + 1.5 * ALBEDO[c]) * 1.0001;
                assert!(
                    pixel[c] <= bound,
                    "seed {seed} pixel {i} channel {c}: {} > {bound}",
                    pixel[c]
                );
            }
        }
    }
}
