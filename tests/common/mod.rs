//! Shared helpers of the integration tests: test scenes built in code and image statistics.
#![allow(dead_code)]

pub mod door_ajar;
pub mod door_ajar_reference;
pub mod generate;
pub mod lamp_behind_glass;
pub mod obj_text;
pub mod sky_spheres;
pub mod surfaces;
pub mod window_room;

use mlt::{Backend, Camera, Material, Scene, SceneDesc};

/// An icosphere of `radius` around the origin, subdivided `levels` times, with every
/// triangle's front (counter-clockwise) side facing the centre.
pub fn inward_icosphere(levels: u32, radius: f32) -> (Vec<f32>, Vec<u32>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut vertices: Vec<[f32; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoint = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut mid = |a: u32, b: u32, vertices: &mut Vec<[f32; 3]>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (vertices[a as usize], vertices[b as usize]);
                vertices.push([
                    (p[0] + q[0]) / 2.0,
                    (p[1] + q[1]) / 2.0,
                    (p[2] + q[2]) / 2.0,
                ]);
                vertices.len() as u32 - 1
            })
        };
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut vertices);
            let bc = mid(b, c, &mut vertices);
            let ca = mid(c, a, &mut vertices);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let positions = vertices
        .iter()
        .flat_map(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l * radius)
        })
        .collect();
    // The icosahedron above winds outward; reverse each face to face inward.
    let indices = faces.iter().flat_map(|&[a, b, c]| [a, c, b]).collect();
    (positions, indices)
}

/// The white furnace: a closed sphere whose inside is diffuse with `albedo` and emits `emission`.
pub fn furnace_scene(albedo: [f32; 3], emission: [f32; 3]) -> Scene {
    furnace_scene_of(Material::diffuse(albedo).with_emission(emission))
}

/// The furnace's sphere made of `material`.
pub fn furnace_scene_of(material: Material) -> Scene {
    let (positions, indices) = inward_icosphere(2, 1.0);
    let materials = [material];
    Scene::new(&SceneDesc {
        positions: &positions,
        indices: &indices,
        material_ids: &[],
        materials: &materials,
        lights: Default::default(),
        backend: Backend::Bvh,
        ..Default::default()
    })
    .unwrap()
}

/// A camera at the furnace's centre.
/// Radiance in the furnace with a depth limit: Le · Σ_{k ≤ depth} albedoᵏ per channel.
pub fn furnace_truth(albedo: [f32; 3], emission: [f32; 3], depth: u32) -> [f64; 3] {
    std::array::from_fn(|c| {
        let a = albedo[c] as f64;
        emission[c] as f64 * (0..=depth).map(|k| a.powi(k as i32)).sum::<f64>()
    })
}

/// Asserts `got` is within `sigmas` standard errors of `truth`, and that the check is sharp:
/// a ±2% error would land at least two more standard errors outside the tolerance, so it
/// fails whatever the noise did. `label` names the value in failure messages.
pub fn assert_within_and_sharp(
    label: &str,
    got: f64,
    truth: f64,
    standard_error: f64,
    sigmas: f64,
) {
    let tolerance = sigmas * standard_error;
    assert!(
        (got - truth).abs() <= tolerance,
        "{label}: {got} vs {truth} ± {tolerance}"
    );
    assert_sharp(label, truth, standard_error, sigmas);
}

/// Asserts that a comparison within `sigmas` standard errors of `truth` would fail a ±2% error
/// by at least two more standard errors.
pub fn assert_sharp(label: &str, truth: f64, standard_error: f64, sigmas: f64) {
    assert!(
        (sigmas + 2.0) * standard_error <= 0.02 * truth.abs(),
        "{label}: a 2% error would not reliably fail: {sigmas} + 2 standard errors of {standard_error} exceed 2% of {truth}"
    );
}

pub fn furnace_camera() -> Camera {
    Camera {
        eye: [0.0, 0.0, 0.0],
        target: [0.3, 0.2, 1.0],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 90.0,
        ..Camera::default()
    }
}

