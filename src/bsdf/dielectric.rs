//! Smooth dielectric interface: Fresnel-weighted choice between reflection and refraction.

use super::scattering::{ScatterSample, TransportMode, reflect};
use crate::spectrum::Spectrum;
use glam::Vec3A;

/// Unpolarized Fresnel reflectance for light arriving with |cos θ| = `cos_i` on the side
/// with index `eta_i`, crossing into index `eta_t`. Returns 1 under total internal reflection.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta_i: f32, eta_t: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_i2 = (1.0 - cos_i * cos_i).max(0.0);
    let sin_t2 = (eta_i / eta_t) * (eta_i / eta_t) * sin_i2;
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let r_parallel = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    let r_perpendicular = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// The interface as seen from direction `wo`: the indices on wo's side and the other, the
/// normal on wo's side and |cos θ|. The front side is outside (index 1), the back side
/// inside (index `ior`). `None` for a grazing `wo`.
struct Interface {
    eta_i: f32,
    eta_t: f32,
    side_normal: Vec3A,
    cos_i: f32,
}

impl Interface {
    #[inline]
    fn seen_from(ior: f32, normal: Vec3A, wo: Vec3A) -> Option<Interface> {
        let cos_o = wo.dot(normal);
        if cos_o == 0.0 {
            return None;
        }
        let (eta_i, eta_t, side_normal) = if cos_o > 0.0 {
            (1.0, ior, normal)
        } else {
            (ior, 1.0, -normal)
        };
        Some(Interface {
            eta_i,
            eta_t,
            side_normal,
            cos_i: cos_o.abs(),
        })
    }
}

/// Samples reflection with probability F and refraction with 1 − F, so the weight is the
/// tint alone (times the radiance scaling (η_i/η_t)² on refraction in radiance mode).
#[inline]
pub(super) fn sample(
    ior: f32,
    color: Spectrum,
    normal: Vec3A,
    wo: Vec3A,
    u_lobe: f32,
    mode: TransportMode,
) -> Option<ScatterSample> {
    let Interface {
        eta_i,
        eta_t,
        side_normal,
        cos_i,
    } = Interface::seen_from(ior, normal, wo)?;
    let fresnel = fresnel_dielectric(cos_i, eta_i, eta_t);
    if u_lobe < fresnel {
        return Some(ScatterSample {
            wi: reflect(wo, side_normal),
            weight: color,
            pdf: fresnel,
            specular: true,
            radiance_scale: 1.0,
        });
    }
    let eta = eta_i / eta_t;
    let wi = refract(wo, side_normal, cos_i, eta);
    Some(refraction(wi, color, eta, fresnel, mode))
}

/// `wo` refracted through the surface (`side_normal` on wo's side, cos_i = wo · side_normal,
/// eta = η_i/η_t), below the critical angle.
#[inline]
pub(super) fn refract(wo: Vec3A, side_normal: Vec3A, cos_i: f32, eta: f32) -> Vec3A {
    let sin_t2 = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    let cos_t = (1.0 - sin_t2).max(0.0).sqrt();
    (-wo * eta + side_normal * (eta * cos_i - cos_t)).normalize()
}

/// The refracted direction of `wo` through an interface of index `ior` (front side outside),
/// or `None` under total internal reflection.
#[inline]
pub(super) fn refracted(ior: f32, normal: Vec3A, wo: Vec3A) -> Option<Vec3A> {
    let Interface {
        eta_i,
        eta_t,
        side_normal,
        cos_i,
    } = Interface::seen_from(ior, normal, wo)?;
    if fresnel_dielectric(cos_i, eta_i, eta_t) >= 1.0 {
        return None;
    }
    Some(refract(wo, side_normal, cos_i, eta_i / eta_t))
}

/// Refraction into `wi`, chosen with probability 1 − F: the weight is the tint, times the
/// radiance scaling η² (η = η_i/η_t) when radiance is carried.
#[inline]
fn refraction(
    wi: Vec3A,
    color: Spectrum,
    eta: f32,
    fresnel: f32,
    mode: TransportMode,
) -> ScatterSample {
    let scale = match mode {
        TransportMode::Radiance => eta * eta,
        TransportMode::Importance => 1.0,
    };
    ScatterSample {
        wi,
        weight: color * scale,
        pdf: 1.0 - fresnel,
        specular: true,
        radiance_scale: scale,
    }
}

