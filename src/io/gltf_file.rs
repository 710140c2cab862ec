//! glTF 2.0 (`.gltf` with external or data-URI buffers, `.glb`); the mapping is documented on
//! [`super::load_scene`].

use super::scene_data::{CameraFile, GLTF_DEFAULT_HEIGHT, IoError, SceneData};
use crate::scene::{AlphaMode, MaterialKind, PunctualLight, TextureRef};
use crate::texture::{TexelData, TextureDesc, TextureEncoding, TextureFilter, WrapMode};
use crate::{Camera, Material};
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use glam::{Mat3, Mat4, Vec3};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

/// Lumens per watt: glTF's photometric light units (candela for point and spot lights, lux
/// for directional ones) are divided by this, the luminous efficacy of light at 555 nm, to
/// give radiometric ones (W/sr, W/m²). Blender's glTF exporter and importer use the same
/// factor, so a Blender lamp of P watts is P watts here.
pub(crate) const LUMENS_PER_WATT: f32 = 683.0;

/// The deepest node hierarchy a glTF file may have.
const MAX_NODE_DEPTH: usize = 1024;

pub(super) fn load_gltf(path: &Path) -> Result<SceneData, IoError> {
    let fail =
        |what: String| IoError::new(format!("cannot load glTF file {}: {what}", path.display()));
    let bytes = std::fs::read(path)
        .map_err(|e| IoError::new(format!("cannot read scene file {}: {e}", path.display())))?;
    // gltf 1.4 subtracts the header's size from a GLB's declared length unchecked (an
    // overflow, found by the gltf_glb fuzzer): a length shorter than the header is refused.
    if let Some(length) = bytes.strip_prefix(b"glTF").and_then(|rest| rest.get(4..8)) {
        let length = u32::from_le_bytes(length.try_into().expect("4 bytes"));
        if length < 12 {
            return Err(fail(format!(
                "its GLB header gives a length of {length} bytes, less than the header's 12"
            )));
        }
    }
    let ::gltf::Gltf { document, blob } =
        ::gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| fail(e.to_string()))?;
    // gltf-json 1.4's validation indexes the accessors with each primitive's POSITION
    // without checking it (a panic, found by the gltf_glb fuzzer): checked here first.
    let json = document.into_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = ::gltf::json::validation::Checked::Valid(::gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= accessors
            {
                return Err(fail(format!(
                    "the POSITION of primitive {p} of mesh {m} is accessor {}, but there are {accessors} accessors",
                    index.value()
                )));
            }
        }
    }
    // gltf 1.4 unwraps an image's mimeType when it has a bufferView, and its uri otherwise,
    // though validation checks neither (a panic, found by the gltf_glb fuzzer).
    for (i, image) in json.images.iter().enumerate() {
        let complete = match &image.buffer_view {
            Some(_) => image.mime_type.is_some(),
            None => image.uri.is_some(),
        };
        if !complete {
            return Err(fail(format!(
                "image {i} needs a uri, or a bufferView with a mimeType"
            )));
        }
    }
    // gltf 1.4 unwraps the percent-decoding of a relative uri, which fails when the bytes
    // are not UTF-8 (a panic, found by the gltf_glb fuzzer).
    let uris = json.buffers.iter().filter_map(|b| b.uri.as_deref());
    let uris = uris.chain(json.images.iter().filter_map(|i| i.uri.as_deref()));
    for uri in uris {
        if !uri.contains(':') && !percent_decodes_to_utf8(uri) {
            return Err(fail(format!(
                "the uri {uri:?} does not percent-decode to UTF-8"
            )));
        }
    }
    // The gltf crate refuses required extensions it does not parse itself; those this
    // loader reads from the JSON are supported all the same.
    let mut json = json;
    json.extensions_required
        .retain(|name| !READ_FROM_JSON.contains(&name.as_str()));
    let document = ::gltf::Document::from_json(json).map_err(|e| fail(e.to_string()))?;
    let base = path.parent().unwrap_or(Path::new(""));
    let buffers = ::gltf::import_buffers(&document, Some(base), blob)
        .map_err(|e| fail(format!("cannot load its buffers: {e}")))?;
    // gltf 1.4 slices an image's bufferView out of its buffer unchecked (a panic, found by
    // the gltf_glb fuzzer): each view an image reads must lie within its buffer.
    for image in document.images() {
        if let ::gltf::image::Source::View { view, .. } = image.source() {
            let buffer_length = buffers
                .get(view.buffer().index())
                .map_or(0, |data| data.len());
            let end = view.offset().checked_add(view.length());
            if end.is_none_or(|end| end > buffer_length) {
                return Err(fail(format!(
                    "image {} reads bytes {}..{} of buffer {}, which holds {buffer_length}",
                    image.index(),
                    view.offset(),
                    end.map_or_else(|| "overflow".to_string(), |end| end.to_string()),
                    view.buffer().index()
                )));
            }
        }
    }

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| fail("it defines no scene".into()))?;

    let images = if document.textures().next().is_some() {
        ::gltf::import_images(&document, Some(base), &buffers)
            .map_err(|e| fail(format!("cannot load its images: {e}")))?
    } else {
        Vec::new()
    };
    let triangle_primitives = || {
        document
            .meshes()
            .flat_map(|m| m.primitives())
            .filter(|p| p.mode() == Mode::Triangles)
    };
    use ::gltf::Semantic;
    let attributes = Attributes {
        normals: triangle_primitives().any(|p| p.get(&Semantic::Normals).is_some()),
        texcoords: triangle_primitives().any(|p| p.get(&Semantic::TexCoords(0)).is_some()),
        colors: triangle_primitives().any(|p| p.get(&Semantic::Colors(0)).is_some()),
        tangents: triangle_primitives().next().is_some()
            && triangle_primitives().all(|p| {
                p.get(&Semantic::Tangents).is_some() && p.get(&Semantic::Normals).is_some()
            }),
    };
    let mut loader = Loader {
        path,
        document: &document,
        buffers: &buffers,
        images: &images,
        attributes,
        data: SceneData::default(),
        material_map: HashMap::new(),
        texture_map: HashMap::new(),
    };
    for node in scene.nodes() {
        loader.visit(&node, Mat4::IDENTITY, &mut Vec::new())?;
    }
    Ok(loader.data)
}

