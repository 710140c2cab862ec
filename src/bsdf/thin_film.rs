//! A thin film over the specular reflection (`KHR_materials_iridescence`): a dielectric
//! layer of index n₂ and thickness d between the outside (index 1) and the base, whose two
//! interfaces' reflections interfere.
//!
//! The interfaces are the specification's: Schlick's Fresnel at each, R₁₂ with
//! F0 = ((n₂ − 1) / (n₂ + 1))² at the outside cosine cos θ₁ and R₂₃ with
//! F0 = ((n₃ − n₂) / (n₃ + n₂))² at the cosine inside the film, cos θ₂ (Snell's law), where
//! the base's index n₃ = (1 + √F0) / (1 − √F0) is derived from the base's normal
//! reflectance F0 (a real index, for metals too, as the specification does). Polarization is
//! ignored: each reflection's amplitude is ±√R, negative where the light meets a denser
//! medium (the specification's phase shifts of 0 or π; the sign of every amplitude flipped
//! at once gives the same reflectance). The film's reflectance at wavelength λ is then the
//! sum of all the waves it reflects (Airy's), exactly:
//!
//! R(λ) = |(a + b e^{iΦ}) / (1 + a b e^{iΦ})|² = (a² + b² + 2ab cos Φ) / (1 + a²b² + 2ab cos Φ),
//!
//! with a = ±√R₁₂, b = ±√R₂₃ and the phase difference Φ = 2π OPD / λ of the optical path
//! difference OPD = 2 n₂ d cos θ₂. |a|, |b| ≤ 1 make it a reflectance in [0, 1].
//!
//! Spectral renders evaluate it at each lane's wavelength: exact for the specification's
//! model. RGB renders need the colour it gives white light: the reflectance integrated over
//! the wavelengths weighted by what each carries of white light in linear sRGB (D65 through
//! the CIE 1931 observer, the weights a spectral render's film uses). As a function of Φ it
//! has the Fourier series (the Poisson kernel)
//!
//! R = 1 − K (1 + 2 Σₘ (−ab)ᵐ cos mΦ), K = (1 − a²)(1 − b²) / (1 − a²b²),
//!
//! so the integral is 1 − K (1 + 2 Σₘ (−ab)ᵐ C(m · OPD)) with C(x) the cosine transform of the
//! weights, ∫ w(λ) cos(2πx/λ) dλ, tabulated once per channel (Belcour and Barla's
//! Fourier-space integration, here with the renderer's own colour matching and every term
//! of the series until it is negligible). RGB mode is exact where a and b are the same at
//! every wavelength (a dielectric base with a white specular colour), up to the table's
//! interpolation; with a coloured base (a metal) each channel uses its own base F0, which
//! approximates the spectral base. Where the integrated colour is outside sRGB (negative, or
//! above what the film reflects at any wavelength) it is clamped to [0, the film's largest
//! reflectance], which keeps it a reflectance.

use crate::spectral::white_light_srgb_per_nm;
use crate::spectrum::Spectrum;
use std::f32::consts::TAU;
use std::sync::OnceLock;

/// The thin film at a surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ThinFilm {
    /// How much of the specular reflection's Fresnel term is the film's, in (0, 1].
    pub factor: f32,
    /// The film's index of refraction, > 0.
    pub ior: f32,
    /// Its thickness in nanometres, > 0.
    pub thickness: f32,
    /// The wavelengths (nm) of the path's lanes in a spectral render; `None` in RGB.
    pub wavelengths: Option<[f32; 4]>,
}

/// Base normal reflectances are kept below 1, where the derived index would be infinite.
const MAX_BASE_F0: f32 = 0.9999;

/// Schlick's Fresnel.
#[inline]
fn schlick(f0: f32, cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    f0 + (1.0 - f0) * (m * m) * (m * m) * m
}

/// The normal reflectance between indices `n1` and `n2`.
#[inline]
fn normal_reflectance(n1: f32, n2: f32) -> f32 {
    let r = (n1 - n2) / (n1 + n2);
    r * r
}

