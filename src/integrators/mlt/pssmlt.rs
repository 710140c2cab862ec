//! Kelemen et al.'s (2002) chains over primary sample space: small steps and large steps,
//! each deposit weighted by the balance heuristic between the chain, its large steps and (for
//! MMLT) the normalization pass's samples, over any `PrimarySpaceTarget`. The driver
//! (`driver`) bootstraps, seeds and runs them.

use super::acceptance;
use super::direct_pass::DirectPass;
use super::driver::{
    ChainPlan, ChainStart, Deposits, MarkovChain, MetropolisOutcome, WeightedChain, deposit,
    finish_without_light, restart_as_bootstrap, run_rounds, tally,
};
use super::normalization::{
    Moments, NormalizationEstimate, NormalizationPass, PassImage, PointWeight,
};
use super::primary_space::{MetropolisSettings, PathSample, PrimarySpaceTarget, new_sampler};
use super::pss::PssSampler;
use crate::control::Control;
use crate::film::Film;
use crate::sampling::Rng;
use crate::scene::CameraModel;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// Stream offsets that keep the chains' own random numbers apart from the bootstrap's.
/// Stream offsets that keep the chains' own random numbers apart from the bootstrap's.
const CHAIN_STREAM: u64 = 0x5eed_c4a1_0000_0000;

const SEED_CHOICE_STREAM: u64 = 0x5eed_c401_0000_0000;

struct Chain<T: PrimarySpaceTarget> {
    group: usize,
    sampler: PssSampler,
    scratch: T::Scratch,
    current: PathSample,
    proposal: PathSample,
    /// (p_large + r_g) × b_g (the bootstrap's), added to f in the deposits' denominators
    /// (see `mutate`); r_g is the normalization pass's rate when its samples join the image
    /// (`PassImage`), else 0.
    mis_offset: f32,
    max_entries: usize,
    accepted: u64,
    rays: u64,
    large_steps: Moments,
    large_step_rays: u64,
}

impl<T: PrimarySpaceTarget> MarkovChain for Chain<T>
where
    T::Scratch: Send,
{
    type Target = T;

    #[inline]
    fn mutate(&mut self, target: &T, camera: &CameraModel, deposits: &mut Deposits) {
        mutate(target, camera, self, deposits);
    }

    fn accepted(&self) -> u64 {
        self.accepted
    }

    fn rays(&self) -> u64 {
        self.rays
    }

    fn max_deposits(&self) -> usize {
        3 * self.max_entries
    }

    fn large_steps(&self) -> Moments {
        self.large_steps
    }

    fn large_step_rays(&self) -> u64 {
        self.large_step_rays
    }
}

/// Independent states per group whose rays estimate what a mutation costs.
const CALIBRATION_STATES: u64 = 256;

const CALIBRATION_STREAM: u64 = 0x5eed_ca1b_0000_0000;

/// The offsets of the deposits' denominators per group (`mutate`), and how the
/// normalization pass's samples join the image (`PassImage`), if it draws any: its samples
/// per mutation are set so that, with the pooled large steps, its rays make the work
/// fraction of all rays, from the rays a bootstrap sample traced and the rays of a few
/// hundred independent states of each group's chains (a mutation's cost; large and small
/// steps trace paths alike).
#[allow(clippy::too_many_arguments)]
fn plan_pass_image<T: PrimarySpaceTarget>(
    target: &T,
    camera: &CameraModel,
    settings: &MetropolisSettings,
    boot: &ChainStart,
    plan: &ChainPlan,
    pass: &NormalizationPass<T>,
    control: &Control,
) -> (Vec<f32>, Option<PassImage>)
where
    T::Scratch: Send,
{
    let b = boot.estimate.b();
    let p_large = settings.large_step_probability as f64;
    let large_steps_only = || b.iter().map(|&b| (p_large * b) as f32).collect();
    let f = settings.normalization_work_fraction as f64;
    let pooled = if pass.pools_large_steps() {
        p_large
    } else {
        0.0
    };
    let bootstrap_samples = boot.estimate.total.count;
    if !target.pass_joins_the_image() || f <= pooled || bootstrap_samples == 0 || boot.rays == 0 {
        return (large_steps_only(), None);
    }
    let mut sampler = new_sampler(target, settings);
    let mut scratch = target.scratch();
    let mut state = PathSample::with_capacity(target.max_entries());
    let mut chain_rays = 0.0;
    for (group, &chains) in plan.chains_per_group.iter().enumerate() {
        if chains == 0 {
            continue;
        }
        let mut rays = 0;
        for i in 0..CALIBRATION_STATES {
            sampler.restart(settings.seed, CALIBRATION_STREAM + i);
            state.clear();
            target.evaluate(
                camera,
                &mut sampler,
                &mut scratch,
                group,
                &mut state,
                &mut rays,
            );
        }
        control.rays.fetch_add(rays, Ordering::Relaxed);
        chain_rays += chains as f64 * rays as f64 / CALIBRATION_STATES as f64;
    }
    let rays_per_mutation = chain_rays / plan.chain_count as f64;
    let rays_per_sample = boot.rays as f64 / bootstrap_samples as f64;
    // P + L = f (C + P) with L = pooled · C: P / C = (f − pooled) / (1 − f).
    let samples_per_mutation = (f - pooled) / (1.0 - f) * rays_per_mutation / rays_per_sample;
    if samples_per_mutation <= 0.0 || !samples_per_mutation.is_finite() {
        return (large_steps_only(), None);
    }
    let points: Vec<u32> = (0..b.len()).map(|g| target.points_per_sample(g)).collect();
    let (offsets, weights) = balance_weights(
        &b,
        &plan.chains_per_group,
        &points,
        p_large,
        samples_per_mutation,
    );
    let image = PassImage {
        weights,
        samples_per_mutation,
        chains: plan.chain_count,
        layer: b.len(),
    };
    (offsets, Some(image))
}

