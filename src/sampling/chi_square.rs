//! Pearson's χ² goodness-of-fit test, shared by the statistical tests of samplers.

/// Normal quantiles: 99.9%, 99.99% and 1 − 10⁻⁶ (for one of hundreds of tests in a
/// family, Bonferroni's correction).
pub(crate) const Z_999: f64 = 3.090_232;
pub(crate) const Z_9999: f64 = 3.719_016;
pub(crate) const Z_1E6: f64 = 4.753_424;

/// Pearson's statistic of `counts` against the probabilities `expected` (which sum to at
/// most 1; the rest is one more cell, "anything else", counted in `rest`).
pub(crate) fn statistic(counts: &[u64], rest: u64, expected: &[f64]) -> f64 {
    let total = (counts.iter().sum::<u64>() + rest) as f64;
    let rest_expected = 1.0 - expected.iter().sum::<f64>();
    let term = |c: u64, p: f64| {
        if p <= 0.0 {
            if c == 0 { 0.0 } else { f64::INFINITY }
        } else {
            (c as f64 - total * p).powi(2) / (total * p)
        }
    };
    counts
        .iter()
        .zip(expected)
        .map(|(&c, &p)| term(c, p))
        .sum::<f64>()
        + term(rest, rest_expected)
}

/// Pearson's statistic of `counts` (of `total` draws; draws in no cell are the rest)
/// against the probabilities `expected`, with the cells expecting fewer than 5 draws and
/// the rest pooled into one cell; and its degrees of freedom. The pooled cell expects at
/// least one draw, so that a numerically integrated `expected` summing to slightly over 1
/// does not make a count there infinitely unlikely.
pub(crate) fn pooled_statistic(counts: &[u64], total: u64, expected: &[f64]) -> (f64, usize) {
    let total_f = total as f64;
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut pooled_count, mut pooled_expected) = (total, 1.0);
    for (&c, &p) in counts.iter().zip(expected) {
        if p * total_f >= 5.0 {
            stat += (c as f64 - total_f * p).powi(2) / (total_f * p);
            cells += 1;
            pooled_count -= c;
            pooled_expected -= p;
        }
    }
    let pooled_expected = (pooled_expected * total_f).max(1.0);
    stat += (pooled_count as f64 - pooled_expected).powi(2) / pooled_expected;
    (stat, cells)
}

/// Upper quantile of the chi-square distribution with `df` degrees of freedom at the
/// normal quantile `z` (Wilson–Hilferty).
pub(crate) fn quantile(df: usize, z: f64) -> f64 {
    let k = df as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// The probabilities of the cells of the sphere cut uniformly in θ ∈ [0, π] (`n_theta`
/// rows) and φ ∈ [0, 2π) (`n_phi` columns), cell (i, j) at index i·n_phi + j, under the
/// solid-angle `density`(θ, φ): each cell integrated by the midpoint rule on a grid
/// refined (8², 16², … 256² points) until two successive grids agree within 10⁻³.
pub(crate) fn sphere_cell_probabilities(
    n_theta: usize,
    n_phi: usize,
    density: impl Fn(f64, f64) -> f64,
) -> Vec<f64> {
    use std::f64::consts::PI;
    let (d_theta, d_phi) = (PI / n_theta as f64, 2.0 * PI / n_phi as f64);
    let cell = |i: usize, j: usize, sub: usize| {
        let (h_theta, h_phi) = (d_theta / sub as f64, d_phi / sub as f64);
        let mut sum = 0.0;
        for a in 0..sub {
            let theta = i as f64 * d_theta + (a as f64 + 0.5) * h_theta;
            let sin_theta = theta.sin();
            for b in 0..sub {
                let phi = j as f64 * d_phi + (b as f64 + 0.5) * h_phi;
                sum += density(theta, phi) * sin_theta;
            }
        }
        sum * h_theta * h_phi
    };
    let mut probabilities = Vec::with_capacity(n_theta * n_phi);
    for i in 0..n_theta {
        for j in 0..n_phi {
            let (mut sub, mut coarse) = (8, cell(i, j, 8));
            let mut fine = cell(i, j, 16);
            while (fine - coarse).abs() > 1e-3 * fine + 1e-9 && sub < 128 {
                sub *= 2;
                coarse = fine;
                fine = cell(i, j, 2 * sub);
            }
            probabilities.push(fine);
        }
    }
    probabilities
}
