//! Random numbers, distributions and warps used by every integrator.

#[cfg(test)]
pub(crate) mod chi_square;
mod distribution;
mod normal;
mod rng;
mod sampler;
mod sobol;
mod warp;

pub use distribution::{Distribution1D, Distribution2D};
pub use normal::standard_normal;
pub use rng::Rng;
pub use sampler::Sampler;
pub use sobol::PixelSampler;
pub use warp::{
    OrthonormalBasis, cosine_hemisphere, cosine_hemisphere_pdf, power_heuristic, uniform_disk,
    uniform_triangle,
};
