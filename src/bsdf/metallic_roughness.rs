//! The glTF 2.0 metallic-roughness BSDF (appendix B of the glTF 2.0 specification, with
//! KHR_materials_ior and KHR_materials_transmission):
//!
//! material = lerp(dielectric, metal, metallic), where
//! - metal = GGX reflection × Schlick's conductor Fresnel with F0 = base_color;
//! - dielectric = F · GGX reflection + (1 − F) · lerp(base_color / π, base_color · BTDF,
//!   transmission), F the Fresnel reflectance of an interface of index `ior`.
//!
//! GGX uses α = roughness² (at least [`MIN_ALPHA`](super::microfacet::MIN_ALPHA)) and
//! the height-correlated G2 (also for transmission, as an approximation of its exact form),
//! sampled through its visible normals. Roughness 0 is the Dirac limit: a mirror, and a
//! smooth dielectric (specular reflection and refraction) over the diffuse base.
//!
//! Choices where the specification leaves room or had to be departed from:
//! - Fresnel of the dielectric: Schlick's with F0 = ((ior − 1) / (ior + 1))², evaluated with
//!   the cosine on the side of the lower index (the transmitted cosine when light arrives
//!   from the denser side) and 1 under total internal reflection. From the outside of glass
//!   that is glTF's Schlick term exactly; it is also symmetric across the interface, which
//!   refraction's reciprocity needs.
//! - The diffuse base is scaled by its albedo under the coat, not glTF's (1 − F(v·h)):
//!   with the half vector of wo and wi the base keeps almost all its energy while the coat
//!   reflects nearly everything at grazing angles, so a smooth white dielectric would
//!   reflect 1.35 times the incident energy at 80° and 1.9 times near 90°. Instead (albedo
//!   scaling, as Cycles and OpenPBR do, in Kulla and Conty's reciprocal form)
//!   base · (1 − R(μo)) (1 − R(μi)) / (1 − R_avg), with R the coat's reflectance: the
//!   Fresnel-weighted share of what its GGX lobe reflects, E_F / E (tabulated in
//!   `multiple_scattering`; the albedo the coat would have with its multiple scattering
//!   kept), and R_avg its cosine-weighted mean. The base then reflects 1 − R(μo) of its
//!   albedo at every μo, and a white dielectric reflects 1 − R(μo) (1 − E(μo)): all but
//!   what the rough coat's single scattering loses, as the specification's model loses
//!   it. Face-on the albedo is the specification's within 1% at every roughness (tested).
//!   It stays reciprocal. For `ior` < 1 the coat's reflectance is Schlick's from the
//!   outside, without the total internal reflection the interface has there.
//! - Multiple scattering between microfacets is left out, as glTF's model leaves it out,
//!   unless `energy_compensation` is set: then the metal gains Kulla and Conty's
//!   compensation lobe (see `multiple_scattering`), a smooth lobe with the light single
//!   scattering loses (a white metal then reflects 1 at every roughness and angle). The
//!   dielectric's coat is not compensated.
//! - An index of refraction within [`INDEX_MATCHED`] of 1 refracts a ray straight on through
//!   every microfacet, so a rough interface's transmission there is a Dirac lobe along −wo
//!   (its half vector and Jacobian are 0/0 in the microfacet form). Its weight is the
//!   microfacet form's limit: 1 − F̄(μo), F̄ Schlick's F averaged over the normals visible
//!   from wo (tabulated in `multiple_scattering`), times the masking of the way out,
//!   G2(wo, −wo) / G1(wo) = (1 + Λ) / (1 + 2Λ). The rough reflection's albedo is at most
//!   F̄(μo) (its exit masking only loses), so the two never exceed 1.
//! - Reflection is two-sided (as the diffuse BSDF). The transmissive part is a real
//!   interface (front side outside with index 1, back side inside with index `ior`), so its
//!   reflectance seen from the back includes total internal reflection; the opaque part is
//!   seen from the outside on either side. For `ior` ≥ 1 both are glTF's F from the front.
//!
//! `KHR_materials_anisotropy` stretches the GGX of every lobe above along a direction in
//! the tangent plane ([`Anisotropy`]): the local frame's x axis is then that direction, and
//! the albedo tables are read at an isotropic equivalent (`table_roughness`).
//!
//! A clear coat (`KHR_materials_clearcoat`, the `clearcoat` module) lies over all of it,
//! with its own roughness and normal; it is composed into the sampling, evaluation, density
//! and lobe choice at the points marked "Clear coat", and skipped where its factor is 0.

use super::clearcoat::{Clearcoat, CoatView};
use super::dielectric::{refract, refracted};
use super::microfacet::TrowbridgeReitz;
use super::multiple_scattering::{CoatReflectance, EnergyCompensation, visible_schlick_mean};
use super::scattering::{ScatterSample, TransportMode, reflect};
use super::sheen::{self, Sheen};
use super::thin_film::ThinFilm;
use super::{BsdfLobes, SpecularLobe};
use crate::sampling::{OrthonormalBasis, cosine_hemisphere, cosine_hemisphere_pdf};
use crate::spectrum::Spectrum;
use glam::{Vec3, Vec3A};
use std::f32::consts::FRAC_1_PI;

/// glTF's metallic-roughness material (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) struct MetallicRoughness {
    /// Linear, each channel in [0, 1].
    pub base_color: Spectrum,
    /// In [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1]; α = roughness².
    pub roughness: f32,
    /// Index of refraction inside (the back side), > 0; glTF's default is 1.5.
    pub ior: f32,
    /// Share of the dielectric's base that is transmitted instead of diffuse, in [0, 1].
    pub transmission: f32,
    /// Whether the metal's reflection gains the multiple-scattering compensation lobe.
    pub energy_compensation: bool,
    /// The clear coat over all of it (factor 0: none).
    pub clearcoat: Clearcoat,
    /// `KHR_materials_specular`: the strength of the dielectric's specular reflection, in
    /// [0, 1] (F0 and F90 are scaled by it).
    pub specular: f32,
    /// `KHR_materials_specular`: the colour scaling the dielectric's F0 (not negative; F0
    /// times it is clamped to 1), each lane at most `specular_color_max`.
    pub specular_color: Spectrum,
    /// The specular colour's largest RGB channel: what the base beneath is weighted by.
    pub specular_color_max: f32,
    /// `KHR_materials_sheen`: the sheen layer over the whole material, if it has one.
    pub sheen: Option<Sheen>,
    /// `KHR_materials_anisotropy`: the microfacets stretched along a direction, if they are.
    pub anisotropy: Option<Anisotropy>,
    /// `KHR_materials_iridescence`: a thin film over the base, if it has one.
    pub film: Option<ThinFilm>,
}

/// `KHR_materials_anisotropy` at a surface point: GGX's roughness along `direction` is
/// α_t = mix(α, 1, strength²), across it α_b = α (α = roughness²). It applies to every
/// lobe of the base's microfacets (the metal's and the dielectric's reflection, and the
/// transmission through them), not to the clear coat nor the sheen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Anisotropy {
    /// In (0, 1].
    pub strength: f32,
    /// Unit, perpendicular to the shading normal (world space): the local frame's x axis.
    /// (A `Vec3`, unaligned: the model is copied by value, and stays smaller so.)
    pub direction: Vec3,
}

/// A microfacet of a rough surface, through which a glossy lobe scatters a direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Microfacet {
    /// Its normal, on the side of the direction it scatters.
    pub normal: Vec3A,
    /// Whether it refracts (else it reflects).
    pub refracts: bool,
}

/// The surface as seen from `wo`: a frame around the normal on wo's side and the indices on
/// wo's side and the other (front outside with index 1, back inside with index `ior`).
#[derive(Clone, Copy)]
struct View {
    basis: OrthonormalBasis,
    /// `wo` in the frame: z > 0.
    wo: Vec3A,
    eta_o: f32,
    eta_t: f32,
}

impl View {
    /// The view of `wo`, in a frame whose x axis is `direction` if the surface is
    /// anisotropic (any frame about the normal otherwise).
    #[inline]
    fn of(ior: f32, normal: Vec3A, wo: Vec3A, direction: Option<Vec3A>) -> Option<View> {
        let cos_o = wo.dot(normal);
        if cos_o == 0.0 {
            return None;
        }
        let (side_normal, eta_o, eta_t) = if cos_o > 0.0 {
            (normal, 1.0, ior)
        } else {
            (-normal, ior, 1.0)
        };
        let basis = match direction {
            None => OrthonormalBasis::from_normal(side_normal),
            Some(tangent) => OrthonormalBasis {
                tangent,
                bitangent: side_normal.cross(tangent),
                normal: side_normal,
            },
        };
        Some(View {
            wo: Vec3A::new(wo.dot(basis.tangent), wo.dot(basis.bitangent), cos_o.abs()),
            basis,
            eta_o,
            eta_t,
        })
    }

    #[inline]
    fn local(&self, w: Vec3A) -> Vec3A {
        Vec3A::new(
            w.dot(self.basis.tangent),
            w.dot(self.basis.bitangent),
            w.dot(self.basis.normal),
        )
    }

    /// η_o / η_t, dielectric.rs's η.
    #[inline]
    fn eta(&self) -> f32 {
        self.eta_o / self.eta_t
    }
}

/// The probabilities with which `sample` picks its lobes for a given `wo`.
#[derive(Clone, Copy, Debug)]
struct LobeChoice {
    reflection: f32,
    diffuse: f32,
    transmission: f32,
    /// The metal's multiple-scattering compensation.
    multiple: f32,
    /// The sum of the lobes' albedo estimates (before normalizing), which the clear coat's
    /// share is weighed against.
    total: f32,
    /// The sheen layer's lobe (0 without sheen).
    sheen: f32,
}

/// Every lobe that can scatter is picked at least this often (before normalizing), so a
/// lobe whose albedo estimate is zero at this `wo` (Schlick's F at normal incidence with
/// F0 = 0, a black tint's zero that eval still reaches through other angles) keeps a density.
const MIN_LOBE_WEIGHT: f32 = 0.05;

/// Within this 1 − cos of the mirror direction (1.4e-3 rad) a given `wi` at roughness 0 is
/// taken to be the specular reflection (a traced path's direction, rebuilt from its
/// vertices, is off by f32 rounding); elsewhere it is the diffuse lobe's.
const MIRROR_TOLERANCE: f32 = 1e-6;

/// How far from 1 an index of refraction may be for a rough interface to be taken as
/// index-matched (see the module's documentation): a microfacet's refraction then turns a
/// ray by less than 1e-3 rad, and the microfacet form's denominator (η_o·cos + η_t·cos,
/// which vanishes at η = 1) still keeps three digits in f32 beyond it.
const INDEX_MATCHED: f32 = 1e-3;

/// Schlick's Fresnel approximation.
#[inline]
fn schlick(f0: f32, cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    f0 + (1.0 - f0) * (m * m) * (m * m) * m
}

/// Schlick's conductor Fresnel, channel by channel.
#[inline]
fn schlick_spectrum(f0: Spectrum, cos: f32) -> Spectrum {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    f0 + (Spectrum::ONE - f0) * ((m * m) * (m * m) * m)
}

/// Schlick's Fresnel with a normal reflectance per lane, rounded as [`schlick`] is.
#[inline]
fn schlick_lanes(f0: Spectrum, cos: f32) -> Spectrum {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    f0 + (Spectrum::ONE - f0) * (m * m) * (m * m) * m
}

/// The cosine on the side of the lower index for light arriving at cosine `cos_o` on the
/// side of index η_o, with `eta` = η_o / η_t; `None` under total internal reflection.
#[inline]
fn rarer_cosine(cos_o: f32, eta: f32) -> Option<f32> {
    if eta <= 1.0 {
        return Some(cos_o);
    }
    let sin_t2 = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
    (sin_t2 < 1.0).then(|| (1.0 - sin_t2).sqrt())
}

#[inline]
fn mean(s: Spectrum) -> f32 {
    (s[0] + s[1] + s[2]) / 3.0
}

/// Refraction of `wo` (frame with the normal along z) through the microfacet `m`, with
/// η = η_o / η_t; `None` under total internal reflection or if `wo` is behind `m`.
#[inline]
fn refract_through(wo: Vec3A, m: Vec3A, eta: f32) -> Option<Vec3A> {
    let cos = wo.dot(m);
    if cos <= 0.0 || eta * eta * (1.0 - cos * cos) >= 1.0 {
        return None;
    }
    Some(refract(wo, m, cos, eta))
}

/// The generalized half vector of a refraction (Walter et al. 2007) on wo's side (z > 0),
/// with wo·h and wi·h, or `None` if no microfacet refracts `wo` into `wi`.
#[inline]
fn refraction_half_vector(view: &View, wi: Vec3A) -> Option<(Vec3A, f32, f32)> {
    let h = view.wo * view.eta_o + wi * view.eta_t;
    let length = h.length();
    if length == 0.0 || h.z == 0.0 {
        return None;
    }
    let h = h * (h.z.signum() / length);
    let (cos_o, cos_i) = (view.wo.dot(h), wi.dot(h));
    (cos_o > 0.0 && cos_i < 0.0).then_some((h, cos_o, cos_i))
}

#[cfg_attr(not(test), allow(dead_code))]
impl MetallicRoughness {
    /// The classes of its lobes: glossy reflection (and transmission) when rough, specular
    /// when smooth, and a diffuse lobe when the dielectric's base is partly opaque.
    pub fn lobes(&self) -> BsdfLobes {
        let scattering = if self.transmits_straight() {
            BsdfLobes::GLOSSY | BsdfLobes::SPECULAR
        } else if !self.is_smooth() {
            BsdfLobes::GLOSSY
        } else {
            BsdfLobes::SPECULAR
        };
        let base = if self.diffuse_tint().is_black()
            && self.compensation().is_none()
            && self.sheen.is_none()
        {
            scattering
        } else {
            scattering | BsdfLobes::DIFFUSE
        };
        // Clear coat: its lobe beside the base's.
        match self.clearcoat {
            coat if !coat.is_present() => base,
            coat if coat.is_smooth() => base | BsdfLobes::SPECULAR,
            _ => base | BsdfLobes::GLOSSY,
        }
    }

