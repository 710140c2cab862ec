//! The lights of `MltSceneDesc` (environment, sun, punctual lights) fed bad input as a C host
//! would: their initializers' defaults, every bad value, pointer and count refused with a
//! message naming it, unused fields ignored, and a host built against the header before
//! the lights getting none.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_bad_input_lights`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;
use mlt::{MLT_MAX_ENVIRONMENT_SIDE, MLT_MAX_PUNCTUAL_LIGHTS};
use std::ptr::{null, null_mut};

/// A scene with every kind of light: `HostScene::floor_and_light` under a 2 × 1
/// environment, a sun, and a point, a spot and a directional light (in that order).
struct HostLights {
    host: HostScene,
    /// What `environment.pixels` points to (set at construction: the vector's buffer does
    /// not move with the struct).
    pixels: Vec<f32>,
    environment: MltEnvironment,
    sun: MltSun,
    punctual: Vec<MltPunctualLight>,
}

impl HostLights {
    fn new() -> Self {
        let pixels = vec![0.5, 0.6, 0.7, 1.0, 1.0, 1.0];
        let environment = MltEnvironment {
            pixels: pixels.as_ptr(),
            width: 2,
            height: 1,
            rotation_degrees: 30.0,
            scale: 2.0,
            ..default_environment()
        };
        let sun = MltSun {
            direction: [1.0, 2.0, 0.5],
            angular_radius_degrees: 1.0,
            irradiance: [3.0, 2.0, 1.0],
            ..default_sun()
        };
        let point = MltPunctualLight {
            position: [0.0, 1.0, 0.0],
            intensity: [1.0, 2.0, 3.0],
            ..default_punctual_light()
        };
        let spot = MltPunctualLight {
            kind: MLT_LIGHT_SPOT,
            position: [0.5, 1.5, 0.0],
            direction: [0.0, -1.0, 0.0],
            inner_cone_degrees: 10.0,
            outer_cone_degrees: 20.0,
            ..default_punctual_light()
        };
        let directional = MltPunctualLight {
            kind: MLT_LIGHT_DIRECTIONAL,
            direction: [0.3, -1.0, 0.0],
            ..default_punctual_light()
        };
        HostLights {
            host: HostScene::floor_and_light(),
            pixels,
            environment,
            sun,
            punctual: vec![point, spot, directional],
        }
    }

    fn desc(&self) -> MltSceneDesc {
        MltSceneDesc {
            environment: &self.environment,
            sun: &self.sun,
            punctual_lights: self.punctual.as_ptr(),
            punctual_lights_len: self.punctual.len(),
            ..self.host.desc()
        }
    }
}

#[test]
fn light_defaults_are_valid_and_documented() {
    let d = default_desc();
    assert!(d.environment.is_null() && d.sun.is_null());
    assert!(d.punctual_lights.is_null() && d.punctual_lights_len == 0);
    let e = default_environment();
    assert!(e.pixels.is_null());
    assert_eq!(
        (e.width, e.height, e.rotation_degrees, e.scale),
        (0, 0, 0.0, 1.0)
    );
    let s = default_sun();
    assert_eq!(
        (s.direction, s.angular_radius_degrees, s.irradiance),
        ([0.0, 1.0, 0.0], 0.27, [1.0; 3])
    );
    let l = default_punctual_light();
    assert_eq!(
        (l.kind, l.position, l.intensity),
        (MLT_LIGHT_POINT, [0.0; 3], [1.0; 3])
    );
    assert_eq!(
        (l.direction, l.inner_cone_degrees, l.outer_cone_degrees),
        ([0.0, 0.0, -1.0], 0.0, 45.0)
    );
    // Every kind of light together, valid.
    let lights = HostLights::new();
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(&lights.desc(), &mut out) });
    drop(Handle(out));
}

#[test]
fn light_initializers_refuse_null_and_unknown_sizes() {
    // SAFETY (each closure): forwards the pointer and size to the initializer under test.
    let initializers: [(&str, usize, Initializer); 3] = [
        (
            "mlt_environment_default",
            size_of::<MltEnvironment>(),
            |p, n| unsafe { mlt_environment_init(p.cast(), n) },
        ),
        ("mlt_sun_default", size_of::<MltSun>(), |p, n| unsafe {
            mlt_sun_init(p.cast(), n)
        }),
        (
            "mlt_punctual_light_default",
            size_of::<MltPunctualLight>(),
            |p, n| unsafe { mlt_punctual_light_init(p.cast(), n) },
        ),
    ];
    assert_initializers_refuse_null_and_unknown_sizes("light initializers", &initializers);
}

