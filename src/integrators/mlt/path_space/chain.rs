//! The path-space render: BDPT bootstrap for b, chains seeded from resampled bootstrap
//! paths, and rounds of mutations with expected-value deposits, run by the same driver as
//! the primary-sample-space chains (`driver::run_rounds`).

use super::bidirectional::Bidirectional;
use super::perturbation::{self, PerturbationSizes, RandomKernel};
use super::{PathSpace, PathVertex};
use crate::control::Control;
use crate::film::Film;
use crate::integrators::bdpt::Bdpt;
use crate::integrators::mlt::acceptance;
use crate::integrators::mlt::direct_pass::DirectPass;
use crate::integrators::mlt::driver::{
    self, ChainPlan, ChainStart, Deposits, MarkovChain, MetropolisOutcome, Mutation,
    MutationCounts, MutationWeights, WeightedChain,
};
use crate::integrators::mlt::normalization::NormalizationPass;
use crate::integrators::mlt::primary_space::{self, MetropolisSettings, PathSample};
use crate::integrators::mlt::targets::BdptAllStrategies;
use crate::sampling::Rng;
use crate::scene::CameraModel;
use crate::spectral::Channels;
use rayon::prelude::*;
use std::marker::PhantomData;

/// Stream offsets of the chains' random numbers and of their seed choices.
const CHAIN_STREAM: u64 = 0x5eed_9a7b_0000_0000;
const SEED_CHOICE_STREAM: u64 = 0x5eed_9a7c_0000_0000;

/// What the chains explore: paths of the scene through the camera, within a depth range.
pub(crate) struct PathSpaceTarget<'a> {
    pub bdpt: BdptAllStrategies<'a>,
    pub camera: CameraModel,
    pub weights: MutationWeights,
    pub sizes: PerturbationSizes,
    /// Perturb directions in the BSDF's sample space (`perturbation` module docs).
    pub perturb_in_sample_space: bool,
}

impl PathSpaceTarget<'_> {
    /// The space of a state that carries `channels`.
    fn space(&self, channels: Channels) -> PathSpace<'_> {
        PathSpace {
            scene: self.bdpt.0.scene,
            camera: &self.camera,
            channels,
        }
    }

    /// The probability of each mutation at path `x`.
    fn mutation_probabilities(&self, space: &PathSpace, x: &[PathVertex]) -> [f32; 4] {
        let admits = perturbation::applicable(space, x);
        let [b, l, c, m] = self.weights.0;
        let w = [
            b,
            if admits.lens { l } else { 0.0 },
            if admits.caustic { c } else { 0.0 },
            if admits.lens { 0.0 } else { m },
        ];
        let total: f32 = w.iter().sum();
        w.map(|x| if total > 0.0 { x / total } else { 0.0 })
    }

    fn bidirectional(&self) -> Bidirectional {
        Bidirectional {
            min_vertices: self.bdpt.0.min_depth as usize + 2,
            max_vertices: self.bdpt.0.max_depth as usize + 2,
        }
    }
}

/// A chain's state: the current path, its wavelengths and its contribution, and room for a
/// proposal.
pub(crate) struct PathChain<'a> {
    rng: Rng,
    current: Vec<PathVertex>,
    current_channels: Channels,
    current_sample: PathSample,
    proposal: Vec<PathVertex>,
    proposal_sample: PathSample,
    eye: Vec<PathVertex>,
    accepted: u64,
    counts: MutationCounts,
    rays: u64,
    _target: PhantomData<&'a ()>,
}

impl<'a> MarkovChain for PathChain<'a> {
    type Target = PathSpaceTarget<'a>;

