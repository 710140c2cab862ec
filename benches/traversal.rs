//! Traversal: rays per second of the ray-query backends through mlt's own query layer
//! (`mlt::accel::Accel`), next to the raw libraries, plus build time and memory.
//!
//! `cargo bench --bench traversal` measures the default backend (mlt's own BVH) and raw
//! obvhs; `cargo bench --bench traversal --features embree` adds Embree 3 through `Accel`
//! and raw Embree. It prints two tables and writes a bar chart of the ray rates, one panel
//! per scene and thread count, to `target/mlt-bench/traversal.png`. Numbers are reported,
//! never asserted.
//!
//! What is traced, on two generated scenes (`room`: ~70k triangles of furniture, shelves of
//! books, spheres, vases and overlapping clutter in a closed room; `terrain`: ~1.2M triangles,
//! a finely tessellated displaced heightfield with scattered rocks, trees and houses):
//! - camera rays, in 8×8 pixel tiles (coherent), through the scene's camera;
//! - diffuse bounces from the camera rays' hits (cosine-distributed, from just off the
//!   surface, as the integrators leave a hit);
//! - random rays, from anywhere in the scene's bounds in uniform directions.
//!
//! Each kind is asked for closest hits, and (the same origins and directions with a finite
//! tmax, a random fraction of 1.5 times the distance to the closest hit, or of the scene's
//! diagonal for a miss) for occlusion. Every backend traces the same rays, in chunks of
//! 1024 spread over a rayon pool of 1 thread and of every core. The tracers:
//! - `mlt bvh`, `mlt embree`: `Accel::intersect` / `Accel::occluded` on `mlt::accel::Ray`;
//! - `mlt bvh4`: the same with the BVH forced to its 4-wide fallback (only on CPUs where the
//!   default is wider, i.e. x86-64 with AVX2 and FMA);
//! - `raw obvhs`: obvhs 0.4 used as its examples do, with no mlt code: its own CWBVH build
//!   (the same `medium_build` preset unless `MLT_BENCH_OBVHS_BUILD` says otherwise), its
//!   `ray_traverse` / `ray_traverse_miss` and its `Triangle::intersect` on its own triangle
//!   array in leaf order;
//! - `raw embree`: `rtcIntersect1` / `rtcOccluded1` through mlt's FFI declarations on the
//!   very scene `mlt embree` built, with rays converted beforehand and no hit conversion.
//!
//! Rates are medians over runs that trace every tracer back to back (after an untimed
//! warm-up, in alternating order); the ratios (mlt's layer
//! against its raw library, and the BVH against Embree) are medians of the ratios within each
//! run. The build table gives the median `Accel::build` time and `Accel::memory_bytes` (BVH:
//! the allocations of its nodes, triangles and index arrays; Embree: what its memory monitor
//! counted, vertex and index buffers included). Both build on every core: obvhs through
//! rayon (its `parallel` feature), Embree through TBB.
//!
//! Environment:
//! - `MLT_BENCH_RAYS`: rays of each kind (default 262144).
//! - `MLT_BENCH_RUNS`: runs of every measurement; the median is reported (default 5).
//! - `MLT_BENCH_BUILDS`: builds per backend and scene for the build time (default 3).
//! - `MLT_BENCH_SCENES`: comma-separated, of `room`, `terrain` (default both).
//! - `MLT_BENCH_THREADS`: comma-separated thread counts (default 1 and every core).
//! - `MLT_BENCH_PREVIEW=1`: also writes a shaded view of each scene through its camera to
//!   `target/mlt-bench/traversal-SCENE.png`.
//! - `MLT_BENCH_TRACERS`: comma-separated, of `mlt bvh`, `mlt bvh4`, `raw obvhs`, `mlt embree`,
//!   `raw embree`, `mlt bvh embree-tree` (default all that the build and CPU have), e.g. to
//!   profile one. `mlt bvh embree-tree` is mlt's traversal over a wide tree collapsed from
//!   Embree's own binary SAH tree (`rtcBuildBVH`) instead of obvhs's: beside `mlt bvh` and
//!   `mlt embree` it separates what the tree costs from what the traversal does.
//! - `MLT_BENCH_QUALITIES`: comma-separated build qualities besides the default `high`, of
//!   `medium`, `fast` (default none): each adds the tracers `mlt bvh QUALITY` and `mlt
//!   embree QUALITY` (built at that `BuildQuality`), their build rows and a `QUALITY
//!   bvh/embree` ratio, e.g. `MLT_BENCH_QUALITIES=medium,fast` for the table of qualities.
//! - `MLT_BENCH_OBVHS_BUILD`: the obvhs build preset of `raw obvhs` (`fastest`, `very_fast`,
//!   `fast`, `medium`, `slow`, `very_slow`; default `medium`, mlt's), to see what a preset
//!   would change; `slow` and `very_slow` split triangles, which mlt's BVH does not support.
//! - `MLT_BENCH_FONT`: a TrueType font for the chart's text (default: a few usual system
//!   paths); without one the chart is written without text.
//!
//! A quick run: `MLT_BENCH_RAYS=20000 MLT_BENCH_RUNS=3 MLT_BENCH_SCENES=room cargo bench --bench traversal`.

