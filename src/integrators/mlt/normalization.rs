//! The normalization of a Metropolis image: b_g = ∫ f_g, the total luminance of the paths a
//! group of chains renders (MMLT: one group per path depth; the other variants: one group).
//! The chains only say where the light is (their deposits have density f_g / b_g); how bright
//! the image is comes from b_g alone, so its error is the image's brightness error.
//!
//! # The estimator
//!
//! b_g is the mean of f_g over independent samples of the chains' own target, drawn from
//! three sources during the whole render:
//!
//! 1. the bootstrap (stratified over the film), which also seeds the chains;
//! 2. for the targets whose large steps evaluate the same function as the bootstrap
//!    (PSSMLT over the path tracer, PSSMLT over BDPT; not MMLT, whose large steps pick one
//!    strategy and have heavier tails), every large step's proposal: Kelemen's large steps
//!    are uniform samples of primary sample space, drawn whatever the chain's state. Only
//!    with the direct pass on: otherwise emitters seen directly are in f, and large steps,
//!    not stratified over the film, add the variance of how many land on them;
//! 3. a *normalization pass* that draws more such samples (uniform over primary sample
//!    space) alongside the chains when 2. does not make `work_fraction` of the work, so
//!    that the independent samples (its own and the pooled large steps) trace about
//!    `work_fraction` of all the rays. After each round of mutations it catches up: for
//!    path-space MLT until its rays make the share; for the primary-sample-space chains by
//!    a number of samples per mutation fixed before the chains start, from the rays a
//!    bootstrap sample traced and those of a few hundred independent chain states. Rays and
//!    mutations are counted exactly, so the number of samples, and the image, do not depend
//!    on timing. With the default fraction, PSSMLT's large steps (30% of its mutations)
//!    already make the share, and the pass draws nothing for it.
//!
//! In primary sample space the pass's samples are not spent on b alone: they are a third
//! sampling technique of the image beside the chains and their large steps, combined with
//! them by Kelemen's balance heuristic (`PassImage`). MMLT's pass samples are BDPT samples,
//! every strategy of every depth at once; where the chains rarely go they carry the image,
//! so the rays the pass takes from the chains come back as image.
//!
//! The image is scaled by the final estimate, after the last round (a time-limited or
//! cancelled render too). So its brightness error shrinks like 1/√(work): a render of four
//! times the work has half the brightness error, and a rare bright path that carried a large
//! share of a small bootstrap is diluted by every later sample.
//!
//! # Why it is right
//!
//! Every sample is an unbiased estimate of b_g, and whether a sample is drawn (how many
//! large steps a chain takes, how far the pass got when a stop came) never depends on its
//! value, so the mean over all of them is an unbiased estimate of b_g for any count. The
//! image is b̂_g times the chains' normalized deposits; the two are not independent (chains
//! start from bootstrap samples and accept large steps), so the image is consistent rather
//! than unbiased, as a Metropolis image always was: both factors converge.
//!
//! # Its cost
//!
//! The independent samples take `work_fraction` of the rays (the pass's samples are path
//! tracer samples for PSSMLT, BDPT samples with all strategies for the others); the large
//! steps cost nothing more, since the chains make them anyway, and in primary sample space
//! neither do the pass's samples, which join the image. `RenderSettings::normalization_work_fraction` documents the default and how
//! it was chosen. The estimate also keeps the sample variance, so a
//! render reports its own brightness uncertainty (`RenderStats::normalization_relative_error`)
//! and the share of b its brightest single sample carried.

use super::primary_space::{MetropolisSettings, PrimarySpaceTarget, new_sampler};
use super::pss::PssSampler;
use crate::control::Control;
use crate::film::Film;
use crate::film::Splat;
use crate::sampling::Rng;
use crate::scene::CameraModel;
use std::sync::atomic::Ordering;

/// Count, sum, sum of squares and largest value of a stream of samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Moments {
    pub count: u64,
    pub sum: f64,
    pub squares: f64,
    pub largest: f64,
}

