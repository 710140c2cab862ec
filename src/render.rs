//! Render settings, their validation, and the driver that runs an integrator over the film in
//! parallel with progress reporting, cancellation and a time limit.

use crate::control::Control;
use crate::error::{Error, MLT_STATUS_INTERNAL_ERROR, MLT_STATUS_OUT_OF_MEMORY, Result};
use crate::film::{Film, Splat};
use crate::filter::{
    FilterSettings, FilterStats, MLT_MAX_FILTER_BUFFERS, MLT_MAX_FILTER_RADIUS,
    MLT_MAX_FILTER_STRENGTH, MLT_MIN_FILTER_BUFFERS,
};
use crate::integrators::bdpt::Bdpt;
use crate::integrators::mlt::driver::{MetropolisOutcome, MutationCounts, MutationWeights};
use crate::integrators::mlt::normalization::NormalizationStats;
use crate::integrators::mlt::path_space::{self, PathSpaceTarget, PerturbationSizes};
use crate::integrators::mlt::primary_space::{MetropolisSettings, PrimarySpaceTarget};
use crate::integrators::mlt::pssmlt;
use crate::integrators::mlt::targets::{BdptAllStrategies, BdptMultiplexed};
use crate::integrators::path::PathTracer;
use crate::integrators::{PixelEstimator, SampleCounters};
use crate::sampling::{Rng, shifted_sobol_2d};
use crate::scene::{Camera, CameraModel, Scene};
use glam::Vec3A;
use rayon::prelude::*;
use std::sync::atomic::Ordering;
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// The light-transport algorithm of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Algorithm {
    /// Unidirectional path tracing with next-event estimation and MIS.
    Path,
    /// Bidirectional path tracing: every connection strategy, combined by MIS.
    Bdpt,
    /// Primary-sample-space Metropolis light transport (Kelemen) over the path tracer.
    Pssmlt,
    /// Multiplexed MLT (Hachisuka): primary-sample-space chains over BDPT that also pick the
    /// path depth and one connection strategy. The default: in the equal-time bench
    /// (`benches/equal_time.rs`, four scenes, hard ones weighted at least as much as the
    /// Cornell boxes) the algorithm whose RMSE stays closest to each scene's best, best on
    /// lamp-behind-glass and within 1.6× of the best everywhere (the README has the table).
    #[default]
    Mmlt,
    /// Primary-sample-space MLT over BDPT, all strategies of a sample summed.
    PssmltBdpt,
    /// Path-space MLT (Veach & Guibas 1997): the chains' states are light paths, changed by
    /// Veach's mutations.
    PathSpaceMlt,
    /// Energy redistribution path tracing (Cline, Talbot & Egbert 2005): BDPT camera
    /// samples whose energy short path-space chains of perturbations spread over nearby
    /// paths (`erpt_chain_length`, `erpt_deposit_energy`). Unbiased, like the path tracer.
    Erpt,
}

impl Algorithm {
    /// Whether the algorithm runs Metropolis chains (settings in mutations per pixel).
    pub fn is_metropolis(self) -> bool {
        matches!(
            self,
            Algorithm::Pssmlt | Algorithm::Mmlt | Algorithm::PssmltBdpt | Algorithm::PathSpaceMlt
        )
    }
}

/// The estimator a render runs, chosen from the settings.
enum Estimator<'a> {
    Path(&'a PathTracer<'a>),
    Bdpt(&'a Bdpt<'a>),
    Pssmlt(&'a PathTracer<'a>),
    Mmlt(&'a BdptMultiplexed<'a>),
    PssmltBdpt(&'a BdptAllStrategies<'a>),
    PathSpaceMlt(&'a Bdpt<'a>),
    Erpt(&'a Bdpt<'a>),
}

impl Estimator<'_> {
    /// Film layers of a Metropolis render: one per group of chains, whose deposits are
    /// scaled by the group's normalization, and one for the normalization pass's samples
    /// where they join the image (`PassImage`).
    fn chain_groups(&self) -> usize {
        fn layers<T: PrimarySpaceTarget>(target: &T) -> usize {
            target.groups() + target.pass_joins_the_image() as usize
        }
        match *self {
            Estimator::Pssmlt(target) => layers(target),
            Estimator::Mmlt(target) => layers(target),
            Estimator::PssmltBdpt(target) => layers(target),
            Estimator::PathSpaceMlt(_) => 1,
            Estimator::Path(_) | Estimator::Bdpt(_) | Estimator::Erpt(_) => 0,
        }
    }
}

/// Path depth below which a Metropolis render with a direct pass leaves paths to that pass.
const DIRECT_PASS_DEPTHS: u32 = 2;

