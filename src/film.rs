//! The film: per-pixel sums of radiance samples and the number of samples taken, turned into
//! an image normalized pixel by pixel (so a partial render is still a valid estimate).

use rayon::prelude::*;

pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Sum of radiance samples per pixel, RGB, in f64 so long renders do not lose precision.
    sums: Vec<[f64; 3]>,
    /// Samples taken per pixel.
    counts: Vec<u32>,
}

/// A horizontal band of rows, the unit of parallel work: its pixels are contiguous.
pub struct FilmBand<'a> {
    pub first_row: u32,
    pub width: u32,
    pub sums: &'a mut [[f64; 3]],
    pub counts: &'a mut [u32],
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        let pixels = width as usize * height as usize;
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; pixels],
            counts: vec![0; pixels],
        }
    }

    /// Splits the film into bands of `rows` rows for parallel iteration, in row order.
    pub fn par_bands(&mut self, rows: u32) -> impl IndexedParallelIterator<Item = FilmBand<'_>> {
        let width = self.width;
        let band_pixels = (rows * width) as usize;
        self.sums
            .par_chunks_mut(band_pixels)
            .zip(self.counts.par_chunks_mut(band_pixels))
            .enumerate()
            .map(move |(band, (sums, counts))| FilmBand {
                first_row: band as u32 * rows,
                width,
                sums,
                counts,
            })
    }

    /// Total samples taken over all pixels.
    pub fn sample_count(&self) -> u64 {
        self.counts.iter().map(|&c| c as u64).sum()
    }

    /// Writes mean radiance per pixel as RGB floats, rows top to bottom. Pixels without a
    /// sample (only possible after an early stop) are black.
    pub fn write_rgb(&self, out: &mut [f32]) {
        for ((pixel, sum), &count) in out.chunks_exact_mut(3).zip(&self.sums).zip(&self.counts) {
            let scale = if count > 0 { 1.0 / count as f64 } else { 0.0 };
            for c in 0..3 {
                pixel[c] = (sum[c] * scale) as f32;
            }
        }
    }
}
