//! Energy redistribution path tracing against ground truth and the path tracer: the white
//! furnace, the Cornell scenes (image mean and 4 × 4 region means within combined standard
//! errors estimated from independent renders, whose pixels are correlated by the chains; a
//! 2% bias resolvable), identical images for any thread count, and the chain settings
//! mattering (a render whose chains moved is not the initial samples' image).
//!
//! Runs in about 35 s on 2 cores (`cargo test --test erpt`).

mod common {
    pub mod door_ajar_reference;
    pub mod references;
    pub mod scenes;
    pub mod stats;
}

use common::door_ajar_reference;
use common::references::{open_reference, path_reference, path_traced_image, render_image};
use common::scenes::{
    OPEN_MAX_DEPTH, OPEN_SIZE, OpenLights, furnace_camera, furnace_scene, furnace_truth,
    load_canonical, open_scene,
};
use common::stats::{
    Estimate, RegionEstimate, assert_estimates_agree, assert_within_and_sharp, mean,
};

use mlt::{Algorithm, Camera, RenderSettings, Scene, StopReason, render};
use std::time::{Duration, Instant};

fn erpt_settings(size: u32, samples_per_pixel: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        algorithm: Algorithm::Erpt,
        samples_per_pixel,
        max_depth: 5,
        seed,
        ..Default::default()
    }
}

fn erpt_estimate(
    scene: &Scene,
    camera: &Camera,
    samples_per_pixel: u32,
    perturb_in_sample_space: bool,
) -> Estimate {
    let renders: Vec<Vec<f32>> = (0..16)
        .map(|seed| {
            let settings = RenderSettings {
                perturb_in_sample_space,
                ..erpt_settings(64, samples_per_pixel, seed)
            };
            render_image(scene, camera, &settings)
        })
        .collect();
    Estimate::from_correlated_renders(64, 64, &renders)
}

#[test]
fn furnace_matches_the_geometric_series() {
    let albedo = [0.5, 0.7, 0.9];
    let emission = [1.0, 0.5, 2.0];
    let scene = furnace_scene(albedo, emission);
    let renders: Vec<Vec<f32>> = (0..16)
        .map(|seed| {
            let settings = RenderSettings {
                max_depth: 3,
                ..erpt_settings(32, 32, seed)
            };
            render_image(&scene, &furnace_camera(), &settings)
        })
        .collect();
    let estimate = Estimate::from_correlated_renders(32, 32, &renders);
    let (mean, variance) = estimate.mean();
    let truth = furnace_truth(albedo, emission, 3);
    for c in 0..3 {
        eprintln!(
            "furnace channel {c}: {} vs {} ({:.2} standard errors)",
            mean[c],
            truth[c],
            (mean[c] - truth[c]) / variance[c].sqrt()
        );
        // 16 renders: a variance with 15 degrees of freedom; P(|t| > 6) = 2·10⁻⁵.
        assert_within_and_sharp(
            &format!("channel {c}"),
            mean[c],
            truth[c],
            variance[c].sqrt(),
            6.0,
        );
    }
}

fn agrees_with_the_path_tracer(
    scene_name: &str,
    samples_per_pixel: u32,
    perturb_in_sample_space: bool,
) {
    let (scene, camera) = load_canonical(scene_name);
    let reference = path_reference(scene_name);
    let test = erpt_estimate(&scene, &camera, samples_per_pixel, perturb_in_sample_space);
    let (tm, tv) = test.mean();
    let (rm, rv) = reference.mean();
    for c in 0..3 {
        let se = (tv[c] + rv[c]).sqrt();
        eprintln!(
            "{scene_name} channel {c}: ERPT {} path {} (difference {:.2} standard errors; standard error {:.3}% of the mean)",
            tm[c],
            rm[c],
            (tm[c] - rm[c]) / se,
            100.0 * se / rm[c]
        );
    }
    // 16 renders a side: region variances have 15 degrees of freedom (see
    // `assert_estimates_agree`); 51 comparisons.
    assert_estimates_agree(&format!("{scene_name} ERPT"), &test, reference, 4, 5.0, 6.0);
}

