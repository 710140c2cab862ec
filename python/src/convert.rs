//! The value types (`mlt/_types.py`'s dataclasses, or any object with their attributes)
//! to and from the Rust structs. Only conversions here: the Rust API validates values.

use crate::arrays::{self, Array};
use crate::errors::{invalid, with_context};
use mlt::params::{ChoiceParameter, Kind, Parameters, Value};
use mlt::{
    Algorithm, Backend, BuildQuality, Camera, Material, PunctualLight, PunctualLightKind,
    RenderSettings, SunDesc, TexelData, TextureDesc, TextureEncoding, TextureFilter, TextureRef,
    WrapMode,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyType};
use std::borrow::Cow;

/// The attribute `name` of `obj` (an instance of the value type `owner`), its conversion
/// error naming `owner.name`.
fn field<'py, T: FromPyObjectOwned<'py>>(
    obj: &Bound<'py, PyAny>,
    owner: &str,
    name: &str,
) -> PyResult<T> {
    let py = obj.py();
    // A missing attribute means the object is not of the type asked for.
    let value = obj.getattr(name).map_err(|_| {
        let class = obj
            .get_type()
            .name()
            .map_or_else(|_| "?".to_owned(), |n| n.to_string());
        PyTypeError::new_err(format!(
            "{owner} has no field {name}: expected an mlt value type, got {class}"
        ))
    })?;
    value
        .extract::<T>()
        .map_err(|e| with_context(py, e.into(), &format!("{owner}.{name}")))
}

/// A string field (an enumeration's name).
fn name_field(obj: &Bound<'_, PyAny>, owner: &str, name: &str) -> PyResult<String> {
    field::<String>(obj, owner, name)
}

/// `value` as one of `choices` (`(name, value)`), or an error listing them. Case, and `-`
/// against `_`, do not matter (`"pssmlt_bdpt"` is `"pssmlt-bdpt"`, `"Metallic-Roughness"`
/// is `"metallic_roughness"`).
fn choose<T: Copy>(
    py: Python<'_>,
    owner: &str,
    name: &str,
    value: &str,
    choices: &[(&str, T)],
) -> PyResult<T> {
    choices
        .iter()
        .find(|(n, _)| same_name(n, value))
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let names: Vec<String> = choices.iter().map(|(n, _)| format!("{n:?}")).collect();
            invalid(
                py,
                &format!(
                    "{owner}.{name} is {value:?}; expected one of {}",
                    names.join(", ")
                ),
            )
        })
}

fn same_name(a: &str, b: &str) -> bool {
    let canonical = |c: char| match c {
        '-' => '_',
        c => c.to_ascii_lowercase(),
    };
    a.len() == b.len() && a.chars().map(canonical).eq(b.chars().map(canonical))
}

const BACKENDS: [(&str, Backend); 2] = [("bvh", Backend::Bvh), ("embree", Backend::Embree)];

pub fn backend(py: Python<'_>, name: &str) -> PyResult<Backend> {
    choose(py, "Scene", "backend", name, &BACKENDS)
}

pub const BUILD_QUALITIES: [(&str, BuildQuality); 3] = [
    ("fast", BuildQuality::Fast),
    ("medium", BuildQuality::Medium),
    ("high", BuildQuality::High),
];

pub fn build_quality(py: Python<'_>, name: &str) -> PyResult<BuildQuality> {
    choose(py, "Scene", "build_quality", name, &BUILD_QUALITIES)
}

pub fn camera(obj: &Bound<'_, PyAny>) -> PyResult<Camera> {
    let owner = "Camera";
    Ok(Camera {
        eye: field(obj, owner, "eye")?,
        target: field(obj, owner, "target")?,
        up: field(obj, owner, "up")?,
        fov_y_deg: field(obj, owner, "fov_y_deg")?,
        lens_radius: field(obj, owner, "lens_radius")?,
        focus_distance: field(obj, owner, "focus_distance")?,
    })
}

/// The settings of `obj`, one attribute per declared setting (`mlt::params`): a value of
/// the wrong type or out of range is refused with the message every front end gives.
pub fn settings(obj: &Bound<'_, PyAny>) -> PyResult<RenderSettings> {
    parameters(obj, "RenderSettings")
}

