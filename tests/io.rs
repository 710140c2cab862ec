//! Scene loaders and image writers of `mlt::io`: OBJ/MTL, glTF and GLB (meshes, materials,
//! textures, cameras, punctual lights), camera sidecars, environment maps and PFM, PNG and
//! EXR read exactly as written; malformed files are errors naming the file and the problem;
//! and the committed generated scenes are what their generators in tests/common/ write.
//!
//! Runs in under a second on 2 cores (`cargo test --test io`).
#![cfg(feature = "cli")]

mod common {
    pub mod door_ajar;
    pub mod lamp_behind_glass;
    pub mod obj_text;
    pub mod sky_spheres;
    pub mod window_room;
}

use common::{door_ajar, lamp_behind_glass, sky_spheres, window_room};

use mlt::io::{self, IoError, SceneData};
use mlt::{Material, MaterialKind, Scene};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes")
}

/// A fresh path in the temp directory, unique per process and call.
fn temp_path(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("mlt-io-test-{}-{n}-{name}", std::process::id()))
}

/// A temp directory holding the given files.
fn temp_dir_with(files: &[(&str, &[u8])]) -> PathBuf {
    let dir = temp_path("dir");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, contents) in files {
        std::fs::write(dir.join(name), contents).unwrap();
    }
    dir
}

fn face_count(obj: &Path) -> usize {
    std::fs::read_to_string(obj)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("f "))
        .count()
}

fn material_named<'a>(data: &'a SceneData, name: &str) -> (u32, &'a Material) {
    let i = data
        .material_names
        .iter()
        .position(|n| n == name)
        .unwrap_or_else(|| panic!("no material {name} in {:?}", data.material_names));
    (i as u32, &data.materials[i])
}

fn vertex(data: &SceneData, i: u32) -> glam::Vec3 {
    let i = i as usize * 3;
    glam::Vec3::from_slice(&data.positions[i..i + 3])
}

/// Unit normal of triangle `t` by its counter-clockwise winding.
fn normal(data: &SceneData, t: usize) -> glam::Vec3 {
    let tri = &data.indices[t * 3..t * 3 + 3];
    let (a, b, c) = (
        vertex(data, tri[0]),
        vertex(data, tri[1]),
        vertex(data, tri[2]),
    );
    (b - a).cross(c - a).normalize()
}

#[test]
fn cornell_box_obj_loads_triangles_materials_and_camera() {
    let path = scenes().join("cornell-box.obj");
    let data = io::load_scene(&path).unwrap();
    assert_eq!(face_count(&path), 32);
    assert_eq!(data.triangle_count(), 32);
    assert_eq!(data.material_ids.len(), 32);
    assert_eq!(data.positions.len() % 3, 0);
    assert!(
        data.indices
            .iter()
            .all(|&i| (i as usize) < data.positions.len() / 3)
    );

    // Exactly the four MTL materials: no default material was needed.
    assert_eq!(data.materials.len(), 4);
    let expect = [
        ("white", [0.725, 0.71, 0.68], [0.0; 3]),
        ("red", [0.63, 0.065, 0.05], [0.0; 3]),
        ("green", [0.14, 0.45, 0.091], [0.0; 3]),
        ("light", [0.0; 3], [17.0, 12.0, 4.0]),
    ];
    for (name, kd, ke) in expect {
        let (_, m) = material_named(&data, name);
        assert_eq!(m.kind, MaterialKind::Diffuse, "{name}");
        assert_eq!(m.color, kd, "{name}");
        assert_eq!(m.emission, ke, "{name}");
    }

    // The two light triangles emit (17, 12, 4) and face -y (winding kept).
    let (light, _) = material_named(&data, "light");
    let lights: Vec<usize> = (0..32).filter(|&t| data.material_ids[t] == light).collect();
    assert_eq!(lights.len(), 2);
    for &t in &lights {
        assert_eq!(
            data.materials[data.material_ids[t] as usize].emission,
            [17.0, 12.0, 4.0]
        );
        assert!((normal(&data, t) - glam::Vec3::NEG_Y).length() < 1e-4);
        assert!((vertex(&data, data.indices[t * 3]).y - 548.7).abs() < 0.2);
    }
    // Emission appears on the light triangles only.
    let emitting = (0..32)
        .filter(|&t| data.materials[data.material_ids[t] as usize].is_emissive())
        .count();
    assert_eq!(emitting, 2);

    // The camera sidecar beside the OBJ.
    let camera = data.camera.expect("cornell-box.camera.json is loaded");
    assert_eq!(camera.width, 256);
    assert_eq!(camera.height, 256);
    assert_eq!(camera.camera.eye, [278.0, 273.0, -800.0]);

    // And the kernel accepts it.
    let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    assert_eq!(scene.info().triangle_count, 32);
    assert_eq!(scene.info().emitter_count, 2);
}

/// Writes a generated scene's files (with `MLT_WRITE_SCENES=1`) or checks the committed
/// ones are what its generator writes.
fn check_generated_scene(files: [(&str, String); 3]) {
    for (name, text) in files {
        let path = scenes().join(name);
        if std::env::var_os("MLT_WRITE_SCENES").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap();
        assert!(
            committed == text,
            "{name} differs from its generator: rewrite it with MLT_WRITE_SCENES=1 cargo test --test io"
        );
    }
}

/// The committed door-ajar files are what `tests/common/door_ajar.rs` writes (with
/// `MLT_WRITE_SCENES=1`, this test writes them instead), and the scene loads with one
/// light, its camera sidecar and a door standing open.
#[test]
fn door_ajar_scene_files_are_what_the_generator_writes() {
    check_generated_scene(door_ajar::files());
    let data = io::load_scene(&scenes().join("door-ajar.obj")).unwrap();
    let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    assert_eq!(scene.info().emitter_count, 2);
    assert!(data.camera.is_some());
    let (door, _) = material_named(&data, "door");
    let door_faces = data.material_ids.iter().filter(|&&m| m == door).count();
    assert_eq!(door_faces, 8);
}

/// The same for `tests/common/lamp_behind_glass.rs`: one two-triangle lamp, and a closed
/// glass slab of ior 1.5 (12 triangles) under it.
#[test]
fn lamp_behind_glass_scene_files_are_what_the_generator_writes() {
    check_generated_scene(lamp_behind_glass::files());
    let data = io::load_scene(&scenes().join("lamp-behind-glass.obj")).unwrap();
    let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    assert_eq!(scene.info().emitter_count, 2);
    assert!(data.camera.is_some());
    let (glass, m) = material_named(&data, "glass");
    assert_eq!((m.kind, m.ior), (MaterialKind::Dielectric, 1.5));
    let glass_faces = data.material_ids.iter().filter(|&&id| id == glass).count();
    assert_eq!(glass_faces, 12);
}

/// The same for `tests/common/window_room.rs`: no emitter (the sky and sun light it) and
/// a window opening in the wall z = 5000.
#[test]
fn window_room_scene_files_are_what_the_generator_writes() {
    check_generated_scene(window_room::files());
    let data = io::load_scene(&scenes().join("window-room.obj")).unwrap();
    let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    assert_eq!(scene.info().emitter_count, 0);
    assert!(data.camera.is_some());
    // A ray out through the window's centre escapes; one through the wall beside it does not.
    let out = |x: f32| {
        mlt::accel::Ray::new(
            glam::Vec3A::new(x, 1400.0, 4000.0),
            glam::Vec3A::Z,
            0.0,
            f32::INFINITY,
        )
    };
    assert!(scene.intersect(&out(2000.0)).is_none());
    assert!(scene.intersect(&out(1000.0)).is_some());
    // Its sky, for the command line's --env: the generator's map, exactly (EXR keeps f32).
    let sky_path = scenes().join("sky.exr");
    let (width, height) = window_room::SKY_SIZE;
    let pixels = window_room::sky_pixels();
    if std::env::var_os("MLT_WRITE_SCENES").is_some() {
        io::write_exr(&sky_path, width, height, &pixels).unwrap();
    }
    let (read, read_width, read_height) = io::load_environment(&sky_path).unwrap();
    assert_eq!((read_width, read_height), (width, height));
    assert!(
        read == pixels,
        "sky.exr differs from its generator: rewrite it with MLT_WRITE_SCENES=1 cargo test --test io"
    );
}

/// The committed sky-spheres glTF files are what `tests/common/sky_spheres.rs` writes (with
/// `MLT_WRITE_SCENES=1`, this test writes them instead), and the scene loads with its
/// camera, a diffuse ground and clay sphere, a mirror and a glass sphere.
#[test]
fn sky_spheres_scene_files_are_what_the_generator_writes() {
    let (bin, gltf) = sky_spheres::files();
    let (bin_path, gltf_path) = (
        scenes().join("sky-spheres.bin"),
        scenes().join("sky-spheres.gltf"),
    );
    if std::env::var_os("MLT_WRITE_SCENES").is_some() {
        std::fs::write(&bin_path, &bin).unwrap();
        std::fs::write(&gltf_path, &gltf).unwrap();
    }
    assert!(
        std::fs::read(&bin_path).unwrap() == bin
            && std::fs::read_to_string(&gltf_path).unwrap() == gltf,
        "sky-spheres differs from its generator: rewrite it with MLT_WRITE_SCENES=1 cargo test --test io"
    );
    let data = io::load_scene(&gltf_path).unwrap();
    assert!(data.camera.is_some());
    // glTF materials are metallic-roughness: (metallic, roughness, transmission, ior).
    let parameters: Vec<_> = data
        .materials
        .iter()
        .map(|m| {
            assert_eq!(m.kind, MaterialKind::MetallicRoughness);
            (m.metallic, m.roughness, m.transmission, m.ior)
        })
        .collect();
    assert_eq!(
        parameters,
        [
            (0.0, 0.8, 0.0, 1.5),
            (0.0, 0.6, 0.0, 1.5),
            (1.0, 0.15, 0.0, 1.5),
            (0.0, 0.0, 1.0, 1.5)
        ]
    );
    // The ground's checker (sRGB, nearest, repeated at half scale) and the clay's bumps
    // (linear, clamped in v), each vertex with a normal and texture coordinates.
    let ground = &data.materials[0];
    let checker = ground.base_color_texture.expect("the checker");
    assert_eq!(checker.scale, [0.5, 0.5]);
    let texture = &data.textures[checker.texture as usize];
    assert_eq!((texture.width, texture.height, texture.channels), (2, 2, 3));
    assert_eq!(texture.encoding, mlt::TextureEncoding::Srgb);
    assert_eq!(texture.filter, mlt::TextureFilter::Nearest);
    assert!(matches!(&texture.data, mlt::TexelData::U8(t) if t[..3] == [200, 190, 170]));
    let bumps = data.materials[1].normal_texture.expect("the normal map");
    let texture = &data.textures[bumps.texture as usize];
    assert_eq!((texture.width, texture.height), (128, 64));
    assert_eq!(texture.encoding, mlt::TextureEncoding::Linear);
    assert_eq!(
        (texture.wrap_u, texture.wrap_v),
        (mlt::WrapMode::Repeat, mlt::WrapMode::ClampToEdge)
    );
    let vertices = data.positions.len() / 3;
    assert_eq!(data.normals.len(), vertices * 3);
    assert_eq!(data.texcoords.len(), vertices * 2);
    assert!(data.tangents.is_empty() && data.colors.is_empty());
    assert_eq!(data.triangle_count(), 2 + 3 * (24 * 48 * 2 - 2 * 48));
}

