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

/// Extensions the gltf crate does not know that this loader reads from the materials' JSON
/// itself: a file that requires them is accepted (the crate refuses required extensions
/// it does not know).
const EXTENSIONS_READ_HERE: &[&str] = &[
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_dispersion",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
];

/// Loads `path`, with each primitive's default material or, given `variant`, the material its
/// `KHR_materials_variants` mapping gives that variant (the default where it maps none).
pub(super) fn load_gltf(path: &Path, variant: Option<&str>) -> Result<SceneData, IoError> {
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
    let mut json = json;
    json.extensions_required
        .retain(|name| !EXTENSIONS_READ_HERE.contains(&name.as_str()));
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

    let variant_materials = variant_materials(&document, variant).map_err(fail)?;

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
        texcoords: [0, 1]
            .map(|set| triangle_primitives().any(|p| p.get(&Semantic::TexCoords(set)).is_some())),
        colors: triangle_primitives().any(|p| p.get(&Semantic::Colors(0)).is_some()),
        tangents: triangle_primitives().next().is_some()
            && triangle_primitives().all(|p| {
                p.get(&Semantic::Tangents).is_some() && p.get(&Semantic::Normals).is_some()
            }),
    };
    let mut loader = Loader {
        path,
        buffers: &buffers,
        images: &images,
        attributes,
        data: SceneData::default(),
        material_map: HashMap::new(),
        texture_map: HashMap::new(),
        textures: document.textures().collect(),
        variant_materials,
        materials: document.materials().collect(),
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
    /// Some primitive has TEXCOORD_0, TEXCOORD_1 (the others get (0, 0)).
    texcoords: [bool; 2],
    /// Some primitive has COLOR_0 (the others get white).
    colors: bool,
    /// Every primitive has tangents and normals (else MikkTSpace computes them all).
    tangents: bool,
}

