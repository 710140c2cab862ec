//! Real surfaces: shading normals, glossy metallic-roughness BSDFs, textures and the
//! material extensions (clear coats, sheen, specular, anisotropy, thin films) in every
//! algorithm. The seven algorithms must agree with each other on the surfaces scene
//! (tests/common/surfaces.rs) with the extensions (`extensions_scene`): the path tracer and
//! BDPT (whose light tracing sees the non-symmetric BSDF of shading normals, and the coat's
//! non-reciprocal layering, from the other end), and each Metropolis algorithm and ERPT
//! against BDPT. Tolerances come from the spread of independent renders, and each check
//! also asserts that a 2% brightness error would fail (`assert_estimates_agree`).

mod common {
    pub mod references;
    pub mod scenes;
    pub mod stats;
    pub mod surfaces;
}

use common::references::{cached_estimate, estimate_over_seeds, render_image};
use common::scenes::canonical_camera;
use common::stats::{Estimate, assert_estimates_agree};
use common::surfaces::surfaces_mesh;
use mlt::params::ChoiceParameter;

use mlt::{
    Algorithm, AlphaMode, Backend, EnvironmentDesc, LightsDesc, Material, RenderSettings, Scene,
    SceneDesc, TexelData, TextureDesc, TextureEncoding, TextureFilter, TextureRef, WrapMode,
};
use std::borrow::Cow;

const SIZE: u32 = 32;
const MAX_DEPTH: u32 = 4;

