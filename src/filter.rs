//! The optional post-process filter for the blotchy, low-frequency noise of Metropolis and
//! ERPT images: non-local means guided by per-pixel variances that the render measures.
//!
//! A Metropolis chain that lingers leaves a blotch; a rare, bright path leaves a lone spike.
//! Neither shows in a pixel's own samples as variance, because a chain's deposits are
//! correlated. So with the filter on, every chain (Metropolis: by chain index) or camera
//! sample (ERPT: by a hash of pixel and sample) also deposits into one of K partial images.
//! The partial images are independent estimates of the image, so their spread at a pixel
//! estimates the variance of the pixel's value, chain correlation included. That variance
//! drives non-local means (Buades et al. 2005, in the form Rousselle, Knaus & Zwicker 2012
//! gave it for rendering):
//!
//! - each pixel becomes a weighted mean of the pixels within `radius`, weighted by how
//!   alike the 7 × 7 patches around them are;
//! - patch differences are measured in units of their variances: d² = ((u_p − u_q)² −
//!   (v_p + min(v_p, v_q))) / (k² (v_p + v_q)), averaged over channels and patch, weight
//!   e^(−max(0, d²)). Differences noise explains are discounted, so noisy regions average
//!   widely, while edges and features (differences far beyond the noise) are kept;
//! - the variances are pooled over 5 × 5 pixels first: a pixel none of the partials reached
//!   has a spread of zero, and would otherwise refuse every neighbour, staying dark while
//!   its bright neighbours are pulled down;
//! - the result is rescaled per channel to the unfiltered image's total. For Metropolis that
//!   total is the bootstrap's normalization b, which the chains do not estimate anyway. The
//!   filter moves energy between pixels and never removes it.
//!
//! Where the partials agree exactly (no noise) nothing changes. The filter is biased
//! (it blurs features the noise hides); the bias shrinks as the variances do.
//! `benches/equal_time.rs` measures bias and gain against a reference, and
//! `tests/filter.rs` bounds them.
//!
//! Rejecting outlier partials per pixel was tried first and dropped. At the budgets the
//! benchmark runs, each pixel is reached by a few chains only, so a partial that stands out
//! is usually real energy, and removing it is bias, not noise removal.

use crate::spectrum::{LUMINANCE_WEIGHTS, Spectrum};
use rayon::prelude::*;

/// Fewest partial images the filter accepts: two already give a spread.
pub const MLT_MIN_FILTER_BUFFERS: u32 = 2;
/// Most partial images the filter accepts (each costs 12 bytes per pixel).
pub const MLT_MAX_FILTER_BUFFERS: u32 = 32;
/// Largest accepted filter strength.
pub const MLT_MAX_FILTER_STRENGTH: f32 = 100.0;
/// Largest accepted filter search radius in pixels.
pub const MLT_MAX_FILTER_RADIUS: u32 = 32;
/// Radius of the patches compared (7 × 7).
const PATCH_RADIUS: usize = 3;
/// Radius of the window the variances are pooled over (5 × 5).
const VARIANCE_POOL_RADIUS: usize = 2;

/// How a render's image is filtered (`RenderSettings::filter_buffers`, `filter_strength`,
/// `filter_radius`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSettings {
    /// Partial images the deposits are split into.
    pub buffers: u32,
    /// k of the patch distance: higher smooths more.
    pub strength: f32,
    /// Search radius in pixels.
    pub radius: u32,
}

/// What the filter did to an image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FilterStats {
    /// Σ |Δ luminance| over pixels / Σ luminance: how much of the image's energy the filter
    /// moved. The total itself is kept (per channel), so the image mean does not change.
    pub changed_fraction: f64,
    /// The mean over pixels of the sum of weights, its own pixel counting 1: about how many
    /// pixels each pixel was averaged over.
    pub mean_neighbours: f64,
}