struct Loader<'a> {
    path: &'a Path,
    buffers: &'a [::gltf::buffer::Data],
    images: &'a [::gltf::image::Data],
    attributes: Attributes,
    data: SceneData,
    /// glTF material index (None: the default material) → index in `data.materials`.
    material_map: HashMap<Option<usize>, u32>,
    /// (glTF texture index, sRGB) → index in `data.textures`: an image used both as colour
    /// and as data becomes two textures.
    texture_map: HashMap<(usize, bool), u32>,
    /// The file's textures, for the extensions read from JSON, which name them by index.
    textures: Vec<::gltf::texture::Texture<'a>>,
    /// (mesh index, primitive index) → the glTF material the chosen variant gives it.
    variant_materials: HashMap<(usize, usize), usize>,
    /// The file's materials, by glTF index.
    materials: Vec<::gltf::Material<'a>>,
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

        let material = match self
            .variant_materials
            .get(&(mesh.index(), primitive.index()))
        {
            Some(&index) => self.material(&self.materials[index].clone())?,
            None => self.material(&primitive.material())?,
        };
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
        let texcoords: [Option<Vec<[f32; 2]>>; 2] = [0, 1].map(|set| {
            reader
                .read_tex_coords(set)
                .map(|read| read.into_f32().collect())
        });
        let colors: Option<Vec<[f32; 4]>> = reader
            .read_colors(0)
            .map(|read| read.into_rgba_f32().collect());
        let tangents: Option<Vec<[f32; 4]>> = match reader.read_tangents() {
            Some(read) if self.attributes.tangents => Some(read.collect()),
            _ => None,
        };
        for (name, count) in [
            ("NORMAL", normals.as_ref().map(Vec::len)),
            ("TEXCOORD_0", texcoords[0].as_ref().map(Vec::len)),
            ("TEXCOORD_1", texcoords[1].as_ref().map(Vec::len)),
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
        let texcoord_sets = [&mut self.data.texcoords, &mut self.data.texcoords1];
        for ((present, values), out) in self
            .attributes
            .texcoords
            .iter()
            .zip(&texcoords)
            .zip(texcoord_sets)
        {
            if *present {
                for &c in &corners {
                    let uv = values.as_ref().map_or([0.0; 2], |t| t[c as usize]);
                    out.extend_from_slice(&uv);
                }
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

    /// `KHR_materials_specular`, `KHR_materials_sheen` and `KHR_materials_iridescence`
    /// (read from the JSON: the gltf crate parses none of them), with their textures and the textures' `KHR_texture_transform`;
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
        if let Some(extension) = material.extension_value("KHR_materials_iridescence") {
            let what = "KHR_materials_iridescence";
            converted.iridescence =
                self.json_number(extension, "iridescenceFactor", 0.0, (0.0, 1.0), what, &name)?;
            converted.iridescence_ior = self.json_number(
                extension,
                "iridescenceIor",
                1.3,
                (1.0, f32::MAX),
                what,
                &name,
            )?;
            converted.iridescence_thickness_minimum = self.json_number(
                extension,
                "iridescenceThicknessMinimum",
                100.0,
                (0.0, f32::MAX),
                what,
                &name,
            )?;
            converted.iridescence_thickness_maximum = self.json_number(
                extension,
                "iridescenceThicknessMaximum",
                400.0,
                (0.0, f32::MAX),
                what,
                &name,
            )?;
            converted.iridescence_texture =
                self.json_texture(extension, "iridescenceTexture", false, what, &name)?;
            converted.iridescence_thickness_texture =
                self.json_texture(extension, "iridescenceThicknessTexture", false, what, &name)?;
        }
        Ok(())
    }

    /// `KHR_materials_anisotropy` (read from the JSON: the gltf crate does not parse it):
    /// strength, rotation and texture (linear); a strength outside [0, 1] or a rotation
    /// that is not a finite number is an error.
    fn anisotropy(
        &mut self,
        material: &::gltf::Material,
        converted: &mut Material,
    ) -> Result<(), IoError> {
        let Some(extension) = material.extension_value("KHR_materials_anisotropy") else {
            return Ok(());
        };
        let name = material
            .index()
            .map_or("(default)".into(), |i| i.to_string());
        let what = "KHR_materials_anisotropy";
        converted.anisotropy = self.json_number(
            extension,
            "anisotropyStrength",
            0.0,
            (0.0, 1.0),
            what,
            &name,
        )?;
        if let Some(value) = extension.get("anisotropyRotation") {
            converted.anisotropy_rotation = value
                .as_f64()
                .map(|v| v as f32)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    self.fail(format!(
                        "material {name}: {what}'s anisotropyRotation is {value}; it must be a finite number (radians)"
                    ))
                })?;
        }
        converted.anisotropy_texture =
            self.json_texture(extension, "anisotropyTexture", false, what, &name)?;
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
        extension
            .get(key)
            .map(|info| {
                self.texture_info(info, &format!("material {material}: {what}'s {key}"), srgb)
            })
            .transpose()
    }

    /// The index in `data.textures` of glTF texture `info` decoded as sRGB or linear, with
    /// its `KHR_texture_transform`.
    fn texture_ref(
        &mut self,
        texture: ::gltf::texture::Texture,
        texcoord: u32,
        transform: Option<::gltf::texture::TextureTransform>,
        srgb: bool,
    ) -> Result<TextureRef, IoError> {
        // KHR_texture_transform may name another set than the textureInfo's.
        let texcoord = transform
            .as_ref()
            .and_then(|t| t.tex_coord())
            .unwrap_or(texcoord);
        if texcoord > 1 {
            return Err(self.fail(format!(
                "texture {} uses TEXCOORD_{texcoord}; mlt reads the sets TEXCOORD_0 and TEXCOORD_1",
                texture.index()
            )));
        }
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
        let mut reference = TextureRef {
            texcoord,
            ..TextureRef::new(index)
        };
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
                ::gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            alpha_cutoff: material.alpha_cutoff().unwrap_or(0.5),
            ..Material::metallic_roughness([r, g, b], pbr.metallic_factor(), pbr.roughness_factor())
        }
        .with_emission(emission);
        if let Some(info) = pbr.base_color_texture() {
            converted.base_color_texture = Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                info.texture_transform(),
                true,
            )?);
        }
        if let Some(info) = pbr.metallic_roughness_texture() {
            converted.metallic_roughness_texture = Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                info.texture_transform(),
                false,
            )?);
        }
        if let Some(normal) = material.normal_texture() {
            converted.normal_texture =
                Some(self.texture_ref(normal.texture(), normal.tex_coord(), None, false)?);
            converted.normal_scale = normal.scale();
        }
        if let Some(info) = material.emissive_texture() {
            converted.emission_texture = Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                info.texture_transform(),
                true,
            )?);
        }
        if let Some(info) = material
            .transmission()
            .and_then(|t| t.transmission_texture())
        {
            converted.transmission_texture = Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                info.texture_transform(),
                false,
            )?);
        }
        self.specular_and_sheen(material, &mut converted)?;
        self.anisotropy(material, &mut converted)?;
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
        if let Some(extension) = material.extension_value("KHR_materials_clearcoat") {
            self.clearcoat(material, extension, &mut converted)?;
        }
        if let Some(extension) = material.extension_value("KHR_materials_volume") {
            self.read_volume(material, extension, &mut converted)?;
        }
        // KHR_materials_unlit (not parsed by the gltf crate): the base colour (times its
        // texture) is emitted as radiance and nothing is scattered, so the surface looks its
        // colour to every path and is one consistent light in every algorithm. The base
        // colour texture stays for its alpha.
        if material.extension_value("KHR_materials_unlit").is_some() {
            converted = Material {
                kind: MaterialKind::Diffuse,
                color: [0.0; 3],
                emission_texture: converted.base_color_texture,
                metallic_roughness_texture: None,
                normal_texture: None,
                transmission_texture: None,
                ..converted
            }
            .with_emission([r, g, b]);
        }
        // Without texture coordinates every lookup would read one texel; glTF files with
        // textures always carry them, so this is a broken file.
        if let Some((slot, texture)) = converted
            .textures()
            .find(|(_, t)| !self.attributes.texcoords[t.texcoord as usize])
        {
            return Err(self.fail(format!(
                "material {}'s {slot} uses TEXCOORD_{} but no primitive has it",
                material
                    .index()
                    .map_or("(default)".into(), |i| i.to_string()),
                texture.texcoord
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

impl Loader<'_> {
    /// `KHR_materials_clearcoat` (not parsed by the gltf crate): the factors, each a number
    /// in [0, 1] (default 0), and the three textures (the normal map with its scale).
    fn clearcoat(
        &mut self,
        material: &::gltf::Material,
        extension: &serde_json::Value,
        converted: &mut Material,
    ) -> Result<(), IoError> {
        let label = material
            .index()
            .map_or("(default)".into(), |i| i.to_string());
        let what = |field: &str| format!("material {label}: KHR_materials_clearcoat's {field}");
        let extension_name = "KHR_materials_clearcoat";
        converted.clearcoat = self.json_number(
            extension,
            "clearcoatFactor",
            0.0,
            (0.0, 1.0),
            extension_name,
            &label,
        )?;
        converted.clearcoat_roughness = self.json_number(
            extension,
            "clearcoatRoughnessFactor",
            0.0,
            (0.0, 1.0),
            extension_name,
            &label,
        )?;
        if let Some(info) = extension.get("clearcoatTexture") {
            converted.clearcoat_texture =
                Some(self.texture_info(info, &what("clearcoatTexture"), false)?);
        }
        if let Some(info) = extension.get("clearcoatRoughnessTexture") {
            converted.clearcoat_roughness_texture =
                Some(self.texture_info(info, &what("clearcoatRoughnessTexture"), false)?);
        }
        if let Some(info) = extension.get("clearcoatNormalTexture") {
            let name = what("clearcoatNormalTexture");
            converted.clearcoat_normal_texture = Some(self.texture_info(info, &name, false)?);
            converted.clearcoat_normal_scale = match info.get("scale") {
                None => 1.0,
                Some(value) => value
                    .as_f64()
                    .filter(|v| v.is_finite())
                    .map(|v| v as f32)
                    .ok_or_else(|| {
                        self.fail(format!("{name}'s scale is {value}; it must be a number"))
                    })?,
            };
        }
        Ok(())
    }

    /// A texture named by a textureInfo read from JSON (`{"index": i, "texCoord": 0}`, with
    /// its `KHR_texture_transform`), decoded as sRGB colour or linear data.
    fn texture_info(
        &mut self,
        info: &serde_json::Value,
        what: &str,
        srgb: bool,
    ) -> Result<TextureRef, IoError> {
        let texture = info
            .get("index")
            .and_then(serde_json::Value::as_u64)
            .and_then(|i| self.textures.get(usize::try_from(i).ok()?))
            .cloned()
            .ok_or_else(|| {
                self.fail(format!(
                    "{what} has index {}; it must name one of the {} textures",
                    info.get("index").map_or("none".into(), |v| v.to_string()),
                    self.textures.len()
                ))
            })?;
        let transform = info
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_transform"));
        // KHR_texture_transform's texCoord overrides the textureInfo's, as `texture_ref` does.
        let texcoord = transform
            .and_then(|t| t.get("texCoord"))
            .or_else(|| info.get("texCoord"))
            .map_or(Some(0), |v| v.as_u64().and_then(|v| u32::try_from(v).ok()))
            .ok_or_else(|| self.fail(format!("{what}'s texCoord must be a set index")))?;
        let mut reference = self.texture_ref(texture, texcoord, None, srgb)?;
        if let Some(transform) = transform {
            let numbers = |field: &str, default: &[f32]| -> Result<Vec<f32>, IoError> {
                let Some(value) = transform.get(field) else {
                    return Ok(default.to_vec());
                };
                let values: Option<Vec<f32>> = match value {
                    serde_json::Value::Array(items) => {
                        items.iter().map(|v| v.as_f64().map(|v| v as f32)).collect()
                    }
                    other => other.as_f64().map(|v| vec![v as f32]),
                };
                values
                    .filter(|v| v.len() == default.len() && v.iter().all(|x| x.is_finite()))
                    .ok_or_else(|| {
                        self.fail(format!(
                            "{what}'s KHR_texture_transform {field} is {value}; it must be {} finite numbers",
                            default.len()
                        ))
                    })
            };
            let offset = numbers("offset", &[0.0, 0.0])?;
            let scale = numbers("scale", &[1.0, 1.0])?;
            reference.offset = [offset[0], offset[1]];
            reference.rotation = numbers("rotation", &[0.0])?[0];
            reference.scale = [scale[0], scale[1]];
        }
        Ok(reference)
    }
    /// `KHR_materials_volume` (read here, not by the gltf crate, to check its values):
    /// `thicknessFactor` (>= 0; 0 is thin-walled), `attenuationColor` (RGB in [0, 1]) and
    /// `attenuationDistance` (> 0; absent: infinity, no absorption). The thickness texture
    /// is not read: a path tracer measures the distances through the mesh itself, and the
    /// factor alone tells a thin wall from a volume.
    fn read_volume(
        &self,
        material: &::gltf::Material,
        extension: &::gltf::json::Value,
        converted: &mut Material,
    ) -> Result<(), IoError> {
        let fail = |what: &str| {
            self.fail(format!(
                "material {}: KHR_materials_volume's {what}",
                material
                    .index()
                    .map_or("(default)".into(), |i| i.to_string())
            ))
        };
        let number = |key: &str| {
            extension
                .get(key)
                .map(|v| v.as_f64().filter(|x| x.is_finite()))
        };
        converted.thickness = match number("thicknessFactor") {
            None => 0.0,
            Some(Some(t)) if t >= 0.0 => t.min(f32::MAX as f64) as f32,
            Some(_) => return Err(fail("thicknessFactor must be a number >= 0")),
        };
        converted.attenuation_distance = match number("attenuationDistance") {
            None => f32::MAX,
            Some(Some(d)) if d > 0.0 => d.min(f32::MAX as f64) as f32,
            Some(_) => return Err(fail("attenuationDistance must be a number > 0")),
        };
        if let Some(color) = extension.get("attenuationColor") {
            let rgb: Option<Vec<f64>> = color.as_array().and_then(|values| {
                values
                    .iter()
                    .map(|v| v.as_f64().filter(|c| (0.0..=1.0).contains(c)))
                    .collect()
            });
            match rgb.as_deref() {
                Some(&[r, g, b]) => {
                    converted.attenuation_color = [r as f32, g as f32, b as f32];
                }
                _ => {
                    return Err(fail("attenuationColor must be three numbers in [0, 1]"));
                }
            }
        }
        Ok(())
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1), for 16-bit colour images.
/// Reads `KHR_materials_variants`: the variant names at the root and every primitive's
/// mappings, checked whether a variant is chosen or not. Returns, for the (first) variant
/// named `variant`, the material of each primitive that maps one to it (empty without a variant).
fn variant_materials(
    document: &::gltf::Document,
    variant: Option<&str>,
) -> Result<HashMap<(usize, usize), usize>, String> {
    const EXTENSION: &str = "KHR_materials_variants";
    let names: Vec<&str> = match document.extension_value(EXTENSION) {
        None => Vec::new(),
        Some(root) => root
            .get("variants")
            .and_then(|v| v.as_array())
            .ok_or_else(|| format!("its {EXTENSION} has no variants array"))?
            .iter()
            .enumerate()
            .map(|(i, v)| {
                v.get("name")
                    .and_then(|n| n.as_str())
                    .ok_or_else(|| format!("variant {i} of its {EXTENSION} has no name"))
            })
            .collect::<Result<_, _>>()?,
    };
    let chosen = match variant {
        None => None,
        Some(wanted) if names.is_empty() => {
            return Err(format!(
                "it has no material variants ({EXTENSION}), so variant {wanted:?} cannot be chosen"
            ));
        }
        Some(wanted) => Some(names.iter().position(|&n| n == wanted).ok_or_else(|| {
            format!(
                "it has no material variant {wanted:?}; its variants are {}",
                names
                    .iter()
                    .map(|n| format!("{n:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })?),
    };
    let material_count = document.materials().len();
    let mut chosen_materials = HashMap::new();
    for mesh in document.meshes() {
        for primitive in mesh.primitives() {
            let Some(extension) = primitive.extension_value(EXTENSION) else {
                continue;
            };
            let what = format!(
                "{EXTENSION} of primitive {} of mesh {}",
                primitive.index(),
                mesh.index()
            );
            let mappings = extension
                .get("mappings")
                .and_then(|m| m.as_array())
                .ok_or_else(|| format!("the {what} has no mappings array"))?;
            // The specification lets each variant appear in one mapping of a primitive.
            let mut mapped = vec![false; names.len()];
            for (m, mapping) in mappings.iter().enumerate() {
                let material = mapping
                    .get("material")
                    .and_then(|v| v.as_u64())
                    .ok_or_else(|| format!("mapping {m} of the {what} has no material index"))?;
                if material >= material_count as u64 {
                    return Err(format!(
                        "mapping {m} of the {what} names material {material}, but there are {material_count} materials"
                    ));
                }
                let variants = mapping
                    .get("variants")
                    .and_then(|v| v.as_array())
                    .ok_or_else(|| format!("mapping {m} of the {what} has no variants array"))?;
                for index in variants {
                    let index = index
                        .as_u64()
                        .filter(|&i| i < names.len() as u64)
                        .ok_or_else(|| {
                            format!(
                                "mapping {m} of the {what} names variant {index}, but there are {} variants",
                                names.len()
                            )
                        })? as usize;
                    if std::mem::replace(&mut mapped[index], true) {
                        return Err(format!(
                            "mapping {m} of the {what} names variant {index}, which an earlier mapping names"
                        ));
                    }
                    if chosen == Some(index) {
                        chosen_materials
                            .insert((mesh.index(), primitive.index()), material as usize);
                    }
                }
            }
        }
    }
    Ok(chosen_materials)
}

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