    /// Samples `wi` given `wo`: `u_lobe` picks reflection, the diffuse base or transmission
    /// in proportion to estimates of their albedos at `wo`, `u` the direction in the lobe
    /// (GGX's visible normals, or the cosine for the base). `None` when the sampled
    /// direction is not one the lobe scatters into.
    pub fn sample(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        u: [f32; 2],
        u_lobe: f32,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let view = self.view(normal, wo)?;
        let choice = self.lobe_choice(&view);
        // Clear coat.
        if self.clearcoat.is_present() {
            return self.coated_sample(&view, choice, normal, wo, u, u_lobe, mode);
        }
        self.sample_base(&view, choice, normal, wo, u, u_lobe, mode)
    }

    /// `sample` without the clear coat.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn sample_base(
        &self,
        view: &View,
        choice: LobeChoice,
        normal: Vec3A,
        wo: Vec3A,
        u: [f32; 2],
        u_lobe: f32,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let view = *view;
        let lobe = choice.pick(u_lobe);
        let Some(distribution) = self.distribution() else {
            return match lobe {
                Lobe::Reflection => {
                    Some(self.specular_reflection(&view, reflect(wo, normal), choice))
                }
                // Smooth materials have no compensation lobe.
                Lobe::Diffuse | Lobe::MultipleScattering => {
                    let local = cosine_hemisphere(u);
                    self.diffuse_scatter(&view, choice, local, view.basis.to_world(local))
                }
                Lobe::Transmission => {
                    let wi = refracted(self.ior, normal, wo)?;
                    Some(self.specular_transmission(&view, wi, choice, mode))
                }
                Lobe::Sheen => {
                    let local = sheen::uniform_hemisphere(u);
                    self.diffuse_scatter(&view, choice, local, view.basis.to_world(local))
                }
            };
        };
        let local = match lobe {
            Lobe::Reflection => {
                let m = distribution.sample_visible_normal(view.wo, u);
                Some(reflect(view.wo, m)).filter(|wi| wi.z > 0.0)
            }
            Lobe::Diffuse | Lobe::MultipleScattering => {
                Some(cosine_hemisphere(u)).filter(|wi| wi.z > 0.0)
            }
            Lobe::Transmission if self.transmits_straight() => {
                return Some(self.specular_transmission(&view, -wo, choice, mode));
            }
            Lobe::Transmission => {
                let m = distribution.sample_visible_normal(view.wo, u);
                refract_through(view.wo, m, view.eta()).filter(|wi| wi.z < 0.0)
            }
            Lobe::Sheen => Some(sheen::uniform_hemisphere(u)).filter(|wi| wi.z > 0.0),
        }?;
        self.rough_scatter(&view, choice, local, view.basis.to_world(local), mode)
    }

    /// BSDF value f(wo, wi), without the cosine, of the lobes that have a density (all but
    /// roughness 0's Dirac reflection and refraction).
    pub fn eval(&self, normal: Vec3A, wo: Vec3A, wi: Vec3A, mode: TransportMode) -> Spectrum {
        let Some(view) = self.view(normal, wo) else {
            return Spectrum::ZERO;
        };
        // Clear coat.
        if self.clearcoat.is_present() {
            let Some(coat) = self.clearcoat.view(normal, wo) else {
                return Spectrum::ZERO;
            };
            return self.coated_eval(&view, &coat, view.local(wi), wi, mode);
        }
        self.eval_local(&view, view.local(wi), mode)
    }

    /// Solid-angle density with which `sample` generates `wi` from `wo` through the lobes
    /// that have a density, their selection probabilities included.
    pub fn pdf(&self, normal: Vec3A, wo: Vec3A, wi: Vec3A) -> f32 {
        let Some(view) = self.view(normal, wo) else {
            return 0.0;
        };
        let choice = self.lobe_choice(&view);
        // Clear coat.
        if self.clearcoat.is_present() {
            let Some(coat) = self.clearcoat.view(normal, wo) else {
                return 0.0;
            };
            return self.coated_pdf(&view, choice, &coat, view.local(wi), wi);
        }
        self.pdf_local(&view, choice, view.local(wi))
    }

    /// What `sample` would return for scattering from `wo` into `wi`. At roughness 0 a
    /// `wi` on the other side is taken to be the exact refracted direction, and one on wo's
    /// side the mirror direction if it is within [`MIRROR_TOLERANCE`] of it or the material
    /// has no diffuse base (else it is the base's).
    pub fn scatter(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let view = self.view(normal, wo)?;
        let choice = self.lobe_choice(&view);
        // Clear coat: without lobes with a density, every direction is a Dirac lobe's.
        if self.clearcoat.is_present() {
            if !self.lobes().has_non_specular() {
                return self.coated_scatter_lobe(&view, choice, normal, wo, wi, mode, true);
            }
            return self.coated_scatter(&view, choice, normal, wo, wi, mode);
        }
        self.scatter_base(&view, choice, wi, mode)
    }

    /// `scatter` without the clear coat.
    #[inline]
    fn scatter_base(
        &self,
        view: &View,
        choice: LobeChoice,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let view = *view;
        let local = view.local(wi);
        if local.z == 0.0 {
            return None;
        }
        let mirror = Vec3A::new(-view.wo.x, -view.wo.y, view.wo.z);
        let dirac = self.distribution().is_none()
            && (local.z < 0.0
                || choice.diffuse == 0.0 && choice.sheen == 0.0
                || local.dot(mirror) > 1.0 - MIRROR_TOLERANCE)
            || self.transmits_straight() && local.z < 0.0;
        self.scatter_local(&view, choice, local, wi, mode, dirac)
    }

    /// What `sample` would return for scattering from `wo` into `wi` through a Dirac lobe
    /// (`dirac`: the mirror or refracted direction, which `wi` is taken to be) or through
    /// the lobes with a density. `None` where the material has no such lobe towards `wi`.
    pub fn scatter_lobe(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
        dirac: bool,
    ) -> Option<ScatterSample> {
        let view = self.view(normal, wo)?;
        let choice = self.lobe_choice(&view);
        // Clear coat.
        if self.clearcoat.is_present() {
            return self.coated_scatter_lobe(&view, choice, normal, wo, wi, mode, dirac);
        }
        let local = view.local(wi);
        if local.z == 0.0 {
            return None;
        }
        self.scatter_local(&view, choice, local, wi, mode, dirac)
    }

    /// `scatter_lobe` with `local` the view's frame's `wi`.
    #[inline]
    fn scatter_local(
        &self,
        view: &View,
        choice: LobeChoice,
        local: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
        dirac: bool,
    ) -> Option<ScatterSample> {
        match (self.distribution().is_some(), dirac) {
            (true, false) => self.rough_scatter(view, choice, local, wi, mode),
            (true, true) if local.z < 0.0 && self.transmits_straight() => (choice.transmission
                > 0.0)
                .then(|| self.specular_transmission(view, wi, choice, mode)),
            (true, true) => None,
            (false, true) if local.z < 0.0 => (choice.transmission > 0.0)
                .then(|| self.specular_transmission(view, wi, choice, mode)),
            (false, true) => Some(self.specular_reflection(view, wi, choice)),
            // The base reflects only.
            (false, false) if local.z < 0.0 => None,
            (false, false) => self.diffuse_scatter(view, choice, local, wi),
        }
    }

    /// The direction a roughness-0 material scatters `wo` into through `lobe`: the mirror
    /// direction, or the refracted one if it transmits (`None` under total internal
    /// reflection). `None` for a rough material.
    pub fn specular_direction(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        lobe: SpecularLobe,
    ) -> Option<Vec3A> {
        // Clear coat: a smooth one's mirror about its own normal (`BaseReflection` names a
        // smooth base's beneath it).
        if lobe == SpecularLobe::Reflection
            && self.clearcoat.is_present()
            && self.clearcoat.is_smooth()
        {
            return Some(reflect(wo, self.clearcoat.normal.unwrap_or(normal)));
        }
        if lobe == SpecularLobe::Refraction && self.transmits_straight() {
            return Some(-wo);
        }
        if !self.is_smooth() {
            return None;
        }
        match lobe {
            SpecularLobe::Reflection | SpecularLobe::BaseReflection => Some(reflect(wo, normal)),
            SpecularLobe::Refraction if !self.transmission_tint().is_black() => {
                refracted(self.ior, normal, wo)
            }
            SpecularLobe::Refraction => None,
        }
    }

    /// The specular lobe that scatters `wo` into `wi`, given `by_sides`, the one the sides
    /// of the directions name (`SpecularLobe::of`): a reflection under a smooth coat with
    /// a normal of its own over a smooth base is the base's mirror (`BaseReflection`) where
    /// `wi` is nearer it than the coat's (see [`Self::nearer_base_mirror`]).
    pub fn specular_lobe(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        wi: Vec3A,
        by_sides: SpecularLobe,
    ) -> SpecularLobe {
        if by_sides == SpecularLobe::Reflection
            && self.has_two_mirrors()
            && self.nearer_base_mirror(normal, wo, wi)
        {
            SpecularLobe::BaseReflection
        } else {
            by_sides
        }
    }

    /// The microfacet through which a rough material scatters `wo` into `wi`: the half
    /// vector of a reflection, the generalized one of a refraction (on wo's side). `None` at
    /// roughness 0, or where no microfacet scatters wo into wi.
    pub fn microfacet(&self, normal: Vec3A, wo: Vec3A, wi: Vec3A) -> Option<Microfacet> {
        self.distribution()?;
        let view = self.view(normal, wo)?;
        let local = view.local(wi);
        let (h, refracts) = if local.z > 0.0 {
            let h = (view.wo + local).normalize();
            (h, false)
        } else if local.z < 0.0
            && !self.transmission_tint().is_black()
            && !self.transmits_straight()
        {
            (refraction_half_vector(&view, local)?.0, true)
        } else {
            return None;
        };
        (h.z > 0.0 && view.wo.dot(h) > 0.0).then(|| Microfacet {
            normal: view.basis.to_world(h),
            refracts,
        })
    }

    /// The direction `wo` scatters into through microfacet `m` (the inverse of
    /// [`Self::microfacet`]), or `None` if m is not on wo's side, the refraction is totally
    /// reflected, or the direction is not one the lobe scatters into.
    pub fn scatter_through(&self, normal: Vec3A, wo: Vec3A, m: Microfacet) -> Option<Vec3A> {
        let view = self.view(normal, wo)?;
        let h = view.local(m.normal);
        if h.z <= 0.0 {
            return None;
        }
        let local = if m.refracts {
            if self.transmission_tint().is_black() || self.transmits_straight() {
                return None;
            }
            refract_through(view.wo, h, view.eta()).filter(|wi| wi.z < 0.0)?
        } else {
            Some(reflect(view.wo, h)).filter(|wi| wi.z > 0.0 && view.wo.dot(h) > 0.0)?
        };
        Some(view.basis.to_world(local))
    }

    /// The coordinates of microfacet normal `m` in the sampling of the normals visible from
    /// `wo` ([`TrowbridgeReitz::visible_normal_coordinates`]).
    pub fn microfacet_coordinates(&self, normal: Vec3A, wo: Vec3A, m: Vec3A) -> Option<[f32; 2]> {
        let distribution = self.distribution()?;
        let view = self.view(normal, wo)?;
        distribution.visible_normal_coordinates(view.wo, view.local(m))
    }

    /// The microfacet normal visible from `wo` at coordinates `u` of their sampling.
    pub fn microfacet_at(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        u: [f32; 2],
        refracts: bool,
    ) -> Option<Microfacet> {
        let distribution = self.distribution()?;
        let view = self.view(normal, wo)?;
        let h = distribution.sample_visible_normal(view.wo, u);
        Some(Microfacet {
            normal: view.basis.to_world(h),
            refracts,
        })
    }

    /// The density, per unit solid angle of `wi`, of a direction found through a microfacet
    /// normal that has unit density per unit solid angle (`in_sample_space` false) or per
    /// unit area of its visible-normal coordinates (true): dω_m/dω_i, times the
    /// visible-normal density of m in the second case. 0 where no microfacet scatters `wo`
    /// into `wi`.
    pub fn microfacet_step_density(
        &self,
        normal: Vec3A,
        wo: Vec3A,
        wi: Vec3A,
        in_sample_space: bool,
    ) -> f32 {
        let (Some(distribution), Some(view)) = (self.distribution(), self.view(normal, wo)) else {
            return 0.0;
        };
        let local = view.local(wi);
        let (h, jacobian) = if local.z > 0.0 {
            let h = (view.wo + local).normalize();
            (h, 1.0 / (4.0 * view.wo.dot(h)))
        } else if let Some((h, cos_oh, cos_ih)) =
            refraction_half_vector(&view, local).filter(|_| !self.transmits_straight())
        {
            let denominator = view.eta_o * cos_oh + view.eta_t * cos_ih;
            (
                h,
                view.eta_t * view.eta_t * cos_ih.abs() / (denominator * denominator),
            )
        } else {
            return 0.0;
        };
        if !(jacobian.is_finite() && jacobian > 0.0) {
            return 0.0;
        }
        if in_sample_space {
            jacobian * distribution.visible_normal_pdf(view.wo, h)
        } else {
            jacobian
        }
    }

    /// The surface as seen from `wo` (see [`View`]).
    #[inline]
    fn view(&self, normal: Vec3A, wo: Vec3A) -> Option<View> {
        View::of(
            self.ior,
            normal,
            wo,
            self.anisotropy.map(|a| Vec3A::from(a.direction)),
        )
    }

    /// Whether its lobes are the Dirac ones of roughness 0 (an anisotropic surface is
    /// rough along its direction even there).
    #[inline]
    fn is_smooth(&self) -> bool {
        self.roughness == 0.0 && self.anisotropy.is_none()
    }

    /// GGX of this roughness (stretched along the anisotropy's direction), or `None` for
    /// the Dirac lobes of roughness 0.
    #[inline]
    fn distribution(&self) -> Option<TrowbridgeReitz> {
        let alpha = self.roughness * self.roughness;
        match self.anisotropy {
            None => (self.roughness > 0.0).then(|| TrowbridgeReitz::new(alpha)),
            Some(a) => {
                let stretch = a.strength * a.strength;
                Some(TrowbridgeReitz::anisotropic(
                    alpha + (1.0 - alpha) * stretch,
                    alpha,
                ))
            }
        }
    }

    /// The perceptual roughness the albedo tables (`multiple_scattering`, tabulated for
    /// isotropic GGX) are read at: the roughness, or for an anisotropic surface the
    /// isotropic one of α = (α_t + α_b) / 2. By quadrature, its albedo is within 0.01–0.09
    /// above the anisotropic lobe's averaged over the azimuth (0.90 for 0.82 at α 0.04,
    /// strength 0.7; 0.57 for 0.51 at α 0.25, strength 1, face-on), where the geometric
    /// mean √(α_t α_b) is up to 0.18 above (it misses most of the loss) and the root mean
    /// square up to 0.03 below (it would compensate more than is lost).
    #[inline]
    fn table_roughness(&self) -> f32 {
        match (self.anisotropy, self.distribution()) {
            (Some(_), Some(d)) => {
                let (alpha_x, alpha_y) = d.alphas();
                ((alpha_x + alpha_y) * 0.5).sqrt()
            }
            _ => self.roughness,
        }
    }

    /// Whether it is rough, transmits, and is index-matched: its transmission is then a
    /// Dirac lobe along −wo (see [`INDEX_MATCHED`]).
    #[inline]
    fn transmits_straight(&self) -> bool {
        !self.is_smooth()
            && (self.ior - 1.0).abs() <= INDEX_MATCHED
            && !self.transmission_tint().is_black()
    }

    #[inline]
    fn f0(&self) -> f32 {
        let r = (self.ior - 1.0) / (self.ior + 1.0);
        r * r
    }

    /// The dielectric's normal reflectance per lane with `KHR_materials_specular`'s colour,
    /// min(F0 · specular_color, 1) (before the strength `specular`).
    #[inline]
    fn specular_f0(&self) -> Spectrum {
        (Spectrum::splat(self.f0()) * self.specular_color).min(Spectrum::ONE)
    }

    /// The largest channel of [`Self::specular_f0`] (by the RGB colour).
    #[inline]
    fn specular_f0_max(&self) -> f32 {
        (self.f0() * self.specular_color_max).min(1.0)
    }

    /// The dielectric interface's reflectance by lane at cosine `cos` to `wo` (η = `eta`):
    /// `specular` × Schlick's with the specular F0, 1 under total internal reflection.
    #[inline]
    fn dielectric_reflectance(&self, cos: f32, eta: f32) -> Spectrum {
        match rarer_cosine(cos, eta) {
            Some(rarer) => self.rarer_dielectric_reflectance(rarer),
            None => Spectrum::ONE,
        }
    }

    /// The dielectric interface's reflectance by lane at cosine `rarer` on the side of the
    /// lower index. Thin film: its reflectance, over a base of normal reflectance
    /// `specular` × the specular F0, mixed in by its factor (as `KHR_materials_iridescence`
    /// writes it with `KHR_materials_specular`). The film is seen from the outside on either
    /// side: a film without losses reflects the same from both.
    #[inline]
    fn rarer_dielectric_reflectance(&self, rarer: f32) -> Spectrum {
        let plain = schlick_lanes(self.specular_f0(), rarer) * self.specular;
        match &self.film {
            None => plain,
            Some(film) => {
                let filmed = film.reflectance(self.specular_f0() * self.specular, rarer);
                plain + (filmed - plain) * film.factor
            }
        }
    }

    /// The largest channel of [`Self::dielectric_reflectance`]: what the layers it covers
    /// (the diffuse base, the transmission) are weighted by, one minus it.
    #[inline]
    fn dielectric_reflectance_max(&self, cos: f32, eta: f32) -> f32 {
        match rarer_cosine(cos, eta) {
            Some(rarer) => self.rarer_dielectric_reflectance_max(rarer),
            None => 1.0,
        }
    }

    /// The largest channel of [`Self::rarer_dielectric_reflectance`] (a thin film's by
    /// its lanes).
    #[inline]
    fn rarer_dielectric_reflectance_max(&self, rarer: f32) -> f32 {
        match &self.film {
            None => self.specular * schlick(self.specular_f0_max(), rarer),
            Some(_) => self.rarer_dielectric_reflectance(rarer).max_component(),
        }
    }

    /// The largest channel of the Fresnel reflectance of the opaque part of the dielectric:
    /// the interface seen from the outside, whichever side `wo` is on.
    #[inline]
    fn opaque_reflectance(&self, cos: f32) -> f32 {
        self.dielectric_reflectance_max(cos, 1.0 / self.ior)
    }

    /// The reflection's Fresnel factor at a microfacet (or the normal) at cosine `cos` to
    /// `wo`: the metal's, and the dielectric's opaque and transmissive parts'.
    #[inline]
    fn reflectance(&self, cos: f32, eta: f32) -> Spectrum {
        let dielectric = self.dielectric_reflectance(cos, 1.0 / self.ior)
            * (1.0 - self.transmission)
            + self.dielectric_reflectance(cos, eta) * self.transmission;
        self.metal_reflectance(cos) * self.metallic + dielectric * (1.0 - self.metallic)
    }

    /// The metal's Fresnel factor: Schlick's with F0 = base colour. Thin film: its
    /// reflectance over a base of that normal reflectance, mixed in by its factor.
    #[inline]
    fn metal_reflectance(&self, cos: f32) -> Spectrum {
        let plain = schlick_spectrum(self.base_color, cos);
        match &self.film {
            None => plain,
            Some(film) => plain + (film.reflectance(self.base_color, cos) - plain) * film.factor,
        }
    }

    /// The metal's multiple-scattering compensation, if it has one: asked for, rough and
    /// with a metallic part that loses energy.
    #[inline]
    fn compensation(&self) -> Option<EnergyCompensation> {
        if !self.energy_compensation || self.metallic == 0.0 || self.is_smooth() {
            return None;
        }
        EnergyCompensation::new(self.table_roughness())
    }

    /// The compensation lobe's tint: the metal's share times F_ms of Schlick's Fresnel
    /// with F0 = base colour, whose cosine-weighted mean is F0 + (1 − F0) / 21.
    #[inline]
    fn multiple_scattering_tint(&self, compensation: &EnergyCompensation) -> Spectrum {
        let f_ms = |f0: f32| compensation.fresnel(f0 + (1.0 - f0) / 21.0);
        let c = self.base_color;
        c.map(f_ms) * self.metallic
    }

    /// The diffuse base's share of the material, times its albedo.
    #[inline]
    fn diffuse_tint(&self) -> Spectrum {
        self.base_color * ((1.0 - self.metallic) * (1.0 - self.transmission))
    }

    /// The transmission's share of the material, times its tint.
    #[inline]
    fn transmission_tint(&self) -> Spectrum {
        self.base_color * ((1.0 - self.metallic) * self.transmission)
    }

    /// Lobe probabilities in proportion to estimates of the lobes' albedos at `wo`: the
    /// Fresnel factors at the macro normal times the tints.
    fn lobe_choice(&self, view: &View) -> LobeChoice {
        let cos_o = view.wo.z;
        let transmitted = 1.0 - self.dielectric_reflectance_max(cos_o, view.eta());
        let reflection = mean(self.reflectance(cos_o, view.eta()));
        // The base's albedo is (1 − R(cos_o)) of its tint; 1 − F(cos_o) is close to it and
        // cheaper (estimates only need to be positive where the lobe scatters).
        let diffuse = mean(self.diffuse_tint()) * (1.0 - self.opaque_reflectance(cos_o));
        let transmission = mean(self.transmission_tint()) * transmitted;
        let at_least = |estimate: f32, scatters: bool| {
            if scatters {
                estimate.max(MIN_LOBE_WEIGHT)
            } else {
                0.0
            }
        };
        // A smooth interface refracts nothing under total internal reflection; a rough one
        // still refracts through tilted microfacets.
        let refracts = if !self.is_smooth() {
            !self.transmission_tint().is_black()
        } else {
            transmission > 0.0
        };
        let reflection = at_least(reflection, true);
        let diffuse = at_least(diffuse, !self.diffuse_tint().is_black());
        let transmission = at_least(transmission, refracts);
        // What the compensation adds at wo; zero exactly where its f is zero for this wo.
        let multiple = self.compensation().map_or(0.0, |c| {
            mean(self.multiple_scattering_tint(&c)) * (1.0 - c.albedo(cos_o))
        });
        // ---- sheen layer: its lobe's estimate ----
        let sheen = self
            .sheen
            .map_or(0.0, |s| s.estimate(cos_o).max(MIN_LOBE_WEIGHT));
        let total = reflection + diffuse + transmission + multiple + sheen;
        LobeChoice {
            reflection: reflection / total,
            diffuse: diffuse / total,
            transmission: transmission / total,
            multiple: multiple / total,
            total,
            sheen: sheen / total,
        }
    }

    /// The reflectance of the coat over the diffuse base: the dielectric's reflection seen
    /// from the outside, by its largest channel (before the strength `specular`).
    #[inline]
    fn coat(&self) -> CoatReflectance {
        CoatReflectance::new(self.table_roughness(), self.specular_f0_max())
    }

    /// The diffuse base's f at cosines `cos_o`, `cos_i` (same side), scaled by what the
    /// coat does not reflect at either: (1 − R(μo)) (1 − R(μi)) / (1 − R_avg), whose
    /// cosine-weighted integral over μi is 1 − R(μo) (see the module's documentation), R
    /// the coat's reflectance times `specular`. A coat that reflects everything (R = 1)
    /// leaves nothing.
    #[inline]
    fn diffuse_f(&self, cos_o: f32, cos_i: f32) -> Spectrum {
        let coat = self.coat();
        let (at_o, at_i, average) = match &self.film {
            None => (
                self.specular * coat.reflectance(cos_o),
                self.specular * coat.reflectance(cos_i),
                self.specular * coat.average(),
            ),
            Some(film) => self.filmed_coat_reflectances(film, &coat, cos_o, cos_i),
        };
        let through_average = 1.0 - average;
        if through_average <= 0.0 {
            return Spectrum::ZERO;
        }
        let through = (1.0 - at_o) * (1.0 - at_i) / through_average;
        self.diffuse_tint() * (through * FRAC_1_PI)
    }

    /// Thin film: what the coat over the diffuse base reflects at `cos_o` and `cos_i`, and
    /// its cosine-weighted mean, for the albedo scaling of `diffuse_f`: the plain coat's
    /// mixed by the film's factor with a bound of the film's. The bound is the film's
    /// reflectance with its two interfaces' waves in phase (its largest at any wavelength
    /// and thickness), of the interfaces' tabulated coat reflectances (Schlick's for a
    /// smooth coat) with the outer F0 and the largest inner one among the lanes, the inner
    /// one taken at the outside cosine (Schlick's there is at least at the cosine inside a
    /// film denser than vacuum). A smooth coat then reflects no more than the base loses,
    /// lane by lane, so a white furnace stays at most 1; for rough coats it is tested. The
    /// mean is a Gauss–Legendre quadrature.
    #[inline(never)]
    fn filmed_coat_reflectances(
        &self,
        film: &ThinFilm,
        coat: &CoatReflectance,
        cos_o: f32,
        cos_i: f32,
    ) -> (f32, f32, f32) {
        let (outer_f0, inner_f0) = film.interface_f0s(self.specular_f0() * self.specular);
        let outer = CoatReflectance::new(self.roughness, outer_f0);
        let inner = CoatReflectance::new(self.roughness, inner_f0);
        // A film rarer than vacuum has its inner cosine below the outside one.
        let inner_cosine = |mu: f32| {
            if film.ior >= 1.0 {
                Some(mu)
            } else {
                let sin2 = (1.0 - mu * mu) / (film.ior * film.ior);
                (sin2 < 1.0).then(|| (1.0 - sin2).sqrt())
            }
        };
        let bound = |mu: f32| match inner_cosine(mu) {
            Some(inside) => ThinFilm::envelope_of(outer.reflectance(mu), inner.reflectance(inside)),
            None => 1.0,
        };
        // 2 ∫ R(μ) μ dμ = ∫ R(√u) du, 8 Gauss–Legendre nodes in u over [0, 1].
        const NODES: [(f32, f32); 4] = [
            (0.183_434_64, 0.362_683_78),
            (0.525_532_4, 0.313_706_65),
            (0.796_666_5, 0.222_381_03),
            (0.960_289_85, 0.101_228_54),
        ];
        let bound_average: f32 = NODES
            .iter()
            .map(|&(x, w)| {
                let (lo, hi) = ((1.0 - x) / 2.0, (1.0 + x) / 2.0);
                w / 2.0 * (bound(lo.sqrt()) + bound(hi.sqrt()))
            })
            .sum();
        let plain = |r: f32| self.specular * r;
        let mix = |plain: f32, filmed: f32| plain + (filmed - plain) * film.factor;
        (
            mix(plain(coat.reflectance(cos_o)), bound(cos_o)),
            mix(plain(coat.reflectance(cos_i)), bound(cos_i)),
            mix(plain(coat.average()), bound_average),
        )
    }

    /// f of the lobes with a density, `wi` in the view's frame: the layers beneath the
    /// sheen, scaled by what it leaves them, and the sheen's lobe.
    #[inline]
    fn eval_local(&self, view: &View, wi: Vec3A, mode: TransportMode) -> Spectrum {
        let f = self.base_eval_local(view, wi, mode);
        // ---- sheen layer ----
        match &self.sheen {
            None => f,
            Some(sheen) => f * sheen.scaling(view.wo.z, wi.z) + sheen.f(view.wo, wi),
        }
    }

    /// The density of `sample` through the lobes with a density, `wi` in the view's frame.
    #[inline]
    fn pdf_local(&self, view: &View, choice: LobeChoice, wi: Vec3A) -> f32 {
        let pdf = self.base_pdf_local(view, choice, wi);
        // ---- sheen layer: its lobe, uniform over wo's hemisphere ----
        if choice.sheen > 0.0 && wi.z > 0.0 {
            pdf + choice.sheen * sheen::UNIFORM_HEMISPHERE_PDF
        } else {
            pdf
        }
    }

    /// What the sheen layer leaves of a Dirac lobe's weight into `wi`.
    #[inline]
    fn sheen_scaling(&self, view: &View, wi: Vec3A) -> f32 {
        self.sheen
            .map_or(1.0, |s| s.scaling(view.wo.z, view.local(wi).z))
    }

    /// f of the lobes beneath the sheen with a density, `wi` in the view's frame.
    fn base_eval_local(&self, view: &View, wi: Vec3A, mode: TransportMode) -> Spectrum {
        let wo = view.wo;
        if wi.z > 0.0 {
            let mut f = self.diffuse_f(wo.z, wi.z);
            if let Some(distribution) = self.distribution() {
                let h = (wo + wi).normalize();
                let microfacets = distribution.d(h) * distribution.g2(wo, wi) / (4.0 * wo.z * wi.z);
                f += self.reflectance(wo.dot(h), view.eta()) * microfacets;
            }
            if let Some(compensation) = self.compensation() {
                f += self.multiple_scattering_tint(&compensation) * compensation.f(wo.z, wi.z);
            }
            return f;
        }
        let (Some(distribution), Some((h, cos_oh, cos_ih))) =
            (self.distribution(), refraction_half_vector(view, wi))
        else {
            return Spectrum::ZERO;
        };
        if wi.z == 0.0 || self.transmission_tint().is_black() || self.transmits_straight() {
            return Spectrum::ZERO;
        }
        let denominator = view.eta_o * cos_oh + view.eta_t * cos_ih;
        // Radiance is compressed into the smaller solid angle on the denser side: the η²
        // of the side the path leaves towards (wo's in radiance mode), so that importance
        // mode is the adjoint, f_importance(wo, wi) = f_radiance(wi, wo).
        let eta_scale = match mode {
            TransportMode::Radiance => view.eta_o * view.eta_o,
            TransportMode::Importance => view.eta_t * view.eta_t,
        };
        // Schlick's F at the cosine on the side of the lower index, as
        // `dielectric_reflectance`, but taken from the pair: recomputing it from Snell's law
        // near the critical angle would cancel catastrophically (and break reciprocity).
        let rarer_cos = if view.eta_o <= view.eta_t {
            cos_oh
        } else {
            -cos_ih
        };
        let transmitted = 1.0 - self.rarer_dielectric_reflectance_max(rarer_cos);
        let microfacets = distribution.d(h) * distribution.g2(wo, wi) * (cos_oh * cos_ih).abs()
            / (wo.z * wi.z.abs() * denominator * denominator);
        self.transmission_tint() * (transmitted * eta_scale * microfacets)
    }

    /// The density of `sample` through the lobes beneath the sheen with a density, `wi` in
    /// the view's frame.
    fn base_pdf_local(&self, view: &View, choice: LobeChoice, wi: Vec3A) -> f32 {
        let wo = view.wo;
        if wi.z > 0.0 {
            let mut pdf = (choice.diffuse + choice.multiple) * cosine_hemisphere_pdf(wi.z);
            if let Some(distribution) = self.distribution() {
                let h = (wo + wi).normalize();
                pdf +=
                    choice.reflection * distribution.visible_normal_pdf(wo, h) / (4.0 * wo.dot(h));
            }
            return pdf;
        }
        if wi.z == 0.0 || choice.transmission == 0.0 || self.transmits_straight() {
            return 0.0;
        }
        let (Some(distribution), Some((h, cos_oh, cos_ih))) =
            (self.distribution(), refraction_half_vector(view, wi))
        else {
            return 0.0;
        };
        let denominator = view.eta_o * cos_oh + view.eta_t * cos_ih;
        // dω_h / dω_i of refraction (Walter et al. 2007, eq. 17).
        let jacobian = view.eta_t * view.eta_t * cos_ih.abs() / (denominator * denominator);
        choice.transmission * distribution.visible_normal_pdf(wo, h) * jacobian
    }

    /// A rough material's scattering into `wi` (`local` in the view's frame).
    fn rough_scatter(
        &self,
        view: &View,
        choice: LobeChoice,
        local: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let pdf = self.pdf_local(view, choice, local);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        let f = self.eval_local(view, local, mode);
        // `eval_local`'s radiance scaling on refraction, η_o² over the η_t² the microfacet
        // term's denominator brings.
        let radiance_scale = match mode {
            TransportMode::Radiance if local.z < 0.0 => view.eta() * view.eta(),
            _ => 1.0,
        };
        Some(ScatterSample {
            wi,
            weight: f * (local.z.abs() / pdf),
            pdf,
            specular: false,
            radiance_scale,
        })
    }

    /// Roughness 0's diffuse base (and sheen) scattering into `wi` (`local` in the view's
    /// frame).
    fn diffuse_scatter(
        &self,
        view: &View,
        choice: LobeChoice,
        local: Vec3A,
        wi: Vec3A,
    ) -> Option<ScatterSample> {
        // ---- sheen layer: the lobes with a density are the base's and the sheen's ----
        if self.sheen.is_some() {
            return self.rough_scatter(view, choice, local, wi, TransportMode::Radiance);
        }
        let pdf = choice.diffuse * cosine_hemisphere_pdf(local.z);
        (pdf > 0.0).then(|| ScatterSample {
            wi,
            weight: self.diffuse_f(view.wo.z, local.z) * (local.z / pdf),
            pdf,
            specular: false,
            radiance_scale: 1.0,
        })
    }

    /// Roughness 0's mirror reflection into `wi`.
    fn specular_reflection(&self, view: &View, wi: Vec3A, choice: LobeChoice) -> ScatterSample {
        ScatterSample {
            wi,
            weight: self.reflectance(view.wo.z, view.eta())
                * (self.sheen_scaling(view, wi) / choice.reflection),
            pdf: choice.reflection,
            specular: true,
            radiance_scale: 1.0,
        }
    }

    /// The Dirac refraction into `wi` (roughness 0's, or a rough index-matched interface's
    /// straight one), with dielectric.rs's radiance scaling η².
    fn specular_transmission(
        &self,
        view: &View,
        wi: Vec3A,
        choice: LobeChoice,
        mode: TransportMode,
    ) -> ScatterSample {
        let eta = view.eta();
        let scale = match mode {
            TransportMode::Radiance => eta * eta,
            TransportMode::Importance => 1.0,
        };
        let transmitted = match self.distribution() {
            None => 1.0 - self.dielectric_reflectance_max(view.wo.z, eta),
            Some(distribution) => {
                // The microfacet form's limit at η = 1 (see the module's documentation).
                let f0 = self.specular_f0_max();
                let mean = visible_schlick_mean(self.table_roughness(), view.wo.z);
                let through = 1.0 - self.specular * (f0 + (1.0 - f0) * mean);
                let lambda = distribution.lambda(view.wo);
                through * (1.0 + lambda) / (1.0 + 2.0 * lambda)
            }
        };
        let transmitted = transmitted * self.sheen_scaling(view, wi);
        ScatterSample {
            wi,
            weight: self.transmission_tint() * (transmitted * scale / choice.transmission),
            pdf: choice.transmission,
            specular: true,
            radiance_scale: scale,
        }
    }
}

