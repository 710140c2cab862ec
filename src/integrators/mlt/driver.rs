//! The driver every Metropolis render runs its chains under: PSSMLT over the path tracer,
//! PSSMLT over BDPT and multiplexed MLT (Hachisuka et al. 2014), whose chains are Kelemen's
//! (`pssmlt`), and path-space MLT, whose chains are Veach's (`path_space`); and the statistics
//! of a render's chains.
//!
//! 1. Bootstrap: N samples, stratified over the film, estimate b_g = ∫ f for every chain group
//!    g (MMLT: one group per path depth, each estimated with all of BDPT's strategies; the
//!    others: a single group). They run in passes that each cover the whole film, so a stop
//!    (time limit, cancel) after any pass still leaves an unbiased b.
//! 2. Chains are allotted to the groups in proportion to b_g (largest remainder, at least one
//!    per group with light) and start from bootstrap samples resampled in proportion to their
//!    value (systematic resampling), which removes start-up bias up to the resampling's own
//!    accuracy. Every chain makes the same number of mutations.
//! 3. Each mutation deposits the proposal with weight a and the current state with 1 − a
//!    (expected-value splatting). A large step's proposal is also an independent sample and
//!    is deposited once more; every deposit is f⃗ / (f + p_large·c_g), the balance heuristic
//!    between the chain (density f/b_g) and the large steps (density p_large), with c_g the
//!    bootstrap's b_g. In bright regions this is the usual f⃗ / f; dim regions, which chains
//!    rarely visit, are carried by the large steps as a path tracer would.
//! 4. The normalization goes on being estimated while the chains run (`normalization`): a
//!    pass of independent samples alongside them and, where they sample the same function,
//!    the chains' large steps. After the last round, group g's chain deposits are scaled by
//!    the final b_g / (its chains × mutations per chain), so each group's expected
//!    luminance is b_g, and its large-step deposits by c_g / (the same), which makes the
//!    combination exact for any c_g. The image's brightness error is the final b_g's
//!    error, which shrinks with the work done, plus the chains' own noise; a single group
//!    normalized by the chains' own visits (pbrt-v3's design) adds the random allotment of
//!    chains to depths on top.
//!
//! Determinism: each chain's random numbers derive from (seed, chain index). Chains run in
//! rounds; within a round they run in parallel, each recording its deposits, which are added
//! to the film in chain order after the round.

use super::direct_pass::DirectPass;
use super::normalization::{Moments, NormalizationEstimate, NormalizationPass, NormalizationStats};
use super::primary_space::{MetropolisSettings, PathSample, PrimarySpaceTarget, new_sampler};
use super::pss::PssSampler;
use crate::control::Control;
use crate::film::{Film, Splat};
use crate::sampling::Rng;
use crate::scene::CameraModel;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// Deposits recorded per round over all chains: bounds the round's memory (16 bytes each)
/// and how long a stop takes (about 0.03 s of one core for PSSMLT on cornell-box). Fixed,
/// not scaled with the thread count, because the round boundaries set the order in which
/// deposits reach the film and so the image's last bits.
const DEPOSITS_PER_ROUND: u64 = 1 << 16;

/// Bootstrap samples evaluated by one parallel work unit with one sampler.
const BOOTSTRAP_CHUNK: u64 = 1024;

/// Fewest bootstrap samples of a pass (see `bootstrap_pass_size`).
const MIN_BOOTSTRAP_PASS: u64 = 1 << 16;

/// Most per-sample, per-group values the bootstrap keeps for resampling chain seeds; the
/// normalization always uses every bootstrap sample.
const BOOTSTRAP_KEPT_VALUES: u64 = 1 << 23;

/// Stream offset of the resampling of chain seeds, apart from the bootstrap's numbers.
const RESAMPLING_STREAM: u64 = 0x5eed_5e1e_0000_0000;

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

