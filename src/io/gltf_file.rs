//! glTF 2.0 (`.gltf` with external or data-URI buffers, `.glb`); the mapping is documented on
//! [`super::load_scene`].

use super::scene_data::{CameraFile, GLTF_DEFAULT_HEIGHT, IoError, SceneData};
use crate::scene::PunctualLight;
use crate::{Camera, Material};
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// Lumens per watt: glTF's photometric light units (candela for point and spot lights, lux
/// for directional ones) are divided by this, the luminous efficacy of light at 555 nm, to
/// give radiometric ones (W/sr, W/m²). Blender's glTF exporter and importer use the same
/// factor, so a Blender lamp of P watts is P watts here.
pub(crate) const LUMENS_PER_WATT: f32 = 683.0;

pub(super) fn load_gltf(path: &Path) -> Result<SceneData, IoError> {
    let fail =
        |what: String| IoError::new(format!("cannot load glTF file {}: {what}", path.display()));
    let ::gltf::Gltf { document, blob } = ::gltf::Gltf::open(path).map_err(|e| match e {
        ::gltf::Error::Io(e) => {
            IoError::new(format!("cannot read scene file {}: {e}", path.display()))
        }
        e => fail(e.to_string()),
    })?;
    let base = path.parent().unwrap_or(Path::new(""));
    let buffers = ::gltf::import_buffers(&document, Some(base), blob)
        .map_err(|e| fail(format!("cannot load its buffers: {e}")))?;

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| fail("it defines no scene".into()))?;

    let mut loader = Loader {
        path,
        buffers: &buffers,
        data: SceneData::default(),
        material_map: HashMap::new(),
    };
    for node in scene.nodes() {
        loader.visit(&node, Mat4::IDENTITY)?;
    }
    Ok(loader.data)
}

struct Loader<'a> {
    path: &'a Path,
    buffers: &'a [::gltf::buffer::Data],
    data: SceneData,
    /// glTF material index (None: the default material) → index in `data.materials`.
    material_map: HashMap<Option<usize>, u32>,
}

impl Loader<'_> {
    fn fail(&self, what: String) -> IoError {
        IoError::new(format!(
            "cannot load glTF file {}: {what}",
            self.path.display()
        ))
    }

    fn visit(&mut self, node: &::gltf::Node, parent: Mat4) -> Result<(), IoError> {
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
        for child in node.children() {
            self.visit(&child, world)?;
        }
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

        let material = self.material(&primitive.material());
        let base = (self.data.positions.len() / 3) as u32;
        for p in positions {
            let p = world.transform_point3(Vec3::from(p));
            self.data.positions.extend_from_slice(&p.to_array());
        }
        // A mirroring transform turns counter-clockwise into clockwise: swap two corners.
        let flip = world.determinant() < 0.0;
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

    fn material(&mut self, material: &::gltf::Material) -> u32 {
        if let Some(&id) = self.material_map.get(&material.index()) {
            return id;
        }
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let emission = material
            .emissive_factor()
            .map(|e| e * material.emissive_strength().unwrap_or(1.0));
        let transmission = material
            .transmission()
            .map_or(0.0, |t| t.transmission_factor());
        let converted = if transmission > 0.0 {
            Material::dielectric(material.ior().unwrap_or(1.5))
        } else if pbr.metallic_factor() == 1.0 && pbr.roughness_factor() == 0.0 {
            Material::mirror([r, g, b])
        } else {
            Material::diffuse([r, g, b])
        }
        .with_emission(emission);
        let name = match (material.name(), material.index()) {
            (Some(name), _) => name.to_owned(),
            (None, Some(i)) => format!("material {i}"),
            (None, None) => "(default)".to_owned(),
        };
        let id = self.data.push_material(name, converted);
        self.material_map.insert(material.index(), id);
        id
    }
}
