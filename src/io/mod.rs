//! Scene files in, images out: what the `mlt-render` front end (and tests) need around the
//! kernel. Compiled only with the `cli` feature (on by default); the kernel itself never
//! touches files.
//!
//! - [`load_scene`] reads Wavefront OBJ (+ MTL, + `NAME.camera.json` beside it) or glTF 2.0
//!   (`.gltf` / `.glb`) into flat arrays ([`SceneData`]) ready for [`crate::Scene::new`].
//! - [`load_camera_json`] reads a camera sidecar file.
//! - [`load_environment`] reads an environment map (`.hdr`, `.exr`) as linear RGB floats.
//! - [`write_image`] writes the renderer's linear RGB buffer as PFM, OpenEXR or PNG.
//!
//! Every failure is an [`IoError`] whose message is one sentence naming the file and what is
//! wrong with it.
//!
//! ## OBJ / MTL mapping
//! Faces are triangulated; all objects and groups go into one set of arrays, each triangle
//! keeping its face's material:
//! - `illum 7`, or a non-zero `Tf` together with `Ni`: a smooth dielectric with index of
//!   refraction `Ni` (1.5 if absent), tinted by `Tf` (white if absent);
//! - `illum 3` or `illum 5`: a perfect mirror reflecting `Ks` (white if absent);
//! - the PBR extension's `Pr` (roughness, 1 if absent), `Pm` (metalness, 0 if absent),
//!   `map_Pr`, `map_Pm`: glTF's metallic-roughness model with base colour `Kd` and index of
//!   refraction `Ni` (1.5); the two maps are combined into one texture (same size needed);
//! - `Ns` with a non-black `Ks` (`illum 2` or none): metallic-roughness with metalness 0,
//!   base colour `Kd` and the GGX roughness matching the Phong exponent,
//!   roughness = (2 / (Ns + 2))^¼ (Walter et al. 2007's α = sqrt(2 / (Ns + 2)), and glTF's
//!   α = roughness²); `Ks`'s colour itself is not used (the dielectric's Fresnel is);
//! - anything else: Lambertian with albedo `Kd` (0.8 grey if absent);
//! - `Ke` on any material makes its triangles area lights;
//! - the PBR extension's `Pc` (clear coat thickness, taken as its factor in [0, 1]) and
//!   `Pcr` (its roughness, 0 if absent) on a metallic-roughness material: its clear coat;
//!   `Pc` alone makes the material metallic-roughness;
//! - the PBR extension's `aniso` (anisotropy strength in [0, 1]) and `anisor` (its
//!   rotation, as a fraction of a full turn, Blender's convention) on a metallic-roughness
//!   material: its anisotropy; `aniso` alone makes the material metallic-roughness;
//! - `Vd` (mlt's own keyword; MTL has none for it) on a dielectric or metallic-roughness
//!   material: its Abbe number, the dispersion `Material::abbe_number` describes.
//!
//! Textures: `map_Kd` (base colour, sRGB), `map_Ke` (emission, sRGB; emission 1 if `Ke` is
//! absent), `norm`, `map_Bump` or `bump` (a tangent-space normal map with `-bm` as its scale;
//! a grey image is a height map and is skipped). The options `-s` and `-o` (u and v) become
//! a texture transform and `-clamp on` clamps; other options are skipped. Images are PNG,
//! JPEG, TGA or Radiance HDR, relative to the material library.
//!
//! Colors are passed through unchanged: the kernel validates them and names the material
//! index in its error. Faces without a material (no `usemtl`) get an extra white diffuse
//! material (albedo 0.8) appended after the file's materials. A `usemtl` naming a
//! material no library defines, or a material library that cannot be read, is an error.
//! Normals (`vn`) and texture coordinates (`vt`, v flipped to glTF's downward convention)
//! are kept when the file has them: then every triangle gets corners of its own (a face
//! without `vn` gets its face normal).
//!
//! ## glTF mapping
//! See [`load_scene`]: meshes of the default scene (or the first scene) with node transforms
//! applied, the first perspective camera, and glTF's metallic-roughness materials with
//! their textures.

mod camera_file;
mod environment_file;
mod gltf_file;
mod image_file;
mod obj;
mod scene_data;

use std::path::Path;

pub use camera_file::load_camera_json;
pub use environment_file::load_environment;
pub use image_file::{ImageFormat, read_pfm, write_exr, write_image, write_pfm, write_png};
pub use scene_data::{CameraFile, IoError, SceneData};

