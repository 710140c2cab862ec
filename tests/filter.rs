//! The post-process filter on real renders: it only acts on the image (the unfiltered image
//! of a filtered render is the render without the filter, bit for bit, on any thread count);
//! it keeps the image's total; and on the Cornell box with a glass ball it lowers the RMSE of
//! path-space MLT and ERPT against a path-traced reference, while moving no 4 × 4 region's
//! mean by more than a stated bound (its bias: the mean over seeds of filtered − unfiltered,
//! which needs no reference, since the unfiltered image is unbiased).
//!
//! Runs in about 9 s on 2 cores (`cargo test --test filter`).

mod common {
    pub mod references;
    pub mod scenes;
    pub mod stats;
}

use common::references::path_traced_image;
use common::scenes::load_canonical;
use common::stats::{luminance, mean, region_means, rmse};

use mlt::{Algorithm, Camera, RenderSettings, Scene, render, render_with_unfiltered};

fn both(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> (Vec<f32>, Vec<f32>) {
    let n = (settings.width * settings.height * 3) as usize;
    let (mut filtered, mut unfiltered) = (vec![0.0; n], vec![0.0; n]);
    let stats = render_with_unfiltered(
        scene,
        camera,
        settings,
        &mut filtered,
        &mut unfiltered,
        None,
    )
    .unwrap();
    assert!(stats.filter.mean_neighbours >= 1.0, "{:?}", stats.filter);
    (filtered, unfiltered)
}

fn settings(algorithm: Algorithm, size: u32, budget: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        algorithm,
        samples_per_pixel: budget,
        mutations_per_pixel: budget,
        bootstrap_samples: 1 << 16,
        chains: 256,
        seed,
        filter_buffers: RenderSettings::DEFAULT_FILTER_BUFFERS,
        ..Default::default()
    }
}

#[test]
fn the_unfiltered_image_is_the_render_without_the_filter() {
    let (scene, camera) = load_canonical("cornell-glass");
    for algorithm in [
        Algorithm::Pssmlt,
        Algorithm::Mmlt,
        Algorithm::PathSpaceMlt,
        Algorithm::Erpt,
    ] {
        let filtered_settings = RenderSettings {
            chains: 64,
            bootstrap_samples: 1 << 12,
            ..settings(algorithm, 32, 4, 3)
        };
        let plain_settings = RenderSettings {
            filter_buffers: 0,
            ..filtered_settings
        };
        let mut plain = vec![0.0; 32 * 32 * 3];
        render(&scene, &camera, &plain_settings, &mut plain, None).unwrap();
        let (filtered, unfiltered) = both(&scene, &camera, &filtered_settings);
        assert!(
            unfiltered == plain,
            "{algorithm:?}: the filter changed the render"
        );
        assert!(
            filtered != unfiltered,
            "{algorithm:?}: the filter did nothing"
        );
        // The total is kept (up to the f32 output).
        let (a, b) = (mean(&filtered), mean(&unfiltered));
        for c in 0..3 {
            assert!(
                (a[c] / b[c] - 1.0).abs() < 1e-5,
                "{algorithm:?}: {a:?} vs {b:?}"
            );
        }
        // Any thread count gives the same filtered image.
        let (one_thread, _) = both(
            &scene,
            &camera,
            &RenderSettings {
                threads: 1,
                ..filtered_settings
            },
        );
        assert!(
            one_thread == filtered,
            "{algorithm:?}: threads changed the image"
        );
    }
}

#[test]
fn lowers_the_error_of_path_space_mlt_and_erpt_with_a_bounded_bias() {
    let size = 64;
    let (scene, camera) = load_canonical("cornell-glass");
    let reference = path_traced_image(&scene, &camera, size, 4096, 99);
    let reference_regions = region_means(&reference, 64, 64, 4);
    // Measured: RMSE ratios 0.742 and 0.742; the largest region shifts 3.0% and 2.5%.
    for (algorithm, budget, max_ratio, max_shift) in [
        (Algorithm::PathSpaceMlt, 64, 0.82, 0.05),
        (Algorithm::Erpt, 16, 0.82, 0.04),
    ] {
        let seeds = 6;
        let (mut filtered_se, mut unfiltered_se) = (0.0, 0.0);
        let mut shifts = [0.0f64; 16];
        for seed in 0..seeds {
            let (filtered, unfiltered) =
                both(&scene, &camera, &settings(algorithm, size, budget, seed));
            filtered_se += rmse(&filtered, &reference).powi(2);
            unfiltered_se += rmse(&unfiltered, &reference).powi(2);
            let (f, u) = (
                region_means(&filtered, 64, 64, 4),
                region_means(&unfiltered, 64, 64, 4),
            );
            for r in 0..16 {
                shifts[r] += (luminance(f[r]) - luminance(u[r]))
                    / luminance(reference_regions[r])
                    / seeds as f64;
            }
        }
        let ratio = (filtered_se / unfiltered_se).sqrt();
        let largest = shifts.iter().fold(0.0f64, |m, s| m.max(s.abs()));
        println!("{algorithm:?}: RMSE ratio {ratio:.3}, largest region shift {largest:.3}");
        assert!(ratio < max_ratio, "{algorithm:?}: RMSE ratio {ratio}");
        assert!(
            largest < max_shift,
            "{algorithm:?}: region shifts {shifts:?}"
        );
    }
}
