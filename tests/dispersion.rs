//! Dispersion, against Snell's law: a camera looks through a glass prism (index 1.5 at the
//! d line, Abbe number 20: a strongly dispersive flint) at a thin emissive slit lit white.
//! Each wavelength refracts by its own Cauchy index (`KHR_materials_dispersion`'s form), so
//! the slit's image is spread over the film into a spectrum. The test traces the prism
//! analytically (two planar refractions with the vector form of Snell's law and the
//! unpolarized Fresnel transmittance, per wavelength at 1 nm), finds for each wavelength
//! which part of each pixel row sees the slit, and sums white light's colour per nanometre
//! (`mlt::white_light_srgb_per_nm`) over it: the expected brightness of every row in linear
//! sRGB. Every algorithm that renders spectrally must give, channel by channel, the same
//! total light and the same centroid row (where the spectrum lies, which puts blue and red
//! where Snell's law does) within 6 standard errors from 6 independent renders. A prism of
//! Abbe number 10% higher moves the blue centroid out of those bounds, and for path
//! tracing and BDPT a 2% error in the luminance of the totals would leave them (both
//! asserted).
//!
//! Runs in about 16 s on 2 cores (`cargo test --test dispersion`).

mod common {
    pub mod references;
    pub mod scenes;
    pub mod stats;
}

use common::references::render_image;
use common::stats::{assert_within_and_sharp, luminance};

use glam::DVec3;
use mlt::{Algorithm, Backend, Camera, Material, RenderSettings, Scene, SceneDesc};

const N_D: f64 = 1.5;
const ABBE: f64 = 20.0;
/// Side of the prism's equilateral cross-section (xy-plane, apex up, centroid at the
/// origin); its length along z is 2·`PRISM_HALF_LENGTH`.
const SIDE: f64 = 1.0;
const PRISM_HALF_LENGTH: f64 = 2.0;
/// The slit lies in the plane x = −`SLIT_DISTANCE`, facing +x, `SLIT_WIDTH` tall in y.
const SLIT_DISTANCE: f64 = 10.0;
const SLIT_WIDTH: f64 = 0.2;
const SLIT_HALF_LENGTH: f64 = 3.0;
const EMISSION: f32 = 50.0;
const WIDTH: u32 = 8;
const HEIGHT: u32 = 128;
const FOV_Y_DEG: f64 = 8.0;
const CAMERA_DISTANCE: f64 = 2.5;
/// The wavelength whose minimum-deviation ray is the camera's axis and hits the slit's
/// middle: the spectrum is centred on it.
const CENTRE_NM: f64 = 500.0;

/// The index at `lambda` nm, written from `KHR_materials_dispersion`'s definition.
fn cauchy(abbe: f64, lambda: f64) -> f64 {
    (N_D + (N_D - 1.0) / abbe * (523_655.0 / (lambda * lambda) - 1.5168)).max(1.0)
}

/// The prism's corners: apex, base left, base right.
fn corners() -> [DVec3; 3] {
    let h = SIDE / 3f64.sqrt();
    [
        DVec3::new(0.0, h, 0.0),
        DVec3::new(-SIDE / 2.0, -h / 2.0, 0.0),
        DVec3::new(SIDE / 2.0, -h / 2.0, 0.0),
    ]
}

/// The outward normal of the prism face through edge (a, b).
fn face_normal(a: DVec3, b: DVec3) -> DVec3 {
    let e = b - a;
    let n = DVec3::new(e.y, -e.x, 0.0).normalize();
    if n.dot(a) < 0.0 { -n } else { n }
}

/// Where a ray meets the face through edge (a, b) (within the face), and the distance.
fn hit_face(origin: DVec3, dir: DVec3, a: DVec3, b: DVec3) -> Option<(f64, DVec3)> {
    let n = face_normal(a, b);
    let t = (a - origin).dot(n) / dir.dot(n);
    if t.is_nan() || t <= 1e-9 {
        return None;
    }
    let p = origin + dir * t;
    let e = b - a;
    let s = (p - a).dot(e) / e.length_squared();
    ((0.0..=1.0).contains(&s) && p.z.abs() <= PRISM_HALF_LENGTH).then_some((t, p))
}

/// Refraction of unit `dir` at a surface with unit normal `n` facing it (dir·n < 0), from
/// index `n_i` into `n_t`: the new direction and the unpolarized Fresnel transmittance;
/// `None` on total internal reflection.
fn refract(dir: DVec3, n: DVec3, n_i: f64, n_t: f64) -> Option<(DVec3, f64)> {
    let eta = n_i / n_t;
    let cos_i = -dir.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let t = dir * eta + n * (eta * cos_i - cos_t);
    Some((t.normalize(), 1.0 - (r_s * r_s + r_p * r_p) / 2.0))
}