impl Estimator<'_> {
    /// Runs the render; `direct` is the path tracer of a Metropolis render's direct pass.
    fn run(
        &self,
        camera: &CameraModel,
        settings: &RenderSettings,
        direct: Option<&PathTracer>,
        film: &mut Film,
        control: &Control,
    ) -> MetropolisOutcome {
        let seed = settings.seed;
        let spp = settings.samples_per_pixel;
        let chains = MetropolisSettings {
            mutations_per_pixel: settings.mutations_per_pixel,
            bootstrap_samples: settings.resolved_bootstrap_samples(),
            chains: settings.chains,
            large_step_probability: settings.large_step_probability,
            small_step_sigma: settings.small_step_sigma,
            normalization_work_fraction: settings.normalization_work_fraction,
            seed,
        };
        // The direct pass keeps pace with the chains: after each round of mutations it
        // catches up to its share of samples.
        let ratio = settings.direct_samples_per_mutation;
        let mut direct_job = direct.map(|direct| {
            let total = ratio * settings.mutations_per_pixel;
            let mut job = CameraSampleJob::new(direct, camera, seed, total, film);
            job.run_until(film, control, 1);
            job
        });
        let mut keep_pace = |film: &mut Film, mutations_per_pixel: f64| {
            if let Some(job) = direct_job.as_mut() {
                let target = (ratio as f64 * mutations_per_pixel)
                    .ceil()
                    .min(u32::MAX as f64);
                job.run_until(film, control, target as u32);
            }
        };
        match *self {
            Estimator::Path(estimator) => {
                CameraSampleJob::new(estimator, camera, seed, spp, film).run(film, control);
                MetropolisOutcome::default()
            }
            Estimator::Bdpt(estimator) => {
                CameraSampleJob::new(estimator, camera, seed, spp, film).run(film, control);
                MetropolisOutcome::default()
            }
            Estimator::Pssmlt(target) => {
                pssmlt::run(target, camera, &chains, film, control, &mut keep_pace)
            }
            Estimator::Mmlt(target) => {
                pssmlt::run(target, camera, &chains, film, control, &mut keep_pace)
            }
            Estimator::PssmltBdpt(target) => {
                pssmlt::run(target, camera, &chains, film, control, &mut keep_pace)
            }
            Estimator::PathSpaceMlt(bdpt) => {
                let target = PathSpaceTarget {
                    bdpt: BdptAllStrategies(Bdpt {
                        scene: bdpt.scene,
                        max_depth: bdpt.max_depth,
                        min_depth: bdpt.min_depth,
                    }),
                    camera: *camera,
                    weights: settings.mutation_weights,
                    sizes: PerturbationSizes::for_image(camera.width, camera.height),
                    perturb_in_sample_space: settings.perturb_in_sample_space,
                };
                let adapt = settings.adapt_mutation_weights;
                path_space::run(&target, &chains, adapt, film, control, &mut keep_pace)
            }
            Estimator::Erpt(bdpt) => {
                let erpt = path_space::ErptSettings {
                    samples_per_pixel: spp,
                    chain_length: settings.erpt_chain_length,
                    deposit_energy: settings.erpt_deposit_energy,
                    seed,
                    weights: settings.mutation_weights,
                    perturb_in_sample_space: settings.perturb_in_sample_space,
                };
                path_space::run_erpt(bdpt, camera, &erpt, film, control)
            }
        }
    }
}

/// Stream offset of the per-pixel shifts of the camera samples' positions (apart from the
/// per-sample streams, which hash the sample index into the seed).
const PIXEL_SHIFT_STREAM: u64 = 0x5eed_0f15_0000_0000;

// Limits beyond which a setting is a mistake, not a request.

