//! The BVH and Embree backends answer the same queries the same way; the BVH at each width
//! this CPU supports (the 8-wide AVX2 tree and the 4-wide fallback) and at each build quality.
//!
//! Scenes: cornell-box, cornell-glass and a generated mesh of ~130k triangles (a displaced
//! sphere and two wavy sheets that cut through it and each other, in a box). Rays, 100k of
//! each kind: camera rays, diffuse bounces (cosine-distributed from the camera rays' hits),
//! random rays (origins anywhere in the bounds, uniform directions), and rays aimed at random
//! points on triangle edges. Every ray is asked for its closest hit and, with a random tmax
//! around that hit, for occlusion, through a scene built with each backend. Closest hits
//! must name the same host triangle, with t within 1e-4 relative and the barycentrics' points
//! as close (plus a few ulps of the scene's magnitude, which dominate for hits right at the
//! origin).
//!
//! A disagreement is explained only by an f64 brute-force intersection with every triangle
//! that shows a rounding-sensitive configuration: a hit point within a tiny distance of a
//! triangle's edge, a grazing ray, two triangles at the same t (within 1e-4 relative), or a
//! hit at the end of the occlusion interval. Unexplained disagreements must be zero; the
//! explained ones at most 1e-5 of the queries (edge-aimed rays excepted: they are built to
//! disagree, to exercise the explanations). A render of cornell-box through both backends
//! must agree within its statistical error.
//!
//! Built only with the `embree` feature: CI's Embree step runs it (`.ci/run`), in about 40 s
//! on 2 cores (with that step's debug assertions).
#![cfg(feature = "embree")]

mod common {
    pub mod generate;
    pub mod obj_text;
    pub mod references;
    pub mod scenes;
    pub mod stats;
    pub mod window_room;
}

use common::generate::{MeshBuilder, bounce_ray, point_in_bounds, random_ray};
use common::references::{path_traced_estimate, render_image};
use common::scenes::{Mesh, canonical_camera, canonical_mesh, cornell_box, cornell_camera};
use common::stats::{Estimate, assert_estimates_agree};
use common::window_room;

use glam::{DVec3, Vec3A};
use mlt::accel::{BvhWidth, Hit, Ray, with_bvh_width};
use mlt::sampling::Rng;
use mlt::{Backend, BuildQuality, Camera, Material, Scene};

const RAYS_PER_KIND: usize = 100_000;
/// Relative agreement of t between backends, and the closeness of two t that makes a tie.
const T_TOLERANCE: f64 = 1e-4;
/// Explained disagreements allowed, per query.
const MAX_DISAGREEMENT_RATE: f64 = 1e-5;
/// A hit point this close to an edge (relative to the scene's magnitude, and divided by the
/// cosine of the incidence angle) lies within the rounding error of f32 intersection.
const EDGE_TOLERANCE: f64 = 1e-6;
/// A ray this close to parallel to a triangle (|cos| of the angle to its normal) grazes it.
const GRAZING_COS: f64 = 1e-4;