/// A camera ray through the prism at `lambda`: in by the right face, out by the left one,
/// on to the slit's plane. Returns the height it reaches there and the transmittance.
fn through_prism(origin: DVec3, dir: DVec3, abbe: f64, lambda: f64) -> Option<(f64, f64)> {
    let [apex, left, right] = corners();
    let n = cauchy(abbe, lambda);
    let (_, p) = hit_face(origin, dir, apex, right)?;
    let (inside, t1) = refract(dir, face_normal(apex, right), 1.0, n)?;
    let out_left = hit_face(p, inside, apex, left);
    let out_bottom = hit_face(p, inside, left, right);
    let (q, normal) = match (out_left, out_bottom) {
        (Some((tl, q)), Some((tb, _))) if tl < tb => (q, face_normal(apex, left)),
        (Some((_, q)), None) => (q, face_normal(apex, left)),
        _ => return None,
    };
    let (out, t2) = refract(inside, -normal, n, 1.0)?;
    if out.x >= 0.0 {
        return None;
    }
    let s = (-SLIT_DISTANCE - q.x) / out.x;
    let reached = q + out * s;
    (reached.z.abs() <= SLIT_HALF_LENGTH).then_some((reached.y, t1 * t2))
}

/// The camera's axis: the minimum-deviation ray at `CENTRE_NM`, through the prism's centroid.
fn camera_axis() -> DVec3 {
    let n = cauchy(ABBE, CENTRE_NM);
    let apex_angle = std::f64::consts::FRAC_PI_3;
    let incidence = (n * (apex_angle / 2.0).sin()).asin();
    let half_deviation = incidence - apex_angle / 2.0;
    DVec3::new(-half_deviation.cos(), half_deviation.sin(), 0.0)
}

fn camera() -> Camera {
    let eye = -camera_axis() * CAMERA_DISTANCE;
    Camera {
        eye: eye.as_vec3().to_array(),
        target: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: FOV_Y_DEG as f32,
        ..Camera::default()
    }
}

/// The pinhole ray through film position (x, y) in pixels, as mlt's camera makes it.
fn film_ray(x: f64, y: f64) -> (DVec3, DVec3) {
    let forward = camera_axis();
    let eye = -forward * CAMERA_DISTANCE;
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let half_height = (FOV_Y_DEG.to_radians() / 2.0).tan();
    let half_width = half_height * WIDTH as f64 / HEIGHT as f64;
    let sx = (2.0 * x / WIDTH as f64 - 1.0) * half_width;
    let sy = (1.0 - 2.0 * y / HEIGHT as f64) * half_height;
    (eye, (forward + right * sx + up * sy).normalize())
}

/// The height of the slit's middle: where the camera's axis reaches at `CENTRE_NM`.
fn slit_centre() -> f64 {
    let (eye, dir) = film_ray(WIDTH as f64 / 2.0, HEIGHT as f64 / 2.0);
    through_prism(eye, dir, ABBE, CENTRE_NM).unwrap().0
}

/// The expected mean linear sRGB of every pixel row (columns alike: the film is 0.25°
/// wide, where the prism's skew rays bend alike), for a prism of Abbe number `abbe`.
fn expected_rows(abbe: f64) -> Vec<[f64; 3]> {
    let centre = slit_centre();
    let mut rows = vec![[0.0f64; 3]; HEIGHT as usize];
    let columns = [0.25, 0.75].map(|f| f * WIDTH as f64);
    for lambda in 360..=830 {
        let lambda = lambda as f64;
        let white = mlt::white_light_srgb_per_nm(lambda as f32);
        for &x in &columns {
            // The slit's edges seen at this wavelength: film heights where the ray reaches
            // the edges (the height reached falls monotonically down the film).
            let reached = |y: f64| through_prism(film_ray(x, y).0, film_ray(x, y).1, abbe, lambda);
            let edge = |target: f64| {
                let (mut lo, mut hi) = (-1.0, HEIGHT as f64 + 1.0);
                for _ in 0..60 {
                    let mid = (lo + hi) / 2.0;
                    match reached(mid) {
                        Some((h, _)) if h > target => lo = mid,
                        _ => hi = mid,
                    }
                }
                (lo + hi) / 2.0
            };
            let (top, bottom) = (
                edge(centre + SLIT_WIDTH / 2.0),
                edge(centre - SLIT_WIDTH / 2.0),
            );
            let Some((_, transmittance)) = reached((top + bottom) / 2.0) else {
                continue;
            };
            for (r, row) in rows.iter_mut().enumerate() {
                let overlap = (bottom.min(r as f64 + 1.0) - top.max(r as f64)).max(0.0);
                for c in 0..3 {
                    row[c] +=
                        white[c] * transmittance * overlap * EMISSION as f64 / columns.len() as f64;
                }
            }
        }
    }
    rows
}

