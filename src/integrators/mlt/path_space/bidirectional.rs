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
//! specular vertex) have p_i = 0 and no term. This is Veach's form (the sum over splits);
//! every term comes from `PathSpace::unweighted_contribution`, which the tests check
//! against BDPT strategy by strategy.

use super::{PathSpace, PathVertex};
use crate::accel::Ray;
use crate::bsdf::{self, TransportMode};
use crate::integrators::spawn_ray;
use crate::sampling::{OrthonormalBasis, Rng, cosine_hemisphere, uniform_triangle};
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
            let luminance = crate::scene::luminance(c);
            (luminance > 0.0).then(|| 1.0 / luminance)
        })
        .sum()
}

/// A proposal's outcome: the new path is in the output buffer, with this acceptance
/// ratio's factor f(y)T(y→x) / (f(x)T(x→y)).
pub(crate) struct Proposal {
    pub ratio: f32,
    pub value: Vec3A,
    pub pixel: u32,
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
        let n_new = n - deleted + added;
        if n_new < self.min_vertices || n_new > self.max_vertices {
            return None;
        }
        let from_light = ((rng.uniform() * (added + 1) as f32) as usize).min(added);
        let from_eye = added - from_light;

        // Light side: the kept prefix, then `from_light` sampled vertices.
        y.clear();
        y.extend_from_slice(&x[..(a + 1) as usize]);
        for _ in 0..from_light {
            let next = self.extend_light_side(space, y, rng, rays)?;
            y.push(next);
        }
        // Lens side: sampled backwards from the kept suffix into `eye` (lens-side order).
        let suffix = &x[b as usize..];
        eye.clear();
        for _ in 0..from_eye {
            let next = self.extend_eye_side(space, suffix, eye, rng, rays)?;
            eye.push(next);
        }
        let s = y.len();
        y.extend(eye.iter().rev());
        y.extend_from_slice(suffix);
        debug_assert_eq!(y.len(), n_new);
        if s >= 1 && s < y.len() {
            let lens_index = y.len() - 1;
            if !space.visible(&y[s - 1], &y[s], s == lens_index, rays) {
                return None;
            }
        }
        let (value, pixel) = space.unweighted_contribution(y, s, true)?;
        let h_y = split_density_sum(space, y, a, added);
        let h_x = split_density_sum(space, x, a, deleted);
        let b_new = a + added as isize + 1;
        let ratio = (added + 1) as f32 * deletion_probability(a, b_new, n_new) * h_x
            / ((deleted + 1) as f32 * deletion_probability(a, b, n) * h_y);
        Some(Proposal {
            ratio,
            value,
            pixel,
        })
    }

    /// The next vertex of the light side whose vertices so far are `path` (none: a new
    /// light point).
    fn extend_light_side(
        &self,
        space: &PathSpace,
        path: &[PathVertex],
        rng: &mut Rng,
        rays: &mut u64,
    ) -> Option<PathVertex> {
        let scene = space.scene;
        match path {
            [] => {
                if scene.lights.is_empty() {
                    return None;
                }
                let (index, _, _) = scene.light_distribution.sample_discrete(rng.uniform());
                let light = &scene.lights[index];
                let [b1, b2] = uniform_triangle(rng.uniform2());
                Some(PathVertex {
                    p: light.v0 + light.edge1 * b1 + light.edge2 * b2,
                    normal: light.normal,
                    triangle: light.triangle,
                })
            }
            [light] => {
                let local = cosine_hemisphere(rng.uniform2());
                if local.z <= 0.0 {
                    return None;
                }
                let direction = OrthonormalBasis::from_normal(light.normal).to_world(local);
                space.trace(&spawn_ray(scene, light.p, light.normal, direction), rays)
            }
            [.., previous, end] => {
                let wi = sample_direction(space, previous, end, TransportMode::Importance, rng)?;
                space.trace(&spawn_ray(scene, end.p, end.normal, wi), rays)
            }
        }
    }

    /// The next vertex of the lens side: `eye` holds its sampled vertices so far (nearest
    /// the lens first), continuing the kept `suffix` (empty: a new lens point).
    fn extend_eye_side(
        &self,
        space: &PathSpace,
        suffix: &[PathVertex],
        eye: &[PathVertex],
        rng: &mut Rng,
        rays: &mut u64,
    ) -> Option<PathVertex> {
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
            return Some(PathVertex {
                p: lens,
                normal: camera.forward,
                triangle: 0,
            });
        };
        let Some(previous) = previous else {
            // The end is the lens: a new film position, uniform over the film.
            let [u, v] = rng.uniform2();
            let direction =
                camera.direction_through(end.p, u * camera.width as f32, v * camera.height as f32);
            return space.trace(&Ray::new(end.p, direction, 0.0, f32::INFINITY), rays);
        };
        let wi = sample_direction(space, previous, end, TransportMode::Radiance, rng)?;
        space.trace(&spawn_ray(space.scene, end.p, end.normal, wi), rays)
    }
}

/// A scattering direction at `at`, arrived at from `from`, sampled by its BSDF.
#[inline]
fn sample_direction(
    space: &PathSpace,
    from: &PathVertex,
    at: &PathVertex,
    mode: TransportMode,
    rng: &mut Rng,
) -> Option<Vec3A> {
    let wo = (from.p - at.p).normalize();
    let shading = &space.scene.shading[at.triangle as usize];
    let material = &space.scene.materials[shading.material as usize];
    let s = bsdf::sample(material, at.normal, wo, rng.uniform2(), rng.uniform(), mode)?;
    Some(s.wi)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