/// Per-channel mean of the pixels of an RGB image and the standard error of that mean,
/// treating pixels as independent samples (they are: each has its own random streams).
pub fn mean_and_standard_error(rgb: &[f32]) -> ([f64; 3], [f64; 3]) {
    let n = (rgb.len() / 3) as f64;
    let mut mean = [0.0; 3];
    let mut error = [0.0; 3];
    for c in 0..3 {
        let values = rgb.iter().skip(c).step_by(3).map(|&v| v as f64);
        let m = values.clone().sum::<f64>() / n;
        let var = values.map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
        mean[c] = m;
        error[c] = (var / n).sqrt();
    }
    (mean, error)
}

/// Luminance of a linear RGB mean (Rec. 709 weights, as `mlt::spectrum::Spectrum::luminance`).
pub fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Root-mean-square difference between two images of equal size.
pub fn rmse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum();
    (sum / a.len() as f64).sqrt()
}

/// Mean RGB of each cell of a `grid` × `grid` partition of the image, row-major.
pub fn region_means(rgb: &[f32], width: usize, height: usize, grid: usize) -> Vec<[f64; 3]> {
    let mut sums = vec![[0.0f64; 3]; grid * grid];
    let mut counts = vec![0usize; grid * grid];
    for y in 0..height {
        for x in 0..width {
            let cell = (y * grid / height) * grid + x * grid / width;
            let p = &rgb[(y * width + x) * 3..][..3];
            for c in 0..3 {
                sums[cell][c] += p[c] as f64;
            }
            counts[cell] += 1;
        }
    }
    sums.iter()
        .zip(&counts)
        .map(|(s, &n)| s.map(|v| v / n as f64))
        .collect()
}

/// An image estimated from several independent renders (different seeds), with the variance
/// of each float of the averaged image. Independent renders make the variance estimate valid
/// for any estimator, including ones whose pixels are correlated (Metropolis chains).
pub struct Estimate {
    pub width: usize,
    pub height: usize,
    pub image: Vec<f32>,
    /// Variance of each float of `image` (the variance of a mean over the renders).
    pub variance: Vec<f64>,
    /// The renders, kept when pixels of one render are correlated (Metropolis), so region
    /// variances come from the spread of whole-region means between renders.
    correlated_renders: Vec<Vec<f32>>,
}

impl Estimate {
    /// Averages `renders` (each a width × height RGB image from its own seed).
    pub fn from_renders(width: usize, height: usize, renders: &[Vec<f32>]) -> Self {
        let k = renders.len();
        assert!(
            k >= 2,
            "need at least two independent renders for a variance"
        );
        let n = width * height * 3;
        let mut image = vec![0.0f32; n];
        let mut variance = vec![0.0f64; n];
        for i in 0..n {
            let mean = renders.iter().map(|r| r[i] as f64).sum::<f64>() / k as f64;
            let var = renders
                .iter()
                .map(|r| (r[i] as f64 - mean).powi(2))
                .sum::<f64>()
                / (k - 1) as f64;
            image[i] = mean as f32;
            variance[i] = var / k as f64;
        }
        Estimate {
            width,
            height,
            image,
            variance,
            correlated_renders: Vec::new(),
        }
    }

    /// As `from_renders`, for estimators whose pixels are correlated within a render (Markov
    /// chains): variances of means over regions are then estimated from the spread of the
    /// region means between the independent renders.
    pub fn from_correlated_renders(width: usize, height: usize, renders: &[Vec<f32>]) -> Self {
        Estimate {
            correlated_renders: renders.to_vec(),
            ..Estimate::from_renders(width, height, renders)
        }
    }

