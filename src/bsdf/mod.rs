//! Scattering at a surface: sampling and evaluating each material's BSDF.
//!
//! Directions point away from the surface: `wo` towards where the path came from, `wi` the
//! new direction. `normal` is the normal of the shading frame (interpolated or
//! normal-mapped); the triangle's front (counter-clockwise) geometric normal decides which
//! side of the surface a direction is on.
//!
//! Integrators use `Bsdf`, a material evaluated at a surface point (built by the scene,
//! textures applied), and ask it for its `BsdfLobes` instead of matching on the material's
//! kind; the free functions below are its arithmetic, one `match` per operation.

mod clearcoat;
mod dielectric;
mod metallic_roughness;
mod microfacet;
mod multiple_scattering;
mod scattering;
mod sheen;
mod thin_film;

pub(crate) use clearcoat::Clearcoat;
pub(crate) use metallic_roughness::{Anisotropy, MetallicRoughness, Microfacet};
pub(crate) use scattering::{BsdfLobes, SpecularLobe};
pub use scattering::{ScatterSample, TransportMode, reflect};
pub(crate) use sheen::Sheen;
pub(crate) use thin_film::ThinFilm;

use crate::sampling::{OrthonormalBasis, cosine_hemisphere, cosine_hemisphere_pdf};
use crate::spectrum::Spectrum;
use glam::Vec3A;
use std::f32::consts::FRAC_1_PI;

/// The scattering model at a surface point, with its parameters evaluated there (textures
/// and vertex colours applied).
// The metallic-roughness variant is much the largest, and it stays inline: a model lives on
// the stack for one scattering event, and boxing it would allocate in the hot loop.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub(crate) enum BsdfModel {
    /// Lambertian with this albedo, two-sided.
    Diffuse(Spectrum),
    /// A perfect mirror with this reflectance, two-sided.
    Mirror(Spectrum),
    /// A smooth dielectric interface: index of refraction inside (the back side), tint.
    Dielectric { ior: f32, tint: Spectrum },
    /// glTF's metallic-roughness model.
    MetallicRoughness(MetallicRoughness),
}

impl BsdfModel {
    /// The classes of its lobes.
    #[inline]
    pub fn lobes(&self) -> BsdfLobes {
        match self {
            BsdfModel::Diffuse(_) => BsdfLobes::DIFFUSE,
            BsdfModel::Mirror(_) | BsdfModel::Dielectric { .. } => BsdfLobes::SPECULAR,
            BsdfModel::MetallicRoughness(m) => m.lobes(),
        }
    }
}

/// A BSDF at a surface point: the evaluated model in the shading frame.
///
/// # Shading normals
///
/// The model scatters about the shading normal (interpolated or normal-mapped), while
/// geometry (the cosines of the geometric term, which side of the surface a direction is
/// on) uses the triangle's geometric normal. Veach (1997, §5.3) shows what keeps every
/// estimator consistent: the BSDF seen by the geometric measure is
/// f̃(wo, wi) = f(wo, wi) · |wi·ns| / |wi·ng| with wi the direction light arrives from, so
/// it is not symmetric, and light subpaths (importance transport, where the sampled
/// direction is the one towards the camera) carry |wo·ns| / |wo·ng| instead. `eval`
/// returns f̃ for the given mode and the integrators multiply by the geometric cosine,
/// which `sample` and `scatter` fold into their weights. A direction that is a reflection
/// for one normal and a transmission for the other has no scattering (it would leak light
/// through the surface).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bsdf {
    model: BsdfModel,
    /// Normal of the shading frame.
    normal: Vec3A,
    /// The triangle's front geometric normal.
    geometric_normal: Vec3A,
    /// Whether the two normals differ (without, the corrections are exactly 1 and skipped).
    shading_normal_differs: bool,
    /// Whether its index of refraction is the path's hero wavelength's (see
    /// `is_dispersive`).
    dispersive: bool,
}