/// Filters the splat image `totals` (per pixel, RGB, rows of `width`) given its partial
/// images (`partials[pixel * buffers + b]`, which sum to `totals`). Returns the filtered
/// image and what was done.
pub fn filter_splats(
    width: usize,
    settings: &FilterSettings,
    partials: &[[f32; 3]],
    totals: &[[f64; 3]],
) -> (Vec<[f64; 3]>, FilterStats) {
    let FilterSettings {
        buffers,
        strength,
        radius,
    } = *settings;
    let buffers = buffers as usize;
    let pixels = totals.len();
    assert_eq!(partials.len(), pixels * buffers);
    assert!(width > 0 && pixels.is_multiple_of(width));
    let Some(variance) = variance_of_the_mean(width, buffers, partials) else {
        return (totals.to_vec(), FilterStats::default());
    };
    let height = pixels / width;
    let k2 = strength as f64 * strength as f64;
    // Keeps 0 / 0 (equal values, no variance) at distance 0 without letting a difference
    // hide behind a tiny denominator.
    let mean_value = totals.iter().map(|t| t[0] + t[1] + t[2]).sum::<f64>() / (3 * pixels) as f64;
    let epsilon = 1e-20 + 1e-12 * mean_value * mean_value;

    let mut weights = vec![0.0f64; pixels];
    let mut sums = vec![[0.0f64; 3]; pixels];
    let mut distance = vec![0.0f64; pixels];
    let mut scratch = vec![0.0f64; pixels];
    let mut patch_distance = vec![0.0f64; pixels];
    let r = radius as isize;
    for dy in -r..=r {
        for dx in -r..=r {
            let partner = |x: usize, y: usize| -> Option<usize> {
                let (qx, qy) = (x as isize + dx, y as isize + dy);
                (qx >= 0 && qy >= 0 && (qx as usize) < width && (qy as usize) < height)
                    .then(|| qy as usize * width + qx as usize)
            };
            // Per-pixel distance to the pixel at the offset; 0 where it is off the image
            // (those pairs are never weighted, and patches near the border average fewer
            // real terms).
            distance
                .par_chunks_mut(width)
                .enumerate()
                .for_each(|(y, row)| {
                    for (x, d) in row.iter_mut().enumerate() {
                        let p = y * width + x;
                        *d = partner(x, y).map_or(0.0, |q| {
                            let mut sum = 0.0;
                            for c in 0..3 {
                                let (vp, vq) = (variance[p][c], variance[q][c]);
                                let diff = totals[p][c] - totals[q][c];
                                sum +=
                                    (diff * diff - (vp + vp.min(vq))) / (epsilon + k2 * (vp + vq));
                            }
                            sum / 3.0
                        });
                    }
                });
            box_mean(
                &distance,
                width,
                1,
                PATCH_RADIUS,
                &mut scratch,
                &mut patch_distance,
            );
            weights
                .par_chunks_mut(width)
                .zip(sums.par_chunks_mut(width))
                .enumerate()
                .for_each(|(y, (weights, sums))| {
                    for x in 0..width {
                        if let Some(q) = partner(x, y) {
                            let w = (-patch_distance[y * width + x].max(0.0)).exp();
                            weights[x] += w;
                            for c in 0..3 {
                                sums[x][c] += w * totals[q][c];
                            }
                        }
                    }
                });
        }
    }
    let mut filtered: Vec<[f64; 3]> = sums
        .iter()
        .zip(&weights)
        .map(|(s, &w)| s.map(|v| v / w))
        .collect();

    // Keep each channel's total: the filter moves energy, it does not remove it.
    let mut before = [0.0f64; 3];
    let mut after = [0.0f64; 3];
    for (t, f) in totals.iter().zip(&filtered) {
        for c in 0..3 {
            before[c] += t[c];
            after[c] += f[c];
        }
    }
    let rescale: [f64; 3] = std::array::from_fn(|c| {
        if after[c] > 0.0 {
            before[c] / after[c]
        } else {
            1.0
        }
    });
    let [r, g, b] = LUMINANCE_WEIGHTS;
    let lum = |v: &[f64; 3]| r * v[0] + g * v[1] + b * v[2];
    let (mut changed, mut energy) = (0.0, 0.0);
    for (t, f) in totals.iter().zip(&mut filtered) {
        for c in 0..3 {
            f[c] *= rescale[c];
        }
        changed += (lum(f) - lum(t)).abs();
        energy += lum(t).abs();
    }
    let stats = FilterStats {
        changed_fraction: if energy > 0.0 { changed / energy } else { 0.0 },
        mean_neighbours: weights.iter().sum::<f64>() / pixels as f64,
    };
    (filtered, stats)
}

