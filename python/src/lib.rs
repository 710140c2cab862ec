//! `mlt._mlt`: the Python extension of mlt, wrapping the crate's public Rust API. The
//! package `mlt` (`mlt/__init__.py`) re-exports it with the value types of `mlt/_types.py`
//! (dataclasses the conversions here read by attribute) and the exceptions of
//! `mlt/_errors.py`.
//!
//! Layout: `scene` (Scene, loaders), `render` (render, the GIL-free progress and cancel
//! plumbing any long call can reuse, stats), `jobs` (plan, render_job, merge), `convert` (value types to Rust structs),
//! `arrays` (array-likes in), `errors` (mlt's errors as exceptions).

mod arrays;
mod convert;
mod errors;
mod jobs;
mod render;
mod scene;

use pyo3::prelude::*;

/// Which of the value types' defaults differ from the Rust crate's: `(name, python, rust)`
/// for each one that does (none, if the dataclasses are in step). `settings`, `camera` and
/// `material` are default-constructed `RenderSettings`, `Camera` and `Material`.
#[pyfunction]
fn _defaults_mismatches(
    settings: &Bound<'_, PyAny>,
    camera: &Bound<'_, PyAny>,
    material: &Bound<'_, PyAny>,
) -> PyResult<Vec<(String, String, String)>> {
    let mut mismatches = Vec::new();
    let mut check = |name: &str, python: String, rust: String| {
        if python != rust {
            mismatches.push((name.to_owned(), python, rust));
        }
    };
    check(
        "RenderSettings",
        format!("{:?}", convert::settings(settings)?),
        format!("{:?}", mlt::RenderSettings::default()),
    );
    check(
        "Camera",
        format!("{:?}", convert::camera(camera)?),
        format!("{:?}", mlt::Camera::default()),
    );
    check(
        "Material",
        format!("{:?}", convert::material(material, 0)?),
        format!("{:?}", mlt::Material::default()),
    );
    Ok(mismatches)
}

/// Every declared render setting as `(name, default, a value outside its range or None,
/// the message that value gets)`: what `tests/test_parameters.py` checks `mlt.RenderSettings`
/// against.
#[pyfunction]
fn _settings_declarations(py: Python<'_>) -> PyResult<Vec<Declaration<'_>>> {
    declarations::<mlt::RenderSettings>(py, |s| s.validate())
}

/// Every declared material parameter, as `_settings_declarations` (the message names the
/// scene's first material).
#[pyfunction]
fn _material_declarations(py: Python<'_>) -> PyResult<Vec<Declaration<'_>>> {
    declarations::<mlt::Material>(py, |m| m.validate(0, 0))
}

fn declarations<S: mlt::params::Parameters>(
    py: Python<'_>,
    validate: fn(&S) -> mlt::Result<()>,
) -> PyResult<Vec<Declaration<'_>>> {
    S::parameters()
        .iter()
        .map(|p| {
            let default = convert::value_to_py(py, p.kind, (p.default)())?;
            let (outside, message) = match p.outside_value() {
                Some(bad) => {
                    let mut values = S::default();
                    values
                        .set(p.name, bad)
                        .map_err(|e| errors::from_mlt(py, &e))?;
                    let message = validate(&values).err().map(|e| e.message);
                    (Some(convert::value_to_py(py, p.kind, bad)?), message)
                }
                None => (None, None),
            };
            Ok((p.name, default, outside, message))
        })
        .collect()
}

type Declaration<'py> = (
    &'static str,
    Bound<'py, PyAny>,
    Option<Bound<'py, PyAny>>,
    Option<String>,
);

#[pymodule]
fn _mlt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::Scene>()?;
    m.add_class::<scene::SceneInfo>()?;
    m.add_class::<render::CancelToken>()?;
    m.add_class::<render::RenderStats>()?;
    m.add_class::<render::NormalizationStats>()?;
    m.add_class::<render::MutationCounts>()?;
    m.add_class::<render::FilterStats>()?;
    m.add_class::<jobs::RenderPlan>()?;
    m.add_class::<jobs::PartialRender>()?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::render_with_unfiltered, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::plan, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::render_job, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::combine, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::merge, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_environment, m)?)?;
    m.add_function(wrap_pyfunction!(_defaults_mismatches, m)?)?;
    m.add_function(wrap_pyfunction!(_settings_declarations, m)?)?;
    m.add_function(wrap_pyfunction!(_material_declarations, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("EMBREE_AVAILABLE", mlt::Backend::Embree.is_available())?;
    Ok(())
}