impl Bsdf {
    /// `model` in the frame of `shading_normal`, on a triangle with `geometric_normal`.
    #[inline]
    pub fn new(model: BsdfModel, shading_normal: Vec3A, geometric_normal: Vec3A) -> Self {
        Bsdf {
            model,
            normal: shading_normal,
            geometric_normal,
            shading_normal_differs: shading_normal != geometric_normal,
            dispersive: false,
        }
    }

    /// The BSDF, marked dispersive or not (see `is_dispersive`).
    #[inline]
    pub fn with_dispersion(mut self, dispersive: bool) -> Self {
        self.dispersive = dispersive;
        self
    }

    /// Whether it refracts the path's wavelengths differently and was built with the
    /// hero wavelength's index: a path that scatters here must go on at the hero
    /// wavelength alone (`Channels::keep_hero_only`).
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.dispersive
    }

    /// The classes of its lobes.
    #[inline]
    pub fn lobes(&self) -> BsdfLobes {
        self.model.lobes()
    }

    /// The normal of the shading frame.
    #[inline]
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn shading_normal(&self) -> Vec3A {
        self.normal
    }

    /// Whether `wo` and `wi` are a reflection for both normals or a transmission for both.
    #[inline]
    fn sides_agree(&self, wo: Vec3A, wi: Vec3A) -> bool {
        let geometric = wo.dot(self.geometric_normal) * wi.dot(self.geometric_normal);
        let shading = wo.dot(self.normal) * wi.dot(self.normal);
        (geometric > 0.0 && shading > 0.0) || (geometric < 0.0 && shading < 0.0)
    }

    /// |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|): turns the radiance-mode weight of sampling wi
    /// from wo into the importance-mode one.
    #[inline]
    fn adjoint_factor(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        let numerator = (wo.dot(self.normal) * wi.dot(self.geometric_normal)).abs();
        let denominator = (wo.dot(self.geometric_normal) * wi.dot(self.normal)).abs();
        if denominator > 0.0 {
            numerator / denominator
        } else {
            0.0
        }
    }

    /// Corrects a sample of the model for the shading normal (see the type's comment).
    #[inline]
    fn corrected(
        &self,
        sample: Option<ScatterSample>,
        wo: Vec3A,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let mut sample = sample?;
        if self.shading_normal_differs {
            if !self.sides_agree(wo, sample.wi) {
                return None;
            }
            if mode == TransportMode::Importance {
                sample.weight *= self.adjoint_factor(wo, sample.wi);
            }
        }
        Some(sample)
    }

    /// Samples a direction `wi` given `wo`. `u` picks the direction, `u_lobe` the lobe.
    /// The weight is f̃ · |wi·ng| / pdf for the mode's f̃ (see the type's comment).
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3A,
        u: [f32; 2],
        u_lobe: f32,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let sample = sample(&self.model, self.normal, wo, u, u_lobe, mode);
        self.corrected(sample, wo, mode)
    }

    /// f̃(wo, wi) for `mode` (without any cosine) of the non-specular lobes; zero for
    /// specular ones. In radiance mode wi is where light arrives from; in importance mode
    /// wo is.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> Spectrum {
        let f = eval(&self.model, self.normal, wo, wi, mode);
        if !self.shading_normal_differs || f.is_black() {
            return f;
        }
        if !self.sides_agree(wo, wi) {
            return Spectrum::ZERO;
        }
        let toward_light = match mode {
            TransportMode::Radiance => wi,
            TransportMode::Importance => wo,
        };
        let cos_geometric = toward_light.dot(self.geometric_normal).abs();
        if cos_geometric == 0.0 {
            return Spectrum::ZERO;
        }
        f * (toward_light.dot(self.normal).abs() / cos_geometric)
    }

    /// Solid-angle density with which `sample` generates `wi` from `wo` (non-specular
    /// lobes only).
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if self.shading_normal_differs && !self.sides_agree(wo, wi) {
            return 0.0;
        }
        pdf(&self.model, self.normal, wo, wi)
    }

    /// What `sample` would return for scattering from `wo` into `wi` (see [`scatter`]).
    #[inline]
    pub fn scatter(&self, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> Option<ScatterSample> {
        let sample = scatter(&self.model, self.normal, wo, wi, mode);
        self.corrected(sample, wo, mode)
    }

    /// What `sample` would return for scattering from `wo` into `wi` through a Dirac lobe
    /// (`dirac`; `wi` is taken to be its direction) or through the lobes with a density,
    /// for a BSDF that has both (`BsdfLobes::is_mixed`); `scatter` for the others, whose
    /// lobes say which.
    #[inline]
    pub fn scatter_lobe(
        &self,
        wo: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
        dirac: bool,
    ) -> Option<ScatterSample> {
        let sample = match &self.model {
            BsdfModel::MetallicRoughness(m) => m.scatter_lobe(self.normal, wo, wi, mode, dirac),
            model => scatter(model, self.normal, wo, wi, mode),
        };
        self.corrected(sample, wo, mode)
    }

    /// The specular lobe that scatters `wo` into `wi` (a Dirac scattering): the sides say
    /// reflection or refraction, and where a smooth coat with a normal of its own lies over
    /// a smooth base, the nearer mirror says whose reflection.
    #[inline]
    pub fn specular_lobe(&self, wo: Vec3A, wi: Vec3A) -> SpecularLobe {
        let by_sides = SpecularLobe::of(self.geometric_normal, wo, wi);
        match &self.model {
            BsdfModel::MetallicRoughness(m) => m.specular_lobe(self.normal, wo, wi, by_sides),
            _ => by_sides,
        }
    }

    /// The direction a specular lobe scatters `wo` into (see [`specular_direction`]);
    /// `None` also where it would leak through the surface.
    #[inline]
    pub fn specular_direction(&self, wo: Vec3A, lobe: SpecularLobe) -> Option<Vec3A> {
        let wi = specular_direction(&self.model, self.normal, wo, lobe)?;
        (!self.shading_normal_differs || self.sides_agree(wo, wi)).then_some(wi)
    }
}

