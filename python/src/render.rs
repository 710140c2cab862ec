//! `mlt.render`: runs a render with the GIL released, reporting progress to a Python
//! callable on the calling thread and stopping on its request, a `CancelToken`, or Ctrl-C.
//!
//! `detached` is the part any long call shares (`render_job` uses it too):
//! it takes the work as a closure given the progress function the Rust API expects.

use crate::convert;
use crate::errors;
use crate::scene::Scene;
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A flag that stops renders: pass it as `render(..., cancel=token)` and call
/// `token.cancel()` from any thread. The render returns soon after (within about 50 ms),
/// with the image of the work done so far, normalized, and `stats.stop == "cancelled"`.
/// A token stays cancelled (every later render with it stops at once) until `reset()`.
#[pyclass(module = "mlt._mlt", frozen)]
pub struct CancelToken {
    flag: Arc<AtomicBool>,
}

#[pymethods]
impl CancelToken {
    #[new]
    fn new() -> Self {
        CancelToken {
            flag: Arc::new(AtomicBool::new(false)),
        }
    }

    /// Asks every render using this token to stop.
    fn cancel(&self) {
        self.flag.store(true, Ordering::Relaxed);
    }

    /// Clears the request, so the token can stop another render.
    fn reset(&self) {
        self.flag.store(false, Ordering::Relaxed);
    }

    /// Whether `cancel()` was called (since the last `reset()`).
    #[getter]
    fn cancelled(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    fn __repr__(&self) -> String {
        format!("CancelToken(cancelled={})", self.cancelled())
    }
}

/// Runs `work` without the GIL, handing it the progress function of the Rust API. That
/// function, called on this thread about every 50 ms, stops the work (returns false) when
/// `cancel` is set, or when, with the GIL taken back, a signal handler raises (Ctrl-C's
/// KeyboardInterrupt), `progress(fraction)` raises or `progress` returns a false value
/// other than None. An exception raised there is re-raised once `work` has returned.
pub fn detached<T, F>(
    py: Python<'_>,
    progress: Option<Bound<'_, PyAny>>,
    cancel: Option<&Bound<'_, CancelToken>>,
    work: F,
) -> PyResult<T>
where
    T: Send,
    F: Send + FnOnce(&mut dyn FnMut(f32) -> bool) -> T,
{
    if let Some(progress) = &progress
        && !progress.is_callable()
    {
        return Err(PyTypeError::new_err(format!(
            "progress must be callable (it is given the fraction done), not {}",
            progress.get_type().name()?
        )));
    }
    let callback = progress.map(Bound::unbind);
    let token = cancel.map(|c| c.get().flag.clone());
    let mut raised: Option<PyErr> = None;
    let mut stopped = false;
    let result = py.detach(|| {
        let mut on_progress = |fraction: f32| -> bool {
            // Once stopped, stay stopped without calling Python again.
            stopped = stopped || token.as_ref().is_some_and(|t| t.load(Ordering::Relaxed));
            if stopped {
                return false;
            }
            Python::attach(|py| {
                let outcome = py.check_signals().and_then(|()| match &callback {
                    Some(callback) => {
                        let answer = callback.call1(py, (fraction,))?;
                        let answer = answer.bind(py);
                        Ok(answer.is_none() || answer.is_truthy()?)
                    }
                    None => Ok(true),
                });
                match outcome {
                    Ok(go_on) => stopped = !go_on,
                    Err(error) => {
                        raised = Some(error);
                        stopped = true;
                    }
                }
            });
            !stopped
        };
        work(&mut on_progress)
    });
    match raised {
        Some(error) => Err(error),
        None => Ok(result),
    }
}

/// A zeroed image buffer, or MemoryError instead of an abort.
pub fn image_buffer(len: usize) -> PyResult<Vec<f32>> {
    let mut buffer = Vec::new();
    buffer
        .try_reserve_exact(len)
        .map_err(|_| PyMemoryError::new_err(format!("cannot allocate an image of {len} floats")))?;
    buffer.resize(len, 0.0);
    Ok(buffer)
}

/// The flat RGB buffer as a (height, width, 3) float32 array, without copying.
pub fn image_array<'py>(
    py: Python<'py>,
    pixels: Vec<f32>,
    settings: &mlt::RenderSettings,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    PyArray1::from_vec(py, pixels).reshape([settings.height as usize, settings.width as usize, 3])
}

fn settings_or_default(settings: Option<&Bound<'_, PyAny>>) -> PyResult<mlt::RenderSettings> {
    settings.map_or(Ok(mlt::RenderSettings::default()), convert::settings)
}