/// Every bad value of the environment, the sun and the punctual lights, and bad pointers
/// and counts, each refused with a message naming it.
#[test]
fn scene_create_bad_lights() {
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let mut cases = cases![h = HostLights::new();
        h.environment.pixels = null() => ["desc.environment.pixels", "NULL"],
        h.environment.pixels = odd.cast() => ["desc.environment.pixels", "aligned"],
        h.environment.width = 0 => ["desc.environment is 0 x 1", "at least 1 x 1"],
        h.environment.height = 0 => ["desc.environment is 2 x 0", "at least 1 x 1"],
        h.environment.width = MLT_MAX_ENVIRONMENT_SIDE + 1
            => ["desc.environment is 65537 x 1", "at most 65536"],
        (h.environment.width, h.environment.height) = (1 << 15, 1 << 14)
            => ["desc.environment is 32768 x 16384", "at most 268435456 texels"],
        h.environment.struct_size = 0
            => ["desc.environment.struct_size is 0", "mlt_environment_default"],
        h.environment.struct_size = size_of::<MltEnvironment>() as u32 + 8
            => ["desc.environment.struct_size", "newer mlt header"],
        h.pixels[4] = -1.0
            => ["desc.environment.pixels[4]", "texel 1", "column 1", "G", "is -1", ">= 0"],
        h.pixels[5] = f32::NAN => ["desc.environment.pixels[5]", "B", "is NaN"],
        h.pixels[0] = f32::INFINITY => ["desc.environment.pixels[0]", "R", "is inf"],
        h.environment.scale = -1.0 => ["desc.environment.scale is -1", ">= 0"],
        h.sun.struct_size = 0 => ["desc.sun.struct_size is 0", "mlt_sun_default"],
        h.sun.direction = [0.0; 3] => ["desc.sun.direction", "non-zero"],
        h.sun.direction = [1e30, 1e30, 0.0] => ["desc.sun.direction", "finite length"],
        h.sun.angular_radius_degrees = 46.0
            => ["desc.sun.angular_radius_degrees is 46", "[0, 45]"],
        h.sun.angular_radius_degrees = -1.0
            => ["desc.sun.angular_radius_degrees is -1", "[0, 45]"],
        h.sun.irradiance[0] = -1.0 => ["desc.sun.irradiance (R) is -1", ">= 0"],
        h.punctual[0].kind = 3
            => ["desc.punctual_lights[0].kind is 3", "MLT_LIGHT_POINT", "MLT_LIGHT_DIRECTIONAL"],
        h.punctual[2].kind = -1 => ["desc.punctual_lights[2].kind is -1", "MLT_LIGHT_SPOT"],
        h.punctual[0].intensity[1] = -2.0
            => ["desc.punctual_lights[0].intensity (G) is -2", ">= 0"],
        (h.punctual[1].inner_cone_degrees, h.punctual[1].outer_cone_degrees) = (30.0, 20.0)
            => ["desc.punctual_lights[1].inner_cone_degrees is 30", "outer_cone_degrees is 20"],
        h.punctual[1].outer_cone_degrees = 10.0
            => ["desc.punctual_lights[1].inner_cone_degrees is 10", "inner < outer"],
        h.punctual[1].outer_cone_degrees = 91.0
            => ["desc.punctual_lights[1]", "outer_cone_degrees is 91", "<= 90"],
        h.punctual[1].inner_cone_degrees = -1.0
            => ["desc.punctual_lights[1].inner_cone_degrees is -1", "0 <= inner"],
        h.punctual[1].direction = [0.0; 3] => ["desc.punctual_lights[1].direction", "non-zero"],
        h.punctual[2].direction = [0.0; 3] => ["desc.punctual_lights[2].direction", "non-zero"],
        h.punctual[1].struct_size = 0
            => ["desc.punctual_lights[1].struct_size is 0", "desc.punctual_lights[0]'s"],
        h.punctual[0].struct_size = 0
            => ["desc.punctual_lights[0].struct_size is 0", "mlt_punctual_light_default"],
    ];
    cases.extend(non_finite_cases![h = HostLights::new();
        h.environment.scale => "desc.environment.scale" + ">= 0",
        h.environment.rotation_degrees => "desc.environment.rotation_degrees" + "finite",
        h.sun.direction[1] => "desc.sun.direction.y" + "finite",
        h.sun.angular_radius_degrees => "desc.sun.angular_radius_degrees" + "[0, 45]",
        h.sun.irradiance[2] => "desc.sun.irradiance (B)" + ">= 0",
        h.punctual[0].position[2] => "desc.punctual_lights[0].position.z" + "finite",
        h.punctual[1].position[0] => "desc.punctual_lights[1].position.x" + "finite",
        h.punctual[0].intensity[0] => "desc.punctual_lights[0].intensity (R)" + ">= 0",
        h.punctual[1].direction[2] => "desc.punctual_lights[1].direction.z" + "finite",
        h.punctual[2].direction[0] => "desc.punctual_lights[2].direction.x" + "finite",
        h.punctual[1].inner_cone_degrees
            => "desc.punctual_lights[1].inner_cone_degrees" + "0 <= inner < outer <= 90",
        h.punctual[1].outer_cone_degrees
            => "desc.punctual_lights[1].outer_cone_degrees" + "0 <= inner < outer <= 90",
    ]);
    assert_create_refuses("lights", &cases, HostLights::desc);

    // Pointers and counts of the description itself.
    let lights = HostLights::new();
    let cases = cases![d = lights.desc();
        d.punctual_lights = null() => ["desc.punctual_lights", "NULL"],
        d.punctual_lights = odd.cast() => ["desc.punctual_lights[0]", "aligned"],
        d.environment = odd.cast() => ["desc.environment", "aligned"],
        d.sun = odd.cast() => ["desc.sun", "aligned"],
        d.punctual_lights_len = MLT_MAX_PUNCTUAL_LIGHTS + 1
            => ["desc.punctual_lights_len is 1048577", "at most 1048576"],
        d.punctual_lights_len = usize::MAX
            => ["desc.punctual_lights_len", "at most 1048576"],
    ];
    assert_create_refuses("light pointers", &cases, |d| *d);
}