/// Largest accepted image width or height.
pub const MLT_MAX_IMAGE_SIDE: u32 = 1 << 16;
/// Largest accepted samples (or mutations) per pixel.
pub const MLT_MAX_SAMPLES_PER_PIXEL: u32 = 1 << 24;
/// Largest accepted max depth.
pub const MLT_MAX_DEPTH_LIMIT: u32 = 1024;
/// Largest accepted thread count.
pub const MLT_MAX_THREADS: u32 = 4096;
/// Largest accepted time limit in seconds.
pub const MLT_MAX_TIME_LIMIT_SECONDS: f64 = 1.0e7;
/// Largest accepted ERPT chain length.
pub const MLT_MAX_ERPT_CHAIN_LENGTH: u32 = 1 << 20;
/// Largest accepted ERPT deposit energy.
pub const MLT_MAX_ERPT_DEPOSIT_ENERGY: f32 = 1.0e30;
/// Largest accepted number of Metropolis bootstrap samples.
pub const MLT_MAX_BOOTSTRAP_SAMPLES: u32 = 1 << 28;
/// Largest accepted share of a Metropolis render's rays spent on its normalization pass.
pub const MLT_MAX_NORMALIZATION_WORK_FRACTION: f32 = 0.9;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub algorithm: Algorithm,
    /// Samples per pixel; 0 means "until the time limit" (which must then be set).
    pub samples_per_pixel: u32,
    /// At most this many scattering vertices between camera and light (0: emitters only).
    pub max_depth: u32,
    pub seed: u64,
    /// Worker threads; 0 (the default) runs on one pool of one thread per core shared by
    /// every such render in the process, so renders from several host threads at once share
    /// the cores; a count gives the render a pool of its own. The image does not depend on it.
    pub threads: u32,
    /// Stop after this many seconds; 0 means no limit.
    pub time_limit_seconds: f64,
    /// Metropolis: mutations per pixel; 0 means "until the time limit".
    pub mutations_per_pixel: u32,
    /// Metropolis: independent samples that seed the chains and start the estimate of the
    /// normalization b (see `normalization_work_fraction`). 0 (the default) sizes the
    /// bootstrap to the render: one sample per `AUTO_BOOTSTRAP_MUTATIONS_PER_SAMPLE`
    /// planned mutations, at least `MIN_AUTO_BOOTSTRAP_SAMPLES`; a render planned by time
    /// alone takes `TIME_LIMITED_BOOTSTRAP_SAMPLES`. `resolved_bootstrap_samples` says
    /// what a render takes.
    pub bootstrap_samples: u32,
    /// Metropolis: number of Markov chains (independent of the thread count).
    pub chains: u32,
    /// PSSMLT: probability that a mutation is a large (independent) step.
    pub large_step_probability: f32,
    /// PSSMLT: standard deviation of a small step in primary sample space.
    pub small_step_sigma: f32,
    /// Metropolis: camera samples of the direct pass per chain mutation (both per pixel).
    /// The direct pass path-traces the paths of depth 0 and 1 (emitters seen directly,
    /// direct lighting), which chains render poorly: they spend mutations in proportion to
    /// brightness, on what stratified camera samples get right. The chains render the longer
    /// paths. The two alternate, so a render stopped early keeps the ratio. 0: no direct
    /// pass; the chains render every depth.
    pub direct_samples_per_mutation: u32,
    /// Metropolis: the share of the rays spent on independent samples of the chains' target
    /// (path-tracer samples for PSSMLT, BDPT samples with all strategies for the others),
    /// drawn alongside the chains to go on estimating the normalization b, which sets the
    /// image's brightness. The image is scaled by the final estimate, over the bootstrap,
    /// these samples and (PSSMLT, PSSMLT over BDPT) the chains' large steps, so its
    /// brightness error shrinks with the render's length (`integrators::mlt::normalization`).
    /// From 0 (no such samples: the bootstrap and the large steps alone) to 0.9.
    /// `RenderStats::normalization` reports the estimate's own standard error.
    pub normalization_work_fraction: f32,
    /// Path-space MLT: relative probabilities of the bidirectional mutation and of the
    /// lens, caustic and multi-chain perturbations (`Mutation as usize` order). Each step
    /// picks among those the current path admits. The bidirectional weight must be
    /// positive: it alone makes every path reachable. ERPT uses the perturbations' weights
    /// (its chains only perturb).
    pub mutation_weights: MutationWeights,
    /// Path-space MLT: run a warm-up of about one mutation per pixel with
    /// `mutation_weights`, then adapt each weight to its mutation's acceptance rate there
    /// (within a factor of 8) and run the rest of the render with those weights frozen, on
    /// chains seeded anew (so every chain is a valid Metropolis chain; see
    /// `path_space::chain::adapted_weights`). `RenderStats::mutation_weights` reports them.
    pub adapt_mutation_weights: bool,
    /// Path-space MLT and ERPT: perturb directions at diffuse vertices and lights by small
    /// steps in their own (cosine-weighted) sample space instead of within a cone, so the
    /// steps follow the BSDF's shape and its density cancels from the transfer ratio.
    pub perturb_in_sample_space: bool,
    /// ERPT: perturbations per chain (L). Each camera sample's energy e starts
    /// ⌊e / (L·e_d) + ξ⌋ chains.
    pub erpt_chain_length: u32,
    /// ERPT: the energy (luminance) e_d each chain step deposits; 0 picks it so that a
    /// camera sample starts one chain on average (from a pre-pass estimating the mean
    /// energy of a sample: e_d = mean / L). Smaller values start more chains.
    pub erpt_deposit_energy: f32,
    /// Metropolis and ERPT: the post-process filter for blotchy noise (`crate::filter`):
    /// non-local means guided by per-pixel variances measured from partial images. 0 turns
    /// it off (the default); otherwise the number of partial images the deposits are split
    /// into, from 2 to 32 (8 is a good start; each costs 12 bytes per pixel). The filter
    /// moves energy between pixels, keeping the image's total: it trades a local bias (blur
    /// of what the noise hides) for lower error. `RenderStats::filter` reports what it did.
    pub filter_buffers: u32,
    /// The filter's strength k: patch differences up to about k standard deviations count
    /// as noise. Higher smooths more (more bias, less noise).
    pub filter_strength: f32,
    /// The filter's search radius in pixels: each pixel averages pixels up to this far.
    pub filter_radius: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 256,
            height: 256,
            algorithm: Algorithm::default(),
            samples_per_pixel: 64,
            max_depth: 5,
            seed: 0,
            threads: 0,
            time_limit_seconds: 0.0,
            mutations_per_pixel: 32,
            bootstrap_samples: 0,
            chains: 1024,
            large_step_probability: 0.3,
            small_step_sigma: 0.01,
            direct_samples_per_mutation: Self::DEFAULT_DIRECT_SAMPLES_PER_MUTATION,
            normalization_work_fraction: Self::DEFAULT_NORMALIZATION_WORK_FRACTION,
            mutation_weights: MutationWeights::default(),
            erpt_chain_length: Self::DEFAULT_ERPT_CHAIN_LENGTH,
            erpt_deposit_energy: 0.0,
            adapt_mutation_weights: false,
            perturb_in_sample_space: false,
            filter_buffers: 0,
            filter_strength: Self::DEFAULT_FILTER_STRENGTH,
            filter_radius: Self::DEFAULT_FILTER_RADIUS,
        }
    }
}

// Rust-side defaults: C hosts get them from `mlt_render_settings_default`.
/// cbindgen:ignore
impl RenderSettings {
    /// An automatic bootstrap (`bootstrap_samples` 0) takes one sample per this many
    /// planned mutations: at the default 256² × 32 mutations per pixel, 2^18 samples, the
    /// best of 2^16, 2^18 and 2^20 on cornell-glass at 10 s of one thread (8 seeds; MMLT's
    /// RMSE 41% and 10% higher with the others, path-space MLT's 9–17%: the bootstrap is
    /// also what the chains are seeded from). Sized to the work, the bootstrap's share of
    /// the render, and so the brightness error's fall with the work, stay the same at any
    /// budget.
    pub const AUTO_BOOTSTRAP_MUTATIONS_PER_SAMPLE: u64 = 8;
    /// The fewest samples of an automatic bootstrap.
    pub const MIN_AUTO_BOOTSTRAP_SAMPLES: u32 = 1 << 16;
    /// The automatic bootstrap of a render with a time limit and no mutation count (the
    /// normalization pass then makes b's error fall with the render's length).
    pub const TIME_LIMITED_BOOTSTRAP_SAMPLES: u32 = 1 << 18;

