//! Brightness over seeds: how far each render's image mean lands from a converged
//! reference's, render after render. A Metropolis image is as bright as its normalization b
//! says, so this measures b's error and its distribution (heavy tails show as a few seeds far
//! out), next to the RMSE of the same renders.
//!
//! `cargo bench --bench brightness` renders, for each scene, algorithm and value of
//! `normalization_work_fraction`, one render per seed with the default settings (256²,
//! max depth 5; spectral mode for a scene whose materials disperse, as in the equal-time
//! bench) and a fixed budget, and prints per render the image mean's difference to the
//! reference (luminance and R/G/B, in percent), the normalization b with its reported
//! relative standard error, the samples it came from and the largest share one sample
//! carried, and the RMSE (corrected for the reference's own noise); then per case the RMS
//! and the largest of the luminance differences, the median reported error and the median
//! RMSE. The reference is the equal-time bench's (BDPT, cached in `target/mlt-bench/`).
//!
//! Environment:
//! - `MLT_BENCH_SCENES`: scenes of tests/scenes (default `door-ajar,lamp-behind-glass`).
//! - `MLT_BENCH_ALGORITHMS`: of `path, bdpt, pssmlt, pssmlt-bdpt, mmlt, path-space-mlt, erpt`
//!   (default the four Metropolis variants).
//! - `MLT_BENCH_NORMALIZATION`: values of `normalization_work_fraction` to compare
//!   (default 0 and the default fraction).
//! - `MLT_BENCH_BOOTSTRAP`: values of `bootstrap_samples` to compare (default the default).
//! - `MLT_BENCH_SEEDS`: renders per case (default 8; seeds 1, 2, …).
//! - `MLT_BENCH_SECONDS`: the time limit of each render (default 30), or
//! - `MLT_BENCH_MUTATIONS`: mutations per pixel (camera samples for path, BDPT and ERPT)
//!   instead of a time limit (default 0: use the time limit).
//! - `MLT_BENCH_THREADS`: threads per render (default 1).
//! - `MLT_BENCH_JOBS`: renders run side by side (default 1). Side-by-side renders share the
//!   machine, so each does a little less work in its time than alone.
//! - `MLT_BENCH_REFERENCE_SPP`: the reference's samples per pixel (default 2048).
//!
//! The issue-15 table: `MLT_BENCH_NORMALIZATION=0.05 cargo bench --bench brightness`
//! (door-ajar and lamp-behind-glass, 8 seeds of 30 s on one thread).

mod common;

use common::reference::{
    DEFAULT_REFERENCE_SPP, HEIGHT, MAX_DEPTH, WIDTH, channel_means, load_scene, luminance,
    reference, rmse,
};
use common::{env_names, env_value, median, output_dir};
use mlt::{Algorithm, RenderSettings, RenderStats, render};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

const ALGORITHMS: &[(&str, Algorithm)] = &[
    ("path", Algorithm::Path),
    ("bdpt", Algorithm::Bdpt),
    ("pssmlt", Algorithm::Pssmlt),
    ("pssmlt-bdpt", Algorithm::PssmltBdpt),
    ("mmlt", Algorithm::Mmlt),
    ("path-space-mlt", Algorithm::PathSpaceMlt),
    ("erpt", Algorithm::Erpt),
];

struct Measured {
    seed: u64,
    stats: RenderStats,
    /// Image mean over the reference's, minus 1: luminance, then R, G, B.
    luminance_error: f64,
    channel_errors: [f64; 3],
    corrected_rmse: f64,
}

