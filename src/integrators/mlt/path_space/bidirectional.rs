//! Veach's bidirectional mutation (thesis §11.4.2): delete a subpath of the current path and
//! regenerate it by sampling from both of the kept ends and connecting them. Because it can
//! replace any part of a path (the whole of it included), it makes the chain ergodic.
//!
//! # The proposal
//!
//! For a path of n vertices x_0 (light) … x_{n-1} (lens):
//! 1. Keep x_0..=x_a and x_b.. (−1 ≤ a < b ≤ n; a = −1 or b = n keeps no vertex on that side)
//!    and delete the n_d = b − a − 1 vertices between. The number of deleted edges b − a is
//!    drawn with `deletion_weight` (short deletions preferred), then a uniformly among the
//!    n − (b − a) + 2 places: p_del(a, b | n).
//! 2. Add n_a = n_d + δ vertices, δ ∈ {−2, …, 2} drawn from `ADDED_OFFSET_PROBABILITY`
//!    (symmetric in δ, so its probabilities cancel in the ratio). A negative n_a, or a path
//!    length outside the depth range, is a failed proposal (the chain stays).
//! 3. Split the n_a vertices uniformly: i from the light side (sampled from x_a onwards as a
//!    light subpath would, or from a new light point if a = −1) and n_a − i from the lens side
//!    (from x_b backwards as a camera subpath would, or from a new lens point if b = n), then
//!    connect the two ends with a shadow ray.
//!
//! # The transfer ratio
//!
//! The new vertices of y could have come from any split, so
//! T(x→y) = p_del(a, b | n) · p_add(n_a) · Σ_i p_i(y) / (n_a + 1), where p_i is the density of
//! BDPT's strategy with a + 1 + i light vertices (the kept vertices' densities, the same in
//! every term, cancel below). With C_s = f/p_s, the unweighted contribution,
//! Σ_i p_i(y) / f(y) = Σ_i 1/|C_{a+1+i}(y)| =: H(y), and the reverse move deletes y's new
//! vertices (b' = a + n_a + 1) and regenerates x's, so
//!
//! ```text
//! f(y) T(y→x)   (n_a + 1) · p_del(a, b' | n') · H(x)
//! ----------- = -------------------------------------
//! f(x) T(x→y)   (n_d + 1) · p_del(a, b  | n ) · H(y)
//! ```
//!
//! where |·| is luminance and splits that cannot produce the path (a connection at a
//! specular vertex, a lens side hitting a delta light) have p_i = 0 and no term. Where a
//! BSDF has a Dirac lobe beside a diffuse one, y records the lobe sampled at each vertex
//! sampled from (x_a and x_b among them) and the diffuse one at the connection's ends; p_i
//! includes the lobes' probabilities (parent module, "Lobes").
//!
//! A new light vertex is picked as `SceneLights::sample_vertex` picks it (a point on a
//! triangle, a point or spot light, or a direction at infinity), and the light side's first
//! ray leaves it as `sample_emission`'s would (`SceneLights::sample_le_ray`); a lens side whose last vertex is the
//! path's light ends on the lights at infinity if its ray leaves the scene. A light that is
//! not a triangle never becomes an inner vertex (a move keeping the whole path as its lens
//! side and adding vertices before it is refused; such paths have f = 0). This is Veach's form (the sum over splits);
//! every term comes from `PathSpace::unweighted_contribution`, which the tests check
//! against BDPT strategy by strategy.

use super::{PathSpace, PathVertex};
use crate::accel::Ray;
use crate::bsdf::TransportMode;
use crate::integrators::{emission_ray, spawn_ray};
use crate::sampling::Rng;
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// Probabilities of δ = n_a − n_d = −2, −1, 0, 1, 2: mostly the same length, as Veach
/// suggests. Symmetric, so p_add(n_a | n_d) = p_add(n_d | n_a).
const ADDED_OFFSET_PROBABILITY: [f32; 5] = [0.1, 0.15, 0.5, 0.15, 0.1];

/// Relative probability of deleting `edges` edges (≥ 1): Veach's preference for replacing
/// one or two edges, then halving with each more.
#[inline]
fn deletion_weight(edges: usize) -> f32 {
    match edges {
        1 => 0.25,
        2 => 0.5,
        k => 0.5f32.powi(k as i32 - 1),
    }
}

/// p_del(a, b | n): the probability of keeping x_0..=x_a and x_b.. of an n-vertex path.
pub(crate) fn deletion_probability(a: isize, b: isize, n: usize) -> f32 {
    let edges = (b - a) as usize;
    let total: f32 = (1..=n + 1).map(deletion_weight).sum();
    deletion_weight(edges) / total / (n + 2 - edges) as f32
}

/// Draws (a, b) with probability `deletion_probability(a, b, n)`.
fn choose_deletion(n: usize, rng: &mut Rng) -> (isize, isize) {
    let total: f32 = (1..=n + 1).map(deletion_weight).sum();
    let mut goal = rng.uniform() * total;
    let mut edges = n + 1;
    for k in 1..=n + 1 {
        goal -= deletion_weight(k);
        if goal < 0.0 {
            edges = k;
            break;
        }
    }
    let places = n + 2 - edges;
    let a = ((rng.uniform() * places as f32) as usize).min(places - 1) as isize - 1;
    (a, a + edges as isize)
}

/// Draws δ = n_a − n_d.
fn choose_added_offset(rng: &mut Rng) -> isize {
    let mut goal = rng.uniform();
    for (i, p) in ADDED_OFFSET_PROBABILITY.iter().enumerate() {
        goal -= p;
        if goal < 0.0 {
            return i as isize - 2;
        }
    }
    2
}

/// Σ over the splits of the `count` vertices after x_a of 1/|C_s|: the density of
/// generating them, summed over the ways the mutation could have, over f (see the module
/// documentation).
pub(crate) fn split_density_sum(
    space: &PathSpace,
    path: &[PathVertex],
    a: isize,
    count: usize,
) -> f32 {
    (0..=count)
        .filter_map(|i| {
            let s = (a + 1) as usize + i;
            let (c, _) = space.unweighted_contribution(path, s, true)?;
            let luminance = c.luminance();
            (luminance > 0.0).then(|| 1.0 / luminance)
        })
        .sum()
}

/// A proposal's outcome: the new path is in the output buffer, with this acceptance
/// ratio's factor f(y)T(y→x) / (f(x)T(x→y)).
pub(crate) struct Proposal {
    pub ratio: f32,
    pub value: Spectrum,
    pub pixel: u32,
    /// The wavelengths y carries (x's, unless the mutation drew new ones).
    pub channels: Channels,
}

/// The mutation over paths of `min_vertices..=max_vertices` vertices.
pub(crate) struct Bidirectional {
    pub min_vertices: usize,
    pub max_vertices: usize,
}

