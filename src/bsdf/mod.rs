//! Scattering at a surface: sampling and evaluating each material's BSDF.
//!
//! Directions point away from the surface: `wo` towards where the path came from, `wi` the
//! new direction. `normal` is the normal of the shading frame, which today is the triangle's
//! front (counter-clockwise) geometric normal.
//!
//! Integrators use `Bsdf`, a material evaluated at a surface point (built by
//! `interaction.rs`), and ask it for its `BsdfLobes` instead of matching on the material's
//! kind; the free functions below are its arithmetic, one `match` per operation.

mod dielectric;
mod metallic_roughness;
mod microfacet;
mod scattering;

pub use dielectric::fresnel_dielectric;
pub use scattering::{ScatterSample, TransportMode, reflect};

use crate::sampling::{OrthonormalBasis, cosine_hemisphere, cosine_hemisphere_pdf};
use crate::scene::{Material, MaterialKind};
use crate::spectrum::Spectrum;
use glam::Vec3A;
use std::f32::consts::FRAC_1_PI;

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

    /// The lobes of `material`.
    #[inline]
    pub fn of(material: &Material) -> BsdfLobes {
        match material.kind {
            MaterialKind::Diffuse => BsdfLobes::DIFFUSE,
            MaterialKind::Mirror | MaterialKind::Dielectric => BsdfLobes::SPECULAR,
        }
    }

    /// Whether all of `other`'s lobes are among these.
    #[inline]
    #[cfg_attr(not(test), allow(dead_code))]
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
}

impl std::ops::BitOr for BsdfLobes {
    type Output = BsdfLobes;
    #[inline]
    fn bitor(self, other: BsdfLobes) -> BsdfLobes {
        BsdfLobes(self.0 | other.0)
    }
}

/// A material's BSDF at a surface point: the material and the shading frame's normal.
/// Small and `Copy`; its methods are the free functions of this module, so the arithmetic
/// is theirs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bsdf<'a> {
    material: &'a Material,
    /// Normal of the shading frame (today the geometric normal).
    normal: Vec3A,
}

impl<'a> Bsdf<'a> {
    #[inline]
    pub fn new(material: &'a Material, normal: Vec3A) -> Self {
        Bsdf { material, normal }
    }

    /// The classes of its lobes.
    #[inline]
    pub fn lobes(&self) -> BsdfLobes {
        BsdfLobes::of(self.material)
    }

    /// See [`sample`].
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3A,
        u: [f32; 2],
        u_lobe: f32,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        sample(self.material, self.normal, wo, u, u_lobe, mode)
    }

    /// See [`eval`].
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Spectrum {
        eval(self.material, self.normal, wo, wi)
    }

    /// See [`pdf`].
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        pdf(self.material, self.normal, wo, wi)
    }

    /// See [`scatter`].
    #[inline]
    pub fn scatter(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> Option<ScatterSample> {
        scatter(self.material, self.normal, wo, wi, mode)
    }

    /// See [`specular_direction`].
    #[inline]
    pub fn specular_direction(&self, wo: Vec3A, lobe: SpecularLobe) -> Option<Vec3A> {
        specular_direction(self.material, self.normal, wo, lobe)
    }
}

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

    /// Today's materials: diffuse is connectible (D), mirror and glass are Dirac (S); a
    /// glossy lobe counts as non-specular, alone or next to a specular one.
    #[test]
    fn lobes_classify_materials() {
        let diffuse = BsdfLobes::of(&Material::diffuse([0.5; 3]));
        assert!(diffuse.has_non_specular() && !diffuse.is_specular());
        assert!(diffuse.contains(BsdfLobes::DIFFUSE));
        for m in [Material::mirror([1.0; 3]), Material::dielectric(1.5)] {
            let lobes = BsdfLobes::of(&m);
            assert!(lobes.is_specular() && !lobes.has_non_specular());
            assert!(lobes.contains(BsdfLobes::SPECULAR));
        }
        assert!(BsdfLobes::GLOSSY.has_non_specular());
        let coated = BsdfLobes::GLOSSY | BsdfLobes::SPECULAR;
        assert!(coated.has_non_specular() && coated.contains(BsdfLobes::SPECULAR));
    }

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
