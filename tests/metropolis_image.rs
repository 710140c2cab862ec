//! The seed lecture's "neat example": a Metropolis chain over the pixels of an image whose
//! normalized histogram converges to the image. Checks convergence rates, the stationary
//! distribution (chi-square, with a wrong chain that must fail the same statistic), the
//! expected-value deposits and determinism across thread counts.
//!
//! Runs in under a second on 2 cores (`cargo test --test metropolis_image`).

use mlt::integrators::mlt::acceptance;
use mlt::integrators::mlt::image_chain::{
    ImageChain, run_counts, run_histogram, run_histogram_expected, uniform_index,
};
use mlt::sampling::Rng;

/// A 32×32 target: two Gaussian blobs, a ring, a constant floor and a dark square of exact
/// zeros.
fn blob_target() -> (Vec<f32>, usize, usize) {
    let (w, h) = (32usize, 32usize);
    let mut t = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
            let g = |cx: f32, cy: f32, s: f32| {
                (-((fx - cx).powi(2) + (fy - cy).powi(2)) / (2.0 * s * s)).exp()
            };
            let r = ((fx - 16.0).powi(2) + (fy - 16.0).powi(2)).sqrt();
            let ring = (-(r - 11.0).powi(2) / 2.0).exp();
            let mut v = 0.2 + 2.0 * g(10.0, 11.0, 3.0) + 1.0 * g(22.0, 20.0, 4.0) + 1.5 * ring;
            if (20..28).contains(&x) && (2..9).contains(&y) {
                v = 0.0;
            }
            t[y * w + x] = v;
        }
    }
    (t, w, h)
}

/// An 8×8 target with values in [0.5, 4] and 8 cells of exact zero.
fn small_target() -> (Vec<f32>, usize, usize) {
    let (w, h) = (8usize, 8usize);
    let mut t = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            t[y * w + x] = if (x + 3 * y) % 8 == 5 {
                0.0
            } else {
                0.5 + 3.5 * (((x * 5 + y * 3) % 8) as f32 / 7.0)
            };
        }
    }
    (t, w, h)
}

fn relative_l2(histogram: &[f64], target: &[f32]) -> f64 {
    let err: f64 = histogram
        .iter()
        .zip(target)
        .map(|(&h, &t)| (h - t as f64).powi(2))
        .sum();
    let norm: f64 = target.iter().map(|&t| (t as f64).powi(2)).sum();
    (err / norm).sqrt()
}

/// Largest non-trivial eigenvalue of the independence Metropolis chain with proposal
/// distribution `q` and target ∝ `t` (Liu 1996): 1 − min over t_i > 0 of q_i / π_i.
fn independence_lambda(q: &[f64], t: &[f32]) -> f64 {
    let s: f64 = t.iter().map(|&v| v as f64).sum();
    let w_min = q
        .iter()
        .zip(t)
        .filter(|&(_, &ti)| ti > 0.0)
        .map(|(&qi, &ti)| qi * s / ti as f64)
        .fold(f64::INFINITY, f64::min);
    1.0 - w_min
}

/// Asymptotic RMS bound on the relative L2 error of the normalized histogram after
/// `mpp` mutations per pixel of the uniform-proposal chain.
///
/// Count i has variance ≈ N τ_i π_i (1 − π_i) with τ_i the integrated autocorrelation
/// time; h_i = c_i Σt / N, so E‖h − t‖² ≤ τ (Σt)² / N and, with N = mpp·n,
/// E‖h − t‖² / ‖t‖² ≤ τ / (mpp · mean(t²)/mean(t)²). For a reversible chain whose
/// non-trivial spectrum lies in [0, λ] (true for independence samplers), τ ≤ (1+λ)/(1−λ).
fn error_bound(t: &[f32], mpp: u64) -> f64 {
    let n = t.len() as f64;
    let lambda = independence_lambda(&vec![1.0 / n; t.len()], t);
    let tau = (1.0 + lambda) / (1.0 - lambda);
    let mean = t.iter().map(|&v| v as f64).sum::<f64>() / n;
    let mean_sq = t.iter().map(|&v| (v as f64).powi(2)).sum::<f64>() / n;
    (tau * mean * mean / (mpp as f64 * mean_sq)).sqrt()
}

