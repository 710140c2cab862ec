//! Camera samples taken pixel by pixel, for every estimator that works that way (the path
//! tracer, BDPT, a Metropolis render's direct pass, and ERPT's camera samples): the
//! schedule of passes over the whole image, each taking the next few samples of every pixel
//! with bands of rows in parallel (`PassSchedule`); each sample's film position and random
//! numbers (`PixelSamples`); and the run of a pixel estimator over the film
//! (`CameraSamplePasses`), each band's samples added to its pixels and its splats to the
//! film. A sample's film position and random numbers depend only on its pixel and index, so
//! the image depends neither on the thread count nor on how the work is cut into bands and
//! passes.

use super::{PixelEstimator, SampleCounters};
use crate::control::{Control, JobShare};
use crate::film::{Film, Splat};
use crate::sampling::PixelSampler;
use crate::scene::CameraModel;
use crate::spectrum::Spectrum;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::Ordering;

/// Passes of camera samples: the first takes one sample per pixel and always runs to its
/// end, so a render stopped at any moment still has a sample in every pixel; later ones
/// take `batch` per pixel, until every pixel has its samples or the render stops.
pub(crate) struct PassSchedule {
    /// 0: until stopped.
    samples_per_pixel: u32,
    /// Samples per pixel of a pass after the first.
    batch: u32,
    /// Samples per pixel of the passes handed out so far.
    taken: u32,
}

impl PassSchedule {
    /// A schedule of `samples_per_pixel` (0: until stopped) over `pixels`, with passes of
    /// about `samples_per_pass` samples over the image: passes bound how long a stop takes
    /// and how unevenly a partial image is sampled.
    pub(crate) fn new(samples_per_pixel: u32, pixels: u64, samples_per_pass: u64) -> Self {
        PassSchedule {
            samples_per_pixel,
            batch: samples_per_pass.div_ceil(pixels).clamp(1, 64) as u32,
            taken: 0,
        }
    }

    /// Samples per pixel of a pass after the first.
    pub(crate) fn batch(&self) -> u32 {
        self.batch
    }

    /// The sample indices of the next pass, taken by every pixel, until every pixel has
    /// `target` samples (or all it should have, if fewer), or `None` when done or stopped.
    pub(crate) fn next_pass(&mut self, target: u32, control: &Control) -> Option<Range<u32>> {
        let total = if self.samples_per_pixel > 0 {
            self.samples_per_pixel.min(target)
        } else {
            target
        };
        if self.taken >= total || (self.taken > 0 && control.should_stop()) {
            return None;
        }
        let first = self.taken;
        let end = if first == 0 {
            1
        } else {
            first.saturating_add(self.batch).min(total)
        };
        self.taken = end;
        Some(first..end)
    }
}

/// Where a pixel's camera samples go and the numbers they read: a low-discrepancy sampler
/// per sample (`PixelSampler`), its film position from a slot of its own.
#[derive(Clone, Copy)]
pub(crate) struct PixelSamples {
    /// The render's seed with a salt of the caller's (apart from other uses of the seed).
    pub seed: u64,
    /// Image width, for pixel indices.
    pub width: u32,
}

/// One camera sample: its index within its pixel, the pixel's index, the film position in
/// pixels, and its numbers.
pub(crate) struct CameraSample {
    pub index: u32,
    pub pixel: u64,
    pub x: f32,
    pub y: f32,
    pub sampler: PixelSampler,
}

impl PixelSamples {
    /// Samples `indices` of pixel (x, y).
    #[inline]
    pub(crate) fn of_pixel(
        &self,
        x: u32,
        y: u32,
        indices: Range<u32>,
    ) -> impl Iterator<Item = CameraSample> + use<> {
        let pixel = y as u64 * self.width as u64 + x as u64;
        let seed = self.seed;
        indices.map(move |index| {
            let sampler = PixelSampler::new(seed, pixel, index);
            let [jx, jy] = sampler.film_position();
            CameraSample {
                index,
                pixel,
                x: x as f32 + jx,
                y: y as f32 + jy,
                sampler,
            }
        })
    }
}

/// Salts the seed of the camera samples' numbers, apart from other uses of the seed.
const CAMERA_SAMPLE_SALT: u64 = 0x5eed_0f15_0000_0000;

/// Rows per band, the unit of parallel work (and of a split render's jobs).
pub(crate) const BAND_ROWS: u32 = 4;

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
pub(crate) struct CameraSamplePasses<'a, E: PixelEstimator> {
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
pub(crate) fn pixels_in_share(camera: &CameraModel, share: JobShare, rows: u32) -> u64 {
    let bands = camera.height.div_ceil(rows);
    (0..bands)
        .filter(|&band| share.owns(band as u64))
        .map(|band| (camera.height - band * rows).min(rows) as u64 * camera.width as u64)
        .sum()
}

impl<'a, E: PixelEstimator> CameraSamplePasses<'a, E> {
    pub(crate) fn new(
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
        CameraSamplePasses {
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
    pub(crate) fn with_share(mut self, share: JobShare) -> Self {
        self.share = share;
        self
    }

    pub(crate) fn run(&mut self, film: &mut Film, control: &Control) {
        self.run_until(film, control, u32::MAX);
    }

    /// Takes samples until every pixel has `target` (or all it should have), or the render
    /// stops.
    pub(crate) fn run_until(&mut self, film: &mut Film, control: &Control, target: u32) {
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