/// The largest f32 below 1: the base's lobe choice rescaled out of the coat's stays below 1.
const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// Clear coat: the coat (see the `clearcoat` module) composed with the base. The coat's lobe
/// is picked with probability p = c F(μo) / (c F(μo) + (1 − c F(μo)) · the base's estimates'
/// sum), the base's lobes with 1 − p as among themselves; a direction with a density has
/// the mixture's, and the Dirac lobes keep their own, times p or 1 − p. A smooth coat over
/// a smooth base with the same normal has one mirror direction: the two Dirac lobes are
/// one there.
impl MetallicRoughness {
    /// The probability of picking the coat's lobe.
    #[inline]
    fn coat_probability(coat: &CoatView, choice: &LobeChoice) -> f32 {
        let estimate = coat.albedo_estimate();
        estimate / (estimate + (1.0 - estimate) * choice.total)
    }

    /// Whether the smooth coat's mirror and a smooth base's are the same Dirac lobe.
    #[inline]
    fn mirrors_coincide(&self) -> bool {
        self.is_smooth() && self.clearcoat.is_smooth() && self.clearcoat.normal.is_none()
    }

    /// f of the lobes with a density: the base's under the coat, and the coat's.
    #[inline]
    fn coated_eval(
        &self,
        view: &View,
        coat: &CoatView,
        local: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Spectrum {
        self.eval_local(view, local, mode) * coat.base_scale(wi, mode)
            + Spectrum::splat(coat.eval(wi, mode))
    }

    /// The mixture's density of `wi` (`local` in the base's frame).
    #[inline]
    fn coated_pdf(
        &self,
        view: &View,
        choice: LobeChoice,
        coat: &CoatView,
        local: Vec3A,
        wi: Vec3A,
    ) -> f32 {
        let p = Self::coat_probability(coat, &choice);
        p * coat.pdf(wi) + (1.0 - p) * self.pdf_local(view, choice, local)
    }

    /// The coated material's scattering into a direction `wi` with a density.
    fn coated_density_scatter(
        &self,
        view: &View,
        choice: LobeChoice,
        coat: &CoatView,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let local = view.local(wi);
        if local.z == 0.0 {
            return None;
        }
        let pdf = self.coated_pdf(view, choice, coat, local, wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let f = self.coated_eval(view, coat, local, wi, mode);
        // As `rough_scatter`: the radiance scaling on refraction.
        let radiance_scale = match mode {
            TransportMode::Radiance if local.z < 0.0 => view.eta() * view.eta(),
            _ => 1.0,
        };
        Some(ScatterSample {
            wi,
            weight: f * (local.z.abs() / pdf),
            pdf,
            specular: false,
            radiance_scale,
        })
    }

    /// A Dirac scattering of the base (`base`: its weight and probability among the base's
    /// lobes) under the coat.
    fn coated_base_dirac(
        &self,
        view: &View,
        choice: LobeChoice,
        coat: &CoatView,
        base: ScatterSample,
        mode: TransportMode,
    ) -> ScatterSample {
        if self.mirrors_coincide() && view.local(base.wi).z > 0.0 {
            return self.merged_mirror(view, choice, coat, base.wi, mode);
        }
        let p = Self::coat_probability(coat, &choice);
        ScatterSample {
            weight: base.weight * (coat.base_scale(base.wi, mode) / (1.0 - p)),
            pdf: base.pdf * (1.0 - p),
            ..base
        }
    }

    /// The smooth coat's mirror reflection (merged with a smooth base's about the same
    /// normal).
    fn coat_mirror(
        &self,
        view: &View,
        choice: LobeChoice,
        coat: &CoatView,
        mode: TransportMode,
    ) -> ScatterSample {
        let wi = coat.mirror();
        if self.mirrors_coincide() {
            return self.merged_mirror(view, choice, coat, wi, mode);
        }
        let p = Self::coat_probability(coat, &choice);
        ScatterSample {
            wi,
            weight: Spectrum::splat(coat.mirror_reflectance(wi, mode) / p),
            pdf: p,
            specular: true,
            radiance_scale: 1.0,
        }
    }

    /// The one mirror lobe of a smooth coat over a smooth base with the same normal.
    fn merged_mirror(
        &self,
        view: &View,
        choice: LobeChoice,
        coat: &CoatView,
        wi: Vec3A,
        mode: TransportMode,
    ) -> ScatterSample {
        let p = Self::coat_probability(coat, &choice);
        let base = self.specular_reflection(view, wi, choice);
        let pdf = p + (1.0 - p) * base.pdf;
        let reflectance = base.weight * (base.pdf * coat.base_scale(wi, mode))
            + Spectrum::splat(coat.mirror_reflectance(wi, mode));
        ScatterSample {
            wi,
            weight: reflectance * (1.0 / pdf),
            pdf,
            specular: true,
            radiance_scale: 1.0,
        }
    }

    /// `sample` with the coat.
    #[allow(clippy::too_many_arguments)]
    fn coated_sample(
        &self,
        view: &View,
        choice: LobeChoice,
        normal: Vec3A,
        wo: Vec3A,
        u: [f32; 2],
        u_lobe: f32,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let coat = self.clearcoat.view(normal, wo)?;
        let p = Self::coat_probability(&coat, &choice);
        if u_lobe < p {
            if coat.is_smooth() {
                coat.sample(u)?;
                return Some(self.coat_mirror(view, choice, &coat, mode));
            }
            let wi = coat.sample(u)?;
            return self.coated_density_scatter(view, choice, &coat, wi, mode);
        }
        let u_base = ((u_lobe - p) / (1.0 - p)).min(BELOW_ONE);
        let base = self.sample_base(view, choice, normal, wo, u, u_base, mode)?;
        if base.specular {
            return Some(self.coated_base_dirac(view, choice, &coat, base, mode));
        }
        self.coated_density_scatter(view, choice, &coat, base.wi, mode)
    }

    /// Whether a smooth coat with a normal of its own lies over a smooth base: two mirrors
    /// about different normals, two Dirac reflections.
    #[inline]
    fn has_two_mirrors(&self) -> bool {
        self.roughness == 0.0
            && self.clearcoat.is_present()
            && self.clearcoat.is_smooth()
            && self.clearcoat.normal.is_some()
    }

    /// Whether `wi`, reflected from `wo`, is nearer the base's mirror direction (about
    /// `normal`) than the coat's (about its own normal). A path's direction rebuilt from
    /// its vertices is off its mirror by rounding; the nearer mirror names it without a
    /// tolerance. (Where the two normals are within rounding of each other the mirrors are
    /// one in all but name, and the choice is arbitrary.)
    #[inline]
    fn nearer_base_mirror(&self, normal: Vec3A, wo: Vec3A, wi: Vec3A) -> bool {
        let coat_normal = self.clearcoat.normal.unwrap_or(normal);
        wi.dot(reflect(wo, normal)) > wi.dot(reflect(wo, coat_normal))
    }

    /// `scatter_lobe` with the coat: with `dirac`, the smooth coat's mirror, the smooth
    /// base's mirror or refraction, whichever `wi` is (by its side, and by the nearer
    /// mirror where there are two); else the lobes with a density (the coat's and the
    /// base's under it), as `coated_density_scatter`, where a smooth base reflects only.
    #[allow(clippy::too_many_arguments)]
    fn coated_scatter_lobe(
        &self,
        view: &View,
        choice: LobeChoice,
        normal: Vec3A,
        wo: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
        dirac: bool,
    ) -> Option<ScatterSample> {
        let coat = self.clearcoat.view(normal, wo)?;
        let local = view.local(wi);
        if local.z == 0.0 {
            return None;
        }
        let smooth_base = self.distribution().is_none();
        if !dirac {
            if smooth_base && local.z < 0.0 {
                return None;
            }
            return self.coated_density_scatter(view, choice, &coat, wi, mode);
        }
        if local.z < 0.0 {
            // Only a smooth base, or a rough index-matched one, refracts through a Dirac
            // lobe.
            let refracts = (smooth_base || self.transmits_straight()) && choice.transmission > 0.0;
            let base = refracts.then(|| self.specular_transmission(view, wi, choice, mode))?;
            return Some(self.coated_base_dirac(view, choice, &coat, base, mode));
        }
        let coat_reflects = coat.is_smooth() && coat.stays_on_wo_side(coat.mirror());
        let base_reflects = smooth_base;
        let through_base = match (coat_reflects, base_reflects) {
            (false, false) => return None,
            (true, false) => false,
            (false, true) => true,
            // Two mirrors: one where their normals are the same (`coat_mirror` merges them).
            (true, true) => self.has_two_mirrors() && self.nearer_base_mirror(normal, wo, wi),
        };
        if through_base {
            let base = self.specular_reflection(view, wi, choice);
            Some(self.coated_base_dirac(view, choice, &coat, base, mode))
        } else {
            Some(self.coat_mirror(view, choice, &coat, mode))
        }
    }

    /// `scatter` with the coat: a `wi` within [`MIRROR_TOLERANCE`] of a smooth coat's
    /// mirror direction is its reflection, one of a smooth base's is the base's (on the
    /// other side its refraction), others have a density.
    fn coated_scatter(
        &self,
        view: &View,
        choice: LobeChoice,
        normal: Vec3A,
        wo: Vec3A,
        wi: Vec3A,
        mode: TransportMode,
    ) -> Option<ScatterSample> {
        let coat = self.clearcoat.view(normal, wo)?;
        let local = view.local(wi);
        if local.z == 0.0 {
            return None;
        }
        if coat.is_smooth()
            && wi.dot(coat.mirror()) > 1.0 - MIRROR_TOLERANCE
            && coat.stays_on_wo_side(wi)
        {
            return Some(self.coat_mirror(view, choice, &coat, mode));
        }
        // A rough index-matched base's straight transmission: nothing else transmits.
        if local.z < 0.0 && self.transmits_straight() {
            return (choice.transmission > 0.0).then(|| {
                let base = self.specular_transmission(view, wi, choice, mode);
                self.coated_base_dirac(view, choice, &coat, base, mode)
            });
        }
        if self.distribution().is_none() {
            let base = if local.z < 0.0 {
                (choice.transmission > 0.0)
                    .then(|| self.specular_transmission(view, wi, choice, mode))
            } else {
                let mirror = Vec3A::new(-view.wo.x, -view.wo.y, view.wo.z);
                (local.dot(mirror) > 1.0 - MIRROR_TOLERANCE)
                    .then(|| self.specular_reflection(view, wi, choice))
            };
            if let Some(base) = base {
                return Some(self.coated_base_dirac(view, choice, &coat, base, mode));
            }
            if local.z < 0.0 {
                return None;
            }
        }
        self.coated_density_scatter(view, choice, &coat, wi, mode)
    }
}

/// The lobe `sample` picked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lobe {
    Reflection,
    Diffuse,
    Transmission,
    MultipleScattering,
    Sheen,
}

impl LobeChoice {
    /// The lobe `u` in [0, 1) picks: reflection, diffuse, transmission, then the
    /// compensation, each over its probability (reflection always has one).
    #[inline]
    fn pick(&self, u: f32) -> Lobe {
        let mut cumulative = 0.0;
        for (lobe, probability) in [
            (Lobe::Reflection, self.reflection),
            (Lobe::Diffuse, self.diffuse),
            (Lobe::Transmission, self.transmission),
            (Lobe::MultipleScattering, self.multiple),
            (Lobe::Sheen, self.sheen),
        ] {
            cumulative += probability;
            if u < cumulative {
                return lobe;
            }
        }
        // Rounding left u past the sum: the last lobe that has a probability.
        [
            (Lobe::Sheen, self.sheen),
            (Lobe::MultipleScattering, self.multiple),
            (Lobe::Transmission, self.transmission),
            (Lobe::Diffuse, self.diffuse),
        ]
        .into_iter()
        .find(|&(_, p)| p > 0.0)
        .map_or(Lobe::Reflection, |(lobe, _)| lobe)
    }
}

#[cfg(test)]
impl MetallicRoughness {
    /// The probability with which `sample` picks transmission from `wo`.
    fn lobe_choice_transmission(&self, normal: Vec3A, wo: Vec3A) -> f32 {
        self.view(normal, wo)
            .map_or(0.0, |view| self.lobe_choice(&view).transmission)
    }
}

#[cfg(test)]
mod tests {
    use super::super::dielectric;
    use super::super::multiple_scattering::{
        EnergyCompensation, single_scattering_albedo, single_scattering_albedos,
    };
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::chi_square::{
        Z_1E6, pooled_statistic, quantile, sphere_cell_probabilities,
    };

