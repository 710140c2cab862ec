//! The surface fields of the C ABI (metallic-roughness materials, textures, vertex normals,
//! texture coordinates, tangents and colours) fed bad input as a C host would: defaults,
//! every bad value, pointer and count refused with a message naming it, and hosts built
//! against older headers getting the defaults of the fields they lack.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_bad_input_surfaces`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::MLT_MAX_TEXTURE_SIDE;
use mlt::capi::*;
use mlt::error::*;
use std::ptr::{null, null_mut};

/// `HostScene::floor_and_light` with every surface attribute and three textures: texture 0
/// 2 × 2 8-bit sRGB RGBA, texture 1 2 × 2 float RGB (linear), texture 2 1 × 1 8-bit linear
/// RGB (a flat normal map). The floor (material 0, diffuse so that every build renders it)
/// uses textures 0, 1 and 2 as base colour, metallic-roughness and normal map, with a
/// texture transform and an alpha cut-out; the light (material 1) has texture 0 as its
/// emission texture. A second set of texture coordinates (u mirrored) is there for the slots
/// that ask for it (none by default).
struct HostSurfaces {
    host: HostScene,
    normals: Vec<f32>,
    texcoords: Vec<f32>,
    /// NULL in the description when empty.
    texcoords1: Vec<f32>,
    tangents: Vec<f32>,
    colors: Vec<f32>,
    /// What the textures' `texels` point to (set at construction: the vectors' buffers do
    /// not move with the struct), kept alive with it.
    #[allow(dead_code)]
    base_color_texels: Vec<u8>,
    metallic_roughness_texels: Vec<f32>,
    #[allow(dead_code)]
    normal_texels: Vec<u8>,
    textures: Vec<MltTexture>,
}

impl HostSurfaces {
    fn new() -> Self {
        let mut host = HostScene::floor_and_light();
        host.materials[0] = MltMaterial {
            metallic: 0.5,
            roughness: 0.25,
            transmission: 0.1,
            alpha: 0.9,
            alpha_mode: MLT_ALPHA_MASK,
            alpha_cutoff: 0.3,
            base_color_texture: MltTextureRef {
                texture: 0,
                offset: [0.25, -0.5],
                rotation: 0.3,
                scale: [2.0, 3.0],
            },
            metallic_roughness_texture: slot(1),
            normal_texture: slot(2),
            normal_scale: 0.8,
            energy_compensation: 1,
            ..host.materials[0]
        };
        host.materials[1].emission_texture = slot(0);
        let base_color_texels = vec![
            255, 128, 0, 255, 20, 40, 60, 200, 0, 0, 0, 0, 255, 255, 255, 255,
        ];
        let metallic_roughness_texels =
            vec![0.0, 1.0, 0.0, 0.0, 0.5, 1.0, 1.0, 0.2, 0.3, 0.0, 0.0, 0.0];
        let normal_texels = vec![128, 128, 255];
        let textures = vec![
            MltTexture {
                width: 2,
                height: 2,
                channels: 4,
                texels: base_color_texels.as_ptr().cast(),
                ..default_texture()
            },
            MltTexture {
                width: 2,
                height: 2,
                channels: 3,
                texel_type: MLT_TEXEL_F32,
                texels: metallic_roughness_texels.as_ptr().cast(),
                encoding: MLT_TEXTURE_LINEAR,
                wrap_u: MLT_WRAP_CLAMP_TO_EDGE,
                wrap_v: MLT_WRAP_MIRRORED_REPEAT,
                filter: MLT_FILTER_NEAREST,
                ..default_texture()
            },
            MltTexture {
                width: 1,
                height: 1,
                channels: 3,
                texels: normal_texels.as_ptr().cast(),
                encoding: MLT_TEXTURE_LINEAR,
                ..default_texture()
            },
        ];
        let up = [0.0, 1.0, 0.0];
        let down = [0.0, -1.0, 0.0];
        let texcoords = vec![
            0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, // floor
            0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, // light
        ];
        let texcoords1 = texcoords
            .chunks(2)
            .flat_map(|uv| [1.0 - uv[0], uv[1]])
            .collect();
        HostSurfaces {
            normals: [up, up, up, up, down, down, down, down].concat(),
            texcoords,
            texcoords1,
            tangents: [[1.0, 0.0, 0.0, -1.0]; 8].concat(),
            colors: [[0.9, 0.8, 0.7, 1.0]; 8].concat(),
            host,
            base_color_texels,
            metallic_roughness_texels,
            normal_texels,
            textures,
        }
    }

