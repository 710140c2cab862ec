//! What the C ABI's lights and textures put into an image: a diffuse quad under a constant
//! environment reflects its albedo, under a point light follows the inverse-square law,
//! and takes its albedo from a texture and vertex colours (each within its standard error);
//! the surfaces scene described through the C ABI renders bit-identically to the same scene
//! described in Rust.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_images`).

mod common {
    pub mod capi;
    pub mod references;
    pub mod scenes;
    pub mod stats;
    pub mod surfaces;
}

use common::capi::*;
use mlt::capi::*;
use std::ffi::c_void;
use std::ptr::null_mut;

/// A 2 × 2 quad at y = 0 facing +y, diffuse with albedo `albedo`, no emitters.
fn lit_quad(albedo: f32) -> HostScene {
    HostScene {
        positions: vec![
            -1.0, 0.0, -1.0, -1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, -1.0,
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        material_ids: vec![0, 0],
        materials: vec![MltMaterial {
            color: [albedo; 3],
            ..default_material()
        }],
        backend: MLT_BACKEND_BVH,
    }
}

/// Looking straight down at the quad from `height`, so that it fills the image.
fn quad_camera(height: f32) -> MltCamera {
    MltCamera {
        eye: [0.0, height, 0.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 2.0 * (0.8 / height).atan().to_degrees(),
        ..default_camera()
    }
}

fn render_lit(desc: &MltSceneDesc, camera: &MltCamera, settings: &MltRenderSettings) -> Vec<f32> {
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(desc, &mut out) });
    let scene = Handle(out);
    let len = settings.width as usize * settings.height as usize * 3;
    let (status, image) = scene.render(camera, settings, len);
    assert_ok(status);
    image
}

/// A diffuse quad of albedo 0.5 under a constant environment of radiance 1, seen from
/// above: it receives π from the whole upper hemisphere and reflects 0.5 · π / π = 0.5 in
/// every direction, so every pixel is 0.5 within its noise (path tracing: BSDF sampling and
/// the environment's light sampling, combined by MIS).
#[test]
fn a_quad_under_a_constant_environment_reflects_its_albedo() {
    let host = lit_quad(0.5);
    let radiance = [1.0f32; 3];
    let environment = MltEnvironment {
        pixels: radiance.as_ptr(),
        width: 1,
        height: 1,
        ..default_environment()
    };
    let desc = MltSceneDesc {
        environment: &environment,
        ..host.desc()
    };
    let image = render_lit(&desc, &quad_camera(2.0), &small_settings(16, 16, 64));
    assert_valid_image(&image, "environment-lit quad");
    let (mean, error) = common::stats::mean_and_standard_error(&image);
    for c in 0..3 {
        common::stats::assert_within_and_sharp(
            &format!("channel {c}"),
            mean[c],
            0.5,
            error[c],
            4.0,
        );
    }
    // Every pixel, against the spread of the pixels (all have the same expectation).
    let deviation = error[0] * ((image.len() / 3) as f64).sqrt();
    let worst = image
        .iter()
        .map(|&v| (v as f64 - 0.5).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= 5.0 * deviation,
        "a pixel is {worst} from 0.5, more than 5 standard deviations ({deviation})"
    );
}

