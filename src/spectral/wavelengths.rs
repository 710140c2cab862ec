//! Hero-wavelength sampling (Wilkie et al. 2014): a camera path carries `WAVELENGTHS`
//! wavelengths drawn from one random number, stratified in the sampler's primary space so
//! that together they cover the visible range evenly, each distributed by the importance
//! density below. Where only one wavelength can go on (a dispersive interface), the others
//! are dropped and the remaining one's density corrected so the estimate stays unbiased.
//!
//! The density follows the eye's response roughly, p(λ) ∝ sech²(B (λ − C)) on
//! [`LAMBDA_MIN`, `LAMBDA_MAX`]: a bell around 538 nm, where the CIE matching functions
//! weigh most together, whose tails still reach the ends of the range (the shape of
//! Radziszewski et al. 2009). Its CDF is a tanh, so sampling inverts it in closed form.
//! (To do once the matching functions are in: measure its variance against theirs.)

use std::sync::OnceLock;

/// The wavelengths a path carries.
pub(crate) const WAVELENGTHS: usize = 4;

/// The range sampled, in nanometres: where CIE 1931's matching functions are not
/// negligible.
pub(crate) const LAMBDA_MIN: f32 = 360.0;
pub(crate) const LAMBDA_MAX: f32 = 830.0;

/// The density's width (1/nm) and centre (nm).
const WIDTH: f32 = 0.0072;
const CENTRE: f32 = 538.0;

/// tanh of the range's ends in the density's coordinate: the CDF's values there (computed
/// once: every path samples four wavelengths).
#[inline]
fn cdf_ends() -> (f32, f32) {
    static ENDS: OnceLock<(f32, f32)> = OnceLock::new();
    *ENDS.get_or_init(|| {
        (
            (WIDTH * (LAMBDA_MIN - CENTRE)).tanh(),
            (WIDTH * (LAMBDA_MAX - CENTRE)).tanh(),
        )
    })
}

/// The density at the wavelength whose tanh coordinate is `t` = tanh(B (λ − C)):
/// sech² = 1 − tanh², so sampling gets its density without a cosh.
#[inline]
fn pdf_of_tanh(t: f32) -> f32 {
    let (low, high) = cdf_ends();
    WIDTH * (1.0 - t * t) / (high - low)
}

/// The importance density of wavelength `lambda` (per nm); 0 outside the range (what the
/// tests check the sampled wavelengths against).
#[cfg(test)]
pub(crate) fn visible_wavelength_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    pdf_of_tanh((WIDTH * (lambda - CENTRE)).tanh())
}

/// The wavelength at which the density's CDF is `u` in [0, 1], and its density.
#[inline]
fn sample_visible_wavelength(u: f32) -> (f32, f32) {
    let (low, high) = cdf_ends();
    let t = low + u * (high - low);
    let lambda = (CENTRE + t.atanh() / WIDTH).clamp(LAMBDA_MIN, LAMBDA_MAX);
    (lambda, pdf_of_tanh(t))
}

/// The wavelengths of a path and the density each was drawn with. A dropped wavelength
/// has density 0 and contributes nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SampledWavelengths {
    pub lambda: [f32; WAVELENGTHS],
    pub pdf: [f32; WAVELENGTHS],
    /// The random number they were drawn from (`sample`): what a Metropolis move steps.
    pub u: f32,
}

impl SampledWavelengths {
    /// Wavelengths from one random number `u` in [0, 1): the i-th at CDF value
    /// u + i / `WAVELENGTHS` (wrapped), so each is distributed by the density and together
    /// they are stratified.
    pub fn sample(u: f32) -> Self {
        let samples: [(f32, f32); WAVELENGTHS] = std::array::from_fn(|i| {
            let shifted = u + i as f32 / WAVELENGTHS as f32;
            let wrapped = if shifted >= 1.0 {
                shifted - 1.0
            } else {
                shifted
            };
            sample_visible_wavelength(wrapped)
        });
        SampledWavelengths {
            lambda: samples.map(|(lambda, _)| lambda),
            pdf: samples.map(|(_, pdf)| pdf),
            u,
        }
    }

    /// Keeps only the first (hero) wavelength. An estimate averages f(λᵢ)/pᵢ over the
    /// `WAVELENGTHS` wavelengths; with the others dropped, the hero's density is divided by
    /// their number, so the average is still f(λ)/p(λ) of a wavelength drawn from p.
    pub fn keep_hero_only(&mut self) {
        if self.pdf[1..].iter().all(|&p| p == 0.0) {
            return;
        }
        self.pdf[0] /= WAVELENGTHS as f32;
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
    }

