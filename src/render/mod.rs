//! Rendering: the driver that runs an integrator over the film in parallel, with progress
//! reporting, cancellation and a time limit (`render`). What a render is asked for and its
//! validation are in `settings`, the proof that a request was checked where it entered in
//! `request`, and what a render reports in `stats`.

pub mod jobs;
mod request;
mod settings;
mod stats;

pub use settings::{
    Algorithm, MLT_MAX_BOOTSTRAP_SAMPLES, MLT_MAX_DEPTH_LIMIT, MLT_MAX_ERPT_CHAIN_LENGTH,
    MLT_MAX_ERPT_DEPOSIT_ENERGY, MLT_MAX_IMAGE_SIDE, MLT_MAX_NORMALIZATION_WORK_FRACTION,
    MLT_MAX_SAMPLES_PER_PIXEL, MLT_MAX_THREADS, MLT_MAX_TIME_LIMIT_SECONDS, RenderSettings,
};
pub use stats::{RenderStats, StopReason};

use crate::control::{Control, JobShare};
use crate::error::{Error, MLT_STATUS_INTERNAL_ERROR, MLT_STATUS_OUT_OF_MEMORY, Result};
use crate::film::{Film, FixedPoint, FixedRgb};
use crate::filter::{FilterSettings, FilterStats};
use crate::integrators::bdpt::Bdpt;
use crate::integrators::camera_samples::{self, CameraSamplePasses};
use crate::integrators::mlt::direct_pass::DirectPass;
use crate::integrators::mlt::driver::{ChainStart, ChainTally, MetropolisOutcome, finish};
use crate::integrators::mlt::path_space::{self, PathSpaceTarget, PerturbationSizes};
use crate::integrators::mlt::primary_space::{MetropolisSettings, PrimarySpaceTarget};
use crate::integrators::mlt::pssmlt;
use crate::integrators::mlt::targets::{BdptAllStrategies, BdptMultiplexed};
use crate::integrators::path::PathTracer;
use crate::scene::{Camera, CameraModel, Scene};
pub(crate) use request::{RenderRequest, ValidSettings};
use std::sync::atomic::Ordering;
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};
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

/// The settings of a render's Metropolis chains, or of `share` of them.
fn metropolis_settings(settings: &ValidSettings, share: JobShare) -> MetropolisSettings {
    MetropolisSettings {
        mutations_per_pixel: settings.mutations_per_pixel,
        bootstrap_samples: settings.resolved_bootstrap_samples(),
        chains: settings.chains,
        large_step_probability: settings.large_step_probability,
        small_step_sigma: settings.small_step_sigma,
        normalization_work_fraction: settings.normalization_work_fraction,
        seed: settings.seed,
        share,
    }
}

