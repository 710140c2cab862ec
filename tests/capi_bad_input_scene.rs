//! `mlt_scene_create` and the calls that take a scene, fed bad input as a C host would: each
//! bad pointer, count, index, float or enum is refused with `MLT_STATUS_INVALID_ARGUMENT`, a
//! message naming it, and `*out` untouched; released or foreign scene pointers are refused
//! by every call; degenerate triangles are accepted, counted and never hit; every build
//! quality builds.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_bad_input_scene`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;
use mlt::error::*;
use std::ptr::{null, null_mut};

/// Releasing NULL touches nothing: the thread's last error stays as it was, and scenes are
/// created and released as before.
#[test]
fn release_null_leaves_the_last_error_and_the_library_as_they_were() {
    let mut out = sentinel_scene();
    // SAFETY: NULL desc must be rejected.
    let status = unsafe { mlt_scene_create(null(), &mut out) };
    assert_invalid(status, &["desc", "NULL"]);
    let error = last_error();
    // SAFETY: NULL is documented as a no-op.
    unsafe {
        mlt_scene_release(null_mut());
        mlt_scene_release(null_mut());
    }
    assert_eq!(last_error(), error);
    drop(HostScene::floor_and_light().create());
}

/// Pointers that are not live scenes (released, never created, misaligned, NULL) are
/// refused by every call that takes a scene, never dereferenced; retain adds a reference
/// that one more release drops.
#[test]
fn released_and_foreign_scene_pointers_are_refused() {
    let floor = HostScene::floor_and_light();
    let mut out = sentinel_scene();
    // SAFETY: a valid description and out-parameter.
    assert_ok(unsafe { mlt_scene_create(&floor.desc(), &mut out) });
    let released = out;
    // SAFETY: pointers are looked up, not dereferenced.
    unsafe {
        assert_ok(mlt_scene_retain(released));
        mlt_scene_release(released);
    }
    let retained = Handle(released);
    assert_eq!(
        retained.info().triangle_count,
        4,
        "retained scene still live"
    );
    drop(retained);

    let mut word = 0u64;
    let stack = (&raw mut word).cast::<MltScene>();
    let odd = stack.cast::<u8>().wrapping_add(1).cast::<MltScene>();
    let camera = floor_camera();
    let settings = small_settings(4, 4, 1);
    let rays = [ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])];
    let plan = {
        let live = floor.create();
        let mut bytes = empty_bytes();
        // SAFETY: a live scene and valid pointers.
        assert_ok(unsafe { mlt_render_plan(live.0, &camera, &settings, &mut bytes) });
        // SAFETY: the bytes mlt gave, read before they are released.
        let plan = unsafe { std::slice::from_raw_parts(bytes.data, bytes.size) }.to_vec();
        // SAFETY: filled by mlt_render_plan, released once.
        unsafe { mlt_bytes_release(&mut bytes) };
        plan
    };
    // Each call that takes a scene: its status, and whether its outputs are untouched.
    type Call<'a> = (
        &'a str,
        Box<dyn Fn(*mut MltScene) -> (MltStatus, bool) + 'a>,
    );
    let calls: [Call; 7] = [
        (
            "mlt_render_plan",
            Box::new(|scene| {
                let mut out = empty_bytes();
                // SAFETY: every other pointer is valid; `scene` must be refused before use.
                let status = unsafe { mlt_render_plan(scene, &camera, &settings, &mut out) };
                (status, out.data.is_null())
            }),
        ),
        (
            "mlt_render_job",
            Box::new(|scene| {
                let mut out = empty_bytes();
                // SAFETY: as above; `plan` holds `plan.len()` bytes.
                let status = unsafe {
                    mlt_render_job(
                        scene,
                        plan.as_ptr(),
                        plan.len(),
                        0,
                        1,
                        1,
                        None,
                        null_mut(),
                        &mut out,
                        null_mut(),
                    )
                };
                (status, out.data.is_null())
            }),
        ),
        (
            "mlt_scene_get_info",
            Box::new(|scene| {
                let mut info = scene_info_default();
                // SAFETY: as above.
                let status = unsafe { mlt_scene_get_info(scene, &mut info) };
                (status, info.triangle_count == 0)
            }),
        ),
        (
            "mlt_render",
            Box::new(|scene| {
                let mut image = vec![SENTINEL_F32; 48];
                // SAFETY: as above; `image` holds the floats passed.
                let status = unsafe {
                    mlt_render(
                        scene,
                        &camera,
                        &settings,
                        image.as_mut_ptr(),
                        image.len(),
                        None,
                        null_mut(),
                    )
                };
                (status, image.iter().all(|&v| v == SENTINEL_F32))
            }),
        ),
        (
            "mlt_intersect",
            Box::new(|scene| {
                let mut hits = [SENTINEL_HIT];
                // SAFETY: as above; one ray, one hit.
                let status = unsafe { mlt_intersect(scene, rays.as_ptr(), 1, hits.as_mut_ptr()) };
                (status, hits[0].triangle_id == SENTINEL_HIT.triangle_id)
            }),
        ),
        (
            "mlt_occluded",
            Box::new(|scene| {
                let mut flags = [0xABu8];
                // SAFETY: as above; one ray, one flag.
                let status = unsafe { mlt_occluded(scene, rays.as_ptr(), 1, flags.as_mut_ptr()) };
                (status, flags[0] == 0xAB)
            }),
        ),
        (
            "mlt_scene_retain",
            // SAFETY: `scene` must be refused before use.
            Box::new(|scene| (unsafe { mlt_scene_retain(scene) }, true)),
        ),
    ];
    let mut results = Vec::new();
    for (what, scene) in [
        ("released", released),
        ("foreign", stack),
        ("misaligned", odd),
        ("sentinel", sentinel_scene()),
    ] {
        for (name, call) in &calls {
            let (status, untouched) = call(scene);
            let result = check_error(
                status,
                MLT_STATUS_INVALID_ARGUMENT,
                &["scene", "not a live scene"],
            )
            .and_then(|()| ensure(untouched, "an output was written"));
            results.push((format!("{what} scene: {name}"), result));
        }
        // SAFETY: looked up, not dereferenced; ignored with a message.
        unsafe { mlt_scene_release(scene) };
        let message = last_error();
        results.push((
            format!("{what} scene: mlt_scene_release"),
            ensure(
                message.contains("not a live scene"),
                &format!("message {message:?}"),
            ),
        ));
    }
    assert_all("pointers that are not live scenes", results);
    assert_eq!(word, 0, "a foreign pointer's memory was written");
    // SAFETY: NULL is refused by retain.
    assert_invalid(unsafe { mlt_scene_retain(null_mut()) }, &["scene", "NULL"]);
}

