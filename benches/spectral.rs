//! The cost of spectral transport: each spectral algorithm renders the canonical scenes in
//! RGB and in spectral mode with the same work (128×128, max depth 5, one thread), and the
//! table gives the medians of the seconds and their ratio, with the rays traced (spectral
//! mode changes the random numbers, not the number of rays on average). `prism` is the
//! dispersive scene (tests/scenes/prism.obj): there a path that enters the glass goes on at
//! one wavelength, so its images are noisier, not slower.
//!
//! `cargo bench --bench spectral`. Environment: `MLT_BENCH_RUNS` (default 3) renders per
//! configuration; `MLT_BENCH_WORK` (default 16) samples or mutations per pixel;
//! `MLT_BENCH_SCENES` (default `cornell-box,cornell-glass,prism`). Timings are reported,
//! never asserted.

mod common;

use common::{env_names, env_value, median};
use mlt::{Algorithm, RenderSettings, Scene, render};
use std::path::Path;

const ALGORITHMS: [(&str, Algorithm); 7] = [
    ("path", Algorithm::Path),
    ("bdpt", Algorithm::Bdpt),
    ("pssmlt", Algorithm::Pssmlt),
    ("mmlt", Algorithm::Mmlt),
    ("pssmlt-bdpt", Algorithm::PssmltBdpt),
    ("path-space-mlt", Algorithm::PathSpaceMlt),
    ("erpt", Algorithm::Erpt),
];

fn main() {
    let runs = env_value("MLT_BENCH_RUNS", 3u32);
    let work = env_value("MLT_BENCH_WORK", 16u32);
    let scenes_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
    let scenes = env_names(
        "MLT_BENCH_SCENES",
        &["cornell-box", "cornell-glass", "prism"],
    );
    println!(
        "{:<14} {:<15} {:>9} {:>11} {:>7} {:>12} {:>12}",
        "scene", "algorithm", "RGB s", "spectral s", "ratio", "RGB Mrays", "spec. Mrays"
    );
    for name in &scenes {
        let data = mlt::io::load_scene(&scenes_dir.join(format!("{name}.obj"))).expect("loads");
        let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).expect("builds");
        let camera = data.camera.expect("camera sidecar").camera;
        for (label, algorithm) in ALGORITHMS {
            let measure = |spectral: bool| {
                let mut seconds = Vec::new();
                let mut rays = Vec::new();
                for run in 0..runs {
                    let settings = RenderSettings {
                        width: 128,
                        height: 128,
                        algorithm,
                        samples_per_pixel: work,
                        mutations_per_pixel: work,
                        max_depth: 5,
                        threads: 1,
                        seed: run as u64,
                        spectral,
                        ..Default::default()
                    };
                    let mut image = vec![0.0f32; 128 * 128 * 3];
                    let stats = render(&scene, &camera, &settings, &mut image, None).unwrap();
                    seconds.push(stats.seconds);
                    rays.push(stats.rays as f64);
                }
                (median(&mut seconds), median(&mut rays))
            };
            let (rgb_seconds, rgb_rays) = measure(false);
            let (spectral_seconds, spectral_rays) = measure(true);
            println!(
                "{name:<14} {label:<15} {rgb_seconds:>9.3} {spectral_seconds:>11.3} {:>7.2} {:>12.2} {:>12.2}",
                spectral_seconds / rgb_seconds,
                rgb_rays / 1e6,
                spectral_rays / 1e6
            );
        }
    }
}