impl Bidirectional {
    /// Proposes a mutation of `x` into `y` (cleared first; `eye` is scratch for the lens
    /// side's new vertices). `None` is a failed proposal: the chain stays at x.
    #[allow(clippy::too_many_arguments)]
    pub fn propose(
        &self,
        space: &PathSpace,
        x: &[PathVertex],
        y: &mut Vec<PathVertex>,
        eye: &mut Vec<PathVertex>,
        rng: &mut Rng,
        rays: &mut u64,
    ) -> Option<Proposal> {
        let n = x.len();
        let (a, b) = choose_deletion(n, rng);
        let deleted = (b - a - 1) as usize;
        let added = deleted as isize + choose_added_offset(rng);
        if added < 0 {
            return None;
        }
        let added = added as usize;
        // Keeping the whole path (the "edge" beyond the lens deleted) and adding vertices
        // would make the old lens an inner vertex: never a path of the scene. (Beyond the
        // light it is one: an emitter may also reflect, as in the furnace.)
        if added > 0 && a + 1 == n as isize {
            return None;
        }
        let n_new = n - deleted + added;
        if n_new < self.min_vertices || n_new > self.max_vertices {
            return None;
        }
        let from_light = ((rng.uniform() * (added + 1) as f32) as usize).min(added);
        let from_eye = added - from_light;
        // Keeping the whole path as the lens side and adding vertices before its light makes
        // the light an inner vertex: possible for an emissive triangle, never for a point
        // light or a direction.
        if added > 0 && b == 0 && x[0].light.is_some() {
            return None;
        }
        // In a spectral render y gets new wavelengths unless a kept vertex disperses (then
        // the kept vertices exist at x's hero wavelength alone). The rule depends only on the
        // kept vertices, which x and y share, so the reverse move draws x's wavelengths with
        // the same (uniform) density and it cancels: y is sampled and measured at its own
        // wavelengths, x at its own.
        let resampled;
        let space_y = if space.channels.hero().is_some()
            && !(0..=a)
                .chain(b..n as isize)
                .any(|k| space.disperses_at(x, k as usize))
        {
            resampled = space.with_channels(Channels::new(true, || rng.uniform()));
            &resampled
        } else {
            space
        };
        let space_x = space;
        let space = space_y;

        // Light side: the kept prefix, then `from_light` sampled vertices.
        // Each vertex sampled from records the lobe it sampled (see "Lobes" in the parent
        // module's documentation), and the connection's ends the lobes with a density.
        y.clear();
        y.extend_from_slice(&x[..(a + 1) as usize]);
        for _ in 0..from_light {
            let (next, dirac) = self.extend_light_side(space, y, rng, rays)?;
            if let Some(end) = y.last_mut() {
                end.dirac = dirac;
            }
            y.push(next);
        }
        // Lens side: sampled backwards from the kept suffix into `eye` (lens-side order).
        let suffix = &x[b as usize..];
        eye.clear();
        let mut suffix_dirac = None;
        for i in 0..from_eye {
            // The last vertex sampled from the lens side is the light when the light side
            // is empty: a ray that leaves the scene then ends on the lights at infinity.
            let is_light = y.is_empty() && i + 1 == from_eye;
            let (next, dirac) = self.extend_eye_side(space, suffix, eye, is_light, rng, rays)?;
            match eye.last_mut() {
                Some(end) => end.dirac = dirac,
                None => suffix_dirac = Some(dirac),
            }
            eye.push(next);
        }
        let s = y.len();
        y.extend(eye.iter().rev());
        y.extend_from_slice(suffix);
        debug_assert_eq!(y.len(), n_new);
        if let (Some(dirac), Some(_)) = (suffix_dirac, suffix.first()) {
            y[n_new - suffix.len()].dirac = dirac;
        }
        for k in [s.wrapping_sub(1), s] {
            if let Some(end) = y.get_mut(k) {
                end.dirac = false;
            }
        }
        if s >= 1 && s < y.len() {
            let lens_index = y.len() - 1;
            if !space.visible(&y[s - 1], &y[s], s == lens_index, rays) {
                return None;
            }
        }
        let (value, pixel) = space.unweighted_contribution(y, s, true)?;
        let h_y = split_density_sum(space, y, a, added);
        let h_x = split_density_sum(space_x, x, a, deleted);
        let b_new = a + added as isize + 1;
        let kept = space_x.kept_density_ratio(space, x, [(a + 1) as usize, b as usize], true);
        let ratio = (added + 1) as f32 * deletion_probability(a, b_new, n_new) * h_x * kept
            / ((deleted + 1) as f32 * deletion_probability(a, b, n) * h_y);
        Some(Proposal {
            ratio,
            value,
            pixel,
            channels: space.channels,
        })
    }

    /// The next vertex of the light side whose vertices so far are `path` (none: a new
    /// light point), and whether the side's last vertex scattered towards it through a
    /// Dirac lobe.
    fn extend_light_side(
        &self,
        space: &PathSpace,
        path: &[PathVertex],
        rng: &mut Rng,
        rays: &mut u64,
    ) -> Option<(PathVertex, bool)> {
        let scene = space.scene;
        match path {
            [] => {
                // No numbers are drawn without a light (the chain's random sequence stays).
                if !scene.lights.has_lights() {
                    return None;
                }
                // With the densities `unweighted_contribution` gives x_0 (`sample_vertex`'s,
                // which are `sample_emission`'s).
                let v = scene.lights.sample_vertex(rng.uniform(), rng.uniform2())?;
                let light =
                    PathVertex::on_light(v.light, v.point, v.normal, v.triangle, v.barycentrics);
                Some((light, false))
            }
            [light] => {
                let emitter = light.emitter();
                let (origin, direction) =
                    scene
                        .lights
                        .sample_le_ray(emitter, light.p, light.normal, rng.uniform2())?;
                let ray = emission_ray(scene, emitter, origin, light.normal, direction);
                Some((space.trace(&ray, rays)?, false))
            }
            [.., previous, end] => {
                let wo = arrival_back(space, previous, false, end);
                let (wi, dirac) = sample_direction(space, wo, end, TransportMode::Importance, rng)?;
                let next = space.trace(&spawn_ray(scene, end.p, end.normal, wi), rays)?;
                Some((next, dirac))
            }
        }
    }

    /// The next vertex of the lens side: `eye` holds its sampled vertices so far (nearest
    /// the lens first), continuing the kept `suffix` (empty: a new lens point), and whether
    /// the side's end scattered towards it through a Dirac lobe. With `is_light`, the vertex
    /// is the path's light (a ray leaving the scene is then on the lights at infinity).
    fn extend_eye_side(
        &self,
        space: &PathSpace,
        suffix: &[PathVertex],
        eye: &[PathVertex],
        is_light: bool,
        rng: &mut Rng,
        rays: &mut u64,
    ) -> Option<(PathVertex, bool)> {
        let camera = space.camera;
        // The end of the lens side and the vertex before it (towards the lens; none if the
        // end is the lens).
        let (end, previous) = if let Some(last) = eye.last() {
            let previous = if eye.len() >= 2 {
                eye.get(eye.len() - 2)
            } else {
                suffix.first()
            };
            (last, previous)
        } else if let Some(end) = suffix.first() {
            (end, suffix.get(1))
        } else {
            let lens = camera.sample_lens(rng.uniform2());
            return Some((PathVertex::point(lens, camera.forward), false));
        };
        let Some(previous) = previous else {
            // The end is the lens: a new film position, uniform over the film.
            let [u, v] = rng.uniform2();
            let direction =
                camera.direction_through(end.p, u * camera.width as f32, v * camera.height as f32);
            let ray = Ray::new(end.p, direction, 0.0, f32::INFINITY);
            let next = if is_light {
                space.trace_or_escape(&ray, rays)
            } else {
                space.trace(&ray, rays)
            };
            return Some((next?, false));
        };
        let previous_is_lens = suffix
            .last()
            .is_some_and(|lens| std::ptr::eq(lens, previous));
        let wo = arrival_back(space, previous, previous_is_lens, end);
        let (wi, dirac) = sample_direction(space, wo, end, TransportMode::Radiance, rng)?;
        let ray = spawn_ray(space.scene, end.p, end.normal, wi);
        let next = if is_light {
            space.trace_or_escape(&ray, rays)
        } else {
            space.trace(&ray, rays)
        };
        Some((next?, dirac))
    }
}

/// The unit direction from `at` back along the ray that reached it from `from`. That ray
/// left from `from`'s offset origin (`spawn_ray`), unless `from` is the lens or a light that
/// is not a triangle: a direction rebuilt from the two points alone would bend a specular
/// chain sampled on from `at` (against BDPT's, which goes on from its rays).
#[inline]
fn arrival_back(
    space: &PathSpace,
    from: &PathVertex,
    from_is_lens: bool,
    at: &PathVertex,
) -> Vec3A {
    if from.is_at_infinity() {
        return from.normal;
    }
    let origin = if from_is_lens || from.light.is_some() {
        from.p
    } else {
        spawn_ray(space.scene, from.p, from.normal, at.p - from.p).origin
    };
    (origin - at.p).normalize()
}

/// A scattering direction at `at`, arrived at along `-wo`, sampled by its BSDF, and
/// whether it sampled a Dirac lobe.
#[inline]
fn sample_direction(
    space: &PathSpace,
    wo: Vec3A,
    at: &PathVertex,
    mode: TransportMode,
    rng: &mut Rng,
) -> Option<(Vec3A, bool)> {
    let s = space
        .surface_bsdf(at)
        .sample(wo, rng.uniform2(), rng.uniform(), mode)?;
    Some((s.wi, s.specular))
}

#[cfg(test)]
mod tests {
    use super::super::test_geometry::Rect;
    use super::*;
    use crate::accel::Backend;
    use crate::integrators::mlt::acceptance;
    use crate::sampling::OrthonormalBasis;
    use crate::sampling::chi_square::{
        Z_999, Z_9999, quantile as chi_square_quantile, statistic as chi_square,
    };
    use crate::scene::{Camera, CameraModel, Material, Scene, SceneDesc};
    use crate::spectral::Channels;
    use glam::DVec3;
    use std::f32::consts::TAU;
    use std::f64::consts::PI;

