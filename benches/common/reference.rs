//! The converged images the benches compare with: BDPT on every core, rendered as two halves
//! with different seeds and cached as PFM in `target/mlt-bench/` (named by scene, size,
//! depth, spp, algorithm and, for a spectral scene, `spectral`; delete them after a change to
//! the renderer that changes its converged image). BDPT is checked against the path tracer on
//! the canonical scenes by `tests/bdpt.rs`, and converges much faster on caustics and on light
//! through a crack.
//!
//! A scene renders in spectral mode (`RenderSettings::spectral`) when one of its materials
//! disperses (an Abbe number above 0, e.g. the flint prism of tests/scenes/prism.obj): RGB
//! mode ignores dispersion, so it would render another image. `BenchScene::settings` is the
//! one place that decides the settings every render of a scene shares (size, depth, mode),
//! for the reference and for the renders compared with it alike.

use mlt::{Algorithm, Camera, RenderSettings, Scene, StopReason, render};
use std::path::Path;

/// The image every bench render and reference has: 256 × 256, max depth 5.
pub const WIDTH: u32 = 256;
pub const HEIGHT: u32 = 256;
pub const MAX_DEPTH: u32 = 5;

pub const DEFAULT_REFERENCE_SPP: u32 = 2048;
pub const REFERENCE_ALGORITHM: (&str, Algorithm) = ("bdpt", Algorithm::Bdpt);

/// Seeds of the two reference halves. The measured renders use seeds 0, 1, 2, …: keeping
/// these far away means no measured render shares random numbers with the reference, which
/// would make its error look smaller than it is.
const REFERENCE_SEEDS: [u64; 2] = [0x5EED_0000_000A, 0x5EED_0000_000B];

/// A converged image and the estimate of its own remaining error.
pub struct Reference {
    pub image: Vec<f32>,
    /// RMSE of the reference against the true image, estimated from its two halves.
    pub rmse: f64,
    pub spp: u32,
}

/// Root-mean-square difference over all floats (the same definition as the tests' `rmse`).
pub fn rmse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum();
    (sum / a.len() as f64).sqrt()
}

pub fn channel_means(image: &[f32]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for pixel in image.chunks_exact(3) {
        for (s, &value) in sum.iter_mut().zip(pixel) {
            *s += value as f64;
        }
    }
    sum.map(|s| s / (image.len() / 3) as f64)
}

pub fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// A scene as the benches render it: the scene, its camera and its transport mode.
pub struct BenchScene {
    pub name: String,
    pub scene: Scene,
    pub camera: Camera,
    /// Spectral transport: one of the scene's materials disperses (see the module doc).
    pub spectral: bool,
}

impl BenchScene {
    /// The settings every render of this scene starts from, reference or compared: the bench
    /// image (`WIDTH` × `HEIGHT`, `MAX_DEPTH`) in the scene's transport mode, everything else
    /// at the defaults. Callers set the algorithm, seed, threads and budget.
    pub fn settings(&self) -> RenderSettings {
        RenderSettings {
            width: WIDTH,
            height: HEIGHT,
            max_depth: MAX_DEPTH,
            spectral: self.spectral,
            ..Default::default()
        }
    }

    /// The transport mode, for tables and plots: "spectral" or "RGB".
    pub fn mode(&self) -> &'static str {
        if self.spectral { "spectral" } else { "RGB" }
    }
}

/// A scene of tests/scenes with its camera sidecar, on the BVH backend; the window room
/// with its sky and sun (tests/common/window_room.rs). Spectral when a material disperses.
pub fn load_scene(name: &str) -> BenchScene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/scenes")
        .join(format!("{name}.obj"));
    let data = mlt::io::load_scene(&path)
        .unwrap_or_else(|e| panic!("scene {name} (MLT_BENCH_SCENES) does not load: {e}"));
    let sky = super::window_room::sky_pixels();
    let mut desc = data.desc(mlt::Backend::Bvh);
    if name == "window-room" {
        desc.lights = super::window_room::lights(&sky);
    }
    let spectral = desc.materials.iter().any(|m| m.abbe_number > 0.0);
    let scene = Scene::new(&desc).expect("scene builds");
    let camera = data.camera.expect("camera sidecar").camera;
    BenchScene {
        name: name.to_string(),
        scene,
        camera,
        spectral,
    }
}

/// The two reference halves, read from the cache or rendered (and cached) when missing. The
/// cache names of RGB scenes carry no mode (the names from before spectral mode, so old caches
/// still hit); spectral ones end in `-spectral-a.pfm` / `-spectral-b.pfm`.
pub fn reference(bench: &BenchScene, spp: u32, dir: &Path) -> Reference {
    let name = &bench.name;
    let mode = if bench.spectral { "-spectral" } else { "" };
    let half_spp = (spp / 2).max(1);
    let halves: Vec<Vec<f32>> = REFERENCE_SEEDS
        .iter()
        .zip(["a", "b"])
        .map(|(&seed, half)| {
            let path = dir.join(format!(
                "reference-{name}-{WIDTH}x{HEIGHT}-depth{MAX_DEPTH}-{spp}spp-{}{mode}-{half}.pfm",
                REFERENCE_ALGORITHM.0
            ));
            if let Ok((WIDTH, HEIGHT, image)) = mlt::io::read_pfm(&path) {
                return image;
            }
            println!(
                "rendering reference half {half} of {name}: {} ({}), {half_spp} spp, all threads",
                REFERENCE_ALGORITHM.0,
                bench.mode()
            );
            let settings = RenderSettings {
                algorithm: REFERENCE_ALGORITHM.1,
                samples_per_pixel: half_spp,
                threads: 0,
                seed,
                ..bench.settings()
            };
            let mut image = vec![0.0f32; (WIDTH * HEIGHT * 3) as usize];
            let stats =
                render(&bench.scene, &bench.camera, &settings, &mut image, None).expect("renders");
            assert_eq!(stats.stop, StopReason::Completed);
            mlt::io::write_pfm(&path, WIDTH, HEIGHT, &image).expect("reference cache writes");
            println!("  {:.1} s, cached in {}", stats.seconds, path.display());
            image
        })
        .collect();
    let image = halves[0]
        .iter()
        .zip(&halves[1])
        .map(|(&a, &b)| 0.5 * (a + b))
        .collect();
    // Each half has variance σ² per float, their difference 2σ² and their mean σ²/2: the
    // mean's RMSE is half the RMSE between the halves.
    Reference {
        image,
        rmse: rmse(&halves[0], &halves[1]) / 2.0,
        spp: half_spp * 2,
    }
}