    /// Mean RGB over the pixels of a rectangle and the variance of that mean.
    pub fn region(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> ([f64; 3], [f64; 3]) {
        if !self.correlated_renders.is_empty() {
            return self.region_between_renders(x0, y0, x1, y1);
        }
        let mut mean = [0.0; 3];
        let mut variance = [0.0; 3];
        let count = ((x1 - x0) * (y1 - y0)) as f64;
        for y in y0..y1 {
            for x in x0..x1 {
                for c in 0..3 {
                    let i = (y * self.width + x) * 3 + c;
                    mean[c] += self.image[i] as f64;
                    variance[c] += self.variance[i];
                }
            }
        }
        (
            mean.map(|m| m / count),
            variance.map(|v| v / (count * count)),
        )
    }

    fn region_between_renders(
        &self,
        x0: usize,
        y0: usize,
        x1: usize,
        y1: usize,
    ) -> ([f64; 3], [f64; 3]) {
        let k = self.correlated_renders.len() as f64;
        let count = ((x1 - x0) * (y1 - y0)) as f64;
        let means: Vec<[f64; 3]> = self
            .correlated_renders
            .iter()
            .map(|render| {
                let mut m = [0.0; 3];
                for y in y0..y1 {
                    for x in x0..x1 {
                        for (c, mc) in m.iter_mut().enumerate() {
                            *mc += render[(y * self.width + x) * 3 + c] as f64;
                        }
                    }
                }
                m.map(|v| v / count)
            })
            .collect();
        let mean: [f64; 3] = std::array::from_fn(|c| means.iter().map(|m| m[c]).sum::<f64>() / k);
        let variance = std::array::from_fn(|c| {
            means.iter().map(|m| (m[c] - mean[c]).powi(2)).sum::<f64>() / (k - 1.0) / k
        });
        (mean, variance)
    }

    /// Whole-image mean and its variance.
    pub fn mean(&self) -> ([f64; 3], [f64; 3]) {
        self.region(0, 0, self.width, self.height)
    }
}

/// An image estimate as `assert_estimates_agree` compares it: the image mean and the means
/// of the cells of a grid, each with its variance.
pub trait RegionEstimate {
    /// Pixels, for estimates made of them (`None`: resolution-free, a cached reference).
    fn pixels(&self) -> Option<(usize, usize)>;
    fn image_mean(&self) -> ([f64; 3], [f64; 3]);
    /// Cell (gx, gy) of a `grid` × `grid` partition.
    fn cell(&self, grid: usize, gx: usize, gy: usize) -> ([f64; 3], [f64; 3]);
}

impl RegionEstimate for Estimate {
    fn pixels(&self) -> Option<(usize, usize)> {
        Some((self.width, self.height))
    }

    fn image_mean(&self) -> ([f64; 3], [f64; 3]) {
        self.mean()
    }

    fn cell(&self, grid: usize, gx: usize, gy: usize) -> ([f64; 3], [f64; 3]) {
        let (w, h) = (self.width, self.height);
        self.region(
            gx * w / grid,
            gy * h / grid,
            (gx + 1) * w / grid,
            (gy + 1) * h / grid,
        )
    }
}

/// A converged reference kept as numbers (committed constants, made by a test that
/// regenerates them): the image mean and the cells of a `GRID` × `GRID` partition, each with
/// the variance of its estimate. With a box filter each is an integral over the film, the
/// same at any resolution whose size the grid divides.
pub struct CachedEstimate<const GRID: usize> {
    pub mean: [f64; 3],
    pub mean_variance: [f64; 3],
    /// Row by row.
    pub cells: [[[f64; 3]; GRID]; GRID],
    pub cell_variances: [[[f64; 3]; GRID]; GRID],
}

impl<const GRID: usize> CachedEstimate<GRID> {
    /// The numbers of `estimate` (whose size `GRID` must divide).
    pub fn of(estimate: &Estimate) -> Self {
        assert!(estimate.width.is_multiple_of(GRID) && estimate.height.is_multiple_of(GRID));
        let cells: [[([f64; 3], [f64; 3]); GRID]; GRID] =
            std::array::from_fn(|gy| std::array::from_fn(|gx| estimate.cell(GRID, gx, gy)));
        let (mean, mean_variance) = estimate.mean();
        CachedEstimate {
            mean,
            mean_variance,
            cells: cells.map(|row| row.map(|cell| cell.0)),
            cell_variances: cells.map(|row| row.map(|cell| cell.1)),
        }
    }
}

impl<const GRID: usize> RegionEstimate for CachedEstimate<GRID> {
    fn pixels(&self) -> Option<(usize, usize)> {
        None
    }

    fn image_mean(&self) -> ([f64; 3], [f64; 3]) {
        (self.mean, self.mean_variance)
    }