/// The balance heuristic over a group's three techniques (`PassImage`): per group, the
/// offset of every deposit's denominator, (p_large + r_g)·b_g, and the weight of a pass
/// point, r_g·b_g / points_g over the same denominator, where the pass puts r_g points per
/// mutation of the group in its space. A group without chains is the pass's alone.
fn balance_weights(
    b: &[f64],
    chains_per_group: &[u64],
    points_per_sample: &[u32],
    p_large: f64,
    samples_per_mutation: f64,
) -> (Vec<f32>, Vec<PointWeight>) {
    let chain_count: u64 = chains_per_group.iter().sum();
    let mut offsets = Vec::with_capacity(b.len());
    let weights = (0..b.len())
        .map(|g| {
            let points = points_per_sample[g] as f64;
            let chains = chains_per_group[g];
            if chains == 0 {
                offsets.push(0.0);
                return PointWeight::Alone {
                    weight: (1.0 / points) as f32,
                };
            }
            let rate = samples_per_mutation * points * chain_count as f64 / chains as f64;
            let offset = ((p_large + rate) * b[g]) as f32;
            offsets.push(offset);
            PointWeight::Combined {
                numerator: (rate * b[g] / points) as f32,
                offset,
            }
        })
        .collect();
    (offsets, weights)
}

/// Runs the chains, and the direct pass alongside them if the render has one.
pub(crate) fn run<T: PrimarySpaceTarget>(
    target: &T,
    camera: &CameraModel,
    settings: &MetropolisSettings,
    start: Option<&ChainStart>,
    film: &mut Film,
    control: &Control,
    direct: Option<&mut DirectPass>,
) -> MetropolisOutcome
where
    T::Scratch: Send,
{
    // A target without groups (multiplexed MLT whose depths are all the direct pass's, as
    // with max_depth 1) has no paths for chains: the image is the other passes' alone.
    if target.groups() == 0 {
        let nothing = NormalizationEstimate::new(0);
        return finish_without_light(camera, settings, &nothing, film, control, direct);
    }
    // 1. Bootstrap (or its result, made by a split render's plan).
    let n = settings.bootstrap_samples as u64;
    let boot = match start {
        Some(start) => start.clone(),
        None => ChainStart::new(target, camera, settings, false, control),
    };
    let b = boot.estimate.b();
    let normalization: f64 = b.iter().sum();
    if normalization <= 0.0 || !normalization.is_finite() {
        return finish_without_light(camera, settings, &boot.estimate, film, control, direct);
    }

    // 2. Chains, allotted to groups and seeded from resampled bootstrap samples; a job of
    // a split render makes its share of them.
    let plan = ChainPlan::new(&b, camera, settings);
    let seeds: Vec<(u64, (usize, u64))> = boot
        .seeds
        .iter()
        .copied()
        .enumerate()
        .map(|(c, seed)| (c as u64, seed))
        .filter(|&(c, _)| settings.share.owns(c))
        .collect();
    let owned: Vec<u64> = seeds.iter().map(|&(c, _)| c).collect();
    let pass = NormalizationPass::new(
        target,
        camera,
        settings,
        boot.estimate.clone(),
        &owned,
        plan.chain_count,
    );
    let (offsets, pass_image) =
        plan_pass_image(target, camera, settings, &boot, &plan, &pass, control);
    let mut pass = pass.with_image(pass_image);
    let mut chains: Vec<WeightedChain<Chain<T>>> = seeds
        .into_par_iter()
        .map(|(c, (group, index))| {
            let mut sampler = new_sampler(target, settings);
            restart_as_bootstrap(&mut sampler, settings, camera, index, n);
            let mut scratch = target.scratch();
            let mut current = PathSample::with_capacity(target.max_entries());
            let mut choice = Rng::new(settings.seed, SEED_CHOICE_STREAM + c);
            let mut rays = 0;
            target.seed(
                camera,
                &mut sampler,
                &mut scratch,
                group,
                choice.uniform(),
                &mut current,
                &mut rays,
            );
            // Chains seeded from the same sample must still move independently.
            sampler.reseed(settings.seed, CHAIN_STREAM + c);
            let chain = Chain {
                group,
                sampler,
                scratch,
                current,
                proposal: PathSample::with_capacity(target.max_entries()),
                mis_offset: offsets[group],
                max_entries: target.max_entries(),
                accepted: 0,
                rays,
                large_steps: Moments::default(),
                large_step_rays: 0,
            };
            WeightedChain::new(chain, c, group, plan.chains_per_group[group], b[group])
        })
        .collect();

    // 3. Rounds of mutations, the normalization estimated alongside; 4. what the image is
    // scaled by, finished once every chain is in.
    let (mut outcome, made) = run_rounds(
        target,
        camera,
        &mut chains,
        &plan,
        0,
        &mut pass,
        film,
        control,
        direct,
    );
    outcome.tally = Some(tally(film, pass, &chains, &plan, settings, made));
    outcome
}

