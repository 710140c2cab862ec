//! Low-discrepancy camera samples: a padded, shuffled, digitally shifted (0, 2)-sequence.
//!
//! Every read of a camera sample's numbers takes a *slot*, one after the other. A slot's
//! points over the samples of one pixel are the first two dimensions of the Sobol sequence
//! (a (0, 2)-sequence: every prefix of 2^k points has one point in each elementary interval
//! of area 2^-k), the sample index shuffled by a nested uniform scramble (Burley 2020,
//! "Practical Hash-based Owen Scrambling": a Laine–Karras hash of the reversed index) and
//! each dimension XORed with a random word (a digital shift). Each slot of each pixel hashes
//! its own shuffle and shifts, so:
//! - every point on its own is uniform in [0, 1)² (the shift), and estimates stay unbiased;
//! - a pixel's samples of one slot are stratified at every power-of-two count, in 1D for a
//!   single number and in 2D for a pair: a light sample or a BSDF sample at a given bounce
//!   converges faster than independent numbers would;
//! - slots are independent of each other (the shuffle decorrelates them: "padding"), pixels
//!   of each other, and seeds of each other, which the statistical tests rely on;
//! - a sample's numbers depend only on (seed, pixel, sample index, slot), never on
//!   scheduling, so images stay identical for any thread count.
//!
//! Why a digital shift and not an Owen scramble of the points: on the Cornell scenes the
//! per-sample RMSE is the same within a percent either way (benches/mitsuba/sampler_compare.py,
//! README), while the Owen scramble's two more hashes and three bit reversals per slot made
//! the path tracer 20% slower; the shift costs one XOR, and with the Sobol matrix applied to
//! the reversed index by byte tables no slot needs a bit reversal at all.
//!
//! The estimators read a fixed number of slots per path vertex, so Russian roulette and lobe
//! selection keep their own slots at each bounce. Streams (`Sampler::start_stream`) start at
//! fixed slots, so BDPT's light subpath and connections do not move with the camera
//! subpath's length.

use super::Sampler;
use super::rng::{mix64, unit_float};

/// Column i of the generator matrix of Sobol dimension 1 (the Pascal matrix mod 2), with the
/// most significant bit first: v_0 = 2^31, v_i = v_{i-1} ^ (v_{i-1} >> 1).
const fn sobol_1_columns() -> [u32; 32] {
    let mut columns = [0u32; 32];
    let mut column = 1u32 << 31;
    let mut i = 0;
    while i < 32 {
        columns[i] = column;
        column ^= column >> 1;
        i += 1;
    }
    columns
}

/// Sobol dimension 1 of an index given bit-reversed, as four byte tables: the generator
/// matrix is linear over GF(2), so each byte contributes the XOR of its set bits' columns
/// (bit k of the reversed index is bit 31 - k of the index).
const SOBOL_1_OF_REVERSED: [[u32; 256]; 4] = {
    let columns = sobol_1_columns();
    let mut tables = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut value = 0;
        while value < 256 {
            let mut sum = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if value & (1 << bit) != 0 {
                    sum ^= columns[31 - (byte * 8 + bit)];
                }
                bit += 1;
            }
            tables[byte][value] = sum;
            value += 1;
        }
        byte += 1;
    }
    tables
};

/// Sobol dimension 1 of the index whose bit reversal is `reversed`.
#[inline]
fn sobol_1_of_reversed(reversed: u32) -> u32 {
    let [b0, b1, b2, b3] = reversed.to_le_bytes();
    SOBOL_1_OF_REVERSED[0][b0 as usize]
        ^ SOBOL_1_OF_REVERSED[1][b1 as usize]
        ^ SOBOL_1_OF_REVERSED[2][b2 as usize]
        ^ SOBOL_1_OF_REVERSED[3][b3 as usize]
}

