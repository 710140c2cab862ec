//! Standard normal variates by the ziggurat method (Marsaglia & Tsang 2000): 128 layers of
//! equal area under the density; almost every draw costs one random word and a comparison,
//! where Box–Muller costs a logarithm and a sine and cosine per pair.

use super::Rng;
use std::sync::LazyLock;

const LAYERS: usize = 128;
/// Where the tail begins, for 128 layers.
const TAIL_START: f64 = 3.442_619_855_899;
/// The area of each layer (and of the base strip with the tail).
const LAYER_AREA: f64 = 9.912_563_035_262_17e-3;

/// `x[i]`: the right edge of layer i (x[0]: the base strip's pseudo-width, x[1] the tail's
/// start, decreasing to x[LAYERS] = 0); `f[i]` the density (unnormalized) there.
struct Layers {
    x: [f32; LAYERS + 1],
    f: [f32; LAYERS + 1],
}

static LAYERS_TABLE: LazyLock<Layers> = LazyLock::new(|| {
    let density = |x: f64| (-0.5 * x * x).exp();
    let mut x = [0.0f64; LAYERS + 1];
    x[0] = LAYER_AREA / density(TAIL_START);
    x[1] = TAIL_START;
    for i in 1..LAYERS - 1 {
        x[i + 1] = (-2.0 * (LAYER_AREA / x[i] + density(x[i])).ln()).sqrt();
    }
    x[LAYERS] = 0.0;
    Layers {
        x: x.map(|v| v as f32),
        f: x.map(|v| density(v) as f32),
    }
});

/// A standard normal variate.
#[inline]
pub fn standard_normal(rng: &mut Rng) -> f32 {
    let layers = &*LAYERS_TABLE;
    loop {
        let bits = rng.next_u32();
        let i = (bits as usize) & (LAYERS - 1);
        // The other 25 bits: uniform in [-1, 1).
        let u = (bits >> 7) as f32 * (1.0 / 16_777_216.0) - 1.0;
        let x = u * layers.x[i];
        if x.abs() < layers.x[i + 1] {
            return x;
        }
        if i == 0 {
            return tail(rng).copysign(u);
        }
        // In the layer's sliver beyond the inner rectangle: accept under the density.
        let y = layers.f[i] + rng.uniform() * (layers.f[i + 1] - layers.f[i]);
        if y < (-0.5 * x * x).exp() {
            return x;
        }
    }
}

/// |x| beyond TAIL_START, distributed as the normal's tail (Marsaglia 1964).
#[cold]
fn tail(rng: &mut Rng) -> f32 {
    let start = TAIL_START as f32;
    loop {
        let a = -(1.0 - rng.uniform()).ln() / start;
        let b = -(1.0 - rng.uniform()).ln();
        if 2.0 * b > a * a {
            return start + a;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard normal CDF (Abramowitz–Stegun 7.1.26 via erf, error < 1.5e-7).
    fn normal_cdf(x: f64) -> f64 {
        let z = x.abs() / std::f64::consts::SQRT_2;
        let t = 1.0 / (1.0 + 0.327_591_1 * z);
        let poly = t
            * (0.254_829_592
                + t * (-0.284_496_736
                    + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
        let erf = 1.0 - poly * (-z * z).exp();
        0.5 * (1.0 + erf.copysign(x))
    }

    #[test]
    fn the_layers_close_at_zero() {
        // The recurrence must end near 0 for these constants, or the layers' areas differ.
        let layers = &*LAYERS_TABLE;
        let last_computed = layers.x[LAYERS - 1];
        assert!(
            last_computed > 0.0 && last_computed < 0.3,
            "{last_computed}"
        );
        assert!(layers.x.windows(2).skip(1).all(|w| w[0] > w[1]));
    }

    #[test]
    fn matches_the_normal_distribution() {
        let mut rng = Rng::new(3, 5);
        let n = 2_000_000usize;
        let edges: Vec<f64> = (-16..=16)
            .map(|k| k as f64 * 0.25)
            .chain([3.6, 4.0])
            .collect();
        let mut below = vec![0u64; edges.len()];
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let x = standard_normal(&mut rng) as f64;
            sum += x;
            sum2 += x * x;
            for (count, &edge) in below.iter_mut().zip(&edges) {
                *count += (x < edge) as u64;
            }
        }
        // Each empirical CDF value within 5 standard errors of the true one.
        for (&count, &edge) in below.iter().zip(&edges) {
            let p = normal_cdf(edge);
            let got = count as f64 / n as f64;
            let se = (p * (1.0 - p) / n as f64).sqrt().max(1e-7);
            assert!(
                (got - p).abs() < 5.0 * se,
                "P(x < {edge}) = {got}, expected {p}"
            );
        }
        let mean = sum / n as f64;
        let variance = sum2 / n as f64 - mean * mean;
        assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "{mean}");
        assert!(
            (variance - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(),
            "{variance}"
        );
    }
}