/// The glass prism and the slit (a thin emissive quad facing the prism).
fn prism_scene() -> Scene {
    let [apex, left, right] = corners();
    let z = PRISM_HALF_LENGTH;
    let at = |p: DVec3, z: f64| [p.x as f32, p.y as f32, z as f32];
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut indices = Vec::new();
    let mut material_ids = Vec::new();
    // A triangle wound counter-clockwise seen from `outside` of its centre.
    let mut triangle = |a: [f32; 3], b: [f32; 3], c: [f32; 3], outward: DVec3, material: u32| {
        let v = |p: [f32; 3]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let normal = (v(b) - v(a)).cross(v(c) - v(a));
        let base = positions.len() as u32;
        positions.extend([a, b, c]);
        if normal.dot(outward) > 0.0 {
            indices.extend([base, base + 1, base + 2]);
        } else {
            indices.extend([base, base + 2, base + 1]);
        }
        material_ids.push(material);
    };
    for (a, b) in [(apex, right), (right, left), (left, apex)] {
        let n = face_normal(a, b);
        triangle(at(a, -z), at(b, -z), at(b, z), n, 0);
        triangle(at(a, -z), at(b, z), at(a, z), n, 0);
    }
    triangle(at(apex, z), at(left, z), at(right, z), DVec3::Z, 0);
    triangle(at(apex, -z), at(left, -z), at(right, -z), -DVec3::Z, 0);
    let (x, y0, y1, w) = (
        -SLIT_DISTANCE as f32,
        (slit_centre() - SLIT_WIDTH / 2.0) as f32,
        (slit_centre() + SLIT_WIDTH / 2.0) as f32,
        SLIT_HALF_LENGTH as f32,
    );
    triangle([x, y0, -w], [x, y1, -w], [x, y1, w], DVec3::X, 1);
    triangle([x, y0, -w], [x, y1, w], [x, y0, w], DVec3::X, 1);
    let positions: Vec<f32> = positions.concat();
    let glass = Material {
        abbe_number: ABBE as f32,
        ..Material::dielectric(N_D as f32)
    };
    let slit = Material::diffuse([0.0; 3]).with_emission([EMISSION; 3]);
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &material_ids,
        materials: &[glass, slit],
        lights: Default::default(),
        backend: Backend::Bvh,
        ..Default::default()
    })
    .unwrap()
}

/// Per channel: the total over rows of the row means, and the centroid row (rows counted
/// from the top, a row's centre at r + ½).
fn totals_and_centroids(rows: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let total = std::array::from_fn(|c| rows.iter().map(|r| r[c]).sum::<f64>());
    let centroid = std::array::from_fn(|c| {
        rows.iter()
            .enumerate()
            .map(|(i, r)| (i as f64 + 0.5) * r[c])
            .sum::<f64>()
            / total[c]
    });
    (total, centroid)
}

/// The mean of each row of an RGB image.
fn row_means(image: &[f32]) -> Vec<[f64; 3]> {
    image
        .chunks_exact(3 * WIDTH as usize)
        .map(|row| {
            std::array::from_fn(|c| {
                row.iter()
                    .skip(c)
                    .step_by(3)
                    .map(|&v| v as f64)
                    .sum::<f64>()
                    / WIDTH as f64
            })
        })
        .collect()
}

fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let k = values.len() as f64;
    let mean = values.iter().sum::<f64>() / k;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (mean, (variance / k).sqrt())
}