impl Estimator<'_> {
    /// A Metropolis render's bootstrap and chain seeds (`None` for the other algorithms).
    fn chain_start(
        &self,
        camera: &CameraModel,
        settings: &ValidSettings,
        control: &Control,
    ) -> Option<ChainStart> {
        let chains = metropolis_settings(settings, JobShare::WHOLE);
        fn start<T: PrimarySpaceTarget>(
            target: &T,
            camera: &CameraModel,
            chains: &MetropolisSettings,
            control: &Control,
        ) -> Option<ChainStart>
        where
            T::Scratch: Send,
        {
            // A target without groups has no chains (`pssmlt::run`).
            (target.groups() > 0).then(|| ChainStart::new(target, camera, chains, false, control))
        }
        match *self {
            Estimator::Pssmlt(target) => start(target, camera, &chains, control),
            Estimator::Mmlt(target) => start(target, camera, &chains, control),
            Estimator::PssmltBdpt(target) => start(target, camera, &chains, control),
            Estimator::PathSpaceMlt(bdpt) => {
                let all_strategies = BdptAllStrategies(Bdpt {
                    scene: bdpt.scene,
                    max_depth: bdpt.max_depth,
                    min_depth: bdpt.min_depth,
                    spectral: bdpt.spectral,
                });
                let adapt = settings.adapt_mutation_weights;
                Some(ChainStart::new(
                    &all_strategies,
                    camera,
                    &chains,
                    adapt,
                    control,
                ))
            }
            Estimator::Path(_) | Estimator::Bdpt(_) | Estimator::Erpt(_) => None,
        }
    }

    /// Runs the render; `direct` is the path tracer of a Metropolis render's direct pass,
    /// `start` the chains' bootstrap and seeds if a split render's plan made them.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        camera: &CameraModel,
        settings: &ValidSettings,
        direct: Option<&PathTracer>,
        share: JobShare,
        start: Option<&ChainStart>,
        film: &mut Film,
        control: &Control,
    ) -> MetropolisOutcome {
        let seed = settings.seed;
        let spp = settings.samples_per_pixel;
        let chains = metropolis_settings(settings, share);
        let mut direct_pass = direct.map(|direct| {
            DirectPass::start(
                direct,
                camera,
                seed,
                settings.direct_samples_per_mutation,
                settings.mutations_per_pixel,
                share,
                film,
                control,
            )
        });
        let direct_pass = direct_pass.as_mut();
        match *self {
            Estimator::Path(estimator) => {
                CameraSamplePasses::new(estimator, camera, seed, spp, film)
                    .with_share(share)
                    .run(film, control);
                MetropolisOutcome::default()
            }
            Estimator::Bdpt(estimator) => {
                CameraSamplePasses::new(estimator, camera, seed, spp, film)
                    .with_share(share)
                    .run(film, control);
                MetropolisOutcome::default()
            }
            Estimator::Pssmlt(target) => {
                pssmlt::run(target, camera, &chains, start, film, control, direct_pass)
            }
            Estimator::Mmlt(target) => {
                pssmlt::run(target, camera, &chains, start, film, control, direct_pass)
            }
            Estimator::PssmltBdpt(target) => {
                pssmlt::run(target, camera, &chains, start, film, control, direct_pass)
            }
            Estimator::PathSpaceMlt(bdpt) => {
                let target = PathSpaceTarget {
                    bdpt: BdptAllStrategies(Bdpt {
                        scene: bdpt.scene,
                        max_depth: bdpt.max_depth,
                        min_depth: bdpt.min_depth,
                        spectral: bdpt.spectral,
                    }),
                    camera: *camera,
                    weights: settings.mutation_weights,
                    sizes: PerturbationSizes::for_image(camera.width, camera.height),
                    perturb_in_sample_space: settings.perturb_in_sample_space,
                };
                let adapt = settings.adapt_mutation_weights;
                path_space::run(&target, &chains, start, adapt, film, control, direct_pass)
            }
            Estimator::Erpt(bdpt) => {
                let erpt = path_space::ErptSettings {
                    samples_per_pixel: spp,
                    chain_length: settings.erpt_chain_length,
                    deposit_energy: settings.erpt_deposit_energy,
                    seed,
                    weights: settings.mutation_weights,
                    perturb_in_sample_space: settings.perturb_in_sample_space,
                    share,
                };
                path_space::run_erpt(bdpt, camera, &erpt, film, control)
            }
        }
    }
}

/// Called from the rendering call's own thread with the fraction done; return `false` to stop.
pub type Progress<'a> = &'a mut dyn FnMut(f32) -> bool;

/// How often the caller's thread wakes to report progress and check the time limit.
const PROGRESS_INTERVAL: Duration = Duration::from_millis(50);

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

/// The Rust entry: checks the request and the output buffers.
fn render_into(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    rgb_out: &mut [f32],
    unfiltered_out: Option<&mut [f32]>,
    progress: Option<Progress>,
) -> Result<RenderStats> {
    let settings = ValidSettings::new(settings)?;
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
    let request = settings.with_camera(camera)?;
    render_request(
        scene,
        &request,
        &mut rgb_out[..needed],
        unfiltered_out.map(|u| &mut u[..needed]),
        progress,
    )
}

/// Renders a checked request into `rgb_out` (and `unfiltered_out`), each exactly the
/// image's floats.
pub(crate) fn render_request(
    scene: &Scene,
    request: &RenderRequest,
    rgb_out: &mut [f32],
    unfiltered_out: Option<&mut [f32]>,
    progress: Option<Progress>,
) -> Result<RenderStats> {
    let (film, mut stats, _) = render_film(scene, request, JobShare::WHOLE, None, progress)?;
    stats.filter = film.write_rgb(rgb_out, unfiltered_out);
    Ok(stats)
}

