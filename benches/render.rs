//! Render throughput: camera samples per second and rays per second of the path tracer on
//! the canonical scenes at 1 and 2 threads (256×256, max depth 5), median of several runs.
//!
//! `cargo bench --bench render` (set MLT_BENCH_SPP / MLT_BENCH_RUNS to change the work).
//! Timings are reported, never asserted: the machines are shared and noisy.

mod common;

use common::{env_value, median};
use mlt::{RenderSettings, Scene, render};
use std::path::Path;

/// pbrt-v3 renders cornell-box at 256×256, 64 spp, max depth 5 in about 10 s on one thread
/// of these machines: about 420k camera samples per second.
const PBRT_V3_SAMPLES_PER_SECOND: f64 = 420_000.0;

fn main() {
    let spp = env_value("MLT_BENCH_SPP", 32u32);
    let runs = env_value("MLT_BENCH_RUNS", 5u32);
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
    println!(
        "{:<14} {:>7} {:>14} {:>10} {:>11} {:>12}",
        "scene", "threads", "samples/s", "Mrays/s", "rays/sample", "vs pbrt-v3"
    );
    for name in ["cornell-box", "cornell-glass"] {
        let data = mlt::io::load_scene(&scenes.join(format!("{name}.obj"))).expect("scene loads");
        let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).expect("scene builds");
        let camera = data.camera.expect("camera sidecar").camera;
        for threads in [1, 2] {
            let settings = RenderSettings {
                width: 256,
                height: 256,
                algorithm: mlt::Algorithm::Path,
                samples_per_pixel: spp,
                max_depth: 5,
                threads,
                ..Default::default()
            };
            let mut image = vec![0.0f32; 256 * 256 * 3];
            let mut samples_per_second = Vec::new();
            let mut rays_per_second = Vec::new();
            let mut rays_per_sample = 0.0;
            for run in 0..runs {
                let settings = RenderSettings {
                    seed: run as u64,
                    ..settings
                };
                let stats = render(&scene, &camera, &settings, &mut image, None).unwrap();
                samples_per_second.push(stats.samples as f64 / stats.seconds);
                rays_per_second.push(stats.rays as f64 / stats.seconds);
                rays_per_sample = stats.rays as f64 / stats.samples as f64;
            }
            let sps = median(&mut samples_per_second);
            let rps = median(&mut rays_per_second);
            let versus = if threads == 1 && name == "cornell-box" {
                format!("{:.2}x", sps / PBRT_V3_SAMPLES_PER_SECOND)
            } else {
                String::from("-")
            };
            println!(
                "{name:<14} {threads:>7} {sps:>14.0} {:>10.2} {rays_per_sample:>11.2} {versus:>12}",
                rps / 1e6
            );
        }
    }
}