mod common;
#[path = "../tests/common/generate.rs"]
mod generate;
mod scenes;

use common::{
    FONT_FAMILY, draw_legend, env_names, env_value, median, output_dir, plot_font_or_color_key,
    series_color,
};
use generate::{bounce_ray, bounds, random_ray};
use glam::Vec3A;
use mlt::accel::{Accel, BvhWidth, Filtering, Ray, with_bvh_width};
use mlt::sampling::Rng;
use mlt::{Backend, BuildQuality, Camera};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use rayon::prelude::*;
use scenes::{BenchScene, SCENES};
use std::error::Error;
use std::hint::black_box;
use std::io::Write;
use std::ops::Range;
use std::path::Path;
use std::time::Instant;

const DEFAULT_RAYS: usize = 1 << 18;
const DEFAULT_RUNS: usize = 5;
const DEFAULT_BUILDS: usize = 3;
/// Rays per rayon task.
const CHUNK: usize = 1024;

// ---------------------------------------------------------------------------------------
// Rays

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Camera,
    Bounce,
    Random,
}

const KINDS: [Kind; 3] = [Kind::Camera, Kind::Bounce, Kind::Random];

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Camera => "camera",
            Kind::Bounce => "bounce",
            Kind::Random => "random",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Query {
    Intersect,
    Occluded,
}

const QUERIES: [Query; 2] = [Query::Intersect, Query::Occluded];

impl Query {
    fn name(self) -> &'static str {
        match self {
            Query::Intersect => "closest",
            Query::Occluded => "occluded",
        }
    }
}

/// The rays of one kind: for closest hits, and the same with a finite tmax for occlusion.
struct KindRays {
    kind: Kind,
    intersect: Vec<Ray>,
    occluded: Vec<Ray>,
}

impl KindRays {
    fn rays(&self, query: Query) -> &[Ray] {
        match query {
            Query::Intersect => &self.intersect,
            Query::Occluded => &self.occluded,
        }
    }
}

/// Camera rays through `count` pixels of a square image, in 8×8 tiles, each jittered in
/// its pixel.
fn camera_rays(camera: &Camera, count: usize, rng: &mut Rng) -> Vec<Ray> {
    const TILE: u32 = 8;
    let side = ((count as f64).sqrt().ceil() as u32).div_ceil(TILE) * TILE;
    let model = camera.model(side, side);
    let mut rays = Vec::with_capacity(count);
    for tile_y in (0..side).step_by(TILE as usize) {
        for tile_x in (0..side).step_by(TILE as usize) {
            for y in tile_y..tile_y + TILE {
                for x in tile_x..tile_x + TILE {
                    let [jx, jy] = rng.uniform2();
                    let (origin, direction) =
                        model.generate_ray(x as f32 + jx, y as f32 + jy, [0.5; 2]);
                    rays.push(Ray::new(origin, direction, 0.0, f32::INFINITY));
                }
            }
        }
    }
    rays.truncate(count);
    rays
}

/// Every kind's rays; hits (for the bounces and the occlusion tmax) come from `accel`.
fn generate_rays(scene: &BenchScene, accel: &Accel, count: usize) -> Vec<KindRays> {
    let bounds = bounds(&scene.triangles);
    let diagonal = (bounds.1 - bounds.0).length();
    let magnitude = bounds.0.abs().max(bounds.1.abs()).max_element();
    let build_order = accel.internal_to_build_order();
    let normal = |triangle: u32| {
        let [a, b, c] = scene.triangles[build_order[triangle as usize] as usize];
        (b - a).cross(c - a).normalize()
    };
    let mut rng = Rng::new(3, 0);
    let camera = camera_rays(&scene.camera, count, &mut rng);
    let hits: Vec<(Ray, mlt::accel::Hit)> = camera
        .iter()
        .filter_map(|ray| Some((*ray, accel.intersect(ray)?)))
        .collect();
    assert!(!hits.is_empty(), "{}: no camera ray hits", scene.name);
    let bounce: Vec<Ray> = hits
        .iter()
        .cycle()
        .take(count)
        .map(|(ray, hit)| bounce_ray(ray, hit.t, normal(hit.triangle), magnitude * 2e-5, &mut rng))
        .collect();
    let random: Vec<Ray> = (0..count)
        .map(|_| random_ray(bounds, f32::INFINITY, &mut rng))
        .collect();
    [
        (Kind::Camera, camera),
        (Kind::Bounce, bounce),
        (Kind::Random, random),
    ]
    .into_iter()
    .map(|(kind, intersect)| {
        let occluded = intersect
            .iter()
            .map(|ray| {
                let reach = accel.intersect(ray).map_or(diagonal, |h| h.t);
                Ray {
                    tmax: reach * 1.5 * rng.uniform(),
                    ..*ray
                }
            })
            .collect();
        KindRays {
            kind,
            intersect,
            occluded,
        }
    })
    .collect()
}