/// The index of a base of normal reflectance `f0` under vacuum.
#[inline]
fn index_of_f0(f0: f32) -> f32 {
    let s = f0.clamp(0.0, MAX_BASE_F0).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// The film's two interfaces at one outside cosine.
#[derive(Clone, Copy, Debug)]
struct Interfaces {
    /// The signed amplitude of the outer interface's reflection.
    a: f32,
    /// The cosine inside the film.
    cos_inside: f32,
}

/// The signed amplitude of a reflection from index `from` at a medium of index `to` with
/// reflectance `r`: negative where the light meets a denser medium.
#[inline]
fn amplitude(r: f32, from: f32, to: f32) -> f32 {
    if to > from { -r.sqrt() } else { r.sqrt() }
}

/// The film's reflectance at phase difference cos Φ = `cos_phase` for amplitudes `a`, `b`.
#[inline]
pub(crate) fn airy(a: f32, b: f32, cos_phase: f32) -> f32 {
    let ab = 2.0 * a * b * cos_phase;
    let denominator = 1.0 + a * a * b * b + ab;
    if denominator <= 0.0 {
        return 1.0;
    }
    ((a * a + b * b + ab) / denominator).clamp(0.0, 1.0)
}

/// The largest reflectance of a film with amplitudes `a`, `b` at any phase.
#[inline]
fn envelope(a: f32, b: f32) -> f32 {
    let r = (a.abs() + b.abs()) / (1.0 + (a * b).abs());
    (r * r).min(1.0)
}

impl ThinFilm {
    /// The outer interface at outside cosine `cos`; `None` where the film reflects
    /// everything (total internal reflection into a film of index below 1).
    #[inline]
    fn interfaces(&self, cos: f32) -> Option<Interfaces> {
        let cos = cos.clamp(0.0, 1.0);
        let r12 = schlick(normal_reflectance(self.ior, 1.0), cos);
        let sin_inside2 = (1.0 - cos * cos) / (self.ior * self.ior);
        if sin_inside2 >= 1.0 {
            return None;
        }
        Some(Interfaces {
            a: amplitude(r12, 1.0, self.ior),
            cos_inside: (1.0 - sin_inside2).sqrt(),
        })
    }

    /// The signed amplitude of the inner interface's reflection over a base of normal
    /// reflectance `base_f0`.
    #[inline]
    fn inner_amplitude(&self, base_f0: f32, cos_inside: f32) -> f32 {
        let base_ior = index_of_f0(base_f0);
        let r23 = schlick(normal_reflectance(base_ior, self.ior), cos_inside);
        amplitude(r23, self.ior, base_ior)
    }

    /// The film's reflectance per lane at outside cosine `cos`, over a base whose normal
    /// reflectance per lane is `base_f0` (see the module's documentation): at each lane's
    /// wavelength in a spectral render, integrated over each channel's wavelengths in RGB.
    #[inline]
    pub fn reflectance(&self, base_f0: Spectrum, cos: f32) -> Spectrum {
        let Some(Interfaces { a, cos_inside }) = self.interfaces(cos) else {
            return Spectrum::ONE;
        };
        let path_difference = 2.0 * self.ior * self.thickness * cos_inside;
        match self.wavelengths {
            Some(lambda) => {
                let mut lanes = [0.0; 4];
                for (lane, (r, lambda)) in lanes.iter_mut().zip(lambda).enumerate() {
                    let b = self.inner_amplitude(base_f0[lane], cos_inside);
                    *r = airy(a, b, (TAU * path_difference / lambda).cos());
                }
                Spectrum::from_lanes(lanes)
            }
            None => {
                let b = [0, 1, 2].map(|c| self.inner_amplitude(base_f0[c], cos_inside));
                let [r, g, b] = white_light_reflectance(a, b, path_difference);
                Spectrum::new(r, g, b)
            }
        }
    }

    /// An upper bound of the film's largest reflectance over the lanes of `base_f0`, at a
    /// cosine where the two interfaces' reflectances are `outer` and `inner` (or more): the
    /// reflectance of waves in phase, for the largest inner reflectance among the lanes.
    /// Increasing in both.
    #[inline]
    pub fn envelope_of(outer: f32, inner: f32) -> f32 {
        envelope(outer.clamp(0.0, 1.0).sqrt(), inner.clamp(0.0, 1.0).sqrt())
    }

    /// The normal reflectances of the outer interface and the largest of the inner one's
    /// over the lanes of `base_f0` (three in RGB).
    #[inline]
    pub fn interface_f0s(&self, base_f0: Spectrum) -> (f32, f32) {
        let lanes = if self.wavelengths.is_some() { 4 } else { 3 };
        let inner = (0..lanes)
            .map(|l| normal_reflectance(index_of_f0(base_f0[l]), self.ior))
            .fold(0.0f32, f32::max);
        (normal_reflectance(self.ior, 1.0), inner)
    }
}

/// Optical path differences between the table's nodes, nm.
const PATH_STEP: f32 = 2.0;
/// The table ends here, and the series' terms beyond are dropped: over its last quarter
/// every channel's cosine transform is below `SMALL_TRANSFORM` (tested; the red channel's
/// decays slowest, as its weights have the sharpest features), so a dropped term changes a
/// channel by less than 2 K |ab|ᵐ × 0.01: at most 2·10⁻⁴ for the films of glTF's sample
/// assets (|ab| ≤ 0.01 face-on) even at a micrometre's optical path difference, more only
/// towards grazing angles, where the film reflects nearly everything anyway.
const PATH_MAX: f32 = 20_000.0;
#[cfg(test)]
const SMALL_TRANSFORM: f32 = 0.01;
/// The series stops where its terms' amplitudes (−ab)ᵐ are below this.
const NEGLIGIBLE_TERM: f32 = 1e-5;

/// C(x) for x = 0, `PATH_STEP`, … `PATH_MAX`: per linear sRGB channel, the cosine transform
/// Σ w(λ) cos(2πx/λ) of white light's per-nanometre colours w (360–830 nm at 1 nm), divided
/// by Σ w (so that C(0) = 1 and a constant reflectance keeps its grey exactly).
fn cosine_transforms() -> &'static [[f32; 3]] {
    static TABLE: OnceLock<Vec<[f32; 3]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let weights: Vec<(f64, [f64; 3])> = (360..=830)
            .map(|l| (l as f64, white_light_srgb_per_nm(l as f32)))
            .collect();
        let totals = [0, 1, 2].map(|c| weights.iter().map(|(_, w)| w[c]).sum::<f64>());
        let nodes = (PATH_MAX / PATH_STEP) as usize + 1;
        (0..nodes)
            .map(|i| {
                let x = i as f64 * PATH_STEP as f64;
                let mut sum = [0.0f64; 3];
                for (lambda, w) in &weights {
                    let c = (std::f64::consts::TAU * x / lambda).cos();
                    for (s, w) in sum.iter_mut().zip(w) {
                        *s += w * c;
                    }
                }
                [0, 1, 2].map(|c| (sum[c] / totals[c]) as f32)
            })
            .collect()
    })
}