/// Upper 99.9% quantile of the chi-square distribution (Wilson–Hilferty; within 0.5% for
/// df ≥ 30).
fn chi_square_q999(df: usize) -> f64 {
    const Z999: f64 = 3.090_232;
    let k = df as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + Z999 * a.sqrt()).powi(3)
}

/// Pearson's statistic of `counts` against `t`, over the cells with t > 0, and its degrees
/// of freedom. Also returns the counts that fell on zero cells.
fn chi_square(counts: &[u64], t: &[f32]) -> (f64, usize, u64) {
    let n: u64 = counts.iter().sum();
    let s: f64 = t.iter().map(|&v| v as f64).sum();
    let mut stat = 0.0;
    let mut cells = 0;
    let mut on_zero = 0;
    for (&c, &ti) in counts.iter().zip(t) {
        if ti > 0.0 {
            let e = ti as f64 / s * n as f64;
            stat += (c as f64 - e).powi(2) / e;
            cells += 1;
        } else {
            on_zero += c;
        }
    }
    (stat, cells - 1, on_zero)
}

const CHI_CHAINS: usize = 100_000;

/// Steps after which the independence sampler with largest non-trivial eigenvalue `lambda`
/// is within total variation λ^steps ≤ 10⁻⁶ / CHI_CHAINS of its target (Mengersen & Tweedie
/// 1996: its distance after k steps from any start is at most λ^k), so that not even one of
/// the CHI_CHAINS final states is expected to differ from an exact draw.
fn steps_to_mix(lambda: f64) -> usize {
    ((1e-6 / CHI_CHAINS as f64).ln() / lambda.ln()).ceil() as usize
}

/// Final states of `CHI_CHAINS` independent chains of `steps` mutations each, every
/// mutation made by `step`: independent draws from the chain's distribution after `steps`
/// steps.
fn final_state_counts(
    t: &[f32],
    w: usize,
    h: usize,
    steps: usize,
    step: impl Fn(&mut ImageChain) -> usize,
) -> Vec<u64> {
    let mut counts = vec![0u64; t.len()];
    for c in 0..CHI_CHAINS {
        let mut chain = ImageChain::new(t, w, h, 0xC41, c as u64);
        let mut p = chain.position();
        for _ in 0..steps {
            p = step(&mut chain);
        }
        counts[p] += 1;
    }
    counts
}

/// A proposal that is not symmetric: column c with probability (c + 1) / 36, row uniform.
/// Returns the pixel and its probability.
fn column_biased_proposal(rng: &mut Rng, w: usize, h: usize) -> (usize, f64) {
    let total = w * (w + 1) / 2;
    let mut u = uniform_index(rng, total);
    let mut col = 0;
    while u > col {
        u -= col + 1;
        col += 1;
    }
    let row = uniform_index(rng, h);
    (row * w + col, column_biased_pdf(row * w + col, w, h))
}

fn column_biased_pdf(p: usize, w: usize, h: usize) -> f64 {
    ((p % w) + 1) as f64 / (w * (w + 1) / 2) as f64 / h as f64
}

#[test]
fn chi_square_quantile_matches_tables() {
    // Tabulated 99.9% quantiles.
    for (df, q) in [(40, 73.402), (50, 86.661), (60, 99.607)] {
        let approx = chi_square_q999(df);
        assert!((approx - q).abs() < 0.005 * q, "df {df}: {approx} vs {q}");
    }
}

