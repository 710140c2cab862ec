//! Energy redistribution path tracing (Cline, Talbot & Egbert, SIGGRAPH 2005).
//!
//! Every pixel takes `samples_per_pixel` BDPT camera samples. Each strategy (s, t) of a
//! sample that contributes is an initial sample: the path the strategy built (an explicit
//! vertex list, `Bdpt::strategy_path`) with the energy e = luminance of its MIS-weighted
//! contribution. It starts N = ⌊e / (L·e_d) + ξ⌋ Metropolis chains of L perturbations (lens,
//! caustic and multi-chain: Veach's, accepted with min(1, ratio) for the target f =
//! luminance of the measurement contribution). After each step a chain deposits energy e_d
//! at its state's pixel, coloured by the state's RGB contribution scaled to luminance e_d
//! (expected-value deposits: a·e_d at the proposal and (1 − a)·e_d at the current state).
//!
//! # Why the image is unbiased
//!
//! Cline et al.'s argument, in path space. Write an initial sample as energy e at path x.
//! BDPT's strategy s puts, in expectation, energy density g_s(x) = w_s(x)·f(x) on path
//! space (its MIS-weighted contribution times its sampling density), and Σ_s g_s = f: the
//! expected energy density of all initial samples of one camera sample per pixel is f
//! itself, restricted to each pixel's paths exactly as BDPT's estimate of the image is.
//! Energy e at x becomes, in expectation, E[N]·L·e_d = e at the chains' states. Each step's
//! kernel K (a mixture of perturbations, picked with probabilities that depend only on the
//! path's pattern of specular vertices, which perturbations keep) satisfies detailed balance
//! with respect to f, so f is invariant: ∫ f(x) K(x→y) dx = f(y). By linearity, the states
//! after k steps of chains started from energy with density f carry energy with density f
//! again, for every k: the expected deposits are Σ_k (1/L)·∫ f(x) K^k(x→y) dx = f(y). Nothing
//! asks the chains to be ergodic or near equilibrium; the kernel only has to leave f
//! invariant. N depending on e is what makes the chains carry e on average, and the
//! per-deposit colour F(y)/f(y) turns the luminance density back into RGB: the expected image
//! is BDPT's, i.e. the path tracer's.
//!
//! A stopped render keeps this: a chain cut short deposits its remaining energy at its
//! current state (whose energy density is already f), and unstarted chains deposit theirs at
//! the initial path (L = 0). The pass of camera samples under way is finished that way, so
//! every pixel has as many camera samples as every other.
//!
//! # Determinism
//!
//! Each (pixel, sample) has its own random stream for its BDPT sample and its chains, and
//! deposits go to per-pixel fixed-point (signed integer) accumulators, whose sums do not depend on
//! the order of addition: the image is the same for any thread count. Deposits are rounded to
//! 2⁻²⁴ e_d; summed over a chain's consecutive deposits in the same pixel before rounding.
//!
//! # Deposit energy
//!
//! `deposit_energy` 0 picks e_d so that a camera sample starts one chain on average: a
//! pre-pass of independent BDPT samples (its own random streams, so e_d is independent of
//! the render's samples and the estimate stays unbiased given it) estimates the mean energy
//! ē of a camera sample (its strategies summed), and e_d = ē / L. The pre-pass takes as many
//! samples as the render (in whole chunks, at least 1024), at most 2^14: a small render
//! does not pay for a pre-pass a thousand times its own size.

use super::perturbation::{self, PerturbationSizes, RandomKernel};
use super::{PathSpace, PathVertex};
use crate::control::Control;
use crate::film::Film;
use crate::integrators::bdpt::{Bdpt, BdptScratch, CONNECTION_STREAM};
use crate::integrators::camera_samples::{PassSchedule, PixelSamples};
use crate::integrators::mlt::acceptance;
use crate::integrators::mlt::driver::{MetropolisOutcome, MutationCounts, MutationWeights};
use crate::integrators::mlt::normalization::NormalizationStats;
use crate::integrators::mlt::primary_space::PathSample;
use crate::integrators::{PixelEstimator, SampleCounters};
use crate::sampling::{PixelSampler, Rng, Sampler};
use crate::scene::CameraModel;
use crate::spectrum::Spectrum;
use rayon::prelude::*;
use std::sync::atomic::{AtomicI64, Ordering};