    #[test]
    fn deletions_are_drawn_with_their_probabilities() {
        let mut rng = Rng::new(3, 0);
        for n in [2usize, 3, 5] {
            let mut counts = std::collections::HashMap::new();
            let draws = 200_000;
            for _ in 0..draws {
                *counts.entry(choose_deletion(n, &mut rng)).or_insert(0u32) += 1;
            }
            let mut total = 0.0;
            for a in -1..n as isize {
                for b in a + 1..=n as isize {
                    let p = deletion_probability(a, b, n);
                    total += p;
                    let observed = *counts.get(&(a, b)).unwrap_or(&0) as f32 / draws as f32;
                    let sigma = (p * (1.0 - p) / draws as f32).sqrt();
                    assert!(
                        (observed - p).abs() <= 5.0 * sigma + 1e-6,
                        "n {n} ({a}, {b}): {observed} vs {p}"
                    );
                }
            }
            assert!(
                (total - 1.0).abs() < 1e-5,
                "n {n}: probabilities sum to {total}"
            );
        }
    }

    // A small scene whose proposal densities and contributions the tests below compute from
    // elementary formulas, independently of `PathSpace`: a diffuse floor, a diffuse strip of
    // wall apart from it (so that G between them stays bounded), a small light facing down
    // above both, and a pinhole camera that sees all of the floor and the wall. Nothing
    // occludes anything: every floor, wall and light point sees every other one (front to
    // front) and the lens, so visibility is 1 in the formulas.

    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Surface {
        Floor,
        Wall,
        Light,
    }

    impl Surface {
        fn rect(self) -> Rect {
            let v = DVec3::new;
            match self {
                // y = 0, x and z in [-1, 1], facing up.
                Surface::Floor => Rect {
                    o: v(-1.0, 0.0, 1.0),
                    a: v(2.0, 0.0, 0.0),
                    b: v(0.0, 0.0, -2.0),
                },
                // z = -1, x in [-1, 1], y in [0.3, 0.8], facing +z.
                Surface::Wall => Rect {
                    o: v(-1.0, 0.3, -1.0),
                    a: v(2.0, 0.0, 0.0),
                    b: v(0.0, 0.5, 0.0),
                },
                // y = 1.5, 0.4 × 0.4, facing down.
                Surface::Light => Rect {
                    o: v(-0.2, 1.5, -0.5),
                    a: v(0.4, 0.0, 0.0),
                    b: v(0.0, 0.0, 0.4),
                },
            }
        }

        /// Diffuse albedo; the light is black (it only emits).
        fn albedo(self) -> DVec3 {
            match self {
                Surface::Floor => DVec3::new(0.8, 0.6, 0.4),
                Surface::Wall => DVec3::new(0.3, 0.6, 0.9),
                Surface::Light => DVec3::ZERO,
            }
        }

        /// The surface a (non-lens) vertex lies on, told by its normal.
        fn of(v: &PathVertex) -> Surface {
            if v.normal.y > 0.5 {
                Surface::Floor
            } else if v.normal.z > 0.5 {
                Surface::Wall
            } else {
                assert!(v.normal.y < -0.5, "{v:?} is on no surface");
                Surface::Light
            }
        }
    }

    /// The light's radiance (grey).
    const EMISSION: f32 = 4.0;
    const EYE: [f32; 3] = [0.0, 1.2, 2.8];
    const LOOK_AT: [f32; 3] = [0.0, 0.25, -0.2];
    const FOV_Y_DEG: f32 = 60.0;

    fn scene() -> Scene {
        scene_with(Default::default())
    }

    /// The small scene with more lights.
    fn scene_with(lights: crate::scene::LightsDesc) -> Scene {
        let albedo = Surface::Floor.albedo().as_vec3().to_array();
        scene_with_floor(lights, Material::diffuse(albedo))
    }

