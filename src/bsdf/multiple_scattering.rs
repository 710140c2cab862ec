//! Energy compensation for GGX reflection (Kulla and Conty 2017): a single-scattering
//! microfacet lobe loses the light that bounces between microfacets more than once (a white
//! metal at roughness 1 reflects only about a third of it at normal incidence). The
//! compensation adds a lobe
//!
//! f_ms(μo, μi) = F_ms · (1 − E(μo)) (1 − E(μi)) / (π (1 − E_avg)),
//!
//! where E(μ) is the single-scattering albedo of a white (F = 1) GGX reflector for light
//! arriving at cosine μ and E_avg = 2 ∫ E(μ) μ dμ its cosine-weighted mean. For F = 1 the two
//! lobes together reflect exactly 1 at every angle; for a coloured Fresnel F_ms =
//! F_avg² E_avg / (1 − F_avg (1 − E_avg)) sums the bounces' geometric series with the mean
//! Fresnel reflectance F_avg.
//!
//! E is tabulated over (μ, roughness) on first use (about 0.1 s), by a deterministic
//! quadrature over the half vectors, and interpolated bilinearly; E_avg is the exact cosine-weighted
//! integral of the interpolated E, so the compensated white reflector's albedo is 1 up to the
//! table's error in E alone.
//!
//! The same quadrature tabulates the reflectance of a GGX coat with Schlick's Fresnel: the
//! Fresnel-weighted share of what its single scattering reflects, E_F(μ) / E(μ) =
//! F0 + (1 − F0) E_s(μ) / E(μ), with E_F the albedo with Fresnel and E_s the albedo weighted
//! by (1 − wo·h)⁵ (linear in F0, so one table serves every index of refraction). It is the
//! albedo the coat would have with its multiple scattering restored (1 for F = 1), and the
//! metallic-roughness model scales its diffuse base by what it leaves
//! ([`CoatReflectance`]).
//!
//! A third table holds the mean of (1 − wo·h)⁵ over the normals visible from wo (all of
//! them, whether their reflection leaves the surface or not): Schlick's Fresnel averaged
//! the way an index-matched rough interface's microfacets pass light straight on
//! ([`visible_schlick_mean`]).

use super::microfacet::{MIN_ALPHA, TrowbridgeReitz};
use super::scattering::reflect;
use glam::Vec3A;
use std::sync::OnceLock;

/// Table nodes over μ = cos θ in [0, 1] (denser near grazing, where E changes fastest: μ =
/// t² at uniform t) and over perceptual roughness in [0, 1] (α = roughness²).
const COSINES: usize = 48;
const ROUGHNESSES: usize = 32;
/// Quadrature nodes per table entry: over the half vector's polar angle (mapped so that
/// they follow GGX's tail) and over its azimuth on one side of the plane of incidence.
const POLAR_NODES: usize = 96;
const AZIMUTH_NODES: usize = 24;

struct AlbedoTable {
    /// E at (roughness j, cosine node i), row-major by roughness.
    albedo: Vec<f32>,
    /// E_avg per roughness node.
    average: Vec<f32>,
    /// E_s / E, E_s the albedo weighted by Schlick's (1 − wo·h)⁵, as `albedo`.
    schlick_share: Vec<f32>,
    /// Its cosine-weighted mean per roughness node, as `average`.
    schlick_share_average: Vec<f32>,
    /// The mean of (1 − wo·h)⁵ over the visible normals, as `albedo`.
    visible_schlick: Vec<f32>,
}

#[inline]
fn cosine_node(i: usize) -> f32 {
    let t = i as f32 / (COSINES - 1) as f32;
    t * t
}

/// The white GGX reflector's albedo at cosine `mu`: ∫ D(h) G2 |wo·h| / μ dω_h over the
/// half vectors that reflect wo above the surface, by the midpoint rule in x with the polar
/// angle θ_h = atan(α tan(πx/2)), which puts the nodes where D's long tail is (sampling
/// the visible normals on a grid would leave the tail, where the loss is, to a node or
/// two), and in the azimuth on one side of the plane of incidence (the integrand is
/// symmetric about it): `polar_nodes` × `azimuth_nodes` nodes.
#[cfg(test)]
pub(crate) fn single_scattering_albedo(
    alpha: f32,
    mu: f32,
    polar_nodes: usize,
    azimuth_nodes: usize,
) -> f64 {
    single_scattering_albedos(alpha, mu, polar_nodes, azimuth_nodes)[0]
}

/// The white albedo E (as [`single_scattering_albedo`]) and E_s, the same integral weighted
/// by Schlick's (1 − wo·h)⁵, in one quadrature.
#[cfg(test)]
pub(crate) fn single_scattering_albedos(
    alpha: f32,
    mu: f32,
    polar_nodes: usize,
    azimuth_nodes: usize,
) -> [f64; 2] {
    let [e, e_s, _] = albedo_quadrature(alpha, mu, polar_nodes, azimuth_nodes);
    [e, e_s]
}

