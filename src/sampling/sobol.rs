//! The first two dimensions of the Sobol sequence with a random digital shift: a (0, 2)-
//! sequence, so every prefix of 2^k points puts one point in each of the 2^k elementary
//! intervals of every shape. Camera samples take their positions within the pixel from it:
//! an edge crossing the pixel (a light's outline) then converges as N^(-3/4) instead of
//! N^(-1/2). The shift, random per pixel, keeps each point uniform on its own, so estimates
//! stay unbiased.

use super::rng::unit_float;

/// Point `index` of the shifted sequence in [0, 1)²; `shift` is a pair of random words.
#[inline]
pub fn shifted_sobol_2d(index: u32, shift: [u32; 2]) -> [f32; 2] {
    // Dimension 0 is the van der Corput sequence (bit reversal); dimension 1 uses the
    // generator matrix whose columns are v_i = v_{i-1} ^ (v_{i-1} >> 1).
    let first = index.reverse_bits();
    let mut second = 0u32;
    let mut column = 1u32 << 31;
    let mut bits = index;
    while bits != 0 {
        if bits & 1 != 0 {
            second ^= column;
        }
        column ^= column >> 1;
        bits >>= 1;
    }
    [unit_float(first ^ shift[0]), unit_float(second ^ shift[1])]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_power_of_two_prefix_is_stratified_in_every_elementary_interval() {
        let shift = [0x9e37_79b9, 0x7f4a_7c15];
        for k in 0..=8u32 {
            let n = 1u32 << k;
            // Every elementary interval of area 1/n: 2^a × 2^(k-a) cells.
            for a in 0..=k {
                let (columns, rows) = (1u32 << a, 1u32 << (k - a));
                let mut cells = vec![0u32; n as usize];
                for i in 0..n {
                    let [x, y] = shifted_sobol_2d(i, shift);
                    let cell = (y * rows as f32) as u32 * columns + (x * columns as f32) as u32;
                    cells[cell as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "n = {n}, {columns}×{rows}");
            }
        }
    }

    #[test]
    fn a_random_shift_makes_each_point_uniform() {
        // Point 5 under many shifts: mean 1/2 and variance 1/12 in each dimension.
        let mut rng = crate::sampling::Rng::new(1, 2);
        let n = 100_000;
        let (mut sum, mut sum2) = ([0.0f64; 2], [0.0f64; 2]);
        for _ in 0..n {
            let p = shifted_sobol_2d(5, [rng.next_u32(), rng.next_u32()]);
            for d in 0..2 {
                sum[d] += p[d] as f64;
                sum2[d] += (p[d] as f64).powi(2);
            }
        }
        for d in 0..2 {
            let mean = sum[d] / n as f64;
            let variance = sum2[d] / n as f64 - mean * mean;
            assert!((mean - 0.5).abs() < 0.005, "{mean}");
            assert!((variance - 1.0 / 12.0).abs() < 0.002, "{variance}");
        }
    }
}