#[test]
fn histogram_converges_to_target() {
    let (t, w, h) = blob_target();
    let chains = 16;
    let mut errors = Vec::new();
    for mpp in [8u64, 64, 512] {
        let hist = run_histogram(&t, w, h, mpp, 1, chains);
        let e = relative_l2(&hist, &t);
        println!(
            "sample deposits {mpp:>4} mpp: relative L2 error {e:.4} (bound {:.4})",
            error_bound(&t, mpp)
        );
        for (i, &ti) in t.iter().enumerate() {
            if ti == 0.0 {
                assert_eq!(hist[i], 0.0, "deposit on zero pixel {i}");
            }
        }
        errors.push((mpp, e));
    }
    for pair in errors.windows(2) {
        let ((m0, e0), (m1, e1)) = (pair[0], pair[1]);
        // Independent-proposal chain: error ∝ 1/√mpp, so ≈ √8 ≈ 2.83 per 8×; the error is
        // a sum over 1024 cells and fluctuates by a few percent between runs.
        assert!(
            e0 / e1 > 2.0,
            "{m0} mpp: {e0}, {m1} mpp: {e1}: ratio {}",
            e0 / e1
        );
    }
    let (mpp, e) = errors[2];
    let bound = error_bound(&t, mpp);
    assert!(
        e < bound,
        "{mpp} mpp: error {e} above the spectral-gap bound {bound}"
    );
}

#[test]
fn stationary_distribution_passes_chi_square_and_wrong_chains_fail() {
    let (t, w, h) = small_target();
    let n = t.len() as f64;

    // The final states of independent chains are independent draws; after `steps` steps
    // their distribution is (for all practical purposes) the target.
    let lambda = independence_lambda(&vec![1.0 / n; t.len()], &t);
    let steps = steps_to_mix(lambda);
    println!("uniform proposal: λ = {lambda:.3}, {steps} steps per chain");
    assert!(
        steps <= 128,
        "target too peaked for a fast test: {steps} steps"
    );

    let counts = final_state_counts(&t, w, h, steps, |c| c.step());
    let (stat, df, on_zero) = chi_square(&counts, &t);
    let q = chi_square_q999(df);
    println!("correct chain: chi-square {stat:.1}, df {df}, 99.9% quantile {q:.1}");
    assert_eq!(on_zero, 0, "final states on zero cells");
    assert!(
        stat < q,
        "correct chain fails chi-square: {stat} ≥ {q} (df {df})"
    );

    // The full histograms of long chains never touch a zero cell either.
    let full = run_counts(&t, w, h, 4096, 3, 8);
    for (i, &ti) in t.iter().enumerate() {
        if ti == 0.0 {
            assert_eq!(full[i], 0, "deposits on zero cell {i}");
        }
    }

    // Wrong acceptance: min(1, √(f(y)/f(x))) samples ∝ √f.
    let sqrt_counts = final_state_counts(&t, w, h, steps, |c| {
        c.step_with(
            |rng, _, n| (uniform_index(rng, n), 1.0),
            |fx, fy, r| acceptance(fx, fy, r).sqrt(),
        )
    });
    let (sqrt_stat, _, _) = chi_square(&sqrt_counts, &t);
    println!("sqrt acceptance: chi-square {sqrt_stat:.1}");
    assert!(
        sqrt_stat > 10.0 * q,
        "sqrt-acceptance chain not detected: {sqrt_stat}"
    );

    // Non-symmetric proposal without the T(y→x)/T(x→y) correction samples ∝ f·q.
    let biased_counts = final_state_counts(&t, w, h, steps, |c| {
        c.step_with(
            |rng, _, _| (column_biased_proposal(rng, w, h).0, 1.0),
            acceptance,
        )
    });
    let (biased_stat, _, _) = chi_square(&biased_counts, &t);
    println!("asymmetric proposal, no T correction: chi-square {biased_stat:.1}");
    assert!(
        biased_stat > 10.0 * q,
        "uncorrected proposal not detected: {biased_stat}"
    );

    // The same proposal with the correct transfer ratio q(x)/q(y) passes.
    let q_pdf: Vec<f64> = (0..t.len()).map(|p| column_biased_pdf(p, w, h)).collect();
    let lambda_q = independence_lambda(&q_pdf, &t);
    let steps_q = steps_to_mix(lambda_q);
    println!("column-biased proposal: λ = {lambda_q:.3}, {steps_q} steps per chain");
    let corrected_counts = final_state_counts(&t, w, h, steps_q, |c| {
        c.step_with(
            |rng, x, _| {
                let (y, q_y) = column_biased_proposal(rng, w, h);
                (y, (column_biased_pdf(x, w, h) / q_y) as f32)
            },
            acceptance,
        )
    });
    let (corrected_stat, _, corrected_zero) = chi_square(&corrected_counts, &t);
    println!("asymmetric proposal with T correction: chi-square {corrected_stat:.1}");
    assert_eq!(corrected_zero, 0);
    assert!(
        corrected_stat < q,
        "corrected chain fails: {corrected_stat} ≥ {q}"
    );
}