/// E and E_s (as [`single_scattering_albedos`]) and the mean of (1 − wo·h)⁵ over the
/// normals visible from wo, the density D(h) max(0, wo·h) normalised by the same
/// quadrature's own sum.
fn albedo_quadrature(alpha: f32, mu: f32, polar_nodes: usize, azimuth_nodes: usize) -> [f64; 3] {
    use std::f64::consts::PI;
    let distribution = TrowbridgeReitz::new(alpha);
    let alpha = alpha.max(MIN_ALPHA);
    let mu = mu.max(1e-4);
    let wo = Vec3A::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let alpha = alpha as f64;
    let (mut sum, mut schlick) = (0.0f64, 0.0f64);
    let (mut visible, mut visible_schlick) = (0.0f64, 0.0f64);
    // The azimuths' sines and cosines, once rather than per polar node.
    let azimuths: Vec<(f64, f64)> = (0..azimuth_nodes)
        .map(|j| (PI * (j as f64 + 0.5) / azimuth_nodes as f64).sin_cos())
        .collect();
    for i in 0..polar_nodes {
        let x = (i as f64 + 0.5) / polar_nodes as f64;
        let t = (PI / 2.0 * x).tan();
        let theta = (alpha * t).atan();
        // dθ/dx, with the sine of the solid angle.
        let d_theta = alpha * PI / 2.0 * (1.0 + t * t) / (1.0 + alpha * alpha * t * t);
        let (sin, cos) = theta.sin_cos();
        for &(sin_phi, cos_phi) in &azimuths {
            let h = Vec3A::new((sin * cos_phi) as f32, (sin * sin_phi) as f32, cos as f32);
            let cos_oh = wo.dot(h);
            if cos_oh <= 0.0 {
                continue;
            }
            let seen = distribution.d(h) as f64 * cos_oh as f64 * sin * d_theta;
            visible += seen;
            visible_schlick += seen * (1.0 - cos_oh as f64).powi(5);
            let wi = reflect(wo, h);
            if wi.z <= 0.0 {
                continue;
            }
            let f = distribution.d(h) as f64 * distribution.g2(wo, wi) as f64 * cos_oh as f64;
            sum += f * sin * d_theta;
            schlick += f * sin * d_theta * (1.0 - cos_oh as f64).powi(5);
        }
    }
    // Both sides of the plane: 2 × π / azimuth_nodes per azimuth node.
    let scale = 2.0 * PI / (azimuth_nodes * polar_nodes) as f64 / mu as f64;
    let visible_mean = if visible > 0.0 {
        visible_schlick / visible
    } else {
        0.0
    };
    [sum * scale, schlick * scale, visible_mean]
}

/// 2 ∫ E(μ) μ dμ of the E that is linear in μ between the cosine nodes, segment by segment
/// exactly.
fn cosine_weighted_mean(row: &[f32]) -> f32 {
    let mut integral = 0.0f64;
    for i in 0..COSINES - 1 {
        let (a, b) = (cosine_node(i) as f64, cosine_node(i + 1) as f64);
        let (ea, eb) = (row[i] as f64, row[i + 1] as f64);
        let slope = (eb - ea) / (b - a);
        let at = |x: f64| (ea - slope * a) * x * x / 2.0 + slope * x * x * x / 3.0;
        integral += at(b) - at(a);
    }
    (2.0 * integral).min(1.0) as f32
}

#[inline]
fn table() -> &'static AlbedoTable {
    static TABLE: OnceLock<AlbedoTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut albedo = Vec::with_capacity(COSINES * ROUGHNESSES);
        let mut schlick_share = Vec::with_capacity(COSINES * ROUGHNESSES);
        let mut average = Vec::with_capacity(ROUGHNESSES);
        let mut schlick_share_average = Vec::with_capacity(ROUGHNESSES);
        let mut visible_schlick = Vec::with_capacity(COSINES * ROUGHNESSES);
        for j in 0..ROUGHNESSES {
            let roughness = j as f32 / (ROUGHNESSES - 1) as f32;
            let alpha = roughness * roughness;
            let mut share_row = Vec::with_capacity(COSINES);
            let row: Vec<f32> = (0..COSINES)
                .map(|i| {
                    let [e, e_s, visible_mean] =
                        albedo_quadrature(alpha, cosine_node(i), POLAR_NODES, AZIMUTH_NODES);
                    let share = if e > 0.0 { (e_s / e).min(1.0) } else { 1.0 };
                    share_row.push(share as f32);
                    visible_schlick.push(visible_mean.min(1.0) as f32);
                    e.min(1.0) as f32
                })
                .collect();
            average.push(cosine_weighted_mean(&row));
            schlick_share_average.push(cosine_weighted_mean(&share_row));
            albedo.extend(row);
            schlick_share.extend(share_row);
        }
        AlbedoTable {
            albedo,
            average,
            schlick_share,
            schlick_share_average,
            visible_schlick,
        }
    })
}