    fn desc(&self) -> MltSceneDesc {
        MltSceneDesc {
            normals: self.normals.as_ptr(),
            normals_len: self.normals.len(),
            texcoords: self.texcoords.as_ptr(),
            texcoords_len: self.texcoords.len(),
            texcoords1: if self.texcoords1.is_empty() {
                null()
            } else {
                self.texcoords1.as_ptr()
            },
            texcoords1_len: self.texcoords1.len(),
            tangents: self.tangents.as_ptr(),
            tangents_len: self.tangents.len(),
            colors: self.colors.as_ptr(),
            colors_len: self.colors.len(),
            textures: self.textures.as_ptr(),
            textures_len: self.textures.len(),
            ..self.host.desc()
        }
    }
}

#[test]
fn surface_defaults_are_valid_and_documented() {
    let m = default_material();
    assert_eq!(
        (m.metallic, m.roughness, m.transmission, m.alpha),
        (0.0, 1.0, 0.0, 1.0)
    );
    assert_eq!(
        (
            m.alpha_mode,
            m.alpha_cutoff,
            m.normal_scale,
            m.energy_compensation
        ),
        (MLT_ALPHA_OPAQUE, 0.5, 1.0, 0)
    );
    for r in [
        m.base_color_texture,
        m.metallic_roughness_texture,
        m.normal_texture,
        m.emission_texture,
    ] {
        assert_eq!(
            (r.texture, r.offset, r.rotation, r.scale),
            (MLT_NO_TEXTURE, [0.0; 2], 0.0, [1.0; 2])
        );
    }
    assert_eq!(m.texcoord1_slots, 0);
    let d = default_desc();
    assert!(d.normals.is_null() && d.texcoords.is_null() && d.tangents.is_null());
    assert!(d.colors.is_null() && d.textures.is_null() && d.texcoords1.is_null());
    assert_eq!(
        (
            d.normals_len,
            d.texcoords_len,
            d.tangents_len,
            d.colors_len,
            d.textures_len,
            d.texcoords1_len
        ),
        (0, 0, 0, 0, 0, 0)
    );
    let t = default_texture();
    assert!(t.texels.is_null());
    assert_eq!((t.width, t.height, t.channels), (0, 0, 4));
    assert_eq!((t.texel_type, t.encoding), (MLT_TEXEL_U8, MLT_TEXTURE_SRGB));
    assert_eq!(
        (t.wrap_u, t.wrap_v, t.filter),
        (MLT_WRAP_REPEAT, MLT_WRAP_REPEAT, MLT_FILTER_BILINEAR)
    );
    // Every attribute and texture together, valid, and rendered.
    let surfaces = HostSurfaces::new();
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(&surfaces.desc(), &mut out) });
    let scene = Handle(out);
    let (status, image) = scene.render(&floor_camera(), &small_settings(4, 4, 2), 48);
    assert_ok(status);
    assert_valid_image(&image, "textured floor");
}

#[test]
fn texture_initializer_refuses_null_and_unknown_sizes() {
    let size = size_of::<MltTexture>();
    // SAFETY: NULL must be refused.
    let status = unsafe { mlt_texture_init(null_mut(), size) };
    let mut results = vec![(
        "out NULL".to_owned(),
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, &["out", "NULL"]),
    )];
    for bad in [0, 3, size - 8, size + 8] {
        let mut storage = [0xABABABABu64; 16];
        // SAFETY: 128 writable bytes, more than any size tried.
        let status = unsafe { mlt_texture_init(storage.as_mut_ptr().cast(), bad) };
        let needles = ["out.struct_size", &bad.to_string(), "mlt_texture_default"];
        let result = check_error(status, MLT_STATUS_INVALID_ARGUMENT, &needles)
            .and_then(|()| ensure(storage.iter().all(|&w| w == 0xABABABABu64), "out written"));
        results.push((format!("struct_size {bad}"), result));
    }
    assert_all("mlt_texture_default", results);
    assert_eq!(default_texture().struct_size as usize, size);
}