    #[inline]
    fn mutate(&mut self, target: &PathSpaceTarget<'a>, _: &CameraModel, deposits: &mut Deposits) {
        let space = target.space(self.current_channels);
        self.proposal_sample.clear();
        // Pick a mutation among those the current path admits.
        let probabilities = if self.current.len() >= 2 {
            target.mutation_probabilities(&space, &self.current)
        } else {
            [1.0, 0.0, 0.0, 0.0]
        };
        let mut u = self.rng.uniform();
        let mutation = Mutation::ALL
            .into_iter()
            .find(|&m| {
                u -= probabilities[m as usize];
                u < 0.0 && probabilities[m as usize] > 0.0
            })
            .unwrap_or(Mutation::Bidirectional);
        self.counts.proposed[mutation as usize] += 1;
        let (rng, rays) = (&mut self.rng, &mut self.rays);
        let (x, y) = (&self.current, &mut self.proposal);
        let proposal = match mutation {
            Mutation::Bidirectional => target
                .bidirectional()
                .propose(&space, x, y, &mut self.eye, rng, rays)
                .map(|mut p| {
                    // The bidirectional mutation may change which perturbations apply, and
                    // with them its own probability of being picked.
                    let space_y = target.space(p.channels);
                    let reverse = target.mutation_probabilities(&space_y, y)[0];
                    p.ratio *= reverse / probabilities[0];
                    p
                }),
            Mutation::Lens | Mutation::MultiChain => {
                let mut kernel = RandomKernel {
                    sizes: &target.sizes,
                    in_sample_space: target.perturb_in_sample_space,
                    rng,
                };
                let multi_chain = mutation == Mutation::MultiChain;
                perturbation::lens(&space, &mut kernel, multi_chain, x, y, rays)
            }
            Mutation::Caustic => {
                let mut kernel = RandomKernel {
                    sizes: &target.sizes,
                    in_sample_space: target.perturb_in_sample_space,
                    rng,
                };
                perturbation::caustic(&space, &mut kernel, x, y, rays)
            }
        };
        let proposal_channels = proposal.as_ref().map(|p| p.channels);
        let a = match proposal {
            Some(proposal) => {
                self.proposal_sample.push(proposal.pixel, proposal.value);
                if self.proposal_sample.target <= 0.0 {
                    0.0
                } else if self.current_sample.target <= 0.0 {
                    // A chain whose seed had no contribution leaves it at once.
                    1.0
                } else {
                    acceptance(1.0, 1.0, proposal.ratio)
                }
            }
            None => 0.0,
        };
        // Expected-value deposits: each carries f⃗/f, so a state counts once per visit.
        if a > 0.0 {
            driver::deposit(&mut deposits.chain, &self.proposal_sample, a, 0.0);
        }
        if a < 1.0 {
            driver::deposit(&mut deposits.chain, &self.current_sample, 1.0 - a, 0.0);
        }
        if self.rng.uniform() < a {
            std::mem::swap(&mut self.current, &mut self.proposal);
            std::mem::swap(&mut self.current_sample, &mut self.proposal_sample);
            if let Some(channels) = proposal_channels {
                self.current_channels = channels;
            }
            self.accepted += 1;
            self.counts.accepted[mutation as usize] += 1;
        }
    }

    fn accepted(&self) -> u64 {
        self.accepted
    }

    fn rays(&self) -> u64 {
        self.rays
    }

    fn max_deposits(&self) -> usize {
        2
    }

    fn mutation_counts(&self) -> MutationCounts {
        self.counts
    }
}