/// The mean of Schlick's (1 − wo·h)⁵ over the microfacet normals visible from a direction
/// at cosine `mu` to the normal, GGX of perceptual roughness `roughness` (> 0).
#[inline]
pub(crate) fn visible_schlick_mean(roughness: f32, mu: f32) -> f32 {
    let (j, w) = roughness_cell(roughness);
    lookup(&table().visible_schlick, j, w, mu)
}

/// The roughness node below `roughness` and the weight of the one above.
#[inline]
fn roughness_cell(roughness: f32) -> (usize, f32) {
    let x = roughness.clamp(0.0, 1.0) * (ROUGHNESSES - 1) as f32;
    let j = (x as usize).min(ROUGHNESSES - 2);
    (j, x - j as f32)
}

/// A tabulated albedo (`albedo` or `schlick` of the table) at roughness node `j` plus
/// weight `w` towards the next, and cosine `mu`: bilinear, linear in μ between the nodes
/// (the integral of the averages assumes it).
#[inline]
fn lookup(values: &[f32], j: usize, w: f32, mu: f32) -> f32 {
    let t = mu.clamp(0.0, 1.0).sqrt() * (COSINES - 1) as f32;
    let i = (t as usize).min(COSINES - 2);
    let (a, b) = (cosine_node(i), cosine_node(i + 1));
    let s = ((mu - a) / (b - a)).clamp(0.0, 1.0);
    let row = |j: usize| {
        let e = &values[j * COSINES..];
        e[i] * (1.0 - s) + e[i + 1] * s
    };
    row(j) * (1.0 - w) + row(j + 1) * w
}

/// A GGX reflector's compensation at one roughness: E and E_avg looked up in the table.
#[derive(Clone, Copy, Debug)]
pub(crate) struct EnergyCompensation {
    roughness_node: usize,
    roughness_weight: f32,
    /// 1 − E_avg.
    missing_average: f32,
}

/// Below this 1 − E_avg (roughness under about 0.03) nothing is missing to compensate, and
/// the lobe's normalization would divide rounding by rounding.
const NEGLIGIBLE: f32 = 1e-4;

impl EnergyCompensation {
    /// The compensation at perceptual roughness `roughness`, or `None` where the single
    /// scattering loses (next to) nothing.
    pub fn new(roughness: f32) -> Option<Self> {
        let table = table();
        let (j, w) = roughness_cell(roughness);
        let average = table.average[j] * (1.0 - w) + table.average[j + 1] * w;
        let missing_average = 1.0 - average;
        (missing_average > NEGLIGIBLE).then_some(EnergyCompensation {
            roughness_node: j,
            roughness_weight: w,
            missing_average,
        })
    }

    /// E(μ): the white single-scattering lobe's albedo at cosine `mu`.
    pub fn albedo(&self, mu: f32) -> f32 {
        lookup(
            &table().albedo,
            self.roughness_node,
            self.roughness_weight,
            mu,
        )
    }

    /// The white compensation lobe f_ms at cosines `mu_o`, `mu_i` (without F_ms).
    pub fn f(&self, mu_o: f32, mu_i: f32) -> f32 {
        (1.0 - self.albedo(mu_o)) * (1.0 - self.albedo(mu_i))
            / (std::f32::consts::PI * self.missing_average)
    }

    /// F_ms for a mean Fresnel reflectance `f_avg`: the share of the light missing from
    /// single scattering that the bounces between microfacets of that reflectance return.
    pub fn fresnel(&self, f_avg: f32) -> f32 {
        let average = 1.0 - self.missing_average;
        f_avg * f_avg * average / (1.0 - f_avg * self.missing_average)
    }
}

/// The reflectance of a dielectric coat, GGX of perceptual roughness `roughness` with
/// Schlick's Fresnel of normal reflectance F0: the Fresnel-weighted share of what it
/// reflects by single scattering, R(μ) = F0 + (1 − F0) E_s(μ) / E(μ), and its
/// cosine-weighted mean. At roughness 0 it is Schlick's F itself, exactly, and its mean
/// F0 + (1 − F0) / 21.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CoatReflectance {
    f0: f32,
    /// The table's rows of E_s / E at the roughness nodes below and above, and the weight
    /// of the one above; `None` at roughness 0.
    rows: Option<(&'static [f32; COSINES], &'static [f32; COSINES], f32)>,
    /// R's cosine-weighted mean.
    average: f32,
}