impl Moments {
    #[inline]
    pub fn add(&mut self, value: f64) {
        self.count += 1;
        self.sum += value;
        self.squares += value * value;
        self.largest = self.largest.max(value);
    }

    pub fn merge(&mut self, other: &Moments) {
        self.count += other.count;
        self.sum += other.sum;
        self.squares += other.squares;
        self.largest = self.largest.max(other.largest);
    }
}

/// Per group, Σ f_g over independent samples, and the moments of Σ_g f_g per sample (every
/// sample evaluates every group).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct NormalizationEstimate {
    pub group_sums: Vec<f64>,
    pub total: Moments,
}

/// What a render's normalization came to.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalizationStats {
    /// b = Σ_g b_g, the image's total luminance per pixel from the chains.
    pub value: f64,
    /// Independent samples b was estimated from.
    pub samples: u64,
    /// The estimated standard error of b over b (from the samples' variance; a tail the
    /// samples never reached is not in it).
    pub relative_error: f64,
    /// The largest share of Σ f a single sample carried: near 1/samples for a well-behaved
    /// scene, much more when rare bright paths dominate.
    pub largest_share: f64,
}

impl NormalizationEstimate {
    pub fn new(groups: usize) -> Self {
        NormalizationEstimate {
            group_sums: vec![0.0; groups],
            total: Moments::default(),
        }
    }

    /// Adds one sample's value per group.
    #[inline]
    pub fn add(&mut self, values: &[f32]) {
        let mut total = 0.0;
        for (sum, &v) in self.group_sums.iter_mut().zip(values) {
            *sum += v as f64;
            total += v as f64;
        }
        self.total.add(total);
    }

    pub fn merge(&mut self, other: &NormalizationEstimate) {
        for (sum, o) in self.group_sums.iter_mut().zip(&other.group_sums) {
            *sum += o;
        }
        self.total.merge(&other.total);
    }

    /// Adds samples of a single-group target (a chain's large steps).
    pub fn merge_single_group(&mut self, moments: &Moments) {
        debug_assert_eq!(self.group_sums.len(), 1);
        self.group_sums[0] += moments.sum;
        self.total.merge(moments);
    }

    /// b_g per group (zeros before any sample).
    pub fn b(&self) -> Vec<f64> {
        let n = self.total.count.max(1) as f64;
        self.group_sums.iter().map(|s| s / n).collect()
    }

    pub fn stats(&self) -> NormalizationStats {
        let Moments {
            count,
            sum,
            squares,
            largest,
        } = self.total;
        if count == 0 || sum <= 0.0 {
            return NormalizationStats {
                samples: count,
                ..Default::default()
            };
        }
        let n = count as f64;
        let mean = sum / n;
        let variance = if count > 1 {
            ((squares - sum * mean) / (n - 1.0)).max(0.0)
        } else {
            0.0
        };
        NormalizationStats {
            value: mean,
            samples: count,
            relative_error: (variance / n).sqrt() / mean,
            largest_share: largest / sum,
        }
    }
}

/// Stream offsets of the pass's samples (apart from the bootstrap's and the chains'), of
/// their positions within the pixel and of each film pass's order.
const PASS_STREAM: u64 = 0x5eed_b0b0_0000_0000;
const PASS_JITTER_STREAM: u64 = 0x5eed_b0b1_0000_0000;
const PASS_ORDER_STREAM: u64 = 0x5eed_b0b2_0000_0000;

