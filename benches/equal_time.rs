//! Equal-time quality: how close each algorithm gets to a converged reference in the same
//! wall-clock time, on the canonical scenes at 256×256, max depth 5, default settings:
//! cornell-box, cornell-glass (caustics through a glass sphere), door-ajar (a room lit
//! through the crack of a door), lamp-behind-glass (a room lit only through the glass
//! cover of a recessed lamp), window-room (a room lit only by the sky and the sun
//! through a small window: an environment map and a sun disc), cornell-glossy (a rough
//! metal floor and a rough gold block: glossy interreflection) and prism (a lamp behind a slit
//! and a flint prism of Abbe number 20 spreading a spectrum on the floor: a dispersive
//! caustic, tests/scenes/prism.obj from tools/prism_scene.py).
//!
//! Spectral scenes: a scene whose materials disperse (an Abbe number above 0: prism) renders
//! in spectral mode (`RenderSettings::spectral`), its reference and every compared render
//! alike (`BenchScene::settings` in benches/common/reference.rs decides both); the others in
//! RGB. An algorithm that refuses a scene's mode or materials (`MLT_STATUS_UNSUPPORTED`, e.g.
//! path-space MLT and ERPT while they have no spectral mode) gets one row saying so and is
//! skipped on that scene.
//!
//! `cargo bench --bench equal_time` prints a table (scene, algorithm, threads, time budget,
//! actual seconds, camera samples and chain mutations per second, the share of mutations
//! accepted, RMSE, RMSE corrected for the reference's own noise, and the per-channel mean
//! brightness difference to the reference; for the Metropolis algorithms also the luminance
//! difference and b's reported error) and writes a
//! log-log plot of RMSE against seconds, one line per algorithm and one panel per scene, to
//! `target/mlt-bench/convergence.png`. Numbers are reported, never asserted.
//!
//! Each algorithm renders with one thread for a series of time budgets (1, 2, 5, 10 s by
//! default: the 1-2-5 series from a tenth of the longest budget up to it), then once with two
//! threads at the longest budget (in the table, not the plot). The table notes renders that
//! overran their budget or finished no sample at all (a black image, left out of the plot).
//! With `MLT_BENCH_REPEATS` = R > 1 the longest budget is rendered R times on each thread
//! count (seeds differ), and a second table gives the medians over those renders: a single
//! render's RMSE is too noisy to rank options that differ by 10–20%.
//!
//! The `-filtered` algorithms run the post-process filter (`mlt::filter`, default settings,
//! 8 partial images). Their rows give the RMSE of the filtered image, the RMSE of the same
//! render unfiltered, and the filter's bias: the largest shift of a 4 × 4 region's mean
//! luminance between the two, relative to the reference's region. The filter runs after the
//! time limit, so its own time shows in the seconds column.
//!
//! The reference is BDPT on every core (checked against the path tracer on these scenes by
//! `tests/bdpt.rs`; it converges much faster on caustics and on light through a crack),
//! rendered as two halves with different seeds and averaged. Half of the RMSE between the halves estimates the reference's own
//! RMSE; the corrected RMSE is sqrt(max(0, RMSE² − reference RMSE²)). The halves are cached
//! as PFM in `target/mlt-bench/` (named by scene, size, depth, spp, algorithm and, for a
//! spectral scene, `spectral`: `reference-prism-256x256-depth5-2048spp-bdpt-spectral-a.pfm`):
//! delete them after a change to the renderer that changes its converged image.
//!
//! Environment:
//! - `MLT_BENCH_SECONDS`: the longest time budget in seconds (default 10).
//! - `MLT_BENCH_REFERENCE_SPP`: total samples per pixel of the reference (default 2048).
//! - `MLT_BENCH_SCENES`: comma-separated scenes of tests/scenes (default
//!   `cornell-box,cornell-glass,door-ajar,lamp-behind-glass,window-room,cornell-glossy,prism`).
//! - `MLT_BENCH_ALGORITHMS`: comma-separated names from `ALGORITHMS` (default all).
//! - `MLT_BENCH_REPEATS`: renders at the longest budget per thread count (default 1).
//! - `MLT_BENCH_FONT`: a TrueType font for the plot's text (default: a few usual system
//!   paths); without one the plot is written without text.
//!
//! A quick run: `MLT_BENCH_SECONDS=2 MLT_BENCH_REFERENCE_SPP=256 cargo bench --bench equal_time`.

