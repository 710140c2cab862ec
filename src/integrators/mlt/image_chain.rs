//! The "neat example" of Metropolis sampling: a Markov chain over the pixels of a discrete
//! 2-D target (an image of non-negative values) whose histogram converges to the normalized
//! image.
//!
//! Each step proposes a uniformly random pixel — a symmetric mutation, T(y→x)/T(x→y) = 1 —
//! accepts it with the shared Metropolis–Hastings rule [`super::acceptance`] (the rule the
//! renderers use) and deposits one unit at the pixel the chain is in after the
//! accept/reject. The stationary distribution is target / Σ target, so
//! histogram × Σ target / (number of mutations) converges to the target itself.
//!
//! [`ImageChain::step_expected`] is the expected-value variant the renderers use: deposit
//! the acceptance probability a at the proposal and 1 − a at the current pixel, then move.
//! It has the same expectation and (usually) lower variance.
//!
//! Stepping never allocates; the histogram runners allocate one histogram per chain.

use super::acceptance;
use crate::sampling::Rng;
use rayon::prelude::*;

/// A Metropolis chain over the `width × height` pixels of `target` (row-major, one
/// non-negative value per pixel).
#[derive(Clone, Debug)]
pub struct ImageChain<'a> {
    target: &'a [f32],
    width: usize,
    height: usize,
    position: usize,
    value: f32,
    rng: Rng,
}

/// What one expected-value step deposits: `1 − acceptance` at `current` (the pixel before
/// the step) and `acceptance` at `proposal`. The two may be the same pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExpectedDeposit {
    pub current: usize,
    pub proposal: usize,
    pub acceptance: f32,
}

/// Uniform random draws from a random start before settling for a zero-valued pixel scan.
const START_ATTEMPTS: usize = 64;

impl<'a> ImageChain<'a> {
    /// A chain over `target` driven by stream `stream` of `seed`, started at a random pixel.
    ///
    /// The start is drawn uniformly among pixels of positive value (by retrying uniform
    /// draws a few times, then scanning forward from the last draw), so a chain never
    /// deposits on a zero pixel. If the target is zero everywhere the chain starts (and
    /// stays) on a zero pixel; any chain started on a zero pixel still works, because the
    /// acceptance rule always leaves a zero-valued state for a positive one.
    ///
    /// Panics if `target.len() != width * height`, the image is empty or has more than
    /// 2³² pixels, or a value is negative or not finite.
    pub fn new(target: &'a [f32], width: usize, height: usize, seed: u64, stream: u64) -> Self {
        let mut chain = Self::with_start(target, width, height, 0, seed, stream);
        let n = target.len();
        let mut position = chain.uniform_pixel();
        let mut attempts = 1;
        while target[position] <= 0.0 && attempts < START_ATTEMPTS {
            position = chain.uniform_pixel();
            attempts += 1;
        }
        if target[position] <= 0.0 {
            position = (0..n)
                .map(|k| (position + k) % n)
                .find(|&p| target[p] > 0.0)
                .unwrap_or(position);
        }
        chain.position = position;
        chain.value = target[position];
        chain
    }

    /// A chain started at pixel `position` (row-major index), which may have value 0.
    /// Panics like [`ImageChain::new`], or if `position` is outside the image.
    pub fn with_start(
        target: &'a [f32],
        width: usize,
        height: usize,
        position: usize,
        seed: u64,
        stream: u64,
    ) -> Self {
        let n = width.checked_mul(height).expect("image size overflows");
        assert_eq!(target.len(), n, "target must hold width × height values");
        assert!(n > 0, "target must not be empty");
        assert!(
            n <= u32::MAX as usize + 1,
            "target has more than 2^32 pixels"
        );
        assert!(
            target.iter().all(|v| v.is_finite() && *v >= 0.0),
            "target values must be finite and non-negative"
        );
        assert!(position < n, "start position outside the image");
        ImageChain {
            target,
            width,
            height,
            position,
            value: target[position],
            rng: Rng::new(seed, stream),
        }
    }

    /// The current pixel (row-major index).
    pub fn position(&self) -> usize {
        self.position
    }

    /// The current pixel as (x, y).
    pub fn position_xy(&self) -> (usize, usize) {
        (self.position % self.width, self.position / self.width)
    }