/// Glossy vertices: a rough surface's scattering through its microfacets, for perturbations
/// that move a glossy path's microfacet normals (in their sampling's coordinates or by a
/// small turn) instead of its directions. `None` or 0 for models without a glossy lobe.
impl Bsdf {
    /// Whether every lobe is glossy (Veach's classes extended by a third: a glossy vertex
    /// has a density, so it connects, and a direction found through a moved microfacet
    /// follows its lobe).
    /// A clear coat makes the vertex `D` even when every lobe is glossy: the microfacet
    /// functions below are the base's, and the coat's lobe has a frame of its own.
    #[inline]
    pub fn is_glossy(&self) -> bool {
        self.lobes() == BsdfLobes::GLOSSY
            && !matches!(self.model, BsdfModel::MetallicRoughness(m) if m.clearcoat.is_present())
    }

    /// The microfacet that scatters `wo` into `wi`.
    #[inline]
    pub fn microfacet(&self, wo: Vec3A, wi: Vec3A) -> Option<Microfacet> {
        match &self.model {
            BsdfModel::MetallicRoughness(m) => m.microfacet(self.normal, wo, wi),
            _ => None,
        }
    }

    /// The direction `wo` scatters into through microfacet `m`.
    #[inline]
    pub fn scatter_through(&self, wo: Vec3A, m: Microfacet) -> Option<Vec3A> {
        let wi = match &self.model {
            BsdfModel::MetallicRoughness(model) => model.scatter_through(self.normal, wo, m)?,
            _ => return None,
        };
        (!self.shading_normal_differs || self.sides_agree(wo, wi)).then_some(wi)
    }

    /// The coordinates of microfacet normal `m` in the sampling of those visible from `wo`.
    #[inline]
    pub fn microfacet_coordinates(&self, wo: Vec3A, m: Vec3A) -> Option<[f32; 2]> {
        match &self.model {
            BsdfModel::MetallicRoughness(model) => model.microfacet_coordinates(self.normal, wo, m),
            _ => None,
        }
    }

    /// The microfacet visible from `wo` at coordinates `u` of their sampling.
    #[inline]
    pub fn microfacet_at(&self, wo: Vec3A, u: [f32; 2], refracts: bool) -> Option<Microfacet> {
        match &self.model {
            BsdfModel::MetallicRoughness(model) => {
                model.microfacet_at(self.normal, wo, u, refracts)
            }
            _ => None,
        }
    }

