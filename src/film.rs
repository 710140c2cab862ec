//! The film: per-pixel sums of radiance samples and the number of samples taken, turned into
//! an image normalized pixel by pixel (so a partial render is still a valid estimate).
//!
//! Every sum is exact: values are rounded once to a fixed-point grid (`FixedPoint`) and
//! added as integers, so a sum does not depend on the order of its terms. Films of work
//! done apart (threads, processes, machines) merge into the bits of one film that did it
//! all (`Film::merge`).

use crate::filter::{FilterSettings, FilterStats, filter_splats};
use crate::spectrum::Spectrum;
use crate::wire::{Reader, Writer};
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

/// An exact sum of RGB values in units of a `FixedPoint`.
pub type FixedRgb = [i128; 3];

/// Fixed-point numbers for exact sums: 64 bits below a scale `2^exponent`, 63 above it.
/// A value is rounded to the grid once, then added as an integer (wrapping, so any order
/// gives the same bits). With the scale set to the scene's brightest light, contributions
/// 2^-64 of it and below are rounded away and a pixel may sum to 2^61 times it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedPoint {
    to_fixed: f64,
    to_float: f64,
}

impl FixedPoint {
    /// The bits below the scale.
    const FRACTION_BITS: i32 = 64;
    /// Largest magnitude of one rounded value, in units of the grid: its sum with a few
    /// more stays within an i128.
    const LIMIT: f64 = (1u128 << 125) as f64;

    /// Fixed point below `2^exponent` (clamped to ±900, where f64 still holds the scale).
    pub fn new(exponent: i32) -> FixedPoint {
        let shift = Self::FRACTION_BITS - exponent.clamp(-900, 900);
        FixedPoint {
            to_fixed: 2f64.powi(shift),
            to_float: 2f64.powi(-shift),
        }
    }

    /// Fixed point scaled to values of about `brightest` (0, or not finite: about 1).
    pub fn for_values_up_to(brightest: f32) -> FixedPoint {
        let exponent = if brightest > 0.0 && brightest.is_finite() {
            (brightest as f64).log2().ceil() as i32
        } else {
            0
        };
        FixedPoint::new(exponent)
    }

    /// log2 of the grid's spacing (the value of one unit).
    pub fn grid_log2(&self) -> i32 {
        self.to_float.log2() as i32
    }

    /// `value` on the grid, rounded to the nearest point (ties to even); NaN is 0 and
    /// magnitudes beyond the range are clamped.
    #[inline]
    pub fn fixed(&self, value: f64) -> i128 {
        (value * self.to_fixed)
            .clamp(-Self::LIMIT, Self::LIMIT)
            .round_ties_even() as i128
    }

    #[inline]
    pub fn float(&self, sum: i128) -> f64 {
        sum as f64 * self.to_float
    }

    /// Adds `value` (each channel) to `sum`.
    #[inline]
    pub fn add(&self, sum: &mut FixedRgb, value: [f64; 3]) {
        for (s, v) in sum.iter_mut().zip(value) {
            *s = s.wrapping_add(self.fixed(v));
        }
    }

    fn rgb(&self, sum: &FixedRgb) -> [f64; 3] {
        sum.map(|s| self.float(s))
    }
}

/// Adds `other` to `sums` element by element.
fn add_sums(sums: &mut [FixedRgb], other: &[FixedRgb]) {
    for (sum, other) in sums.iter_mut().zip(other) {
        for (s, o) in sum.iter_mut().zip(other) {
            *s = s.wrapping_add(*o);
        }
    }
}

