//! Scattering at a surface: sampling and evaluating each material's BSDF.
//!
//! Directions point away from the surface: `wo` towards where the path came from, `wi` the
//! new direction. `normal` is the triangle's front (counter-clockwise) geometric normal.

mod dielectric;
mod scattering;

pub use dielectric::fresnel_dielectric;
pub use scattering::{ScatterSample, TransportMode, reflect};

use crate::sampling::{OrthonormalBasis, cosine_hemisphere, cosine_hemisphere_pdf};
use crate::scene::{Material, MaterialKind};
use crate::spectrum::Spectrum;
use glam::Vec3A;
use std::f32::consts::FRAC_1_PI;

/// Samples a direction `wi` given `wo`. `u` picks the direction, `u_lobe` the lobe.
#[inline]
pub fn sample(
    material: &Material,
    normal: Vec3A,
    wo: Vec3A,
    u: [f32; 2],
    u_lobe: f32,
    mode: TransportMode,
) -> Option<ScatterSample> {
    let color = Spectrum::from(material.color);
    let cos_o = wo.dot(normal);
    match material.kind {
        MaterialKind::Diffuse => {
            // Two-sided: scatter into the hemisphere wo is in.
            let side_normal = if cos_o >= 0.0 { normal } else { -normal };
            let local = cosine_hemisphere(u);
            if local.z <= 0.0 {
                return None;
            }
            let wi = OrthonormalBasis::from_normal(side_normal).to_world(local);
            Some(ScatterSample {
                wi,
                weight: color,
                pdf: cosine_hemisphere_pdf(local.z),
                specular: false,
            })
        }
        MaterialKind::Mirror => Some(ScatterSample {
            wi: reflect(wo, normal),
            weight: color,
            pdf: 1.0,
            specular: true,
        }),
        MaterialKind::Dielectric => {
            dielectric::sample(material.ior, color, normal, wo, u_lobe, mode)
        }
    }
}

/// BSDF value f(wo, wi) (without the cosine) for non-specular materials; zero otherwise.
#[inline]
pub fn eval(material: &Material, normal: Vec3A, wo: Vec3A, wi: Vec3A) -> Spectrum {
    match material.kind {
        MaterialKind::Diffuse => {
            if wo.dot(normal) * wi.dot(normal) > 0.0 {
                Spectrum::from(material.color) * FRAC_1_PI
            } else {
                Spectrum::ZERO
            }
        }
        _ => Spectrum::ZERO,
    }
}

/// Solid-angle density with which `sample` generates `wi` from `wo` (non-specular only).
#[inline]
pub fn pdf(material: &Material, normal: Vec3A, wo: Vec3A, wi: Vec3A) -> f32 {
    match material.kind {
        MaterialKind::Diffuse => {
            let cos_i = wi.dot(normal);
            if wo.dot(normal) * cos_i > 0.0 {
                cosine_hemisphere_pdf(cos_i.abs())
            } else {
                0.0
            }
        }
        _ => 0.0,
    }
}

/// What `sample` would return for scattering from `wo` into `wi`: the weight (BSDF ×
/// |cos θi| / pdf) and the density (solid angle, or the lobe probability for a specular
/// lobe), for path-space methods that evaluate given paths. A specular `wi` is taken to be
/// the exact mirror or refracted direction of its side (the path was traced that way); it
/// is not checked.
#[inline]
pub fn scatter(
    material: &Material,
    normal: Vec3A,
    wo: Vec3A,
    wi: Vec3A,
    mode: TransportMode,
) -> Option<ScatterSample> {
    let color = Spectrum::from(material.color);
    let (cos_o, cos_i) = (wo.dot(normal), wi.dot(normal));
    let same_side = cos_o * cos_i > 0.0;
    match material.kind {
        MaterialKind::Diffuse => same_side.then(|| ScatterSample {
            wi,
            weight: color,
            pdf: cosine_hemisphere_pdf(cos_i.abs()),
            specular: false,
        }),
        MaterialKind::Mirror => same_side.then_some(ScatterSample {
            wi,
            weight: color,
            pdf: 1.0,
            specular: true,
        }),
        MaterialKind::Dielectric => dielectric::scatter(material.ior, color, normal, wo, wi, mode),
    }
}

/// The lobe of a specular scattering: whether `wi` stays on `wo`'s side of the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecularLobe {
    Reflection,
    Refraction,
}

impl SpecularLobe {
    /// The lobe that scatters `wo` into `wi` at a surface with normal `normal`.
    #[inline]
    pub fn of(normal: Vec3A, wo: Vec3A, wi: Vec3A) -> SpecularLobe {
        if wo.dot(normal) * wi.dot(normal) > 0.0 {
            SpecularLobe::Reflection
        } else {
            SpecularLobe::Refraction
        }
    }
}

/// The direction a specular material scatters `wo` into through `lobe`, or `None` if it
/// has no such lobe (a mirror's refraction, total internal reflection).
#[inline]
pub fn specular_direction(
    material: &Material,
    normal: Vec3A,
    wo: Vec3A,
    lobe: SpecularLobe,
) -> Option<Vec3A> {
    match (material.kind, lobe) {
        (MaterialKind::Mirror | MaterialKind::Dielectric, SpecularLobe::Reflection) => {
            Some(reflect(wo, normal))
        }
        (MaterialKind::Dielectric, SpecularLobe::Refraction) => {
            dielectric::refracted(material.ior, normal, wo)
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// Energy conservation and reciprocity-style check: the albedo estimated by sampling
    /// equals the material's color for diffuse, and the pdf matches eval/cos for diffuse.
    #[test]
    fn diffuse_sample_is_consistent_with_eval_and_pdf() {
        let m = Material::diffuse([0.5, 0.25, 0.75]);
        let n = Vec3A::new(0.0, 0.6, 0.8);
        let wo = Vec3A::new(0.3, -0.5, -0.8).normalize();
        let mut rng = Rng::new(1, 2);
        for _ in 0..1000 {
            let s = sample(
                &m,
                n,
                wo,
                rng.uniform2(),
                rng.uniform(),
                TransportMode::Radiance,
            )
            .unwrap();
            let cos = s.wi.dot(n).abs();
            let f = eval(&m, n, wo, s.wi);
            let p = pdf(&m, n, wo, s.wi);
            assert!((p - s.pdf).abs() < 1e-3 * p.max(1.0));
            let expected = f * cos / p;
            assert!((expected - s.weight).abs().max_component() < 1e-3);
            assert!(s.wi.dot(n) < 0.0, "stays on the side of wo");
        }
    }
}
