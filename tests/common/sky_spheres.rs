//! The sky-spheres scene: a glTF 2.0 file as game-engine tooling writes them, three spheres
//! (diffuse, mirror, glass) on a grey ground, meant to be lit by an environment map
//! (tests/scenes/sky.exr) and the sun: the README's example of a glTF scene under a sky.
//!
//! Written as tests/scenes/sky-spheres.{gltf,bin} by this generator (`tests/io.rs` checks
//! the committed files are what it writes; `MLT_WRITE_SCENES=1 cargo test --test io`
//! rewrites them). Metres, y up; the camera looks along −z, the sun of window_room.rs is
//! behind it.

use serde_json::json;

/// A mesh: positions, normals (smooth shading), indices.
type MeshArrays = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>);

/// A UV sphere with `rings` × `segments` quads, wound outward, with its exact normals.
fn sphere(center: [f32; 3], radius: f32, rings: u32, segments: u32) -> MeshArrays {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            let normal = [
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ];
            positions.push([0, 1, 2].map(|k| center[k] + radius * normal[k]));
            normals.push(normal);
        }
    }
    let at = |i: u32, j: u32| i * (segments + 1) + j;
    let mut indices = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Skip the degenerate triangles at the poles.
            if i != 0 {
                indices.extend([a, b, d]);
            }
            if i != rings - 1 {
                indices.extend([b, c, d]);
            }
        }
    }
    (positions, normals, indices)
}

/// The meshes: ground, then the three spheres.
fn meshes() -> Vec<MeshArrays> {
    let h = 10.0;
    let ground = (
        vec![[-h, 0.0, -h], [-h, 0.0, h], [h, 0.0, h], [h, 0.0, -h]],
        vec![[0.0, 1.0, 0.0]; 4],
        vec![0, 1, 2, 0, 2, 3],
    );
    vec![
        ground,
        sphere([-2.3, 1.0, 0.0], 1.0, 24, 48),
        sphere([0.0, 1.0, -0.8], 1.0, 24, 48),
        sphere([2.3, 1.0, 0.0], 1.0, 24, 48),
    ]
}

/// The binary buffer (positions, normals and indices of each mesh) and the glTF JSON text.
pub fn files() -> (Vec<u8>, String) {
    let mut bin = Vec::new();
    let mut buffer_views = Vec::new();
    let mut accessors = Vec::new();
    let mut meshes_json = Vec::new();
    let materials = [
        (
            "ground",
            json!({"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.45, 0.45, 0.42, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}),
        ),
        (
            "clay",
            json!({"name": "clay", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.32, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}),
        ),
        (
            "mirror",
            json!({"name": "mirror", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.93, 0.9, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.0}}),
        ),
        (
            "glass",
            json!({"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}}}),
        ),
    ];
    for (index, (positions, normals, indices)) in meshes().iter().enumerate() {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        let offset = bin.len();
        for p in positions {
            for c in 0..3 {
                min[c] = min[c].min(p[c]);
                max[c] = max[c].max(p[c]);
                bin.extend_from_slice(&p[c].to_le_bytes());
            }
        }
        buffer_views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": positions.len() * 12, "target": 34962}));
        accessors.push(json!({"bufferView": buffer_views.len() - 1, "componentType": 5126, "count": positions.len(), "type": "VEC3", "min": min, "max": max}));
        let offset = bin.len();
        for n in normals.iter().flatten() {
            bin.extend_from_slice(&n.to_le_bytes());
        }
        buffer_views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": normals.len() * 12, "target": 34962}));
        accessors.push(json!({"bufferView": buffer_views.len() - 1, "componentType": 5126, "count": normals.len(), "type": "VEC3"}));
        let offset = bin.len();
        for i in indices {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        buffer_views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": indices.len() * 4, "target": 34963}));
        accessors.push(json!({"bufferView": buffer_views.len() - 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}));
        meshes_json.push(json!({"name": materials[index].0, "primitives": [{
            "attributes": {"POSITION": accessors.len() - 3, "NORMAL": accessors.len() - 2}, "indices": accessors.len() - 1, "material": index}]}));
    }
    let gltf = json!({
        "asset": {"version": "2.0", "generator": "mlt tests/common/sky_spheres.rs"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": [
            {"mesh": 0}, {"mesh": 1}, {"mesh": 2}, {"mesh": 3},
            // The camera looks along its node's −z: from (0, 2.2, 8), tilted down by 8°.
            {"camera": 0, "translation": [0.0, 2.2, 8.0], "rotation": [-0.069756474, 0.0, 0.0, 0.9975641]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1, "aspectRatio": 1.5}}],
        "meshes": meshes_json,
        "materials": materials.iter().map(|(_, m)| m.clone()).collect::<Vec<_>>(),
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"uri": "sky-spheres.bin", "byteLength": bin.len()}],
    });
    (bin, serde_json::to_string_pretty(&gltf).unwrap() + "\n")
}
