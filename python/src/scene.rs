//! `mlt.Scene`: a validated scene with its acceleration structure, built from arrays or
//! loaded from a file. Immutable, so any number of renders (from any threads) share it.

use crate::arrays;
use crate::convert::{self, OwnedLights};
use crate::errors::{self, invalid};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyFileNotFoundError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A scene: triangles, their materials and the lights, validated, with the ray-query
/// structure built. Make one with `Scene.from_arrays` or `Scene.load`; it cannot change,
/// and renders from several threads may share it.
#[pyclass(module = "mlt._mlt", frozen)]
pub struct Scene {
    pub(crate) scene: mlt::Scene,
}

/// Facts about a built scene.
#[pyclass(module = "mlt._mlt", frozen, get_all)]
pub struct SceneInfo {
    /// Triangles given, degenerate ones included.
    triangle_count: usize,
    /// Triangles of zero area (or a non-finite normal): never hit, never emit.
    degenerate_triangle_count: usize,
    /// Non-degenerate emissive triangles: the area lights.
    emitter_count: usize,
    bounds_min: (f32, f32, f32),
    bounds_max: (f32, f32, f32),
    /// The build quality: "fast", "medium" or "high".
    build_quality: &'static str,
    /// Bytes the acceleration structure holds.
    accel_memory_bytes: usize,
    /// Seconds its build took.
    accel_build_seconds: f64,
}

#[pymethods]
impl SceneInfo {
    fn __repr__(&self) -> String {
        format!(
            "SceneInfo(triangle_count={}, degenerate_triangle_count={}, emitter_count={}, bounds_min={:?}, bounds_max={:?}, build_quality={:?}, accel_memory_bytes={}, accel_build_seconds={})",
            self.triangle_count,
            self.degenerate_triangle_count,
            self.emitter_count,
            self.bounds_min,
            self.bounds_max,
            self.build_quality,
            self.accel_memory_bytes,
            self.accel_build_seconds
        )
    }
}

/// What `SceneDesc` borrows, owned: the arrays copied out of Python, so the scene is built
/// without the GIL.
#[derive(Default)]
struct OwnedDesc {
    positions: Vec<f32>,
    indices: Vec<u32>,
    material_ids: Vec<u32>,
    materials: Vec<mlt::Material>,
    normals: Vec<f32>,
    texcoords: Vec<f32>,
    texcoords1: Vec<f32>,
    tangents: Vec<f32>,
    colors: Vec<f32>,
    textures: Vec<mlt::TextureDesc<'static>>,
}

impl OwnedDesc {
    fn desc<'a>(
        &'a self,
        lights: &'a OwnedLights,
        backend: mlt::Backend,
        build_quality: mlt::BuildQuality,
    ) -> mlt::SceneDesc<'a> {
        mlt::SceneDesc {
            positions: &self.positions,
            indices: &self.indices,
            material_ids: &self.material_ids,
            materials: &self.materials,
            lights: lights.desc(),
            backend,
            build_quality,
            normals: &self.normals,
            texcoords: &self.texcoords,
            texcoords1: &self.texcoords1,
            tangents: &self.tangents,
            colors: &self.colors,
            textures: &self.textures,
        }
    }
}

/// Builds the scene with the GIL released (a large mesh's BVH takes seconds).
fn build(py: Python<'_>, desc: &mlt::SceneDesc) -> Result<mlt::Scene, mlt::Error> {
    py.detach(|| mlt::Scene::new(desc))
}

