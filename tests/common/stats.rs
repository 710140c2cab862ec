//! Image statistics: means and standard errors, estimates averaged over independent renders,
//! and the assertions that compare an estimate with the truth or with another estimate
//! (within a multiple of the standard error, and sharp enough to fail a 2% error).
// Each test file uses a part of these helpers.
#![allow(dead_code)]

/// Asserts `got` is within `sigmas` standard errors of `truth`, and that the check is sharp:
/// a ±2% error would land at least two more standard errors outside the tolerance, so it
/// fails whatever the noise did. `label` names the value in failure messages.
pub fn assert_within_and_sharp(
    label: &str,
    got: f64,
    truth: f64,
    standard_error: f64,
    sigmas: f64,
) {
    let tolerance = sigmas * standard_error;
    assert!(
        (got - truth).abs() <= tolerance,
        "{label}: {got} vs {truth} ± {tolerance}"
    );
    assert_sharp(label, truth, standard_error, sigmas);
}

/// Asserts that a comparison within `sigmas` standard errors of `truth` would fail a ±2% error
/// by at least two more standard errors.
pub fn assert_sharp(label: &str, truth: f64, standard_error: f64, sigmas: f64) {
    assert!(
        (sigmas + 2.0) * standard_error <= 0.02 * truth.abs(),
        "{label}: a 2% error would not reliably fail: {sigmas} + 2 standard errors of {standard_error} exceed 2% of {truth}"
    );
}

/// Per-channel mean of the pixels of an RGB image and the standard error of that mean,
/// treating pixels as independent samples (they are: each has its own random streams).
pub fn mean_and_standard_error(rgb: &[f32]) -> ([f64; 3], [f64; 3]) {
    let n = (rgb.len() / 3) as f64;
    let mut mean = [0.0; 3];
    let mut error = [0.0; 3];
    for c in 0..3 {
        let values = rgb.iter().skip(c).step_by(3).map(|&v| v as f64);
        let m = values.clone().sum::<f64>() / n;
        let var = values.map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
        mean[c] = m;
        error[c] = (var / n).sqrt();
    }
    (mean, error)
}

/// Luminance of a linear RGB mean (Rec. 709 weights, as `mlt::spectrum::Spectrum::luminance`).
pub fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Root-mean-square difference between two images of equal size.
pub fn rmse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum();
    (sum / a.len() as f64).sqrt()
}

/// Mean RGB of each cell of a `grid` × `grid` partition of the image, row-major.
pub fn region_means(rgb: &[f32], width: usize, height: usize, grid: usize) -> Vec<[f64; 3]> {
    let mut sums = vec![[0.0f64; 3]; grid * grid];
    let mut counts = vec![0usize; grid * grid];
    for y in 0..height {
        for x in 0..width {
            let cell = (y * grid / height) * grid + x * grid / width;
            let p = &rgb[(y * width + x) * 3..][..3];
            for c in 0..3 {
                sums[cell][c] += p[c] as f64;
            }
            counts[cell] += 1;
        }
    }
    sums.iter()
        .zip(&counts)
        .map(|(s, &n)| s.map(|v| v / n as f64))
        .collect()
}

/// Per-channel mean of an RGB image.
pub fn mean(image: &[f32]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for pixel in image.chunks_exact(3) {
        for (s, &value) in sum.iter_mut().zip(pixel) {
            *s += value as f64;
        }
    }
    let n = (image.len() / 3).max(1) as f64;
    sum.map(|s| s / n)
}

/// An image estimated from several independent renders (different seeds), with the variance
/// of each float of the averaged image. Independent renders make the variance estimate valid
/// for any estimator, including ones whose pixels are correlated (Metropolis chains).
pub struct Estimate {
    pub width: usize,
    pub height: usize,
    pub image: Vec<f32>,
    /// Variance of each float of `image` (the variance of a mean over the renders).
    pub variance: Vec<f64>,
    /// The renders, kept when pixels of one render are correlated (Metropolis), so region
    /// variances come from the spread of whole-region means between renders.
    correlated_renders: Vec<Vec<f32>>,
}

