//! Where an estimator's random numbers come from: an independent stream (`Rng`) for Monte
//! Carlo, or a Markov chain's primary sample vector for Metropolis.

use super::Rng;

pub trait Sampler {
    /// The next number in [0, 1).
    fn uniform(&mut self) -> f32;

    #[inline]
    fn uniform2(&mut self) -> [f32; 2] {
        [self.uniform(), self.uniform()]
    }

    /// Continues from the start of stream `stream`. A Metropolis sampler interleaves its
    /// coordinates by stream, so that the numbers a part of the estimator reads (the camera
    /// subpath, the light subpath, the connection) keep their coordinates when another part
    /// reads more or fewer. Independent samplers have one stream and ignore this.
    #[inline]
    fn start_stream(&mut self, _stream: usize) {}
}

impl Sampler for Rng {
    #[inline]
    fn uniform(&mut self) -> f32 {
        Rng::uniform(self)
    }
}
