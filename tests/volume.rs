//! Absorbing volumes (`KHR_materials_volume`): Beer–Lambert's law inside closed transmissive
//! meshes, in every algorithm.
//!
//! - A camera looks through a glass slab at a lamp behind it: with the index matched
//!   (1.0) every path crosses the slab straight, and each pixel is the lamp's radiance times
//!   exp(−σ d) = colour^(d / distance) to float precision (the path tracer and BDPT); at
//!   index 1.5 the two Fresnel transmissions (1 − F0)² multiply it.
//! - A rough index-matched slab passes light straight on, each face letting through the
//!   closed form 20/21 of it at roughness 1, in every algorithm but the light tracer (which
//!   cannot see a lamp through Dirac lobes).
//! - A grey attenuation absorbs the same in spectral renders as in RGB ones.
//! - On the surfaces scene with its rough glass sphere made absorbing, every algorithm
//!   agrees with BDPT, and BDPT with the path tracer (and each check would fail a 2% error).
//!
//! As much work as tests/surfaces.rs (`cargo test --test volume`): 156 s measured on 2
//! cores shared with other jobs (load 10 to 11), 99 s in another run.

mod common {
    pub mod references;
    pub mod scenes;
    pub mod stats;
    pub mod surfaces;
}

use common::references::{cached_estimate, estimate_over_seeds, render_image};
use common::scenes::canonical_camera;
use common::stats::{Estimate, assert_estimates_agree, assert_within_and_sharp};
use common::surfaces::surfaces_mesh;

use mlt::{Algorithm, Backend, Camera, Material, RenderSettings, Scene, SceneDesc};

/// The slab's depth along z (it spans z in [−DEPTH, 0], and x, y in [−10, 10]).
const DEPTH: f32 = 0.5;

/// A box slab of material `slab` (outward faces) before a lamp of radiance 1 at z = −3
/// facing +z, much wider than the camera's view.
fn slab_scene(slab: Material) -> Scene {
    let (w, z0, z1) = (10.0f32, -DEPTH, 0.0f32);
    #[rustfmt::skip]
    let positions = vec![
        // The slab's corners: 0-3 at z1 (front), 4-7 at z0 (back).
        -w, -w, z1,  w, -w, z1,  w, w, z1,  -w, w, z1,
        -w, -w, z0,  w, -w, z0,  w, w, z0,  -w, w, z0,
        // The lamp.
        -w, -w, -3.0,  w, -w, -3.0,  w, w, -3.0,  -w, w, -3.0,
    ];
    #[rustfmt::skip]
    let indices = vec![
        0, 1, 2, 0, 2, 3, // front, +z
        4, 6, 5, 4, 7, 6, // back, −z
        0, 4, 5, 0, 5, 1, // −y
        3, 2, 6, 3, 6, 7, // +y
        0, 3, 7, 0, 7, 4, // −x
        1, 5, 6, 1, 6, 2, // +x
        8, 9, 10, 8, 10, 11, // the lamp, +z
    ];
    let mut material_ids = vec![0; 12];
    material_ids.extend([1, 1]);
    let lamp = Material::diffuse([0.0; 3]).with_emission([1.0; 3]);
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &material_ids,
        materials: &[slab, lamp],
        backend: Backend::Bvh,
        ..Default::default()
    })
    .expect("a valid scene")
}

