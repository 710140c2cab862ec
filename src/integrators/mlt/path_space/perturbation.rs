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

/// Where a perturbation's random moves come from.
pub(crate) trait Kernel {
    /// An offset of the film position, in pixels.
    fn film_offset(&mut self) -> [f32; 2];
    /// A direction near `old`.
    fn direction(&mut self, old: Vec3A) -> Vec3A;
}

/// The perturbations' kernels: symmetric, of the given sizes.
pub(crate) struct RandomKernel<'a> {
    pub sizes: &'a PerturbationSizes,
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
    fn direction(&mut self, old: Vec3A) -> Vec3A {
        perturb_direction(old, self.sizes, self.rng)
    }
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
        let new = kernel.direction(old);
        ray = spawn_ray(space.scene, v.p, v.normal, new);
        k -= 1;
    };
    let density_y = multi_chain_densities(space, y, s);
    let density_x = multi_chain_densities(space, x, s);
    proposal(space, x, y, s, density_x, density_y)
}

/// The product, over the non-specular vertices of the lens side (after the first s) whose
/// successor towards the light is specular, of the BSDF density of the direction onwards:
/// the vertices where the multi-chain perturbation turned the path (none for the lens
/// perturbation). Taken from the vertices, as C_s takes its directions.
fn multi_chain_densities(space: &PathSpace, path: &[PathVertex], s: usize) -> f32 {
    let n = path.len();
    (s.max(1)..n - 1)
        .filter(|&k| !space.is_specular(&path[k]) && space.is_specular(&path[k - 1]))
        .map(|k| match direction(&path[k], &path[k - 1]) {
            Some((onwards, _)) => direction_density(space, Some(&path[k + 1]), &path[k], onwards),
            None => 0.0,
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
    // The non-specular vertex the specular chain before x_{n-2} starts from.
    let c = (1..n - 3)
        .rev()
        .find(|&k| !space.is_specular(&x[k]))
        .unwrap_or(0);
    let (old, _) = direction(&x[c], &x[c + 1])?;
    let new = kernel.direction(old);
    let from = c.checked_sub(1).map(|i| &x[i]);
    if direction_density(space, from, &x[c], new) <= 0.0 {
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
    // The densities C_s divided by at x_c, from the vertices as C_s takes them.
    let density = |path: &[PathVertex]| match direction(&path[c], &path[c + 1]) {
        Some((onwards, _)) => direction_density(space, from, &path[c], onwards),
        None => 0.0,
    };
    proposal(space, x, y, n - 1, density(x), density(y))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Backend, Camera, CameraModel, Material, Scene, SceneDesc};

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
        fn direction(&mut self, old: Vec3A) -> Vec3A {
            Vec3A::from(self.rotation * glam::Vec3::from(old))
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
            backend: Backend::Bvh,
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
        PathVertex {
            p: camera.eye,
            normal: camera.forward,
            triangle: 0,
        }
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
}