    /// The bootstrap samples a Metropolis render takes (see `bootstrap_samples`).
    pub fn resolved_bootstrap_samples(&self) -> u32 {
        if self.bootstrap_samples > 0 {
            return self.bootstrap_samples;
        }
        if self.mutations_per_pixel == 0 {
            return Self::TIME_LIMITED_BOOTSTRAP_SAMPLES;
        }
        let mutations = self.width as u64 * self.height as u64 * self.mutations_per_pixel as u64;
        (mutations / Self::AUTO_BOOTSTRAP_MUTATIONS_PER_SAMPLE).clamp(
            Self::MIN_AUTO_BOOTSTRAP_SAMPLES as u64,
            MLT_MAX_BOOTSTRAP_SAMPLES as u64,
        ) as u32
    }
    /// The default `direct_samples_per_mutation`: one, the best measured at equal time on
    /// the Cornell scenes (benches/equal_time.rs).
    pub const DEFAULT_DIRECT_SAMPLES_PER_MUTATION: u32 = 1;
    /// The default `normalization_work_fraction`, chosen by `benches/brightness.rs`. Against
    /// a bootstrap alone (fraction 0), 20 seeds of 10 s on one thread on the four bench
    /// scenes, MMLT and path-space MLT: at 0.05 every median RMSE is within its standard
    /// error (0.5–5%) of fraction 0's (−1.8% to +1.7%), while the brightness spread over the
    /// seeds falls (lamp-behind-glass 0.77% → 0.57%) and goes on falling with the render's
    /// length; 0.1 cost up to 6% more RMSE (door-ajar), 0.2 up to 8.5%. PSSMLT's large
    /// steps (30% of its mutations) already make the share, so it costs PSSMLT nothing;
    /// MMLT's pass samples join the image, which gives back about half of what they cost.
    pub const DEFAULT_NORMALIZATION_WORK_FRACTION: f32 = 0.05;
    /// The default `erpt_chain_length`: the best at equal time of 5, 10, 20, 40 and 100 on
    /// cornell-glass and door-ajar (`benches/equal_time.rs`, medians of 3 renders of 10 s;
    /// 5 to 20 within noise of each other, 100, about Cline et al.'s length, 2 to 3 times
    /// worse: long chains leave few camera samples per pixel).
    pub const DEFAULT_ERPT_CHAIN_LENGTH: u32 = 10;
    /// The partial images a filtered render uses unless told otherwise (the CLI's
    /// `--filter`): 7 degrees of freedom per pixel for the variance (before pooling over
    /// 5 × 5 pixels), 96 bytes per pixel.
    pub const DEFAULT_FILTER_BUFFERS: u32 = 8;
    /// The default `filter_strength`: Rousselle et al.'s choice; 1.0 gained no more on
    /// cornell-glass and door-ajar and shifted regions further.
    pub const DEFAULT_FILTER_STRENGTH: f32 = 0.45;
    /// The default `filter_radius`: a 15 × 15 search window.
    pub const DEFAULT_FILTER_RADIUS: u32 = 7;

