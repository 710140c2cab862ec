//! `mlt_intersect` and `mlt_occluded` fed bad input as a C host would: NULL pointers,
//! impossible counts and every bad ray field are refused, naming the ray, before any result
//! is written; and their results follow the header's conventions (t in multiples of the
//! direction, barycentrics in the host's vertex order, tmax inclusive).
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_bad_input_rays`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;
use mlt::error::*;
use std::ptr::{null, null_mut};

#[test]
fn ray_queries_null_pointers() {
    let scene = HostScene::floor_and_light().create();
    let rays = [ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])];
    // A query with one ray, its output NULL or a sentinel: the status, and whether the
    // sentinel is untouched.
    let intersect = |scene: *const MltScene, rays: *const MltRay, output: bool| {
        let mut hits = [SENTINEL_HIT];
        let out = if output {
            hits.as_mut_ptr()
        } else {
            null_mut()
        };
        // SAFETY: each pointer is valid for one element, or NULL, which mlt must refuse.
        let status = unsafe { mlt_intersect(scene, rays, 1, out) };
        (status, hits[0].triangle_id == SENTINEL_HIT.triangle_id)
    };
    let occluded = |scene: *const MltScene, rays: *const MltRay, output: bool| {
        let mut flags = [0xABu8];
        let out = if output {
            flags.as_mut_ptr()
        } else {
            null_mut()
        };
        // SAFETY: as above.
        let status = unsafe { mlt_occluded(scene, rays, 1, out) };
        (status, flags[0] == 0xAB)
    };
    let (live, valid) = (scene.0.cast_const(), rays.as_ptr());
    assert_calls_refused(
        "NULL pointers of the ray queries",
        vec![
            (
                "mlt_intersect scene",
                Box::new(|| intersect(null(), valid, true)),
                &["scene", "NULL"],
            ),
            (
                "mlt_intersect rays",
                Box::new(|| intersect(live, null(), true)),
                &["rays", "NULL"],
            ),
            (
                "mlt_intersect hits_out",
                Box::new(|| intersect(live, valid, false)),
                &["hits_out", "NULL"],
            ),
            (
                "mlt_occluded scene",
                Box::new(|| occluded(null(), valid, true)),
                &["scene", "NULL"],
            ),
            (
                "mlt_occluded rays",
                Box::new(|| occluded(live, null(), true)),
                &["rays", "NULL"],
            ),
            (
                "mlt_occluded occluded_out",
                Box::new(|| occluded(live, valid, false)),
                &["occluded_out", "NULL"],
            ),
        ],
    );
}

#[test]
fn ray_queries_with_zero_rays_accept_null() {
    let scene = HostScene::floor_and_light().create();
    // SAFETY: count 0 makes both arrays unused.
    unsafe {
        assert_ok(mlt_intersect(scene.0, null(), 0, null_mut()));
        assert_ok(mlt_occluded(scene.0, null(), 0, null_mut()));
    }
}

#[test]
fn ray_queries_with_impossible_counts() {
    let scene = HostScene::floor_and_light().create();
    let rays = [ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])];
    let mut hits = [SENTINEL_HIT];
    // SAFETY: the count overflows the address space and must be rejected before any access.
    let s = unsafe { mlt_intersect(scene.0, rays.as_ptr(), usize::MAX, hits.as_mut_ptr()) };
    assert_invalid(s, &["rays", "address space"]);
    assert_eq!(hits[0].triangle_id, SENTINEL_HIT.triangle_id);
}

/// Every bad ray, each at index 1 behind a good ray 0: the message names rays[1] and the
/// outputs stay untouched (all rays are validated before any result is written).
#[test]
fn bad_rays() {
    let scene = HostScene::floor_and_light().create();
    let good = ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]);
    let mut cases = cases![r = good;
        r.direction = [0.0; 3] => ["rays[1].direction", "non-zero"],
        r.tmin = -1.0 => ["rays[1].tmin is -1", ">= 0"],
        { r.tmin = 2.0; r.tmax = 1.0 } => ["rays[1].tmax is 1", "tmin (2)"],
        // tmax may be +inf (no limit), not NaN or -inf.
        r.tmax = f32::NAN => ["rays[1].tmax is NaN"],
        r.tmax = f32::NEG_INFINITY => ["rays[1].tmax is -inf"],
    ];
    cases.extend(non_finite_cases![r = good;
        r.origin[0] => "rays[1].origin.x" + "finite",
        r.origin[1] => "rays[1].origin.y" + "finite",
        r.origin[2] => "rays[1].origin.z" + "finite",
        r.direction[0] => "rays[1].direction.x" + "finite",
        r.direction[1] => "rays[1].direction.y" + "finite",
        r.direction[2] => "rays[1].direction.z" + "finite",
        r.tmin => "rays[1].tmin" + "finite and >= 0",
    ]);
    assert_cases("rays", &cases, |&bad, needles| {
        let rays = [good, bad];
        let (status, hits) = scene.intersect(&rays);
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)
            .and_then(|()| {
                ensure(
                    hits.iter()
                        .all(|h| h.triangle_id == SENTINEL_HIT.triangle_id),
                    "hits_out written although rays[1] is bad",
                )
            })
            .map_err(|e| format!("mlt_intersect: {e}"))?;
        let (status, flags) = scene.occluded(&rays);
        check_error(status, MLT_STATUS_INVALID_ARGUMENT, needles)
            .and_then(|()| {
                ensure(
                    flags == [0xAB, 0xAB],
                    "occluded_out written although rays[1] is bad",
                )
            })
            .map_err(|e| format!("mlt_occluded: {e}"))
    });
}

#[test]
fn ray_query_results_follow_the_host_conventions() {
    let host = HostScene::floor_and_light();
    let scene = host.create();
    // Non-unit direction: t is in multiples of it. Origin 1 above the floor at (0.3, 0.2).
    let rays = [
        ray([0.3, 1.0, 0.2], [0.0, -2.0, 0.0]),
        MltRay {
            tmax: 0.4,
            ..ray([0.3, 1.0, 0.2], [0.0, -2.0, 0.0])
        },
        MltRay {
            tmax: 0.5,
            ..ray([0.3, 1.0, 0.2], [0.0, -2.0, 0.0])
        },
        // The light quad is one-sided for emission but a surface from both sides.
        ray([0.3, 1.0, 0.2], [0.0, 1.0, 0.0]),
        ray([0.3, 1.0, 0.2], [0.0, 0.0, 1.0]),
    ];
    let (status, hits) = scene.intersect(&rays);
    assert_ok(status);
    let h = hits[0];
    assert!(h.triangle_id < 2, "the floor is triangles 0 and 1");
    assert!((h.t - 0.5).abs() < 1e-6, "t = {}", h.t);
    // The hit point from the barycentrics of the host's vertex order.
    let tri = &host.indices[h.triangle_id as usize * 3..][..3];
    let vertex = |i: u32| &host.positions[i as usize * 3..][..3];
    let point: Vec<f32> = (0..3)
        .map(|c| {
            (1.0 - h.u - h.v) * vertex(tri[0])[c]
                + h.u * vertex(tri[1])[c]
                + h.v * vertex(tri[2])[c]
        })
        .collect();
    for (p, expected) in point.iter().zip([0.3, 0.0, 0.2]) {
        assert!((p - expected).abs() < 1e-5, "hit point {point:?}");
    }
    assert_eq!(hits[1].triangle_id, MLT_INVALID_ID, "tmax before the floor");
    assert!(
        hits[2].triangle_id < 2,
        "tmax exactly at the floor still hits"
    );
    assert!(hits[3].triangle_id == 2 || hits[3].triangle_id == 3);
    assert!((hits[3].t - 1.0).abs() < 1e-6);
    assert_eq!(hits[4].triangle_id, MLT_INVALID_ID);
    let (status, flags) = scene.occluded(&rays);
    assert_ok(status);
    assert_eq!(flags, [1, 0, 1, 1, 0]);
}

#[test]
fn tiny_or_huge_but_finite_ray_directions_are_accepted() {
    // The header: direction "Finite and non-zero", t in multiples of it. Both of these are.
    let scene = HostScene::floor_and_light().create();
    let rays = [
        ray([0.3, 1.0, 0.2], [0.0, -1e-30, 0.0]),
        ray([0.3, 1.0, 0.2], [1e-30, -3e38, 1e-30]),
    ];
    let (status, hits) = scene.intersect(&rays);
    assert_ok(status);
    assert!(hits.iter().all(|h| h.triangle_id < 2), "{hits:?}");
    assert!((hits[0].t / 1e30 - 1.0).abs() < 1e-5, "t = {}", hits[0].t);
    assert!((hits[1].t * 3e38 - 1.0).abs() < 1e-5, "t = {}", hits[1].t);
    let (status, flags) = scene.occluded(&rays);
    assert_ok(status);
    assert_eq!(flags, [1, 1]);
}