/// Every new field of a material, a texture and the scene description, each bad value
/// refused with a message naming it.
#[test]
fn scene_create_bad_surfaces() {
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let mut cases = cases![h = HostSurfaces::new();
        // Materials.
        h.host.materials[0].metallic = -0.1 => ["desc.materials[0].metallic is -0.1", "[0, 1]"],
        h.host.materials[0].metallic = 1.5 => ["desc.materials[0].metallic is 1.5", "[0, 1]"],
        h.host.materials[0].roughness = 2.0 => ["desc.materials[0].roughness is 2", "[0, 1]"],
        h.host.materials[1].roughness = -1.0 => ["desc.materials[1].roughness is -1", "[0, 1]"],
        h.host.materials[0].transmission = 1.01
            => ["desc.materials[0].transmission is 1.01", "[0, 1]"],
        h.host.materials[0].alpha = -0.5 => ["desc.materials[0].alpha is -0.5", "[0, 1]"],
        h.host.materials[0].clearcoat = 1.5 => ["desc.materials[0].clearcoat is 1.5", "[0, 1]"],
        h.host.materials[1].clearcoat = -0.25
            => ["desc.materials[1].clearcoat is -0.25", "[0, 1]"],
        h.host.materials[0].clearcoat_roughness = f32::NAN
            => ["desc.materials[0].clearcoat_roughness", "NaN"],
        h.host.materials[1].clearcoat_roughness = 2.0
            => ["desc.materials[1].clearcoat_roughness is 2", "[0, 1]"],
        h.host.materials[0].clearcoat_normal_texture.texture = 3
            => ["desc.materials[0].clearcoat_normal_texture.texture is 3", "3 textures"],
        h.host.materials[0].alpha_cutoff = -0.25
            => ["desc.materials[0].alpha_cutoff is -0.25", "negative"],
        h.host.materials[0].alpha_mode = 3
            => ["desc.materials[0].alpha_mode is 3", "MLT_ALPHA_OPAQUE", "MLT_ALPHA_MASK", "MLT_ALPHA_BLEND"],
        h.host.materials[1].alpha_mode = -1 => ["desc.materials[1].alpha_mode is -1"],
        h.host.materials[0].energy_compensation = 2
            => ["desc.materials[0].energy_compensation is 2", "0 or 1"],
        h.host.materials[0].abbe_number = -20.0
            => ["desc.materials[0].abbe_number is -20", "positive", "0: no dispersion"],
        h.host.materials[1].abbe_number = f32::NAN => ["desc.materials[1].abbe_number", "NaN"],
        h.host.materials[1].abbe_number = f32::INFINITY
            => ["desc.materials[1].abbe_number", "inf"],
        h.host.materials[0].thickness = -1.0
            => ["desc.materials[0].thickness is -1", "negative", "0: thin-walled"],
        h.host.materials[0].attenuation_distance = 0.0
            => ["desc.materials[0].attenuation_distance is 0", "greater than 0"],
        h.host.materials[1].attenuation_distance = -2.0
            => ["desc.materials[1].attenuation_distance is -2", "greater than 0"],
        h.host.materials[0].attenuation_color = [0.5, 1.5, 0.5]
            => ["desc.materials[0].attenuation_color", "1.5", "[0, 1]"],
        h.host.materials[1].attenuation_color = [-0.25, 0.5, 0.5]
            => ["desc.materials[1].attenuation_color", "-0.25", "[0, 1]"],
        h.host.materials[0].base_color_texture.texture = 3
            => ["desc.materials[0].base_color_texture.texture is 3", "3 textures"],
        h.host.materials[0].metallic_roughness_texture.texture = i32::MAX
            => ["desc.materials[0].metallic_roughness_texture.texture is 2147483647"],
        h.host.materials[0].normal_texture.texture = -2
            => ["desc.materials[0].normal_texture.texture is -2", "MLT_NO_TEXTURE (-1)"],
        h.host.materials[1].emission_texture.texture = i32::MIN
            => ["desc.materials[1].emission_texture.texture is -2147483648", "MLT_NO_TEXTURE"],
        h.host.materials[1].emission_texture.texture = 3
            => ["desc.materials[1].emission_texture.texture is 3", "3 textures"],
        h.host.materials[1].kind = 4 => ["desc.materials[1].kind is 4"],
        // Texture coordinate set 1.
        {
            h.host.materials[0].texcoord1_slots = MLT_TEXCOORD1_NORMAL;
            h.texcoords1.clear();
        } => ["desc.materials[0].normal_texture uses texture coordinate set 1", "desc.texcoords1 is empty"],
        h.host.materials[1].texcoord1_slots = 1 << 31
            => ["desc.materials[1].texcoord1_slots is 0x80000000", "bit 31 names no texture slot",
                "bits 0 (base_color_texture)"],
        h.host.materials[0].texcoord1_slots = u32::MAX
            => ["desc.materials[0].texcoord1_slots is 0xffffffff", "names no texture slot"],
        // Textures: enums.
        h.textures[0].texel_type = 2
            => ["desc.textures[0].texel_type is 2", "MLT_TEXEL_U8", "MLT_TEXEL_F32"],
        h.textures[2].texel_type = -1 => ["desc.textures[2].texel_type is -1"],
        h.textures[1].encoding = MLT_TEXTURE_SRGB
            => ["desc.textures[1].encoding is MLT_TEXTURE_SRGB", "MLT_TEXEL_F32", "8-bit"],
        h.textures[0].encoding = 2
            => ["desc.textures[0].encoding is 2", "MLT_TEXTURE_SRGB", "MLT_TEXTURE_LINEAR"],
        h.textures[0].wrap_u = 3
            => ["desc.textures[0].wrap_u is 3", "MLT_WRAP_REPEAT", "MLT_WRAP_MIRRORED_REPEAT"],
        h.textures[1].wrap_v = -1 => ["desc.textures[1].wrap_v is -1", "MLT_WRAP_CLAMP_TO_EDGE"],
        h.textures[2].filter = 2
            => ["desc.textures[2].filter is 2", "MLT_FILTER_NEAREST", "MLT_FILTER_BILINEAR"],
        // Textures: sizes (each refused before the texels are read).
        h.textures[0].width = 0 => ["desc.textures[0].width is 0", "at least 1 x 1"],
        h.textures[1].height = 0 => ["desc.textures[1].height is 0", "at least 1 x 1"],
        h.textures[0].width = MLT_MAX_TEXTURE_SIDE + 1
            => ["desc.textures[0].width is 32769", "at most 32768"],
        (h.textures[0].width, h.textures[0].height) = (1 << 15, 1 << 14)
            => ["desc.textures[0] is 32768 x 16384", "at most 268435456"],
        (h.textures[1].width, h.textures[1].height, h.textures[1].channels)
            = (u32::MAX, u32::MAX, u32::MAX)
            => ["desc.textures[1].width is 4294967295"],
        h.textures[0].channels = 0 => ["desc.textures[0].channels is 0", "1 (grey)"],
        h.textures[2].channels = 5 => ["desc.textures[2].channels is 5", "4 (RGBA)"],
        // Textures: texels.
        h.textures[2].texels = null() => ["desc.textures[2].texels is NULL"],
        h.textures[1].texels = odd.cast() => ["desc.textures[1].texels", "aligned"],
        h.metallic_roughness_texels[4] = -1.0
            => ["desc.textures[1].texels[4]", "row 0", "column 1", "channel 1", "is -1", ">= 0"],
        h.metallic_roughness_texels[9] = f32::NAN
            => ["desc.textures[1].texels[9]", "row 1", "column 1", "channel 0", "is NaN"],
        h.metallic_roughness_texels[11] = f32::INFINITY
            => ["desc.textures[1].texels[11]", "is inf"],
        h.textures[0].struct_size = 0
            => ["desc.textures[0].struct_size is 0", "mlt_texture_default"],
        h.textures[2].struct_size = 40
            => ["desc.textures[2].struct_size is 40", "desc.textures[0]'s"],
        // Vertex attributes: lengths.
        h.normals.pop() => ["desc.normals has 23 floats", "3 per vertex", "24 for 8 vertices"],
        h.texcoords.push(0.0) => ["desc.texcoords has 17 floats", "2 per vertex", "16"],
        h.texcoords1.pop() => ["desc.texcoords1 has 15 floats", "2 per vertex", "16"],
        h.tangents.truncate(28) => ["desc.tangents has 28 floats", "4 per vertex", "32"],
        h.colors.truncate(24) => ["desc.colors has 24 floats", "4 per vertex", "32"],
        // Vertex attributes: values.
        h.normals[3..6].copy_from_slice(&[0.0; 3])
            => ["desc.normals of vertex 1", "nonzero length"],
        h.tangents[7] = 0.0 => ["desc.tangents of vertex 1", "w = ±1"],
        h.tangents[12..15].copy_from_slice(&[0.0; 3])
            => ["desc.tangents of vertex 3", "nonzero length"],
        h.colors[5] = 1.5 => ["desc.colors[5]", "vertex 1", "g", "is 1.5", "[0, 1]"],
        h.colors[0] = -0.1 => ["desc.colors[0]", "vertex 0", "r", "is -0.1", "[0, 1]"],
        h.colors[31] = f32::NAN => ["desc.colors[31]", "vertex 7", "a", "is NaN"],
    ];
    cases.extend(non_finite_cases![h = HostSurfaces::new();
        h.host.materials[0].metallic => "desc.materials[0].metallic" + "finite",
        h.host.materials[0].roughness => "desc.materials[0].roughness" + "finite",
        h.host.materials[1].transmission => "desc.materials[1].transmission" + "finite",
        h.host.materials[0].alpha => "desc.materials[0].alpha" + "finite",
        h.host.materials[0].thickness => "desc.materials[0].thickness" + "finite",
        h.host.materials[1].attenuation_distance
            => "desc.materials[1].attenuation_distance" + "finite",
        h.host.materials[0].alpha_cutoff => "desc.materials[0].alpha_cutoff" + "finite",
        h.host.materials[0].normal_scale => "desc.materials[0].normal_scale" + "finite",
        h.host.materials[0].clearcoat => "desc.materials[0].clearcoat" + "finite",
        h.host.materials[1].clearcoat_normal_scale
            => "desc.materials[1].clearcoat_normal_scale" + "finite",
        h.host.materials[0].base_color_texture.rotation
            => "desc.materials[0].base_color_texture.rotation" + "finite",
        h.host.materials[0].base_color_texture.offset[1]
            => "desc.materials[0].base_color_texture.offset.v" + "finite",
        h.host.materials[0].normal_texture.scale[0]
            => "desc.materials[0].normal_texture.scale.u" + "finite",
        h.host.materials[1].emission_texture.scale[1]
            => "desc.materials[1].emission_texture.scale.v" + "finite",
        h.normals[4] => "desc.normals[4] (vertex 1, y)" + "finite",
        h.texcoords[3] => "desc.texcoords[3] (vertex 1, v)" + "finite",
        h.texcoords1[4] => "desc.texcoords1[4] (vertex 2, u)" + "finite",
        h.tangents[8] => "desc.tangents[8] (vertex 2, x)" + "finite",
        h.colors[2] => "desc.colors[2] (vertex 0, b)",
    ]);
    assert_create_refuses("surfaces", &cases, HostSurfaces::desc);

    // Pointers and counts of the description itself.
    let surfaces = HostSurfaces::new();
    let cases = cases![d = surfaces.desc();
        d.normals = null() => ["desc.normals is NULL"],
        d.texcoords = null() => ["desc.texcoords is NULL"],
        d.texcoords1 = null() => ["desc.texcoords1 is NULL"],
        d.texcoords1 = odd.cast() => ["desc.texcoords1", "aligned"],
        d.texcoords1_len = usize::MAX => ["desc.texcoords1", "address space"],
        d.texcoords1_len = 14 => ["desc.texcoords1 has 14 floats"],
        d.tangents = null() => ["desc.tangents is NULL"],
        d.colors = null() => ["desc.colors is NULL"],
        d.textures = null() => ["desc.textures[0] is NULL"],
        d.normals = odd.cast() => ["desc.normals", "aligned"],
        d.textures = odd.cast() => ["desc.textures[0]", "aligned"],
        d.colors_len = usize::MAX => ["desc.colors", "address space"],
        d.texcoords_len = 15 => ["desc.texcoords has 15 floats"],
        (d.texcoords, d.texcoords_len) = (null(), 0)
            => ["desc.materials[0] has textures", "desc.texcoords is empty"],
        d.textures_len = 2 => ["desc.materials[0].normal_texture.texture is 2", "2 textures"],
    ];
    assert_create_refuses("surface pointers", &cases, |d| *d);
}