    pub fn validate(&self) -> Result<()> {
        for (name, side) in [("width", self.width), ("height", self.height)] {
            if side == 0 || side > MLT_MAX_IMAGE_SIDE {
                return Err(Error::invalid(format!(
                    "settings.{name} is {side}; it must be between 1 and {MLT_MAX_IMAGE_SIDE}"
                )));
            }
        }
        if self.samples_per_pixel > MLT_MAX_SAMPLES_PER_PIXEL {
            return Err(Error::invalid(format!(
                "settings.samples_per_pixel is {}; at most {MLT_MAX_SAMPLES_PER_PIXEL} are supported",
                self.samples_per_pixel
            )));
        }
        if self.max_depth > MLT_MAX_DEPTH_LIMIT {
            return Err(Error::invalid(format!(
                "settings.max_depth is {}; at most {MLT_MAX_DEPTH_LIMIT} is supported",
                self.max_depth
            )));
        }
        if self.threads > MLT_MAX_THREADS {
            return Err(Error::invalid(format!(
                "settings.threads is {}; use 0 for all cores or at most {MLT_MAX_THREADS}",
                self.threads
            )));
        }
        let t = self.time_limit_seconds;
        if !(t.is_finite() && (0.0..=MLT_MAX_TIME_LIMIT_SECONDS).contains(&t)) {
            return Err(Error::invalid(format!(
                "settings.time_limit_seconds is {t}; it must be 0 (no limit) or a positive number of seconds up to {MLT_MAX_TIME_LIMIT_SECONDS}"
            )));
        }
        if self.algorithm.is_metropolis() {
            if self.mutations_per_pixel == 0 && t == 0.0 {
                return Err(Error::invalid(
                    "settings.mutations_per_pixel is 0 and there is no time limit; the render would never end",
                ));
            }
            let direct = self.direct_samples_per_mutation as u64;
            if direct * (self.mutations_per_pixel.max(1) as u64) > MLT_MAX_SAMPLES_PER_PIXEL as u64
            {
                return Err(Error::invalid(format!(
                    "settings.direct_samples_per_mutation is {direct}; times settings.mutations_per_pixel ({}) it must be at most {MLT_MAX_SAMPLES_PER_PIXEL}",
                    self.mutations_per_pixel
                )));
            }
            if self.mutations_per_pixel > MLT_MAX_SAMPLES_PER_PIXEL {
                return Err(Error::invalid(format!(
                    "settings.mutations_per_pixel is {}; at most {MLT_MAX_SAMPLES_PER_PIXEL} are supported",
                    self.mutations_per_pixel
                )));
            }
        } else if self.samples_per_pixel == 0 && t == 0.0 {
            return Err(Error::invalid(
                "settings.samples_per_pixel is 0 and there is no time limit; the render would never end",
            ));
        }
        if self.bootstrap_samples > MLT_MAX_BOOTSTRAP_SAMPLES {
            return Err(Error::invalid(format!(
                "settings.bootstrap_samples is {}; it must be 0 (automatic) or at most {MLT_MAX_BOOTSTRAP_SAMPLES}",
                self.bootstrap_samples
            )));
        }
        let bootstrap = self.resolved_bootstrap_samples();
        if self.chains == 0 || self.chains > bootstrap {
            return Err(Error::invalid(format!(
                "settings.chains is {}; it must be between 1 and the bootstrap samples ({bootstrap})",
                self.chains
            )));
        }
        let fraction = self.normalization_work_fraction;
        if !(fraction.is_finite()
            && (0.0..=MLT_MAX_NORMALIZATION_WORK_FRACTION).contains(&fraction))
        {
            return Err(Error::invalid(format!(
                "settings.normalization_work_fraction is {fraction}; it must be from 0 to {MLT_MAX_NORMALIZATION_WORK_FRACTION}"
            )));
        }
        let p = self.large_step_probability;
        if !(p.is_finite() && (0.0..=1.0).contains(&p)) {
            return Err(Error::invalid(format!(
                "settings.large_step_probability is {p}; it must be in [0, 1]"
            )));
        }
        let sigma = self.small_step_sigma;
        if !(sigma.is_finite() && sigma > 0.0 && sigma <= 1.0) {
            return Err(Error::invalid(format!(
                "settings.small_step_sigma is {sigma}; it must be in (0, 1]"
            )));
        }
        let weights = self.mutation_weights.0;
        if let Some((i, w)) = weights
            .iter()
            .enumerate()
            .find(|&(_, &w)| !(w.is_finite() && (0.0..=1e6).contains(&w)))
        {
            return Err(Error::invalid(format!(
                "settings.mutation_weights[{i}] is {w}; weights must be finite, from 0 to 1e6"
            )));
        }
        if weights[0] <= 0.0 {
            return Err(Error::invalid(
                "settings.mutation_weights[0] (the bidirectional mutation) is 0; it must be positive, or the chains cannot reach every path",
            ));
        }
        let length = self.erpt_chain_length;
        if length == 0 || length > MLT_MAX_ERPT_CHAIN_LENGTH {
            return Err(Error::invalid(format!(
                "settings.erpt_chain_length is {length}; it must be between 1 and {MLT_MAX_ERPT_CHAIN_LENGTH}"
            )));
        }
        let e_d = self.erpt_deposit_energy;
        if !(e_d.is_finite() && (0.0..=MLT_MAX_ERPT_DEPOSIT_ENERGY).contains(&e_d)) {
            return Err(Error::invalid(format!(
                "settings.erpt_deposit_energy is {e_d}; it must be 0 (automatic) or a positive number up to {MLT_MAX_ERPT_DEPOSIT_ENERGY:e}"
            )));
        }
        let buffers = self.filter_buffers;
        if buffers != 0 {
            if !(MLT_MIN_FILTER_BUFFERS..=MLT_MAX_FILTER_BUFFERS).contains(&buffers) {
                return Err(Error::invalid(format!(
                    "settings.filter_buffers is {buffers}; it must be 0 (no filter) or from {MLT_MIN_FILTER_BUFFERS} to {MLT_MAX_FILTER_BUFFERS}"
                )));
            }
            if !(self.algorithm.is_metropolis() || self.algorithm == Algorithm::Erpt) {
                return Err(Error::invalid(format!(
                    "settings.filter_buffers is {buffers} but the algorithm is {:?}; the filter is for Metropolis and ERPT images (set it to 0)",
                    self.algorithm
                )));
            }
        }
        let k = self.filter_strength;
        if !(k.is_finite() && k > 0.0 && k <= MLT_MAX_FILTER_STRENGTH) {
            return Err(Error::invalid(format!(
                "settings.filter_strength is {k}; it must be positive, up to {MLT_MAX_FILTER_STRENGTH}"
            )));
        }
        let radius = self.filter_radius;
        if radius == 0 || radius > MLT_MAX_FILTER_RADIUS {
            return Err(Error::invalid(format!(
                "settings.filter_radius is {radius}; it must be from 1 to {MLT_MAX_FILTER_RADIUS} pixels"
            )));
        }
        Ok(())
    }

    /// Floats the RGB output of this image holds, or an error if it overflows.
    pub fn output_len(&self) -> Result<usize> {
        (self.width as usize)
            .checked_mul(self.height as usize)
            .and_then(|p| p.checked_mul(3))
            .ok_or_else(|| {
                Error::invalid(format!(
                    "an image of {} x {} pixels x 3 floats overflows the address space",
                    self.width, self.height
                ))
            })
    }
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    Completed,
    Cancelled,
    TimeLimitReached,
}