    /// The small scene with more lights and the floor's material.
    fn scene_with_floor(lights: crate::scene::LightsDesc, floor: Material) -> Scene {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        let mut material_ids = Vec::new();
        for (material, surface) in [Surface::Floor, Surface::Wall, Surface::Light]
            .into_iter()
            .enumerate()
        {
            let r = surface.rect();
            let base = (positions.len() / 3) as u32;
            for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                positions.extend_from_slice(&r.point(s, t).as_vec3().to_array());
            }
            indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
            material_ids.extend_from_slice(&[material as u32; 2]);
        }
        let albedo = |s: Surface| s.albedo().as_vec3().to_array();
        Scene::new(&SceneDesc {
            positions: &positions,
            indices: &indices,
            material_ids: &material_ids,
            materials: &[
                floor,
                Material::diffuse(albedo(Surface::Wall)),
                Material::diffuse([0.0; 3]).with_emission([EMISSION; 3]),
            ],
            lights,
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap()
    }

    /// An 8×8 film: the pixel plays no part in these tests (the target is f, over the whole
    /// film).
    fn camera() -> CameraModel {
        Camera {
            eye: EYE,
            target: LOOK_AT,
            up: [0.0, 1.0, 0.0],
            fov_y_deg: FOV_Y_DEG,
            lens_radius: 0.0,
            focus_distance: 0.0,
        }
        .model(8, 8)
    }

    /// The pinhole camera from its description, for the independent formulas.
    struct Pinhole {
        eye: DVec3,
        forward: DVec3,
        right: DVec3,
        up: DVec3,
        /// tan(fov / 2): the square film spans ±this on the image plane at distance 1.
        tan_half: f64,
    }

    impl Pinhole {
        fn new() -> Self {
            let eye = Vec3A::from(EYE).as_dvec3();
            let forward = (Vec3A::from(LOOK_AT).as_dvec3() - eye).normalize();
            let right = forward.cross(DVec3::Y).normalize();
            Pinhole {
                eye,
                forward,
                right,
                up: right.cross(forward),
                tan_half: (0.5 * (FOV_Y_DEG as f64).to_radians()).tan(),
            }
        }

        /// The area density, on the surface of `v`, of the ray from the eye through a film
        /// point drawn uniformly: uniform on the image plane at distance 1 (area A =
        /// 4 tan²), which is 1 / (A cos³θ) per steradian, times |cos θ_v| / d². It is also
        /// the importance factor G(v, lens)·We of the measurement (We = 1 / (A cos⁴θ)), so
        /// that a path's camera ray has weight 1 in both.
        fn density(&self, v: &PathVertex) -> f64 {
            let d = v.p.as_dvec3() - self.eye;
            let d2 = d.length_squared();
            let w = d / d2.sqrt();
            let c = w.dot(self.forward);
            let on_film = c > 0.0
                && (w.dot(self.right) / c).abs() < self.tan_half
                && (w.dot(self.up) / c).abs() < self.tan_half;
            if !on_film {
                return 0.0;
            }
            let film_area = 4.0 * self.tan_half * self.tan_half;
            v.normal.as_dvec3().dot(w).abs() / (film_area * c.powi(3) * d2)
        }
    }

    fn luminance(rgb: DVec3) -> f64 {
        rgb.dot(DVec3::from_array(crate::spectrum::LUMINANCE_WEIGHTS))
    }

    /// |cos| at both ends over the squared distance.
    fn geometry(u: &PathVertex, v: &PathVertex) -> f64 {
        let d = v.p.as_dvec3() - u.p.as_dvec3();
        let d2 = d.length_squared();
        let w = d / d2.sqrt();
        u.normal.as_dvec3().dot(w).abs() * v.normal.as_dvec3().dot(w).abs() / d2
    }

    /// The area density at `to` of a direction drawn at `at` with density ∝ cos: diffuse
    /// scattering into the hemisphere of `from` (cos/π per steradian), or, with `from`
    /// `None`, emission from the front of the light. Times |cos θ_to| / d² per area.
    fn cosine_density(from: Option<DVec3>, at: &PathVertex, to: &PathVertex) -> f64 {
        let (p, n) = (at.p.as_dvec3(), at.normal.as_dvec3());
        let d = to.p.as_dvec3() - p;
        let d2 = d.length_squared();
        let w = d / d2.sqrt();
        let side = from.map_or(1.0, |f| (f - p).dot(n));
        if n.dot(w) * side <= 0.0 {
            return 0.0;
        }
        n.dot(w).abs() / PI * to.normal.as_dvec3().dot(w).abs() / d2
    }

    /// The luminance of f(path) = Le · Π G · Π (ρ/π) · G(last, lens) We for a path from the
    /// light to the lens (the last vertex), from the formulas above.
    fn contribution(camera: &Pinhole, path: &[PathVertex]) -> f64 {
        let lens = path.len() - 1;
        if Surface::of(&path[0]) != Surface::Light
            || path[0].normal.dot(path[1].p - path[0].p) <= 0.0
        {
            // Light leaves the front of the light only.
            return 0.0;
        }
        let mut rgb = DVec3::splat(EMISSION as f64);
        for j in 1..lens {
            rgb *= geometry(&path[j - 1], &path[j]);
            // Diffuse reflection, both neighbours on one side.
            let n = path[j].normal.as_dvec3();
            let p = path[j].p.as_dvec3();
            let next = if j + 1 == lens {
                camera.eye
            } else {
                path[j + 1].p.as_dvec3()
            };
            if (path[j - 1].p.as_dvec3() - p).dot(n) * (next - p).dot(n) <= 0.0 {
                return 0.0;
            }
            rgb *= Surface::of(&path[j]).albedo() / PI;
        }
        luminance(rgb) * camera.density(&path[lens - 1])
    }

    /// The density of the vertices `path[first..first + count]` given the others, when the
    /// first `i` of them were sampled from the light side (onwards from `path[first - 1]`)
    /// and the rest from the lens side (backwards from `path[first + count]`): the product
    /// of each sampled vertex's area density given those before it on its side.
    fn split_density(
        camera: &Pinhole,
        path: &[PathVertex],
        first: usize,
        count: usize,
        i: usize,
    ) -> f64 {
        let lens = path.len() - 1;
        let point = |j: usize| {
            if j == lens {
                camera.eye
            } else {
                path[j].p.as_dvec3()
            }
        };
        let light_area = Surface::Light.rect().area();
        let mut p = 1.0;
        for j in first..first + i {
            p *= if j == 0 {
                // A new light point, uniform on the light.
                1.0 / light_area
            } else if j == lens {
                // No traced ray hits a pinhole.
                0.0
            } else {
                let from = (j >= 2).then(|| point(j - 2));
                cosine_density(from, &path[j - 1], &path[j])
            };
        }
        for j in first + i..first + count {
            p *= if j == lens {
                // A new lens point is the eye again: the pinhole's Dirac delta, with the
                // same unit weight in every term and both directions.
                1.0
            } else if j + 1 == lens {
                camera.density(&path[j])
            } else {
                cosine_density(Some(point(j + 2)), &path[j + 1], &path[j])
            };
        }
        p
    }

    /// p_del(a, b | n) from Veach's weights (thesis §11.4.2): w(1) = 1/4, w(2) = 1/2,
    /// w(k) = 2^(1−k) beyond, normalized over 1 ≤ k ≤ n + 1 deleted edges, then uniform
    /// over the n + 2 − k places.
    fn veach_deletion(a: isize, b: isize, n: usize) -> f64 {
        let w = |k: usize| match k {
            1 => 0.25,
            2 => 0.5,
            k => 0.5f64.powi(k as i32 - 1),
        };
        let k = (b - a) as usize;
        w(k) / (1..=n + 1).map(w).sum::<f64>() / (n + 2 - k) as f64
    }

    /// p_add(δ): mostly the same length.
    fn offset_probability(delta: isize) -> f64 {
        [0.1, 0.15, 0.5, 0.15, 0.1][(delta + 2) as usize]
    }

    /// T(x→y) of the discrete choice with probability `choice` that added `added` vertices
    /// after `path[a]`: the choice's probability times the mean over the splits of their
    /// densities.
    fn transfer(camera: &Pinhole, y: &[PathVertex], a: isize, added: usize, choice: f64) -> f64 {
        let first = (a + 1) as usize;
        let sum: f64 = (0..=added)
            .map(|i| split_density(camera, y, first, added, i))
            .sum();
        choice * sum / (added + 1) as f64
    }

    /// The mutation's discrete choice: keep ..=a and b.., add n_d + δ.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
    struct Choice {
        a: isize,
        b: isize,
        delta: isize,
    }

    impl Choice {
        /// The choice `propose` is about to make with `rng`: its first draws, read from a
        /// copy of the generator.
        fn peek(n: usize, rng: &Rng) -> Choice {
            let mut copy = rng.clone();
            let (a, b) = choose_deletion(n, &mut copy);
            let delta = choose_added_offset(&mut copy);
            Choice { a, b, delta }
        }

        fn deleted(self) -> usize {
            (self.b - self.a - 1) as usize
        }

        fn added(self) -> usize {
            (self.deleted() as isize + self.delta) as usize
        }
    }

    /// f(y)T(y→x) / (f(x)T(x→y)) from the formulas above, for y proposed from x by `c`.
    fn expected_ratio(camera: &Pinhole, x: &[PathVertex], y: &[PathVertex], c: Choice) -> f64 {
        let (n_d, n_a) = (c.deleted(), c.added());
        let forward_choice = veach_deletion(c.a, c.b, x.len()) * offset_probability(c.delta);
        let b_reverse = c.a + n_a as isize + 1;
        let reverse_choice = veach_deletion(c.a, b_reverse, y.len()) * offset_probability(-c.delta);
        let forward = transfer(camera, y, c.a, n_a, forward_choice);
        let reverse = transfer(camera, x, c.a, n_d, reverse_choice);
        contribution(camera, y) * reverse / (contribution(camera, x) * forward)
    }

    /// The smallest |cos| at the ends of the path's edges (the lens excluded): paths with
    /// grazing edges (e.g. a connection along the floor, which f32 hit points make slightly
    /// non-coplanar) are left out of exact comparisons.
    fn smallest_cosine(path: &[PathVertex]) -> f64 {
        let lens = path.len() - 1;
        let mut smallest = f64::INFINITY;
        for j in 0..lens {
            let next = if j + 1 == lens {
                Vec3A::from(EYE)
            } else {
                path[j + 1].p
            };
            let w = (next - path[j].p).normalize();
            smallest = smallest.min(w.dot(path[j].normal).abs() as f64);
            if j + 1 < lens {
                smallest = smallest.min(w.dot(path[j + 1].normal).abs() as f64);
            }
        }
        smallest
    }

    /// The vertex `ray` hits first.
    fn hit(space: &PathSpace, origin: [f32; 3], direction: Vec3A) -> PathVertex {
        let ray = Ray::new(Vec3A::from(origin), direction, 0.0, f32::INFINITY);
        space.trace(&ray, &mut 0).expect("the ray hits")
    }

    /// A light, a wall, a floor vertex and the lens.
    fn vertices(space: &PathSpace) -> [PathVertex; 4] {
        let light = hit(space, [0.05, 1.0, -0.25], Vec3A::Y);
        let wall = hit(space, [-0.2, 0.55, 0.0], -Vec3A::Z);
        let floor = hit(space, [0.3, 1.0, 0.2], -Vec3A::Y);
        let lens = PathVertex::point(space.camera.eye, space.camera.forward);
        assert_eq!(
            [light, wall, floor].map(|v| Surface::of(&v)),
            [Surface::Light, Surface::Wall, Surface::Floor]
        );
        [light, wall, floor, lens]
    }

    /// Cells on some surfaces: each surface's rectangle cut into nu × nv cells.
    struct Grid(Vec<(Surface, usize, usize)>);

    impl Grid {
        fn len(&self) -> usize {
            self.0.iter().map(|&(_, nu, nv)| nu * nv).sum()
        }

        /// The cell a point of `surface` lies in, if the grid covers that surface.
        fn cell(&self, surface: Surface, p: DVec3) -> Option<usize> {
            let mut offset = 0;
            for &(s, nu, nv) in &self.0 {
                if s == surface {
                    let r = s.rect();
                    let d = p - r.o;
                    let index = |x: f64, cells: usize| ((x * cells as f64) as usize).min(cells - 1);
                    let u = index((d.dot(r.a) / r.a.length_squared()).max(0.0), nu);
                    let v = index((d.dot(r.b) / r.b.length_squared()).max(0.0), nv);
                    return Some(offset + v * nu + u);
                }
                offset += nu * nv;
            }
            None
        }

        /// Midpoint-rule nodes: (cell, vertex, area weight), m × m per cell.
        fn nodes(&self, m: usize) -> Vec<(usize, PathVertex, f64)> {
            let mut nodes = Vec::new();
            let mut offset = 0;
            for &(s, nu, nv) in &self.0 {
                let r = s.rect();
                let (ku, kv) = (nu * m, nv * m);
                let weight = r.area() / (ku * kv) as f64;
                for j in 0..kv {
                    for i in 0..ku {
                        let p = r.point((i as f64 + 0.5) / ku as f64, (j as f64 + 0.5) / kv as f64);
                        let cell = offset + (j / m) * nu + i / m;
                        let vertex = PathVertex::point(
                            Vec3A::from(p.as_vec3()),
                            Vec3A::from(r.normal().as_vec3()),
                        );
                        nodes.push((cell, vertex, weight));
                    }
                }
                offset += nu * nv;
            }
            nodes
        }
    }

    /// The first rays of a light side from a point light, a spot light and a light at
    /// infinity have the densities `unweighted_contribution` divides by: directions
    /// uniform over the sphere or the spot's outer cone (cos θ and φ uniform), and origins
    /// uniform over the disc of radius R facing the light, at R from the bounding sphere's
    /// centre (r² / R² and the angle uniform), leaving along the light's direction. Chi-square
    /// tests over 20 bins of each coordinate, and one with the cone's density shaped
    /// (cos θ = 1 − u²(1 − cos θ_max)) fails.
    #[test]
    fn emission_rays_from_lights_that_are_not_triangles_have_their_densities() {
        use crate::scene::{LightsDesc, PunctualLight, SunDesc};
        let punctual = [
            PunctualLight::point([0.0, 1.2, 0.0], [1.0; 3]),
            PunctualLight::spot([0.0, 1.2, 0.0], [0.2, -1.0, 0.1], [1.0; 3], 10.0, 40.0),
            PunctualLight::directional([0.3, -1.0, 0.4], [1.0; 3]),
        ];
        let scene = scene_with(LightsDesc {
            sun: Some(SunDesc::from_radiance([-0.2, 1.0, 0.3], 4.0, [50.0; 3])),
            punctual: &punctual,
            ..Default::default()
        });
        let (center, radius) = scene.lights.bounding_sphere();
        let bins = 20;
        let draws = 100_000;
        let threshold = chi_square_quantile(bins - 1, Z_9999);
        let uniform = vec![1.0 / bins as f64; bins];
        let bin = |x: f32| ((x * bins as f32) as usize).min(bins - 1);
        // The lights' indices: the area lights (triangles) first, then the punctual ones,
        // then the sun.
        let areas = scene.lights.area_light_count();
        let position = Vec3A::new(0.0, 1.2, 0.0);
        let lights = [
            (scene.lights.emitter(areas), position),
            (scene.lights.emitter(areas + 1), position),
            (
                scene.lights.emitter(areas + 2),
                Vec3A::new(-0.3, 1.0, -0.4).normalize(),
            ),
            (
                scene.lights.emitter(areas + 3),
                Vec3A::new(0.1, 0.9, 0.2).normalize(),
            ),
        ];
        let mut rng = Rng::new(0xE111, 0);
        for (index, &(light, at)) in lights.iter().enumerate() {
            let vertex = PathVertex::on_light(light, at, at, 0, [0.0; 2]);
            let cone = scene.lights.cone(light);
            let (mut first, mut second) = (vec![0u64; bins], vec![0u64; bins]);
            let mut shaped = vec![0u64; bins];
            for _ in 0..draws {
                let u = rng.uniform2();
                let (origin, direction) = scene
                    .lights
                    .sample_le_ray(light, vertex.p, vertex.normal, u)
                    .expect("a ray");
                let ray = emission_ray(&scene, light, origin, vertex.normal, direction);
                // Coordinates that are uniform under the density.
                let (a, b) = if light.is_delta_position() {
                    let (axis, cos_max) = cone.unwrap_or((Vec3A::Y, -1.0));
                    let basis = OrthonormalBasis::from_normal(axis);
                    let w = ray.direction;
                    assert!((ray.origin - vertex.p).length() < 1e-6);
                    let phi = basis.bitangent.dot(w).atan2(basis.tangent.dot(w));
                    let a = (1.0 - axis.dot(w)) / (1.0 - cos_max);
                    if cone.is_some() {
                        // A shaped cone, cos θ = 1 − u²(1 − cos θ_max), would have a = u².
                        shaped[bin(u[0] * u[0])] += 1;
                    }
                    (a, phi / TAU + 0.5)
                } else {
                    let toward = vertex.normal;
                    assert!((ray.direction + toward).length() < 1e-5);
                    let offset = ray.origin - center - toward * radius;
                    assert!(offset.dot(toward).abs() < 1e-3 * radius);
                    let basis = OrthonormalBasis::from_normal(toward);
                    let (x, y) = (basis.tangent.dot(offset), basis.bitangent.dot(offset));
                    ((x * x + y * y) / (radius * radius), y.atan2(x) / TAU + 0.5)
                };
                first[bin(a)] += 1;
                second[bin(b)] += 1;
            }
            for (name, counts) in [("radial", &first), ("angle", &second)] {
                let stat = chi_square(counts, 0, &uniform);
                assert!(
                    stat < threshold,
                    "light {index} {name}: chi-square {stat} ≥ {threshold}: {counts:?}"
                );
            }
            if cone.is_some() {
                let stat = chi_square(&shaped, 0, &uniform);
                assert!(stat > 10.0 * threshold, "the shaped cone passes: {stat}");
            }
        }
    }

    /// The proposal density: the proposals of one discrete choice from a fixed path x,
    /// histogrammed over cells of the new vertex, against T(x→y) = p_del · p_add · Σ_i p_i(y)
    /// / (n_a + 1) integrated over each cell, with every p_i built from the sampling
    /// densities (uniform light points, cosine emission and scattering, uniform film points)
    /// converted to area measure. Each iteration draws a fresh generator; only those whose
    /// first draws pick the studied choice go on to `propose` (the others are counted in
    /// "anything else"), so the counts per iteration estimate T including p_del · p_add.
    /// The same statistic rejects T without the 1/(n_a + 1), and T with one split's density
    /// in place of the mean.
    #[test]
    fn proposal_density_matches_the_mean_over_splits() {
        let scene = scene();
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let pinhole = Pinhole::new();
        let [light, wall, floor, lens] = vertices(&space);
        let mutation = Bidirectional {
            min_vertices: 3,
            max_vertices: 5,
        };
        let both = || Grid(vec![(Surface::Floor, 4, 4), (Surface::Wall, 4, 2)]);
        let short = vec![light, floor, lens];
        let long = vec![light, wall, floor, lens];
        let choice = |a, b, delta| Choice { a, b, delta };
        // (x, choice, cells of the new vertex): one vertex replaced (the floor vertex, the
        // light vertex, the wall vertex), with the lens regenerated too (a new lens point
        // is the eye again; the split that traces the lens has p = 0), and two vertices
        // replaced by one.
        let studies = [
            ("L F E, replace F", &short, choice(0, 2, 0), both()),
            ("L F E, replace F and E", &short, choice(0, 3, 0), both()),
            (
                "L F E, replace L",
                &short,
                choice(-1, 1, 0),
                Grid(vec![(Surface::Light, 2, 2)]),
            ),
            (
                "L W F E, replace F",
                &long,
                choice(1, 3, 0),
                Grid(vec![(Surface::Floor, 4, 4)]),
            ),
            (
                "L W F E, replace W",
                &long,
                choice(0, 2, 0),
                Grid(vec![(Surface::Wall, 4, 2)]),
            ),
            (
                "L W F E, replace W F by one",
                &long,
                choice(0, 3, -1),
                both(),
            ),
        ];
        let iterations = 4_000_000u64;
        for (index, (name, x, studied, grid)) in studies.iter().enumerate() {
            let (mut y, mut eye) = (Vec::new(), Vec::new());
            let mut counts = vec![0u64; grid.len()];
            let mut proposed = 0;
            let mut worst_ratio_error = 0f64;
            for i in 0..iterations {
                let mut rng = Rng::new(0xB1D1 + index as u64, i);
                if Choice::peek(x.len(), &rng) != *studied {
                    continue;
                }
                proposed += 1;
                let Some(proposal) =
                    mutation.propose(&space, x, &mut y, &mut eye, &mut rng, &mut 0)
                else {
                    continue;
                };
                // The proposal made the peeked choice: it kept x's vertices around the new
                // one (and a new lens point, which is x's).
                let new = (studied.a + 1) as usize;
                assert_eq!(
                    y.len(),
                    x.len() - studied.deleted() + studied.added(),
                    "{name}"
                );
                assert_eq!(y[..new], x[..new], "{name}");
                assert_eq!(y[new + 1..], x[x.len() + new + 1 - y.len()..], "{name}");
                let Some(cell) = grid.cell(Surface::of(&y[new]), y[new].p.as_dvec3()) else {
                    continue;
                };
                counts[cell] += 1;
                // The ratio too, on the same proposals.
                let expected = expected_ratio(&pinhole, x, &y, *studied);
                worst_ratio_error =
                    worst_ratio_error.max((proposal.ratio as f64 / expected - 1.0).abs());
            }
            let rest = iterations - counts.iter().sum::<u64>();

            // T(x→y) over each cell, by the midpoint rule (16 × 16 nodes a cell).
            let x_choice =
                veach_deletion(studied.a, studied.b, x.len()) * offset_probability(studied.delta);
            // Per cell: the mean over the splits, and each split's density alone (all times
            // the choice's probability).
            let n_a = studied.added();
            let mut mean = vec![0.0; grid.len()];
            let mut single = vec![vec![0.0; grid.len()]; n_a + 1];
            for (cell, z, weight) in grid.nodes(16) {
                let mut y = x[..(studied.a + 1) as usize].to_vec();
                y.push(z);
                if studied.b as usize == x.len() {
                    y.push(lens);
                }
                y.extend_from_slice(&x[studied.b as usize..]);
                if contribution(&pinhole, &y) <= 0.0 {
                    continue;
                }
                mean[cell] += weight * transfer(&pinhole, &y, studied.a, n_a, x_choice);
                for (s, sums) in single.iter_mut().enumerate() {
                    sums[cell] += weight
                        * x_choice
                        * split_density(&pinhole, &y, (studied.a + 1) as usize, n_a, s);
                }
            }
            // The cells and "anything else": as many degrees of freedom as cells. Six
            // studies: each at 99.99%.
            let df = counts.len();
            let stat = chi_square(&counts, rest, &mean);
            let threshold = chi_square_quantile(df, Z_9999);
            let total: u64 = counts.iter().sum();
            let expected_total = mean.iter().sum::<f64>() * iterations as f64;
            println!(
                "{name}: {proposed} proposals, {total} in cells (expected {expected_total:.0}), \
                 chi-square {stat:.1} (df {df}, 99.99% quantile {threshold:.1}); \
                 ratio vs independent: worst relative error {worst_ratio_error:.2e}"
            );
            for (cell, (&c, &p)) in counts.iter().zip(&mean).enumerate() {
                let e = p * iterations as f64;
                println!(
                    "  cell {cell:2}: {c:6} vs {e:8.1} (z {:+.2})",
                    (c as f64 - e) / e.sqrt()
                );
            }
            assert!(stat < threshold, "{name}: chi-square {stat} ≥ {threshold}");
            assert!(total > 10_000, "{name}: {total} proposals in cells");
            assert!(
                worst_ratio_error < 1e-3,
                "{name}: ratio error {worst_ratio_error}"
            );

            // Wrong densities fail the same statistic by far.
            let without_mean: Vec<f64> = mean.iter().map(|p| p * (n_a + 1) as f64).collect();
            let mut wrong = vec![("without 1/(n_a + 1)".to_string(), without_mean)];
            for (s, density) in single.into_iter().enumerate() {
                wrong.push((format!("split {s} of 0..={n_a} alone"), density));
            }
            for (flaw, density) in wrong {
                let stat = chi_square(&counts, rest, &density);
                println!("  {flaw}: chi-square {stat:.1}");
                assert!(
                    stat > 10.0 * threshold,
                    "{name}: {flaw} not rejected: {stat}"
                );
            }
        }
    }

    /// The ratio: every proposal of every discrete choice (lengths 3 to 5) from a
    /// 3- and a 4-vertex path, against f(y)T(y→x) / (f(x)T(x→y)) with T and f from the
    /// formulas above. Covers length changes (where (n_a + 1)/(n_d + 1) and the p_del of the
    /// reverse move differ from 1), new light points (s = 0 splits) and new lens points.
    /// Leaving out any factor of the ratio would miss by far more than the tolerance (the
    /// test counts the proposals on which each such flaw would be caught).
    #[test]
    fn ratio_matches_independent_transfer_densities() {
        let scene = scene();
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let pinhole = Pinhole::new();
        let [light, wall, floor, lens] = vertices(&space);
        let mutation = Bidirectional {
            min_vertices: 3,
            max_vertices: 5,
        };
        let tolerance = 1e-3;
        // Per (n_d, n_a): proposals compared, the worst relative error, and how many of them
        // would be caught without (n_a + 1)/(n_d + 1), without the p_del ratio and without
        // H(x)/H(y).
        let mut classes = std::collections::BTreeMap::<(usize, usize), (u32, f64, [u32; 3])>::new();
        let (mut skipped, mut identities) = (0, 0);
        for (index, x) in [vec![light, floor, lens], vec![light, wall, floor, lens]]
            .iter()
            .enumerate()
        {
            let (mut y, mut eye) = (Vec::new(), Vec::new());
            for i in 0..300_000 {
                let mut rng = Rng::new(0x4A71 + index as u64, i);
                let c = Choice::peek(x.len(), &rng);
                let Some(proposal) =
                    mutation.propose(&space, x, &mut y, &mut eye, &mut rng, &mut 0)
                else {
                    continue;
                };
                if y == *x {
                    // Nothing replaced, or only the lens point (the eye again).
                    assert_eq!(proposal.ratio, 1.0, "{c:?}: identity");
                    identities += 1;
                    continue;
                }
                // Keeping the lens and going on past it (a = n − 1, n_a > 0) is not a path
                // of the scene: `propose` refuses it.
                assert!(
                    !y[..y.len() - 1].iter().any(|v| v.p == camera.eye),
                    "{c:?}: through the lens"
                );
                if smallest_cosine(&y) < 0.02 || smallest_cosine(x) < 0.02 {
                    skipped += 1;
                    continue;
                }
                let expected = expected_ratio(&pinhole, x, &y, c);
                let error = (proposal.ratio as f64 / expected - 1.0).abs();
                let (n_d, n_a) = (c.deleted(), c.added());
                let counts = (n_a + 1) as f64 / (n_d + 1) as f64;
                let deletions = veach_deletion(c.a, c.a + n_a as isize + 1, y.len())
                    / veach_deletion(c.a, c.b, x.len());
                let without_h = counts * deletions;
                let caught = [expected / counts, expected / deletions, without_h]
                    .map(|flawed| ((flawed / expected - 1.0).abs() > 10.0 * tolerance) as u32);
                let entry = classes.entry((n_d, n_a)).or_default();
                entry.0 += 1;
                entry.1 = entry.1.max(error);
                for (total, c) in entry.2.iter_mut().zip(caught) {
                    *total += c;
                }
            }
        }
        println!("{identities} identities, {skipped} proposals with a grazing edge skipped");
        for (&(n_d, n_a), &(count, worst, caught)) in &classes {
            println!(
                "n_d {n_d} → n_a {n_a}: {count:6} compared, worst relative error {worst:.2e}; \
                 caught without (n_a+1)/(n_d+1): {}, without the p_del ratio: {}, without \
                 H(x)/H(y): {}",
                caught[0], caught[1], caught[2]
            );
            assert!(
                worst < tolerance,
                "n_d {n_d} → n_a {n_a}: ratio error {worst}"
            );
        }
        // Enough length changes, both ways and by up to two, and replacements of two
        // vertices were compared.
        for class in [
            (1, 2),
            (2, 1),
            (1, 3),
            (2, 2),
            (3, 2),
            (0, 1),
            (1, 0),
            (3, 4),
            (4, 3),
        ] {
            let (count, _, _) = classes.get(&class).copied().unwrap_or_default();
            assert!(count >= 50, "{class:?}: {count} compared");
        }
        let total = |k: usize| classes.values().map(|e| e.2[k]).sum::<u32>();
        let compared: u32 = classes.values().map(|e| e.0).sum();
        println!(
            "{compared} compared; caught {} / {} / {}",
            total(0),
            total(1),
            total(2)
        );
        assert!(total(0) > 10_000 && total(1) > 10_000);
        assert!(total(2) as f64 > 0.95 * compared as f64);
    }

    /// The chain test's cells: 3-vertex paths by their middle vertex (floor 4×4, wall 4×2),
    /// then 4-vertex paths by the vertex before the lens (floor 2×2, wall 2×1).
    fn chain_grids() -> (Grid, Grid) {
        (
            Grid(vec![(Surface::Floor, 4, 4), (Surface::Wall, 4, 2)]),
            Grid(vec![(Surface::Floor, 2, 2), (Surface::Wall, 2, 1)]),
        )
    }

    fn chain_cell(path: &[PathVertex]) -> usize {
        let (three, four) = chain_grids();
        let v = &path[path.len() - 2];
        let cell = |grid: &Grid| grid.cell(Surface::of(v), v.p.as_dvec3()).expect("a cell");
        match path.len() {
            3 => cell(&three),
            4 => three.len() + cell(&four),
            n => panic!("a path of {n} vertices"),
        }
    }

    /// The chain's target over the cells: ∫ f over the paths of each, normalized, by the
    /// midpoint rule with `m` × `m` nodes per cell (of the vertex binned; the light and the
    /// other vertex of 4-vertex paths on fixed grids).
    fn chain_target(pinhole: &Pinhole, lens: PathVertex, m: usize) -> Vec<f64> {
        let (three, four) = chain_grids();
        let lights = Grid(vec![(Surface::Light, 1, 1)]).nodes(6);
        let mut target = vec![0.0; three.len() + four.len()];
        // 3 vertices: light → z → lens.
        for (cell, z, weight) in three.nodes(m) {
            for &(_, l, light_weight) in &lights {
                target[cell] += weight * light_weight * contribution(pinhole, &[l, z, lens]);
            }
        }
        // 4 vertices: light → z1 → z2 → lens. f factors into the light's irradiance-like
        // ∫ Le G(l, z1) dl at z1, ρ1/π, G(z1, z2), ρ2/π and z2's camera factor (checked against
        // `contribution` on a few nodes): floor and wall see each other and the light front
        // to front, and G = 0 within one surface.
        let firsts = Grid(vec![(Surface::Floor, 4, 4), (Surface::Wall, 4, 1)]).nodes(m);
        let irradiance: Vec<f64> = firsts
            .iter()
            .map(|(_, z1, _)| {
                lights
                    .iter()
                    .map(|(_, l, w)| w * EMISSION as f64 * geometry(l, z1))
                    .sum()
            })
            .collect();
        let seconds = four.nodes(m);
        for (k, &(cell, z2, w2)) in seconds.iter().enumerate() {
            let camera_factor = pinhole.density(&z2);
            let albedo2 = Surface::of(&z2).albedo() / PI;
            for (j, (&(_, z1, w1), &e)) in firsts.iter().zip(&irradiance).enumerate() {
                let f = e
                    * luminance(Surface::of(&z1).albedo() / PI * albedo2)
                    * geometry(&z1, &z2)
                    * camera_factor;
                if (j * 7 + k * 13) % 100_003 == 0 {
                    let direct: f64 = lights
                        .iter()
                        .map(|(_, l, w)| w * contribution(pinhole, &[*l, z1, z2, lens]))
                        .sum();
                    assert!(
                        (direct - f).abs() <= 1e-9 * direct.abs().max(1e-12),
                        "{direct} vs {f}"
                    );
                }
                target[three.len() + cell] += w1 * w2 * f;
            }
        }
        let total: f64 = target.iter().sum();
        target.iter().map(|t| t / total).collect()
    }

    /// Which acceptance a chain uses: the mutation's ratio, or a flawed one.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Ratio {
        Correct,
        /// Without H(x)/H(y): the discrete choices' probabilities only.
        WithoutH,
        /// Without (n_a + 1)/(n_d + 1), the numbers of splits.
        WithoutSplitCounts,
        /// With p_del(a, b | n) in place of the reverse move's p_del(a, b' | n').
        WithoutReverseDeletion,
    }