    /// The density of `wi` found through a microfacet moved in solid angle or in its
    /// sampling's coordinates (see `MetallicRoughness::microfacet_step_density`).
    #[inline]
    pub fn microfacet_step_density(&self, wo: Vec3A, wi: Vec3A, in_sample_space: bool) -> f32 {
        if self.shading_normal_differs && !self.sides_agree(wo, wi) {
            return 0.0;
        }
        match &self.model {
            BsdfModel::MetallicRoughness(model) => {
                model.microfacet_step_density(self.normal, wo, wi, in_sample_space)
            }
            _ => 0.0,
        }
    }
}

/// Samples a direction `wi` given `wo` in the frame of `normal`. `u` picks the direction,
/// `u_lobe` the lobe.
#[inline]
fn sample(
    model: &BsdfModel,
    normal: Vec3A,
    wo: Vec3A,
    u: [f32; 2],
    u_lobe: f32,
    mode: TransportMode,
) -> Option<ScatterSample> {
    let cos_o = wo.dot(normal);
    match *model {
        BsdfModel::Diffuse(albedo) => {
            // Two-sided: scatter into the hemisphere wo is in.
            let side_normal = if cos_o >= 0.0 { normal } else { -normal };
            let local = cosine_hemisphere(u);
            if local.z <= 0.0 {
                return None;
            }
            let wi = OrthonormalBasis::from_normal(side_normal).to_world(local);
            Some(ScatterSample {
                wi,
                weight: albedo,
                pdf: cosine_hemisphere_pdf(local.z),
                specular: false,
                radiance_scale: 1.0,
            })
        }
        BsdfModel::Mirror(reflectance) => Some(ScatterSample {
            wi: reflect(wo, normal),
            weight: reflectance,
            pdf: 1.0,
            specular: true,
            radiance_scale: 1.0,
        }),
        BsdfModel::Dielectric { ior, tint } => {
            dielectric::sample(ior, tint, normal, wo, u_lobe, mode)
        }
        BsdfModel::MetallicRoughness(m) => m.sample(normal, wo, u, u_lobe, mode),
    }
}

