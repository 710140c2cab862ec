//! Lights at infinity that rays can hit: the environment map (or constant colour) and the
//! sun's disc, sampled together as one light.

use crate::sampling::Distribution2D;
use crate::scene::light_desc::{EnvironmentDesc, SunDesc};
use crate::spectrum::Spectrum;
use glam::Vec3A;
use std::f32::consts::PI;

/// An equirectangular radiance map (see `EnvironmentDesc` for the layout), sampled in
/// proportion to luminance times sin θ.
#[derive(Clone, Debug)]
pub(crate) struct EnvironmentMap {
    /// Scaled radiance, rows from the top.
    texels: Vec<Spectrum>,
    width: usize,
    height: usize,
    /// cos and sin of the rotation about +Y.
    rotation: (f32, f32),
    /// Over (u, v); `None` for a 1 × 1 map, which is sampled uniformly over the sphere.
    distribution: Option<Distribution2D>,
    /// ∫ luminance dω.
    luminance_integral: f32,
}

impl EnvironmentMap {
    pub fn new(desc: &EnvironmentDesc) -> EnvironmentMap {
        let (width, height) = (desc.width as usize, desc.height as usize);
        let texels: Vec<Spectrum> = desc
            .pixels
            .chunks_exact(3)
            .map(|t| Spectrum::new(t[0], t[1], t[2]) * desc.scale)
            .collect();
        let (sin, cos) = desc.rotation_degrees.to_radians().sin_cos();
        let row_sin = |row: usize| (PI * (row as f32 + 0.5) / height as f32).sin();
        let mut luminance_integral = 0.0f64;
        let texel_solid_angle = 2.0 * PI * PI / (width * height) as f32;
        for (i, texel) in texels.iter().enumerate() {
            luminance_integral +=
                (texel.luminance() * row_sin(i / width) * texel_solid_angle) as f64;
        }
        let distribution = (width * height > 1).then(|| {
            let weights: Vec<f32> = texels
                .iter()
                .enumerate()
                .map(|(i, texel)| texel.luminance() * row_sin(i / width))
                .collect();
            Distribution2D::new(&weights, width, height)
        });
        let luminance_integral = if distribution.is_none() {
            4.0 * PI * texels[0].luminance()
        } else {
            luminance_integral as f32
        };
        EnvironmentMap {
            texels,
            width,
            height,
            rotation: (cos, sin),
            distribution,
            luminance_integral,
        }
    }

    pub fn luminance_integral(&self) -> f32 {
        self.luminance_integral
    }

    /// World direction → the map's own frame.
    #[inline]
    fn to_local(&self, w: Vec3A) -> Vec3A {
        let (c, s) = self.rotation;
        Vec3A::new(c * w.x - s * w.z, w.y, s * w.x + c * w.z)
    }

    #[inline]
    fn to_world(&self, local: Vec3A) -> Vec3A {
        let (c, s) = self.rotation;
        Vec3A::new(
            c * local.x + s * local.z,
            local.y,
            -s * local.x + c * local.z,
        )
    }

    /// (u, v) of a local direction, and sin θ.
    #[inline]
    fn uv(local: Vec3A) -> ([f32; 2], f32) {
        let mut u = local.x.atan2(-local.z) * (0.5 / PI);
        if u < 0.0 {
            u += 1.0;
        }
        // θ from atan2 and sin θ from x and z keep their precision near the poles, where
        // acos(y) and √(1 − y²) lose it (and the density divides by sin θ).
        let sin_theta = (local.x * local.x + local.z * local.z).sqrt();
        let v = sin_theta.atan2(local.y) * (1.0 / PI);
        (
            [
                u.min(1.0 - f32::EPSILON / 2.0),
                v.min(1.0 - f32::EPSILON / 2.0),
            ],
            sin_theta,
        )
    }

    #[inline]
    fn texel(&self, [u, v]: [f32; 2]) -> Spectrum {
        let column = ((u * self.width as f32) as usize).min(self.width - 1);
        let row = ((v * self.height as f32) as usize).min(self.height - 1);
        self.texels[row * self.width + column]
    }

    /// Radiance arriving from direction `w` (unit, pointing away from the scene).
    #[inline]
    pub fn radiance(&self, w: Vec3A) -> Spectrum {
        if self.distribution.is_none() {
            return self.texels[0];
        }
        self.texel(Self::uv(self.to_local(w)).0)
    }

