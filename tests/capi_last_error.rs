//! `mlt_last_error_message()`'s life cycle: every kind of successful call clears it, and it
//! belongs to the thread whose call failed.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_last_error`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;
use std::ptr::{null, null_mut};

#[test]
fn last_error_is_cleared_by_each_kind_of_success() {
    let scene = HostScene::floor_and_light().create();
    let fail = || {
        // SAFETY: NULL must be rejected.
        let s = unsafe { mlt_camera_init(null_mut(), size_of::<MltCamera>()) };
        assert_invalid(s, &["out"]);
        assert!(!last_error().is_empty());
    };
    fail();
    let _ = scene.info(); // asserts the message is "" afterwards
    fail();
    let (status, _) = scene.render(&floor_camera(), &small_settings(4, 4, 1), 48);
    assert_ok(status);
    fail();
    let (status, _) = scene.intersect(&[ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])]);
    assert_ok(status);
    fail();
    let (status, _) = scene.occluded(&[ray([0.0, 1.0, 0.0], [0.0, -1.0, 0.0])]);
    assert_ok(status);
    fail();
    let _ = HostScene::floor_and_light().create();
    fail();
    let _ = default_settings();
    fail();
    let mut plan = empty_bytes();
    // SAFETY: valid pointers.
    assert_ok(unsafe {
        mlt_render_plan(
            scene.0,
            &floor_camera(),
            &small_settings(4, 4, 1),
            &mut plan,
        )
    });
    fail();
    let mut partial = empty_bytes();
    // SAFETY: the plan's bytes as mlt gave them.
    assert_ok(unsafe {
        mlt_render_job(
            scene.0,
            plan.data,
            plan.size,
            0,
            1,
            1,
            None,
            null_mut(),
            &mut partial,
            null_mut(),
        )
    });
    fail();
    let mut image = [0.0f32; 48];
    let partials = [partial.data.cast_const()];
    // SAFETY: one partial result of `partial.size` bytes; 48 floats.
    assert_ok(unsafe {
        mlt_render_merge(
            plan.data,
            plan.size,
            partials.as_ptr(),
            &partial.size,
            1,
            image.as_mut_ptr(),
            48,
            null_mut(),
        )
    });
    fail();
    let mut combined = empty_bytes();
    // SAFETY: one partial result of `partial.size` bytes.
    assert_ok(unsafe {
        mlt_render_combine(
            plan.data,
            plan.size,
            partials.as_ptr(),
            &partial.size,
            1,
            &mut combined,
        )
    });
    fail();
    // SAFETY: filled by mlt, released once each.
    unsafe { mlt_bytes_release(&mut combined) };
    // SAFETY: as above.
    unsafe { mlt_bytes_release(&mut partial) };
    assert_eq!(last_error(), "", "a release clears the last error");
    // SAFETY: as above.
    unsafe { mlt_bytes_release(&mut plan) };
}

#[test]
fn last_error_belongs_to_the_failing_thread() {
    // SAFETY: NULL must be rejected.
    let s = unsafe { mlt_scene_create(null(), null_mut()) };
    assert_invalid(s, &["desc"]);
    let other = std::thread::spawn(last_error).join().unwrap();
    assert_eq!(other, "", "another thread has no error");
    assert!(
        last_error().contains("desc"),
        "this thread's message survives"
    );
}
