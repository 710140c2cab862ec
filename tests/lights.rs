//! Lights beyond emissive triangles (environment, sun, point, spot and directional lights)
//! against closed forms, for every algorithm that supports them: a convex diffuse sphere
//! under a constant environment, and a diffuse plane under a constant sky, a sun at several
//! elevations (delta and disc), a point and a spot light. Then the algorithms against each
//! other on two scenes: the window room (tests/common/window_room.rs: sky and sun through a
//! small window) and the Cornell box lit by a spot light and the sun through its open
//! front. Tolerances come from the spread of independent renders (Student's t with their
//! degrees of freedom), and each check also asserts that a 2% brightness error would fail.
//!
//! Runs in about 64 s on 2 cores (`cargo test --test lights`).

mod common {
    pub mod obj_text;
    pub mod references;
    pub mod scenes;
    pub mod stats;
    pub mod window_room;
}

use common::references::{cached_estimate, render_image};
use common::scenes::{Mesh, canonical_camera, canonical_mesh, inward_icosphere};
use common::stats::{Estimate, assert_estimates_agree};
use common::window_room;

use mlt::params::ChoiceParameter;
use mlt::{
    Algorithm, Backend, Camera, EnvironmentDesc, LightsDesc, Material, PunctualLight,
    RenderSettings, Scene, SunDesc,
};
use std::f64::consts::PI;

const SIZE: u32 = 16;
const RENDERS: u64 = 8;

/// Settings for a small render. The Metropolis algorithms run without the direct pass,
/// so that their chains carry every path (here all paths are short).
/// `effort` multiplies the samples and mutations.
fn settings(algorithm: Algorithm, max_depth: u32, seed: u64, effort: u32) -> RenderSettings {
    RenderSettings {
        width: SIZE,
        height: SIZE,
        algorithm,
        samples_per_pixel: 32 * effort,
        mutations_per_pixel: 64 * effort,
        bootstrap_samples: 1 << 15,
        chains: 64,
        direct_samples_per_mutation: 0,
        max_depth,
        seed,
        threads: 1,
        ..Default::default()
    }
}

/// Asserts that the image mean of `RENDERS` independent renders is `truth` per channel.
fn assert_renders_match(
    label: &str,
    mesh: &Mesh,
    lights: LightsDesc,
    camera: &Camera,
    max_depth: u32,
    truth: [f64; 3],
) {
    assert_renders_match_with_effort(label, mesh, lights, camera, max_depth, truth, 1);
}

/// `assert_renders_match` with `effort` times the samples and mutations.
fn assert_renders_match_with_effort(
    label: &str,
    mesh: &Mesh,
    lights: LightsDesc,
    camera: &Camera,
    max_depth: u32,
    truth: [f64; 3],
    effort: u32,
) {
    let scene = mesh.scene_lit(Backend::Bvh, lights);
    for &algorithm in Algorithm::ALL {
        let renders: Vec<Vec<f32>> = (0..RENDERS)
            .map(|seed| {
                render_image(
                    &scene,
                    camera,
                    &settings(algorithm, max_depth, 100 + seed, effort),
                )
            })
            .collect();
        let estimate = Estimate::from_correlated_renders(SIZE as usize, SIZE as usize, &renders);
        let (mean, variance) = estimate.mean();
        for c in 0..3 {
            // 8 renders: 7 degrees of freedom; P(|t| > 6) = 9·10⁻⁴ per comparison. Plus
            // 10⁻³ for what is not noise: the light's variation over the patch a pixel sees
            // and single-precision rounding (delta lights seen by the path tracer have
            // next to no noise).
            let error = variance[c].sqrt();
            let tolerance = 6.0 * error + 1e-3 * truth[c];
            let label = format!("{label} {algorithm:?} channel {c}");
            assert!(
                (mean[c] - truth[c]).abs() <= tolerance,
                "{label}: {} vs {} ± {tolerance}",
                mean[c],
                truth[c]
            );
            assert!(
                tolerance + 2.0 * error <= 0.02 * truth[c],
                "{label}: a 2% error would not reliably fail (tolerance {tolerance}, standard error {error})"
            );
        }
    }
}

/// A diffuse icosphere of radius 1 at the origin, facing outward.
fn outward_sphere(albedo: [f32; 3]) -> Mesh {
    let (positions, indices) = inward_icosphere(2, 1.0);
    let indices = indices
        .chunks_exact(3)
        .flat_map(|t| [t[0], t[2], t[1]])
        .collect();
    Mesh {
        positions,
        indices,
        material_ids: Vec::new(),
        materials: vec![Material::diffuse(albedo)],
    }
}

