//! The sheen layer of `KHR_materials_sheen`: the back-scattering of velvet's fibres as a
//! microfacet lobe with the "Charlie" distribution of Estevez and Kulla (2017),
//!
//! f_sheen = sheen_color · D(h) · V(μo, μi), D(h) = (2 + 1/α) sin(θh)^(1/α) / (2π),
//! V = 1 / ((1 + Λ(μo) + Λ(μi)) 4 μo μi),
//!
//! with α = sheen_roughness² and Λ the specification's fit of the Charlie shadowing (its
//! normative choice; Ashikhmin's simpler visibility would not conserve energy under albedo
//! scaling). α is kept at least [`MIN_ALPHA`]: the specification's default roughness 0
//! would be a lobe of zero width.
//!
//! The layer over the metallic-roughness material is the specification's albedo scaling in
//! its reciprocal form: f = f_sheen + f_base · min(1 − c E(μo), 1 − c E(μi)), with c the
//! sheen colour's largest channel and E the white sheen lobe's directional albedo. The
//! minimum is symmetric in wo and wi, and the base reflects at most 1 − c E(μo) of what
//! arrives from wo while the sheen reflects c E(μo) or less: never more than 1 in a
//! furnace. (The specification's cheaper form, 1 − c E(μo) alone, would not be reciprocal.)
//!
//! The fitted shadowing does not conserve energy at low roughness: the lobe's directional
//! albedo reaches 2.9 at grazing angles at roughness 0.07 (1.15 at 0.2; at most 1 from
//! 0.25 up). Where it exceeds 1 the lobe is normalized, reciprocally, to
//! f_sheen n(μo) n(μi) with n = 1 / max(1, E_spec): its albedo is then at most 1, and
//! elsewhere it is the specification's lobe exactly.
//!
//! E_spec and the normalized lobe's E are tabulated over (μ, roughness) on first use by a
//! deterministic quadrature over wi (about 4 million evaluations of the lobe, 6 million
//! with the normalized rows' second pass) and interpolated bilinearly.
//! `sample` draws the lobe's directions uniformly over the hemisphere: the lobe is broad,
//! and peaks at grazing angles that cosine sampling would seldom reach.

use crate::spectrum::Spectrum;
use glam::Vec3A;
use std::f32::consts::PI;
use std::sync::OnceLock;

/// The smallest α = roughness² of the Charlie distribution (roughness 0.07).
pub(crate) const MIN_ALPHA: f32 = 0.0049;

/// Table nodes over μ = cos θ in [0, 1] (μ = t² at uniform t, denser at grazing angles) and
/// over perceptual sheen roughness in [0, 1].
const COSINES: usize = 32;
const ROUGHNESSES: usize = 32;
/// Quadrature nodes per table entry: over wi's polar angle and over its azimuth on one side
/// of the plane of incidence (the lobe is symmetric about it).
const POLAR_NODES: usize = 128;
const AZIMUTH_NODES: usize = 32;

/// The Charlie distribution D(h) for cos θh = `cos_h`.
#[inline]
pub(crate) fn distribution(alpha: f32, cos_h: f32) -> f32 {
    let inverse = 1.0 / alpha;
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + inverse) * sin2.powf(0.5 * inverse) / (2.0 * PI)
}

/// The specification's fit L(x) of the Charlie shadowing's exponent at α.
#[inline]
fn exponent_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |a: f32, b: f32| a + (b - a) * t;
    let a = mix(21.5473, 25.3245);
    let b = mix(3.82987, 3.32435);
    let c = mix(0.19823, 0.16801);
    let d = mix(-1.97760, -1.27393);
    let e = mix(-4.32054, -4.85967);
    a / (1.0 + b * x.powf(c)) + d * x + e
}

/// Λ(μ) of the Charlie shadowing (the specification's fit, mirrored about μ = 0.5).
#[inline]
pub(crate) fn lambda(alpha: f32, mu: f32) -> f32 {
    // A rounded cosine above 1 would take the fit's power of a negative number.
    let mu = mu.abs().min(1.0);
    if mu < 0.5 {
        exponent_fit(mu, alpha).exp()
    } else {
        (2.0 * exponent_fit(0.5, alpha) - exponent_fit(1.0 - mu, alpha)).exp()
    }
}

/// The white lobe D V for `wo`, `wi` on the same side (z > 0, in the frame of the normal).
#[inline]
fn white_f(alpha: f32, wo: Vec3A, wi: Vec3A, lambda_o: f32) -> f32 {
    let h = wo + wi;
    let length2 = h.length_squared();
    if length2 <= 0.0 {
        return 0.0;
    }
    let cos_h = h.z / length2.sqrt();
    let visibility = 1.0 / ((1.0 + lambda_o + lambda(alpha, wi.z)) * (4.0 * wo.z * wi.z));
    distribution(alpha, cos_h) * visibility
}