/// Runs path-space MLT, and the direct pass alongside it if the render has one. With
/// `adapt_weights`, the mutation weights are adapted after a warm-up (see
/// `adapted_weights`).
pub(crate) fn run(
    target: &PathSpaceTarget,
    settings: &MetropolisSettings,
    start: Option<&ChainStart>,
    adapt_weights: bool,
    film: &mut Film,
    control: &Control,
    mut direct: Option<&mut DirectPass>,
) -> MetropolisOutcome {
    let camera = &target.camera;
    // 1. Bootstrap with BDPT, all strategies summed: b = ∫ f.
    let n = settings.bootstrap_samples as u64;
    let boot = match start {
        Some(start) => start.clone(),
        None => ChainStart::new(&target.bdpt, camera, settings, adapt_weights, control),
    };
    let b = boot.estimate.b()[0];
    if b <= 0.0 || !b.is_finite() {
        let mut outcome =
            driver::finish_without_light(camera, settings, &boot.estimate, film, control, direct);
        outcome.mutation_weights = target.weights;
        return outcome;
    }

    // 2. Chains seeded from bootstrap paths resampled in proportion to their contribution;
    // the normalization goes on being estimated with more BDPT samples alongside them.
    let plan = ChainPlan::new(&[b], camera, settings);
    // A job of a split render makes its share of the chains.
    let share = settings.share;
    let (owned, others): (Vec<u64>, Vec<u64>) = (0..plan.chain_count).partition(|&c| share.owns(c));
    let mut pass = NormalizationPass::new(
        &target.bdpt,
        camera,
        settings,
        boot.estimate.clone(),
        &owned,
        plan.chain_count,
    );
    let seed_chains = |seeds: &[(usize, u64)], first_stream: u64, which: &[u64]| {
        which
            .par_iter()
            .map(|&c| {
                let (_, index) = seeds[c as usize];
                let chain = seed_chain(target, settings, index, n, first_stream + c);
                WeightedChain::new(chain, c, 0, plan.chain_count, b)
            })
            .collect::<Vec<WeightedChain<PathChain>>>()
    };

    // 3. Rounds of mutations: all with the given weights, or a warm-up with them and the
    // rest with the adapted ones.
    let warmup = plan.first_round();
    let adapting = adapt_weights && plan.mutations_per_chain > warmup;
    let first_phase = if adapting {
        warmup
    } else {
        plan.mutations_per_chain
    };
    let mut chains = seed_chains(&boot.seeds, 0, &owned);
    // The second phase seeds its chains from the bootstrap too; otherwise free it now.
    let boot = adapting.then_some(boot);
    let (mut outcome, made) = driver::run_rounds(
        target,
        camera,
        &mut chains,
        &plan.phase(first_phase),
        0,
        &mut pass,
        film,
        control,
        direct.as_deref_mut(),
    );
    outcome.mutation_weights = target.weights;
    let Some(boot) = boot.filter(|_| !control.should_stop()) else {
        outcome.tally = Some(driver::tally(film, pass, &chains, &plan, settings, made));
        return outcome;
    };
    // The weights adapt to the warm-up of every chain of the render, so a job also runs
    // the warm-up of the chains it does not own (one round, about a mutation per pixel),
    // apart: on a film of its own, uncounted, and without the normalization pass.
    let mut others_counts = MutationCounts::default();
    if !others.is_empty() {
        let no_pass = MetropolisSettings {
            normalization_work_fraction: 0.0,
            ..*settings
        };
        let mut others_chains = seed_chains(&boot.seeds, 0, &others);
        let mut others_pass = NormalizationPass::new(
            &target.bdpt,
            camera,
            &no_pass,
            boot.estimate.clone(),
            &others,
            plan.chain_count,
        );
        let mut scratch_film = film.empty_like();
        driver::run_rounds(
            target,
            camera,
            &mut others_chains,
            &plan.phase(first_phase),
            0,
            &mut others_pass,
            &mut scratch_film,
            &Control::new(None, true),
            None,
        );
        for chain in &others_chains {
            others_counts.add(&chain.chain.counts);
        }
    }
    let mut counts = others_counts;
    for chain in &chains {
        counts.add(&chain.chain.counts);
    }
    let adapted = PathSpaceTarget {
        bdpt: BdptAllStrategies(Bdpt {
            scene: target.bdpt.0.scene,
            max_depth: target.bdpt.0.max_depth,
            min_depth: target.bdpt.0.min_depth,
            spectral: target.bdpt.0.spectral,
        }),
        camera: target.camera,
        weights: adapted_weights(target.weights, &counts),
        sizes: target.sizes,
        perturb_in_sample_space: target.perturb_in_sample_space,
    };
    outcome.mutation_weights = adapted.weights;
    // Fresh chains, seeded independently of the warm-up (see `adapted_weights`).
    let rays: Vec<u64> = chains.iter().map(|c| c.chain.rays()).collect();
    pass.start_phase(&rays, &vec![0; rays.len()]);
    let mut chains = seed_chains(&boot.adapted_seeds, plan.chain_count, &owned);
    drop(boot);
    let (rest, made) = driver::run_rounds(
        &adapted,
        camera,
        &mut chains,
        &plan.phase(plan.mutations_per_chain - warmup),
        warmup,
        &mut pass,
        film,
        control,
        direct,
    );
    outcome.mutations += rest.mutations;
    outcome.accepted += rest.accepted;
    outcome.mutation_counts.add(&rest.mutation_counts);
    outcome.cut_short = rest.cut_short;
    outcome.tally = Some(driver::tally(film, pass, &chains, &plan, settings, made));
    outcome
}

