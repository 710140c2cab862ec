//! What a render is asked for: the algorithm, the settings with their defaults and the
//! limits beyond which a setting is a mistake, and their validation.

use crate::error::{Error, Result};
use crate::filter::{
    MLT_MAX_FILTER_BUFFERS, MLT_MAX_FILTER_RADIUS, MLT_MAX_FILTER_STRENGTH, MLT_MIN_FILTER_BUFFERS,
};
use crate::integrators::mlt::driver::MutationWeights;
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
    /// Spectral transport: each camera path carries `WAVELENGTHS` (4) wavelengths drawn by
    /// hero-wavelength sampling instead of RGB; RGB colours become smooth spectra (lights
    /// times D65) and the film gets CIE XYZ converted to linear sRGB. Dispersive
    /// dielectrics (`Material::abbe_number`) split light by wavelength only in this mode.
    pub spectral: bool,
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
            spectral: false,
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
