//! The functions of primary sample space that Metropolis chains explore: the path tracer
//! (PSSMLT, Kelemen et al. 2002), BDPT with all strategies of a sample summed (PSSMLT over
//! BDPT), and BDPT with the path depth and one strategy picked by the chain (multiplexed MLT,
//! Hachisuka et al. 2014).

use super::primary_space::{PathSample, PrimarySpaceTarget, film_position};
use super::pss::PssSampler;
use crate::integrators::PathVertex;
use crate::integrators::bdpt::{
    Bdpt, BdptScratch, CAMERA_STREAM, CONNECTION_STREAM, Contribution, STREAMS,
};
use crate::integrators::path::{PathTracer, RayCone};
use crate::integrators::{PixelEstimator, SampleCounters};
use crate::sampling::Sampler;
use crate::scene::CameraModel;
use crate::spectrum::Spectrum;

/// PSSMLT over the path tracer: one stream, read in the path tracer's order.
impl PrimarySpaceTarget for PathTracer<'_> {
    type Scratch = PathSample;

    fn scratch(&self) -> PathSample {
        PathSample::with_capacity(1)
    }

    fn streams(&self) -> usize {
        1
    }

    fn dimensions(&self) -> usize {
        // Film 2, lens 2; per vertex light sample 3, BSDF sample 3, roulette 1.
        4 + 7 * (self.max_depth as usize + 1)
    }

    fn max_entries(&self) -> usize {
        1
    }

    fn groups(&self) -> usize {
        1
    }

    /// With emitters seen directly in f (no direct pass), the film position decides much of
    /// a sample's value, and large steps, uniform over the film, would add more variance to
    /// the bootstrap's stratified estimate than they take away.
    fn large_steps_are_bootstrap_samples(&self) -> bool {
        self.min_depth > 0
    }

    fn bootstrap(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut PathSample,
        targets: &mut [f32],
        rays: &mut u64,
    ) {
        scratch.clear();
        trace_path(self, camera, sampler, scratch, rays);
        targets[0] += scratch.target;
    }

    fn pass_sample(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut PathSample,
        targets: &mut [f32],
        rays: &mut u64,
        point: &mut dyn FnMut(usize, &PathSample),
    ) {
        self.bootstrap(camera, sampler, scratch, targets, rays);
        point(0, scratch);
    }

    fn seed(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        _: &mut PathSample,
        _: usize,
        _: f32,
        out: &mut PathSample,
        rays: &mut u64,
    ) {
        trace_path(self, camera, sampler, out, rays);
    }

    fn evaluate(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        _: &mut PathSample,
        _: usize,
        out: &mut PathSample,
        rays: &mut u64,
    ) {
        trace_path(self, camera, sampler, out, rays);
    }
}

#[inline]
fn trace_path(
    tracer: &PathTracer,
    camera: &CameraModel,
    sampler: &mut PssSampler,
    out: &mut PathSample,
    rays: &mut u64,
) {
    let (x, y, pixel) = film_position(camera, sampler.uniform2());
    let lens = sampler.uniform2();
    let (origin, direction) = camera.generate_ray(x, y, lens);
    // Metropolis reads textures at full resolution: a footprint is a camera pixel's, and
    // the chains' paths are not tied to one.
    out.push(
        pixel,
        tracer.radiance(origin, direction, RayCone::NONE, sampler, rays),
    );
}

/// Memory of the BDPT targets: the subpaths, a path sample for the bootstrap, and the
/// strategies of one depth for seeding multiplexed chains.
pub(crate) struct BdptTargetScratch {
    paths: BdptScratch,
    sample: PathSample,
    strategies: Vec<(usize, Contribution, f32)>,
}

impl BdptTargetScratch {
    /// The channels the last sample drew (`BdptScratch::drawn_channels`).
    pub(crate) fn drawn_channels(&self) -> crate::spectral::Channels {
        self.paths.drawn_channels()
    }
}