/// A 480×360 view of the scene through its camera, shaded by the cosine between the ray and
/// the surface, to see what is traced.
fn write_preview(path: &Path, scene: &BenchScene, accel: &Accel) -> Result<(), Box<dyn Error>> {
    let (width, height) = (480, 360);
    let model = scene.camera.model(width, height);
    let build_order = accel.internal_to_build_order();
    let root = BitMapBackend::new(path, (width, height)).into_drawing_area();
    for y in 0..height {
        for x in 0..width {
            let (origin, direction) = model.generate_ray(x as f32 + 0.5, y as f32 + 0.5, [0.5; 2]);
            let color = match accel.intersect(&Ray::new(origin, direction, 0.0, f32::INFINITY)) {
                Some(hit) => {
                    let [a, b, c] = scene.triangles[build_order[hit.triangle as usize] as usize];
                    let cos = (b - a).cross(c - a).normalize().dot(direction).abs();
                    let grey = (40.0 + 200.0 * cos) as u8;
                    RGBColor(grey, grey, grey)
                }
                None => RGBColor(150, 190, 230),
            };
            root.draw_pixel((x as i32, y as i32), &color)?;
        }
    }
    root.present()?;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Tracers

/// One way of answering the queries, with the rays converted to what it takes.
trait Tracer: Sync {
    fn name(&self) -> &'static str;
    /// How many of the rays `range` of kind `kind` (an index into `KINDS`) hit (closest hit)
    /// or are blocked (occlusion).
    fn trace(&self, kind: usize, query: Query, range: Range<usize>) -> usize;
}

/// mlt's query layer.
struct MltTracer<'a> {
    name: &'static str,
    accel: &'a Accel,
    rays: &'a [KindRays],
}

impl Tracer for MltTracer<'_> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn trace(&self, kind: usize, query: Query, range: Range<usize>) -> usize {
        let rays = &self.rays[kind].rays(query)[range];
        match query {
            Query::Intersect => rays
                .iter()
                .filter(|r| self.accel.intersect(r).is_some())
                .count(),
            Query::Occluded => rays.iter().filter(|r| self.accel.occluded(r)).count(),
        }
    }
}

/// The obvhs build preset of the raw baseline: `MLT_BENCH_OBVHS_BUILD`, default `medium`
/// (mlt's). The `slow` ones split triangles (a triangle may be in several leaves), which mlt's
/// BVH does not support; raw obvhs does.
fn obvhs_build_params() -> obvhs::BvhBuildParams {
    use obvhs::BvhBuildParams as P;
    match std::env::var("MLT_BENCH_OBVHS_BUILD").as_deref() {
        Ok("fastest") => P::fastest_build(),
        Ok("very_fast") => P::very_fast_build(),
        Ok("fast") => P::fast_build(),
        Ok("medium") | Err(_) => P::medium_build(),
        Ok("slow") => P::slow_build(),
        Ok("very_slow") => P::very_slow_build(),
        Ok(other) => panic!(
            "MLT_BENCH_OBVHS_BUILD={other:?}: one of fastest, very_fast, fast, medium, slow, very_slow"
        ),
    }
}

/// obvhs on its own: its build, traversal and triangle test, on its triangles in leaf order.
struct ObvhsTracer {
    bvh: obvhs::cwbvh::CwBvh,
    triangles: Vec<obvhs::triangle::Triangle>,
    /// Per kind: closest-hit and occlusion rays.
    rays: Vec<[Vec<obvhs::ray::Ray>; 2]>,
    /// Seconds of the build (one build, from the triangles to the leaf-order array).
    build_seconds: f64,
}

impl ObvhsTracer {
    fn build(triangles: &[[Vec3A; 3]]) -> ObvhsTracer {
        let start = Instant::now();
        let triangles: Vec<obvhs::triangle::Triangle> = triangles
            .iter()
            .map(|&[v0, v1, v2]| obvhs::triangle::Triangle { v0, v1, v2 })
            .collect();
        let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &triangles,
            obvhs_build_params(),
            &mut std::time::Duration::default(),
        );
        let triangles = bvh
            .primitive_indices
            .iter()
            .map(|&i| triangles[i as usize])
            .collect();
        ObvhsTracer {
            bvh,
            triangles,
            rays: Vec::new(),
            build_seconds: start.elapsed().as_secs_f64(),
        }
    }

    fn with_rays(mut self, rays: &[KindRays]) -> ObvhsTracer {
        let convert = |rays: &[Ray]| {
            rays.iter()
                .map(|r| obvhs::ray::Ray::new(r.origin, r.direction, r.tmin, r.tmax))
                .collect()
        };
        self.rays = rays
            .iter()
            .map(|k| [convert(&k.intersect), convert(&k.occluded)])
            .collect();
        self
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.bvh.nodes.as_slice())
            + std::mem::size_of_val(self.bvh.primitive_indices.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
    }
}