/// `KHR_materials_transmission`'s `transmissionTexture` becomes the material's
/// transmission texture, with its texture transform: the sky-spheres glass given the
/// clay's (linear) normal-map image as one.
#[test]
fn gltf_transmission_texture_is_read() {
    let text = std::fs::read_to_string(scenes().join("sky-spheres.gltf")).unwrap();
    let textured = text.replacen(
        r#""transmissionFactor": 1.0"#,
        r#""transmissionFactor": 1.0, "transmissionTexture": { "index": 1, "extensions": { "KHR_texture_transform": { "rotation": 0.5 } } }"#,
        1,
    );
    assert_ne!(text, textured);
    let dir = temp_path("transmission-texture");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        scenes().join("sky-spheres.bin"),
        dir.join("sky-spheres.bin"),
    )
    .unwrap();
    let path = dir.join("sky-spheres.gltf");
    std::fs::write(&path, textured).unwrap();
    let data = io::load_scene(&path).unwrap();
    let (_, glass) = material_named(&data, "glass");
    let (_, clay) = material_named(&data, "clay");
    let slot = glass
        .transmission_texture
        .expect("the transmission texture");
    assert_eq!(slot.texture, clay.normal_texture.unwrap().texture);
    assert_eq!(slot.rotation, 0.5);
    assert_eq!(clay.transmission_texture, None);
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
}

/// sky-spheres.gltf with `KHR_materials_clearcoat` (required) on its metal, whose
/// `extension` JSON is given, written to a folder of its own named `name`.
fn sky_spheres_with_clearcoat(name: &str, extension: &str) -> PathBuf {
    let text = std::fs::read_to_string(scenes().join("sky-spheres.gltf")).unwrap();
    let coated = text
        .replacen(
            r#""extensionsUsed": ["#,
            r#""extensionsRequired": ["KHR_materials_clearcoat"], "extensionsUsed": ["KHR_materials_clearcoat", "#,
            1,
        )
        .replacen(
            r#""name": "metal","#,
            &format!(r#""name": "metal", "extensions": {{"KHR_materials_clearcoat": {extension}}},"#),
            1,
        );
    assert_eq!(
        coated.matches("KHR_materials_clearcoat").count(),
        3,
        "{coated}"
    );
    let dir = temp_path(name);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        scenes().join("sky-spheres.bin"),
        dir.join("sky-spheres.bin"),
    )
    .unwrap();
    let path = dir.join("sky-spheres.gltf");
    std::fs::write(&path, coated).unwrap();
    path
}

/// A file that requires `KHR_materials_clearcoat` loads, with its factors, its textures
/// (and their transforms) and its normal map's scale.
#[test]
fn gltf_clearcoat_is_read() {
    let path = sky_spheres_with_clearcoat(
        "clearcoat",
        r#"{"clearcoatFactor": 0.75, "clearcoatRoughnessFactor": 0.125,
            "clearcoatTexture": {"index": 0, "texCoord": 0},
            "clearcoatRoughnessTexture": {"index": 1,
                "extensions": {"KHR_texture_transform": {"offset": [0.25, 0.5], "rotation": 0.5, "scale": [2, 3]}}},
            "clearcoatNormalTexture": {"index": 1, "scale": 0.5}}"#,
    );
    let data = io::load_scene(&path).unwrap();
    let (_, metal) = material_named(&data, "metal");
    let (_, clay) = material_named(&data, "clay");
    assert_eq!((metal.clearcoat, metal.clearcoat_roughness), (0.75, 0.125));
    let normal_map = clay.normal_texture.unwrap().texture;
    assert_ne!(metal.clearcoat_texture.unwrap().texture, normal_map);
    let roughness = metal.clearcoat_roughness_texture.unwrap();
    assert_eq!(roughness.texture, normal_map);
    assert_eq!(
        (roughness.offset, roughness.rotation, roughness.scale),
        ([0.25, 0.5], 0.5, [2.0, 3.0])
    );
    assert_eq!(metal.clearcoat_normal_texture.unwrap().texture, normal_map);
    assert_eq!(metal.clearcoat_normal_scale, 0.5);
    assert_eq!(metal.normal_texture, None);
    assert_eq!((clay.clearcoat, clay.clearcoat_texture), (0.0, None));
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
}

/// Bad clear coat values are refused by the loader, naming the field.
#[test]
fn gltf_bad_clearcoat_values_are_refused() {
    for (extension, expected) in [
        (r#"{"clearcoatFactor": 1.5}"#, "clearcoatFactor is 1.5"),
        (r#"{"clearcoatFactor": -0.1}"#, "clearcoatFactor is -0.1"),
        (
            r#"{"clearcoatRoughnessFactor": "rough"}"#,
            "clearcoatRoughnessFactor",
        ),
        (
            r#"{"clearcoatTexture": {"index": 9}}"#,
            "clearcoatTexture has index 9",
        ),
        (
            r#"{"clearcoatNormalTexture": {"index": 1, "scale": "x"}}"#,
            "scale",
        ),
    ] {
        let path = sky_spheres_with_clearcoat("bad-clearcoat", extension);
        let error = io::load_scene(&path).unwrap_err().to_string();
        assert!(
            error.contains("KHR_materials_clearcoat") && error.contains(expected),
            "{extension}: {error}"
        );
    }
}

/// MTL's PBR clear coat: `Pc` (its factor) and `Pcr` (its roughness); a NaN roughness is
/// refused when the scene is made, naming the field.
#[test]
fn mtl_clearcoat_is_read_and_bad_values_refused() {
    let obj =
        b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paint\nf 1 2 3\nusemtl nan\nf 1 2 3\n";
    let mtl =
        b"newmtl paint\nKd 0.5 0.1 0.1\nPc 0.8\nPcr 0.05\nnewmtl nan\nPr 0.5\nPc 1\nPcr nan\n";
    let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl)]);
    let data = io::load_scene(&dir.join("t.obj")).unwrap();
    let (_, paint) = material_named(&data, "paint");
    assert_eq!(paint.kind, MaterialKind::MetallicRoughness);
    assert_eq!((paint.clearcoat, paint.clearcoat_roughness), (0.8, 0.05));
    let Err(error) = Scene::new(&data.desc(mlt::Backend::Bvh)) else {
        panic!("a NaN clear coat roughness was accepted");
    };
    let error = error.to_string();
    assert!(
        error.contains("clearcoat_roughness") && error.contains("NaN"),
        "{error}"
    );
}

/// The sky-spheres scene with its clay given `KHR_materials_specular` and
/// `KHR_materials_sheen` (`clay_extensions`, JSON members), both listed as required, written
/// beside its buffer.
fn sky_spheres_with_clay_extensions(name: &str, clay_extensions: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scenes().join("sky-spheres.gltf")).unwrap();
    let edited = text
        .replacen(
            r#""name": "clay","#,
            &format!(r#""name": "clay", "extensions": {{ {clay_extensions} }},"#),
            1,
        )
        .replacen(
            r#""extensionsUsed": ["#,
            r#""extensionsRequired": ["KHR_materials_specular", "KHR_materials_sheen"], "extensionsUsed": ["KHR_materials_specular", "KHR_materials_sheen","#,
            1,
        );
    let dir = temp_path(name);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        scenes().join("sky-spheres.bin"),
        dir.join("sky-spheres.bin"),
    )
    .unwrap();
    let path = dir.join("sky-spheres.gltf");
    std::fs::write(&path, edited).unwrap();
    path
}

/// `KHR_materials_specular` and `KHR_materials_sheen` are read, factors and textures (with
/// their texture transforms, colours as sRGB), and a file that requires them loads;
/// values out of the specifications' ranges are clear errors.
#[test]
fn gltf_specular_and_sheen_are_read() {
    let path = sky_spheres_with_clay_extensions(
        "specular-sheen",
        r#""KHR_materials_specular": { "specularFactor": 0.5, "specularColorFactor": [2.0, 1.0, 0.5],
              "specularTexture": { "index": 1 }, "specularColorTexture": { "index": 1 } },
            "KHR_materials_sheen": { "sheenColorFactor": [0.9, 0.4, 0.1], "sheenRoughnessFactor": 0.3,
              "sheenColorTexture": { "index": 1, "extensions": { "KHR_texture_transform": { "scale": [30.0, -30.0] } } },
              "sheenRoughnessTexture": { "index": 1 } }"#,
    );
    let data = io::load_scene(&path).unwrap();
    let (_, clay) = material_named(&data, "clay");
    assert_eq!(clay.specular, 0.5);
    assert_eq!(clay.specular_color, [2.0, 1.0, 0.5]);
    assert_eq!(clay.sheen_color, [0.9, 0.4, 0.1]);
    assert_eq!(clay.sheen_roughness, 0.3);
    let colour = clay.sheen_color_texture.expect("the sheen colour texture");
    assert_eq!(colour.scale, [30.0, -30.0]);
    let linear = clay.normal_texture.unwrap().texture;
    // Colours are sRGB, strengths and roughnesses linear: one image, two textures.
    assert_eq!(clay.specular_texture.unwrap().texture, linear);
    assert_eq!(clay.sheen_roughness_texture.unwrap().texture, linear);
    assert_ne!(colour.texture, linear);
    assert_eq!(clay.specular_color_texture.unwrap().texture, colour.texture);
    let (_, glass) = material_named(&data, "glass");
    assert_eq!((glass.specular, glass.sheen_color), (1.0, [0.0; 3]));
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();

    for (bad, needle) in [
        (
            r#""KHR_materials_specular": { "specularFactor": -0.5 }"#,
            "specularFactor",
        ),
        (
            r#""KHR_materials_specular": { "specularColorFactor": [1.0, -1.0, 1.0] }"#,
            "specularColorFactor",
        ),
        (
            r#""KHR_materials_sheen": { "sheenColorFactor": [1.5, 0.0, 0.0] }"#,
            "sheenColorFactor",
        ),
        (
            r#""KHR_materials_sheen": { "sheenRoughnessFactor": "rough" }"#,
            "sheenRoughnessFactor",
        ),
        (
            r#""KHR_materials_sheen": { "sheenColorTexture": { "index": 99 } }"#,
            "sheenColorTexture",
        ),
    ] {
        let path = sky_spheres_with_clay_extensions("specular-sheen-bad", bad);
        let Err(error) = io::load_scene(&path) else {
            panic!("{bad} loads");
        };
        let error = error.to_string();
        assert!(error.contains(needle), "{bad}: {error}");
    }
}