impl Estimate {
    /// Averages `renders` (each a width × height RGB image from its own seed).
    pub fn from_renders(width: usize, height: usize, renders: &[Vec<f32>]) -> Self {
        let k = renders.len();
        assert!(
            k >= 2,
            "need at least two independent renders for a variance"
        );
        let n = width * height * 3;
        let mut image = vec![0.0f32; n];
        let mut variance = vec![0.0f64; n];
        for i in 0..n {
            let mean = renders.iter().map(|r| r[i] as f64).sum::<f64>() / k as f64;
            let var = renders
                .iter()
                .map(|r| (r[i] as f64 - mean).powi(2))
                .sum::<f64>()
                / (k - 1) as f64;
            image[i] = mean as f32;
            variance[i] = var / k as f64;
        }
        Estimate {
            width,
            height,
            image,
            variance,
            correlated_renders: Vec::new(),
        }
    }

    /// As `from_renders`, for estimators whose pixels are correlated within a render (Markov
    /// chains): variances of means over regions are then estimated from the spread of the
    /// region means between the independent renders.
    pub fn from_correlated_renders(width: usize, height: usize, renders: &[Vec<f32>]) -> Self {
        Estimate {
            correlated_renders: renders.to_vec(),
            ..Estimate::from_renders(width, height, renders)
        }
    }

    /// Mean RGB over the pixels of a rectangle and the variance of that mean.
    pub fn region(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> ([f64; 3], [f64; 3]) {
        if !self.correlated_renders.is_empty() {
            return self.region_between_renders(x0, y0, x1, y1);
        }
        let mut mean = [0.0; 3];
        let mut variance = [0.0; 3];
        let count = ((x1 - x0) * (y1 - y0)) as f64;
        for y in y0..y1 {
            for x in x0..x1 {
                for c in 0..3 {
                    let i = (y * self.width + x) * 3 + c;
                    mean[c] += self.image[i] as f64;
                    variance[c] += self.variance[i];
                }
            }
        }
        (
            mean.map(|m| m / count),
            variance.map(|v| v / (count * count)),
        )
    }

    fn region_between_renders(
        &self,
        x0: usize,
        y0: usize,
        x1: usize,
        y1: usize,
    ) -> ([f64; 3], [f64; 3]) {
        let k = self.correlated_renders.len() as f64;
        let count = ((x1 - x0) * (y1 - y0)) as f64;
        let means: Vec<[f64; 3]> = self
            .correlated_renders
            .iter()
            .map(|render| {
                let mut m = [0.0; 3];
                for y in y0..y1 {
                    for x in x0..x1 {
                        for (c, mc) in m.iter_mut().enumerate() {
                            *mc += render[(y * self.width + x) * 3 + c] as f64;
                        }
                    }
                }
                m.map(|v| v / count)
            })
            .collect();
        let mean: [f64; 3] = std::array::from_fn(|c| means.iter().map(|m| m[c]).sum::<f64>() / k);
        let variance = std::array::from_fn(|c| {
            means.iter().map(|m| (m[c] - mean[c]).powi(2)).sum::<f64>() / (k - 1.0) / k
        });
        (mean, variance)
    }

    /// Whole-image mean and its variance.
    pub fn mean(&self) -> ([f64; 3], [f64; 3]) {
        self.region(0, 0, self.width, self.height)
    }
}

/// An image estimate as `assert_estimates_agree` compares it: the image mean and the means
/// of the cells of a grid, each with its variance.
pub trait RegionEstimate {
    /// Pixels, for estimates made of them (`None`: resolution-free, a cached reference).
    fn pixels(&self) -> Option<(usize, usize)>;
    fn image_mean(&self) -> ([f64; 3], [f64; 3]);
    /// Cell (gx, gy) of a `grid` × `grid` partition.
    fn cell(&self, grid: usize, gx: usize, gy: usize) -> ([f64; 3], [f64; 3]);
}

impl RegionEstimate for Estimate {
    fn pixels(&self) -> Option<(usize, usize)> {
        Some((self.width, self.height))
    }

    fn image_mean(&self) -> ([f64; 3], [f64; 3]) {
        self.mean()
    }