mod common;

use common::reference::{
    BenchScene, DEFAULT_REFERENCE_SPP, HEIGHT, MAX_DEPTH, REFERENCE_ALGORITHM, Reference, WIDTH,
    channel_means, load_scene, luminance, reference, rmse,
};
use common::{
    FONT_FAMILY, draw_legend, env_names, env_value, output_dir, plot_font_or_color_key,
    series_color,
};
use mlt::error::MLT_STATUS_UNSUPPORTED;
use mlt::{Algorithm, RenderSettings, RenderStats, StopReason, render_with_unfiltered};
use plotters::prelude::*;
use std::error::Error;
use std::io::Write;
use std::path::Path;

/// An algorithm as compared: the name the table, the plot and `MLT_BENCH_ALGORITHMS` use,
/// its `direct_samples_per_mutation` (Metropolis: the default direct pass, or 0 for chains
/// over every depth), path-space MLT's and ERPT's options and the post-process filter.
#[derive(Clone, Copy)]
struct Compared {
    name: &'static str,
    algorithm: Algorithm,
    direct_samples_per_mutation: u32,
    adapt_mutation_weights: bool,
    perturb_in_sample_space: bool,
    erpt_chain_length: u32,
    filter: bool,
}

const fn compared(name: &'static str, algorithm: Algorithm, direct: u32) -> Compared {
    Compared {
        name,
        algorithm,
        direct_samples_per_mutation: direct,
        adapt_mutation_weights: false,
        perturb_in_sample_space: false,
        erpt_chain_length: RenderSettings::DEFAULT_ERPT_CHAIN_LENGTH,
        filter: false,
    }
}

/// The algorithms compared. A new algorithm is one more line here.
const DIRECT: u32 = RenderSettings::DEFAULT_DIRECT_SAMPLES_PER_MUTATION;
const ALGORITHMS: &[Compared] = &[
    compared("path", Algorithm::Path, 0),
    compared("bdpt", Algorithm::Bdpt, 0),
    compared("pssmlt", Algorithm::Pssmlt, DIRECT),
    compared("pssmlt-bdpt", Algorithm::PssmltBdpt, DIRECT),
    compared("mmlt", Algorithm::Mmlt, DIRECT),
    compared("mmlt-no-direct", Algorithm::Mmlt, 0),
    compared("pssmlt-no-direct", Algorithm::Pssmlt, 0),
    compared("path-space-mlt", Algorithm::PathSpaceMlt, DIRECT),
    compared("path-space-mlt-no-direct", Algorithm::PathSpaceMlt, 0),
    Compared {
        adapt_mutation_weights: true,
        ..compared("path-space-mlt-adapted", Algorithm::PathSpaceMlt, DIRECT)
    },
    Compared {
        perturb_in_sample_space: true,
        ..compared(
            "path-space-mlt-sample-space",
            Algorithm::PathSpaceMlt,
            DIRECT,
        )
    },
    compared("erpt", Algorithm::Erpt, 0),
    Compared {
        perturb_in_sample_space: true,
        ..compared("erpt-sample-space", Algorithm::Erpt, 0)
    },
    Compared {
        erpt_chain_length: 5,
        ..compared("erpt-chains-5", Algorithm::Erpt, 0)
    },
    Compared {
        erpt_chain_length: 20,
        ..compared("erpt-chains-20", Algorithm::Erpt, 0)
    },
    Compared {
        erpt_chain_length: 100,
        ..compared("erpt-chains-100", Algorithm::Erpt, 0)
    },
    Compared {
        filter: true,
        ..compared("pssmlt-filtered", Algorithm::Pssmlt, DIRECT)
    },
    Compared {
        filter: true,
        ..compared("path-space-mlt-filtered", Algorithm::PathSpaceMlt, DIRECT)
    },
    Compared {
        filter: true,
        ..compared("erpt-filtered", Algorithm::Erpt, 0)
    },
];

