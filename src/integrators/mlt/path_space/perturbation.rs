//! Veach's perturbations (thesis §11.4.3–11.4.4): small moves that keep a path's length and
//! its pattern of vertex classes, for the features bidirectional mutations find hard to
//! explore (caustics, glossy and mirrored views).
//!
//! Veach classes vertices as specular (S) or not (D). A sharp glossy lobe is neither: it
//! has a density, so a connection can end there, but a connection across it (or a
//! direction turned at random) is almost always outside the lobe. So the perturbations
//! know a third class, G (`PathSpace::class`: every lobe glossy), and trace through glossy
//! vertices as through specular ones, moving each one's microfacet by a small step instead
//! of keeping its lobe exactly (below). "Chain" means a run of S and G vertices. On a
//! surface with a Dirac lobe beside a diffuse one the class is the lobe the path records
//! there (parent module, "Lobes"): a retraced vertex keeps x's, and a move that finds a
//! surface without it is refused.
//!
//! - **Lens perturbation** (paths `… D D (S|G)* E`, or `L (S|G)* E`): move the film point by
//!   a random offset, trace from the (unchanged) lens point through the chain to a diffuse
//!   vertex, and connect it to the kept vertex before it (D or G).
//! - **Multi-chain perturbation** (`… S D (S|G)* E`, where the lens perturbation cannot
//!   connect): as the lens perturbation, but at each diffuse vertex whose predecessor is
//!   specular the direction onwards is perturbed by a small angle and traced through the
//!   next chain, until a vertex can be connected (or the light is reached).
//! - **Caustic perturbation** (`… D (S|G)+ D E`): perturb the direction leaving the diffuse
//!   vertex before the chain by a small angle, trace through the chain to a new last vertex
//!   and connect it to the lens.
//!
//! Lights that are not triangles: the lens and multi-chain perturbations keep x_0 unless
//! they trace to it (`L (S|G)* E`), and then a light at infinity is found by a ray that
//! leaves the scene, a triangle by one that hits it: a proposal whose light changes kind is
//! refused (both ways), so the perturbations keep the light's kind and with it the
//! applicable perturbations. The caustic perturbation does not apply when its chain starts
//! at a light that is not a triangle (`L S+ D E` under a point light or from infinity): a
//! point light's emission is not cosine-weighted about a normal and a direction's starts
//! anywhere on a disc, so there is no emitted direction to turn within the densities
//! above. Those paths are still explored by the bidirectional mutation.
//!
//! # Transfer ratios
//!
//! The film offset has a density that depends only on its length, so it is symmetric in
//! film coordinates, and so is the angle kernel in solid angle (it depends only on the angle
//! between the old and the new direction). The rest of each move is deterministic. Writing
//! T in path measure, the symmetric kernels cancel and what remains are the Jacobians from
//! film coordinates or directions to the moved vertices. Those are the densities of BDPT's
//! strategy with the same split, with the specular lobes taken as given (`lobes_sampled`
//! false: a perturbation keeps each vertex's lobe), except at the vertices d whose
//! direction onwards the move chose (turned, or found through a moved microfacet): C_s
//! divided by their sampling density p_σ(ω_d), while the move's density there is the
//! kernel's times q(ω_d), the Jacobian of its map onto the direction. So, with s the kept
//! light vertices:
//!
//! ```text
//! f(y) T(y→x)   |C_s(y)| · Π p_σ(y, ω_d) / q(y, ω_d)
//! ----------- = -----------------------------------
//! f(x) T(x→y)   |C_s(x)| · Π p_σ(x, ω_d) / q(x, ω_d)
//! ```
//!
//! (`moved_direction_factor`). A turned direction has q = 1. A glossy vertex's direction
//! is found through a microfacet normal m turned within the cone, keeping its reflection or
//! refraction: q = dω_m/dω_d (Walter et al. 2007), and p_σ / q is the lobe's
//! probability times the density of visible normals D_ω(m) (Heitz 2018). The film offset
//! needs no factor: the camera samples film points uniformly, and C_s's camera factor is
//! already per unit of film area.
//!
//! # Steps in the BSDF's sample space
//!
//! With `RandomKernel::in_sample_space`, a direction is perturbed where the vertex samples
//! it: its coordinates u in the vertex's sampling take a small symmetric step, and the new
//! direction is the sampling's image of the new u at the new vertex. At a diffuse vertex or
//! a light that is the cosine-weighted sampling (p_σ = cos θ / π for a Lambertian surface or
//! an emitter): the steps are wide where the lobe is wide and fine towards grazing angles.
//! At a glossy vertex it is the sampling of the normals visible from the direction the
//! path arrives from (`TrowbridgeReitz::visible_normal_coordinates` inverts it): the steps
//! follow the lobe, fine where it is sharp. The map from u to directions has Jacobian
//! 1 / q with q the sampling's own density (cos θ / π; D_ω(m) dω_m/dω_d), so the symmetric
//! step cancels and, where q is the BSDF's whole density, so does p_σ / q: a Lambertian or
//! metal vertex adds no factor, a rough glass one the probability of its reflection or
//! refraction.

use super::bidirectional::Proposal;
use super::{PathSpace, PathVertex, VertexClass, direction};
use crate::accel::Ray;
use crate::bsdf::{Microfacet, SpecularLobe};
use crate::integrators::spawn_ray;
use crate::sampling::{OrthonormalBasis, Rng};
use crate::spectral::{Channels, SampledWavelengths};
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

/// The coordinates (sin² θ, φ / 2π) of direction `w` in the cosine-weighted sampling of the
/// hemisphere around `normal`: the inverse of `from_sample_space`.
#[inline]
fn to_sample_space(normal: Vec3A, w: Vec3A) -> [f32; 2] {
    let basis = OrthonormalBasis::from_normal(normal);
    let (x, y) = (basis.tangent.dot(w), basis.bitangent.dot(w));
    let phi = y.atan2(x) * (1.0 / TAU);
    [
        (x * x + y * y).min(1.0),
        if phi < 0.0 { phi + 1.0 } else { phi },
    ]
}

/// The direction with sample-space coordinates `u` in the hemisphere around `normal`; its
/// density per unit solid angle is cos θ / π when u is uniform.
#[inline]
fn from_sample_space(normal: Vec3A, [u1, u2]: [f32; 2]) -> Vec3A {
    let basis = OrthonormalBasis::from_normal(normal);
    let (sin_theta, cos_theta) = (u1.sqrt(), (1.0 - u1).max(0.0).sqrt());
    let (sin_phi, cos_phi) = (TAU * u2).sin_cos();
    basis
        .to_world(Vec3A::new(
            sin_theta * cos_phi,
            sin_theta * sin_phi,
            cos_theta,
        ))
        .normalize()
}

/// `u` folded back into [0, 1] by reflection at both ends: with a symmetric step, the
/// folded walk is symmetric too (each image of the step has its mirror image).
#[inline]
fn reflect_into_unit(u: f32) -> f32 {
    let v = u.rem_euclid(2.0);
    if v > 1.0 { 2.0 - v } else { v }
}

/// Where a perturbation's random moves come from. Each is symmetric: a move and its
/// reverse have the same density.
pub(crate) trait Kernel {
    /// An offset of the film position, in pixels.
    fn film_offset(&mut self) -> [f32; 2];
    /// `w` turned by a small angle, with a density on the sphere that depends only on the
    /// angle.
    fn turn(&mut self, w: Vec3A) -> Vec3A;
    /// Sample-space coordinates moved by a small step: u[0] folded into [0, 1] at both
    /// ends, u[1] (an angle) wrapped.
    fn step(&mut self, u: [f32; 2]) -> [f32; 2];
    /// Whether directions and microfacets move in their samplings' coordinates (`step`)
    /// rather than by turns (see the module docs).
    fn in_sample_space(&self) -> bool;
    /// The random number a path's wavelengths are drawn from (`SampledWavelengths::u`)
    /// moved by a small step, wrapped into [0, 1).
    fn wavelength_step(&mut self, u: f32) -> f32;
}

/// Steps of the wavelengths' random number range from this length …
const WAVELENGTH_STEP_MIN: f32 = 1e-4;
/// … to this one (a tenth of the visible range's probability, about 25 nm about green),
/// with density ∝ 1/length.
const WAVELENGTH_STEP_MAX: f32 = 0.1;

/// `u` (a path's wavelengths' random number) moved by a step of log-uniform length between
/// `WAVELENGTH_STEP_MIN` and `WAVELENGTH_STEP_MAX` either way, wrapped into [0, 1): a
/// symmetric move.
#[inline]
pub(crate) fn step_wavelength_number(u: f32, rng: &mut Rng) -> f32 {
    let length = log_uniform(WAVELENGTH_STEP_MIN, WAVELENGTH_STEP_MAX, rng.uniform());
    let signed = if rng.uniform() < 0.5 { -length } else { length };
    let wrapped = (u + signed).rem_euclid(1.0);
    // rem_euclid of a tiny negative number rounds to 1.
    if wrapped < 1.0 { wrapped } else { 0.0 }
}

