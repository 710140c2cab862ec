//! Overhead outside traversal: for every algorithm on the traversal bench's scenes, the rays
//! per second a render traces against the rate at which the acceleration structure alone
//! answers the very same rays, and so the share of the render's time spent outside
//! traversal (shading, sampling, light sampling, splatting, Metropolis bookkeeping).
//!
//! `cargo bench --bench overhead` (add `--features embree` and `MLT_BENCH_BACKEND=embree`
//! to measure renders on Embree). Numbers are reported, never asserted; the replay's answers
//! are asserted to be the render's.
//!
//! The method, per scene and algorithm, on 1 thread with a fixed seed:
//! 1. A recording render: `Scene::record_queries` makes the scene log every ray query the
//!    render makes (closest hit or occlusion, in order) with the answer it got. Recording
//!    slows the queries down, so this render is not timed.
//! 2. Timed renders: the same settings on the same scene with the recording off (a normal
//!    render: queries take the unchanged path, which tests one flag per query as before
//!    recordings existed). The median of `MLT_BENCH_RUNS` render times.
//! 3. Timed replays: the recorded rays through `Scene::accel()`'s `intersect` / `occluded` in
//!    a tight loop, in the render's order: the level every render query reaches in a scene
//!    without alpha cut-outs (`Scene::closest_hit` / `Scene::blocked` add nothing else), so
//!    the replay is pure traversal. The median of `MLT_BENCH_RUNS` replays. An untimed pass
//!    first checks that every replayed answer equals the recorded one (hit triangle,
//!    distance and barycentrics; occluded or not), and that the timed render traced as many
//!    rays as the recording (`RenderStats::rays`).
//!
//! The table's `outside` column is 1 − replay time / render time: the share of the render
//! spent outside traversal. It slightly overstates that share: the replay runs with the
//! structure's nodes hot in the caches, while in a render shading evicts some of them
//! between queries, so part of the render's traversal time is cache misses the replay does
//! not pay.
//!
//! The scenes are the traversal bench's triangles (`benches/scenes/mod.rs`) with materials
//! and lights so that every algorithm has work: a grey diffuse material with one block of
//! 512 triangles in eight glossy (a rough gold metal, roughness 0.3); the closed room is lit
//! by a 1.2 × 0.8 m panel under its ceiling, the terrain by a sun (0.27° radius) and a
//! constant blue sky.
//!
//! Environment:
//! - `MLT_BENCH_SCENES`: comma-separated, of `room`, `terrain` (default both).
//! - `MLT_BENCH_ALGORITHMS`: comma-separated, of `path`, `path-spectral`, `bdpt`, `pssmlt`,
//!   `mmlt`, `pssmlt-bdpt`, `path-space-mlt`, `erpt` (default all).
//! - `MLT_BENCH_WIDTH`, `MLT_BENCH_HEIGHT`: the image (default 160 × 120).
//! - `MLT_BENCH_SPP`: samples per pixel of the path tracer (default 32).
//! - `MLT_BENCH_BDPT_SPP`: samples per pixel of BDPT and ERPT (default 4).
//! - `MLT_BENCH_MUTATIONS`: mutations per pixel of the Metropolis algorithms (default 8;
//!   their bootstrap is the default, at least 65536 samples).
//! - `MLT_BENCH_DEPTH`: the maximum path depth (default 5).
//! - `MLT_BENCH_RUNS`: timed renders and replays per row; the medians are reported
//!   (default 3).
//! - `MLT_BENCH_BACKEND`: `bvh` (default) or `embree`.
//! - `MLT_BENCH_RENDER_ONLY=1`: only the timed renders (no recording, no replay), to profile
//!   them, e.g. `MLT_BENCH_RENDER_ONLY=1 MLT_BENCH_SCENES=room MLT_BENCH_ALGORITHMS=bdpt perf
//!   record -e cpu-clock -F 2000 target/release/deps/overhead-HASH --bench`.

mod common;
#[path = "../tests/common/generate.rs"]
mod generate;
mod scenes;

use common::{env_names, env_value, median};
use glam::Vec3A;
use mlt::accel::Accel;
use mlt::scene::RecordedQuery;
use mlt::{
    Algorithm, Backend, Camera, EnvironmentDesc, LightsDesc, Material, RenderSettings, Scene,
    SceneDesc, SunDesc, render,
};
use std::hint::black_box;
use std::time::Instant;

/// The rows: name, algorithm and whether the render is spectral.
const ALGORITHMS: &[(&str, Algorithm, bool)] = &[
    ("path", Algorithm::Path, false),
    ("path-spectral", Algorithm::Path, true),
    ("bdpt", Algorithm::Bdpt, false),
    ("pssmlt", Algorithm::Pssmlt, false),
    ("mmlt", Algorithm::Mmlt, false),
    ("pssmlt-bdpt", Algorithm::PssmltBdpt, false),
    ("path-space-mlt", Algorithm::PathSpaceMlt, false),
    ("erpt", Algorithm::Erpt, false),
];

