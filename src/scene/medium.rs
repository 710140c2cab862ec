//! The absorbing volumes closed transmissive meshes enclose (glTF's `KHR_materials_volume`):
//! what light loses along a path segment that travels inside one, by Beer–Lambert's law.
//!
//! A material with a volume (`Material::thickness` > 0, an attenuation that absorbs, and a
//! surface light can pass: a dielectric, or metallic-roughness with transmission) fills the
//! space behind its triangles' back sides. A segment's medium is told by its ends: it is
//! inside the volume of a triangle it leaves through that triangle's back side (or arrives
//! at from behind). Assumed, as glTF assumes: meshes with a volume are closed and do not
//! nest or overlap, and the camera and the lights are outside every volume. Otherwise: a
//! segment between two volumes' back sides takes the volume of the lower material index;
//! a segment from a back side that escapes the scene (an open mesh) is absorbed entirely
//! where the attenuation is below 1; a lens or a light that is not a triangle inside a
//! volume sees no absorption on the segments that end at it, unless the other end says so.
//!
//! Absorption is not sampled: it multiplies the paths' contributions (BDPT's subpath
//! throughputs and connections, the path-space measurement contribution) and leaves every
//! density, so every MIS weight, unchanged.

use super::material::{Material, MaterialKind};
use crate::spectral::{Channels, FittedColour};
use crate::spectrum::Spectrum;

/// The absorbing volume behind a material's surface.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Medium {
    /// The colour white light has after `distance` inside, fitted for spectral renders.
    attenuation: FittedColour,
    /// 1 / attenuation distance.
    inverse_distance: f32,
}

impl Medium {
    /// The volume behind `material`'s surface, if it has one that absorbs.
    pub fn of(material: &Material) -> Option<Medium> {
        let transmits = match material.kind {
            MaterialKind::Dielectric => true,
            MaterialKind::MetallicRoughness => material.transmission > 0.0,
            MaterialKind::Diffuse | MaterialKind::Mirror => false,
        };
        let absorbs = material.attenuation_distance < f32::MAX
            && material.attenuation_color.iter().any(|&c| c < 1.0);
        (transmits && material.thickness > 0.0 && absorbs).then(|| Medium {
            attenuation: FittedColour::reflectance(material.attenuation_color),
            inverse_distance: 1.0 / material.attenuation_distance,
        })
    }

    /// The fraction of light left after `distance` inside, in `channels`: colour^(distance /
    /// attenuation distance) = exp(−σ distance) with σ = −ln(colour) / attenuation distance
    /// per channel. An infinite distance leaves nothing where the colour is below 1.
    #[inline]
    pub fn transmittance(&self, distance: f32, channels: &Channels) -> Spectrum {
        let exponent = distance * self.inverse_distance;
        // powf(1, ∞) = 1 and powf(0, 0) = 1: the limits Beer–Lambert's law has.
        channels
            .fitted_reflectance(&self.attenuation)
            .map(|c| c.clamp(0.0, 1.0).powf(exponent))
    }
}