/// The film position of pass sample `i`, in [0, 1)². Like the bootstrap's, the samples are
/// stratified over the film: film pass k = i / pixels visits every pixel once, in the order
/// j ↦ (a_k·j + c_k) mod pixels, with a multiplier a_k near pixels / φ, coprime to the pixel
/// count, and an offset c_k uniform over the pixels, both per film pass. The multiplier
/// spreads consecutive samples over the film, so any stretch of a film pass covers it
/// evenly (stratified, as the bootstrap; uniform positions add the variance of how often
/// the samples land on bright pixels, such as a light seen directly). The uniform offset
/// puts every pixel at a uniform place in the order, so wherever the pass stops (a round's
/// catch-up, a time limit) each pixel was reached with the same probability and the mean
/// stays unbiased.
fn pass_film_position(i: u64, camera: &CameraModel, seed: u64) -> [f32; 2] {
    let (width, height) = (camera.width as u64, camera.height as u64);
    let pixels = width * height;
    let (k, j) = (i / pixels, i % pixels);
    let mut order = Rng::new(seed, PASS_ORDER_STREAM + k);
    let offset = ((order.next_u32() as u64) << 32 | order.next_u32() as u64) % pixels;
    let mut multiplier = ((pixels as f64 * 0.618_033_988_749_895) as u64).max(1);
    multiplier += (order.next_u32() as u64) % 64;
    while gcd(multiplier, pixels) != 1 {
        multiplier += 1;
    }
    let pixel = ((multiplier as u128 * j as u128 + offset as u128) % pixels as u128) as u64;
    let mut jitter = Rng::new(seed, PASS_JITTER_STREAM + i);
    let [u, v] = jitter.uniform2();
    let x = ((pixel % width) as f32 + u) / width as f32;
    let y = ((pixel / width) as f32 + v) / height as f32;
    [x.min(1.0f32.next_down()), y.min(1.0f32.next_down())]
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// How a point of a pass sample (`PrimarySpaceTarget::pass_sample`) of a group is weighted
/// into the image.
#[derive(Clone, Copy, Debug)]
pub(crate) enum PointWeight {
    /// Combined with the group's chains and their large steps by the balance heuristic:
    /// `numerator / (f + offset)` (see `PassImage`).
    Combined { numerator: f32, offset: f32 },
    /// A group without chains (its light was not in the bootstrap): the pass alone renders
    /// it, each point standing for `weight` = 1 / its points per sample.
    Alone { weight: f32 },
}

impl PointWeight {
    /// The weight of a point whose state has value `target`.
    #[inline]
    pub fn of(self, target: f32) -> f32 {
        match self {
            PointWeight::Combined { numerator, offset } => numerator / (target + offset),
            PointWeight::Alone { weight } => weight,
        }
    }
}

/// The pass's samples as a third sampling technique of the image, beside the chains and
/// their large steps (primary sample space only: there the pass's density is known).
///
/// Kelemen et al. weight the chain's deposits and the large steps' by the balance heuristic
/// over the chain's density f/b and the large steps' density p_large, both per mutation.
/// The pass is one more uniform technique: per mutation of group g it puts r_g points in
/// the chains' space (`samples_per_mutation` × the group's points per sample × all chains
/// / the chains of g), so every deposit's weight becomes 1/(f + (p_large + r_g)·c_g), the large
/// steps' and the pass's times c_g, and the chains' times the final b_g. As with the large
/// steps, any constants keep the weights a partition of unity, so c_g is the bootstrap's
/// b_g and r_g the planned rate; the pass's points are averaged over the samples actually
/// drawn (a layer of the film scaled at the end). Where the chains rarely go, the pass's
/// BDPT samples, which evaluate every strategy of every depth at once, carry the image.
pub(crate) struct PassImage {
    pub weights: Vec<PointWeight>,
    /// Samples the pass draws per chain mutation (it draws exactly that many, so the weights
    /// are what was planned).
    pub samples_per_mutation: f64,
    /// The chains, and the film layer the pass's points go to.
    pub chains: u64,
    pub layer: usize,
}

/// The normalization pass: independent samples of `target` drawn alongside the chains, a
/// fixed share of the rays, added to the estimate the bootstrap started.
///
/// The pass's samples belong to the chains: chain c draws samples c, c + C, c + 2C, … (C
/// chains in all) in its own parallel task, after each round of its mutations, as many as
/// its own mutations or rays call for, and keeps their sum apart (`PassSlot`). So what is
/// drawn, and the order every sum is added in, depends only on each chain's own work, never
/// on the thread count or on how the chains are split into jobs (`render::jobs`); and the
/// samples of whole rounds form a prefix of the sample sequence, which the film positions
/// stratify (`pass_film_position`).
pub(crate) struct NormalizationPass<'a, T: PrimarySpaceTarget> {
    pub context: PassContext<'a, T>,
    /// One per chain of this run, in the order of its chains (`None`: the pass draws
    /// nothing).
    pub slots: Vec<Option<PassSlot<T::Scratch>>>,
    /// The bootstrap's estimate, which the chains' samples are added to at the end.
    pub estimate: NormalizationEstimate,
}

