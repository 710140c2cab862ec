//! The surfaces scene, built in code: the canonical Cornell box with glTF
//! metallic-roughness materials — a rough gold tall block, a short block half rough metal
//! and half glossy plastic with the multiple-scattering energy compensation, and on it a smooth-shaded rough glass sphere (per-vertex normals on a coarse icosphere,
//! so shading and geometric normals differ by up to ~18°) — a floor whose colour is a
//! checker texture, and a lamp whose emission a 2 × 2 texture modulates. It is where the algorithms must agree
//! once BSDFs are evaluated in a shading frame that is not the triangle's (light tracing
//! and path tracing see the non-symmetric BSDF of shading normals from opposite ends) and
//! once colour and emission vary across a triangle.

use super::scenes::{Mesh, canonical_mesh, inward_icosphere};
use mlt::{
    Backend, Material, Scene, SceneDesc, TexelData, TextureDesc, TextureEncoding, TextureFilter,
    TextureRef, WrapMode,
};
use std::borrow::Cow;

/// A scene as arrays, with the per-vertex attributes `Mesh` does not carry.
pub struct SurfacesMesh {
    pub mesh: Mesh,
    /// 3 floats per vertex.
    pub normals: Vec<f32>,
    /// 2 floats per vertex.
    pub texcoords: Vec<f32>,
    pub textures: Vec<TextureDesc<'static>>,
}

impl SurfacesMesh {
    pub fn scene(&self, backend: Backend) -> Scene {
        Scene::new(&SceneDesc {
            positions: &self.mesh.positions,
            indices: &self.mesh.indices,
            material_ids: &self.mesh.material_ids,
            materials: &self.mesh.materials,
            normals: &self.normals,
            texcoords: &self.texcoords,
            textures: &self.textures,
            backend,
            ..Default::default()
        })
        .expect("a valid scene")
    }

    /// Appends a triangle list with its own vertices and normals, all of material
    /// `material`.
    fn append(
        &mut self,
        positions: &[f32],
        normals: &[f32],
        texcoords: &[f32],
        indices: &[u32],
        material: u32,
    ) {
        let base = (self.mesh.positions.len() / 3) as u32;
        self.mesh.positions.extend_from_slice(positions);
        self.normals.extend_from_slice(normals);
        self.texcoords.extend_from_slice(texcoords);
        self.mesh.indices.extend(indices.iter().map(|&i| i + base));
        self.mesh
            .material_ids
            .extend(std::iter::repeat_n(material, indices.len() / 3));
    }
}