/// The variance of each pixel's value (per channel), from the spread of the partial images,
/// each scaled by its share of the luminance to an estimate of the whole, pooled over
/// 5 × 5 pixels. `None` when fewer than two partials hold energy.
fn variance_of_the_mean(
    width: usize,
    buffers: usize,
    partials: &[[f32; 3]],
) -> Option<Vec<[f64; 3]>> {
    let mut shares = vec![0.0f64; buffers];
    for pixel in partials.chunks_exact(buffers) {
        for (share, p) in shares.iter_mut().zip(pixel) {
            *share += Spectrum::from(*p).luminance().max(0.0) as f64;
        }
    }
    let total: f64 = shares.iter().sum();
    let active = shares.iter().filter(|&&s| s > 0.0).count();
    if active < 2 || !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let n = active as f64;
    let scales: Vec<f64> = shares
        .iter()
        .map(|&s| if s > 0.0 { total / s } else { 0.0 })
        .collect();
    let mut variance = vec![0.0f64; partials.len() / buffers * 3];
    variance
        .par_chunks_mut(3)
        .zip(partials.par_chunks(buffers))
        .for_each(|(variance, pixel)| {
            for (c, v) in variance.iter_mut().enumerate() {
                let (mut s1, mut s2) = (0.0, 0.0);
                for (p, &scale) in pixel.iter().zip(&scales).filter(|(_, s)| **s > 0.0) {
                    let x = p[c] as f64 * scale;
                    s1 += x;
                    s2 += x * x;
                }
                // Sample variance of the estimates, over n for their mean.
                *v = ((s2 - s1 * s1 / n) / (n - 1.0)).max(0.0) / n;
            }
        });
    let mut scratch = vec![0.0f64; variance.len()];
    let mut pooled = vec![0.0f64; variance.len()];
    box_mean(
        &variance,
        width,
        3,
        VARIANCE_POOL_RADIUS,
        &mut scratch,
        &mut pooled,
    );
    Some(pooled.chunks_exact(3).map(|v| [v[0], v[1], v[2]]).collect())
}

/// Mean of `values` (`channels` per pixel, rows of `width` pixels) over the window of
/// `radius` around each pixel, clipped to the image, into `out` (`scratch` holds the rows'
/// means; both as long as `values`).
fn box_mean(
    values: &[f64],
    width: usize,
    channels: usize,
    radius: usize,
    scratch: &mut [f64],
    out: &mut [f64],
) {
    let row = width * channels;
    let height = values.len() / row;
    scratch
        .par_chunks_mut(row)
        .zip(values.par_chunks(row))
        .for_each(|(out, line)| box_line(line, out, channels, radius));
    let rows = &*scratch;
    // Then the columns, summed directly: the window is short.
    out.par_chunks_mut(row)
        .enumerate()
        .for_each(|(y, out_row)| {
            let lo = y.saturating_sub(radius);
            let hi = (y + radius).min(height - 1);
            let count = (hi - lo + 1) as f64;
            for (i, o) in out_row.iter_mut().enumerate() {
                let mut sum = 0.0;
                for yy in lo..=hi {
                    sum += rows[yy * row + i];
                }
                *o = sum / count;
            }
        });
}