const DEFAULT_SCENES: &[&str] = &[
    "cornell-box",
    "cornell-glass",
    "door-ajar",
    "lamp-behind-glass",
    "window-room",
    "cornell-glossy",
    "prism",
];
const DEFAULT_MAX_SECONDS: f64 = 10.0;
/// One time-limited render compared with the reference.
struct Measurement {
    algorithm: &'static str,
    threads: u32,
    budget_seconds: f64,
    stats: RenderStats,
    rmse: f64,
    corrected_rmse: f64,
    /// Per channel: image mean / reference mean − 1, in percent.
    mean_difference_percent: [f64; 3],
    /// The same for the luminance: the render's brightness error.
    brightness_difference_percent: f64,
    /// With the filter: the corrected RMSE of the same render unfiltered …
    unfiltered_corrected_rmse: Option<f64>,
    /// … and the largest shift of a 4 × 4 region's mean luminance the filter made, relative
    /// to the reference's region, in percent.
    filter_shift_percent: Option<f64>,
    /// Which render of several at the same budget and thread count (0 is plotted).
    repeat: u32,
}

struct SceneResult {
    scene: String,
    spectral: bool,
    reference_rmse: f64,
    measurements: Vec<Measurement>,
}

/// The 1-2-5 series from a tenth of `max_seconds` up to it, ending at `max_seconds` itself
/// (10 → 1, 2, 5, 10; 2 → 0.2, 0.5, 1, 2; 30 → 5, 10, 20, 30).
fn time_budgets(max_seconds: f64) -> Vec<f64> {
    assert!(
        max_seconds > 0.0 && max_seconds.is_finite(),
        "MLT_BENCH_SECONDS must be a positive number of seconds"
    );
    // Tolerances so that 10 / 10 = 1 counts as inside the range despite rounding.
    let low = max_seconds / 10.0 * (1.0 - 1e-9);
    let high = max_seconds * (1.0 - 1e-9);
    let first_decade = low.log10().floor() as i32;
    let mut budgets: Vec<f64> = (first_decade..=first_decade + 2)
        .flat_map(|exponent| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(exponent)))
        .filter(|&b| b >= low && b < high)
        .collect();
    budgets.push(max_seconds);
    budgets
}

/// Renders with `algorithm` until `budget_seconds` pass and compares with the reference. Fails
/// only when the render does (an algorithm that refuses the scene's mode: `Unsupported`).
#[allow(clippy::too_many_arguments)]
fn measure(
    bench: &BenchScene,
    reference: &Reference,
    compared: Compared,
    threads: u32,
    budget_seconds: f64,
    seed: u64,
    repeat: u32,
) -> mlt::Result<Measurement> {
    let name = compared.name;
    // Everything else stays at the defaults (with the scene's mode): they are what is judged.
    let settings = RenderSettings {
        algorithm: compared.algorithm,
        threads,
        seed,
        time_limit_seconds: budget_seconds,
        // 0: until the time limit.
        samples_per_pixel: 0,
        mutations_per_pixel: 0,
        direct_samples_per_mutation: compared.direct_samples_per_mutation,
        adapt_mutation_weights: compared.adapt_mutation_weights,
        perturb_in_sample_space: compared.perturb_in_sample_space,
        erpt_chain_length: compared.erpt_chain_length,
        filter_buffers: if compared.filter {
            RenderSettings::DEFAULT_FILTER_BUFFERS
        } else {
            0
        },
        ..bench.settings()
    };
    let mut image = vec![0.0f32; (WIDTH * HEIGHT * 3) as usize];
    let mut unfiltered = image.clone();
    let stats = render_with_unfiltered(
        &bench.scene,
        &bench.camera,
        &settings,
        &mut image,
        &mut unfiltered,
        None,
    )?;
    let corrected = |rmse: f64| {
        (rmse * rmse - reference.rmse * reference.rmse)
            .max(0.0)
            .sqrt()
    };
    let (unfiltered_corrected_rmse, filter_shift_percent) = if compared.filter {
        let luminance = |v: &[f64; 3]| 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        let regions =
            |image: &[f32]| -> Vec<f64> { region_means(image).iter().map(luminance).collect() };
        let (f, u, r) = (
            regions(&image),
            regions(&unfiltered),
            regions(&reference.image),
        );
        let shift = (0..f.len())
            .map(|i| ((f[i] - u[i]) / r[i]).abs())
            .fold(0.0, f64::max);
        (
            Some(corrected(rmse(&unfiltered, &reference.image))),
            Some(100.0 * shift),
        )
    } else {
        (None, None)
    };
    // With no sample count the render always ends at the time limit.
    assert_eq!(stats.stop, StopReason::TimeLimitReached, "{name}");
    let rmse = rmse(&image, &reference.image);
    let means = channel_means(&image);
    let reference_means = channel_means(&reference.image);
    Ok(Measurement {
        algorithm: name,
        threads,
        budget_seconds,
        stats,
        rmse,
        corrected_rmse: corrected(rmse),
        mean_difference_percent: std::array::from_fn(|c| {
            (means[c] / reference_means[c] - 1.0) * 100.0
        }),
        brightness_difference_percent: (luminance(means) / luminance(reference_means) - 1.0)
            * 100.0,
        unfiltered_corrected_rmse,
        filter_shift_percent,
        repeat,
    })
}