    /// The cells of the final states of `chains` independent chains of `steps`
    /// bidirectional mutations each, over paths of 3 or 4 vertices, accepted with
    /// min(1, ratio) as `chain.rs` does. A share `long_share` of the chains starts from
    /// `long`, the others from `short`.
    fn final_states(
        space: &PathSpace,
        [short, long]: [&[PathVertex]; 2],
        long_share: f64,
        chains: u64,
        steps: usize,
        ratio: Ratio,
    ) -> Vec<u64> {
        let mutation = Bidirectional {
            min_vertices: 3,
            max_vertices: 4,
        };
        let (three, four) = chain_grids();
        let mut counts = vec![0u64; three.len() + four.len()];
        let (mut x, mut y, mut eye) = (Vec::new(), Vec::new(), Vec::new());
        for c in 0..chains {
            let mut rng = Rng::new(0xC4A1, c);
            x.clear();
            x.extend_from_slice(if (c as f64 + 0.5) / (chains as f64) < long_share {
                long
            } else {
                short
            });
            for _ in 0..steps {
                let choice = Choice::peek(x.len(), &rng);
                let Some(proposal) =
                    mutation.propose(space, &x, &mut y, &mut eye, &mut rng, &mut 0)
                else {
                    continue;
                };
                let (n_d, n_a) = (choice.deleted(), choice.added());
                let r = match ratio {
                    Ratio::Correct => proposal.ratio,
                    Ratio::WithoutH => {
                        proposal.ratio * split_density_sum(space, &y, choice.a, n_a)
                            / split_density_sum(space, &x, choice.a, n_d)
                    }
                    Ratio::WithoutSplitCounts => {
                        proposal.ratio * (n_d + 1) as f32 / (n_a + 1) as f32
                    }
                    Ratio::WithoutReverseDeletion => {
                        let b_reverse = choice.a + n_a as isize + 1;
                        proposal.ratio * deletion_probability(choice.a, choice.b, x.len())
                            / deletion_probability(choice.a, b_reverse, y.len())
                    }
                };
                if rng.uniform() < acceptance(1.0, 1.0, r) {
                    std::mem::swap(&mut x, &mut y);
                }
            }
            counts[chain_cell(&x)] += 1;
        }
        counts
    }