/// A triangle scene built with both backends, plus the host's triangles in f64.
struct Pair {
    name: &'static str,
    /// The default BVH: as wide as the CPU supports, at the default build quality.
    bvh: Scene,
    /// The other BVHs, named: the 4-wide fallback (when the default is wider) and the
    /// faster build qualities.
    variants: Vec<(&'static str, Scene)>,
    embree: Scene,
    camera: Camera,
    triangles: Vec<[DVec3; 3]>,
    bounds: (Vec3A, Vec3A),
    /// Largest coordinate magnitude: the scale of f32 rounding.
    magnitude: f64,
}

impl Pair {
    fn new(name: &'static str, mesh: &Mesh, camera: Camera) -> Pair {
        let bvh = mesh.scene_with(Backend::Bvh);
        let mut variants = Vec::new();
        if BvhWidth::best() != BvhWidth::Four {
            let bvh4 = with_bvh_width(BvhWidth::Four, || mesh.scene_with(Backend::Bvh));
            variants.push(("4-wide", bvh4));
        }
        for (name, quality) in [
            ("medium build", BuildQuality::Medium),
            ("fast build", BuildQuality::Fast),
        ] {
            variants.push((name, mesh.scene_built(Backend::Bvh, quality)));
        }
        let embree = mesh.scene_with(Backend::Embree);
        let info = bvh.info();
        let embree_info = embree.info();
        assert_eq!(
            (info.triangle_count, info.degenerate_triangle_count),
            (
                embree_info.triangle_count,
                embree_info.degenerate_triangle_count
            )
        );
        assert_eq!(info.emitter_count, embree_info.emitter_count);
        assert_eq!(
            (info.bounds_min, info.bounds_max),
            (embree_info.bounds_min, embree_info.bounds_max)
        );
        let vertex = |i: u32| {
            let p = &mesh.positions[3 * i as usize..][..3];
            DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
        };
        let triangles = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [vertex(t[0]), vertex(t[1]), vertex(t[2])])
            .collect();
        let bounds = (Vec3A::from(info.bounds_min), Vec3A::from(info.bounds_max));
        let magnitude = bounds.0.abs().max(bounds.1.abs()).max_element() as f64;
        Pair {
            name,
            bvh,
            variants,
            embree,
            camera,
            triangles,
            bounds,
            magnitude,
        }
    }

    fn normal(&self, triangle: u32) -> Vec3A {
        let [a, b, c] = self.triangles[triangle as usize];
        (b - a).cross(c - a).normalize().as_vec3a()
    }

    /// f32 rounding of positions: a few ulps of the largest coordinate.
    fn rounding(&self) -> f64 {
        16.0 * f32::EPSILON as f64 * self.magnitude
    }

    /// Agreement of two closest hits: the same triangle, t within 1e-4 relative, and the
    /// points the barycentrics name as close (both up to the rounding of coordinates, which
    /// dominates for hits very near the origin or on small triangles).
    fn hits_agree(&self, a: Option<Hit>, b: Option<Hit>) -> bool {
        match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => {
                let tolerance = T_TOLERANCE * a.t.max(b.t) as f64 + self.rounding();
                a.triangle == b.triangle
                    && (a.t as f64 - b.t as f64).abs() <= tolerance
                    && self.barycentric_distance(a.triangle, [a.u, a.v], [b.u, b.v]) <= tolerance
            }
            _ => false,
        }
    }

    /// Distance between the points of a triangle with barycentrics `p` and `q` (of v1, v2).
    fn barycentric_distance(&self, triangle: u32, p: [f32; 2], q: [f32; 2]) -> f64 {
        let [v0, v1, v2] = self.triangles[triangle as usize];
        let (du, dv) = ((p[0] - q[0]) as f64, (p[1] - q[1]) as f64);
        ((v1 - v0) * du + (v2 - v0) * dv).length()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Camera,
    Bounce,
    Random,
    /// Aimed at random points on triangle edges: mostly ties of the two triangles sharing the
    /// edge, so they disagree often and exercise the explanations; not counted in the rate.
    Edge,
}

/// Camera rays through random film positions.
fn camera_rays(pair: &Pair, rng: &mut Rng) -> impl Iterator<Item = Ray> {
    let model = pair.camera.model(512, 512);
    std::iter::repeat_with(move || {
        let (origin, direction) =
            model.generate_ray(rng.uniform() * 512.0, rng.uniform() * 512.0, [0.5; 2]);
        Ray::new(origin, direction, 0.0, f32::INFINITY)
    })
}