impl MutationCounts {
    pub fn add(&mut self, other: &MutationCounts) {
        for m in 0..4 {
            self.proposed[m] += other.proposed[m];
            self.accepted[m] += other.accepted[m];
        }
    }
}

/// What a Metropolis render measured.
#[derive(Clone, Debug, Default)]
pub struct MetropolisOutcome {
    /// What the normalization is made of, to be finished (`finish`) once every chain is in:
    /// at the end of the render, or at the merge of a split render's jobs.
    pub(crate) tally: Option<ChainTally>,
    pub mutations: u64,
    pub accepted: u64,
    /// The normalization b = ∫ f (summed over chain groups) the image is scaled by.
    pub normalization: NormalizationStats,
    /// Path-space chains: proposals and acceptances per mutation …
    pub mutation_counts: MutationCounts,
    /// … and the weights they ran with (after the warm-up, if adapted).
    pub mutation_weights: MutationWeights,
    /// Whether the chains stopped before their planned mutations (a time limit, a cancel).
    pub cut_short: bool,
}

/// A Markov chain of a Metropolis render: its state, random numbers and scratch memory.
pub(crate) trait MarkovChain: Send {
    /// What the chain explores (shared by all chains).
    type Target: Sync;
    /// Makes one mutation and appends its deposits.
    fn mutate(&mut self, target: &Self::Target, camera: &CameraModel, deposits: &mut Deposits);
    /// Proposals accepted so far.
    fn accepted(&self) -> u64;
    /// Rays traced so far.
    fn rays(&self) -> u64;
    /// Most deposits one mutation makes.
    fn max_deposits(&self) -> usize;
    /// Proposals and acceptances per mutation, for chains with several (path space).
    fn mutation_counts(&self) -> MutationCounts {
        MutationCounts::default()
    }
    /// The target values of the large steps' proposals so far (primary sample space) …
    fn large_steps(&self) -> Moments {
        Moments::default()
    }
    /// … and the rays they traced.
    fn large_step_rays(&self) -> u64 {
        0
    }
}

/// What a chain's mutations deposit: the chain's own expected-value deposits, whose
/// expected luminance is its group's normalization b_g (so they are scaled by the final
/// estimate of b_g), and large steps' proposals again as independent samples, scaled by the
/// bootstrap's b_g, the constant of Kelemen's combination (see `mutate`).
#[derive(Default)]
pub(crate) struct Deposits {
    pub chain: Vec<Splat>,
    pub independent: Vec<Splat>,
}

impl Deposits {
    fn with_capacity(splats: usize) -> Self {
        Deposits {
            chain: Vec::with_capacity(splats),
            independent: Vec::with_capacity(splats),
        }
    }

    fn clear(&mut self) {
        self.chain.clear();
        self.independent.clear();
    }
}

/// A chain of a render with its group, the factors of its deposits and the deposits of the
/// current round.
pub(crate) struct WeightedChain<C> {
    pub chain: C,
    /// Its index among the chains of the whole render.
    pub index: u64,
    /// The group whose normalization scales the chain's deposits (a layer of the film).
    group: usize,
    /// 1 / the chains of its group: its share of the group's deposits.
    share: f64,
    /// The bootstrap's b_g: the factor of its independent deposits, and of its deposits in
    /// the filter's partial images (which only guide the filter and are not rescaled).
    bootstrap_b: f64,
    deposits: Deposits,
}

impl<C> WeightedChain<C> {
    pub fn new(chain: C, index: u64, group: usize, chains_in_group: u64, bootstrap_b: f64) -> Self {
        WeightedChain {
            chain,
            index,
            group,
            share: 1.0 / chains_in_group as f64,
            bootstrap_b,
            deposits: Deposits::default(),
        }
    }
}