/// The perturbations' kernels: symmetric, of the given sizes; directions turned within a
/// cone or, `in_sample_space`, stepped in the vertex's sample space (module docs).
pub(crate) struct RandomKernel<'a> {
    pub sizes: &'a PerturbationSizes,
    pub in_sample_space: bool,
    pub rng: &'a mut Rng,
}

impl Kernel for RandomKernel<'_> {
    #[inline]
    fn film_offset(&mut self) -> [f32; 2] {
        let radius = log_uniform(self.sizes.film_min, self.sizes.film_max, self.rng.uniform());
        let phi = TAU * self.rng.uniform();
        [radius * phi.cos(), radius * phi.sin()]
    }

    #[inline]
    fn turn(&mut self, w: Vec3A) -> Vec3A {
        perturb_direction(w, self.sizes, self.rng)
    }

    #[inline]
    fn step(&mut self, [u1, u2]: [f32; 2]) -> [f32; 2] {
        // A step of log-uniform length towards a uniform angle: symmetric in u.
        let length = log_uniform(
            self.sizes.angle_min,
            self.sizes.angle_max,
            self.rng.uniform(),
        );
        let (sin, cos) = (TAU * self.rng.uniform()).sin_cos();
        [
            reflect_into_unit(u1 + length * cos),
            (u2 + length * sin).rem_euclid(1.0),
        ]
    }

    fn in_sample_space(&self) -> bool {
        self.in_sample_space
    }

    #[inline]
    fn wavelength_step(&mut self, u: f32) -> f32 {
        step_wavelength_number(u, self.rng)
    }
}

/// A direction near `old`, which left a diffuse vertex (or a light) sampling directions
/// around `old_side` (its sampling hemisphere's normal), for the vertex sampling around
/// `new_side`: turned, or stepped in the cosine-weighted sampling's coordinates. `None`:
/// the new direction has no density there (the move is refused).
#[inline]
fn perturbed_direction(
    kernel: &mut impl Kernel,
    old: Vec3A,
    old_side: Vec3A,
    new_side: Vec3A,
) -> Option<Vec3A> {
    if !kernel.in_sample_space() {
        return Some(kernel.turn(old));
    }
    let [u1, u2] = kernel.step(to_sample_space(old_side, old));
    // At u1 = 1 the direction is tangent to the surface: density 0.
    (u1 < 1.0).then(|| from_sample_space(new_side, [u1, u2]))
}

/// The direction onwards from glossy vertex `at` of y (in `space_y`), arrived at along
/// `-wo`: through x's microfacet (in `space_x`) at its vertex (`x_at`, between `x_from`
/// and `x_onwards`), moved by the kernel (turned, or stepped in the coordinates of the normals visible from y's
/// direction back), keeping its reflection or refraction. `None` if the moved microfacet
/// does not scatter the path onwards.
#[inline]
fn glossy_onwards(
    [space_x, space_y]: [&PathSpace; 2],
    kernel: &mut impl Kernel,
    [x_from, x_at, x_onwards]: [&PathVertex; 3],
    wo: Vec3A,
    at: &PathVertex,
) -> Option<Vec3A> {
    let (wo_x, _) = direction(x_at, x_from)?;
    let (wi_x, _) = direction(x_at, x_onwards)?;
    let bsdf_x = space_x.surface_bsdf(x_at);
    let microfacet = bsdf_x.microfacet(wo_x, wi_x)?;
    let bsdf = space_y.surface_bsdf(at);
    let moved = if kernel.in_sample_space() {
        // The sampling's coordinates are (azimuth, cap height): step folds the second.
        let [azimuth, height] = bsdf_x.microfacet_coordinates(wo_x, microfacet.normal)?;
        let [height, azimuth] = kernel.step([height, azimuth]);
        bsdf.microfacet_at(wo, [azimuth, height], microfacet.refracts)?
    } else {
        Microfacet {
            normal: kernel.turn(microfacet.normal),
            ..microfacet
        }
    };
    bsdf.scatter_through(wo, moved)
}

/// The normal of the hemisphere vertex `at` samples directions in: a light's front, or a
/// diffuse surface's side facing the vertex `from` it was arrived at from.
#[inline]
fn sampling_side(from: Option<&PathVertex>, at: &PathVertex) -> Vec3A {
    let toward = |from: &PathVertex| {
        if from.is_at_infinity() {
            from.normal
        } else {
            from.p - at.p
        }
    };
    match from {
        Some(from) if at.normal.dot(toward(from)) < 0.0 => -at.normal,
        _ => at.normal,
    }
}

/// The first diffuse vertex before the lens (the light, x_0, at the latest): where the
/// lens perturbation's chain of specular and glossy vertices from the lens ends.
#[inline]
fn first_diffuse_from_lens(space: &PathSpace, x: &[PathVertex]) -> usize {
    (1..x.len() - 1)
        .rev()
        .find(|&k| space.class(&x[k]) == VertexClass::Diffuse)
        .unwrap_or(0)
}

/// The space of a perturbation's proposal: x's, or in a spectral render, where none of the
/// vertices the move keeps (x_0 … x_{first_moved − 1}, and the lens) disperses, x's
/// wavelengths moved by the kernel's symmetric step (module docs, "Wavelengths").
fn proposal_space<'a>(
    space: &PathSpace<'a>,
    kernel: &mut impl Kernel,
    x: &[PathVertex],
    first_moved: usize,
) -> PathSpace<'a> {
    match space.channels {
        Channels::Wavelengths(w) if !(0..first_moved).any(|k| space.disperses_at(x, k)) => {
            let u = kernel.wavelength_step(w.u);
            space.with_channels(Channels::Wavelengths(SampledWavelengths::sample(u)))
        }
        _ => *space,
    }
}

/// Which perturbations a path admits. Perturbations keep the path's pattern of vertex
/// classes, so a proposal admits the same ones as the path it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Applicable {
    /// The lens perturbation (else the multi-chain one: exactly one applies).
    pub lens: bool,
    pub caustic: bool,
}

pub(crate) fn applicable(space: &PathSpace, x: &[PathVertex]) -> Applicable {
    let n = x.len();
    let m = first_diffuse_from_lens(space, x);
    let lens = m == 0 || !space.is_specular(&x[m - 1]);
    // A light that is not a triangle (a point light, a direction) has no emitted direction
    // to perturb (a direction's emission starts anywhere on a disc): the caustic
    // perturbation applies only where its chain starts at a surface. The perturbations keep
    // the light's kind, so this too is the same at x and at its proposals.
    let caustic = n >= 4
        && space.class(&x[n - 2]) == VertexClass::Diffuse
        && space.class(&x[n - 3]) != VertexClass::Diffuse
        && (x[0].light.is_none() || caustic_start(space, x) > 0);
    Applicable { lens, caustic }
}

/// The diffuse vertex the caustic perturbation turns: where the chain of specular and
/// glossy vertices before x_{n-2} starts (x_0, the light, at the latest).
#[inline]
fn caustic_start(space: &PathSpace, x: &[PathVertex]) -> usize {
    (1..x.len() - 3)
        .rev()
        .find(|&k| space.class(&x[k]) == VertexClass::Diffuse)
        .unwrap_or(0)
}

/// The lobe vertex `k` of `x` scatters through (x_{k+1} → x_k → x_{k-1}).
#[inline]
fn lobe_at(space: &PathSpace, x: &[PathVertex], k: usize) -> Option<SpecularLobe> {
    let (wo, _) = direction(&x[k], &x[k + 1])?;
    let (wi, _) = direction(&x[k], &x[k - 1])?;
    Some(space.surface_bsdf(&x[k]).specular_lobe(wo, wi))
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
            Some((wo, _)) => space.surface_bsdf(at).pdf(wo, wi),
            None => 0.0,
        },
    }
}

/// At a vertex whose direction onwards (towards `onwards`) a perturbation moved: the
/// density C_s divides by there over the density of the kernel's map onto that direction
/// (module docs). A diffuse vertex or light, `from` its predecessor on the side that moved
/// it (`None` at a light): p_σ, over cos θ / π in sample space; a glossy vertex: p_σ over
/// the moved microfacet's density.
fn moved_direction_factor(
    space: &PathSpace,
    in_sample_space: bool,
    from: Option<&PathVertex>,
    at: &PathVertex,
    onwards: &PathVertex,
) -> f32 {
    let Some((wi, _)) = direction(at, onwards) else {
        return 0.0;
    };
    let density = direction_density(space, from, at, wi);
    if space.class(at) == VertexClass::Glossy
        && let Some((wo, _)) = from.and_then(|from| direction(at, from))
    {
        let step = space
            .surface_bsdf(at)
            .microfacet_step_density(wo, wi, in_sample_space);
        return if step > 0.0 { density / step } else { 0.0 };
    }
    if in_sample_space {
        let cosine = wi.dot(sampling_side(from, at)) * FRAC_1_PI;
        return if cosine > 0.0 { density / cosine } else { 0.0 };
    }
    density
}