/// What a render did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderStats {
    pub stop: StopReason,
    /// Camera samples taken over the whole image (path tracing, BDPT, a Metropolis render's
    /// direct pass).
    pub samples: u64,
    /// Metropolis: mutations made by all chains.
    pub mutations: u64,
    /// Rays traced (closest-hit and shadow).
    pub rays: u64,
    /// Samples whose radiance was not finite and were dropped (counted in `samples`).
    pub invalid_samples: u64,
    pub seconds: f64,
    pub threads: u32,
    /// Metropolis: accepted mutations.
    pub accepted_mutations: u64,
    /// Metropolis: the normalization b = ∫ luminance(f) the image was scaled by (its final
    /// estimate), how many independent samples it came from, its estimated relative
    /// standard error and the largest share of it one sample carried. ERPT: `value` is the
    /// deposit energy e_d the chains used.
    pub normalization: NormalizationStats,
    /// Path-space MLT: proposals and acceptances per mutation …
    pub mutation_counts: MutationCounts,
    /// … and the weights the chains ran with (after the warm-up, if adapted). ERPT: the
    /// weights of its perturbations.
    pub mutation_weights: MutationWeights,
    /// What the post-process filter did (zeros when it is off).
    pub filter: FilterStats,
}

/// Called from the rendering call's own thread with the fraction done; return `false` to stop.
pub type Progress<'a> = &'a mut dyn FnMut(f32) -> bool;

/// How often the caller's thread wakes to report progress and check the time limit.
const PROGRESS_INTERVAL: Duration = Duration::from_millis(50);
/// Rows per unit of parallel work.
const BAND_ROWS: u32 = 4;
/// Target samples per pass over the whole image: passes bound how long a stop takes and how
/// unevenly a partial image is sampled.
const SAMPLES_PER_PASS: u64 = 1 << 18;

/// Renders into `rgb_out` (width × height × 3 floats, rows top to bottom).
pub fn render(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    rgb_out: &mut [f32],
    progress: Option<Progress>,
) -> Result<RenderStats> {
    render_into(scene, camera, settings, rgb_out, None, progress)
}

/// Renders like [`render`], and also writes the image as it was before the post-process
/// filter into `unfiltered_out` (the same image when the filter is off): what measuring the
/// filter's bias and gain on one render takes.
pub fn render_with_unfiltered(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    rgb_out: &mut [f32],
    unfiltered_out: &mut [f32],
    progress: Option<Progress>,
) -> Result<RenderStats> {
    render_into(
        scene,
        camera,
        settings,
        rgb_out,
        Some(unfiltered_out),
        progress,
    )
}

fn render_into(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    rgb_out: &mut [f32],
    unfiltered_out: Option<&mut [f32]>,
    progress: Option<Progress>,
) -> Result<RenderStats> {
    settings.validate()?;
    camera.validate()?;
    let needed = settings.output_len()?;
    let shortest = rgb_out
        .len()
        .min(unfiltered_out.as_ref().map_or(usize::MAX, |u| u.len()));
    if shortest < needed {
        return Err(Error::invalid(format!(
            "the output buffer holds {shortest} floats but a {} x {} RGB image needs {needed}",
            settings.width, settings.height
        )));
    }
    let own_pool;
    let pool = if settings.threads == 0 {
        shared_pool()?
    } else {
        own_pool = new_pool(settings.threads as usize)?;
        &own_pool
    };
    let threads = pool.current_num_threads() as u32;

    let start = Instant::now();
    let deadline = (settings.time_limit_seconds > 0.0)
        .then(|| start + Duration::from_secs_f64(settings.time_limit_seconds));
    let control = Control::new(deadline, settings.algorithm.is_metropolis());
    let model = camera.model(settings.width, settings.height);
    model.validate()?;
    // A Metropolis render with a direct pass leaves the shortest paths to a path tracer.
    let direct = (settings.algorithm.is_metropolis() && settings.direct_samples_per_mutation > 0)
        .then(|| PathTracer {
            scene,
            max_depth: settings.max_depth.min(DIRECT_PASS_DEPTHS - 1),
            min_depth: 0,
        });
    let min_depth = if direct.is_some() {
        DIRECT_PASS_DEPTHS
    } else {
        0
    };
    let path_tracer = PathTracer {
        scene,
        max_depth: settings.max_depth,
        min_depth,
    };
    let bdpt = Bdpt {
        scene,
        max_depth: settings.max_depth,
        min_depth,
    };
    let multiplexed;
    let all_strategies;
    let estimator: Estimator = match settings.algorithm {
        Algorithm::Path => Estimator::Path(&path_tracer),
        Algorithm::Bdpt => Estimator::Bdpt(&bdpt),
        Algorithm::Pssmlt => Estimator::Pssmlt(&path_tracer),
        Algorithm::Mmlt => {
            multiplexed = BdptMultiplexed(bdpt);
            Estimator::Mmlt(&multiplexed)
        }
        Algorithm::PssmltBdpt => {
            all_strategies = BdptAllStrategies(bdpt);
            Estimator::PssmltBdpt(&all_strategies)
        }
        Algorithm::PathSpaceMlt => Estimator::PathSpaceMlt(&bdpt),
        Algorithm::Erpt => Estimator::Erpt(&bdpt),
    };
    let mut film = try_film(settings, estimator.chain_groups())?;
    let pixels = settings.width as u64 * settings.height as u64;
    // Progress counts camera samples and mutations alike; without a count (time limit
    // only) there is no plan.
    let planned = if settings.algorithm.is_metropolis() {
        let direct_samples = if direct.is_some() {
            settings.direct_samples_per_mutation as u64 * settings.mutations_per_pixel as u64
        } else {
            0
        };
        if settings.mutations_per_pixel > 0 {
            (settings.mutations_per_pixel as u64 + direct_samples) * pixels
        } else {
            0
        }
    } else {
        settings.samples_per_pixel as u64 * pixels
    };

    let mut progress = progress;
    let done = DoneSignal::default();
    let outcome = std::thread::scope(|s| {
        let done = &done;
        let control = &control;
        let film = &mut film;
        let estimator = &estimator;
        let direct = direct.as_ref();
        let model = &model;
        let worker = s.spawn(move || {
            // Signals even when the render panics, so the caller never waits forever.
            let _signal = SignalOnDrop(done);
            pool.install(|| estimator.run(model, settings, direct, film, control))
        });
        while !done.wait(PROGRESS_INTERVAL) {
            if let Some(callback) = progress.as_mut() {
                let fraction = control.fraction(planned, start);
                if !callback(fraction) {
                    control.cancel();
                }
            }
            if deadline.is_some_and(|d| Instant::now() >= d) {
                control.stop();
            }
        }
        worker.join()
    });
    let Ok(metropolis) = outcome else {
        return Err(Error::new(
            MLT_STATUS_INTERNAL_ERROR,
            "a rendering thread panicked; this is a bug in mlt",
        ));
    };
    let filter = film.write_rgb(
        &mut rgb_out[..needed],
        unfiltered_out.map(|u| &mut u[..needed]),
    );
    let stop = if control.was_cancelled() {
        StopReason::Cancelled
    } else if planned == 0 || control.work_done() < planned {
        StopReason::TimeLimitReached
    } else {
        StopReason::Completed
    };
    if let (StopReason::Completed, Some(callback)) = (stop, progress.as_mut()) {
        // The last word is always 1.0 for a finished render; a cancel now changes nothing.
        let _ = callback(1.0);
    }
    Ok(RenderStats {
        stop,
        samples: control.samples_done.load(Ordering::Relaxed),
        mutations: control.mutations_done.load(Ordering::Relaxed),
        rays: control.rays.load(Ordering::Relaxed),
        invalid_samples: control.invalid.load(Ordering::Relaxed),
        seconds: start.elapsed().as_secs_f64(),
        threads,
        accepted_mutations: metropolis.accepted,
        normalization: metropolis.normalization,
        mutation_counts: metropolis.mutation_counts,
        mutation_weights: metropolis.mutation_weights,
        filter,
    })
}