/// `renders` independent renders of the surfaces scene with the material extensions
/// (`extensions_scene`) with `settings`.
fn estimate(settings: RenderSettings, renders: u64) -> Estimate {
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        max_depth: MAX_DEPTH,
        ..settings
    };
    estimate_over_seeds(
        &extensions_scene(),
        &canonical_camera("cornell-box"),
        &settings,
        900..900 + renders,
    )
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
    // At full resolution, as BDPT reads textures: at 32² the floor's far end is seen at a
    // footprint just above a texel (level of detail up to 0.18), which filtering would blur.
    let settings = RenderSettings {
        algorithm: Algorithm::Path,
        samples_per_pixel: 192,
        full_resolution_textures: true,
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

/// A Metropolis algorithm (or ERPT, whose camera samples are BDPT's) against BDPT; path-space
/// perturbations turning directions and microfacets, or stepping them in their samplings'
/// coordinates.
fn agrees_with_bdpt(algorithm: Algorithm, perturb_in_sample_space: bool) {
    let settings = RenderSettings {
        algorithm,
        perturb_in_sample_space,
        // ERPT's image mean spreads more here (σ 0.29% at 40, past the 0.286% a 2% error
        // needs to fail): the glossy, stretched and filmed gold block's bright paths.
        samples_per_pixel: if algorithm == Algorithm::Erpt { 64 } else { 40 },
        mutations_per_pixel: 128,
        bootstrap_samples: 1 << 16,
        chains: 256,
        ..Default::default()
    };
    assert_estimates_agree(
        &format!(
            "surfaces {algorithm:?} (perturbing in sample space: {perturb_in_sample_space}) against BDPT"
        ),
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
        agrees_with_bdpt(algorithm, false);
    }
}

/// Through the scene's glossy vertices (rough gold, rough glass) the perturbations move
/// microfacets (perturbation.rs); the short block, a rough coat over a diffuse base beside
/// a compensated metal, under a smooth clear coat, is a diffuse vertex to them or, through
/// the clear coat's mirror, a specular one.
#[test]
fn path_space_mlt_and_erpt_agree_with_bdpt() {
    for algorithm in [Algorithm::PathSpaceMlt, Algorithm::Erpt] {
        agrees_with_bdpt(algorithm, false);
    }
    agrees_with_bdpt(Algorithm::PathSpaceMlt, true);
}

/// The surfaces scene with the material extensions: clear coats (a smooth one, a Dirac
/// lobe, over the half-metal block, and a rough one with its own normal map, the checker
/// bending the coat's normal square by square, over the textured floor), sheen over a
/// rough non-metal on the red wall, a tinted, weakened specular reflection on the green
/// wall's, anisotropic microfacets (`KHR_materials_anisotropy`, along directions turned
/// from MikkTSpace's tangents) on the gold block, under a thin film (index 1.8, 300 nm),
/// and on the rough glass sphere (its refraction through the stretched microfacets). The
/// gold block stays uncoated: a glossy vertex, whose microfacets the perturbations move in
/// the stretched frame. (Alpha BLEND and volumes have scenes of their own: the blended
/// coverage tests below and tests/volume.rs.)
fn extensions_scene() -> Scene {
    let mut surfaces = surfaces_mesh();
    for m in &mut surfaces.mesh.materials {
        if m.base_color_texture.is_some() {
            *m = Material {
                kind: mlt::MaterialKind::MetallicRoughness,
                metallic: 0.0,
                roughness: 0.8,
                clearcoat: 1.0,
                clearcoat_roughness: 0.2,
                clearcoat_normal_texture: m.base_color_texture,
                clearcoat_normal_scale: 0.5,
                ..*m
            };
        } else if m.metallic == 0.5 {
            (m.clearcoat, m.clearcoat_roughness) = (0.8, 0.0);
        } else if m.kind == mlt::MaterialKind::MetallicRoughness && m.metallic == 1.0 {
            // The gold block: brushed, under a thin film.
            (m.anisotropy, m.anisotropy_rotation) = (0.9, 0.5);
            (m.iridescence, m.iridescence_ior) = (1.0, 1.8);
            m.iridescence_thickness_maximum = 300.0;
        } else if m.kind == mlt::MaterialKind::MetallicRoughness && m.transmission > 0.0 {
            // The rough glass sphere: refraction through stretched microfacets.
            (m.anisotropy, m.anisotropy_rotation) = (0.7, -1.0);
        } else if m.kind == mlt::MaterialKind::Diffuse && m.color[0] > 2.0 * m.color[1] {
            // The red wall.
            *m = Material {
                sheen_color: [0.9, 0.7, 0.6],
                sheen_roughness: 0.4,
                ..Material::metallic_roughness(m.color, 0.0, 0.7)
            };
        } else if m.kind == mlt::MaterialKind::Diffuse && m.color[1] > 2.0 * m.color[0] {
            // The green wall.
            *m = Material {
                specular: 0.6,
                specular_color: [0.5, 1.0, 0.7],
                ..Material::metallic_roughness(m.color, 0.0, 0.35)
            };
        }
    }
    surfaces.scene(Backend::Bvh)
}

/// The Cornell box with smooth coats over its blocks (metallic-roughness at roughness 0,
/// non-metal): the short block's over a red diffuse base, the tall block's over a base
/// half diffuse and half transmissive (Dirac reflection and refraction beside the diffuse
/// lobe), and the floor's over its white base. The walls have smooth clear coats (a Dirac
/// lobe beside the base's): the back one over a white non-metal of roughness 1 (its
/// diffuse base and a rough reflection), the green one over a green metal of roughness 0.3,
/// and the red one, facing it, over a red non-metal of roughness 1, so that paths also
/// bounce between two coats' mirrors. Path-space MLT and ERPT record at each such vertex
/// which lobe the path scatters through (path_space/mod.rs, "Lobes").
fn coated_box() -> mlt::Scene {
    let mut mesh = common::scenes::canonical_mesh("cornell-box");
    let coated = mesh.materials.len() as u32;
    mesh.materials
        .push(Material::metallic_roughness([0.7, 0.25, 0.15], 0.0, 0.0));
    mesh.materials.push(Material {
        transmission: 0.5,
        ..Material::metallic_roughness([0.6, 0.8, 0.9], 0.0, 0.0)
    });
    mesh.materials
        .push(Material::metallic_roughness([0.8; 3], 0.0, 0.0));
    let clear_coat = |m: Material| Material {
        clearcoat: 1.0,
        clearcoat_roughness: 0.0,
        ..m
    };
    mesh.materials.push(clear_coat(Material::metallic_roughness(
        [0.725, 0.71, 0.68],
        0.0,
        1.0,
    )));
    mesh.materials.push(clear_coat(Material::metallic_roughness(
        [0.3, 0.8, 0.35],
        1.0,
        0.3,
    )));
    mesh.materials.push(clear_coat(Material::metallic_roughness(
        [0.63, 0.065, 0.05],
        0.0,
        1.0,
    )));
    for (triangle, material) in mesh.material_ids.iter_mut().enumerate() {
        match triangle {
            0..2 => *material = coated + 2,
            4..6 => *material = coated + 3,
            6..8 => *material = coated + 4,
            8..10 => *material = coated + 5,
            10..20 => *material = coated,
            20..30 => *material = coated + 1,
            _ => {}
        }
    }
    mesh.scene()
}

/// `renders` independent renders of the coated box with `settings`.
fn coated_estimate(settings: RenderSettings, renders: u64) -> Estimate {
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        max_depth: MAX_DEPTH,
        ..settings
    };
    estimate_over_seeds(
        &coated_box(),
        &canonical_camera("cornell-box"),
        &settings,
        700..700 + renders,
    )
}