/// The lens perturbation, or with `multi_chain` the multi-chain perturbation, of `x` into
/// `y`. `None`: the chain stays (the move does not apply, leaves the film, or changes the
/// path's pattern).
pub(crate) fn lens(
    space: &PathSpace,
    kernel: &mut impl Kernel,
    multi_chain: bool,
    x: &[PathVertex],
    y: &mut Vec<PathVertex>,
    rays: &mut u64,
) -> Option<Proposal> {
    let n = x.len();
    if applicable(space, x).lens == multi_chain {
        return None;
    }
    // The move traces from the lens back to the first diffuse vertex it can connect from
    // (one whose predecessor is not specular), or to the light.
    let first_moved = (1..n - 1)
        .rev()
        .find(|&k| space.class(&x[k]) == VertexClass::Diffuse && !space.is_specular(&x[k - 1]))
        .unwrap_or(0);
    let space_x = space;
    let space_y = &proposal_space(space, kernel, x, first_moved);
    let space = space_y;
    let camera = space.camera;
    let lens = &x[n - 1];
    let (to_scene, _) = direction(lens, &x[n - 2])?;
    let [fx, fy] = camera.raster_position(lens.p, to_scene)?;
    let [dx, dy] = kernel.film_offset();
    let (fx, fy) = (fx + dx, fy + dy);
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
    let mut k = n - 2;
    let s = loop {
        if k == 0 {
            // x's light was seen through the chain: so must y's, a light of the same kind
            // (a surface, or a direction at infinity, which a ray that leaves the scene
            // finds), so that the proposal admits the same perturbations as x.
            let v = match x[0].light {
                None => {
                    let v = space.trace(&ray, rays)?;
                    if space.is_specular(&v) {
                        return None;
                    }
                    v
                }
                // A light at infinity that rays hit (the environment, the sun disc).
                Some(light) if !light.is_delta() => {
                    let v = space.trace_or_escape(&ray, rays)?;
                    if !v.is_at_infinity() {
                        return None;
                    }
                    v
                }
                // A delta light (reached from the light side only, by light tracing): no
                // ray finds it.
                Some(_) => return None,
            };
            y[0] = v;
            break 0;
        }
        let mut v = space.trace(&ray, rays)?;
        // x's lobe there, kept.
        v.dirac = space_x.is_specular(&x[k]);
        let class = space.class(&v);
        if class != space_x.class(&x[k]) {
            return None;
        }
        y[k] = v;
        // Onwards from the direction the ray arrived along, not from the vertex before:
        // the ray left that vertex's offset origin, and a direction rebuilt from the
        // vertices would bend every specular chain slightly (against BDPT's, which goes on
        // from its rays).
        let wo = -ray.direction;
        let next = match class {
            VertexClass::Specular => space
                .surface_bsdf(&v)
                .specular_direction(wo, lobe_at(space_x, x, k)?)?,
            VertexClass::Glossy => glossy_onwards(
                [space_x, space_y],
                kernel,
                [&x[k + 1], &x[k], &x[k - 1]],
                wo,
                &v,
            )?,
            VertexClass::Diffuse => {
                if !space_x.is_specular(&x[k - 1]) {
                    // Connect to the kept vertex before it.
                    if !space.visible(&y[k], &y[k - 1], false, rays) {
                        return None;
                    }
                    break k;
                }
                // Multi-chain: perturb the direction onwards and trace the next chain.
                let (old, _) = direction(&x[k], &x[k - 1])?;
                perturbed_direction(
                    kernel,
                    old,
                    sampling_side(Some(&x[k + 1]), &x[k]),
                    sampling_side(Some(&y[k + 1]), &y[k]),
                )?
            }
        };
        ray = spawn_ray(space.scene, v.p, v.normal, next);
        k -= 1;
    };
    debug_assert_eq!(s, first_moved);
    let in_sample_space = kernel.in_sample_space();
    let density_y = lens_side_factors(space_y, in_sample_space, y, s);
    let density_x = lens_side_factors(space_x, in_sample_space, x, s);
    let kept = space_x.kept_density_ratio(space_y, x, [s, n - 1], false);
    proposal([space_x, space_y], x, y, s, density_x, density_y * kept)
}

/// The product of `moved_direction_factor` over the lens-side vertices (after the first s)
/// whose direction onwards the lens or multi-chain perturbation moved: the glossy ones, and
/// the diffuse ones whose successor towards the light is specular (none of those for the
/// lens perturbation). Taken from the vertices, as C_s takes its directions.
fn lens_side_factors(
    space: &PathSpace,
    in_sample_space: bool,
    path: &[PathVertex],
    s: usize,
) -> f32 {
    let n = path.len();
    (s.max(1)..n - 1)
        .filter(|&k| match space.class(&path[k]) {
            VertexClass::Glossy => k > s,
            VertexClass::Diffuse => space.is_specular(&path[k - 1]),
            VertexClass::Specular => false,
        })
        .map(|k| {
            moved_direction_factor(
                space,
                in_sample_space,
                Some(&path[k + 1]),
                &path[k],
                &path[k - 1],
            )
        })
        .product()
}

/// The caustic perturbation of `x` into `y` (see the module documentation).
pub(crate) fn caustic(
    space: &PathSpace,
    kernel: &mut impl Kernel,
    x: &[PathVertex],
    y: &mut Vec<PathVertex>,
    rays: &mut u64,
) -> Option<Proposal> {
    let n = x.len();
    if !applicable(space, x).caustic {
        return None;
    }
    // The diffuse vertex the chain before x_{n-2} starts from.
    let c = caustic_start(space, x);
    let space_x = space;
    let space_y = &proposal_space(space, kernel, x, c + 1);
    let space = space_y;
    let (old, _) = direction(&x[c], &x[c + 1])?;
    let from = c.checked_sub(1).map(|i| &x[i]);
    let side = sampling_side(from, &x[c]);
    let new = perturbed_direction(kernel, old, side, side)?;
    if direction_density(space, from, &x[c], new) <= 0.0 {
        return None;
    }
    y.clear();
    y.extend_from_slice(x);
    let mut ray = spawn_ray(space.scene, x[c].p, x[c].normal, new);
    for k in c + 1..=n - 2 {
        let mut v = space.trace(&ray, rays)?;
        v.dirac = space_x.is_specular(&x[k]);
        let class = space.class(&v);
        if class != space_x.class(&x[k]) {
            return None;
        }
        y[k] = v;
        if k == n - 2 {
            break;
        }
        // Onwards from the ray's own direction (see `lens`).
        let wo = -ray.direction;
        let next = if class == VertexClass::Glossy {
            glossy_onwards(
                [space_x, space_y],
                kernel,
                [&x[k - 1], &x[k], &x[k + 1]],
                wo,
                &v,
            )?
        } else {
            // x's lobe at k, seen from the light side (x_{k-1} → x_k → x_{k+1}).
            let (wo_x, _) = direction(&x[k], &x[k - 1])?;
            let (wi_x, _) = direction(&x[k], &x[k + 1])?;
            let lobe = space_x.surface_bsdf(&x[k]).specular_lobe(wo_x, wi_x);
            space.surface_bsdf(&v).specular_direction(wo, lobe)?
        };
        ray = spawn_ray(space.scene, v.p, v.normal, next);
    }
    if !space.visible(&y[n - 2], &y[n - 1], true, rays) {
        return None;
    }
    // The factors of the moved directions: at x_c and at the glossy vertices after it, from
    // the light side, as C_s takes them.
    let in_sample_space = kernel.in_sample_space();
    let factors = |space: &PathSpace, path: &[PathVertex]| {
        let at_start = moved_direction_factor(space, in_sample_space, from, &path[c], &path[c + 1]);
        (c + 1..n - 2)
            .filter(|&k| space.class(&path[k]) == VertexClass::Glossy)
            .map(|k| {
                moved_direction_factor(
                    space,
                    in_sample_space,
                    Some(&path[k - 1]),
                    &path[k],
                    &path[k + 1],
                )
            })
            .product::<f32>()
            * at_start
    };
    let (density_x, density_y) = (factors(space_x, x), factors(space_y, y));
    let kept = space_x.kept_density_ratio(space_y, x, [c + 1, n - 1], false);
    proposal([space_x, space_y], x, y, n - 1, density_x, density_y * kept)
}