/// Bootstrap samples per pass: a pass covers the film once, stratified, so b from any
/// number of whole passes is unbiased and a stop during the bootstrap costs only precision.
/// Passes span at least `MIN_BOOTSTRAP_PASS` samples to keep every worker busy.
fn bootstrap_pass_size(n: u64, camera: &CameraModel) -> u64 {
    let pixels = camera.width as u64 * camera.height as u64;
    n.min(pixels.max(MIN_BOOTSTRAP_PASS))
}

/// The stratified film position of bootstrap sample `i` of `n`: within its pass, the samples
/// sweep the pixels in order, each covering an equal share of the film.
fn bootstrap_film_position(i: u64, n: u64, camera: &CameraModel, rng: &mut Rng) -> [f32; 2] {
    let pixels = camera.width as u64 * camera.height as u64;
    let pass_size = bootstrap_pass_size(n, camera);
    let pass_start = i / pass_size * pass_size;
    let in_pass = (n - pass_start).min(pass_size);
    let t = ((i - pass_start) as f64 + rng.uniform() as f64) / in_pass as f64 * pixels as f64;
    let pixel = (t.floor() as u64).min(pixels - 1);
    let x = (pixel % camera.width as u64) as f64 + (t - pixel as f64);
    let y = (pixel / camera.width as u64) as f32 + rng.uniform();
    [
        ((x / camera.width as f64) as f32).min(1.0 - f32::EPSILON),
        (y / camera.height as f32).min(1.0 - f32::EPSILON),
    ]
}

/// Restarts `sampler` as bootstrap sample `i` of `n`.
pub(crate) fn restart_as_bootstrap(
    sampler: &mut PssSampler,
    settings: &MetropolisSettings,
    camera: &CameraModel,
    i: u64,
    n: u64,
) {
    let mut jitter = Rng::new(settings.seed, i);
    let position = bootstrap_film_position(i, n, camera, &mut jitter);
    // The sampler's stream is offset so its numbers differ from the jitter's.
    sampler.restart_at(settings.seed, i + (1 << 40), position);
}

/// The bootstrap: its estimate of the normalization, and the values of the first samples
/// (sample-major, per group) for resampling.
pub(crate) struct Bootstrap {
    /// Over the samples taken: all asked for, or the whole passes done before a stop.
    pub estimate: NormalizationEstimate,
    /// The rays its samples traced.
    pub rays: u64,
    pub kept: Vec<f32>,
    kept_samples: u64,
}

pub(crate) fn bootstrap<T: PrimarySpaceTarget>(
    target: &T,
    camera: &CameraModel,
    settings: &MetropolisSettings,
    control: &Control,
) -> Bootstrap {
    let groups = target.groups();
    let n = settings.bootstrap_samples as u64;
    let kept_limit = n.min(BOOTSTRAP_KEPT_VALUES / groups as u64).max(1);
    let pass_size = bootstrap_pass_size(n, camera);
    let mut estimate = NormalizationEstimate::new(groups);
    let mut kept = Vec::with_capacity(kept_limit as usize * groups);
    let mut rays = 0;
    let mut done = 0;
    // The first pass always runs: the chains need a normalization.
    while done < n && (done == 0 || !control.should_stop()) {
        let end = (done + pass_size).min(n);
        let results: Vec<(NormalizationEstimate, Vec<f32>, u64)> = (done..end)
            .step_by(BOOTSTRAP_CHUNK as usize)
            .collect::<Vec<u64>>()
            .into_par_iter()
            .map(|first| {
                let mut sampler = new_sampler(target, settings);
                let mut scratch = target.scratch();
                let mut estimate = NormalizationEstimate::new(groups);
                let mut values = vec![0.0f32; groups];
                let last = (first + BOOTSTRAP_CHUNK).min(end);
                let mut kept = Vec::with_capacity(
                    (last.min(kept_limit).saturating_sub(first)) as usize * groups,
                );
                let mut rays = 0;
                for i in first..last {
                    restart_as_bootstrap(&mut sampler, settings, camera, i, n);
                    values.fill(0.0);
                    target.bootstrap(camera, &mut sampler, &mut scratch, &mut values, &mut rays);
                    estimate.add(&values);
                    if i < kept_limit {
                        kept.extend_from_slice(&values);
                    }
                }
                (estimate, kept, rays)
            })
            .collect();
        // Merged in sample order, whatever the scheduling.
        for (chunk_estimate, chunk_kept, chunk_rays) in results {
            estimate.merge(&chunk_estimate);
            kept.extend_from_slice(&chunk_kept);
            rays += chunk_rays;
        }
        done = end;
    }
    control.rays.fetch_add(rays, Ordering::Relaxed);
    Bootstrap {
        estimate,
        rays,
        kept_samples: done.min(kept_limit),
        kept,
    }
}