/// Path-space MLT (its perturbations turning directions, and stepping them in their
/// samplings' coordinates) and ERPT agree with BDPT on smooth coats over diffuse and
/// transmissive bases, and on smooth clear coats over a rough non-metal and a metal, two of
/// them facing each other. 16 renders each; `MLT_COATED_RENDERS` asks for more (over 512,
/// the image means were within 0.07% of BDPT's at σ 0.04%, every region within 2.7 σ, and
/// the per-render region means not skewed: the mirror-to-mirror paths have no heavy tail
/// that 16 renders would miss).
#[test]
fn path_space_mlt_and_erpt_agree_with_bdpt_on_smooth_coats() {
    let renders = std::env::var("MLT_COATED_RENDERS").map_or(16, |v| v.parse().expect("a count"));
    let bdpt = coated_estimate(
        RenderSettings {
            algorithm: Algorithm::Bdpt,
            samples_per_pixel: 48,
            ..Default::default()
        },
        renders,
    );
    for (algorithm, perturb_in_sample_space) in [
        (Algorithm::PathSpaceMlt, false),
        (Algorithm::PathSpaceMlt, true),
        (Algorithm::Erpt, false),
    ] {
        let settings = RenderSettings {
            algorithm,
            perturb_in_sample_space,
            samples_per_pixel: 40,
            mutations_per_pixel: 64,
            bootstrap_samples: 1 << 15,
            chains: 256,
            ..Default::default()
        };
        assert_estimates_agree(
            &format!(
                "coated box {algorithm:?} (perturbing in sample space: {perturb_in_sample_space}) against BDPT"
            ),
            &coated_estimate(settings, renders),
            &bdpt,
            4,
            5.0,
            6.0,
        );
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

/// A 2 × 2 m quad in the plane z = 0 facing +z, with texture coordinates running over
/// it once ((0, 0) at its top-left corner seen from +z), and a lamp behind it.
fn quad_before_a_lamp() -> (Vec<f32>, Vec<u32>, Vec<f32>) {
    #[rustfmt::skip]
    let positions = vec![
        -1.0, 1.0, 0.0,  1.0, 1.0, 0.0,  1.0, -1.0, 0.0,  -1.0, -1.0, 0.0,
        -3.0, 3.0, -1.0,  3.0, 3.0, -1.0,  3.0, -3.0, -1.0,  -3.0, -3.0, -1.0,
    ];
    let indices = vec![0, 3, 2, 0, 2, 1, 4, 7, 6, 4, 6, 5];
    #[rustfmt::skip]
    let texcoords = vec![
        0.0, 0.0,  1.0, 0.0,  1.0, 1.0,  0.0, 1.0,
        0.0, 0.0,  0.0, 0.0,  0.0, 0.0,  0.0, 0.0,
    ];
    (positions, indices, texcoords)
}

/// The quad with `materials[0]` before the lamp with `materials[1]`, and `textures`.
fn quad_before_a_lamp_scene(
    materials: &[Material; 2],
    textures: &[TextureDesc],
    backend: Backend,
) -> Scene {
    let (positions, indices, texcoords) = quad_before_a_lamp();
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &[0, 0, 1, 1],
        materials,
        texcoords: &texcoords,
        textures,
        backend,
        ..Default::default()
    })
    .unwrap()
}

