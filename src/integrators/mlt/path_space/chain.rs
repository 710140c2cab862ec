//! The path-space render: BDPT bootstrap for b, chains seeded from resampled bootstrap
//! paths, and rounds of mutations with expected-value deposits, run by the same driver as
//! the primary-sample-space chains (`pssmlt::run_rounds`).

use super::bidirectional::Bidirectional;
use super::perturbation::{self, PerturbationSizes, RandomKernel};
use super::{PathSpace, PathVertex};
use crate::film::Film;
use crate::integrators::Splat;
use crate::integrators::mlt::acceptance;
use crate::integrators::mlt::pssmlt::{
    self, ChainPlan, MarkovChain, PathSample, PssmltOutcome, PssmltSettings, WeightedChain,
};
use crate::integrators::mlt::targets::BdptAllStrategies;
use crate::render::Control;
use crate::sampling::Rng;
use crate::scene::CameraModel;
use rayon::prelude::*;
use std::marker::PhantomData;

/// Stream offsets of the chains' random numbers and of their seed choices.
const CHAIN_STREAM: u64 = 0x5eed_9a7b_0000_0000;
const SEED_CHOICE_STREAM: u64 = 0x5eed_9a7c_0000_0000;

/// The mutations of a path-space chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mutation {
    Bidirectional = 0,
    Lens = 1,
    Caustic = 2,
    MultiChain = 3,
}

impl Mutation {
    pub const ALL: [Mutation; 4] = [
        Mutation::Bidirectional,
        Mutation::Lens,
        Mutation::Caustic,
        Mutation::MultiChain,
    ];
}

/// Relative probabilities of the mutations; each step picks among those the current path
/// admits (the bidirectional mutation always applies; exactly one of the lens and
/// multi-chain perturbations does; the caustic perturbation needs `… D S+ D E`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MutationWeights(pub [f32; 4]);

impl Default for MutationWeights {
    fn default() -> Self {
        MutationWeights([0.5, 0.25, 0.25, 0.25])
    }
}

/// Proposals and acceptances per mutation (indexed by `Mutation as usize`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MutationCounts {
    pub proposed: [u64; 4],
    pub accepted: [u64; 4],
}

/// What the chains explore: paths of the scene through the camera, within a depth range.
pub(crate) struct PathSpaceTarget<'a> {
    pub bdpt: BdptAllStrategies<'a>,
    pub camera: CameraModel,
    pub weights: MutationWeights,
    pub sizes: PerturbationSizes,
}

impl PathSpaceTarget<'_> {
    fn space(&self) -> PathSpace<'_> {
        PathSpace {
            scene: self.bdpt.0.scene,
            camera: &self.camera,
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

/// A chain's state: the current path and its contribution, and room for a proposal.
pub(crate) struct PathChain<'a> {
    rng: Rng,
    current: Vec<PathVertex>,
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
    fn mutate(&mut self, target: &PathSpaceTarget<'a>, _: &CameraModel, deposits: &mut Vec<Splat>) {
        let space = target.space();
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
                    let reverse = target.mutation_probabilities(&space, y)[0];
                    p.ratio *= reverse / probabilities[0];
                    p
                }),
            Mutation::Lens | Mutation::MultiChain => {
                let mut kernel = RandomKernel {
                    sizes: &target.sizes,
                    rng,
                };
                let multi_chain = mutation == Mutation::MultiChain;
                perturbation::lens(&space, &mut kernel, multi_chain, x, y, rays)
            }
            Mutation::Caustic => {
                let mut kernel = RandomKernel {
                    sizes: &target.sizes,
                    rng,
                };
                perturbation::caustic(&space, &mut kernel, x, y, rays)
            }
        };
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
            pssmlt::deposit(deposits, &self.proposal_sample, a, 0.0);
        }
        if a < 1.0 {
            pssmlt::deposit(deposits, &self.current_sample, 1.0 - a, 0.0);
        }
        if self.rng.uniform() < a {
            std::mem::swap(&mut self.current, &mut self.proposal);
            std::mem::swap(&mut self.current_sample, &mut self.proposal_sample);
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

/// Runs path-space MLT; see `pssmlt::run` for `after_round`.
pub(crate) fn run(
    target: &PathSpaceTarget,
    settings: &PssmltSettings,
    film: &mut Film,
    control: &Control,
    after_round: &mut dyn FnMut(&mut Film, f64),
) -> PssmltOutcome {
    let camera = &target.camera;
    // 1. Bootstrap with BDPT, all strategies summed: b = ∫ f.
    let n = settings.bootstrap_samples as u64;
    let boot = pssmlt::bootstrap(&target.bdpt, camera, settings, control);
    let b = boot.sums[0] / boot.samples as f64;
    if b <= 0.0 || !b.is_finite() {
        return pssmlt::finish_without_light(camera, settings, film, control, after_round);
    }

    // 2. Chains seeded from bootstrap paths resampled in proportion to their contribution.
    let plan = ChainPlan::new(&[b], camera, settings);
    let seeds = pssmlt::resample_seeds(&boot, &plan.chains_per_group, settings.seed);
    drop(boot);
    let max_vertices = target.bdpt.0.max_depth as usize + 2;
    let space = target.space();
    let mut chains: Vec<WeightedChain<PathChain>> = seeds
        .into_par_iter()
        .enumerate()
        .map(|(c, (_, index))| {
            let mut sampler = pssmlt::new_sampler(&target.bdpt, settings);
            pssmlt::restart_as_bootstrap(&mut sampler, settings, camera, index, n);
            let mut scratch =
                crate::integrators::mlt::pssmlt::PrimarySpaceTarget::scratch(&target.bdpt);
            let mut choice = Rng::new(settings.seed, SEED_CHOICE_STREAM + c as u64);
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
            if let Some((value, pixel)) =
                seeded.and_then(|s| space.unweighted_contribution(&current, s, true))
            {
                current_sample.push(pixel, value);
            }
            let chain = PathChain {
                rng: Rng::new(settings.seed, CHAIN_STREAM + c as u64),
                current,
                current_sample,
                proposal: Vec::with_capacity(max_vertices),
                proposal_sample: PathSample::with_capacity(1),
                eye: Vec::with_capacity(max_vertices),
                accepted: 0,
                counts: MutationCounts::default(),
                rays,
                _target: PhantomData,
            };
            WeightedChain::new(chain, b / plan.chain_count as f64)
        })
        .collect();

    // 3. Rounds of mutations.
    let mut outcome = pssmlt::run_rounds(
        target,
        camera,
        &mut chains,
        &plan,
        film,
        control,
        after_round,
    );
    outcome.normalization = b;
    outcome
}