/// The struct of parameters `S` read from `obj`, one attribute per declared parameter
/// (`mlt::params`), `owner` naming it in messages. What the type cannot hold is refused
/// here; the ranges are checked by Rust's validation.
fn parameters<S: Parameters>(obj: &Bound<'_, PyAny>, owner: &str) -> PyResult<S> {
    let py = obj.py();
    let mut values = S::default();
    for p in S::parameters() {
        let name = p.name;
        let value = match p.kind {
            Kind::U32 | Kind::U64 => Value::Int(field::<i128>(obj, owner, name)?),
            Kind::F32 | Kind::F64 => Value::Float(field::<f64>(obj, owner, name)?),
            Kind::Bool => Value::Bool(field::<bool>(obj, owner, name)?),
            Kind::F32x3 => Value::Vec3(field::<[f32; 3]>(obj, owner, name)?),
            Kind::F32x4 => Value::Floats(field::<[f32; 4]>(obj, owner, name)?),
            Kind::Texture => Value::Texture(texture_ref(obj, owner, name)?),
            Kind::Choice(choices) => {
                let given = name_field(obj, owner, name)?;
                let choice = choices
                    .names
                    .iter()
                    .find(|n| same_name(n, &given))
                    .ok_or_else(|| {
                        let names: Vec<String> =
                            choices.names.iter().map(|n| format!("{n:?}")).collect();
                        invalid(
                            py,
                            &format!(
                                "{owner}.{name} is {given:?}; expected one of {}",
                                names.join(", ")
                            ),
                        )
                    })?;
                Value::Choice(choice)
            }
        };
        values
            .set(name, value)
            .map_err(|e| crate::errors::from_mlt(py, &e))?;
    }
    Ok(values)
}

/// The Python float that prints as `value` does (0.3f32 as 0.3, not 0.30000001192092896),
/// so values read back from Rust compare equal to the ones given; it converts back to the
/// same f32.
fn shortest(value: f32) -> f64 {
    value.to_string().parse().unwrap_or(f64::from(value))
}

/// The Python name of an algorithm (`mlt.Algorithm`'s value).
pub fn algorithm_name(algorithm: Algorithm) -> &'static str {
    algorithm.name()
}

static SETTINGS_CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// A parameter's value as the Python dataclasses (`mlt.RenderSettings`, `mlt.Material`)
/// hold it.
pub fn value_to_py<'py>(py: Python<'py>, kind: Kind, value: Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match (kind, value) {
        (_, Value::Int(v)) => v.into_pyobject(py)?.into_any(),
        (Kind::F32, Value::Float(v)) => shortest(v as f32).into_pyobject(py)?.into_any(),
        (_, Value::Float(v)) => v.into_pyobject(py)?.into_any(),
        (_, Value::Bool(v)) => v.into_pyobject(py)?.to_owned().into_any(),
        (_, Value::Vec3(v)) => {
            let [a, b, c] = v.map(shortest);
            (a, b, c).into_pyobject(py)?.into_any()
        }
        (_, Value::Floats(v)) => {
            let [a, b, c, d] = v.map(shortest);
            (a, b, c, d).into_pyobject(py)?.into_any()
        }
        (_, Value::Texture(None)) => py.None().into_bound(py),
        (_, Value::Texture(Some(t))) => TEXTURE_REF_CLASS
            .import(py, "mlt._types", "TextureRef")?
            .call1((
            t.texture,
            shortest_pair(t.offset),
            t.rotation,
            shortest_pair(t.scale),
        ))?,
        (Kind::Choice(choices), Value::Choice(name)) if choices.type_name == "Algorithm" => {
            ALGORITHM_CLASS
                .import(py, "mlt._types", "Algorithm")?
                .call1((name,))?
        }
        (_, Value::Choice(name)) => name.into_pyobject(py)?.into_any(),
    })
}
static TEXTURE_REF_CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn shortest_pair(v: [f32; 2]) -> (f64, f64) {
    (shortest(v[0]), shortest(v[1]))
}
static ALGORITHM_CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// An `mlt.RenderSettings`, the inverse of `settings`.
pub fn settings_to_py<'py>(
    py: Python<'py>,
    settings: &RenderSettings,
) -> PyResult<Bound<'py, PyAny>> {
    let kwargs = PyDict::new(py);
    for p in RenderSettings::parameters() {
        let value = settings.get(p.name).expect("a declared setting");
        kwargs.set_item(p.name, value_to_py(py, p.kind, value)?)?;
    }
    SETTINGS_CLASS
        .import(py, "mlt._types", "RenderSettings")?
        .call((), Some(&kwargs))
}

