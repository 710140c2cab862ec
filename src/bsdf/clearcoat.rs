//! A clear coat over the metallic-roughness material (glTF's `KHR_materials_clearcoat`):
//! a white dielectric GGX reflection of index 1.5 (F0 = 0.04) with its own roughness and
//! its own shading normal, over the whole material beneath:
//!
//! f = c F(μv) D G2 / (4 μo μi) + (1 − c F(μv)) f_base,
//!
//! c the coat's factor, F Schlick's Fresnel at the cosine μv of the direction towards the
//! viewer (wo in radiance transport) to the coat's normal, as the specification's
//! `fresnel_coat` writes it. c F(μv) is the coat's reflectance with its multiple scattering
//! kept (its single scattering reflects c F(μv) E(μv), E the white GGX albedo), so the
//! base is scaled by what the coat does not reflect, as the dielectric's diffuse base is by
//! `CoatReflectance` (there R = E_F / E because that lobe's Fresnel is taken at each
//! microfacet; the specification's coat takes it at the normal, where R is F itself, so no
//! table is needed). A white base under it reflects 1 − c F(μv) (1 − E(μv)) ≤ 1 at every
//! angle, whatever the base is (diffuse, metal, transmission): the white furnace never
//! exceeds 1.
//!
//! Not reciprocal, as the specification's layering is not: the Fresnel factor depends on
//! the viewer's direction. A reciprocal form (1 − c R(μo)) (1 − c R(μi)) / (1 − c R_avg),
//! the dielectric's, conserves energy over a Lambertian base only (over a smooth white
//! metal it would reflect 5% more than arrives face-on), and without the normalization it
//! darkens the base by 8% face-on. Importance transport evaluates the adjoint (the viewer
//! is then wi), so light and camera subpaths estimate the same image.
//!
//! The coat's normal: from its own normal map, else the interpolated normal, never the
//! base's normal map. The BSDF's frame is the base's shading normal ns, and `Bsdf` turns
//! the model's f into Veach's f̃ = f |wℓ·ns| / |wℓ·ng| (wℓ the direction towards the light:
//! wi in radiance transport, wo in importance transport), so that integrators multiply by
//! the geometric cosine. The coat lobe is evaluated in its own frame and returned as
//! f_coat |wℓ·nc| / |wℓ·ns|: after `Bsdf`'s correction it is f_coat |wℓ·nc| / |wℓ·ng|,
//! Veach's construction for the coat's own shading normal nc. Directions below the coat
//! (for nc) do not reflect off it.
//!
//! At roughness 0 the coat is a Dirac lobe, the mirror about nc with reflectance c F(μo).

use super::microfacet::TrowbridgeReitz;
use super::scattering::{TransportMode, reflect};
use crate::sampling::OrthonormalBasis;
use glam::Vec3A;

/// Normal reflectance of the coat: an index of refraction of 1.5, as the specification
/// fixes it.
pub(crate) const COAT_F0: f32 = 0.04;

/// The coat's parameters at a surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Clearcoat {
    /// In [0, 1]; 0: no coat.
    pub factor: f32,
    /// Perceptual roughness in [0, 1]; α = roughness², 0 the Dirac mirror.
    pub roughness: f32,
    /// The coat's own shading normal (world space, unit), or `None` where it is the
    /// base's.
    pub normal: Option<Vec3A>,
}

impl Clearcoat {
    /// No coat. (`pub(crate)`: cbindgen exports `pub` associated constants.)
    pub(crate) const NONE: Clearcoat = Clearcoat {
        factor: 0.0,
        roughness: 0.0,
        normal: None,
    };

    /// Whether there is a coat to evaluate.
    #[inline(always)]
    pub fn is_present(&self) -> bool {
        self.factor > 0.0
    }