/// Stream offset of the pre-pass.
const PREPASS_STREAM: u64 = 0x5eed_e398_0000_0000;
/// Mixed into the seed of the (pixel, sample) streams, so an ERPT render's camera samples
/// are not BDPT's with the same seed.
const SEED_SALT: u64 = 0xe397_5a17_0000_0001;
/// Salt of the hash that assigns camera samples to the filter's partial images.
const BUFFER_SALT: u64 = 0xe397_b0ff_0000_0002;
/// Most and fewest camera samples of the pre-pass that estimates the mean energy per sample
/// (`prepass_samples`), split into `PREPASS_CHUNKS` parallel work units: a fixed number, so
/// the pre-pass allocates the same whatever its size.
const MAX_PREPASS_SAMPLES: u64 = 1 << 14;
const MIN_PREPASS_SAMPLES: u64 = 1 << 10;
const PREPASS_CHUNKS: u64 = 64;

/// The pre-pass's samples for a render of `samples_per_pixel` (0: until stopped) over
/// `pixels`: as many as the render takes, within the bounds, in whole chunks.
fn prepass_samples(pixels: u64, samples_per_pixel: u32) -> u64 {
    let render = if samples_per_pixel == 0 {
        MAX_PREPASS_SAMPLES
    } else {
        pixels.saturating_mul(samples_per_pixel as u64)
    };
    render
        .clamp(MIN_PREPASS_SAMPLES, MAX_PREPASS_SAMPLES)
        .next_multiple_of(PREPASS_CHUNKS)
}
/// Target camera samples per pass over the image (after the first).
const PASS_SAMPLES: u64 = 1 << 15;
/// Rows per work unit.
pub(crate) const BAND_ROWS: u32 = 2;
/// Fixed-point units per e_d of the accumulators, at least: the unit is the power of two at
/// or below e_d / 2^24 (never finer than the film's grid), so that the sums convert to the
/// film's fixed point exactly and jobs of a split render add up to the bits of one render.
const FIXED_POINT_BITS: i32 = 24;

/// The settings of an ERPT render.
pub(crate) struct ErptSettings {
    /// 0: until stopped.
    pub samples_per_pixel: u32,
    /// At least 1 (the render's settings are validated).
    pub chain_length: u32,
    /// 0: automatic (see the module documentation).
    pub deposit_energy: f32,
    pub seed: u64,
    pub weights: MutationWeights,
    /// Perturb directions in the BSDF's sample space (`perturbation` module docs).
    pub perturb_in_sample_space: bool,
    /// The bands of rows this run samples (a job's share of a split render).
    pub share: crate::control::JobShare,
}

/// Per-work-unit memory, made once per render.
struct UnitScratch {
    bdpt: BdptScratch,
    initial: Vec<PathVertex>,
    current: Vec<PathVertex>,
    proposal: Vec<PathVertex>,
    counts: MutationCounts,
    /// Camera samples, mutations and acceptances of the unit's last pass.
    taken: u64,
    mutations: u64,
    accepted: u64,
}

/// Deposits of one chain not yet added to the accumulators: consecutive deposits in the
/// same pixel are summed first.
struct Pending {
    pixel: u32,
    /// The partial image of the post-process filter the deposits also go to.
    buffer: usize,
    value: [f64; 3],
}

struct Redistributor<'a> {
    bdpt: &'a Bdpt<'a>,
    space: PathSpace<'a>,
    sizes: PerturbationSizes,
    perturb_in_sample_space: bool,
    weights: MutationWeights,
    chain_length: u32,
    deposit_energy: f32,
    /// Fixed-point sums per pixel, partial image (`buffers` per pixel) and channel.
    sums: &'a [[AtomicI64; 3]],
    buffers: usize,
    scale: f64,
}

