//! What every BSDF speaks: the quantity a path carries, a sampled scattering, and mirror
//! reflection.

use crate::spectrum::Spectrum;
use glam::Vec3A;

/// Which quantity a path carries; refraction scales radiance but not importance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    Radiance,
    Importance,
}

/// A sampled scattering direction.
#[derive(Clone, Copy, Debug)]
pub struct ScatterSample {
    pub wi: Vec3A,
    /// BSDF × |cos θi| / pdf: the factor the path throughput is multiplied by.
    pub weight: Spectrum,
    /// Solid-angle density of `wi` (for specular lobes, the discrete lobe probability).
    pub pdf: f32,
    /// A Dirac lobe: no other strategy can generate this direction.
    pub specular: bool,
}

/// Mirror reflection of `wo` about `normal` (either orientation).
#[inline]
pub fn reflect(wo: Vec3A, normal: Vec3A) -> Vec3A {
    normal * (2.0 * wo.dot(normal)) - wo
}