/// The kind `MLT_MATERIAL_METALLIC_ROUGHNESS` passes the C ABI's checks: the scene is
/// created (and renders), or, in a build whose kernel cannot render the model yet, refused
/// as `MLT_STATUS_UNSUPPORTED` naming it, never as an invalid argument.
#[test]
fn metallic_roughness_materials_pass_the_c_abi() {
    let mut surfaces = HostSurfaces::new();
    surfaces.host.materials[0].kind = MLT_MATERIAL_METALLIC_ROUGHNESS;
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    let status = unsafe { mlt_scene_create(&surfaces.desc(), &mut out) };
    if status == MLT_STATUS_UNSUPPORTED {
        assert!(out.is_null());
        assert!(
            last_error().contains("desc.materials[0]"),
            "{}",
            last_error()
        );
        assert!(
            last_error().contains("metallic-roughness"),
            "{}",
            last_error()
        );
        return;
    }
    assert_ok(status);
    let scene = Handle(out);
    let (status, image) = scene.render(&floor_camera(), &small_settings(4, 4, 2), 48);
    assert_ok(status);
    assert_valid_image(&image, "metallic-roughness floor");
}

/// Materials as a host built against mlt 0.2's header has them.
fn materials_of_02(materials: &[MltMaterial]) -> [MaterialOf02; 2] {
    std::array::from_fn(|i| {
        let m = materials[i];
        MaterialOf02 {
            struct_size: 36,
            kind: m.kind,
            color: m.color,
            emission: m.emission,
            ior: m.ior,
        }
    })
}