#[test]
fn scene_create_null_desc_or_out() {
    let host = HostScene::floor_and_light();
    assert_calls_refused(
        "NULL pointers of mlt_scene_create",
        vec![
            (
                "desc",
                Box::new(|| {
                    let mut out = sentinel_scene();
                    // SAFETY: NULL desc must be rejected.
                    let status = unsafe { mlt_scene_create(null(), &mut out) };
                    (status, out == sentinel_scene())
                }),
                &["desc", "NULL"],
            ),
            (
                "out",
                // SAFETY: NULL out must be rejected.
                Box::new(|| (unsafe { mlt_scene_create(&host.desc(), null_mut()) }, true)),
                &["out", "NULL"],
            ),
        ],
    );
}

/// Array pointers mlt must refuse before reading them: NULL with a length, misaligned, and
/// lengths whose byte size overflows.
#[test]
fn scene_create_bad_arrays() {
    let host = HostScene::floor_and_light();
    // u64 storage: one byte past its start is misaligned for every multi-byte type.
    let storage = [0u64; 8];
    let odd = storage.as_ptr().cast::<u8>().wrapping_add(1);
    let cases = cases![d = host.desc();
        d.positions = null() => ["positions", "NULL"],
        d.indices = null() => ["indices", "NULL"],
        d.materials = null() => ["materials", "NULL"],
        d.material_ids = null() => ["material_ids", "NULL"],
        d.positions = odd.cast() => ["positions", "aligned"],
        d.indices = odd.cast() => ["indices", "aligned"],
        d.positions_len = usize::MAX / 2 => ["positions", "address space"],
        d.indices_len = usize::MAX => ["indices", "address space"],
    ];
    assert_create_refuses("scene arrays", &cases, |d| *d);
}

#[test]
fn scene_create_null_arrays_with_zero_length_are_an_empty_scene() {
    let desc = default_desc();
    let mut out = null_mut();
    // SAFETY: NULL arrays with length 0 are documented as fine.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let scene = Handle(out);
    let info = scene.info();
    assert_eq!(info.triangle_count, 0);
    assert_eq!(info.emitter_count, 0);
    let (status, image) = scene.render(&default_camera(), &small_settings(4, 4, 2), 48);
    assert_ok(status);
    assert!(
        image.iter().all(|&v| v == 0.0),
        "an empty scene renders black"
    );
}

