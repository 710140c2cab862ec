//! The schedule of camera samples, shared by every estimator that takes them pixel by pixel
//! (the path tracer, BDPT and a Metropolis render's direct pass through the render driver's
//! camera pass, and ERPT): passes over the whole image, each taking the next few samples of
//! every pixel with bands of rows in parallel. A sample's film position and random numbers
//! depend only on its pixel and index, so the image depends neither on the thread count nor
//! on how the work is cut into bands and passes.

use crate::control::Control;
use crate::sampling::PixelSampler;
use std::ops::Range;

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
