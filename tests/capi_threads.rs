//! Scenes shared by host threads through the C ABI: several threads render and query one
//! scene at once and get bit-identical images for the same seed (and different images for
//! different seeds); a scene released while renders run stays alive until they return.
//!
//! Runs in under a second on 2 cores (`cargo test --test capi_threads`).

mod common {
    pub mod capi;
    pub mod scenes;
}

use common::capi::*;
use mlt::capi::*;

/// A scene released while renders and queries on other threads are running stays alive
/// until they return: each image equals the same render on a scene nobody releases.
#[test]
fn a_scene_released_during_renders_stays_alive_until_they_return() {
    let floor = HostScene::floor_and_light();
    let camera = floor_camera();
    let settings = MltRenderSettings {
        threads: 1,
        // Long enough (about half a second unloaded) that the renders are still tracing
        // rays when the progress callback's first call, after 50 ms, lets the release
        // happen.
        ..small_settings(16, 16, 16384)
    };
    let reference = floor.create().render(&camera, &settings, 16 * 16 * 3);
    assert_ok(reference.0);

    const RENDERS: usize = 3;
    let doomed = floor.create();
    let started = std::sync::Barrier::new(RENDERS + 1);
    let images = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..RENDERS)
            .map(|_| {
                // The address crosses threads as a number: the threads must not borrow the
                // handle that is dropped under them.
                let (scene, started, camera, settings) =
                    (doomed.0 as usize, &started, &camera, &settings);
                scope.spawn(move || {
                    let mut image = vec![0.0f32; 16 * 16 * 3];
                    // The first progress call (while the render's workers trace) waits
                    // until every render is under way; then the scene is released.
                    let mut first = Some(started);
                    let mut released_at = None;
                    let mut on_progress = |fraction: f32| {
                        if let Some(barrier) = first.take() {
                            released_at = Some(fraction);
                            barrier.wait();
                        }
                        true
                    };
                    let status = render_with_progress(
                        scene as *const MltScene,
                        camera,
                        settings,
                        &mut image,
                        &mut on_progress,
                    );
                    (status, image, released_at)
                })
            })
            .collect();
        started.wait();
        // Every render is running: drop the only host reference under them.
        drop(doomed);
        workers
            .into_iter()
            .map(|w| w.join().expect("render thread"))
            .collect::<Vec<_>>()
    });
    for (status, image, released_at) in images {
        assert_ok(status);
        let released_at = released_at.expect("the callback was called");
        assert!(
            released_at < 0.75,
            "the release came at {released_at} of a render, not well before its end"
        );
        assert!(
            image == reference.1,
            "a render lost its scene while running"
        );
    }
}

#[test]
fn several_host_threads_render_one_scene_at_once() {
    let (scene, camera) = cornell();
    let settings = MltRenderSettings {
        seed: 42,
        threads: 1,
        ..small_settings(16, 16, 16)
    };
    let (status, expected) = scene.render(&camera, &settings, 16 * 16 * 3);
    assert_ok(status);
    let images: Vec<Vec<f32>> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..4)
            .map(|i| {
                let scene = &scene;
                s.spawn(move || {
                    let settings = MltRenderSettings {
                        threads: (i % 2) + 1,
                        ..settings
                    };
                    let (status, image) = scene.render(&camera, &settings, 16 * 16 * 3);
                    assert_ok(status);
                    // Queries on the same scene at the same time.
                    let (status, hits) = scene.intersect(&[ray(camera.eye, [0.0, 0.0, 1.0])]);
                    assert_ok(status);
                    assert_ne!(hits[0].triangle_id, MLT_INVALID_ID);
                    image
                })
            })
            .collect();
        workers.into_iter().map(|w| w.join().unwrap()).collect()
    });
    for image in images {
        assert!(
            image
                .iter()
                .zip(&expected)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "same seed and settings must give bitwise equal images"
        );
    }
}

#[test]
fn different_seeds_give_different_images() {
    let (scene, camera) = cornell();
    let a = scene.render(&camera, &small_settings(8, 8, 2), 192).1;
    let b = scene
        .render(
            &camera,
            &MltRenderSettings {
                seed: 1,
                ..small_settings(8, 8, 2)
            },
            192,
        )
        .1;
    assert_ne!(a, b);
}