fn rays(pair: &Pair, kind: Kind, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, kind as u64);
    match kind {
        Kind::Camera => camera_rays(pair, &mut rng).take(RAYS_PER_KIND).collect(),
        Kind::Bounce => {
            // Leave each hit as the integrators do: off the surface on the side the ray came
            // from, in a cosine-distributed direction.
            let epsilon = pair.magnitude as f32 * 2e-5;
            let mut directions = Rng::new(seed, 100);
            camera_rays(pair, &mut rng)
                .filter_map(|ray| {
                    let hit = pair.bvh.intersect(&ray)?;
                    let normal = pair.normal(hit.triangle);
                    Some(bounce_ray(&ray, hit.t, normal, epsilon, &mut directions))
                })
                .take(RAYS_PER_KIND)
                .collect()
        }
        Kind::Random => (0..RAYS_PER_KIND)
            .map(|_| random_ray(pair.bounds, f32::INFINITY, &mut rng))
            .collect(),
        Kind::Edge => std::iter::repeat_with(|| {
            let triangle = (rng.next_u32() as usize) % pair.triangles.len();
            let vertices = pair.triangles[triangle].map(|v| v.as_vec3a());
            let edge = (rng.next_u32() % 3) as usize;
            let (from, to) = (vertices[edge], vertices[(edge + 1) % 3]);
            let target = from + (to - from) * rng.uniform();
            let origin = point_in_bounds(pair.bounds, &mut rng);
            let direction = (target - origin).normalize();
            direction
                .is_finite()
                .then(|| Ray::new(origin, direction, 0.0, f32::INFINITY))
        })
        .flatten()
        .take(RAYS_PER_KIND)
        .collect(),
    }
}

/// Where a ray meets a triangle's plane, in f64.
#[derive(Clone, Copy, Debug)]
struct PlaneHit {
    triangle: u32,
    t: f64,
    /// Distance of the plane point from the triangle's boundary: positive inside, negative
    /// outside (the largest violation of one edge).
    edge_distance: f64,
    /// |cos| of the angle between the ray and the triangle's normal.
    cos: f64,
}

fn plane_hit(
    triangle: u32,
    [a, b, c]: [DVec3; 3],
    origin: DVec3,
    direction: DVec3,
) -> Option<PlaneHit> {
    let cross = (b - a).cross(c - a);
    let double_area = cross.length();
    if double_area == 0.0 {
        return None; // degenerate: never hit
    }
    let normal = cross / double_area;
    let cos = normal.dot(direction);
    if cos == 0.0 {
        return None;
    }
    let t = normal.dot(a - origin) / cos;
    let p = origin + direction * t;
    // Signed distances from the edges opposite each vertex, in the plane.
    let distance =
        |from: DVec3, to: DVec3| (to - from).cross(p - from).dot(normal) / (to - from).length();
    let d = [distance(b, c), distance(c, a), distance(a, b)];
    let inside = d.iter().all(|&x| x >= 0.0);
    let edge_distance = if inside {
        d.into_iter().fold(f64::INFINITY, f64::min)
    } else {
        d.into_iter().filter(|&x| x < 0.0).fold(0.0, f64::min)
    };
    Some(PlaneHit {
        triangle,
        t,
        edge_distance,
        cos: cos.abs(),
    })
}

/// A reason a ray is rounding-sensitive, from f64 intersections with every triangle.
struct Judge<'a> {
    pair: &'a Pair,
}