/// A hash of `x` (bit-reversed) in which each output bit is its input bit flipped by a
/// function of the less significant bits and `seed`: on a bit-reversed index, a nested
/// uniform scramble, which maps every aligned block of 2^k indices onto another. The form
/// is Laine and Karras's (2011); the constants are Vegdahl's (2021).
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// The slot of the in-pixel film position: apart from the slots the estimators count.
const FILM_SLOT: u32 = u32::MAX;
/// Slots each stream may use before the next stream's first (a path of 2^16 vertices).
const SLOTS_PER_STREAM: u32 = 1 << 20;

/// The numbers of one camera sample: sample `index` of pixel `pixel` under `seed`.
#[derive(Clone, Debug)]
pub struct PixelSampler {
    /// A hash of (seed, pixel): every slot's scrambles derive from it.
    key: u64,
    /// The sample index, bit-reversed (the form the index shuffle takes).
    reversed_index: u32,
    /// The next slot.
    slot: u32,
}

impl PixelSampler {
    #[inline]
    pub fn new(seed: u64, pixel: u64, index: u32) -> Self {
        PixelSampler {
            key: mix64(mix64(seed ^ 0x5a3c_0f1e_d2b4_9687) ^ pixel),
            reversed_index: index.reverse_bits(),
            slot: 0,
        }
    }

    /// The sample's position within its pixel, in [0, 1)², from a slot of its own.
    #[inline]
    pub fn film_position(&self) -> [f32; 2] {
        self.point_2d(FILM_SLOT)
    }