/// A pinhole at z = 1 whose 90° view just covers the quad.
fn quad_camera() -> mlt::Camera {
    mlt::Camera {
        eye: [0.0, 0.0, 1.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 90.0,
        ..Default::default()
    }
}

/// An alpha cut-out lets camera rays through where its texture's alpha is below the
/// cutoff, in every backend: a black quad whose 2 × 2 alpha texture opens its top-left
/// and bottom-right quarters shows the lamp behind exactly there. Without the cut-out (or
/// with the texture's orientation wrong) whole quarters would be black or lit.
#[test]
fn alpha_cut_outs_let_rays_through_in_every_backend() {
    // Grey + alpha, 8-bit: alpha 0 (a hole) on the diagonal.
    let texture = TextureDesc {
        width: 2,
        height: 2,
        channels: 2,
        data: TexelData::U8(Cow::Owned(vec![255, 0, 255, 255, 255, 255, 255, 0])),
        encoding: TextureEncoding::Linear,
        wrap_u: WrapMode::ClampToEdge,
        wrap_v: WrapMode::ClampToEdge,
        filter: TextureFilter::Nearest,
    };
    let materials = [
        Material {
            alpha_mode: AlphaMode::Mask,
            base_color_texture: Some(TextureRef::new(0)),
            ..Material::diffuse([0.0; 3])
        },
        Material::diffuse([0.0; 3]).with_emission([1.0; 3]),
    ];
    for backend in [Backend::Bvh, Backend::Embree] {
        if !backend.is_available() {
            continue;
        }
        let scene = quad_before_a_lamp_scene(&materials, std::slice::from_ref(&texture), backend);
        let settings = RenderSettings {
            width: 8,
            height: 8,
            algorithm: Algorithm::Path,
            samples_per_pixel: 4,
            max_depth: 2,
            ..Default::default()
        };
        let image = render_image(&scene, &quad_camera(), &settings);
        // Pixels away from the quarters' edges (columns and rows 3 and 4).
        for y in [0usize, 1, 2, 5, 6, 7] {
            for x in [0usize, 1, 2, 5, 6, 7] {
                let hole = (x < 4) == (y < 4);
                let value = image[(y * 8 + x) * 3];
                let expected = if hole { 1.0 } else { 0.0 };
                assert!(
                    (value - expected).abs() < 1e-4,
                    "{backend:?}: pixel ({x}, {y}) is {value}, expected {expected}"
                );
            }
        }
    }
}

/// Blended alpha is stochastic coverage: a black 8 × 8 m quad of alpha 0.3
/// (`AlphaMode::Blend`) at z = 0 before a diffuse plane (albedo 0.8) at z = −1, lit by a sun
/// of irradiance π through the quad. Sunlight crosses the quad once to reach the plane and
/// once more on its way to the camera, each time at another point, so the camera sees
/// 0.7 × 0.7 × 0.8 cos θ (θ the sun's angle): in every algorithm (camera paths and light
/// paths crossing it, connections through it) and every backend. Each estimate comes from
/// 16 independent renders (the spread of their means gives its standard error, valid for
/// Markov chains too), and each check would fail a 2% error by two more standard errors.
#[test]
fn alpha_blend_lets_one_minus_alpha_through_in_every_algorithm_and_backend() {
    #[rustfmt::skip]
    let positions = [
        -4.0, 4.0, 0.0,  4.0, 4.0, 0.0,  4.0, -4.0, 0.0,  -4.0, -4.0, 0.0,
        -8.0, 8.0, -1.0,  8.0, 8.0, -1.0,  8.0, -8.0, -1.0,  -8.0, -8.0, -1.0,
    ];
    let indices = [0, 3, 2, 0, 2, 1, 4, 7, 6, 4, 6, 5];
    let materials = [
        Material {
            alpha_mode: AlphaMode::Blend,
            alpha: 0.3,
            ..Material::diffuse([0.0; 3])
        },
        Material::diffuse([0.8; 3]),
    ];
    let sun = [0.5f32, 0.0, 1.0];
    let cos_sun = 1.0 / (1.0f64 + 0.25).sqrt();
    let truth = 0.7 * 0.7 * 0.8 * cos_sun;
    for backend in [Backend::Bvh, Backend::Embree] {
        if !backend.is_available() {
            continue;
        }
        let scene = Scene::new(&SceneDesc {
            positions: &positions,
            indices: &indices,
            material_ids: &[0, 0, 1, 1],
            materials: &materials,
            lights: mlt::LightsDesc {
                sun: Some(mlt::SunDesc {
                    direction: sun,
                    angular_radius_degrees: 0.0,
                    irradiance: [std::f32::consts::PI; 3],
                }),
                ..Default::default()
            },
            backend,
            ..Default::default()
        })
        .unwrap();
        every_algorithm_meets(
            &format!("through alpha 0.3 with {backend:?}"),
            (&scene, &quad_camera()),
            truth,
            6.0,
            |algorithm| RenderSettings {
                width: 16,
                height: 16,
                algorithm,
                samples_per_pixel: 128,
                mutations_per_pixel: 64,
                bootstrap_samples: 1 << 16,
                chains: 64,
                // The chains render every path, the direct light too.
                direct_samples_per_mutation: 0,
                max_depth: 2,
                seed: 4500,
                ..Default::default()
            },
        );
    }
}

/// An emissive blended quad emits only where it is a surface: a lamp of radiance 1 and
/// alpha 0.3 (8 × 8 m, at z = 0, emitting downwards) over a diffuse floor (albedo 0.8) 1 m
/// below, seen at 9.5° from the side through a 0.5° view under the lamp. The floor's
/// radiance is 0.8 × 0.3 × F, F the form factor from the floor's centre to the whole quad
/// (four corner rectangles of 4 × 4 m at height 1, in closed form): coverage takes 0.7 of
/// the lamp away for light samples as for rays that hit it. Light sampling that ignored
/// alpha would give 0.8 F there (2.7 times as bright) in the strategies that sample the
/// lamp. Every algorithm, 16 independent renders each (the spread of their means gives the
/// standard error, valid for Markov chains too); each check would fail a 2% error by two
/// more standard errors.
#[test]
fn an_emissive_blended_surface_emits_only_where_it_is() {
    #[rustfmt::skip]
    let positions = [
        -4.0, 4.0, 0.0,  4.0, 4.0, 0.0,  4.0, -4.0, 0.0,  -4.0, -4.0, 0.0,
        -8.0, 8.0, -1.0,  8.0, 8.0, -1.0,  8.0, -8.0, -1.0,  -8.0, -8.0, -1.0,
    ];
    // The lamp wound clockwise seen from above (its front faces −z), the floor
    // counter-clockwise (+z).
    let indices = [0, 1, 2, 0, 2, 3, 4, 7, 6, 4, 6, 5];
    let materials = [
        Material {
            alpha_mode: AlphaMode::Blend,
            alpha: 0.3,
            ..Material::diffuse([0.0; 3]).with_emission([1.0; 3])
        },
        Material::diffuse([0.8; 3]),
    ];
    let corner = |a: f64, b: f64| {
        let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
        (a / ra * (b / ra).atan() + b / rb * (a / rb).atan()) / (2.0 * std::f64::consts::PI)
    };
    let truth = 0.8 * 0.3 * 4.0 * corner(4.0, 4.0);
    let scene = Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &[0, 0, 1, 1],
        materials: &materials,
        ..Default::default()
    })
    .unwrap();
    let camera = mlt::Camera {
        eye: [6.0, 0.0, -0.0],
        target: [0.0, 0.0, -1.0],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 0.5,
        ..Default::default()
    };
    every_algorithm_meets(
        "under an emissive alpha 0.3",
        (&scene, &camera),
        truth,
        4.0,
        |algorithm| RenderSettings {
            width: 8,
            height: 8,
            algorithm,
            samples_per_pixel: 256,
            mutations_per_pixel: 256,
            bootstrap_samples: 1 << 14,
            chains: 64,
            direct_samples_per_mutation: 0,
            max_depth: 1,
            seed: 4600,
            ..Default::default()
        },
    );
}

