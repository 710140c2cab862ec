//! `mlt.plan`, `mlt.render_job`, `mlt.combine`, `mlt.merge`: a render split into jobs that merge into the
//! bits of one render (`mlt::jobs`). Plans and partial results pickle as their byte buffers
//! (version and checksum included), so any process pool or cluster can carry them.

use crate::convert;
use crate::errors;
use crate::render::{CancelToken, RenderStats, detached, image_array, image_buffer};
use crate::scene::Scene;
use numpy::PyArray3;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};

/// What a split render is (`mlt::jobs::RenderPlan`): made once by `mlt.plan`, handed to
/// every `render_job` and to `merge`. `to_bytes()` / `RenderPlan.from_bytes()` carry it
/// between processes; pickling does the same.
#[pyclass(module = "mlt._mlt", frozen, eq)]
#[derive(PartialEq)]
pub struct RenderPlan {
    plan: mlt::jobs::RenderPlan,
}

#[pymethods]
impl RenderPlan {
    /// Reads a plan written by `to_bytes` (by this library version). A buffer truncated,
    /// corrupted or from another version raises `InvalidArgumentError`.
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let plan = py
            .detach(|| mlt::jobs::RenderPlan::from_bytes(data))
            .map_err(|e| errors::from_mlt(py, &e))?;
        Ok(RenderPlan { plan })
    }

    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.plan.to_bytes())
    }

    /// A hash of the plan's contents; every partial result names the plan it belongs to.
    #[getter]
    fn id(&self) -> u64 {
        self.plan.id()
    }

    /// The plan's `RenderSettings` (its `threads` is the plan step's; each job has its own).
    #[getter]
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        convert::settings_to_py(py, self.plan.settings())
    }

    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        convert::camera_to_py(py, self.plan.camera())
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let from_bytes = slf.get_type().getattr("from_bytes")?;
        Ok((from_bytes, PyTuple::new(py, [slf.get().to_bytes(py)])?))
    }

    fn __repr__(&self) -> String {
        let s = self.plan.settings();
        format!(
            "RenderPlan(id={:016x}, algorithm={:?}, width={}, height={}, seed={})",
            self.plan.id(),
            convert::algorithm_name(s.algorithm),
            s.width,
            s.height,
            s.seed
        )
    }
}

/// What one job rendered (`mlt::jobs::PartialRender`), or several after `combine`: its
/// film's exact sums and its counters. `to_bytes()` / `PartialRender.from_bytes()` and pickling carry it.
#[pyclass(module = "mlt._mlt", frozen)]
pub struct PartialRender {
    partial: mlt::jobs::PartialRender,
}

#[pymethods]
impl PartialRender {
    /// Reads a partial result written by `to_bytes` (by this library version). A buffer
    /// truncated, corrupted or from another version raises `InvalidArgumentError`.
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let partial = py
            .detach(|| mlt::jobs::PartialRender::from_bytes(data))
            .map_err(|e| errors::from_mlt(py, &e))?;
        Ok(PartialRender { partial })
    }

    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let bytes = py.detach(|| self.partial.to_bytes());
        PyBytes::new(py, &bytes)
    }

    /// This job's number, from 0 (for a combination, the first job it holds).
    #[getter]
    fn job(&self) -> u32 {
        self.partial.job()
    }

    /// The jobs whose work it holds, ascending: `[job]` for one job's result.
    #[getter]
    fn held_jobs(&self) -> Vec<u32> {
        self.partial.held_jobs().to_vec()
    }

    /// How many jobs the render was split into.
    #[getter]
    fn jobs(&self) -> u32 {
        self.partial.jobs()
    }

    /// The id of the plan this job rendered.
    #[getter]
    fn plan_id(&self) -> u64 {
        self.partial.plan_id()
    }

    /// The `RenderStats` of the jobs it holds, added up.
    #[getter]
    fn stats(&self, py: Python<'_>) -> PyResult<RenderStats> {
        RenderStats::new(py, self.partial.stats())
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let from_bytes = slf.get_type().getattr("from_bytes")?;
        Ok((from_bytes, PyTuple::new(py, [slf.get().to_bytes(py)])?))
    }

    fn __repr__(&self) -> String {
        format!(
            "PartialRender(held_jobs={:?}, jobs={}, plan_id={:016x})",
            self.partial.held_jobs(),
            self.partial.jobs(),
            self.partial.plan_id()
        )
    }
}

/// Plans a render of `scene` seen by `camera` with `settings`, to be split into jobs.
/// Validates everything `render` would. For the Metropolis algorithms it runs the bootstrap
/// (with `settings.threads`, within the time limit) and fixes every chain's seed, so the
/// jobs need not repeat it; for the others it is immediate. The GIL is released meanwhile.
#[pyfunction]
#[pyo3(signature = (scene, camera, settings=None))]
pub fn plan(
    py: Python<'_>,
    scene: &Bound<'_, Scene>,
    camera: &Bound<'_, PyAny>,
    settings: Option<&Bound<'_, PyAny>>,
) -> PyResult<RenderPlan> {
    let camera = convert::camera(camera)?;
    let settings = settings.map_or(Ok(mlt::RenderSettings::default()), convert::settings)?;
    let scene = &scene.get().scene;
    let plan = py
        .detach(|| mlt::jobs::plan(scene, &camera, &settings))
        .map_err(|e| errors::from_mlt(py, &e))?;
    Ok(RenderPlan { plan })
}

