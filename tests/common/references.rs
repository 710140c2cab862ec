//! Reference images: renders of the path tracer (or BDPT, where the path tracer is too slow
//! to be sharp) averaged over seeds, computed once per test binary and shared by its tests.
// Each test file uses a part of these helpers.
#![allow(dead_code)]

use super::scenes::{OPEN_MAX_DEPTH, OPEN_SIZE, OpenLights, load_canonical, open_scene};
use super::stats::Estimate;
use mlt::{Camera, Scene};

/// A `size` × `size` path-traced image (max depth 5) with `spp` samples per pixel.
pub fn path_traced_image(
    scene: &Scene,
    camera: &Camera,
    size: u32,
    spp: u32,
    seed: u64,
) -> Vec<f32> {
    let settings = mlt::RenderSettings {
        width: size,
        height: size,
        algorithm: mlt::Algorithm::Path,
        samples_per_pixel: spp,
        max_depth: 5,
        seed,
        ..Default::default()
    };
    let mut image = vec![0.0; (size * size * 3) as usize];
    mlt::render(scene, camera, &settings, &mut image, None).unwrap();
    image
}

/// `path_traced_image` averaged over independent renders, one per seed.
pub fn path_traced_estimate(
    scene: &Scene,
    camera: &Camera,
    size: u32,
    spp: u32,
    seeds: std::ops::Range<u64>,
) -> Estimate {
    let renders: Vec<Vec<f32>> = seeds
        .map(|seed| path_traced_image(scene, camera, size, spp, seed))
        .collect();
    Estimate::from_renders(size as usize, size as usize, &renders)
}

/// Renders `settings` into a new image (the render must succeed).
pub fn render_image(scene: &Scene, camera: &Camera, settings: &mlt::RenderSettings) -> Vec<f32> {
    let mut image = vec![0.0; (settings.width * settings.height * 3) as usize];
    mlt::render(scene, camera, settings, &mut image, None).unwrap();
    image
}

/// `settings` rendered once per seed in `seeds` (each replacing `settings.seed`), as one
/// estimate over the renders.
pub fn estimate_over_seeds(
    scene: &Scene,
    camera: &Camera,
    settings: &mlt::RenderSettings,
    seeds: std::ops::Range<u64>,
) -> Estimate {
    let renders: Vec<Vec<f32>> = seeds
        .map(|seed| render_image(scene, camera, &mlt::RenderSettings { seed, ..*settings }))
        .collect();
    let (width, height) = (settings.width as usize, settings.height as usize);
    Estimate::from_correlated_renders(width, height, &renders)
}

/// An estimate computed once per test binary under `key`: the tests comparing against the
/// same reference share it (one asking while another computes it waits for that one).
pub fn cached_estimate(key: &str, compute: impl FnOnce() -> Estimate) -> &'static Estimate {
    cached(key, compute)
}

/// A value computed once per test binary under `key` (a reference, or a render several tests
/// look at), as `cached_estimate`; a key holds one type.
pub fn cached<T: std::any::Any + Send + Sync>(
    key: &str,
    compute: impl FnOnce() -> T,
) -> &'static T {
    type Value = Box<dyn std::any::Any + Send + Sync>;
    type Slot = &'static std::sync::OnceLock<Value>;
    static SLOTS: std::sync::Mutex<Vec<(String, Slot)>> = std::sync::Mutex::new(Vec::new());
    let slot: Slot = {
        let mut slots = SLOTS.lock().unwrap();
        match slots.iter().find(|(k, _)| k == key) {
            Some(&(_, slot)) => slot,
            None => {
                let slot: Slot = Box::leak(Box::default());
                slots.push((key.to_owned(), slot));
                slot
            }
        }
    };
    slot.get_or_init(|| Box::new(compute()))
        .downcast_ref()
        .unwrap_or_else(|| panic!("{key:?} is cached as another type"))
}

/// The path tracer's estimate of a canonical scene, the reference of the Metropolis and
/// ERPT tests on the Cornell scenes: 8 renders of 64 × 64 pixels at 256 samples.
pub fn path_reference(scene_name: &str) -> &'static Estimate {
    cached_estimate(&format!("path {scene_name}"), || {
        let (scene, camera) = load_canonical(scene_name);
        path_traced_estimate(&scene, &camera, 64, 256, 1000..1008)
    })
}

/// BDPT's estimate (16 renders of 64 × 64 pixels, max depth 5), the reference where the
/// path tracer is too slow to be sharp (the door-ajar scene, caustics): `tests/bdpt.rs`
/// checks BDPT against the path tracer.
pub fn bdpt_estimate(scene: &Scene, camera: &Camera, samples_per_pixel: u32) -> Estimate {
    let renders: Vec<Vec<f32>> = (1000..1016)
        .map(|seed| {
            let settings = mlt::RenderSettings {
                width: 64,
                height: 64,
                algorithm: mlt::Algorithm::Bdpt,
                samples_per_pixel,
                max_depth: 5,
                seed,
                ..Default::default()
            };
            render_image(scene, camera, &settings)
        })
        .collect();
    // Light-tracing splats correlate a render's pixels.
    Estimate::from_correlated_renders(64, 64, &renders)
}

/// The path tracer's estimate of an open scene: 8 renders of `OPEN_SIZE`² at 1024 samples.
pub fn open_reference(lights: OpenLights) -> &'static Estimate {
    cached_estimate(&format!("path open {lights:?}"), || {
        let (scene, camera) = open_scene(lights);
        let renders: Vec<Vec<f32>> = (2000..2008)
            .map(|seed| {
                let settings = mlt::RenderSettings {
                    width: OPEN_SIZE,
                    height: OPEN_SIZE,
                    algorithm: mlt::Algorithm::Path,
                    samples_per_pixel: 1024,
                    max_depth: OPEN_MAX_DEPTH,
                    seed,
                    ..Default::default()
                };
                render_image(&scene, &camera, &settings)
            })
            .collect();
        Estimate::from_renders(OPEN_SIZE as usize, OPEN_SIZE as usize, &renders)
    })
}