/// The same quad lit only by a point light of intensity I at height h above its centre:
/// the irradiance at a point at distance d is I h / d³ and the radiance it reflects
/// albedo / π times that. Each pixel is compared with that radiance averaged over the
/// pixel's footprint; what remains is the noise of where in the pixel samples land.
#[test]
fn a_quad_under_a_point_light_follows_the_inverse_square_law() {
    let (albedo, intensity, h) = (0.5f32, 2.0f32, 1.0f32);
    let host = lit_quad(albedo);
    let light = MltPunctualLight {
        position: [0.0, h, 0.0],
        intensity: [intensity; 3],
        ..default_punctual_light()
    };
    let desc = MltSceneDesc {
        punctual_lights: &light,
        punctual_lights_len: 1,
        ..host.desc()
    };
    let camera = quad_camera(3.0);
    let (width, height) = (16u32, 16u32);
    let image = render_lit(&desc, &camera, &small_settings(width, height, 16));
    assert_valid_image(&image, "point-lit quad");

    let model = mlt::Camera {
        eye: camera.eye,
        target: camera.target,
        up: camera.up,
        fov_y_deg: camera.fov_y_deg,
        ..mlt::Camera::default()
    }
    .model(width, height);
    let radiance_at = |x: f32, y: f32| -> f64 {
        let (origin, direction) = model.generate_ray(x, y, [0.0, 0.0]);
        let t = -origin.y / direction.y;
        let p = origin + direction * t;
        let d2 = (p.x * p.x + (p.z * p.z) + h * h) as f64;
        albedo as f64 / std::f64::consts::PI * intensity as f64 * h as f64 / d2.powf(1.5)
    };
    const SUB: usize = 16;
    let mut residuals = Vec::new();
    let mut truth_sum = 0.0;
    for py in 0..height as usize {
        for px in 0..width as usize {
            let mut expected = 0.0;
            for sy in 0..SUB {
                for sx in 0..SUB {
                    let x = px as f32 + (sx as f32 + 0.5) / SUB as f32;
                    let y = py as f32 + (sy as f32 + 0.5) / SUB as f32;
                    expected += radiance_at(x, y);
                }
            }
            expected /= (SUB * SUB) as f64;
            truth_sum += expected;
            let i = (py * width as usize + px) * 3;
            for c in 0..3 {
                residuals.push(image[i + c] - expected as f32);
            }
        }
    }
    let pixels = (width * height) as f64;
    let truth = truth_sum / pixels;
    let (residual, error) = common::stats::mean_and_standard_error(&residuals);
    for c in 0..3 {
        common::stats::assert_within_and_sharp(
            &format!("channel {c} (mean {truth})"),
            truth + residual[c],
            truth,
            error[c],
            4.0,
        );
    }
}

/// The textures' values reach the image: a white diffuse quad whose base colour texture
/// is a 1 × 1 float texel (0.5, 0.25, 1) and whose vertex colours are (1, 1, 0.5), under
/// a constant environment of radiance 1, reflects (0.5, 0.25, 0.5) (see
/// `a_quad_under_a_constant_environment_reflects_its_albedo`).
#[test]
fn a_texture_and_vertex_colours_set_the_albedo() {
    let mut host = lit_quad(1.0);
    host.materials[0].base_color_texture = slot(0);
    let texel = [0.5f32, 0.25, 1.0];
    let texture = MltTexture {
        width: 1,
        height: 1,
        channels: 3,
        texel_type: MLT_TEXEL_F32,
        texels: texel.as_ptr().cast(),
        encoding: MLT_TEXTURE_LINEAR,
        ..default_texture()
    };
    let texcoords = [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0];
    let colors = [[1.0f32, 1.0, 0.5, 1.0]; 4].concat();
    let radiance = [1.0f32; 3];
    let environment = MltEnvironment {
        pixels: radiance.as_ptr(),
        width: 1,
        height: 1,
        ..default_environment()
    };
    let desc = MltSceneDesc {
        environment: &environment,
        texcoords: texcoords.as_ptr(),
        texcoords_len: texcoords.len(),
        colors: colors.as_ptr(),
        colors_len: colors.len(),
        textures: &texture,
        textures_len: 1,
        ..host.desc()
    };
    let image = render_lit(&desc, &quad_camera(2.0), &small_settings(16, 16, 32));
    assert_valid_image(&image, "textured quad");
    let (mean, error) = common::stats::mean_and_standard_error(&image);
    for (c, expected) in [0.5, 0.25, 0.5].into_iter().enumerate() {
        common::stats::assert_within_and_sharp(
            &format!("channel {c}"),
            mean[c],
            expected,
            error[c],
            4.0,
        );
    }
}