    fn cell(&self, grid: usize, gx: usize, gy: usize) -> ([f64; 3], [f64; 3]) {
        assert_eq!(
            grid, GRID,
            "the cached reference has a {GRID} × {GRID} grid"
        );
        (self.cells[gy][gx], self.cell_variances[gy][gx])
    }
}

/// A `size` × `size` path-traced image (max depth 5) with `spp` samples per pixel.
pub fn path_traced_image(
    scene: &Scene,
    camera: &Camera,
    size: u32,
    spp: u32,
    seed: u64,
) -> Vec<f32> {
    let settings = mlt::RenderSettings {
        width: size,
        height: size,
        algorithm: mlt::Algorithm::Path,
        samples_per_pixel: spp,
        max_depth: 5,
        seed,
        ..Default::default()
    };
    let mut image = vec![0.0; (size * size * 3) as usize];
    mlt::render(scene, camera, &settings, &mut image, None).unwrap();
    image
}

/// `path_traced_image` averaged over independent renders, one per seed.
pub fn path_traced_estimate(
    scene: &Scene,
    camera: &Camera,
    size: u32,
    spp: u32,
    seeds: std::ops::Range<u64>,
) -> Estimate {
    let renders: Vec<Vec<f32>> = seeds
        .map(|seed| path_traced_image(scene, camera, size, spp, seed))
        .collect();
    Estimate::from_renders(size as usize, size as usize, &renders)
}

/// Renders `settings` into a new image (the render must succeed).
pub fn render_image(scene: &Scene, camera: &Camera, settings: &mlt::RenderSettings) -> Vec<f32> {
    let mut image = vec![0.0; (settings.width * settings.height * 3) as usize];
    mlt::render(scene, camera, settings, &mut image, None).unwrap();
    image
}

/// An estimate computed once per test binary under `key`: the tests comparing against the
/// same reference share it (one asking while another computes it waits for that one).
pub fn cached_estimate(key: &str, compute: impl FnOnce() -> Estimate) -> &'static Estimate {
    type Slot = &'static std::sync::OnceLock<Estimate>;
    static SLOTS: std::sync::Mutex<Vec<(String, Slot)>> = std::sync::Mutex::new(Vec::new());
    let slot: Slot = {
        let mut slots = SLOTS.lock().unwrap();
        match slots.iter().find(|(k, _)| k == key) {
            Some(&(_, slot)) => slot,
            None => {
                let slot: Slot = Box::leak(Box::default());
                slots.push((key.to_owned(), slot));
                slot
            }
        }
    };
    slot.get_or_init(compute)
}

/// The path tracer's estimate of a canonical scene, the reference of the Metropolis and
/// ERPT tests on the Cornell scenes: 8 renders of 64 × 64 pixels at 256 samples.
pub fn path_reference(scene_name: &str) -> &'static Estimate {
    cached_estimate(&format!("path {scene_name}"), || {
        let (scene, camera) = load_canonical(scene_name);
        path_traced_estimate(&scene, &camera, 64, 256, 1000..1008)
    })
}

/// BDPT's estimate (16 renders of 64 × 64 pixels, max depth 5), the reference where the
/// path tracer is too slow to be sharp (the door-ajar scene, caustics): `tests/bdpt.rs`
/// checks BDPT against the path tracer.
pub fn bdpt_estimate(scene: &Scene, camera: &Camera, samples_per_pixel: u32) -> Estimate {
    let renders: Vec<Vec<f32>> = (1000..1016)
        .map(|seed| {
            let settings = mlt::RenderSettings {
                width: 64,
                height: 64,
                algorithm: mlt::Algorithm::Bdpt,
                samples_per_pixel,
                max_depth: 5,
                seed,
                ..Default::default()
            };
            render_image(scene, camera, &settings)
        })
        .collect();
    // Light-tracing splats correlate a render's pixels.
    Estimate::from_correlated_renders(64, 64, &renders)
}

