//! The overhead bench's ray recording (`Scene::record_queries`, hidden API), which
//! `benches/overhead.rs` relies on to replay a render's very rays.
//!
//! Runs in under a second on 2 cores (`cargo test --test ray_recording`).

mod common {
    pub mod scenes;
}

use common::scenes::load_canonical;

use mlt::scene::RecordedQuery;

/// The overhead bench's ray recording (`Scene::record_queries`): it records every query a
/// render makes, in order, with the answer the render got, and leaves the render unchanged.
#[test]
fn recorded_queries_are_the_renders() {
    let (mut scene, camera) = load_canonical("cornell-glass");
    let settings = mlt::RenderSettings {
        width: 32,
        height: 32,
        algorithm: mlt::Algorithm::Bdpt,
        samples_per_pixel: 2,
        max_depth: 5,
        threads: 1,
        seed: 3,
        ..Default::default()
    };
    let mut plain = vec![0.0f32; 32 * 32 * 3];
    let stats = mlt::render(&scene, &camera, &settings, &mut plain, None).expect("render");
    assert!(
        scene.take_recorded_queries().is_empty(),
        "no recording was on"
    );
    scene.record_queries();
    let mut recorded_image = vec![0.0f32; 32 * 32 * 3];
    mlt::render(&scene, &camera, &settings, &mut recorded_image, None).expect("render");
    let queries = scene.take_recorded_queries();
    assert_eq!(recorded_image, plain, "recording changed the render");
    assert_eq!(
        queries.len() as u64,
        stats.rays,
        "every ray the render traced"
    );
    let occlusion = queries
        .iter()
        .filter(|q| matches!(q, RecordedQuery::Occluded { .. }))
        .count();
    assert!(
        occlusion > 0 && occlusion < queries.len(),
        "both kinds: {occlusion}"
    );
    for query in &queries {
        match query {
            RecordedQuery::ClosestHit { ray, hit } => {
                assert_eq!(scene.accel().intersect(ray), *hit)
            }
            RecordedQuery::Occluded { ray, occluded } => {
                assert_eq!(scene.accel().occluded(ray), *occluded)
            }
        }
    }
    // Taking the recording stops it.
    mlt::render(&scene, &camera, &settings, &mut recorded_image, None).expect("render");
    assert!(scene.take_recorded_queries().is_empty());
}