#[test]
fn scene_create_bad_counts() {
    let host = HostScene::floor_and_light();
    let cases = cases![d = host.desc();
        d.positions_len = 23 => ["positions", "23"],
        d.indices_len = 11 => ["indices", "11"],
        d.material_ids_len = 3 => ["material_ids", "3", "4 triangles"],
        {
            (d.materials, d.materials_len) = (null(), 0);
            (d.material_ids, d.material_ids_len) = (null(), 0);
        } => ["materials", "empty"],
    ];
    assert_create_refuses("scene counts", &cases, |d| *d);
}

#[test]
fn scene_create_indices_out_of_range() {
    let host = HostScene::floor_and_light();
    let cases = cases![h = host.clone();
        h.indices[7] = 8 => ["indices[7]", "8", "8 vertices"],
        h.indices[7] = u32::MAX => ["indices[7]", "4294967295"],
        h.material_ids[3] = 2 => ["material_ids[3]", "2", "2 materials"],
    ];
    assert_create_refuses("scene indices", &cases, HostScene::desc);
}

#[test]
fn missing_material_ids_mean_material_0() {
    let host = HostScene::floor_and_light();
    let desc = MltSceneDesc {
        material_ids: null(),
        material_ids_len: 0,
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: valid desc.
    assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
    let scene = Handle(out);
    assert_eq!(scene.info().emitter_count, 0, "material 0 does not emit");
}

/// Every float of the vertices and materials must be finite (`ior` too where it is ignored,
/// on a diffuse material), colors within [0, 1] and emission not negative.
#[test]
fn scene_create_bad_floats() {
    let host = HostScene::floor_and_light();
    let mut cases = cases![h = host.clone();
        h.positions[13] = f32::NAN => ["positions[13]", "vertex 4", "y", "NaN"],
        h.positions[13] = f32::INFINITY => ["positions[13]", "vertex 4", "y", "inf"],
        h.positions[13] = f32::NEG_INFINITY => ["positions[13]", "vertex 4", "y", "-inf"],
        h.materials[0].color[2] = -0.5 => ["materials[0].color.z", "-0.5"],
        h.materials[1].color[0] = 1.5 => ["materials[1].color.x", "1.5"],
        h.materials[1].emission[2] = -1.0 => ["materials[1].emission.z", "-1", "negative"],
    ];
    cases.extend(non_finite_cases![h = host.clone();
        h.materials[0].color[0] => "desc.materials[0].color.x" + "finite",
        h.materials[0].color[1] => "desc.materials[0].color.y" + "finite",
        h.materials[0].color[2] => "desc.materials[0].color.z" + "finite",
        h.materials[1].emission[0] => "desc.materials[1].emission.x" + "finite",
        h.materials[1].emission[1] => "desc.materials[1].emission.y" + "finite",
        h.materials[1].emission[2] => "desc.materials[1].emission.z" + "finite",
        h.materials[0].ior => "desc.materials[0].ior" + "finite",
    ]);
    assert_create_refuses("scene floats", &cases, HostScene::desc);
}

#[test]
fn scene_create_bad_dielectric_ior() {
    let mut dielectric = HostScene::floor_and_light();
    dielectric.materials[0].kind = MLT_MATERIAL_DIELECTRIC;
    let mut cases = cases![h = dielectric.clone();
        h.materials[0].ior = 0.0 => ["materials[0].ior", "greater than 0"],
        h.materials[0].ior = -0.0 => ["materials[0].ior", "greater than 0"],
        h.materials[0].ior = -1.5 => ["materials[0].ior", "greater than 0"],
    ];
    cases.extend(non_finite_cases![h = dielectric.clone();
        h.materials[0].ior => "desc.materials[0].ior" + "finite",
    ]);
    assert_create_refuses("dielectric ior", &cases, HostScene::desc);
}

#[test]
fn ior_is_ignored_for_non_dielectrics() {
    // The header: "Ignored otherwise". Zero or negative is accepted for diffuse and mirror
    // (a non-finite one is not: `scene_create_bad_floats`).
    for kind in [MLT_MATERIAL_DIFFUSE, MLT_MATERIAL_MIRROR] {
        let mut host = HostScene::floor_and_light();
        host.materials[0].kind = kind;
        host.materials[0].ior = -1.0;
        drop(host.create());
    }
}

#[test]
fn scene_create_unknown_enums() {
    let host = HostScene::floor_and_light();
    let cases = cases![h = host.clone();
        h.materials[1].kind = 4
            => ["materials[1].kind is 4", "MLT_MATERIAL_DIFFUSE", "MLT_MATERIAL_METALLIC_ROUGHNESS"],
        h.materials[1].kind = -1 => ["materials[1].kind is -1", "MLT_MATERIAL_DIFFUSE"],
        h.materials[1].kind = i32::MAX
            => ["materials[1].kind is 2147483647", "MLT_MATERIAL_DIFFUSE"],
        h.backend = 2 => ["backend", "2"],
        h.backend = -1 => ["backend", "-1"],
        h.backend = i32::MIN => ["backend", "-2147483648"],
    ];
    assert_create_refuses("scene enums", &cases, HostScene::desc);
}

#[test]
#[cfg(not(feature = "embree"))]
fn embree_backend_is_unsupported_without_the_feature() {
    let mut host = HostScene::floor_and_light();
    host.backend = MLT_BACKEND_EMBREE;
    let needles = ["Embree", "`embree` feature"];
    pass(check_create_refused(
        &host.desc(),
        MLT_STATUS_UNSUPPORTED,
        &needles,
    ));
}

#[test]
#[cfg(feature = "embree")]
fn embree_backend_builds_with_the_feature() {
    let mut host = HostScene::floor_and_light();
    host.backend = MLT_BACKEND_EMBREE;
    let scene = host.create();
    let info = scene.info();
    assert_eq!(info.backend, MLT_BACKEND_EMBREE);
    assert_eq!((info.triangle_count, info.emitter_count), (4, 2));
    let (status, hits) = scene.intersect(&[ray([0.5, 1.0, 0.25], [0.0, 2.0, 0.0])]);
    assert_ok(status);
    assert!(hits[0].triangle_id >= 2, "the upward ray hits the light");
    // Embree's t may be an ulp off (3.13.5 reports 0.49999997 on some CPUs).
    assert!(
        (hits[0].t - 0.5).abs() <= 2.0 * f32::EPSILON,
        "t in multiples of the direction: {}",
        hits[0].t
    );
}

/// The floor-and-light scene plus, floating at y = 1, a triangle with a repeated vertex and a
/// triangle with collinear vertices, both emissive.
fn with_degenerates() -> HostScene {
    let mut host = HostScene::floor_and_light();
    host.positions.extend([
        -0.5, 1.0, 0.0, // 8
        0.5, 1.0, 0.0, // 9
        0.0, 1.0, 0.0, // 10: midpoint of 8-9
    ]);
    host.indices.extend([8, 9, 9, 8, 10, 9]);
    host.material_ids.extend([1, 1]);
    host
}

#[test]
fn degenerate_triangles_are_accepted_and_counted() {
    let scene = with_degenerates().create();
    let info = scene.info();
    assert_eq!(info.triangle_count, 6);
    assert_eq!(info.degenerate_triangle_count, 2);
    assert_eq!(info.emitter_count, 2, "degenerate triangles never emit");
    assert_eq!(info.bounds_min, [-1.0, 0.0, -1.0]);
    assert_eq!(info.bounds_max, [1.0, 2.0, 1.0]);
    assert_eq!(info.backend, MLT_BACKEND_BVH);
}

#[test]
fn degenerate_triangles_are_never_hit() {
    for backend in supported_backends() {
        let mut host = with_degenerates();
        host.backend = backend;
        degenerate_triangles_are_never_hit_with(host.create());
    }
}

fn degenerate_triangles_are_never_hit_with(scene: Handle) {
    // Rays through the degenerate triangles' line, from several directions.
    let rays = [
        ray([0.0, 1.0, -3.0], [0.0, 0.0, 1.0]), // along z, through the midpoint
        ray([0.25, 1.0, -3.0], [0.0, 0.0, 1.0]),
        ray([-3.0, 1.0, 0.0], [1.0, 0.0, 0.0]), // along the line itself
        ray([0.0, 1.5, 0.0], [0.0, -1.0, 0.0]), // down through it onto the floor
    ];
    let (status, hits) = scene.intersect(&rays);
    assert_ok(status);
    for (i, hit) in hits.iter().enumerate() {
        assert!(
            hit.triangle_id != 4 && hit.triangle_id != 5,
            "ray {i} hit degenerate triangle {}",
            hit.triangle_id
        );
    }
    assert_eq!(hits[0].triangle_id, MLT_INVALID_ID);
    assert_eq!(hits[0].t, f32::INFINITY);
    assert!(
        hits[3].triangle_id < 2,
        "the downward ray reaches the floor"
    );
    assert!((hits[3].t - 1.5).abs() < 1e-5);
    let (status, flags) = scene.occluded(&rays[..3]);
    assert_ok(status);
    assert_eq!(flags, [0, 0, 0]);
}

#[test]
fn a_scene_of_only_degenerate_triangles_renders_black() {
    let host = HostScene {
        positions: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0],
        indices: vec![0, 1, 2, 0, 0, 1, 2, 2, 2],
        material_ids: vec![0, 1, 1],
        materials: vec![
            default_material(),
            MltMaterial {
                emission: [5.0; 3],
                ..default_material()
            },
        ],
        backend: MLT_BACKEND_BVH,
    };
    let scene = host.create();
    let info = scene.info();
    assert_eq!(
        (
            info.triangle_count,
            info.degenerate_triangle_count,
            info.emitter_count
        ),
        (3, 3, 0)
    );
    let camera = MltCamera {
        eye: [1.0, 1.0, -5.0],
        target: [1.0, 1.0, 1.0],
        ..default_camera()
    };
    let (status, image) = scene.render(&camera, &small_settings(8, 8, 4), 8 * 8 * 3);
    assert_ok(status);
    assert!(image.iter().all(|&v| v == 0.0));
    let (status, hits) = scene.intersect(&[ray([1.0, 1.0, -5.0], [0.0, 0.0, 1.0])]);
    assert_ok(status);
    assert_eq!(hits[0].triangle_id, MLT_INVALID_ID);
}