/// Which per-vertex attributes the scene carries: each is given for every vertex or none.
struct Attributes {
    /// Some primitive has normals (the others get their flat face normals).
    normals: bool,
    /// Some primitive has TEXCOORD_0 (the others get (0, 0)).
    texcoords: bool,
    /// Some primitive has COLOR_0 (the others get white).
    colors: bool,
    /// Every primitive has tangents and normals (else MikkTSpace computes them all).
    tangents: bool,
}

/// The material extensions this loader reads from the JSON, which the gltf crate does not
/// parse.
const READ_FROM_JSON: &[&str] = &[
    "KHR_materials_dispersion",
    "KHR_materials_specular",
    "KHR_materials_sheen",
];

struct Loader<'a> {
    path: &'a Path,
    document: &'a ::gltf::Document,
    buffers: &'a [::gltf::buffer::Data],
    images: &'a [::gltf::image::Data],
    attributes: Attributes,
    data: SceneData,
    /// glTF material index (None: the default material) → index in `data.materials`.
    material_map: HashMap<Option<usize>, u32>,
    /// (glTF texture index, sRGB) → index in `data.textures`: an image used both as colour
    /// and as data becomes two textures.
    texture_map: HashMap<(usize, bool), u32>,
}

impl Loader<'_> {
    fn fail(&self, what: String) -> IoError {
        IoError::new(format!(
            "cannot load glTF file {}: {what}",
            self.path.display()
        ))
    }

    /// Adds `node` and its subtree; `path` holds the indices of its ancestors. gltf's
    /// validation lets a node be its own ancestor (found by the gltf_glb fuzzer: the walk
    /// recursed until the stack overflowed): a cycle is an error, and so is a hierarchy
    /// deeper than `MAX_NODE_DEPTH`, which would exhaust the stack too.
    fn visit(
        &mut self,
        node: &::gltf::Node,
        parent: Mat4,
        path: &mut Vec<usize>,
    ) -> Result<(), IoError> {
        if path.contains(&node.index()) {
            return Err(self.fail(format!("node {} is its own ancestor", node.index())));
        }
        if path.len() >= MAX_NODE_DEPTH {
            return Err(self.fail(format!(
                "node {} lies deeper than {MAX_NODE_DEPTH} levels in the node hierarchy",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(self.fail(format!("node {} has a non-finite transform", node.index())));
        }
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                self.add_primitive(&mesh, &primitive, world)?;
            }
        }
        if let Some(light) = node.light() {
            let light = self.light(node, &light, world)?;
            self.data.punctual_lights.push(light);
        }
        if self.data.camera.is_none()
            && let Some(camera) = node.camera()
            && let ::gltf::camera::Projection::Perspective(perspective) = camera.projection()
        {
            self.data.camera = Some(self.camera(node, &perspective, world)?);
        }
        path.push(node.index());
        for child in node.children() {
            self.visit(&child, world, path)?;
        }
        path.pop();
        Ok(())
    }

    /// A `KHR_lights_punctual` light at its node: position the node's world origin, direction
    /// its world −Z (normalized), radiometric intensity `color × intensity / 683` (see
    /// [`LUMENS_PER_WATT`]), cone angles in degrees. `range` is ignored (the light falls off
    /// with the inverse square of the distance everywhere).
    fn light(
        &self,
        node: &::gltf::Node,
        light: &::gltf::khr_lights_punctual::Light,
        world: Mat4,
    ) -> Result<PunctualLight, IoError> {
        use ::gltf::khr_lights_punctual::Kind;
        let what = || format!("light {} (of node {})", light.index(), node.index());
        let intensity = light
            .color()
            .map(|c| c * light.intensity() / LUMENS_PER_WATT);
        if intensity.iter().any(|v| !(*v >= 0.0 && v.is_finite())) {
            return Err(self.fail(format!(
                "{} has color {:?} and intensity {}; both must be finite and >= 0",
                what(),
                light.color(),
                light.intensity()
            )));
        }
        let position = world.transform_point3(Vec3::ZERO).to_array();
        let axis = world.transform_vector3(Vec3::NEG_Z);
        let direction = axis.try_normalize().ok_or_else(|| {
            self.fail(format!(
                "{}: its node's transform maps -Z to {axis}, which has no direction",
                what()
            ))
        })?;
        let direction = direction.to_array();
        Ok(match light.kind() {
            Kind::Point => PunctualLight::point(position, intensity),
            Kind::Directional => PunctualLight::directional(direction, intensity),
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let (inner, outer) = (inner_cone_angle.to_degrees(), outer_cone_angle.to_degrees());
                if !(inner >= 0.0 && inner <= outer && outer > 0.0 && outer <= 90.0) {
                    return Err(self.fail(format!(
                        "{} has innerConeAngle {inner_cone_angle} and outerConeAngle {outer_cone_angle}; glTF needs 0 <= inner <= outer <= pi/2 (and outer > 0)",
                        what()
                    )));
                }
                // Equal angles (a hard-edged cone, as Blender exports a spot without blend):
                // the kernel's falloff needs inner < outer, so the falloff is made 0.1% of
                // the cone wide.
                let inner = inner.min(outer * (1.0 - 1e-3));
                PunctualLight::spot(position, direction, intensity, inner, outer)
            }
        })
    }

    fn camera(
        &self,
        node: &::gltf::Node,
        perspective: &::gltf::camera::Perspective,
        world: Mat4,
    ) -> Result<CameraFile, IoError> {
        let eye = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(Vec3::NEG_Z);
        let up = world.transform_vector3(Vec3::Y);
        let camera = Camera {
            eye: eye.to_array(),
            target: (eye + forward).to_array(),
            up: up.to_array(),
            fov_y_deg: perspective.yfov().to_degrees(),
            ..Camera::default()
        };
        camera.validate().map_err(|e| {
            self.fail(format!(
                "the camera of node {} is invalid: {}",
                node.index(),
                e.message
            ))
        })?;
        let height = GLTF_DEFAULT_HEIGHT;
        let width = match perspective.aspect_ratio() {
            None => height,
            Some(aspect) => {
                let width = (height as f32 * aspect).round();
                if !(width >= 1.0 && width <= crate::render::MLT_MAX_IMAGE_SIDE as f32) {
                    return Err(self.fail(format!(
                        "the camera of node {} has aspect ratio {aspect}, which gives no usable image size",
                        node.index()
                    )));
                }
                width as u32
            }
        };
        Ok(CameraFile {
            camera,
            width,
            height,
        })
    }

    fn add_primitive(
        &mut self,
        mesh: &::gltf::Mesh,
        primitive: &::gltf::Primitive,
        world: Mat4,
    ) -> Result<(), IoError> {
        if primitive.mode() != Mode::Triangles {
            return Ok(());
        }
        let what = format!("primitive {} of mesh {}", primitive.index(), mesh.index());
        let buffers = self.buffers;
        let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(|d| &d.0[..]));

        let accessor = primitive
            .get(&::gltf::Semantic::Positions)
            .ok_or_else(|| self.fail(format!("{what} has no POSITION attribute")))?;
        if accessor.dimensions() != Dimensions::Vec3 || accessor.data_type() != DataType::F32 {
            return Err(self.fail(format!(
                "the POSITION attribute of {what} is not VEC3 of FLOAT"
            )));
        }
        if accessor.count() == 0 {
            return Ok(());
        }
        let positions: Vec<[f32; 3]> = reader
            .read_positions()
            .ok_or_else(|| {
                self.fail(format!(
                    "the POSITION data of {what} lies outside its buffer"
                ))
            })?
            .collect();
        let vertex_count = positions.len();

        let indices: Vec<u32> = match primitive.indices() {
            None => (0..vertex_count as u32).collect(),
            Some(accessor) => {
                if accessor.dimensions() != Dimensions::Scalar
                    || !matches!(
                        accessor.data_type(),
                        DataType::U8 | DataType::U16 | DataType::U32
                    )
                {
                    return Err(self.fail(format!(
                        "the indices of {what} are not unsigned integer scalars"
                    )));
                }
                if accessor.count() == 0 {
                    return Ok(());
                }
                reader
                    .read_indices()
                    .ok_or_else(|| {
                        self.fail(format!("the index data of {what} lies outside its buffer"))
                    })?
                    .into_u32()
                    .collect()
            }
        };
        if let Some((i, &bad)) = indices
            .iter()
            .enumerate()
            .find(|&(_, &v)| v as usize >= vertex_count)
        {
            return Err(self.fail(format!(
                "index {i} of {what} is {bad}, but it has only {vertex_count} vertices"
            )));
        }

        // gltf's readers take an attribute accessor's element type on trust (a debug
        // assertion only, found by the gltf_glb fuzzer): one of another type would be read
        // with the wrong size. These are the types glTF allows.
        let floats_or_normalized = &[DataType::F32, DataType::U8, DataType::U16][..];
        for (semantic, name, dimensions, types) in [
            (
                ::gltf::Semantic::Normals,
                "NORMAL",
                &[Dimensions::Vec3][..],
                &[DataType::F32][..],
            ),
            (
                ::gltf::Semantic::Tangents,
                "TANGENT",
                &[Dimensions::Vec4],
                &[DataType::F32],
            ),
            (
                ::gltf::Semantic::TexCoords(0),
                "TEXCOORD_0",
                &[Dimensions::Vec2],
                floats_or_normalized,
            ),
            (
                ::gltf::Semantic::Colors(0),
                "COLOR_0",
                &[Dimensions::Vec3, Dimensions::Vec4],
                floats_or_normalized,
            ),
        ] {
            if let Some(accessor) = primitive.get(&semantic)
                && (!dimensions.contains(&accessor.dimensions())
                    || !types.contains(&accessor.data_type()))
            {
                return Err(self.fail(format!(
                    "the {name} attribute of {what} is {:?} of {:?}, which glTF does not allow",
                    accessor.dimensions(),
                    accessor.data_type()
                )));
            }
        }

        let material = self.material(&primitive.material())?;
        let attribute = |what_attribute: &str| {
            self.fail(format!(
                "the {what_attribute} data of {what} lies outside its buffer or has the wrong length"
            ))
        };
        let normals: Option<Vec<[f32; 3]>> = match primitive.get(&::gltf::Semantic::Normals) {
            Some(_) => Some(
                reader
                    .read_normals()
                    .ok_or_else(|| attribute("NORMAL"))?
                    .collect(),
            ),
            None => None,
        };
        let texcoords: Option<Vec<[f32; 2]>> = reader
            .read_tex_coords(0)
            .map(|read| read.into_f32().collect());
        let colors: Option<Vec<[f32; 4]>> = reader
            .read_colors(0)
            .map(|read| read.into_rgba_f32().collect());
        let tangents: Option<Vec<[f32; 4]>> = match reader.read_tangents() {
            Some(read) if self.attributes.tangents => Some(read.collect()),
            _ => None,
        };
        for (name, count) in [
            ("NORMAL", normals.as_ref().map(Vec::len)),
            ("TEXCOORD_0", texcoords.as_ref().map(Vec::len)),
            ("COLOR_0", colors.as_ref().map(Vec::len)),
            ("TANGENT", tangents.as_ref().map(Vec::len)),
        ] {
            if count.is_some_and(|n| n != vertex_count) {
                return Err(attribute(name));
            }
        }

        // Without normals of its own in a scene that has them elsewhere, the primitive is
        // flat-shaded (glTF's rule): each triangle gets its own corners with its face normal.
        let flat = self.attributes.normals && normals.is_none();
        let corners: Vec<u32> = if flat {
            indices.clone()
        } else {
            (0..vertex_count as u32).collect()
        };
        let indices: Vec<u32> = if flat {
            (0..indices.len() as u32).collect()
        } else {
            indices
        };

        let linear = Mat3::from_mat4(world);
        let normal_matrix = linear.inverse().transpose();
        // A mirroring transform turns counter-clockwise into clockwise (swap two corners)
        // and flips the bitangent's handedness.
        let flip = world.determinant() < 0.0;
        let base = (self.data.positions.len() / 3) as u32;
        for &c in &corners {
            let p = world.transform_point3(Vec3::from(positions[c as usize]));
            self.data.positions.extend_from_slice(&p.to_array());
        }
        if self.attributes.normals {
            match &normals {
                Some(normals) => {
                    for &c in &corners {
                        let n = (normal_matrix * Vec3::from(normals[c as usize]))
                            .try_normalize()
                            .ok_or_else(|| {
                                self.fail(format!(
                                    "the normal of vertex {c} of {what} has no direction"
                                ))
                            })?;
                        self.data.normals.extend_from_slice(&n.to_array());
                    }
                }
                None => {
                    for triangle in corners.chunks_exact(3) {
                        let [a, b, c] = [0, 1, 2].map(|k| {
                            world.transform_point3(Vec3::from(positions[triangle[k] as usize]))
                        });
                        let mut n = (b - a).cross(c - a).normalize_or(Vec3::Y);
                        if flip {
                            // The corners are swapped below: the front side stays this one.
                            n = -n;
                        }
                        for _ in 0..3 {
                            self.data.normals.extend_from_slice(&n.to_array());
                        }
                    }
                }
            }
        }
        if self.attributes.texcoords {
            for &c in &corners {
                let uv = texcoords.as_ref().map_or([0.0; 2], |t| t[c as usize]);
                self.data.texcoords.extend_from_slice(&uv);
            }
        }
        if self.attributes.colors {
            for &c in &corners {
                let color = colors.as_ref().map_or([1.0; 4], |t| t[c as usize]);
                self.data.colors.extend_from_slice(&color);
            }
        }
        if let Some(tangents) = &tangents {
            for &c in &corners {
                let [x, y, z, w] = tangents[c as usize];
                let t = (linear * Vec3::new(x, y, z)).normalize_or(Vec3::X);
                let w = if flip { -w.signum() } else { w.signum() };
                self.data.tangents.extend_from_slice(&[t.x, t.y, t.z, w]);
            }
        }
        let triangles = indices.len() / 3;
        for tri in indices.chunks_exact(3) {
            let (b, c) = if flip {
                (tri[2], tri[1])
            } else {
                (tri[1], tri[2])
            };
            self.data
                .indices
                .extend_from_slice(&[base + tri[0], base + b, base + c]);
        }
        self.data
            .material_ids
            .extend(std::iter::repeat_n(material, triangles));
        Ok(())
    }

    /// `KHR_materials_specular` and `KHR_materials_sheen` (read from the JSON: the gltf
    /// crate parses neither), with their textures and the textures' `KHR_texture_transform`;
    /// numbers out of the specifications' ranges are errors.
    fn specular_and_sheen(
        &mut self,
        material: &::gltf::Material,
        converted: &mut Material,
    ) -> Result<(), IoError> {
        let name = material
            .index()
            .map_or("(default)".into(), |i| i.to_string());
        if let Some(extension) = material.extension_value("KHR_materials_specular") {
            let what = "KHR_materials_specular";
            converted.specular =
                self.json_number(extension, "specularFactor", 1.0, (0.0, 1.0), what, &name)?;
            converted.specular_color = self.json_colour(
                extension,
                "specularColorFactor",
                [1.0; 3],
                (0.0, f32::MAX),
                what,
                &name,
            )?;
            converted.specular_texture =
                self.json_texture(extension, "specularTexture", false, what, &name)?;
            converted.specular_color_texture =
                self.json_texture(extension, "specularColorTexture", true, what, &name)?;
        }
        if let Some(extension) = material.extension_value("KHR_materials_sheen") {
            let what = "KHR_materials_sheen";
            converted.sheen_color = self.json_colour(
                extension,
                "sheenColorFactor",
                [0.0; 3],
                (0.0, 1.0),
                what,
                &name,
            )?;
            converted.sheen_roughness = self.json_number(
                extension,
                "sheenRoughnessFactor",
                0.0,
                (0.0, 1.0),
                what,
                &name,
            )?;
            converted.sheen_color_texture =
                self.json_texture(extension, "sheenColorTexture", true, what, &name)?;
            converted.sheen_roughness_texture =
                self.json_texture(extension, "sheenRoughnessTexture", false, what, &name)?;
        }
        Ok(())
    }

    /// The number `key` of an extension's JSON (`default` if absent), within `range`.
    fn json_number(
        &self,
        extension: &::serde_json::Value,
        key: &str,
        default: f32,
        (min, max): (f32, f32),
        what: &str,
        material: &str,
    ) -> Result<f32, IoError> {
        let Some(value) = extension.get(key) else {
            return Ok(default);
        };
        value
            .as_f64()
            .map(|v| v as f32)
            .filter(|v| v.is_finite() && (min..=max).contains(v))
            .ok_or_else(|| {
                self.fail(format!(
                    "material {material}: {what}'s {key} is {value}; it must be a number in [{min}, {max}]"
                ))
            })
    }

    /// The RGB colour `key` of an extension's JSON (`default` if absent), each channel
    /// within `range`.
    fn json_colour(
        &self,
        extension: &::serde_json::Value,
        key: &str,
        default: [f32; 3],
        (min, max): (f32, f32),
        what: &str,
        material: &str,
    ) -> Result<[f32; 3], IoError> {
        let Some(value) = extension.get(key) else {
            return Ok(default);
        };
        let channels: Option<Vec<f32>> = value.as_array().and_then(|a| {
            a.iter()
                .map(|c| c.as_f64().map(|c| c as f32))
                .collect::<Option<Vec<f32>>>()
        });
        match channels.as_deref() {
            Some(&[r, g, b]) if [r, g, b].iter().all(|c| c.is_finite() && (min..=max).contains(c)) => {
                Ok([r, g, b])
            }
            _ => Err(self.fail(format!(
                "material {material}: {what}'s {key} is {value}; it must be three numbers in [{min}, {max}]"
            ))),
        }
    }

    /// The texture `key` of an extension's JSON (a textureInfo), decoded as sRGB or linear,
    /// with its `KHR_texture_transform`.
    fn json_texture(
        &mut self,
        extension: &::serde_json::Value,
        key: &str,
        srgb: bool,
        what: &str,
        material: &str,
    ) -> Result<Option<TextureRef>, IoError> {
        let Some(info) = extension.get(key) else {
            return Ok(None);
        };
        let texture = info
            .get("index")
            .and_then(|i| i.as_u64())
            .and_then(|i| self.document.textures().nth(i as usize))
            .ok_or_else(|| {
                self.fail(format!(
                    "material {material}: {what}'s {key} names no texture of the file"
                ))
            })?;
        let mut reference = self.texture_ref(texture, None, srgb)?;
        if let Some(transform) = info
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_transform"))
        {
            let pair = |key: &str, default: [f32; 2]| -> Option<[f32; 2]> {
                let Some(v) = transform.get(key) else {
                    return Some(default);
                };
                let a = v.as_array()?;
                match a.as_slice() {
                    [x, y] => Some([x.as_f64()? as f32, y.as_f64()? as f32]),
                    _ => None,
                }
            };
            let rotation = match transform.get("rotation") {
                None => Some(0.0),
                Some(r) => r.as_f64().map(|r| r as f32),
            };
            match (pair("offset", [0.0; 2]), rotation, pair("scale", [1.0; 2])) {
                (Some(offset), Some(rotation), Some(scale)) => {
                    reference.offset = offset;
                    reference.rotation = rotation;
                    reference.scale = scale;
                }
                _ => {
                    return Err(self.fail(format!(
                        "material {material}: {what}'s {key} has a malformed KHR_texture_transform"
                    )));
                }
            }
        }
        Ok(Some(reference))
    }

    /// The index in `data.textures` of glTF texture `info` decoded as sRGB or linear, with
    /// its `KHR_texture_transform`.
    fn texture_ref(
        &mut self,
        texture: ::gltf::texture::Texture,
        transform: Option<::gltf::texture::TextureTransform>,
        srgb: bool,
    ) -> Result<TextureRef, IoError> {
        let index = match self.texture_map.get(&(texture.index(), srgb)) {
            Some(&index) => index,
            None => {
                let desc = self.texture(&texture, srgb)?;
                self.data.textures.push(desc);
                let index = (self.data.textures.len() - 1) as u32;
                self.texture_map.insert((texture.index(), srgb), index);
                index
            }
        };
        let mut reference = TextureRef::new(index);
        if let Some(transform) = transform {
            reference.offset = transform.offset();
            reference.rotation = transform.rotation();
            reference.scale = transform.scale();
        }
        Ok(reference)
    }

    /// A glTF texture's image and sampler as a texture: 8-bit images stay 8-bit (sRGB or
    /// linear), 16-bit ones become linear floats (sRGB decoded here), float ones stay floats.
    fn texture(
        &self,
        texture: &::gltf::texture::Texture,
        srgb: bool,
    ) -> Result<TextureDesc<'static>, IoError> {
        use ::gltf::image::Format;
        use ::gltf::texture::{MagFilter, WrappingMode};
        let image = &self.images[texture.source().index()];
        let (channels, bytes_per_channel) = match image.format {
            Format::R8 => (1, 1),
            Format::R8G8 => (2, 1),
            Format::R8G8B8 => (3, 1),
            Format::R8G8B8A8 => (4, 1),
            Format::R16 => (1, 2),
            Format::R16G16 => (2, 2),
            Format::R16G16B16 => (3, 2),
            Format::R16G16B16A16 => (4, 2),
            Format::R32G32B32FLOAT => (3, 4),
            Format::R32G32B32A32FLOAT => (4, 4),
        };
        let colour_channels = if channels % 2 == 0 {
            channels - 1
        } else {
            channels
        };
        let (data, encoding) = match bytes_per_channel {
            1 => (
                TexelData::U8(Cow::Owned(image.pixels.clone())),
                if srgb {
                    TextureEncoding::Srgb
                } else {
                    TextureEncoding::Linear
                },
            ),
            2 => {
                let floats = image
                    .pixels
                    .chunks_exact(2)
                    .enumerate()
                    .map(|(i, b)| {
                        let value = u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0;
                        if srgb && i % channels < colour_channels {
                            srgb_to_linear(value)
                        } else {
                            value
                        }
                    })
                    .collect();
                (TexelData::F32(Cow::Owned(floats)), TextureEncoding::Linear)
            }
            _ => {
                let floats = image
                    .pixels
                    .chunks_exact(4)
                    .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                    .collect();
                (TexelData::F32(Cow::Owned(floats)), TextureEncoding::Linear)
            }
        };
        let wrap = |mode| match mode {
            WrappingMode::Repeat => WrapMode::Repeat,
            WrappingMode::ClampToEdge => WrapMode::ClampToEdge,
            WrappingMode::MirroredRepeat => WrapMode::MirroredRepeat,
        };
        let sampler = texture.sampler();
        Ok(TextureDesc {
            width: image.width,
            height: image.height,
            channels: channels as u32,
            data,
            encoding,
            wrap_u: wrap(sampler.wrap_s()),
            wrap_v: wrap(sampler.wrap_t()),
            filter: match sampler.mag_filter() {
                Some(MagFilter::Nearest) => TextureFilter::Nearest,
                _ => TextureFilter::Bilinear,
            },
        })
    }

    fn material(&mut self, material: &::gltf::Material) -> Result<u32, IoError> {
        if let Some(&id) = self.material_map.get(&material.index()) {
            return Ok(id);
        }
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, a] = pbr.base_color_factor();
        let emission = material
            .emissive_factor()
            .map(|e| e * material.emissive_strength().unwrap_or(1.0));
        let mut converted = Material {
            kind: MaterialKind::MetallicRoughness,
            alpha: a,
            ior: material.ior().unwrap_or(1.5),
            transmission: material
                .transmission()
                .map_or(0.0, |t| t.transmission_factor()),
            alpha_mode: match material.alpha_mode() {
                ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                // Blending is rendered as a cut-out at the cutoff (0.5 by default).
                ::gltf::material::AlphaMode::Mask | ::gltf::material::AlphaMode::Blend => {
                    AlphaMode::Mask
                }
            },
            alpha_cutoff: material.alpha_cutoff().unwrap_or(0.5),
            ..Material::metallic_roughness([r, g, b], pbr.metallic_factor(), pbr.roughness_factor())
        }
        .with_emission(emission);
        if let Some(info) = pbr.base_color_texture() {
            converted.base_color_texture =
                Some(self.texture_ref(info.texture(), info.texture_transform(), true)?);
        }
        if let Some(info) = pbr.metallic_roughness_texture() {
            converted.metallic_roughness_texture =
                Some(self.texture_ref(info.texture(), info.texture_transform(), false)?);
        }
        if let Some(normal) = material.normal_texture() {
            converted.normal_texture = Some(self.texture_ref(normal.texture(), None, false)?);
            converted.normal_scale = normal.scale();
        }
        if let Some(info) = material.emissive_texture() {
            converted.emission_texture =
                Some(self.texture_ref(info.texture(), info.texture_transform(), true)?);
        }
        if let Some(info) = material
            .transmission()
            .and_then(|t| t.transmission_texture())
        {
            converted.transmission_texture =
                Some(self.texture_ref(info.texture(), info.texture_transform(), false)?);
        }
        self.specular_and_sheen(material, &mut converted)?;
        // KHR_materials_dispersion (not parsed by the gltf crate): `dispersion` is 20 / V_d.
        if let Some(extension) = material.extension_value("KHR_materials_dispersion") {
            let dispersion = extension
                .get("dispersion")
                .map_or(Some(0.0), |v| v.as_f64())
                .filter(|d| d.is_finite() && *d >= 0.0)
                .ok_or_else(|| {
                    self.fail(format!(
                        "material {}: KHR_materials_dispersion's dispersion must be a number >= 0",
                        material
                            .index()
                            .map_or("(default)".into(), |i| i.to_string())
                    ))
                })?;
            if dispersion > 0.0 {
                converted.abbe_number = (20.0 / dispersion) as f32;
            }
        }
        if converted.has_textures() && !self.attributes.texcoords {
            // Without texture coordinates every lookup would read one texel; glTF files
            // with textures always carry them, so this is a broken file.
            return Err(self.fail(format!(
                "material {} has textures but no primitive has TEXCOORD_0",
                material
                    .index()
                    .map_or("(default)".into(), |i| i.to_string())
            )));
        }
        let name = match (material.name(), material.index()) {
            (Some(name), _) => name.to_owned(),
            (None, Some(i)) => format!("material {i}"),
            (None, None) => "(default)".to_owned(),
        };
        let id = self.data.push_material(name, converted);
        self.material_map.insert(material.index(), id);
        Ok(id)
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1), for 16-bit colour images.
fn srgb_to_linear(value: f32) -> f32 {
    if value <= 0.04045 {
        value / 12.92
    } else {
        ((value + 0.055) / 1.055).powf(2.4)
    }
}

/// Whether a uri's %XX escapes decode, with the rest of its bytes, to UTF-8.
fn percent_decodes_to_utf8(uri: &str) -> bool {
    let bytes = uri.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let escape = bytes
            .get(i + 1..i + 3)
            .filter(|h| bytes[i] == b'%' && h.iter().all(u8::is_ascii_hexdigit));
        match escape {
            Some(hex) => {
                let hex = std::str::from_utf8(hex).expect("ASCII hex digits");
                decoded.push(u8::from_str_radix(hex, 16).expect("two hex digits"));
                i += 3;
            }
            None => {
                decoded.push(bytes[i]);
                i += 1;
            }
        }
    }
    String::from_utf8(decoded).is_ok()
}
