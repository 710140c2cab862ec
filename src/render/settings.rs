//! What a render is asked for: the algorithm, the settings with their defaults and the
//! limits beyond which a setting is a mistake, and their validation.

use crate::error::{Error, Result};
use crate::filter::{
    MLT_MAX_FILTER_BUFFERS, MLT_MAX_FILTER_RADIUS, MLT_MAX_FILTER_STRENGTH, MLT_MIN_FILTER_BUFFERS,
};
use crate::integrators::mlt::driver::MutationWeights;
use crate::integrators::path::Roulette;
use crate::params::{
    ChoiceParameter, Kind, ParameterType, Range, Unfit, Value, declare_parameters, in_unit_interval,
};
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

impl ChoiceParameter for Algorithm {
    /// The names of the command line, Python and the docs.
    const NAMES: &'static [&'static str] = &[
        "path",
        "bdpt",
        "pssmlt",
        "mmlt",
        "pssmlt-bdpt",
        "path-space-mlt",
        "erpt",
    ];
    const ALL: &'static [Algorithm] = &[
        Algorithm::Path,
        Algorithm::Bdpt,
        Algorithm::Pssmlt,
        Algorithm::Mmlt,
        Algorithm::PssmltBdpt,
        Algorithm::PathSpaceMlt,
        Algorithm::Erpt,
    ];
    const TYPE_NAME: &'static str = "Algorithm";
    const C_PREFIX: &'static str = "MLT_ALGORITHM";
}

impl ParameterType for MutationWeights {
    const KIND: Kind = Kind::F32x4;
    fn to_value(self) -> Value {
        self.0.to_value()
    }
    fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
        <[f32; 4]>::from_value(value).map(MutationWeights)
    }
    fn first(&self, bad: impl Fn(f64) -> bool) -> Option<(String, String)> {
        self.0.first(bad)
    }
}