/// Asserts that every algorithm's image mean (red) with `settings(algorithm)` is within
/// `sigmas` standard errors of `truth`, and sharp enough to fail a 2% error. Each algorithm
/// renders 16 times, from its settings' seed on: the spread of the renders' means gives
/// the standard error, valid for Markov chains too.
fn every_algorithm_meets(
    label: &str,
    (scene, camera): (&Scene, &mlt::Camera),
    truth: f64,
    sigmas: f64,
    settings: impl Fn(Algorithm) -> RenderSettings,
) {
    for &algorithm in Algorithm::ALL {
        let settings = settings(algorithm);
        let estimate =
            estimate_over_seeds(scene, camera, &settings, settings.seed..settings.seed + 16);
        let (mean, variance) = estimate.mean();
        common::stats::assert_within_and_sharp(
            &format!("{algorithm:?} {label}"),
            mean[0],
            truth,
            variance[0].sqrt(),
            sigmas,
        );
    }
}

/// A texture reads the texture coordinate set its `TextureRef::texcoord` names: a lamp quad
/// whose emission texture is black at set 0's coordinates and white at set 1's renders
/// black or white by the set, with either backend's hits; and a reference to set 1 without
/// `texcoords1`, or to set 2, is refused by name.
#[test]
fn a_texture_reads_the_texture_coordinate_set_it_names() {
    let (positions, indices, _) = quad_before_a_lamp();
    let (positions, indices) = (&positions[..12], &indices[..6]);
    // Texel 0 black, texel 1 white; set 0 inside texel 0, set 1 inside texel 1.
    let texture = TextureDesc {
        width: 2,
        height: 1,
        channels: 1,
        data: TexelData::U8(Cow::Owned(vec![0, 255])),
        encoding: TextureEncoding::Linear,
        wrap_u: WrapMode::ClampToEdge,
        wrap_v: WrapMode::ClampToEdge,
        filter: TextureFilter::Nearest,
    };
    let set0 = [0.1, 0.5, 0.3, 0.2, 0.4, 0.9, 0.2, 0.6];
    let set1 = [0.6, 0.5, 0.8, 0.2, 0.9, 0.9, 0.7, 0.6];
    let lamp = |texcoord| {
        [Material {
            emission_texture: Some(TextureRef {
                texcoord,
                ..TextureRef::new(0)
            }),
            ..Material::diffuse([0.0; 3]).with_emission([1.0; 3])
        }]
    };
    let settings = RenderSettings {
        width: 4,
        height: 4,
        algorithm: Algorithm::Path,
        samples_per_pixel: 1,
        max_depth: 0,
        ..Default::default()
    };
    for backend in [Backend::Bvh, Backend::Embree] {
        if !backend.is_available() {
            continue;
        }
        for (texcoord, expected) in [(0, 0.0), (1, 1.0)] {
            let materials = lamp(texcoord);
            let scene = Scene::new(&SceneDesc {
                positions,
                indices,
                materials: &materials,
                texcoords: &set0,
                texcoords1: &set1,
                textures: std::slice::from_ref(&texture),
                backend,
                ..Default::default()
            })
            .unwrap();
            let image = render_image(&scene, &quad_camera(), &settings);
            assert!(
                image.iter().all(|&v| (v - expected).abs() < 1e-5),
                "{backend:?}, set {texcoord}: {image:?}"
            );
        }
    }
    let refused = |texcoord, texcoords1: &[f32]| {
        let materials = lamp(texcoord);
        Scene::new(&SceneDesc {
            positions,
            indices,
            materials: &materials,
            texcoords: &set0,
            texcoords1,
            textures: std::slice::from_ref(&texture),
            ..Default::default()
        })
        .err()
        .expect("refused")
        .to_string()
    };
    let error = refused(1, &[]);
    assert!(
        error.contains("emission_texture") && error.contains("texcoords1"),
        "{error}"
    );
    let error = refused(2, &set1);
    assert!(error.contains("texcoord is 2"), "{error}");
}

