//! A diffuse floor under a square area light: the radiance of the floor point below the
//! light's centre is ρ·Le·F, with F the analytic point-to-parallel-rectangle form factor.
//! This checks light sampling (selection and area pdfs), BSDF sampling and their MIS weights
//! against ground truth that does not depend on the renderer.
//!
//! Runs in under a second on 2 cores (`cargo test --test area_light`).

mod common {
    pub mod stats;
}

use common::stats::{assert_within_and_sharp, mean_and_standard_error};

use mlt::{Algorithm, Backend, Camera, Material, RenderSettings, Scene, SceneDesc, render};
use std::f64::consts::PI;

/// Form factor from a point to a parallel a × b rectangle at height c, the point below one corner.
fn corner_form_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

const ALBEDO: f32 = 0.6;
const EMISSION: [f32; 3] = [3.0, 2.0, 1.0];

fn scene(split_light: bool) -> Scene {
    let floor = [
        [-50.0, 0.0, -50.0],
        [-50.0, 0.0, 50.0],
        [50.0, 0.0, 50.0],
        [50.0, 0.0, -50.0],
    ];
    let light = [
        [-0.5, 1.0, -0.5],
        [0.5, 1.0, -0.5],
        [0.5, 1.0, 0.5],
        [-0.5, 1.0, 0.5],
    ];
    let inner = [[0.2, 1.0, -0.1]];
    let positions: Vec<f32> = floor
        .iter()
        .chain(&light)
        .chain(&inner)
        .flatten()
        .copied()
        .collect();
    // Floor faces +y, light faces -y (counter-clockwise seen from below).
    let mut indices = vec![0, 1, 2, 0, 2, 3];
    let mut material_ids = vec![0, 0];
    if split_light {
        // The same square as four triangles of different areas around an inner vertex:
        // exercises the power-proportional light selection.
        indices.extend([4, 5, 8, 5, 6, 8, 6, 7, 8, 7, 4, 8]);
        material_ids.extend([1, 1, 1, 1]);
    } else {
        indices.extend([4, 5, 6, 4, 6, 7]);
        material_ids.extend([1, 1]);
    }
    let materials = [
        Material::diffuse([ALBEDO; 3]),
        Material::diffuse([0.0; 3]).with_emission(EMISSION),
    ];
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &material_ids,
        materials: &materials,
        lights: Default::default(),
        backend: Backend::Bvh,
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn floor_radiance_matches_the_form_factor() {
    for split_light in [false, true] {
        check_floor_radiance(&scene(split_light));
    }
}

fn check_floor_radiance(scene: &Scene) {
    let camera = Camera {
        eye: [0.0, 0.6, -3.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 0.2,
        ..Camera::default()
    };
    let form_factor = 4.0 * corner_form_factor(0.5, 0.5, 1.0);
    for max_depth in [1, 3] {
        let settings = RenderSettings {
            width: 64,
            height: 64,
            algorithm: Algorithm::Path,
            samples_per_pixel: 16,
            max_depth,
            seed: 3,
            ..Default::default()
        };
        let mut image = vec![0.0; 64 * 64 * 3];
        render(scene, &camera, &settings, &mut image, None).unwrap();
        let (mean, error) = mean_and_standard_error(&image);
        for c in 0..3 {
            // Nothing but the floor and the light's black back: deeper paths add nothing.
            let truth = ALBEDO as f64 * EMISSION[c] as f64 * form_factor;
            let label = format!("depth {max_depth} channel {c}");
            assert_within_and_sharp(&label, mean[c], truth, error[c], 4.0);
        }
    }
}