impl Judge<'_> {
    fn edge_tolerance(&self, hit: &PlaneHit) -> f64 {
        EDGE_TOLERANCE * self.pair.magnitude / hit.cos
    }

    /// Triangles the ray hits in f64 or misses by less than the edge tolerance, t >= tmin
    /// (less the tolerance), sorted by t.
    fn candidates(&self, ray: &Ray) -> Vec<PlaneHit> {
        let origin = ray.origin.as_dvec3();
        let direction = ray.direction.as_dvec3();
        let mut hits: Vec<PlaneHit> = self
            .pair
            .triangles
            .iter()
            .enumerate()
            .filter_map(|(i, &tri)| plane_hit(i as u32, tri, origin, direction))
            .filter(|h| {
                h.edge_distance >= -self.edge_tolerance(h)
                    && h.t >= ray.tmin as f64 - T_TOLERANCE * h.t.abs()
            })
            .collect();
        hits.sort_by(|a, b| a.t.total_cmp(&b.t));
        hits
    }

    /// Why the hits up to `t_limit` are rounding-sensitive, if they are.
    fn sensitive(&self, hits: &[PlaneHit], t_limit: f64) -> Option<String> {
        let relevant: Vec<&PlaneHit> = hits
            .iter()
            .filter(|h| h.t <= t_limit * (1.0 + T_TOLERANCE))
            .collect();
        for h in &relevant {
            if h.cos < GRAZING_COS {
                return Some(format!(
                    "grazing triangle {} (cos {:.1e})",
                    h.triangle, h.cos
                ));
            }
            if h.edge_distance.abs() <= self.edge_tolerance(h) {
                return Some(format!(
                    "edge of triangle {} (distance {:.1e} of magnitude {})",
                    h.triangle, h.edge_distance, self.pair.magnitude
                ));
            }
        }
        for w in relevant.windows(2) {
            if (w[1].t - w[0].t) <= T_TOLERANCE * w[1].t.abs() {
                return Some(format!(
                    "tie of triangles {} and {} at t {}",
                    w[0].triangle, w[1].triangle, w[0].t
                ));
            }
        }
        None
    }

    /// Closest-hit disagreement: sensitive up to the farthest reported hit.
    fn intersect(&self, ray: &Ray, a: Option<Hit>, b: Option<Hit>) -> Option<String> {
        let t_limit = [a, b]
            .iter()
            .flatten()
            .map(|h| h.t as f64)
            .fold(0.0, f64::max);
        self.sensitive(&self.candidates(ray), t_limit)
    }

    /// Occlusion disagreement: a sensitive hit in the interval, or one at its end.
    fn occluded(&self, ray: &Ray) -> Option<String> {
        let hits = self.candidates(ray);
        let tmax = ray.tmax as f64;
        if let Some(h) = hits
            .iter()
            .find(|h| (h.t - tmax).abs() <= T_TOLERANCE * tmax)
        {
            return Some(format!(
                "triangle {} at the end of the interval",
                h.triangle
            ));
        }
        self.sensitive(&hits, tmax)
    }
}

#[derive(Default)]
struct Tally {
    queries: usize,
    hits: usize,
    blocked: usize,
    /// Closest-hit and occlusion disagreements, explained or not.
    intersect_disagreements: usize,
    occluded_disagreements: usize,
    /// Closest-hit disagreements where one backend's hit is farther (or missing).
    bvh_farther: usize,
    embree_farther: usize,
    max_t_error: f64,
    /// Largest distance between the points the barycentrics name, relative to the magnitude.
    max_point_error: f64,
    unexplained: Vec<String>,
    /// Explained disagreements with their reasons.
    examples: Vec<String>,
    judged: usize,
}

impl Tally {
    /// Files a disagreement described by `what` as explained (with the reason `explain`
    /// finds) or unexplained. Only the first `MAX_JUDGED` are judged: explaining is slow.
    fn judge(&mut self, what: String, explain: impl FnOnce() -> Option<String>) {
        self.judged += 1;
        if self.judged <= MAX_JUDGED {
            match explain() {
                Some(reason) => self.examples.push(format!("{what}: {reason}")),
                None => self.unexplained.push(what),
            }
        }
    }
}

/// At most this many disagreements per kind of ray get the (slow) brute-force explanation.
const MAX_JUDGED: usize = 500;