/// Tells the calling thread the render finished. A mutex and condition variable rather than
/// a channel: waiting on them never allocates, so allocation counts do not depend on timing.
#[derive(Default)]
struct DoneSignal {
    done: Mutex<bool>,
    changed: Condvar,
}

impl DoneSignal {
    /// Waits up to `timeout`; returns whether the render has finished.
    fn wait(&self, timeout: Duration) -> bool {
        let guard = self.done.lock().unwrap_or_else(|e| e.into_inner());
        let (guard, _) = self
            .changed
            .wait_timeout_while(guard, timeout, |done| !*done)
            .unwrap_or_else(|e| e.into_inner());
        *guard
    }
}

struct SignalOnDrop<'a>(&'a DoneSignal);

impl Drop for SignalOnDrop<'_> {
    fn drop(&mut self) {
        *self.0.done.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.0.changed.notify_all();
    }
}

/// Allocates the film (with a layer for each of `chain_groups` groups of Metropolis chains),
/// reporting failure as a status instead of aborting.
fn try_film(settings: &RenderSettings, chain_groups: usize) -> Result<Film> {
    let (width, height) = (settings.width, settings.height);
    let pixels = width as usize * height as usize;
    // Probe the largest allocations first: `vec!` would abort the process on failure.
    let out_of_memory = || {
        Error::new(
            MLT_STATUS_OUT_OF_MEMORY,
            format!("could not allocate the film for {width} x {height} pixels"),
        )
    };
    let mut probe: Vec<[f64; 3]> = Vec::new();
    probe
        .try_reserve_exact(pixels)
        .map_err(|_| out_of_memory())?;
    drop(probe);
    let buffers = settings.filter_buffers;
    let mut partials: Vec<[f32; 3]> = Vec::new();
    partials
        .try_reserve_exact(pixels * buffers as usize)
        .map_err(|_| out_of_memory())?;
    drop(partials);
    let mut layers: Vec<[f64; 3]> = Vec::new();
    layers
        .try_reserve_exact(pixels * chain_groups)
        .map_err(|_| out_of_memory())?;
    drop(layers);
    let mut film = Film::new(width, height, settings.algorithm != Algorithm::Path);
    if chain_groups > 0 {
        film.enable_chain_layers(chain_groups);
    }
    if buffers > 0 {
        film.enable_filter(FilterSettings {
            buffers,
            strength: settings.filter_strength,
            radius: settings.filter_radius,
        });
    }
    Ok(film)
}

/// A pool of `threads` worker threads (0: one per core).
fn new_pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("mlt-worker-{i}"))
        .build()
        .map_err(|e| {
            Error::new(
                MLT_STATUS_OUT_OF_MEMORY,
                format!("could not start worker threads: {e}"),
            )
        })
}