/// Triangles per block of the material assignment; every `GLOSSY_EVERY`th block is glossy.
const BLOCK: usize = 512;
const GLOSSY_EVERY: usize = 8;

const SKY: [f32; 3] = [0.35, 0.5, 0.8];

/// The bench scene `name` as an `mlt::Scene` with materials and lights, and its camera.
fn build_scene(name: &str, backend: Backend) -> (Scene, Camera) {
    let bench = scenes::by_name(name).unwrap_or_else(|| {
        panic!(
            "MLT_BENCH_SCENES: unknown {name:?}; known: {:?}",
            scenes::SCENES
        )
    });
    let mut triangles = bench.triangles;
    let mut material_ids: Vec<u32> = (0..triangles.len())
        .map(|i| u32::from((i / BLOCK) % GLOSSY_EVERY == 1))
        .collect();
    let mut materials = vec![
        Material::diffuse([0.6, 0.6, 0.6]),
        Material::metallic_roughness([0.9, 0.7, 0.35], 1.0, 0.3),
    ];
    let mut lights = LightsDesc::default();
    let sun;
    if bench.name == "room" {
        // A panel just under the ceiling (y = 3), facing down.
        let (y, a, b) = (2.98, 0.6, 0.4);
        let corner = |x: f32, z: f32| Vec3A::new(x, y, z);
        triangles.push([corner(-a, -b), corner(a, -b), corner(a, b)]);
        triangles.push([corner(-a, -b), corner(a, b), corner(-a, b)]);
        materials.push(Material::diffuse([0.0; 3]).with_emission([30.0, 28.0, 24.0]));
        material_ids.extend([2, 2]);
    } else {
        sun = SunDesc {
            direction: [0.4, 0.8, 0.3],
            angular_radius_degrees: 0.27,
            irradiance: [3.0, 2.9, 2.6],
        };
        lights.sun = Some(sun);
        lights.environment = Some(EnvironmentDesc::constant(&SKY));
    }
    let positions: Vec<f32> = triangles
        .iter()
        .flat_map(|t| t.iter().flat_map(|v| v.to_array()))
        .collect();
    let indices: Vec<u32> = (0..positions.len() as u32 / 3).collect();
    let scene = Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &material_ids,
        materials: &materials,
        lights,
        backend,
        ..Default::default()
    })
    .expect("scene builds");
    assert!(
        !scene.has_cutouts(),
        "the replay is unfiltered: no alpha cut-outs"
    );
    (scene, bench.camera)
}

/// What a replay of `queries` answered: closest-hit queries that hit, occlusion queries
/// that were occluded.
#[derive(Debug, PartialEq, Eq)]
struct Answers {
    hits: u64,
    occluded: u64,
}

/// The answers the render got.
fn recorded_answers(queries: &[RecordedQuery]) -> Answers {
    let mut answers = Answers {
        hits: 0,
        occluded: 0,
    };
    for query in queries {
        match query {
            RecordedQuery::ClosestHit { hit, .. } => answers.hits += u64::from(hit.is_some()),
            RecordedQuery::Occluded { occluded, .. } => answers.occluded += u64::from(*occluded),
        }
    }
    answers
}

/// The timed replay: every query through the structure, in order.
#[inline(never)]
fn replay(accel: &Accel, queries: &[RecordedQuery]) -> Answers {
    let mut answers = Answers {
        hits: 0,
        occluded: 0,
    };
    for query in queries {
        match query {
            RecordedQuery::ClosestHit { ray, .. } => {
                answers.hits += u64::from(accel.intersect(ray).is_some())
            }
            RecordedQuery::Occluded { ray, .. } => {
                answers.occluded += u64::from(accel.occluded(ray))
            }
        }
    }
    answers
}

/// Queries whose replayed answer differs from the recorded one.
fn mismatches(accel: &Accel, queries: &[RecordedQuery]) -> usize {
    queries
        .iter()
        .filter(|query| match query {
            RecordedQuery::ClosestHit { ray, hit } => accel.intersect(ray) != *hit,
            RecordedQuery::Occluded { ray, occluded } => accel.occluded(ray) != *occluded,
        })
        .count()
}