/// What every chain's share of the pass reads.
pub(crate) struct PassContext<'a, T: PrimarySpaceTarget> {
    target: &'a T,
    camera: &'a CameraModel,
    seed: u64,
    /// The share of all rays that independent samples are to trace.
    work_fraction: f64,
    /// The chains of the whole render: sample j of chain c is sample j·C + c.
    chain_count: u64,
    /// With its samples in the image, the pass keeps pace by samples per mutation instead
    /// of by rays.
    image: Option<PassImage>,
}

/// A chain's share of the pass: its sampler and scratch, and what its samples came to.
pub(crate) struct PassSlot<S> {
    /// The chain's index in the whole render.
    chain: u64,
    sampler: PssSampler,
    scratch: S,
    values: Vec<f32>,
    /// Its samples' values (every group) …
    pub estimate: NormalizationEstimate,
    /// … how many, and the rays they traced.
    pub drawn: u64,
    rays: u64,
    /// The rays of this chain slot's chains in earlier phases, and of those the rays of
    /// large steps that count as independent samples.
    chain_rays_before: u64,
    large_step_rays_before: u64,
    /// With the pass in the image: the points of the samples drawn this round, and each
    /// sample's index with the end of its points.
    pub deposits: Vec<Splat>,
    pub sample_ends: Vec<(u64, usize)>,
}

impl<'a, T: PrimarySpaceTarget> NormalizationPass<'a, T>
where
    T::Scratch: Send,
{
    /// A pass continuing `estimate` (the bootstrap's), with a slot for each of `chains`
    /// (indices into the `chain_count` chains of the whole render); with a work fraction of
    /// 0 it draws nothing.
    pub fn new(
        target: &'a T,
        camera: &'a CameraModel,
        settings: &MetropolisSettings,
        estimate: NormalizationEstimate,
        chains: &[u64],
        chain_count: u64,
    ) -> Self {
        let groups = target.groups();
        let fraction = settings.normalization_work_fraction as f64;
        let slots = chains
            .iter()
            .map(|&chain| {
                (fraction > 0.0).then(|| PassSlot {
                    chain,
                    sampler: new_sampler(target, settings),
                    scratch: target.scratch(),
                    values: vec![0.0; groups],
                    estimate: NormalizationEstimate::new(groups),
                    drawn: 0,
                    rays: 0,
                    chain_rays_before: 0,
                    large_step_rays_before: 0,
                    deposits: Vec::new(),
                    sample_ends: Vec::new(),
                })
            })
            .collect();
        NormalizationPass {
            context: PassContext {
                target,
                camera,
                seed: settings.seed,
                work_fraction: fraction,
                chain_count,
                image: None,
            },
            slots,
            estimate,
        }
    }

    /// Puts the pass's samples in the image (`PassImage`); a pass drawing nothing is left
    /// as it is.
    pub fn with_image(mut self, image: Option<PassImage>) -> Self {
        self.context.image = image.filter(|_| self.context.work_fraction > 0.0);
        self
    }

    /// Reserves, once, room for the points of the samples each chain draws in a round of
    /// `mutations` mutations.
    pub fn reserve_for_round(&mut self, mutations: u64) {
        let Some(image) = &self.context.image else {
            return;
        };
        let target = self.context.target;
        let groups = self.estimate.group_sums.len();
        let points: u32 = (0..groups).map(|g| target.points_per_sample(g)).sum();
        let samples = (image.samples_per_mutation * mutations as f64).ceil() as usize + 1;
        for slot in self.slots.iter_mut().flatten() {
            slot.deposits = Vec::with_capacity(samples * target.max_entries() * points as usize);
            slot.sample_ends = Vec::with_capacity(samples);
        }
    }

    /// The film layer of the pass's points, if they join the image.
    pub fn image_layer(&self) -> Option<usize> {
        self.context.image.as_ref().map(|image| image.layer)
    }

    /// Whether the chains' large steps also count: the target's large steps evaluate what
    /// the bootstrap does.
    pub fn pools_large_steps(&self) -> bool {
        self.context.pools_large_steps()
    }

    /// Starts a new phase of chains (path-space MLT's adapted chains), whose ray counts
    /// start again from their seeds: `chain_rays[i]` (and `large_step_rays[i]`) are what
    /// slot i's chain of the phase that ends traced.
    pub fn start_phase(&mut self, chain_rays: &[u64], large_step_rays: &[u64]) {
        for ((slot, &rays), &large) in self.slots.iter_mut().zip(chain_rays).zip(large_step_rays) {
            if let Some(slot) = slot {
                slot.chain_rays_before += rays;
                slot.large_step_rays_before += large;
            }
        }
    }

    /// Adds the points the slots drew this round to the film, sample i's to the filter's
    /// partial image i, and forgets them.
    pub fn deposit_round(&mut self, film: &mut Film) {
        let Some(image) = &self.context.image else {
            return;
        };
        // The partial images get the planned factor: mutations per chain / samples.
        let partial_scale = 1.0 / (image.samples_per_mutation * image.chains as f64);
        for slot in self.slots.iter_mut().flatten() {
            let mut start = 0;
            for &(i, end) in &slot.sample_ends {
                let points = &slot.deposits[start..end];
                film.add_chain_splats(image.layer, points, 1.0, partial_scale, i as usize);
                start = end;
            }
            slot.deposits.clear();
            slot.sample_ends.clear();
        }
    }
}