static MATERIAL_CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// A material: an `mlt.Material` (or an object with its attributes), or a dict of its
/// fields (`{"kind": "diffuse", "color": (1, 0, 0)}`; unknown keys are an error), one
/// attribute per declared material parameter.
pub fn material(obj: &Bound<'_, PyAny>, index: usize) -> PyResult<Material> {
    let py = obj.py();
    let owner = format!("materials[{index}]");
    let owned;
    let obj = match obj.cast::<PyDict>() {
        Ok(dict) => {
            let class = MATERIAL_CLASS.import(py, "mlt._types", "Material")?;
            owned = class
                .call((), Some(dict))
                .map_err(|e| with_context(py, e, &owner))?;
            &owned
        }
        Err(_) => obj,
    };
    parameters(obj, &owner)
}

fn texture_ref(obj: &Bound<'_, PyAny>, owner: &str, name: &str) -> PyResult<Option<TextureRef>> {
    let value: Option<Bound<PyAny>> = field(obj, owner, name)?;
    let Some(value) = value else {
        return Ok(None);
    };
    let owner = format!("{owner}.{name}");
    Ok(Some(TextureRef {
        texture: field(&value, &owner, "texture")?,
        texcoord: field(&value, &owner, "texcoord")?,
        offset: field(&value, &owner, "offset")?,
        rotation: field(&value, &owner, "rotation")?,
        scale: field(&value, &owner, "scale")?,
    }))
}