/// The lobe of a given scattering (reflection if `wi` stays on `wo`'s side, else
/// refraction) with the weight and probability `sample` gives it.
#[inline]
pub(super) fn scatter(
    ior: f32,
    color: Spectrum,
    normal: Vec3A,
    wo: Vec3A,
    wi: Vec3A,
    mode: TransportMode,
) -> Option<ScatterSample> {
    let (cos_o, cos_i) = (wo.dot(normal), wi.dot(normal));
    if cos_o == 0.0 || cos_i == 0.0 {
        return None;
    }
    let (eta_i, eta_t) = if cos_o > 0.0 { (1.0, ior) } else { (ior, 1.0) };
    let fresnel = fresnel_dielectric(cos_o.abs(), eta_i, eta_t);
    if cos_o * cos_i > 0.0 {
        return Some(ScatterSample {
            wi,
            weight: color,
            pdf: fresnel,
            specular: true,
            radiance_scale: 1.0,
        });
    }
    if fresnel >= 1.0 {
        return None;
    }
    Some(refraction(wi, color, eta_i / eta_t, fresnel, mode))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_known_values() {
        // Normal incidence, glass: ((1.5-1)/(1.5+1))² = 0.04.
        assert!((fresnel_dielectric(1.0, 1.0, 1.5) - 0.04).abs() < 1e-6);
        // Symmetric from inside at normal incidence.
        assert!((fresnel_dielectric(1.0, 1.5, 1.0) - 0.04).abs() < 1e-6);
        // Total internal reflection beyond the critical angle (41.8° for 1.5).
        assert_eq!(fresnel_dielectric(45f32.to_radians().cos(), 1.5, 1.0), 1.0);
        // Grazing incidence reflects everything.
        assert!((fresnel_dielectric(0.0, 1.0, 1.5) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn scatter_gives_what_sample_gave() {
        let n = Vec3A::new(0.2, 0.9, -0.1).normalize();
        let color = Spectrum::new(0.9, 0.8, 0.7);
        for wo in [Vec3A::new(0.5, 0.8, 0.1), Vec3A::new(-0.3, -0.6, 0.4)] {
            let wo = wo.normalize();
            for mode in [TransportMode::Radiance, TransportMode::Importance] {
                for u_lobe in [0.001, 0.999] {
                    let s = sample(1.5, color, n, wo, u_lobe, mode).unwrap();
                    let e = scatter(1.5, color, n, wo, s.wi, mode).unwrap();
                    assert_eq!(
                        (e.weight, e.pdf),
                        (s.weight, s.pdf),
                        "{wo} {mode:?} {u_lobe}"
                    );
                }
            }
        }
    }

    #[test]
    fn refracted_is_the_direction_sample_refracts_into() {
        let n = Vec3A::new(0.2, 0.9, -0.1).normalize();
        for wo in [Vec3A::new(0.5, 0.8, 0.1), Vec3A::new(-0.3, -0.6, 0.4)] {
            let wo = wo.normalize();
            let s = sample(1.5, Spectrum::ONE, n, wo, 0.999, TransportMode::Radiance).unwrap();
            assert_eq!(refracted(1.5, n, wo), Some(s.wi));
        }
        // Beyond the critical angle from inside: no refraction.
        let grazing = Vec3A::new(0.9, -0.3, 0.0).normalize();
        assert_eq!(refracted(1.5, Vec3A::Y, grazing), None);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3A::Y;
        let wo = Vec3A::new(0.5, 0.8, 0.0).normalize();
        // u_lobe = 0.999 picks refraction (F is small at this angle).
        let s = sample(1.5, Spectrum::ONE, n, wo, 0.999, TransportMode::Radiance).unwrap();
        let sin_i = wo.cross(n).length();
        let sin_t = s.wi.cross(n).length();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(s.wi.y < 0.0);
        assert!((s.weight[0] - 1.0 / 2.25).abs() < 1e-6);
        // The reversed path (arriving from inside along s.wi) leaves along wo.
        let back = sample(
            1.5,
            Spectrum::ONE,
            n,
            s.wi,
            0.999,
            TransportMode::Importance,
        )
        .unwrap();
        assert!((back.wi - wo).length() < 1e-5);
    }
}