/// Window means along one row of pixels of `channels` values each.
fn box_line(line: &[f64], out: &mut [f64], channels: usize, radius: usize) {
    let length = line.len() / channels;
    for c in 0..channels {
        let at = |i: usize| line[i * channels + c];
        let mut sum: f64 = (0..=radius.min(length - 1)).map(at).sum();
        for i in 0..length {
            let lo = i.saturating_sub(radius);
            let hi = (i + radius).min(length - 1);
            out[i * channels + c] = sum / (hi - lo + 1) as f64;
            // Slide: add the pixel entering the window, drop the one leaving it.
            if i + radius + 1 < length {
                sum += at(i + radius + 1);
            }
            if i >= radius {
                sum -= at(i - radius);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn settings(buffers: usize, strength: f32, radius: u32) -> FilterSettings {
        FilterSettings {
            buffers: buffers as u32,
            strength,
            radius,
        }
    }

    /// A step image: `low` left of column `width / 2`, `high` from it on.
    fn step(width: usize, height: usize, low: f64, high: f64) -> Vec<f64> {
        (0..width * height)
            .map(|i| if i % width < width / 2 { low } else { high })
            .collect()
    }

    /// Partial images of `truth`: each an independent estimate (noise of relative size
    /// `noise`, symmetric) scaled down by the number of partials.
    fn noisy_partials(truth: &[f64], buffers: usize, noise: f64) -> Vec<[f32; 3]> {
        let mut rng = Rng::new(7, 0);
        let mut partials = Vec::with_capacity(truth.len() * buffers);
        for &t in truth {
            for _ in 0..buffers {
                // Sum of 4 uniforms: symmetric, variance 1/3, scaled to variance 1.
                let u: f64 = (0..4).map(|_| rng.uniform() as f64 - 0.5).sum::<f64>() * 3f64.sqrt();
                let v = (t * (1.0 + noise * u) / buffers as f64) as f32;
                partials.push([v; 3]);
            }
        }
        partials
    }

    fn totals(partials: &[[f32; 3]], buffers: usize) -> Vec<[f64; 3]> {
        partials
            .chunks_exact(buffers)
            .map(|p| std::array::from_fn(|c| p.iter().map(|v| v[c] as f64).sum()))
            .collect()
    }

    fn rmse(image: &[[f64; 3]], truth: &[f64]) -> f64 {
        let sum: f64 = image
            .iter()
            .zip(truth)
            .map(|(v, t)| (v[0] - t).powi(2))
            .sum();
        (sum / truth.len() as f64).sqrt()
    }

    fn channel_totals(image: &[[f64; 3]]) -> [f64; 3] {
        std::array::from_fn(|c| image.iter().map(|v| v[c]).sum())
    }

    #[test]
    fn box_mean_matches_a_direct_window_sum() {
        let (width, height, channels, radius) = (7, 5, 2, 2);
        let values: Vec<f64> = (0..width * height * channels)
            .map(|i| ((i * 37) % 11) as f64)
            .collect();
        let mut scratch = vec![0.0; values.len()];
        let mut means = vec![0.0; values.len()];
        box_mean(&values, width, channels, radius, &mut scratch, &mut means);
        for y in 0..height {
            for x in 0..width {
                for c in 0..channels {
                    let (mut sum, mut count) = (0.0, 0.0);
                    for yy in y.saturating_sub(radius)..=(y + radius).min(height - 1) {
                        for xx in x.saturating_sub(radius)..=(x + radius).min(width - 1) {
                            sum += values[(yy * width + xx) * channels + c];
                            count += 1.0;
                        }
                    }
                    let got = means[(y * width + x) * channels + c];
                    assert!((got - sum / count).abs() < 1e-12, "({x}, {y}, {c})");
                }
            }
        }
    }

    #[test]
    fn smooths_noise_keeps_an_edge_and_keeps_the_total() {
        let (width, height, buffers) = (48, 32, 8);
        let truth = step(width, height, 1.0, 3.0);
        let partials = noisy_partials(&truth, buffers, 0.5);
        let totals = totals(&partials, buffers);
        let (filtered, stats) =
            filter_splats(width, &settings(buffers, 0.45, 7), &partials, &totals);
        let (before, after) = (rmse(&totals, &truth), rmse(&filtered, &truth));
        assert!(after < 0.5 * before, "RMSE {before} -> {after}");
        // The columns on either side of the edge keep their level: not averaged across it.
        for (x, level) in [(width / 2 - 1, 1.0), (width / 2, 3.0)] {
            let column: f64 = (0..height).map(|y| filtered[y * width + x][0]).sum::<f64>();
            let mean = column / height as f64;
            assert!(
                (mean / level - 1.0).abs() < 0.05,
                "column {x}: {mean} vs {level}"
            );
        }
        let (a, b) = (channel_totals(&totals), channel_totals(&filtered));
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() < 1e-9 * a[c]);
        }
        assert!(
            stats.changed_fraction > 0.0 && stats.mean_neighbours > 2.0,
            "{stats:?}"
        );
    }

    #[test]
    fn where_the_partials_agree_nothing_changes() {
        // No noise: every partial is the same share of a varied image.
        let (width, height, buffers) = (16, 12, 4);
        let truth: Vec<f64> = (0..width * height).map(|i| 1.0 + (i % 7) as f64).collect();
        let partials = noisy_partials(&truth, buffers, 0.0);
        let totals = totals(&partials, buffers);
        let (filtered, stats) =
            filter_splats(width, &settings(buffers, 0.45, 5), &partials, &totals);
        for (f, t) in filtered.iter().zip(&totals) {
            for c in 0..3 {
                assert!((f[c] - t[c]).abs() <= 1e-12 * t[c], "{f:?} {t:?}");
            }
        }
        assert_eq!(stats.changed_fraction, 0.0);
    }

    #[test]
    fn fewer_than_two_partials_with_energy_change_nothing() {
        let (width, buffers) = (4, 4);
        let mut partials = vec![[0.0f32; 3]; 4 * 4 * buffers];
        for (i, p) in partials.iter_mut().enumerate() {
            if i % buffers == 1 {
                *p = [(i % 7) as f32; 3];
            }
        }
        let totals = totals(&partials, buffers);
        let (filtered, stats) =
            filter_splats(width, &settings(buffers, 1.0, 3), &partials, &totals);
        assert_eq!(filtered, totals);
        assert_eq!(stats, FilterStats::default());
    }

    #[test]
    fn a_stronger_filter_averages_more() {
        let (width, height, buffers) = (32, 32, 8);
        let truth = step(width, height, 1.0, 2.0);
        let partials = noisy_partials(&truth, buffers, 0.5);
        let totals = totals(&partials, buffers);
        let (_, weak) = filter_splats(width, &settings(buffers, 0.1, 5), &partials, &totals);
        let (_, strong) = filter_splats(width, &settings(buffers, 1.0, 5), &partials, &totals);
        assert!(
            strong.mean_neighbours > weak.mean_neighbours * 1.3,
            "{weak:?} {strong:?}"
        );
    }
}