    /// Whether its lobe is a Dirac mirror.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.roughness <= 0.0
    }

    /// The coat as seen from `wo` on a surface whose (base) shading normal is `normal`;
    /// `None` when wo is in the coat's tangent plane.
    #[inline]
    pub fn view(&self, normal: Vec3A, wo: Vec3A) -> Option<CoatView> {
        let n = self.normal.unwrap_or(normal);
        let cos_o = wo.dot(n);
        if cos_o == 0.0 {
            return None;
        }
        let side_normal = if cos_o > 0.0 { n } else { -n };
        let basis = OrthonormalBasis::from_normal(side_normal);
        Some(CoatView {
            wo: Vec3A::new(wo.dot(basis.tangent), wo.dot(basis.bitangent), cos_o.abs()),
            wo_world: wo,
            basis,
            shading_normal: normal,
            own_normal: self.normal.is_some(),
            factor: self.factor,
            distribution: (self.roughness > 0.0)
                .then(|| TrowbridgeReitz::new(self.roughness * self.roughness)),
        })
    }
}

/// Schlick's Fresnel with the coat's F0.
#[inline]
fn fresnel(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    COAT_F0 + (1.0 - COAT_F0) * (m * m) * (m * m) * m
}

/// The coat seen from one `wo`: its frame (normal on wo's side) and lobe.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CoatView {
    basis: OrthonormalBasis,
    /// `wo` in the coat's frame: z > 0.
    wo: Vec3A,
    wo_world: Vec3A,
    /// The base's shading normal (the BSDF's frame).
    shading_normal: Vec3A,
    /// Whether the coat's normal differs from the base's.
    own_normal: bool,
    factor: f32,
    /// GGX, or `None` for the Dirac mirror.
    distribution: Option<TrowbridgeReitz>,
}

impl CoatView {
    #[inline]
    fn local(&self, w: Vec3A) -> Vec3A {
        Vec3A::new(
            w.dot(self.basis.tangent),
            w.dot(self.basis.bitangent),
            w.dot(self.basis.normal),
        )
    }