/// Mean RGB of each cell of a 4 × 4 partition of a `WIDTH` × `HEIGHT` image, row-major.
fn region_means(rgb: &[f32]) -> Vec<[f64; 3]> {
    const GRID: usize = 4;
    let (width, height) = (WIDTH as usize, HEIGHT as usize);
    let mut sums = vec![[0.0f64; 3]; GRID * GRID];
    for (i, pixel) in rgb.chunks_exact(3).enumerate() {
        let (x, y) = (i % width, i / width);
        let cell = (y * GRID / height) * GRID + x * GRID / width;
        for c in 0..3 {
            sums[cell][c] += pixel[c] as f64;
        }
    }
    let per_cell = (width * height / (GRID * GRID)) as f64;
    sums.iter().map(|s| s.map(|v| v / per_cell)).collect()
}

fn print_header() {
    println!(
        "{:<14} {:<28} {:>7} {:>7} {:>8} {:>12} {:>12} {:>9} {:>10} {:>10}  mean vs reference (R/G/B)  [filter: unfiltered corrected, largest region shift]  brightness (luminance), b's reported error",
        "scene",
        "algo",
        "threads",
        "budget",
        "seconds",
        "samples/s",
        "mutations/s",
        "accepted",
        "RMSE",
        "corrected",
    );
}

/// How far past its budget a render may run before the table points it out: a stop waits for
/// the current band or round of work to finish.
const OVERRUN_TOLERANCE_SECONDS: f64 = 0.1;

fn print_row(scene: &str, m: &Measurement) {
    let [r, g, b] = m.mean_difference_percent;
    let mut notes = String::new();
    if m.stats.samples == 0 && m.stats.mutations == 0 {
        notes.push_str("  no sample finished: black image, not plotted");
    }
    if m.stats.seconds > m.budget_seconds * 1.1 + OVERRUN_TOLERANCE_SECONDS {
        notes.push_str("  over budget");
    }
    if let (Some(unfiltered), Some(shift)) = (m.unfiltered_corrected_rmse, m.filter_shift_percent) {
        notes = format!("  [{unfiltered:.5}, {shift:.1}%]{notes}");
    }
    if m.stats.mutations > 0 {
        let b = m.stats.normalization;
        notes = format!(
            "  brightness {:+.2}%, b ± {:.2}%{notes}",
            m.brightness_difference_percent,
            100.0 * b.relative_error
        );
    }
    println!(
        "{scene:<14} {:<28} {:>7} {:>7.2} {:>8.2} {:>12.0} {:>12.0} {:>8.1}% {:>10.5} {:>10.5}  {r:+6.2}% {g:+6.2}% {b:+6.2}%{notes}",
        m.algorithm,
        m.threads,
        m.budget_seconds,
        m.stats.seconds,
        m.stats.samples as f64 / m.stats.seconds,
        m.stats.mutations as f64 / m.stats.seconds,
        100.0 * m.stats.accepted_mutations as f64 / m.stats.mutations.max(1) as f64,
        m.rmse,
        m.corrected_rmse,
    );
    // Rows appear as they are measured: a full run takes many minutes.
    let _ = std::io::stdout().flush();
}