/// Renders job `job` of `jobs` (numbered from 0) of `plan` on `scene`, which must be built
/// from the same description as the plan's scene (arrays, materials, lights, textures and
/// backend), in this or any other process. Returns a `PartialRender`.
///
/// `threads` (0: every core) is this job's own; the plan's time limit applies to each job.
/// `progress` and `cancel` work as in `render`; a job stopped early still merges (into a
/// correctly normalized image of the work done). Raises `InvalidArgumentError` for a scene
/// not the plan's, or `job` not below `jobs`, or `jobs` beyond 65536.
#[pyfunction]
#[pyo3(signature = (scene, plan, job, jobs, *, threads=0, progress=None, cancel=None))]
#[allow(clippy::too_many_arguments)]
pub fn render_job(
    py: Python<'_>,
    scene: &Bound<'_, Scene>,
    plan: &Bound<'_, RenderPlan>,
    job: u32,
    jobs: u32,
    threads: u32,
    progress: Option<Bound<'_, PyAny>>,
    cancel: Option<&Bound<'_, CancelToken>>,
) -> PyResult<PartialRender> {
    let scene = &scene.get().scene;
    let plan = &plan.get().plan;
    let result = detached(py, progress, cancel, |on_progress| {
        mlt::jobs::render_job(scene, plan, job, jobs, threads, Some(on_progress))
    })?;
    let partial = result.map_err(|e| errors::from_mlt(py, &e))?;
    Ok(PartialRender { partial })
}

/// Merges the partial results of every job of `plan` (`PartialRender`s or their bytes, one
/// per job or `combine`d, holding every job once, in any order) into `(image, stats)`, the
/// image `render` would return for the plan, bit for bit. The stats add the jobs' counts;
/// `seconds` is the sum of the jobs' times, `threads` the most any job used. Raises
/// `InvalidArgumentError` for a job missing or given twice, or of another plan.
#[pyfunction]
pub fn merge<'py>(
    py: Python<'py>,
    plan: &Bound<'py, RenderPlan>,
    partials: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, RenderStats)> {
    let plan = &plan.get().plan;
    let settings = plan.settings();
    let mut image = image_buffer(
        settings
            .output_len()
            .map_err(|e| errors::from_mlt(py, &e))?,
    )?;
    let stats = with_partials(py, partials, "merge", |partials| {
        mlt::jobs::merge(plan, partials, &mut image)
    })?;
    Ok((
        image_array(py, image, settings)?,
        RenderStats::new(py, &stats)?,
    ))
}

/// Adds partial results of `plan` that hold disjoint sets of jobs (`PartialRender`s or
/// their bytes, any number, in any order) into one `PartialRender` holding all their jobs,
/// for `merge` or a further `combine`: merging it gives the bits merging its parts would,
/// so a cluster can merge N jobs in a tree. Raises `InvalidArgumentError` for a job held
/// twice, or of another plan.
#[pyfunction]
pub fn combine<'py>(
    py: Python<'py>,
    plan: &Bound<'py, RenderPlan>,
    partials: &Bound<'py, PyAny>,
) -> PyResult<PartialRender> {
    let plan = &plan.get().plan;
    let partial = with_partials(py, partials, "combine", |partials| {
        mlt::jobs::combine(plan, partials)
    })?;
    Ok(PartialRender { partial })
}

/// Runs `fold` (`merge` or `combine`, named `call`) with the GIL released on the items of
/// `partials`, each taken (and bytes decoded) one at a time, so only one job's film is held
/// beside the sum. An item that is neither a `PartialRender` nor bytes-like, or does not
/// decode, ends the items `fold` sees and is the error raised.
fn with_partials<T: Send>(
    py: Python<'_>,
    partials: &Bound<'_, PyAny>,
    call: &str,
    fold: impl Send + FnOnce(&mut dyn Iterator<Item = mlt::jobs::PartialRender>) -> mlt::Result<T>,
) -> PyResult<T> {
    let items: Vec<Py<PyAny>> = partials
        .try_iter()?
        .map(|item| item.map(Bound::unbind))
        .collect::<PyResult<_>>()?;
    let mut failure: Option<PyErr> = None;
    let result = py.detach(|| {
        let mut partials = items.iter().map_while(|item| {
            Python::attach(|py| match partial_of(item.bind(py), call) {
                Ok(partial) => Some(partial),
                Err(error) => {
                    failure = Some(error);
                    None
                }
            })
        });
        fold(&mut partials)
    });
    if let Some(error) = failure {
        return Err(error);
    }
    result.map_err(|e| errors::from_mlt(py, &e))
}

/// An item of `merge`'s or `combine`'s partials: a `PartialRender` (copied) or a bytes-like
/// buffer (decoded).
fn partial_of(item: &Bound<'_, PyAny>, call: &str) -> PyResult<mlt::jobs::PartialRender> {
    let py = item.py();
    if let Ok(partial) = item.cast::<PartialRender>() {
        return Ok(partial.get().partial.clone());
    }
    match item.extract::<&[u8]>() {
        Ok(bytes) => {
            mlt::jobs::PartialRender::from_bytes(bytes).map_err(|e| errors::from_mlt(py, &e))
        }
        Err(_) => Err(PyTypeError::new_err(format!(
            "{call} takes PartialRender objects or their bytes, not {}",
            item.get_type().name()?
        ))),
    }
}
