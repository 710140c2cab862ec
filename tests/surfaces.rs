//! Real surfaces: shading normals (and, as they land, glossy metallic-roughness BSDFs and
//! textures) in every algorithm. The algorithms must agree with each other on the surfaces
//! scene (tests/common/surfaces.rs): the path tracer and BDPT (whose light tracing sees the
//! non-symmetric BSDF of shading normals from the other end), and each Metropolis algorithm
//! against BDPT. Tolerances come from the spread of independent renders, and each check
//! also asserts that a 2% brightness error would fail (`assert_estimates_agree`).

mod common;

use common::surfaces::surfaces_mesh;
use common::{Estimate, assert_estimates_agree, cached_estimate, canonical_camera, render_image};
use mlt::{Algorithm, Backend, RenderSettings};

const SIZE: u32 = 32;
const MAX_DEPTH: u32 = 4;

/// `renders` independent renders of the surfaces scene with `settings`.
fn estimate(settings: RenderSettings, renders: u64) -> Estimate {
    let scene = surfaces_mesh().scene(Backend::Bvh);
    let camera = canonical_camera("cornell-box");
    let images: Vec<Vec<f32>> = (0..renders)
        .map(|seed| {
            let settings = RenderSettings {
                width: SIZE,
                height: SIZE,
                max_depth: MAX_DEPTH,
                seed: 900 + seed,
                ..settings
            };
            render_image(&scene, &camera, &settings)
        })
        .collect();
    Estimate::from_correlated_renders(SIZE as usize, SIZE as usize, &images)
}

/// BDPT's estimate, once per test binary: the reference of the Metropolis algorithms,
/// itself checked against the path tracer.
fn bdpt_reference() -> &'static Estimate {
    cached_estimate("bdpt surfaces", || {
        let settings = RenderSettings {
            algorithm: Algorithm::Bdpt,
            samples_per_pixel: 64,
            ..Default::default()
        };
        estimate(settings, 16)
    })
}

#[test]
fn bdpt_agrees_with_the_path_tracer() {
    let settings = RenderSettings {
        algorithm: Algorithm::Path,
        samples_per_pixel: 192,
        ..Default::default()
    };
    assert_estimates_agree(
        "surfaces BDPT against the path tracer",
        bdpt_reference(),
        &estimate(settings, 16),
        4,
        5.0,
        6.0,
    );
}

/// A Metropolis algorithm (or ERPT, whose camera samples are BDPT's) against BDPT.
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
        &format!("surfaces {algorithm:?} against BDPT"),
        &estimate(settings, 16),
        bdpt_reference(),
        4,
        5.0,
        6.0,
    );
}

#[test]
fn primary_space_metropolis_agrees_with_bdpt() {
    for algorithm in [Algorithm::Pssmlt, Algorithm::PssmltBdpt, Algorithm::Mmlt] {
        agrees_with_bdpt(algorithm);
    }
}

#[test]
fn path_space_mlt_and_erpt_agree_with_bdpt() {
    for algorithm in [Algorithm::PathSpaceMlt, Algorithm::Erpt] {
        agrees_with_bdpt(algorithm);
    }
}

/// Writes the BDPT reference at 256², for looking at (`MLT_WRITE_SURFACES=DIR`).
#[test]
fn write_surfaces_image() {
    let Some(dir) = std::env::var_os("MLT_WRITE_SURFACES") else {
        return;
    };
    let scene = surfaces_mesh().scene(Backend::Bvh);
    let settings = RenderSettings {
        width: 256,
        height: 256,
        algorithm: Algorithm::Path,
        samples_per_pixel: 256,
        max_depth: MAX_DEPTH,
        ..Default::default()
    };
    let image = render_image(&scene, &canonical_camera("cornell-box"), &settings);
    let path = std::path::Path::new(&dir).join("surfaces.png");
    mlt::io::write_png(&path, 256, 256, &image).unwrap();
}