fn bdpt_scratch(bdpt: &Bdpt) -> BdptTargetScratch {
    BdptTargetScratch {
        paths: bdpt.scratch(),
        sample: PathSample::with_capacity(bdpt_max_entries(bdpt)),
        strategies: Vec::with_capacity(bdpt.max_depth as usize + 2),
    }
}

/// The sample's own pixel plus one light-tracing splat per light vertex.
fn bdpt_max_entries(bdpt: &Bdpt) -> usize {
    bdpt.max_depth as usize + 3
}

/// Starts the camera stream: the film position, then the strategy coordinate (read by every
/// BDPT target so the coordinates after it keep their places). Returns x, y, the pixel and
/// the strategy coordinate.
#[inline]
fn start_camera_stream(camera: &CameraModel, sampler: &mut PssSampler) -> (f32, f32, u32, f32) {
    sampler.start_stream(CAMERA_STREAM);
    let (x, y, pixel) = film_position(camera, sampler.uniform2());
    let strategy = sampler.uniform();
    (x, y, pixel, strategy)
}

/// Traces full-length subpaths (as plain BDPT does) and calls `visit` for every strategy.
fn trace_all_strategies(
    bdpt: &Bdpt,
    camera: &CameraModel,
    sampler: &mut PssSampler,
    paths: &mut BdptScratch,
    rays: &mut u64,
    visit: impl FnMut(usize, usize, Contribution),
) -> u32 {
    let mut counters = SampleCounters::default();
    let (x, y, pixel, _) = start_camera_stream(camera, sampler);
    bdpt.sample_all_strategies(camera, x, y, sampler, paths, &mut counters, visit);
    *rays += counters.rays;
    pixel
}

/// A BDPT sample with all strategies summed: the own pixel's radiance and the splats.
fn evaluate_all_strategies(
    bdpt: &Bdpt,
    camera: &CameraModel,
    sampler: &mut PssSampler,
    paths: &mut BdptScratch,
    out: &mut PathSample,
    rays: &mut u64,
) {
    let mut radiance = Spectrum::ZERO;
    let pixel = trace_all_strategies(bdpt, camera, sampler, paths, rays, |_, _, c| {
        match c.splat_pixel {
            None => radiance += c.value,
            Some(splat_pixel) => out.push(splat_pixel, c.value),
        }
    });
    out.push(pixel, radiance);
}

/// PSSMLT over BDPT: a state is one BDPT sample, all its strategies summed.
pub(crate) struct BdptAllStrategies<'a>(pub Bdpt<'a>);

impl BdptAllStrategies<'_> {
    /// Replays the bootstrap sample `sampler` was restarted at, picks one of its strategies
    /// in proportion to its MIS-weighted luminance (`choice` ∈ [0, 1)) and writes the path
    /// that strategy built into `out`; returns its s (light vertices), or `None` if the
    /// sample has no light. Path-space chains start there: over the bootstrap, a path is
    /// picked with probability ∝ w_s·f/p_s, which resamples f/b.
    pub(crate) fn seed_path(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        choice: f32,
        out: &mut Vec<PathVertex>,
        rays: &mut u64,
    ) -> Option<usize> {
        let bdpt = &self.0;
        let mut counters = SampleCounters::default();
        let (x, y, _, _) = start_camera_stream(camera, sampler);
        let mut found: Vec<(usize, usize, f32)> = Vec::new();
        bdpt.sample_all_strategies(
            camera,
            x,
            y,
            sampler,
            &mut scratch.paths,
            &mut counters,
            |s, t, c| found.push((s, t, PathSample::usable_luminance(c.value))),
        );
        let total: f32 = found.iter().map(|&(_, _, l)| l).sum();
        if total <= 0.0 {
            return None;
        }
        let goal = choice * total;
        let mut cumulative = 0.0;
        let &(s, t, _) = found
            .iter()
            .find(|&&(_, _, l)| {
                cumulative += l;
                l > 0.0 && cumulative > goal
            })
            .or_else(|| found.iter().rev().find(|&&(_, _, l)| l > 0.0))?;
        // The connection stream restarts for every strategy, so this repeats the chosen
        // one exactly and leaves its sampled vertex in the scratch.
        sampler.start_stream(CONNECTION_STREAM);
        bdpt.connect(camera, &mut scratch.paths, s, t, sampler, &mut counters)?;
        bdpt.strategy_path(&scratch.paths, s, t, out);
        *rays += counters.rays;
        Some(s)
    }
}