/// The row of an algorithm that refuses the scene (`Unsupported`): the reason, without the
/// error's advice after the first semicolon.
fn print_unsupported(bench: &BenchScene, algorithm: &str, error: &mlt::Error) {
    let reason = error.message.split(';').next().unwrap_or_default();
    let mode = if bench.spectral {
        " in spectral mode"
    } else {
        ""
    };
    println!(
        "{:<14} {algorithm:<28} unsupported{mode}, skipped: {reason}",
        bench.name
    );
    let _ = std::io::stdout().flush();
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

/// Medians over the repeated renders at the longest budget, per algorithm and thread count.
fn print_medians(scene: &str, measurements: &[Measurement], max_seconds: f64, repeats: u32) {
    println!(
        "{scene}: medians over {repeats} renders of {max_seconds} s: {:<28} {:>7} {:>10} {:>9}  {:>27}  [filter: unfiltered corrected, largest region shift]",
        "algo", "threads", "corrected", "accepted", "brightness: mean, sd, max|.|"
    );
    let mut names: Vec<&str> = measurements.iter().map(|m| m.algorithm).collect();
    names.dedup();
    for name in names {
        for threads in [1, 2] {
            let runs: Vec<&Measurement> = measurements
                .iter()
                .filter(|m| {
                    m.algorithm == name && m.threads == threads && m.budget_seconds == max_seconds
                })
                .collect();
            let of = |f: &dyn Fn(&Measurement) -> f64| median(runs.iter().map(|m| f(m)).collect());
            let corrected = of(&|m| m.corrected_rmse);
            let accepted = of(&|m| {
                100.0 * m.stats.accepted_mutations as f64 / m.stats.mutations.max(1) as f64
            });
            let filter = if runs.iter().all(|m| m.unfiltered_corrected_rmse.is_some()) {
                format!(
                    "  [{:.5}, {:.1}%]",
                    of(&|m| m.unfiltered_corrected_rmse.unwrap_or(0.0)),
                    of(&|m| m.filter_shift_percent.unwrap_or(0.0))
                )
            } else {
                String::new()
            };
            // The brightness error over the repeats: its mean (a bias), spread and largest.
            let errors: Vec<f64> = runs
                .iter()
                .map(|m| m.brightness_difference_percent)
                .collect();
            let n = errors.len().max(1) as f64;
            let mean = errors.iter().sum::<f64>() / n;
            let spread = if errors.len() > 1 {
                (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
            } else {
                0.0
            };
            let largest = errors.iter().fold(0.0f64, |a, e| a.max(e.abs()));
            println!(
                "{scene}: medians over {repeats} renders of {max_seconds} s: {name:<28} {threads:>7} {corrected:>10.5} {accepted:>8.1}%  {mean:>+8.2}% {spread:>7.2}% {largest:>7.2}%{filter}"
            );
        }
    }
}

/// Tick values of a log axis over `min..max`: labelled ones on the 1-2-5 series and unlabelled
/// grid lines at every multiple of a power of ten. (plotters' own log ticks start at the first
/// power of ten inside the range, which leaves a range like 0.2..2 with a single label.)
fn log_ticks(min: f64, max: f64) -> (Vec<f64>, Vec<f64>) {
    let mut labelled = Vec::new();
    let mut grid = Vec::new();
    for exponent in min.log10().floor() as i32..=max.log10().ceil() as i32 {
        for mantissa in 1..=9 {
            let value = mantissa as f64 * 10f64.powi(exponent);
            if value < min || value > max {
                continue;
            }
            if [1, 2, 5].contains(&mantissa) {
                labelled.push(value);
            } else {
                grid.push(value);
            }
        }
    }
    (labelled, grid)
}

/// A tick label with as many decimals as its size needs (0.05, 0.2, 2, 10).
fn tick_label(value: f64) -> String {
    let decimals = (-value.log10().floor()).max(0.0) as usize;
    format!("{value:.decimals$}")
}

/// Log-log RMSE against seconds of the one-thread runs, one panel per scene. Renders that
/// finished no sample are left out: they are black and say nothing about convergence. Without
/// a font every text element (title, labels, legend) is left out, since drawing text would fail.
fn plot(path: &Path, results: &[SceneResult], with_text: bool) -> Result<(), Box<dyn Error>> {
    let root = BitMapBackend::new(path, (640 * results.len() as u32, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = if with_text {
        root.titled(
            &format!(
                "Equal-time convergence: {WIDTH}×{HEIGHT}, max depth {MAX_DEPTH}, 1 thread, default settings"
            ),
            (FONT_FAMILY, 22),
        )?
    } else {
        root
    };
    for (panel, result) in root.split_evenly((1, results.len())).iter().zip(results) {
        let plotted: Vec<&Measurement> = result
            .measurements
            .iter()
            .filter(|m| {
                m.threads == 1
                    && m.repeat == 0
                    && (m.stats.samples > 0 || m.stats.mutations > 0)
                    && m.rmse > 0.0
            })
            .collect();
        if plotted.is_empty() {
            continue;
        }
        let (mut x_min, mut x_max, mut y_min, mut y_max) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
        for m in &plotted {
            x_min = x_min.min(m.stats.seconds);
            x_max = x_max.max(m.stats.seconds);
            y_min = y_min.min(m.rmse);
            y_max = y_max.max(m.rmse);
        }
        if result.reference_rmse > 0.0 {
            y_min = y_min.min(result.reference_rmse);
        }
        // A margin so markers at the ends are not cut by the axes.
        let (x_min, x_max, y_min, y_max) = (x_min / 1.25, x_max * 1.25, y_min / 1.25, y_max * 1.25);
        let (x_labelled, x_grid) = log_ticks(x_min, x_max);
        let (y_labelled, y_grid) = log_ticks(y_min, y_max);
        let mut builder = ChartBuilder::on(panel);
        builder.margin(16);
        if with_text {
            let caption = if result.spectral {
                format!("{} (spectral)", result.scene)
            } else {
                result.scene.clone()
            };
            builder
                .caption(caption, (FONT_FAMILY, 20))
                .x_label_area_size(44)
                .y_label_area_size(64);
        }
        let mut chart = builder.build_cartesian_2d(
            (x_min..x_max)
                .log_scale()
                .with_key_points(x_labelled)
                .with_light_points(x_grid),
            (y_min..y_max)
                .log_scale()
                .with_key_points(y_labelled)
                .with_light_points(y_grid),
        )?;
        let mut mesh = chart.configure_mesh();
        mesh.bold_line_style(BLACK.mix(0.25))
            .light_line_style(BLACK.mix(0.08));
        if with_text {
            mesh.x_desc("seconds (actual, 1 thread)")
                .y_desc("RMSE vs reference")
                .x_label_formatter(&|&x| tick_label(x))
                .y_label_formatter(&|&y| tick_label(y))
                .label_style((FONT_FAMILY, 14));
        } else {
            mesh.x_labels(0).y_labels(0);
        }
        mesh.draw()?;

        // The reference's own error: differences much below this line are not measurable.
        let noise_style = BLACK.mix(0.6).stroke_width(1);
        let floor = chart.draw_series(DashedLineSeries::new(
            [
                (x_min, result.reference_rmse),
                (x_max, result.reference_rmse),
            ],
            6,
            4,
            noise_style,
        ))?;
        if with_text {
            floor
                .label("reference noise")
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], noise_style));
        }
        for (index, &Compared { name, .. }) in ALGORITHMS.iter().enumerate() {
            let mut points: Vec<(f64, f64)> = plotted
                .iter()
                .filter(|m| m.algorithm == name)
                .map(|m| (m.stats.seconds, m.rmse))
                .collect();
            // By actual time: short budgets can overrun past longer ones.
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            if points.is_empty() {
                continue;
            }
            let color = series_color(index);
            let series =
                chart.draw_series(LineSeries::new(points, color.stroke_width(2)).point_size(4))?;
            if with_text {
                series.label(name).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
                });
            }
        }
        if with_text {
            // Upper right: the curves fall from upper left to lower right.
            draw_legend(&mut chart)?;
        }
    }
    root.present()?;
    Ok(())
}

