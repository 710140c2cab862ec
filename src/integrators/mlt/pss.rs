//! The primary-sample-space sampler of Kelemen et al. (2002): the chain's state is the vector
//! of uniform numbers an estimator consumes. Coordinates are mutated lazily, when the
//! estimator asks for them: a large step replaces a coordinate by a fresh uniform number, a
//! small step perturbs it by a wrapped Gaussian whose variance accumulates over the
//! iterations the coordinate was not read. A rejected proposal restores the backups.
//! Both steps are symmetric, so the transfer ratio is 1.

use crate::sampling::{Rng, Sampler, standard_normal};

#[derive(Clone, Copy, Debug)]
struct PrimarySample {
    value: f32,
    /// Iteration at which `value` was last brought up to date (`UNREAD`: never).
    modified: u64,
    backup_value: f32,
    backup_modified: u64,
}

/// `PrimarySample::modified` of a coordinate no evaluation has read.
const UNREAD: u64 = u64::MAX;

impl PrimarySample {
    const UNREAD: PrimarySample = PrimarySample {
        value: 0.0,
        modified: UNREAD,
        backup_value: 0.0,
        backup_modified: UNREAD,
    };
}

pub struct PssSampler {
    rng: Rng,
    samples: Vec<PrimarySample>,
    /// Coordinates are interleaved by stream: coordinate k of stream j is `j + k·streams`.
    streams: usize,
    stream: usize,
    /// The next coordinate of the current stream.
    next: usize,
    /// Values the first two coordinates of stream 0 (the film position) take in the first
    /// evaluation instead of random ones: the bootstrap stratifies the film with them.
    film_position: Option<[f32; 2]>,
    iteration: u64,
    large_step: bool,
    last_large_step: u64,
    large_step_probability: f32,
    /// Standard deviation of one small step.
    sigma: f32,
}

impl PssSampler {
    /// A sampler whose first evaluation (before any `start_iteration`) is an independent
    /// sample determined by (seed, stream): a chain restarted with the same pair reproduces
    /// the bootstrap path it was resampled from. `streams` is the number of interleaved
    /// streams (see `Sampler::start_stream`); `dimensions` the most coordinates an
    /// evaluation reads, reserved up front so that mutations never allocate.
    pub fn new(
        seed: u64,
        stream: u64,
        large_step_probability: f32,
        sigma: f32,
        streams: usize,
        dimensions: usize,
    ) -> Self {
        PssSampler {
            rng: Rng::new(seed, stream),
            samples: Vec::with_capacity(dimensions),
            streams: streams.max(1),
            stream: 0,
            next: 0,
            film_position: None,
            iteration: 0,
            large_step: true,
            last_large_step: 0,
            large_step_probability,
            sigma,
        }
    }

    /// Makes the sampler new again for (seed, stream), keeping its memory: the state
    /// `PssSampler::new` would give.
    pub fn restart(&mut self, seed: u64, stream: u64) {
        self.rng = Rng::new(seed, stream);
        self.samples.clear();
        self.stream = 0;
        self.next = 0;
        self.film_position = None;
        self.iteration = 0;
        self.large_step = true;
        self.last_large_step = 0;
    }

    /// `restart`, with the film position of the first evaluation given (in [0, 1)²).
    pub fn restart_at(&mut self, seed: u64, stream: u64, film_position: [f32; 2]) {
        self.restart(seed, stream);
        self.film_position = Some(film_position);
    }

    /// Continues with the random numbers of (seed, stream), keeping the state.
    pub fn reseed(&mut self, seed: u64, stream: u64) {
        self.rng = Rng::new(seed, stream);
    }

    /// Sets coordinate `index` of `stream`, which the current state has read, to `value`:
    /// a chain seeded from a sample that summed alternatives picks one this way.
    pub fn set_coordinate(&mut self, stream: usize, index: usize, value: f32) {
        let i = stream + index * self.streams;
        debug_assert!(i < self.samples.len() && (0.0..1.0).contains(&value));
        self.samples[i].value = value;
    }

