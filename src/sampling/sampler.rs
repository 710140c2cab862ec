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
}

impl Sampler for Rng {
    #[inline]
    fn uniform(&mut self) -> f32 {
        Rng::uniform(self)
    }
}