#[test]
fn cornell_box_agrees_with_the_path_tracer() {
    agrees_with_the_path_tracer("cornell-box", 8, false);
}

#[test]
fn cornell_glass_agrees_with_the_path_tracer() {
    agrees_with_the_path_tracer("cornell-glass", 8, false);
}

/// With the perturbations stepping in the BSDF's sample space (the caustic and multi-chain
/// perturbations carry the light through the glass here).
#[test]
fn cornell_glass_in_sample_space_agrees_with_the_path_tracer() {
    agrees_with_the_path_tracer("cornell-glass", 8, true);
}

/// The door-ajar scene (tests/common/door_ajar.rs), lit only through the crack of a door,
/// against BDPT's cached estimate (tests/common/door_ajar_reference.rs; `tests/bdpt.rs`
/// checks BDPT against the path tracer there).
#[test]
fn door_ajar_agrees_with_bdpt() {
    let (scene, camera) = load_canonical("door-ajar");
    let reference = &door_ajar_reference::BDPT;
    let test = erpt_estimate(&scene, &camera, DOOR_AJAR_SAMPLES, false);
    let (tm, tv) = test.mean();
    let (rm, rv) = reference.image_mean();
    for c in 0..3 {
        let se = (tv[c] + rv[c]).sqrt();
        eprintln!(
            "door-ajar channel {c}: ERPT {} BDPT {} (difference {:.2} standard errors; standard error {:.3}% of the mean)",
            tm[c],
            rm[c],
            (tm[c] - rm[c]) / se,
            100.0 * se / rm[c]
        );
    }
    assert_estimates_agree("door-ajar ERPT", &test, reference, 4, 5.0, 6.0);
}

const DOOR_AJAR_SAMPLES: u32 = 24;

#[test]
fn image_is_identical_for_any_thread_count() {
    let (scene, camera) = load_canonical("cornell-glass");
    let bits = |threads| {
        let settings = RenderSettings {
            threads,
            ..erpt_settings(24, 3, 5)
        };
        let image = render_image(&scene, &camera, &settings);
        image.iter().map(|v| v.to_bits()).collect::<Vec<u32>>()
    };
    let one = bits(1);
    assert!(one.iter().any(|&b| f32::from_bits(b) > 0.0));
    assert_eq!(one, bits(2), "2 threads");
    assert_eq!(one, bits(3), "3 threads");
}

/// The chains move energy: with chains, an image differs from one whose deposit energy is
/// so large that no chain starts (all energy lost), and the statistics count mutations.
#[test]
fn chains_run_and_a_huge_deposit_energy_starts_none() {
    let (scene, camera) = load_canonical("cornell-box");
    let settings = erpt_settings(16, 2, 1);
    let mut image = vec![0.0; 16 * 16 * 3];
    let stats = render(&scene, &camera, &settings, &mut image, None).unwrap();
    assert!(stats.mutations > 0 && stats.accepted_mutations > 0);
    assert!(
        stats.normalization.value > 0.0,
        "the automatic e_d is reported"
    );
    let none = RenderSettings {
        erpt_deposit_energy: 1e30,
        ..settings
    };
    let stats = render(&scene, &camera, &none, &mut image, None).unwrap();
    assert_eq!(stats.mutations, 0);
    assert!(image.iter().all(|&v| v == 0.0));
    // Through glass every perturbation applies somewhere; the bidirectional mutation never
    // runs, and the counts add up. (8 samples per pixel: chains on caustic paths start from
    // the few camera samples that find the lamp through the sphere.)
    let (scene, camera) = load_canonical("cornell-glass");
    let settings = erpt_settings(16, 8, 1);
    let stats = render(&scene, &camera, &settings, &mut image, None).unwrap();
    let counts = stats.mutation_counts;
    assert_eq!(counts.proposed[0], 0);
    assert!(counts.proposed[1..].iter().all(|&n| n > 0), "{counts:?}");
    assert_eq!(counts.proposed.iter().sum::<u64>(), stats.mutations);
    assert_eq!(
        counts.accepted.iter().sum::<u64>(),
        stats.accepted_mutations
    );
}