    /// A tilted shading normal, so no test relies on the frame being the world's.
    fn normal() -> Vec3A {
        Vec3A::new(0.2, 0.9, -0.3).normalize()
    }

    /// A direction at polar angle θ from `normal()` (θ > 90°: from below), slightly off
    /// any axis of the frame.
    fn direction(theta_deg: f32) -> Vec3A {
        let basis = OrthonormalBasis::from_normal(normal());
        let (s, c) = theta_deg.to_radians().sin_cos();
        basis
            .to_world(Vec3A::new(s * 0.96, s * 0.28, c))
            .normalize()
    }

    fn material(roughness: f32, metallic: f32, transmission: f32, ior: f32) -> MetallicRoughness {
        MetallicRoughness {
            base_color: Spectrum::new(0.9, 0.6, 0.3),
            metallic,
            roughness,
            ior,
            transmission,
            energy_compensation: false,
            clearcoat: Clearcoat::NONE,
            specular: 1.0,
            specular_color: Spectrum::ONE,
            specular_color_max: 1.0,
            sheen: None,
            anisotropy: None,
            film: None,
        }
    }

    /// `m` made anisotropic: `strength`, its direction turned by `angle` (radians) from the
    /// test frame's tangent about `normal()` (off the axes `cell` bins by).
    fn anisotropic(m: MetallicRoughness, strength: f32, angle: f32) -> MetallicRoughness {
        let basis = OrthonormalBasis::from_normal(normal());
        let (s, c) = angle.sin_cos();
        MetallicRoughness {
            anisotropy: Some(Anisotropy {
                strength,
                direction: (basis.tangent * c + basis.bitangent * s).into(),
            }),
            ..m
        }
    }