/// The colour of a contribution scaled to unit luminance.
#[inline]
fn unit_colour(value: Spectrum) -> Option<Spectrum> {
    let luminance = PathSample::usable_luminance(value);
    (luminance > 0.0).then(|| value / luminance)
}

impl Redistributor<'_> {
    fn flush(&self, pending: &mut Pending) {
        let sums = &self.sums[pending.pixel as usize * self.buffers + pending.buffer];
        for (sum, value) in sums.iter().zip(pending.value) {
            // `as` saturates; so does the sum (only reachable with an absurdly small e_d).
            // Signed: in a spectral render a path's colour at few wavelengths can lie outside
            // sRGB's gamut, with a negative channel that the other deposits make up for.
            let units = (value * self.scale).round() as i64;
            if units != 0 {
                let _ = sum.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |s| {
                    Some(s.saturating_add(units))
                });
            }
        }
        pending.value = [0.0; 3];
    }

    #[inline]
    fn deposit(&self, pending: &mut Pending, pixel: u32, value: Spectrum) {
        if pixel != pending.pixel {
            self.flush(pending);
            pending.pixel = pixel;
        }
        for c in 0..3 {
            pending.value[c] += value[c] as f64;
        }
    }

    /// Runs `chains` chains of L perturbations from path `initial` (contribution colour
    /// `colour` at unit luminance, in `pixel`) in `space` (the sample's wavelengths, which
    /// the perturbations keep). On a stop, the remaining energy goes to the current state.
    /// Returns the mutations made.
    #[allow(clippy::too_many_arguments)]
    fn redistribute(
        &self,
        space: &PathSpace,
        chains: u64,
        pixel: u32,
        buffer: usize,
        colour: Spectrum,
        rng: &mut Rng,
        scratch: &mut UnitScratch,
        rays: &mut u64,
        control: &Control,
    ) -> (u64, u64) {
        let e_d = self.deposit_energy;
        let length = self.chain_length;
        let mut pending = Pending {
            pixel,
            buffer,
            value: [0.0; 3],
        };
        let admits = perturbation::applicable(space, &scratch.initial);
        let [_, lens, caustic, multi] = self.weights.0;
        // Perturbations keep the pattern of specular vertices, so these probabilities are
        // the same at every state of the chain (and at its proposals).
        let choice = [
            if admits.lens { lens } else { 0.0 },
            if admits.caustic { caustic } else { 0.0 },
            if admits.lens { 0.0 } else { multi },
        ];
        let total: f32 = choice.iter().sum();
        let (mut mutations, mut accepted) = (0, 0);
        for chain in 0..chains {
            if total <= 0.0 || control.should_stop() {
                // No mutation applies (the kernel is the identity), or the render stops:
                // the energy stays at the initial path.
                let rest = (chains - chain) as f32 * length as f32 * e_d;
                self.deposit(&mut pending, pixel, colour * rest);
                break;
            }
            scratch.current.clear();
            scratch.current.extend_from_slice(&scratch.initial);
            let mut current_pixel = pixel;
            // The state's wavelengths: the sample's, then those of each accepted proposal.
            let mut current_space = *space;
            let mut current_deposit = colour * e_d;
            for step in 0..length {
                if step % 16 == 15 && control.should_stop() {
                    let rest = (length - step) as f32;
                    self.deposit(&mut pending, current_pixel, current_deposit * rest);
                    break;
                }
                let mut u = rng.uniform() * total;
                let pick = (0..3)
                    .find(|&m| {
                        u -= choice[m];
                        u < 0.0 && choice[m] > 0.0
                    })
                    .unwrap_or_else(|| (0..3).rev().find(|&m| choice[m] > 0.0).unwrap_or(0));
                let mut kernel = RandomKernel {
                    sizes: &self.sizes,
                    in_sample_space: self.perturb_in_sample_space,
                    rng,
                };
                let (x, y) = (&scratch.current, &mut scratch.proposal);
                let proposal = match pick {
                    0 => perturbation::lens(&current_space, &mut kernel, false, x, y, rays),
                    1 => perturbation::caustic(&current_space, &mut kernel, x, y, rays),
                    _ => perturbation::lens(&current_space, &mut kernel, true, x, y, rays),
                };
                scratch.counts.proposed[pick + 1] += 1;
                mutations += 1;
                let proposal = proposal.and_then(|p| {
                    let colour = unit_colour(p.value)?;
                    let a = acceptance(1.0, 1.0, p.ratio);
                    (a > 0.0).then_some((a, colour * e_d, p.pixel, p.channels))
                });
                let a = proposal.map_or(0.0, |(a, ..)| a);
                if let Some((a, deposit, pixel, _)) = proposal {
                    self.deposit(&mut pending, pixel, deposit * a);
                }
                if a < 1.0 {
                    self.deposit(&mut pending, current_pixel, current_deposit * (1.0 - a));
                }
                if let Some((a, deposit, pixel, channels)) = proposal
                    && rng.uniform() < a
                {
                    std::mem::swap(&mut scratch.current, &mut scratch.proposal);
                    current_space = space.with_channels(channels);
                    current_pixel = pixel;
                    current_deposit = deposit;
                    accepted += 1;
                    scratch.counts.accepted[pick + 1] += 1;
                }
            }
        }
        self.flush(&mut pending);
        (mutations, accepted)
    }

    /// One camera sample through film position (x, y) and the chains of its strategies,
    /// whose deposits also go to partial image `buffer`. The camera sample reads `sampler`,
    /// the chains `rng` (a Markov chain's steps need independent numbers). Returns
    /// (mutations, accepted, whether the sample was valid).
    #[allow(clippy::too_many_arguments)]
    fn sample(
        &self,
        x: f32,
        y: f32,
        buffer: usize,
        sampler: &mut PixelSampler,
        rng: &mut Rng,
        scratch: &mut UnitScratch,
        counters: &mut SampleCounters,
        control: &Control,
    ) -> (u64, u64, bool) {
        let bdpt = self.bdpt;
        let camera = self.space.camera;
        let max_depth = bdpt.max_depth as usize;
        let (n_camera, n_light) = bdpt.trace_subpaths(
            camera,
            x,
            y,
            max_depth + 2,
            max_depth + 1,
            sampler,
            &mut scratch.bdpt,
            counters,
        );
        let space = self.space.with_channels(scratch.bdpt.drawn_channels());
        let per_chain = self.chain_length as f64 * self.deposit_energy as f64;
        let (mut mutations, mut accepted, mut valid) = (0, 0, true);
        for t in 1..=n_camera {
            for s in 0..=n_light {
                let vertices = s + t;
                if vertices < 2 + bdpt.min_depth as usize
                    || vertices - 2 > max_depth
                    || (s == 1 && t == 1)
                {
                    continue;
                }
                sampler.start_stream(CONNECTION_STREAM);
                let Some(c) = bdpt.connect(camera, &mut scratch.bdpt, s, t, sampler, counters)
                else {
                    continue;
                };
                let Some(colour) = unit_colour(c.value) else {
                    valid &= c.value.is_finite();
                    continue;
                };
                let energy = PathSample::usable_luminance(c.value) as f64;
                bdpt.strategy_path(&scratch.bdpt, s, t, &mut scratch.initial);
                let chains = (energy / per_chain + rng.uniform() as f64).floor() as u64;
                if chains == 0 {
                    continue;
                }
                let pixel = space.pixel(&scratch.initial).or(c.splat_pixel);
                let Some(pixel) = pixel else {
                    continue;
                };
                let (m, a) = self.redistribute(
                    &space,
                    chains,
                    pixel,
                    buffer,
                    colour,
                    rng,
                    scratch,
                    &mut counters.rays,
                    control,
                );
                mutations += m;
                accepted += a;
            }
        }
        (mutations, accepted, valid)
    }
}