    /// Begins an iteration that reads the current state unchanged (a small step of size 0),
    /// to check that a state evaluates as it did.
    #[cfg(test)]
    pub(crate) fn start_replay(&mut self) {
        self.sigma = 0.0;
        self.iteration += 1;
        self.large_step = false;
        self.stream = 0;
        self.next = 0;
    }

    /// Begins a proposal.
    pub fn start_iteration(&mut self) {
        self.iteration += 1;
        self.large_step = self.rng.uniform() < self.large_step_probability;
        self.stream = 0;
        self.next = 0;
    }

    pub fn is_large_step(&self) -> bool {
        self.large_step
    }

    /// A uniform number for the chain's own decisions (acceptance), outside the state.
    pub fn decision(&mut self) -> f32 {
        self.rng.uniform()
    }

    /// Keeps the proposal.
    pub fn accept(&mut self) {
        if self.large_step {
            self.last_large_step = self.iteration;
        }
    }

    /// Returns to the state before the proposal.
    pub fn reject(&mut self) {
        for x in &mut self.samples {
            if x.modified == self.iteration {
                x.value = x.backup_value;
                x.modified = x.backup_modified;
            }
        }
        self.iteration -= 1;
    }

    /// Brings coordinate `i` up to the current iteration. A coordinate read again in the same
    /// iteration keeps its value (BDPT reads its connection stream once per strategy).
    #[inline]
    fn ensure_ready(&mut self, i: usize) {
        if i >= self.samples.len() {
            self.samples.resize(i + 1, PrimarySample::UNREAD);
        }
        let x = &mut self.samples[i];
        if x.modified == self.iteration {
            return;
        }
        // Coordinates never read, or not read since the last accepted large step, are
        // independent of the state: draw them afresh as that large step would have.
        if x.modified == UNREAD || x.modified < self.last_large_step {
            x.value = self.rng.uniform();
            x.modified = self.last_large_step;
        }
        x.backup_value = x.value;
        x.backup_modified = x.modified;
        let preset = match self.film_position {
            Some(position) if self.iteration == 0 && i < 2 * self.streams => i
                .is_multiple_of(self.streams)
                .then(|| position[i / self.streams]),
            _ => None,
        };
        if let Some(value) = preset {
            x.value = value;
        } else if self.large_step {
            x.value = self.rng.uniform();
        } else {
            // Unread for k iterations, the coordinate takes the k small steps it missed at
            // once: their sum is Gaussian with k times the variance.
            let small_steps = self.iteration - x.modified;
            let mut step = self.sigma * standard_normal(&mut self.rng);
            if small_steps > 1 {
                step *= (small_steps as f32).sqrt();
            }
            x.value = wrap_to_unit(x.value + step);
        }
        x.modified = self.iteration;
    }
}

impl Sampler for PssSampler {
    #[inline]
    fn uniform(&mut self) -> f32 {
        let i = self.stream + self.next * self.streams;
        self.next += 1;
        self.ensure_ready(i);
        self.samples[i].value
    }

    #[inline]
    fn start_stream(&mut self, stream: usize) {
        debug_assert!(stream < self.streams);
        self.stream = stream;
        self.next = 0;
    }
}

