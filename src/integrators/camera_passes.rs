//! The schedule of camera samples, shared by every estimator that takes them pixel by pixel
//! (the path tracer, BDPT and a Metropolis render's direct pass through the render driver's
//! camera pass, and ERPT): passes over the whole image, each taking the next few samples of
//! every pixel with bands of rows in parallel. A sample's film position and random numbers
//! depend only on its pixel and index, so the image depends neither on the thread count nor
//! on how the work is cut into bands and passes.

use crate::control::Control;
use crate::sampling::{Rng, shifted_sobol_2d};
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

/// Where a pixel's camera samples go: spread over the pixel as a (0, 2)-sequence shifted
/// per pixel, each with its own random stream.
#[derive(Clone, Copy)]
pub(crate) struct PixelSamples {
    pub seed: u64,
    /// Stream offset of the per-pixel shifts (apart from the per-sample streams, which
    /// hash the sample index into the seed).
    pub shift_stream: u64,
    /// Image width, for pixel indices.
    pub width: u32,
}

/// One camera sample: its index within its pixel, the pixel's index, the film position in
/// pixels, and its random numbers.
pub(crate) struct CameraSample {
    pub index: u32,
    pub pixel: u64,
    pub x: f32,
    pub y: f32,
    pub rng: Rng,
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
        let mut shift = Rng::new(self.seed, self.shift_stream + pixel);
        let shift = [shift.next_u32(), shift.next_u32()];
        let seed = self.seed;
        indices.map(move |index| {
            let [jx, jy] = shifted_sobol_2d(index, shift);
            CameraSample {
                index,
                pixel,
                x: x as f32 + jx,
                y: y as f32 + jy,
                rng: Rng::for_pixel_sample(seed, pixel, index as u64),
            }
        })
    }
}