/// α of perceptual sheen roughness `roughness`.
#[inline]
pub(crate) fn alpha_of(roughness: f32) -> f32 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// The white sheen lobe's directional albedo E(μ) = ∫ D V μi dωi at α, by the midpoint rule
/// over wi's polar angle and its azimuth on one side of the plane of incidence:
/// `polar_nodes` × `azimuth_nodes` nodes.
#[cfg(test)]
pub(crate) fn directional_albedo(
    alpha: f32,
    mu: f32,
    polar_nodes: usize,
    azimuth_nodes: usize,
) -> f64 {
    weighted_albedo(alpha, mu, polar_nodes, azimuth_nodes, |_| 1.0)
}

/// ∫ D V n(μi) μi dωi, as [`directional_albedo`] with the weight `n` of wi's cosine.
pub(crate) fn weighted_albedo(
    alpha: f32,
    mu: f32,
    polar_nodes: usize,
    azimuth_nodes: usize,
    n: impl Fn(f32) -> f32,
) -> f64 {
    use std::f64::consts::PI;
    let mu = mu.clamp(1e-4, 1.0);
    let wo = Vec3A::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let lambda_o = lambda(alpha, mu);
    let azimuths: Vec<(f32, f32)> = (0..azimuth_nodes)
        .map(|j| {
            let (s, c) = (PI * (j as f64 + 0.5) / azimuth_nodes as f64).sin_cos();
            (s as f32, c as f32)
        })
        .collect();
    let mut sum = 0.0f64;
    for i in 0..polar_nodes {
        let theta = PI / 2.0 * (i as f64 + 0.5) / polar_nodes as f64;
        let (sin, cos) = theta.sin_cos();
        let mut ring = 0.0f64;
        for &(sin_phi, cos_phi) in &azimuths {
            let wi = Vec3A::new(sin as f32 * cos_phi, sin as f32 * sin_phi, cos as f32);
            ring += white_f(alpha, wo, wi, lambda_o) as f64;
        }
        sum += ring * cos * sin * n(cos as f32) as f64;
    }
    // Both sides of the plane: 2 × π / azimuth_nodes per azimuth node, π/2 / polar_nodes.
    sum * 2.0 * PI / azimuth_nodes as f64 * (PI / 2.0) / polar_nodes as f64
}

#[inline]
fn cosine_node(i: usize) -> f32 {
    let t = i as f32 / (COSINES - 1) as f32;
    t * t
}

struct AlbedoTable {
    /// The specification's lobe's E at (roughness node j, cosine node i), row-major by
    /// roughness: where it exceeds 1 the lobe is normalized.
    specification: Vec<f32>,
    /// The normalized lobe's albedo, as `specification`.
    normalized: Vec<f32>,
}

/// The value at cosine `mu` of a row of the table, linear in μ between the nodes.
#[inline]
fn interpolate(row: &[f32; COSINES], mu: f32) -> f32 {
    let mu = mu.abs().min(1.0);
    let i = ((mu.sqrt() * (COSINES - 1) as f32) as usize).min(COSINES - 2);
    let (a, b) = (cosine_node(i), cosine_node(i + 1));
    let s = ((mu - a) / (b - a)).clamp(0.0, 1.0);
    row[i] + (row[i + 1] - row[i]) * s
}

/// The normalization of the lobe at a cosine whose specification albedo is `albedo`.
#[inline]
fn normalization(albedo: f32) -> f32 {
    1.0 / albedo.max(1.0)
}

fn table() -> &'static AlbedoTable {
    static TABLE: OnceLock<AlbedoTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut specification = Vec::with_capacity(COSINES * ROUGHNESSES);
        let mut normalized = Vec::with_capacity(COSINES * ROUGHNESSES);
        for j in 0..ROUGHNESSES {
            let alpha = alpha_of(j as f32 / (ROUGHNESSES - 1) as f32);
            let row: [f32; COSINES] = std::array::from_fn(|i| {
                weighted_albedo(alpha, cosine_node(i), POLAR_NODES, AZIMUTH_NODES, |_| 1.0) as f32
            });
            let n = |mu: f32| normalization(interpolate(&row, mu));
            // The rows where the specification's lobe conserves energy need no second pass.
            let normalized_row: [f32; COSINES] = if row.iter().all(|&e| e <= 1.0) {
                row
            } else {
                std::array::from_fn(|i| {
                    let mu = cosine_node(i);
                    n(mu) * weighted_albedo(alpha, mu, POLAR_NODES, AZIMUTH_NODES, n) as f32
                })
            };
            specification.extend(row);
            normalized.extend(normalized_row.map(|e| e.min(1.0)));
        }
        AlbedoTable {
            specification,
            normalized,
        }
    })
}

/// A sheen layer: its colour, α and the table's rows of E at its roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Sheen {
    /// Linear, each lane at most `color_max`.
    color: Spectrum,
    /// The colour's largest RGB channel, in (0, 1]: what scales the layers beneath.
    color_max: f32,
    alpha: f32,
    /// The table's rows (the specification's E, the normalized lobe's) at the roughness
    /// nodes below and above, and the weight of the one above.
    rows: [(&'static [f32; COSINES], &'static [f32; COSINES]); 2],
    weight: f32,
}

