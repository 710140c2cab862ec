//! Geometry shared by the mutation tests' independent computations.

use glam::DVec3;

/// A rectangle o + s·a + t·b, s, t ∈ [0, 1], with its front side along a × b.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rect {
    pub o: DVec3,
    pub a: DVec3,
    pub b: DVec3,
}

impl Rect {
    pub fn point(&self, s: f64, t: f64) -> DVec3 {
        self.o + self.a * s + self.b * t
    }

    pub fn normal(&self) -> DVec3 {
        self.a.cross(self.b).normalize()
    }

    pub fn area(&self) -> f64 {
        self.a.cross(self.b).length()
    }

    /// (s, t) of a point of the rectangle's plane.
    pub fn coordinates(&self, p: DVec3) -> (f64, f64) {
        let d = p - self.o;
        (
            d.dot(self.a) / self.a.length_squared(),
            d.dot(self.b) / self.b.length_squared(),
        )
    }

    /// Midpoint-rule nodes of `k` × `k` cells: (i, j, point, area weight).
    pub fn nodes(&self, k: usize) -> impl Iterator<Item = (usize, usize, DVec3, f64)> + '_ {
        let weight = self.area() / (k * k) as f64;
        (0..k * k).map(move |n| {
            let (i, j) = (n % k, n / k);
            let s = (i as f64 + 0.5) / k as f64;
            let t = (j as f64 + 0.5) / k as f64;
            (i, j, self.point(s, t), weight)
        })
    }
}