/// Chains per group: `total` in proportion to `b`, at least one per group with b > 0
/// (largest remainder).
pub(crate) fn allot_chains(b: &[f64], total: u64) -> Vec<u64> {
    let sum: f64 = b.iter().sum();
    let lit = b.iter().filter(|&&x| x > 0.0).count() as u64;
    let total = total.max(lit);
    // Every lit group has one chain; the rest go by the largest remainder of their share.
    let spare = (total - lit) as f64;
    let shares: Vec<f64> = b.iter().map(|&x| x / sum * spare).collect();
    let mut chains: Vec<u64> = b
        .iter()
        .zip(&shares)
        .map(|(&x, &share)| if x > 0.0 { 1 + share as u64 } else { 0 })
        .collect();
    let mut left = total - chains.iter().sum::<u64>();
    let mut order: Vec<usize> = (0..b.len()).filter(|&g| b[g] > 0.0).collect();
    order.sort_by(|&a, &c| {
        let fa = shares[a] - shares[a].floor();
        let fc = shares[c] - shares[c].floor();
        fc.total_cmp(&fa).then(a.cmp(&c))
    });
    for g in order.into_iter().cycle() {
        if left == 0 {
            break;
        }
        chains[g] += 1;
        left -= 1;
    }
    chains
}

/// For each group, `chains[g]` bootstrap sample indices drawn in proportion to the kept
/// values of that group by systematic resampling (one uniform number per group, so the
/// seeds spread over the samples as evenly as their values allow).
pub(crate) fn resample_seeds(
    bootstrap: &Bootstrap,
    chains: &[u64],
    seed: u64,
) -> Vec<(usize, u64)> {
    let groups = chains.len();
    let mut seeds = Vec::with_capacity(chains.iter().sum::<u64>() as usize);
    for (g, &count) in chains.iter().enumerate() {
        if count == 0 {
            continue;
        }
        let total: f64 = (0..bootstrap.kept_samples as usize)
            .map(|i| bootstrap.kept[i * groups + g] as f64)
            .sum();
        let offset = Rng::new(seed, RESAMPLING_STREAM + g as u64).uniform() as f64;
        let mut i = 0usize;
        let mut cumulative = bootstrap.kept[g] as f64;
        for k in 0..count {
            let goal = (k as f64 + offset) / count as f64 * total;
            while cumulative <= goal && i + 1 < bootstrap.kept_samples as usize {
                i += 1;
                cumulative += bootstrap.kept[i * groups + g] as f64;
            }
            seeds.push((g, i as u64));
        }
    }
    seeds
}

/// Stream offset of the seeds of path-space MLT's chains after the warm-up, apart from the
/// warm-up's own.
pub(crate) const ADAPTED_PHASE_SEED: u64 = 0xada7_7ed0_0000_0000;

/// What every chain of a render starts from: the bootstrap's estimate and the rays it
/// traced, and each chain's group and bootstrap sample (resampled), for the chains of the
/// render and, for path-space MLT adapting its weights, for those after the warm-up. Made
/// once, by the render or by the plan of a split render, whose jobs all start from it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ChainStart {
    pub estimate: NormalizationEstimate,
    pub rays: u64,
    pub seeds: Vec<(usize, u64)>,
    pub adapted_seeds: Vec<(usize, u64)>,
}

