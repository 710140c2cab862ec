//! Deterministic geometry and rays, shared by the backend tests and the traversal bench
//! (`benches/traversal.rs` includes this file by path): triangle meshes built from
//! parametric grids and simple solids, and random, camera-hit bounce and uniform rays.
#![allow(dead_code)]

use glam::{DAffine3, DVec3, Vec3A};
use mlt::accel::Ray;
use mlt::sampling::{OrthonormalBasis, Rng, cosine_hemisphere};
use std::f64::consts::{PI, TAU};

/// An indexed triangle mesh under construction: three coordinates per vertex, three indices
/// per triangle. No triangle it makes is degenerate (for sizes well above f32 rounding).
#[derive(Clone, Debug, Default)]
pub struct MeshBuilder {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
}

impl MeshBuilder {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    fn vertex(&mut self, p: DVec3) -> u32 {
        let index = (self.positions.len() / 3) as u32;
        self.positions.extend([p.x as f32, p.y as f32, p.z as f32]);
        index
    }

    /// A grid of (rows + 1) × (columns + 1) vertices `point(s, u)` for s, u in [0, 1], as two
    /// triangles per cell.
    pub fn grid(&mut self, rows: u32, columns: u32, point: impl Fn(f64, f64) -> DVec3) {
        let base = (self.positions.len() / 3) as u32;
        for i in 0..=rows {
            for j in 0..=columns {
                self.vertex(point(i as f64 / rows as f64, j as f64 / columns as f64));
            }
        }
        let at = |i: u32, j: u32| base + i * (columns + 1) + j;
        for i in 0..rows {
            for j in 0..columns {
                self.indices
                    .extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                self.indices
                    .extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }

    /// Triangles from `center` to consecutive points `ring(j / segments)`, j in 0..=segments.
    fn fan(&mut self, center: DVec3, segments: u32, ring: impl Fn(f64) -> DVec3) {
        let c = self.vertex(center);
        let first = self.vertex(ring(0.0));
        for j in 1..=segments {
            let next = self.vertex(ring(j as f64 / segments as f64));
            self.indices.extend([c, next - 1, next]);
        }
        debug_assert_eq!(first + segments, (self.positions.len() / 3) as u32 - 1);
    }

    /// The cube [-1, 1]³ mapped by `to`, each face split into `cells` × `cells` squares.
    pub fn cuboid(&mut self, to: DAffine3, cells: u32) {
        for axis in 0..3 {
            for side in [-1.0, 1.0] {
                self.grid(cells, cells, |s, u| {
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = 2.0 * s - 1.0;
                    p[(axis + 2) % 3] = 2.0 * u - 1.0;
                    to.transform_point3(DVec3::from_array(p))
                });
            }
        }
    }

    /// The cylinder of radius 1 around the z axis from z = 0 to 1, mapped by `to`: `segments`
    /// around, `rows` along, with both ends closed when `caps`.
    pub fn cylinder(&mut self, to: DAffine3, segments: u32, rows: u32, caps: bool) {
        let at = |z: f64, a: f64| {
            let angle = a * TAU;
            to.transform_point3(DVec3::new(angle.cos(), angle.sin(), z))
        };
        self.grid(rows, segments, at);
        if caps {
            for z in [0.0, 1.0] {
                self.fan(
                    to.transform_point3(DVec3::new(0.0, 0.0, z)),
                    segments,
                    |a| at(z, a),
                );
            }
        }
    }

    /// The closed sphere of radius `radius(theta, phi)` (theta from the +z pole) mapped by
    /// `to`: `rings` from pole to pole, `segments` around.
    pub fn sphere(
        &mut self,
        to: DAffine3,
        rings: u32,
        segments: u32,
        radius: impl Fn(f64, f64) -> f64,
    ) {
        let at = |theta: f64, phi: f64| {
            let r = radius(theta, phi);
            to.transform_point3(DVec3::new(
                r * theta.sin() * phi.cos(),
                r * theta.sin() * phi.sin(),
                r * theta.cos(),
            ))
        };
        let cap = PI / rings as f64;
        self.grid(rings - 2, segments, |s, u| {
            at(cap + s * (PI - 2.0 * cap), u * TAU)
        });
        self.fan(at(0.0, 0.0), segments, |u| at(cap, u * TAU));
        self.fan(at(PI, 0.0), segments, |u| at(PI - cap, u * TAU));
    }

    /// The triangles as vertex triples.
    pub fn triangles(&self) -> Vec<[Vec3A; 3]> {
        let vertex = |i: u32| Vec3A::from_slice(&self.positions[3 * i as usize..][..3]);
        self.indices
            .chunks_exact(3)
            .map(|t| [vertex(t[0]), vertex(t[1]), vertex(t[2])])
            .collect()
    }
}

/// The bounding box of triangles.
pub fn bounds(triangles: &[[Vec3A; 3]]) -> (Vec3A, Vec3A) {
    triangles.iter().flatten().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), &v| (lo.min(v), hi.max(v)),
    )
}

/// A direction uniform on the unit sphere.
pub fn uniform_direction(rng: &mut Rng) -> Vec3A {
    let z = 1.0 - 2.0 * rng.uniform();
    let phi = std::f32::consts::TAU * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3A::new(r * phi.cos(), r * phi.sin(), z)
}

/// A point uniform in the box `(lo, hi)`.
pub fn point_in_bounds((lo, hi): (Vec3A, Vec3A), rng: &mut Rng) -> Vec3A {
    lo + (hi - lo) * Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform())
}

/// A ray from a point uniform in `bounds` in a uniform direction, t in [0, tmax].
pub fn random_ray(bounds: (Vec3A, Vec3A), tmax: f32, rng: &mut Rng) -> Ray {
    let direction = uniform_direction(rng);
    Ray::new(point_in_bounds(bounds, rng), direction, 0.0, tmax)
}

/// The diffuse bounce from `ray`'s hit at `t` on a surface with geometric normal `normal`,
/// as the integrators leave a hit: from `epsilon` off the surface on the side the ray came
/// from, in a cosine-distributed direction about the normal.
pub fn bounce_ray(ray: &Ray, t: f32, normal: Vec3A, epsilon: f32, rng: &mut Rng) -> Ray {
    let normal = if normal.dot(ray.direction) > 0.0 {
        -normal
    } else {
        normal
    };
    let point = ray.origin + ray.direction * t + normal * epsilon;
    let local = cosine_hemisphere(rng.uniform2());
    let direction = OrthonormalBasis::from_normal(normal).to_world(local);
    Ray::new(point, direction.normalize(), 0.0, f32::INFINITY)
}