    /// A white sheen layer of `roughness` (white, so that the furnaces test it).
    fn white_sheen(roughness: f32) -> Option<Sheen> {
        Sheen::new(Spectrum::ONE, 1.0, roughness)
    }

    /// The materials the statistical tests cover: each roughness with metal, dielectric and
    /// their mixture, opaque and transmissive, over three indices (a metal has no index);
    /// the metal and a mixture also with the energy compensation; `KHR_materials_specular`'s
    /// strength and colours (beyond 1, up to F0 clamped to 1); sheen over the diffuse base,
    /// the metal and transmission; anisotropy of the metal (also compensated), the
    /// dielectric and transmission.
    fn materials(roughnesses: &[f32]) -> Vec<MetallicRoughness> {
        let mut all = Vec::new();
        for &roughness in roughnesses {
            all.push(anisotropic(material(roughness, 1.0, 0.0, 1.5), 0.8, 0.4));
            all.push(anisotropic(material(roughness, 0.0, 0.0, 1.5), 1.0, 1.2));
            all.push(anisotropic(material(roughness, 0.0, 1.0, 1.5), 0.6, -0.7));
            all.push(MetallicRoughness {
                energy_compensation: true,
                ..anisotropic(material(roughness, 1.0, 0.0, 1.5), 0.9, 2.0)
            });
        }
        for &roughness in roughnesses {
            all.push(material(roughness, 1.0, 0.0, 1.5));
            for metallic in [0.0, 0.5] {
                for transmission in [0.0, 1.0] {
                    for ior in [1.33, 1.5, 2.4] {
                        all.push(material(roughness, metallic, transmission, ior));
                    }
                }
            }
            all.push(material(roughness, 0.0, 0.5, 1.5));
            // Index-matched: rough, a Dirac transmission beside the glossy reflection.
            all.push(material(roughness, 0.0, 1.0, 1.0));
            all.push(material(roughness, 0.3, 0.5, 1.0 + INDEX_MATCHED / 2.0));
        }
        for &roughness in roughnesses {
            for (metallic, transmission) in [(1.0, 0.0), (0.5, 0.5)] {
                all.push(MetallicRoughness {
                    energy_compensation: true,
                    ..material(roughness, metallic, transmission, 1.5)
                });
            }
        }
        for &roughness in roughnesses {
            for transmission in [0.0, 1.0] {
                all.push(MetallicRoughness {
                    specular: 0.6,
                    specular_color: Spectrum::new(50.0, 1.0, 0.2),
                    specular_color_max: 50.0,
                    ..material(roughness, 0.0, transmission, 1.5)
                });
            }
            all.push(MetallicRoughness {
                sheen: Sheen::new(Spectrum::new(0.9, 0.5, 0.2), 0.9, 0.5),
                ..material(roughness, 0.0, 0.0, 1.5)
            });
            all.push(MetallicRoughness {
                sheen: white_sheen(0.0),
                ..material(roughness, 1.0, 0.0, 1.5)
            });
            all.push(MetallicRoughness {
                sheen: white_sheen(1.0),
                specular: 0.8,
                specular_color: Spectrum::new(2.0, 1.0, 0.5),
                specular_color_max: 2.0,
                ..material(roughness, 0.0, 1.0, 1.33)
            });
            all.push(MetallicRoughness {
                sheen: white_sheen(0.2),
                energy_compensation: true,
                ..material(roughness, 0.5, 0.5, 1.5)
            });
            // Thin films, RGB and spectral, over the opaque and transmissive dielectric,
            // the metal and a specular colour.
            all.push(MetallicRoughness {
                film: Some(film(1.0, 1.3, 400.0, false)),
                ..material(roughness, 0.0, 0.0, 1.5)
            });
            all.push(MetallicRoughness {
                film: Some(film(0.7, 2.0, 250.0, true)),
                ..material(roughness, 0.0, 1.0, 1.5)
            });
            all.push(MetallicRoughness {
                film: Some(film(1.0, 1.8, 300.0, true)),
                ..material(roughness, 1.0, 0.0, 1.5)
            });
            all.push(MetallicRoughness {
                film: Some(film(1.0, 2.5, 150.0, false)),
                specular: 0.8,
                specular_color: Spectrum::new(2.0, 1.0, 0.5),
                specular_color_max: 2.0,
                ..material(roughness, 0.3, 0.5, 1.33)
            });
        }
        all
    }

    /// A thin film; `spectral`: at four wavelengths across the visible range.
    fn film(factor: f32, ior: f32, thickness: f32, spectral: bool) -> ThinFilm {
        ThinFilm {
            factor,
            ior,
            thickness,
            wavelengths: spectral.then_some([430.0, 505.0, 580.0, 655.0]),
        }
    }

    /// Incident angles: normal, oblique, grazing, and the same from below.
    const ANGLES: [f32; 6] = [3.0, 45.0, 85.0, 177.0, 120.0, 95.0];

    /// Histogram cells over the sphere of directions: θ (to `normal()`) and φ uniform.
    const N_THETA: usize = 36;
    const N_PHI: usize = 36;

    fn cell(w: Vec3A) -> usize {
        let basis = OrthonormalBasis::from_normal(normal());
        let (x, y, z) = (
            w.dot(basis.tangent),
            w.dot(basis.bitangent),
            w.dot(basis.normal),
        );
        let theta = z.clamp(-1.0, 1.0).acos();
        let i = ((theta / std::f32::consts::PI * N_THETA as f32) as usize).min(N_THETA - 1);
        let phi = y.atan2(x).rem_euclid(2.0 * std::f32::consts::PI);
        let j = ((phi / (2.0 * std::f32::consts::PI) * N_PHI as f32) as usize).min(N_PHI - 1);
        i * N_PHI + j
    }

    /// The probability of each cell: `pdf` integrated over it (adaptively: transmission's
    /// density has ridges a fixed grid misses by a few percent).
    fn cell_probabilities(pdf: impl Fn(Vec3A) -> f32) -> Vec<f64> {
        let basis = OrthonormalBasis::from_normal(normal());
        sphere_cell_probabilities(N_THETA, N_PHI, |theta, phi| {
            let (s, c) = theta.sin_cos();
            let local = Vec3A::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
            pdf(basis.to_world(local)) as f64
        })
    }

    /// χ² statistic and threshold of `sample`'s directions (200 000 draws) from `wo` against
    /// the cells' probabilities under `expected`'s pdf.
    fn chi_square_of(
        m: &MetallicRoughness,
        expected: &MetallicRoughness,
        wo: Vec3A,
        rng: &mut Rng,
    ) -> (f64, f64, String) {
        const DRAWS: usize = 200_000;
        let n = normal();
        let mut counts = vec![0u64; N_THETA * N_PHI];
        for _ in 0..DRAWS {
            let u = rng.uniform2();
            let u_lobe = rng.uniform();
            if let Some(s) = m.sample(n, wo, u, u_lobe, TransportMode::Radiance)
                && !s.specular
            {
                counts[cell(s.wi)] += 1;
            }
        }
        let p = cell_probabilities(|wi| expected.pdf(n, wo, wi));
        let (stat, df) = pooled_statistic(&counts, DRAWS as u64, &p);
        let mut worst: Vec<_> = (0..p.len())
            .map(|k| {
                let e = p[k] * DRAWS as f64;
                ((counts[k] as f64 - e).powi(2) / e.max(1.0), k, counts[k], e)
            })
            .collect();
        worst.sort_by(|a, b| b.0.total_cmp(&a.0));
        worst.truncate(4);
        (stat, quantile(df, Z_1E6), format!("{worst:?}"))
    }

    /// `sample`'s directions follow `pdf` (the rest of the draws, `None` or an index-matched
    /// interface's Dirac transmission, being the mass `pdf` leaves out) for every rough material and incident angle.
    #[test]
    fn sampled_directions_follow_pdf() {
        let mut rng = Rng::new(18, 1);
        for m in materials(&[0.2, 0.5, 1.0]) {
            for theta in ANGLES {
                let (stat, threshold, worst) = chi_square_of(&m, &m, direction(theta), &mut rng);
                assert!(
                    stat < threshold,
                    "{m:?} θ {theta}: χ² {stat} ≥ {threshold}, {worst}"
                );
            }
        }
    }

    /// The χ² test rejects a density that is slightly off: the pdf of a 10% rougher
    /// material, and of a 3% lower index for refraction.
    #[test]
    fn chi_square_rejects_a_slightly_wrong_pdf() {
        let mut rng = Rng::new(18, 2);
        for m in [material(0.3, 1.0, 0.0, 1.5), material(0.5, 0.0, 0.0, 1.5)] {
            for theta in [30.0, 70.0] {
                let rougher = MetallicRoughness {
                    roughness: m.roughness * 1.1,
                    ..m
                };
                let (stat, threshold, _) = chi_square_of(&m, &rougher, direction(theta), &mut rng);
                assert!(stat > threshold, "{m:?} θ {theta}: χ² {stat} < {threshold}");
            }
        }
        let glass = material(0.3, 0.0, 1.0, 1.5);
        let lower = MetallicRoughness {
            ior: 1.455,
            ..glass
        };
        for theta in [30.0, 150.0] {
            let (stat, threshold, _) = chi_square_of(&glass, &lower, direction(theta), &mut rng);
            assert!(stat > threshold, "θ {theta}: χ² {stat} < {threshold}");
        }
    }