impl ChainStart {
    /// Runs the bootstrap and draws the chains' seeds (none when it found no light).
    pub fn new<T: PrimarySpaceTarget>(
        target: &T,
        camera: &CameraModel,
        settings: &MetropolisSettings,
        adapted_phase: bool,
        control: &Control,
    ) -> Self {
        let boot = bootstrap(target, camera, settings, control);
        let b = boot.estimate.b();
        let normalization: f64 = b.iter().sum();
        let (seeds, adapted_seeds) = if normalization > 0.0 && normalization.is_finite() {
            let plan = ChainPlan::new(&b, camera, settings);
            let draw = |seed| resample_seeds(&boot, &plan.chains_per_group, seed);
            let adapted = if adapted_phase {
                draw(settings.seed ^ ADAPTED_PHASE_SEED)
            } else {
                Vec::new()
            };
            (draw(settings.seed), adapted)
        } else {
            (Vec::new(), Vec::new())
        };
        ChainStart {
            estimate: boot.estimate,
            rays: boot.rays,
            seeds,
            adapted_seeds,
        }
    }
}

/// What a render's chains are to do: their total mutations and how they are split.
#[derive(Clone)]
pub(crate) struct ChainPlan {
    pub chains_per_group: Vec<u64>,
    pub chain_count: u64,
    pub mutations_per_chain: u64,
    pixels: u64,
}

impl ChainPlan {
    /// Chains allotted to the groups by their normalizations `b`, each making an equal share
    /// of the mutations asked for (or, without a count, enough for any time limit).
    pub fn new(b: &[f64], camera: &CameraModel, settings: &MetropolisSettings) -> Self {
        let pixels = camera.width as u64 * camera.height as u64;
        let total = if settings.mutations_per_pixel > 0 {
            settings.mutations_per_pixel as u64 * pixels
        } else {
            u64::MAX / 4
        };
        let chains_per_group = allot_chains(b, (settings.chains as u64).min(total));
        let chain_count: u64 = chains_per_group.iter().sum();
        ChainPlan {
            mutations_per_chain: total.div_ceil(chain_count),
            chains_per_group,
            chain_count,
            pixels,
        }
    }

    /// The same chains making `mutations_per_chain` each: one phase of the render.
    pub fn phase(&self, mutations_per_chain: u64) -> Self {
        ChainPlan {
            mutations_per_chain,
            ..self.clone()
        }
    }

    /// About one mutation per pixel for each chain: the first round of a render.
    pub fn first_round(&self) -> u64 {
        self.pixels.div_ceil(self.chain_count.max(1))
    }
}

/// The end of a render whose bootstrap found no light reaching the camera: the chains'
/// image is black and their mutations count as done; the direct pass still takes its share.
pub(crate) fn finish_without_light(
    camera: &CameraModel,
    settings: &MetropolisSettings,
    bootstrap: &NormalizationEstimate,
    film: &mut Film,
    control: &Control,
    direct: Option<&mut DirectPass>,
) -> MetropolisOutcome {
    let pixels = camera.width as u64 * camera.height as u64;
    // A job of a split render counts its share.
    let share = settings.share;
    let mutations = settings.mutations_per_pixel as u64 * pixels;
    let job_mutations = mutations / share.count as u64
        + (mutations % share.count as u64 > share.index as u64) as u64;
    control
        .mutations_done
        .fetch_add(job_mutations, Ordering::Relaxed);
    let mutations_per_pixel = if settings.mutations_per_pixel > 0 {
        settings.mutations_per_pixel as f64
    } else {
        f64::INFINITY
    };
    if let Some(direct) = direct {
        direct.keep_pace(film, control, mutations_per_pixel);
    }
    MetropolisOutcome {
        normalization: bootstrap.stats(),
        tally: Some(ChainTally::without_chains(bootstrap.clone())),
        ..Default::default()
    }
}