    /// The target value at the current pixel.
    pub fn value(&self) -> f32 {
        self.value
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// A uniformly random pixel index (exact: Lemire's multiply-and-reject).
    #[inline]
    fn uniform_pixel(&mut self) -> usize {
        uniform_index(&mut self.rng, self.target.len())
    }

    /// One mutation: propose a uniformly random pixel, accept it with
    /// [`super::acceptance`]`(f(current), f(proposal), 1)`, and return the pixel to deposit
    /// one unit at (the chain's position after the accept/reject).
    #[inline]
    pub fn step(&mut self) -> usize {
        self.step_with(
            |rng, _, n| (uniform_index(rng, n), 1.0),
            |f_current, f_proposal, transfer_ratio| {
                acceptance(f_current, f_proposal, transfer_ratio)
            },
        )
    }

    /// One expected-value mutation: uniform proposal, acceptance a as in
    /// [`ImageChain::step`]. Returns the deposits (a at the proposal, 1 − a at the pixel
    /// before the step); the chain then moves with probability a.
    #[inline]
    pub fn step_expected(&mut self) -> ExpectedDeposit {
        let current = self.position;
        let proposal = self.uniform_pixel();
        let f_proposal = self.target[proposal];
        let a = acceptance(self.value, f_proposal, 1.0);
        if self.rng.uniform() < a {
            self.position = proposal;
            self.value = f_proposal;
        }
        ExpectedDeposit {
            current,
            proposal,
            acceptance: a,
        }
    }

    /// One mutation with a caller-supplied proposal and acceptance rule, for experimenting
    /// with (and testing against) other chains. `propose(rng, current, n)` returns the
    /// proposed pixel and the transfer ratio T(y→x)/T(x→y) it claims;
    /// `accept(f_current, f_proposal, transfer_ratio)` returns the acceptance probability.
    /// Returns the position after the accept/reject.
    #[inline]
    pub fn step_with<P, A>(&mut self, propose: P, accept: A) -> usize
    where
        P: FnOnce(&mut Rng, usize, usize) -> (usize, f32),
        A: FnOnce(f32, f32, f32) -> f32,
    {
        let (proposal, transfer_ratio) = propose(&mut self.rng, self.position, self.target.len());
        let f_proposal = self.target[proposal];
        let a = accept(self.value, f_proposal, transfer_ratio);
        if self.rng.uniform() < a {
            self.position = proposal;
            self.value = f_proposal;
        }
        self.position
    }
}

/// A uniformly random integer in [0, n), n ≤ 2³², exactly uniform (Lemire 2019).
#[inline]
pub fn uniform_index(rng: &mut Rng, n: usize) -> usize {
    debug_assert!(n > 0 && n <= u32::MAX as usize + 1);
    if n > u32::MAX as usize {
        return rng.next_u32() as usize;
    }
    let n32 = n as u32;
    let mut m = rng.next_u32() as u64 * n as u64;
    if (m as u32) < n32 {
        let threshold = n32.wrapping_neg() % n32;
        while (m as u32) < threshold {
            m = rng.next_u32() as u64 * n as u64;
        }
    }
    (m >> 32) as usize
}

/// Mutations chain `chain` of `chains` performs when `total` are shared among them.
fn chain_mutations(total: u64, chains: usize, chain: usize) -> u64 {
    let chains = chains as u64;
    total / chains + u64::from((chain as u64) < total % chains)
}

fn total_mutations(target: &[f32], mutations_per_pixel: u64) -> u64 {
    mutations_per_pixel
        .checked_mul(target.len() as u64)
        .expect("number of mutations overflows")
}

fn normalization(target: &[f32], total: u64) -> f64 {
    if total == 0 {
        return 0.0;
    }
    target.iter().map(|&v| v as f64).sum::<f64>() / total as f64
}

/// Raw deposit counts of `chains` independent chains (streams 0..chains of `seed`) sharing
/// `mutations_per_pixel × width × height` mutations. Integer counts, so the result does not
/// depend on how rayon schedules the chains.
pub fn run_counts(
    target: &[f32],
    width: usize,
    height: usize,
    mutations_per_pixel: u64,
    seed: u64,
    chains: usize,
) -> Vec<u64> {
    assert!(chains > 0, "need at least one chain");
    let n = target.len();
    let total = total_mutations(target, mutations_per_pixel);
    (0..chains)
        .into_par_iter()
        .fold(
            || vec![0u64; n],
            |mut counts, c| {
                let mut chain = ImageChain::new(target, width, height, seed, c as u64);
                for _ in 0..chain_mutations(total, chains, c) {
                    counts[chain.step()] += 1;
                }
                counts
            },
        )
        .reduce(
            || vec![0u64; n],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    *x += y;
                }
                a
            },
        )
}

/// The normalized histogram of `chains` independent chains sharing
/// `mutations_per_pixel × width × height` mutations: count_i × Σ target / total mutations,
/// whose expectation converges to `target`. Deterministic for a given seed and chain count,
/// whatever the number of threads.
pub fn run_histogram(
    target: &[f32],
    width: usize,
    height: usize,
    mutations_per_pixel: u64,
    seed: u64,
    chains: usize,
) -> Vec<f64> {
    let counts = run_counts(target, width, height, mutations_per_pixel, seed, chains);
    let scale = normalization(target, total_mutations(target, mutations_per_pixel));
    counts.iter().map(|&c| c as f64 * scale).collect()
}

/// Chains whose per-chain histograms are held at once by [`run_histogram_expected`].
const CHAIN_BATCH: usize = 64;

/// Like [`run_histogram`] with expected-value deposits ([`ImageChain::step_expected`]).
/// Per-chain histograms are added in chain order, so the floating-point result is
/// deterministic whatever the number of threads.
pub fn run_histogram_expected(
    target: &[f32],
    width: usize,
    height: usize,
    mutations_per_pixel: u64,
    seed: u64,
    chains: usize,
) -> Vec<f64> {
    assert!(chains > 0, "need at least one chain");
    let n = target.len();
    let total = total_mutations(target, mutations_per_pixel);
    let mut sum = vec![0f64; n];
    for first in (0..chains).step_by(CHAIN_BATCH) {
        let batch: Vec<Vec<f64>> = (first..chains.min(first + CHAIN_BATCH))
            .into_par_iter()
            .map(|c| {
                let mut histogram = vec![0f64; n];
                let mut chain = ImageChain::new(target, width, height, seed, c as u64);
                for _ in 0..chain_mutations(total, chains, c) {
                    let d = chain.step_expected();
                    histogram[d.current] += 1.0 - d.acceptance as f64;
                    histogram[d.proposal] += d.acceptance as f64;
                }
                histogram
            })
            .collect();
        for histogram in &batch {
            for (s, h) in sum.iter_mut().zip(histogram) {
                *s += h;
            }
        }
    }
    let scale = normalization(target, total);
    sum.iter_mut().for_each(|s| *s *= scale);
    sum
}