    /// A direction sampled in proportion to luminance · sin θ, its radiance and its density
    /// in solid angle.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> Option<(Vec3A, Spectrum, f32)> {
        let Some(distribution) = &self.distribution else {
            let local = uniform_sphere(u);
            return Some((local, self.texels[0], 1.0 / (4.0 * PI)));
        };
        let (uv, pdf_uv) = distribution.sample(u);
        if pdf_uv <= 0.0 {
            return None;
        }
        let (sin_phi, cos_phi) = (2.0 * PI * uv[0]).sin_cos();
        let (sin_theta, cos_theta) = (PI * uv[1]).sin_cos();
        if sin_theta <= 0.0 {
            return None;
        }
        let local = Vec3A::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta);
        let pdf = pdf_uv / (2.0 * PI * PI * sin_theta);
        Some((self.to_world(local), self.texel(uv), pdf))
    }

    /// Density of `sample` at direction `w`, in solid angle.
    #[inline]
    pub fn pdf(&self, w: Vec3A) -> f32 {
        let Some(distribution) = &self.distribution else {
            return 1.0 / (4.0 * PI);
        };
        let (uv, sin_theta) = Self::uv(self.to_local(w));
        if sin_theta <= 0.0 {
            return 0.0;
        }
        distribution.pdf(uv) / (2.0 * PI * PI * sin_theta)
    }
}

/// A uniformly distributed unit vector.
#[inline]
pub(crate) fn uniform_sphere(u: [f32; 2]) -> Vec3A {
    let y = 1.0 - 2.0 * u[1];
    let r = (1.0 - y * y).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * u[0]).sin_cos();
    Vec3A::new(r * sin_phi, y, -r * cos_phi)
}

/// The sun's disc: uniform radiance within a cone about `toward`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SunDisc {
    toward: Vec3A,
    radiance: Spectrum,
    /// sin² of the angular radius: the membership test (|w × toward|² against it) keeps its
    /// precision for the real sun's 0.27°, where 1 − cos is 1e-5.
    sin2_radius: f32,
    /// 1 − cos of the angular radius, computed in double precision.
    one_minus_cos: f32,
}

impl SunDisc {
    /// The disc of a sun with a positive angular radius.
    pub fn new(desc: &SunDesc) -> SunDisc {
        let radius = (desc.angular_radius_degrees as f64).to_radians();
        let sin = radius.sin();
        let [r, g, b] = desc.disc_radiance().map(|l| l as f32);
        SunDisc {
            toward: Vec3A::from(desc.direction).normalize(),
            radiance: Spectrum::new(r, g, b),
            sin2_radius: (sin * sin) as f32,
            one_minus_cos: (2.0 * (radius / 2.0).sin().powi(2)) as f32,
        }
    }

    #[inline]
    fn solid_angle(&self) -> f32 {
        2.0 * PI * self.one_minus_cos
    }

    pub fn luminance_integral(&self) -> f32 {
        self.radiance.luminance() * self.solid_angle()
    }

    #[inline]
    fn contains(&self, w: Vec3A) -> bool {
        w.dot(self.toward) > 0.0 && w.cross(self.toward).length_squared() <= self.sin2_radius
    }

    #[inline]
    pub fn radiance(&self, w: Vec3A) -> Spectrum {
        if self.contains(w) {
            self.radiance
        } else {
            Spectrum::ZERO
        }
    }

    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> Vec3A {
        let t = u[0] * self.one_minus_cos;
        let cos_theta = 1.0 - t;
        let sin_theta = (t * (2.0 - t)).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let local = Vec3A::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta);
        crate::sampling::OrthonormalBasis::from_normal(self.toward).to_world(local)
    }

    #[inline]
    pub fn pdf(&self, w: Vec3A) -> f32 {
        if self.contains(w) {
            1.0 / self.solid_angle()
        } else {
            0.0
        }
    }
}

/// Everything at infinity that rays can hit, sampled as one light: a mixture of the
/// environment's and the sun's densities, in proportion to their ∫ luminance dω, so that
/// the radiance of a direction (the sum of both) over the mixture's density is the estimate.
#[derive(Clone, Debug)]
pub(crate) struct InfiniteLight {
    pub environment: Option<EnvironmentMap>,
    pub sun: Option<SunDisc>,
    /// Probability of sampling the environment rather than the sun.
    environment_fraction: f32,
}