fn main() {
    let scenes = env_names("MLT_BENCH_SCENES", &["door-ajar", "lamp-behind-glass"]);
    let algorithms: Vec<(&str, Algorithm)> = env_names(
        "MLT_BENCH_ALGORITHMS",
        &["pssmlt", "pssmlt-bdpt", "mmlt", "path-space-mlt"],
    )
    .iter()
    .map(|wanted| {
        *ALGORITHMS
            .iter()
            .find(|(name, _)| name == wanted)
            .unwrap_or_else(|| panic!("MLT_BENCH_ALGORITHMS: unknown {wanted:?}"))
    })
    .collect();
    let default_fraction = RenderSettings::DEFAULT_NORMALIZATION_WORK_FRACTION.to_string();
    let ratios: Vec<f32> = env_names("MLT_BENCH_NORMALIZATION", &["0", &default_fraction])
        .iter()
        .map(|r| r.parse().expect("MLT_BENCH_NORMALIZATION: numbers"))
        .collect();
    let default_bootstrap = RenderSettings::default().bootstrap_samples.to_string();
    let bootstraps: Vec<u32> = env_names("MLT_BENCH_BOOTSTRAP", &[&default_bootstrap])
        .iter()
        .map(|n| n.parse().expect("MLT_BENCH_BOOTSTRAP: numbers"))
        .collect();
    let seeds: u64 = env_value("MLT_BENCH_SEEDS", 8);
    let seconds: f64 = env_value("MLT_BENCH_SECONDS", 30.0);
    let mutations: u32 = env_value("MLT_BENCH_MUTATIONS", 0);
    let threads: u32 = env_value("MLT_BENCH_THREADS", 1);
    let jobs: usize = env_value("MLT_BENCH_JOBS", 1);
    let reference_spp = env_value("MLT_BENCH_REFERENCE_SPP", DEFAULT_REFERENCE_SPP);
    let dir = output_dir();
    std::fs::create_dir_all(&dir).expect("output directory");
    let budget = if mutations > 0 {
        format!("{mutations} mutations (or samples) per pixel")
    } else {
        format!("{seconds} s")
    };
    println!(
        "brightness: {WIDTH}x{HEIGHT}, max depth {MAX_DEPTH}, {seeds} seeds of {budget} on {threads} thread(s), {jobs} at a time"
    );

    for name in &scenes {
        let bench = load_scene(name);
        let (scene, camera) = (&bench.scene, &bench.camera);
        let reference = reference(&bench, reference_spp, &dir);
        let reference_means = channel_means(&reference.image);
        let reference_luminance = luminance(reference_means);
        println!(
            "\n{name} ({}): reference BDPT {} spp, mean luminance {reference_luminance:.5}, RMSE ≈ {:.5}",
            bench.mode(),
            reference.spp,
            reference.rmse
        );
        println!(
            "{:<15} {:>6} {:>8} {:>5} {:>8}  {:>22} {:>9} {:>8} {:>10} {:>8} {:>10} {:>8}",
            "algorithm",
            "fraction",
            "boot",
            "seed",
            "mean %",
            "R/G/B %",
            "b",
            "b err %",
            "samples",
            "top %",
            "mutations",
            "RMSE"
        );
        for &(algorithm_name, algorithm) in &algorithms {
            let metropolis = algorithm.is_metropolis();
            let ratios: &[f32] = if metropolis { &ratios } else { &[0.0] };
            let cases: Vec<(f32, u32)> = ratios
                .iter()
                .flat_map(|&r| bootstraps.iter().map(move |&b| (r, b)))
                .collect();
            for (ratio, bootstrap) in cases {
                let next = AtomicUsize::new(0);
                let results = Mutex::new(Vec::new());
                std::thread::scope(|s| {
                    for _ in 0..jobs.max(1) {
                        s.spawn(|| {
                            loop {
                                let i = next.fetch_add(1, Ordering::Relaxed) as u64;
                                if i >= seeds {
                                    break;
                                }
                                let seed = i + 1;
                                let mut settings = RenderSettings {
                                    algorithm,
                                    threads,
                                    seed,
                                    time_limit_seconds: if mutations > 0 { 0.0 } else { seconds },
                                    samples_per_pixel: mutations,
                                    mutations_per_pixel: mutations,
                                    normalization_work_fraction: ratio,
                                    bootstrap_samples: bootstrap,
                                    ..bench.settings()
                                };
                                // A small fixed bootstrap caps the chains it seeds.
                                settings.chains =
                                    settings.chains.min(settings.resolved_bootstrap_samples());
                                let mut image = vec![0.0f32; (WIDTH * HEIGHT * 3) as usize];
                                let stats = render(scene, camera, &settings, &mut image, None)
                                    .unwrap_or_else(|e| panic!("{algorithm_name}: {e}"));
                                let means = channel_means(&image);
                                let raw = rmse(&image, &reference.image);
                                let measured = Measured {
                                    seed,
                                    stats,
                                    luminance_error: luminance(means) / reference_luminance - 1.0,
                                    channel_errors: std::array::from_fn(|c| {
                                        means[c] / reference_means[c] - 1.0
                                    }),
                                    corrected_rmse: (raw * raw - reference.rmse * reference.rmse)
                                        .max(0.0)
                                        .sqrt(),
                                };
                                results.lock().unwrap().push(measured);
                            }
                        });
                    }
                });
                let mut results = results.into_inner().unwrap();
                results.sort_by_key(|m| m.seed);
                for m in &results {
                    let b = m.stats.normalization;
                    let [r, g, bl] = m.channel_errors.map(|e| 100.0 * e);
                    println!(
                        "{:<15} {:>6} {:>8} {:>5} {:>+8.2}  {:>+6.2}/{:>+6.2}/{:>+6.2} {:>9.5} {:>8.2} {:>10} {:>8.3} {:>10} {:>8.5}",
                        algorithm_name,
                        ratio,
                        bootstrap,
                        m.seed,
                        100.0 * m.luminance_error,
                        r,
                        g,
                        bl,
                        b.value,
                        100.0 * b.relative_error,
                        b.samples,
                        100.0 * b.largest_share,
                        m.stats.mutations.max(m.stats.samples),
                        m.corrected_rmse
                    );
                }
                let errors: Vec<f64> = results.iter().map(|m| m.luminance_error).collect();
                let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
                let largest = errors.iter().fold(0.0f64, |a, e| a.max(e.abs()));
                let mut reported: Vec<f64> = results
                    .iter()
                    .map(|m| m.stats.normalization.relative_error)
                    .collect();
                let mut rmses: Vec<f64> = results.iter().map(|m| m.corrected_rmse).collect();
                println!(
                    "{:<15} {:>6} {:>8}   all: RMS {:.2}%, largest {:.2}% of the mean; median reported b error {:.2}%; median RMSE {:.5}",
                    algorithm_name,
                    ratio,
                    bootstrap,
                    100.0 * rms,
                    100.0 * largest,
                    100.0 * median(&mut reported),
                    median(&mut rmses)
                );
            }
        }
    }
}