/// Asserts that two independent estimates of the same image agree: the image mean within
/// `sigmas` combined standard errors and the mean of every cell of a `grid` × `grid`
/// partition within `region_sigmas`. Also asserts the comparison is sharp: a 2% brightness
/// error of the whole image would fail it (see `assert_sharp`). `label` names the comparison in
/// failure messages.
///
/// Choose the multiples for the number of comparisons (3 channels × (1 + grid²)) and how
/// the variances were estimated: per-pixel variances over many samples are near-exact, but a
/// variance from the spread of k whole renders (Markov chains) has k − 1 degrees of freedom
/// and Student's t tails; with 16 renders, |t| > 6 has probability 2·10⁻⁵ per comparison.
pub fn assert_estimates_agree(
    label: &str,
    test: &dyn RegionEstimate,
    reference: &dyn RegionEstimate,
    grid: usize,
    sigmas: f64,
    region_sigmas: f64,
) {
    if let (Some(a), Some(b)) = (test.pixels(), reference.pixels()) {
        assert_eq!(a, b);
    }
    let (tm, tv) = test.image_mean();
    let (rm, rv) = reference.image_mean();
    for c in 0..3 {
        let sigma = (tv[c] + rv[c]).sqrt();
        // For tuning a test's cost (shown with --nocapture): a 2% error fails only while
        // (sigmas + 2)·σ stays within 2% of the mean.
        eprintln!(
            "{label}: image mean channel {c}: {:+.2} σ, σ = {:.3}% (at most {:.3}%)",
            (tm[c] - rm[c]) / sigma,
            100.0 * sigma / rm[c],
            2.0 / (sigmas + 2.0)
        );
        let tolerance = sigmas * sigma;
        assert!(
            (tm[c] - rm[c]).abs() <= tolerance,
            "{label}: image mean channel {c} is {} but the reference is {} (tolerance {tolerance})",
            tm[c],
            rm[c]
        );
        assert_sharp(
            &format!("{label}: image mean channel {c}"),
            rm[c],
            (tv[c] + rv[c]).sqrt(),
            sigmas,
        );
    }
    assert_regions_agree(label, test, reference, grid, region_sigmas);
}

/// The region part of `assert_estimates_agree`: every cell of a `grid` × `grid` partition
/// within `region_sigmas` combined standard errors.
pub fn assert_regions_agree(
    label: &str,
    test: &dyn RegionEstimate,
    reference: &dyn RegionEstimate,
    grid: usize,
    region_sigmas: f64,
) {
    for gy in 0..grid {
        for gx in 0..grid {
            let (tm, tv) = test.cell(grid, gx, gy);
            let (rm, rv) = reference.cell(grid, gx, gy);
            for c in 0..3 {
                let tolerance = region_sigmas * (tv[c] + rv[c]).sqrt();
                assert!(
                    (tm[c] - rm[c]).abs() <= tolerance,
                    "{label}: region ({gx}, {gy}) channel {c} is {} but the reference is {} (tolerance {tolerance})",
                    tm[c],
                    rm[c]
                );
            }
        }
    }
}

/// A triangle scene as plain arrays, in file order, for tests that go through the C ABI.
pub struct Mesh {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
    pub material_ids: Vec<u32>,
    pub materials: Vec<Material>,
}

impl Mesh {
    pub fn rust_materials(&self) -> Vec<Material> {
        self.materials.clone()
    }

    pub fn c_materials(&self) -> Vec<mlt::capi::MltMaterial> {
        use mlt::capi::*;
        let slot = |r: Option<mlt::TextureRef>| match r {
            Some(r) => MltTextureRef {
                texture: r.texture as i32,
                offset: r.offset,
                rotation: r.rotation,
                scale: r.scale,
            },
            None => MltTextureRef {
                texture: MLT_NO_TEXTURE,
                offset: [0.0; 2],
                rotation: 0.0,
                scale: [1.0; 2],
            },
        };
        self.materials
            .iter()
            .map(|m| MltMaterial {
                struct_size: size_of::<MltMaterial>() as u32,
                kind: match m.kind {
                    mlt::MaterialKind::Diffuse => MLT_MATERIAL_DIFFUSE,
                    mlt::MaterialKind::Mirror => MLT_MATERIAL_MIRROR,
                    mlt::MaterialKind::Dielectric => MLT_MATERIAL_DIELECTRIC,
                    mlt::MaterialKind::MetallicRoughness => MLT_MATERIAL_METALLIC_ROUGHNESS,
                },
                color: m.color,
                emission: m.emission,
                ior: m.ior,
                metallic: m.metallic,
                roughness: m.roughness,
                transmission: m.transmission,
                alpha: m.alpha,
                alpha_mode: match m.alpha_mode {
                    mlt::AlphaMode::Opaque => MLT_ALPHA_OPAQUE,
                    mlt::AlphaMode::Mask => MLT_ALPHA_MASK,
                },
                alpha_cutoff: m.alpha_cutoff,
                base_color_texture: slot(m.base_color_texture),
                metallic_roughness_texture: slot(m.metallic_roughness_texture),
                normal_texture: slot(m.normal_texture),
                emission_texture: slot(m.emission_texture),
                normal_scale: m.normal_scale,
                energy_compensation: m.energy_compensation as u32,
                abbe_number: m.abbe_number,
            })
            .collect()
    }