    /// Equal within `relative`, or both below 1e-6 (the far tails of a sharp lobe, where
    /// f32 half vectors lose their relative precision).
    fn close(a: Spectrum, b: Spectrum, relative: f32) -> bool {
        let scale = a.max_component().max(b.max_component());
        (a - b).abs().max_component() <= relative * scale || scale < 1e-6
    }

    /// Every sample's weight is eval·|cos|/pdf with pdf = `pdf`, `scatter` gives it back, and
    /// a Dirac sample goes where `specular_direction` says.
    #[test]
    fn sample_eval_pdf_and_scatter_agree() {
        let n = normal();
        let mut rng = Rng::new(18, 3);
        for m in materials(&[0.0, 0.01, 0.05, 0.2, 1.0]) {
            for theta in ANGLES {
                let wo = direction(theta);
                // α = 1e-4 (roughness 0.01) at grazing angles: D's slope amplifies the
                // rounding of the half vector to up to a few percent.
                let tolerance = match m.roughness {
                    r if r < 0.03 => 5e-2,
                    r if r < 0.1 => 1e-2,
                    _ => 2e-3,
                };
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    for _ in 0..500 {
                        let Some(s) = m.sample(n, wo, rng.uniform2(), rng.uniform(), mode) else {
                            continue;
                        };
                        let context = format!("{m:?} θ {theta} {mode:?} {s:?}");
                        // `scatter` takes a roughness-0 diffuse sample this close to the
                        // mirror direction for the mirror's.
                        let mirror = reflect(wo, n);
                        if m.roughness == 0.0
                            && !s.specular
                            && s.wi.dot(mirror) > 1.0 - MIRROR_TOLERANCE
                        {
                            continue;
                        }
                        assert!(s.weight.is_finite() && s.pdf > 0.0, "{context}");
                        assert!((s.wi.length() - 1.0).abs() < 1e-4, "{context}");
                        // Within 1e-3 of the tangent plane the cosine `scatter` recomputes
                        // from the world direction keeps only a few digits (cosine-sampled
                        // lobes reach there).
                        if s.wi.dot(n).abs() < 1e-3 {
                            continue;
                        }
                        let again = m.scatter(n, wo, s.wi, mode).expect(&context);
                        assert_eq!(again.specular, s.specular, "{context}");
                        let pdf_error = (again.pdf - s.pdf).abs();
                        assert!(pdf_error <= tolerance * s.pdf, "{context} {again:?}");
                        assert!(
                            close(again.weight, s.weight, tolerance),
                            "{context} {again:?}"
                        );
                        if s.specular {
                            let lobe = SpecularLobe::of(n, wo, s.wi);
                            assert_eq!(m.specular_direction(n, wo, lobe), Some(s.wi), "{context}");
                            continue;
                        }
                        let pdf = m.pdf(n, wo, s.wi);
                        assert!(
                            (pdf - s.pdf).abs() <= tolerance * pdf,
                            "{context} pdf {pdf}"
                        );
                        let expected = m.eval(n, wo, s.wi, mode) * (s.wi.dot(n).abs() / pdf);
                        assert!(close(expected, s.weight, tolerance), "{context} {expected}");
                    }
                }
            }
        }
    }

    /// Reflection is reciprocal, and transmission's importance mode is radiance's adjoint:
    /// f_importance(wo, wi) = f_radiance(wi, wo); both modes agree on reflection. To 2e-4
    /// relative (f32 rounding leaves at most 2.2e-5 at this seed, and four others pass): a
    /// factor read at a different cosine in one mode (an albedo table, a Fresnel term) or
    /// an η² off would show.
    #[test]
    fn reflection_is_reciprocal_and_transmission_adjoint() {
        let n = normal();
        let mut rng = Rng::new(18, 4);
        let random_direction = |rng: &mut Rng| {
            let [a, b] = rng.uniform2();
            let z = 2.0 * a - 1.0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * std::f32::consts::PI * b;
            Vec3A::new(r * phi.cos(), r * phi.sin(), z)
        };
        for m in materials(&[0.05, 0.3, 1.0]) {
            for _ in 0..2000 {
                let (wo, wi) = (random_direction(&mut rng), random_direction(&mut rng));
                let forward = m.eval(n, wo, wi, TransportMode::Radiance);
                let adjoint = m.eval(n, wi, wo, TransportMode::Importance);
                assert!(
                    close(forward, adjoint, 2e-4),
                    "{m:?} {wo} {wi}: {forward} {adjoint}"
                );
                if wo.dot(n) * wi.dot(n) > 0.0 {
                    let reversed = m.eval(n, wi, wo, TransportMode::Radiance);
                    assert!(close(forward, reversed, 2e-4), "{m:?} {wo} {wi}");
                }
            }
        }
    }

    /// The albedo ∫ f |cos| dωi (importance mode: the scattered share of the incident
    /// flux), estimated by sampling, the directions' `u` stratified on a square grid of
    /// about `draws` cells (a low sheen roughness's peak at grazing angles makes plain
    /// sampling noisy).
    fn albedo(m: &MetallicRoughness, wo: Vec3A, draws: usize, rng: &mut Rng) -> Spectrum {
        let n = normal();
        let k = (draws as f64).sqrt() as usize;
        let mut sum = Spectrum::ZERO;
        for i in 0..k {
            for j in 0..k {
                let [a, b] = rng.uniform2();
                let u = [(i as f32 + a) / k as f32, (j as f32 + b) / k as f32];
                let u_lobe = rng.uniform();
                if let Some(s) = m.sample(n, wo, u, u_lobe, TransportMode::Importance) {
                    sum += s.weight;
                }
            }
        }
        sum * (1.0 / (k * k) as f32)
    }