/// Mutations per chain that time-limited jobs of a split render (which have no count to
/// scale to) scale their chains' work to: any constant, the same for every job.
const TIME_LIMITED_JOB_MUTATIONS: u64 = 1 << 20;

/// What a render's chains leave for their normalization, kept apart until every chain is in
/// (the jobs of a split render each hold some chains' share).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ChainTally {
    /// The bootstrap's estimate, which the chains' independent samples join.
    pub bootstrap: NormalizationEstimate,
    /// Per chain (its index in the whole render), the estimate of its independent samples:
    /// its share of the normalization pass, and its large steps when they are pooled.
    pub chains: Vec<(u64, NormalizationEstimate)>,
    /// The film layer of the pass's points, if they join the image, and the samples the
    /// pass drew in all.
    pub pass_layer: Option<usize>,
    pub pass_samples: u64,
    /// The mutations per chain that the chains' deposits on the film count as.
    pub mutations_per_chain: u64,
}

impl ChainTally {
    /// A tally of no chains (no light reached the camera, or no depth was left to them).
    pub fn without_chains(bootstrap: NormalizationEstimate) -> Self {
        ChainTally {
            bootstrap,
            chains: Vec::new(),
            pass_layer: None,
            pass_samples: 0,
            mutations_per_chain: 0,
        }
    }

    /// Adds the chains of another job of the same render.
    pub fn merge(&mut self, other: ChainTally) -> Result<(), String> {
        if self.bootstrap != other.bootstrap
            || self.pass_layer != other.pass_layer
            || self.mutations_per_chain != other.mutations_per_chain
        {
            return Err("its chains' bootstrap or normalization differs".into());
        }
        self.chains.extend(other.chains);
        self.pass_samples += other.pass_samples;
        Ok(())
    }
}

/// Scales each group's chain deposits on the film by its final normalization estimate: the
/// bootstrap's, with every chain's independent samples added in chain order (so the sum's
/// bits do not depend on how the chains were split), and reports it.
pub(crate) fn finish(film: &mut Film, mut tally: ChainTally) -> NormalizationStats {
    let mut estimate = tally.bootstrap;
    tally.chains.sort_by_key(|&(chain, _)| chain);
    for (_, chain) in &tally.chains {
        estimate.merge(chain);
    }
    let mut scales = estimate.b();
    if let Some(layer) = tally.pass_layer {
        // Relative to the splat scale (pixels / mutations per chain): the pass's points
        // count per sample drawn.
        let scale = if tally.pass_samples > 0 {
            tally.mutations_per_chain as f64 / tally.pass_samples as f64
        } else {
            0.0
        };
        scales.resize(layer + 1, 0.0);
        scales[layer] = scale;
    }
    film.set_chain_layer_scales(&scales);
    if tally.mutations_per_chain > 0 {
        let pixels = film.width as f64 * film.height as f64;
        film.set_splat_scale(pixels / tally.mutations_per_chain as f64);
    }
    estimate.stats()
}