/// The Cornell box with flat normals (each triangle's own vertices carry its face normal:
/// shading and geometric normals agree there) and the smooth sphere.
pub fn surfaces_mesh() -> SurfacesMesh {
    let box_mesh = canonical_mesh("cornell-box");
    let mut scene = SurfacesMesh {
        mesh: Mesh {
            positions: Vec::new(),
            indices: Vec::new(),
            material_ids: Vec::new(),
            materials: box_mesh.materials.clone(),
        },
        normals: Vec::new(),
        texcoords: Vec::new(),
        textures: vec![checker(), lamp_pattern()],
    };
    // The floor's colour: the checker, 4 × 4 squares across the floor.
    let floor_material = scene.mesh.materials.len() as u32;
    scene.mesh.materials.push(Material {
        base_color_texture: Some(TextureRef {
            scale: [0.5, 0.5],
            ..TextureRef::new(0)
        }),
        ..Material::diffuse([0.9; 3])
    });
    // Rough gold, and half metal, half plastic with the energy compensation (its metal part
    // gains the compensation lobe; the plastic's coat and diffuse base stay as they are).
    let metal = scene.mesh.materials.len() as u32;
    scene
        .mesh
        .materials
        .push(Material::metallic_roughness([1.0, 0.78, 0.34], 1.0, 0.3));
    let plastic = metal + 1;
    scene.mesh.materials.push(Material {
        energy_compensation: true,
        ..Material::metallic_roughness([0.2, 0.35, 0.7], 0.5, 0.6)
    });
    // The lamp's emission, modulated across it by the 2 × 2 pattern.
    let lamp = box_mesh
        .materials
        .iter()
        .position(Material::is_emissive)
        .expect("the box has a lamp");
    let lamp_material = scene.mesh.materials.len() as u32;
    scene.mesh.materials.push(Material {
        emission_texture: Some(TextureRef::new(1)),
        ..box_mesh.materials[lamp]
    });
    let corner = |i: u32| -> [f32; 3] {
        let i = i as usize * 3;
        [
            box_mesh.positions[i],
            box_mesh.positions[i + 1],
            box_mesh.positions[i + 2],
        ]
    };
    for (triangle, corners) in box_mesh.indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [corner(corners[0]), corner(corners[1]), corner(corners[2])];
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let positions: Vec<f32> = [a, b, c].concat();
        let normals: Vec<f32> = [n, n, n].concat();
        let mut material = box_mesh.material_ids.get(triangle).copied().unwrap_or(0);
        // Planar texture coordinates over the floor (y = 0) and the lamp (in x and z).
        let planar = |p: [f32; 3], (x0, x1, z0, z1): (f32, f32, f32, f32)| {
            [(p[0] - x0) / (x1 - x0), (p[2] - z0) / (z1 - z0)]
        };
        if (10..20).contains(&triangle) {
            material = plastic;
        } else if (20..30).contains(&triangle) {
            material = metal;
        }
        let texcoords: Vec<f32> = if triangle < 2 {
            material = floor_material;
            [a, b, c]
                .iter()
                .flat_map(|&p| planar(p, (0.0, 556.0, 0.0, 559.2)))
                .collect()
        } else if material as usize == lamp {
            material = lamp_material;
            [a, b, c]
                .iter()
                .flat_map(|&p| planar(p, (213.0, 343.0, 227.0, 332.0)))
                .collect()
        } else {
            vec![0.0; 6]
        };
        scene.append(&positions, &normals, &texcoords, &[0, 1, 2], material);
    }
    // A smooth-shaded rough glass sphere on the short block (top at y = 165, centre
    // near x = 185, z = 169).
    let sphere_material = scene.mesh.materials.len() as u32;
    scene.mesh.materials.push(Material {
        transmission: 1.0,
        ..Material::metallic_roughness([1.0; 3], 0.0, 0.25)
    });
    let (radius, center) = (70.0f32, [185.0f32, 165.0 + 70.0, 169.0]);
    let (unit, inward) = inward_icosphere(1, 1.0);
    let outward: Vec<u32> = inward
        .chunks_exact(3)
        .flat_map(|t| [t[0], t[2], t[1]])
        .collect();
    let positions: Vec<f32> = unit
        .chunks_exact(3)
        .flat_map(|v| [0, 1, 2].map(|k| center[k] + radius * v[k]))
        .collect();
    let texcoords = vec![0.0; unit.len() / 3 * 2];
    scene.append(&positions, &unit, &texcoords, &outward, sphere_material);
    scene
}

/// An 8 × 8 checker of two colours (sRGB bytes), sampled nearest: sharp squares.
fn checker() -> TextureDesc<'static> {
    let texels = (0..64)
        .flat_map(|i| {
            if (i % 8 + i / 8) % 2 == 0 {
                [230, 200, 120]
            } else {
                [60, 90, 160]
            }
        })
        .collect();
    TextureDesc {
        width: 8,
        height: 8,
        channels: 3,
        data: TexelData::U8(Cow::Owned(texels)),
        encoding: TextureEncoding::Srgb,
        wrap_u: WrapMode::Repeat,
        wrap_v: WrapMode::Repeat,
        filter: TextureFilter::Nearest,
    }
}

/// A 2 × 2 linear float pattern, blended bilinearly across the lamp.
fn lamp_pattern() -> TextureDesc<'static> {
    TextureDesc {
        width: 2,
        height: 2,
        channels: 3,
        data: TexelData::F32(Cow::Owned(vec![
            1.0, 1.0, 1.0, 0.2, 0.6, 1.0, //
            1.0, 0.5, 0.2, 0.0, 0.0, 0.0,
        ])),
        encoding: TextureEncoding::Linear,
        wrap_u: WrapMode::ClampToEdge,
        wrap_v: WrapMode::ClampToEdge,
        filter: TextureFilter::Bilinear,
    }
}