/// `KHR_materials_anisotropy` is read: strength, rotation and texture (linear, with its
/// transform); a strength outside [0, 1], a rotation that is not a number and a missing
/// texture are clear errors.
#[test]
fn gltf_anisotropy_is_read() {
    let path = sky_spheres_with_clay_extensions(
        "anisotropy",
        r#""KHR_materials_anisotropy": { "anisotropyStrength": 0.6, "anisotropyRotation": 1.25,
              "anisotropyTexture": { "index": 1, "extensions": { "KHR_texture_transform": { "scale": [2.0, 3.0] } } } }"#,
    );
    let data = io::load_scene(&path).unwrap();
    let (_, clay) = material_named(&data, "clay");
    assert_eq!((clay.anisotropy, clay.anisotropy_rotation), (0.6, 1.25));
    let texture = clay.anisotropy_texture.expect("the anisotropy texture");
    assert_eq!(texture.scale, [2.0, 3.0]);
    assert_eq!(
        texture.texture,
        clay.normal_texture.unwrap().texture,
        "linear"
    );
    let (_, glass) = material_named(&data, "glass");
    assert_eq!((glass.anisotropy, glass.anisotropy_texture), (0.0, None));
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();

    for (bad, needle) in [
        (
            r#""KHR_materials_anisotropy": { "anisotropyStrength": 1.5 }"#,
            "anisotropyStrength",
        ),
        (
            r#""KHR_materials_anisotropy": { "anisotropyStrength": -0.1 }"#,
            "anisotropyStrength",
        ),
        (
            r#""KHR_materials_anisotropy": { "anisotropyRotation": "north" }"#,
            "anisotropyRotation",
        ),
        (
            r#""KHR_materials_anisotropy": { "anisotropyTexture": { "index": 99 } }"#,
            "anisotropyTexture",
        ),
    ] {
        let path = sky_spheres_with_clay_extensions("anisotropy-bad", bad);
        let Err(error) = io::load_scene(&path) else {
            panic!("{bad} loads");
        };
        let error = error.to_string();
        assert!(error.contains(needle), "{bad}: {error}");
    }
}

/// MTL's PBR anisotropy: `aniso` its strength, `anisor` its rotation in turns; a strength
/// above 1 is refused when the scene is made, naming the field.
#[test]
fn mtl_anisotropy_is_read_and_bad_values_refused() {
    let obj =
        b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl brushed\nf 1 2 3\nusemtl bad\nf 1 2 3\n";
    let mtl = b"newmtl brushed\nKd 0.9 0.9 0.9\nPm 1\nPr 0.3\naniso 0.8\nanisor 0.25\nnewmtl bad\naniso 2\n";
    let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl)]);
    let data = io::load_scene(&dir.join("t.obj")).unwrap();
    let (_, brushed) = material_named(&data, "brushed");
    assert_eq!(brushed.kind, MaterialKind::MetallicRoughness);
    assert_eq!(brushed.anisotropy, 0.8);
    assert_eq!(brushed.anisotropy_rotation, std::f32::consts::FRAC_PI_2);
    let Err(error) = Scene::new(&data.desc(mlt::Backend::Bvh)) else {
        panic!("an anisotropy of 2 was accepted");
    };
    let error = error.to_string();
    assert!(
        error.contains("anisotropy") && error.contains("[0, 1]"),
        "{error}"
    );
}

/// `sky_spheres_with_clay_extensions` with `KHR_materials_iridescence` required too.
fn sky_spheres_with_iridescent_clay(name: &str, clay_extensions: &str) -> std::path::PathBuf {
    let path = sky_spheres_with_clay_extensions(name, clay_extensions);
    let text = std::fs::read_to_string(&path).unwrap().replacen(
        r#""extensionsRequired": ["#,
        r#""extensionsRequired": ["KHR_materials_iridescence", "#,
        1,
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// `KHR_materials_iridescence` is read, factors and textures, with the specification's
/// defaults where a member is absent, and a file that requires it loads; values out of its
/// ranges are clear errors, in the loader and in the material's own checks.
#[test]
fn gltf_iridescence_is_read() {
    let path = sky_spheres_with_iridescent_clay(
        "iridescence",
        r#""KHR_materials_iridescence": { "iridescenceFactor": 0.8, "iridescenceIor": 1.6,
              "iridescenceThicknessMinimum": 150.0, "iridescenceThicknessMaximum": 600.0,
              "iridescenceTexture": { "index": 1 }, "iridescenceThicknessTexture": { "index": 1 } }"#,
    );
    let data = io::load_scene(&path).unwrap();
    let (_, clay) = material_named(&data, "clay");
    assert_eq!(clay.iridescence, 0.8);
    assert_eq!(clay.iridescence_ior, 1.6);
    assert_eq!(
        (
            clay.iridescence_thickness_minimum,
            clay.iridescence_thickness_maximum
        ),
        (150.0, 600.0)
    );
    // Linear, as the normal map: one image, one texture.
    let linear = clay.normal_texture.unwrap().texture;
    assert_eq!(clay.iridescence_texture.unwrap().texture, linear);
    assert_eq!(clay.iridescence_thickness_texture.unwrap().texture, linear);
    let (_, glass) = material_named(&data, "glass");
    assert_eq!(glass.iridescence, 0.0);
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();

    let path = sky_spheres_with_iridescent_clay(
        "iridescence-defaults",
        r#""KHR_materials_iridescence": { "iridescenceFactor": 1.0 }"#,
    );
    let data = io::load_scene(&path).unwrap();
    let (_, clay) = material_named(&data, "clay");
    assert_eq!(
        (
            clay.iridescence,
            clay.iridescence_ior,
            clay.iridescence_thickness_minimum,
            clay.iridescence_thickness_maximum
        ),
        (1.0, 1.3, 100.0, 400.0)
    );
    assert_eq!(clay.iridescence_texture, None);

    for (bad, needle) in [
        (
            r#""KHR_materials_iridescence": { "iridescenceFactor": 1.5 }"#,
            "iridescenceFactor",
        ),
        (
            r#""KHR_materials_iridescence": { "iridescenceIor": 0.5 }"#,
            "iridescenceIor",
        ),
        (
            r#""KHR_materials_iridescence": { "iridescenceThicknessMaximum": -1.0 }"#,
            "iridescenceThicknessMaximum",
        ),
        (
            r#""KHR_materials_iridescence": { "iridescenceThicknessMinimum": "thin" }"#,
            "iridescenceThicknessMinimum",
        ),
        (
            r#""KHR_materials_iridescence": { "iridescenceThicknessTexture": { "index": 99 } }"#,
            "iridescenceThicknessTexture",
        ),
    ] {
        let path = sky_spheres_with_iridescent_clay("iridescence-bad", bad);
        let Err(error) = io::load_scene(&path) else {
            panic!("{bad} loads");
        };
        let error = error.to_string();
        assert!(error.contains(needle), "{bad}: {error}");
    }

    let film = Material {
        iridescence: 1.0,
        ..Material::metallic_roughness([0.5; 3], 0.0, 0.5)
    };
    for (bad, field) in [
        (
            Material {
                iridescence_ior: 0.0,
                ..film
            },
            "iridescence_ior",
        ),
        (
            Material {
                iridescence_thickness_maximum: f32::NAN,
                ..film
            },
            "iridescence_thickness_maximum",
        ),
        (
            Material {
                iridescence_thickness_minimum: -5.0,
                ..film
            },
            "iridescence_thickness_minimum",
        ),
        (
            Material {
                iridescence: f32::NAN,
                ..film
            },
            "iridescence",
        ),
    ] {
        let error = bad.validate(0, 0).unwrap_err().to_string();
        assert!(error.contains(field), "{error}");
    }
    film.validate(0, 0).unwrap();
}

#[test]
fn cornell_glass_has_a_dielectric_with_ior_1_5() {
    let path = scenes().join("cornell-glass.obj");
    let data = io::load_scene(&path).unwrap();
    assert_eq!(data.triangle_count(), face_count(&path));
    let (glass, m) = material_named(&data, "glass");
    assert_eq!(m.kind, MaterialKind::Dielectric);
    assert_eq!(m.ior, 1.5);
    assert_eq!(m.color, [1.0; 3]);
    assert_eq!(m.emission, [0.0; 3]);
    let glass_triangles = data.material_ids.iter().filter(|&&id| id == glass).count();
    assert!(glass_triangles > 1000, "{glass_triangles}");
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
}

/// The dispersion example scene (written by `tools/prism_scene.py`): a flint prism (`Vd 20`),
/// one lamp, and its camera.
#[test]
fn prism_scene_has_a_dispersive_prism_and_one_lamp() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/prism.obj");
    let data = io::load_scene(&path).unwrap();
    let (_, flint) = material_named(&data, "flint");
    assert_eq!(
        (flint.kind, flint.ior, flint.abbe_number),
        (MaterialKind::Dielectric, 1.5, 20.0)
    );
    let lamps = data.materials.iter().filter(|m| m.is_emissive()).count();
    assert_eq!(lamps, 1);
    assert!(data.camera.is_some());
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
}

