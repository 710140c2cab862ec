//! Scenes the tests render: the canonical scene files of tests/scenes as arrays (`Mesh`) or
//! built, the white furnace, and the Cornell box opened to the sky.
// Each test file uses a part of these helpers.
#![allow(dead_code)]

use mlt::{Backend, Camera, Material, Scene, SceneDesc};

/// An icosphere of `radius` around the origin, subdivided `levels` times, with every
/// triangle's front (counter-clockwise) side facing the centre.
pub fn inward_icosphere(levels: u32, radius: f32) -> (Vec<f32>, Vec<u32>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut vertices: Vec<[f32; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoint = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut mid = |a: u32, b: u32, vertices: &mut Vec<[f32; 3]>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (vertices[a as usize], vertices[b as usize]);
                vertices.push([
                    (p[0] + q[0]) / 2.0,
                    (p[1] + q[1]) / 2.0,
                    (p[2] + q[2]) / 2.0,
                ]);
                vertices.len() as u32 - 1
            })
        };
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut vertices);
            let bc = mid(b, c, &mut vertices);
            let ca = mid(c, a, &mut vertices);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let positions = vertices
        .iter()
        .flat_map(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l * radius)
        })
        .collect();
    // The icosahedron above winds outward; reverse each face to face inward.
    let indices = faces.iter().flat_map(|&[a, b, c]| [a, c, b]).collect();
    (positions, indices)
}

/// The white furnace: a closed sphere whose inside is diffuse with `albedo` and emits `emission`.
pub fn furnace_scene(albedo: [f32; 3], emission: [f32; 3]) -> Scene {
    furnace_scene_of(Material::diffuse(albedo).with_emission(emission))
}

/// The furnace's sphere made of `material`.
pub fn furnace_scene_of(material: Material) -> Scene {
    let (positions, indices) = inward_icosphere(2, 1.0);
    let materials = [material];
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &[],
        materials: &materials,
        lights: Default::default(),
        backend: Backend::Bvh,
        ..Default::default()
    })
    .unwrap()
}

/// Radiance in the furnace with a depth limit: Le · Σ_{k ≤ depth} albedoᵏ per channel.
pub fn furnace_truth(albedo: [f32; 3], emission: [f32; 3], depth: u32) -> [f64; 3] {
    std::array::from_fn(|c| {
        let a = albedo[c] as f64;
        emission[c] as f64 * (0..=depth).map(|k| a.powi(k as i32)).sum::<f64>()
    })
}

/// A camera at the furnace's centre.
pub fn furnace_camera() -> Camera {
    Camera {
        eye: [0.0, 0.0, 0.0],
        target: [0.3, 0.2, 1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 90.0,
        ..Camera::default()
    }
}

/// A triangle scene as plain arrays, in file order, for tests that go through the C ABI.
pub struct Mesh {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
    pub material_ids: Vec<u32>,
    pub materials: Vec<Material>,
}

impl Mesh {
    pub fn rust_materials(&self) -> Vec<Material> {
        self.materials.clone()
    }

    /// The materials as a host of today's header passes them.
    pub fn c_materials(&self) -> Vec<mlt::capi::MltMaterial> {
        self.materials
            .iter()
            .map(mlt::capi::MltMaterial::from)
            .collect()
    }

    pub fn scene(&self) -> Scene {
        self.scene_with(Backend::Bvh)
    }

    pub fn scene_with(&self, backend: Backend) -> Scene {
        self.scene_lit(backend, Default::default())
    }

    /// The scene built with `backend` at `quality`.
    pub fn scene_built(&self, backend: Backend, quality: mlt::BuildQuality) -> Scene {
        self.build(backend, quality, Default::default())
    }

    /// The scene with lights besides its emissive triangles.
    pub fn scene_lit(&self, backend: Backend, lights: mlt::LightsDesc) -> Scene {
        self.build(backend, Default::default(), lights)
    }

    fn build(
        &self,
        backend: Backend,
        build_quality: mlt::BuildQuality,
        lights: mlt::LightsDesc,
    ) -> Scene {
        Scene::new(&SceneDesc {
            positions: &self.positions,
            indices: &self.indices,
            material_ids: &self.material_ids,
            materials: &self.materials,
            lights,
            backend,
            build_quality,
            ..Default::default()
        })
        .expect("a valid scene")
    }
}

pub fn scenes_dir() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes")
}

