//! Primary-sample-space MLT (Kelemen et al. 2002) over the path tracer.
//!
//! 1. Bootstrap: N independent samples estimate b = ∫ luminance(f) over primary sample space.
//! 2. Chains start from bootstrap samples resampled in proportion to their luminance, which
//!    removes start-up bias up to the resampling's own accuracy.
//! 3. Each mutation splats the proposal with weight a and the current state with 1 − a
//!    (expected-value splatting), each as f / luminance(f).
//! 4. The image is the splat sum × b / (mutations per pixel); b is refined with the large
//!    steps, which are independent samples of the same integral.
//!
//! Determinism: chains run in rounds; within a round they run in parallel, each recording
//! its splats, which are added to the film in chain order after the round.

use super::acceptance;
use super::pss::PssSampler;
use crate::film::Film;
use crate::integrators::path::PathTracer;
use crate::integrators::{SampleCounters, Splat};
use crate::render::Control;
use crate::sampling::{Distribution1D, Rng, Sampler};
use crate::scene::{CameraModel, luminance};
use glam::Vec3A;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// Target mutations per round over all chains: bounds the splat memory and how long a stop
/// takes.
const MUTATIONS_PER_ROUND: u64 = 1 << 18;
/// Stream offset that keeps the chains' start selection apart from the bootstrap streams.
const CHAIN_SELECTION_STREAM: u64 = 0x5eed_c4a1_0000_0000;

#[derive(Clone, Copy, Debug)]
pub struct PssmltSettings {
    pub mutations_per_pixel: u32,
    pub bootstrap_samples: u32,
    pub chains: u32,
    pub large_step_probability: f32,
    pub small_step_sigma: f32,
    pub seed: u64,
}

/// What a PSSMLT render measured.
#[derive(Clone, Copy, Debug, Default)]
pub struct PssmltOutcome {
    pub mutations: u64,
    pub accepted: u64,
    /// The normalization b = ∫ luminance(f) used for the image.
    pub normalization: f64,
}

struct Chain {
    sampler: PssSampler,
    current: Vec3A,
    current_luminance: f32,
    current_pixel: u32,
    remaining: u64,
    splats: Vec<Splat>,
    large_step_sum: f64,
    large_steps: u64,
    accepted: u64,
    mutations: u64,
    rays: u64,
}

/// One evaluation of the estimator at the sampler's state: (contribution, pixel).
#[inline]
fn evaluate(
    tracer: &PathTracer,
    camera: &CameraModel,
    sampler: &mut PssSampler,
    rays: &mut u64,
) -> (Vec3A, u32) {
    let [u, v] = sampler.uniform2();
    let x = (u * camera.width as f32).min(camera.width as f32 - 1.0);
    let y = (v * camera.height as f32).min(camera.height as f32 - 1.0);
    let lens = sampler.uniform2();
    let (origin, direction) = camera.generate_ray(x, y, lens);
    let l = tracer.radiance(origin, direction, sampler, rays);
    let pixel = y as u32 * camera.width + x as u32;
    let l = if l.is_finite() { l } else { Vec3A::ZERO };
    (l, pixel)
}