/// A pinhole at z = 5 looking down −z through the slab with a 1° view: every ray crosses
/// it within 0.71° of its normal, so its path inside is DEPTH to within 8·10⁻⁵.
fn slab_camera() -> Camera {
    Camera {
        eye: [0.0, 0.0, 5.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 1.0,
        ..Default::default()
    }
}

/// A smooth glass of index `ior` that absorbs: the slab's depth is two attenuation
/// distances, so it lets colour² through. The thickness factor only marks a volume.
fn absorbing_glass(ior: f32, colour: [f32; 3]) -> Material {
    Material {
        thickness: 1.0,
        attenuation_color: colour,
        attenuation_distance: DEPTH / 2.0,
        ..Material::dielectric(ior)
    }
}

const COLOUR: [f32; 3] = [0.5, 0.25, 0.8];

fn slab_settings(algorithm: Algorithm, spp: u32) -> RenderSettings {
    RenderSettings {
        width: 16,
        height: 16,
        algorithm,
        samples_per_pixel: spp,
        max_depth: 2,
        ..Default::default()
    }
}

/// Index-matched: every pixel of the path tracer and BDPT is exactly colour², and a thin
/// wall (thickness 0) or no attenuation absorbs nothing.
#[test]
fn beer_lambert_through_an_index_matched_slab() {
    let expected = COLOUR.map(|c| c * c);
    for algorithm in [Algorithm::Path, Algorithm::Bdpt] {
        let image = render_image(
            &slab_scene(absorbing_glass(1.0, COLOUR)),
            &slab_camera(),
            &slab_settings(algorithm, 4),
        );
        for (i, &value) in image.iter().enumerate() {
            let truth = expected[i % 3];
            assert!(
                (value - truth).abs() <= 2e-4 * truth,
                "{algorithm:?}: pixel {} channel {}: {value} instead of {truth}",
                i / 3,
                i % 3
            );
        }
        for clear in [
            Material {
                thickness: 0.0,
                ..absorbing_glass(1.0, COLOUR)
            },
            Material {
                attenuation_distance: f32::MAX,
                ..absorbing_glass(1.0, COLOUR)
            },
        ] {
            let image = render_image(
                &slab_scene(clear),
                &slab_camera(),
                &slab_settings(algorithm, 4),
            );
            assert!(
                image.iter().all(|&v| (v - 1.0).abs() <= 1e-5),
                "{algorithm:?}: a thin wall or no attenuation absorbs"
            );
        }
    }
}

/// At index 1.5 the light crossing straight (depth 2: no internal reflection) is
/// (1 − F0)² colour², F0 = ((n − 1)/(n + 1))² at normal incidence; the paths reflected at
/// the first face leave the scene.
#[test]
fn beer_lambert_through_a_glass_slab_with_fresnel() {
    let f0 = ((1.5f64 - 1.0) / (1.5 + 1.0)).powi(2);
    let image = render_image(
        &slab_scene(absorbing_glass(1.5, COLOUR)),
        &slab_camera(),
        &slab_settings(Algorithm::Path, 256),
    );
    let (mean, standard_error) = common::stats::mean_and_standard_error(&image);
    for c in 0..3 {
        let truth = (1.0 - f0).powi(2) * (COLOUR[c] as f64).powi(2);
        // Each sample is colour² or 0: the standard error from that Bernoulli spread.
        let p = (1.0 - f0).powi(2);
        let sample_error =
            (COLOUR[c] as f64).powi(2) * (p * (1.0 - p) / (16.0 * 16.0 * 256.0)).sqrt();
        assert_within_and_sharp(
            &format!("channel {c}"),
            mean[c],
            truth,
            sample_error.max(standard_error[c]),
            4.0,
        );
    }
}

/// A rough (roughness 1) index-matched slab that absorbs: microfacets of index 1 pass light
/// straight on, each face letting through 1 − F̄ of it, F̄ Schlick's F (F0 = 0) averaged
/// over the normals visible face-on. At α = 1 GGX's D is 1/π, so F̄ = 2 ∫ (1 − μ)⁵ μ dμ =
/// 1/21 in closed form (the views are within 0.71° of the normal: F̄ and the masking move
/// by less than 10⁻⁴ there), and the slab lets through (20/21)² colour². Each sample is
/// that over the two lobe choices' probability, or 0 where a face's rough reflection is
/// picked instead (it leaves the scene).
#[test]
fn a_rough_index_matched_slab_passes_light_straight_on() {
    let slab = Material {
        transmission: 1.0,
        ior: 1.0,
        thickness: 1.0,
        attenuation_color: COLOUR,
        attenuation_distance: DEPTH / 2.0,
        ..Material::metallic_roughness([1.0; 3], 0.0, 1.0)
    };
    let through = (20.0f64 / 21.0).powi(2);
    for algorithm in [Algorithm::Path, Algorithm::Bdpt] {
        let image = render_image(
            &slab_scene(slab),
            &slab_camera(),
            &slab_settings(algorithm, 64),
        );
        let (mean, standard_error) = common::stats::mean_and_standard_error(&image);
        for c in 0..3 {
            assert_within_and_sharp(
                &format!("{algorithm:?} channel {c}"),
                mean[c],
                through * (COLOUR[c] as f64).powi(2),
                standard_error[c],
                4.0,
            );
        }
    }
    // A Metropolis render's pixels share chains: the error is the spread of whole-image
    // means over independent seeds.
    for algorithm in [
        Algorithm::Pssmlt,
        Algorithm::PssmltBdpt,
        Algorithm::Mmlt,
        Algorithm::PathSpaceMlt,
        Algorithm::Erpt,
    ] {
        let means: Vec<f64> = (0..SEEDS)
            .map(|seed| {
                let settings = RenderSettings {
                    seed,
                    ..slab_settings(algorithm, 16)
                };
                let image = render_image(&slab_scene(slab), &slab_camera(), &settings);
                common::stats::mean_and_standard_error(&image).0[2]
            })
            .collect();
        let mean = means.iter().sum::<f64>() / SEEDS as f64;
        let spread = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (SEEDS - 1) as f64;
        assert_within_and_sharp(
            &format!("{algorithm:?} blue"),
            mean,
            through * (COLOUR[2] as f64).powi(2),
            (spread / SEEDS as f64).sqrt(),
            4.0,
        );
    }
}

/// Independent renders of each Metropolis algorithm in the rough index-matched slab's test.
const SEEDS: u64 = 16;

/// A grey attenuation is grey at every wavelength: the spectral render of the index-matched
/// slab is the clear slab's times grey², as the RGB render is.
#[test]
fn a_grey_attenuation_absorbs_the_same_in_spectral_renders() {
    let grey = [0.5; 3];
    let spectral = |material: Material| {
        let settings = RenderSettings {
            spectral: true,
            ..slab_settings(Algorithm::Path, 16)
        };
        render_image(&slab_scene(material), &slab_camera(), &settings)
    };
    let absorbed = spectral(absorbing_glass(1.0, grey));
    let clear = spectral(Material {
        thickness: 0.0,
        ..absorbing_glass(1.0, grey)
    });
    let rgb = render_image(
        &slab_scene(absorbing_glass(1.0, grey)),
        &slab_camera(),
        &slab_settings(Algorithm::Path, 4),
    );
    assert!(rgb.iter().all(|&v| (v - 0.25).abs() <= 1e-4), "RGB");
    // Same seed, same wavelengths: pixel by pixel the ratio is grey² where the upsampled
    // grey is flat.
    for (i, (&a, &c)) in absorbed.iter().zip(&clear).enumerate() {
        assert!(
            (a - 0.25 * c).abs() <= 2e-3 * c,
            "pixel {} channel {}: {a} against {} (the clear slab's {c} × 0.25)",
            i / 3,
            i % 3,
            0.25 * c
        );
    }
}

const SIZE: u32 = 32;
const MAX_DEPTH: u32 = 4;

/// The surfaces scene with its rough glass sphere (the last material) filled with a
/// bluish absorbing volume whose attenuation distance is its radius.
fn volume_scene() -> Scene {
    let mut mesh = surfaces_mesh();
    let sphere = mesh
        .mesh
        .materials
        .last_mut()
        .expect("the sphere's material");
    assert!(sphere.transmission > 0.0, "the last material is the glass");
    sphere.thickness = 1.0;
    sphere.attenuation_color = [0.3, 0.6, 0.9];
    sphere.attenuation_distance = 70.0;
    mesh.scene(Backend::Bvh)
}

/// `renders` independent renders of the volume scene with `settings`.
fn estimate(settings: RenderSettings, renders: u64) -> Estimate {
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        max_depth: MAX_DEPTH,
        ..settings
    };
    estimate_over_seeds(
        &volume_scene(),
        &canonical_camera("cornell-box"),
        &settings,
        700..700 + renders,
    )
}