/// A canonical scene of tests/scenes (`NAME.obj` with its camera sidecar), built.
pub fn load_canonical(name: &str) -> (Scene, Camera) {
    (canonical_mesh(name).scene(), canonical_camera(name))
}

/// A canonical scene of tests/scenes (`NAME.obj`) as arrays.
pub fn canonical_mesh(name: &str) -> Mesh {
    let data = mlt::io::load_scene(&scenes_dir().join(format!("{name}.obj"))).expect("loads");
    Mesh {
        positions: data.positions,
        indices: data.indices,
        material_ids: data.material_ids,
        materials: data.materials,
    }
}

/// A canonical scene's camera (tests/scenes/NAME.camera.json).
pub fn canonical_camera(name: &str) -> Camera {
    mlt::io::load_camera_json(&scenes_dir().join(format!("{name}.camera.json")))
        .expect("loads")
        .camera
}

/// The canonical Cornell box (tests/scenes/cornell-box.obj) as arrays.
pub fn cornell_box() -> Mesh {
    canonical_mesh("cornell-box")
}

/// The Cornell box's camera (tests/scenes/cornell-box.camera.json).
pub fn cornell_camera() -> Camera {
    canonical_camera("cornell-box")
}

/// The Cornell box open above: without its ceiling and its ceiling light, lit by `lights`
/// only (light from infinity gets in from above and through the open front). A camera
/// nearer than the canonical one sees the floor, the walls and some sky above them.
pub fn open_cornell_box(lights: mlt::LightsDesc) -> (Scene, Camera) {
    let mesh = canonical_mesh("cornell-box");
    let top = mesh
        .positions
        .chunks(3)
        .map(|p| p[1])
        .fold(f32::MIN, f32::max);
    let mut indices = Vec::new();
    let mut material_ids = Vec::new();
    for (triangle, &material) in mesh.indices.chunks(3).zip(&mesh.material_ids) {
        let high = triangle
            .iter()
            .all(|&v| mesh.positions[3 * v as usize + 1] >= top - 1.0);
        if high {
            continue;
        }
        indices.extend_from_slice(triangle);
        material_ids.push(material);
    }
    let scene = Scene::new(&mlt::SceneDesc {
        positions: &mesh.positions,
        indices: &indices,
        material_ids: &material_ids,
        materials: &mesh.materials,
        lights,
        backend: mlt::Backend::Bvh,
        ..Default::default()
    })
    .unwrap();
    let camera = Camera {
        eye: [278.0, 420.0, -500.0],
        target: [278.0, 330.0, 0.0],
        ..canonical_camera("cornell-box")
    };
    (scene, camera)
}

/// The lights of the open scenes of the path-space MLT and ERPT tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpenLights {
    /// A constant sky and a sun disc.
    SkyAndSun,
    /// A spot light inside the box and a directional light from above.
    SpotAndDirectional,
}

/// [`open_cornell_box`] with `lights`.
pub fn open_scene(lights: OpenLights) -> (Scene, Camera) {
    let sky = [0.5f32, 0.6, 0.8];
    let punctual = [
        mlt::PunctualLight::spot(
            [200.0, 500.0, 250.0],
            [0.3, -1.0, 0.2],
            [3.2e5, 2.4e5, 1.6e5],
            15.0,
            35.0,
        ),
        mlt::PunctualLight::directional([-0.4, -1.0, 0.3], [0.8, 0.8, 0.6]),
    ];
    open_cornell_box(match lights {
        OpenLights::SkyAndSun => mlt::LightsDesc {
            environment: Some(mlt::EnvironmentDesc::constant(&sky)),
            sun: Some(mlt::SunDesc::from_radiance(
                [0.4, 1.0, -0.5],
                3.0,
                [300.0, 270.0, 220.0],
            )),
            punctual: &[],
        },
        OpenLights::SpotAndDirectional => mlt::LightsDesc {
            punctual: &punctual,
            ..Default::default()
        },
    })
}

/// Image size and depth of the open-scene tests (small: they run in CI).
pub const OPEN_SIZE: u32 = 32;
pub const OPEN_MAX_DEPTH: u32 = 3;
