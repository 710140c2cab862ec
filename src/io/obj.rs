//! Wavefront OBJ + MTL through tobj; the material mapping is documented in the module docs.

use super::camera_file::load_camera_json;
use super::scene_data::{DEFAULT_ALBEDO, IoError, SceneData};
use crate::Material;
use crate::scene::{MaterialKind, TextureRef};
use crate::texture::{TexelData, TextureDesc, TextureEncoding, TextureFilter, WrapMode};
use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
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
    if let Err((line, message)) = check_face_indices(&bytes) {
        return Err(IoError::new(format!(
            "cannot parse OBJ file {} (line {line}): {message}",
            path.display()
        )));
    }
    // The first material library that failed, to name it in the error.
    let library_error: RefCell<Option<(PathBuf, String)>> = RefCell::new(None);
    let directory = path.parent().unwrap_or(Path::new(""));
    let loaded = tobj::load_obj_buf(&mut bytes.as_slice(), &options, |library| {
        let full = directory.join(library);
        let result = match std::fs::read(&full) {
            Ok(text) => check_colour_statements(&text)
                .and_then(|()| tobj::load_mtl_buf(&mut text.as_slice()).map_err(|e| e.to_string())),
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
    let mut images = TextureFiles {
        directory,
        loaded: HashMap::new(),
    };
    for material in &materials {
        let invalid = |problem: String| {
            IoError::new(format!(
                "material '{}' used by {} is invalid: {problem}",
                material.name,
                path.display()
            ))
        };
        let mut converted = convert_material(material).map_err(invalid)?;
        add_textures(material, &mut converted, &mut images, &mut data.textures).map_err(invalid)?;
        data.push_material(material.name.clone(), converted);
    }
    // Normals and texture coordinates are per corner in OBJ (`f v/vt/vn`): a scene that has
    // some gets them for every corner, each triangle with corners of its own (flat face
    // normals and (0, 0) where a mesh has none).
    let per_corner = models
        .iter()
        .any(|m| !m.mesh.normals.is_empty() || !m.mesh.texcoords.is_empty());
    let any_normals = models.iter().any(|m| !m.mesh.normals.is_empty());
    let any_texcoords = models.iter().any(|m| !m.mesh.texcoords.is_empty());
    let mut default_material = None;
    for model in &models {
        let mesh = &model.mesh;
        let base = (data.positions.len() / 3) as u32;
        if per_corner {
            add_corners(mesh, any_normals, any_texcoords, &mut data);
        } else {
            data.positions.extend_from_slice(&mesh.positions);
            data.indices.extend(mesh.indices.iter().map(|&i| base + i));
        }
        let material = match mesh.material_id {
            Some(id) => id as u32,
            None => *default_material.get_or_insert_with(|| {
                data.push_material("(default)".into(), Material::diffuse(DEFAULT_ALBEDO))
            }),
        };
        data.material_ids
            .extend(std::iter::repeat_n(material, mesh.indices.len() / 3));
    }

    if data.materials.iter().any(Material::has_textures) && data.texcoords.is_empty() {
        return Err(IoError::new(format!(
            "{} has textured materials but no texture coordinates (vt)",
            path.display()
        )));
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
    let number = |key: &str| -> Result<Option<f32>, String> {
        match m.unknown_param.get(key) {
            None => Ok(None),
            Some(text) => text
                .trim()
                .parse::<f32>()
                .map(Some)
                .map_err(|_| format!("{key} '{text}' is not a number")),
        }
    };
    let (roughness, metallic) = (number("Pr")?, number("Pm")?);
    let abbe_number = number("Vd")?.unwrap_or(0.0);
    // The PBR extension's clear coat: `Pc` its thickness (here its factor), `Pcr` its
    // roughness.
    let (clearcoat, clearcoat_roughness) = (number("Pc")?, number("Pcr")?);
    // The PBR extension's sheen colour, `Ps r g b` or `Ps v` (grey), in [0, 1].
    let sheen = match m.unknown_param.get("Ps") {
        Some(text) => Some(
            parse_tf(text)
                .filter(|c| c.iter().all(|&c| (0.0..=1.0).contains(&c)))
                .ok_or_else(|| format!("Ps '{text}' is not one or three numbers in [0, 1]"))?,
        ),
        None => None,
    };
    // The PBR extension's anisotropy, `aniso` its strength in [0, 1] and `anisor` its
    // rotation as a fraction of a full turn (Blender's convention, which writes them).
    let (anisotropy, anisotropy_turns) = (number("aniso")?, number("anisor")?);
    let pbr = roughness.is_some()
        || metallic.is_some()
        || clearcoat.is_some()
        || anisotropy.is_some()
        || sheen.is_some()
        || m.unknown_param.contains_key("map_Pr")
        || m.unknown_param.contains_key("map_Pm");
    let glossy = matches!(illum, None | Some(2))
        && m.shininess.is_some()
        && m.specular.is_some_and(|ks| ks.iter().any(|&c| c > 0.0));
    let diffuse = m.diffuse.unwrap_or(DEFAULT_ALBEDO);
    let material = if illum == Some(7) || (transmits && m.optical_density.is_some()) {
        let mut glass = Material::dielectric(m.optical_density.unwrap_or(1.5));
        glass.color = transmission.unwrap_or([1.0; 3]);
        glass
    } else if matches!(illum, Some(3) | Some(5)) {
        Material::mirror(m.specular.unwrap_or([1.0; 3]))
    } else if pbr {
        Material {
            ior: m.optical_density.unwrap_or(1.5),
            ..Material::metallic_roughness(
                diffuse,
                metallic.unwrap_or(0.0),
                roughness.unwrap_or(1.0),
            )
        }
    } else if glossy {
        Material {
            ior: m.optical_density.unwrap_or(1.5),
            ..Material::metallic_roughness(
                diffuse,
                0.0,
                phong_roughness(m.shininess.unwrap_or(0.0)),
            )
        }
    } else {
        Material::diffuse(diffuse)
    };
    let material = match material.kind {
        MaterialKind::Dielectric => Material {
            abbe_number,
            ..material
        },
        MaterialKind::MetallicRoughness => Material {
            abbe_number,
            clearcoat: clearcoat.unwrap_or(0.0),
            clearcoat_roughness: clearcoat_roughness.unwrap_or(0.0),
            sheen_color: sheen.unwrap_or([0.0; 3]),
            anisotropy: anisotropy.unwrap_or(0.0),
            anisotropy_rotation: anisotropy_turns.unwrap_or(0.0) * std::f32::consts::TAU,
            ..material
        },
        _ => material,
    };
    Ok(material.with_emission(m.emissive.unwrap_or([0.0; 3])))
}

/// The GGX roughness that matches a Phong exponent `Ns`: Walter et al. 2007's Beckmann
/// equivalent α = sqrt(2 / (Ns + 2)), and glTF's α = roughness².
fn phong_roughness(shininess: f32) -> f32 {
    (2.0 / (shininess.max(0.0) + 2.0)).sqrt().sqrt()
}

/// Texture images of a material library, each decoded once per encoding.
struct TextureFiles<'a> {
    directory: &'a Path,
    /// (file, sRGB) → index in the scene's textures.
    loaded: HashMap<(PathBuf, bool), u32>,
}

/// An MTL texture statement (`map_Kd -clamp on -s 2 2 file.png`): the file and the options
/// mlt uses (`-bm` scale, `-o` offset, `-s` scale, `-clamp`); the others are skipped.
struct TextureStatement {
    file: String,
    bump_scale: f32,
    offset: [f32; 2],
    scale: [f32; 2],
    clamp: bool,
}

fn parse_texture_statement(text: &str) -> Result<TextureStatement, String> {
    let mut statement = TextureStatement {
        file: String::new(),
        bump_scale: 1.0,
        offset: [0.0; 2],
        scale: [1.0; 2],
        clamp: false,
    };
    let words: Vec<&str> = text.split_whitespace().collect();
    let mut i = 0;
    let parse = |w: Option<&&str>| -> Result<f32, String> {
        w.and_then(|w| w.parse().ok())
            .ok_or_else(|| format!("texture options '{text}' are malformed"))
    };
    while i < words.len() {
        let option = words[i];
        let numbers_after = |from: usize| {
            words[from..]
                .iter()
                .take(3)
                .take_while(|w| w.parse::<f32>().is_ok())
                .count()
        };
        match option {
            "-bm" => {
                statement.bump_scale = parse(words.get(i + 1))?;
                i += 2;
            }
            "-o" | "-s" => {
                let n = numbers_after(i + 1);
                let u = parse(words.get(i + 1))?;
                let v = if n >= 2 { parse(words.get(i + 2))? } else { u };
                if option == "-o" {
                    statement.offset = [u, v];
                } else {
                    statement.scale = [u, v];
                }
                i += 1 + n.max(1);
            }
            "-t" | "-mm" => i += 1 + numbers_after(i + 1).max(1),
            "-clamp" => {
                statement.clamp = words.get(i + 1) == Some(&"on");
                i += 2;
            }
            "-blendu" | "-blendv" | "-boost" | "-texres" | "-imfchan" | "-type" | "-cc" => i += 2,
            _ => {
                // The file name is the rest of the line (it may contain spaces).
                statement.file = words[i..].join(" ");
                break;
            }
        }
    }
    if statement.file.is_empty() {
        return Err(format!("texture statement '{text}' names no file"));
    }
    Ok(statement)
}

/// Reads an image file as 8-bit texels (its channel count kept) or linear floats (HDR).
fn read_texture_image(
    path: &Path,
    srgb: bool,
    clamp: bool,
) -> Result<TextureDesc<'static>, String> {
    let image =
        image::open(path).map_err(|e| format!("cannot read texture {}: {e}", path.display()))?;
    let (width, height) = (image.width(), image.height());
    use image::DynamicImage as Image;
    let (channels, data, encoding) = match image {
        Image::ImageLuma8(i) => (1, TexelData::U8(Cow::Owned(i.into_raw())), None),
        Image::ImageLumaA8(i) => (2, TexelData::U8(Cow::Owned(i.into_raw())), None),
        Image::ImageRgb8(i) => (3, TexelData::U8(Cow::Owned(i.into_raw())), None),
        Image::ImageRgba8(i) => (4, TexelData::U8(Cow::Owned(i.into_raw())), None),
        Image::ImageRgb32F(i) => (
            3,
            TexelData::F32(Cow::Owned(i.into_raw())),
            Some(TextureEncoding::Linear),
        ),
        Image::ImageRgba32F(i) => (
            4,
            TexelData::F32(Cow::Owned(i.into_raw())),
            Some(TextureEncoding::Linear),
        ),
        other => (
            4,
            TexelData::U8(Cow::Owned(other.into_rgba8().into_raw())),
            None,
        ),
    };
    let wrap = if clamp {
        WrapMode::ClampToEdge
    } else {
        WrapMode::Repeat
    };
    Ok(TextureDesc {
        width,
        height,
        channels,
        data,
        encoding: encoding.unwrap_or(if srgb {
            TextureEncoding::Srgb
        } else {
            TextureEncoding::Linear
        }),
        wrap_u: wrap,
        wrap_v: wrap,
        filter: TextureFilter::Bilinear,
    })
}

impl TextureFiles<'_> {
    /// The texture of `statement`'s file, decoded as sRGB colour or linear data.
    fn reference(
        &mut self,
        statement: &TextureStatement,
        srgb: bool,
        textures: &mut Vec<TextureDesc<'static>>,
    ) -> Result<TextureRef, String> {
        let file = self.directory.join(statement.file.replace('\\', "/"));
        let index = match self.loaded.get(&(file.clone(), srgb)) {
            Some(&index) => index,
            None => {
                textures.push(read_texture_image(&file, srgb, statement.clamp)?);
                let index = (textures.len() - 1) as u32;
                self.loaded.insert((file, srgb), index);
                index
            }
        };
        // OBJ's v grows upwards, glTF's (the kernel's) downwards: v' = 1 − v, applied
        // to the coordinates when loading them. In those coordinates OBJ's v ↦ s·v + o
        // becomes v' ↦ s·v' + (1 − s − o).
        let [s, o] = [statement.scale[1], statement.offset[1]];
        Ok(TextureRef {
            offset: [statement.offset[0], 1.0 - s - o],
            scale: statement.scale,
            ..TextureRef::new(index)
        })
    }
}