impl PrimarySpaceTarget for BdptAllStrategies<'_> {
    type Scratch = BdptTargetScratch;

    fn scratch(&self) -> BdptTargetScratch {
        bdpt_scratch(&self.0)
    }

    fn streams(&self) -> usize {
        STREAMS
    }

    fn dimensions(&self) -> usize {
        STREAMS * self.0.coordinates_per_stream()
    }

    fn max_entries(&self) -> usize {
        bdpt_max_entries(&self.0)
    }

    fn groups(&self) -> usize {
        1
    }

    fn large_steps_are_bootstrap_samples(&self) -> bool {
        self.0.min_depth > 0
    }

    fn bootstrap(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        targets: &mut [f32],
        rays: &mut u64,
    ) {
        let sample = &mut scratch.sample;
        sample.clear();
        evaluate_all_strategies(&self.0, camera, sampler, &mut scratch.paths, sample, rays);
        targets[0] += sample.target;
    }

    fn pass_sample(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        targets: &mut [f32],
        rays: &mut u64,
        point: &mut dyn FnMut(usize, &PathSample),
    ) {
        self.bootstrap(camera, sampler, scratch, targets, rays);
        point(0, &scratch.sample);
    }

    fn seed(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        _: usize,
        _: f32,
        out: &mut PathSample,
        rays: &mut u64,
    ) {
        evaluate_all_strategies(&self.0, camera, sampler, &mut scratch.paths, out, rays);
    }

    fn evaluate(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        _: usize,
        out: &mut PathSample,
        rays: &mut u64,
    ) {
        evaluate_all_strategies(&self.0, camera, sampler, &mut scratch.paths, out, rays);
    }
}

/// Multiplexed MLT: chains are grouped by path depth (scattering vertices, from `min_depth`:
/// group g holds depth min_depth + g); the strategy
/// coordinate of the camera stream picks one strategy (s, t) of that depth, whose
/// MIS-weighted contribution, times the number of strategies, is the state's value.
pub(crate) struct BdptMultiplexed<'a>(pub Bdpt<'a>);

/// The strategy (s, t) a coordinate picks among those of a depth, and how many there are.
/// Depth 0 has one: the camera sees the light (s = 1, t = 1 is never used).
#[inline]
fn strategy(depth: usize, u: f32) -> (usize, usize, usize) {
    if depth == 0 {
        return (0, 2, 1);
    }
    let count = depth + 2;
    let s = ((u * count as f32) as usize).min(count - 1);
    (s, count - s, count)
}

/// Index of the strategy coordinate in the camera stream (after the film position).
const STRATEGY_COORDINATE: usize = 2;