/// Renders `scene` seen by `camera` (an `mlt.Camera`) with `settings` (an
/// `mlt.RenderSettings`; default: its defaults).
///
/// Returns `(image, stats)`: a float32 array of shape (height, width, 3), linear RGB with
/// rows from the top, and the `RenderStats`.
///
/// The GIL is released while rendering, so other Python threads run. `progress`, if
/// given, is called on this thread about every 50 ms with the fraction done (0 to 1; 1.0
/// last when the render completes); returning False (any false value but None) stops the
/// render, as does `cancel` (a `CancelToken`) once cancelled: the image is then valid, with
/// the work done so far, and `stats.stop` is "cancelled". An exception raised by
/// `progress`, and KeyboardInterrupt (Ctrl-C), stop the render and are raised when it has
/// stopped.
///
/// The image depends on the settings' seed, never on the thread count. Raises
/// `InvalidArgumentError` for invalid settings or camera.
#[pyfunction]
#[pyo3(signature = (scene, camera, settings=None, *, progress=None, cancel=None))]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, Scene>,
    camera: &Bound<'py, PyAny>,
    settings: Option<&Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, RenderStats)> {
    let camera = convert::camera(camera)?;
    let settings = settings_or_default(settings)?;
    let mut image = image_buffer(
        settings
            .output_len()
            .map_err(|e| errors::from_mlt(py, &e))?,
    )?;
    let scene = &scene.get().scene;
    let result = detached(py, progress, cancel, |on_progress| {
        mlt::render(scene, &camera, &settings, &mut image, Some(on_progress))
    })?;
    let stats = result.map_err(|e| errors::from_mlt(py, &e))?;
    Ok((
        image_array(py, image, &settings)?,
        RenderStats::new(py, &stats)?,
    ))
}

/// Renders like `render`, and also returns the image as it was before the post-process
/// filter (`RenderSettings.filter_buffers`; the same image when the filter is off):
/// `(image, unfiltered, stats)`.
#[pyfunction]
#[pyo3(signature = (scene, camera, settings=None, *, progress=None, cancel=None))]
#[allow(clippy::type_complexity)]
pub fn render_with_unfiltered<'py>(
    py: Python<'py>,
    scene: &Bound<'py, Scene>,
    camera: &Bound<'py, PyAny>,
    settings: Option<&Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<(
    Bound<'py, PyArray3<f32>>,
    Bound<'py, PyArray3<f32>>,
    RenderStats,
)> {
    let camera = convert::camera(camera)?;
    let settings = settings_or_default(settings)?;
    let len = settings
        .output_len()
        .map_err(|e| errors::from_mlt(py, &e))?;
    let mut image = image_buffer(len)?;
    let mut unfiltered = image_buffer(len)?;
    let scene = &scene.get().scene;
    let result = detached(py, progress, cancel, |on_progress| {
        mlt::render_with_unfiltered(
            scene,
            &camera,
            &settings,
            &mut image,
            &mut unfiltered,
            Some(on_progress),
        )
    })?;
    let stats = result.map_err(|e| errors::from_mlt(py, &e))?;
    Ok((
        image_array(py, image, &settings)?,
        image_array(py, unfiltered, &settings)?,
        RenderStats::new(py, &stats)?,
    ))
}

/// What a render did (`mlt::RenderStats`).
#[pyclass(module = "mlt._mlt", frozen, get_all)]
pub struct RenderStats {
    /// "completed", "cancelled" (by `progress` or a `CancelToken`) or
    /// "time_limit_reached".
    stop: &'static str,
    /// Camera samples over the whole image (path tracing, BDPT, a Metropolis render's
    /// direct pass).
    samples: u64,
    /// Metropolis: mutations made by all chains.
    mutations: u64,
    /// Rays traced (closest-hit and shadow).
    rays: u64,
    /// Samples whose radiance was not finite and were dropped (counted in `samples`).
    invalid_samples: u64,
    seconds: f64,
    threads: u32,
    /// Metropolis: accepted mutations.
    accepted_mutations: u64,
    /// Metropolis: the normalization b the image was scaled by; ERPT: its deposit energy.
    normalization: Py<NormalizationStats>,
    /// Path-space MLT: proposals and acceptances per mutation.
    mutation_counts: Py<MutationCounts>,
    /// Path-space MLT and ERPT: the weights of the bidirectional mutation and the lens,
    /// caustic and multi-chain perturbations the chains ran with.
    mutation_weights: (f32, f32, f32, f32),
    /// What the post-process filter did (zeros when it is off).
    filter: Py<FilterStats>,
}

/// The Metropolis normalization b = ∫ luminance(f) (`mlt::NormalizationStats`).
#[pyclass(module = "mlt._mlt", frozen, get_all)]
pub struct NormalizationStats {
    value: f64,
    /// Independent samples b was estimated from.
    samples: u64,
    /// The estimate's standard error over b.
    relative_error: f64,
    /// The largest share of the sum one sample carried.
    largest_share: f64,
}

/// Proposals and acceptances of path-space MLT's mutations, in the order bidirectional,
/// lens, caustic, multi-chain.
#[pyclass(module = "mlt._mlt", frozen, get_all)]
pub struct MutationCounts {
    proposed: (u64, u64, u64, u64),
    accepted: (u64, u64, u64, u64),
}

/// What the post-process filter did (`mlt::FilterStats`).
#[pyclass(module = "mlt._mlt", frozen, get_all)]
pub struct FilterStats {
    /// Σ |Δ luminance| / Σ luminance: the share of the image's energy the filter moved.
    changed_fraction: f64,
    /// About how many pixels each pixel was averaged over.
    mean_neighbours: f64,
}

