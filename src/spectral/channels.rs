//! What the four lanes of a path's [`Spectrum`]s mean, and the conversions in and out.
//!
//! In RGB mode a path's spectra are linear sRGB (R, G, B, and G again: see `spectrum.rs`)
//! and every conversion is the identity. In spectral mode they are the values at the
//! path's sampled wavelengths: colours given as RGB (materials, textures, lights) become
//! spectra there, and the path's radiance becomes linear sRGB again through CIE XYZ when
//! it leaves the integrator, so the film, the filter and the Metropolis targets (the
//! luminance of that RGB, which is the estimate's Y) see RGB in both modes.

use super::cie::{cie_1931_xyz, d65};
use super::color::linear_srgb_from_xyz;
use super::rgb_to_spectrum::{SigmoidPolynomial, reflectance_coefficients};
use super::wavelengths::{SampledWavelengths, WAVELENGTHS};
use crate::spectrum::Spectrum;
use std::sync::OnceLock;

/// The meaning of a path's spectrum lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Channels {
    /// Linear sRGB.
    Rgb,
    /// Values at these wavelengths.
    Wavelengths(SampledWavelengths),
}

impl Channels {
    /// The channels of a new camera path: RGB, or (`spectral`) wavelengths drawn from `u`.
    /// RGB mode leaves `u` unread, so RGB renders draw the random numbers they always did.
    #[inline]
    pub fn new(spectral: bool, u: impl FnOnce() -> f32) -> Channels {
        if spectral {
            Channels::Wavelengths(SampledWavelengths::sample(u()))
        } else {
            Channels::Rgb
        }
    }

    /// The reflectance (or transmittance) given as linear sRGB `rgb`: each channel within
    /// [0, 1] by the smooth, bounded upsampling; above 1 the spectrum of the colour divided
    /// by its largest channel, scaled back up.
    // The RGB case inline and the spectral one out of line: RGB renders pay one branch.
    #[inline(always)]
    pub fn reflectance(&self, rgb: [f32; 3]) -> Spectrum {
        match self {
            Channels::Rgb => Spectrum::from(rgb),
            Channels::Wavelengths(w) => spectral_reflectance(w, rgb),
        }
    }

    /// The emitted radiance given as linear sRGB `rgb` (unbounded): a smooth spectrum of
    /// the colour's chromaticity times sRGB's illuminant, D65, scaled so that a light of
    /// RGB (1, 1, 1) comes out as RGB (1, 1, 1).
    #[inline(always)]
    pub fn illuminant(&self, rgb: [f32; 3]) -> Spectrum {
        match self {
            Channels::Rgb => Spectrum::from(rgb),
            Channels::Wavelengths(w) => spectral_illuminant(w, rgb),
        }
    }

    /// The linear sRGB of `value`, a spectrum in these channels (as an RGB spectrum): in
    /// spectral mode the Monte Carlo estimate of its CIE XYZ over the wavelengths still
    /// carried, Σ value·(x̄, ȳ, z̄)/p / `WAVELENGTHS`, through the XYZ → sRGB matrix.
    #[inline(always)]
    pub fn rgb_of(&self, value: Spectrum) -> Spectrum {
        match self {
            Channels::Rgb => value,
            Channels::Wavelengths(w) => rgb_of_sampled(w, value),
        }
    }

    /// Keeps only the hero wavelength, where the path can go on at one wavelength only (a
    /// dispersive interface). Nothing in RGB mode.
    #[inline]
    pub fn keep_hero_only(&mut self) {
        if let Channels::Wavelengths(w) = self {
            w.keep_hero_only();
        }
    }

    /// The wavelengths of the four lanes in nm; `None` in RGB mode.
    #[inline]
    pub fn wavelengths(&self) -> Option<[f32; 4]> {
        match self {
            Channels::Rgb => None,
            Channels::Wavelengths(w) => Some(w.lambda),
        }
    }

    /// The hero wavelength (lane 0) in nm; `None` in RGB mode.
    #[inline]
    pub fn hero(&self) -> Option<f32> {
        match self {
            Channels::Rgb => None,
            Channels::Wavelengths(w) => Some(w.lambda[0]),
        }
    }
}

/// A colour with its spectral fit made once (a material's constant colour or emission),
/// so that spectral renders do not look the fit up at every hit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FittedColour {
    rgb: [f32; 3],
    fit: SigmoidPolynomial,
    /// What the fitted spectrum is multiplied by.
    scale: f32,
}

impl FittedColour {
    /// A reflectance, as `Channels::reflectance` fits it.
    pub fn reflectance(rgb: [f32; 3]) -> Self {
        let m = rgb[0].max(rgb[1]).max(rgb[2]);
        let scale = if m > 1.0 { m } else { 1.0 };
        FittedColour {
            rgb,
            fit: reflectance_coefficients(rgb.map(|c| c / scale)),
            scale,
        }
    }