    pub fn scene(&self) -> Scene {
        self.scene_with(Backend::Bvh)
    }

    pub fn scene_with(&self, backend: Backend) -> Scene {
        self.scene_lit(backend, Default::default())
    }

    /// The scene built with `backend` at `quality`.
    pub fn scene_built(&self, backend: Backend, quality: mlt::BuildQuality) -> Scene {
        self.build(backend, quality, Default::default())
    }

    /// The scene with lights besides its emissive triangles.
    pub fn scene_lit(&self, backend: Backend, lights: mlt::LightsDesc) -> Scene {
        self.build(backend, Default::default(), lights)
    }

    fn build(
        &self,
        backend: Backend,
        build_quality: mlt::BuildQuality,
        lights: mlt::LightsDesc,
    ) -> Scene {
        Scene::new(&SceneDesc {
            positions: &self.positions,
            indices: &self.indices,
            material_ids: &self.material_ids,
            materials: &self.materials,
            lights,
            backend,
            build_quality,
            ..Default::default()
        })
        .expect("a valid scene")
    }
}

pub fn scenes_dir() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes")
}

/// A canonical scene of tests/scenes (`NAME.obj` with its camera sidecar), built.
pub fn load_canonical(name: &str) -> (Scene, Camera) {
    (canonical_mesh(name).scene(), canonical_camera(name))
}

/// A canonical scene of tests/scenes (`NAME.obj`) as arrays.
pub fn canonical_mesh(name: &str) -> Mesh {
    let data = mlt::io::load_scene(&scenes_dir().join(format!("{name}.obj"))).expect("loads");
    Mesh {
        positions: data.positions,
        indices: data.indices,
        material_ids: data.material_ids,
        materials: data.materials,
    }
}

/// A canonical scene's camera (tests/scenes/NAME.camera.json).
pub fn canonical_camera(name: &str) -> Camera {
    mlt::io::load_camera_json(&scenes_dir().join(format!("{name}.camera.json")))
        .expect("loads")
        .camera
}

/// The canonical Cornell box (tests/scenes/cornell-box.obj) as arrays.
pub fn cornell_box() -> Mesh {
    canonical_mesh("cornell-box")
}

/// The Cornell box's camera (tests/scenes/cornell-box.camera.json).
pub fn cornell_camera() -> Camera {
    canonical_camera("cornell-box")
}

/// Per-channel mean of an RGB image.
pub fn mean(image: &[f32]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for pixel in image.chunks_exact(3) {
        for (s, &value) in sum.iter_mut().zip(pixel) {
            *s += value as f64;
        }
    }
    let n = (image.len() / 3).max(1) as f64;
    sum.map(|s| s / n)
}

/// The C (or C++) compiler the `cc` crate would use for this platform: honours CC / CXX and
/// friends. `cc` normally reads TARGET, HOST and OPT_LEVEL from a build script's environment;
/// here they are set explicitly. If cc cannot decide, fall back to `cc` / `c++` on PATH.
pub fn compiler(cpp: bool) -> std::process::Command {
    let triple = host_triple();
    let tool = triple.and_then(|t| {
        cc::Build::new()
            .cargo_metadata(false)
            .cargo_warnings(false)
            .emit_rerun_if_env_changed(false)
            .opt_level(0)
            .debug(false)
            .target(t)
            .host(t)
            .cpp(cpp)
            .try_get_compiler()
            .ok()
    });
    match tool {
        Some(tool) => tool.to_command(),
        None => std::process::Command::new(if cpp { "c++" } else { "cc" }),
    }
}