/// The mean luminance of a BDPT camera sample's strategies, summed, over independent film
/// positions: what the automatic deposit energy is made from.
fn mean_sample_energy(
    bdpt: &Bdpt,
    camera: &CameraModel,
    samples: u64,
    seed: u64,
    control: &Control,
) -> f64 {
    let chunk_size = samples / PREPASS_CHUNKS;
    let sums: Vec<(f64, u64)> = (0..PREPASS_CHUNKS)
        .into_par_iter()
        .map(|chunk| {
            let mut scratch = bdpt.scratch();
            let mut counters = SampleCounters::default();
            let mut sum = 0.0;
            for i in chunk * chunk_size..(chunk + 1) * chunk_size {
                let mut rng = Rng::new(seed, PREPASS_STREAM + i);
                let [u, v] = rng.uniform2();
                let (x, y) = (u * camera.width as f32, v * camera.height as f32);
                bdpt.sample_all_strategies(
                    camera,
                    x,
                    y,
                    &mut rng,
                    &mut scratch,
                    &mut counters,
                    |_, _, c| sum += PathSample::usable_luminance(c.value) as f64,
                );
            }
            (sum, counters.rays)
        })
        .collect();
    let rays: u64 = sums.iter().map(|&(_, r)| r).sum();
    control.rays.fetch_add(rays, Ordering::Relaxed);
    sums.iter().map(|&(s, _)| s).sum::<f64>() / (PREPASS_CHUNKS * chunk_size) as f64
}

