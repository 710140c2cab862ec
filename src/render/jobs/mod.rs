//! A render split into jobs for many machines, merged into the bits of one render.
//!
//! 1. [`plan`] fixes what the render is (scene fingerprint, camera, settings) and returns a
//!    [`RenderPlan`], which travels as bytes ([`RenderPlan::to_bytes`]).
//! 2. [`render_job`] renders job k of N of a plan on any machine holding the same scene and
//!    returns a [`PartialRender`]: its film's exact sums and its counters, also as bytes.
//! 3. [`merge`] adds the partial results of all N jobs, in any order, and writes the image.
//!    Between the two, [`combine`] may add any disjoint set of partial results into one, so
//!    a cluster can merge in a tree (each node adds a few) instead of one node adding all N.
//!
//! Why the merge is exact: a render's work is cut into units fixed by its settings alone
//! (for the camera-sample algorithms, each pass over each band of rows), job k does the units
//! whose index is k modulo N, and the film sums in fixed point (`film::FixedPoint`), where
//! addition is associative. So the merged film holds the bits of the film one machine would
//! have, for any N and any order of the partial results.
//!
//! Every buffer carries a magic number, the format and library versions and a checksum; a
//! partial result names its plan's id and its job. A buffer from another plan, scene or
//! version, a corrupted or truncated one, a job missing or given twice, is an error.

use super::request::{RenderRequest, ValidSettings};
use super::{
    JobShare, Progress, RenderSettings, RenderStats, StopReason, plan_chain_start, render_film,
};
use crate::error::{Error, MLT_STATUS_INVALID_ARGUMENT, Result};
use crate::film::{Film, read_film, write_film};
use crate::filter::FilterStats;
use crate::integrators::mlt::driver::{
    ChainStart, ChainTally, MutationCounts, MutationWeights, finish,
};
use crate::integrators::mlt::normalization::{Moments, NormalizationEstimate, NormalizationStats};
use crate::params::{Kind, Parameters, Value};
use crate::scene::{Camera, Scene};
use crate::wire::{Reader, Writer};

const PLAN_MAGIC: &[u8; 8] = b"MLTPLAN\0";
const PARTIAL_MAGIC: &[u8; 8] = b"MLTPART\0";

/// Most jobs a render can be split into.
pub const MLT_MAX_JOBS: u32 = 1 << 16;

/// What a split render is: made once by [`plan`], handed to every job and to the merge.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderPlan {
    /// The settings and camera, checked.
    request: RenderRequest,
    /// `Scene::fingerprint` of the scene the plan was made for.
    scene: u64,
    /// A Metropolis render's bootstrap and chain seeds, made once for every job.
    chain_start: Option<ChainStart>,
    /// A hash of the plan's bytes: partial results name the plan they belong to.
    id: u64,
}