/// The pool every render with `threads` 0 runs on: one thread per core for the whole
/// process, started by the first such render, so that a host rendering from several
/// threads at once shares the cores instead of starting a pool per render.
fn shared_pool() -> Result<&'static rayon::ThreadPool> {
    static SHARED: std::sync::OnceLock<std::result::Result<rayon::ThreadPool, String>> =
        std::sync::OnceLock::new();
    SHARED
        .get_or_init(|| new_pool(0).map_err(|e| e.message))
        .as_ref()
        .map_err(|message| Error::new(MLT_STATUS_OUT_OF_MEMORY, message.clone()))
}

/// Per-work-unit state of a render: the estimator's scratch memory and the splats of the
/// current pass. Created once per render so sampling never allocates.
struct BandState<S> {
    scratch: S,
    splats: Vec<Splat>,
    light_paths: u64,
}

/// Runs a pixel estimator over the film, pass by pass; can stop at a sample count and go on
/// later (a Metropolis render interleaves its direct pass with the chains).
struct CameraSampleJob<'a, E: PixelEstimator> {
    estimator: &'a E,
    camera: CameraModel,
    seed: u64,
    /// 0 = until stopped.
    samples_per_pixel: u32,
    /// Samples per pixel of a full pass.
    batch: u32,
    /// Samples per pixel taken so far.
    samples_taken: u32,
    states: Vec<BandState<E::Scratch>>,
}

impl<'a, E: PixelEstimator> CameraSampleJob<'a, E> {
    fn new(
        estimator: &'a E,
        camera: &CameraModel,
        seed: u64,
        samples_per_pixel: u32,
        film: &Film,
    ) -> Self {
        let width = film.width;
        let pixels = width as u64 * film.height as u64;
        let batch = SAMPLES_PER_PASS.div_ceil(pixels).clamp(1, 64) as u32;
        let bands = film.height.div_ceil(BAND_ROWS) as usize;
        let splat_capacity = if estimator.splats() {
            (BAND_ROWS * width * batch * 2) as usize
        } else {
            0
        };
        let states = (0..bands)
            .map(|_| BandState {
                scratch: estimator.scratch(),
                splats: Vec::with_capacity(splat_capacity),
                light_paths: 0,
            })
            .collect();
        CameraSampleJob {
            estimator,
            camera: *camera,
            seed,
            samples_per_pixel,
            batch,
            samples_taken: 0,
            states,
        }
    }

    fn run(&mut self, film: &mut Film, control: &Control) {
        self.run_until(film, control, u32::MAX);
    }

    /// Takes samples until every pixel has `target` (or all it should have), or the render
    /// stops.
    fn run_until(&mut self, film: &mut Film, control: &Control, target: u32) {
        let width = film.width;
        let batch = self.batch;
        let total = if self.samples_per_pixel > 0 {
            self.samples_per_pixel.min(target)
        } else {
            target
        };
        let states = &mut self.states;
        // The first pass takes one sample per pixel and always completes, so a render
        // stopped at any moment still has a sample in every pixel.
        while self.samples_taken < total && (self.samples_taken == 0 || !control.should_stop()) {
            let first = self.samples_taken;
            let end = if first == 0 {
                1
            } else {
                first.saturating_add(batch).min(total)
            };
            film.par_bands(BAND_ROWS)
                .zip(states.par_iter_mut())
                .for_each(|(band, state)| {
                    state.splats.clear();
                    state.light_paths = 0;
                    if first > 0 && control.should_stop() {
                        return;
                    }
                    let mut counters = SampleCounters::default();
                    let mut invalid = 0u64;
                    for (i, (sum, count)) in
                        band.sums.iter_mut().zip(band.counts.iter_mut()).enumerate()
                    {
                        let x = i as u32 % width;
                        let y = band.first_row + i as u32 / width;
                        let pixel = y as u64 * width as u64 + x as u64;
                        let mut pixel_sum = Vec3A::ZERO;
                        // The pixel's samples spread over it as a (0, 2)-sequence.
                        let mut shift = Rng::new(self.seed, PIXEL_SHIFT_STREAM + pixel);
                        let shift = [shift.next_u32(), shift.next_u32()];
                        for sample in first..end {
                            let mut rng = Rng::for_pixel_sample(self.seed, pixel, sample as u64);
                            let [jx, jy] = shifted_sobol_2d(sample, shift);
                            let splats_before = state.splats.len();
                            let l = self.estimator.sample(
                                &self.camera,
                                x as f32 + jx,
                                y as f32 + jy,
                                &mut rng,
                                &mut counters,
                                &mut state.scratch,
                                &mut state.splats,
                            );
                            let splats_valid = state.splats[splats_before..]
                                .iter()
                                .all(|s| s.value.is_finite());
                            if l.is_finite() && splats_valid {
                                pixel_sum += l;
                            } else {
                                state.splats.truncate(splats_before);
                                invalid += 1;
                            }
                        }
                        for c in 0..3 {
                            sum[c] += pixel_sum[c] as f64;
                        }
                        *count += end - first;
                    }
                    let band_samples = band.counts.len() as u64 * (end - first) as u64;
                    state.light_paths = band_samples;
                    control
                        .samples_done
                        .fetch_add(band_samples, Ordering::Relaxed);
                    control.rays.fetch_add(counters.rays, Ordering::Relaxed);
                    control.invalid.fetch_add(invalid, Ordering::Relaxed);
                });
            if self.estimator.splats() {
                for state in states.iter() {
                    film.add_splats(&state.splats, state.light_paths);
                }
            }
            self.samples_taken = end;
        }
    }
}
