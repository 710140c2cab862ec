//! The film: per-pixel sums of radiance samples and the number of samples taken, turned into
//! an image normalized pixel by pixel (so a partial render is still a valid estimate).

use crate::filter::{FilterSettings, FilterStats, filter_splats};
use crate::spectrum::Spectrum;
use glam::Vec3;
use rayon::prelude::*;

/// A contribution to an arbitrary pixel (light tracing onto the film, Metropolis deposits),
/// recorded by a work unit and added to the film in a fixed order so the image never depends
/// on scheduling. 16 bytes: work units keep many.
#[derive(Clone, Copy, Debug)]
pub struct Splat {
    pub pixel: u32,
    /// The contribution in the film's RGB (a 16-byte-aligned `Spectrum` would double the
    /// splat's size).
    pub value: Vec3,
}

impl Splat {
    /// A contribution of `value` to `pixel`: where a spectrum becomes the film's RGB.
    #[inline]
    pub fn new(pixel: u32, value: Spectrum) -> Splat {
        Splat {
            pixel,
            value: Vec3::from_array(value.to_array()),
        }
    }
}

pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Sum of radiance samples per pixel, RGB, in f64 so long renders do not lose precision.
    sums: Vec<[f64; 3]>,
    /// Samples taken per pixel.
    counts: Vec<u32>,
    /// Sum of splats (light tracing) per pixel; empty when the estimator does not splat.
    splats: Vec<[f64; 3]>,
    /// Light paths traced in all, the normalization of the splats.
    light_paths: u64,
    /// Metropolis chains' deposits per group of chains, `chain_layers[group * pixels +
    /// pixel]`, kept apart because each group is scaled by its own normalization, known only
    /// when the render ends (24 bytes per pixel and group) …
    chain_layers: Vec<[f64; 3]>,
    /// … by these factors (one per group), on top of the splat scale.
    chain_layer_scales: Vec<f64>,
    /// Overrides the splat normalization (Metropolis: pixels / mutations per chain).
    splat_scale: Option<f64>,
    /// The post-process filter (`crate::filter`), if on …
    filter: Option<FilterSettings>,
    /// … and the splats again, split into its partial images:
    /// `partials[pixel * buffers + buffer]`.
    partials: Vec<[f32; 3]>,
}

/// A horizontal band of rows, the unit of parallel work: its pixels are contiguous.
pub struct FilmBand<'a> {
    pub first_row: u32,
    pub width: u32,
    pub sums: &'a mut [[f64; 3]],
    pub counts: &'a mut [u32],
}

