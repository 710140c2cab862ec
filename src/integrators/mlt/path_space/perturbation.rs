//! Veach's perturbations (thesis §11.4.3–11.4.4): small moves that keep a path's length and
//! its pattern of specular (S) and non-specular (D) vertices, for the features bidirectional
//! mutations find hard to explore (caustics, glossy and mirrored views).
//!
//! - **Lens perturbation** (paths `… D D S* E`, or `L S* E`): move the film point by a
//!   random offset, trace from the (unchanged) lens point through the same specular lobes
//!   to a non-specular vertex, and connect it to the kept vertex before it.
//! - **Multi-chain perturbation** (`… S D S* E`, where the lens perturbation cannot connect):
//!   as the lens perturbation, but at each non-specular vertex whose predecessor is specular
//!   the direction onwards is perturbed by a small angle and traced through the next
//!   specular chain, until a vertex can be connected (or the light is reached).
//! - **Caustic perturbation** (`… D S+ D E`): perturb the direction leaving the non-specular
//!   vertex before the specular chain by a small angle, trace through the chain to a new
//!   last vertex and connect it to the lens.
//!
//! # Transfer ratios
//!
//! The film offset has a density that depends only on its length, so it is symmetric in
//! film coordinates, and so is the angle kernel in solid angle (it depends only on the angle
//! between the old and the new direction). The rest of each move is deterministic. Writing
//! T in path measure, the symmetric kernels cancel and what remains are the Jacobians from
//! film coordinates or directions to the moved vertices. Those are the densities of BDPT's
//! strategy with the same split, with the specular lobes taken as given (`lobes_sampled`
//! false: a perturbation keeps each vertex's lobe) and without the BSDF density of the
//! perturbed directions (the kernel replaced it). So, with s the kept light vertices:
//!
//! ```text
//! f(y) T(y→x)   |C_s(y)| · Π p_σ(y, ω_d)
//! ----------- = ------------------------
//! f(x) T(x→y)   |C_s(x)| · Π p_σ(x, ω_d)
//! ```
//!
//! over the vertices d whose outgoing direction was perturbed (their BSDF or emission
//! density of that direction, which C_s divided by). The film offset needs no such factor:
//! the camera samples film points uniformly, and C_s's camera factor is already per unit of
//! film area.

use super::bidirectional::Proposal;
use super::{PathSpace, PathVertex, direction};
use crate::accel::Ray;
use crate::bsdf::{self, SpecularLobe};
use crate::integrators::spawn_ray;
use crate::sampling::{OrthonormalBasis, Rng};
use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, TAU};

/// The sizes of the perturbations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PerturbationSizes {
    /// Film offsets range from this many pixels …
    pub film_min: f32,
    /// … to this many, with density ∝ 1/r² over the annulus (Veach's choice).
    pub film_max: f32,
    /// Direction perturbations range from this angle (radians) …
    pub angle_min: f32,
    /// … to this one, also with density ∝ 1/θ in θ.
    pub angle_max: f32,
}

impl PerturbationSizes {
    /// Veach's sizes: film offsets from 0.1 pixel to the radius of a disc covering 5% of the
    /// image; angles from 0.0001 to 0.1 radians.
    pub fn for_image(width: u32, height: u32) -> Self {
        PerturbationSizes {
            film_min: 0.1,
            film_max: (0.05 * width as f32 * height as f32 / std::f32::consts::PI)
                .sqrt()
                .max(1.0),
            angle_min: 1e-4,
            angle_max: 0.1,
        }
    }
}

/// A length between `min` and `max` with density ∝ 1/r (log-uniform).
#[inline]
fn log_uniform(min: f32, max: f32, u: f32) -> f32 {
    max * (min / max).powf(u)
}

/// `w` turned by a log-uniform angle in [min, max] towards a uniform azimuth: a density on
/// the sphere that depends only on the angle between `w` and the result.
#[inline]
fn perturb_direction(w: Vec3A, sizes: &PerturbationSizes, rng: &mut Rng) -> Vec3A {
    let theta = log_uniform(sizes.angle_min, sizes.angle_max, rng.uniform());
    let phi = TAU * rng.uniform();
    let basis = OrthonormalBasis::from_normal(w);
    let local = Vec3A::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    );
    basis.to_world(local).normalize()
}