/// Collects the chains' independent samples for `finish`. `mutations_per_chain` is what
/// each chain made; a job of a split render that made fewer than planned (a time limit)
/// scales its chains' deposits up to the plan's count, so that the jobs' work adds up
/// however far each got.
pub(crate) fn tally<N: PrimarySpaceTarget, C: MarkovChain>(
    film: &mut Film,
    pass: NormalizationPass<N>,
    chains: &[WeightedChain<C>],
    plan: &ChainPlan,
    settings: &MetropolisSettings,
    mutations_per_chain: u64,
) -> ChainTally
where
    N::Scratch: Send,
{
    let pools_large_steps = pass.pools_large_steps();
    let pass_layer = pass.image_layer();
    let groups = pass.estimate.group_sums.len();
    let mut pass_samples = 0;
    let per_chain = chains
        .iter()
        .zip(pass.slots)
        .map(|(chain, slot)| {
            let mut estimate = NormalizationEstimate::new(groups);
            if let Some(slot) = slot {
                estimate.merge(&slot.estimate);
                pass_samples += slot.drawn;
            }
            if pools_large_steps {
                estimate.merge_single_group(&chain.chain.large_steps());
            }
            (chain.index, estimate)
        })
        .collect();
    let reference = if settings.share.count == 1 || mutations_per_chain == 0 {
        mutations_per_chain
    } else if settings.mutations_per_pixel > 0 {
        plan.mutations_per_chain
    } else {
        TIME_LIMITED_JOB_MUTATIONS
    };
    if reference != mutations_per_chain {
        film.scale_chain_work(reference as f64 / mutations_per_chain as f64, pass_layer);
    }
    ChainTally {
        bootstrap: pass.estimate,
        chains: per_chain,
        pass_layer,
        pass_samples,
        mutations_per_chain: reference,
    }
}

/// Runs `chains` in rounds, every chain making the same number of mutations, adds their
/// deposits to the film after each round (each chain's into its group's layer), lets each
/// chain's share of the normalization pass and the direct pass (if any) catch up with them,
/// and returns what they did with the mutations each chain made in all.
///
/// The first round, about one mutation per pixel, always runs, so a stopped render still
/// has an image. `done_before`: mutations per chain made in an earlier phase of the render
/// by as many chains of the same groups, whose deposits are already on the film. Rounds are
/// sized by the plan's chains, not by this run's (a job's share of them), so that a split
/// render's jobs keep the same pace and the direct pass takes the same samples in each.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_rounds<C: MarkovChain, N: PrimarySpaceTarget>(
    target: &C::Target,
    camera: &CameraModel,
    chains: &mut [WeightedChain<C>],
    plan: &ChainPlan,
    done_before: u64,
    normalization: &mut NormalizationPass<N>,
    film: &mut Film,
    control: &Control,
    mut direct: Option<&mut DirectPass>,
) -> (MetropolisOutcome, u64)
where
    N::Scratch: Send,
{
    let deposits_per_mutation = chains
        .iter()
        .map(|c| c.chain.max_deposits())
        .max()
        .unwrap_or(1) as u64;
    let per_round = (DEPOSITS_PER_ROUND / deposits_per_mutation / plan.chain_count.max(1)).max(1);
    for chain in chains.iter_mut() {
        chain.deposits = Deposits::with_capacity((per_round * deposits_per_mutation) as usize);
    }
    normalization.reserve_for_round(per_round);
    let mut mutations_done = 0u64;
    let first_round = plan.first_round().min(per_round);
    while mutations_done < plan.mutations_per_chain
        && (mutations_done + done_before == 0 || !control.should_stop())
    {
        let round = if mutations_done == 0 {
            first_round
        } else {
            per_round
        };
        let steps = (plan.mutations_per_chain - mutations_done).min(round);
        let made = done_before + mutations_done + steps;
        let pass = &normalization.context;
        chains
            .par_iter_mut()
            .zip(normalization.slots.par_iter_mut())
            .for_each(|(weighted, slot)| {
                weighted.deposits.clear();
                for _ in 0..steps {
                    weighted
                        .chain
                        .mutate(target, camera, &mut weighted.deposits);
                }
                control.mutations_done.fetch_add(steps, Ordering::Relaxed);
                if let Some(slot) = slot {
                    let chain = &weighted.chain;
                    pass.catch_up(slot, chain.rays(), chain.large_step_rays(), made, control);
                }
            });
        mutations_done += steps;
        // Chains are independent, so chain i's deposits also make partial image i mod K
        // of the post-process filter.
        for chain in chains.iter() {
            let independent_weight = chain.share * chain.bootstrap_b;
            let buffer = chain.index as usize;
            film.add_chain_splats(
                chain.group,
                &chain.deposits.chain,
                chain.share,
                chain.bootstrap_b,
                buffer,
            );
            film.add_weighted_splats(&chain.deposits.independent, independent_weight, buffer);
        }
        normalization.deposit_round(film);
        if let Some(direct) = direct.as_deref_mut() {
            let mutations_per_pixel = made as f64 * plan.chain_count as f64 / plan.pixels as f64;
            direct.keep_pace(film, control, mutations_per_pixel);
        }
    }

    let mut outcome = MetropolisOutcome {
        mutations: mutations_done * chains.len() as u64,
        cut_short: mutations_done < plan.mutations_per_chain,
        ..Default::default()
    };
    let mut rays = 0;
    for chain in chains.iter() {
        outcome.accepted += chain.chain.accepted();
        rays += chain.chain.rays();
        outcome.mutation_counts.add(&chain.chain.mutation_counts());
    }
    control.rays.fetch_add(rays, Ordering::Relaxed);
    (outcome, done_before + mutations_done)
}