/// The proposal y of a perturbation of x that kept s light vertices, with the densities of
/// the perturbed directions (see the module documentation for the ratio).
fn proposal(
    [space_x, space_y]: [&PathSpace; 2],
    x: &[PathVertex],
    y: &[PathVertex],
    s: usize,
    density_x: f32,
    density_y: f32,
) -> Option<Proposal> {
    if !(density_x > 0.0 && density_y > 0.0) {
        return None;
    }
    let (value, pixel) = space_y.unweighted_contribution(y, s, false)?;
    let (value_x, _) = space_x.unweighted_contribution(x, s, false)?;
    let ratio = value.luminance() * density_y / (value_x.luminance() * density_x);
    Some(Proposal {
        ratio,
        value,
        pixel,
        channels: space_y.channels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Backend;
    use crate::bsdf;
    use crate::scene::{Camera, CameraModel, Material, Scene, SceneDesc};
    use crate::spectral::Channels;

    /// Fixed moves, to set up a given proposal: a film offset, and directions turned by a
    /// fixed rotation.
    struct FixedKernel {
        film_offset: [f32; 2],
        rotation: glam::Quat,
    }

    impl Kernel for FixedKernel {
        fn film_offset(&mut self) -> [f32; 2] {
            self.film_offset
        }
        fn turn(&mut self, w: Vec3A) -> Vec3A {
            Vec3A::from(self.rotation * glam::Vec3::from(w))
        }
        fn step(&mut self, u: [f32; 2]) -> [f32; 2] {
            u
        }
        fn in_sample_space(&self) -> bool {
            false
        }
        fn wavelength_step(&mut self, u: f32) -> f32 {
            u
        }
    }

    /// A room corner: a diffuse floor (y = 0), back wall (z = -3) and left wall (x = -3), a
    /// mirror (x = 2.5,
    /// facing -x) and a small light under the ceiling facing down; materials 0 diffuse,
    /// 1 mirror, 2 light.
    fn corner() -> Scene {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        let mut material_ids = Vec::new();
        // A quad from corner `o` spanned by `a` and `b`, front side along a × b.
        let mut quad = |o: [f32; 3], a: [f32; 3], b: [f32; 3], material: u32| {
            let base = (positions.len() / 3) as u32;
            for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                for axis in 0..3 {
                    positions.push(o[axis] + s * a[axis] + t * b[axis]);
                }
            }
            indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
            material_ids.extend_from_slice(&[material, material]);
        };
        quad([-3.0, 0.0, 3.0], [6.0, 0.0, 0.0], [0.0, 0.0, -6.0], 0); // floor, up
        quad([-3.0, 0.0, -3.0], [6.0, 0.0, 0.0], [0.0, 3.0, 0.0], 0); // back wall, +z
        quad([-3.0, 0.0, 3.0], [0.0, 0.0, -6.0], [0.0, 3.0, 0.0], 0); // left wall, +x
        quad([2.5, 0.0, -2.0], [0.0, 0.0, 4.0], [0.0, 2.5, 0.0], 1); // mirror, -x
        quad([-0.5, 2.9, -2.8], [1.0, 0.0, 0.0], [0.0, 0.0, 0.5], 2); // light, down
        Scene::new(&SceneDesc {
            positions: &positions,
            indices: &indices,
            material_ids: &material_ids,
            materials: &[
                Material::diffuse([0.7, 0.6, 0.5]),
                Material::mirror([0.9, 0.9, 0.9]),
                Material::diffuse([0.0; 3]).with_emission([5.0, 5.0, 5.0]),
            ],
            lights: Default::default(),
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap()
    }

    fn camera() -> CameraModel {
        Camera {
            eye: [-2.0, 1.6, 1.5],
            target: [2.5, 1.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 40.0,
            lens_radius: 0.0,
            focus_distance: 0.0,
        }
        .model(64, 64)
    }

    fn vertex(space: &PathSpace, ray: &Ray) -> PathVertex {
        space.trace(ray, &mut 0).expect("the ray hits")
    }

    /// Asserts a proposal's ratio equals the independently computed one, which is not 1.
    fn assert_ratio(proposal: &Proposal, expected: f32, case: &str) {
        assert!(
            (proposal.ratio / expected - 1.0).abs() < 1e-4,
            "{case}: ratio {} vs {expected}",
            proposal.ratio
        );
        assert!(
            (expected - 1.0).abs() > 1e-4,
            "{case}: the move changes the contribution"
        );
    }

    /// The lens vertex of the pinhole camera.
    fn eye(camera: &CameraModel) -> PathVertex {
        PathVertex::point(camera.eye, camera.forward)
    }

    /// The mirror and floor vertices seen from the lens through one film point.
    fn mirror_then_floor(space: &PathSpace) -> (PathVertex, PathVertex) {
        let camera = space.camera;
        let to_mirror = camera.direction_through(camera.eye, 30.0, 36.0);
        let mirror = vertex(space, &Ray::new(camera.eye, to_mirror, 0.0, f32::INFINITY));
        assert!(space.is_specular(&mirror));
        let reflected = bsdf::reflect(-to_mirror, mirror.normal);
        let floor = vertex(
            space,
            &spawn_ray(space.scene, mirror.p, mirror.normal, reflected),
        );
        assert_eq!(floor.normal, Vec3A::Y, "the mirror sees the floor");
        (mirror, floor)
    }

    /// G between two surface vertices.
    fn geometry(a: &PathVertex, b: &PathVertex) -> f32 {
        let (w, d2) = direction(a, b).unwrap();
        w.dot(a.normal).abs() * w.dot(b.normal).abs() / d2
    }

    /// The seed's walk-through: a lens perturbation of an L D D S E path. Parametrized by
    /// the film point (with the light and wall vertices fixed), the move is symmetric, and
    /// the path's contribution per unit of film area changes only through the connection
    /// from the floor to the wall (diffuse BSDFs are constant): the acceptance ratio is
    /// G(x1, y2) / G(x1, x2), cos θ₁ cos θ₂ / d² of the changed diffuse–diffuse connection.
    #[test]
    fn lens_perturbation_of_the_seeds_l_d_d_s_e_path() {
        let scene = corner();
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let eye = eye(&camera);
        // Lens → mirror → floor, then the wall and the light by hand.
        let (mirror, floor) = mirror_then_floor(&space);
        let wall = vertex(
            &space,
            &Ray::new(Vec3A::new(0.0, 1.5, 0.0), -Vec3A::Z, 0.0, f32::INFINITY),
        );
        let light = vertex(
            &space,
            &Ray::new(Vec3A::new(0.0, 1.0, -2.55), Vec3A::Y, 0.0, f32::INFINITY),
        );
        let x = [light, wall, floor, mirror, eye];
        assert!(space.unweighted_contribution(&x, 2, false).is_some());
        assert!(applicable(&space, &x).lens);
        for offset in [[1.5, -0.7], [-4.0, 3.0], [0.3, 0.2]] {
            let mut kernel = FixedKernel {
                film_offset: offset,
                rotation: glam::Quat::IDENTITY,
            };
            let mut y = Vec::new();
            let proposal = lens(&space, &mut kernel, false, &x, &mut y, &mut 0)
                .expect("the perturbed path is valid");
            assert_eq!(&y[..2], &x[..2], "the light side is kept");
            assert_eq!(y[4], x[4], "the lens point is kept");
            assert!(space.is_specular(&y[3]) && y[2].normal == Vec3A::Y);
            let expected = geometry(&x[1], &y[2]) / geometry(&x[1], &x[2]);
            assert!(
                (proposal.ratio / expected - 1.0).abs() < 1e-4,
                "offset {offset:?}: ratio {} vs {expected}",
                proposal.ratio
            );
            assert!(
                (expected - 1.0).abs() > 1e-3,
                "the move changes the connection"
            );
        }
    }

    /// A caustic perturbation of an L S D E path (light → mirror → floor → lens).
    /// Parametrized by the light point and its emitted direction (projected solid angle),
    /// the move is symmetric, and the contribution is Le·cos θ_light · ρ · f_floor ·
    /// G(floor, lens) · We: the ratio is that of cos θ_light · G(floor, lens) · We.
    #[test]
    fn caustic_perturbation_matches_the_contribution_per_emitted_direction() {
        let scene = corner();
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let eye = eye(&camera);
        let light = vertex(
            &space,
            &Ray::new(Vec3A::new(0.0, 1.0, -2.55), Vec3A::Y, 0.0, f32::INFINITY),
        );
        // From the light down to the mirror, reflected onto the floor.
        let to_mirror = (Vec3A::new(2.5, 0.83, -1.09) - light.p).normalize();
        let mirror = vertex(&space, &spawn_ray(&scene, light.p, light.normal, to_mirror));
        assert!(space.is_specular(&mirror));
        let reflected = bsdf::reflect(-to_mirror, mirror.normal);
        let floor = vertex(
            &space,
            &spawn_ray(&scene, mirror.p, mirror.normal, reflected),
        );
        assert_eq!(floor.normal, Vec3A::Y);
        let x = [light, mirror, floor, eye];
        assert!(applicable(&space, &x).caustic);
        assert!(
            space.unweighted_contribution(&x, 3, false).is_some(),
            "{x:?} pixel {:?}",
            space.pixel(&x)
        );
        let parametrized = |path: &[PathVertex]| {
            let (w, _) = direction(&path[0], &path[1]).unwrap();
            let (to_floor, d2) = direction(&path[3], &path[2]).unwrap();
            let importance = camera.importance(path[3].p, to_floor).unwrap().importance;
            let g = to_floor.dot(camera.forward) * to_floor.dot(path[2].normal).abs() / d2;
            w.dot(path[0].normal) * g * importance
        };
        for (angle, axis) in [(0.02f32, Vec3A::X), (0.05, Vec3A::Z), (0.01, Vec3A::Y)] {
            let mut kernel = FixedKernel {
                film_offset: [0.0; 2],
                rotation: glam::Quat::from_axis_angle(axis.into(), angle),
            };
            let mut y = Vec::new();
            let proposal =
                caustic(&space, &mut kernel, &x, &mut y, &mut 0).expect("a valid caustic path");
            assert_eq!(
                (y[0], y[3]),
                (x[0], x[3]),
                "the light point and the lens are kept"
            );
            let expected = parametrized(&y) / parametrized(&x);
            assert_ratio(&proposal, expected, &format!("angle {angle} about {axis}"));
        }
    }

    /// A multi-chain perturbation of an L D S D S E path (light → left wall → mirror → floor →
    /// mirror → lens): the film point moves, and at the floor the direction onwards turns
    /// by a small rotation before the second mirror. Parametrized by the film point and that
    /// direction (solid angle), with the light point fixed, the move is symmetric, and the
    /// contribution changes through cos θ at the floor and the wall–light connection.
    #[test]
    fn multi_chain_perturbation_matches_the_contribution_per_film_area_and_direction() {
        let scene = corner();
        let camera = camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let eye = eye(&camera);
        let (near_mirror, floor) = mirror_then_floor(&space);
        let up = (Vec3A::new(2.5, 0.6, -1.9) - floor.p).normalize();
        let far_mirror = vertex(&space, &spawn_ray(&scene, floor.p, floor.normal, up));
        assert!(space.is_specular(&far_mirror));
        let back = bsdf::reflect(-up, far_mirror.normal);
        let wall = vertex(
            &space,
            &spawn_ray(&scene, far_mirror.p, far_mirror.normal, back),
        );
        assert_eq!(
            wall.normal,
            Vec3A::X,
            "the second mirror sees the left wall"
        );
        let light = vertex(
            &space,
            &Ray::new(Vec3A::new(0.0, 1.0, -2.55), Vec3A::Y, 0.0, f32::INFINITY),
        );
        let x = [light, wall, far_mirror, floor, near_mirror, eye];
        assert!(
            !applicable(&space, &x).lens,
            "the floor cannot connect: multi-chain"
        );
        let parametrized = |path: &[PathVertex]| {
            let (onwards, _) = direction(&path[3], &path[2]).unwrap();
            onwards.dot(path[3].normal).abs() * geometry(&path[1], &path[0])
        };
        for (offset, angle, axis) in [
            ([0.8f32, -0.5f32], 0.02f32, Vec3A::X),
            ([-1.5, 0.7], 0.01, Vec3A::Z),
        ] {
            let mut kernel = FixedKernel {
                film_offset: offset,
                rotation: glam::Quat::from_axis_angle(axis.into(), angle),
            };
            let mut y = Vec::new();
            let proposal = lens(&space, &mut kernel, true, &x, &mut y, &mut 0)
                .expect("a valid multi-chain path");
            assert_eq!(
                (y[0], y[5]),
                (x[0], x[5]),
                "the light point and the lens are kept"
            );
            let expected = parametrized(&y) / parametrized(&x);
            assert_ratio(
                &proposal,
                expected,
                &format!("offset {offset:?}, angle {angle}"),
            );
        }
    }

    // Detailed balance. The tests above check single proposals' ratios; the ones below check
    // that chains of one perturbation each, accepted with min(1, ratio) as `chain.rs` does,
    // keep f as their stationary distribution, which also catches a factor left out of both
    // the ratio and its independent derivation. They use a second small scene whose path
    // contributions they compute from elementary formulas, independently of `PathSpace`: a
    // diffuse floor (y = 0, x and z in [-1, 1]), a large mirror (x = 1.5, facing -x) beside
    // it, a 1 × 1 light (y = 1, facing down) above the floor's mirror side, and a camera that
    // sees all of the floor. Two path families: light → floor → lens (L D E, for the lens
    // perturbation) and light → mirror → floor → lens (L S D E, for the caustic and the
    // multi-chain perturbations). Nothing occludes a path of either family, every light
    // point sees every floor point both directly and through the mirror, and every floor
    // point lies on the film: the integrands below are smooth, without visibility.
    //
    // Each test draws many paths of its family exactly ∝ f (rejection sampling), runs an
    // independent chain from each, and compares the final states' floor cells (4 × 4) with
    // ∫ f over the cells by Pearson's chi-square. A correct chain leaves f invariant, so its
    // final states are independent draws ∝ f however well it mixes (the perturbations keep
    // some vertices, e.g. the light point, so each chain only explores f given those: starting
    // ∝ f makes the joint distribution f). A chain with a flawed ratio drifts from f towards
    // its own stationary distribution, as far as it mixes in its steps: the tests run enough
    // steps for the flawed statistics to level off, and require the correct chains to move.

    use super::super::test_geometry::Rect;
    use crate::integrators::mlt::acceptance;
    use crate::sampling::chi_square::{
        Z_999, quantile as chi_square_quantile, statistic as chi_square,
    };
    use glam::DVec3;

    const FLOOR: Rect = Rect {
        o: DVec3::new(-1.0, 0.0, 1.0),
        a: DVec3::new(2.0, 0.0, 0.0),
        b: DVec3::new(0.0, 0.0, -2.0),
    };
    const MIRROR_X: f64 = 1.5;
    const MIRROR: Rect = Rect {
        o: DVec3::new(MIRROR_X, 0.0, -1.5),
        a: DVec3::new(0.0, 0.0, 3.0),
        b: DVec3::new(0.0, 2.0, 0.0),
    };
    const LIGHT: Rect = Rect {
        o: DVec3::new(0.3, 1.0, -0.5),
        a: DVec3::new(1.0, 0.0, 0.0),
        b: DVec3::new(0.0, 0.0, 1.0),
    };
    const BALANCE_EYE: [f32; 3] = [-2.4, 2.6, 0.0];
    const BALANCE_LOOK_AT: [f32; 3] = [0.1, 0.0, 0.0];
    const BALANCE_FOV_Y_DEG: f32 = 50.0;
    /// The histograms' cells: the floor cut into CELLS × CELLS.
    const CELLS: usize = 4;
    /// Independent chains per run.
    const CHAINS: usize = 10_000;
    /// Flawed chains must exceed the correct chains' threshold this many times over.
    const FLAW_MARGIN: f64 = 3.0;
    /// Correct chains must accept at least this share of their steps (a chain that never
    /// moves keeps f too).
    const MIN_ACCEPTED: f64 = 0.3;

    /// Floor, mirror and light; materials 0 diffuse, 1 mirror, 2 light.
    fn balance_scene() -> Scene {
        balance_scene_with_floor(Material::diffuse([0.8, 0.6, 0.4]))
    }

    /// The floor's roughness in the glossy family's scene (α = 0.36).
    const GLOSSY_FLOOR_ROUGHNESS: f64 = 0.6;

    /// The balance scene with a floor of rough white metal.
    fn glossy_balance_scene() -> Scene {
        balance_scene_with_floor(Material::metallic_roughness(
            [1.0; 3],
            1.0,
            GLOSSY_FLOOR_ROUGHNESS as f32,
        ))
    }

    /// The floor's BRDF in the glossy scene, from the formulas: GGX D, the height-correlated
    /// Smith G2 and Fresnel 1 (white metal), for light arriving at floor point p from l and
    /// leaving towards the eye.
    fn glossy_floor_brdf(p: DVec3, l: DVec3) -> f64 {
        let alpha = GLOSSY_FLOOR_ROUGHNESS * GLOSSY_FLOOR_ROUGHNESS;
        let n = FLOOR.normal();
        let wo = (Vec3A::from(BALANCE_EYE).as_dvec3() - p).normalize();
        let wi = (l - p).normalize();
        let h = (wo + wi).normalize();
        let cos_h = h.dot(n);
        let tan2_h = (1.0 - cos_h * cos_h) / (cos_h * cos_h);
        let d = 1.0
            / (std::f64::consts::PI
                * alpha
                * alpha
                * cos_h.powi(4)
                * (1.0 + tan2_h / (alpha * alpha)).powi(2));
        let lambda = |w: DVec3| {
            let c = w.dot(n);
            let tan2 = (1.0 - c * c) / (c * c);
            0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
        };
        let g2 = 1.0 / (1.0 + lambda(wo) + lambda(wi));
        d * g2 / (4.0 * wo.dot(n) * wi.dot(n))
    }

    /// Floor, mirror and light; materials 0 the floor's, 1 mirror, 2 light.
    fn balance_scene_with_floor(floor: Material) -> Scene {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        let mut material_ids = Vec::new();
        for (material, r) in [FLOOR, MIRROR, LIGHT].into_iter().enumerate() {
            let base = (positions.len() / 3) as u32;
            for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                positions.extend_from_slice(&r.point(s, t).as_vec3().to_array());
            }
            indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
            material_ids.extend_from_slice(&[material as u32; 2]);
        }
        Scene::new(&SceneDesc {
            positions: &positions,
            indices: &indices,
            material_ids: &material_ids,
            materials: &[
                floor,
                Material::mirror([0.9, 0.8, 0.7]),
                Material::diffuse([0.0; 3]).with_emission([4.0, 4.0, 4.0]),
            ],
            lights: Default::default(),
            backend: Backend::Bvh,
            ..Default::default()
        })
        .unwrap()
    }

    /// 32 × 32 pixels (film offsets are in pixels; the floor spans some 15 to 24 of them).
    fn balance_camera() -> CameraModel {
        Camera {
            eye: BALANCE_EYE,
            target: BALANCE_LOOK_AT,
            up: [0.0, 1.0, 0.0],
            fov_y_deg: BALANCE_FOV_Y_DEG,
            lens_radius: 0.0,
            focus_distance: 0.0,
        }
        .model(32, 32)
    }

    /// G(p, lens)·We of a surface point p with normal n, from the camera's description: the
    /// area density at p of the ray through a film point drawn uniformly (uniform on the
    /// image plane at distance 1, of area 4 tan²(fov/2): 1 / (A cos³θ) per steradian, times
    /// |cos θ_p| / d²); 0 off the film.
    fn film_density(p: DVec3, n: DVec3) -> f64 {
        let eye = Vec3A::from(BALANCE_EYE).as_dvec3();
        let forward = (Vec3A::from(BALANCE_LOOK_AT).as_dvec3() - eye).normalize();
        let right = forward.cross(DVec3::Y).normalize();
        let up = right.cross(forward);
        let tan_half = (0.5 * (BALANCE_FOV_Y_DEG as f64).to_radians()).tan();
        let d = p - eye;
        let d2 = d.length_squared();
        let w = d / d2.sqrt();
        let c = w.dot(forward);
        let on_film =
            c > 0.0 && (w.dot(right) / c).abs() < tan_half && (w.dot(up) / c).abs() < tan_half;
        if !on_film {
            return 0.0;
        }
        n.dot(w).abs() / (4.0 * tan_half * tan_half * c.powi(3) * d2)
    }

    /// The cell of a floor point.
    fn floor_cell(p: DVec3) -> usize {
        let (s, t) = FLOOR.coordinates(p);
        let index = |x: f64| ((x * CELLS as f64).max(0.0) as usize).min(CELLS - 1);
        index(t) * CELLS + index(s)
    }

    /// The path families: light → floor → lens, or light → mirror → floor → lens; or light
    /// → glossy floor → lens, in the glossy scene.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Family {
        Direct,
        Mirrored,
        Glossy,
    }

    /// ∫ f over each floor cell (normalized), with `m` × `m` nodes per cell and 2m × 2m on
    /// the light. Up to constants (Le, the albedos), f per unit area of the light point and
    /// the floor point is cos θ_light cos θ_floor / d² · G(floor, lens)We, where for the
    /// mirrored family the path unfolds into a straight line from the light's mirror image
    /// (the mirror's Dirac delta: Veach's generalized geometry term).
    fn floor_target(family: Family, m: usize) -> Vec<f64> {
        let lights: Vec<_> = LIGHT.nodes(2 * m).collect();
        let mut target = [0.0; CELLS * CELLS];
        let n_floor = FLOOR.normal();
        for (i, j, p, weight) in FLOOR.nodes(CELLS * m) {
            let camera = film_density(p, n_floor);
            assert!(camera > 0.0, "the camera sees all of the floor");
            let mut irradiance = 0.0;
            for &(_, _, l, light_weight) in &lights {
                let (mut l, mut n_light) = (l, LIGHT.normal());
                if family == Family::Mirrored {
                    let image = |v: DVec3| DVec3::new(-v.x, v.y, v.z);
                    l = image(l - DVec3::X * MIRROR_X) + DVec3::X * MIRROR_X;
                    n_light = image(n_light);
                    let t = (MIRROR_X - l.x) / (p.x - l.x);
                    let (s, u) = MIRROR.coordinates(l + (p - l) * t);
                    assert!(
                        (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&u),
                        "every light point sees every floor point through the mirror"
                    );
                }
                let d = p - l;
                let d2 = d.length_squared();
                let w = d / d2.sqrt();
                let (cos_light, cos_floor) = (n_light.dot(w), -n_floor.dot(w));
                assert!(cos_light > 0.0 && cos_floor > 0.0);
                let brdf = if family == Family::Glossy {
                    glossy_floor_brdf(p, l)
                } else {
                    1.0
                };
                irradiance += light_weight * cos_light * cos_floor / d2 * brdf;
            }
            target[(j / m) * CELLS + i / m] += weight * irradiance * camera;
        }
        let total: f64 = target.iter().sum();
        target.iter().map(|t| t / total).collect()
    }

    /// The target ∫ f per floor cell, checked for the quadrature's convergence.
    fn converged_target(family: Family) -> Vec<f64> {
        // The glossy highlight needs finer nodes (8 vs 16 differ by 1.8e-3 there).
        let m = if family == Family::Glossy { 24 } else { 16 };
        let target = floor_target(family, m);
        let coarse = floor_target(family, m / 2);
        let error = target
            .iter()
            .zip(&coarse)
            .map(|(t, c)| (c / t - 1.0).abs())
            .fold(0.0, f64::max);
        println!("{family:?}: quadrature m = {} vs {m}: {error:.1e}", m / 2);
        // Far below the counts' relative errors (3% and more).
        assert!(error < 1e-3);
        target
    }

    /// `count` independent paths of `family` drawn ∝ f: the light tracer's paths (a light
    /// point uniform on the light, an emitted direction ∝ cos, traced, through the mirror
    /// for the mirrored family), each kept with probability G(floor, lens)We / bound. Their
    /// density p is (1/A_light)·(cos θ_light / π)·(cos θ_floor / d²) per unit light and
    /// floor area (d unfolded), so f/p ∝ G(floor, lens)We, and the kept paths' density is
    /// ∝ p · f/p = f.
    fn family_paths(space: &PathSpace, family: Family, count: usize) -> Vec<Vec<PathVertex>> {
        let n_floor = FLOOR.normal();
        // G(floor, lens)We is smooth on the floor: 1.25 × its maximum on a fine grid bounds
        // it (and every draw is checked against the bound).
        // In the glossy family, f/p also has the floor's BRDF: the bound is taken over light
        // points too.
        let lights: Vec<DVec3> = if family == Family::Glossy {
            LIGHT.nodes(12).map(|(_, _, l, _)| l).collect()
        } else {
            Vec::new()
        };
        let brdf_bound = |p: DVec3| {
            lights
                .iter()
                .map(|&l| glossy_floor_brdf(p, l))
                .fold(f64::MIN_POSITIVE, f64::max)
        };
        let bound = 1.25
            * FLOOR
                .nodes(200)
                .map(|(_, _, p, _)| {
                    let brdf = if family == Family::Glossy {
                        brdf_bound(p)
                    } else {
                        1.0
                    };
                    film_density(p, n_floor) * brdf
                })
                .fold(0.0, f64::max);
        let mut rng = Rng::new(0xBA1A, family as u64);
        let mut paths = Vec::with_capacity(count);
        while paths.len() < count {
            let [s, t] = rng.uniform2();
            let on_light = LIGHT.point(s as f64, t as f64).as_vec3();
            let below = Vec3A::from(on_light) - 0.1 * Vec3A::Y;
            let light = vertex(space, &Ray::new(below, Vec3A::Y, 0.0, f32::INFINITY));
            assert_eq!(light.normal, -Vec3A::Y, "a point on the light's front");
            // ∝ cos about the light's normal, -y (Malley's method).
            let [u, v] = rng.uniform2();
            let (r, phi) = (u.sqrt(), TAU * v);
            let emitted = Vec3A::new(r * phi.cos(), -(1.0 - u).sqrt(), r * phi.sin());
            let mut path = vec![light];
            let mut ray = spawn_ray(space.scene, light.p, light.normal, emitted);
            if family == Family::Mirrored {
                let Some(mirror) = space.trace(&ray, &mut 0) else {
                    continue;
                };
                if !space.is_specular(&mirror) {
                    continue;
                }
                let reflected = bsdf::reflect(-ray.direction, mirror.normal);
                ray = spawn_ray(space.scene, mirror.p, mirror.normal, reflected);
                path.push(mirror);
            }
            let Some(floor) = space.trace(&ray, &mut 0) else {
                continue;
            };
            if space.is_specular(&floor) || floor.normal != Vec3A::Y {
                continue;
            }
            let brdf = if family == Family::Glossy {
                glossy_floor_brdf(floor.p.as_dvec3(), light.p.as_dvec3())
            } else {
                1.0
            };
            let weight = film_density(floor.p.as_dvec3(), n_floor) * brdf / bound;
            assert!(weight <= 1.0, "the bound holds at {floor:?}");
            if (rng.uniform() as f64) < weight {
                path.extend([floor, eye(space.camera)]);
                let s = path.len() - 1;
                assert!(space.unweighted_contribution(&path, s, false).is_some());
                paths.push(path);
            }
        }
        paths
    }

    /// The 5% and 95% quantiles of `values`.
    fn spread(values: impl Iterator<Item = f32>) -> (f32, f32) {
        let mut sorted: Vec<f32> = values.collect();
        sorted.sort_by(f32::total_cmp);
        let at = |q: f64| sorted[(q * (sorted.len() - 1) as f64) as usize];
        (at(0.05), at(0.95))
    }

    /// The floor cells of the final states of chains of `steps` steps, one from each of
    /// `starts`, each step a proposal from `propose` (its ratio, `None` if there is none)
    /// accepted with min(1, ratio); and the share of steps accepted.
    fn final_cells(
        starts: &[Vec<PathVertex>],
        steps: usize,
        mut propose: impl FnMut(&[PathVertex], &mut Vec<PathVertex>, &mut Rng) -> Option<f32>,
    ) -> (Vec<u64>, f64) {
        let mut counts = vec![0u64; CELLS * CELLS];
        let mut accepted = 0u64;
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (c, start) in starts.iter().enumerate() {
            let mut rng = Rng::new(0xDE7A11, c as u64);
            x.clone_from(start);
            for _ in 0..steps {
                let Some(ratio) = propose(&x, &mut y, &mut rng) else {
                    continue;
                };
                if rng.uniform() < acceptance(1.0, 1.0, ratio) {
                    std::mem::swap(&mut x, &mut y);
                    accepted += 1;
                }
            }
            let floor = &x[x.len() - 2];
            assert_eq!(floor.normal, Vec3A::Y, "the chain stays in its family");
            counts[floor_cell(floor.p.as_dvec3())] += 1;
        }
        (counts, accepted as f64 / (starts.len() * steps) as f64)
    }

    /// Which ratio a chain uses: the perturbation's, or one without a factor.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Flaw {
        /// Without the density of the perturbed direction: the caustic perturbation's at
        /// the light, the multi-chain perturbation's `lens_side_factors` at the floor.
        WithoutDirectionDensity,
        /// Steps in sample space with the cone's ratio: the densities of the perturbed
        /// directions, which the sample-space kernel's own density cancels, left in.
        WithConeDensities,
        /// The lens perturbation without the changed connection's G ratio …
        WithoutG,
        /// … or with it twice.
        ExtraG,
    }

    /// Runs `run(None)`, the correct chains, and `run(Some(flaw))` for each flaw; asserts
    /// the correct chains move and pass the chi-square test against `target` at 99.9%, and
    /// each flawed run fails it by `FLAW_MARGIN` × the quantile.
    fn assert_balance(
        name: &str,
        target: &[f64],
        flaws: &[Flaw],
        mut run: impl FnMut(Option<Flaw>) -> (Vec<u64>, f64),
    ) {
        let df = target.len() - 1;
        let threshold = chi_square_quantile(df, Z_999);
        let (counts, accepted) = run(None);
        let stat = chi_square(&counts, 0, target);
        let n = counts.iter().sum::<u64>() as f64;
        println!(
            "{name}: chi-square {stat:.1} (df {df}, 99.9% quantile {threshold:.1}), \
             accepted {accepted:.2}"
        );
        for (cell, (&c, &p)) in counts.iter().zip(target).enumerate() {
            let e = p * n;
            let z = (c as f64 - e) / e.sqrt();
            println!("  cell {cell:2}: {c:5} vs {e:7.1} (z {z:+.2})");
        }
        assert!(stat < threshold, "{name}: chi-square {stat} ≥ {threshold}");
        assert!(accepted > MIN_ACCEPTED, "{name}: accepted {accepted}");
        for &flaw in flaws {
            let (counts, accepted) = run(Some(flaw));
            let stat = chi_square(&counts, 0, target);
            println!("{name}, {flaw:?}: chi-square {stat:.1}, accepted {accepted:.2}");
            assert!(
                stat > FLAW_MARGIN * threshold,
                "{name}, {flaw:?}: chi-square {stat} ≤ {FLAW_MARGIN} × {threshold}"
            );
        }
    }

    /// How a test's chains run: their kernel's sizes and kind, and their length.
    struct ChainRun {
        sizes: PerturbationSizes,
        steps: usize,
        in_sample_space: bool,
    }

    /// Chains of one perturbation (`perturb`) from `starts`, paths drawn ∝ f, against
    /// `target`: with the correct ratio they pass; with the flawed one they fail. The flaw
    /// is the density the two kernels differ by, `factor`, left out of the cone's ratio
    /// (`WithoutDirectionDensity`) or left in the sample space's (`WithConeDensities`); it
    /// must vary over the family for the test to have power.
    fn kernel_chains_sample_f(
        name: &str,
        target: &[f64],
        starts: &[Vec<PathVertex>],
        run: ChainRun,
        factor: impl Fn(&[PathVertex]) -> f32,
        perturb: impl Fn(&mut RandomKernel, &[PathVertex], &mut Vec<PathVertex>) -> Option<Proposal>,
    ) {
        let (low, high) = spread(starts.iter().map(|x| factor(x)));
        println!("{name}: the flawed factor over the family: 5% {low:.2}, 95% {high:.2}");
        assert!(high > 1.7 * low, "the flawed factor varies");
        let (name, flaw) = if run.in_sample_space {
            (format!("{name} in sample space"), Flaw::WithConeDensities)
        } else {
            (name.to_owned(), Flaw::WithoutDirectionDensity)
        };
        assert_balance(&name, target, &[flaw], |flaw| {
            final_cells(starts, run.steps, |x, y, rng| {
                let mut kernel = RandomKernel {
                    sizes: &run.sizes,
                    in_sample_space: run.in_sample_space,
                    rng,
                };
                let p = perturb(&mut kernel, x, y)?;
                Some(match flaw {
                    None => p.ratio,
                    Some(Flaw::WithConeDensities) => p.ratio * factor(y) / factor(x),
                    Some(_) => p.ratio * factor(x) / factor(y),
                })
            })
        });
    }

    /// cos θ at the light of the direction it emits (the caustic perturbation's direction
    /// density there, times π).
    fn emitted_cosine(path: &[PathVertex]) -> f32 {
        let (w, _) = direction(&path[0], &path[1]).unwrap();
        w.dot(path[0].normal)
    }

    /// |cos θ| at the floor of the direction towards the mirror (the multi-chain
    /// perturbation's direction density there, times π).
    fn onwards_cosine(path: &[PathVertex]) -> f32 {
        let (w, _) = direction(&path[2], &path[1]).unwrap();
        w.dot(path[2].normal).abs()
    }

    /// Caustic perturbations of L S D E paths sample f: chains of them (angles 0.01 to 0.5
    /// rad, against a family roughly 0.4 by 1 rad as seen from a light point) from
    /// paths drawn ∝ f end in floor cells that pass a chi-square test against ∫ f. Given the
    /// light point, which the perturbation keeps, f per unit solid angle of the emitted
    /// direction is ∝ cos θ_light · G(floor, lens)We (the mirror and floor factors cancel
    /// against the Jacobian). Without the direction's density cos θ_light / π in the ratio,
    /// the chains sample G(floor, lens)We alone; cos θ_light varies by a factor of two over
    /// the family. The flawed chains' statistic levels off within 50 steps (563 at 50, 524 at
    /// 200, 481 at 400 steps); 200 are run.
    #[test]
    fn caustic_chain_samples_f_and_a_ratio_without_the_direction_density_does_not() {
        caustic_chains_sample_f(false);
    }

    /// Caustic perturbation chains (see above), with cone or sample-space steps: the
    /// correct ratio passes and the other kernel's density factor fails.
    fn caustic_chains_sample_f(in_sample_space: bool) {
        let scene = balance_scene();
        let camera = balance_camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let starts = family_paths(&space, Family::Mirrored, CHAINS);
        assert!(starts.iter().all(|x| applicable(&space, x).caustic));
        let run = ChainRun {
            sizes: PerturbationSizes {
                film_min: 0.0,
                film_max: 0.0,
                angle_min: 0.01,
                angle_max: 0.5,
            },
            steps: 200,
            in_sample_space,
        };
        kernel_chains_sample_f(
            "caustic",
            &converged_target(Family::Mirrored),
            &starts,
            run,
            emitted_cosine,
            |kernel, x, y| caustic(&space, kernel, x, y, &mut 0),
        );
    }

    /// Multi-chain perturbations of L S D E paths (E D S L from the lens: the floor cannot
    /// connect to the mirror, so the lens perturbation does not apply) sample f: the chains
    /// move the film point (up to 6 pixels) and turn the direction from the floor to the
    /// mirror (up to 0.3 rad), tracing on to a new light point. Per unit film area and solid
    /// angle of that direction, f is ∝ cos θ_floor of the direction (the other factors
    /// cancel against the Jacobians), which the ratio gets from `lens_side_factors`;
    /// without it the chains sample film points and directions uniformly. cos θ_floor varies
    /// by a factor of two over the family. The flawed chains' statistic levels off after
    /// about 200 steps (185, 417, 420 and 439 at 100, 200, 400 and 1000 steps); 400 are run.
    #[test]
    fn multi_chain_samples_f_and_a_ratio_without_the_direction_densities_does_not() {
        multi_chains_sample_f(false);
    }

    /// Multi-chain perturbation chains (see above), with cone or sample-space steps: the
    /// correct ratio passes and the other kernel's density factor fails.
    fn multi_chains_sample_f(in_sample_space: bool) {
        let scene = balance_scene();
        let camera = balance_camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let starts = family_paths(&space, Family::Mirrored, CHAINS);
        assert!(starts.iter().all(|x| !applicable(&space, x).lens));
        let run = ChainRun {
            sizes: PerturbationSizes {
                film_min: 0.1,
                film_max: 6.0,
                angle_min: 0.005,
                angle_max: 0.3,
            },
            steps: 400,
            in_sample_space,
        };
        kernel_chains_sample_f(
            "multi-chain",
            &converged_target(Family::Mirrored),
            &starts,
            run,
            onwards_cosine,
            |kernel, x, y| lens(&space, kernel, true, x, y, &mut 0),
        );
    }

    /// Lens perturbations of L D E paths sample f: the chains move the film point (up to 8
    /// pixels) and connect the new floor point to the kept light point. Per unit film area,
    /// f is ∝ G(light, floor), which the ratio gets from the contributions; chains without
    /// that ratio (accepting every move that stays on the floor) or with it twice do not
    /// sample f. The flawed chains' statistics mostly level off within 50 steps (6070 and
    /// 1916 at 50, 6968 and 2251 at 200, 6597 and 2186 at 400 steps); 200 are run.
    #[test]
    fn lens_chain_samples_f_and_ratios_with_a_wrong_g_do_not() {
        let scene = balance_scene();
        let camera = balance_camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let target = converged_target(Family::Direct);
        let starts = family_paths(&space, Family::Direct, CHAINS);
        assert!(starts.iter().all(|x| applicable(&space, x).lens));
        let sizes = PerturbationSizes {
            film_min: 0.1,
            film_max: 8.0,
            angle_min: 0.0,
            angle_max: 0.0,
        };
        let g = |path: &[PathVertex]| geometry(&path[0], &path[1]);
        assert_balance("lens", &target, &[Flaw::WithoutG, Flaw::ExtraG], |flaw| {
            final_cells(&starts, 200, |x, y, rng| {
                let mut kernel = RandomKernel {
                    sizes: &sizes,
                    in_sample_space: false,
                    rng,
                };
                let p = lens(&space, &mut kernel, false, x, y, &mut 0)?;
                Some(match flaw {
                    None | Some(Flaw::WithoutDirectionDensity) => p.ratio,
                    Some(Flaw::WithoutG) => p.ratio * g(x) / g(y),
                    Some(Flaw::ExtraG) => p.ratio * g(y) / g(x),
                    Some(Flaw::WithConeDensities) => unreachable!(),
                })
            })
        });
    }

    /// The density of the normals visible from the lens at the glossy floor vertex of an
    /// L G E path, of the microfacet towards the light: what the cone's ratio has and the
    /// sample-space ratio does not.
    fn visible_normal_density(space: &PathSpace, path: &[PathVertex]) -> f32 {
        let (wo, _) = direction(&path[1], &path[2]).unwrap();
        let (wi, _) = direction(&path[1], &path[0]).unwrap();
        let bsdf = space.surface_bsdf(&path[1]);
        bsdf.microfacet_step_density(wo, wi, true) / bsdf.microfacet_step_density(wo, wi, false)
    }

    /// Lens perturbations of L G E paths through a glossy floor (rough white metal, α =
    /// 0.36) sample f: the chains move the film point (up to 3 pixels) and the floor's
    /// microfacet (turned by up to 0.15 rad, or stepped by up to 0.15 in the coordinates of
    /// the visible normals), tracing on from the new floor point to a new light point. Per
    /// unit film area and of the microfacet's kernel, f is ∝ the floor's BSDF density of the
    /// direction found over the density of the map onto it; the ratio gets it from C_s and
    /// `moved_direction_factor`. The flawed chains leave out (cone) or keep (sample space)
    /// the visible-normal density, which varies across the highlight.
    fn glossy_chains_sample_f(in_sample_space: bool) {
        let scene = glossy_balance_scene();
        let camera = balance_camera();
        let space = PathSpace {
            scene: &scene,
            camera: &camera,
            channels: Channels::Rgb,
        };
        let starts = family_paths(&space, Family::Glossy, CHAINS);
        assert!(
            starts.iter().all(|x| {
                space.class(&x[1]) == VertexClass::Glossy && applicable(&space, x).lens
            })
        );
        let run = ChainRun {
            sizes: PerturbationSizes {
                film_min: 0.1,
                film_max: 3.0,
                angle_min: 0.005,
                angle_max: 0.15,
            },
            steps: 200,
            in_sample_space,
        };
        kernel_chains_sample_f(
            "glossy lens",
            &converged_target(Family::Glossy),
            &starts,
            run,
            |path| visible_normal_density(&space, path),
            |kernel, x, y| lens(&space, kernel, false, x, y, &mut 0),
        );
    }

    #[test]
    fn glossy_lens_chain_samples_f_and_a_ratio_without_the_microfacet_density_does_not() {
        glossy_chains_sample_f(false);
    }

    #[test]
    fn glossy_lens_chain_in_sample_space_samples_f_and_the_cone_ratio_does_not() {
        glossy_chains_sample_f(true);
    }

    /// Sample-space coordinates and directions invert each other, on both sides of a
    /// surface, and a step folded at u1 = 0 and 1 stays in [0, 1].
    #[test]
    fn sample_space_coordinates_round_trip() {
        let mut rng = Rng::new(7, 0);
        for normal in [Vec3A::Y, -Vec3A::Z, Vec3A::new(0.48, -0.6, 0.64)] {
            for _ in 0..1000 {
                let u = [rng.uniform() * 0.999, rng.uniform()];
                let w = from_sample_space(normal, u);
                assert!(w.dot(normal) > 0.0, "in the hemisphere");
                let back = to_sample_space(normal, w);
                assert!((back[0] - u[0]).abs() < 1e-4, "{u:?} → {back:?}");
                let d = (back[1] - u[1]).abs();
                assert!(d.min(1.0 - d) < 1e-4, "{u:?} → {back:?}");
            }
        }
        for (u, folded) in [(-0.25, 0.25), (1.25, 0.75), (2.5, 0.5), (0.5, 0.5)] {
            assert!((reflect_into_unit(u) - folded).abs() < 1e-6);
        }
    }

    /// As `caustic_chain_samples_f_…`, with the direction at the light stepped in its
    /// sample space (steps of 0.01 to 0.5 in u): the chains sample f with the ratio
    /// |C_s(y)| / |C_s(x)|; chains that keep the cone's density factor cos θ_light / π in
    /// the ratio sample f · cos θ_light instead.
    #[test]
    fn caustic_chain_in_sample_space_samples_f_and_the_cone_ratio_does_not() {
        caustic_chains_sample_f(true);
    }

    /// As `multi_chain_samples_f_…`, with the direction onwards from the floor stepped in
    /// the floor's sample space (0.005 to 0.3 in u), at the floor point the chain moved to;
    /// the cone's density factor left in the ratio makes the chains sample f · cos θ_floor.
    #[test]
    fn multi_chain_in_sample_space_samples_f_and_the_cone_ratio_does_not() {
        multi_chains_sample_f(true);
    }
}