/// A colour statement with fewer than three values made tobj panic (found by the obj_mtl
/// fuzzer): it is an error naming the library, the line and the statement.
#[test]
fn mtl_colour_statements_with_too_few_values_are_errors() {
    for statement in ["Kd 0 0", "Ka", "Ks 1", "Ke 0.5 2"] {
        let mtl = format!("newmtl m\nNs 10\n{statement}\n");
        let obj = b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
        let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl.as_bytes())]);
        let error = io::load_scene(&dir.join("t.obj")).unwrap_err().message;
        let key = statement.split(' ').next().unwrap();
        assert!(error.contains("t.mtl"), "{error}");
        assert!(
            error.contains(&format!("line 3: {key} needs three numbers")),
            "{error}"
        );
    }
}

/// Face indices far out of range made tobj overflow (found by the obj_mtl fuzzer): they are
/// errors naming the line; in-range absolute and relative indices still load.
#[test]
fn obj_face_indices_out_of_range_are_errors() {
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n";
    for face in [
        "f 1//6148914691236517206 2//1 3//1",
        "f 1/99/1 2/1/1 3/1/1",
        "f 1 2 -4",
        "f 0 1 2",
        "f 1 2 -9223372036854775808",
    ] {
        let path = temp_path("faces.obj");
        std::fs::write(&path, format!("{head}{face}\n")).unwrap();
        let error = io::load_scene(&path).unwrap_err().message;
        assert!(error.contains("(line 6): face index"), "{face}: {error}");
    }
    let path = temp_path("faces.obj");
    std::fs::write(&path, format!("{head}f 1/1/1 -2/-1/-1 3//1\n")).unwrap();
    assert_eq!(io::load_scene(&path).unwrap().triangle_count(), 1);
}

/// The MTL PBR extension's sheen colour `Ps` (one or three numbers) makes a
/// metallic-roughness material with that sheen; out of [0, 1] or NaN it is an error.
#[test]
fn mtl_sheen_colour_is_read() {
    let mtl = b"newmtl velvet\nKd 0.1 0.1 0.5\nPs 0.9 0.5 0.2\nnewmtl grey\nPr 0.5\nPs 0.4\n";
    let obj =
        b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl velvet\nf 1 2 3\nusemtl grey\nf 1 2 3\n";
    let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl)]);
    let data = io::load_scene(&dir.join("t.obj")).unwrap();
    let velvet = material_named(&data, "velvet").1;
    assert_eq!(velvet.kind, MaterialKind::MetallicRoughness);
    assert_eq!(velvet.sheen_color, [0.9, 0.5, 0.2]);
    assert_eq!(material_named(&data, "grey").1.sheen_color, [0.4; 3]);
    for bad in ["Ps 1.5", "Ps NaN", "Ps -0.1 0 0", "Ps 0.5 0.5"] {
        let mtl = format!("newmtl velvet\n{bad}\nnewmtl grey\n");
        let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl.as_bytes())]);
        let Err(error) = io::load_scene(&dir.join("t.obj")) else {
            panic!("{bad} loads");
        };
        let error = error.to_string();
        assert!(error.contains("Ps"), "{bad}: {error}");
    }
}