/// The textures of an MTL material: `map_Kd` (base colour, sRGB), `norm` / `map_Bump` /
/// `bump` (a tangent-space normal map; a grey image is a height map, which is skipped),
/// `map_Ke` (emission, sRGB), `map_Ps` (sheen colour, sRGB), and `map_Pr` / `map_Pm`
/// (roughness and metalness, combined
/// into one texture as glTF's green and blue channels; they must have the same size).
fn add_textures(
    m: &tobj::Material,
    material: &mut Material,
    files: &mut TextureFiles,
    textures: &mut Vec<TextureDesc<'static>>,
) -> Result<(), String> {
    if let Some(text) = &m.diffuse_texture {
        let statement = parse_texture_statement(text)?;
        material.base_color_texture = Some(files.reference(&statement, true, textures)?);
    }
    if let Some(text) = m.unknown_param.get("map_Ke") {
        let statement = parse_texture_statement(text)?;
        material.emission_texture = Some(files.reference(&statement, true, textures)?);
        if !material.is_emissive() {
            // map_Ke alone means emission as the texture says.
            material.emission = [1.0; 3];
        }
    }
    let normal_map = m.unknown_param.get("norm").or(m.normal_texture.as_ref());
    if let Some(text) = normal_map {
        let statement = parse_texture_statement(text)?;
        let reference = files.reference(&statement, false, textures)?;
        if textures[reference.texture as usize].channels >= 3 {
            material.normal_texture = Some(reference);
            material.normal_scale = statement.bump_scale;
        }
    }
    if let Some(text) = m.unknown_param.get("map_Ps")
        && material.kind == MaterialKind::MetallicRoughness
    {
        let statement = parse_texture_statement(text)?;
        material.sheen_color_texture = Some(files.reference(&statement, true, textures)?);
        if material.sheen_color == [0.0; 3] {
            // map_Ps alone means a sheen as the texture says.
            material.sheen_color = [1.0; 3];
        }
    }
    let roughness = m.unknown_param.get("map_Pr");
    let metalness = m.unknown_param.get("map_Pm");
    if (roughness.is_some() || metalness.is_some())
        && material.kind == MaterialKind::MetallicRoughness
    {
        let read = |text: &String| -> Result<TextureDesc<'static>, String> {
            let statement = parse_texture_statement(text)?;
            read_texture_image(
                &files.directory.join(&statement.file),
                false,
                statement.clamp,
            )
        };
        let roughness = roughness.map(read).transpose()?;
        let metalness = metalness.map(read).transpose()?;
        let (width, height) = roughness
            .as_ref()
            .or(metalness.as_ref())
            .map(|t| (t.width, t.height))
            .unwrap_or((1, 1));
        for t in roughness.iter().chain(&metalness) {
            if (t.width, t.height) != (width, height) {
                return Err("map_Pr and map_Pm images have different sizes".into());
            }
        }
        let first_channel = |t: &Option<TextureDesc<'static>>, i: usize| -> u8 {
            match t {
                None => 255,
                Some(t) => match &t.data {
                    TexelData::U8(v) => v[i * t.channels as usize],
                    TexelData::F32(v) => {
                        (v[i * t.channels as usize].clamp(0.0, 1.0) * 255.0).round() as u8
                    }
                },
            }
        };
        let texels = (0..(width * height) as usize)
            .flat_map(|i| {
                [
                    0,
                    first_channel(&roughness, i),
                    first_channel(&metalness, i),
                ]
            })
            .collect();
        textures.push(TextureDesc {
            width,
            height,
            channels: 3,
            data: TexelData::U8(Cow::Owned(texels)),
            encoding: TextureEncoding::Linear,
            wrap_u: WrapMode::Repeat,
            wrap_v: WrapMode::Repeat,
            filter: TextureFilter::Bilinear,
        });
        material.metallic_roughness_texture = Some(TextureRef::new((textures.len() - 1) as u32));
        // The maps replace the factors (glTF multiplies them).
        material.roughness = 1.0;
        material.metallic = 1.0;
    }
    Ok(())
}