    /// Whether the other wavelengths were dropped.
    #[cfg(test)]
    pub fn hero_only(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::chi_square::{Z_999, pooled_statistic, quantile};

    /// The density integrates to 1 over the range (midpoint rule).
    #[test]
    fn density_is_normalized() {
        let n = 100_000;
        let step = (LAMBDA_MAX - LAMBDA_MIN) as f64 / n as f64;
        let integral: f64 = (0..n)
            .map(|i| {
                visible_wavelength_pdf(LAMBDA_MIN + (i as f64 + 0.5) as f32 * step as f32) as f64
            })
            .sum::<f64>()
            * step;
        assert!((integral - 1.0).abs() < 1e-4, "{integral}");
        assert_eq!(visible_wavelength_pdf(LAMBDA_MIN - 1.0), 0.0);
        assert_eq!(visible_wavelength_pdf(LAMBDA_MAX + 1.0), 0.0);
    }

    /// χ² of `draws` wavelengths (every wavelength of each sample) in 5 nm bins against
    /// `pdf` integrated over each bin (Simpson's rule), and the 99.9% threshold.
    fn chi_square(pdf: impl Fn(f32) -> f32, draws: usize, rng: &mut Rng) -> (f64, f64) {
        let bins = ((LAMBDA_MAX - LAMBDA_MIN) / 5.0) as usize;
        let width = (LAMBDA_MAX - LAMBDA_MIN) / bins as f32;
        let mut counts = vec![0u64; bins];
        for _ in 0..draws / WAVELENGTHS {
            for lambda in SampledWavelengths::sample(rng.uniform()).lambda {
                let bin = (((lambda - LAMBDA_MIN) / width) as usize).min(bins - 1);
                counts[bin] += 1;
            }
        }
        let expected: Vec<f64> = (0..bins)
            .map(|b| {
                let a = LAMBDA_MIN + b as f32 * width;
                let (m, e) = (a + width / 2.0, a + width);
                (width as f64 / 6.0) * (pdf(a) + 4.0 * pdf(m) + pdf(e)) as f64
            })
            .collect();
        let total = (draws / WAVELENGTHS * WAVELENGTHS) as u64;
        let (stat, cells) = pooled_statistic(&counts, total, &expected);
        (stat, quantile(cells, Z_999))
    }

    /// The sampled wavelengths follow the density, and a density 4% narrower than the one
    /// sampled is told apart by the same test.
    #[test]
    fn sampled_wavelengths_follow_the_density() {
        let mut rng = Rng::new(19, 1);
        let (stat, threshold) = chi_square(visible_wavelength_pdf, 1_000_000, &mut rng);
        assert!(stat < threshold, "χ² {stat} ≥ {threshold}");
        let narrower = |lambda: f32| {
            let w = WIDTH * 1.04;
            let ends = |x: f32| (w * (x - CENTRE)).tanh();
            if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
                return 0.0;
            }
            let c = (w * (lambda - CENTRE)).cosh();
            w / ((ends(LAMBDA_MAX) - ends(LAMBDA_MIN)) * c * c)
        };
        let (stat, threshold) = chi_square(narrower, 1_000_000, &mut rng);
        assert!(
            stat > threshold,
            "a 4% narrower density passed: χ² {stat} < {threshold}"
        );
    }

    /// The wavelengths of one sample are stratified: their CDF values are u + i/4.
    #[test]
    fn wavelengths_of_a_sample_are_stratified() {
        let (low, high) = cdf_ends();
        let cdf = |lambda: f32| ((WIDTH * (lambda - CENTRE)).tanh() - low) / (high - low);
        for u in [0.0f32, 0.1, 0.37, 0.74, 0.999] {
            let s = SampledWavelengths::sample(u);
            for (i, &lambda) in s.lambda.iter().enumerate() {
                let expected = (u + i as f32 / WAVELENGTHS as f32).fract();
                assert!(
                    (cdf(lambda) - expected).abs() < 1e-4,
                    "u {u} i {i}: {lambda}"
                );
                let pdf = visible_wavelength_pdf(lambda);
                assert!(
                    (s.pdf[i] - pdf).abs() <= 1e-4 * pdf,
                    "{} vs {pdf}",
                    s.pdf[i]
                );
            }
        }
    }

    /// Keeping the hero alone: f/p of the hero, averaged as if all were there, is the
    /// plain one-wavelength estimate; doing it twice changes nothing.
    #[test]
    fn keeping_the_hero_corrects_its_density() {
        let mut s = SampledWavelengths::sample(0.3);
        let hero_pdf = s.pdf[0];
        assert!(!s.hero_only());
        s.keep_hero_only();
        assert!(s.hero_only());
        assert_eq!(s.pdf[0] * WAVELENGTHS as f32, hero_pdf);
        let once = s;
        s.keep_hero_only();
        assert_eq!(s, once);
    }
}