/// BSDF value f(wo, wi) (without the cosine) of the non-specular lobes, for the quantity
/// `mode` carries (refraction is not symmetric); zero for specular models.
#[inline]
fn eval(model: &BsdfModel, normal: Vec3A, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> Spectrum {
    match *model {
        BsdfModel::MetallicRoughness(m) => m.eval(normal, wo, wi, mode),
        BsdfModel::Diffuse(albedo) => {
            if wo.dot(normal) * wi.dot(normal) > 0.0 {
                albedo * FRAC_1_PI
            } else {
                Spectrum::ZERO
            }
        }
        _ => Spectrum::ZERO,
    }
}

/// Solid-angle density with which `sample` generates `wi` from `wo` (non-specular only).
#[inline]
fn pdf(model: &BsdfModel, normal: Vec3A, wo: Vec3A, wi: Vec3A) -> f32 {
    match model {
        BsdfModel::MetallicRoughness(m) => m.pdf(normal, wo, wi),
        BsdfModel::Diffuse(_) => {
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
fn scatter(
    model: &BsdfModel,
    normal: Vec3A,
    wo: Vec3A,
    wi: Vec3A,
    mode: TransportMode,
) -> Option<ScatterSample> {
    let (cos_o, cos_i) = (wo.dot(normal), wi.dot(normal));
    let same_side = cos_o * cos_i > 0.0;
    match *model {
        BsdfModel::Diffuse(albedo) => same_side.then(|| ScatterSample {
            wi,
            weight: albedo,
            pdf: cosine_hemisphere_pdf(cos_i.abs()),
            specular: false,
            radiance_scale: 1.0,
        }),
        BsdfModel::Mirror(reflectance) => same_side.then_some(ScatterSample {
            wi,
            weight: reflectance,
            pdf: 1.0,
            specular: true,
            radiance_scale: 1.0,
        }),
        BsdfModel::Dielectric { ior, tint } => dielectric::scatter(ior, tint, normal, wo, wi, mode),
        BsdfModel::MetallicRoughness(m) => m.scatter(normal, wo, wi, mode),
    }
}

/// The direction a specular model scatters `wo` into through `lobe`, or `None` if it has
/// no such lobe (a mirror's refraction, total internal reflection).
#[inline]
fn specular_direction(
    model: &BsdfModel,
    normal: Vec3A,
    wo: Vec3A,
    lobe: SpecularLobe,
) -> Option<Vec3A> {
    match (*model, lobe) {
        (BsdfModel::Mirror(_) | BsdfModel::Dielectric { .. }, SpecularLobe::Reflection) => {
            Some(reflect(wo, normal))
        }
        (BsdfModel::Dielectric { ior, .. }, SpecularLobe::Refraction) => {
            dielectric::refracted(ior, normal, wo)
        }
        (BsdfModel::MetallicRoughness(m), lobe) => m.specular_direction(normal, wo, lobe),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::scene::Material;
    use crate::spectral::Channels;

    /// Today's materials: diffuse is connectible (D), mirror and glass are Dirac (S); a
    /// glossy lobe counts as non-specular, alone or next to a specular one.
    #[test]
    fn lobes_classify_materials() {
        let diffuse = Material::diffuse([0.5; 3])
            .bsdf_model(&Channels::Rgb)
            .lobes();
        assert!(diffuse.has_non_specular() && !diffuse.is_specular());
        assert!(diffuse.contains(BsdfLobes::DIFFUSE));
        for m in [Material::mirror([1.0; 3]), Material::dielectric(1.5)] {
            let lobes = m.bsdf_model(&Channels::Rgb).lobes();
            assert!(lobes.is_specular() && !lobes.has_non_specular());
            assert!(lobes.contains(BsdfLobes::SPECULAR));
        }
        assert!(BsdfLobes::GLOSSY.has_non_specular());
        let coated = BsdfLobes::GLOSSY | BsdfLobes::SPECULAR;
        assert!(coated.has_non_specular() && coated.contains(BsdfLobes::SPECULAR));
    }

    /// A film of strength 0 or thickness 0 is no film (as `KHR_materials_iridescence`
    /// defines): the model is the plain material's, in RGB and spectral renders, and a
    /// film of both has one.
    #[test]
    fn a_film_without_strength_or_thickness_is_none() {
        let plain = Material::metallic_roughness([0.6, 0.3, 0.2], 0.5, 0.4);
        let spectral = Channels::new(true, || 0.3);
        for channels in [Channels::Rgb, spectral] {
            let model = |m: Material| match m.bsdf_model(&channels) {
                BsdfModel::MetallicRoughness(m) => m,
                _ => unreachable!(),
            };
            for m in [
                Material {
                    iridescence: 0.0,
                    ..plain
                },
                Material {
                    iridescence: 1.0,
                    iridescence_thickness_maximum: 0.0,
                    ..plain
                },
            ] {
                assert_eq!(model(m), model(plain));
            }
            let filmed = model(Material {
                iridescence: 0.5,
                ..plain
            });
            assert_eq!(filmed.film.map(|f| f.thickness), Some(400.0));
        }
    }

    /// Energy conservation and reciprocity-style check: the albedo estimated by sampling
    /// equals the material's color for diffuse, and the pdf matches eval/cos for diffuse.
    #[test]
    fn diffuse_sample_is_consistent_with_eval_and_pdf() {
        let m = Material::diffuse([0.5, 0.25, 0.75]).bsdf_model(&Channels::Rgb);
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
            let f = eval(&m, n, wo, s.wi, TransportMode::Radiance);
            let p = pdf(&m, n, wo, s.wi);
            assert!((p - s.pdf).abs() < 1e-3 * p.max(1.0));
            let expected = f * cos / p;
            assert!((expected - s.weight).abs().max_component() < 1e-3);
            assert!(s.wi.dot(n) < 0.0, "stays on the side of wo");
        }
    }
}
