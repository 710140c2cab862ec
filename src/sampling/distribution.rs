//! Piecewise-constant distributions sampled by CDF inversion.

/// A discrete/piecewise-constant 1-D distribution over `n` equal bins of [0, 1).
#[derive(Clone, Debug)]
pub struct Distribution1D {
    weights: Vec<f32>,
    /// cdf[0] = 0, cdf[n] = 1.
    cdf: Vec<f32>,
    total: f32,
}

impl Distribution1D {
    /// Builds from non-negative finite weights. With a zero total every bin is equally likely.
    pub fn new(weights: &[f32]) -> Self {
        let n = weights.len();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0f32);
        let mut running = 0.0f64;
        for &w in weights {
            debug_assert!(w >= 0.0 && w.is_finite());
            running += w as f64;
            cdf.push(running as f32);
        }
        let total = running as f32;
        if total > 0.0 {
            for c in cdf.iter_mut() {
                *c = (*c as f64 / running) as f32;
            }
        } else {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f32 / n.max(1) as f32;
            }
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let weights = if total > 0.0 {
            weights.to_vec()
        } else {
            vec![1.0; n]
        };
        Distribution1D {
            weights,
            cdf,
            total: if total > 0.0 { total } else { n as f32 },
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.weights.len()
    }

    /// Probability of choosing bin `i` when sampling discretely.
    #[inline]
    pub fn discrete_pdf(&self, i: usize) -> f32 {
        self.weights[i] / self.total
    }

    /// Picks a bin with probability proportional to its weight; returns (bin, probability,
    /// `u` remapped to [0, 1) within the bin so it can be reused).
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find_bin(u);
        let lo = self.cdf[i];
        let width = self.cdf[i + 1] - lo;
        let remapped = if width > 0.0 {
            ((u - lo) / width).clamp(0.0, 1.0 - f32::EPSILON / 2.0)
        } else {
            0.0
        };
        (i, self.discrete_pdf(i), remapped)
    }

    /// Samples x in [0, 1) with density proportional to the piecewise-constant function;
    /// returns (x, density, bin).
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, p, within) = self.sample_discrete(u);
        let n = self.len() as f32;
        ((i as f32 + within) / n, p * n, i)
    }

    /// Density of `sample_continuous` at x in [0, 1).
    #[inline]
    pub fn continuous_pdf(&self, x: f32) -> f32 {
        let n = self.len();
        let i = ((x * n as f32) as usize).min(n - 1);
        self.discrete_pdf(i) * n as f32
    }

    /// Largest i with cdf[i] <= u, restricted to bins of non-zero width.
    #[inline]
    fn find_bin(&self, u: f32) -> usize {
        let n = self.len();
        // partition_point gives the first index whose cdf exceeds u.
        let idx = self.cdf.partition_point(|&c| c <= u);
        let mut i = idx.saturating_sub(1).min(n - 1);
        // Zero-width bins share a cdf value with their successor; skip over them.
        while i + 1 < n && self.cdf[i + 1] <= self.cdf[i] {
            i += 1;
        }
        i
    }
}

/// A piecewise-constant 2-D distribution on [0,1)²: a marginal over rows and a conditional per row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `values` is row-major with `width` columns and `height` rows.
    pub fn new(values: &[f32], width: usize, height: usize) -> Self {
        assert_eq!(values.len(), width * height);
        let rows: Vec<Distribution1D> = values
            .chunks_exact(width)
            .map(Distribution1D::new)
            .collect();
        // From the values themselves: a row of zeros gets a uniform conditional (so its
        // Distribution1D reports a non-zero total) but must never be chosen.
        let row_totals: Vec<f32> = values
            .chunks_exact(width)
            .map(|row| row.iter().map(|&v| v as f64).sum::<f64>() as f32)
            .collect();
        Distribution2D {
            marginal: Distribution1D::new(&row_totals),
            rows,
        }
    }

    /// Returns ([x, y], density).
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> ([f32; 2], f32) {
        let (y, pdf_y, row) = self.marginal.sample_continuous(u[1]);
        let (x, pdf_x, _) = self.rows[row].sample_continuous(u[0]);
        ([x, y], pdf_x * pdf_y)
    }

    #[inline]
    pub fn pdf(&self, p: [f32; 2]) -> f32 {
        let height = self.rows.len();
        let row = ((p[1] * height as f32) as usize).min(height - 1);
        self.marginal.continuous_pdf(p[1]) * self.rows[row].continuous_pdf(p[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn discrete_frequencies_match_weights() {
        let weights = [1.0, 0.0, 3.0, 4.0, 0.0];
        let d = Distribution1D::new(&weights);
        let mut counts = [0usize; 5];
        let mut rng = Rng::new(9, 9);
        let n = 400_000;
        for _ in 0..n {
            let (i, p, r) = d.sample_discrete(rng.uniform());
            assert!((0.0..1.0).contains(&r));
            assert_eq!(p, weights[i] / 8.0);
            counts[i] += 1;
        }
        for i in 0..5 {
            let expected = weights[i] / 8.0;
            let freq = counts[i] as f32 / n as f32;
            // 5σ of a binomial proportion.
            let sigma = (expected * (1.0 - expected) / n as f32).sqrt();
            assert!(
                (freq - expected).abs() <= 5.0 * sigma + 1e-9,
                "{i}: {freq} vs {expected}"
            );
        }
        // Edge values never land in a zero-weight bin.
        assert_eq!(d.sample_discrete(0.0).0, 0);
        assert_eq!(d.sample_discrete(0.999_999_9).0, 3);
    }

    #[test]
    fn two_d_density_integrates_to_one_and_matches_samples() {
        // The middle row is all zeros: never chosen.
        let values = [0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 5.0, 1.0, 2.0];
        let d = Distribution2D::new(&values, 3, 3);
        let mut rng = Rng::new(4, 4);
        let mut counts = [0usize; 9];
        let n = 300_000;
        for _ in 0..n {
            let ([x, y], pdf) = d.sample(rng.uniform2());
            let cell = (y * 3.0) as usize * 3 + (x * 3.0) as usize;
            assert!((pdf - d.pdf([x, y])).abs() < 1e-4 * pdf.max(1.0));
            counts[cell] += 1;
        }
        let total: f32 = values.iter().sum();
        for (cell, &v) in values.iter().enumerate() {
            let expected = v / total;
            let freq = counts[cell] as f32 / n as f32;
            let sigma = (expected * (1.0 - expected) / n as f32).sqrt();
            assert!((freq - expected).abs() <= 5.0 * sigma + 1e-9, "{cell}");
        }
    }
}