impl Tracer for ObvhsTracer {
    fn name(&self) -> &'static str {
        "raw obvhs"
    }

    fn trace(&self, kind: usize, query: Query, range: Range<usize>) -> usize {
        let test = |ray: &obvhs::ray::Ray, id: usize| self.triangles[id].intersect(ray);
        match query {
            Query::Intersect => self.rays[kind][0][range]
                .iter()
                .filter(|&&ray| {
                    let mut hit = obvhs::ray::RayHit::none();
                    self.bvh.ray_traverse(ray, &mut hit, test)
                })
                .count(),
            Query::Occluded => self.rays[kind][1][range]
                .iter()
                .filter(|&&ray| !self.bvh.ray_traverse_miss(ray, test))
                .count(),
        }
    }
}

#[cfg(feature = "embree")]
mod raw_embree {
    use super::{KindRays, Query, Range, Tracer};
    use mlt::accel::embree::ffi::*;
    use mlt::accel::embree::{rtc_ray, rtc_rayhit};

    /// Embree called directly on a committed scene, with the rays converted beforehand (by
    /// the conversions `mlt embree` makes for each query).
    pub struct EmbreeTracer {
        scene: RTCScene,
        /// Per kind: closest-hit rays (ready to copy and pass) and occlusion rays.
        rays: Vec<(Vec<RTCRayHit>, Vec<RTCRay>)>,
    }

    // SAFETY: the scene is committed and only traversed, which Embree allows from any number
    // of threads; `mlt embree`'s accel owns it and outlives the tracer.
    unsafe impl Sync for EmbreeTracer {}

    impl EmbreeTracer {
        pub fn new(accel: &mlt::accel::Accel, rays: &[KindRays]) -> EmbreeTracer {
            let mlt::accel::Accel::Embree(embree) = accel else {
                panic!("not an Embree accel");
            };
            let rays = rays
                .iter()
                .map(|k| {
                    let hits = k.intersect.iter().map(rtc_rayhit).collect();
                    (hits, k.occluded.iter().map(rtc_ray).collect())
                })
                .collect();
            EmbreeTracer {
                scene: embree.raw_scene(),
                rays,
            }
        }
    }

    impl Tracer for EmbreeTracer {
        fn name(&self) -> &'static str {
            "raw embree"
        }

        fn trace(&self, kind: usize, query: Query, range: Range<usize>) -> usize {
            let mut context = RTCIntersectContext::new();
            let mut count = 0;
            match query {
                Query::Intersect => {
                    for prepared in &self.rays[kind].0[range] {
                        let mut rayhit = *prepared;
                        // SAFETY: a committed scene alive for the tracer's life; initialized,
                        // aligned locals.
                        unsafe { rtcIntersect1(self.scene, &mut context, &mut rayhit) };
                        count += (rayhit.hit.geomID != RTC_INVALID_GEOMETRY_ID) as usize;
                    }
                }
                Query::Occluded => {
                    for prepared in &self.rays[kind].1[range] {
                        let mut ray = *prepared;
                        // SAFETY: as above.
                        unsafe { rtcOccluded1(self.scene, &mut context, &mut ray) };
                        count += (ray.tfar == f32::NEG_INFINITY) as usize;
                    }
                }
            }
            count
        }
    }
}

/// Seconds to trace every ray of `kind` with `query` on `pool`, and the count of hits.
fn time_trace(
    pool: &rayon::ThreadPool,
    tracer: &dyn Tracer,
    kind: usize,
    query: Query,
    count: usize,
) -> (f64, usize) {
    let start = Instant::now();
    let hits = pool.install(|| {
        (0..count.div_ceil(CHUNK))
            .into_par_iter()
            .map(|chunk| tracer.trace(kind, query, chunk * CHUNK..((chunk + 1) * CHUNK).min(count)))
            .sum()
    });
    (start.elapsed().as_secs_f64(), black_box(hits))
}

// ---------------------------------------------------------------------------------------
// Measurement and report

/// The build qualities measured besides the default: `MLT_BENCH_QUALITIES`.
fn extra_qualities() -> Vec<BuildQuality> {
    env_names("MLT_BENCH_QUALITIES", &[])
        .iter()
        .map(|name| match name.as_str() {
            "medium" => BuildQuality::Medium,
            "fast" => BuildQuality::Fast,
            other => panic!("MLT_BENCH_QUALITIES: unknown {other:?}; one of medium, fast"),
        })
        .collect()
}

