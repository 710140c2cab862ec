//! Warps from the unit square to the domains the integrators sample.

use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, PI};

/// Cosine-weighted direction around +z (Malley's method over a concentric disk).
#[inline]
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3A {
    let [dx, dy] = uniform_disk(u);
    let z = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
    Vec3A::new(dx, dy, z)
}

#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Shirley–Chiu concentric map from the unit square to the unit disk.
#[inline]
pub fn uniform_disk(u: [f32; 2]) -> [f32; 2] {
    let ox = 2.0 * u[0] - 1.0;
    let oy = 2.0 * u[1] - 1.0;
    if ox == 0.0 && oy == 0.0 {
        return [0.0, 0.0];
    }
    let (r, theta) = if ox.abs() > oy.abs() {
        (ox, (PI / 4.0) * (oy / ox))
    } else {
        (oy, PI / 2.0 - (PI / 4.0) * (ox / oy))
    };
    let (s, c) = theta.sin_cos();
    [r * c, r * s]
}

/// Barycentric coordinates (b1, b2) of a uniformly distributed point on a triangle.
#[inline]
pub fn uniform_triangle(u: [f32; 2]) -> [f32; 2] {
    // Heitz's low-distortion mapping keeps neighbouring samples neighbours.
    let (b0, b1);
    if u[0] < u[1] {
        b0 = u[0] / 2.0;
        b1 = u[1] - b0;
    } else {
        b1 = u[1] / 2.0;
        b0 = u[0] - b1;
    }
    [b0, b1]
}

/// Veach's power heuristic with β = 2 for two strategies with one sample each.
#[inline]
pub fn power_heuristic(pdf_this: f32, pdf_other: f32) -> f32 {
    let a = pdf_this * pdf_this;
    let b = pdf_other * pdf_other;
    if a + b > 0.0 { a / (a + b) } else { 0.0 }
}

/// A right-handed frame around a unit normal (Duff et al. 2017, branchless).
#[derive(Clone, Copy, Debug)]
pub struct OrthonormalBasis {
    pub tangent: Vec3A,
    pub bitangent: Vec3A,
    pub normal: Vec3A,
}

impl OrthonormalBasis {
    #[inline]
    pub fn from_normal(n: Vec3A) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let tangent = Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bitangent = Vec3A::new(b, sign + n.y * n.y * a, -n.y);
        OrthonormalBasis {
            tangent,
            bitangent,
            normal: n,
        }
    }

    #[inline]
    pub fn to_world(self, v: Vec3A) -> Vec3A {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn cosine_hemisphere_matches_its_pdf() {
        // E[1/pdf] over the hemisphere = hemisphere solid angle = 2π.
        let mut rng = Rng::new(1, 1);
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let d = cosine_hemisphere(rng.uniform2());
            assert!((d.length() - 1.0).abs() < 1e-4);
            assert!(d.z >= 0.0);
            let pdf = cosine_hemisphere_pdf(d.z);
            if pdf > 1e-3 {
                sum += (1.0 / pdf as f64).min(1e6);
            }
        }
        let est = sum / n as f64;
        // Mass lost by the pdf > 1e-3 cut is below 2e-5 of 2π; variance-limited tolerance ~1%.
        assert!((est - 2.0 * std::f64::consts::PI).abs() < 0.2, "{est}");
    }

    #[test]
    fn basis_is_orthonormal() {
        let mut rng = Rng::new(2, 2);
        for _ in 0..1000 {
            let v = Vec3A::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            )
            .normalize();
            let b = OrthonormalBasis::from_normal(v);
            assert!(b.tangent.dot(b.bitangent).abs() < 1e-5);
            assert!(b.tangent.dot(b.normal).abs() < 1e-5);
            assert!((b.tangent.cross(b.bitangent) - b.normal).length() < 1e-4);
        }
    }

    #[test]
    fn uniform_triangle_stays_inside() {
        let mut rng = Rng::new(3, 3);
        for _ in 0..10_000 {
            let [b1, b2] = uniform_triangle(rng.uniform2());
            assert!(b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 + 1e-6);
        }
    }
}