#[derive(Clone)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// The fixed point of the sums in the scene's units of light (`sums`, `splats`,
    /// `partials`) …
    scene_units: FixedPoint,
    /// … and of the chain layers, whose deposits are divided by their paths' values.
    chain_units: FixedPoint,
    /// Sum of radiance samples per pixel, RGB.
    sums: Vec<FixedRgb>,
    /// Samples taken per pixel.
    counts: Vec<u32>,
    /// Sum of splats (light tracing) per pixel; empty when the estimator does not splat.
    splats: Vec<FixedRgb>,
    /// Light paths traced in all, the normalization of the splats.
    light_paths: u64,
    /// Metropolis chains' deposits per group of chains, `chain_layers[group * pixels +
    /// pixel]`, kept apart because each group is scaled by its own normalization, known only
    /// when the render ends (48 bytes per pixel and group) …
    chain_layers: Vec<FixedRgb>,
    /// … by these factors (one per group), on top of the splat scale.
    chain_layer_scales: Vec<f64>,
    /// Overrides the splat normalization (Metropolis: pixels / mutations per chain).
    splat_scale: Option<f64>,
    /// The post-process filter (`crate::filter`), if on …
    filter: Option<FilterSettings>,
    /// … and the splats again, split into its partial images:
    /// `partials[pixel * buffers + buffer]`.
    partials: Vec<FixedRgb>,
}

/// A horizontal band of rows, the unit of parallel work: its pixels are contiguous.
pub struct FilmBand<'a> {
    pub first_row: u32,
    units: FixedPoint,
    sums: &'a mut [FixedRgb],
    counts: &'a mut [u32],
}

impl FilmBand<'_> {
    /// The band's pixels.
    pub(crate) fn len(&self) -> usize {
        self.counts.len()
    }

    /// Adds the sum of `count` samples to the band's pixel `i`.
    #[inline]
    pub fn add(&mut self, i: usize, sum: Spectrum, count: u32) {
        self.units
            .add(&mut self.sums[i], sum.to_array().map(|v| v as f64));
        self.counts[i] += count;
    }
}