/// The tracer name of `backend` built at `quality`.
fn mlt_tracer_name(backend: Backend, quality: BuildQuality) -> &'static str {
    match (backend, quality) {
        (Backend::Bvh, BuildQuality::High) => "mlt bvh",
        (Backend::Bvh, BuildQuality::Medium) => "mlt bvh medium",
        (Backend::Bvh, BuildQuality::Fast) => "mlt bvh fast",
        (Backend::Embree, BuildQuality::High) => "mlt embree",
        (Backend::Embree, BuildQuality::Medium) => "mlt embree medium",
        (Backend::Embree, BuildQuality::Fast) => "mlt embree fast",
    }
}

/// The tracers' names, in table and chart order; those without Embree only in builds with it.
/// `MLT_BENCH_TRACERS` picks some.
fn tracer_names() -> Vec<&'static str> {
    let mut all = vec!["mlt bvh"];
    for &quality in &extra_qualities() {
        all.push(mlt_tracer_name(Backend::Bvh, quality));
    }
    if BvhWidth::best() != BvhWidth::Four {
        all.push("mlt bvh4");
    }
    all.push("raw obvhs");
    if cfg!(feature = "embree") {
        all.extend(["mlt embree", "raw embree", EMBREE_TREE]);
        for &quality in &extra_qualities() {
            all.push(mlt_tracer_name(Backend::Embree, quality));
        }
    }
    let wanted = env_names("MLT_BENCH_TRACERS", &all);
    for name in &wanted {
        assert!(
            all.contains(&name.as_str()),
            "MLT_BENCH_TRACERS: unknown {name:?}; this build has {all:?}"
        );
    }
    all.retain(|name| wanted.iter().any(|w| w == name));
    all
}

/// The BVH's traversal over a wide tree collapsed from Embree's binary SAH tree instead of
/// obvhs's (`BvhAccel::build_over_embree_tree`): with the same traversal as `mlt bvh`, the
/// difference between the two is the tree's.
const EMBREE_TREE: &str = "mlt bvh embree-tree";

/// The ratios the table reports: (label, numerator tracer, denominator tracer).
const RATIOS: &[(&str, &str, &str)] = &[
    ("embree-tree/embree", EMBREE_TREE, "mlt embree"),
    ("bvh/obvhs", "mlt bvh", "raw obvhs"),
    ("embree/raw", "mlt embree", "raw embree"),
    ("bvh/embree", "mlt bvh", "mlt embree"),
    ("bvh4/embree", "mlt bvh4", "mlt embree"),
    ("medium bvh/embree", "mlt bvh medium", "mlt embree medium"),
    ("fast bvh/embree", "mlt bvh fast", "mlt embree fast"),
];

struct RateRow {
    scene: &'static str,
    threads: usize,
    kind: Kind,
    query: Query,
    /// Hits or blocked rays, as a fraction of the rays (from the first tracer).
    hit_fraction: f64,
    /// Per tracer (in `tracer_names` order): median Mrays/s.
    mrays: Vec<f64>,
    /// Per entry of `RATIOS` available in this build: the median of the per-run ratios.
    ratios: Vec<Option<f64>>,
    /// Whether the tracers disagreed on the number of hits by more than 0.1%.
    disagreement: bool,
}

fn measure_rates(
    scene: &'static str,
    threads: usize,
    rays: &[KindRays],
    tracers: &[&dyn Tracer],
    runs: usize,
) -> Vec<RateRow> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut rows = Vec::new();
    for (kind_index, kind_rays) in rays.iter().enumerate() {
        for query in QUERIES {
            let count = kind_rays.rays(query).len();
            // seconds[tracer][run]
            let mut seconds = vec![Vec::new(); tracers.len()];
            let mut hits = vec![0; tracers.len()];
            // An untimed warm-up, then runs in alternating order, so that no tracer always
            // finds the caches as another left them.
            for run in 0..=runs {
                let mut order: Vec<usize> = (0..tracers.len()).collect();
                if run % 2 == 0 {
                    order.reverse();
                }
                for t in order {
                    let (s, h) = time_trace(&pool, tracers[t], kind_index, query, count);
                    if run > 0 {
                        seconds[t].push(s);
                    }
                    hits[t] = h;
                }
            }
            let names: Vec<&str> = tracers.iter().map(|t| t.name()).collect();
            let mrays = seconds
                .iter()
                .map(|s| count as f64 / median(&mut s.clone()) / 1e6)
                .collect();
            let ratios = RATIOS
                .iter()
                .map(|&(_, a, b)| {
                    let a = names.iter().position(|n| *n == a)?;
                    let b = names.iter().position(|n| *n == b)?;
                    // Rates' ratio is the inverse of the times'.
                    let mut per_run: Vec<f64> = seconds[b]
                        .iter()
                        .zip(&seconds[a])
                        .map(|(sb, sa)| sb / sa)
                        .collect();
                    Some(median(&mut per_run))
                })
                .collect();
            let spread = hits.iter().max().unwrap() - hits.iter().min().unwrap();
            let row = RateRow {
                scene,
                threads,
                kind: kind_rays.kind,
                query,
                hit_fraction: hits[0] as f64 / count as f64,
                mrays,
                ratios,
                disagreement: spread as f64 > 1e-3 * count as f64,
            };
            print_rate_row(&row);
            rows.push(row);
        }
    }
    rows
}