impl Sheen {
    /// The layer of colour `color` (its lanes clamped to `color_max`, the RGB colour's largest
    /// channel, in [0, 1]) and perceptual roughness `roughness` in [0, 1]; `None` without
    /// sheen (`color_max` 0).
    #[inline]
    pub fn new(color: Spectrum, color_max: f32, roughness: f32) -> Option<Sheen> {
        if color_max <= 0.0 {
            return None;
        }
        let table = table();
        let x = roughness.clamp(0.0, 1.0) * (ROUGHNESSES - 1) as f32;
        let j = (x as usize).min(ROUGHNESSES - 2);
        let row = |values: &'static [f32], j: usize| -> &'static [f32; COSINES] {
            values[j * COSINES..(j + 1) * COSINES]
                .try_into()
                .expect("a row of the table")
        };
        let rows = |values: &'static [f32]| (row(values, j), row(values, j + 1));
        Some(Sheen {
            color: color.min(Spectrum::splat(color_max)),
            color_max,
            alpha: alpha_of(roughness),
            rows: [rows(&table.specification), rows(&table.normalized)],
            weight: x - j as f32,
        })
    }

    /// Table `k` (0 the specification's E, 1 the normalized lobe's) at cosine `mu`.
    #[inline]
    fn lookup(&self, k: usize, mu: f32) -> f32 {
        let (lower, upper) = self.rows[k];
        let below = interpolate(lower, mu);
        below + (interpolate(upper, mu) - below) * self.weight
    }

    /// E(μ): the white lobe's directional albedo for light arriving at cosine `mu`.
    #[inline]
    pub fn albedo(&self, mu: f32) -> f32 {
        self.lookup(1, mu)
    }

    /// The normalization n(μ) = 1 / max(1, E_spec(μ)) of the lobe (1 where the
    /// specification's conserves energy).
    #[inline]
    fn normalization(&self, mu: f32) -> f32 {
        normalization(self.lookup(0, mu))
    }

    /// What the layers beneath keep of their f for cosines `mu_o`, `mu_i`:
    /// min(1 − c E(μo), 1 − c E(μi)).
    #[inline]
    pub fn scaling(&self, mu_o: f32, mu_i: f32) -> f32 {
        1.0 - self.color_max * self.albedo(mu_o).max(self.albedo(mu_i))
    }

    /// The lobe's albedo at `mu_o` by its largest channel: the lobe choice's estimate.
    #[inline]
    pub fn estimate(&self, mu_o: f32) -> f32 {
        self.color_max * self.albedo(mu_o)
    }

    /// f_sheen for `wo`, `wi` in the frame of the normal on wo's side (wo.z > 0); zero for
    /// `wi` on the other side.
    #[inline]
    pub fn f(&self, wo: Vec3A, wi: Vec3A) -> Spectrum {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Spectrum::ZERO;
        }
        let n = self.normalization(wo.z) * self.normalization(wi.z);
        self.color * (white_f(self.alpha, wo, wi, lambda(self.alpha, wo.z)) * n)
    }
}

/// A direction drawn uniformly over the hemisphere z > 0.
#[inline]
pub(crate) fn uniform_hemisphere(u: [f32; 2]) -> Vec3A {
    let z = u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u[1]).sin_cos();
    Vec3A::new(r * c, r * s, z)
}

/// The density of [`uniform_hemisphere`] per unit solid angle.
pub(crate) const UNIFORM_HEMISPHERE_PDF: f32 = 1.0 / (2.0 * PI);

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables, interpolated between their nodes, are the lobes' albedos by the same
    /// quadrature at 32 times their nodes, within 1% (or 2e-3 where E is small): the
    /// specification's E, and the normalized lobe's (with the table's normalization), which
    /// is at most 1 and is the specification's from roughness 0.25 up.
    #[test]
    fn tables_are_the_directional_albedos() {
        for roughness in [0.0f32, 0.1, 0.2, 0.3, 0.55, 0.8, 1.0] {
            let sheen = Sheen::new(Spectrum::ONE, 1.0, roughness).unwrap();
            let alpha = alpha_of(roughness);
            for mu in [0.02f32, 0.1, 0.3, 0.6, 0.9, 1.0] {
                let fine = directional_albedo(alpha, mu, 1024, 128);
                let table = sheen.lookup(0, mu) as f64;
                let n = |mu| sheen.normalization(mu);
                let normalized = n(mu) as f64 * weighted_albedo(alpha, mu, 1024, 128, n);
                let table_normalized = sheen.albedo(mu) as f64;
                println!(
                    "roughness {roughness} μ {mu}: E {fine:.5} (table {table:.5}), \
                     normalized {normalized:.5} (table {table_normalized:.5})"
                );
                for (table, fine) in [(table, fine), (table_normalized, normalized)] {
                    assert!(
                        (table - fine).abs() < 2e-3 + 1e-2 * fine,
                        "roughness {roughness} μ {mu}: table {table}, quadrature {fine}"
                    );
                }
                assert!(
                    normalized <= 1.003,
                    "roughness {roughness} μ {mu}: {normalized}"
                );
                if roughness >= 0.25 {
                    assert_eq!(sheen.normalization(mu), 1.0);
                }
            }
        }
    }
}