#[test]
fn get_info_null_pointers() {
    let scene = HostScene::floor_and_light().create();
    assert_calls_refused(
        "NULL pointers of mlt_scene_get_info",
        vec![
            (
                "scene",
                Box::new(|| {
                    let mut info = MltSceneInfo {
                        triangle_count: 99,
                        ..scene_info_default()
                    };
                    // SAFETY: NULL must be rejected.
                    let status = unsafe { mlt_scene_get_info(null(), &mut info) };
                    (status, info.triangle_count == 99)
                }),
                &["scene", "NULL"],
            ),
            (
                "out",
                // SAFETY: NULL out must be rejected.
                Box::new(|| (unsafe { mlt_scene_get_info(scene.0, null_mut()) }, true)),
                &["out", "NULL"],
            ),
        ],
    );
}

/// Every build quality builds (the scene info says which, with the structure's memory and
/// build time) and renders the same image up to rounding; unknown values are refused; and a
/// host built against the header before the field gets the default, whatever its memory
/// holds past its struct.
#[test]
fn build_qualities() {
    let host = HostScene::floor_and_light();
    let settings = small_settings(4, 4, 4);
    let (status, expected) = host.create().render(&floor_camera(), &settings, 48);
    assert_ok(status);
    for backend in supported_backends() {
        for quality in [
            MLT_BUILD_QUALITY_HIGH,
            MLT_BUILD_QUALITY_MEDIUM,
            MLT_BUILD_QUALITY_FAST,
        ] {
            let desc = MltSceneDesc {
                backend,
                build_quality: quality,
                ..host.desc()
            };
            let mut out = null_mut();
            // SAFETY: a valid description.
            assert_ok(unsafe { mlt_scene_create(&desc, &mut out) });
            let scene = Handle(out);
            let info = scene.info();
            assert_eq!(info.build_quality, quality);
            assert!(info.accel_memory_bytes > 0, "{info:?}");
            assert!(info.accel_build_seconds >= 0.0, "{info:?}");
            let (status, image) = scene.render(&floor_camera(), &settings, 48);
            assert_ok(status);
            let difference: f32 = image
                .iter()
                .zip(&expected)
                .map(|(a, b)| (a - b).abs())
                .sum();
            let total: f32 = expected.iter().sum();
            assert!(
                difference <= 1e-4 * total,
                "backend {backend}, quality {quality}"
            );
        }
    }
    assert_eq!(default_desc().build_quality, MLT_BUILD_QUALITY_HIGH);
    let cases = cases![d = host.desc();
        d.build_quality = 3 => ["desc.build_quality", "3", "MLT_BUILD_QUALITY_HIGH"],
        d.build_quality = -1 => ["desc.build_quality", "-1", "MLT_BUILD_QUALITY_HIGH"],
        d.build_quality = i32::MIN
            => ["desc.build_quality", "-2147483648", "MLT_BUILD_QUALITY_HIGH"],
    ];
    assert_create_refuses("build qualities", &cases, |d| *d);
    let older = MltSceneDesc {
        struct_size: earlier_size::<MltSceneDesc>(std::mem::offset_of!(
            MltSceneDesc,
            build_quality
        )),
        // Garbage an older host's memory may hold past its struct.
        build_quality: 12345,
        ..host.desc()
    };
    let mut out = null_mut();
    // SAFETY: an older layout's struct; mlt reads only its first bytes.
    assert_ok(unsafe { mlt_scene_create(&older, &mut out) });
    assert_eq!(Handle(out).info().build_quality, MLT_BUILD_QUALITY_HIGH);
}