impl PrimarySpaceTarget for BdptMultiplexed<'_> {
    type Scratch = BdptTargetScratch;

    fn scratch(&self) -> BdptTargetScratch {
        bdpt_scratch(&self.0)
    }

    fn streams(&self) -> usize {
        STREAMS
    }

    fn dimensions(&self) -> usize {
        STREAMS * self.0.coordinates_per_stream()
    }

    fn max_entries(&self) -> usize {
        1
    }

    fn groups(&self) -> usize {
        (self.0.max_depth + 1).saturating_sub(self.0.min_depth) as usize
    }

    /// All strategies of full-length subpaths, each added to its depth's group: ∫ over the
    /// strategy coordinate of (strategies × one strategy's value) is their sum.
    fn bootstrap(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        targets: &mut [f32],
        rays: &mut u64,
    ) {
        let min_depth = self.0.min_depth as usize;
        trace_all_strategies(
            &self.0,
            camera,
            sampler,
            &mut scratch.paths,
            rays,
            |s, t, c| targets[s + t - 2 - min_depth] += PathSample::usable_luminance(c.value),
        );
    }

    /// Each strategy is a point: the state whose strategy coordinate lies in its interval.
    fn pass_sample(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        targets: &mut [f32],
        rays: &mut u64,
        point: &mut dyn FnMut(usize, &PathSample),
    ) {
        let min_depth = self.0.min_depth as usize;
        let mut counters = SampleCounters::default();
        let (x, y, pixel, _) = start_camera_stream(camera, sampler);
        let sample = &mut scratch.sample;
        self.0.sample_all_strategies(
            camera,
            x,
            y,
            sampler,
            &mut scratch.paths,
            &mut counters,
            |s, t, c| {
                let depth = s + t - 2;
                let (_, _, count) = strategy(depth, 0.0);
                targets[depth - min_depth] += PathSample::usable_luminance(c.value);
                sample.clear();
                sample.push(c.splat_pixel.unwrap_or(pixel), c.value * count as f32);
                if sample.target > 0.0 {
                    point(depth - min_depth, sample);
                }
            },
        );
        *rays += counters.rays;
    }

    fn pass_joins_the_image(&self) -> bool {
        true
    }

    fn points_per_sample(&self, group: usize) -> u32 {
        strategy(group + self.0.min_depth as usize, 0.0).2 as u32
    }

    /// Reproduces the bootstrap sample, picks one strategy of `group` in proportion to its
    /// value and sets the strategy coordinate inside that strategy's interval. Subpaths
    /// cut to the strategy's lengths are prefixes of the full ones (the streams keep every
    /// vertex's coordinates), and each strategy reads the connection stream from its start,
    /// so the state evaluates to the picked strategy's value.
    fn seed(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        group: usize,
        choice: f32,
        out: &mut PathSample,
        rays: &mut u64,
    ) {
        let depth = group + self.0.min_depth as usize;
        scratch.strategies.clear();
        let strategies = &mut scratch.strategies;
        let pixel = trace_all_strategies(
            &self.0,
            camera,
            sampler,
            &mut scratch.paths,
            rays,
            |s, t, c| {
                let luminance = PathSample::usable_luminance(c.value);
                if s + t - 2 == depth && luminance > 0.0 {
                    strategies.push((s, c, luminance));
                }
            },
        );
        let total: f32 = strategies.iter().map(|&(_, _, l)| l).sum();
        let mut goal = choice * total;
        let Some(&(s, c, _)) = strategies
            .iter()
            .find(|&&(_, _, l)| {
                let found = goal < l;
                if !found {
                    goal -= l;
                }
                found
            })
            .or(strategies.last())
        else {
            return;
        };
        let (_, _, count) = strategy(depth, 0.0);
        // Where in the strategy's interval: the rest of `choice`, still uniform.
        let within = (goal / total.max(f32::MIN_POSITIVE)).clamp(0.0, 0.999);
        let u = ((s as f32 + within) / count as f32).min(1.0 - f32::EPSILON);
        debug_assert_eq!(strategy(depth, u).0, s);
        sampler.set_coordinate(CAMERA_STREAM, STRATEGY_COORDINATE, u);
        out.push(c.splat_pixel.unwrap_or(pixel), c.value * count as f32);
    }

    fn evaluate(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut BdptTargetScratch,
        group: usize,
        out: &mut PathSample,
        rays: &mut u64,
    ) {
        let bdpt = &self.0;
        let mut counters = SampleCounters::default();
        // The strategy is read before the subpaths, so it fixes their lengths.
        let (x, y, pixel, u) = start_camera_stream(camera, sampler);
        let (s, t, count) = strategy(group + self.0.min_depth as usize, u);
        let lengths = bdpt.trace_subpaths(
            camera,
            x,
            y,
            t,
            s,
            sampler,
            &mut scratch.paths,
            &mut counters,
        );
        if lengths == (t, s) {
            sampler.start_stream(CONNECTION_STREAM);
            if let Some(c) = bdpt.connect(camera, &mut scratch.paths, s, t, sampler, &mut counters)
            {
                out.push(c.splat_pixel.unwrap_or(pixel), c.value * count as f32);
            }
        }
        *rays += counters.rays;
    }
}

