//! The path tracer on the Cornell box: its error falls like 1/√spp. Whether it converges to
//! the right image is checked against independent estimates elsewhere, not against itself:
//! analytic ground truth in `tests/furnace.rs` and `tests/area_light.rs`, and BDPT, a
//! different estimator, on both Cornell scenes (the box and the glass one, whose caustics
//! are reached only through specular chains) in `tests/bdpt.rs`.
//!
//! Runs in about 2 s on 2 cores (`cargo test --test cornell`).

mod common {
    pub mod references;
    pub mod scenes;
    pub mod stats;
}

use common::references::{path_traced_estimate, path_traced_image};
use common::scenes::load_canonical;
use common::stats::rmse;

const SIZE: u32 = 64;

#[test]
fn cornell_error_falls_like_one_over_square_root_of_samples() {
    let (scene, camera) = load_canonical("cornell-box");
    let reference = path_traced_estimate(&scene, &camera, SIZE, 256, 2000..2004).image;
    // Mean squared error over four renders: pixels on the light's edge make a single
    // render's error heavy-tailed at low sample counts.
    let rms_error = |spp: u32, seeds: std::ops::Range<u64>| {
        let renders = (seeds.end - seeds.start) as f64;
        let mse: f64 = seeds
            .map(|seed| {
                rmse(
                    &path_traced_image(&scene, &camera, SIZE, spp, seed),
                    &reference,
                )
                .powi(2)
            })
            .sum::<f64>()
            / renders;
        mse.sqrt()
    };
    let coarse = rms_error(16, 0..4);
    let fine = rms_error(256, 10..14);
    // 16× the samples shrink the error 4× where the integrand is many-dimensional (the
    // shading); the pixels on the light's edge, where the stratified positions within the
    // pixel do the work, converge like N^(-3/4), up to 8×. The reference's own noise (1024
    // spp) pulls the ratio down a little. A biased estimator's error stops shrinking (ratio
    // near 1), a 1/N^¼ rate gives 2, and renders correlated with the reference would make
    // the fine error vanish (a ratio far above 8).
    let ratio = coarse / fine;
    assert!(
        (3.0..=8.5).contains(&ratio),
        "ratio {ratio} ({coarse} / {fine})"
    );
}