impl Film {
    pub fn new(width: u32, height: u32, with_splats: bool) -> Self {
        let pixels = width as usize * height as usize;
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; pixels],
            counts: vec![0; pixels],
            splats: if with_splats {
                vec![[0.0; 3]; pixels]
            } else {
                Vec::new()
            },
            light_paths: 0,
            chain_layers: Vec::new(),
            chain_layer_scales: Vec::new(),
            splat_scale: None,
            filter: None,
            partials: Vec::new(),
        }
    }

    /// Turns the post-process filter on: splats are also kept in its partial images, and
    /// the written image is filtered (`crate::filter`).
    pub fn enable_filter(&mut self, settings: FilterSettings) {
        self.partials = vec![[0.0; 3]; self.splats.len() * settings.buffers as usize];
        self.filter = Some(settings);
    }

    /// Keeps the deposits of `groups` groups of Metropolis chains in layers of their own
    /// (`add_chain_splats`), each scaled by `set_chain_layer_scales` when written.
    pub fn enable_chain_layers(&mut self, groups: usize) {
        self.chain_layers = vec![[0.0; 3]; self.counts.len() * groups];
        self.chain_layer_scales = vec![0.0; groups];
    }

    /// Sets each chain layer's factor (Metropolis: the group's final normalization).
    pub fn set_chain_layer_scales(&mut self, scales: &[f64]) {
        for (scale, &s) in self.chain_layer_scales.iter_mut().zip(scales) {
            *scale = s;
        }
    }

    /// Adds `weight` × the deposits of a chain of `group` (in the chain's order) to its
    /// layer, and with the filter on `weight × partial_scale` × them to partial image
    /// `buffer` (taken modulo their number). `partial_scale` stands in for the layer's
    /// factor, not yet known: the partial images only guide the filter.
    pub fn add_chain_splats(
        &mut self,
        group: usize,
        splats: &[Splat],
        weight: f64,
        partial_scale: f64,
        buffer: usize,
    ) {
        let pixels = self.counts.len();
        let layer = &mut self.chain_layers[group * pixels..(group + 1) * pixels];
        add_weighted(layer, splats, weight);
        self.add_to_partial(splats, weight * partial_scale, buffer);
    }

    /// The number of partial images splats are split into; 0 when the filter is off.
    pub fn filter_buffers(&self) -> usize {
        self.filter.map_or(0, |f| f.buffers as usize)
    }

    /// Sets the factor splats are multiplied by, instead of pixels / light paths.
    pub fn set_splat_scale(&mut self, scale: f64) {
        self.splat_scale = Some(scale);
    }

    /// Adds the splats of a work unit (in the unit's order) and the light paths it traced.
    pub fn add_splats(&mut self, splats: &[Splat], light_paths: u64) {
        self.light_paths += light_paths;
        self.add_weighted_splats(splats, 1.0, 0);
    }

    /// Adds per-pixel splat sums (one RGB triple per pixel, in pixel order) that stand for
    /// `light_paths` light paths.
    pub fn add_splat_sums(&mut self, sums: impl Iterator<Item = [f64; 3]>, light_paths: u64) {
        self.light_paths += light_paths;
        for (total, sum) in self.splats.iter_mut().zip(sums) {
            for (t, s) in total.iter_mut().zip(sum) {
                *t += s;
            }
        }
    }

    /// Adds `weight` × the splats of a work unit, in the unit's order, and with the filter
    /// on also to partial image `buffer` (taken modulo their number).
    pub fn add_weighted_splats(&mut self, splats: &[Splat], weight: f64, buffer: usize) {
        add_weighted(&mut self.splats, splats, weight);
        self.add_to_partial(splats, weight, buffer);
    }

    fn add_to_partial(&mut self, splats: &[Splat], weight: f64, buffer: usize) {
        let buffers = self.filter_buffers();
        if buffers > 0 {
            let buffer = buffer % buffers;
            for splat in splats {
                let partial = &mut self.partials[splat.pixel as usize * buffers + buffer];
                for (s, v) in partial.iter_mut().zip(splat.value.to_array()) {
                    *s += (v as f64 * weight) as f32;
                }
            }
        }
    }

    /// Adds per-(pixel, partial image) splat sums, in `partials` order (pixel by pixel, each
    /// pixel's `filter_buffers()` partials in turn); their total must also be added with
    /// `add_splat_sums`.
    pub fn add_partial_splat_sums(&mut self, sums: impl Iterator<Item = [f64; 3]>) {
        for (partial, sum) in self.partials.iter_mut().zip(sums) {
            for (p, s) in partial.iter_mut().zip(sum) {
                *p += s as f32;
            }
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

    /// Writes the estimate per pixel as RGB floats, rows top to bottom: the mean of the
    /// pixel's own samples plus the splats, which are normalized by the light paths per
    /// pixel (each light path's splats estimate the whole film once). With the filter on,
    /// the splats are filtered (the pixels' own samples are not: they are a Metropolis
    /// render's direct pass), and `unfiltered`, if given, receives the image without it.
    pub fn write_rgb(&self, out: &mut [f32], unfiltered: Option<&mut [f32]>) -> FilterStats {
        let combined;
        let splats = if self.chain_layers.is_empty() {
            &self.splats
        } else {
            combined = self.splats_with_chain_layers();
            &combined
        };
        let Some(filter) = &self.filter else {
            self.write_rgb_with(out, splats);
            if let Some(unfiltered) = unfiltered {
                unfiltered.copy_from_slice(out);
            }
            return FilterStats::default();
        };
        let (filtered, stats) = filter_splats(self.width as usize, filter, &self.partials, splats);
        self.write_rgb_with(out, &filtered);
        if let Some(unfiltered) = unfiltered {
            self.write_rgb_with(unfiltered, splats);
        }
        stats
    }

    /// The splats plus every chain layer times its factor.
    fn splats_with_chain_layers(&self) -> Vec<[f64; 3]> {
        let pixels = self.counts.len();
        let mut combined = if self.splats.is_empty() {
            vec![[0.0; 3]; pixels]
        } else {
            self.splats.clone()
        };
        for (layer, &scale) in self
            .chain_layers
            .chunks_exact(pixels)
            .zip(&self.chain_layer_scales)
        {
            for (total, value) in combined.iter_mut().zip(layer) {
                for c in 0..3 {
                    total[c] += value[c] * scale;
                }
            }
        }
        combined
    }

    fn write_rgb_with(&self, out: &mut [f32], splats: &[[f64; 3]]) {
        let pixels = self.counts.len() as f64;
        let splat_scale = if let Some(scale) = self.splat_scale {
            scale
        } else if self.light_paths > 0 {
            pixels / self.light_paths as f64
        } else {
            0.0
        };
        for (i, ((pixel, sum), &count)) in out
            .chunks_exact_mut(3)
            .zip(&self.sums)
            .zip(&self.counts)
            .enumerate()
        {
            let scale = if count > 0 { 1.0 / count as f64 } else { 0.0 };
            let splat = splats.get(i).copied().unwrap_or([0.0; 3]);
            for c in 0..3 {
                pixel[c] = (sum[c] * scale + splat[c] * splat_scale) as f32;
            }
        }
    }
}

/// Adds `weight` × each splat to its pixel of `sums`, in order.
fn add_weighted(sums: &mut [[f64; 3]], splats: &[Splat], weight: f64) {
    for splat in splats {
        let sum = &mut sums[splat.pixel as usize];
        for (s, v) in sum.iter_mut().zip(splat.value.to_array()) {
            *s += v as f64 * weight;
        }
    }
}
