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
//! - anything else: Lambertian with albedo `Kd` (0.8 grey if absent);
//! - `Ke` on any material makes its triangles area lights.
//!
//! Colors are passed through unchanged: the kernel validates them and names the material
//! index in its error. Faces without a material (no `usemtl`) get an extra white diffuse
//! material (albedo 0.8) appended after the file's materials. A `usemtl` naming a
//! material no library defines, or a material library that cannot be read, is an error.
//! Normals and texture coordinates are ignored.
//!
//! ## glTF mapping
//! See [`load_scene`]: meshes of the default scene (or the first scene) with node transforms
//! applied, the first perspective camera, and materials reduced to the kernel's three kinds.
//! Textures are ignored.

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
///   when no aspect ratio is given. Materials: emission = `emissiveFactor` ×
///   `KHR_materials_emissive_strength`; `KHR_materials_transmission` factor > 0 → dielectric
///   with `KHR_materials_ior` (1.5 if absent); metallic 1 and roughness 0 → mirror with the
///   base color; else diffuse with the base color. Primitives without a material get the glTF
///   default material (white diffuse). Textures, normals and other attributes are ignored.
///   `KHR_lights_punctual` lights (files may list it in `extensionsRequired`) go into
///   [`SceneData::punctual_lights`]: at their node's world origin, pointing along its world
///   −Z, with `color × intensity / 683` (candela and lux over 683 lm/W, Blender's factor:
///   W/sr for point and spot lights, W/m² for directional ones), spot cone angles in
///   degrees; `range` is ignored.
///
/// A file without any triangle is an error.
pub fn load_scene(path: &Path) -> Result<SceneData, IoError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let data = match extension.as_deref() {
        Some("obj") => obj::load_obj(path)?,
        Some("gltf") | Some("glb") => gltf_file::load_gltf(path)?,
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