    /// Detailed balance: Metropolis chains with only the bidirectional
    /// mutation, over the paths of 3 and 4 vertices of the small scene, have f (its
    /// luminance) as their stationary distribution: the final states of many independent
    /// chains, by cell (the middle vertex of 3-vertex paths on a 4×4 floor and 4×2 wall grid,
    /// the vertex before the lens of 4-vertex paths on a 2×2 and 2×1 one), pass a chi-square
    /// test against ∫ f over the cells, integrated numerically from the formulas above
    /// (4-vertex paths carry 6% of it), and the 4-vertex share a z-test. Chains whose ratio
    /// lacks H(x)/H(y), the split counts or the reverse deletion probability fail both (the
    /// first two by far).
    ///
    /// The final states are independent draws from the chain's distribution after `steps`
    /// steps. Same-length moves are accepted about 90% of the time, but the length relaxes
    /// slowly (from 3-vertex starts only, the 4-vertex share was 0.023, 0.048, 0.061 and 0.063
    /// after 20, 50, 100 and 200 steps, for 0.062): so the chains start in each length in
    /// the target's proportions (from fixed paths: same-length moves forget them within a
    /// few steps), and run 200 steps.
    #[test]
    fn bidirectional_chain_samples_f_and_flawed_ratios_do_not() {
        let scene = scene();
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let pinhole = Pinhole::new();
        let [light, wall, floor, lens] = vertices(&space);
        let target = chain_target(&pinhole, lens, 24);
        // The quadrature has converged far below the counts' relative errors (2% and more).
        let coarse = chain_target(&pinhole, lens, 12);
        let quadrature_error = target
            .iter()
            .zip(&coarse)
            .map(|(t, c)| (c / t - 1.0).abs())
            .fold(0.0, f64::max);
        let long_share: f64 = target[chain_grids().0.len()..].iter().sum();
        println!(
            "target: 4-vertex share {long_share:.4}, quadrature m = 12 vs 24: {quadrature_error:.1e}"
        );
        assert!(quadrature_error < 5e-3);

        let (chains, steps) = (60_000, 200);
        let df = target.len() - 1;
        let threshold = chi_square_quantile(df, Z_999);
        let starts = [&[light, floor, lens][..], &[light, wall, floor, lens][..]];
        // The chi-square over the cells, and the z-score of the 4-vertex share (the length,
        // which the flaws that only touch length changes move most).
        let run = |ratio| {
            let counts = final_states(&space, starts, long_share, chains, steps, ratio);
            let stat = chi_square(&counts, 0, &target);
            let long = counts[chain_grids().0.len()..].iter().sum::<u64>() as f64 / chains as f64;
            let z = (long - long_share) / (long_share * (1.0 - long_share) / chains as f64).sqrt();
            println!(
                "{ratio:?}: chi-square {stat:.1} (df {df}, 99.9% quantile {threshold:.1}), \
                 4-vertex share {long:.4} (z {z:+.1})"
            );
            (stat, z, counts)
        };
        let (stat, z, counts) = run(Ratio::Correct);
        for (cell, (&c, &p)) in counts.iter().zip(&target).enumerate() {
            let e = p * chains as f64;
            println!(
                "  cell {cell:2}: {c:6} vs {e:8.1} (z {:+.2})",
                (c as f64 - e) / e.sqrt()
            );
        }
        assert!(
            stat < threshold,
            "correct chain: chi-square {stat} ≥ {threshold}"
        );
        assert!(
            z.abs() < Z_999,
            "correct chain: 4-vertex share off by {z} σ"
        );
        for flaw in [
            Ratio::WithoutH,
            Ratio::WithoutSplitCounts,
            Ratio::WithoutReverseDeletion,
        ] {
            let (stat, z, _) = run(flaw);
            assert!(
                stat > 1.5 * threshold && z.abs() > 2.0 * Z_999,
                "{flaw:?} not rejected: chi-square {stat}, z {z}"
            );
        }
    }

