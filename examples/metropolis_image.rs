//! The seed lecture's "neat example" of Metropolis sampling: a chain over the pixels of an
//! image, proposing a uniformly random pixel each step and accepting with probability
//! val[new] / val[current]. Its histogram converges to the (normalized) image.
//!
//! ```text
//! cargo run --release --example metropolis_image [OUTPUT_DIR]
//! ```
//!
//! Writes `metropolis-target.png`, `metropolis-8mpp.png` and `metropolis-256mpp.png` (grey,
//! all three on the same scale, enlarged 4× with nearest-neighbour) into OUTPUT_DIR (default
//! the current directory) and prints the error of each histogram against the target.

use mlt::integrators::mlt::image_chain::run_histogram;
use std::path::PathBuf;

const WIDTH: usize = 64;
const HEIGHT: usize = 64;
const ZOOM: usize = 4;
const CHAINS: usize = 8;
const SEED: u64 = 1;

/// Gaussian blobs on a dim floor, a bright ring, and a dark rectangle of exact zeros.
fn target() -> Vec<f32> {
    let mut t = vec![0f32; WIDTH * HEIGHT];
    let blobs = [
        (18.0, 20.0, 6.0, 1.0),
        (44.0, 40.0, 8.0, 0.7),
        (24.0, 46.0, 4.0, 0.9),
    ];
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
            let mut v = 0.05;
            for &(cx, cy, s, a) in &blobs {
                let d2 = (fx - cx).powi(2) + (fy - cy).powi(2);
                v += a * (-d2 / (2.0 * s * s)).exp();
            }
            let r = ((fx - 32.0).powi(2) + (fy - 32.0).powi(2)).sqrt();
            v += 1.2 * (-(r - 24.0).powi(2) / (2.0 * 1.5f32.powi(2))).exp();
            if (40..58).contains(&x) && (6..18).contains(&y) {
                v = 0.0;
            }
            t[y * WIDTH + x] = v;
        }
    }
    t
}

fn write(dir: &std::path::Path, name: &str, values: &[f64], scale: f64) {
    let mut rgb = Vec::with_capacity(WIDTH * HEIGHT * ZOOM * ZOOM * 3);
    for y in 0..HEIGHT * ZOOM {
        for x in 0..WIDTH * ZOOM {
            let v = (values[(y / ZOOM) * WIDTH + x / ZOOM] * scale) as f32;
            rgb.extend_from_slice(&[v, v, v]);
        }
    }
    let path = dir.join(name);
    mlt::io::write_png(&path, (WIDTH * ZOOM) as u32, (HEIGHT * ZOOM) as u32, &rgb)
        .unwrap_or_else(|e| panic!("{e}"));
    println!("wrote {}", path.display());
}

fn main() {
    let dir = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("."));
    std::fs::create_dir_all(&dir).expect("cannot create the output directory");

    let t = target();
    let t64: Vec<f64> = t.iter().map(|&v| v as f64).collect();
    let max = t64.iter().cloned().fold(0.0, f64::max);
    let scale = 1.0 / max;
    let norm = (t64.iter().map(|v| v * v).sum::<f64>() / t64.len() as f64).sqrt();

    write(&dir, "metropolis-target.png", &t64, scale);
    for mpp in [8u64, 256] {
        let start = std::time::Instant::now();
        let hist = run_histogram(&t, WIDTH, HEIGHT, mpp, SEED, CHAINS);
        let elapsed = start.elapsed();
        let rmse = (hist
            .iter()
            .zip(&t64)
            .map(|(h, v)| (h - v).powi(2))
            .sum::<f64>()
            / t64.len() as f64)
            .sqrt();
        println!(
            "{mpp:>3} mutations per pixel ({} mutations, {CHAINS} chains, {:.1} ms): \
             RMSE {rmse:.4} (target max {max:.3}, RMS {norm:.3}; relative {:.3})",
            mpp * (WIDTH * HEIGHT) as u64,
            elapsed.as_secs_f64() * 1e3,
            rmse / norm
        );
        write(&dir, &format!("metropolis-{mpp}mpp.png"), &hist, scale);
    }
}