impl CoatReflectance {
    #[inline]
    pub fn new(roughness: f32, f0: f32) -> Self {
        if roughness <= 0.0 {
            return CoatReflectance {
                f0,
                rows: None,
                average: f0 + (1.0 - f0) / 21.0,
            };
        }
        let table = table();
        let (j, w) = roughness_cell(roughness);
        let row = |j: usize| -> &'static [f32; COSINES] {
            table.schlick_share[j * COSINES..(j + 1) * COSINES]
                .try_into()
                .expect("a row of the table")
        };
        let shares = &table.schlick_share_average;
        CoatReflectance {
            f0,
            rows: Some((row(j), row(j + 1), w)),
            average: f0 + (1.0 - f0) * (shares[j] * (1.0 - w) + shares[j + 1] * w),
        }
    }

    /// R(μ): the coat's reflectance for light arriving at cosine `mu` (linear in μ between
    /// the table's nodes, as the mean's integral assumes).
    #[inline]
    pub fn reflectance(&self, mu: f32) -> f32 {
        let mu = mu.clamp(0.0, 1.0);
        let share = match self.rows {
            None => (1.0 - mu).powi(5),
            Some((lower, upper, w)) => {
                let i = ((mu.sqrt() * (COSINES - 1) as f32) as usize).min(COSINES - 2);
                let (a, b) = (cosine_node(i), cosine_node(i + 1));
                let s = ((mu - a) / (b - a)).clamp(0.0, 1.0);
                let at = |row: &[f32; COSINES]| row[i] + (row[i + 1] - row[i]) * s;
                at(lower) + (at(upper) - at(lower)) * w
            }
        };
        self.f0 + (1.0 - self.f0) * share
    }

    /// The cosine-weighted mean of R.
    #[inline]
    pub fn average(&self) -> f32 {
        self.average
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The compensation lobe returns what single scattering misses: ∫ f_ms μi dωi = 1 − E(μo)
    /// (its normalization by E_avg), and a coloured Fresnel returns less of it.
    #[test]
    fn compensation_lobe_returns_the_missing_energy() {
        for roughness in [0.3f32, 0.6, 1.0] {
            let compensation = EnergyCompensation::new(roughness).unwrap();
            for mu_o in [0.1f32, 0.5, 1.0] {
                let n = 20_000;
                let integral: f64 = (0..n)
                    .map(|k| {
                        let mu_i = (k as f32 + 0.5) / n as f32;
                        (compensation.f(mu_o, mu_i) * mu_i) as f64
                    })
                    .sum::<f64>()
                    * std::f64::consts::TAU
                    / n as f64;
                let missing = 1.0 - compensation.albedo(mu_o) as f64;
                assert!(
                    (integral - missing).abs() < 1e-3 * missing.max(1e-2),
                    "roughness {roughness} μo {mu_o}: {integral} vs {missing}"
                );
            }
            assert!((compensation.fresnel(1.0) - 1.0).abs() < 1e-6);
            assert!(compensation.fresnel(0.5) < 0.5);
        }
        assert!(EnergyCompensation::new(0.0).is_none());
    }

    /// The coat's tabulated reflectance is the quadrature of GGX with Schlick's Fresnel
    /// at fine resolution (within the table's interpolation), its mean the cosine-weighted
    /// integral of it, and at roughness 0 Schlick's F and its mean exactly.
    #[test]
    fn coat_reflectance_is_the_fresnel_share_of_the_single_scattering() {
        for roughness in [0.1f32, 0.45, 0.8, 1.0] {
            for f0 in [0.02f32, 0.04, 0.17] {
                let coat = CoatReflectance::new(roughness, f0);
                for mu in [0.05f32, 0.3, 0.7, 1.0] {
                    let [e, e_s] = single_scattering_albedos(roughness * roughness, mu, 1500, 180);
                    let fine = f0 as f64 + (1.0 - f0 as f64) * e_s / e;
                    let table = coat.reflectance(mu) as f64;
                    assert!(
                        (table - fine).abs() < 2e-3 + 1e-2 * fine,
                        "roughness {roughness} F0 {f0} μ {mu}: table {table}, quadrature {fine}"
                    );
                }
                let n = 4000;
                let mean: f64 = (0..n)
                    .map(|k| {
                        let mu = (k as f32 + 0.5) / n as f32;
                        (coat.reflectance(mu) * mu) as f64
                    })
                    .sum::<f64>()
                    * 2.0
                    / n as f64;
                assert!(
                    (mean - coat.average() as f64).abs() < 1e-4,
                    "roughness {roughness} F0 {f0}: {mean} vs {}",
                    coat.average()
                );
            }
        }
        let smooth = CoatReflectance::new(0.0, 0.04);
        assert_eq!(smooth.reflectance(1.0), 0.04);
        assert!((smooth.reflectance(0.0) - 1.0).abs() < 1e-6);
        assert!((smooth.average() - (0.04 + 0.96 / 21.0)).abs() < 1e-7);
    }
}