impl InfiniteLight {
    pub fn new(environment: Option<EnvironmentMap>, sun: Option<SunDisc>) -> InfiniteLight {
        let e = environment.as_ref().map_or(0.0, |e| e.luminance_integral());
        let s = sun.as_ref().map_or(0.0, |s| s.luminance_integral());
        let environment_fraction = if e + s > 0.0 {
            e / (e + s)
        } else if environment.is_some() {
            1.0
        } else {
            0.0
        };
        InfiniteLight {
            environment,
            sun,
            environment_fraction,
        }
    }

    /// ∫ luminance dω over every direction.
    pub fn luminance_integral(&self) -> f32 {
        self.environment
            .as_ref()
            .map_or(0.0, |e| e.luminance_integral())
            + self.sun.as_ref().map_or(0.0, |s| s.luminance_integral())
    }

    /// Radiance arriving from direction `w` (unit, pointing away from the scene).
    #[inline]
    pub fn radiance(&self, w: Vec3A) -> Spectrum {
        let mut l = Spectrum::ZERO;
        if let Some(environment) = &self.environment {
            l += environment.radiance(w);
        }
        if let Some(sun) = &self.sun {
            l += sun.radiance(w);
        }
        l
    }

    /// Density in solid angle of `sample` choosing `w`.
    #[inline]
    pub fn pdf(&self, w: Vec3A) -> f32 {
        let mut pdf = 0.0;
        if let Some(environment) = &self.environment {
            pdf += self.environment_fraction * environment.pdf(w);
        }
        if let Some(sun) = &self.sun {
            pdf += (1.0 - self.environment_fraction) * sun.pdf(w);
        }
        pdf
    }

