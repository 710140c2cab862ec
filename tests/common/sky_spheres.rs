//! The sky-spheres scene: a glTF 2.0 file as game-engine tooling writes them, three spheres
//! on a ground, meant to be lit by an environment map (tests/scenes/sky.exr) and the sun:
//! the README's example of a textured glTF scene under a sky. The ground's colour is a
//! checker texture (PNG, 8-bit sRGB, repeated by `KHR_texture_transform`); the clay sphere
//! carries a tangent-space normal map of bumps (tangents left to MikkTSpace); the middle
//! sphere is a slightly rough metal, the right one smooth glass. Every mesh has smooth
//! normals and texture coordinates.
//!
//! Written as tests/scenes/sky-spheres.{gltf,bin} by this generator (`tests/io.rs` checks
//! the committed files are what it writes; `MLT_WRITE_SCENES=1 cargo test --test io`
//! rewrites them). Metres, y up; the camera looks along −z, the sun of window_room.rs is
//! behind it.

use image::ImageEncoder;
use serde_json::json;

/// A mesh: positions, normals (smooth shading), texture coordinates, indices.
type MeshArrays = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u32>);

/// A UV sphere with `rings` × `segments` quads, wound outward, with its exact normals.
fn sphere(center: [f32; 3], radius: f32, rings: u32, segments: u32) -> MeshArrays {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut texcoords = Vec::new();
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
            texcoords.push([j as f32 / segments as f32, i as f32 / rings as f32]);
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
    (positions, normals, texcoords, indices)
}

/// The meshes: ground, then the three spheres.
fn meshes() -> Vec<MeshArrays> {
    let h = 10.0;
    let ground = (
        vec![[-h, 0.0, -h], [-h, 0.0, h], [h, 0.0, h], [h, 0.0, -h]],
        vec![[0.0, 1.0, 0.0]; 4],
        // One unit of texture per metre; the checker repeats every 2 (texture transform).
        vec![[-h, -h], [-h, h], [h, h], [h, -h]],
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
            json!({"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8,
                "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [0.5, 0.5]}}}}}),
        ),
        (
            "clay",
            json!({"name": "clay", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.32, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6},
                "normalTexture": {"index": 1, "scale": 1.0}}),
        ),
        (
            "metal",
            json!({"name": "metal", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.93, 0.9, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.15}}),
        ),
        (
            "glass",
            json!({"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}}}),
        ),
    ];
    for (index, (positions, normals, texcoords, indices)) in meshes().iter().enumerate() {
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
        for t in texcoords.iter().flatten() {
            bin.extend_from_slice(&t.to_le_bytes());
        }
        buffer_views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": texcoords.len() * 8, "target": 34962}));
        accessors.push(json!({"bufferView": buffer_views.len() - 1, "componentType": 5126, "count": texcoords.len(), "type": "VEC2"}));
        let offset = bin.len();
        for i in indices {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        buffer_views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": indices.len() * 4, "target": 34963}));
        accessors.push(json!({"bufferView": buffer_views.len() - 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}));
        meshes_json.push(json!({"name": materials[index].0, "primitives": [{
            "attributes": {"POSITION": accessors.len() - 4, "NORMAL": accessors.len() - 3, "TEXCOORD_0": accessors.len() - 2},
            "indices": accessors.len() - 1, "material": index}]}));
    }
    // The images, PNG in the buffer (4-byte aligned views).
    let mut images = Vec::new();
    for png in [checker_png(), bumps_png()] {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let offset = bin.len();
        bin.extend_from_slice(&png);
        buffer_views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": png.len()}));
        images.push(json!({"bufferView": buffer_views.len() - 1, "mimeType": "image/png"}));
    }
    let gltf = json!({
        "asset": {"version": "2.0", "generator": "mlt tests/common/sky_spheres.rs"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_texture_transform"],
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
        // Nearest for the checker's sharp squares, the default (linear) for the bumps.
        "samplers": [{"magFilter": 9728, "wrapS": 10497, "wrapT": 10497}, {"wrapS": 10497, "wrapT": 33071}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1}],
        "images": images,
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"uri": "sky-spheres.bin", "byteLength": bin.len()}],
    });
    (bin, serde_json::to_string_pretty(&gltf).unwrap() + "\n")
}

/// A 2 × 2 checker of warm and cool greys, 8-bit sRGB.
fn checker_png() -> Vec<u8> {
    let texels = [200u8, 190, 170, 90, 100, 115, 90, 100, 115, 200, 190, 170];
    png(2, 2, image::ColorType::Rgb8, &texels)
}

/// A tangent-space normal map of round bumps, 32 around and 16 down the sphere's texture
/// coordinates: 128 × 64 RGB, each texel (n + 1) / 2 of the bump's normal (+Y up).
fn bumps_png() -> Vec<u8> {
    let (width, height) = (128u32, 64u32);
    let mut texels = Vec::new();
    for y in 0..height {
        for x in 0..width {
            // Height h = sin(2π·6u)·sin(2π·3v) with u, v at the texel centre; its gradient
            // in texels tilts the normal (v grows downwards, the map's +Y is up).
            let u = (x as f32 + 0.5) / width as f32;
            let v = (y as f32 + 0.5) / height as f32;
            let tau = std::f32::consts::TAU;
            let (fu, fv) = (16.0, 8.0);
            let dh_du = fu * tau * (fu * tau * u).cos() * (fv * tau * v).sin();
            let dh_dv = fv * tau * (fu * tau * u).sin() * (fv * tau * v).cos();
            // Slopes up to about 0.4.
            let strength = 0.004;
            let n = [-dh_du * strength, dh_dv * strength, 1.0];
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            for c in n {
                texels.push((((c / length) * 0.5 + 0.5) * 255.0).round() as u8);
            }
        }
    }
    png(width, height, image::ColorType::Rgb8, &texels)
}

fn png(width: u32, height: u32, color: image::ColorType, texels: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(texels, width, height, color.into())
        .expect("encodes");
    bytes
}