impl Film {
    /// A film whose sums are exact below `scene_units` (`FixedPoint::for_values_up_to` the
    /// scene's brightest light).
    pub fn new(width: u32, height: u32, with_splats: bool, scene_units: FixedPoint) -> Self {
        let pixels = width as usize * height as usize;
        Film {
            width,
            height,
            scene_units,
            chain_units: FixedPoint::new(0),
            sums: vec![[0; 3]; pixels],
            counts: vec![0; pixels],
            splats: if with_splats {
                vec![[0; 3]; pixels]
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

    /// A film of the same size, units and chain layers, with nothing on it and no filter.
    pub fn empty_like(&self) -> Film {
        let mut film = Film::new(
            self.width,
            self.height,
            !self.splats.is_empty(),
            self.scene_units,
        );
        if !self.chain_layer_scales.is_empty() {
            film.enable_chain_layers(self.chain_layer_scales.len());
        }
        film
    }

    /// Turns the post-process filter on: splats are also kept in its partial images, and
    /// the written image is filtered (`crate::filter`).
    pub fn enable_filter(&mut self, settings: FilterSettings) {
        self.partials = vec![[0; 3]; self.splats.len() * settings.buffers as usize];
        self.filter = Some(settings);
    }

    /// Keeps the deposits of `groups` groups of Metropolis chains in layers of their own
    /// (`add_chain_splats`), each scaled by `set_chain_layer_scales` when written.
    pub fn enable_chain_layers(&mut self, groups: usize) {
        self.chain_layers = vec![[0; 3]; self.counts.len() * groups];
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
        add_weighted(self.chain_units, layer, splats, weight);
        self.add_to_partial(splats, weight * partial_scale, buffer);
    }

    /// Multiplies the chains' work on the film by `factor`: the splats (a Metropolis
    /// render's large steps), the partial images and every chain layer but `except` (the
    /// normalization pass's, which counts per sample). A job of a split render cut short
    /// scales its chains up to the mutations planned (`driver::tally`).
    pub fn scale_chain_work(&mut self, factor: f64, except: Option<usize>) {
        let scale = |units: FixedPoint, sums: &mut [FixedRgb]| {
            for sum in sums {
                *sum = sum.map(|v| units.fixed(units.float(v) * factor));
            }
        };
        scale(self.scene_units, &mut self.splats);
        scale(self.scene_units, &mut self.partials);
        let pixels = self.counts.len();
        for (layer, sums) in self.chain_layers.chunks_exact_mut(pixels).enumerate() {
            if Some(layer) != except {
                scale(self.chain_units, sums);
            }
        }
    }

    /// The layers of Metropolis chains' deposits (`enable_chain_layers`).
    pub fn chain_layer_count(&self) -> usize {
        self.chain_layer_scales.len()
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

    /// Adds `weight` × the splats of a work unit, in the unit's order, and with the filter
    /// on also to partial image `buffer` (taken modulo their number).
    pub fn add_weighted_splats(&mut self, splats: &[Splat], weight: f64, buffer: usize) {
        add_weighted(self.scene_units, &mut self.splats, splats, weight);
        self.add_to_partial(splats, weight, buffer);
    }

    fn add_to_partial(&mut self, splats: &[Splat], weight: f64, buffer: usize) {
        let buffers = self.filter_buffers();
        if buffers > 0 {
            let buffer = buffer % buffers;
            for splat in splats {
                let partial = &mut self.partials[splat.pixel as usize * buffers + buffer];
                let value = splat.value.to_array().map(|v| v as f64 * weight);
                self.scene_units.add(partial, value);
            }
        }
    }

    /// Adds integer per-pixel splat sums in units of `2^grid_log2` (at least the film's own
    /// grid, `scene_grid_log2`: then the conversion is exact, a shift, so sums made apart
    /// add up to the bits of one), standing for `light_paths` light paths; with
    /// `partials`, also the per-(pixel, partial image) sums in `partials` order.
    pub fn add_integer_splat_sums(
        &mut self,
        sums: impl Iterator<Item = [i64; 3]>,
        partials: Option<&mut dyn Iterator<Item = [i64; 3]>>,
        grid_log2: i32,
        light_paths: u64,
    ) {
        let shift = grid_log2 - self.scene_units.grid_log2();
        assert!(
            shift >= 0,
            "a grid of 2^{grid_log2} is finer than the film's"
        );
        // Beyond the film's range (a deposit energy far above the scene's brightest light),
        // values are clamped as `FixedPoint::fixed` clamps them.
        let limit = 1i128 << 125;
        let bound = if shift < 126 { limit >> shift } else { 0 };
        let convert = |v: [i64; 3]| {
            v.map(|c| {
                let c = c as i128;
                if c == 0 {
                    0
                } else if c.abs() <= bound {
                    c << shift
                } else {
                    c.signum() * limit
                }
            })
        };
        self.light_paths += light_paths;
        for (total, sum) in self.splats.iter_mut().zip(sums) {
            add_sums(std::slice::from_mut(total), &[convert(sum)]);
        }
        if let Some(partials) = partials {
            for (total, sum) in self.partials.iter_mut().zip(partials) {
                add_sums(std::slice::from_mut(total), &[convert(sum)]);
            }
        }
    }

    /// log2 of the spacing of the film's grid in the scene's units of light.
    pub fn scene_grid_log2(&self) -> i32 {
        self.scene_units.grid_log2()
    }

    /// Splits the film into bands of `rows` rows for parallel iteration, in row order.
    pub fn par_bands(&mut self, rows: u32) -> impl IndexedParallelIterator<Item = FilmBand<'_>> {
        let width = self.width;
        let units = self.scene_units;
        let band_pixels = (rows * width) as usize;
        self.sums
            .par_chunks_mut(band_pixels)
            .zip(self.counts.par_chunks_mut(band_pixels))
            .enumerate()
            .map(move |(band, (sums, counts))| FilmBand {
                first_row: band as u32 * rows,
                units,
                sums,
                counts,
            })
    }

    /// Adds the work of `other`, a film of the same size and settings: the result has the
    /// bits of one film that did the work of both. The chain layers' factors and the splat
    /// scale are not work: they stay as set on `self`.
    pub fn merge(&mut self, other: &Film) -> Result<(), String> {
        let shape = |f: &Film| {
            (
                f.width,
                f.height,
                f.scene_units,
                f.splats.len(),
                f.chain_layers.len(),
                f.partials.len(),
            )
        };
        if shape(self) != shape(other) {
            return Err(format!(
                "the films differ in size, units or layers: {:?} and {:?}",
                shape(self),
                shape(other)
            ));
        }
        add_sums(&mut self.sums, &other.sums);
        for (count, other) in self.counts.iter_mut().zip(&other.counts) {
            *count += other;
        }
        add_sums(&mut self.splats, &other.splats);
        self.light_paths += other.light_paths;
        add_sums(&mut self.chain_layers, &other.chain_layers);
        add_sums(&mut self.partials, &other.partials);
        Ok(())
    }

    /// Writes the estimate per pixel as RGB floats, rows top to bottom: the mean of the
    /// pixel's own samples plus the splats, which are normalized by the light paths per
    /// pixel (each light path's splats estimate the whole film once). With the filter on,
    /// the splats are filtered (the pixels' own samples are not: they are a Metropolis
    /// render's direct pass), and `unfiltered`, if given, receives the image without it.
    pub fn write_rgb(&self, out: &mut [f32], unfiltered: Option<&mut [f32]>) -> FilterStats {
        let splats = self.splats_with_chain_layers();
        let splats = &splats;
        let Some(filter) = &self.filter else {
            self.write_rgb_with(out, splats);
            if let Some(unfiltered) = unfiltered {
                unfiltered.copy_from_slice(out);
            }
            return FilterStats::default();
        };
        let partials: Vec<[f32; 3]> = self
            .partials
            .iter()
            .map(|p| self.scene_units.rgb(p).map(|v| v as f32))
            .collect();
        let (filtered, stats) = filter_splats(self.width as usize, filter, &partials, splats);
        self.write_rgb_with(out, &filtered);
        if let Some(unfiltered) = unfiltered {
            self.write_rgb_with(unfiltered, splats);
        }
        stats
    }

    /// The splats plus every chain layer times its factor (empty without either).
    fn splats_with_chain_layers(&self) -> Vec<[f64; 3]> {
        let pixels = self.counts.len();
        let mut combined: Vec<[f64; 3]> = if self.splats.is_empty() {
            if self.chain_layers.is_empty() {
                return Vec::new();
            }
            vec![[0.0; 3]; pixels]
        } else {
            self.splats
                .iter()
                .map(|s| self.scene_units.rgb(s))
                .collect()
        };
        for (layer, &scale) in self
            .chain_layers
            .chunks_exact(pixels)
            .zip(&self.chain_layer_scales)
        {
            for (total, value) in combined.iter_mut().zip(layer) {
                let value = self.chain_units.rgb(value);
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
            let sum = self.scene_units.rgb(sum);
            let splat = splats.get(i).copied().unwrap_or([0.0; 3]);
            for c in 0..3 {
                pixel[c] = (sum[c] * scale + splat[c] * splat_scale) as f32;
            }
        }
    }
}

/// Writes a film's sums, counts and settings (`crate::render::jobs`: a job's partial result).
pub(crate) fn write_film(film: &Film, w: &mut Writer) {
    fn sums(w: &mut Writer, sums: &[FixedRgb]) {
        w.len(sums.len());
        for v in sums.iter().flatten() {
            w.varint_i128(*v);
        }
    }
    fn units(w: &mut Writer, units: FixedPoint) {
        w.f64(units.to_fixed);
        w.f64(units.to_float);
    }
    w.u32(film.width);
    w.u32(film.height);
    units(w, film.scene_units);
    units(w, film.chain_units);
    sums(w, &film.sums);
    for &count in &film.counts {
        w.varint_i128(count as i128);
    }
    sums(w, &film.splats);
    w.u64(film.light_paths);
    sums(w, &film.chain_layers);
    w.len(film.chain_layer_scales.len());
    for &scale in &film.chain_layer_scales {
        w.f64(scale);
    }
    w.bool(film.splat_scale.is_some());
    w.f64(film.splat_scale.unwrap_or(0.0));
    w.bool(film.filter.is_some());
    let filter = film.filter.unwrap_or(FilterSettings {
        buffers: 0,
        strength: 0.0,
        radius: 0,
    });
    w.u32(filter.buffers);
    w.f32(filter.strength);
    w.u32(filter.radius);
    sums(w, &film.partials);
}

/// Reads what `write_film` wrote; sizes that do not fit the film are an error.
pub(crate) fn read_film(r: &mut Reader) -> Result<Film, crate::Error> {
    fn sums(r: &mut Reader, multiple_of: usize) -> Result<Vec<FixedRgb>, crate::Error> {
        let n = r.len(3)?;
        if multiple_of == 0 || n % multiple_of != 0 {
            return Err(r.malformed("a layer of sums does not fit the film"));
        }
        (0..n)
            .map(|_| Ok([r.varint_i128()?, r.varint_i128()?, r.varint_i128()?]))
            .collect()
    }
    fn units(r: &mut Reader) -> Result<FixedPoint, crate::Error> {
        Ok(FixedPoint {
            to_fixed: r.f64()?,
            to_float: r.f64()?,
        })
    }
    let width = r.u32()?;
    let height = r.u32()?;
    let pixels = width as usize * height as usize;
    if pixels == 0 {
        return Err(r.malformed("the film has no pixels"));
    }
    let scene_units = units(r)?;
    let chain_units = units(r)?;
    let film_sums = sums(r, pixels)?;
    if film_sums.len() != pixels {
        return Err(r.malformed("the film's sums do not fit its size"));
    }
    let counts = (0..pixels)
        .map(|_| u32::try_from(r.varint_i128()?).map_err(|_| r.malformed("a sample count")))
        .collect::<Result<Vec<u32>, _>>()?;
    let splats = sums(r, pixels)?;
    if splats.len() > pixels {
        return Err(r.malformed("the film has more splats than pixels"));
    }
    let light_paths = r.u64()?;
    let chain_layers = sums(r, pixels)?;
    let layers = r.len(8)?;
    if layers * pixels != chain_layers.len() {
        return Err(r.malformed("the chain layers and their factors differ in number"));
    }
    let chain_layer_scales = (0..layers).map(|_| r.f64()).collect::<Result<_, _>>()?;
    let has_splat_scale = r.bool()?;
    let splat_scale = r.f64()?;
    let splat_scale = has_splat_scale.then_some(splat_scale);
    let filtered = r.bool()?;
    let filter = FilterSettings {
        buffers: r.u32()?,
        strength: r.f32()?,
        radius: r.u32()?,
    };
    let in_range = (crate::filter::MLT_MIN_FILTER_BUFFERS..=crate::filter::MLT_MAX_FILTER_BUFFERS)
        .contains(&filter.buffers)
        && filter.radius <= crate::filter::MLT_MAX_FILTER_RADIUS
        && (0.0..=crate::filter::MLT_MAX_FILTER_STRENGTH).contains(&filter.strength);
    if filtered && !in_range {
        return Err(r.malformed("the filter's settings are out of range"));
    }
    let partials = sums(r, pixels)?;
    let expected_partials = if filtered {
        splats.len() * filter.buffers as usize
    } else {
        0
    };
    if partials.len() != expected_partials {
        return Err(r.malformed("the filter's partial images do not fit the film"));
    }
    Ok(Film {
        width,
        height,
        scene_units,
        chain_units,
        sums: film_sums,
        counts,
        splats,
        light_paths,
        chain_layers,
        chain_layer_scales,
        splat_scale,
        filter: filtered.then_some(filter),
        partials,
    })
}

/// Adds `weight` × each splat to its pixel of `sums`.
fn add_weighted(units: FixedPoint, sums: &mut [FixedRgb], splats: &[Splat], weight: f64) {
    for splat in splats {
        let value = splat.value.to_array().map(|v| v as f64 * weight);
        units.add(&mut sums[splat.pixel as usize], value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn fixed_point_rounds_once_and_sums_in_any_order() {
        let units = FixedPoint::new(0);
        assert_eq!(units.fixed(1.0), 1 << 64);
        assert_eq!(units.fixed(-0.5), -(1 << 63));
        // Below half a unit of the grid rounds to 0; NaN is 0; the range is clamped.
        assert_eq!(units.fixed(2f64.powi(-66)), 0);
        assert_eq!(units.fixed(f64::NAN), 0);
        assert_eq!(units.fixed(f64::INFINITY), 1 << 125);
        assert_eq!(units.float(units.fixed(0.1)), 0.1);
        // f64 sums of these depend on their order; fixed-point sums do not.
        let values = [1e10, 1.0, -1e10, 3e-7, 0.1, 2.5e5];
        let in_order = values.iter().fold(0i128, |s, &v| s + units.fixed(v));
        let reversed = values.iter().rev().fold(0i128, |s, &v| s + units.fixed(v));
        assert_eq!(in_order, reversed);
        assert_ne!(values.iter().sum::<f64>(), values.iter().rev().sum::<f64>());
        // The scale follows the scene's brightest light.
        let bright = FixedPoint::for_values_up_to(3.0e9);
        assert_eq!(bright.fixed(2f64.powi(32)), 1 << 64);
        assert_eq!(FixedPoint::for_values_up_to(0.0), units);
        assert_eq!(FixedPoint::for_values_up_to(f32::NAN), units);
    }

    /// Random splats of every kind the film takes, as work units: (pixel samples, splats,
    /// chain deposits and their partials).
    fn work_units(film: &Film, count: usize) -> Vec<Vec<Splat>> {
        let pixels = (film.width * film.height) as u64;
        let mut rng = Rng::new(7, 11);
        (0..count)
            .map(|_| {
                (0..40)
                    .map(|_| {
                        let scale = 10f32.powi((rng.uniform() * 12.0) as i32 - 6);
                        Splat {
                            pixel: (rng.uniform() * pixels as f32) as u32 % pixels as u32,
                            value: Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * scale,
                        }
                    })
                    .collect()
            })
            .collect()
    }

    fn blank(units: FixedPoint) -> Film {
        let mut film = Film::new(5, 4, true, units);
        film.enable_chain_layers(2);
        film.enable_filter(FilterSettings {
            buffers: 3,
            strength: 0.45,
            radius: 2,
        });
        film.set_chain_layer_scales(&[0.7, 1.3]);
        film
    }

    fn add_work(film: &mut Film, units: &[(usize, &Vec<Splat>)]) {
        for &(u, splats) in units {
            film.add_splats(splats, 3);
            film.add_weighted_splats(splats, 0.25, u);
            film.add_chain_splats(u % 2, splats, 1.0 / 3.0, 0.5, u);
            let mut bands = film.par_bands(2).collect::<Vec<_>>();
            let band_count = bands.len();
            let band = &mut bands[u % band_count];
            for i in 0..band.len() {
                let v = splats[i % splats.len()].value;
                band.add(i, Spectrum::new(v.x, v.y, v.z), 2);
            }
        }
    }

    fn image(film: &Film) -> Vec<f32> {
        let mut out = vec![0.0; (film.width * film.height * 3) as usize];
        film.write_rgb(&mut out, None);
        out
    }

    #[test]
    fn films_of_work_done_apart_merge_into_the_bits_of_one() {
        let units = FixedPoint::for_values_up_to(40.0);
        let mut whole = blank(units);
        let work = work_units(&whole, 24);
        let indexed: Vec<(usize, &Vec<Splat>)> = work.iter().enumerate().collect();
        add_work(&mut whole, &indexed);
        let expected = image(&whole);
        assert!(expected.iter().all(|v| v.is_finite()) && expected.iter().any(|&v| v > 0.0));

        // Split into 1 to 5 parts by interleaving, each part in reverse order, merged from
        // the last part to the first.
        for parts in 1..=5 {
            let mut films: Vec<Film> = (0..parts).map(|_| blank(units)).collect();
            for (p, film) in films.iter_mut().enumerate() {
                let mine: Vec<(usize, &Vec<Splat>)> = indexed
                    .iter()
                    .rev()
                    .filter(|(u, _)| u % parts == p)
                    .copied()
                    .collect();
                add_work(film, &mine);
            }
            let mut merged = blank(units);
            for film in films.iter().rev() {
                merged.merge(film).unwrap();
            }
            assert_eq!(image(&merged), expected, "{parts} parts");
        }

        // Films of another shape or scale are refused.
        let mut other = Film::new(5, 4, true, units);
        assert!(other.merge(&whole).is_err());
        let mut other = blank(FixedPoint::new(0));
        assert!(other.merge(&whole).unwrap_err().contains("differ"));
    }
}