    /// A direction towards the light, the radiance arriving from it and its density.
    #[inline]
    pub fn sample(&self, [u0, u1]: [f32; 2]) -> Option<(Vec3A, Spectrum, f32)> {
        let q = self.environment_fraction;
        let w = if u0 < q {
            let u0 = (u0 / q).min(1.0 - f32::EPSILON / 2.0);
            self.environment.as_ref()?.sample([u0, u1])?.0
        } else {
            let u0 = ((u0 - q) / (1.0 - q)).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
            self.sun.as_ref()?.sample([u0, u1])
        };
        let pdf = self.pdf(w);
        (pdf > 0.0).then(|| (w, self.radiance(w), pdf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A 16 × 8 map with a gradient, a dark band and one bright texel.
    fn test_map() -> (Vec<f32>, u32, u32) {
        let (w, h) = (16u32, 8u32);
        let mut pixels = Vec::new();
        for row in 0..h {
            for column in 0..w {
                let value = if row == 6 {
                    0.0
                } else {
                    0.2 + 0.1 * column as f32
                };
                pixels.extend_from_slice(&[value, value * 0.5, 0.1]);
            }
        }
        let bright = (2 * w + 11) as usize * 3;
        pixels[bright..bright + 3].copy_from_slice(&[40.0, 30.0, 20.0]);
        (pixels, w, h)
    }

    fn map(rotation_degrees: f32) -> EnvironmentMap {
        let (pixels, width, height) = test_map();
        EnvironmentMap::new(&EnvironmentDesc {
            pixels: &pixels,
            width,
            height,
            rotation_degrees,
            scale: 1.5,
        })
    }

    /// The sampled directions' histogram over cells of the sphere matches the density
    /// integrated over each cell (χ² test), for the map as given and rotated; and the
    /// density integrates to 1.
    #[test]
    fn sampled_directions_follow_the_density() {
        // Cells of half a texel in θ and φ; the rotation (3 columns) keeps them aligned
        // with the texels, where density · sin θ is constant, so each cell's probability is
        // exact: pdf(centre) · sin θ(centre) · Δθ · Δφ.
        for rotation in [0.0, 67.5] {
            let env = map(rotation);
            let (nt, np) = (16usize, 32usize);
            let (dt, dp) = (PI / nt as f32, 2.0 * PI / np as f32);
            let world = |theta: f32, phi: f32| {
                Vec3A::new(
                    phi.sin() * theta.sin(),
                    theta.cos(),
                    -phi.cos() * theta.sin(),
                )
            };
            let cell = |w: Vec3A| {
                let theta = (w.x * w.x + w.z * w.z).sqrt().atan2(w.y);
                let mut phi = w.x.atan2(-w.z);
                if phi < 0.0 {
                    phi += 2.0 * PI;
                }
                ((theta / dt) as usize).min(nt - 1) * np + ((phi / dp) as usize).min(np - 1)
            };
            let mut expected = vec![0.0f64; nt * np];
            for i in 0..nt {
                for j in 0..np {
                    let theta = (i as f32 + 0.5) * dt;
                    let w = world(theta, (j as f32 + 0.5) * dp);
                    expected[i * np + j] = (env.pdf(w) * theta.sin() * dt * dp) as f64;
                }
            }
            let total: f64 = expected.iter().sum();
            assert!(
                (total - 1.0).abs() < 1e-4,
                "the density integrates to {total}"
            );
            let n = 400_000;
            let mut counts = vec![0u32; nt * np];
            let mut rng = Rng::new(5, 1);
            // Samples whose direction, rounded, falls into a neighbouring texel on the way
            // back (only at texel edges).
            let mut edge_cases = 0;
            for _ in 0..n {
                let (w, radiance, pdf) = env.sample(rng.uniform2()).unwrap();
                assert!((w.length() - 1.0).abs() < 1e-4);
                let relative = (pdf - env.pdf(w)).abs() / pdf;
                if relative > 1e-3 || radiance != env.radiance(w) {
                    edge_cases += 1;
                }
                counts[cell(w)] += 1;
            }
            assert!(
                edge_cases < n / 10_000,
                "{edge_cases} samples disagree with pdf()"
            );
            let mut chi2 = 0.0;
            let mut bins = 0;
            for (count, p) in counts.iter().zip(&expected) {
                let e = p * n as f64;
                if e > 5.0 {
                    chi2 += (*count as f64 - e).powi(2) / e;
                    bins += 1;
                } else {
                    assert!((*count as f64) < e + 6.0 * e.sqrt() + 10.0);
                }
            }
            // χ² with `bins` − 1 degrees of freedom: mean k, σ √(2k); 5σ.
            let k = (bins - 1) as f64;
            assert!(
                chi2 < k + 5.0 * (2.0 * k).sqrt(),
                "rotation {rotation}: χ² {chi2} over {bins} bins"
            );
        }
    }

    /// The rotation turns the map about +Y as documented: what the unrotated map shows
    /// along d arrives from R_y(α) d (R_y the right-handed rotation), and the density turns
    /// with it. The map's centre looks along +Z.
    #[test]
    fn rotation_turns_the_map_about_y() {
        let (unrotated, rotated) = (map(0.0), map(67.5));
        let (sin, cos) = 67.5f32.to_radians().sin_cos();
        let r_y = |d: Vec3A| Vec3A::new(cos * d.x + sin * d.z, d.y, -sin * d.x + cos * d.z);
        let mut rng = Rng::new(8, 8);
        for _ in 0..1000 {
            let d = uniform_sphere(rng.uniform2());
            assert_eq!(rotated.radiance(r_y(d)), unrotated.radiance(d));
            let (a, b) = (rotated.pdf(r_y(d)), unrotated.pdf(d));
            assert!((a - b).abs() <= 1e-4 * a.max(b), "{a} vs {b}");
        }
        // Column u = 0.5 (φ = π) is the direction +Z.
        assert_eq!(EnvironmentMap::uv(Vec3A::Z).0, [0.5, 0.5]);
    }

    /// A deliberate error the χ² test must catch: forgetting the sin θ factor.
    #[test]
    fn the_histogram_test_catches_a_missing_sin_theta() {
        let env = map(0.0);
        let mut rng = Rng::new(5, 2);
        // Fraction of samples in the top quarter of the sphere (y > 0.5) against the
        // density's prediction, and against a density without sin θ.
        let n = 200_000;
        let hits = (0..n)
            .filter(|_| env.sample(rng.uniform2()).unwrap().0.y > 0.5)
            .count();
        let (mut with_sin, mut without_sin) = (0.0f64, 0.0f64);
        let steps = 400;
        for i in 0..steps {
            for j in 0..steps {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / steps as f32;
                let phi = 2.0 * PI * (j as f32 + 0.5) / steps as f32;
                let r = (1.0 - y * y).sqrt();
                let w = Vec3A::new(r * phi.sin(), y, -r * phi.cos());
                if y > 0.5 {
                    let solid = 4.0 * PI as f64 / (steps * steps) as f64;
                    with_sin += env.pdf(w) as f64 * solid;
                    // Without sin θ: the density per (u, v) over 2π² (no 1/sin θ).
                    without_sin += (env.pdf(w) * r) as f64 * solid;
                }
            }
        }
        let frequency = hits as f64 / n as f64;
        let sigma = (frequency * (1.0 - frequency) / n as f64).sqrt();
        assert!(
            (frequency - with_sin).abs() < 5.0 * sigma,
            "{frequency} vs {with_sin}"
        );
        assert!(
            (frequency - without_sin).abs() > 5.0 * sigma,
            "{frequency} vs {without_sin}"
        );
    }

    /// A map that is black but for one texel is sampled only there, with the radiance over
    /// the density integrating that texel's power exactly.
    #[test]
    fn a_single_bright_texel_is_where_samples_go() {
        let (w, h) = (32u32, 16u32);
        let mut pixels = vec![0.0f32; (w * h * 3) as usize];
        let (row, column) = (5usize, 20usize);
        let i = (row * w as usize + column) * 3;
        pixels[i..i + 3].copy_from_slice(&[3.0, 2.0, 1.0]);
        let env = EnvironmentMap::new(&EnvironmentDesc {
            pixels: &pixels,
            width: w,
            height: h,
            rotation_degrees: 0.0,
            scale: 1.0,
        });
        let mut rng = Rng::new(1, 1);
        let mut estimate = Spectrum::ZERO;
        let n = 10_000;
        for _ in 0..n {
            let (dir, radiance, pdf) = env.sample(rng.uniform2()).unwrap();
            let ([u, v], _) = EnvironmentMap::uv(dir);
            assert_eq!(
                ((v * h as f32) as usize, (u * w as f32) as usize),
                (row, column)
            );
            estimate += radiance / pdf / n as f32;
        }
        // The texel's solid angle: Δφ (cos θ0 − cos θ1).
        let theta = |r: usize| PI * r as f32 / h as f32;
        let solid = 2.0 * PI / w as f32 * (theta(row).cos() - theta(row + 1).cos());
        let expected = Spectrum::new(3.0, 2.0, 1.0) * solid;
        // Piecewise-constant in (u, v) with the density's sin θ at each sample: within the
        // texel sin θ varies, so the estimate is exact only on average.
        assert!(
            ((estimate - expected).abs() / expected).max_component() < 0.01,
            "{estimate} vs {expected}"
        );
    }

    /// A sun disc: its radiance over the density integrates to the given irradiance times
    /// the mean cosine (≈ 1 for a small disc), and the membership test is sharp at 0.27°.
    #[test]
    fn sun_disc_integrates_to_its_irradiance() {
        for radius in [0.27f32, 5.0] {
            let sun = SunDisc::new(&SunDesc {
                direction: [0.3, 1.0, -0.2],
                angular_radius_degrees: radius,
                irradiance: [2.0, 1.0, 0.5],
            });
            let mut rng = Rng::new(3, 3);
            let mut irradiance = Spectrum::ZERO;
            let n = 20_000;
            for _ in 0..n {
                let w = sun.sample(rng.uniform2());
                assert!(sun.contains(w));
                irradiance += sun.radiance(w) * w.dot(sun.toward) / sun.pdf(w) / n as f32;
            }
            let expected = Spectrum::new(2.0, 1.0, 0.5);
            assert!(
                ((irradiance - expected).abs() / expected).max_component() < 1e-3,
                "{radius}: {irradiance}"
            );
            // Just outside the disc: nothing.
            let basis = crate::sampling::OrthonormalBasis::from_normal(sun.toward);
            let outside = (radius * 1.01).to_radians();
            let w = basis.to_world(Vec3A::new(outside.sin(), 0.0, outside.cos()));
            assert_eq!(sun.radiance(w), Spectrum::ZERO);
        }
    }
}