/// Records `weight` × the state's contributions, each divided by the state's target value
/// plus `mis_offset`. Each contribution is divided first: with a subnormal target (a scene
/// of colours near 1e-40, found by the capi_scene fuzzer) `weight / denominator` alone
/// overflows to infinity, while a contribution over its own path's value stays near 1.
#[inline]
pub(crate) fn deposit(deposits: &mut Vec<Splat>, state: &PathSample, weight: f32, mis_offset: f32) {
    let denominator = state.target + mis_offset;
    for entry in &state.entries {
        deposits.push(Splat {
            pixel: entry.pixel,
            value: entry.value / denominator * weight,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::mlt::primary_space::film_position;

    #[test]
    fn chains_follow_the_groups_normalizations() {
        assert_eq!(allot_chains(&[3.0, 1.0], 8), vec![6, 2]);
        // Every lit group gets a chain, however dim.
        assert_eq!(allot_chains(&[1000.0, 0.0, 1e-6], 4), vec![3, 0, 1]);
        assert_eq!(allot_chains(&[1.0, 1.0, 1.0], 2), vec![1, 1, 1]);
        let chains = allot_chains(&[0.5, 0.3, 0.2], 1000);
        assert_eq!(chains.iter().sum::<u64>(), 1000);
        assert_eq!(chains, vec![500, 300, 200]);
    }

    #[test]
    fn bootstrap_positions_cover_each_pixel_equally() {
        let camera = crate::scene::Camera::default().model(4, 2);
        let n = 8 * 5;
        let mut counts = [0u32; 8];
        let mut rng = Rng::new(1, 2);
        for i in 0..n {
            let p = bootstrap_film_position(i, n, &camera, &mut rng);
            let (_, _, pixel) = film_position(&camera, p);
            counts[pixel as usize] += 1;
        }
        assert_eq!(counts, [5; 8]);
    }

    #[test]
    fn every_bootstrap_pass_covers_each_pixel_equally() {
        // 64 pixels: passes of MIN_BOOTSTRAP_PASS samples, the last one half as long.
        let camera = crate::scene::Camera::default().model(8, 8);
        let n = 3 * MIN_BOOTSTRAP_PASS + MIN_BOOTSTRAP_PASS / 2;
        assert_eq!(bootstrap_pass_size(n, &camera), MIN_BOOTSTRAP_PASS);
        let mut counts = vec![[0u32; 64]; 4];
        let mut rng = Rng::new(1, 2);
        for i in 0..n {
            let p = bootstrap_film_position(i, n, &camera, &mut rng);
            let (_, _, pixel) = film_position(&camera, p);
            counts[(i / MIN_BOOTSTRAP_PASS) as usize][pixel as usize] += 1;
        }
        let per_pixel = (MIN_BOOTSTRAP_PASS / 64) as u32;
        assert_eq!(counts[..3], [[per_pixel; 64]; 3]);
        assert_eq!(counts[3], [per_pixel / 2; 64]);
    }
}