/// The target triple this test was compiled for, for the common platforms.
pub fn host_triple() -> Option<&'static str> {
    use std::env::consts::{ARCH, OS};
    let env_gnu = cfg!(target_env = "gnu");
    Some(match (ARCH, OS) {
        ("x86_64", "linux") if env_gnu => "x86_64-unknown-linux-gnu",
        ("aarch64", "linux") if env_gnu => "aarch64-unknown-linux-gnu",
        ("x86_64", "linux") => "x86_64-unknown-linux-musl",
        ("aarch64", "linux") => "aarch64-unknown-linux-musl",
        ("x86_64", "macos") => "x86_64-apple-darwin",
        ("aarch64", "macos") => "aarch64-apple-darwin",
        ("x86_64", "freebsd") => "x86_64-unknown-freebsd",
        _ => return None,
    })
}

/// The Cornell box open above: without its ceiling and its ceiling light, lit by `lights`
/// only (light from infinity gets in from above and through the open front). A camera
/// nearer than the canonical one sees the floor, the walls and some sky above them.
pub fn open_cornell_box(lights: mlt::LightsDesc) -> (Scene, Camera) {
    let mesh = canonical_mesh("cornell-box");
    let top = mesh
        .positions
        .chunks(3)
        .map(|p| p[1])
        .fold(f32::MIN, f32::max);
    let mut indices = Vec::new();
    let mut material_ids = Vec::new();
    for (triangle, &material) in mesh.indices.chunks(3).zip(&mesh.material_ids) {
        let high = triangle
            .iter()
            .all(|&v| mesh.positions[3 * v as usize + 1] >= top - 1.0);
        if high {
            continue;
        }
        indices.extend_from_slice(triangle);
        material_ids.push(material);
    }
    let scene = Scene::new(&mlt::SceneDesc {
        positions: &mesh.positions,
        indices: &indices,
        material_ids: &material_ids,
        materials: &mesh.materials,
        lights,
        backend: mlt::Backend::Bvh,
        ..Default::default()
    })
    .unwrap();
    let camera = Camera {
        eye: [278.0, 420.0, -500.0],
        target: [278.0, 330.0, 0.0],
        ..canonical_camera("cornell-box")
    };
    (scene, camera)
}

/// The lights of the open scenes of the path-space MLT and ERPT tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpenLights {
    /// A constant sky and a sun disc.
    SkyAndSun,
    /// A spot light inside the box and a directional light from above.
    SpotAndDirectional,
}

/// [`open_cornell_box`] with `lights`.
pub fn open_scene(lights: OpenLights) -> (Scene, Camera) {
    let sky = [0.5f32, 0.6, 0.8];
    let punctual = [
        mlt::PunctualLight::spot(
            [200.0, 500.0, 250.0],
            [0.3, -1.0, 0.2],
            [3.2e5, 2.4e5, 1.6e5],
            15.0,
            35.0,
        ),
        mlt::PunctualLight::directional([-0.4, -1.0, 0.3], [0.8, 0.8, 0.6]),
    ];
    open_cornell_box(match lights {
        OpenLights::SkyAndSun => mlt::LightsDesc {
            environment: Some(mlt::EnvironmentDesc::constant(&sky)),
            sun: Some(mlt::SunDesc::from_radiance(
                [0.4, 1.0, -0.5],
                3.0,
                [300.0, 270.0, 220.0],
            )),
            punctual: &[],
        },
        OpenLights::SpotAndDirectional => mlt::LightsDesc {
            punctual: &punctual,
            ..Default::default()
        },
    })
}

/// Image size and depth of the open-scene tests (small: they run in CI).
pub const OPEN_SIZE: u32 = 32;
pub const OPEN_MAX_DEPTH: u32 = 3;

/// The path tracer's estimate of an open scene: 8 renders of `OPEN_SIZE`² at 1024 samples.
pub fn open_reference(lights: OpenLights) -> &'static Estimate {
    cached_estimate(&format!("path open {lights:?}"), || {
        let (scene, camera) = open_scene(lights);
        let renders: Vec<Vec<f32>> = (2000..2008)
            .map(|seed| {
                let settings = mlt::RenderSettings {
                    width: OPEN_SIZE,
                    height: OPEN_SIZE,
                    algorithm: mlt::Algorithm::Path,
                    samples_per_pixel: 1024,
                    max_depth: OPEN_MAX_DEPTH,
                    seed,
                    ..Default::default()
                };
                render_image(&scene, &camera, &settings)
            })
            .collect();
        Estimate::from_renders(OPEN_SIZE as usize, OPEN_SIZE as usize, &renders)
    })
}