    /// The transmitted share of the flux (importance mode) through a rough interface of index
    /// `ior`, by stratified sampling of its transmission lobe alone.
    fn transmitted_albedo(m: &MetallicRoughness, wo: Vec3A, draws: usize) -> f32 {
        let n = normal();
        let k = (draws as f64).sqrt() as usize;
        let mut rng = Rng::new(18, 9);
        let mut sum = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let [a, b] = rng.uniform2();
                let u = [(i as f32 + a) / k as f32, (j as f32 + b) / k as f32];
                // `u_lobe` near 1 picks transmission, the last lobe of a transmissive
                // dielectric: the weight is f·|cos| over its probability times the
                // direction's density.
                if let Some(s) = m.sample(n, wo, u, 0.999_999, TransportMode::Importance)
                    && s.wi.dot(n) * wo.dot(n) < 0.0
                {
                    sum += (s.weight.max_component() * m.lobe_choice_transmission(n, wo)) as f64;
                }
            }
        }
        (sum / (k * k) as f64) as f32
    }

    /// An index-matched rough interface transmits along −wo, a Dirac lobe, with the
    /// weight the microfacet refraction tends to as the index goes to 1: at index 1.002 the
    /// sampled transmission's share is within 0.5% of it (face-on, oblique and from below,
    /// roughness 0.5 and 1).
    #[test]
    fn index_matched_rough_transmission_is_the_limit_of_refraction() {
        for roughness in [0.5, 1.0] {
            let matched = MetallicRoughness {
                base_color: Spectrum::ONE,
                ..material(roughness, 0.0, 1.0, 1.0)
            };
            assert!(matched.lobes().is_mixed());
            for theta in [3.0, 45.0, 70.0, 177.0, 130.0] {
                let wo = direction(theta);
                let n = normal();
                let straight = (0..64)
                    .filter_map(|k| {
                        let u = [(k as f32 + 0.5) / 64.0, 0.37];
                        matched.sample(n, wo, u, 0.999_999, TransportMode::Importance)
                    })
                    .find(|s| s.specular)
                    .expect("the Dirac transmission");
                assert_eq!(straight.wi, -wo);
                assert_eq!(
                    matched.specular_direction(n, wo, SpecularLobe::Refraction),
                    Some(-wo)
                );
                let share = straight.weight.max_component() * straight.pdf;
                // Beyond INDEX_MATCHED, so refracted through the microfacets: the share
                // converges linearly in η − 1 (0.0124, 0.0069, 0.0037 and 0.0016 above the
                // limit at 1.02, 1.01, 1.005 and 1.002, roughness 0.5, θ 70°).
                let near = MetallicRoughness {
                    ior: 1.002,
                    ..matched
                };
                let limit = transmitted_albedo(&near, wo, 400_000);
                assert!(
                    (share - limit).abs() <= 5e-3 * limit,
                    "roughness {roughness} θ {theta}: {share} at index 1, {limit} at 1.002"
                );
                // Nothing of it has a density, and the glossy reflection is still there.
                assert_eq!(matched.pdf(n, wo, -wo), 0.0);
                assert!(matched.eval(n, wo, -wo, TransportMode::Radiance).is_black());
            }
        }
    }

    /// No material, white or tinted, scatters more than it receives.
    #[test]
    fn albedo_is_at_most_one() {
        let mut rng = Rng::new(18, 5);
        let mut all = materials(&[0.0, 0.05, 0.2, 0.5, 1.0]);
        let white: Vec<_> = all
            .iter()
            .map(|m| MetallicRoughness {
                base_color: Spectrum::ONE,
                ..*m
            })
            .collect();
        all.extend(white);
        // The compensation of an anisotropic metal is tested on its own below.
        for m in all
            .into_iter()
            .filter(|m| !(m.anisotropy.is_some() && m.energy_compensation))
        {
            // A sheen's peak at grazing angles needs more draws for the same noise, and so
            // do transmission, picked by its macro-normal Fresnel estimate while tilted
            // microfacets pass far more at grazing angles (weights up to 20: 40 000 draws
            // once gave 1.011 for a true 0.968 at 89.5°), and a stretched lobe (40 000
            // draws once gave 1.018 for a true 0.93).
            for theta in ANGLES.into_iter().chain([89.5]) {
                let grazing = (theta - 90.0f32).abs() < 10.0;
                let draws = if m.sheen.is_some() {
                    250_000
                } else if (m.transmission > 0.0 || m.anisotropy.is_some()) && grazing {
                    160_000
                } else {
                    40_000
                };
                let a = albedo(&m, direction(theta), draws, &mut rng);
                assert!(a.max_component() <= 1.01, "{m:?} θ {theta}: albedo {a}");
            }
        }
    }

    /// The glTF specification's directional albedo at normal incidence of a non-metal
    /// (its appendix B: diffuse c/π · (1 − F(v·h)) plus F(v·h) times GGX), integrated
    /// without the tables: the diffuse part over the polar angle of wi (at normal
    /// incidence v·h = cos(θi/2)), the coat's by the half-vector quadrature at 3000 × 360
    /// nodes.
    fn specification_face_on_albedo(color: f32, roughness: f32, f0: f32) -> f64 {
        let schlick = |cos: f64| f0 as f64 + (1.0 - f0 as f64) * (1.0 - cos).powi(5);
        let n = 20_000;
        let diffuse: f64 = (0..n)
            .map(|k| {
                let theta = (k as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                (1.0 - schlick((theta / 2.0).cos())) * theta.cos() * theta.sin()
            })
            .sum::<f64>()
            * 2.0
            * std::f64::consts::FRAC_PI_2
            / n as f64;
        let coat = if roughness == 0.0 {
            f0 as f64
        } else {
            let [e, e_s] = single_scattering_albedos(roughness * roughness, 1.0, 3000, 360);
            f0 as f64 * e + (1.0 - f0 as f64) * e_s
        };
        color as f64 * diffuse + coat
    }

    /// Face-on, a non-metal reflects what the specification's model does, within 0.5%, at
    /// every roughness: the albedo-scaled base loses nothing the specification keeps
    /// (the product (1 − F(μo)) (1 − F(μi)) it replaced was 8.5% dark at roughness 1).
    /// The specification's directional albedo of a non-metal (base colour `color`, index
    /// giving `f0`) at roughness 1 for light arriving at polar angle `theta_deg`: its f,
    /// c/π (1 − F(v·h)) + F(v·h) D G2 / (4 μo μi), integrated over wi by the midpoint rule
    /// in μi and φi (1000 × 2000 nodes; at roughness 1 every part of it is smooth).
    fn specification_albedo_at_roughness_one(color: f64, f0: f64, theta_deg: f64) -> f64 {
        use std::f64::consts::PI;
        let (sin_o, mu_o) = theta_deg.to_radians().sin_cos();
        let lambda = |mu: f64| ((1.0 + (1.0 - mu * mu) / (mu * mu)).sqrt() - 1.0) / 2.0;
        let (n_mu, n_phi) = (1000, 2000);
        let mut sum = 0.0;
        for i in 0..n_mu {
            let mu_i = (i as f64 + 0.5) / n_mu as f64;
            let sin_i = (1.0 - mu_i * mu_i).sqrt();
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) / n_phi as f64 * 2.0 * PI;
                let h = [sin_o + sin_i * phi.cos(), sin_i * phi.sin(), mu_o + mu_i];
                let length = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
                let cos_vh = (sin_o * h[0] + mu_o * h[2]) / length;
                let fresnel = f0 + (1.0 - f0) * (1.0 - cos_vh).powi(5);
                // GGX with α = 1: D = 1/π.
                let d = 1.0 / PI;
                let g2 = 1.0 / (1.0 + lambda(mu_o) + lambda(mu_i));
                let f = color / PI * (1.0 - fresnel) + fresnel * d * g2 / (4.0 * mu_o * mu_i);
                sum += f * mu_i;
            }
        }
        sum * 2.0 * PI / (n_mu * n_phi) as f64
    }

    /// At roughness 1, where the specification's model does not create energy, a grey
    /// non-metal follows it at oblique incidence too, within 1% up to 76° (Cycles' albedo
    /// scaling is 5% below it at 64–76°).
    #[test]
    fn oblique_albedo_at_roughness_one_is_the_specifications() {
        let mut rng = Rng::new(45, 3);
        let m = MetallicRoughness {
            base_color: Spectrum::splat(0.8),
            ..material(1.0, 0.0, 0.0, 1.5)
        };
        for theta in [40.0f32, 64.0, 76.0] {
            let ours = albedo(&m, direction(theta), 200_000, &mut rng)[0] as f64;
            let specification =
                specification_albedo_at_roughness_one(0.8, m.f0() as f64, theta as f64);
            assert!(
                (ours / specification - 1.0).abs() < 0.01,
                "θ {theta}: {ours} vs the specification's {specification}"
            );
        }
    }

    #[test]
    fn face_on_albedo_is_the_specifications() {
        let mut rng = Rng::new(45, 1);
        for ior in [1.33f32, 1.5, 2.4] {
            for roughness in [0.0f32, 0.1, 0.25, 0.5, 0.75, 1.0] {
                let m = MetallicRoughness {
                    base_color: Spectrum::splat(0.8),
                    ..material(roughness, 0.0, 0.0, ior)
                };
                let ours = albedo(&m, normal(), 200_000, &mut rng)[0] as f64;
                let specification = specification_face_on_albedo(0.8, roughness, m.f0());
                assert!(
                    (ours / specification - 1.0).abs() < 0.005,
                    "ior {ior} roughness {roughness}: {ours} vs the specification's {specification}"
                );
            }
        }
    }

    /// A white non-metal reflects all the light but what its coat's single scattering
    /// loses, 1 − R(μo) (1 − E(μo)) (E the white GGX albedo, R the coat's reflectance, both
    /// by the fine quadrature), at every angle and roughness; never more than arrives.
    #[test]
    fn white_dielectric_loses_only_the_coats_multiple_scattering() {
        let mut rng = Rng::new(45, 2);
        for roughness in [0.0f32, 0.1, 0.3, 0.6, 1.0] {
            let m = MetallicRoughness {
                base_color: Spectrum::ONE,
                ..material(roughness, 0.0, 0.0, 1.5)
            };
            for theta in [0.0f32, 30.0, 60.0, 80.0, 89.0, 120.0, 170.0] {
                let wo = direction(theta);
                let mu = wo.dot(normal()).abs();
                let expected = if roughness == 0.0 {
                    1.0
                } else {
                    let [e, e_s] = single_scattering_albedos(roughness * roughness, mu, 1500, 180);
                    let r = m.f0() as f64 + (1.0 - m.f0() as f64) * e_s / e;
                    1.0 - r * (1.0 - e)
                };
                let a = albedo(&m, wo, 100_000, &mut rng)[0] as f64;
                assert!(
                    (a - expected).abs() < 0.01 && a <= 1.005,
                    "roughness {roughness} θ {theta}: albedo {a}, expected {expected}"
                );
            }
        }
    }

    /// A white metal's (F = 1) albedo by the compensation table's quadrature over half
    /// vectors (multiple_scattering.rs), with 3000 × 360 nodes: about 470 times the
    /// table's.
    fn white_metal_albedo_by_quadrature(alpha: f32, mu: f32) -> f64 {
        single_scattering_albedo(alpha, mu, 3000, 360)
    }

    /// A white metal's albedo is the microfacet integral (computed without the sampler);
    /// what it misses of 1 is the energy single scattering loses, which a
    /// multiple-scattering compensation would restore. Roughness 0 loses nothing.
    #[test]
    fn white_metal_albedo_is_the_single_scattering_integral() {
        let mut rng = Rng::new(18, 6);
        let n = normal();
        let basis = OrthonormalBasis::from_normal(n);
        for roughness in [0.0f32, 0.25, 0.5, 1.0] {
            let m = MetallicRoughness {
                base_color: Spectrum::ONE,
                ..material(roughness, 1.0, 0.0, 1.5)
            };
            for theta in [0.0f32, 45.0, 75.0] {
                let wo = direction(theta);
                let sampled = albedo(&m, wo, 400_000, &mut rng)[0] as f64;
                let local = Vec3A::new(wo.dot(basis.tangent), wo.dot(basis.bitangent), wo.dot(n));
                let integral = if roughness > 0.0 {
                    white_metal_albedo_by_quadrature(roughness * roughness, local.z)
                } else {
                    1.0
                };
                println!(
                    "white metal, roughness {roughness}, θo {theta}°: albedo {sampled:.4} \
                     (quadrature {integral:.4}), energy loss {:.4}",
                    1.0 - integral
                );
                assert!(
                    (sampled - integral).abs() < 4e-3,
                    "roughness {roughness} θ {theta}: sampled {sampled}, integral {integral}"
                );
            }
        }
    }

    /// The compensation's table of the white metal's single-scattering albedo E, interpolated
    /// between its nodes, agrees with its quadrature at 470 times the nodes; the test above
    /// checks that quadrature against the sampler, and the furnace below checks E through
    /// the sampler independently of both.
    #[test]
    fn compensation_table_is_the_single_scattering_albedo() {
        for roughness in [0.15f32, 0.25, 0.3, 0.5, 0.77, 1.0] {
            let compensation = EnergyCompensation::new(roughness).unwrap();
            for mu in [0.05f32, 0.2, 0.5, 0.9, 1.0] {
                let integral = white_metal_albedo_by_quadrature(roughness * roughness, mu);
                let tabulated = compensation.albedo(mu) as f64;
                assert!(
                    (tabulated - integral).abs() < 3e-3,
                    "roughness {roughness} μ {mu}: table {tabulated}, quadrature {integral}"
                );
            }
        }
    }

    /// The furnace with the compensation: a white metal reflects all the light at every
    /// roughness and angle (by sampling: the compensation lobe's sampling and density
    /// included), where single scattering alone reflects 31% at roughness 1 (normal
    /// incidence); a coloured metal reflects more than without it but no more than its
    /// colour's mean Fresnel series allows (at most 1). The printout is what the
    /// compensation changes.
    #[test]
    fn compensated_white_metal_reflects_everything() {
        let mut rng = Rng::new(18, 7);
        for roughness in [0.1f32, 0.25, 0.5, 0.75, 1.0] {
            for theta in [0.0f32, 45.0, 75.0, 88.0] {
                let wo = direction(theta);
                let white = material(roughness, 1.0, 0.0, 1.5);
                let white = MetallicRoughness {
                    base_color: Spectrum::ONE,
                    ..white
                };
                let compensated = MetallicRoughness {
                    energy_compensation: true,
                    ..white
                };
                let single = albedo(&white, wo, 100_000, &mut rng)[0];
                let total = albedo(&compensated, wo, 100_000, &mut rng)[0];
                let gold = MetallicRoughness {
                    base_color: Spectrum::new(1.0, 0.78, 0.34),
                    ..compensated
                };
                let gold_single = albedo(
                    &MetallicRoughness {
                        energy_compensation: false,
                        ..gold
                    },
                    wo,
                    100_000,
                    &mut rng,
                );
                let gold_total = albedo(&gold, wo, 100_000, &mut rng);
                println!(
                    "roughness {roughness}, θo {theta}°: white {single:.4} → {total:.4}, \
                     gold {gold_single} → {gold_total}"
                );
                assert!(
                    (total - 1.0).abs() < 0.01,
                    "roughness {roughness} θ {theta}: compensated white albedo {total} (single {single})"
                );
                for c in 0..3 {
                    assert!(gold_total[c] >= gold_single[c] - 0.005 && gold_total[c] <= 1.005);
                }
            }
        }
    }

    /// Roughness 0 is the mirror and the smooth dielectric: the same directions, weights
    /// and probabilities up to the Fresnel models (Schlick's here, the exact one there).
    #[test]
    fn roughness_zero_is_mirror_and_smooth_dielectric() {
        let n = normal();
        for theta in [10.0f32, 50.0, 80.0, 130.0, 170.0] {
            let wo = direction(theta);
            let cos = wo.dot(n).abs();
            let metal = material(0.0, 1.0, 0.0, 1.5);
            assert_eq!(metal.lobes(), BsdfLobes::SPECULAR);
            let s = metal
                .sample(n, wo, [0.3, 0.7], 0.5, TransportMode::Radiance)
                .unwrap();
            assert!(s.specular && s.pdf == 1.0);
            assert!((s.wi - reflect(wo, n)).length() < 1e-6);
            assert!(close(
                s.weight,
                schlick_spectrum(metal.base_color, cos),
                1e-5
            ));

            for ior in [1.33f32, 1.5, 2.4] {
                let glass = MetallicRoughness {
                    base_color: Spectrum::ONE,
                    ..material(0.0, 0.0, 1.0, ior)
                };
                assert_eq!(glass.lobes(), BsdfLobes::SPECULAR);
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    for u_lobe in [0.0001, 0.9999] {
                        let ours = glass.sample(n, wo, [0.5; 2], u_lobe, mode).unwrap();
                        let theirs =
                            dielectric::sample(ior, Spectrum::ONE, n, wo, u_lobe, mode).unwrap();
                        let context = format!("θ {theta} ior {ior} {mode:?} {u_lobe}");
                        assert!(ours.specular && theirs.specular, "{context}");
                        // Same lobe (or, under total internal reflection, both reflect).
                        let lobe = SpecularLobe::of(n, wo, ours.wi);
                        if lobe != SpecularLobe::of(n, wo, theirs.wi) {
                            continue;
                        }
                        assert!((ours.wi - theirs.wi).length() < 1e-5, "{context}");
                        // Weight × probability is the lobe's share: F or (1 − F) × η².
                        let (f_ours, f_exact) =
                            (ours.weight[0] * ours.pdf, theirs.weight[0] * theirs.pdf);
                        let (share_ours, share_exact) = match lobe {
                            SpecularLobe::Reflection | SpecularLobe::BaseReflection => {
                                (f_ours, f_exact)
                            }
                            SpecularLobe::Refraction => {
                                // Divide out the common η² scale: the weight of refraction
                                // at probability (1 − F) is the scale itself there.
                                let scale = theirs.weight[0];
                                (f_ours / scale, f_exact / scale)
                            }
                        };
                        assert!(
                            (share_ours - share_exact).abs() < 0.08,
                            "{context}: {share_ours} vs {share_exact}"
                        );
                    }
                }
            }

            // The coated diffuse: a Dirac coat over the base; its reflection is the
            // coat's F, the diffuse base has a density.
            let plastic = material(0.0, 0.0, 0.0, 1.5);
            assert_eq!(plastic.lobes(), BsdfLobes::SPECULAR | BsdfLobes::DIFFUSE);
            let s = plastic
                .sample(n, wo, [0.3, 0.7], 0.0, TransportMode::Radiance)
                .unwrap();
            assert!(s.specular && (s.wi - reflect(wo, n)).length() < 1e-6);
            // Its opaque coat is seen from the outside on either side.
            let f = dielectric::fresnel_dielectric(cos, 1.0, 1.5);
            assert!((s.weight[0] * s.pdf - f).abs() < 0.04, "θ {theta}");
            assert!(plastic.pdf(n, wo, reflect(wo, n)) > 0.0);
        }
    }

    /// Tiny nonzero roughness stays finite (α is clamped), and lobes report GLOSSY.
    #[test]
    fn tiny_roughness_stays_finite() {
        let n = normal();
        let mut rng = Rng::new(18, 7);
        for roughness in [1e-6f32, 1e-3, 0.01] {
            for m in [
                material(roughness, 1.0, 0.0, 1.5),
                material(roughness, 0.0, 1.0, 1.5),
            ] {
                assert!(m.lobes().contains(BsdfLobes::GLOSSY));
                for theta in ANGLES {
                    let wo = direction(theta);
                    for _ in 0..200 {
                        let s = m.sample(
                            n,
                            wo,
                            rng.uniform2(),
                            rng.uniform(),
                            TransportMode::Radiance,
                        );
                        if let Some(s) = s {
                            assert!(
                                s.weight.is_finite() && s.pdf.is_finite() && s.pdf > 0.0,
                                "{m:?} {s:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// With specular strength 0 the dielectric is its diffuse base alone: f = c/π for
    /// every pair of directions on one side, at every roughness and specular colour.
    #[test]
    fn specular_zero_leaves_the_diffuse_base_alone() {
        let n = normal();
        for roughness in [0.0f32, 0.3, 1.0] {
            for color in [Spectrum::ONE, Spectrum::new(50.0, 1.0, 0.0)] {
                let m = MetallicRoughness {
                    base_color: Spectrum::splat(0.8),
                    specular: 0.0,
                    specular_color: color,
                    specular_color_max: color.max_component(),
                    ..material(roughness, 0.0, 0.0, 1.5)
                };
                for (a, b) in [(0.0f32, 0.0f32), (10.0, 60.0), (45.0, 89.0), (80.0, 5.0)] {
                    let f = m.eval(n, direction(a), direction(b), TransportMode::Radiance);
                    let expected = 0.8 * FRAC_1_PI;
                    assert!(
                        (f - Spectrum::splat(expected)).abs().max_component() < 1e-6,
                        "roughness {roughness} {a}° {b}°: {f} vs {expected}"
                    );
                }
                let mut rng = Rng::new(45, 10);
                let a = albedo(&m, normal(), 100_000, &mut rng);
                assert!((a[0] - 0.8).abs() < 2e-3, "roughness {roughness}: {a}");
            }
        }
    }

    /// A specular colour large enough to clamp F0 at 1 (and any between) never reflects
    /// more than arrives, white base or not, opaque or transmissive, at any angle; with
    /// F0 clamped at 1 and strength 1 the diffuse base is gone.
    #[test]
    fn specular_colour_never_creates_energy() {
        let mut rng = Rng::new(45, 11);
        for roughness in [0.0f32, 0.2, 0.6, 1.0] {
            for scale in [1.0f32, 5.0, 25.0, 100.0] {
                for transmission in [0.0, 1.0] {
                    let m = MetallicRoughness {
                        base_color: Spectrum::ONE,
                        specular_color: Spectrum::new(scale, scale * 0.5, 1.0),
                        specular_color_max: scale.max(1.0),
                        ..material(roughness, 0.0, transmission, 1.5)
                    };
                    for theta in [0.0f32, 40.0, 75.0, 89.0, 150.0] {
                        let a = albedo(&m, direction(theta), 30_000, &mut rng);
                        assert!(
                            a.max_component() <= 1.01,
                            "roughness {roughness} colour ×{scale} transmission {transmission} θ {theta}: {a}"
                        );
                    }
                }
            }
            let mirror_like = MetallicRoughness {
                specular_color: Spectrum::splat(100.0),
                specular_color_max: 100.0,
                ..material(roughness, 0.0, 0.0, 1.5)
            };
            assert!(mirror_like.diffuse_f(0.5, 0.7).is_black());
        }
    }

    /// Sheen over a diffuse base, a metal, transmission and their mixtures, white
    /// everywhere: never more than arrives, at any angle, at any sheen roughness (the
    /// lowest is where the specification's lobe alone would reflect up to 2.9 times). The
    /// true albedos come within 1% of 1 at grazing angles (0.990 at 88° over a rough
    /// dielectric at the lowest sheen roughness, by 4 million stratified draws).
    /// A white dielectric under a thin film (the base is white, the worst case for the
    /// albedo scaling) reflects at most what it receives, at every angle, for films rarer
    /// and denser than the base, thin and thick, smooth and rough, RGB and spectral; and a
    /// film on a smooth surface reflects its own reflectance exactly. Albedos by the
    /// stratified estimator at 40 000 draws (its standard deviation about 0.2% here; the
    /// largest measured 1.0001).
    #[test]
    fn white_furnace_with_a_film_is_at_most_one() {
        let mut rng = Rng::new(45, 2);
        let mut largest = 0.0f32;
        for roughness in [0.0, 0.3, 1.0] {
            for (ior, thickness) in [(1.3, 400.0), (2.0, 250.0), (2.5, 120.0), (1.1, 900.0)] {
                for spectral in [false, true] {
                    let m = MetallicRoughness {
                        base_color: Spectrum::ONE,
                        film: Some(film(1.0, ior, thickness, spectral)),
                        ..material(roughness, 0.0, 0.0, 1.5)
                    };
                    for theta in [0.0, 45.0, 75.0, 89.5] {
                        let a = albedo(&m, direction(theta), 40_000, &mut rng);
                        largest = largest.max(a.max_component());
                        assert!(a.max_component() <= 1.006, "{m:?} θ {theta}: albedo {a}");
                    }
                }
            }
        }
        eprintln!("largest film albedo {largest}");
    }

    /// At roughness 0 with a black base the material is the film alone: the mirror's weight
    /// is the film's reflectance at the view's cosine, mixed with Schlick's by the factor.
    #[test]
    fn smooth_film_reflects_the_films_reflectance() {
        let f = film(0.6, 1.8, 330.0, true);
        let m = MetallicRoughness {
            base_color: Spectrum::ZERO,
            film: Some(f),
            ..material(0.0, 0.0, 0.0, 1.5)
        };
        for theta in [0.0f32, 40.0, 80.0] {
            let wo = direction(theta);
            let cos = theta.to_radians().cos();
            let s = m
                .scatter(normal(), wo, reflect(wo, normal()), TransportMode::Radiance)
                .unwrap();
            let plain = schlick(0.04, cos);
            let filmed = f.reflectance(Spectrum::splat(0.04), cos);
            let expected = Spectrum::splat(plain) + (filmed - Spectrum::splat(plain)) * 0.6;
            let got = s.weight * s.pdf;
            assert!(close(got, expected, 1e-3), "θ {theta}: {got} vs {expected}");
        }
    }

    #[test]
    fn white_furnace_with_sheen_is_at_most_one() {
        let mut rng = Rng::new(45, 12);
        for sheen_roughness in [0.0f32, 0.15, 0.4, 1.0] {
            for roughness in [0.0f32, 0.3, 1.0] {
                for (metallic, transmission) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.3, 0.3)] {
                    let m = MetallicRoughness {
                        base_color: Spectrum::ONE,
                        sheen: white_sheen(sheen_roughness),
                        energy_compensation: true,
                        ..material(roughness, metallic, transmission, 1.5)
                    };
                    for theta in [0.0f32, 50.0, 80.0, 88.0, 89.7, 135.0, 178.0] {
                        let a = albedo(&m, direction(theta), 250_000, &mut rng);
                        assert!(
                            a.max_component() <= 1.01,
                            "sheen roughness {sheen_roughness} {m:?} θ {theta}: {a}"
                        );
                    }
                }
            }
        }
    }

    /// The specification's sheen lobe, from its formulas (Charlie D, its fitted Λ),
    /// integrated over wi in f64 by the midpoint rule (2000 polar × 1000 azimuth nodes
    /// over the half plane): the white sheen layer's directional albedo.
    fn specification_sheen_albedo(roughness: f64, theta_deg: f64) -> f64 {
        use std::f64::consts::PI;
        let alpha = roughness * roughness;
        let fit = |x: f64| {
            let t = (1.0 - alpha) * (1.0 - alpha);
            let mix = |a: f64, b: f64| a * (1.0 - t) + b * t;
            mix(21.5473, 25.3245) / (1.0 + mix(3.82987, 3.32435) * x.powf(mix(0.19823, 0.16801)))
                + mix(-1.97760, -1.27393) * x
                + mix(-4.32054, -4.85967)
        };
        let lambda = |mu: f64| {
            if mu < 0.5 {
                fit(mu).exp()
            } else {
                (2.0 * fit(0.5) - fit(1.0 - mu)).exp()
            }
        };
        let (sin_o, mu_o) = theta_deg.to_radians().sin_cos();
        let (n_theta, n_phi) = (2000, 1000);
        let mut sum = 0.0;
        for i in 0..n_theta {
            let theta = (i as f64 + 0.5) / n_theta as f64 * PI / 2.0;
            let (sin_i, mu_i) = theta.sin_cos();
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) / n_phi as f64 * PI;
                let h = [sin_o + sin_i * phi.cos(), sin_i * phi.sin(), mu_o + mu_i];
                let cos_h = h[2] / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
                let d = (2.0 + 1.0 / alpha) * (1.0 - cos_h * cos_h).powf(0.5 / alpha) / (2.0 * PI);
                let f = d / ((1.0 + lambda(mu_o) + lambda(mu_i)) * 4.0 * mu_o * mu_i);
                sum += f * mu_i * sin_i;
            }
        }
        sum * (PI / 2.0 / n_theta as f64) * (2.0 * PI / n_phi as f64)
    }

    /// The sheen layer alone (over a black base without specular reflection), sampled by
    /// `sample` on a stratified grid, reflects the specification's directional albedo
    /// within 0.5%, at roughnesses where that conserves energy (below 0.25 the lobe is
    /// normalized; `sheen`'s tests cover it).
    #[test]
    fn sheen_albedo_is_the_specifications() {
        let n = normal();
        let mut rng = Rng::new(45, 13);
        for sheen_roughness in [0.3f32, 0.6, 1.0] {
            let m = MetallicRoughness {
                base_color: Spectrum::ZERO,
                specular: 0.0,
                sheen: white_sheen(sheen_roughness),
                ..material(0.5, 0.0, 0.0, 1.5)
            };
            for theta in [0.0f32, 30.0, 60.0, 80.0] {
                let wo = direction(theta);
                let k = 500;
                let mut sum = 0.0f64;
                for i in 0..k {
                    for j in 0..k {
                        let [a, b] = rng.uniform2();
                        let u = [(i as f32 + a) / k as f32, (j as f32 + b) / k as f32];
                        if let Some(s) =
                            m.sample(n, wo, u, rng.uniform(), TransportMode::Importance)
                        {
                            sum += s.weight[0] as f64;
                        }
                    }
                }
                let ours = sum / (k * k) as f64;
                let specification =
                    specification_sheen_albedo(sheen_roughness as f64, theta as f64);
                println!(
                    "sheen roughness {sheen_roughness} θ {theta}: {ours:.5} vs {specification:.5}"
                );
                assert!(
                    (ours / specification - 1.0).abs() < 0.005,
                    "sheen roughness {sheen_roughness} θ {theta}: {ours} vs the specification's {specification}"
                );
            }
        }
    }

    /// Where the stretch vanishes (roughness 1: α_t = mix(1, 1, s²) = 1) an anisotropic
    /// material is the isotropic one: its frame about the normal changes only rounding.
    /// (Strength 0 is no anisotropy at all: the surface gives the model `None`.)
    #[test]
    fn anisotropy_without_stretch_is_the_isotropic_lobe() {
        let n = normal();
        let mut rng = Rng::new(18, 11);
        for (metallic, transmission) in [(1.0, 0.0), (0.0, 0.0), (0.0, 1.0)] {
            let isotropic = material(1.0, metallic, transmission, 1.5);
            let stretched = anisotropic(isotropic, 1.0, 0.9);
            assert_eq!(stretched.table_roughness(), 1.0);
            for _ in 0..2000 {
                let wo = direction(rng.uniform() * 180.0);
                let wi = direction(rng.uniform() * 180.0);
                let turn = rng.uniform() * std::f32::consts::TAU;
                let wi = glam::Quat::from_axis_angle(n.into(), turn) * glam::Vec3::from(wi);
                let wi = Vec3A::from(wi);
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    let (a, b) = (
                        isotropic.eval(n, wo, wi, mode),
                        stretched.eval(n, wo, wi, mode),
                    );
                    assert!(close(a, b, 1e-4), "{wo} {wi}: {a} {b}");
                }
                let (a, b) = (isotropic.pdf(n, wo, wi), stretched.pdf(n, wo, wi));
                assert!((a - b).abs() <= 1e-3 * a.max(b), "{wo} {wi}: pdf {a} {b}");
            }
        }
    }

    /// Turning the anisotropy's direction by 90° (tangent → bitangent) turns the lobe with
    /// it: f and pdf at (wo, wi) are the unturned material's at both directions turned back.
    #[test]
    fn quarter_turn_of_the_direction_turns_the_lobe() {
        let n = normal();
        let mut rng = Rng::new(18, 12);
        // R⁻¹ w for the turn R by +90° about n (R v = n (n·v) + n × v).
        let turn_back = |w: Vec3A| n * n.dot(w) - n.cross(w);
        for (roughness, metallic, transmission) in
            [(0.3, 1.0, 0.0), (0.0, 0.0, 0.0), (0.5, 0.0, 1.0)]
        {
            let m = anisotropic(material(roughness, metallic, transmission, 1.5), 0.9, 0.3);
            let direction_of = |m: &MetallicRoughness| Vec3A::from(m.anisotropy.unwrap().direction);
            let turned = MetallicRoughness {
                anisotropy: Some(Anisotropy {
                    strength: 0.9,
                    direction: n.cross(direction_of(&m)).into(),
                }),
                ..m
            };
            let mut differing = 0;
            for _ in 0..500 {
                let wo = direction(rng.uniform() * 180.0);
                let Some(s) = turned.sample(
                    n,
                    wo,
                    rng.uniform2(),
                    rng.uniform(),
                    TransportMode::Radiance,
                ) else {
                    continue;
                };
                let wi = s.wi;
                // α_b = 10⁻⁴ at roughness 0: f32 rounding of the turned directions moves
                // the half vector by a few percent of a peak 10⁻⁴ wide.
                let tolerance = if roughness == 0.0 { 5e-2 } else { 2e-3 };
                let f = turned.eval(n, wo, wi, TransportMode::Radiance);
                let expected = m.eval(n, turn_back(wo), turn_back(wi), TransportMode::Radiance);
                assert!(close(f, expected, tolerance), "{wo} {wi}: {f} {expected}");
                let (p, q) = (
                    turned.pdf(n, wo, wi),
                    m.pdf(n, turn_back(wo), turn_back(wi)),
                );
                assert!(
                    (p - q).abs() <= tolerance * p.max(q),
                    "{wo} {wi}: pdf {p} {q}"
                );
                // The unturned lobe is another one (the test can fail).
                let unturned = m.eval(n, wo, wi, TransportMode::Radiance);
                if !close(f, unturned, 0.1) {
                    differing += 1;
                }
            }
            // (Over a diffuse base the sampled directions are mostly the base's.)
            if metallic == 1.0 {
                assert!(differing > 250, "the turn changes {differing} of 500");
            }
        }
    }

    /// A white anisotropic metal's albedo is its microfacet integral by quadrature over
    /// the half vectors (no sampler). The compensation, read from the isotropic tables at
    /// `table_roughness`, restores most of the loss; at oblique angles it can overshoot by
    /// a few percent (the printout; it is an option glTF's model does not have).
    #[test]
    fn white_anisotropic_metal_albedo() {
        let mut rng = Rng::new(18, 13);
        let n = normal();
        for (roughness, strength) in [(0.2f32, 0.7f32), (0.5, 1.0), (0.35, 0.5)] {
            let m = anisotropic(
                MetallicRoughness {
                    base_color: Spectrum::ONE,
                    ..material(roughness, 1.0, 0.0, 1.5)
                },
                strength,
                0.6,
            );
            let distribution = m.distribution().unwrap();
            for theta in [0.0f32, 45.0, 75.0, 88.0] {
                let wo = direction(theta);
                let view = m.view(n, wo).unwrap();
                // ∫ D(h) G2 (wo·h) / μo dω_h over the half vectors that reflect above, by
                // the midpoint rule in (cos θh, φh) with cos θh's nodes dense near 1.
                let (n_theta, n_phi) = (2000, 720);
                let mut integral = 0.0f64;
                for i in 0..n_theta {
                    let t = (i as f64 + 0.5) / n_theta as f64;
                    let z = 1.0 - t * t;
                    let dz = 2.0 * t / n_theta as f64;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for j in 0..n_phi {
                        let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n_phi as f64;
                        let h =
                            Vec3A::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                        let cos_oh = view.wo.dot(h);
                        if cos_oh <= 0.0 {
                            continue;
                        }
                        let wi = reflect(view.wo, h);
                        if wi.z <= 0.0 {
                            continue;
                        }
                        let value =
                            distribution.d(h) * distribution.g2(view.wo, wi) * cos_oh / view.wo.z;
                        integral += value as f64 * dz * std::f64::consts::TAU / n_phi as f64;
                    }
                }
                let sampled = albedo(&m, wo, 200_000, &mut rng)[0] as f64;
                let compensated = albedo(
                    &MetallicRoughness {
                        energy_compensation: true,
                        ..m
                    },
                    wo,
                    200_000,
                    &mut rng,
                )[0] as f64;
                println!(
                    "anisotropic white metal, roughness {roughness} strength {strength}, θo \
                     {theta}°: albedo {sampled:.4} (quadrature {integral:.4}), compensated \
                     {compensated:.4}"
                );
                assert!(sampled <= 1.0 + 5e-3 && integral <= 1.0 + 1e-3);
                assert!(
                    (sampled - integral).abs() < 5e-3,
                    "roughness {roughness} θ {theta}: sampled {sampled}, integral {integral}"
                );
                assert!(
                    compensated <= 1.03 && compensated >= sampled,
                    "roughness {roughness} θ {theta}: compensated {compensated}"
                );
            }
        }
    }
}
