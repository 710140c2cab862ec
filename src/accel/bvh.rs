//! The default backend: an obvhs compressed wide BVH (CWBVH, 8-wide) with triangles stored
//! in leaf order, traversed with obvhs's node test and our own triangle test.
//!
//! obvhs 0.4 notes: traversal reports positions in `primitive_indices` (leaf order), which is
//! why triangles are permuted into that order here; its node test clips at a fixed t of 1e-4,
//! so geometry closer than that to a ray origin may be missed (integrators offset origins far
//! more than that); the `slow` build presets split triangles, so they are not used.

use super::{Hit, Ray};
use glam::{UVec2, Vec3A};
use obvhs::{
    BvhBuildParams, cwbvh::CwBvh, cwbvh::builder::build_cwbvh_from_tris, triangle::Triangle,
};
use std::time::Duration;

/// A triangle laid out for the intersection test (Möller–Trumbore with the normal precomputed).
#[derive(Clone, Copy, Debug)]
struct IntersectionTriangle {
    v0: Vec3A,
    /// v0 - v1
    e1: Vec3A,
    /// v2 - v0
    e2: Vec3A,
    /// e1 × e2
    ng: Vec3A,
}

impl IntersectionTriangle {
    fn new(v0: Vec3A, v1: Vec3A, v2: Vec3A) -> Self {
        let e1 = v0 - v1;
        let e2 = v2 - v0;
        IntersectionTriangle {
            v0,
            e1,
            e2,
            ng: e1.cross(e2),
        }
    }

    /// Returns (t, u, v) when the ray hits within [tmin, tmax].
    #[inline(always)]
    fn intersect(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32, f32)> {
        let c = self.v0 - origin;
        let r = direction.cross(c);
        let det = self.ng.dot(direction);
        let inv_det = 1.0 / det;
        let u = r.dot(self.e2) * inv_det;
        let v = r.dot(self.e1) * inv_det;
        let t = self.ng.dot(c) * inv_det;
        // Written so NaN (det = 0) fails every comparison.
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= tmin && t <= tmax {
            Some((t, u, v))
        } else {
            None
        }
    }
}

pub struct BvhAccel {
    bvh: CwBvh,
    triangles: Vec<IntersectionTriangle>,
    /// For each leaf-order triangle, its index in the list the BVH was built from.
    build_order: Vec<u32>,
}

impl BvhAccel {
    /// Builds over triangles given as vertex triples. None of them may be degenerate.
    pub fn build(vertices: &[[Vec3A; 3]]) -> Self {
        if vertices.is_empty() {
            return BvhAccel {
                bvh: CwBvh::default(),
                triangles: Vec::new(),
                build_order: Vec::new(),
            };
        }
        let tris: Vec<Triangle> = vertices
            .iter()
            .map(|&[v0, v1, v2]| Triangle { v0, v1, v2 })
            .collect();
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let build_order = bvh.primitive_indices.clone();
        let triangles = build_order
            .iter()
            .map(|&i| {
                let [v0, v1, v2] = vertices[i as usize];
                IntersectionTriangle::new(v0, v1, v2)
            })
            .collect();
        BvhAccel {
            bvh,
            triangles,
            build_order,
        }
    }

    pub fn internal_to_build_order(&self) -> &[u32] {
        &self.build_order
    }

    /// The bytes of the structure, from the arrays' lengths: the CWBVH's nodes and index
    /// array (and exact node boxes, if any), the leaf-order triangles and the build order.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(self.bvh.nodes.as_slice())
            + size_of_val(self.bvh.primitive_indices.as_slice())
            + self
                .bvh
                .exact_node_aabbs
                .as_ref()
                .map_or(0, |boxes| size_of_val(boxes.as_slice()))
            + size_of_val(self.triangles.as_slice())
            + size_of_val(self.build_order.as_slice())
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if self.triangles.is_empty() {
            return None;
        }
        let mut traverse_ray = obvhs::ray::Ray::new(ray.origin, ray.direction, ray.tmin, ray.tmax);
        let mut best: Option<Hit> = None;
        let mut state = self.bvh.new_traversal(ray.direction);
        let mut node;
        obvhs::traverse!(
            self.bvh,
            node,
            state,
            node.intersect_ray(&traverse_ray, state.oct_inv4),
            {
                let id = state.primitive_id;
                // SAFETY-free: indices come from the BVH built over exactly these triangles.
                let tri = &self.triangles[id as usize];
                if let Some((t, u, v)) =
                    tri.intersect(ray.origin, ray.direction, ray.tmin, traverse_ray.tmax)
                {
                    traverse_ray.tmax = t;
                    best = Some(Hit {
                        triangle: id,
                        t,
                        u,
                        v,
                    });
                }
            }
        );
        best
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let traverse_ray = obvhs::ray::Ray::new(ray.origin, ray.direction, ray.tmin, ray.tmax);
        let mut state = self.bvh.new_traversal(ray.direction);
        let mut node;
        // A plain `break` in the macro's primitive block would only leave the loop over the
        // current leaf's triangles and traversal would go on: leave the whole traversal.
        'traversal: {
            obvhs::traverse!(
                self.bvh,
                node,
                state,
                node.intersect_ray(&traverse_ray, state.oct_inv4),
                {
                    let tri = &self.triangles[state.primitive_id as usize];
                    if tri
                        .intersect(ray.origin, ray.direction, ray.tmin, ray.tmax)
                        .is_some()
                    {
                        break 'traversal true;
                    }
                }
            );
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn random_point(rng: &mut Rng) -> Vec3A {
        Vec3A::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0 - 5.0
    }

    /// The BVH must return exactly what testing every triangle returns.
    #[test]
    fn matches_brute_force() {
        let mut rng = Rng::new(5, 5);
        let tris: Vec<[Vec3A; 3]> = (0..500)
            .map(|_| {
                let c = random_point(&mut rng);
                [
                    c,
                    c + random_point(&mut rng) * 0.2,
                    c + random_point(&mut rng) * 0.2,
                ]
            })
            .collect();
        let accel = BvhAccel::build(&tris);
        let brute: Vec<IntersectionTriangle> = tris
            .iter()
            .map(|&[a, b, c]| IntersectionTriangle::new(a, b, c))
            .collect();
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = random_point(&mut rng) * 1.5;
            let d = (random_point(&mut rng)).normalize();
            let ray = Ray::new(o, d, 1e-3, f32::INFINITY);
            let mut best: Option<(f32, usize)> = None;
            for (i, tri) in brute.iter().enumerate() {
                if let Some((t, _, _)) = tri.intersect(o, d, 1e-3, f32::INFINITY)
                    && best.is_none_or(|(bt, _)| t < bt)
                {
                    best = Some((t, i));
                }
            }
            let hit = accel.intersect(&ray);
            match (best, hit) {
                (None, None) => {}
                (Some((t, i)), Some(h)) => {
                    hits += 1;
                    assert_eq!(accel.build_order[h.triangle as usize] as usize, i);
                    assert!((h.t - t).abs() <= 1e-4 * t.max(1.0));
                    let [a, b, c] = tris[i];
                    let p = a * (1.0 - h.u - h.v) + b * h.u + c * h.v;
                    assert!((p - (o + d * h.t)).length() < 1e-3);
                }
                other => panic!("mismatch {other:?}"),
            }
            assert_eq!(accel.occluded(&ray), best.is_some());
        }
        assert!(hits > 1000);
    }
}