#[test]
fn mtl_mapping_mirror_tf_glass_defaults_and_faces_without_material() {
    let mtl = b"newmtl m\nKs 0.9 0.8 0.7\nillum 5\n\
        newmtl tf\nTf 0.5 0.6 0.7\nNi 1.33\nillum 2\n\
        newmtl glass7\nillum 7\nVd 36\n\
        newmtl emissive_mirror\nillum 3\nKe 1 2 3\n\
        newmtl bare\n";
    let obj = b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
        f 1 2 3\nusemtl m\nf 2 4 3\nusemtl tf\nf 1 2 3\nusemtl glass7\nf 1 2 3\n\
        usemtl emissive_mirror\nf 1 2 3\nusemtl bare\nf 1 2 4 3\n";
    let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl)]);
    let data = io::load_scene(&dir.join("t.obj")).unwrap();
    // The quad is triangulated.
    assert_eq!(data.triangle_count(), 7);
    let m = material_named(&data, "m").1;
    assert_eq!((m.kind, m.color), (MaterialKind::Mirror, [0.9, 0.8, 0.7]));
    let tf = material_named(&data, "tf").1;
    assert_eq!(
        (tf.kind, tf.color, tf.ior),
        (MaterialKind::Dielectric, [0.5, 0.6, 0.7], 1.33)
    );
    let g = material_named(&data, "glass7").1;
    assert_eq!(
        (g.kind, g.color, g.ior, g.abbe_number),
        (MaterialKind::Dielectric, [1.0; 3], 1.5, 36.0)
    );
    assert_eq!(tf.abbe_number, 0.0);
    let em = material_named(&data, "emissive_mirror").1;
    assert_eq!(
        (em.kind, em.emission),
        (MaterialKind::Mirror, [1.0, 2.0, 3.0])
    );
    let bare = material_named(&data, "bare").1;
    assert_eq!(*bare, Material::diffuse([0.8; 3]));
    // The first face has no material: it gets the appended default white diffuse.
    assert_eq!(data.materials.len(), 6);
    let default = data.material_ids[0] as usize;
    assert_eq!(default, 5);
    assert_eq!(data.materials[default], Material::diffuse([0.8; 3]));
    assert_eq!(data.material_ids[1], material_named(&data, "m").0);
    // No sidecar camera here.
    assert!(data.camera.is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

fn load_error(path: &Path) -> IoError {
    match io::load_scene(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => {
            assert!(!e.to_string().contains('\n'), "{e}");
            e
        }
    }
}

#[test]
fn obj_errors_name_the_file_and_the_problem() {
    let missing = temp_path("missing.obj");
    let e = load_error(&missing);
    assert!(e.message.contains(&*missing.to_string_lossy()), "{e}");

    let dir = temp_dir_with(&[
        (
            "range.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
        ),
        (
            "nomtl.obj",
            b"mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        ),
        (
            "unknown.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nothere\nf 1 2 3\n",
        ),
        ("empty.obj", b"v 0 0 0\n"),
        (
            "badtf.obj",
            b"mtllib badtf.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        ),
        ("badtf.mtl", b"newmtl x\nTf spectral a.spd\n"),
        ("scene.xyz", b""),
    ]);
    let e = load_error(&dir.join("range.obj"));
    assert!(e.message.contains("range.obj"), "{e}");
    assert!(e.message.contains("line 5"), "{e}");
    assert!(e.message.contains("out of bounds"), "{e}");

    let e = load_error(&dir.join("nomtl.obj"));
    assert!(e.message.contains("absent.mtl"), "{e}");

    let e = load_error(&dir.join("unknown.obj"));
    assert!(e.message.contains("'nothere'"), "{e}");
    assert!(e.message.contains("line 4"), "{e}");

    let e = load_error(&dir.join("empty.obj"));
    assert!(e.message.contains("no triangles"), "{e}");

    let e = load_error(&dir.join("badtf.obj"));
    assert!(e.message.contains("Tf"), "{e}");

    let e = load_error(&dir.join("scene.xyz"));
    assert!(e.message.contains("unsupported file extension"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn camera_json_fields_are_read_exactly() {
    let path = scenes().join("cornell-box.camera.json");
    let c = io::load_camera_json(&path).unwrap();
    assert_eq!(c.camera.eye, [278.0, 273.0, -800.0]);
    assert_eq!(c.camera.target, [278.0, 273.0, -799.0]);
    assert_eq!(c.camera.up, [0.0, 1.0, 0.0]);
    assert_eq!(c.camera.fov_y_deg, 39.307648);
    assert_eq!((c.width, c.height), (256, 256));
    assert_eq!((c.camera.lens_radius, c.camera.focus_distance), (0.0, 0.0));

    let dir = temp_dir_with(&[(
        "lens.json",
        br#"{"eye":[1,2,3],"target":[1,2,4],"up":[0,1,0],"fov_y_deg":45.5,
            "width":640,"height":480,"lens_radius":0.25,"focus_distance":7}"#,
    )]);
    let c = io::load_camera_json(&dir.join("lens.json")).unwrap();
    assert_eq!(c.camera.eye, [1.0, 2.0, 3.0]);
    assert_eq!(c.camera.fov_y_deg, 45.5);
    assert_eq!((c.width, c.height), (640, 480));
    assert_eq!(c.camera.lens_radius, 0.25);
    assert_eq!(c.camera.focus_distance, 7.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn camera_json_errors() {
    let good = r#""eye":[0,0,0],"target":[0,0,1],"up":[0,1,0],"width":8,"height":8"#;
    let cases = [
        (format!(r#"{{{good},"fov_y_deg":0}}"#), "fov_y_deg"),
        (format!(r#"{{{good},"fov_y_deg":180}}"#), "fov_y_deg"),
        (format!(r#"{{{good}}}"#), "fov_y_deg"),
        (format!(r#"{{{good},"fov_y_deg":40,"fov":3}}"#), "fov"),
        (
            r#"{"eye":[0,0,0],"target":[0,0,1],"up":[0,1,0],"width":0,"height":8,"fov_y_deg":40}"#
                .to_owned(),
            "width",
        ),
        (
            r#"{"eye":[0,0,0],"target":[0,0,0],"up":[0,1,0],"width":8,"height":8,"fov_y_deg":40}"#
                .to_owned(),
            "coincide",
        ),
        ("{ not json".to_owned(), "line 1"),
    ];
    for (text, needle) in cases {
        let path = temp_path("camera.json");
        std::fs::write(&path, &text).unwrap();
        let e = io::load_camera_json(&path).expect_err(&text);
        assert!(e.message.contains(needle), "{text}: {e}");
        assert!(e.message.contains(&*path.to_string_lossy()), "{e}");
        std::fs::remove_file(&path).unwrap();
    }
}

/// A 3 x 2 image whose every float differs.
fn test_image() -> (u32, u32, Vec<f32>) {
    let rgb = (0..18).map(|i| i as f32 * 0.25 - 1.0).collect();
    (3, 2, rgb)
}

#[test]
fn pfm_round_trip_is_exact_and_stores_the_bottom_row_first() {
    let (w, h, rgb) = test_image();
    let path = temp_path("image.pfm");
    io::write_image(&path, w, h, &rgb).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let header = b"PF\n3 2\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    assert_eq!(bytes.len(), header.len() + 18 * 4);
    let data: Vec<f32> = bytes[header.len()..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    // The file's first row is the image's bottom row (rgb rows are top to bottom).
    assert_eq!(&data[..9], &rgb[9..]);
    assert_eq!(&data[9..], &rgb[..9]);

    let (rw, rh, back) = io::read_pfm(&path).unwrap();
    assert_eq!((rw, rh), (w, h));
    assert_eq!(back, rgb);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn read_pfm_accepts_big_endian_and_greyscale() {
    let path = temp_path("grey.pfm");
    let mut bytes = b"Pf\n2 2\n1.0\n".to_vec();
    for v in [1.0f32, 2.0, 3.0, 4.0] {
        bytes.extend_from_slice(&v.to_be_bytes());
    }
    std::fs::write(&path, &bytes).unwrap();
    let (w, h, rgb) = io::read_pfm(&path).unwrap();
    assert_eq!((w, h), (2, 2));
    assert_eq!(
        rgb,
        [3.0, 3.0, 3.0, 4.0, 4.0, 4.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0]
    );
    std::fs::write(&path, &bytes[..bytes.len() - 1]).unwrap();
    assert!(io::read_pfm(&path).is_err());
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn exr_is_written_and_readable() {
    let (w, h, rgb) = test_image();
    let path = temp_path("image.exr");
    io::write_image(&path, w, h, &rgb).unwrap();
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |resolution, _| vec![[0.0f32; 3]; resolution.width() * resolution.height()],
        |pixels: &mut Vec<[f32; 3]>, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[position.y() * 3 + position.x()] = [r, g, b];
        },
    )
    .unwrap();
    let size = image.layer_data.size;
    assert_eq!((size.width(), size.height()), (3, 2));
    let back: Vec<f32> = image.layer_data.channel_data.pixels.concat();
    assert_eq!(back, rgb);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn png_is_srgb_encoded_and_readable() {
    // Top row: black, 18% grey, white; bottom row: over-range, negative, 0.5.
    let rgb = [
        0.0, 0.0, 0.0, 0.18, 0.18, 0.18, 1.0, 1.0, 1.0, //
        5.0, 5.0, 5.0, -1.0, -1.0, -1.0, 0.5, 0.25, 0.0,
    ];
    let path = temp_path("image.png");
    io::write_image(&path, 3, 2, &rgb).unwrap();
    let image = image::open(&path).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (3, 2));
    assert_eq!(image.get_pixel(0, 0).0, [0, 0, 0]);
    assert_eq!(image.get_pixel(1, 0).0, [118, 118, 118]);
    assert_eq!(image.get_pixel(2, 0).0, [255, 255, 255]);
    assert_eq!(image.get_pixel(0, 1).0, [255, 255, 255]);
    assert_eq!(image.get_pixel(1, 1).0, [0, 0, 0]);
    assert_eq!(image.get_pixel(2, 1).0, [188, 137, 0]);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn image_writer_errors() {
    let (w, h, rgb) = test_image();
    let e = io::write_image(&temp_path("x.bmp"), w, h, &rgb).unwrap_err();
    assert!(
        e.message.contains("x.bmp") && e.message.contains("extension"),
        "{e}"
    );
    let e = io::write_image(&temp_path("short.pfm"), w, h, &rgb[..17]).unwrap_err();
    assert!(e.message.contains("17 floats"), "{e}");
    let unwritable = temp_path("no-such-dir").join("x.png");
    let e = io::write_image(&unwritable, w, h, &rgb).unwrap_err();
    assert!(e.message.contains(&*unwritable.to_string_lossy()), "{e}");
}

// ---------------------------------------------------------------------------------------
// glTF

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A unit quad in the x = 0 plane facing +x (4 f32x3 positions, 6 u16 indices, padded).
fn quad_buffer() -> Vec<u8> {
    let positions: [[f32; 3]; 4] = [
        [0.0, -1.0, -1.0],
        [0.0, -1.0, 1.0],
        [0.0, 1.0, 1.0],
        [0.0, 1.0, -1.0],
    ];
    let indices: [u16; 6] = [0, 2, 1, 0, 3, 2];
    let mut buffer = Vec::new();
    for p in positions {
        for c in p {
            buffer.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in indices {
        buffer.extend_from_slice(&i.to_le_bytes());
    }
    buffer
}

/// Two instances of the quad (one mirrored, under a translated parent), an emissive material
/// with strength 4, a glass material and a camera at (5, 0, 0) turned to look down -x.
fn gltf_json(buffer_uri: Option<&str>, buffer_len: usize) -> String {
    let uri = buffer_uri.map_or(String::new(), |u| format!(r#""uri": "{u}", "#));
    let s = std::f32::consts::FRAC_1_SQRT_2;
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "extensionsUsed": ["KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_dispersion", "KHR_materials_volume"],
  "scene": 0,
  "scenes": [{{ "nodes": [0, 3] }}],
  "nodes": [
    {{ "name": "group", "translation": [1, 0, 0], "children": [1, 2] }},
    {{ "name": "quad", "mesh": 0 }},
    {{ "name": "mirrored", "mesh": 1, "translation": [0, 3, 0], "scale": [1, 1, -1] }},
    {{ "name": "camera", "camera": 0, "translation": [5, 0, 0], "rotation": [0, {s}, 0, {s}] }}
  ],
  "cameras": [{{ "type": "perspective", "perspective": {{ "yfov": 0.5, "aspectRatio": 1.5, "znear": 0.01 }} }}],
  "meshes": [
    {{ "primitives": [{{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "material": 0 }}] }},
    {{ "primitives": [{{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "material": 1 }}] }}
  ],
  "materials": [
    {{ "name": "lamp", "emissiveFactor": [1, 0.5, 0.25],
       "extensions": {{ "KHR_materials_emissive_strength": {{ "emissiveStrength": 4 }} }},
       "pbrMetallicRoughness": {{ "baseColorFactor": [0.2, 0.3, 0.4, 1] }} }},
    {{ "name": "glass",
       "extensions": {{ "KHR_materials_transmission": {{ "transmissionFactor": 1 }},
                        "KHR_materials_ior": {{ "ior": 1.33 }},
                        "KHR_materials_dispersion": {{ "dispersion": 0.5 }},
                        "KHR_materials_volume": {{ "thicknessFactor": 0.25, "attenuationDistance": 2,
                                                   "attenuationColor": [0.5, 0.75, 1] }} }} }}
  ],
  "buffers": [{{ {uri}"byteLength": {buffer_len} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 12 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
       "min": [0, -1, -1], "max": [0, 1, 1] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#
    )
}

fn check_gltf_scene(data: &SceneData) {
    assert_eq!(data.triangle_count(), 4);
    assert_eq!(data.materials.len(), 2);
    // glTF's defaults: metallic 1, roughness 1 (the "glass" gives no pbrMetallicRoughness,
    // so it is a rough metal whose transmission has no dielectric part to apply to).
    let (lamp_id, lamp) = material_named(data, "lamp");
    assert_eq!(lamp.kind, MaterialKind::MetallicRoughness);
    assert_eq!((lamp.metallic, lamp.roughness), (1.0, 1.0));
    assert_eq!(lamp.color, [0.2, 0.3, 0.4]);
    assert_eq!(lamp.emission, [4.0, 2.0, 1.0]);
    let (glass_id, glass) = material_named(data, "glass");
    assert_eq!(glass.kind, MaterialKind::MetallicRoughness);
    assert_eq!((glass.ior, glass.transmission), (1.33, 1.0));
    // KHR_materials_dispersion's 20 / V_d.
    assert_eq!((glass.abbe_number, lamp.abbe_number), (40.0, 0.0));
    // KHR_materials_volume; a material without it has glTF's defaults (thin-walled, no
    // absorption: an infinite distance is the largest float).
    assert_eq!(glass.thickness, 0.25);
    assert_eq!(glass.attenuation_color, [0.5, 0.75, 1.0]);
    assert_eq!(glass.attenuation_distance, 2.0);
    assert_eq!(
        (
            lamp.thickness,
            lamp.attenuation_color,
            lamp.attenuation_distance
        ),
        (0.0, [1.0; 3], f32::MAX)
    );
    assert_eq!(glass.emission, [0.0; 3]);
    assert_eq!(data.material_ids, [lamp_id, lamp_id, glass_id, glass_id]);

    // The parent's translation moves both quads to x = 1; the mirrored one is also moved up.
    for t in 0..4 {
        for k in 0..3 {
            let p = vertex(data, data.indices[t * 3 + k]);
            assert!((p.x - 1.0).abs() < 1e-6, "{p}");
            let up = if t >= 2 { 3.0 } else { 0.0 };
            assert!((p.y - up).abs() <= 1.0 + 1e-6, "{p}");
        }
        // Both face +x: the mirrored instance had its winding flipped.
        assert!(
            (normal(data, t) - glam::Vec3::X).length() < 1e-5,
            "triangle {t}"
        );
    }

    let camera = data.camera.expect("the glTF camera");
    assert_eq!((camera.width, camera.height), (768, 512));
    assert!((camera.camera.fov_y_deg - 0.5f32.to_degrees()).abs() < 1e-4);
    let close =
        |a: [f32; 3], b: [f32; 3]| (glam::Vec3::from(a) - glam::Vec3::from(b)).length() < 1e-5;
    assert!(
        close(camera.camera.eye, [5.0, 0.0, 0.0]),
        "{:?}",
        camera.camera
    );
    assert!(
        close(camera.camera.target, [4.0, 0.0, 0.0]),
        "{:?}",
        camera.camera
    );
    assert!(
        close(camera.camera.up, [0.0, 1.0, 0.0]),
        "{:?}",
        camera.camera
    );
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
}

/// A quad with two texture coordinate sets and one texture, whose base colour texture reads
/// `TEXCOORD_{base_set}` (with `alphaMode` BLEND), written with its image into a fresh
/// directory; returns the glTF's path.
fn two_uv_sets_gltf(base_set: u32) -> PathBuf {
    let dir = temp_path("two-uv-sets");
    std::fs::create_dir_all(&dir).unwrap();
    io::write_png(
        &dir.join("texture.png"),
        2,
        1,
        &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
    )
    .unwrap();
    let mut buffer = quad_buffer();
    for set in [[0.25f32, 0.5], [0.75, 0.5]] {
        for corner in 0..4 {
            for (k, c) in set.iter().enumerate() {
                // Each corner its own coordinates, so the order of corners is checked too.
                buffer.extend_from_slice(&(c + 0.01 * (corner * 2 + k) as f32).to_le_bytes());
            }
        }
    }
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json = format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [{{ "attributes": {{ "POSITION": 0, "TEXCOORD_0": 2, "TEXCOORD_1": 3 }},
                                  "indices": 1, "material": 0 }}] }}],
  "materials": [{{ "name": "two sets", "alphaMode": "BLEND",
                   "pbrMetallicRoughness": {{ "baseColorFactor": [1, 1, 1, 0.3],
                                              "baseColorTexture": {{ "index": 0, "texCoord": {base_set} }} }},
                   "emissiveFactor": [1, 1, 1],
                   "emissiveTexture": {{ "index": 0 }} }}],
  "textures": [{{ "source": 0 }}],
  "images": [{{ "uri": "texture.png" }}],
  "buffers": [{{ "uri": "{uri}", "byteLength": {len} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 12 }},
    {{ "buffer": 0, "byteOffset": 60, "byteLength": 32 }},
    {{ "buffer": 0, "byteOffset": 92, "byteLength": 32 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
       "min": [0, -1, -1], "max": [0, 1, 1] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" }},
    {{ "bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2" }},
    {{ "bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2" }}
  ]
}}"#,
        len = buffer.len()
    );
    let path = dir.join("two-uv-sets.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// glTF's `texCoord` picks the texture coordinate set: the loader reads `TEXCOORD_1` into
/// `texcoords1` (vertex for vertex) and gives the base colour texture set 1, the emissive
/// one set 0; `alphaMode` BLEND is `AlphaMode::Blend`. A set past 1 is refused by name.
#[test]
fn gltf_tex_coord_selects_the_texture_coordinate_set() {
    let path = two_uv_sets_gltf(1);
    let data = io::load_scene(&path).unwrap();
    let (_, material) = material_named(&data, "two sets");
    assert_eq!(material.alpha_mode, mlt::AlphaMode::Blend);
    assert_eq!(material.alpha, 0.3);
    assert_eq!(material.base_color_texture.unwrap().texcoord, 1);
    assert_eq!(material.emission_texture.unwrap().texcoord, 0);
    assert_eq!(data.texcoords.len(), 8);
    assert_eq!(data.texcoords1.len(), 8);
    for vertex in 0..4 {
        for k in 0..2 {
            let offset = 0.01 * (vertex * 2 + k) as f32;
            assert_eq!(data.texcoords[vertex * 2 + k], [0.25, 0.5][k] + offset);
            assert_eq!(data.texcoords1[vertex * 2 + k], [0.75, 0.5][k] + offset);
        }
    }
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();

    let path = two_uv_sets_gltf(2);
    let error = io::load_scene(&path).unwrap_err().to_string();
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    assert!(
        error.contains("TEXCOORD_2") && error.contains("TEXCOORD_1"),
        "{error}"
    );
}

/// `KHR_materials_unlit`: the material emits its base colour and scatters nothing, so the
/// camera sees the base colour itself (paths up to 4 bounces add nothing).
#[test]
fn gltf_unlit_material_is_seen_as_its_base_colour() {
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json = format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "extensionsUsed": ["KHR_materials_unlit"],
  "scene": 0,
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [{{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "material": 0 }}] }}],
  "materials": [{{ "name": "unlit", "extensions": {{ "KHR_materials_unlit": {{}} }},
                   "pbrMetallicRoughness": {{ "baseColorFactor": [0.2, 0.4, 0.6, 1] }} }}],
  "buffers": [{{ "uri": "{uri}", "byteLength": {len} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 12 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
       "min": [0, -1, -1], "max": [0, 1, 1] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        len = buffer.len()
    );
    let path = temp_path("unlit.gltf");
    std::fs::write(&path, json).unwrap();
    let data = io::load_scene(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let (_, material) = material_named(&data, "unlit");
    assert_eq!(material.emission, [0.2, 0.4, 0.6]);
    assert_eq!(material.color, [0.0; 3]);
    let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    let camera = mlt::Camera {
        eye: [5.0, 0.0, 0.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 10.0,
        ..Default::default()
    };
    let settings = mlt::RenderSettings {
        width: 4,
        height: 4,
        algorithm: mlt::Algorithm::Path,
        samples_per_pixel: 4,
        max_depth: 4,
        ..Default::default()
    };
    let mut image = vec![0.0; 4 * 4 * 3];
    mlt::render(&scene, &camera, &settings, &mut image, None).unwrap();
    for pixel in image.chunks_exact(3) {
        for (got, want) in pixel.iter().zip([0.2, 0.4, 0.6]) {
            assert!((got - want).abs() < 1e-5, "{pixel:?}");
        }
    }
}

/// A negative `KHR_materials_dispersion` is refused with a message naming it.
#[test]
fn gltf_with_negative_dispersion_is_refused() {
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json =
        gltf_json(Some(&uri), buffer.len()).replace(r#""dispersion": 0.5"#, r#""dispersion": -1"#);
    let path = temp_path("negative-dispersion.gltf");
    std::fs::write(&path, json).unwrap();
    let error = io::load_scene(&path).unwrap_err().to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(
        error.contains("KHR_materials_dispersion") && error.contains(">= 0"),
        "{error}"
    );
}

/// Bad `KHR_materials_volume` values are refused with a message naming the value.
#[test]
fn gltf_with_bad_volumes_is_refused() {
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json = gltf_json(Some(&uri), buffer.len());
    for (good, bad, expected) in [
        (
            r#""thicknessFactor": 0.25"#,
            r#""thicknessFactor": -1"#,
            "thicknessFactor must be a number >= 0",
        ),
        (
            r#""attenuationDistance": 2"#,
            r#""attenuationDistance": 0"#,
            "attenuationDistance must be a number > 0",
        ),
        (
            r#""attenuationDistance": 2"#,
            r#""attenuationDistance": -3"#,
            "attenuationDistance must be a number > 0",
        ),
        (
            r#""attenuationDistance": 2"#,
            r#""attenuationDistance": "far""#,
            "attenuationDistance must be a number > 0",
        ),
        (
            r#"[0.5, 0.75, 1]"#,
            r#"[0.5, 1.5, 1]"#,
            "attenuationColor must be three numbers in [0, 1]",
        ),
        (
            r#"[0.5, 0.75, 1]"#,
            r#"[0.5, 0.75]"#,
            "attenuationColor must be three numbers in [0, 1]",
        ),
    ] {
        let path = temp_path("bad-volume.gltf");
        std::fs::write(&path, json.replace(good, bad)).unwrap();
        let error = io::load_scene(&path).unwrap_err().to_string();
        std::fs::remove_file(&path).unwrap();
        assert!(
            error.contains("KHR_materials_volume") && error.contains(expected),
            "{bad}: {error}"
        );
    }
}

/// glTF material values mlt cannot render are clear errors naming the value and the
/// material when the scene is built: a roughness above 1 or below 0, one too large for a
/// float (JSON has no NaN; 1e39 becomes an infinite float), and so a metalness.
#[test]
fn gltf_with_bad_material_values_is_refused() {
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json = gltf_json(Some(&uri), buffer.len());
    let good = r#""baseColorFactor": [0.2, 0.3, 0.4, 1]"#;
    assert!(json.contains(good));
    for (bad, expected) in [
        (
            r#""roughnessFactor": 2"#,
            "roughness is 2; it must be in [0, 1]",
        ),
        (
            r#""roughnessFactor": -1"#,
            "roughness is -1; it must be in [0, 1]",
        ),
        (
            r#""roughnessFactor": 1e39"#,
            "roughness is inf; it must be a finite number",
        ),
        (
            r#""metallicFactor": 1e39"#,
            "metallic is inf; it must be a finite number",
        ),
    ] {
        let path = temp_path("bad-material.gltf");
        std::fs::write(&path, json.replace(good, &format!("{good}, {bad}"))).unwrap();
        let data = io::load_scene(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let Err(error) = Scene::new(&data.desc(mlt::Backend::Bvh)) else {
            panic!("{bad} was accepted");
        };
        let message = data.describe_error(&error);
        assert!(
            message.contains(expected) && message.contains("(material 'lamp')"),
            "{bad}: {message}"
        );
    }
}

#[test]
fn gltf_with_data_uri_buffer_loads_meshes_materials_and_camera() {
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json = gltf_json(Some(&uri), buffer.len());
    let path = temp_path("quad.gltf");
    std::fs::write(&path, json).unwrap();
    let data = io::load_scene(&path).unwrap();
    check_gltf_scene(&data);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn glb_loads_the_same_scene() {
    let buffer = quad_buffer();
    let mut json = gltf_json(None, buffer.len()).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = buffer.clone();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut glb = Vec::new();
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    let path = temp_path("quad.glb");
    std::fs::write(&path, glb).unwrap();
    let data = io::load_scene(&path).unwrap();
    check_gltf_scene(&data);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn gltf_errors_name_the_file() {
    let path = temp_path("broken.gltf");
    std::fs::write(&path, "{ \"asset\": ").unwrap();
    let e = io::load_scene(&path).unwrap_err();
    assert!(e.message.contains(&*path.to_string_lossy()), "{e}");

    // An index beyond the primitive's vertices.
    let mut buffer = quad_buffer();
    buffer[48..50].copy_from_slice(&7u16.to_le_bytes());
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    std::fs::write(&path, gltf_json(Some(&uri), buffer.len())).unwrap();
    let e = io::load_scene(&path).unwrap_err();
    assert!(
        e.message.contains("is 7") && e.message.contains("4 vertices"),
        "{e}"
    );

    // A GLB whose header gives a length shorter than the header: gltf subtracted with
    // overflow (a panic with overflow checks, found by the gltf_glb fuzzer).
    let glb = temp_path("short.glb");
    std::fs::write(
        &glb,
        [&b"glTF"[..], &2u32.to_le_bytes(), &4u32.to_le_bytes()].concat(),
    )
    .unwrap();
    let e = io::load_scene(&glb).unwrap_err();
    assert!(e.message.contains("GLB header gives a length of 4"), "{e}");
    std::fs::remove_file(&glb).unwrap();

    // A node that is its own ancestor: the walk recursed until the stack overflowed (found
    // by the gltf_glb fuzzer).
    let text = r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1]}, {"children": [0]}]}"#;
    std::fs::write(&path, text).unwrap();
    let e = io::load_scene(&path).unwrap_err();
    assert!(e.message.contains("node 0 is its own ancestor"), "{e}");

    // Images without the source gltf unwraps (a panic, found by the gltf_glb fuzzer).
    for image in [r#"{"bufferView": 0}"#, "{}"] {
        let text = format!(
            r#"{{"asset": {{"version": "2.0"}}, "images": [{image}],
            "bufferViews": [{{"buffer": 0, "byteLength": 4}}],
            "buffers": [{{"byteLength": 4, "uri": "data:application/octet-stream;base64,AAAAAA=="}}],
            "textures": [{{"source": 0}}]}}"#
        );
        std::fs::write(&path, text).unwrap();
        let e = io::load_scene(&path).unwrap_err();
        assert!(
            e.message
                .contains("image 0 needs a uri, or a bufferView with a mimeType"),
            "{e}"
        );
    }

    // A POSITION naming an accessor that does not exist: gltf-json's validation indexed
    // past the accessors (a panic, found by the gltf_glb fuzzer).
    let text = r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}}]}],
        "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3"}]}"#;
    std::fs::write(&path, text).unwrap();
    let e = io::load_scene(&path).unwrap_err();
    assert!(
        e.message
            .contains("POSITION of primitive 0 of mesh 0 is accessor 1"),
        "{e}"
    );

    // A relative uri whose escapes decode to bytes that are not UTF-8: gltf unwrapped the
    // decoding (a panic, found by the gltf_glb fuzzer).
    let text = r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": []}],
        "buffers": [{"byteLength": 4, "uri": "a%FFb.bin"}]}"#;
    std::fs::write(&path, text).unwrap();
    let e = io::load_scene(&path).unwrap_err();
    assert!(
        e.message.contains("does not percent-decode to UTF-8"),
        "{e}"
    );

    // An image whose bufferView lies beyond its buffer: gltf sliced out of range (a panic,
    // found by the gltf_glb fuzzer).
    let text = r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": []}],
        "images": [{"bufferView": 0, "mimeType": "image/png"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 8, "byteLength": 4}],
        "buffers": [{"byteLength": 4, "uri": "data:application/octet-stream;base64,AAAAAA=="}],
        "textures": [{"source": 0}]}"#;
    std::fs::write(&path, text).unwrap();
    let e = io::load_scene(&path).unwrap_err();
    assert!(
        e.message
            .contains("image 0 reads bytes 8..12 of buffer 0, which holds 4"),
        "{e}"
    );

    // Attributes whose accessors have a type glTF does not allow them: gltf read them with
    // the wrong element size (a debug assertion, found by the gltf_glb fuzzer).
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    for (attribute, accessor) in [
        (
            "NORMAL",
            r#""componentType": 5126, "count": 4, "type": "VEC2""#,
        ),
        (
            "TEXCOORD_0",
            r#""componentType": 5126, "count": 4, "type": "VEC3""#,
        ),
        (
            "COLOR_0",
            r#""componentType": 5125, "count": 4, "type": "VEC4""#,
        ),
        (
            "TANGENT",
            r#""componentType": 5126, "count": 4, "type": "VEC3""#,
        ),
    ] {
        let json = gltf_json(Some(&uri), buffer.len())
            .replacen(
                r#""attributes": { "POSITION": 0 }"#,
                &format!(r#""attributes": {{ "POSITION": 0, "{attribute}": 2 }}"#),
                1,
            )
            .replace(
                r#""type": "SCALAR" }"#,
                &format!(r#""type": "SCALAR" }}, {{ "bufferView": 0, {accessor} }}"#),
            );
        std::fs::write(&path, json).unwrap();
        let e = io::load_scene(&path).unwrap_err();
        assert!(
            e.message.contains(&format!(
                "the {attribute} attribute of primitive 0 of mesh 0"
            )) && e.message.contains("which glTF does not allow"),
            "{attribute}: {e}"
        );
    }
    std::fs::remove_file(&path).unwrap();
}

// ---------------------------------------------------------------------------------------
// glTF KHR_lights_punctual and environment maps
// ---------------------------------------------------------------------------------------

#[track_caller]
fn assert_close(got: [f32; 3], expected: [f32; 3], what: &str) {
    let close = got
        .iter()
        .zip(expected)
        .all(|(g, e)| (g - e).abs() <= 1e-5 * (1.0 + e.abs()));
    assert!(close, "{what}: {got:?}, expected {expected:?}");
}

/// tests/scenes/lights-punctual.gltf (hand-written; the extension in `extensionsRequired`):
/// under a parent node translated by (1, 2, 3) and turned 90° about +Y, a spot light 2
/// units along the parent's −Z, a point light under a node scaled by 2, a directional light
/// turned −90° about +X (pointing down); and at the root a spot light with glTF's default
/// cone angles. Positions are the nodes' world origins, directions their world −Z, and
/// intensities `color × intensity / 683` (candela and lux to W/sr and W/m²).
#[test]
fn gltf_punctual_lights_are_placed_by_the_node_hierarchy() {
    use mlt::PunctualLightKind;
    let data = io::load_scene(&scenes().join("lights-punctual.gltf")).unwrap();
    let lights = &data.punctual_lights;
    assert_eq!(lights.len(), 4, "{lights:?}");
    // Depth-first order of the nodes: the parent's children (spot, point, sun), then the
    // root's default spot.
    let spot = &lights[0];
    assert_eq!(spot.kind, PunctualLightKind::Spot);
    // R_y(90°) maps (0, 0, −2) to (−2, 0, 0) and −Z to −X.
    assert_close(spot.position, [-1.0, 2.0, 3.0], "spot position");
    assert_close(spot.direction, [-1.0, 0.0, 0.0], "spot direction");
    assert_close(spot.intensity, [1.0, 0.5, 0.25], "spot intensity (683 cd)");
    assert!((spot.inner_cone_degrees - 0.2f32.to_degrees()).abs() < 1e-4);
    assert!((spot.outer_cone_degrees - 0.5f32.to_degrees()).abs() < 1e-4);

    let point = &lights[1];
    assert_eq!(point.kind, PunctualLightKind::Point);
    // (1, 0, 0) scaled by 2 and moved by (0, 1, 0) is (2, 1, 0); turned, (0, 1, −2).
    assert_close(point.position, [1.0, 3.0, 1.0], "point position");
    assert_close(
        point.intensity,
        [0.1; 3],
        "point intensity (68.3 cd; range ignored)",
    );

    let sun = &lights[2];
    assert_eq!(sun.kind, PunctualLightKind::Directional);
    assert_close(sun.direction, [0.0, -1.0, 0.0], "directional direction");
    assert_close(
        sun.intensity,
        [1.0, 2.0, 2.0],
        "directional irradiance (1366 lx)",
    );

    let default_spot = &lights[3];
    assert_eq!(default_spot.kind, PunctualLightKind::Spot);
    assert_close(default_spot.position, [0.0; 3], "default spot position");
    assert_close(
        default_spot.direction,
        [0.0, 0.0, -1.0],
        "default spot direction",
    );
    assert_close(
        default_spot.intensity,
        [1.0 / 683.0; 3],
        "default colour and intensity",
    );
    assert_eq!(default_spot.inner_cone_degrees, 0.0);
    assert!((default_spot.outer_cone_degrees - 45.0).abs() < 1e-4);

    // The lights reach the scene.
    let scene = Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    assert_eq!(scene.info().triangle_count, 1);
}

/// glTF files whose lights the kernel cannot take are refused naming the light.
#[test]
fn gltf_bad_lights_are_errors_naming_the_light() {
    let text = std::fs::read_to_string(scenes().join("lights-punctual.gltf")).unwrap();
    for (from, to, needle) in [
        (
            "\"outerConeAngle\": 0.5",
            "\"outerConeAngle\": 1.6",
            "light 0 (of node 1) has innerConeAngle 0.2 and outerConeAngle 1.6",
        ),
        (
            "\"intensity\": 68.3",
            "\"intensity\": -1.0",
            "light 1 (of node 3)",
        ),
        (
            "\"scale\": [\n        2.0,\n        2.0,\n        2.0\n      ]",
            "\"scale\": [\n        0.0,\n        0.0,\n        0.0\n      ]",
            "has no direction",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let path = temp_path("bad-light.gltf");
        std::fs::write(&path, text.replace(from, to)).unwrap();
        let message = load_error(&path).message;
        assert!(message.contains(needle), "{message}");
        assert!(message.contains("bad-light.gltf"), "{message}");
        std::fs::remove_file(&path).unwrap();
    }
}

/// A spot light with equal inner and outer cone angles (a hard edge, as Blender exports a
/// spot without blend) gets a falloff 0.1% of the cone wide, which the kernel accepts.
#[test]
fn gltf_spot_with_equal_cone_angles_has_a_hard_edge() {
    let text = std::fs::read_to_string(scenes().join("lights-punctual.gltf")).unwrap();
    let path = temp_path("hard-spot.gltf");
    std::fs::write(
        &path,
        text.replace("\"innerConeAngle\": 0.2", "\"innerConeAngle\": 0.5"),
    )
    .unwrap();
    let data = io::load_scene(&path).unwrap();
    let spot = &data.punctual_lights[0];
    let outer = 0.5f32.to_degrees();
    assert!((spot.outer_cone_degrees - outer).abs() < 1e-4);
    assert!(spot.inner_cone_degrees < outer && spot.inner_cone_degrees > 0.998 * outer);
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
    std::fs::remove_file(&path).unwrap();
}

/// A tiny Radiance .hdr written with the image crate reads back (RGBE keeps about 1% of
/// precision), rows from the top; so does an EXR written by `io::write_exr`, exactly.
#[test]
fn environment_maps_load_from_hdr_and_exr() {
    let (width, height) = (4u32, 2u32);
    let pixels: Vec<f32> = (0..width * height * 3)
        .map(|i| 0.25 * (i + 1) as f32)
        .collect();
    let hdr = temp_path("env.hdr");
    let file = std::io::BufWriter::new(std::fs::File::create(&hdr).unwrap());
    let texels: Vec<image::Rgb<f32>> = pixels
        .chunks_exact(3)
        .map(|p| image::Rgb([p[0], p[1], p[2]]))
        .collect();
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&texels, width as usize, height as usize)
        .unwrap();
    let (read, w, h) = io::load_environment(&hdr).unwrap();
    assert_eq!((w, h), (width, height));
    for (got, expected) in read.iter().zip(&pixels) {
        assert!(
            (got - expected).abs() <= 0.01 * expected,
            "{got} vs {expected}"
        );
    }
    std::fs::remove_file(&hdr).unwrap();

    let exr = temp_path("env.exr");
    io::write_exr(&exr, width, height, &pixels).unwrap();
    assert_eq!(io::load_environment(&exr).unwrap(), (pixels, width, height));
    std::fs::remove_file(&exr).unwrap();
}

#[test]
fn environment_map_errors_name_the_file() {
    let missing = temp_path("missing.hdr");
    let message = io::load_environment(&missing).unwrap_err().message;
    assert!(message.contains("missing.hdr"), "{message}");
    let wrong = temp_path("env.png");
    let message = io::load_environment(&wrong).unwrap_err().message;
    assert!(message.contains("expected .hdr or .exr"), "{message}");
    let garbage = temp_path("garbage.hdr");
    std::fs::write(&garbage, b"not an image").unwrap();
    let message = io::load_environment(&garbage).unwrap_err().message;
    assert!(message.contains("garbage.hdr"), "{message}");
    std::fs::remove_file(&garbage).unwrap();
    let negative = temp_path("negative.exr");
    io::write_exr(&negative, 2, 1, &[1.0, 1.0, 1.0, 1.0, -2.0, 1.0]).unwrap();
    let message = io::load_environment(&negative).unwrap_err().message;
    assert!(
        message.contains("column 1, row 0") && message.contains("G = -2"),
        "{message}"
    );
    std::fs::remove_file(&negative).unwrap();
}

/// OBJ's per-corner normals and texture coordinates (v flipped to glTF's convention, each
/// triangle with corners of its own), `map_Kd` with `-s`, a Phong `Ns` with a non-black
/// `Ks` as a GGX roughness, and the PBR keys `Pr` / `Pm`.
#[test]
fn obj_maps_texture_coordinates_normals_textures_and_pbr_keys() {
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255],
        2,
        2,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let obj = b"mtllib t.mtl
v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vt 1 0
vt 0 1
vn 0 0 2
usemtl textured
f 1/1/1 2/2/1 3/3/1
usemtl glossy
f 1/1/1 2/2/1 3/3/1
usemtl pbr
f 1 2 3
";
    let mtl = b"newmtl textured
Kd 1 1 1
map_Kd -s 2 2 checker.png
newmtl glossy
Kd 0.5 0.5 0.5
Ks 0.5 0.5 0.5
Ns 98
illum 2
newmtl pbr
Kd 0.9 0.1 0.1
Pr 0.3
Pm 1
";
    let dir = temp_dir_with(&[("t.obj", obj), ("t.mtl", mtl), ("checker.png", &png)]);
    let data = io::load_scene(&dir.join("t.obj")).unwrap();
    assert_eq!(data.triangle_count(), 3);
    // Corners of their own; the face without vn gets its face normal.
    assert_eq!(data.positions.len(), 9 * 3);
    assert_eq!(&data.texcoords[..6], &[0.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
    assert_eq!(data.texcoords.len(), 9 * 2);
    assert_eq!(&data.normals[..3], &[0.0, 0.0, 1.0]);
    assert_eq!(&data.normals[18..21], &[0.0, 0.0, 1.0]);

    let (_, textured) = material_named(&data, "textured");
    assert_eq!(textured.kind, MaterialKind::Diffuse);
    let checker = textured.base_color_texture.expect("map_Kd");
    // OBJ's v ↦ 2v becomes v' ↦ 2v' − 1 in glTF's flipped coordinates.
    assert_eq!((checker.scale, checker.offset), ([2.0, 2.0], [0.0, -1.0]));
    let texture = &data.textures[checker.texture as usize];
    assert_eq!((texture.width, texture.height, texture.channels), (2, 2, 3));
    assert_eq!(texture.encoding, mlt::TextureEncoding::Srgb);

    let (_, glossy) = material_named(&data, "glossy");
    assert_eq!(glossy.kind, MaterialKind::MetallicRoughness);
    // α = sqrt(2 / (98 + 2)) = 0.1414, roughness = sqrt(α) = 0.3761.
    assert!(
        (glossy.roughness - 0.376_06).abs() < 1e-4,
        "{}",
        glossy.roughness
    );
    assert_eq!((glossy.metallic, glossy.color), (0.0, [0.5; 3]));

    let (_, pbr) = material_named(&data, "pbr");
    assert_eq!(pbr.kind, MaterialKind::MetallicRoughness);
    assert_eq!((pbr.roughness, pbr.metallic), (0.3, 1.0));
    Scene::new(&data.desc(mlt::Backend::Bvh)).unwrap();
}

/// A mesh of two quads, primitive 0 and 1, both "plain" by default, with the
/// `KHR_materials_variants` variants "red" and "blue": "red" makes primitive 0 red and
/// primitive 1 blue; "blue" makes primitive 0 blue and leaves primitive 1 plain.
/// `mappings_0` is primitive 0's mappings array.
fn variants_gltf(mappings_0: &str) -> PathBuf {
    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let json = format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "extensionsUsed": ["KHR_materials_variants"],
  "extensions": {{ "KHR_materials_variants": {{ "variants": [{{ "name": "red" }}, {{ "name": "blue" }}] }} }},
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [
    {{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "material": 0,
       "extensions": {{ "KHR_materials_variants": {{ "mappings": {mappings_0} }} }} }},
    {{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "material": 0,
       "extensions": {{ "KHR_materials_variants": {{ "mappings": [{{ "material": 2, "variants": [0] }}] }} }} }}
  ] }}],
  "materials": [
    {{ "name": "plain" }},
    {{ "name": "red", "pbrMetallicRoughness": {{ "baseColorFactor": [1, 0, 0, 1] }} }},
    {{ "name": "blue", "pbrMetallicRoughness": {{ "baseColorFactor": [0, 0, 1, 1] }} }}
  ],
  "buffers": [{{ "uri": "{uri}", "byteLength": {len} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 12 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
       "min": [0, -1, -1], "max": [0, 1, 1] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        len = buffer.len()
    );
    let path = temp_path("variants.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

const VARIANT_MAPPINGS: &str =
    r#"[{ "material": 1, "variants": [0] }, { "material": 2, "variants": [1] }]"#;

/// The material names of the triangles of primitive 0 and of primitive 1.
fn primitive_materials(data: &SceneData) -> [&str; 2] {
    let name = |triangle: usize| data.material_names[data.material_ids[triangle] as usize].as_str();
    assert_eq!(data.triangle_count(), 4);
    assert_eq!(name(0), name(1));
    assert_eq!(name(2), name(3));
    [name(0), name(2)]
}

/// `KHR_materials_variants`: without a variant every primitive keeps its default material;
/// a variant gives each primitive the material its mapping names for it, and the default
/// where it maps none.
#[test]
fn gltf_material_variants_pick_each_primitives_material() {
    let path = variants_gltf(VARIANT_MAPPINGS);
    let default = io::load_scene(&path).unwrap();
    assert_eq!(primitive_materials(&default), ["plain", "plain"]);
    assert_eq!(default.material_names, ["plain"]);
    let red = io::load_scene_variant(&path, Some("red")).unwrap();
    assert_eq!(primitive_materials(&red), ["red", "blue"]);
    assert_eq!(material_named(&red, "red").1.color, [1.0, 0.0, 0.0]);
    assert_eq!(material_named(&red, "blue").1.color, [0.0, 0.0, 1.0]);
    let blue = io::load_scene_variant(&path, Some("blue")).unwrap();
    assert_eq!(primitive_materials(&blue), ["blue", "plain"]);
    Scene::new(&blue.desc(mlt::Backend::Bvh)).unwrap();
    std::fs::remove_file(&path).unwrap();
}

/// A variant the file does not define is an error listing the ones it does; so is a variant
/// asked of a file without variants (glTF or OBJ); a mapping naming a material or a variant
/// the file lacks is an error whether a variant is chosen or not.
#[test]
fn gltf_bad_material_variants_are_errors() {
    let path = variants_gltf(VARIANT_MAPPINGS);
    let error = io::load_scene_variant(&path, Some("green"))
        .unwrap_err()
        .to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(
        error.contains(r#""green""#) && error.contains(r#""red", "blue""#),
        "{error}"
    );

    let buffer = quad_buffer();
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let path = temp_path("no-variants.gltf");
    std::fs::write(&path, gltf_json(Some(&uri), buffer.len())).unwrap();
    let error = io::load_scene_variant(&path, Some("red"))
        .unwrap_err()
        .to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(error.contains("no material variants"), "{error}");
    let error = io::load_scene_variant(&scenes().join("door-ajar.obj"), Some("red"))
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("only glTF files have material variants"),
        "{error}"
    );

    for (mappings, expected) in [
        (
            r#"[{ "material": 7, "variants": [0] }]"#,
            "names material 7, but there are 3 materials",
        ),
        (
            r#"[{ "material": 1, "variants": [2] }]"#,
            "names variant 2, but there are 2 variants",
        ),
        (
            r#"[{ "material": 1, "variants": [-1] }]"#,
            "names variant -1",
        ),
        (r#"[{ "variants": [0] }]"#, "has no material index"),
        (
            r#"[{ "material": 1, "variants": [0] }, { "material": 2, "variants": [1, 0] }]"#,
            "mapping 1 of the KHR_materials_variants of primitive 0 of mesh 0 names variant 0, which an earlier mapping names",
        ),
    ] {
        let path = variants_gltf(mappings);
        for variant in [None, Some("red")] {
            let error = io::load_scene_variant(&path, variant)
                .unwrap_err()
                .to_string();
            assert!(
                error.contains(expected) && error.contains("primitive 0 of mesh 0"),
                "{error}"
            );
        }
        std::fs::remove_file(&path).unwrap();
    }
}