/// mlt 0.2's `MltMaterial`: the fields before `metallic`.
#[repr(C)]
#[derive(Clone, Copy)]
struct MaterialOf02 {
    struct_size: u32,
    kind: i32,
    color: [f32; 3],
    emission: [f32; 3],
    ior: f32,
}

/// Hosts built against older headers: a material array of mlt 0.2's 36-byte layout, and a
/// scene description of the 112-byte layout (lights, no surface attributes), whatever
/// their memory holds past their structs, give the scene a current host gets with the
/// defaults of the new fields: the same image.
#[test]
fn older_materials_and_scene_descs_default_the_surface_fields() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    let settings = small_settings(4, 4, 4);
    let (status, expected) = scene.render(&floor_camera(), &settings, 48);
    assert_ok(status);

    #[repr(C)]
    struct OlderMaterials {
        materials: [MaterialOf02; 2],
        /// What lies past an older host's array: NaN, never read.
        garbage: [u32; 64],
    }
    let older_materials = OlderMaterials {
        materials: materials_of_02(&host.materials),
        garbage: [0xFFFF_FFFF; 64],
    };
    let first_missing = std::mem::offset_of!(MltMaterial, metallic);
    assert_eq!(earlier_size::<MltMaterial>(first_missing), 36);
    assert_eq!(
        size_of::<MaterialOf02>(),
        36,
        "mlt 0.2's sizeof(MltMaterial)"
    );
    let desc = MltSceneDesc {
        materials: older_materials.materials.as_ptr().cast(),
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: an array of 2 materials of the older layout, as their struct_size says.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let (status, image) = Handle(out).render(&floor_camera(), &settings, 48);
    assert_ok(status);
    assert_eq!(image, expected, "0.2 materials: the same scene");

    let older_desc = MltSceneDesc {
        struct_size: earlier_size::<MltSceneDesc>(std::mem::offset_of!(MltSceneDesc, normals)),
        // Garbage an older host's memory may hold: mlt must not read it.
        normals: std::ptr::dangling(),
        normals_len: usize::MAX,
        texcoords: std::ptr::dangling(),
        texcoords_len: 3,
        tangents: null(),
        tangents_len: 5,
        colors: std::ptr::dangling(),
        colors_len: 7,
        textures: std::ptr::dangling(),
        textures_len: usize::MAX,
        ..host.desc()
    };
    assert_eq!(
        older_desc.struct_size, 112,
        "the lights' sizeof(MltSceneDesc)"
    );
    let mut out = null_mut();
    // SAFETY: an older layout's struct; mlt reads only its first 112 bytes.
    assert_ok(unsafe { mlt_scene_create(&older_desc, &mut out) });
    let (status, image) = Handle(out).render(&floor_camera(), &settings, 48);
    assert_ok(status);
    assert_eq!(image, expected, "a 112-byte desc: the same scene");
}