/// The surfaces scene (metallic-roughness materials, a checker base colour texture, a
/// textured lamp, per-vertex normals and texture coordinates) described through the C ABI
/// renders bit-identically to the same scene described in Rust: every new field of
/// `MltMaterial`, `MltTexture` and `MltSceneDesc` reaches the scene as the Rust API sets it.
#[test]
fn the_surfaces_scene_through_the_c_abi_renders_as_through_rust() {
    let surfaces = common::surfaces::surfaces_mesh();
    let textures: Vec<MltTexture> = surfaces
        .textures
        .iter()
        .map(|t| {
            let (texel_type, texels) = match &t.data {
                mlt::TexelData::U8(v) => (MLT_TEXEL_U8, v.as_ptr().cast::<c_void>()),
                mlt::TexelData::F32(v) => (MLT_TEXEL_F32, v.as_ptr().cast::<c_void>()),
            };
            let mut texture = std::mem::MaybeUninit::<MltTexture>::uninit();
            // SAFETY: writable memory of this size.
            assert_ok(unsafe { mlt_texture_init(texture.as_mut_ptr(), size_of::<MltTexture>()) });
            // SAFETY: initialized on success.
            let texture = unsafe { texture.assume_init() };
            MltTexture {
                width: t.width,
                height: t.height,
                channels: t.channels,
                texel_type,
                texels,
                encoding: match t.encoding {
                    mlt::TextureEncoding::Srgb => MLT_TEXTURE_SRGB,
                    mlt::TextureEncoding::Linear => MLT_TEXTURE_LINEAR,
                },
                wrap_u: wrap_mode(t.wrap_u),
                wrap_v: wrap_mode(t.wrap_v),
                filter: match t.filter {
                    mlt::TextureFilter::Nearest => MLT_FILTER_NEAREST,
                    mlt::TextureFilter::Bilinear => MLT_FILTER_BILINEAR,
                },
                ..texture
            }
        })
        .collect();
    let host = HostScene {
        materials: surfaces.mesh.c_materials(),
        positions: surfaces.mesh.positions.clone(),
        indices: surfaces.mesh.indices.clone(),
        material_ids: surfaces.mesh.material_ids.clone(),
        backend: MLT_BACKEND_BVH,
    };
    let desc = MltSceneDesc {
        normals: surfaces.normals.as_ptr(),
        normals_len: surfaces.normals.len(),
        texcoords: surfaces.texcoords.as_ptr(),
        texcoords_len: surfaces.texcoords.len(),
        textures: textures.as_ptr(),
        textures_len: textures.len(),
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: the desc points into live vectors of the stated lengths.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let c_scene = Handle(out);
    let rust_scene = surfaces.scene(mlt::Backend::Bvh);
    let camera = common::scenes::cornell_camera();
    let c_camera = MltCamera {
        eye: camera.eye,
        target: camera.target,
        up: camera.up,
        fov_y_deg: camera.fov_y_deg,
        lens_radius: camera.lens_radius,
        focus_distance: camera.focus_distance,
        ..default_camera()
    };
    for (algorithm, c_algorithm) in [
        (mlt::Algorithm::Path, MLT_ALGORITHM_PATH),
        (mlt::Algorithm::Bdpt, MLT_ALGORITHM_BDPT),
        (mlt::Algorithm::Mmlt, MLT_ALGORITHM_MMLT),
    ] {
        let settings = MltRenderSettings {
            algorithm: c_algorithm,
            ..small_settings(16, 16, 8)
        };
        let (status, c_image) = c_scene.render(&c_camera, &settings, 16 * 16 * 3);
        assert_ok(status);
        let rust_settings = mlt::RenderSettings {
            width: 16,
            height: 16,
            algorithm,
            samples_per_pixel: 8,
            ..Default::default()
        };
        let rust_image = common::references::render_image(&rust_scene, &camera, &rust_settings);
        assert!(
            c_image.iter().any(|&v| v > 0.0),
            "{algorithm:?}: a black image"
        );
        assert!(
            c_image
                .iter()
                .zip(&rust_image)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{algorithm:?}: the C ABI's render differs from the Rust API's"
        );
    }
}

fn wrap_mode(mode: mlt::WrapMode) -> i32 {
    match mode {
        mlt::WrapMode::Repeat => MLT_WRAP_REPEAT,
        mlt::WrapMode::ClampToEdge => MLT_WRAP_CLAMP_TO_EDGE,
        mlt::WrapMode::MirroredRepeat => MLT_WRAP_MIRRORED_REPEAT,
    }
}