/// Loads a scene by its file extension (case-insensitive):
///
/// - `.obj`: Wavefront OBJ with its MTL libraries (see the [module docs](self)); if
///   `NAME.camera.json` exists beside `NAME.obj` it is loaded into [`SceneData::camera`].
/// - `.gltf` / `.glb`: glTF 2.0. All `TRIANGLES` primitives reachable from the default
///   scene's nodes (the first scene if none is marked default), with world transforms applied
///   (winding flipped under mirroring transforms so front faces stay front). The camera is the
///   first perspective camera met walking the nodes depth-first: eye at the node's world
///   position, looking down its -Z with +Y up, `yfov` converted to degrees; the image is
///   512 pixels high and `round(height × aspectRatio)` wide, or square
///   when no aspect ratio is given. Materials are glTF's metallic-roughness model
///   ([`crate::MaterialKind::MetallicRoughness`]): base colour and alpha, metallic and
///   roughness factors and textures, `normalTexture` with its scale, emission =
///   `emissiveFactor` × `KHR_materials_emissive_strength` × `emissiveTexture`,
///   `KHR_materials_transmission` (factor and texture), `KHR_materials_ior`,
///   `KHR_materials_dispersion`, `KHR_texture_transform`, `KHR_materials_clearcoat`
///   (factors, textures and the coat's own normal map), `KHR_materials_specular` and
///   `KHR_materials_sheen` (factors and textures), `KHR_materials_anisotropy` (strength,
///   rotation and texture), `KHR_materials_iridescence` (the thin film's factors and
///   textures), `KHR_materials_volume` (thickness as
///   the flag, attenuation colour and distance), `KHR_materials_unlit` (the base colour
///   emitted, nothing scattered), `KHR_materials_variants` (see [`load_scene_variant`]);
///   files may require any of these. Alpha modes (`BLEND` as stochastic coverage,
///   [`crate::AlphaMode::Blend`]). Images (PNG, JPEG; embedded, data URIs or files) become
///   textures: base colour and emission decoded as sRGB, the others linear, with the
///   sampler's wrap modes and nearest or bilinear filtering. Attributes: `NORMAL`,
///   `TEXCOORD_0` and `TEXCOORD_1` (each texture reads the set its `texCoord` names; later
///   sets are refused), `COLOR_0` and `TANGENT` (used when every primitive has it; else
///   MikkTSpace computes them); a primitive without normals in a scene that has some is
///   flat-shaded.
///   Primitives without a material get the glTF default material (white, metallic 1,
///   roughness 1). `KHR_materials_variants`: the primitives' default materials here; see
///   [`load_scene_variant`] to pick a variant. Occlusion textures are ignored.
///   `KHR_lights_punctual` lights (files may list it in `extensionsRequired`) go into
///   [`SceneData::punctual_lights`]: at their node's world origin, pointing along its world
///   −Z, with `color × intensity / 683` (candela and lux over 683 lm/W, Blender's factor:
///   W/sr for point and spot lights, W/m² for directional ones), spot cone angles in
///   degrees; `range` is ignored.
///
/// A file without any triangle is an error.
pub fn load_scene(path: &Path) -> Result<SceneData, IoError> {
    load_scene_variant(path, None)
}

/// [`load_scene`], with glTF's `KHR_materials_variants`: `None` keeps each primitive's default
/// material; `Some(name)` gives each primitive the material its mapping names for the variant
/// `name` (its default where it maps none). A name the file does not define is an error that
/// lists the file's variants, and so is a name given for a file without variants (OBJ files
/// have none); of several variants of one name, the first is taken. Every mapping is
/// checked either way: one naming a material or a variant the file does not have, or a
/// variant an earlier mapping of the primitive names, is an error.
pub fn load_scene_variant(path: &Path, variant: Option<&str>) -> Result<SceneData, IoError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let data = match extension.as_deref() {
        Some("obj") => match variant {
            None => obj::load_obj(path)?,
            Some(name) => {
                return Err(IoError::new(format!(
                    "cannot load scene {}: only glTF files have material variants, so variant {name:?} cannot be chosen",
                    path.display()
                )));
            }
        },
        Some("gltf") | Some("glb") => gltf_file::load_gltf(path, variant)?,
        _ => {
            return Err(IoError::new(format!(
                "cannot load scene {}: unsupported file extension (expected .obj, .gltf or .glb)",
                path.display()
            )));
        }
    };
    if data.indices.is_empty() {
        return Err(IoError::new(format!(
            "scene file {} contains no triangles",
            path.display()
        )));
    }
    debug_assert_eq!(data.material_ids.len(), data.triangle_count());
    debug_assert_eq!(data.materials.len(), data.material_names.len());
    Ok(data)
}