/// Appends `mesh` with corners of their own: positions, the normals (the face's where the
/// mesh has none) and texture coordinates (v flipped to glTF's convention; (0, 0) where the
/// mesh has none).
fn add_corners(mesh: &tobj::Mesh, normals: bool, texcoords: bool, data: &mut SceneData) {
    let vertex = |i: u32| {
        let i = i as usize * 3;
        glam::Vec3::new(
            mesh.positions[i],
            mesh.positions[i + 1],
            mesh.positions[i + 2],
        )
    };
    for (triangle, corners) in mesh.indices.chunks_exact(3).enumerate() {
        let face_normal = (vertex(corners[1]) - vertex(corners[0]))
            .cross(vertex(corners[2]) - vertex(corners[0]))
            .normalize_or(glam::Vec3::Y);
        for (k, &corner) in corners.iter().enumerate() {
            let at = triangle * 3 + k;
            data.indices.push((data.positions.len() / 3) as u32);
            data.positions.extend_from_slice(&vertex(corner).to_array());
            if normals {
                let normal = match mesh.normal_indices.get(at) {
                    Some(&n) if !mesh.normals.is_empty() => {
                        let n = n as usize * 3;
                        glam::Vec3::from_slice(&mesh.normals[n..n + 3])
                            .try_normalize()
                            .unwrap_or(face_normal)
                    }
                    _ => face_normal,
                };
                data.normals.extend_from_slice(&normal.to_array());
            }
            if texcoords {
                let uv = match mesh.texcoord_indices.get(at) {
                    Some(&t) if !mesh.texcoords.is_empty() => {
                        let t = t as usize * 2;
                        [mesh.texcoords[t], 1.0 - mesh.texcoords[t + 1]]
                    }
                    _ => [0.0; 2],
                };
                data.texcoords.extend_from_slice(&uv);
            }
        }
    }
}