fn main() {
    let max_seconds = env_value("MLT_BENCH_SECONDS", DEFAULT_MAX_SECONDS);
    let reference_spp = env_value("MLT_BENCH_REFERENCE_SPP", DEFAULT_REFERENCE_SPP);
    let scenes = env_names("MLT_BENCH_SCENES", DEFAULT_SCENES);
    let all_algorithms: Vec<&str> = ALGORITHMS.iter().map(|c| c.name).collect();
    let algorithms: Vec<Compared> = env_names("MLT_BENCH_ALGORITHMS", &all_algorithms)
        .iter()
        .map(|wanted| {
            *ALGORITHMS
                .iter()
                .find(|c| c.name == wanted)
                .unwrap_or_else(|| {
                    panic!("MLT_BENCH_ALGORITHMS: unknown {wanted:?}; known: {all_algorithms:?}")
                })
        })
        .collect();
    let repeats: u32 = env_value("MLT_BENCH_REPEATS", 1);
    assert!(repeats >= 1, "MLT_BENCH_REPEATS must be at least 1");
    let budgets = time_budgets(max_seconds);
    let dir = output_dir();
    std::fs::create_dir_all(&dir).expect("output directory");
    println!(
        "equal time: {WIDTH}x{HEIGHT}, max depth {MAX_DEPTH}, budgets {budgets:?} s on 1 thread and {max_seconds} s on 2 threads"
    );

    let mut results = Vec::new();
    for name in &scenes {
        let bench = load_scene(name);
        let reference = reference(&bench, reference_spp, &dir);
        let [r, g, b] = channel_means(&reference.image);
        println!(
            "{name} ({}): reference {} {} spp (two halves), mean RGB {r:.4} {g:.4} {b:.4}, its own RMSE ≈ {:.5}",
            bench.mode(),
            REFERENCE_ALGORITHM.0,
            reference.spp,
            reference.rmse
        );
        print_header();
        let mut measurements = Vec::new();
        for &algorithm in &algorithms {
            let extra = (1..repeats).map(|repeat| (1, max_seconds, repeat));
            let two_threads = (0..repeats).map(|repeat| (2, max_seconds, repeat));
            let runs = budgets
                .iter()
                .map(|&budget| (1, budget, 0))
                .chain(extra)
                .chain(two_threads);
            for (seed, (threads, budget, repeat)) in runs.enumerate() {
                match measure(
                    &bench,
                    &reference,
                    algorithm,
                    threads,
                    budget,
                    seed as u64,
                    repeat,
                ) {
                    Ok(m) => {
                        print_row(name, &m);
                        measurements.push(m);
                    }
                    // It would refuse every budget alike: one row, then the next algorithm.
                    Err(e) if e.status == MLT_STATUS_UNSUPPORTED => {
                        print_unsupported(&bench, algorithm.name, &e);
                        break;
                    }
                    Err(e) => panic!("{} fails to render {name}: {e}", algorithm.name),
                }
            }
        }
        if repeats > 1 {
            print_medians(name, &measurements, max_seconds, repeats);
        }
        results.push(SceneResult {
            scene: name.clone(),
            spectral: bench.spectral,
            reference_rmse: reference.rmse,
            measurements,
        });
    }

    let with_text = plot_font_or_color_key(ALGORITHMS.iter().map(|c| c.name));
    let plot_path = dir.join("convergence.png");
    match plot(&plot_path, &results, with_text) {
        Ok(()) => println!("plot: {}", plot_path.display()),
        Err(e) => println!("plot failed: {e}"),
    }
}