    /// Detailed balance with mixed lobes: the small scene's floor under a smooth clear coat
    /// (a Dirac mirror beside the rough non-metal's lobes with a density), so a path's state
    /// includes which lobe scatters it there (path_space/mod.rs, "Lobes"). Chains of the
    /// bidirectional mutation alone, over paths of 3 and 4 vertices, end in the cells of
    /// `chain_cell` and the lobe signatures of their inner vertices in the proportions of
    /// f: BDPT's MIS-weighted contributions, binned by the path and signature each strategy
    /// built (`Bdpt::strategy_path`), estimate ∫ f over each bin independently of the
    /// mutation. A chi-square test that counts both estimates' variances passes, and
    /// chains whose ratio leaves out the lobe choice's probability at the floor fail it.
    #[test]
    fn bidirectional_chain_samples_f_through_mixed_lobes() {
        use crate::integrators::SampleCounters;
        use crate::integrators::bdpt::Bdpt;
        let albedo = Surface::Floor.albedo().as_vec3().to_array();
        let floor = Material {
            clearcoat: 1.0,
            clearcoat_roughness: 0.0,
            ..Material::metallic_roughness(albedo, 0.0, 1.0)
        };
        let scene = scene_with_floor(Default::default(), floor);
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let cells = {
            let (three, four) = chain_grids();
            three.len() + four.len()
        };
        // A path's bin: its cell, and whether each inner vertex scatters through the
        // floor's Dirac lobe.
        let bin = |path: &[PathVertex]| {
            let signature = (1..path.len() - 1)
                .filter(|&k| space.is_specular(&path[k]))
                .fold(0, |bits, k| bits | 1 << (k - 1));
            chain_cell(path) * 4 + signature
        };
        let bins = 4 * cells;

        // BDPT's estimate of ∫ f over each bin, with its variance.
        let bdpt = Bdpt {
            scene: &scene,
            max_depth: 2,
            min_depth: 1,
            spectral: false,
        };
        let mut scratch = crate::integrators::PixelEstimator::scratch(&bdpt);
        let mut counters = SampleCounters::default();
        let mut rng = Rng::new(0x10b5, 0);
        let (mut sum, mut sum2) = (vec![0.0f64; bins], vec![0.0f64; bins]);
        let mut sample = vec![0.0f64; bins];
        let mut path = Vec::new();
        let samples = 400_000u32;
        for _ in 0..samples {
            let [fx, fy] = rng.uniform2();
            let (n_camera, n_light) = bdpt.trace_subpaths(
                &camera,
                fx * 8.0,
                fy * 8.0,
                4,
                3,
                &mut rng,
                &mut scratch,
                &mut counters,
            );
            sample.fill(0.0);
            for t in 1..=n_camera {
                for s in 0..=n_light {
                    if !(3..=4).contains(&(s + t)) || (s == 1 && t == 1) {
                        continue;
                    }
                    let Some(c) =
                        bdpt.connect(&camera, &mut scratch, s, t, &mut rng, &mut counters)
                    else {
                        continue;
                    };
                    let value = c.value.luminance() as f64;
                    if value.is_nan() || value <= 0.0 {
                        continue;
                    }
                    bdpt.strategy_path(&scratch, s, t, &mut path);
                    sample[bin(&path)] += value;
                }
            }
            for ((s, s2), v) in sum.iter_mut().zip(&mut sum2).zip(&sample) {
                *s += v;
                *s2 += v * v;
            }
        }
        let n = samples as f64;
        let total: f64 = sum.iter().sum();
        let target: Vec<f64> = sum.iter().map(|s| s / total).collect();
        // The variance of each share (the total's own noise is second order).
        let target_variance: Vec<f64> = sum
            .iter()
            .zip(&sum2)
            .map(|(s, s2)| (s2 / n - (s / n) * (s / n)) / (n - 1.0) / (total / n).powi(2))
            .collect();
        let mirror_share: f64 = (0..bins).filter(|b| b % 4 != 0).map(|b| target[b]).sum();
        println!("BDPT: share through the coat's mirror {mirror_share:.4}");
        assert!(
            mirror_share > 0.01,
            "the coat's mirror carries {mirror_share}"
        );

        // The chains: the correct ratio, and one without the lobe choice's probability
        // at the floor (C_s would not divide by it: the ratio gains P_y / P_x).
        let lobe_probability = |path: &[PathVertex]| -> f64 {
            (1..path.len() - 1)
                .filter(|&k| Surface::of(&path[k]) == Surface::Floor)
                .map(|k| {
                    let (wo, _) = super::super::direction(&path[k], &path[k + 1]).unwrap();
                    let bsdf = space.surface_bsdf(&path[k]);
                    let mirror = crate::bsdf::reflect(wo, bsdf.shading_normal());
                    let p = bsdf
                        .scatter_lobe(wo, mirror, TransportMode::Radiance, true)
                        .map_or(0.0, |s| s.pdf as f64);
                    if space.is_specular(&path[k]) {
                        p
                    } else {
                        1.0 - p
                    }
                })
                .product()
        };
        let [light, wall, floor, lens] = vertices(&space);
        let long_share: f64 = (0..bins)
            .filter(|b| b / 4 >= chain_grids().0.len())
            .map(|b| target[b])
            .sum();
        let mutation = Bidirectional {
            min_vertices: 3,
            max_vertices: 4,
        };
        let (chains, steps) = (20_000u64, 300);
        let run = |flawed: bool| {
            let mut counts = vec![0u64; bins];
            let (mut x, mut y, mut eye) = (Vec::new(), Vec::new(), Vec::new());
            for c in 0..chains {
                let mut rng = Rng::new(0xC0A7, c);
                x.clear();
                if (c as f64 + 0.5) / (chains as f64) < long_share {
                    x.extend_from_slice(&[light, wall, floor, lens]);
                } else {
                    x.extend_from_slice(&[light, floor, lens]);
                }
                for _ in 0..steps {
                    let Some(proposal) =
                        mutation.propose(&space, &x, &mut y, &mut eye, &mut rng, &mut 0)
                    else {
                        continue;
                    };
                    let mut r = proposal.ratio as f64;
                    if flawed {
                        r *= lobe_probability(&y) / lobe_probability(&x);
                    }
                    if rng.uniform() < acceptance(1.0, 1.0, r as f32) {
                        std::mem::swap(&mut x, &mut y);
                    }
                }
                counts[bin(&x)] += 1;
            }
            // Pearson's statistic with both estimates' variances, over the bins BDPT
            // reaches (the others must stay empty).
            let m = chains as f64;
            let (mut stat, mut df, mut stray) = (0.0, 0usize, 0u64);
            for (b, ((&count, &p), &var)) in
                counts.iter().zip(&target).zip(&target_variance).enumerate()
            {
                if p <= 0.0 {
                    stray += count;
                    continue;
                }
                let expected = m * p;
                let term = (count as f64 - expected).powi(2) / (expected + m * m * var);
                if term > 4.0 {
                    println!(
                        "  bin {b}: {count} against {expected:.1} (reference σ {:.1})",
                        m * var.sqrt()
                    );
                }
                stat += term;
                df += 1;
            }
            let mirror: u64 = (0..bins).filter(|b| b % 4 != 0).map(|b| counts[b]).sum();
            println!(
                "flawed {flawed}: chi-square {stat:.1} on {df} bins (99.9% quantile {:.1}), \
                 through the mirror {:.4}, {stray} in bins BDPT never reached",
                chi_square_quantile(df - 1, Z_999),
                mirror as f64 / m
            );
            (stat, chi_square_quantile(df - 1, Z_999), stray)
        };
        let (stat, threshold, stray) = run(false);
        assert!(
            stat < threshold && stray == 0,
            "chi-square {stat} ≥ {threshold}"
        );
        let (stat, threshold, _) = run(true);
        assert!(
            stat > 2.0 * threshold,
            "without the lobe probability: chi-square {stat} < 2 × {threshold}"
        );
    }
}