fn bdpt_reference() -> &'static Estimate {
    cached_estimate("bdpt volume", || {
        let settings = RenderSettings {
            algorithm: Algorithm::Bdpt,
            samples_per_pixel: 64,
            ..Default::default()
        };
        estimate(settings, 16)
    })
}

#[test]
fn bdpt_agrees_with_the_path_tracer_through_a_volume() {
    let settings = RenderSettings {
        algorithm: Algorithm::Path,
        samples_per_pixel: 192,
        ..Default::default()
    };
    assert_estimates_agree(
        "volume: BDPT against the path tracer",
        bdpt_reference(),
        &estimate(settings, 16),
        4,
        5.0,
        6.0,
    );
}

fn agrees_with_bdpt(algorithm: Algorithm) {
    let settings = RenderSettings {
        algorithm,
        samples_per_pixel: 40,
        mutations_per_pixel: 128,
        bootstrap_samples: 1 << 16,
        chains: 256,
        ..Default::default()
    };
    assert_estimates_agree(
        &format!("volume: {algorithm:?} against BDPT"),
        &estimate(settings, 16),
        bdpt_reference(),
        4,
        5.0,
        6.0,
    );
}

#[test]
fn every_metropolis_algorithm_agrees_with_bdpt_through_a_volume() {
    for algorithm in [
        Algorithm::Pssmlt,
        Algorithm::PssmltBdpt,
        Algorithm::Mmlt,
        Algorithm::PathSpaceMlt,
        Algorithm::Erpt,
    ] {
        agrees_with_bdpt(algorithm);
    }
}