/// Lights that are valid but unused are not checked: a point light's direction and cone,
/// a directional light's position and cone.
#[test]
fn unused_light_fields_are_ignored() {
    let mut lights = HostLights::new();
    lights.punctual[0].direction = [0.0; 3];
    lights.punctual[0].outer_cone_degrees = -5.0;
    lights.punctual[2].position = [f32::NAN; 3];
    let mut out = null_mut();
    // SAFETY: the desc points into live values.
    assert_ok(unsafe { mlt_scene_create(&lights.desc(), &mut out) });
    drop(Handle(out));
}

/// A host built against the header before the lights (its `MltSceneDesc` ends at
/// `backend`) gets no lights, whatever its memory holds past its struct.
#[test]
fn an_older_scene_desc_has_no_lights() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    let settings = small_settings(4, 4, 4);
    let (status, expected) = scene.render(&floor_camera(), &settings, 48);
    assert_ok(status);
    let older = MltSceneDesc {
        struct_size: earlier_size::<MltSceneDesc>(std::mem::offset_of!(MltSceneDesc, environment)),
        // Garbage an older host's memory may hold: mlt must not read it.
        environment: std::ptr::dangling(),
        sun: std::ptr::dangling(),
        punctual_lights: std::ptr::dangling(),
        punctual_lights_len: usize::MAX,
        ..host.desc()
    };
    assert_eq!(older.struct_size, 80, "mlt 0.2's sizeof(MltSceneDesc)");
    let mut out = null_mut();
    // SAFETY: an older layout's struct; mlt reads only its first 80 bytes.
    assert_ok(unsafe { mlt_scene_create(&older, &mut out) });
    let older_scene = Handle(out);
    let (status, image) = older_scene.render(&floor_camera(), &settings, 48);
    assert_ok(status);
    assert_eq!(image, expected, "the same scene, without lights");
}