/// Looks at the sphere from 3 units away with a field of view that the sphere fills.
fn sphere_camera() -> Camera {
    Camera {
        eye: [0.3, 0.4, 3.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 15.0,
        ..Camera::default()
    }
}

/// A convex surface under a constant environment sees the environment over its whole upper
/// hemisphere and nothing of itself: its radiance is albedo × L at every depth limit, and
/// with albedo 1 (the red channel) it equals the environment's.
#[test]
fn convex_sphere_under_a_constant_environment() {
    let albedo = [1.0, 0.7, 0.4];
    let radiance = [0.8, 1.0, 2.5];
    let mesh = outward_sphere(albedo);
    let lights = LightsDesc {
        environment: Some(EnvironmentDesc::constant(&radiance)),
        ..Default::default()
    };
    for depth in [1, 4] {
        let truth = std::array::from_fn(|c| (albedo[c] * radiance[c]) as f64);
        assert_renders_match(
            &format!("sphere depth {depth}"),
            &mesh,
            lights,
            &sphere_camera(),
            depth,
            truth,
        );
    }
}

/// A 2 × 2 diffuse square in the plane y = 0, facing +y. (Its size does not matter to
/// the light it gets, but lights at infinity are picked by their power on the scene's
/// bounding sphere: a larger plane would starve the spot of samples.)
fn plane(albedo: [f32; 3]) -> Mesh {
    let h = 1.0;
    Mesh {
        positions: vec![-h, 0.0, -h, h, 0.0, -h, h, 0.0, h, -h, 0.0, h],
        indices: vec![0, 2, 1, 0, 3, 2],
        material_ids: Vec::new(),
        materials: vec![Material::diffuse(albedo)],
    }
}

/// Looks straight down at the origin from height 1, seeing a patch 3.5 cm across: every
/// light below is evaluated at the origin to better than 10⁻³.
fn plane_camera() -> Camera {
    Camera {
        eye: [0.0, 1.0, 0.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 2.0,
        ..Camera::default()
    }
}

const PLANE_ALBEDO: [f32; 3] = [0.8, 0.5, 0.3];

/// The radiance of the diffuse plane under irradiance `e`: albedo · E / π.
fn lambert(e: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|c| PLANE_ALBEDO[c] as f64 * e[c] / PI)
}

#[test]
fn plane_under_a_constant_sky() {
    let radiance = [1.0, 2.0, 0.5];
    let lights = LightsDesc {
        environment: Some(EnvironmentDesc::constant(&radiance)),
        ..Default::default()
    };
    // E = π L over the upper hemisphere.
    let truth = lambert(radiance.map(|l| PI * l as f64));
    assert_renders_match(
        "sky",
        &plane(PLANE_ALBEDO),
        lights,
        &plane_camera(),
        3,
        truth,
    );
}

/// A sun at elevation h gives irradiance E sin h, a delta direction and a disc alike (the
/// cosine over a spherical cap above the horizon integrates exactly to its centre's).
#[test]
fn plane_under_the_sun_at_several_elevations() {
    let irradiance = [3.0, 2.0, 1.0];
    for (elevation, radius) in [(90.0f64, 0.0), (35.0, 0.0), (60.0, 0.27), (20.0, 5.0)] {
        let (sin, cos) = elevation.to_radians().sin_cos();
        let sun = SunDesc {
            direction: [(cos * 0.6) as f32, sin as f32, (cos * 0.8) as f32],
            angular_radius_degrees: radius,
            irradiance,
        };
        let lights = LightsDesc {
            sun: Some(sun),
            ..Default::default()
        };
        let truth = lambert(irradiance.map(|e| e as f64 * sin));
        assert_renders_match(
            &format!("sun at {elevation}° radius {radius}°"),
            &plane(PLANE_ALBEDO),
            lights,
            &plane_camera(),
            2,
            truth,
        );
    }
}

/// A point light at height 2 above the origin: E = I / d².
#[test]
fn plane_under_a_point_light() {
    let intensity = [4.0, 8.0, 2.0];
    let light = [PunctualLight::point([0.0, 2.0, 0.0], intensity)];
    let lights = LightsDesc {
        punctual: &light,
        ..Default::default()
    };
    let truth = lambert(intensity.map(|i| i as f64 / 4.0));
    assert_renders_match(
        "point light",
        &plane(PLANE_ALBEDO),
        lights,
        &plane_camera(),
        2,
        truth,
    );
}

/// A spot above the origin, tilted so that the origin is 25° off its axis, between the
/// inner (15°) and outer (35°) cone: glTF's falloff ((cos ψ − cos outer) / (cos inner −
/// cos outer))², times I / d².
#[test]
fn plane_under_a_spot_light() {
    let intensity = [6.0, 3.0, 9.0];
    let tilt = 25f64.to_radians();
    let axis = [tilt.sin() as f32, -tilt.cos() as f32, 0.0];
    let spot = [PunctualLight::spot(
        [0.0, 2.0, 0.0],
        axis,
        intensity,
        15.0,
        35.0,
    )];
    let (inner, outer) = (15f64.to_radians().cos(), 35f64.to_radians().cos());
    let falloff = ((tilt.cos() - outer) / (inner - outer)).powi(2);
    let lights = LightsDesc {
        punctual: &spot,
        ..Default::default()
    };
    let truth = lambert(intensity.map(|i| i as f64 * falloff / 4.0));
    assert_renders_match(
        "spot",
        &plane(PLANE_ALBEDO),
        lights,
        &plane_camera(),
        2,
        truth,
    );
}

/// A directional light from straight above and a point light, picked between by power:
/// their irradiances add. (The point light hangs where its power on the scene, 4 I, over
/// its irradiance, I / d², equals the directional light's, E R² over E, for the plane's
/// bounding radius R ≈ 1.43: light selection then adds no noise, and a wrong selection
/// probability still shows as a wrong brightness.)
#[test]
fn plane_under_a_directional_and_a_point_light() {
    let colour = [0.5, 0.25, 0.75];
    let height = 0.714f32;
    let list = [
        PunctualLight::directional([0.0, -1.0, 0.0], colour),
        PunctualLight::point(
            [0.0, height, 0.0],
            colour.map(|c| 2.0 * c * height * height),
        ),
    ];
    let lights = LightsDesc {
        punctual: &list,
        ..Default::default()
    };
    let truth = lambert(colour.map(|c| 3.0 * c as f64));
    assert_renders_match(
        "directional and point",
        &plane(PLANE_ALBEDO),
        lights,
        &plane_camera(),
        2,
        truth,
    );
}

/// The window room under its sky map and sun.
fn window_room_scene() -> (Scene, Camera) {
    let mesh = canonical_mesh("window-room");
    let sky = window_room::sky_pixels();
    let lights = window_room::lights(&sky);
    (
        mesh.scene_lit(Backend::Bvh, lights),
        canonical_camera("window-room"),
    )
}

/// The Cornell box with its ceiling lamp off, lit by a spot under the ceiling aimed at the
/// tall block and by a sun disc shining in through the open front.
fn spot_and_sun_box() -> (Scene, Camera) {
    let mut mesh = canonical_mesh("cornell-box");
    for material in &mut mesh.materials {
        material.emission = [0.0; 3];
    }
    let spot = [PunctualLight::spot(
        [278.0, 530.0, 280.0],
        [0.2, -1.0, 0.25],
        [2.0e5, 1.8e5, 1.5e5],
        20.0,
        40.0,
    )];
    let lights = LightsDesc {
        sun: Some(SunDesc {
            direction: [-0.25, 0.6, -1.0],
            angular_radius_degrees: 1.0,
            irradiance: [1.0, 0.95, 0.85],
        }),
        punctual: &spot,
        ..Default::default()
    };
    (
        mesh.scene_lit(Backend::Bvh, lights),
        canonical_camera("cornell-box"),
    )
}

/// The glTF spheres under the window room's sky and sun.
fn sky_spheres_scene() -> (Scene, Camera) {
    let data = mlt::io::load_scene(&common::scenes::scenes_dir().join("sky-spheres.gltf")).unwrap();
    let sky = window_room::sky_pixels();
    let mut desc = data.desc(Backend::Bvh);
    desc.lights = window_room::lights(&sky);
    (Scene::new(&desc).unwrap(), data.camera.unwrap().camera)
}

const AGREEMENT_SIZE: u32 = 32;

fn lit_scene(name: &str) -> (Scene, Camera) {
    match name {
        "window-room" => window_room_scene(),
        "spot-and-sun" => spot_and_sun_box(),
        "sky-spheres" => sky_spheres_scene(),
        _ => unreachable!(),
    }
}

/// `renders` independent renders of a lit scene with `settings` (size and seed set here).
fn lit_estimate(name: &str, settings: RenderSettings, renders: u64) -> Estimate {
    let (scene, camera) = lit_scene(name);
    let images: Vec<Vec<f32>> = (0..renders)
        .map(|seed| {
            let settings = RenderSettings {
                width: AGREEMENT_SIZE,
                height: AGREEMENT_SIZE,
                seed: 500 + seed,
                ..settings
            };
            render_image(&scene, &camera, &settings)
        })
        .collect();
    let size = AGREEMENT_SIZE as usize;
    Estimate::from_correlated_renders(size, size, &images)
}

/// Work per pixel for a lit scene: the window room's image is mostly light after bounces,
/// and needs more for a 2% error to be resolvable.
fn effort(name: &str) -> u32 {
    if name == "window-room" { 2 } else { 1 }
}

/// BDPT's estimate of a lit scene (16 renders at max depth 5), once per test binary: the
/// reference of the Metropolis algorithms, itself checked against the path tracer.
fn bdpt_reference(name: &str) -> &'static Estimate {
    cached_estimate(&format!("bdpt {name}"), || {
        let settings = RenderSettings {
            algorithm: Algorithm::Bdpt,
            samples_per_pixel: 64 * effort(name),
            max_depth: 5,
            ..Default::default()
        };
        lit_estimate(name, settings, 16)
    })
}

