//! Wavefront OBJ + MTL through tobj; the material mapping is documented in the module docs.

use super::camera_file::load_camera_json;
use super::scene_data::{DEFAULT_ALBEDO, IoError, SceneData};
use crate::Material;
use std::cell::RefCell;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

pub(super) fn load_obj(path: &Path) -> Result<SceneData, IoError> {
    let bytes = std::fs::read(path)
        .map_err(|e| IoError::new(format!("cannot read scene file {}: {e}", path.display())))?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // The first material library that failed, to name it in the error.
    let library_error: RefCell<Option<(PathBuf, String)>> = RefCell::new(None);
    let directory = path.parent().unwrap_or(Path::new(""));
    let loaded = tobj::load_obj_buf(&mut bytes.as_slice(), &options, |library| {
        let full = directory.join(library);
        let result = match std::fs::read(&full) {
            Ok(text) => tobj::load_mtl_buf(&mut text.as_slice()).map_err(|e| e.to_string()),
            Err(e) => Err(e.to_string()),
        };
        match result {
            Ok(materials) => Ok(materials),
            Err(message) => {
                library_error.borrow_mut().get_or_insert((full, message));
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    let (models, materials) = loaded.map_err(|e| {
        let location = locate_face_error(&bytes, &e)
            .map(|line| format!(" (line {line})"))
            .unwrap_or_default();
        IoError::new(format!(
            "cannot parse OBJ file {}{location}: {e}",
            path.display()
        ))
    })?;
    if let Some((library, message)) = library_error.into_inner() {
        return Err(IoError::new(format!(
            "cannot load material library {} used by {}: {message}",
            library.display(),
            path.display()
        )));
    }
    let materials = materials.map_err(|e| {
        IoError::new(format!(
            "cannot load the materials of {}: {e}",
            path.display()
        ))
    })?;
    check_material_names(&bytes, &materials, path)?;

    let mut data = SceneData::default();
    for material in &materials {
        let converted = convert_material(material).map_err(|problem| {
            IoError::new(format!(
                "material '{}' used by {} is invalid: {problem}",
                material.name,
                path.display()
            ))
        })?;
        data.push_material(material.name.clone(), converted);
    }
    let mut default_material = None;
    for model in &models {
        let mesh = &model.mesh;
        let base = (data.positions.len() / 3) as u32;
        data.positions.extend_from_slice(&mesh.positions);
        data.indices.extend(mesh.indices.iter().map(|&i| base + i));
        let material = match mesh.material_id {
            Some(id) => id as u32,
            None => *default_material.get_or_insert_with(|| {
                data.push_material("(default)".into(), Material::diffuse(DEFAULT_ALBEDO))
            }),
        };
        data.material_ids
            .extend(std::iter::repeat_n(material, mesh.indices.len() / 3));
    }

    let sidecar = path.with_extension("camera.json");
    if sidecar.is_file() {
        data.camera = Some(load_camera_json(&sidecar)?);
    }
    Ok(data)
}

/// Maps an MTL material to the kernel's kinds; `Err` says what is malformed.
fn convert_material(m: &tobj::Material) -> Result<Material, String> {
    let transmission = match m.unknown_param.get("Tf") {
        Some(text) => Some(parse_tf(text).ok_or_else(|| {
            format!(
                "Tf '{text}' is not one or three numbers (spectral and xyz forms are not supported)"
            )
        })?),
        None => None,
    };
    let illum = m.illumination_model;
    let transmits = transmission.is_some_and(|t| t.iter().any(|&c| c != 0.0));
    let material = if illum == Some(7) || (transmits && m.optical_density.is_some()) {
        let mut glass = Material::dielectric(m.optical_density.unwrap_or(1.5));
        glass.color = transmission.unwrap_or([1.0; 3]);
        glass
    } else if matches!(illum, Some(3) | Some(5)) {
        Material::mirror(m.specular.unwrap_or([1.0; 3]))
    } else {
        Material::diffuse(m.diffuse.unwrap_or(DEFAULT_ALBEDO))
    };
    Ok(material.with_emission(m.emissive.unwrap_or([0.0; 3])))
}

/// `Tf r g b` or `Tf v` (grey).
fn parse_tf(text: &str) -> Option<[f32; 3]> {
    let values: Vec<f32> = text
        .split_whitespace()
        .map(|w| w.parse().ok())
        .collect::<Option<_>>()?;
    match values[..] {
        [v] => Some([v; 3]),
        [r, g, b] => Some([r, g, b]),
        _ => None,
    }
}

/// tobj silently drops a `usemtl` whose material no library defines: make it an error.
fn check_material_names(
    bytes: &[u8],
    materials: &[tobj::Material],
    path: &Path,
) -> Result<(), IoError> {
    let known: HashSet<&str> = materials.iter().map(|m| m.name.as_str()).collect();
    for (number, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
        let line = line.trim();
        if let Some(name) = line.strip_prefix("usemtl")
            && line[6..].starts_with(char::is_whitespace)
        {
            let name = name.trim();
            if !known.contains(name) {
                return Err(IoError::new(format!(
                    "OBJ file {} (line {}) uses material '{name}', which none of its material libraries defines",
                    path.display(),
                    number + 1
                )));
            }
        }
    }
    Ok(())
}

/// For an out-of-range face index, the (1-based) line of the offending face.
fn locate_face_error(bytes: &[u8], error: &tobj::LoadError) -> Option<usize> {
    if !matches!(
        error,
        tobj::LoadError::FaceVertexOutOfBounds | tobj::LoadError::FaceParseError
    ) {
        return None;
    }
    let mut vertices: i64 = 0;
    for (number, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices += 1,
            Some("f") => {
                let bad = words.any(|word| {
                    match word.split('/').next().and_then(|v| v.parse::<i64>().ok()) {
                        Some(i) if i > 0 => i > vertices,
                        Some(i) if i < 0 => -i > vertices,
                        _ => true,
                    }
                });
                if bad {
                    return Some(number + 1);
                }
            }
            _ => {}
        }
    }
    None
}