/// A normal map bends the shading normal exactly as normals baked into the vertices
/// would: the quad with a one-texel normal map (and given tangents) renders as the quad
/// whose vertex normals are that texel's normal in world space, under a sun at a grazing
/// angle that makes shading depend strongly on the normal; and differs from the flat quad.
#[test]
fn a_normal_map_shades_like_its_normal_baked_into_the_vertices() {
    let (positions, indices, texcoords) = quad_before_a_lamp();
    let positions = positions[..12].to_vec();
    let indices = indices[..6].to_vec();
    let texcoords = texcoords[..8].to_vec();
    let texel = [200u8, 90, 220];
    // Tangent space: x along +u (world +x), y up the image (world +y: v grows downwards,
    // towards −y), z the normal (+z).
    let [x, y, z] = texel.map(|c| c as f32 / 255.0 * 2.0 - 1.0);
    let length = (x * x + y * y + z * z).sqrt();
    let baked = [x / length, y / length, z / length];
    let tangents: Vec<f32> = [1.0, 0.0, 0.0, 1.0].repeat(4);
    let normal_map = TextureDesc {
        width: 1,
        height: 1,
        channels: 3,
        data: TexelData::U8(Cow::Owned(texel.to_vec())),
        encoding: TextureEncoding::Linear,
        wrap_u: WrapMode::Repeat,
        wrap_v: WrapMode::Repeat,
        filter: TextureFilter::Nearest,
    };
    let mapped = [Material {
        normal_texture: Some(TextureRef::new(0)),
        ..Material::diffuse([0.8; 3])
    }];
    let plain = [Material::diffuse([0.8; 3])];
    let lights = mlt::LightsDesc {
        sun: Some(mlt::SunDesc {
            direction: [-1.0, 0.3, 0.4],
            angular_radius_degrees: 0.0,
            irradiance: [1.0; 3],
        }),
        ..Default::default()
    };
    let settings = RenderSettings {
        width: 8,
        height: 8,
        algorithm: Algorithm::Path,
        samples_per_pixel: 4,
        max_depth: 1,
        ..Default::default()
    };
    let render =
        |desc: SceneDesc| render_image(&Scene::new(&desc).unwrap(), &quad_camera(), &settings);
    let base = SceneDesc {
        positions: &positions,
        indices: &indices,
        lights,
        ..Default::default()
    };
    let normal_mapped = render(SceneDesc {
        materials: &mapped,
        texcoords: &texcoords,
        tangents: &tangents,
        textures: std::slice::from_ref(&normal_map),
        ..base
    });
    let baked_normals: Vec<f32> = baked.repeat(4);
    let baked = render(SceneDesc {
        materials: &plain,
        normals: &baked_normals,
        ..base
    });
    let flat = render(SceneDesc {
        materials: &plain,
        ..base
    });
    for (i, (m, b)) in normal_mapped.iter().zip(&baked).enumerate() {
        assert!(
            (m - b).abs() <= 1e-4 * b.abs().max(1.0),
            "float {i}: mapped {m}, baked {b}"
        );
    }
    let (mapped_mean, flat_mean) = (
        common::stats::mean(&normal_mapped)[0],
        common::stats::mean(&flat)[0],
    );
    assert!(
        (mapped_mean - flat_mean).abs() > 0.2 * flat_mean,
        "the map changes nothing: {mapped_mean} against {flat_mean} flat"
    );
}