// The render settings, each declared once: the C, C++ and Python fields, the command-line
// flags, the range checks of `validate` and `docs/settings.md` follow from this table. The
// order is the C struct's: append new settings at the end.
declare_parameters! {
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct RenderSettings in "settings" {
        width: u32 = 256 => {
            doc: "Image width in pixels.",
            flag: "width",
            range: Range::closed(1.0, MLT_MAX_IMAGE_SIDE as f64),
            rule: |_| format!("it must be between 1 and {MLT_MAX_IMAGE_SIDE}"),
        },
        height: u32 = 256 => {
            doc: "Image height in pixels.",
            flag: "height",
            range: Range::closed(1.0, MLT_MAX_IMAGE_SIDE as f64),
            rule: |_| format!("it must be between 1 and {MLT_MAX_IMAGE_SIDE}"),
        },
        algorithm: Algorithm = Algorithm::default() => {
            doc: "The light-transport algorithm.",
            flag: "algorithm",
        },
        /// Samples per pixel; 0 means "until the time limit" (which must then be set).
        samples_per_pixel: u32 = 64 => {
            doc: "Path tracing, BDPT and ERPT: samples per pixel (0: until the time limit).",
            flag: "spp",
            range: Range::closed(0.0, MLT_MAX_SAMPLES_PER_PIXEL as f64),
            rule: |_| format!("at most {MLT_MAX_SAMPLES_PER_PIXEL} are supported"),
        },
        /// At most this many scattering vertices between camera and light (0: emitters only).
        max_depth: u32 = 5 => {
            doc: "Most scattering vertices between camera and light (0: emitters seen directly).",
            flag: "max-depth",
            range: Range::closed(0.0, MLT_MAX_DEPTH_LIMIT as f64),
            rule: |_| format!("at most {MLT_MAX_DEPTH_LIMIT} is supported"),
        },
        /// Worker threads; 0 (the default) runs on one pool of one thread per core shared by
        /// every such render in the process, so renders from several host threads at once share
        /// the cores; a count gives the render a pool of its own. The image does not depend on it.
        threads: u32 = 0 => {
            doc: "Worker threads (0: a pool of one per core shared by such renders); the image does not depend on it.",
            flag: "threads",
            range: Range::closed(0.0, MLT_MAX_THREADS as f64),
            rule: |_| format!("use 0 for all cores or at most {MLT_MAX_THREADS}"),
        },
        seed: u64 = 0 => {
            doc: "Seed of every random number: equal seeds and settings give equal images.",
            flag: "seed",
        },
        /// Stop after this many seconds; 0 means no limit.
        time_limit_seconds: f64 = 0.0 => {
            doc: "Stop after this many seconds (0: no limit).",
            flag: "time-limit",
            range: Range::closed(0.0, MLT_MAX_TIME_LIMIT_SECONDS),
            rule: |_| format!("it must be 0 (no limit) or a positive number of seconds up to {MLT_MAX_TIME_LIMIT_SECONDS}"),
        },
        /// Metropolis: mutations per pixel; 0 means "until the time limit".
        mutations_per_pixel: u32 = 32 => {
            doc: "Metropolis: mutations per pixel (0: until the time limit).",
            flag: "mutations-per-pixel",
            range: Range::closed(0.0, MLT_MAX_SAMPLES_PER_PIXEL as f64),
            rule: |_| format!("at most {MLT_MAX_SAMPLES_PER_PIXEL} are supported"),
        },
        /// Metropolis: independent samples that seed the chains and start the estimate of the
        /// normalization b (see `normalization_work_fraction`). 0 (the default) sizes the
        /// bootstrap to the render: one sample per `AUTO_BOOTSTRAP_MUTATIONS_PER_SAMPLE`
        /// planned mutations, at least `MIN_AUTO_BOOTSTRAP_SAMPLES`; a render planned by time
        /// alone takes `TIME_LIMITED_BOOTSTRAP_SAMPLES`. `resolved_bootstrap_samples` says
        /// what a render takes.
        bootstrap_samples: u32 = 0 => {
            doc: "Metropolis: samples seeding the chains and the brightness estimate (0: one per 8 planned mutations, at least 65536; 262144 for a render planned by time alone).",
            flag: "bootstrap",
            range: Range::closed(0.0, MLT_MAX_BOOTSTRAP_SAMPLES as f64),
            rule: |_| format!("it must be 0 (automatic) or at most {MLT_MAX_BOOTSTRAP_SAMPLES}"),
        },
        /// Metropolis: number of Markov chains (independent of the thread count).
        chains: u32 = 1024 => {
            doc: "Metropolis: number of Markov chains, at most the bootstrap samples.",
            flag: "chains",
            range: Range::closed(1.0, MLT_MAX_BOOTSTRAP_SAMPLES as f64),
            rule: |s| format!(
                "it must be between 1 and the bootstrap samples ({})",
                s.resolved_bootstrap_samples()
            ),
        },
        /// PSSMLT: probability that a mutation is a large (independent) step.
        large_step_probability: f32 = 0.3 => {
            doc: "PSSMLT: probability of a large (independent) step.",
            flag: "large-step",
            range: Range::UNIT,
            rule: in_unit_interval,
        },
        /// PSSMLT: standard deviation of a small step in primary sample space.
        small_step_sigma: f32 = 0.01 => {
            doc: "PSSMLT: standard deviation of a small step in primary sample space.",
            flag: "small-step",
            range: Range::above(0.0, 1.0),
            rule: |_| "it must be in (0, 1]".into(),
        },
        /// Metropolis: camera samples of the direct pass per chain mutation (both per pixel).
        /// The direct pass path-traces the paths of depth 0 and 1 (emitters seen directly,
        /// direct lighting), which chains render poorly: they spend mutations in proportion to
        /// brightness, on what stratified camera samples get right. The chains render the longer
        /// paths. The two alternate, so a render stopped early keeps the ratio. 0: no direct
        /// pass; the chains render every depth.
        direct_samples_per_mutation: u32 = RenderSettings::DEFAULT_DIRECT_SAMPLES_PER_MUTATION => {
            doc: "Metropolis: path-traced samples of depths 0 and 1 per chain mutation (0: the chains render every depth).",
            flag: "direct-per-mutation",
        },
        /// Path-space MLT: relative probabilities of the bidirectional mutation and of the
        /// lens, caustic and multi-chain perturbations (`Mutation as usize` order). Each step
        /// picks among those the current path admits. The bidirectional weight must be
        /// positive: it alone makes every path reachable. ERPT uses the perturbations' weights
        /// (its chains only perturb).
        mutation_weights: MutationWeights = MutationWeights::default() => {
            doc: "Path-space MLT: relative probabilities of the bidirectional mutation and the lens, caustic and multi-chain perturbations (the first positive).",
            flag: "mutation-weights",
            range: Range::closed(0.0, 1e6),
            rule: |_| "weights must be finite, from 0 to 1e6".into(),
        },
        /// ERPT: perturbations per chain (L). Each camera sample's energy e starts
        /// ⌊e / (L·e_d) + ξ⌋ chains.
        erpt_chain_length: u32 = RenderSettings::DEFAULT_ERPT_CHAIN_LENGTH => {
            doc: "ERPT: perturbations per chain.",
            flag: "erpt-chain-length",
            range: Range::closed(1.0, MLT_MAX_ERPT_CHAIN_LENGTH as f64),
            rule: |_| format!("it must be between 1 and {MLT_MAX_ERPT_CHAIN_LENGTH}"),
        },
        /// ERPT: the energy (luminance) e_d each chain step deposits; 0 picks it so that a
        /// camera sample starts one chain on average (from a pre-pass estimating the mean
        /// energy of a sample: e_d = mean / L). Smaller values start more chains.
        erpt_deposit_energy: f32 = 0.0 => {
            doc: "ERPT: energy (luminance) each chain step deposits (0: one chain per camera sample on average).",
            flag: "erpt-deposit",
            range: Range::closed(0.0, MLT_MAX_ERPT_DEPOSIT_ENERGY as f64),
            rule: |_| format!("it must be 0 (automatic) or a positive number up to {MLT_MAX_ERPT_DEPOSIT_ENERGY:e}"),
        },
        /// Path-space MLT: run a warm-up of about one mutation per pixel with
        /// `mutation_weights`, then adapt each weight to its mutation's acceptance rate there
        /// (within a factor of 8) and run the rest of the render with those weights frozen, on
        /// chains seeded anew (so every chain is a valid Metropolis chain; see
        /// `path_space::chain::adapted_weights`). `RenderStats::mutation_weights` reports them.
        adapt_mutation_weights: bool = false => {
            doc: "Path-space MLT: after a warm-up, weight each mutation by its acceptance rate there.",
            flag: "adapt-mutation-weights",
        },
        /// Path-space MLT and ERPT: perturb directions at diffuse vertices and lights by small
        /// steps in their own (cosine-weighted) sample space instead of within a cone, so the
        /// steps follow the BSDF's shape and its density cancels from the transfer ratio.
        perturb_in_sample_space: bool = false => {
            doc: "Path-space MLT and ERPT: perturb directions in the BSDF's sample space instead of within a cone.",
            flag: "perturb-in-sample-space",
        },
        /// Metropolis and ERPT: the post-process filter for blotchy noise (`crate::filter`):
        /// non-local means guided by per-pixel variances measured from partial images. 0 turns
        /// it off (the default); otherwise the number of partial images the deposits are split
        /// into, from 2 to 32 (8 is a good start; each costs 12 bytes per pixel). The filter
        /// moves energy between pixels, keeping the image's total: it trades a local bias (blur
        /// of what the noise hides) for lower error. `RenderStats::filter` reports what it did.
        filter_buffers: u32 = 0 => {
            doc: "Metropolis and ERPT: partial images of the post-process noise filter (0: no filter; 8 is a good start).",
            flag: "filter-buffers",
            range: Range::closed(MLT_MIN_FILTER_BUFFERS as f64, MLT_MAX_FILTER_BUFFERS as f64).or(0.0),
            rule: |_| format!("it must be 0 (no filter) or from {MLT_MIN_FILTER_BUFFERS} to {MLT_MAX_FILTER_BUFFERS}"),
        },
        /// The filter's strength k: patch differences up to about k standard deviations count
        /// as noise. Higher smooths more (more bias, less noise).
        filter_strength: f32 = RenderSettings::DEFAULT_FILTER_STRENGTH => {
            doc: "The filter's strength (higher smooths more).",
            flag: "filter-strength",
            range: Range::above(0.0, MLT_MAX_FILTER_STRENGTH as f64),
            rule: |_| format!("it must be positive, up to {MLT_MAX_FILTER_STRENGTH}"),
        },
        /// The filter's search radius in pixels: each pixel averages pixels up to this far.
        filter_radius: u32 = RenderSettings::DEFAULT_FILTER_RADIUS => {
            doc: "The filter's search radius in pixels.",
            flag: "filter-radius",
            range: Range::closed(1.0, MLT_MAX_FILTER_RADIUS as f64),
            rule: |_| format!("it must be from 1 to {MLT_MAX_FILTER_RADIUS} pixels"),
        },
        /// Metropolis: the share of the rays spent on independent samples of the chains' target
        /// (path-tracer samples for PSSMLT, BDPT samples with all strategies for the others),
        /// drawn alongside the chains to go on estimating the normalization b, which sets the
        /// image's brightness. The image is scaled by the final estimate, over the bootstrap,
        /// these samples and (PSSMLT, PSSMLT over BDPT) the chains' large steps, so its
        /// brightness error shrinks with the render's length (`integrators::mlt::normalization`).
        /// From 0 (no such samples: the bootstrap and the large steps alone) to 0.9.
        /// `RenderStats::normalization` reports the estimate's own standard error.
        normalization_work_fraction: f32 = RenderSettings::DEFAULT_NORMALIZATION_WORK_FRACTION => {
            doc: "Metropolis: share of the rays spent on samples that go on estimating the brightness (0: the bootstrap and large steps alone).",
            flag: "normalization-fraction",
            range: Range::closed(0.0, MLT_MAX_NORMALIZATION_WORK_FRACTION as f64),
            rule: |_| format!("it must be from 0 to {MLT_MAX_NORMALIZATION_WORK_FRACTION}"),
        },
        /// Spectral transport: each camera path carries `WAVELENGTHS` (4) wavelengths drawn by
        /// hero-wavelength sampling instead of RGB; RGB colours become smooth spectra (lights
        /// times D65) and the film gets CIE XYZ converted to linear sRGB. Dispersive
        /// dielectrics (`Material::abbe_number`) split light by wavelength only in this mode.
        spectral: bool = false => {
            doc: "Spectral transport: four wavelengths per path instead of RGB; dispersive glass splits light.",
            flag: "spectral",
        },
        roulette_start_depth: u32 = 3 => {
            doc: "Path tracing and PSSMLT: scattering vertices after which Russian roulette may end a path.",
            flag: "roulette-start-depth",
            range: Range::closed(0.0, MLT_MAX_DEPTH_LIMIT as f64),
            rule: |_| format!("it must be at most {MLT_MAX_DEPTH_LIMIT}"),
        },
        roulette_max_survival: f32 = 0.95 => {
            doc: "Path tracing and PSSMLT: the highest probability with which Russian roulette lets a path go on.",
            flag: "roulette-max-survival",
            range: Range::above(0.0, 1.0),
            rule: |_| "it must be in (0, 1]".into(),
        },
        /// Path tracing reads textures at full resolution, as the other algorithms do. By
        /// default its camera paths filter the textures they meet over their pixel's
        /// footprint (mip-mapped lookups at the level of detail of a ray cone; see
        /// `integrators::path::RayCone`) until their first diffuse or glossy bounce, so that
        /// a distant high-resolution texture does not alias; then its image converges to the
        /// other algorithms' except where a texture has detail below a pixel, which it shows
        /// averaged.
        full_resolution_textures: bool = false => {
            doc: "Path tracing: read textures at full resolution, as the other algorithms do (by default camera paths filter them over the pixel's footprint, mip-mapped, until their first diffuse or glossy bounce).",
            flag: "full-resolution-textures",
        },
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

    /// Checks every setting against its declared range, then the rules between settings.
    pub fn validate(&self) -> Result<()> {
        self.check_ranges(<Self as crate::params::Parameters>::PREFIX)?;
        let t = self.time_limit_seconds;
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
        } else if self.samples_per_pixel == 0 && t == 0.0 {
            return Err(Error::invalid(
                "settings.samples_per_pixel is 0 and there is no time limit; the render would never end",
            ));
        }
        let bootstrap = self.resolved_bootstrap_samples();
        if self.chains > bootstrap {
            return Err(Error::invalid(format!(
                "settings.chains is {}; it must be between 1 and the bootstrap samples ({bootstrap})",
                self.chains
            )));
        }
        if self.mutation_weights.0[0] <= 0.0 {
            return Err(Error::invalid(
                "settings.mutation_weights[0] (the bidirectional mutation) is 0; it must be positive, or the chains cannot reach every path",
            ));
        }
        let buffers = self.filter_buffers;
        if buffers != 0 && !(self.algorithm.is_metropolis() || self.algorithm == Algorithm::Erpt) {
            return Err(Error::invalid(format!(
                "settings.filter_buffers is {buffers} but the algorithm is {:?}; the filter is for Metropolis and ERPT images (set it to 0)",
                self.algorithm
            )));
        }
        Ok(())
    }

    /// The path tracer's Russian roulette.
    pub(crate) fn roulette(&self) -> Roulette {
        Roulette {
            start_depth: self.roulette_start_depth,
            max_survival: self.roulette_max_survival,
        }
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