/// Renders `share` of the work onto a film, without writing the image: what `render` and a
/// job of a split render (`jobs`) have in common. The stats' `filter` is left at zero.
fn render_film(
    scene: &Scene,
    request: &RenderRequest,
    share: JobShare,
    start_from: Option<&ChainStart>,
    progress: Option<Progress>,
) -> Result<(Film, RenderStats, Option<ChainTally>)> {
    let settings = request.settings();
    let own_pool;
    let pool = if settings.threads == 0 {
        shared_pool()?
    } else {
        own_pool = JoinedPool::new(settings.threads as usize)?;
        own_pool.pool()
    };
    let threads = pool.current_num_threads() as u32;

    let start = Instant::now();
    let deadline = (settings.time_limit_seconds > 0.0)
        .then(|| start + Duration::from_secs_f64(settings.time_limit_seconds));
    let control = Control::new(deadline, settings.algorithm.is_metropolis());
    let model = request.model();
    with_estimator(scene, settings, |estimator, direct| {
        run_estimator(
            scene, settings, share, start_from, progress, estimator, direct, pool, threads, model,
            control, start,
        )
    })
}

/// The bootstrap and chain seeds of a Metropolis render (`None` for the other algorithms),
/// made once by a split render's plan (`jobs::plan`) for all its jobs.
fn plan_chain_start(scene: &Scene, request: &RenderRequest) -> Result<Option<ChainStart>> {
    let settings = request.settings();
    if !settings.algorithm.is_metropolis() {
        return Ok(None);
    }
    let own_pool;
    let pool = if settings.threads == 0 {
        shared_pool()?
    } else {
        own_pool = JoinedPool::new(settings.threads as usize)?;
        own_pool.pool()
    };
    let deadline = (settings.time_limit_seconds > 0.0)
        .then(|| Instant::now() + Duration::from_secs_f64(settings.time_limit_seconds));
    let control = Control::new(deadline, true);
    let model = request.model();
    with_estimator(scene, settings, |estimator, _| {
        Ok(pool.install(|| estimator.chain_start(model, settings, &control)))
    })
}

