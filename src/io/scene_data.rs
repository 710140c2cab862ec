//! What the file readers share: the scene they fill, the camera a file comes with, their
//! defaults and their error.

use crate::accel::Backend;
use crate::scene::{Camera, Material, SceneDesc};
use std::fmt;

/// Albedo of the diffuse material given to OBJ faces without a material, and of
/// materials without `Kd`.
pub(crate) const DEFAULT_ALBEDO: [f32; 3] = [0.8, 0.8, 0.8];

/// Size of the image when a glTF camera gives no aspect ratio (square), and its height
/// otherwise.
pub(crate) const GLTF_DEFAULT_HEIGHT: u32 = 512;

/// An error reading or writing a file: a sentence naming the file and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IoError {
    pub message: String,
}

impl IoError {
    pub fn new(message: impl Into<String>) -> Self {
        IoError {
            message: message.into(),
        }
    }
}

impl fmt::Display for IoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for IoError {}

/// A camera and the image size it was set up for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFile {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
}

/// A loaded scene: the flat arrays [`crate::SceneDesc`] borrows, plus the camera the file
/// came with, if any.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneData {
    /// x, y, z per vertex.
    pub positions: Vec<f32>,
    /// Three vertex indices per triangle, counter-clockwise front.
    pub indices: Vec<u32>,
    /// One index into `materials` per triangle.
    pub material_ids: Vec<u32>,
    pub materials: Vec<Material>,
    /// The name of each material in `materials` (same length), for error messages.
    pub material_names: Vec<String>,
    /// The OBJ's `NAME.camera.json` sidecar or the glTF's first camera.
    pub camera: Option<CameraFile>,
    /// The glTF's `KHR_lights_punctual` lights, placed by its node hierarchy.
    pub punctual_lights: Vec<crate::scene::PunctualLight>,
    /// Per-vertex attributes, each empty or complete (see [`SceneDesc`]).
    pub normals: Vec<f32>,
    pub texcoords: Vec<f32>,
    pub texcoords1: Vec<f32>,
    pub tangents: Vec<f32>,
    pub colors: Vec<f32>,
    /// The textures the materials refer to, with their texels.
    pub textures: Vec<crate::texture::TextureDesc<'static>>,
}

impl SceneData {
    /// The error's message, with the file's name of the material it is about (the kernel
    /// knows materials by index only).
    pub fn describe_error(&self, error: &crate::Error) -> String {
        match error.material.and_then(|i| self.material_names.get(i)) {
            Some(name) => format!("{} (material '{name}')", error.message),
            None => error.message.clone(),
        }
    }

    /// Applies the loaders' material options to every material: `energy_compensation` for
    /// all (rough metals keep their multiply scattered light), and `abbe_number` to each
    /// transmissive one (a dielectric, or a metallic-roughness material with transmission)
    /// that has no dispersion of its own.
    pub fn override_materials(&mut self, energy_compensation: bool, abbe_number: Option<f32>) {
        for material in &mut self.materials {
            material.energy_compensation = energy_compensation;
            let transmits = material.kind == crate::MaterialKind::Dielectric
                || (material.kind == crate::MaterialKind::MetallicRoughness
                    && material.transmission > 0.0);
            if let Some(abbe_number) = abbe_number
                && transmits
                && material.abbe_number == 0.0
            {
                material.abbe_number = abbe_number;
            }
        }
    }

    /// Borrows the arrays as a scene description for [`crate::Scene::new`], at the default
    /// build quality.
    pub fn desc(&self, backend: Backend) -> SceneDesc<'_> {
        SceneDesc {
            positions: &self.positions,
            indices: &self.indices,
            material_ids: &self.material_ids,
            materials: &self.materials,
            lights: crate::scene::LightsDesc {
                punctual: &self.punctual_lights,
                ..Default::default()
            },
            backend,
            build_quality: Default::default(),
            normals: &self.normals,
            texcoords: &self.texcoords,
            texcoords1: &self.texcoords1,
            tangents: &self.tangents,
            colors: &self.colors,
            textures: &self.textures,
        }
    }

    /// The box around every vertex (zero for no vertices).
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for p in self.positions.chunks_exact(3) {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        if self.positions.is_empty() {
            return ([0.0; 3], [0.0; 3]);
        }
        (min, max)
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Adds `material` (named `name`) and returns its index.
    pub(crate) fn push_material(&mut self, name: String, material: Material) -> u32 {
        self.materials.push(material);
        self.material_names.push(name);
        (self.materials.len() - 1) as u32
    }
}