/// Compares `bvh` (one of the pair's BVH scenes) with Embree.
fn compare(pair: &Pair, bvh: &Scene, kind: Kind) -> Tally {
    let judge = Judge { pair };
    let mut tally = Tally::default();
    let mut tmax_rng = Rng::new(7, kind as u64 + 10);
    let diagonal = (pair.bounds.1 - pair.bounds.0).length();
    for ray in rays(pair, kind, 1) {
        tally.queries += 1;
        let a = bvh.intersect(&ray);
        let b = pair.embree.intersect(&ray);
        if let (Some(a), Some(b)) = (a, b)
            && a.triangle == b.triangle
        {
            tally.hits += 1;
            let t_error = (a.t as f64 - b.t as f64).abs() / a.t.max(b.t) as f64;
            tally.max_t_error = tally.max_t_error.max(t_error);
            let distance = pair.barycentric_distance(a.triangle, [a.u, a.v], [b.u, b.v]);
            tally.max_point_error = tally.max_point_error.max(distance / pair.magnitude);
        }
        if !pair.hits_agree(a, b) {
            tally.intersect_disagreements += 1;
            let far = |h: Option<Hit>| h.map_or(f64::INFINITY, |h| h.t as f64);
            let (ta, tb) = (far(a), far(b));
            if (ta - tb).abs() > T_TOLERANCE * ta.min(tb) + pair.rounding() {
                // One backend went past a surface the other stopped at.
                if ta > tb {
                    tally.bvh_farther += 1;
                } else {
                    tally.embree_farther += 1;
                }
            }
            tally.judge(
                format!("intersect {ray:?}: bvh {a:?}, embree {b:?}"),
                || judge.intersect(&ray, a, b),
            );
        }
        // Occlusion up to a random distance around the hit (or within the scene).
        let reach = a.map_or(diagonal, |h| h.t);
        let shadow = Ray::new(
            ray.origin,
            ray.direction,
            ray.tmin,
            reach * 1.5 * tmax_rng.uniform(),
        );
        let (oa, ob) = (bvh.occluded(&shadow), pair.embree.occluded(&shadow));
        tally.blocked += oa as usize;
        if oa != ob {
            tally.occluded_disagreements += 1;
            tally.judge(
                format!("occluded {shadow:?}: bvh {oa}, embree {ob}"),
                || judge.occluded(&shadow),
            );
        }
    }
    tally
}

fn check_pair(pair: &Pair) {
    check_bvh(pair, "default", &pair.bvh);
    for (name, bvh) in &pair.variants {
        check_bvh(pair, name, bvh);
    }
}

/// Every query of every kind through `bvh` against Embree.
fn check_bvh(pair: &Pair, variant: &str, bvh: &Scene) {
    let name = format!("{} ({variant} bvh)", pair.name);
    let mut queries = 0;
    let mut disagreements = 0;
    let mut unexplained = Vec::new();
    for kind in [Kind::Camera, Kind::Bounce, Kind::Random, Kind::Edge] {
        let t = compare(pair, bvh, kind);
        assert_eq!(t.queries, RAYS_PER_KIND);
        println!(
            "{} {kind:?}: {} rays, {} on the same triangle (max t error {:.1e} relative, point error {:.1e} of the magnitude), {} blocked; disagreements: closest hit {} (farther hit: bvh {}, embree {}), occlusion {}",
            name,
            t.queries,
            t.hits,
            t.max_t_error,
            t.max_point_error,
            t.blocked,
            t.intersect_disagreements,
            t.bvh_farther,
            t.embree_farther,
            t.occluded_disagreements
        );
        for e in t.examples.iter().take(3) {
            println!("  e.g. {e}");
        }
        // Each kind must exercise both answers.
        assert!(
            t.hits > RAYS_PER_KIND / 4,
            "{} {kind:?}: only {} hits",
            name,
            t.hits
        );
        assert!(t.blocked > RAYS_PER_KIND / 10 && t.blocked < RAYS_PER_KIND * 9 / 10);
        if kind == Kind::Edge {
            assert!(
                !t.examples.is_empty(),
                "{}: edge-aimed rays should exercise the explanations",
                name
            );
        } else {
            queries += 2 * t.queries;
            disagreements += t.intersect_disagreements + t.occluded_disagreements;
        }
        unexplained.extend(t.unexplained.into_iter().map(|u| format!("{kind:?}: {u}")));
    }
    assert!(
        unexplained.is_empty(),
        "{}: {} disagreements without a rounding-sensitive configuration:\n{}",
        name,
        unexplained.len(),
        unexplained.join("\n")
    );
    let rate = disagreements as f64 / queries as f64;
    assert!(
        rate <= MAX_DISAGREEMENT_RATE,
        "{}: {disagreements} of {queries} queries disagree ({rate:.1e})",
        name
    );
}

#[test]
fn cornell_box_rays_agree() {
    check_pair(&Pair::new("cornell-box", &cornell_box(), cornell_camera()));
}

#[test]
fn cornell_glass_rays_agree() {
    check_pair(&Pair::new(
        "cornell-glass",
        &canonical_mesh("cornell-glass"),
        canonical_camera("cornell-glass"),
    ));
}