fn print_rate_header() {
    let mut header = format!(
        "{:<8} {:>7} {:<7} {:<8} {:>6}",
        "scene", "threads", "rays", "query", "hits"
    );
    for name in tracer_names() {
        header.push_str(&format!(" {name:>10}"));
    }
    for &(label, a, b) in RATIOS {
        if tracer_names().contains(&a) && tracer_names().contains(&b) {
            header.push_str(&format!(" {label:>10}"));
        }
    }
    println!("{header}");
    println!("(rates in Mrays/s; ratios of rates, medians of per-run ratios)");
}

fn print_rate_row(row: &RateRow) {
    let mut line = format!(
        "{:<8} {:>7} {:<7} {:<8} {:>5.1}%",
        row.scene,
        row.threads,
        row.kind.name(),
        row.query.name(),
        100.0 * row.hit_fraction
    );
    for m in &row.mrays {
        line.push_str(&format!(" {m:>10.2}"));
    }
    for r in row.ratios.iter().flatten() {
        line.push_str(&format!(" {r:>9.2}x"));
    }
    if row.disagreement {
        line.push_str("  (tracers disagree on the hit count by more than 0.1%)");
    }
    println!("{line}");
    let _ = std::io::stdout().flush();
}

struct BuildRow {
    scene: &'static str,
    triangles: usize,
    backend: &'static str,
    seconds: f64,
    bytes: usize,
}

/// Builds `backend` `builds` times over the scene at the default quality; returns the last
/// build and its row.
fn measure_build(scene: &BenchScene, backend: Backend, builds: usize) -> (Accel, BuildRow) {
    measure_build_at(scene, backend, BuildQuality::default(), builds)
}

/// `measure_build` at `quality`.
fn measure_build_at(
    scene: &BenchScene,
    backend: Backend,
    quality: BuildQuality,
    builds: usize,
) -> (Accel, BuildRow) {
    let name = mlt_tracer_name(backend, quality);
    measure_build_named(scene, backend, quality, builds, name)
}

/// `measure_build` with the 4-wide BVH.
fn measure_build_bvh4(scene: &BenchScene, builds: usize) -> (Accel, BuildRow) {
    with_bvh_width(BvhWidth::Four, || {
        measure_build_named(
            scene,
            Backend::Bvh,
            BuildQuality::default(),
            builds,
            "mlt bvh4",
        )
    })
}

fn measure_build_named(
    scene: &BenchScene,
    backend: Backend,
    quality: BuildQuality,
    builds: usize,
    name: &'static str,
) -> (Accel, BuildRow) {
    let mut seconds = Vec::new();
    let mut accel = None;
    for _ in 0..builds.max(1) {
        // The previous build is dropped first: the memory of one structure at a time.
        drop(accel.take());
        let start = Instant::now();
        accel = Some(
            Accel::build(backend, quality, &scene.triangles, Filtering::Unfiltered)
                .expect("the backend builds"),
        );
        seconds.push(start.elapsed().as_secs_f64());
    }
    let accel = accel.unwrap();
    let row = BuildRow {
        scene: scene.name,
        triangles: scene.triangles.len(),
        backend: name,
        seconds: median(&mut seconds),
        bytes: accel.memory_bytes(),
    };
    (accel, row)
}

fn print_build_rows(rows: &[BuildRow]) {
    println!(
        "{:<8} {:>10} {:<17} {:>9} {:>10} {:>9}",
        "scene", "triangles", "backend", "build s", "memory MB", "B/tri"
    );
    for r in rows {
        println!(
            "{:<8} {:>10} {:<17} {:>9.3} {:>10.1} {:>9.1}",
            r.scene,
            r.triangles,
            r.backend,
            r.seconds,
            r.bytes as f64 / 1e6,
            r.bytes as f64 / r.triangles as f64
        );
    }
}