fn bdpt_agrees_with_the_path_tracer(name: &str) {
    let settings = RenderSettings {
        algorithm: Algorithm::Path,
        samples_per_pixel: 256 * effort(name),
        max_depth: 5,
        ..Default::default()
    };
    let path = lit_estimate(name, settings, 16);
    assert_estimates_agree(
        &format!("{name} BDPT against the path tracer"),
        bdpt_reference(name),
        &path,
        4,
        5.0,
        6.0,
    );
}

/// A Metropolis algorithm (or ERPT, whose camera samples are BDPT's) against BDPT.
fn metropolis_agrees_with_bdpt(name: &str, algorithm: Algorithm) {
    let settings = RenderSettings {
        algorithm,
        samples_per_pixel: 40 * effort(name),
        mutations_per_pixel: 128 * effort(name),
        bootstrap_samples: 1 << 16,
        chains: 256,
        max_depth: 5,
        ..Default::default()
    };
    let test = lit_estimate(name, settings, 16);
    assert_estimates_agree(
        &format!("{name} {algorithm:?} against BDPT"),
        &test,
        bdpt_reference(name),
        4,
        5.0,
        6.0,
    );
}

#[test]
fn window_room_bdpt_agrees_with_the_path_tracer() {
    bdpt_agrees_with_the_path_tracer("window-room");
}