impl<T: PrimarySpaceTarget> PassContext<'_, T> {
    fn pools_large_steps(&self) -> bool {
        self.target.large_steps_are_bootstrap_samples()
    }

    /// Lets a chain's slot catch up with its chain, which has traced `chain_rays`
    /// (`large_step_rays` of them for large steps) and made `mutations` mutations in all:
    /// samples until its samples' rays and the pooled large steps' make the work fraction of
    /// the chain's and theirs (nothing once the render is stopping); with the pass in the
    /// image, until it has drawn its samples per mutation, even when stopping: the weights
    /// count on them.
    pub fn catch_up(
        &self,
        slot: &mut PassSlot<T::Scratch>,
        chain_rays: u64,
        large_step_rays: u64,
        mutations: u64,
        control: &Control,
    ) {
        let rays_before = slot.rays;
        if let Some(image) = &self.image {
            let goal = (image.samples_per_mutation * mutations as f64).ceil() as u64;
            while slot.drawn < goal {
                self.draw(slot, Some(&image.weights));
            }
        } else {
            // The pass's rays P and the pooled large steps' L must make f of all rays C + P:
            // P + L ≥ f (C + P), so P ≥ (f C − L) / (1 − f).
            let f = self.work_fraction;
            let chain = (slot.chain_rays_before + chain_rays) as f64;
            let large_steps = if self.pools_large_steps() {
                (slot.large_step_rays_before + large_step_rays) as f64
            } else {
                0.0
            };
            let goal = ((f * chain - large_steps) / (1.0 - f)).max(0.0) as u64;
            while slot.rays < goal && !control.should_stop() {
                self.draw(slot, None);
            }
        }
        control
            .rays
            .fetch_add(slot.rays - rays_before, Ordering::Relaxed);
    }

    /// Draws the slot's next sample (with `weights`, keeping its points for the image).
    fn draw(&self, slot: &mut PassSlot<T::Scratch>, weights: Option<&[PointWeight]>) {
        let (target, camera, seed) = (self.target, self.camera, self.seed);
        let i = slot.drawn * self.chain_count + slot.chain;
        let position = pass_film_position(i, camera, seed);
        slot.sampler.restart_at(seed, PASS_STREAM + i, position);
        slot.values.fill(0.0);
        if let Some(weights) = weights {
            let deposits = &mut slot.deposits;
            target.pass_sample(
                camera,
                &mut slot.sampler,
                &mut slot.scratch,
                &mut slot.values,
                &mut slot.rays,
                &mut |group, point| {
                    let weight = weights[group].of(point.target);
                    deposits.extend(point.entries.iter().map(|e| Splat {
                        pixel: e.pixel,
                        value: e.value * weight,
                    }));
                },
            );
            slot.sample_ends.push((i, slot.deposits.len()));
        } else {
            target.bootstrap(
                camera,
                &mut slot.sampler,
                &mut slot.scratch,
                &mut slot.values,
                &mut slot.rays,
            );
        }
        slot.estimate.add(&slot.values);
        slot.drawn += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each film pass of the normalization pass visits every pixel once, and wherever it is
    /// cut, each pixel was as likely to be reached.
    #[test]
    fn pass_positions_cover_the_film_and_every_prefix_is_fair() {
        let camera = crate::scene::Camera::default().model(6, 4);
        let pixels = 24u64;
        let pixel_of = |i: u64| {
            let [x, y] = pass_film_position(i, &camera, 7);
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            (y * 4.0) as u64 * 6 + (x * 6.0) as u64
        };
        let passes = 6000u64;
        let mut in_prefix = vec![0u32; pixels as usize];
        for k in 0..passes {
            let mut seen = vec![false; pixels as usize];
            for j in 0..pixels {
                let p = pixel_of(k * pixels + j) as usize;
                assert!(!seen[p], "pass {k} visits pixel {p} twice");
                seen[p] = true;
                if j < 5 {
                    in_prefix[p] += 1;
                }
            }
        }
        // A prefix of 5 of 24: each pixel 6000 · 5/24 = 1250 times, ± 3.5 standard
        // deviations (about 32).
        for (p, &n) in in_prefix.iter().enumerate() {
            assert!(
                (1135..=1365).contains(&n),
                "pixel {p}: {n} of 6000 prefixes"
            );
        }
    }

    #[test]
    fn estimate_reports_mean_standard_error_and_largest_share() {
        let mut estimate = NormalizationEstimate::new(2);
        // Totals 1, 2, 3, 6 (mean 3, sample variance 14/3).
        for values in [[0.5, 0.5], [2.0, 0.0], [1.0, 2.0], [4.0, 2.0]] {
            estimate.add(&values);
        }
        assert_eq!(estimate.b(), vec![7.5 / 4.0, 4.5 / 4.0]);
        let stats = estimate.stats();
        assert_eq!(stats.samples, 4);
        assert!((stats.value - 3.0).abs() < 1e-12);
        let expected = (14.0f64 / 3.0 / 4.0).sqrt() / 3.0;
        assert!((stats.relative_error - expected).abs() < 1e-12, "{stats:?}");
        assert!((stats.largest_share - 0.5).abs() < 1e-12);

        // Merging is adding the samples; a chain's large steps join a single group.
        let mut other = NormalizationEstimate::new(2);
        other.add(&[1.0, 1.0]);
        estimate.merge(&other);
        assert_eq!(estimate.total.count, 5);
        assert_eq!(estimate.b(), vec![8.5 / 5.0, 5.5 / 5.0]);
        let mut single = NormalizationEstimate::new(1);
        single.add(&[2.0]);
        let mut large_steps = Moments::default();
        large_steps.add(4.0);
        large_steps.add(0.0);
        single.merge_single_group(&large_steps);
        assert_eq!(single.b(), vec![2.0]);
        assert_eq!(single.stats().largest_share, 4.0 / 6.0);

        assert_eq!(
            NormalizationEstimate::new(2).stats(),
            NormalizationStats::default()
        );
    }
}