/// Runs ERPT over the film. `outcome.normalization` reports the deposit energy used.
pub(crate) fn run(
    bdpt: &Bdpt,
    camera: &CameraModel,
    settings: &ErptSettings,
    film: &mut Film,
    control: &Control,
) -> MetropolisOutcome {
    let (width, height) = (camera.width, camera.height);
    let pixels = width as usize * height as usize;
    let chain_length = settings.chain_length;
    let deposit_energy = if settings.deposit_energy > 0.0 {
        settings.deposit_energy
    } else {
        let samples = prepass_samples(pixels as u64, settings.samples_per_pixel);
        let mean = mean_sample_energy(bdpt, camera, samples, settings.seed, control);
        let e_d = (mean / chain_length as f64) as f32;
        if e_d > 0.0 && e_d.is_finite() {
            e_d
        } else {
            1.0
        }
    };
    // With the filter on, each camera sample's chains also deposit into one partial image
    // (by a hash of pixel and sample, so every partial sees every region); the film's
    // splats are the partials' sums.
    let buffers = film.filter_buffers().max(1);
    let grid_log2 = ((deposit_energy as f64).log2().floor() as i32 - FIXED_POINT_BITS)
        .max(film.scene_grid_log2());
    let sums: Vec<[AtomicI64; 3]> = (0..pixels * buffers).map(|_| Default::default()).collect();
    let redistributor = Redistributor {
        bdpt,
        space: PathSpace {
            scene: bdpt.scene,
            camera,
            // Each camera sample's chains carry the wavelengths it drew (`sample`).
            channels: crate::spectral::Channels::Rgb,
        },
        sizes: PerturbationSizes::for_image(width, height),
        perturb_in_sample_space: settings.perturb_in_sample_space,
        weights: settings.weights,
        chain_length,
        deposit_energy,
        sums: &sums,
        buffers,
        scale: 2f64.powi(-grid_log2),
    };
    let bands = height.div_ceil(BAND_ROWS);
    let max_vertices = bdpt.max_depth as usize + 2;
    let mut units: Vec<UnitScratch> = (0..bands)
        .map(|_| UnitScratch {
            bdpt: bdpt.scratch(),
            initial: Vec::with_capacity(max_vertices),
            current: Vec::with_capacity(max_vertices),
            proposal: Vec::with_capacity(max_vertices),
            counts: MutationCounts::default(),
            taken: 0,
            mutations: 0,
            accepted: 0,
        })
        .collect();
    let seed = settings.seed ^ SEED_SALT;
    let mut outcome = MetropolisOutcome {
        normalization: NormalizationStats {
            value: deposit_energy as f64,
            ..Default::default()
        },
        ..Default::default()
    };
    // The schedule's first pass takes one sample per pixel, later ones up to a batch. A
    // pass always completes here, so every pixel has the same number of camera samples and
    // the splat normalization is exact; once the render stops, the rest of the pass only
    // takes the BDPT samples and leaves their energy where it is (chains of length 0),
    // which bounds how long a stop takes by one pass of camera samples.
    let mut schedule = PassSchedule::new(settings.samples_per_pixel, pixels as u64, PASS_SAMPLES);
    let samples = PixelSamples { seed, width };
    let mut samples_taken = 0u64;
    while let Some(indices) = schedule.next_pass(u32::MAX, control) {
        units.par_iter_mut().enumerate().for_each(|(band, unit)| {
            unit.taken = 0;
            unit.mutations = 0;
            unit.accepted = 0;
            if !settings.share.owns(band as u64) {
                return;
            }
            let mut counters = SampleCounters::default();
            let (mut taken, mut mutations, mut accepted, mut invalid) = (0, 0, 0, 0);
            let first_row = band as u32 * BAND_ROWS;
            for y in first_row..(first_row + BAND_ROWS).min(height) {
                for x in 0..width {
                    for mut sample in samples.of_pixel(x, y, indices.clone()) {
                        let buffer = if buffers > 1 {
                            let mut hash = Rng::for_pixel_sample(
                                seed ^ BUFFER_SALT,
                                sample.pixel,
                                sample.index as u64,
                            );
                            hash.next_u32() as usize % buffers
                        } else {
                            0
                        };
                        let mut chain_rng =
                            Rng::for_pixel_sample(seed, sample.pixel, sample.index as u64);
                        let (m, a, valid) = redistributor.sample(
                            sample.x,
                            sample.y,
                            buffer,
                            &mut sample.sampler,
                            &mut chain_rng,
                            unit,
                            &mut counters,
                            control,
                        );
                        mutations += m;
                        accepted += a;
                        invalid += !valid as u64;
                        taken += 1;
                    }
                }
            }
            control.samples_done.fetch_add(taken, Ordering::Relaxed);
            control
                .mutations_done
                .fetch_add(mutations, Ordering::Relaxed);
            control.rays.fetch_add(counters.rays, Ordering::Relaxed);
            control.invalid.fetch_add(invalid, Ordering::Relaxed);
            unit.taken = taken;
            unit.mutations = mutations;
            unit.accepted = accepted;
        });
        for unit in &units {
            samples_taken += unit.taken;
            outcome.mutations += unit.mutations;
            outcome.accepted += unit.accepted;
        }
    }
    for unit in &units {
        outcome.mutation_counts.add(&unit.counts);
    }
    outcome.mutation_weights = settings.weights;
    // The film divides splats by (samples taken / pixels): one camera sample per pixel.
    let load =
        |s: &[AtomicI64; 3]| -> [i64; 3] { std::array::from_fn(|c| s[c].load(Ordering::Relaxed)) };
    let totals = sums.chunks_exact(buffers).map(|pixel| {
        // Integer sums first, so the total does not depend on the number of partials.
        std::array::from_fn(|c| {
            pixel
                .iter()
                .map(|s| s[c].load(Ordering::Relaxed))
                .fold(0i64, i64::saturating_add)
        })
    });
    let mut partials = sums.iter().map(load);
    let partials = (buffers > 1).then_some(&mut partials as &mut dyn Iterator<Item = [i64; 3]>);
    film.add_integer_splat_sums(totals, partials, grid_log2, samples_taken);
    outcome
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prepass_is_as_large_as_the_render_within_bounds() {
        // A 4 × 4 thumbnail at 3 spp: the fewest, not 2^14.
        assert_eq!(prepass_samples(16, 3), MIN_PREPASS_SAMPLES);
        assert_eq!(prepass_samples(40 * 30, 2), 2432);
        assert_eq!(prepass_samples(1920 * 1080, 16), MAX_PREPASS_SAMPLES);
        // Until stopped, or more samples than a u64 holds: the most.
        assert_eq!(prepass_samples(16, 0), MAX_PREPASS_SAMPLES);
        assert_eq!(prepass_samples(u64::MAX, 5), MAX_PREPASS_SAMPLES);
    }
}
