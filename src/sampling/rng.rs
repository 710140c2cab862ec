//! A small, fast PCG32 generator whose streams are derived by hashing, so that any
//! (seed, pixel, sample) triple gets its own reproducible sequence.

/// PCG-XSH-RR 32-bit generator (O'Neill 2014).
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    increment: u64,
}

const PCG_MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// SplitMix64 finalizer: a bijective 64-bit mix with good avalanche.
#[inline]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The top 24 bits of `bits` as a float in [0, 1): exactly representable, so 1.0 is never
/// returned.
#[inline]
pub fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

impl Rng {
    /// A generator for `stream` of `seed`: distinct streams are statistically independent.
    #[inline]
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Rng {
            state: 0,
            increment: (mix64(stream ^ 0x9e37_79b9_7f4a_7c15) << 1) | 1,
        };
        rng.next_u32();
        // The starting state depends on the stream too: PCG streams that differ only in
        // their increment and share a state are correlated.
        rng.state = rng.state.wrapping_add(mix64(seed ^ mix64(stream)));
        rng.next_u32();
        rng
    }

    /// The generator of one pixel sample: depends only on its arguments, never on scheduling.
    #[inline]
    pub fn for_pixel_sample(seed: u64, pixel: u64, sample: u64) -> Self {
        Rng::new(
            mix64(seed ^ mix64(sample.wrapping_add(0x632b_e59b_d9b4_e019))),
            pixel,
        )
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(PCG_MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1): 24 random mantissa bits, so 1.0 is never returned.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        unit_float(self.next_u32())
    }

    #[inline]
    pub fn uniform2(&mut self) -> [f32; 2] {
        [self.uniform(), self.uniform()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_is_in_unit_interval_with_mean_one_half() {
        let mut rng = Rng::new(7, 3);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let u = rng.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u as f64;
        }
        let mean = sum / n as f64;
        // Standard error of the mean of U(0,1) is sqrt(1/12/n) ≈ 6.5e-4.
        assert!(
            (mean - 0.5).abs() < 4.0 * (1.0 / 12.0 / n as f64).sqrt(),
            "{mean}"
        );
    }

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u32> = (0..8)
            .map({
                let mut r = Rng::for_pixel_sample(1, 2, 3);
                move |_| r.next_u32()
            })
            .collect();
        let b: Vec<u32> = (0..8)
            .map({
                let mut r = Rng::for_pixel_sample(1, 2, 3);
                move |_| r.next_u32()
            })
            .collect();
        let c: Vec<u32> = (0..8)
            .map({
                let mut r = Rng::for_pixel_sample(1, 2, 4);
                move |_| r.next_u32()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