/// Mutation weights adapted to the acceptance counted over a warm-up: each weight times its
/// mutation's acceptance rate, within a factor of `MAX_ADAPTATION` of the given weight (a
/// mutation never proposed keeps its weight times the overall rate).
///
/// Why the chains stay valid: a chain whose kernel changes with its own history is no longer
/// a Markov chain, and f need not be its stationary density. Here every chain runs with one
/// fixed mixture of mutations: the warm-up chains with the given weights, then new chains
/// with the adapted weights, frozen for the rest of the render and seeded from the bootstrap
/// anew, not from the warm-up chains' states (whose distribution, given the counts that set
/// the weights, is no longer f). Each mixture of mutations that all satisfy detailed balance
/// with respect to f does too, whatever its weights, and both phases' deposits count with
/// the same weight per mutation. The bidirectional mutation keeps a positive weight, so the
/// adapted chains stay ergodic.
pub(crate) fn adapted_weights(
    weights: MutationWeights,
    counts: &MutationCounts,
) -> MutationWeights {
    let proposed: u64 = counts.proposed.iter().sum();
    let accepted: u64 = counts.accepted.iter().sum();
    if proposed == 0 {
        return weights;
    }
    let overall = accepted as f32 / proposed as f32;
    let mut adapted = weights.0;
    for (m, w) in adapted.iter_mut().enumerate() {
        let rate = if counts.proposed[m] > 0 {
            counts.accepted[m] as f32 / counts.proposed[m] as f32
        } else {
            overall
        };
        let factor =
            (rate / overall.max(f32::MIN_POSITIVE)).clamp(1.0 / MAX_ADAPTATION, MAX_ADAPTATION);
        *w *= factor;
    }
    MutationWeights(adapted)
}

/// How far adaptation may move a weight (a factor either way).
const MAX_ADAPTATION: f32 = 8.0;

/// A chain seeded from bootstrap sample `index` (of `bootstrap_samples`), moving with random
/// stream `stream`.
fn seed_chain<'a>(
    target: &PathSpaceTarget<'a>,
    settings: &MetropolisSettings,
    index: u64,
    bootstrap_samples: u64,
    stream: u64,
) -> PathChain<'a> {
    let camera = &target.camera;
    let max_vertices = target.bdpt.0.max_depth as usize + 2;
    let mut sampler = primary_space::new_sampler(&target.bdpt, settings);
    driver::restart_as_bootstrap(&mut sampler, settings, camera, index, bootstrap_samples);
    let mut scratch = primary_space::PrimarySpaceTarget::scratch(&target.bdpt);
    let mut choice = Rng::new(settings.seed, SEED_CHOICE_STREAM + stream);
    let mut current = Vec::with_capacity(max_vertices);
    let mut current_sample = PathSample::with_capacity(1);
    let mut rays = 0;
    let seeded = target.bdpt.seed_path(
        camera,
        &mut sampler,
        &mut scratch,
        choice.uniform(),
        &mut current,
        &mut rays,
    );
    // The state carries the wavelengths the bootstrap sample drew.
    let channels = scratch.drawn_channels();
    if let Some((value, pixel)) = seeded.and_then(|s| {
        target
            .space(channels)
            .unweighted_contribution(&current, s, true)
    }) {
        current_sample.push(pixel, value);
    }
    PathChain {
        rng: Rng::new(settings.seed, CHAIN_STREAM + stream),
        current,
        current_channels: channels,
        current_sample,
        proposal: Vec::with_capacity(max_vertices),
        proposal_sample: PathSample::with_capacity(1),
        eye: Vec::with_capacity(max_vertices),
        accepted: 0,
        counts: MutationCounts::default(),
        rays,
        _target: PhantomData,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each weight follows its mutation's acceptance rate relative to the overall rate,
    /// within a factor of `MAX_ADAPTATION`; a mutation never proposed keeps its weight.
    #[test]
    fn adapted_weights_follow_the_acceptance_rates() {
        let counts = MutationCounts {
            proposed: [1000, 1000, 0, 1000],
            accepted: [100, 800, 0, 0],
        };
        let overall = 900.0 / 3000.0;
        let adapted = adapted_weights(MutationWeights([0.5, 0.25, 0.25, 0.25]), &counts);
        let expected = [
            0.5 * 0.1 / overall,
            0.25 * 0.8 / overall,
            0.25,
            0.25 / MAX_ADAPTATION,
        ];
        for (got, want) in adapted.0.iter().zip(expected) {
            assert!((got - want).abs() < 1e-6, "{:?} vs {expected:?}", adapted.0);
        }
        assert!(
            adapted.0[0] > 0.0,
            "the bidirectional mutation keeps a weight"
        );
        let none = MutationCounts::default();
        assert_eq!(
            adapted_weights(MutationWeights::default(), &none),
            MutationWeights::default()
        );
    }
}