/// A time limit and a cancel both stop a render soon, with an image still near the path
/// tracer's mean (chains cut short leave their energy at their current state), and progress
/// goes up to 1 for a finished render.
#[test]
fn time_limit_cancel_and_progress() {
    let (scene, camera) = load_canonical("cornell-box");
    let reference = mean(&path_traced_image(&scene, &camera, 64, 64, 9));
    let near = |image: &[f32], label: &str| {
        let got = mean(image);
        for c in 0..3 {
            assert!(
                (got[c] - reference[c]).abs() < 0.1 * reference[c],
                "{label} channel {c}: {} vs {}",
                got[c],
                reference[c]
            );
        }
    };
    let mut image = vec![0.0; 64 * 64 * 3];
    // Its own two workers: on the process-wide pool it would queue behind the renders of
    // the tests running beside it, and its half second could pass before a pixel pass.
    let timed = RenderSettings {
        time_limit_seconds: 0.5,
        threads: 2,
        ..erpt_settings(64, 0, 2)
    };
    let start = Instant::now();
    let stats = render(&scene, &camera, &timed, &mut image, None).unwrap();
    assert!(start.elapsed() < Duration::from_secs(5));
    assert_eq!(stats.stop, StopReason::TimeLimitReached);
    assert!(stats.samples >= 64 * 64 && stats.mutations > 0);
    near(&image, "time limit");

    let mut calls = 0;
    let mut cancel_soon = |_: f32| {
        calls += 1;
        calls < 3
    };
    let long = erpt_settings(64, 1 << 20, 3);
    let stats = render(&scene, &camera, &long, &mut image, Some(&mut cancel_soon)).unwrap();
    assert_eq!(stats.stop, StopReason::Cancelled);
    assert!(stats.samples < (1u64 << 20) * 64 * 64);
    near(&image, "cancelled");

    let mut last = 0.0;
    let mut record = |fraction: f32| {
        assert!(fraction >= last && fraction <= 1.0);
        last = fraction;
        true
    };
    let stats = render(
        &scene,
        &camera,
        &erpt_settings(32, 4, 4),
        &mut image[..32 * 32 * 3],
        Some(&mut record),
    )
    .unwrap();
    assert_eq!(stats.stop, StopReason::Completed);
    assert_eq!(stats.samples, 4 * 32 * 32);
    assert_eq!(last, 1.0);
}

/// ERPT (lens, caustic and multi-chain perturbations) on the open box lit by `lights`,
/// against the path tracer: image mean and 4 × 4 region means within combined standard
/// errors of 16 renders, a 2% bias resolvable.
fn agrees_with_the_path_tracer_in_the_open(lights: OpenLights) {
    let (scene, camera) = open_scene(lights);
    let reference = open_reference(lights);
    let renders: Vec<Vec<f32>> = (0..16)
        .map(|seed| {
            let settings = RenderSettings {
                max_depth: OPEN_MAX_DEPTH,
                perturb_in_sample_space: seed % 2 == 1,
                ..erpt_settings(OPEN_SIZE, 64, seed)
            };
            render_image(&scene, &camera, &settings)
        })
        .collect();
    let test = Estimate::from_correlated_renders(OPEN_SIZE as usize, OPEN_SIZE as usize, &renders);
    let (tm, tv) = test.mean();
    let (rm, rv) = reference.mean();
    for c in 0..3 {
        eprintln!(
            "{lights:?} channel {c}: ERPT {} path {} ({:+.2} standard errors of {:.3}%)",
            tm[c],
            rm[c],
            (tm[c] - rm[c]) / (tv[c] + rv[c]).sqrt(),
            100.0 * (tv[c] + rv[c]).sqrt() / rm[c]
        );
    }
    assert_estimates_agree(
        &format!("open {lights:?} ERPT"),
        &test,
        reference,
        4,
        5.0,
        6.0,
    );
}

#[test]
fn agrees_with_the_path_tracer_under_sky_and_sun() {
    agrees_with_the_path_tracer_in_the_open(OpenLights::SkyAndSun);
}

#[test]
fn agrees_with_the_path_tracer_under_spot_and_directional_lights() {
    agrees_with_the_path_tracer_in_the_open(OpenLights::SpotAndDirectional);
}