/// A texture's description with its texels copied.
pub fn texture(obj: &Bound<'_, PyAny>, index: usize) -> PyResult<TextureDesc<'static>> {
    let py = obj.py();
    let owner = format!("textures[{index}]");
    let data_name = format!("{owner}.data");
    let data = Array::new(&obj.getattr("data")?, &data_name)?;
    let (height, width, channels) = match data.shape[..] {
        [h, w] => (h, w, 1),
        [h, w, c] => (h, w, c),
        _ => {
            return Err(invalid(
                py,
                &format!(
                    "{data_name} has shape {}; expected (height, width) or (height, width, channels)",
                    data.shape_text()
                ),
            ));
        }
    };
    let side = |n: usize, what: &str| {
        u32::try_from(n).map_err(|_| invalid(py, &format!("{data_name} is {n} texels {what}")))
    };
    let texels = match data.to_u8()? {
        Some(bytes) => TexelData::U8(Cow::Owned(bytes)),
        None => TexelData::F32(Cow::Owned(data.to_f32(&data_name)?)),
    };
    let owner = owner.as_str();
    let wrap = |name: &str| -> PyResult<WrapMode> {
        let value = name_field(obj, owner, name)?;
        choose(
            py,
            owner,
            name,
            &value,
            &[
                ("repeat", WrapMode::Repeat),
                ("clamp_to_edge", WrapMode::ClampToEdge),
                ("mirrored_repeat", WrapMode::MirroredRepeat),
            ],
        )
    };
    let encoding = name_field(obj, owner, "encoding")?;
    let filter = name_field(obj, owner, "filter")?;
    Ok(TextureDesc {
        width: side(width, "wide")?,
        height: side(height, "high")?,
        channels: side(channels, "deep")?,
        data: texels,
        encoding: choose(
            py,
            owner,
            "encoding",
            &encoding,
            &[
                ("srgb", TextureEncoding::Srgb),
                ("linear", TextureEncoding::Linear),
            ],
        )?,
        wrap_u: wrap("wrap_u")?,
        wrap_v: wrap("wrap_v")?,
        filter: choose(
            py,
            owner,
            "filter",
            &filter,
            &[
                ("bilinear", TextureFilter::Bilinear),
                ("nearest", TextureFilter::Nearest),
            ],
        )?,
    })
}

pub fn sun(obj: &Bound<'_, PyAny>) -> PyResult<SunDesc> {
    let owner = "Sun";
    Ok(SunDesc {
        direction: field(obj, owner, "direction")?,
        angular_radius_degrees: field(obj, owner, "angular_radius_degrees")?,
        irradiance: field(obj, owner, "irradiance")?,
    })
}

pub fn punctual_light(obj: &Bound<'_, PyAny>, index: usize) -> PyResult<PunctualLight> {
    let owner = format!("lights[{index}]");
    let owner = owner.as_str();
    let kind = name_field(obj, owner, "kind")?;
    Ok(PunctualLight {
        kind: choose(
            obj.py(),
            owner,
            "kind",
            &kind,
            &[
                ("point", PunctualLightKind::Point),
                ("spot", PunctualLightKind::Spot),
                ("directional", PunctualLightKind::Directional),
            ],
        )?,
        position: field(obj, owner, "position")?,
        direction: field(obj, owner, "direction")?,
        intensity: field(obj, owner, "intensity")?,
        inner_cone_degrees: field(obj, owner, "inner_cone_degrees")?,
        outer_cone_degrees: field(obj, owner, "outer_cone_degrees")?,
    })
}

/// An environment's texels (flat RGB), width, height, rotation and scale.
pub struct OwnedEnvironment {
    pub pixels: Vec<f32>,
    pub width: u32,
    pub height: u32,
    pub rotation_degrees: f32,
    pub scale: f32,
}

pub fn environment(obj: &Bound<'_, PyAny>) -> PyResult<OwnedEnvironment> {
    let py = obj.py();
    let name = "Environment.pixels";
    let pixels = Array::new(&obj.getattr("pixels")?, name)?;
    pixels.check_shape(
        name,
        &[None, None, Some(3)],
        "(height, width, 3): RGB texels",
    )?;
    let side = |n: usize| {
        u32::try_from(n).map_err(|_| invalid(py, &format!("{name} has {n} texels on a side")))
    };
    let (height, width) = match pixels.shape[..] {
        [h, w, _] => (side(h)?, side(w)?),
        _ => (0, 0), // Empty: the Rust API names the size.
    };
    Ok(OwnedEnvironment {
        pixels: pixels.to_f32(name)?,
        width,
        height,
        rotation_degrees: field(obj, "Environment", "rotation_degrees")?,
        scale: field(obj, "Environment", "scale")?,
    })
}

/// The lights besides emissive triangles, owned, to lend to a `SceneDesc`.
#[derive(Default)]
pub struct OwnedLights {
    pub environment: Option<OwnedEnvironment>,
    pub sun: Option<SunDesc>,
    pub punctual: Vec<PunctualLight>,
}

impl OwnedLights {
    pub fn extract(
        environment: Option<&Bound<'_, PyAny>>,
        sun: Option<&Bound<'_, PyAny>>,
        lights: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let punctual = match lights {
            Some(lights) => lights
                .try_iter()?
                .enumerate()
                .map(|(i, light)| punctual_light(&light?, i))
                .collect::<PyResult<_>>()?,
            None => Vec::new(),
        };
        Ok(OwnedLights {
            environment: environment.map(self::environment).transpose()?,
            sun: sun.map(self::sun).transpose()?,
            punctual,
        })
    }

    pub fn desc(&self) -> mlt::LightsDesc<'_> {
        mlt::LightsDesc {
            environment: self.environment.as_ref().map(|e| mlt::EnvironmentDesc {
                pixels: &e.pixels,
                width: e.width,
                height: e.height,
                rotation_degrees: e.rotation_degrees,
                scale: e.scale,
            }),
            sun: self.sun,
            punctual: &self.punctual,
        }
    }
}

/// An optional per-vertex array of `columns` floats (`None`: empty).
pub fn vertex_rows(
    obj: Option<&Bound<'_, PyAny>>,
    name: &str,
    columns: usize,
) -> PyResult<Vec<f32>> {
    obj.map_or(Ok(Vec::new()), |obj| arrays::rows_f32(obj, name, columns))
}

static CAMERA_CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// An `mlt.Camera`.
pub fn camera_to_py<'py>(py: Python<'py>, camera: &Camera) -> PyResult<Bound<'py, PyAny>> {
    // Tuples, as the dataclass declares (arrays would convert to lists).
    let tuple = |v: [f32; 3]| (shortest(v[0]), shortest(v[1]), shortest(v[2]));
    let kwargs = PyDict::new(py);
    kwargs.set_item("eye", tuple(camera.eye))?;
    kwargs.set_item("target", tuple(camera.target))?;
    kwargs.set_item("up", tuple(camera.up))?;
    kwargs.set_item("fov_y_deg", shortest(camera.fov_y_deg))?;
    kwargs.set_item("lens_radius", shortest(camera.lens_radius))?;
    kwargs.set_item("focus_distance", shortest(camera.focus_distance))?;
    CAMERA_CLASS
        .import(py, "mlt._types", "Camera")?
        .call((), Some(&kwargs))
}