/// Grouped bars: one panel per scene and thread count, a group per ray kind and query, a bar
/// per tracer. Without a font every text element is left out.
fn plot(path: &Path, rows: &[RateRow], with_text: bool) -> Result<(), Box<dyn Error>> {
    let mut panels: Vec<(&str, usize)> = Vec::new();
    for r in rows {
        if !panels.contains(&(r.scene, r.threads)) {
            panels.push((r.scene, r.threads));
        }
    }
    let scenes = panels.iter().map(|p| p.0).fold(Vec::new(), |mut v, s| {
        if !v.contains(&s) {
            v.push(s);
        }
        v
    });
    let columns = panels.len().div_ceil(scenes.len().max(1));
    let root = BitMapBackend::new(path, (560 * columns as u32, 420 * scenes.len() as u32))
        .into_drawing_area();
    root.fill(&WHITE)?;
    // Untitled, for group labels placed at pixel coordinates.
    let base = root.clone();
    let root = if with_text {
        root.titled(
            "Ray rates (Mrays/s, median): mlt's query layer and the raw libraries",
            (FONT_FAMILY, 22),
        )?
    } else {
        root
    };
    let names = tracer_names();
    let groups: Vec<(Kind, Query)> = KINDS
        .iter()
        .flat_map(|&k| QUERIES.map(|q| (k, q)))
        .collect();
    for (area, &(scene, threads)) in root
        .split_evenly((scenes.len(), columns))
        .iter()
        .zip(&panels)
    {
        let panel: Vec<&RateRow> = rows
            .iter()
            .filter(|r| r.scene == scene && r.threads == threads)
            .collect();
        let top = panel
            .iter()
            .flat_map(|r| r.mrays.iter().copied())
            .fold(0.0, f64::max)
            * 1.4; // room for the legend above the bars
        let mut builder = ChartBuilder::on(area);
        builder.margin(12);
        if with_text {
            let thread_text = if threads == 1 {
                "1 thread".into()
            } else {
                format!("{threads} threads")
            };
            builder
                .caption(format!("{scene}, {thread_text}"), (FONT_FAMILY, 18))
                .x_label_area_size(36)
                .y_label_area_size(48);
        }
        let mut chart =
            builder.build_cartesian_2d(-0.5..groups.len() as f64 - 0.5, 0.0..top.max(1e-3))?;
        let mut mesh = chart.configure_mesh();
        // The groups are labelled below, at their centres.
        mesh.disable_x_mesh()
            .x_labels(0)
            .bold_line_style(BLACK.mix(0.2))
            .light_line_style(BLACK.mix(0.05));
        if with_text {
            mesh.y_desc("Mrays/s").label_style((FONT_FAMILY, 13));
        } else {
            mesh.y_labels(0);
        }
        mesh.draw()?;
        if with_text {
            let style = TextStyle::from((FONT_FAMILY, 13).into_font())
                .pos(Pos::new(HPos::Center, VPos::Top));
            for (g, &(kind, query)) in groups.iter().enumerate() {
                let (x, y) = chart.backend_coord(&(g as f64, 0.0));
                let query = if query == Query::Intersect {
                    "hit"
                } else {
                    "occl"
                };
                base.draw(&Text::new(
                    format!("{} {query}", kind.name()),
                    (x, y + 6),
                    style.clone(),
                ))?;
            }
        }
        let width = 0.8 / names.len() as f64;
        for (t, name) in names.iter().enumerate() {
            let color = series_color(t);
            let bars = groups.iter().enumerate().filter_map(|(g, &(kind, query))| {
                let row = panel.iter().find(|r| r.kind == kind && r.query == query)?;
                let x0 = g as f64 - 0.4 + t as f64 * width;
                Some(Rectangle::new(
                    [(x0, 0.0), (x0 + width * 0.92, row.mrays[t])],
                    color.filled(),
                ))
            });
            let series = chart.draw_series(bars)?;
            if with_text {
                series.label(*name).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 14, y + 5)], color.filled())
                });
            }
        }
        if with_text {
            draw_legend(&mut chart)?;
        }
    }
    root.present()?;
    Ok(())
}