/// A transmission texture's red channel multiplies the transmission: a quad of
/// transmission 1 under a texture of 0.25 renders bit for bit as one of transmission 0.25
/// under a texture of 1, and lets through about a quarter of the lamp light behind it that
/// the untextured quad of transmission 1 lets through.
#[test]
fn a_transmission_texture_multiplies_the_transmission() {
    let grey = |value: f32| TextureDesc {
        width: 1,
        height: 1,
        channels: 1,
        data: TexelData::F32(Cow::Owned(vec![value])),
        encoding: TextureEncoding::Linear,
        wrap_u: WrapMode::Repeat,
        wrap_v: WrapMode::Repeat,
        filter: TextureFilter::Nearest,
    };
    let textures = [grey(0.25), grey(1.0)];
    let glass = |transmission: f32, texture: Option<u32>| Material {
        transmission,
        transmission_texture: texture.map(TextureRef::new),
        ..Material::metallic_roughness([1.0; 3], 0.0, 0.2)
    };
    let lamp = Material::diffuse([0.0; 3]).with_emission([1.0; 3]);
    let settings = RenderSettings {
        width: 8,
        height: 8,
        algorithm: Algorithm::Path,
        samples_per_pixel: 16,
        max_depth: 2,
        ..Default::default()
    };
    let render = |quad: Material| {
        let scene = quad_before_a_lamp_scene(&[quad, lamp], &textures, Backend::Bvh);
        render_image(&scene, &quad_camera(), &settings)
    };
    let quarter_by_texture = render(glass(1.0, Some(0)));
    let quarter_by_factor = render(glass(0.25, Some(1)));
    assert_eq!(quarter_by_texture, quarter_by_factor);
    let full = render(glass(1.0, None));
    let ratio = common::stats::mean(&quarter_by_texture)[0] / common::stats::mean(&full)[0];
    assert!((0.2..0.3).contains(&ratio), "{ratio}");
}