/// The first non-specular vertex before the lens (the light, x_0, at the latest).
#[inline]
fn first_non_specular_from_lens(space: &PathSpace, x: &[PathVertex]) -> usize {
    (1..x.len() - 1)
        .rev()
        .find(|&k| !space.is_specular(&x[k]))
        .unwrap_or(0)
}

/// Which perturbations a path admits. Perturbations keep the pattern of specular vertices,
/// so a proposal admits the same ones as the path it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Applicable {
    /// The lens perturbation (else the multi-chain one: exactly one applies).
    pub lens: bool,
    pub caustic: bool,
}

pub(crate) fn applicable(space: &PathSpace, x: &[PathVertex]) -> Applicable {
    let n = x.len();
    let m = first_non_specular_from_lens(space, x);
    let lens = m == 0 || !space.is_specular(&x[m - 1]);
    let caustic = n >= 4 && !space.is_specular(&x[n - 2]) && space.is_specular(&x[n - 3]);
    Applicable { lens, caustic }
}

/// The lobe vertex `k` of `x` scatters through (x_{k+1} → x_k → x_{k-1}).
#[inline]
fn lobe_at(x: &[PathVertex], k: usize) -> Option<SpecularLobe> {
    let (wo, _) = direction(&x[k], &x[k + 1])?;
    let (wi, _) = direction(&x[k], &x[k - 1])?;
    Some(SpecularLobe::of(x[k].normal, wo, wi))
}

/// The density with which vertex `at` (a light, `from` = `None`, or a non-specular surface
/// arrived at from `from`) samples direction `wi`: what C_s divides by there.
#[inline]
fn direction_density(
    space: &PathSpace,
    from: Option<&PathVertex>,
    at: &PathVertex,
    wi: Vec3A,
) -> f32 {
    match from {
        None => (wi.dot(at.normal) * FRAC_1_PI).max(0.0),
        Some(from) => match direction(at, from) {
            Some((wo, _)) => bsdf::pdf(space.material(at), at.normal, wo, wi),
            None => 0.0,
        },
    }
}

/// The lens perturbation, or with `multi_chain` the multi-chain perturbation, of `x` into
/// `y`. `None`: the chain stays (the move does not apply, leaves the film, or changes the
/// path's pattern).
pub(crate) fn lens(
    space: &PathSpace,
    sizes: &PerturbationSizes,
    multi_chain: bool,
    x: &[PathVertex],
    y: &mut Vec<PathVertex>,
    rng: &mut Rng,
    rays: &mut u64,
) -> Option<Proposal> {
    let n = x.len();
    if applicable(space, x).lens == multi_chain {
        return None;
    }
    let camera = space.camera;
    let lens = &x[n - 1];
    let (to_scene, _) = direction(lens, &x[n - 2])?;
    let [fx, fy] = camera.raster_position(lens.p, to_scene)?;
    let radius = log_uniform(sizes.film_min, sizes.film_max, rng.uniform());
    let phi = TAU * rng.uniform();
    let (fx, fy) = (fx + radius * phi.cos(), fy + radius * phi.sin());
    if !(0.0..camera.width as f32).contains(&fx) || !(0.0..camera.height as f32).contains(&fy) {
        return None;
    }
    y.clear();
    y.extend_from_slice(x);
    let mut ray = Ray::new(
        lens.p,
        camera.direction_through(lens.p, fx, fy),
        0.0,
        f32::INFINITY,
    );
    // Densities of the perturbed directions (multi-chain), in y and in x.
    let (mut density_y, mut density_x) = (1.0f32, 1.0f32);
    let mut k = n - 2;
    let s = loop {
        let v = space.trace(&ray, rays)?;
        let specular = space.is_specular(&v);
        if k == 0 {
            // x's light was seen through the specular chain: so must y's.
            if specular {
                return None;
            }
            y[0] = v;
            break 0;
        }
        if specular != space.is_specular(&x[k]) {
            return None;
        }
        y[k] = v;
        if specular {
            let (wo, _) = direction(&y[k], &y[k + 1])?;
            let next =
                bsdf::specular_direction(space.material(&y[k]), v.normal, wo, lobe_at(x, k)?)?;
            ray = spawn_ray(space.scene, v.p, v.normal, next);
            k -= 1;
            continue;
        }
        if !space.is_specular(&x[k - 1]) {
            // Connect to the kept vertex before it.
            if !space.visible(&y[k], &y[k - 1], false, rays) {
                return None;
            }
            break k;
        }
        // Multi-chain: perturb the direction onwards and trace the next specular chain.
        let (old, _) = direction(&x[k], &x[k - 1])?;
        let new = perturb_direction(old, sizes, rng);
        ray = spawn_ray(space.scene, v.p, v.normal, new);
        // The density C_s divides by at this vertex: the BSDF's, from the lens side.
        density_y *= direction_density(space, Some(&y[k + 1]), &y[k], new);
        density_x *= direction_density(space, Some(&x[k + 1]), &x[k], old);
        k -= 1;
    };
    proposal(space, x, y, s, density_x, density_y)
}