/// The floor of `HostScene::floor_and_light` with a base colour texture of two texels, black
/// (left) and white (right), read at a constant point of each set of texture coordinates.
struct TwoSets {
    host: HostScene,
    texcoords: Vec<f32>,
    texcoords1: Vec<f32>,
    #[allow(dead_code)]
    texels: Vec<u8>,
    texture: MltTexture,
}

/// The texel centres of `TwoSets`' texture.
const BLACK_TEXEL: [f32; 2] = [0.25, 0.5];
const WHITE_TEXEL: [f32; 2] = [0.75, 0.5];

impl TwoSets {
    /// Set 0 at `set0`, set 1 at `set1` on every vertex; the floor's base colour slot reads
    /// the sets `texcoord1_slots` says.
    fn new(set0: [f32; 2], set1: [f32; 2], texcoord1_slots: u32) -> Self {
        let mut host = HostScene::floor_and_light();
        host.materials[0].base_color_texture = slot(0);
        host.materials[0].color = [1.0; 3];
        host.materials[0].texcoord1_slots = texcoord1_slots;
        let texels = vec![0, 0, 0, 255, 255, 255];
        let texture = MltTexture {
            width: 2,
            height: 1,
            channels: 3,
            texels: texels.as_ptr().cast(),
            encoding: MLT_TEXTURE_LINEAR,
            wrap_u: MLT_WRAP_CLAMP_TO_EDGE,
            wrap_v: MLT_WRAP_CLAMP_TO_EDGE,
            filter: MLT_FILTER_NEAREST,
            ..default_texture()
        };
        TwoSets {
            host,
            texcoords: set0.repeat(8),
            texcoords1: set1.repeat(8),
            texels,
            texture,
        }
    }

