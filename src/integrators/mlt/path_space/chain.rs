//! The path-space render: BDPT bootstrap for b, chains seeded from resampled bootstrap
//! paths, and rounds of mutations with expected-value deposits, run by the same driver as
//! the primary-sample-space chains (`pssmlt::run_rounds`).

use super::bidirectional::Bidirectional;
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

/// What the chains explore: paths of the scene through the camera, within a depth range.
pub(crate) struct PathSpaceTarget<'a> {
    pub bdpt: BdptAllStrategies<'a>,
    pub camera: CameraModel,
}

impl PathSpaceTarget<'_> {
    fn space(&self) -> PathSpace<'_> {
        PathSpace {
            scene: self.bdpt.0.scene,
            camera: &self.camera,
        }
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
    rays: u64,
    _target: PhantomData<&'a ()>,
}

impl<'a> MarkovChain for PathChain<'a> {
    type Target = PathSpaceTarget<'a>;

    #[inline]
    fn mutate(&mut self, target: &PathSpaceTarget<'a>, _: &CameraModel, deposits: &mut Vec<Splat>) {
        let space = target.space();
        self.proposal_sample.clear();
        let proposal = target.bidirectional().propose(
            &space,
            &self.current,
            &mut self.proposal,
            &mut self.eye,
            &mut self.rng,
            &mut self.rays,
        );
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