/// Plans a render of `scene` to be split into jobs. Validates everything `render` would.
/// For the Metropolis algorithms it runs the bootstrap (with `settings.threads`, within the
/// time limit) and fixes every chain's group and seed, so the jobs need not repeat it.
pub fn plan(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> Result<RenderPlan> {
    let request = ValidSettings::new(settings)?.with_camera(camera)?;
    let mut plan = RenderPlan {
        request,
        scene: scene.fingerprint(),
        chain_start: plan_chain_start(scene, &request)?,
        id: 0,
    };
    let mut w = Writer::default();
    plan.write_contents(&mut w);
    plan.id = xxhash_rust::xxh3::xxh3_64(&w.finish(PLAN_MAGIC));
    Ok(plan)
}

impl RenderPlan {
    pub fn settings(&self) -> &RenderSettings {
        self.request.settings()
    }

    pub fn camera(&self) -> &Camera {
        self.request.camera()
    }

    /// Identifies the plan: a hash of its contents, named by its partial results.
    pub fn id(&self) -> u64 {
        self.id
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        self.write_contents(&mut w);
        w.u64(self.id);
        w.finish(PLAN_MAGIC)
    }

    pub fn from_bytes(bytes: &[u8]) -> Result<RenderPlan> {
        let mut r = Reader::open(bytes, PLAN_MAGIC, "render plan")?;
        let settings = read_settings(&mut r)?;
        let camera = read_camera(&mut r)?;
        let scene = r.u64()?;
        let chain_start = read_chain_start(&mut r, &settings)?;
        let id = r.u64()?;
        r.end()?;
        let mut w = Writer::default();
        write_contents(&mut w, &settings, &camera, scene, chain_start.as_ref());
        if xxhash_rust::xxh3::xxh3_64(&w.finish(PLAN_MAGIC)) != id {
            return Err(Error::new(
                MLT_STATUS_INVALID_ARGUMENT,
                "the render plan's id does not match its contents",
            ));
        }
        Ok(RenderPlan {
            request: ValidSettings::new(&settings)?.with_camera(&camera)?,
            scene,
            chain_start,
            id,
        })
    }

    fn write_contents(&self, w: &mut Writer) {
        write_contents(
            w,
            self.settings(),
            self.camera(),
            self.scene,
            self.chain_start.as_ref(),
        );
    }
}

/// A plan's contents, which its id hashes.
fn write_contents(
    w: &mut Writer,
    settings: &RenderSettings,
    camera: &Camera,
    scene: u64,
    chain_start: Option<&ChainStart>,
) {
    write_settings(w, settings);
    write_camera(w, camera);
    w.u64(scene);
    write_chain_start(w, chain_start);
}

/// What one job rendered (or, after [`combine`], several): its film's exact sums and its
/// counters.
#[derive(Clone)]
pub struct PartialRender {
    plan: u64,
    /// The jobs whose work it holds, ascending: one for [`render_job`]'s result.
    held: Vec<u32>,
    jobs: u32,
    film: Film,
    stats: RenderStats,
    /// A Metropolis job's chains' share of the normalization.
    tally: Option<ChainTally>,
}

impl PartialRender {
    /// This is job `job()` of `jobs()`; for a combination of jobs, the first it holds.
    pub fn job(&self) -> u32 {
        self.held[0]
    }

    /// The jobs whose work it holds, ascending: `[job()]` for one job's result.
    pub fn held_jobs(&self) -> &[u32] {
        &self.held
    }

    /// "job 3 of 8", or "jobs [2, 5] of 8" for a combination: for messages.
    pub fn name(&self) -> String {
        match self.held.as_slice() {
            [job] => format!("job {job} of {}", self.jobs),
            held => format!("jobs {held:?} of {}", self.jobs),
        }
    }

    pub fn jobs(&self) -> u32 {
        self.jobs
    }

    /// The id of the plan it belongs to.
    pub fn plan_id(&self) -> u64 {
        self.plan
    }

    /// What the job did (its `filter` is zero: the filter runs at the merge).
    pub fn stats(&self) -> &RenderStats {
        &self.stats
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(self.plan);
        w.u32(self.jobs);
        w.len(self.held.len());
        for &job in &self.held {
            w.u32(job);
        }
        write_stats(&mut w, &self.stats);
        write_film(&self.film, &mut w);
        write_tally(&mut w, self.tally.as_ref());
        w.finish(PARTIAL_MAGIC)
    }

    pub fn from_bytes(bytes: &[u8]) -> Result<PartialRender> {
        let mut r = Reader::open(bytes, PARTIAL_MAGIC, "partial render")?;
        let plan = r.u64()?;
        let jobs = r.u32()?;
        let held = (0..r.len(4)?)
            .map(|_| r.u32())
            .collect::<Result<Vec<u32>>>()?;
        let stats = read_stats(&mut r)?;
        let film = read_film(&mut r)?;
        let tally = read_tally(&mut r)?;
        r.end()?;
        let ascending = held.windows(2).all(|pair| pair[0] < pair[1]);
        if jobs == 0
            || jobs > MLT_MAX_JOBS
            || held.is_empty()
            || !ascending
            || held.last().is_some_and(|&last| last >= jobs)
        {
            return Err(Error::new(
                MLT_STATUS_INVALID_ARGUMENT,
                format!("the partial render claims to hold jobs {held:?} of {jobs}"),
            ));
        }
        Ok(PartialRender {
            plan,
            held,
            jobs,
            film,
            stats,
            tally,
        })
    }
}

/// Renders job `job` of `jobs` (numbered from 0) of `plan` on `scene`, which must be built
/// from the same description as the plan's (backend included: the two backends agree only
/// to the last bits). `threads` (0: every core) and the progress callback are this job's
/// own; the plan's time limit applies to each job.
pub fn render_job(
    scene: &Scene,
    plan: &RenderPlan,
    job: u32,
    jobs: u32,
    threads: u32,
    progress: Option<Progress>,
) -> Result<PartialRender> {
    if jobs == 0 || jobs > MLT_MAX_JOBS {
        return Err(Error::invalid(format!(
            "jobs is {jobs}: a render splits into 1 to {MLT_MAX_JOBS} jobs"
        )));
    }
    if job >= jobs {
        return Err(Error::invalid(format!(
            "job {job} does not exist: jobs are numbered 0 to {}",
            jobs - 1
        )));
    }
    if scene.fingerprint() != plan.scene {
        return Err(Error::invalid(
            "the scene is not the one the plan was made for: every job must build its scene from the same description (arrays, materials, lights, textures and backend)",
        ));
    }
    let request = plan.request.with_threads(threads)?;
    let share = JobShare {
        index: job,
        count: jobs,
    };
    let (film, stats, tally) =
        render_film(scene, &request, share, plan.chain_start.as_ref(), progress)?;
    Ok(PartialRender {
        plan: plan.id,
        held: vec![job],
        jobs,
        film,
        stats,
        tally,
    })
}

/// Merges the partial results of every job of `plan`, given in any order (each one job's or
/// a [`combine`]d set), and writes the image into `rgb_out` (width × height × 3 floats) as
/// `render` would. The stats add the jobs' counts; `seconds` is the sum of the jobs' times,
/// `threads` the most any job used, `stop` the first of Cancelled, TimeLimitReached,
/// Completed that some job reports.
pub fn merge(
    plan: &RenderPlan,
    partials: impl IntoIterator<Item = PartialRender>,
    rgb_out: &mut [f32],
) -> Result<RenderStats> {
    let needed = plan.settings().output_len()?;
    if rgb_out.len() < needed {
        return Err(Error::invalid(format!(
            "the output buffer holds {} floats but a {} x {} RGB image needs {needed}",
            rgb_out.len(),
            plan.settings().width,
            plan.settings().height
        )));
    }
    let Folded {
        mut film,
        mut stats,
        tally,
        jobs,
        held,
    } = fold(plan, partials)?;
    let missing: Vec<usize> = (0..held.len()).filter(|&j| !held[j]).collect();
    if !missing.is_empty() {
        return Err(Error::invalid(format!(
            "jobs {missing:?} of {jobs} are missing: the image needs every job"
        )));
    }
    if let Some(tally) = tally {
        if tally
            .pass_layer
            .is_some_and(|layer| layer >= film.chain_layer_count())
        {
            return Err(Error::invalid(
                "the partial renders name a film layer they do not have",
            ));
        }
        stats.normalization = finish(&mut film, tally);
    }
    // The plan's bootstrap traced rays for every job.
    stats.rays += plan.chain_start.as_ref().map_or(0, |start| start.rays);
    stats.filter = film.write_rgb(&mut rgb_out[..needed], None);
    Ok(stats)
}

/// Adds partial results of `plan` that hold disjoint sets of jobs (any number, in any order)
/// into one partial result holding all their jobs, for [`merge`] or a further `combine`.
/// Merging the combination gives the bits merging its parts would: a cluster can add its N
/// results in a tree, each node reading a few, instead of one node reading all N.
pub fn combine(
    plan: &RenderPlan,
    partials: impl IntoIterator<Item = PartialRender>,
) -> Result<PartialRender> {
    let Folded {
        film,
        stats,
        tally,
        jobs,
        held,
    } = fold(plan, partials)?;
    Ok(PartialRender {
        plan: plan.id,
        held: (0..jobs).filter(|&j| held[j as usize]).collect(),
        jobs,
        film,
        stats,
        tally,
    })
}

/// The sum of some partial results of one plan, and which jobs it holds.
struct Folded {
    film: Film,
    stats: RenderStats,
    tally: Option<ChainTally>,
    jobs: u32,
    held: Vec<bool>,
}

/// Adds partial results of `plan`, checking that each belongs to it, fits the others, and
/// holds no job another holds.
fn fold(plan: &RenderPlan, partials: impl IntoIterator<Item = PartialRender>) -> Result<Folded> {
    let mut folded: Option<Folded> = None;
    for partial in partials {
        if partial.plan != plan.id {
            return Err(Error::invalid(format!(
                "{} belongs to another plan (id {:016x}, not {:016x})",
                partial.name(),
                partial.plan,
                plan.id
            )));
        }
        if (partial.film.width, partial.film.height)
            != (plan.settings().width, plan.settings().height)
        {
            return Err(Error::invalid(format!(
                "{}: the image is {} x {}, the plan's {} x {}",
                partial.name(),
                partial.film.width,
                partial.film.height,
                plan.settings().width,
                plan.settings().height
            )));
        }
        let Some(sum) = folded.as_mut() else {
            let mut held = vec![false; partial.jobs as usize];
            for &job in &partial.held {
                held[job as usize] = true;
            }
            folded = Some(Folded {
                film: partial.film,
                stats: partial.stats,
                tally: partial.tally,
                jobs: partial.jobs,
                held,
            });
            continue;
        };
        if partial.jobs != sum.jobs {
            return Err(Error::invalid(format!(
                "{} was split from {} jobs, another from {}: a render is split one way",
                partial.name(),
                partial.jobs,
                sum.jobs
            )));
        }
        for &job in &partial.held {
            if std::mem::replace(&mut sum.held[job as usize], true) {
                return Err(Error::invalid(format!(
                    "job {job} of {} is given twice",
                    partial.jobs
                )));
            }
        }
        let name = partial.name();
        let misfit = |why: String| Error::invalid(format!("{name} does not fit the others: {why}"));
        sum.film.merge(&partial.film).map_err(misfit)?;
        match (sum.tally.as_mut(), partial.tally) {
            (None, None) => {}
            (Some(tally), Some(other)) => tally.merge(other).map_err(misfit)?,
            _ => return Err(misfit("one has Metropolis chains, the other not".into())),
        }
        add_stats(&mut sum.stats, &partial.stats);
    }
    folded.ok_or_else(|| Error::invalid("no partial render to merge"))
}

fn add_stats(total: &mut RenderStats, job: &RenderStats) {
    let rank = |stop: StopReason| match stop {
        StopReason::Cancelled => 2,
        StopReason::TimeLimitReached => 1,
        StopReason::Completed => 0,
    };
    if rank(job.stop) > rank(total.stop) {
        total.stop = job.stop;
    }
    total.samples += job.samples;
    total.mutations += job.mutations;
    total.rays += job.rays;
    total.invalid_samples += job.invalid_samples;
    total.seconds += job.seconds;
    total.threads = total.threads.max(job.threads);
    total.accepted_mutations += job.accepted_mutations;
    total.mutation_counts.add(&job.mutation_counts);
}

/// Every declared setting in declaration order (`render::settings`), so a new setting is
/// encoded with no code here.
fn write_settings(w: &mut Writer, settings: &RenderSettings) {
    for p in RenderSettings::parameters() {
        match (p.kind, settings.get(p.name).expect("a declared setting")) {
            (Kind::U64, Value::Int(v)) => w.u64(v as u64),
            (_, Value::Int(v)) => w.u32(v as u32),
            (Kind::F64, Value::Float(v)) => w.f64(v),
            (_, Value::Float(v)) => w.f32(v as f32),
            (_, Value::Bool(v)) => w.bool(v),
            (Kind::Choice(choices), Value::Choice(name)) => w.u32(
                choices
                    .names
                    .iter()
                    .position(|&n| n == name)
                    .expect("a declared name") as u32,
            ),
            (_, Value::Choice(_)) => unreachable!("a choice's kind names its choices"),
            (_, Value::Vec3(values)) => values.into_iter().for_each(|v| w.f32(v)),
            (_, Value::Floats(values)) => values.into_iter().for_each(|v| w.f32(v)),
            (_, Value::Texture(_)) => unreachable!("settings have no textures"),
        }
    }
}

fn read_settings(r: &mut Reader) -> Result<RenderSettings> {
    let mut settings = RenderSettings::default();
    for p in RenderSettings::parameters() {
        let value = match p.kind {
            Kind::U32 => Value::Int(r.u32()?.into()),
            Kind::U64 => Value::Int(r.u64()?.into()),
            Kind::F32 => Value::Float(r.f32()?.into()),
            Kind::F64 => Value::Float(r.f64()?),
            Kind::Bool => Value::Bool(r.bool()?),
            Kind::Choice(choices) => {
                let code = r.u32()?;
                Value::Choice(
                    choices
                        .names
                        .get(code as usize)
                        .ok_or_else(|| r.malformed(&format!("an unknown {}", p.name)))?,
                )
            }
            Kind::F32x3 => Value::Vec3([r.f32()?, r.f32()?, r.f32()?]),
            Kind::F32x4 => Value::Floats([r.f32()?, r.f32()?, r.f32()?, r.f32()?]),
            Kind::Texture => unreachable!("settings have no textures"),
        };
        settings.set(p.name, value)?;
    }
    Ok(settings)
}

fn write_camera(w: &mut Writer, camera: &Camera) {
    let Camera {
        eye,
        target,
        up,
        fov_y_deg,
        lens_radius,
        focus_distance,
    } = *camera;
    for v in eye.into_iter().chain(target).chain(up) {
        w.f32(v);
    }
    w.f32(fov_y_deg);
    w.f32(lens_radius);
    w.f32(focus_distance);
}

fn read_camera(r: &mut Reader) -> Result<Camera> {
    let mut vector = || -> Result<[f32; 3]> { Ok([r.f32()?, r.f32()?, r.f32()?]) };
    Ok(Camera {
        eye: vector()?,
        target: vector()?,
        up: vector()?,
        fov_y_deg: r.f32()?,
        lens_radius: r.f32()?,
        focus_distance: r.f32()?,
    })
}

fn write_stats(w: &mut Writer, stats: &RenderStats) {
    let RenderStats {
        stop,
        samples,
        mutations,
        rays,
        invalid_samples,
        seconds,
        threads,
        accepted_mutations,
        normalization,
        mutation_counts,
        mutation_weights,
        filter: _,
    } = *stats;
    w.u8(match stop {
        StopReason::Completed => 0,
        StopReason::Cancelled => 1,
        StopReason::TimeLimitReached => 2,
    });
    w.u64(samples);
    w.u64(mutations);
    w.u64(rays);
    w.u64(invalid_samples);
    w.f64(seconds);
    w.u32(threads);
    w.u64(accepted_mutations);
    let NormalizationStats {
        value,
        samples,
        relative_error,
        largest_share,
    } = normalization;
    w.f64(value);
    w.u64(samples);
    w.f64(relative_error);
    w.f64(largest_share);
    for count in mutation_counts
        .proposed
        .iter()
        .chain(&mutation_counts.accepted)
    {
        w.u64(*count);
    }
    for weight in mutation_weights.0 {
        w.f32(weight);
    }
}

fn read_stats(r: &mut Reader) -> Result<RenderStats> {
    let stop = match r.u8()? {
        0 => StopReason::Completed,
        1 => StopReason::Cancelled,
        2 => StopReason::TimeLimitReached,
        _ => return Err(r.malformed("an unknown stop reason")),
    };
    fn counts(r: &mut Reader) -> Result<[u64; 4]> {
        Ok([r.u64()?, r.u64()?, r.u64()?, r.u64()?])
    }
    let (samples, mutations, rays, invalid_samples) = (r.u64()?, r.u64()?, r.u64()?, r.u64()?);
    let (seconds, threads, accepted_mutations) = (r.f64()?, r.u32()?, r.u64()?);
    let normalization = NormalizationStats {
        value: r.f64()?,
        samples: r.u64()?,
        relative_error: r.f64()?,
        largest_share: r.f64()?,
    };
    let mutation_counts = MutationCounts {
        proposed: counts(r)?,
        accepted: counts(r)?,
    };
    Ok(RenderStats {
        stop,
        samples,
        mutations,
        rays,
        invalid_samples,
        seconds,
        threads,
        accepted_mutations,
        normalization,
        mutation_counts,
        mutation_weights: MutationWeights([r.f32()?, r.f32()?, r.f32()?, r.f32()?]),
        filter: FilterStats::default(),
    })
}

fn write_estimate(w: &mut Writer, estimate: &NormalizationEstimate) {
    w.len(estimate.group_sums.len());
    for &sum in &estimate.group_sums {
        w.f64(sum);
    }
    let Moments {
        count,
        sum,
        squares,
        largest,
    } = estimate.total;
    w.u64(count);
    w.f64(sum);
    w.f64(squares);
    w.f64(largest);
}

fn read_estimate(r: &mut Reader) -> Result<NormalizationEstimate> {
    let groups = r.len(8)?;
    let group_sums = (0..groups).map(|_| r.f64()).collect::<Result<_>>()?;
    Ok(NormalizationEstimate {
        group_sums,
        total: Moments {
            count: r.u64()?,
            sum: r.f64()?,
            squares: r.f64()?,
            largest: r.f64()?,
        },
    })
}

fn write_tally(w: &mut Writer, tally: Option<&ChainTally>) {
    w.bool(tally.is_some());
    let Some(tally) = tally else {
        return;
    };
    write_estimate(w, &tally.bootstrap);
    w.len(tally.chains.len());
    for (chain, estimate) in &tally.chains {
        w.u64(*chain);
        write_estimate(w, estimate);
    }
    w.bool(tally.pass_layer.is_some());
    w.u64(tally.pass_layer.unwrap_or(0) as u64);
    w.u64(tally.pass_samples);
    w.u64(tally.mutations_per_chain);
}

fn read_tally(r: &mut Reader) -> Result<Option<ChainTally>> {
    if !r.bool()? {
        return Ok(None);
    }
    let bootstrap = read_estimate(r)?;
    let groups = bootstrap.group_sums.len();
    let chains = (0..r.len(40)?)
        .map(|_| {
            let chain = r.u64()?;
            let estimate = read_estimate(r)?;
            if estimate.group_sums.len() != groups {
                return Err(r.malformed("a chain's estimate has another number of groups"));
            }
            Ok((chain, estimate))
        })
        .collect::<Result<_>>()?;
    let has_pass_layer = r.bool()?;
    let pass_layer = r.u64()? as usize;
    Ok(Some(ChainTally {
        bootstrap,
        chains,
        pass_layer: has_pass_layer.then_some(pass_layer),
        pass_samples: r.u64()?,
        mutations_per_chain: r.u64()?,
    }))
}

fn write_seeds(w: &mut Writer, seeds: &[(usize, u64)]) {
    w.len(seeds.len());
    for &(group, index) in seeds {
        w.u32(group as u32);
        w.u64(index);
    }
}

fn write_chain_start(w: &mut Writer, start: Option<&ChainStart>) {
    w.bool(start.is_some());
    let Some(start) = start else {
        return;
    };
    write_estimate(w, &start.estimate);
    w.u64(start.rays);
    write_seeds(w, &start.seeds);
    write_seeds(w, &start.adapted_seeds);
}

fn read_chain_start(r: &mut Reader, settings: &RenderSettings) -> Result<Option<ChainStart>> {
    if !r.bool()? {
        return Ok(None);
    }
    let estimate = read_estimate(r)?;
    let rays = r.u64()?;
    let groups = estimate.group_sums.len();
    let samples = settings.resolved_bootstrap_samples() as u64;
    let mut seeds = || -> Result<Vec<(usize, u64)>> {
        (0..r.len(12)?)
            .map(|_| {
                let (group, index) = (r.u32()? as usize, r.u64()?);
                if group >= groups || index >= samples {
                    return Err(r.malformed("a chain's seed names no bootstrap sample"));
                }
                Ok((group, index))
            })
            .collect()
    };
    let (seeds, adapted_seeds) = (seeds()?, seeds()?);
    Ok(Some(ChainStart {
        estimate,
        rays,
        seeds,
        adapted_seeds,
    }))
}