/// `value` wrapped into [0, 1). Small steps rarely leave the interval by more than its
/// width, so branches usually replace `floor` (a libm call without SSE4.1).
#[inline]
fn wrap_to_unit(value: f32) -> f32 {
    let wrapped = if (0.0..1.0).contains(&value) {
        value
    } else if (-1.0..0.0).contains(&value) {
        value + 1.0
    } else if (1.0..2.0).contains(&value) {
        value - 1.0
    } else {
        value - value.floor()
    };
    // Rounding (a tiny negative value plus one) can land on 1.0 itself.
    if wrapped < 1.0 { wrapped } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejection_restores_the_state_exactly() {
        let mut s = PssSampler::new(1, 2, 0.3, 0.01, 1, 8);
        let first: Vec<f32> = (0..5).map(|_| s.uniform()).collect();
        for _ in 0..50 {
            s.start_iteration();
            let _: Vec<f32> = (0..5).map(|_| s.uniform()).collect();
            s.reject();
        }
        // Re-reading after rejections: an unchanged small step of size 0 is impossible, so
        // compare through a fresh iteration's backups instead: every value is restored.
        s.start_iteration();
        for (i, &v) in first.iter().enumerate() {
            s.ensure_ready(i);
            assert_eq!(s.samples[i].backup_value, v, "coordinate {i}");
        }
    }

    #[test]
    fn a_coordinate_read_twice_in_an_iteration_keeps_its_value() {
        let mut s = PssSampler::new(5, 6, 0.5, 0.01, 2, 8);
        let read = |s: &mut PssSampler| {
            s.start_stream(1);
            let first = s.uniform2();
            s.start_stream(1);
            assert_eq!(first, s.uniform2());
            first
        };
        let mut current = read(&mut s);
        for k in 0..200 {
            s.start_iteration();
            let proposal = read(&mut s);
            if k % 2 == 0 {
                s.accept();
                current = proposal;
            } else {
                s.reject();
                // The rejected proposal's second reading did not become the backup.
                s.start_replay();
                assert_eq!(read(&mut s), current);
                s.reject();
            }
        }
    }

    #[test]
    fn reproduces_its_first_sample() {
        let mut a = PssSampler::new(7, 9, 0.3, 0.01, 1, 8);
        let mut b = PssSampler::new(7, 9, 0.3, 0.01, 1, 8);
        let va: Vec<f32> = (0..6).map(|_| a.uniform()).collect();
        let vb: Vec<f32> = (0..6).map(|_| b.uniform()).collect();
        assert_eq!(va, vb);
    }

    #[test]
    fn coordinates_stay_uniform_under_mutation() {
        // The uniform density is stationary for these mutations when every proposal is
        // accepted: the mean and variance of a coordinate stay those of U(0, 1).
        let mut s = PssSampler::new(3, 4, 0.2, 0.05, 1, 2);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            s.start_iteration();
            let v = s.uniform() as f64;
            s.accept();
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / n as f64;
        let var = sum2 / n as f64 - mean * mean;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 0.005, "{var}");
    }
}

#[cfg(test)]
mod chain_tests {
    use super::*;
    use crate::integrators::mlt::acceptance;

    /// A chain over primary sample space with expected-value splatting reproduces a known
    /// target: f(u) = 1 + 3·u₀ on 16 bins of u₀ (discontinuous across the wrap-around).
    #[test]
    fn histogram_matches_a_ramp_target() {
        let f = |u0: f32, u1: f32| 1.0 + 3.0 * u0 + 0.0 * u1;
        let _ = f;
        // Reads a third coordinate only on the right half, like a path that bounces more.
        let eval = |s: &mut PssSampler| -> (f32, f32) {
            let u = s.uniform2();
            let v = if u[0] >= 0.5 {
                1.0 + 4.0 * s.uniform()
            } else {
                1.0
            };
            (u[0], v * (1.0 + 3.0 * u[0]))
        };
        let bins = 16;
        let mut histogram = vec![0.0f64; bins];
        for chain in 0..8u64 {
            let mut s = PssSampler::new(11, chain, 0.3, 0.05, 1, 2);
            let (mut x0, mut fx) = eval(&mut s);
            for _ in 0..400_000 {
                s.start_iteration();
                let (y0, fy) = eval(&mut s);
                let u = [y0];
                let a = acceptance(fx, fy, 1.0);
                histogram[(u[0] * bins as f32) as usize] += a as f64;
                histogram[(x0 * bins as f32) as usize] += 1.0 - a as f64;
                if s.decision() < a {
                    x0 = u[0];
                    fx = fy;
                    s.accept();
                } else {
                    s.reject();
                }
            }
        }
        let total: f64 = histogram.iter().sum();
        for (i, h) in histogram.iter().enumerate() {
            let center = (i as f64 + 0.5) / bins as f64;
            // ∫ f = ∫₀^½ (1+3u) du + 3·∫_½^1 (1+3u) du = 0.875 + 3·1.625 = 5.75.
            let weight = if center >= 0.5 { 3.0 } else { 1.0 };
            let expected = weight * (1.0 + 3.0 * center) / 5.75 / bins as f64;
            let got = h / total;
            assert!(
                (got - expected).abs() < 0.03 * expected,
                "bin {i}: {got} vs {expected}"
            );
        }
    }
}