    fn render(&self) -> Vec<f32> {
        let desc = MltSceneDesc {
            texcoords: self.texcoords.as_ptr(),
            texcoords_len: self.texcoords.len(),
            texcoords1: self.texcoords1.as_ptr(),
            texcoords1_len: self.texcoords1.len(),
            textures: &self.texture,
            textures_len: 1,
            ..self.host.desc()
        };
        let mut out = null_mut();
        // SAFETY: the desc points into live values.
        assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
        let (status, image) = Handle(out).render(&TwoSets::camera(), &small_settings(8, 8, 4), 192);
        assert_ok(status);
        image
    }

    /// Straight down at the floor from below the light: the floor fills the image.
    fn camera() -> MltCamera {
        MltCamera {
            eye: [0.0, 1.5, 0.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 0.0, 1.0],
            fov_y_deg: 60.0,
            ..default_camera()
        }
    }
}

/// A slot whose bit of `texcoord1_slots` is set reads texture coordinate set 1, the others
/// set 0: the floor reading the white texel through set 1 is the image of the floor reading
/// it through set 0, bit for bit, and the floor reading the black texel is darker.
#[test]
fn a_slot_reads_texture_coordinate_set_1_where_its_bit_is_set() {
    let white_through_set1 =
        TwoSets::new(BLACK_TEXEL, WHITE_TEXEL, MLT_TEXCOORD1_BASE_COLOR).render();
    let white_through_set0 = TwoSets::new(WHITE_TEXEL, BLACK_TEXEL, 0).render();
    let black_through_set0 = TwoSets::new(BLACK_TEXEL, WHITE_TEXEL, 0).render();
    // A bit of a slot without a texture changes nothing.
    let black_with_other_bits = TwoSets::new(
        BLACK_TEXEL,
        WHITE_TEXEL,
        MLT_TEXCOORD1_EMISSION | MLT_TEXCOORD1_NORMAL,
    )
    .render();
    assert_valid_image(&white_through_set1, "set 1");
    assert_eq!(white_through_set1, white_through_set0);
    assert_eq!(black_with_other_bits, black_through_set0);
    // The floor fills the image: black reflects nothing, white every pixel.
    assert!(black_through_set0.iter().all(|&v| v == 0.0));
    assert!(
        white_through_set1.iter().all(|&v| v > 0.0),
        "{white_through_set1:?}"
    );
}