/// tobj 4 overflows on a face index far out of range (a panic, or without overflow checks a
/// wrong index; found by the obj_mtl fuzzer): every index of a face must name one of the
/// file's vertices, texture coordinates or normals, 1 to their count or -1 to minus the
/// count read so far. Kinds the file has none of are ignored by tobj, and here. Returns
/// the (1-based) line and what is wrong.
fn check_face_indices(bytes: &[u8]) -> Result<(), (usize, String)> {
    const KINDS: [(&str, &str); 3] = [
        ("v", "vertices"),
        ("vt", "texture coordinates"),
        ("vn", "normals"),
    ];
    let text = String::from_utf8_lossy(bytes);
    let kind = |line: &str| {
        let first = line.split_whitespace().next();
        KINDS.iter().position(|(key, _)| first == Some(*key))
    };
    let mut totals = [0i64; 3];
    for line in text.lines() {
        if let Some(k) = kind(line) {
            totals[k] += 1;
        }
    }
    let mut so_far = [0i64; 3];
    for (number, line) in text.lines().enumerate() {
        if let Some(k) = kind(line) {
            so_far[k] += 1;
            continue;
        }
        let mut words = line.split_whitespace();
        if words.next() != Some("f") {
            continue;
        }
        for word in words {
            for (k, part) in word.split('/').take(3).enumerate() {
                // Malformed numbers are tobj's to report.
                let Ok(index) = part.parse::<i64>() else {
                    continue;
                };
                let named = if index > 0 {
                    index <= totals[k]
                } else {
                    index.checked_neg().is_some_and(|i| i > 0 && i <= so_far[k])
                };
                if totals[k] > 0 && !named {
                    return Err((
                        number + 1,
                        format!(
                            "face index {index} is out of bounds: the file has {} {}",
                            totals[k], KINDS[k].1
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// tobj 4 panics on a colour statement (`Ka`, `Kd`, `Ks`, `Ke`) with fewer than three
/// values (found by the obj_mtl fuzzer): such a library is refused before tobj reads it.
fn check_colour_statements(text: &[u8]) -> Result<(), String> {
    for (number, line) in String::from_utf8_lossy(text).lines().enumerate() {
        let mut words = line.split_whitespace();
        if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next()
            && words.count() < 3
        {
            return Err(format!(
                "line {}: {key} needs three numbers (r g b)",
                number + 1
            ));
        }
    }
    Ok(())
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