/// C(x) per channel, linear between the nodes; 0 beyond the table.
#[inline]
fn cosine_transform(table: &[[f32; 3]], x: f32) -> Option<[f32; 3]> {
    let t = x / PATH_STEP;
    let i = t as usize;
    if i + 1 >= table.len() {
        return None;
    }
    let s = t - i as f32;
    let (lo, hi) = (table[i], table[i + 1]);
    Some([0, 1, 2].map(|c| lo[c] + (hi[c] - lo[c]) * s))
}

/// The linear sRGB a film with outer amplitude `a` and inner amplitudes `b` (per channel)
/// reflects of white light at optical path difference `path_difference` nm (see the
/// module's documentation), clamped to [0, the largest reflectance at any wavelength].
fn white_light_reflectance(a: f32, b: [f32; 3], path_difference: f32) -> [f32; 3] {
    let table = cosine_transforms();
    let ratio = b.map(|b| -a * b);
    let mut power = ratio;
    let mut series = [0.0f32; 3];
    let step = path_difference.max(0.0);
    let mut x = step;
    // Each term's amplitude falls by |ab| < 1; the transform vanishes past the table.
    while power.iter().any(|p| p.abs() > NEGLIGIBLE_TERM) {
        let Some(transform) = cosine_transform(table, x) else {
            break;
        };
        for c in 0..3 {
            series[c] += power[c] * transform[c];
            power[c] *= ratio[c];
        }
        x += step;
    }
    [0, 1, 2].map(|c| {
        let ab2 = ratio[c] * ratio[c];
        if ab2 >= 1.0 {
            return 1.0;
        }
        let k = (1.0 - a * a) * (1.0 - b[c] * b[c]) / (1.0 - ab2);
        (1.0 - k * (1.0 + 2.0 * series[c])).clamp(0.0, envelope(a, b[c]))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textbook single film on a dielectric at normal incidence, in complex arithmetic:
    /// r = (r₁₂ + r₂₃ e^{2iδ}) / (1 + r₁₂ r₂₃ e^{2iδ}), r_ij = (n_i − n_j) / (n_i + n_j),
    /// δ = 2π n₂ d / λ.
    fn textbook_normal_incidence(n2: f64, n3: f64, d: f64, lambda: f64) -> f64 {
        let r12 = (1.0 - n2) / (1.0 + n2);
        let r23 = (n2 - n3) / (n2 + n3);
        let delta = std::f64::consts::TAU * n2 * d / lambda;
        let (s, c) = (2.0 * delta).sin_cos();
        // Numerator and denominator as complex numbers (re, im).
        let num = (r12 + r23 * c, r23 * s);
        let den = (1.0 + r12 * r23 * c, r12 * r23 * s);
        (num.0 * num.0 + num.1 * num.1) / (den.0 * den.0 + den.1 * den.1)
    }

    fn spectral_film(ior: f32, thickness: f32, lambda: [f32; 4]) -> ThinFilm {
        ThinFilm {
            factor: 1.0,
            ior,
            thickness,
            wavelengths: Some(lambda),
        }
    }

    /// At normal incidence Schlick's Fresnel is exact, so the film's reflectance is the
    /// textbook Airy formula's, at every wavelength and thickness, films denser and rarer
    /// than the base alike.
    #[test]
    fn normal_incidence_is_the_textbook_airy_formula() {
        let lambda = [380.0, 470.0, 555.0, 700.0];
        for (n2, n3) in [(1.3f32, 1.5f32), (2.0, 1.5), (1.8, 1.2), (1.45, 3.0)] {
            let base_f0 = Spectrum::splat(normal_reflectance(n3, 1.0));
            for d in [0.0f32, 50.0, 120.0, 333.0, 400.0, 1000.0] {
                let r = spectral_film(n2, d, lambda).reflectance(base_f0, 1.0);
                for (l, lambda) in lambda.iter().enumerate() {
                    let expected =
                        textbook_normal_incidence(n2 as f64, n3 as f64, d as f64, *lambda as f64);
                    assert!(
                        (r[l] as f64 - expected).abs() < 2e-5,
                        "n2 {n2} n3 {n3} d {d} λ {lambda}: {} vs {expected}",
                        r[l]
                    );
                }
            }
        }
    }

    /// A film of thickness 0 is no film: at normal incidence the two interfaces reflect
    /// as the base alone does, ((n₃ − 1) / (n₃ + 1))².
    #[test]
    fn zero_thickness_at_normal_incidence_is_the_bases_fresnel() {
        for n3 in [1.2f32, 1.5, 2.4] {
            let f0 = normal_reflectance(n3, 1.0);
            for n2 in [1.1f32, 1.3, 1.9, 2.6] {
                let r = spectral_film(n2, 0.0, [400.0, 500.0, 600.0, 700.0])
                    .reflectance(Spectrum::splat(f0), 1.0);
                assert!(
                    (r[0] - f0).abs() < 1e-5,
                    "n2 {n2} n3 {n3}: {} vs {f0}",
                    r[0]
                );
            }
        }
    }

    /// The reflectance stays in [0, 1] and under the envelope over a sweep of angles,
    /// thicknesses, film and base indices, spectral and RGB.
    #[test]
    fn reflectance_is_in_unit_interval() {
        for ior in [0.8f32, 1.0, 1.3, 1.7, 2.5] {
            for base in [0.0f32, 0.04, 0.2, 0.9, 1.0] {
                for d in [0.0f32, 10.0, 100.0, 400.0, 1200.0] {
                    for i in 0..=20 {
                        let cos = i as f32 / 20.0;
                        let spectral = spectral_film(ior, d, [380.0, 480.0, 580.0, 780.0]);
                        let rgb = ThinFilm {
                            wavelengths: None,
                            ..spectral
                        };
                        for film in [spectral, rgb] {
                            let r = film.reflectance(Spectrum::new(base, 0.5 * base, 0.0), cos);
                            for l in 0..4 {
                                assert!(
                                    (0.0..=1.0).contains(&r[l]),
                                    "{film:?} cos {cos} base {base}: {r}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// The table's end: the channels' transforms are small there (see `PATH_MAX`).
    #[test]
    fn cosine_transform_vanishes_past_the_table() {
        let table = cosine_transforms();
        let tail = &table[table.len() * 3 / 4..];
        let largest = tail
            .iter()
            .flat_map(|c| c.iter())
            .fold(0.0f32, |m, c| m.max(c.abs()));
        assert!(largest < SMALL_TRANSFORM, "{largest}");
        assert!((table[0][0] - 1.0).abs() < 1e-6);
    }

    /// The RGB colour is the spectral reflectance integrated numerically (trapezoids of
    /// 0.25 nm over 360–830 nm against white light's per-nanometre colours, the weights of
    /// a spectral render's film; no series, no table), clamped as the RGB colour is. What
    /// may differ is the table's 1 nm sums and linear interpolation (at most
    /// (2π/λ)² h²/8 ≈ 1.2·10⁻⁴ of a transform at h = 2 nm, λ = 400 nm, times 2K|ab| ≤ 0.1
    /// here) and the dropped tail: the tolerance, 2·10⁻⁴, is a quarter of 2% of the
    /// smallest reflectance compared (a glass's 0.04; measured: 5·10⁻⁵).
    #[test]
    fn rgb_is_the_integrated_spectral_reflectance() {
        let mut worst = 0.0f64;
        let mut compared = 0;
        for (ior, base) in [(1.3f32, 0.04f32), (2.0, 0.04), (1.5, 0.2), (1.3, 0.9)] {
            for d in [50.0f32, 150.0, 300.0, 400.0, 700.0, 2000.0] {
                for cos in [1.0f32, 0.8, 0.5, 0.2] {
                    let rgb = ThinFilm {
                        factor: 1.0,
                        ior,
                        thickness: d,
                        wavelengths: None,
                    };
                    let film = |lambda: f32| ThinFilm {
                        wavelengths: Some([lambda; 4]),
                        ..rgb
                    };
                    let base_f0 = Spectrum::splat(base);
                    let mut integral = [0.0f64; 3];
                    let mut total = [0.0f64; 3];
                    let steps = (830 - 360) * 4;
                    for k in 0..=steps {
                        let lambda = 360.0 + k as f32 * 0.25;
                        let end = if k == 0 || k == steps { 0.5 } else { 1.0 };
                        let w = white_light_srgb_per_nm(lambda);
                        let r = film(lambda).reflectance(base_f0, cos)[0] as f64;
                        for c in 0..3 {
                            integral[c] += end * w[c] * r;
                            total[c] += end * w[c];
                        }
                    }
                    let got = rgb.reflectance(base_f0, cos);
                    for c in 0..3 {
                        // The clamp to the envelope, computed independently: the in-phase
                        // sum of the two interfaces' amplitudes.
                        let film = film(500.0);
                        let (a, b) = {
                            let i = film.interfaces(cos).unwrap();
                            (i.a, film.inner_amplitude(base, i.cos_inside))
                        };
                        let largest = ((a.abs() + b.abs()) / (1.0 + (a * b).abs())).powi(2);
                        let expected = (integral[c] / total[c]).clamp(0.0, largest as f64);
                        let error = (got[c] as f64 - expected).abs();
                        worst = worst.max(error);
                        compared += 1;
                        assert!(
                            error < 2e-4,
                            "ior {ior} base {base} d {d} cos {cos} channel {c}: {} vs {expected}",
                            got[c]
                        );
                    }
                }
            }
        }
        assert!(compared > 200, "{compared}");
        eprintln!("largest difference {worst:e} over {compared} channels");
    }
}