    /// An emission, as `Channels::illuminant` fits it.
    pub fn illuminant(rgb: [f32; 3]) -> Self {
        let m = rgb[0].max(rgb[1]).max(rgb[2]);
        if m.is_nan() || m <= 0.0 {
            return FittedColour {
                rgb,
                fit: SigmoidPolynomial::constant(0.0),
                scale: 0.0,
            };
        }
        let scale = 2.0 * m;
        FittedColour {
            rgb,
            fit: reflectance_coefficients(rgb.map(|c| c / scale)),
            scale,
        }
    }
}

impl Channels {
    /// `Channels::reflectance` of a colour fitted beforehand.
    #[inline(always)]
    pub fn fitted_reflectance(&self, colour: &FittedColour) -> Spectrum {
        match self {
            Channels::Rgb => Spectrum::from(colour.rgb),
            Channels::Wavelengths(w) => {
                Spectrum::from_lanes(w.lambda.map(|l| colour.fit.eval(l))) * colour.scale
            }
        }
    }

    /// `Channels::illuminant` of an emission fitted beforehand.
    #[inline(always)]
    pub fn fitted_illuminant(&self, colour: &FittedColour) -> Spectrum {
        match self {
            Channels::Rgb => Spectrum::from(colour.rgb),
            Channels::Wavelengths(w) => fitted_illuminant_at(w, colour),
        }
    }
}

#[inline(never)]
fn fitted_illuminant_at(w: &SampledWavelengths, colour: &FittedColour) -> Spectrum {
    let per_y = *d65_per_luminance();
    Spectrum::from_lanes(w.lambda.map(|l| colour.fit.eval(l) * d65(l) * per_y)) * colour.scale
}

#[inline(never)]
fn spectral_reflectance(w: &SampledWavelengths, rgb: [f32; 3]) -> Spectrum {
    Channels::Wavelengths(*w).fitted_reflectance(&FittedColour::reflectance(rgb))
}

#[inline(never)]
fn spectral_illuminant(w: &SampledWavelengths, rgb: [f32; 3]) -> Spectrum {
    // The chromaticity fitted at half the largest channel, inside the table's interior
    // where the spectra are smooth (see `FittedColour::illuminant`).
    fitted_illuminant_at(w, &FittedColour::illuminant(rgb))
}

#[inline(never)]
fn rgb_of_sampled(w: &SampledWavelengths, value: Spectrum) -> Spectrum {
    let mut xyz = [0.0f64; 3];
    for ((&lambda, &pdf), v) in w.lambda.iter().zip(&w.pdf).zip(value.lanes()) {
        if pdf > 0.0 && v != 0.0 {
            let cmf = cie_1931_xyz(lambda);
            let weight = (v / pdf) as f64;
            for (sum, c) in xyz.iter_mut().zip(cmf) {
                *sum += weight * c as f64;
            }
        }
    }
    let [r, g, b] = linear_srgb_from_xyz(xyz.map(|c| c / WAVELENGTHS as f64)).map(|c| c as f32);
    Spectrum::new(r, g, b)
}

/// The linear sRGB that a white light (emission RGB (1, 1, 1), whose spectrum in a spectral
/// render is D65 scaled to luminance 1) carries per nanometre of wavelength at `lambda`:
/// D65(λ)·(x̄, ȳ, z̄)(λ) / ∫ D65 ȳ dλ through the XYZ → linear sRGB matrix. Summed at 1 nm
/// over 360–830 nm it is (1, 1, 1). What a spectral image shows where only wavelength λ of
/// white light arrives, for predicting dispersion (a prism's spectrum) outside the renderer.
pub fn white_light_srgb_per_nm(lambda: f32) -> [f64; 3] {
    let per_y = *d65_per_luminance() as f64;
    let xyz = cie_1931_xyz(lambda).map(|c| c as f64 * d65(lambda) as f64 * per_y);
    linear_srgb_from_xyz(xyz)
}

/// 1 / ∫ D65 ȳ dλ: D65 scaled by it has luminance Y = 1, the Y of RGB (1, 1, 1).
fn d65_per_luminance() -> &'static f32 {
    static SCALE: OnceLock<f32> = OnceLock::new();
    SCALE.get_or_init(|| {
        let integral: f64 = (360..=830)
            .map(|l| (d65(l as f32) * cie_1931_xyz(l as f32)[1]) as f64)
            .sum();
        (1.0 / integral) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// White light's per-nanometre colours add up to white.
    #[test]
    fn white_light_adds_up_to_white() {
        let mut sum = [0.0f64; 3];
        for lambda in 360..=830 {
            for (s, c) in sum.iter_mut().zip(white_light_srgb_per_nm(lambda as f32)) {
                *s += c;
            }
        }
        for c in sum {
            assert!((c - 1.0).abs() < 1e-4, "{sum:?}");
        }
    }
}
