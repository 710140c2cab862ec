//! The pass of camera samples of a pixel estimator (the path tracer, BDPT, a Metropolis
//! render's direct pass) over the film: the shared schedule of
//! `integrators::camera_passes`, each band's samples added to its pixels and its splats
//! to the film.

use crate::control::Control;
use crate::control::JobShare;
use crate::film::{Film, Splat};
use crate::integrators::camera_passes::{PassSchedule, PixelSamples};
use crate::integrators::{PixelEstimator, SampleCounters};
use crate::scene::CameraModel;
use crate::spectrum::Spectrum;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// Salts the seed of the camera samples' numbers, apart from other uses of the seed.
const CAMERA_SAMPLE_SALT: u64 = 0x5eed_0f15_0000_0000;

/// Rows per unit of parallel work.
const BAND_ROWS: u32 = 4;

/// Target samples per pass over the whole image.
const SAMPLES_PER_PASS: u64 = 1 << 18;

/// Per-work-unit state of a render: the estimator's scratch memory and the splats of the
/// current pass. Created once per render so sampling never allocates.
struct BandState<S> {
    scratch: S,
    splats: Vec<Splat>,
    light_paths: u64,
}

/// Runs a pixel estimator over the film, pass by pass; can stop at a sample count and go on
/// later (a Metropolis render interleaves its direct pass with the chains).
pub(super) struct CameraSampleJob<'a, E: PixelEstimator> {
    estimator: &'a E,
    camera: CameraModel,
    samples: PixelSamples,
    schedule: PassSchedule,
    states: Vec<BandState<E::Scratch>>,
    /// The bands this run samples (a job's share of a split render).
    share: JobShare,
}

/// Pixels of the bands of `rows` rows (`BAND_ROWS`, or ERPT's) of the image of `camera`
/// that `share` owns.
pub(super) fn pixels_in_share(camera: &CameraModel, share: JobShare, rows: u32) -> u64 {
    let bands = camera.height.div_ceil(rows);
    (0..bands)
        .filter(|&band| share.owns(band as u64))
        .map(|band| (camera.height - band * rows).min(rows) as u64 * camera.width as u64)
        .sum()
}

/// Rows per band of the camera-sample passes.
pub(super) const ROWS: u32 = BAND_ROWS;

impl<'a, E: PixelEstimator> CameraSampleJob<'a, E> {
    pub(super) fn new(
        estimator: &'a E,
        camera: &CameraModel,
        seed: u64,
        samples_per_pixel: u32,
        film: &Film,
    ) -> Self {
        let width = film.width;
        let pixels = width as u64 * film.height as u64;
        let schedule = PassSchedule::new(samples_per_pixel, pixels, SAMPLES_PER_PASS);
        let batch = schedule.batch();
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
            samples: PixelSamples {
                seed: seed ^ CAMERA_SAMPLE_SALT,
                width,
            },
            schedule,
            states,
            share: JobShare::WHOLE,
        }
    }

    /// Samples only the bands `share` owns: every pass of a band is one work unit, the
    /// same whatever the number of jobs.
    pub(super) fn with_share(mut self, share: JobShare) -> Self {
        self.share = share;
        self
    }

    pub(super) fn run(&mut self, film: &mut Film, control: &Control) {
        self.run_until(film, control, u32::MAX);
    }

    /// Takes samples until every pixel has `target` (or all it should have), or the render
    /// stops.
    pub(super) fn run_until(&mut self, film: &mut Film, control: &Control, target: u32) {
        let width = film.width;
        let states = &mut self.states;
        let share = self.share;
        while let Some(indices) = self.schedule.next_pass(target, control) {
            let (first, end) = (indices.start, indices.end);
            film.par_bands(BAND_ROWS)
                .zip(states.par_iter_mut())
                .enumerate()
                .for_each(|(index, (mut band, state))| {
                    state.splats.clear();
                    state.light_paths = 0;
                    if !share.owns(index as u64) {
                        return;
                    }
                    // After the first pass a stop skips the bands not yet begun: pixels
                    // keep their own sample counts.
                    if first > 0 && control.should_stop() {
                        return;
                    }
                    let mut counters = SampleCounters::default();
                    let mut invalid = 0u64;
                    for i in 0..band.len() {
                        let x = i as u32 % width;
                        let y = band.first_row + i as u32 / width;
                        let mut pixel_sum = Spectrum::ZERO;
                        for mut sample in self.samples.of_pixel(x, y, first..end) {
                            let splats_before = state.splats.len();
                            let l = self.estimator.sample(
                                &self.camera,
                                sample.x,
                                sample.y,
                                &mut sample.sampler,
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
                        band.add(i, pixel_sum, end - first);
                    }
                    let band_samples = band.len() as u64 * (end - first) as u64;
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
        }
    }
}
