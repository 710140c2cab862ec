//! Shared by the C ABI tests: the canonical Cornell box, read from tests/scenes/cornell-box.obj
//! with a tiny OBJ/MTL reader (only `v`, `f`, `usemtl`, `newmtl`, `Kd`, `Ke`), so the tests need
//! no loader feature and compare the C examples' hand-written geometry against the file.

#![allow(dead_code)]

use mlt::capi::{MLT_MATERIAL_DIFFUSE, MltMaterial};
use std::path::PathBuf;

/// A triangle scene as plain arrays, in file order.
pub struct Mesh {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
    pub material_ids: Vec<u32>,
    /// (albedo, emission) per material, in the order of first use.
    pub materials: Vec<([f32; 3], [f32; 3])>,
}

impl Mesh {
    pub fn rust_materials(&self) -> Vec<mlt::Material> {
        self.materials
            .iter()
            .map(|&(kd, ke)| mlt::Material::diffuse(kd).with_emission(ke))
            .collect()
    }

    pub fn c_materials(&self) -> Vec<MltMaterial> {
        self.materials
            .iter()
            .map(|&(kd, ke)| MltMaterial {
                kind: MLT_MATERIAL_DIFFUSE,
                color: kd,
                emission: ke,
                ior: 1.5,
            })
            .collect()
    }

    pub fn scene(&self) -> mlt::Scene {
        mlt::Scene::new(&mlt::SceneDesc {
            positions: &self.positions,
            indices: &self.indices,
            material_ids: &self.material_ids,
            materials: &self.rust_materials(),
            backend: mlt::Backend::Bvh,
        })
        .expect("the Cornell box is a valid scene")
    }
}

pub fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes")
}

fn floats<const N: usize>(words: &[&str]) -> [f32; N] {
    let mut out = [0.0; N];
    for (o, w) in out.iter_mut().zip(words) {
        *o = w.parse().expect("a number");
    }
    out
}

/// Reads tests/scenes/cornell-box.obj and its .mtl.
pub fn cornell_box() -> Mesh {
    let dir = scenes_dir();
    let mtl = std::fs::read_to_string(dir.join("cornell-box.mtl")).unwrap();
    let mut library: Vec<(String, [f32; 3], [f32; 3])> = Vec::new();
    for line in mtl.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["newmtl", name] => library.push((name.to_string(), [0.0; 3], [0.0; 3])),
            ["Kd", rest @ ..] => library.last_mut().unwrap().1 = floats(rest),
            ["Ke", rest @ ..] => library.last_mut().unwrap().2 = floats(rest),
            _ => {}
        }
    }
    let obj = std::fs::read_to_string(dir.join("cornell-box.obj")).unwrap();
    let mut mesh = Mesh {
        positions: Vec::new(),
        indices: Vec::new(),
        material_ids: Vec::new(),
        materials: Vec::new(),
    };
    let mut used: Vec<String> = Vec::new();
    let mut current = 0u32;
    for line in obj.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["v", rest @ ..] => mesh.positions.extend(floats::<3>(rest)),
            ["usemtl", name] => {
                current = match used.iter().position(|u| u == name) {
                    Some(i) => i as u32,
                    None => {
                        let (_, kd, ke) = library.iter().find(|m| m.0 == *name).unwrap();
                        used.push(name.to_string());
                        mesh.materials.push((*kd, *ke));
                        used.len() as u32 - 1
                    }
                }
            }
            ["f", a, b, c] => {
                for v in [a, b, c] {
                    mesh.indices.push(v.parse::<u32>().unwrap() - 1);
                }
                mesh.material_ids.push(current);
            }
            _ => {}
        }
    }
    assert_eq!(
        mesh.indices.len(),
        32 * 3,
        "the Cornell box has 32 triangles"
    );
    mesh
}

/// The Cornell box's camera (tests/scenes/cornell-box.camera.json).
pub fn cornell_camera() -> mlt::Camera {
    mlt::Camera {
        eye: [278.0, 273.0, -800.0],
        target: [278.0, 273.0, -799.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 39.307648,
        lens_radius: 0.0,
        focus_distance: 0.0,
    }
}

pub fn mean(image: &[f32]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for pixel in image.chunks_exact(3) {
        for (s, &value) in sum.iter_mut().zip(pixel) {
            *s += value as f64;
        }
    }
    let n = (image.len() / 3).max(1) as f64;
    sum.map(|s| s / n)
}