#[inline]
fn mutate<T: PrimarySpaceTarget>(
    target: &T,
    camera: &CameraModel,
    chain: &mut Chain<T>,
    deposits: &mut Deposits,
) {
    chain.sampler.start_iteration();
    chain.proposal.clear();
    let rays_before = chain.rays;
    target.evaluate(
        camera,
        &mut chain.sampler,
        &mut chain.scratch,
        chain.group,
        &mut chain.proposal,
        &mut chain.rays,
    );
    let a = acceptance(chain.current.target, chain.proposal.target, 1.0);
    // Kelemen et al.'s combination: the expected-value deposits have density f/b, and a
    // large step is also an independent uniform sample (density p_large) deposited once
    // more. Weighting every deposit by 1/(f/b + p_large), the balance heuristic over the
    // two, lets the large steps carry the dim parts of the image, which the chain visits
    // rarely. The weights stay a partition of unity with any constant c in place of b:
    // 1/(f + p_large·c) on every deposit, the chain's scaled by b (its final estimate) and
    // the large steps' by c. So c is the bootstrap's b, fixed before the chains start, and
    // only the chain's deposits wait for the final b. The normalization pass's samples,
    // when they join the image, are a third technique of the same kind (`PassImage`).
    let mis = chain.mis_offset;
    if chain.sampler.is_large_step() {
        chain.large_steps.add(chain.proposal.target as f64);
        chain.large_step_rays += chain.rays - rays_before;
        deposit(&mut deposits.independent, &chain.proposal, 1.0, mis);
    }
    if a > 0.0 {
        deposit(&mut deposits.chain, &chain.proposal, a, mis);
    }
    if a < 1.0 && chain.current.target > 0.0 {
        deposit(&mut deposits.chain, &chain.current, 1.0 - a, mis);
    }
    if chain.sampler.decision() < a {
        std::mem::swap(&mut chain.current, &mut chain.proposal);
        chain.sampler.accept();
        chain.accepted += 1;
    } else {
        chain.sampler.reject();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At every target value, a state's weights as a chain deposit (f), a large step
    /// (p_large·b) and the pass's points of its sample (points × the point weight) sum to
    /// the denominator: the three techniques' weights are a partition of unity.
    #[test]
    fn pass_chain_and_large_step_weights_sum_to_one() {
        let b = [0.5, 0.02, 0.0, 0.3];
        let chains = [600, 24, 0, 400];
        let points = [4, 5, 6, 7];
        let (p_large, samples_per_mutation) = (0.3, 0.04);
        let (offsets, weights) =
            balance_weights(&b, &chains, &points, p_large, samples_per_mutation);
        for g in [0, 1, 3] {
            for f in [0.0f32, 1e-4, 0.01, 0.3, 2.0, 50.0] {
                let chain = f / (f + offsets[g]);
                let large_step = (p_large * b[g]) as f32 / (f + offsets[g]);
                let pass = points[g] as f32 * weights[g].of(f);
                let sum = chain + large_step + pass;
                assert!((sum - 1.0).abs() < 1e-5, "group {g}, f {f}: {sum}");
            }
        }
        // The pass's points per mutation of a group: samples per mutation × points per
        // sample × chains per chain of the group; a group without chains is the pass's.
        let rate = 0.04 * 4.0 * 1024.0 / 600.0;
        assert!((offsets[0] - ((0.3 + rate) * 0.5) as f32).abs() < 1e-6);
        assert_eq!(points[2] as f32 * weights[2].of(1.0), 1.0);
    }
}