/// Builds the estimator `settings` ask for (and the direct pass's path tracer) and hands
/// them to `f`.
fn with_estimator<R>(
    scene: &Scene,
    settings: &ValidSettings,
    f: impl FnOnce(&Estimator, Option<&PathTracer>) -> Result<R>,
) -> Result<R> {
    // A Metropolis render with a direct pass leaves the shortest paths to a path tracer
    // (with a max depth below 2, all of them: the chains then have nothing to render).
    let direct = (settings.algorithm.is_metropolis() && settings.direct_samples_per_mutation > 0)
        .then(|| PathTracer {
            scene,
            max_depth: settings.max_depth.min(DIRECT_PASS_DEPTHS - 1),
            min_depth: 0,
            spectral: settings.spectral,
            roulette: settings.roulette(),
            // The chains read textures at full resolution: so does their direct pass.
            texture_filtering: false,
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
        spectral: settings.spectral,
        roulette: settings.roulette(),
        // Only `Algorithm::Path`'s camera samples carry cones; PSSMLT's do not.
        texture_filtering: !settings.full_resolution_textures,
    };
    let bdpt = Bdpt {
        scene,
        max_depth: settings.max_depth,
        min_depth,
        spectral: settings.spectral,
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
    f(&estimator, direct.as_ref())
}

/// The rest of `render_film`, with the estimator built.
#[allow(clippy::too_many_arguments)]
fn run_estimator(
    scene: &Scene,
    settings: &ValidSettings,
    share: JobShare,
    start_from: Option<&ChainStart>,
    progress: Option<Progress>,
    estimator: &Estimator,
    direct: Option<&PathTracer>,
    pool: &rayon::ThreadPool,
    threads: u32,
    model: &CameraModel,
    control: Control,
    start: Instant,
) -> Result<(Film, RenderStats, Option<ChainTally>)> {
    let mut film = try_film(settings, estimator.chain_groups(), scene)?;
    let pixels = settings.width as u64 * settings.height as u64;
    // Progress counts camera samples and mutations alike; without a count (time limit
    // only) there is no plan. A job's share may hold no work at all.
    let counted = if settings.algorithm.is_metropolis() {
        settings.mutations_per_pixel > 0
    } else {
        settings.samples_per_pixel > 0
    };
    let planned = if settings.algorithm.is_metropolis() {
        let direct_samples = if direct.is_some() {
            settings.direct_samples_per_mutation as u64 * settings.mutations_per_pixel as u64
        } else {
            0
        };
        if settings.mutations_per_pixel > 0 {
            (settings.mutations_per_pixel as u64 + direct_samples) * pixels / share.count as u64
        } else {
            0
        }
    } else {
        let rows = if settings.algorithm == Algorithm::Erpt {
            path_space::ERPT_BAND_ROWS
        } else {
            camera_samples::BAND_ROWS
        };
        settings.samples_per_pixel as u64 * camera_samples::pixels_in_share(model, share, rows)
    };

    let mut progress = progress;
    let done = DoneSignal::default();
    let outcome = std::thread::scope(|s| {
        let done = &done;
        let control = &control;
        let film = &mut film;
        let worker = s.spawn(move || {
            // Signals even when the render panics, so the caller never waits forever.
            let _signal = SignalOnDrop(done);
            pool.install(|| {
                estimator.run(model, settings, direct, share, start_from, film, control)
            })
        });
        while !done.wait(PROGRESS_INTERVAL) {
            if let Some(callback) = progress.as_mut() {
                let fraction = control.fraction(planned, start);
                if !callback(fraction) {
                    control.cancel();
                }
            }
            // Past the deadline, this stops the workers.
            control.should_stop();
        }
        worker.join()
    });
    let Ok(mut metropolis) = outcome else {
        return Err(Error::new(
            MLT_STATUS_INTERNAL_ERROR,
            "a rendering thread panicked; this is a bug in mlt",
        ));
    };
    // A Metropolis job's share of the plan is known only approximately beforehand (its
    // chains' count comes from the bootstrap): its chains say whether they finished.
    let metropolis_job = share != JobShare::WHOLE && settings.algorithm.is_metropolis();
    let stop = if control.was_cancelled() {
        StopReason::Cancelled
    } else if !counted
        || (metropolis_job && metropolis.cut_short)
        || (!metropolis_job && control.work_done() < planned)
    {
        StopReason::TimeLimitReached
    } else {
        StopReason::Completed
    };
    if let (StopReason::Completed, Some(callback)) = (stop, progress.as_mut()) {
        // The last word is always 1.0 for a finished render; a cancel now changes nothing.
        let _ = callback(1.0);
    }
    let mut stats = RenderStats {
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
        filter: FilterStats::default(),
    };
    let mut tally = metropolis.tally.take();
    if share == JobShare::WHOLE
        && let Some(tally) = tally.take()
    {
        stats.normalization = finish(&mut film, tally);
    }
    Ok((film, stats, tally))
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
fn try_film(settings: &ValidSettings, chain_groups: usize, scene: &Scene) -> Result<Film> {
    let (width, height) = (settings.width, settings.height);
    let pixels = width as usize * height as usize;
    // Probe the largest allocations first: `vec!` would abort the process on failure.
    let out_of_memory = || {
        Error::new(
            MLT_STATUS_OUT_OF_MEMORY,
            format!("could not allocate the film for {width} x {height} pixels"),
        )
    };
    let mut probe: Vec<FixedRgb> = Vec::new();
    probe
        .try_reserve_exact(pixels)
        .map_err(|_| out_of_memory())?;
    drop(probe);
    let buffers = settings.filter_buffers;
    let mut partials: Vec<FixedRgb> = Vec::new();
    partials
        .try_reserve_exact(pixels * buffers as usize)
        .map_err(|_| out_of_memory())?;
    drop(partials);
    let mut layers: Vec<FixedRgb> = Vec::new();
    layers
        .try_reserve_exact(pixels * chain_groups)
        .map_err(|_| out_of_memory())?;
    drop(layers);
    let units = FixedPoint::for_values_up_to(scene.brightest_light());
    let mut film = Film::new(width, height, settings.algorithm != Algorithm::Path, units);
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
    pool_builder(threads).build().map_err(could_not_start)
}

fn pool_builder(threads: usize) -> rayon::ThreadPoolBuilder {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("mlt-worker-{i}"))
}

fn could_not_start(error: impl std::fmt::Display) -> Error {
    Error::new(
        MLT_STATUS_OUT_OF_MEMORY,
        format!("could not start worker threads: {error}"),
    )
}

/// A render's own pool, whose threads are joined when it is dropped. A dropped rayon pool
/// only tells its threads to exit; these are waited for, so no thread of a render outlives
/// the call (a host may unload the library right after it).
struct JoinedPool {
    /// Always `Some` until dropped: taken out so it is dropped before the joins.
    pool: Option<rayon::ThreadPool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl JoinedPool {
    fn new(threads: usize) -> Result<JoinedPool> {
        let handles = Mutex::new(Vec::with_capacity(threads));
        let pool = pool_builder(threads)
            .spawn_handler(|thread| {
                let mut builder = std::thread::Builder::new();
                if let Some(name) = thread.name() {
                    builder = builder.name(name.to_owned());
                }
                if let Some(size) = thread.stack_size() {
                    builder = builder.stack_size(size);
                }
                let handle = builder.spawn(|| thread.run())?;
                handles
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(handle);
                Ok(())
            })
            .build()
            .map_err(could_not_start)?;
        let threads = handles.into_inner().unwrap_or_else(|e| e.into_inner());
        Ok(JoinedPool {
            pool: Some(pool),
            threads,
        })
    }

    fn pool(&self) -> &rayon::ThreadPool {
        self.pool.as_ref().expect("present until dropped")
    }
}

impl Drop for JoinedPool {
    fn drop(&mut self) {
        drop(self.pool.take()); // tells its threads to exit once idle
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}

/// The pool every render with `threads` 0 runs on: one thread per core for the whole
/// process, started by the first such render, so that a host rendering from several
/// threads at once shares the cores instead of starting a pool per render. The C ABI
/// builds scenes on it too, so a host process has one pool, not this and rayon's global.
pub(crate) fn shared_pool() -> Result<&'static rayon::ThreadPool> {
    static SHARED: std::sync::OnceLock<std::result::Result<rayon::ThreadPool, String>> =
        std::sync::OnceLock::new();
    SHARED
        .get_or_init(|| new_pool(0).map_err(|e| e.message))
        .as_ref()
        .map_err(|message| Error::new(MLT_STATUS_OUT_OF_MEMORY, message.clone()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, SceneDesc};

    /// A square emitter of `radiance` (diffuse 0.5) filling the image of the camera.
    fn emitter_filling_the_image(radiance: f32) -> (Scene, Camera) {
        let scene = Scene::new(&SceneDesc {
            positions: &[
                -2.0, -2.0, 0.0, 2.0, -2.0, 0.0, 2.0, 2.0, 0.0, -2.0, 2.0, 0.0,
            ],
            indices: &[0, 1, 2, 0, 2, 3],
            materials: &[Material::diffuse([0.5; 3]).with_emission([radiance; 3])],
            ..Default::default()
        })
        .unwrap();
        let camera = Camera {
            eye: [0.0, 0.0, 3.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 30.0,
            ..Default::default()
        };
        (scene, camera)
    }

    /// Light so faint that paths' values are subnormal floats (colours near 1e-40, found by
    /// the capi_scene fuzzer): the Metropolis deposits, a path's contribution over its value,
    /// stay finite and the image keeps its brightness.
    #[test]
    fn metropolis_with_subnormal_light() {
        let radiance = 1e-40f32;
        let (scene, camera) = emitter_filling_the_image(radiance);
        for algorithm in [Algorithm::Pssmlt, Algorithm::Mmlt, Algorithm::PssmltBdpt] {
            let settings = RenderSettings {
                width: 4,
                height: 4,
                algorithm,
                mutations_per_pixel: 8,
                bootstrap_samples: 256,
                chains: 4,
                threads: 1,
                direct_samples_per_mutation: 0,
                ..Default::default()
            };
            let mut image = [0.0f32; 48];
            render(&scene, &camera, &settings, &mut image, None).unwrap();
            let mean = image.iter().map(|&v| v as f64).sum::<f64>() / image.len() as f64;
            assert!(
                (mean / radiance as f64 - 1.0).abs() < 0.05,
                "{algorithm:?}: mean {mean:e}"
            );
        }
    }

    /// A Metropolis render with the direct pass on and a max depth below the depths it
    /// leaves to the chains (found by the capi_scene fuzzer and the stress program: MMLT had
    /// no depth left to sample and divided by zero) is the direct pass's: here an emitter of
    /// radiance 1 filling the image.
    #[test]
    fn metropolis_with_a_max_depth_below_the_direct_pass() {
        let (scene, camera) = emitter_filling_the_image(1.0);
        for algorithm in [
            Algorithm::Pssmlt,
            Algorithm::Mmlt,
            Algorithm::PssmltBdpt,
            Algorithm::PathSpaceMlt,
        ] {
            for max_depth in [0, 1] {
                let settings = RenderSettings {
                    width: 4,
                    height: 4,
                    algorithm,
                    max_depth,
                    mutations_per_pixel: 8,
                    bootstrap_samples: 256,
                    chains: 4,
                    threads: 1,
                    ..Default::default()
                };
                let mut image = [0.0f32; 48];
                render(&scene, &camera, &settings, &mut image, None).unwrap();
                let mean = image.iter().sum::<f32>() / image.len() as f32;
                assert!(
                    (mean - 1.0).abs() < 0.05,
                    "{algorithm:?}, max depth {max_depth}: mean {mean}"
                );
            }
        }
    }
}