/// Renders the prism with `algorithm` at `budget` samples or mutations per pixel, `renders`
/// times (seeds differ), and checks every channel's total and centroid row against Snell's
/// law within 6 standard errors (6 renders: 5 degrees of freedom, P(|t| > 6) ≈ 2·10⁻³; 12
/// renders: P ≈ 10⁻⁴). The blue centroid, which
/// moves most with the dispersion, must tell the prism from one of Abbe number 10% higher.
/// With `sharp_brightness`, the luminance of the totals must also resolve a 2% error.
fn check_algorithm(algorithm: Algorithm, budget: u32, renders: u64, sharp_brightness: bool) {
    let scene = prism_scene();
    let (truth_total, truth_centroid) = totals_and_centroids(&expected_rows(ABBE));
    let (_, stronger_centroid) = totals_and_centroids(&expected_rows(ABBE * 1.1));
    let renders: Vec<([f64; 3], [f64; 3])> = (0..renders)
        .map(|seed| {
            let settings = RenderSettings {
                width: WIDTH,
                height: HEIGHT,
                algorithm,
                samples_per_pixel: budget,
                mutations_per_pixel: budget,
                max_depth: 4,
                seed: 40 + seed,
                spectral: true,
                ..Default::default()
            };
            totals_and_centroids(&row_means(&render_image(&scene, &camera(), &settings)))
        })
        .collect();
    let sigmas = 6.0;
    for c in 0..3 {
        let (total, total_error) =
            mean_and_error(&renders.iter().map(|r| r.0[c]).collect::<Vec<_>>());
        let (centroid, centroid_error) =
            mean_and_error(&renders.iter().map(|r| r.1[c]).collect::<Vec<_>>());
        eprintln!(
            "{algorithm:?} channel {c}: total {total:.4} ± {total_error:.4} (truth {:.4}), centroid row {centroid:.3} ± {centroid_error:.3} (truth {:.3}, Abbe number ×1.1: {:.3})",
            truth_total[c], truth_centroid[c], stronger_centroid[c]
        );
        let tolerance = sigmas * total_error;
        assert!(
            (total - truth_total[c]).abs() <= tolerance,
            "{algorithm:?} channel {c}: total {total} vs {} ± {tolerance}",
            truth_total[c]
        );
        let tolerance = sigmas * centroid_error;
        assert!(
            (centroid - truth_centroid[c]).abs() <= tolerance,
            "{algorithm:?} channel {c}: centroid row {centroid} vs {} ± {tolerance}",
            truth_centroid[c]
        );
        if c == 2 {
            assert!(
                (stronger_centroid[c] - truth_centroid[c]).abs() > tolerance + 2.0 * centroid_error,
                "{algorithm:?}: an Abbe number 10% off would pass"
            );
        }
    }
    let luminances: Vec<f64> = renders.iter().map(|r| luminance(r.0)).collect();
    let (total, error) = mean_and_error(&luminances);
    let truth = luminance(truth_total);
    if sharp_brightness {
        assert_within_and_sharp(
            &format!("{algorithm:?} luminance"),
            total,
            truth,
            error,
            sigmas,
        );
    } else {
        assert!(
            (total - truth).abs() <= sigmas * error,
            "{algorithm:?} luminance: {total} vs {truth} ± {}",
            sigmas * error
        );
    }
}

/// The analytic spectrum itself: blue is deviated most, so it lies on the other side of
/// the film from red, and the spectrum spans tens of rows.
#[test]
fn snell_spreads_the_spectrum_in_order() {
    let (_, centroid) = totals_and_centroids(&expected_rows(ABBE));
    eprintln!("centroid rows (R, G, B): {centroid:.2?}");
    assert!(
        (centroid[2] - centroid[0]).abs() > 10.0,
        "red and blue {centroid:?}"
    );
    assert!(
        (centroid[1] - centroid[0]).signum() == (centroid[2] - centroid[1]).signum(),
        "green between red and blue: {centroid:?}"
    );
}

// 12 renders, not 6: the path tracer's low-discrepancy samples make its centroid so
// precise that the spread of 6 renders alone (5 degrees of freedom) too often understates its
// standard error (seeds 40-45 put it at a quarter of the 24-render value).
#[test]
fn path_tracing_disperses_by_snells_law() {
    check_algorithm(Algorithm::Path, 1024, 12, true);
}

#[test]
fn bdpt_disperses_by_snells_law() {
    check_algorithm(Algorithm::Bdpt, 1024, 6, true);
}

// The Metropolis samplers' images are as bright as the path tracer's and BDPT's whose
// paths they run (their brightness is checked sharply on the spectral furnace in
// `tests/spectral.rs` and on the Cornell scenes in `tests/metropolis.rs`); here their
// spectra's positions are checked as sharply as the others', their totals within the
// same 6 standard errors.

#[test]
fn pssmlt_disperses_by_snells_law() {
    check_algorithm(Algorithm::Pssmlt, 512, 6, false);
}

#[test]
fn mmlt_disperses_by_snells_law() {
    check_algorithm(Algorithm::Mmlt, 512, 6, false);
}

#[test]
fn pssmlt_bdpt_disperses_by_snells_law() {
    check_algorithm(Algorithm::PssmltBdpt, 256, 6, false);
}

// Path-space MLT's chains change wavelength by small steps with the perturbations and by
// fresh draws with bidirectional mutations (see `path_space`'s module documentation); their
// target is the luminance, so they visit the blue end, where the eye is least sensitive,
// rarely, and each render's blue total is noisy and skewed (a few renders in which a chain
// lingers in the blue hold much of it): 12 renders give its mean a usable spread.
#[test]
fn path_space_mlt_disperses_by_snells_law() {
    check_algorithm(Algorithm::PathSpaceMlt, 512, 12, false);
}

#[test]
fn erpt_disperses_by_snells_law() {
    check_algorithm(Algorithm::Erpt, 64, 6, false);
}