fn tuple4<T: Copy>(a: [T; 4]) -> (T, T, T, T) {
    (a[0], a[1], a[2], a[3])
}

impl RenderStats {
    pub fn new(py: Python<'_>, stats: &mlt::RenderStats) -> PyResult<Self> {
        let n = &stats.normalization;
        Ok(RenderStats {
            stop: match stats.stop {
                mlt::StopReason::Completed => "completed",
                mlt::StopReason::Cancelled => "cancelled",
                mlt::StopReason::TimeLimitReached => "time_limit_reached",
            },
            samples: stats.samples,
            mutations: stats.mutations,
            rays: stats.rays,
            invalid_samples: stats.invalid_samples,
            seconds: stats.seconds,
            threads: stats.threads,
            accepted_mutations: stats.accepted_mutations,
            normalization: Py::new(
                py,
                NormalizationStats {
                    value: n.value,
                    samples: n.samples,
                    relative_error: n.relative_error,
                    largest_share: n.largest_share,
                },
            )?,
            mutation_counts: Py::new(
                py,
                MutationCounts {
                    proposed: tuple4(stats.mutation_counts.proposed),
                    accepted: tuple4(stats.mutation_counts.accepted),
                },
            )?,
            mutation_weights: tuple4(stats.mutation_weights.0),
            filter: Py::new(
                py,
                FilterStats {
                    changed_fraction: stats.filter.changed_fraction,
                    mean_neighbours: stats.filter.mean_neighbours,
                },
            )?,
        })
    }
}

/// `RenderStats`' fields as plain values, for pickling.
type StatsState = (
    String,
    u64,
    u64,
    u64,
    u64,
    f64,
    u32,
    u64,
    (f64, u64, f64, f64),
    ((u64, u64, u64, u64), (u64, u64, u64, u64)),
    (f32, f32, f32, f32),
    (f64, f64),
);

#[pymethods]
impl RenderStats {
    /// Rebuilds stats pickled by `__reduce__`.
    #[staticmethod]
    fn _from_state(py: Python<'_>, state: StatsState) -> PyResult<Self> {
        let (
            stop,
            samples,
            mutations,
            rays,
            invalid_samples,
            seconds,
            threads,
            accepted,
            normalization,
            counts,
            mutation_weights,
            filter,
        ) = state;
        let stop = ["completed", "cancelled", "time_limit_reached"]
            .into_iter()
            .find(|&name| name == stop)
            .ok_or_else(|| errors::invalid(py, &format!("{stop:?} is not a stop reason")))?;
        let (value, norm_samples, relative_error, largest_share) = normalization;
        let (proposed, accepted_counts) = counts;
        let (changed_fraction, mean_neighbours) = filter;
        Ok(RenderStats {
            stop,
            samples,
            mutations,
            rays,
            invalid_samples,
            seconds,
            threads,
            accepted_mutations: accepted,
            normalization: Py::new(
                py,
                NormalizationStats {
                    value,
                    samples: norm_samples,
                    relative_error,
                    largest_share,
                },
            )?,
            mutation_counts: Py::new(
                py,
                MutationCounts {
                    proposed,
                    accepted: accepted_counts,
                },
            )?,
            mutation_weights,
            filter: Py::new(
                py,
                FilterStats {
                    changed_fraction,
                    mean_neighbours,
                },
            )?,
        })
    }

    /// Pickles as its fields' values (the stats travel back from cluster workers).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (StatsState,))> {
        let stats = slf.get();
        let n = stats.normalization.get();
        let counts = stats.mutation_counts.get();
        let filter = stats.filter.get();
        let state: StatsState = (
            stats.stop.to_owned(),
            stats.samples,
            stats.mutations,
            stats.rays,
            stats.invalid_samples,
            stats.seconds,
            stats.threads,
            stats.accepted_mutations,
            (n.value, n.samples, n.relative_error, n.largest_share),
            (counts.proposed, counts.accepted),
            stats.mutation_weights,
            (filter.changed_fraction, filter.mean_neighbours),
        );
        Ok((slf.get_type().getattr("_from_state")?, (state,)))
    }

    fn __repr__(&self) -> String {
        format!(
            "RenderStats(stop={:?}, samples={}, mutations={}, rays={}, seconds={:.3}, threads={})",
            self.stop, self.samples, self.mutations, self.rays, self.seconds, self.threads
        )
    }
}

#[pymethods]
impl NormalizationStats {
    fn __repr__(&self) -> String {
        format!(
            "NormalizationStats(value={}, samples={}, relative_error={}, largest_share={})",
            self.value, self.samples, self.relative_error, self.largest_share
        )
    }
}

#[pymethods]
impl MutationCounts {
    fn __repr__(&self) -> String {
        format!(
            "MutationCounts(proposed={:?}, accepted={:?})",
            self.proposed, self.accepted
        )
    }
}

#[pymethods]
impl FilterStats {
    fn __repr__(&self) -> String {
        format!(
            "FilterStats(changed_fraction={}, mean_neighbours={})",
            self.changed_fraction, self.mean_neighbours
        )
    }
}