#[cfg(all(test, feature = "cli"))]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn strategies_cover_each_depth_once() {
        assert_eq!(strategy(0, 0.7), (0, 2, 1));
        for depth in 1..6 {
            let count = depth + 2;
            let mut seen = vec![false; count];
            for k in 0..1000 {
                let (s, t, n) = strategy(depth, k as f32 / 1000.0);
                assert_eq!((s + t, n), (count, count));
                seen[s] = true;
            }
            assert!(seen.iter().all(|&x| x), "depth {depth}");
        }
        assert_eq!(strategy(3, 0.999_999_9).0, 4);
    }

    /// A pass sample's points are its bootstrap value split into chain states: per group,
    /// the points' values over the group's points per sample sum to what `bootstrap` adds
    /// (MMLT: a point per strategy, each valued as a chain at that strategy would be).
    #[test]
    fn pass_points_split_the_bootstrap_values() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/cornell-glass.obj");
        let data = crate::io::load_scene(&path).unwrap();
        let scene = Scene::new(&data.desc(crate::accel::Backend::Bvh)).unwrap();
        let camera = data.camera.unwrap().camera.model(32, 32);
        let bdpt = |min_depth| Bdpt {
            scene: &scene,
            max_depth: 5,
            min_depth,
            spectral: false,
        };
        let tracer = PathTracer {
            scene: &scene,
            max_depth: 5,
            min_depth: 2,
            spectral: false,
            roulette: crate::render::RenderSettings::default().roulette(),
            texture_filtering: false,
        };
        check_pass_points(&BdptMultiplexed(bdpt(2)), &camera);
        check_pass_points(&BdptMultiplexed(bdpt(0)), &camera);
        check_pass_points(&BdptAllStrategies(bdpt(2)), &camera);
        check_pass_points(&tracer, &camera);
    }

    fn check_pass_points<T: PrimarySpaceTarget>(target: &T, camera: &CameraModel) {
        let groups = target.groups();
        let mut scratch = target.scratch();
        let mut sampler = PssSampler::new(1, 0, 0.3, 0.01, target.streams(), target.dimensions());
        let (mut bootstrapped, mut passed, mut split) =
            (vec![0.0; groups], vec![0.0; groups], vec![0.0; groups]);
        let mut lit = 0;
        for i in 0..2000u64 {
            let position = [(i % 97) as f32 / 97.0, (i % 89) as f32 / 89.0];
            let mut rays = 0;
            bootstrapped.fill(0.0);
            sampler.restart_at(1, i, position);
            target.bootstrap(
                camera,
                &mut sampler,
                &mut scratch,
                &mut bootstrapped,
                &mut rays,
            );
            passed.fill(0.0);
            split.fill(0.0);
            sampler.restart_at(1, i, position);
            target.pass_sample(
                camera,
                &mut sampler,
                &mut scratch,
                &mut passed,
                &mut rays,
                &mut |group, point| {
                    let entries: f32 = point
                        .entries
                        .iter()
                        .map(|e| Spectrum::from(e.value.to_array()).luminance())
                        .sum();
                    assert!((entries - point.target).abs() <= 1e-5 * point.target);
                    split[group] += point.target / target.points_per_sample(group) as f32;
                },
            );
            assert_eq!(bootstrapped, passed, "sample {i}");
            for g in 0..groups {
                let tolerance = 1e-5 * bootstrapped[g].max(1e-20);
                assert!(
                    (split[g] - bootstrapped[g]).abs() <= tolerance,
                    "sample {i} group {g}: points {} vs bootstrap {}",
                    split[g],
                    bootstrapped[g]
                );
                lit += (split[g] > 0.0) as u32;
            }
        }
        assert!(lit > 100, "only {lit} lit groups");
    }

    /// A multiplexed chain's first state, picked from a bootstrap sample that evaluated all
    /// strategies on full-length subpaths, evaluates to the same value when the chain reads
    /// it with subpaths cut to the strategy's lengths: the per-depth normalizations the
    /// bootstrap estimates are then integrals of the very function the chains sample.
    #[test]
    fn seeded_states_evaluate_as_the_bootstrap_saw_them() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/cornell-glass.obj");
        let data = crate::io::load_scene(&path).unwrap();
        let scene = Scene::new(&data.desc(crate::accel::Backend::Bvh)).unwrap();
        let camera = data.camera.unwrap().camera.model(32, 32);
        for min_depth in [0, 2] {
            let target = BdptMultiplexed(Bdpt {
                scene: &scene,
                max_depth: 5,
                min_depth,
                spectral: false,
            });
            let mut scratch = target.scratch();
            let mut seeded = PathSample::with_capacity(1);
            let mut replayed = PathSample::with_capacity(1);
            let mut strategies_seen = std::collections::BTreeSet::new();
            let mut rays = 0;
            for i in 0..3000u64 {
                let group = i as usize % target.groups();
                let mut sampler =
                    PssSampler::new(1, 0, 0.3, 0.01, target.streams(), target.dimensions());
                let position = [(i % 97) as f32 / 97.0, (i % 89) as f32 / 89.0];
                sampler.restart_at(1, i, position);
                seeded.clear();
                let choice = (i % 101) as f32 / 101.0;
                target.seed(
                    &camera,
                    &mut sampler,
                    &mut scratch,
                    group,
                    choice,
                    &mut seeded,
                    &mut rays,
                );
                if seeded.target == 0.0 {
                    continue;
                }
                sampler.start_replay();
                replayed.clear();
                target.evaluate(
                    &camera,
                    &mut sampler,
                    &mut scratch,
                    group,
                    &mut replayed,
                    &mut rays,
                );
                let (a, b) = (seeded.entries[0], replayed.entries.first().copied());
                let b = b.unwrap_or_else(|| panic!("sample {i} group {group}: replay is black"));
                assert_eq!(a.pixel, b.pixel, "sample {i} group {group}");
                let difference = (a.value - b.value).abs().max_element();
                assert!(
                    difference <= 1e-5 * a.value.abs().max_element(),
                    "sample {i} group {group}: {:?} vs {:?}",
                    a.value,
                    b.value
                );
                // The strategy the state holds.
                let mut replay = sampler;
                replay.start_replay();
                let (_, _, _, u) = start_camera_stream(&camera, &mut replay);
                let (s, t, _) = strategy(group + min_depth as usize, u);
                strategies_seen.insert((s.min(2), t.min(2)));
            }
            // Emitters hit (s = 0; weighted low beyond depth 1, so rarely picked there),
            // light sampling (s = 1), light tracing (t = 1) and connections in between.
            let kinds: &[(usize, usize)] = if min_depth == 0 {
                &[(0, 2), (1, 2), (2, 1), (2, 2)]
            } else {
                &[(1, 2), (2, 1), (2, 2)]
            };
            for &kind in kinds {
                assert!(
                    strategies_seen.contains(&kind),
                    "min depth {min_depth}: no state of kind {kind:?} in {strategies_seen:?}"
                );
            }
        }
    }
}