#[test]
fn generated_mesh_rays_agree() {
    let mesh = generated_mesh();
    assert!(mesh.indices.len() / 3 >= 100_000);
    let camera = Camera {
        eye: [10.0, 35.0, -95.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 70.0,
        ..Camera::default()
    };
    check_pair(&Pair::new("generated", &mesh, camera));
}

/// ~130k triangles inside a box of side 200: a displaced sphere (radius ~40, open at the
/// poles), a wavy heightfield sheet y = f(x, z) and a wavy wall x = g(y, z) that cut through
/// it and each other. Many thin triangles, shared edges, intersection curves and grazing
/// views. Deterministic.
fn generated_mesh() -> Mesh {
    use std::f64::consts::{PI, TAU};
    let mut mesh = MeshBuilder::default();
    mesh.grid(150, 200, |s, u| {
        let theta = 0.05 + s * (PI - 0.1);
        let phi = u * TAU;
        let r = 40.0
            * (1.0
                + 0.2 * (5.0 * theta).sin() * (3.0 * phi).cos()
                + 0.05 * (17.0 * theta + 11.0 * phi).sin());
        DVec3::new(
            r * theta.sin() * phi.cos(),
            r * theta.cos(),
            r * theta.sin() * phi.sin(),
        )
    });
    mesh.grid(160, 160, |s, u| {
        let (x, z) = (-90.0 + 180.0 * s, -90.0 + 180.0 * u);
        DVec3::new(
            x,
            20.0 * (0.07 * x).sin() * (0.05 * z).cos() + 3.0 * (0.4 * x + 0.3 * z).sin(),
            z,
        )
    });
    mesh.grid(100, 100, |s, u| {
        let (y, z) = (-90.0 + 180.0 * s, -90.0 + 180.0 * u);
        DVec3::new(15.0 * (0.09 * z + 0.02 * y).sin() + 5.0, y, z)
    });
    // The box, two triangles per face.
    mesh.cuboid(glam::DAffine3::from_scale(DVec3::splat(100.0)), 1);
    let MeshBuilder { positions, indices } = mesh;
    Mesh {
        positions,
        indices,
        material_ids: Vec::new(),
        materials: vec![Material::diffuse([0.5; 3])],
    }
}

/// Path-traced images of cornell-box through each backend agree within their statistical
/// error. (Equal seeds would not give near-equal images: lights are picked by their index in
/// the backend's internal triangle order, which differs.)
#[test]
fn rendered_images_agree() {
    let mesh = cornell_box();
    let camera = cornell_camera();
    let estimate =
        |backend, seeds| path_traced_estimate(&mesh.scene_with(backend), &camera, 64, 128, seeds);
    assert_estimates_agree(
        "cornell-box, embree vs bvh",
        &estimate(Backend::Embree, 100..104),
        &estimate(Backend::Bvh, 0..4),
        4,
        4.0,
        4.0,
    );
}

/// The window room (tests/common/window_room.rs) lit by its sky map and sun through each
/// backend: rays that leave the scene, shadow rays towards infinity and light subpaths from
/// the disc around the scene agree within the statistical error (BDPT, which uses them all).
#[test]
fn window_room_images_agree() {
    let mesh = canonical_mesh("window-room");
    let camera = canonical_camera("window-room");
    let sky = window_room::sky_pixels();
    let lights = window_room::lights(&sky);
    let estimate = |backend, seeds: std::ops::Range<u64>| {
        let scene = mesh.scene_lit(backend, lights);
        let renders: Vec<Vec<f32>> = seeds
            .map(|seed| {
                let settings = mlt::RenderSettings {
                    width: 32,
                    height: 32,
                    algorithm: mlt::Algorithm::Bdpt,
                    samples_per_pixel: 160,
                    seed,
                    ..Default::default()
                };
                render_image(&scene, &camera, &settings)
            })
            .collect();
        Estimate::from_correlated_renders(32, 32, &renders)
    };
    assert_estimates_agree(
        "window room, embree vs bvh",
        &estimate(Backend::Embree, 100..112),
        &estimate(Backend::Bvh, 0..12),
        2,
        5.0,
        6.0,
    );
}