#[pymethods]
impl Scene {
    /// Builds a scene from arrays.
    ///
    /// positions: (N, 3) vertex coordinates (float32, or numbers convertible to it).
    /// indices: (M, 3) vertex indices per triangle, counter-clockwise seen from the front
    /// (integers, converted to uint32).
    /// materials: `Material`s (or dicts of their fields); default one 0.8 grey diffuse.
    /// material_ids: (M,) index into `materials` per triangle; default material 0.
    /// normals (N, 3), texcoords (N, 2), texcoords1 (N, 2), tangents (N, 4), colors (N, 4) or
    /// (N, 3): optional per-vertex shading normals, texture coordinates (glTF's convention:
    /// (0, 0) is the image's top-left) and a second set of them (for `TextureRef`s whose
    /// `texcoord` is 1), tangents for normal maps, linear RGB(A) colours.
    /// textures: `Texture`s the materials refer to.
    /// environment, sun, lights: an `Environment`, a `Sun`, and `PunctualLight`s.
    /// backend: "bvh" (default) or "embree" (only in builds with the feature).
    /// build_quality: "high" (default: the acceleration structure that renders fastest),
    /// "medium" or "fast" (the quickest build, for scenes rebuilt often; slower rays).
    ///
    /// Raises `InvalidArgumentError` (a `ValueError`) naming the array and element at fault:
    /// a wrong shape or dtype, a non-finite coordinate, an index out of range.
    #[staticmethod]
    #[pyo3(signature = (positions, indices, materials=None, material_ids=None, *, normals=None, texcoords=None, texcoords1=None, tangents=None, colors=None, textures=None, environment=None, sun=None, lights=None, backend="bvh", build_quality="high"))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        py: Python<'_>,
        positions: &Bound<'_, PyAny>,
        indices: &Bound<'_, PyAny>,
        materials: Option<&Bound<'_, PyAny>>,
        material_ids: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
        texcoords: Option<&Bound<'_, PyAny>>,
        texcoords1: Option<&Bound<'_, PyAny>>,
        tangents: Option<&Bound<'_, PyAny>>,
        colors: Option<&Bound<'_, PyAny>>,
        textures: Option<&Bound<'_, PyAny>>,
        environment: Option<&Bound<'_, PyAny>>,
        sun: Option<&Bound<'_, PyAny>>,
        lights: Option<&Bound<'_, PyAny>>,
        backend: &str,
        build_quality: &str,
    ) -> PyResult<Scene> {
        let backend = convert::backend(py, backend)?;
        let build_quality = convert::build_quality(py, build_quality)?;
        let materials = match materials {
            Some(materials) => materials
                .try_iter()?
                .enumerate()
                .map(|(i, m)| convert::material(&m?, i))
                .collect::<PyResult<Vec<_>>>()?,
            None => vec![mlt::Material::diffuse([0.8; 3])],
        };
        let colors = match colors {
            Some(colors) => rgba(colors)?,
            None => Vec::new(),
        };
        let textures = match textures {
            Some(textures) => textures
                .try_iter()?
                .enumerate()
                .map(|(i, t)| convert::texture(&t?, i))
                .collect::<PyResult<Vec<_>>>()?,
            None => Vec::new(),
        };
        let owned = OwnedDesc {
            positions: arrays::rows_f32(positions, "positions", 3)?,
            indices: arrays::triangles_u32(indices, "indices")?,
            material_ids: material_ids.map_or(Ok(Vec::new()), |ids| {
                arrays::vector_u32(ids, "material_ids")
            })?,
            materials,
            normals: convert::vertex_rows(normals, "normals", 3)?,
            texcoords: convert::vertex_rows(texcoords, "texcoords", 2)?,
            texcoords1: convert::vertex_rows(texcoords1, "texcoords1", 2)?,
            tangents: convert::vertex_rows(tangents, "tangents", 4)?,
            colors,
            textures,
        };
        let lights = OwnedLights::extract(environment, sun, lights)?;
        let scene = build(py, &owned.desc(&lights, backend, build_quality))
            .map_err(|e| errors::from_mlt(py, &e))?;
        Ok(Scene { scene })
    }

    /// Loads a scene file the way `mlt-render` does: Wavefront OBJ (with its MTL files, and
    /// `NAME.camera.json` beside `NAME.obj` if present) or glTF 2.0 (`.gltf`, `.glb`).
    ///
    /// Returns `(scene, camera)`: the camera the file defines (the OBJ's sidecar or the
    /// glTF's first perspective camera), or None (`Scene.framing_camera` then frames it as
    /// `mlt-render` does). environment, sun and lights add lights as in `from_arrays` (a
    /// glTF's own punctual lights are kept); energy_compensation sets every material's
    /// (`--energy-compensation`); abbe_number gives every transmissive material without a
    /// dispersion this Abbe number (`--abbe-number`); variant picks a glTF file's material
    /// variant by name (`KHR_materials_variants`, `--variant`; None: the default materials).
    ///
    /// Raises FileNotFoundError for a missing file and `LoadError` for one that cannot be
    /// read, or for a variant the file does not have (the message lists its variants).
    #[staticmethod]
    #[pyo3(signature = (path, *, environment=None, sun=None, lights=None, energy_compensation=false, abbe_number=None, backend="bvh", build_quality="high", variant=None))]
    #[allow(clippy::too_many_arguments)]
    fn load<'py>(
        py: Python<'py>,
        path: PathBuf,
        environment: Option<&Bound<'py, PyAny>>,
        sun: Option<&Bound<'py, PyAny>>,
        lights: Option<&Bound<'py, PyAny>>,
        energy_compensation: bool,
        abbe_number: Option<f32>,
        backend: &str,
        build_quality: &str,
        variant: Option<String>,
    ) -> PyResult<(Scene, Option<Bound<'py, PyAny>>)> {
        let backend = convert::backend(py, backend)?;
        let build_quality = convert::build_quality(py, build_quality)?;
        if !path.exists() {
            return Err(PyFileNotFoundError::new_err((
                2,
                format!("scene file {} does not exist", path.display()),
                path.display().to_string(),
            )));
        }
        let mut lights = OwnedLights::extract(environment, sun, lights)?;
        let mut data = py
            .detach(|| mlt::io::load_scene_variant(&path, variant.as_deref()))
            .map_err(|e| errors::load_error(py, &e.message))?;
        data.override_materials(energy_compensation, abbe_number);
        // The file's punctual lights first, so their indices in errors are the file's.
        let mut punctual = std::mem::take(&mut data.punctual_lights);
        punctual.append(&mut lights.punctual);
        lights.punctual = punctual;
        let mut desc = data.desc(backend);
        desc.build_quality = build_quality;
        desc.lights = lights.desc();
        let scene = build(py, &desc).map_err(|e| {
            let message = data.describe_error(&e);
            let message = format!("cannot build the scene from {}: {message}", path.display());
            errors::from_mlt(py, &mlt::Error::new(e.status, message))
        })?;
        let camera = data
            .camera
            .map(|file| convert::camera_to_py(py, &file.camera))
            .transpose()?;
        Ok((Scene { scene }, camera))
    }

    /// Triangle and emitter counts, the bounding box, and the acceleration structure's build
    /// quality, memory and build time.
    #[getter]
    fn info(&self) -> SceneInfo {
        let info = self.scene.info();
        let tuple = |v: [f32; 3]| (v[0], v[1], v[2]);
        SceneInfo {
            triangle_count: info.triangle_count,
            degenerate_triangle_count: info.degenerate_triangle_count,
            emitter_count: info.emitter_count,
            bounds_min: tuple(info.bounds_min),
            bounds_max: tuple(info.bounds_max),
            build_quality: convert::BUILD_QUALITIES
                .iter()
                .find(|(_, q)| *q == info.build_quality)
                .map_or("high", |(name, _)| name),
            accel_memory_bytes: info.accel_memory_bytes,
            accel_build_seconds: info.accel_build_seconds,
        }
    }

    /// The camera `mlt-render` frames a scene without one with: from the front (+Z) and a
    /// little above, looking at the bounding box's centre with a 40 degree field of view.
    fn framing_camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let info = self.scene.info();
        let file = mlt::io::CameraFile::framing(info.bounds_min, info.bounds_max);
        convert::camera_to_py(py, &file.camera)
    }

    fn __repr__(&self) -> String {
        let info = self.scene.info();
        format!(
            "<mlt.Scene: {} triangles, {} emitters>",
            info.triangle_count, info.emitter_count
        )
    }
}