/// The caustic perturbation of `x` into `y` (see the module documentation).
pub(crate) fn caustic(
    space: &PathSpace,
    sizes: &PerturbationSizes,
    x: &[PathVertex],
    y: &mut Vec<PathVertex>,
    rng: &mut Rng,
    rays: &mut u64,
) -> Option<Proposal> {
    let n = x.len();
    if !applicable(space, x).caustic {
        return None;
    }
    // The non-specular vertex the specular chain before x_{n-2} starts from.
    let c = (1..n - 3)
        .rev()
        .find(|&k| !space.is_specular(&x[k]))
        .unwrap_or(0);
    let (old, _) = direction(&x[c], &x[c + 1])?;
    let new = perturb_direction(old, sizes, rng);
    let from = c.checked_sub(1).map(|i| &x[i]);
    let density_y = direction_density(space, from, &x[c], new);
    let density_x = direction_density(space, from, &x[c], old);
    if density_y <= 0.0 {
        return None;
    }
    y.clear();
    y.extend_from_slice(x);
    let mut ray = spawn_ray(space.scene, x[c].p, x[c].normal, new);
    for k in c + 1..=n - 2 {
        let v = space.trace(&ray, rays)?;
        let specular = space.is_specular(&v);
        if specular != space.is_specular(&x[k]) {
            return None;
        }
        y[k] = v;
        if k < n - 2 {
            let (wo, _) = direction(&y[k], &y[k - 1])?;
            // x's lobe at k, seen from the light side (x_{k-1} → x_k → x_{k+1}).
            let (wo_x, _) = direction(&x[k], &x[k - 1])?;
            let (wi_x, _) = direction(&x[k], &x[k + 1])?;
            let lobe = SpecularLobe::of(x[k].normal, wo_x, wi_x);
            let next = bsdf::specular_direction(space.material(&y[k]), v.normal, wo, lobe)?;
            ray = spawn_ray(space.scene, v.p, v.normal, next);
        }
    }
    if !space.visible(&y[n - 2], &y[n - 1], true, rays) {
        return None;
    }
    proposal(space, x, y, n - 1, density_x, density_y)
}

/// The proposal y of a perturbation of x that kept s light vertices, with the densities of
/// the perturbed directions (see the module documentation for the ratio).
fn proposal(
    space: &PathSpace,
    x: &[PathVertex],
    y: &[PathVertex],
    s: usize,
    density_x: f32,
    density_y: f32,
) -> Option<Proposal> {
    let (value, pixel) = space.unweighted_contribution(y, s, false)?;
    let (value_x, _) = space.unweighted_contribution(x, s, false)?;
    let ratio =
        crate::scene::luminance(value) * density_y / (crate::scene::luminance(value_x) * density_x);
    Some(Proposal {
        ratio,
        value,
        pixel,
    })
}