/// A ground plane far into the distance under a constant white sky, its base colour a
/// 512 × 512 checker of single texels (linear bytes 0 and 200, so every mip level holds
/// their mean exactly; sampled nearest, sharp), tiling every 2 units: from a pinhole 1 above it every pixel covers
/// many texels. Direct light only.
fn distant_checker_plane() -> Scene {
    #[rustfmt::skip]
    let positions = [
        -60.0, 0.0, -120.0,  60.0, 0.0, -120.0,  60.0, 0.0, 2.0,  -60.0, 0.0, 2.0,
    ];
    let texcoords: Vec<f32> = positions
        .chunks_exact(3)
        .flat_map(|p| [p[0] / 2.0, p[2] / 2.0])
        .collect();
    let texels: Vec<u8> = (0..512 * 512)
        .map(|i| if (i % 512 + i / 512) % 2 == 0 { 0 } else { 200 })
        .collect();
    let texture = TextureDesc {
        width: 512,
        height: 512,
        channels: 1,
        data: TexelData::U8(Cow::Owned(texels)),
        encoding: TextureEncoding::Linear,
        wrap_u: WrapMode::Repeat,
        wrap_v: WrapMode::Repeat,
        filter: TextureFilter::Nearest,
    };
    let materials = [Material {
        base_color_texture: Some(TextureRef::new(0)),
        ..Material::diffuse([1.0; 3])
    }];
    static SKY: [f32; 3] = [1.0; 3];
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &[0, 2, 1, 0, 3, 2],
        materials: &materials,
        texcoords: &texcoords,
        textures: std::slice::from_ref(&texture),
        lights: LightsDesc {
            environment: Some(EnvironmentDesc::constant(&SKY)),
            ..Default::default()
        },
        backend: Backend::Bvh,
        ..Default::default()
    })
    .unwrap()
}

/// Texture filtering: at 4 samples per pixel the path tracer's image of the distant checker
/// plane is much closer to the converged image (the unfiltered path tracer at 256 samples)
/// with its camera rays' cones than without (where each sample reads one black or light
/// texel; 0.03 against 0.15), and filtering keeps the image's mean (the pyramid keeps the texture's): the
/// filtered mean at 64 samples agrees with the converged one within 4 standard errors,
/// sharp enough to fail a 2% error.
#[test]
fn texture_filtering_removes_the_aliasing_of_a_distant_checker_and_keeps_its_mean() {
    let scene = distant_checker_plane();
    let camera = mlt::Camera {
        eye: [0.0, 1.0, 0.0],
        target: [0.0, 0.6, -10.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 40.0,
        ..Default::default()
    };
    let render = |samples_per_pixel, full_resolution_textures, seed| {
        render_image(
            &scene,
            &camera,
            &RenderSettings {
                algorithm: Algorithm::Path,
                width: SIZE,
                height: SIZE,
                max_depth: 1,
                samples_per_pixel,
                full_resolution_textures,
                seed,
                ..Default::default()
            },
        )
    };
    let converged = render(256, true, 1);
    let filtered = common::stats::rmse(&render(4, false, 2), &converged);
    let unfiltered = common::stats::rmse(&render(4, true, 2), &converged);
    println!("RMSE at 4 samples: {filtered} filtered, {unfiltered} at full resolution");
    assert!(
        filtered < 0.4 * unfiltered,
        "RMSE at 4 samples: {filtered} filtered, {unfiltered} at full resolution"
    );
    // The mean of the per-pixel differences, pixels being independent samples.
    let filtered = render(64, false, 3);
    let differences: Vec<f32> = filtered
        .iter()
        .zip(&converged)
        .map(|(f, c)| f - c)
        .collect();
    let (difference, error) = common::stats::mean_and_standard_error(&differences);
    let (mean, _) = common::stats::mean_and_standard_error(&converged);
    common::stats::assert_within_and_sharp(
        "filtered image's mean against the converged one",
        mean[1] + difference[1],
        mean[1],
        error[1],
        4.0,
    );
}