pub(crate) fn run(
    tracer: &PathTracer,
    camera: &CameraModel,
    settings: &PssmltSettings,
    film: &mut Film,
    control: &Control,
) -> PssmltOutcome {
    let dimensions = 4 + 7 * (tracer.max_depth as usize + 1);
    // 1. Bootstrap, in fixed chunks that each reuse one sampler (no allocation per sample).
    const BOOTSTRAP_CHUNK: u64 = 1024;
    let bootstrap_count = settings.bootstrap_samples as u64;
    let mut bootstrap = vec![(0.0f32, 0u64); bootstrap_count as usize];
    bootstrap
        .par_chunks_mut(BOOTSTRAP_CHUNK as usize)
        .enumerate()
        .for_each(|(chunk, out)| {
            let mut sampler = PssSampler::new(
                settings.seed,
                0,
                settings.large_step_probability,
                settings.small_step_sigma,
                dimensions,
            );
            for (i, slot) in out.iter_mut().enumerate() {
                sampler.restart(settings.seed, chunk as u64 * BOOTSTRAP_CHUNK + i as u64);
                let mut rays = 0;
                let l = evaluate(tracer, camera, &mut sampler, &mut rays).0;
                *slot = (luminance(l), rays);
            }
        });
    let weights: Vec<f32> = bootstrap.iter().map(|&(w, _)| w).collect();
    let bootstrap_sum: f64 = weights.iter().map(|&w| w as f64).sum();
    control
        .rays
        .fetch_add(bootstrap.iter().map(|&(_, r)| r).sum(), Ordering::Relaxed);
    drop(bootstrap);
    if bootstrap_sum <= 0.0 {
        return PssmltOutcome::default();
    }
    let distribution = Distribution1D::new(&weights);

    // 2. Chains from resampled bootstrap paths.
    let pixels = camera.width as u64 * camera.height as u64;
    // Without a mutation count the render runs until the time limit stops it.
    let total = if settings.mutations_per_pixel > 0 {
        settings.mutations_per_pixel as u64 * pixels
    } else {
        u64::MAX / 4
    };
    let chain_count = (settings.chains as u64).min(total).max(1);
    let per_round = (MUTATIONS_PER_ROUND / chain_count).max(1);
    let mut chains: Vec<Chain> = (0..chain_count)
        .into_par_iter()
        .map(|c| {
            let mut select = Rng::new(settings.seed, CHAIN_SELECTION_STREAM + c);
            let (index, _, _) = distribution.sample_discrete(select.uniform());
            let mut sampler = PssSampler::new(
                settings.seed,
                index as u64,
                settings.large_step_probability,
                settings.small_step_sigma,
                dimensions,
            );
            let mut rays = 0;
            let (current, current_pixel) = evaluate(tracer, camera, &mut sampler, &mut rays);
            Chain {
                sampler,
                current,
                current_luminance: luminance(current),
                current_pixel,
                remaining: total / chain_count + u64::from(c < total % chain_count),
                splats: Vec::with_capacity(2 * per_round as usize),
                large_step_sum: 0.0,
                large_steps: 0,
                accepted: 0,
                mutations: 0,
                rays,
            }
        })
        .collect();

    // 3. Rounds of mutations.
    while chains.iter().any(|c| c.remaining > 0) && !control.should_stop() {
        chains.par_iter_mut().for_each(|chain| {
            chain.splats.clear();
            let steps = chain.remaining.min(per_round);
            for _ in 0..steps {
                mutate(tracer, camera, chain);
            }
            chain.remaining -= steps;
            control.samples_done.fetch_add(steps, Ordering::Relaxed);
        });
        for chain in &chains {
            film.add_splats(&chain.splats, 0);
        }
    }

    // 4. Normalization.
    let mut outcome = PssmltOutcome::default();
    let mut luminance_sum = bootstrap_sum;
    let mut independent_samples = settings.bootstrap_samples as u64;
    let mut rays = 0;
    for chain in &chains {
        luminance_sum += chain.large_step_sum;
        independent_samples += chain.large_steps;
        outcome.mutations += chain.mutations;
        outcome.accepted += chain.accepted;
        rays += chain.rays;
    }
    control.rays.fetch_add(rays, Ordering::Relaxed);
    outcome.normalization = luminance_sum / independent_samples as f64;
    if outcome.mutations > 0 {
        film.set_splat_scale(outcome.normalization * pixels as f64 / outcome.mutations as f64);
    }
    outcome
}

#[inline]
fn mutate(tracer: &PathTracer, camera: &CameraModel, chain: &mut Chain) {
    let mut counters = SampleCounters::default();
    chain.sampler.start_iteration();
    let (proposal, proposal_pixel) =
        evaluate(tracer, camera, &mut chain.sampler, &mut counters.rays);
    let proposal_luminance = luminance(proposal);
    if chain.sampler.is_large_step() {
        chain.large_step_sum += proposal_luminance as f64;
        chain.large_steps += 1;
    }
    let a = acceptance(chain.current_luminance, proposal_luminance, 1.0);
    if a > 0.0 {
        chain.splats.push(Splat {
            pixel: proposal_pixel,
            value: proposal * (a / proposal_luminance),
        });
    }
    if a < 1.0 && chain.current_luminance > 0.0 {
        chain.splats.push(Splat {
            pixel: chain.current_pixel,
            value: chain.current * ((1.0 - a) / chain.current_luminance),
        });
    }
    if chain.sampler.decision() < a {
        chain.current = proposal;
        chain.current_luminance = proposal_luminance;
        chain.current_pixel = proposal_pixel;
        chain.sampler.accept();
        chain.accepted += 1;
    } else {
        chain.sampler.reject();
    }
    chain.mutations += 1;
    chain.rays += counters.rays;
}
