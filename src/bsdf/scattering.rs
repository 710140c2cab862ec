//! What every BSDF speaks: the quantity a path carries, a sampled scattering, the classes
//! of lobes, and mirror reflection.

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
    /// The factor `weight` holds for radiance crossing into another medium, (η_i/η_t)² at
    /// a refraction in radiance mode, else 1. Russian roulette divides it out: a path in
    /// glass carries less throughput without being any less important.
    pub radiance_scale: f32,
}

/// Mirror reflection of `wo` about `normal` (either orientation).
#[inline]
pub fn reflect(wo: Vec3A, normal: Vec3A) -> Vec3A {
    normal * (2.0 * wo.dot(normal)) - wo
}

/// The classes of lobes a BSDF has: what integrators decide by, so a new material only has
/// to report its lobes here.
///
/// - Diffuse and glossy lobes have a density over directions: a connection (next-event
///   estimation, a BDPT or bidirectional-mutation connection) can end at them, and in Veach's
///   path classification (`D`/`S`) both are `D`. No material has a glossy lobe yet.
/// - A specular lobe is a Dirac delta: only sampling the BSDF can follow it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BsdfLobes(u8);

// The constants are `pub(crate)`, not `pub`: cbindgen exports `pub` associated constants
// to include/mlt.h whatever the type's visibility.
impl BsdfLobes {
    pub(crate) const DIFFUSE: BsdfLobes = BsdfLobes(1);
    pub(crate) const GLOSSY: BsdfLobes = BsdfLobes(2);
    pub(crate) const SPECULAR: BsdfLobes = BsdfLobes(4);

    /// Whether all of `other`'s lobes are among these.
    #[inline]
    pub fn contains(self, other: BsdfLobes) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether some lobe has a density over directions (diffuse or glossy): then a
    /// connection can end here, and Veach's classification calls the vertex `D`.
    #[inline]
    pub fn has_non_specular(self) -> bool {
        self.0 & (BsdfLobes::DIFFUSE.0 | BsdfLobes::GLOSSY.0) != 0
    }

    /// Whether every lobe is a Dirac delta: no connection can end here (Veach's `S`).
    #[inline]
    pub fn is_specular(self) -> bool {
        !self.has_non_specular()
    }

    /// Whether a Dirac lobe is beside one with a density (a smooth coat over a diffuse
    /// base): which of them scatters is then part of a path's state in path-space MLT.
    #[inline]
    pub fn is_mixed(self) -> bool {
        self.contains(BsdfLobes::SPECULAR) && self.has_non_specular()
    }
}

impl std::ops::BitOr for BsdfLobes {
    type Output = BsdfLobes;
    #[inline]
    fn bitor(self, other: BsdfLobes) -> BsdfLobes {
        BsdfLobes(self.0 | other.0)
    }
}

/// The lobe of a specular scattering: whether `wi` stays on `wo`'s side of the surface,
/// and which mirror reflects it where a smooth clear coat with a normal of its own lies
/// over a smooth base (two mirrors about different normals).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecularLobe {
    /// The mirror: a smooth coat's where there is one, else the surface's.
    Reflection,
    Refraction,
    /// A smooth base's mirror under a smooth coat that has a normal of its own.
    BaseReflection,
}

impl SpecularLobe {
    /// The lobe that scatters `wo` into `wi` at a surface with normal `normal`, by the
    /// sides alone (`Bsdf::specular_lobe` tells the two mirrors apart).
    #[inline]
    pub fn of(normal: Vec3A, wo: Vec3A, wi: Vec3A) -> SpecularLobe {
        if wo.dot(normal) * wi.dot(normal) > 0.0 {
            SpecularLobe::Reflection
        } else {
            SpecularLobe::Refraction
        }
    }
}