    fn cell(&self, grid: usize, gx: usize, gy: usize) -> ([f64; 3], [f64; 3]) {
        let (w, h) = (self.width, self.height);
        self.region(
            gx * w / grid,
            gy * h / grid,
            (gx + 1) * w / grid,
            (gy + 1) * h / grid,
        )
    }
}

/// A converged reference kept as numbers (committed constants, made by a test that
/// regenerates them): the image mean and the cells of a `GRID` × `GRID` partition, each with
/// the variance of its estimate. With a box filter each is an integral over the film, the
/// same at any resolution whose size the grid divides.
pub struct CachedEstimate<const GRID: usize> {
    pub mean: [f64; 3],
    pub mean_variance: [f64; 3],
    /// Row by row.
    pub cells: [[[f64; 3]; GRID]; GRID],
    pub cell_variances: [[[f64; 3]; GRID]; GRID],
}

impl<const GRID: usize> CachedEstimate<GRID> {
    /// The numbers of `estimate` (whose size `GRID` must divide).
    pub fn of(estimate: &Estimate) -> Self {
        assert!(estimate.width.is_multiple_of(GRID) && estimate.height.is_multiple_of(GRID));
        let cells: [[([f64; 3], [f64; 3]); GRID]; GRID] =
            std::array::from_fn(|gy| std::array::from_fn(|gx| estimate.cell(GRID, gx, gy)));
        let (mean, mean_variance) = estimate.mean();
        CachedEstimate {
            mean,
            mean_variance,
            cells: cells.map(|row| row.map(|cell| cell.0)),
            cell_variances: cells.map(|row| row.map(|cell| cell.1)),
        }
    }
}

impl<const GRID: usize> RegionEstimate for CachedEstimate<GRID> {
    fn pixels(&self) -> Option<(usize, usize)> {
        None
    }

    fn image_mean(&self) -> ([f64; 3], [f64; 3]) {
        (self.mean, self.mean_variance)
    }

    fn cell(&self, grid: usize, gx: usize, gy: usize) -> ([f64; 3], [f64; 3]) {
        assert_eq!(
            grid, GRID,
            "the cached reference has a {GRID} × {GRID} grid"
        );
        (self.cells[gy][gx], self.cell_variances[gy][gx])
    }
}

/// Asserts that two independent estimates of the same image agree: the image mean within
/// `sigmas` combined standard errors and the mean of every cell of a `grid` × `grid`
/// partition within `region_sigmas`. Also asserts the comparison is sharp: a 2% brightness
/// error of the whole image would fail it (see `assert_sharp`). `label` names the comparison in
/// failure messages.
///
/// Choose the multiples for the number of comparisons (3 channels × (1 + grid²)) and how
/// the variances were estimated: per-pixel variances over many samples are near-exact, but a
/// variance from the spread of k whole renders (Markov chains) has k − 1 degrees of freedom
/// and Student's t tails; with 16 renders, |t| > 6 has probability 2·10⁻⁵ per comparison.
pub fn assert_estimates_agree(
    label: &str,
    test: &dyn RegionEstimate,
    reference: &dyn RegionEstimate,
    grid: usize,
    sigmas: f64,
    region_sigmas: f64,
) {
    if let (Some(a), Some(b)) = (test.pixels(), reference.pixels()) {
        assert_eq!(a, b);
    }
    let (tm, tv) = test.image_mean();
    let (rm, rv) = reference.image_mean();
    for c in 0..3 {
        let sigma = (tv[c] + rv[c]).sqrt();
        // For tuning a test's cost (shown with --nocapture): a 2% error fails only while
        // (sigmas + 2)·σ stays within 2% of the mean.
        eprintln!(
            "{label}: image mean channel {c}: {:+.2} σ, σ = {:.3}% (at most {:.3}%)",
            (tm[c] - rm[c]) / sigma,
            100.0 * sigma / rm[c],
            2.0 / (sigmas + 2.0)
        );
        let tolerance = sigmas * sigma;
        assert!(
            (tm[c] - rm[c]).abs() <= tolerance,
            "{label}: image mean channel {c} is {} but the reference is {} (tolerance {tolerance})",
            tm[c],
            rm[c]
        );
        assert_sharp(
            &format!("{label}: image mean channel {c}"),
            rm[c],
            (tv[c] + rv[c]).sqrt(),
            sigmas,
        );
    }
    assert_regions_agree(label, test, reference, grid, region_sigmas);
}

/// The region part of `assert_estimates_agree`: every cell of a `grid` × `grid` partition
/// within `region_sigmas` combined standard errors.
pub fn assert_regions_agree(
    label: &str,
    test: &dyn RegionEstimate,
    reference: &dyn RegionEstimate,
    grid: usize,
    region_sigmas: f64,
) {
    for gy in 0..grid {
        for gx in 0..grid {
            let (tm, tv) = test.cell(grid, gx, gy);
            let (rm, rv) = reference.cell(grid, gx, gy);
            for c in 0..3 {
                let tolerance = region_sigmas * (tv[c] + rv[c]).sqrt();
                assert!(
                    (tm[c] - rm[c]).abs() <= tolerance,
                    "{label}: region ({gx}, {gy}) channel {c} is {} but the reference is {} (tolerance {tolerance})",
                    tm[c],
                    rm[c]
                );
            }
        }
    }
}