fn main() {
    let scene_names = env_names("MLT_BENCH_SCENES", scenes::SCENES);
    let all: Vec<&str> = ALGORITHMS.iter().map(|a| a.0).collect();
    let rows: Vec<(&str, Algorithm, bool)> = env_names("MLT_BENCH_ALGORITHMS", &all)
        .iter()
        .map(|wanted| {
            *ALGORITHMS
                .iter()
                .find(|a| a.0 == wanted)
                .unwrap_or_else(|| {
                    panic!("MLT_BENCH_ALGORITHMS: unknown {wanted:?}; known: {all:?}")
                })
        })
        .collect();
    let width: u32 = env_value("MLT_BENCH_WIDTH", 160);
    let height: u32 = env_value("MLT_BENCH_HEIGHT", 120);
    let path_spp: u32 = env_value("MLT_BENCH_SPP", 32);
    let bdpt_spp: u32 = env_value("MLT_BENCH_BDPT_SPP", 4);
    let mutations: u32 = env_value("MLT_BENCH_MUTATIONS", 8);
    let max_depth: u32 = env_value("MLT_BENCH_DEPTH", 5);
    let runs: usize = env_value("MLT_BENCH_RUNS", 3usize).max(1);
    let render_only = env_value("MLT_BENCH_RENDER_ONLY", 0u32) != 0;
    let backend = match std::env::var("MLT_BENCH_BACKEND").as_deref() {
        Err(_) | Ok("bvh") => Backend::Bvh,
        Ok("embree") => Backend::Embree,
        Ok(other) => panic!("MLT_BENCH_BACKEND: unknown {other:?}; known: bvh, embree"),
    };
    println!(
        "overhead outside traversal: {width}x{height}, {path_spp} spp (path), {bdpt_spp} spp (bdpt, erpt), {mutations} mutations per pixel (Metropolis), max depth {max_depth}, 1 thread, {backend:?}, median of {runs} runs"
    );
    println!(
        "{:<8} {:<15} {:>10} {:>9} {:>10} {:>11} {:>11} {:>11} {:>8}",
        "scene",
        "algorithm",
        "rays",
        "occlusion",
        "render s",
        "render Mr/s",
        "replay s",
        "replay Mr/s",
        "outside"
    );
    for scene_name in &scene_names {
        let (mut scene, camera) = build_scene(scene_name, backend);
        for &(name, algorithm, spectral) in &rows {
            let settings = RenderSettings {
                width,
                height,
                algorithm,
                samples_per_pixel: if algorithm == Algorithm::Path {
                    path_spp
                } else {
                    bdpt_spp
                },
                mutations_per_pixel: mutations,
                max_depth,
                seed: 7,
                threads: 1,
                spectral,
                ..Default::default()
            };
            let mut image = vec![0.0f32; (width * height * 3) as usize];
            if render_only {
                for _ in 0..runs {
                    let start = Instant::now();
                    let stats =
                        render(&scene, &camera, &settings, &mut image, None).expect("render");
                    let seconds = start.elapsed().as_secs_f64();
                    println!(
                        "{scene_name:<8} {name:<15} {:>10} {:>9} {seconds:>10.3} {:>11.2}",
                        stats.rays,
                        "-",
                        stats.rays as f64 / seconds / 1e6
                    );
                }
                continue;
            }
            scene.record_queries();
            render(&scene, &camera, &settings, &mut image, None).expect("render");
            let queries = scene.take_recorded_queries();
            let recorded = recorded_answers(&queries);
            let occlusion = queries
                .iter()
                .filter(|q| matches!(q, RecordedQuery::Occluded { .. }))
                .count();
            let wrong = mismatches(scene.accel(), &queries);
            assert_eq!(
                wrong,
                0,
                "{scene_name} {name}: {wrong} of {} replayed answers differ from the render's",
                queries.len()
            );
            let mut render_seconds = Vec::new();
            for _ in 0..runs {
                let start = Instant::now();
                let stats = render(&scene, &camera, &settings, &mut image, None).expect("render");
                render_seconds.push(start.elapsed().as_secs_f64());
                assert_eq!(
                    stats.rays,
                    queries.len() as u64,
                    "{scene_name} {name}: the timed render traced other rays than the recording"
                );
            }
            let mut replay_seconds = Vec::new();
            for _ in 0..runs {
                let start = Instant::now();
                let answers = replay(black_box(scene.accel()), black_box(&queries));
                replay_seconds.push(start.elapsed().as_secs_f64());
                assert_eq!(answers, recorded, "{scene_name} {name}: replay answers");
            }
            let render_s = median(&mut render_seconds);
            let replay_s = median(&mut replay_seconds);
            let rays = queries.len() as f64;
            println!(
                "{scene_name:<8} {name:<15} {:>10} {:>8.1}% {render_s:>10.3} {:>11.2} {replay_s:>11.3} {:>11.2} {:>7.1}%",
                queries.len(),
                100.0 * occlusion as f64 / rays,
                rays / render_s / 1e6,
                rays / replay_s / 1e6,
                100.0 * (1.0 - replay_s / render_s)
            );
        }
    }
}