#[test]
fn chain_started_on_zero_pixel_leaves_it_for_good() {
    let (t, w, h) = small_target();
    let zero = t.iter().position(|&v| v == 0.0).unwrap();
    let mut chain = ImageChain::with_start(&t, w, h, zero, 5, 0);
    assert_eq!(chain.value(), 0.0);
    let mut left = false;
    for _ in 0..10_000 {
        let p = chain.step();
        if t[p] > 0.0 {
            left = true;
        } else {
            assert!(!left, "chain returned to zero pixel {p}");
        }
    }
    assert!(left);
    // A random start is never on a zero pixel.
    for stream in 0..1000 {
        assert!(ImageChain::new(&t, w, h, 9, stream).value() > 0.0);
    }
}

#[test]
fn expected_value_deposits_converge_to_target() {
    let (t, w, h) = blob_target();
    let s: f64 = t.iter().map(|&v| v as f64).sum();
    let mut errors = Vec::new();
    for mpp in [8u64, 64, 512] {
        let hist = run_histogram_expected(&t, w, h, mpp, 1, 16);
        let sample = run_histogram(&t, w, h, mpp, 1, 16);
        let e = relative_l2(&hist, &t);
        let e_sample = relative_l2(&sample, &t);
        println!(
            "expected deposits {mpp:>4} mpp: relative L2 error {e:.4} (sample deposits {e_sample:.4})"
        );
        // Every mutation deposits exactly one unit in total.
        let total: f64 = hist.iter().sum();
        assert!((total - s).abs() < 1e-9 * s, "{total} vs {s}");
        for (i, &ti) in t.iter().enumerate() {
            if ti == 0.0 {
                assert_eq!(hist[i], 0.0, "deposit on zero pixel {i}");
            }
        }
        errors.push((mpp, e, e_sample));
    }
    for pair in errors.windows(2) {
        let ((m0, e0, _), (m1, e1, _)) = (pair[0], pair[1]);
        assert!(
            e0 / e1 > 2.0,
            "{m0} mpp: {e0}, {m1} mpp: {e1}: ratio {}",
            e0 / e1
        );
    }
    let (mpp, e, e_sample) = errors[2];
    let bound = error_bound(&t, mpp);
    assert!(e < bound, "{mpp} mpp: error {e} above bound {bound}");
    // Rao–Blackwellized deposits have lower variance than sample deposits here.
    assert!(
        e < e_sample,
        "expected deposits {e} not better than samples {e_sample}"
    );
}

#[test]
fn histograms_are_deterministic_across_thread_counts() {
    let (t, w, h) = blob_target();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                (
                    run_histogram(&t, w, h, 16, 42, 37),
                    run_histogram_expected(&t, w, h, 16, 42, 70),
                )
            })
    };
    let (a1, b1) = run(1);
    let (a2, b2) = run(2);
    assert!(a1.iter().zip(&a2).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(b1.iter().zip(&b2).all(|(x, y)| x.to_bits() == y.to_bits()));
    let (a3, _) = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| (run_histogram(&t, w, h, 16, 43, 37), ()));
    assert_ne!(a1, a3, "seed has no effect");
}