    /// Whether its lobe is a Dirac mirror.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.distribution.is_none()
    }

    /// Whether `wi` is on wo's side of the base's shading normal too: a reflection off a
    /// coat with its own normal that crosses the base's tangent plane would pass light
    /// through the surface, so it is not one.
    #[inline]
    pub fn stays_on_wo_side(&self, wi: Vec3A) -> bool {
        !self.own_normal
            || wi.dot(self.shading_normal) * self.wo_world.dot(self.shading_normal) > 0.0
    }

    /// The direction towards the viewer of a scattering from `wo` into `wi` in `mode`.
    #[inline]
    fn towards_viewer(&self, wi: Vec3A, mode: TransportMode) -> Vec3A {
        match mode {
            TransportMode::Radiance => self.wo_world,
            TransportMode::Importance => wi,
        }
    }

    /// c F(μv): what the coat reflects of the light the viewer in direction `viewer` sees.
    #[inline]
    fn reflectance(&self, viewer: Vec3A) -> f32 {
        self.factor * fresnel(viewer.dot(self.basis.normal).abs())
    }

    /// The factor of the base's f under the coat for scattering from `wo` into `wi`:
    /// 1 − c F(μv).
    #[inline]
    pub fn base_scale(&self, wi: Vec3A, mode: TransportMode) -> f32 {
        1.0 - self.reflectance(self.towards_viewer(wi, mode))
    }

    /// An estimate of the coat lobe's albedo at wo, for the lobe choice: c F(μo).
    #[inline]
    pub fn albedo_estimate(&self) -> f32 {
        self.factor * fresnel(self.wo.z)
    }

    /// |wℓ·nc| / |wℓ·ns|, wℓ the direction towards the light: what turns the coat lobe's f
    /// into the model's frame (see the module's documentation); 0 where wℓ is in the base's
    /// tangent plane.
    #[inline]
    fn frame_correction(&self, wi: Vec3A, mode: TransportMode) -> f32 {
        if !self.own_normal {
            return 1.0;
        }
        let towards_light = match mode {
            TransportMode::Radiance => wi,
            TransportMode::Importance => self.wo_world,
        };
        let base = towards_light.dot(self.shading_normal).abs();
        if base > 0.0 {
            towards_light.dot(self.basis.normal).abs() / base
        } else {
            0.0
        }
    }

    /// The coat lobe's f(wo, wi) in the model's frame (corrected for its own normal), 0 for
    /// the Dirac mirror and below the coat.
    #[inline]
    pub fn eval(&self, wi: Vec3A, mode: TransportMode) -> f32 {
        let Some(distribution) = self.distribution else {
            return 0.0;
        };
        let local = self.local(wi);
        if local.z <= 0.0 || !self.stays_on_wo_side(wi) {
            return 0.0;
        }
        let h = (self.wo + local).normalize();
        let microfacets =
            distribution.d(h) * distribution.g2(self.wo, local) / (4.0 * self.wo.z * local.z);
        self.reflectance(self.towards_viewer(wi, mode))
            * microfacets
            * self.frame_correction(wi, mode)
    }

    /// The solid-angle density with which `sample` generates `wi` (0 for the mirror).
    #[inline]
    pub fn pdf(&self, wi: Vec3A) -> f32 {
        let Some(distribution) = self.distribution else {
            return 0.0;
        };
        let local = self.local(wi);
        if local.z <= 0.0 || !self.stays_on_wo_side(wi) {
            return 0.0;
        }
        let h = (self.wo + local).normalize();
        let cos_oh = self.wo.dot(h);
        if cos_oh <= 0.0 {
            return 0.0;
        }
        distribution.visible_normal_pdf(self.wo, h) / (4.0 * cos_oh)
    }

    /// A direction reflected by the coat: through a visible GGX normal at `u`, or the
    /// mirror direction; `None` below the coat or behind the base's tangent plane.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> Option<Vec3A> {
        let Some(distribution) = self.distribution else {
            return Some(self.mirror()).filter(|&wi| self.stays_on_wo_side(wi));
        };
        let m = distribution.sample_visible_normal(self.wo, u);
        let local = reflect(self.wo, m);
        Some(self.basis.to_world(local)).filter(|&wi| local.z > 0.0 && self.stays_on_wo_side(wi))
    }

    /// The mirror direction of wo about the coat's normal.
    #[inline]
    pub fn mirror(&self) -> Vec3A {
        reflect(self.wo_world, self.basis.normal)
    }

    /// The smooth coat's reflectance into its mirror direction `wi` (a Dirac lobe's
    /// weight × probability), corrected for its normal: in importance transport `Bsdf`
    /// applies the base frame's |wo·ns| / |wi·ns|, which the coat's mirror replaces by 1.
    #[inline]
    pub fn mirror_reflectance(&self, wi: Vec3A, mode: TransportMode) -> f32 {
        let reflectance = self.factor * fresnel(self.wo.z);
        if !self.own_normal || mode == TransportMode::Radiance {
            return reflectance;
        }
        let (cos_i, cos_o) = (
            wi.dot(self.shading_normal).abs(),
            self.wo_world.dot(self.shading_normal).abs(),
        );
        if cos_o > 0.0 {
            reflectance * cos_i / cos_o
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::metallic_roughness::MetallicRoughness;
    use super::super::multiple_scattering::single_scattering_albedo;
    use super::super::scattering::{BsdfLobes, SpecularLobe};
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::chi_square::{
        Z_1E6, pooled_statistic, quantile, sphere_cell_probabilities,
    };
    use crate::spectrum::Spectrum;

    /// The base's shading normal, tilted so that no test relies on the world's frame.
    fn normal() -> Vec3A {
        Vec3A::new(0.2, 0.9, -0.3).normalize()
    }

    /// A coat normal 15° off `normal()`, as a coat normal map bends it.
    fn coat_normal() -> Vec3A {
        let basis = OrthonormalBasis::from_normal(normal());
        let (s, c) = 15f32.to_radians().sin_cos();
        basis.to_world(Vec3A::new(s * 0.6, s * 0.8, c)).normalize()
    }

    /// A direction at polar angle θ from `normal()` (θ > 90°: from below).
    fn direction(theta_deg: f32) -> Vec3A {
        let basis = OrthonormalBasis::from_normal(normal());
        let (s, c) = theta_deg.to_radians().sin_cos();
        basis
            .to_world(Vec3A::new(s * 0.96, s * 0.28, c))
            .normalize()
    }

    fn base(roughness: f32, metallic: f32, transmission: f32) -> MetallicRoughness {
        MetallicRoughness {
            base_color: Spectrum::new(0.9, 0.6, 0.3),
            metallic,
            roughness,
            ior: 1.5,
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

    fn coated(m: MetallicRoughness, factor: f32, roughness: f32, own: bool) -> MetallicRoughness {
        MetallicRoughness {
            clearcoat: Clearcoat {
                factor,
                roughness,
                normal: own.then(coat_normal),
            },
            ..m
        }
    }

    /// Coats (rough and smooth, with and without their own normal) over a dielectric over
    /// a diffuse base, a metal, a transmissive dielectric and a mixture, at the base
    /// roughnesses given.
    fn materials(base_roughnesses: &[f32], coat_roughnesses: &[f32]) -> Vec<MetallicRoughness> {
        let mut all = Vec::new();
        for &r in base_roughnesses {
            for b in [
                base(r, 0.0, 0.0),
                base(r, 1.0, 0.0),
                base(r, 0.0, 1.0),
                base(r, 0.5, 0.5),
            ] {
                for &coat in coat_roughnesses {
                    for (factor, own) in [(1.0, false), (0.6, true)] {
                        all.push(coated(b, factor, coat, own));
                    }
                }
            }
        }
        all
    }

    const ANGLES: [f32; 6] = [3.0, 45.0, 85.0, 177.0, 120.0, 95.0];

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

    /// χ² statistic and threshold of `m`'s sampled directions from `wo` against the cells'
    /// probabilities under `expected`'s pdf.
    fn chi_square(
        m: &MetallicRoughness,
        expected: &MetallicRoughness,
        wo: Vec3A,
        rng: &mut Rng,
    ) -> (f64, f64) {
        const DRAWS: usize = 200_000;
        let n = normal();
        let mut counts = vec![0u64; N_THETA * N_PHI];
        for _ in 0..DRAWS {
            let (u, u_lobe) = (rng.uniform2(), rng.uniform());
            if let Some(s) = m.sample(n, wo, u, u_lobe, TransportMode::Radiance) {
                assert!(!s.specular, "{m:?}");
                counts[cell(s.wi)] += 1;
            }
        }
        let basis = OrthonormalBasis::from_normal(n);
        let p = sphere_cell_probabilities(N_THETA, N_PHI, |theta, phi| {
            let (s, c) = theta.sin_cos();
            let local = Vec3A::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
            expected.pdf(n, wo, basis.to_world(local)) as f64
        });
        let (stat, df) = pooled_statistic(&counts, DRAWS as u64, &p);
        (stat, quantile(df, Z_1E6))
    }

    /// The coated material's directions follow its pdf (the coat's own frame included),
    /// and a coat 10% rougher in the pdf is rejected.
    #[test]
    fn coated_sampling_follows_pdf() {
        let mut rng = Rng::new(45, 11);
        for m in materials(&[0.3], &[0.15, 0.6]) {
            for theta in [3.0, 60.0, 120.0] {
                let (stat, threshold) = chi_square(&m, &m, direction(theta), &mut rng);
                assert!(stat < threshold, "{m:?} θ {theta}: χ² {stat} ≥ {threshold}");
            }
        }
        let m = coated(base(0.6, 0.0, 0.0), 1.0, 0.2, true);
        let rougher = coated(m, 1.0, 0.22, true);
        let (stat, threshold) = chi_square(&m, &rougher, direction(70.0), &mut rng);
        assert!(stat > threshold, "χ² {stat} < {threshold}");
    }

    fn close(a: Spectrum, b: Spectrum, relative: f32) -> bool {
        let scale = a.max_component().max(b.max_component());
        (a - b).abs().max_component() <= relative * scale || scale < 1e-6
    }

    /// Every sample's weight is eval·|cos|/pdf with pdf = `pdf`, `scatter` gives it back,
    /// and a Dirac sample goes where `specular_direction` says (for a smooth coat: its
    /// mirror about its own normal).
    #[test]
    fn coated_sample_eval_pdf_and_scatter_agree() {
        let n = normal();
        let mut rng = Rng::new(45, 12);
        // And coats over a rough index-matched glass (a Dirac transmission straight on).
        let index_matched = [0.0, 0.5].map(|coat| {
            coated(
                MetallicRoughness {
                    ior: 1.0,
                    ..base(0.5, 0.0, 1.0)
                },
                1.0,
                coat,
                false,
            )
        });
        for m in materials(&[0.0, 0.2, 1.0], &[0.0, 0.05, 0.5])
            .into_iter()
            .chain(index_matched)
        {
            for theta in ANGLES {
                let wo = direction(theta);
                let tolerance = if m.clearcoat.roughness == 0.05 {
                    1e-2
                } else {
                    2e-3
                };
                let coat_mirror = reflect(wo, m.clearcoat.normal.unwrap_or(n));
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    for _ in 0..300 {
                        let Some(s) = m.sample(n, wo, rng.uniform2(), rng.uniform(), mode) else {
                            continue;
                        };
                        let context = format!("{m:?} θ {theta} {mode:?} {s:?}");
                        assert!(s.weight.is_finite() && s.pdf > 0.0, "{context}");
                        // `scatter` takes a direction with a density this close to a
                        // mirror direction for the mirror's; near the tangent plane
                        // cosines keep few digits.
                        let near_mirror = |mirror: Vec3A| s.wi.dot(mirror) > 1.0 - 2e-6;
                        if !s.specular
                            && ((m.clearcoat.is_smooth() && near_mirror(coat_mirror))
                                || (m.roughness == 0.0 && near_mirror(reflect(wo, n))))
                            || s.wi.dot(n).abs() < 1e-3
                        {
                            continue;
                        }
                        // Given the lobe (as a path-space vertex records it), scattering
                        // into the sampled direction gives the sample back.
                        let lobe = m
                            .scatter_lobe(n, wo, s.wi, mode, s.specular)
                            .expect(&context);
                        assert_eq!(lobe.specular, s.specular, "{context}");
                        assert!(
                            (lobe.pdf - s.pdf).abs() <= tolerance * s.pdf
                                && close(lobe.weight, s.weight, tolerance),
                            "scatter_lobe: {context} {lobe:?}"
                        );
                        let again = m.scatter(n, wo, s.wi, mode).expect(&context);
                        assert_eq!(again.specular, s.specular, "{context}");
                        assert!(
                            (again.pdf - s.pdf).abs() <= tolerance * s.pdf,
                            "{context} {again:?}"
                        );
                        assert!(
                            close(again.weight, s.weight, tolerance),
                            "{context} {again:?}"
                        );
                        if s.specular {
                            // The coat's mirror may fall behind the base's normal.
                            let coat_reflection =
                                m.clearcoat.is_smooth() && (s.wi - coat_mirror).length() < 1e-5;
                            let by_sides = if coat_reflection {
                                SpecularLobe::Reflection
                            } else {
                                SpecularLobe::of(n, wo, s.wi)
                            };
                            // Two smooth reflections about different normals: the nearer
                            // mirror names the lobe.
                            let lobe = m.specular_lobe(n, wo, s.wi, by_sides);
                            let direction = m.specular_direction(n, wo, lobe).unwrap();
                            assert!((direction - s.wi).length() < 1e-5, "{context} {lobe:?}");
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

    fn random_direction(rng: &mut Rng) -> Vec3A {
        let [a, b] = rng.uniform2();
        let z = 2.0 * a - 1.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * b;
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// The coat is not reciprocal (its Fresnel factor is the viewer's), but importance
    /// transport is radiance transport's adjoint, f_importance(wo, wi) = f_radiance(wi, wo),
    /// its own normal's frame correction included; without a coat, reflection stays
    /// reciprocal.
    #[test]
    fn importance_is_the_adjoint_of_radiance() {
        let n = normal();
        let mut rng = Rng::new(45, 13);
        let mut asymmetric = 0;
        for m in materials(&[0.3, 1.0], &[0.1, 0.5]) {
            for _ in 0..1000 {
                let (wo, wi) = (random_direction(&mut rng), random_direction(&mut rng));
                let forward = m.eval(n, wo, wi, TransportMode::Radiance);
                let adjoint = m.eval(n, wi, wo, TransportMode::Importance);
                assert!(
                    close(forward, adjoint, 5e-3),
                    "{m:?} {wo} {wi}: {forward} {adjoint}"
                );
                let reversed = m.eval(n, wi, wo, TransportMode::Radiance);
                if !close(forward, reversed, 1e-2) {
                    asymmetric += 1;
                }
            }
        }
        assert!(asymmetric > 0, "the coat's layering is not reciprocal");
    }

    /// The white furnace: what a viewer sees of a white material under a coat, at every
    /// angle (from both sides), never exceeds 1, over a diffuse base, a metal and
    /// transmission, rough or smooth; a white mirror under a smooth coat (the same normal)
    /// reflects exactly 1.
    /// Radiance transport (the viewer's side), with refraction's radiance scaling divided
    /// out.
    #[test]
    fn white_furnace_never_exceeds_one() {
        let n = normal();
        let mut rng = Rng::new(45, 14);
        let white = |m: MetallicRoughness| MetallicRoughness {
            base_color: Spectrum::ONE,
            ..m
        };
        for m in materials(&[0.0, 0.3, 1.0], &[0.0, 0.3, 1.0]) {
            let m = white(m);
            for theta in ANGLES.into_iter().chain([60.0, 89.5]) {
                let wo = direction(theta);
                let draws = 40_000;
                let mut sum = Spectrum::ZERO;
                for _ in 0..draws {
                    let s = m.sample(
                        n,
                        wo,
                        rng.uniform2(),
                        rng.uniform(),
                        TransportMode::Radiance,
                    );
                    if let Some(s) = s {
                        sum += s.weight * (1.0 / s.radiance_scale);
                    }
                }
                let a = sum * (1.0 / draws as f32);
                assert!(a.max_component() <= 1.01, "{m:?} θ {theta}: {a}");
                // (A coat with its own normal loses the reflections that would cross the
                // base's tangent plane.)
                let one_mirror = m.clearcoat.is_smooth() && m.clearcoat.normal.is_none();
                if m.metallic == 1.0 && m.roughness == 0.0 && one_mirror {
                    assert!((a[0] - 1.0).abs() < 1e-4, "{m:?} θ {theta}: {a}");
                }
            }
        }
    }

    /// The specification's coated material's f, `color`-grey non-metal of index 1.5 at
    /// roughness 1 under a coat of factor `c` and roughness `r` (the same normal), at
    /// μo, μi and cos(v·h): (1 − c F(μo)) f_base + c F(μo) D_c G_c / (4 μo μi).
    fn specification_f(color: f64, c: f64, r: f64, mu_o: f64, mu_i: f64, cos_vh: f64) -> f64 {
        use std::f64::consts::PI;
        let schlick = |f0: f64, cos: f64| f0 + (1.0 - f0) * (1.0 - cos).powi(5);
        let lambda = |alpha2: f64, mu: f64| {
            ((1.0 + alpha2 * (1.0 - mu * mu) / (mu * mu)).sqrt() - 1.0) / 2.0
        };
        let g2 = |alpha2: f64| 1.0 / (1.0 + lambda(alpha2, mu_o) + lambda(alpha2, mu_i));
        let f_vh = schlick(0.04, cos_vh);
        // The base at α = 1: D = 1/π.
        let base = color / PI * (1.0 - f_vh) + f_vh / PI * g2(1.0) / (4.0 * mu_o * mu_i);
        let alpha2 = (r * r) * (r * r);
        // n·h of the reflection's half vector: |wo + wi| = 2 cos(v·h).
        let cos_nh = (mu_o + mu_i) / (2.0 * cos_vh);
        let t = cos_nh * cos_nh * (alpha2 - 1.0) + 1.0;
        let d = alpha2 / (PI * t * t);
        let coat = d * g2(alpha2) / (4.0 * mu_o * mu_i);
        let coat_f = c * schlick(0.04, mu_o);
        (1.0 - coat_f) * base + coat_f * coat
    }

    /// The specification's directional albedo of the coated material at polar angle θ,
    /// by the midpoint rule in μi and φi (1000 × 2000 nodes).
    fn specification_albedo(color: f64, c: f64, r: f64, theta_deg: f64) -> f64 {
        use std::f64::consts::PI;
        let (sin_o, mu_o) = theta_deg.to_radians().sin_cos();
        let (n_mu, n_phi) = (1000, 2000);
        let mut sum = 0.0;
        for i in 0..n_mu {
            let mu_i = (i as f64 + 0.5) / n_mu as f64;
            let sin_i = (1.0 - mu_i * mu_i).sqrt();
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) / n_phi as f64 * 2.0 * PI;
                // wo = (sin_o, 0, μo), wi = (−sin_i cos φ, −sin_i sin φ, μi) mirrored at φ = 0.
                let cos_oi = -sin_o * sin_i * phi.cos() + mu_o * mu_i;
                let cos_vh = ((1.0 + cos_oi) / 2.0).sqrt();
                sum += specification_f(color, c, r, mu_o, mu_i, cos_vh) * mu_i;
            }
        }
        sum * 2.0 * PI / (n_mu * n_phi) as f64
    }

    /// The coated material's directional albedo is the specification's formula integrated
    /// numerically, within 1%, over a grey non-metal at roughness 1 (where the base follows
    /// the specification within 1% up to 76°), for full and partial coats.
    #[test]
    fn coated_albedo_is_the_specifications() {
        let n = normal();
        let mut rng = Rng::new(45, 15);
        for (c, r) in [(1.0f32, 0.5f32), (1.0, 1.0), (0.5, 0.7)] {
            let m = coated(
                MetallicRoughness {
                    base_color: Spectrum::splat(0.8),
                    ..base(1.0, 0.0, 0.0)
                },
                c,
                r,
                false,
            );
            for theta in [0.0f32, 40.0, 70.0] {
                let wo = direction(theta);
                let draws = 200_000;
                let mut sum = 0.0f64;
                for _ in 0..draws {
                    let s = m.sample(
                        n,
                        wo,
                        rng.uniform2(),
                        rng.uniform(),
                        TransportMode::Radiance,
                    );
                    sum += s.map_or(0.0, |s| s.weight[0] as f64);
                }
                let ours = sum / draws as f64;
                let specification = specification_albedo(0.8, c as f64, r as f64, theta as f64);
                assert!(
                    (ours / specification - 1.0).abs() < 0.01,
                    "coat {c} roughness {r} θ {theta}: {ours} vs the specification's {specification}"
                );
            }
        }
        // The coat alone: c F(μo) E(μo), E by the half-vector quadrature.
        let coat = Clearcoat {
            factor: 1.0,
            roughness: 0.4,
            normal: None,
        };
        for theta in [0.0f32, 50.0, 80.0] {
            let wo = direction(theta);
            let view = coat.view(n, wo).unwrap();
            let draws = 100_000;
            let mut sum = 0.0f64;
            for _ in 0..draws {
                if let Some(wi) = view.sample(rng.uniform2()) {
                    let pdf = view.pdf(wi);
                    sum += (view.eval(wi, TransportMode::Radiance) * wi.dot(n) / pdf) as f64;
                }
            }
            let mu = wo.dot(n);
            let expected = fresnel(mu) as f64 * single_scattering_albedo(0.16, mu, 1500, 180);
            let ours = sum / draws as f64;
            assert!(
                (ours / expected - 1.0).abs() < 0.01,
                "θ {theta}: {ours} vs {expected}"
            );
        }
    }

    /// The coat's highlight follows its own normal, the base's stays at its own: a glossy
    /// coat tilted 15° off a glossy metal's normal reflects strongly about its normal, and
    /// about the metal's normal the material is the metal under (1 − c F).
    #[test]
    fn coat_highlight_follows_its_own_normal() {
        let n = normal();
        let metal = base(0.25, 1.0, 0.0);
        let m = coated(metal, 1.0, 0.05, true);
        for theta in [10.0f32, 35.0] {
            let wo = direction(theta);
            for mode in [TransportMode::Radiance, TransportMode::Importance] {
                let coat_mirror = reflect(wo, coat_normal());
                let base_mirror = reflect(wo, n);
                let ratio = |wi: Vec3A| m.eval(n, wo, wi, mode)[0] / metal.eval(n, wo, wi, mode)[0];
                assert!(
                    ratio(coat_mirror) > 20.0,
                    "θ {theta}: {}",
                    ratio(coat_mirror)
                );
                let viewer = match mode {
                    TransportMode::Radiance => wo,
                    TransportMode::Importance => base_mirror,
                };
                let scale = 1.0 - fresnel(viewer.dot(coat_normal()).abs());
                assert!(
                    (ratio(base_mirror) - scale).abs() < 1e-4,
                    "θ {theta}: {} vs {scale}",
                    ratio(base_mirror)
                );
                // The uncoated metal's highlight is where the coated one's base is.
                assert!(
                    metal.eval(n, wo, base_mirror, mode)[0]
                        > 5.0 * metal.eval(n, wo, coat_mirror, mode)[0]
                );
            }
        }
    }

    /// A coat adds its lobe's class: specular when smooth, glossy when rough, nothing
    /// without a factor.
    #[test]
    fn coat_lobes_are_reported() {
        let diffuse = base(0.5, 0.0, 0.0);
        assert_eq!(diffuse.lobes(), BsdfLobes::GLOSSY | BsdfLobes::DIFFUSE);
        assert_eq!(coated(diffuse, 0.0, 0.0, false).lobes(), diffuse.lobes());
        let smooth = coated(diffuse, 1.0, 0.0, false).lobes();
        assert!(smooth.contains(BsdfLobes::SPECULAR) && smooth.has_non_specular());
        let metal = base(0.5, 1.0, 0.0);
        assert_eq!(coated(metal, 0.5, 0.3, true).lobes(), BsdfLobes::GLOSSY);
        let mirror = base(0.0, 1.0, 0.0);
        assert_eq!(coated(mirror, 1.0, 0.0, false).lobes(), BsdfLobes::SPECULAR);
        assert_eq!(
            coated(mirror, 1.0, 0.2, false).lobes(),
            BsdfLobes::SPECULAR | BsdfLobes::GLOSSY
        );
    }
}