/// Per-vertex colours of 3 or 4 channels, as RGBA.
fn rgba(colors: &Bound<'_, PyAny>) -> PyResult<Vec<f32>> {
    let py = colors.py();
    let array = arrays::Array::new(colors, "colors")?;
    let columns = match array.shape[..] {
        [_, c @ (3 | 4)] => c,
        [0] => 4,
        _ => {
            return Err(invalid(
                py,
                &format!(
                    "colors has shape {}; expected (N, 4) RGBA or (N, 3) RGB per vertex",
                    array.shape_text()
                ),
            ));
        }
    };
    let values = array.to_f32("colors")?;
    if columns == 4 {
        return Ok(values);
    }
    // Opaque: alpha 1.
    Ok(values
        .chunks_exact(3)
        .flat_map(|c| [c[0], c[1], c[2], 1.0])
        .collect())
}

/// Reads an environment map (`.hdr` or `.exr`) as a float32 array of shape
/// (height, width, 3): linear RGB radiance, rows from the top.
#[pyfunction]
pub fn load_environment<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    if !path.exists() {
        return Err(PyFileNotFoundError::new_err((
            2,
            format!("environment file {} does not exist", path.display()),
            path.display().to_string(),
        )));
    }
    let (pixels, width, height) = py
        .detach(|| mlt::io::load_environment(&path))
        .map_err(|e| errors::load_error(py, &e.message))?;
    Ok(PyArray1::from_vec(py, pixels)
        .reshape([height as usize, width as usize, 3])?
        .into_any())
}