#[test]
fn spot_and_sun_bdpt_agrees_with_the_path_tracer() {
    bdpt_agrees_with_the_path_tracer("spot-and-sun");
}

#[test]
fn window_room_primary_space_metropolis_agrees_with_bdpt() {
    for algorithm in [Algorithm::Pssmlt, Algorithm::PssmltBdpt, Algorithm::Mmlt] {
        metropolis_agrees_with_bdpt("window-room", algorithm);
    }
}

#[test]
fn spot_and_sun_primary_space_metropolis_agrees_with_bdpt() {
    for algorithm in [Algorithm::Pssmlt, Algorithm::PssmltBdpt, Algorithm::Mmlt] {
        metropolis_agrees_with_bdpt("spot-and-sun", algorithm);
    }
}

#[test]
fn window_room_path_space_mlt_and_erpt_agree_with_bdpt() {
    for algorithm in [Algorithm::PathSpaceMlt, Algorithm::Erpt] {
        metropolis_agrees_with_bdpt("window-room", algorithm);
    }
}

#[test]
fn spot_and_sun_path_space_mlt_and_erpt_agree_with_bdpt() {
    for algorithm in [Algorithm::PathSpaceMlt, Algorithm::Erpt] {
        metropolis_agrees_with_bdpt("spot-and-sun", algorithm);
    }
}

/// Writes the lit scenes' BDPT references as images, for looking at (`MLT_WRITE_LIT=DIR`).
#[test]
fn write_lit_scene_images() {
    let Some(dir) = std::env::var_os("MLT_WRITE_LIT") else {
        return;
    };
    for name in ["window-room", "spot-and-sun", "sky-spheres"] {
        let (scene, camera) = lit_scene(name);
        let settings = RenderSettings {
            width: 256,
            height: 256,
            algorithm: Algorithm::Bdpt,
            samples_per_pixel: 64,
            ..Default::default()
        };
        let image = render_image(&scene, &camera, &settings);
        mlt::io::write_png(
            &std::path::Path::new(&dir).join(format!("{name}.png")),
            256,
            256,
            &image,
        )
        .unwrap();
    }
}