/// Hosts built against the header before texture coordinate set 1 (materials of 520 bytes,
/// scene descriptions of 200) get set 0 everywhere, whatever their memory holds past their
/// structs: the image of a current host's scene without set 1.
#[test]
fn layouts_before_texture_coordinate_set_1_read_set_0() {
    let two_sets = TwoSets::new(WHITE_TEXEL, BLACK_TEXEL, 0);
    let expected = two_sets.render();

    let old_material = std::mem::offset_of!(MltMaterial, texcoord1_slots);
    assert_eq!(earlier_size::<MltMaterial>(old_material), 520);
    let old_desc = std::mem::offset_of!(MltSceneDesc, texcoords1);
    assert_eq!(earlier_size::<MltSceneDesc>(old_desc), 200);

    // Two 520-byte materials, then bits no header has (every texcoord1 bit set): read past
    // the array, they would be refused.
    let count = two_sets.host.materials.len();
    let mut words = vec![u32::MAX; (old_material * count) / 4 + 64];
    for (i, material) in two_sets.host.materials.iter().enumerate() {
        let material = MltMaterial {
            struct_size: old_material as u32,
            ..*material
        };
        // SAFETY: the first 520 bytes of a material into element i of the 520-byte stride
        // array, which `words` holds.
        unsafe {
            std::ptr::copy_nonoverlapping(
                (&raw const material).cast::<u8>(),
                words.as_mut_ptr().cast::<u8>().add(i * old_material),
                old_material,
            )
        };
    }
    let desc = MltSceneDesc {
        struct_size: old_desc as u32,
        materials: words.as_ptr().cast(),
        texcoords: two_sets.texcoords.as_ptr(),
        texcoords_len: two_sets.texcoords.len(),
        textures: &two_sets.texture,
        textures_len: 1,
        // Garbage an older host's memory may hold: mlt must not read it.
        texcoords1: std::ptr::dangling(),
        texcoords1_len: 3,
        ..two_sets.host.desc()
    };
    let mut out = null_mut();
    // SAFETY: older layouts' structs; mlt reads the first 200 bytes of the desc and 520 of
    // each material.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let (status, image) = Handle(out).render(&TwoSets::camera(), &small_settings(8, 8, 4), 192);
    assert_ok(status);
    assert_eq!(image, expected, "older layouts: the scene reading set 0");
}