fn main() {
    let ray_count: usize = env_value("MLT_BENCH_RAYS", DEFAULT_RAYS);
    let runs: usize = env_value("MLT_BENCH_RUNS", DEFAULT_RUNS).max(1);
    let builds: usize = env_value("MLT_BENCH_BUILDS", DEFAULT_BUILDS);
    let scene_names = env_names("MLT_BENCH_SCENES", SCENES);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let default_threads = if cores > 1 { vec![1, cores] } else { vec![1] };
    let thread_counts: Vec<usize> = match std::env::var("MLT_BENCH_THREADS") {
        Ok(list) => list
            .split(',')
            .map(|n| n.trim().parse().expect("MLT_BENCH_THREADS: thread counts"))
            .collect(),
        Err(_) => default_threads,
    };
    println!(
        "traversal: {ray_count} rays of each kind, median of {runs} runs, {builds} builds, threads {thread_counts:?}; tracers {:?}",
        tracer_names()
    );

    let mut build_rows = Vec::new();
    let mut rate_rows = Vec::new();
    for name in &scene_names {
        let scene = scenes::by_name(name).unwrap_or_else(|| {
            panic!("MLT_BENCH_SCENES: unknown scene {name:?}; known: {SCENES:?}")
        });
        println!("\n{}: {} triangles", scene.name, scene.triangles.len());
        let (bvh, row) = measure_build(&scene, Backend::Bvh, builds);
        build_rows.push(row);
        let rays = generate_rays(&scene, &bvh, ray_count);
        if env_value("MLT_BENCH_PREVIEW", 0) != 0 {
            let path = output_dir().join(format!("traversal-{}.png", scene.name));
            std::fs::create_dir_all(output_dir()).expect("output directory");
            match write_preview(&path, &scene, &bvh) {
                Ok(()) => println!("preview: {}", path.display()),
                Err(e) => println!("preview failed: {e}"),
            }
        }
        let obvhs = ObvhsTracer::build(&scene.triangles).with_rays(&rays);
        build_rows.push(BuildRow {
            backend: "raw obvhs",
            seconds: obvhs.build_seconds,
            bytes: obvhs.memory_bytes(),
            ..*build_rows.last().unwrap()
        });
        let bvh4 = tracer_names().contains(&"mlt bvh4").then(|| {
            let (bvh4, row) = measure_build_bvh4(&scene, builds);
            build_rows.push(row);
            bvh4
        });
        #[cfg(feature = "embree")]
        let (embree, row) = measure_build(&scene, Backend::Embree, builds);
        #[cfg(feature = "embree")]
        build_rows.push(row);
        // The other qualities' structures, named as their tracers.
        let mut at_qualities = Vec::new();
        for &quality in &extra_qualities() {
            let backends = [Backend::Bvh, Backend::Embree];
            for backend in backends.into_iter().filter(|b| b.is_available()) {
                let (accel, row) = measure_build_at(&scene, backend, quality, builds);
                build_rows.push(row);
                at_qualities.push((mlt_tracer_name(backend, quality), accel));
            }
        }
        #[cfg(feature = "embree")]
        let embree_tree = tracer_names().contains(&EMBREE_TREE).then(|| {
            let start = Instant::now();
            let accel = Accel::Bvh(
                mlt::accel::BvhAccel::build_over_embree_tree(&scene.triangles)
                    .expect("the BVH builds over Embree's tree"),
            );
            build_rows.push(BuildRow {
                scene: scene.name,
                triangles: scene.triangles.len(),
                backend: EMBREE_TREE,
                seconds: start.elapsed().as_secs_f64(),
                bytes: accel.memory_bytes(),
            });
            accel
        });
        let mut tracers: Vec<Box<dyn Tracer + '_>> = vec![
            Box::new(MltTracer {
                name: "mlt bvh",
                accel: &bvh,
                rays: &rays,
            }),
            Box::new(obvhs),
        ];
        if let Some(bvh4) = &bvh4 {
            tracers.insert(
                1,
                Box::new(MltTracer {
                    name: "mlt bvh4",
                    accel: bvh4,
                    rays: &rays,
                }),
            );
        }
        #[cfg(feature = "embree")]
        {
            if let Some(accel) = &embree_tree {
                tracers.push(Box::new(MltTracer {
                    name: EMBREE_TREE,
                    accel,
                    rays: &rays,
                }));
            }
            tracers.push(Box::new(MltTracer {
                name: "mlt embree",
                accel: &embree,
                rays: &rays,
            }));
            tracers.push(Box::new(raw_embree::EmbreeTracer::new(&embree, &rays)));
        }
        for (name, accel) in &at_qualities {
            tracers.push(Box::new(MltTracer {
                name,
                accel,
                rays: &rays,
            }));
        }
        let names = tracer_names();
        // In `tracer_names` order, the table's and the chart's.
        let tracer_refs: Vec<&dyn Tracer> = names
            .iter()
            .filter_map(|name| tracers.iter().find(|t| t.name() == *name))
            .map(|t| t.as_ref())
            .collect();
        print_rate_header();
        for &threads in &thread_counts {
            rate_rows.extend(measure_rates(
                scene.name,
                threads,
                &rays,
                &tracer_refs,
                runs,
            ));
        }
    }
    println!("\nbuild (median of {builds}; raw obvhs: one build):");
    print_build_rows(&build_rows);

    let dir = output_dir();
    std::fs::create_dir_all(&dir).expect("output directory");
    let with_text = plot_font_or_color_key(tracer_names());
    let chart_path = dir.join("traversal.png");
    match plot(&chart_path, &rate_rows, with_text) {
        Ok(()) => println!("chart: {}", chart_path.display()),
        Err(e) => println!("chart failed: {e}"),
    }
}