    /// The three scramble words of `slot`: the index shuffle's and each dimension's shift.
    #[inline]
    fn seeds(&self, slot: u32) -> (u32, u32, u32) {
        let hash = mix64(self.key ^ (slot as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        // A third word from the same hash: the high half of an odd multiple.
        let more = (hash.wrapping_mul(0xd1b5_4a32_d192_ed03) >> 32) as u32;
        (hash as u32, (hash >> 32) as u32, more)
    }

    /// Van der Corput of the sample's index shuffled for `seed` (a nested uniform scramble:
    /// the first 2^k indices map onto an aligned block of 2^k, so the stratification of
    /// every power-of-two prefix survives). Van der Corput is the index bit-reversed, so it
    /// is the scrambled reversed index itself.
    #[inline]
    fn shuffled_van_der_corput(&self, seed: u32) -> u32 {
        laine_karras(self.reversed_index, seed)
    }

    #[inline]
    fn point_1d(&self, slot: u32) -> f32 {
        let (shuffle, shift, _) = self.seeds(slot);
        unit_float(self.shuffled_van_der_corput(shuffle) ^ shift)
    }

    #[inline]
    fn point_2d(&self, slot: u32) -> [f32; 2] {
        let (shuffle, shift_x, shift_y) = self.seeds(slot);
        let x = self.shuffled_van_der_corput(shuffle);
        [
            unit_float(x ^ shift_x),
            unit_float(sobol_1_of_reversed(x) ^ shift_y),
        ]
    }
}

impl Sampler for PixelSampler {
    #[inline]
    fn uniform(&mut self) -> f32 {
        let u = self.point_1d(self.slot);
        self.slot += 1;
        u
    }

    #[inline]
    fn uniform2(&mut self) -> [f32; 2] {
        let u = self.point_2d(self.slot);
        self.slot += 1;
        u
    }

    #[inline]
    fn start_stream(&mut self, stream: usize) {
        self.slot = stream as u32 * SLOTS_PER_STREAM;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slot `slot`'s 2D points of samples 0..n of one pixel.
    fn points(seed: u64, pixel: u64, n: u32, slot: u32) -> Vec<[f32; 2]> {
        (0..n)
            .map(|i| PixelSampler::new(seed, pixel, i).point_2d(slot))
            .collect()
    }

    /// Whether `points` put one point in every elementary interval of area 1/len.
    fn is_02_net(points: &[[f32; 2]]) -> bool {
        let n = points.len() as u32;
        let k = n.trailing_zeros();
        (0..=k).all(|a| {
            let (columns, rows) = (1u32 << a, 1u32 << (k - a));
            let mut cells = vec![0u32; n as usize];
            for &[x, y] in points {
                let cell = (y * rows as f32) as u32 * columns + (x * columns as f32) as u32;
                cells[cell as usize] += 1;
            }
            cells.iter().all(|&c| c == 1)
        })
    }

    #[test]
    fn sobol_1_tables_match_the_generator_matrix() {
        let columns = sobol_1_columns();
        for index in [0u32, 1, 2, 3, 5, 255, 256, 0x1234_5678, u32::MAX] {
            let mut direct = 0u32;
            for (bit, column) in columns.iter().enumerate() {
                if index & (1 << bit) != 0 {
                    direct ^= column;
                }
            }
            assert_eq!(sobol_1_of_reversed(index.reverse_bits()), direct, "{index}");
        }
    }

    #[test]
    fn every_power_of_two_prefix_of_a_pixel_slot_is_a_02_net() {
        for (seed, pixel, slot) in [(1, 0, 0), (1, 7, 3), (9, 123_456, 40), (2, 5, FILM_SLOT)] {
            for k in 0..=10u32 {
                let prefix = points(seed, pixel, 1 << k, slot);
                assert!(
                    is_02_net(&prefix),
                    "seed {seed} pixel {pixel} slot {slot} n 2^{k}"
                );
            }
            // And 1D: one point in each interval of length 1/n.
            let n = 256;
            let mut cells = vec![0u32; n];
            for i in 0..n as u32 {
                let u = PixelSampler::new(seed, pixel, i).point_1d(slot);
                cells[(u * n as f32) as usize] += 1;
            }
            assert!(cells.iter().all(|&c| c == 1));
        }
    }

    /// Each point alone is uniform over seeds (what keeps estimates unbiased): sample 5 of a
    /// pixel over many seeds has the mean and variance of U(0, 1) in both dimensions, and
    /// a uniform histogram.
    #[test]
    fn each_point_is_uniform_over_seeds() {
        let n = 200_000u64;
        let bins = 16;
        let mut histogram = vec![[0u64; 2]; bins];
        let (mut sum, mut sum2) = ([0.0f64; 2], [0.0f64; 2]);
        for seed in 0..n {
            let p = PixelSampler::new(seed, 77, 5).point_2d(2);
            for d in 0..2 {
                sum[d] += p[d] as f64;
                sum2[d] += (p[d] as f64).powi(2);
                histogram[(p[d] * bins as f32) as usize][d] += 1;
            }
        }
        for d in 0..2 {
            let mean = sum[d] / n as f64;
            let variance = sum2[d] / n as f64 - mean * mean;
            // Standard errors: 0.00065 for the mean, 0.00019 for the variance.
            assert!((mean - 0.5).abs() < 0.004, "{mean}");
            assert!((variance - 1.0 / 12.0).abs() < 0.0012, "{variance}");
            let expected = n as f64 / bins as f64;
            let chi2: f64 = histogram
                .iter()
                .map(|h| (h[d] as f64 - expected).powi(2) / expected)
                .sum();
            // 15 degrees of freedom: P(χ² > 50) ≈ 10⁻⁵.
            assert!(chi2 < 50.0, "dimension {d}: χ² {chi2}");
        }
    }

    /// Slots, pixels and seeds are independent: the correlation of two numbers over many
    /// pixels' samples is near zero for two slots of one sample, for one slot of two
    /// pixels, and for one slot under two seeds.
    #[test]
    fn slots_pixels_and_seeds_are_uncorrelated() {
        let n = 100_000u64;
        let correlation = |pairs: &dyn Fn(u64) -> (f32, f32)| {
            let (mut sx, mut sy, mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for i in 0..n {
                let (x, y) = pairs(i);
                let (x, y) = (x as f64, y as f64);
                sx += x;
                sy += y;
                sxy += x * y;
                sxx += x * x;
                syy += y * y;
            }
            let nf = n as f64;
            let cov = sxy / nf - sx * sy / nf / nf;
            cov / ((sxx / nf - (sx / nf).powi(2)) * (syy / nf - (sy / nf).powi(2))).sqrt()
        };
        // 1/√n = 0.0032: 5 standard errors.
        let limit = 0.016;
        let index = |i: u64| (i % 64) as u32;
        type SamplePairs<'a> = &'a dyn Fn(u64) -> (f32, f32);
        let cases: [(&str, SamplePairs); 4] = [
            ("slot 0 and slot 1", &|i| {
                let s = PixelSampler::new(3, i / 64, index(i));
                (s.point_1d(0), s.point_1d(1))
            }),
            ("the two dimensions of a slot", &|i| {
                let [x, y] = PixelSampler::new(3, i / 64, index(i)).point_2d(4);
                (x, y)
            }),
            ("neighbouring pixels", &|i| {
                let a = PixelSampler::new(3, i / 64, index(i)).point_1d(2);
                let b = PixelSampler::new(3, i / 64 + 1, index(i)).point_1d(2);
                (a, b)
            }),
            ("seeds 3 and 4", &|i| {
                let a = PixelSampler::new(3, i / 64, index(i)).point_1d(2);
                let b = PixelSampler::new(4, i / 64, index(i)).point_1d(2);
                (a, b)
            }),
        ];
        for (name, pairs) in cases {
            let r = correlation(pairs);
            assert!(r.abs() < limit, "{name}: correlation {r}");
        }
    }

    /// What the stratification buys: a pixel's 256 samples of one slot integrate a smooth
    /// function with an RMS error (over 200 pixels) under a tenth of independent samples'
    /// σ/√n, and an edge (a disc's indicator, a light's outline) under half of it.
    #[test]
    fn a_pixel_slot_integrates_faster_than_independent_samples() {
        let n = 256u32;
        let pixels = 200u64;
        let smooth = |[x, y]: [f32; 2]| ((x * 3.0).sin() * (y * 2.0).cos() + x * y) as f64;
        let disc =
            |[x, y]: [f32; 2]| (((x - 0.4).powi(2) + (y - 0.55).powi(2)) < 0.09) as u8 as f64;
        type Integrand<'a> = &'a dyn Fn([f32; 2]) -> f64;
        let cases: [(&str, Integrand, f64); 2] = [("smooth", &smooth, 0.1), ("disc", &disc, 0.5)];
        for (name, f, ratio) in cases {
            // The exact integral and σ from a fine grid.
            let grid = 1024;
            let values: Vec<f64> = (0..grid * grid)
                .map(|i| {
                    let x = ((i % grid) as f32 + 0.5) / grid as f32;
                    let y = ((i / grid) as f32 + 0.5) / grid as f32;
                    f([x, y])
                })
                .collect();
            let exact = values.iter().sum::<f64>() / values.len() as f64;
            let sigma = (values.iter().map(|v| (v - exact).powi(2)).sum::<f64>()
                / values.len() as f64)
                .sqrt();
            let squared: f64 = (0..pixels)
                .map(|pixel| {
                    let mean = (0..n)
                        .map(|i| f(PixelSampler::new(11, pixel, i).point_2d(6)))
                        .sum::<f64>()
                        / n as f64;
                    (mean - exact).powi(2)
                })
                .sum();
            let rms = (squared / pixels as f64).sqrt();
            let independent = sigma / (n as f64).sqrt();
            assert!(
                rms < ratio * independent,
                "{name}: RMS error {rms:.2e}, independent samples' {independent:.2e}"
            );
        }
    }

    #[test]
    fn reads_take_consecutive_slots_and_streams_start_at_fixed_ones() {
        let mut sampler = PixelSampler::new(5, 9, 3);
        let reference = sampler.clone();
        let a = sampler.uniform();
        let b = sampler.uniform2();
        assert_eq!(a, reference.point_1d(0));
        assert_eq!(b, reference.point_2d(1));
        sampler.start_stream(2);
        assert_eq!(sampler.uniform(), reference.point_1d(2 * SLOTS_PER_STREAM));
        assert_eq!(reference.film_position(), reference.point_2d(FILM_SLOT));
    }
}
