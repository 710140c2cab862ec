//! The validated, immutable scene: geometry in the backend's order, materials, area lights.

mod camera;
mod light_desc;
pub(crate) mod lights;
mod material;
pub(crate) mod medium;
pub(crate) mod surface;
mod tangents;

pub use camera::{Camera, CameraModel};
pub use light_desc::{
    EnvironmentDesc, LightsDesc, MLT_MAX_ENVIRONMENT_SIDE, MLT_MAX_ENVIRONMENT_TEXELS,
    MLT_MAX_PUNCTUAL_LIGHTS, PunctualLight, PunctualLightKind, SunDesc,
};
pub use lights::AreaLight;
pub use material::{AlphaMode, Material, MaterialKind, TextureRef};

use crate::accel::{Accel, Backend, BuildQuality, Filtering, Hit, Ray};
use crate::error::{Error, Result};
use crate::spectral::Channels;
use crate::spectrum::Spectrum;
use crate::texture::{Texture, TextureDesc};
use glam::Vec3A;

/// A ray query a render made, with the answer it got (see `Scene::record_queries`).
#[cfg_attr(
    not(any(test, feature = "internals")),
    expect(
        dead_code,
        reason = "the recording is read by the overhead bench and its test"
    )
)]
#[derive(Clone, Copy, Debug)]
pub enum RecordedQuery {
    /// A closest-hit query (`Accel::intersect`).
    ClosestHit { ray: Ray, hit: Option<Hit> },
    /// An occlusion query (`Accel::occluded`).
    Occluded { ray: Ray, occluded: bool },
}

/// Host-side description of a scene: plain arrays, as the C ABI passes them.
#[derive(Clone, Copy, Debug)]
pub struct SceneDesc<'a> {
    /// x, y, z per vertex.
    pub positions: &'a [f32],
    /// Three vertex indices per triangle; counter-clockwise is the front side.
    pub indices: &'a [u32],
    /// One material index per triangle; empty means material 0 for every triangle.
    pub material_ids: &'a [u32],
    pub materials: &'a [Material],
    /// Lights besides the emissive triangles: environment, sun, punctual lights.
    pub lights: LightsDesc<'a>,
    pub backend: Backend,
    /// How much work the acceleration structure's build spends for faster rays.
    pub build_quality: BuildQuality,
    /// Per-vertex shading normals, x, y, z per vertex (any nonzero length; normalized on
    /// use), or empty for flat triangles. Interpolated across each triangle; a normal on the
    /// back side of its triangle is turned to the front.
    pub normals: &'a [f32],
    /// Per-vertex texture coordinates, u, v per vertex, or empty. glTF's convention: (0, 0)
    /// is the top-left corner of a texture, v grows downwards.
    pub texcoords: &'a [f32],
    /// A second set of per-vertex texture coordinates (glTF `TEXCOORD_1`), u, v per vertex,
    /// or empty; textures whose `TextureRef::texcoord` is 1 are looked up at these.
    pub texcoords1: &'a [f32],
    /// Per-vertex tangents for normal maps, x, y, z, w per vertex (w = ±1: the bitangent
    /// is w · normal × tangent, glTF's convention), or empty: then they are computed with
    /// MikkTSpace where a material has a normal map.
    pub tangents: &'a [f32],
    /// Per-vertex linear RGBA colours in [0, 1] multiplying the base colour and alpha (glTF
    /// `COLOR_0`), or empty.
    pub colors: &'a [f32],
    /// Textures the materials refer to by index. A scene with a textured material needs
    /// `texcoords`.
    pub textures: &'a [TextureDesc<'a>],
}

impl Default for SceneDesc<'_> {
    /// No geometry, no lights, the default backend.
    fn default() -> Self {
        SceneDesc {
            positions: &[],
            indices: &[],
            material_ids: &[],
            materials: &[],
            lights: LightsDesc::default(),
            backend: Backend::default(),
            build_quality: BuildQuality::default(),
            normals: &[],
            texcoords: &[],
            texcoords1: &[],
            tangents: &[],
            colors: &[],
            textures: &[],
        }
    }
}

impl<'a> SceneDesc<'a> {
    fn vertex_arrays(&self) -> surface::VertexArrays<'a> {
        surface::VertexArrays {
            normals: self.normals,
            texcoords: self.texcoords,
            texcoords1: self.texcoords1,
            tangents: self.tangents,
            colors: self.colors,
        }
    }
}

/// Facts about a built scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneInfo {
    pub triangle_count: usize,
    /// Triangles with zero area (or a non-finite normal): kept in the id space, never hit,
    /// never emit.
    pub degenerate_triangle_count: usize,
    /// Non-degenerate triangles with emission: the area lights.
    pub emitter_count: usize,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    /// The acceleration structure's build quality, the bytes it holds
    /// (`Accel::memory_bytes`) and the seconds its build took.
    pub build_quality: BuildQuality,
    pub accel_memory_bytes: usize,
    pub accel_build_seconds: f64,
}

/// Per-triangle data the integrators read after a hit, in the backend's internal order.
#[derive(Clone, Copy, Debug)]
pub struct TriangleShading {
    /// Unit geometric normal of the front (counter-clockwise) side.
    pub normal: Vec3A,
    pub material: u32,
    /// Probability density per unit area of picking a point on this triangle by light
    /// sampling (selection probability / area); 0 for non-emitters.
    pub light_area_pdf: f32,
}

pub struct Scene {
    pub(crate) accel: Accel,
    pub(crate) shading: Vec<TriangleShading>,
    /// Per-corner vertex attributes, in internal triangle order.
    attributes: surface::SurfaceAttributes,
    textures: Vec<Texture>,
    pub(crate) materials: Vec<Material>,
    /// Each material's absorbing volume, if it has one (see `medium`).
    media: Vec<Option<medium::Medium>>,
    /// Whether some material has a volume: else `transmittance` is 1 without a look.
    has_media: bool,
    /// Each material's constant colour and emission with their spectral fits.
    material_colours: Vec<surface::MaterialColours>,
    /// Every light, in selection order: area lights (in the host's triangle order), punctual
    /// lights, a delta sun, the lights at infinity; with their selection distribution.
    pub(crate) lights: lights::SceneLights,
    /// Whether some triangle's material is an alpha cut-out (`AlphaMode::Mask`) or blended
    /// (`AlphaMode::Blend`, a cut-out at a per-point threshold): then ray queries test
    /// candidate hits against its alpha.
    has_cutouts: bool,
    /// Whether ray queries leave the plain structure query for `closest_hit_slow` and
    /// `blocked_slow`: `has_cutouts`, or a ray recording is on. One flag, so a normal query
    /// tests exactly what it tested before recordings existed.
    slow_queries: bool,
    /// The ray recording `record_queries` started, if any (the overhead bench's).
    recording: Option<Box<std::sync::Mutex<Vec<RecordedQuery>>>>,
    /// Internal triangle index → the host's triangle id.
    internal_to_input: Vec<u32>,
    /// Offset that moves ray origins off surfaces, scaled to the scene's coordinates.
    pub(crate) ray_epsilon: f32,
    info: SceneInfo,
    fingerprint: u64,
}

/// XXH3-64 of a scene description: its arrays as bytes, its small structs (materials,
/// lights, texture settings) by their `Debug` form, which names every field and prints
/// every float exactly.
fn fingerprint(desc: &SceneDesc) -> u64 {
    use xxhash_rust::xxh3::Xxh3;
    fn words<T: Copy>(hasher: &mut Xxh3, values: &[T], bytes: impl Fn(T) -> [u8; 4]) {
        hasher.update(&(values.len() as u64).to_le_bytes());
        let mut buffer = [0u8; 1024];
        for chunk in values.chunks(buffer.len() / 4) {
            for (slot, &v) in buffer.chunks_exact_mut(4).zip(chunk) {
                slot.copy_from_slice(&bytes(v));
            }
            hasher.update(&buffer[..chunk.len() * 4]);
        }
    }
    let floats = |h: &mut Xxh3, v: &[f32]| words(h, v, f32::to_le_bytes);
    let mut h = Xxh3::new();
    floats(&mut h, desc.positions);
    words(&mut h, desc.indices, u32::to_le_bytes);
    words(&mut h, desc.material_ids, u32::to_le_bytes);
    floats(&mut h, desc.normals);
    floats(&mut h, desc.texcoords);
    // Only when given: the fingerprints of scenes with one set stay as they were.
    if !desc.texcoords1.is_empty() {
        floats(&mut h, desc.texcoords1);
    }
    floats(&mut h, desc.tangents);
    floats(&mut h, desc.colors);
    let LightsDesc {
        environment,
        sun,
        punctual,
    } = desc.lights;
    if let Some(environment) = environment {
        floats(&mut h, environment.pixels);
    }
    let small = format!(
        "{:?} {:?} {:?} {:?} {:?} {:?}",
        desc.materials,
        environment.map(|e| (e.width, e.height, e.rotation_degrees, e.scale)),
        sun,
        punctual,
        desc.backend,
        desc.build_quality,
    );
    h.update(small.as_bytes());
    for texture in desc.textures {
        let settings = format!(
            "{} {} {} {:?} {:?} {:?} {:?}",
            texture.width,
            texture.height,
            texture.channels,
            texture.encoding,
            texture.wrap_u,
            texture.wrap_v,
            texture.filter
        );
        h.update(settings.as_bytes());
        match &texture.data {
            crate::texture::TexelData::U8(bytes) => {
                h.update(&(bytes.len() as u64).to_le_bytes());
                h.update(bytes);
            }
            crate::texture::TexelData::F32(values) => floats(&mut h, values),
        }
    }
    h.digest()
}

impl Scene {
    /// Validates the description and builds the acceleration structure.
    pub fn new(desc: &SceneDesc) -> Result<Scene> {
        validate_arrays(desc)?;
        desc.lights.validate()?;
        let textures = desc
            .textures
            .iter()
            .enumerate()
            .map(|(i, texture)| Texture::new(texture, i))
            .collect::<Result<Vec<_>>>()?;
        let tangents = corner_tangents(desc);
        let vertex = |i: u32| {
            let i = i as usize * 3;
            Vec3A::new(
                desc.positions[i],
                desc.positions[i + 1],
                desc.positions[i + 2],
            )
        };
        let triangle_count = desc.indices.len() / 3;
        let mut kept_vertices = Vec::with_capacity(triangle_count);
        let mut kept_ids = Vec::with_capacity(triangle_count);
        let vertex_arrays = desc.vertex_arrays();
        let mut bounds_min = Vec3A::splat(f32::INFINITY);
        let mut bounds_max = Vec3A::splat(f32::NEG_INFINITY);
        for (id, tri) in desc.indices.chunks_exact(3).enumerate() {
            let v = [vertex(tri[0]), vertex(tri[1]), vertex(tri[2])];
            let normal = (v[1] - v[0]).cross(v[2] - v[0]);
            let length = normal.length();
            if !(length > 0.0 && length.is_finite()) {
                continue;
            }
            for p in v {
                bounds_min = bounds_min.min(p);
                bounds_max = bounds_max.max(p);
            }
            kept_vertices.push(v);
            kept_ids.push(id as u32);
        }
        if kept_vertices.is_empty() {
            bounds_min = Vec3A::ZERO;
            bounds_max = Vec3A::ZERO;
        }

        let has_cutouts = desc
            .materials
            .iter()
            .any(|m| m.alpha_mode != AlphaMode::Opaque);
        let filtering = if has_cutouts {
            Filtering::Filtered
        } else {
            Filtering::Unfiltered
        };
        let build_start = std::time::Instant::now();
        let accel = Accel::build(desc.backend, desc.build_quality, &kept_vertices, filtering)?;
        let accel_build_seconds = build_start.elapsed().as_secs_f64();
        let order = accel.internal_to_build_order();

        let material_of = |id: u32| {
            if desc.material_ids.is_empty() {
                0
            } else {
                desc.material_ids[id as usize]
            }
        };
        let mut shading = Vec::with_capacity(order.len());
        let mut attributes = surface::SurfaceAttributes::with_capacity(&vertex_arrays, order.len());
        let mut internal_to_input = Vec::with_capacity(order.len());
        let mut lights = Vec::new();
        for (internal, &build) in order.iter().enumerate() {
            let [v0, v1, v2] = kept_vertices[build as usize];
            let id = kept_ids[build as usize];
            let material = material_of(id);
            let cross = (v1 - v0).cross(v2 - v0);
            let normal = cross.normalize();
            let emission = Spectrum::from(desc.materials[material as usize].emission);
            if emission.max_component() > 0.0 {
                lights.push(AreaLight {
                    v0,
                    edge1: v1 - v0,
                    edge2: v2 - v0,
                    normal,
                    emission,
                    power_scale: 1.0,
                    area_pdf: 0.0,
                    triangle: internal as u32,
                });
            }
            shading.push(TriangleShading {
                normal,
                material,
                light_area_pdf: 0.0,
            });
            internal_to_input.push(id);
            let corners = &desc.indices[id as usize * 3..id as usize * 3 + 3];
            attributes.push(
                &vertex_arrays,
                [corners[0], corners[1], corners[2]],
                cross.length(),
                &tangents,
                id,
            );
        }
        let material_colours: Vec<surface::MaterialColours> = desc
            .materials
            .iter()
            .map(surface::MaterialColours::new)
            .collect();
        for light in &mut lights {
            let index = shading[light.triangle as usize].material as usize;
            let material = &desc.materials[index];
            if material.emission_texture.is_some() {
                let point = |barycentrics| surface::SurfacePoint {
                    attributes: &attributes,
                    textures: &textures,
                    material,
                    colours: &material_colours[index],
                    triangle: light.triangle,
                    barycentrics,
                    footprint: 0.0,
                };
                light.power_scale = surface::mean_emission_scale(point, light.emission);
            }
        }
        // Lights in the host's triangle order, not the backend's: the same seed then picks
        // the same lights with either backend.
        lights.sort_by_key(|light| internal_to_input[light.triangle as usize]);
        let emitter_count = lights.len();
        let center = (bounds_min + bounds_max) * 0.5;
        // A little larger than the box's sphere: rays from its disc start outside the geometry.
        let radius = ((bounds_max - bounds_min).length() * 0.5 * 1.01).max(1e-3);
        // Lights are picked in proportion to their emitted power.
        let scene_lights =
            lights::SceneLights::new(lights, &desc.lights, (center, radius), |internal| {
                internal_to_input[internal as usize]
            })?;
        for (triangle, area_pdf) in scene_lights.area_light_pdfs() {
            shading[triangle as usize].light_area_pdf = area_pdf;
        }
        let magnitude = bounds_min
            .abs()
            .max(bounds_max.abs())
            .max_element()
            .max(1e-3);
        let info = SceneInfo {
            triangle_count,
            degenerate_triangle_count: triangle_count - order.len(),
            emitter_count,
            bounds_min: bounds_min.to_array(),
            bounds_max: bounds_max.to_array(),
            build_quality: desc.build_quality,
            accel_memory_bytes: accel.memory_bytes(),
            accel_build_seconds,
        };
        let media: Vec<Option<medium::Medium>> =
            desc.materials.iter().map(medium::Medium::of).collect();
        let has_media = media.iter().any(Option::is_some);
        Ok(Scene {
            accel,
            shading,
            media,
            has_media,
            has_cutouts,
            slow_queries: has_cutouts,
            recording: None,
            attributes,
            textures,
            materials: desc.materials.to_vec(),
            material_colours,
            lights: scene_lights,
            internal_to_input,
            ray_epsilon: magnitude * 2e-5,
            info,
            fingerprint: fingerprint(desc),
        })
    }

    /// A hash of everything the scene was built from: the jobs of a render split across
    /// machines (`crate::render::jobs`) check that they all render the scene their plan was
    /// made for.
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }

    /// The area density with which `sample_li` picks a point on internal triangle
    /// `triangle` (0 for triangles that do not emit).
    #[inline]
    pub(crate) fn light_area_pdf(&self, triangle: u32) -> f32 {
        self.shading[triangle as usize].light_area_pdf
    }

    /// The BSDF at barycentrics `barycentrics` of internal triangle `triangle`: its
    /// material with textures and vertex colours applied, in the shading frame there; its
    /// textures filtered over a ray footprint `footprint` wide in space (0: read at full
    /// resolution; `SurfacePoint::footprint`).
    #[inline(always)]
    pub(crate) fn bsdf_at(
        &self,
        triangle: u32,
        barycentrics: [f32; 2],
        footprint: f32,
        channels: &Channels,
    ) -> crate::bsdf::Bsdf {
        let normal = self.shading[triangle as usize].normal;
        surface::SurfacePoint {
            footprint,
            ..self.surface_point(triangle, barycentrics)
        }
        .bsdf(normal, channels)
    }

    /// The fraction of light that travels a path segment without being absorbed: the
    /// transmittance of the volume the segment runs through (see `medium`: a segment is
    /// inside the volume of a triangle whose back side it leaves or reaches), 1 outside
    /// every volume. `from` and `to` are the internal triangles the segment's ends lie on
    /// (`None`: the lens, a light that is not a triangle, a direction at infinity),
    /// `direction` the unit direction from `from` to `to`, `distance` its length (infinite
    /// towards or from a light at infinity, or for a ray that escapes). Symmetric: the
    /// segment read from `to` to `from` has the same transmittance, as path-space
    /// mutations need. The integrators' hot loops ask `has_media` first, so that a scene
    /// without a volume costs them one branch per segment.
    #[inline(always)]
    pub(crate) fn transmittance(
        &self,
        from: Option<u32>,
        to: Option<u32>,
        direction: Vec3A,
        distance: f32,
        channels: &Channels,
    ) -> Spectrum {
        if !self.has_media {
            return Spectrum::ONE;
        }
        self.medium_transmittance(from, to, direction, distance, channels)
    }

    /// `transmittance` of the segment from point `a` on `from` to point `b` on `to`.
    #[inline(always)]
    pub(crate) fn transmittance_between(
        &self,
        from: Option<u32>,
        to: Option<u32>,
        a: Vec3A,
        b: Vec3A,
        channels: &Channels,
    ) -> Spectrum {
        if !self.has_media {
            return Spectrum::ONE;
        }
        let d = b - a;
        let distance = d.length();
        if distance == 0.0 {
            return Spectrum::ONE;
        }
        self.medium_transmittance(from, to, d / distance, distance, channels)
    }

    /// `transmittance` in a scene with volumes.
    #[inline(never)]
    fn medium_transmittance(
        &self,
        from: Option<u32>,
        to: Option<u32>,
        direction: Vec3A,
        distance: f32,
        channels: &Channels,
    ) -> Spectrum {
        // The material whose volume lies behind `triangle` on the side `outward` points to.
        let behind = |triangle: Option<u32>, outward: Vec3A| {
            let shading = &self.shading[triangle? as usize];
            let material = shading.material as usize;
            (self.media[material].is_some() && outward.dot(shading.normal) < 0.0)
                .then_some(material)
        };
        let material = match (behind(from, direction), behind(to, -direction)) {
            (Some(a), Some(b)) => a.min(b),
            (a, b) => match a.or(b) {
                Some(m) => m,
                None => return Spectrum::ONE,
            },
        };
        match &self.media[material] {
            Some(medium) => medium.transmittance(distance, channels),
            None => Spectrum::ONE,
        }
    }

    /// `transmittance` of the shadow segment from a point on internal triangle `triangle`
    /// to the light vertex `light` sampled from it.
    #[inline(always)]
    pub(crate) fn light_transmittance(
        &self,
        triangle: u32,
        light: &lights::LightLiSample,
        channels: &Channels,
    ) -> Spectrum {
        if !self.has_media {
            return Spectrum::ONE;
        }
        let (to, distance) = if light.light.at_infinity() {
            (None, f32::INFINITY)
        } else {
            let to = light.light.is_area().then_some(light.triangle);
            (to, light.distance2.sqrt())
        };
        self.medium_transmittance(Some(triangle), to, light.wi, distance, channels)
    }

    /// Whether the scene has textures (what a ray cone could filter).
    #[inline]
    pub(crate) fn has_textures(&self) -> bool {
        !self.textures.is_empty()
    }

    /// Whether some material encloses an absorbing volume (see `transmittance`).
    #[inline]
    pub(crate) fn has_media(&self) -> bool {
        self.has_media
    }

    /// Whether internal triangle `triangle`'s material disperses light in `channels` (see
    /// `Material::disperses`).
    #[inline]
    pub(crate) fn disperses(&self, triangle: u32, channels: &Channels) -> bool {
        let material = self.shading[triangle as usize].material as usize;
        self.materials[material].disperses(channels)
    }

    /// Whether a candidate hit at barycentrics (u, v) of internal triangle `triangle` is a
    /// surface: false where an alpha cut-out removes it, or where blended coverage lets the
    /// point through (alpha at most the point's `coverage_threshold`).
    #[inline]
    fn is_solid(&self, triangle: u32, u: f32, v: f32) -> bool {
        let material = &self.materials[self.shading[triangle as usize].material as usize];
        match material.alpha_mode {
            AlphaMode::Opaque => true,
            AlphaMode::Mask => {
                self.surface_point(triangle, [u, v]).alpha() >= material.alpha_cutoff
            }
            AlphaMode::Blend => {
                // The host's triangle id, not the internal one: the internal order is each
                // backend's build order.
                let threshold = coverage_threshold(self.internal_to_input[triangle as usize], u, v);
                self.surface_point(triangle, [u, v]).alpha() > threshold
            }
        }
    }

    /// The closest surface `ray` hits (internal triangle ids), through alpha cut-outs.
    #[inline]
    pub(crate) fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        if self.slow_queries {
            self.closest_hit_slow(ray)
        } else {
            self.accel.intersect(ray)
        }
    }

    /// `closest_hit` in a scene with alpha cut-outs or a ray recording.
    #[inline(never)]
    fn closest_hit_slow(&self, ray: &Ray) -> Option<Hit> {
        let hit = if self.has_cutouts {
            self.accel
                .intersect_filtered(ray, &|triangle, u, v| self.is_solid(triangle, u, v))
        } else {
            self.accel.intersect(ray)
        };
        self.record(RecordedQuery::ClosestHit { ray: *ray, hit });
        hit
    }

    /// Whether a surface blocks `ray` within its interval, through alpha cut-outs.
    #[inline]
    pub(crate) fn blocked(&self, ray: &Ray) -> bool {
        if self.slow_queries {
            self.blocked_slow(ray)
        } else {
            self.accel.occluded(ray)
        }
    }

    /// `blocked` in a scene with alpha cut-outs or a ray recording.
    #[inline(never)]
    fn blocked_slow(&self, ray: &Ray) -> bool {
        let occluded = if self.has_cutouts {
            self.accel
                .occluded_filtered(ray, &|triangle, u, v| self.is_solid(triangle, u, v))
        } else {
            self.accel.occluded(ray)
        };
        self.record(RecordedQuery::Occluded {
            ray: *ray,
            occluded,
        });
        occluded
    }

    /// Appends `query` to the recording, if one is on.
    fn record(&self, query: RecordedQuery) {
        if let Some(recording) = &self.recording {
            recording
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .push(query);
        }
    }

    /// Starts recording every ray query renders make of this scene (dropping an earlier
    /// recording), for `take_recorded_queries`. Slows every query down (a lock and a push
    /// each); renders without a recording pay nothing. Queries from several threads are
    /// recorded in the order they take the lock. For the overhead bench
    /// (`benches/overhead.rs`), which replays a render's rays through `accel`.
    #[cfg(any(test, feature = "internals"))]
    pub fn record_queries(&mut self) {
        self.recording = Some(Box::default());
        self.slow_queries = true;
    }

    /// Stops the recording `record_queries` started and returns its queries in order (empty
    /// when none was on).
    #[cfg(any(test, feature = "internals"))]
    pub fn take_recorded_queries(&mut self) -> Vec<RecordedQuery> {
        self.slow_queries = self.has_cutouts;
        self.recording
            .take()
            .map(|recording| {
                recording
                    .into_inner()
                    .unwrap_or_else(|poisoned| poisoned.into_inner())
            })
            .unwrap_or_default()
    }

    /// The acceleration structure renders query (`Accel::intersect` and `Accel::occluded`
    /// directly, in a scene without alpha cut-outs), in internal triangle ids.
    #[cfg(any(test, feature = "internals"))]
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    /// Whether some material is an alpha cut-out: then queries are filtered, and a replay
    /// through `accel`'s unfiltered queries would not answer as renders did.
    #[cfg(any(test, feature = "internals"))]
    pub fn has_cutouts(&self) -> bool {
        self.has_cutouts
    }

    /// The surface at barycentrics `barycentrics` of internal triangle `triangle`.
    #[inline]
    pub(crate) fn surface_point(
        &self,
        triangle: u32,
        barycentrics: [f32; 2],
    ) -> surface::SurfacePoint<'_> {
        let material = self.shading[triangle as usize].material as usize;
        surface::SurfacePoint {
            attributes: &self.attributes,
            textures: &self.textures,
            material: &self.materials[material],
            colours: &self.material_colours[material],
            triangle,
            barycentrics,
            footprint: 0.0,
        }
    }

    /// Radiance the front side of internal triangle `triangle` emits at `barycentrics`, if
    /// it is a light (`light_area_pdf` > 0: the integrators ask that first), in `channels`.
    #[inline]
    pub(crate) fn emission(
        &self,
        triangle: u32,
        barycentrics: [f32; 2],
        channels: &Channels,
    ) -> Spectrum {
        // Where alpha removes the surface no ray meets it, and nothing is emitted there
        // either: light samples pick points on the triangle without asking.
        if self.materials[self.shading[triangle as usize].material as usize].alpha_mode
            != AlphaMode::Opaque
            && !self.is_solid(triangle, barycentrics[0], barycentrics[1])
        {
            return Spectrum::ZERO;
        }
        self.surface_point(triangle, barycentrics)
            .emission(channels)
    }

    /// A light picked by power and what it sends towards shading point `p`, in `channels`
    /// (`SceneLights::sample_li`).
    #[inline(always)]
    pub(crate) fn sample_li(
        &self,
        p: Vec3A,
        u_select: f32,
        u_point: [f32; 2],
        channels: &Channels,
    ) -> Option<lights::LightLiSample> {
        self.lights.sample_li(self, p, u_select, u_point, channels)
    }

    /// The start of a light subpath, its emission and weight in `channels`
    /// (`SceneLights::sample_emission`).
    #[inline]
    pub(crate) fn sample_emission(
        &self,
        u_select: f32,
        u_point: [f32; 2],
        u_direction: [f32; 2],
        channels: &Channels,
    ) -> Option<lights::EmissionSample> {
        self.lights
            .sample_emission(self, u_select, u_point, u_direction, channels)
    }

    /// Density of light vertex `emitter` as the start of a light subpath
    /// (`SceneLights::pdf_origin`); `toward` is the direction of a light at infinity.
    #[inline]
    pub(crate) fn emission_origin_pdf(&self, emitter: lights::Emitter, toward: Vec3A) -> f32 {
        self.lights.pdf_origin(self, emitter, toward)
    }

    /// What light vertex `light` emits towards `w`, in `channels`, and its density as a
    /// light sample (`SceneLights::emitted`).
    #[inline]
    pub(crate) fn light_emitted(
        &self,
        light: lights::Emitter,
        normal: Vec3A,
        barycentrics: [f32; 2],
        w: Vec3A,
        channels: &Channels,
    ) -> Option<(Spectrum, f32)> {
        self.lights
            .emitted(self, light, normal, barycentrics, w, channels)
    }

    /// The scale of the scene's units of light (`SceneLights::brightest`).
    pub(crate) fn brightest_light(&self) -> f32 {
        self.lights.brightest()
    }

    pub fn info(&self) -> SceneInfo {
        self.info
    }

    /// Closest hit in the host's triangle ids, through alpha cut-outs; `None` on a miss.
    /// Hidden: `Ray` and `Hit` are internal (C hosts call `mlt_intersect`).
    #[doc(hidden)]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit(ray).map(|hit| Hit {
            triangle: self.internal_to_input[hit.triangle as usize],
            ..hit
        })
    }

    /// Whether any non-degenerate triangle lies on the ray within [tmin, tmax], through
    /// alpha cut-outs. Hidden, as `intersect`.
    #[doc(hidden)]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.blocked(ray)
    }
}

impl lights::EmissiveSurfaces for Scene {
    #[inline]
    fn surface_emission(
        &self,
        triangle: u32,
        barycentrics: [f32; 2],
        channels: &Channels,
    ) -> Spectrum {
        self.emission(triangle, barycentrics, channels)
    }

    #[inline]
    fn emission_varies(&self, triangle: u32) -> bool {
        let material = &self.materials[self.shading[triangle as usize].material as usize];
        material.emission_texture.is_some() || material.alpha_mode != AlphaMode::Opaque
    }

    #[inline]
    fn triangle_light_pdf(&self, triangle: u32) -> f32 {
        self.light_area_pdf(triangle)
    }
}

fn validate_arrays(desc: &SceneDesc) -> Result<()> {
    if !desc.positions.len().is_multiple_of(3) {
        return Err(Error::invalid(format!(
            "desc.positions has {} floats; it must hold 3 per vertex (a multiple of 3)",
            desc.positions.len()
        )));
    }
    if !desc.indices.len().is_multiple_of(3) {
        return Err(Error::invalid(format!(
            "desc.indices has {} entries; it must hold 3 per triangle (a multiple of 3)",
            desc.indices.len()
        )));
    }
    let vertex_count = desc.positions.len() / 3;
    let triangle_count = desc.indices.len() / 3;
    if vertex_count > u32::MAX as usize || triangle_count > (u32::MAX - 1) as usize {
        return Err(Error::invalid(format!(
            "the scene has {vertex_count} vertices and {triangle_count} triangles; at most 2^32 - 2 of each are supported"
        )));
    }
    if !desc.material_ids.is_empty() && desc.material_ids.len() != triangle_count {
        return Err(Error::invalid(format!(
            "desc.material_ids has {} entries but there are {triangle_count} triangles; give one per triangle (or none for material 0 everywhere)",
            desc.material_ids.len()
        )));
    }
    if desc.materials.is_empty() && triangle_count > 0 {
        return Err(Error::invalid(
            "desc.materials is empty; a scene with triangles needs at least one material",
        ));
    }
    for (i, &p) in desc.positions.iter().enumerate() {
        if !p.is_finite() {
            return Err(Error::invalid(format!(
                "desc.positions[{i}] (vertex {}, {}) is {p}; vertex coordinates must be finite",
                i / 3,
                ["x", "y", "z"][i % 3]
            )));
        }
    }
    for (i, &v) in desc.indices.iter().enumerate() {
        if v as usize >= vertex_count {
            return Err(Error::invalid(format!(
                "desc.indices[{i}] (triangle {}) is {v}, but there are only {vertex_count} vertices",
                i / 3
            )));
        }
    }
    for (i, &m) in desc.material_ids.iter().enumerate() {
        if m as usize >= desc.materials.len() {
            return Err(Error::invalid(format!(
                "desc.material_ids[{i}] is {m}, but there are only {} materials",
                desc.materials.len()
            )));
        }
    }
    desc.vertex_arrays().validate(vertex_count)?;
    for (i, material) in desc.materials.iter().enumerate() {
        material
            .validate(i, desc.textures.len())
            .map_err(|e| e.about_material(i))?;
        if material.has_textures() && desc.texcoords.is_empty() && !desc.indices.is_empty() {
            return Err(Error::invalid(format!(
                "desc.materials[{i}] has textures but desc.texcoords is empty; textured materials need texture coordinates"
            ))
            .about_material(i));
        }
        if let Some((slot, _)) = material.textures().find(|(_, t)| t.texcoord == 1)
            && desc.texcoords1.is_empty()
            && !desc.indices.is_empty()
        {
            return Err(Error::invalid(format!(
                "desc.materials[{i}].{slot} uses texture coordinate set 1 but desc.texcoords1 is empty"
            ))
            .about_material(i));
        }
    }
    Ok(())
}

/// Per-corner tangents of the host's triangles (3 per triangle), where a material has a
/// normal map or anisotropy: the host's per-vertex tangents, or MikkTSpace's from the
/// normals (vertex normals averaged from the faces when the host gave none) and texture
/// coordinates. Empty when no material needs them, or there are neither tangents nor
/// texture coordinates (a normal map needs texture coordinates; anisotropy can do with
/// the host's tangents alone).
fn corner_tangents(desc: &SceneDesc) -> Vec<[f32; 4]> {
    let normal_mapped = desc
        .materials
        .iter()
        .any(|m| m.normal_texture.is_some() || m.clearcoat_normal_texture.is_some());
    let anisotropic = desc.materials.iter().any(|m| m.anisotropy > 0.0);
    let host_tangents_usable =
        !desc.tangents.is_empty() && (anisotropic || !desc.texcoords.is_empty());
    if !(normal_mapped || anisotropic) || desc.texcoords.is_empty() && !host_tangents_usable {
        return Vec::new();
    }
    if host_tangents_usable {
        return desc
            .indices
            .iter()
            .map(|&v| {
                let i = v as usize * 4;
                [
                    desc.tangents[i],
                    desc.tangents[i + 1],
                    desc.tangents[i + 2],
                    desc.tangents[i + 3],
                ]
            })
            .collect();
    }
    let face_normals;
    let normals = if desc.normals.is_empty() {
        face_normals = area_weighted_vertex_normals(desc.positions, desc.indices);
        &face_normals[..]
    } else {
        desc.normals
    };
    tangents::mikktspace_tangents(desc.positions, normals, desc.texcoords, desc.indices)
}

/// Vertex normals as the area-weighted sum of the adjacent faces' normals (+Y where that
/// sum vanishes).
fn area_weighted_vertex_normals(positions: &[f32], indices: &[u32]) -> Vec<f32> {
    let vertex = |i: u32| Vec3A::from_slice(&positions[i as usize * 3..i as usize * 3 + 3]);
    let mut sums = vec![Vec3A::ZERO; positions.len() / 3];
    for t in indices.chunks_exact(3) {
        let n = (vertex(t[1]) - vertex(t[0])).cross(vertex(t[2]) - vertex(t[0]));
        if n.is_finite() {
            for &v in t {
                sums[v as usize] += n;
            }
        }
    }
    sums.iter()
        .flat_map(|n| n.try_normalize().unwrap_or(Vec3A::Y).to_array())
        .collect()
}

/// Cells per barycentric axis of `coverage_threshold`'s grid (2^16).
const COVERAGE_CELLS: f32 = 65536.0;

/// The pseudo-random threshold in [0, 1) that blended coverage (`AlphaMode::Blend`) compares
/// alpha with at barycentrics (u, v) of host triangle `triangle`: a hash of the triangle and
/// the cell of a 2^16 × 2^16 grid over its barycentrics. A fixed function of the surface
/// point, not of the ray, so every ray reaching a point (camera, light, shadow or
/// connection, traced either way) finds the same surface there, except within float error
/// of a cell's edge; a cell is 2^8 ulps of barycentrics near 1, where a ray's intersection
/// errs by a few. Over more than a few cells the surface covers a fraction alpha.
#[inline]
pub(crate) fn coverage_threshold(triangle: u32, u: f32, v: f32) -> f32 {
    // Float-to-int casts saturate (NaN to 0); barycentrics a rounding error outside [0, 1]
    // land in the edge cells.
    let cell = |b: f32| ((b * COVERAGE_CELLS) as u32).min(COVERAGE_CELLS as u32 - 1) as u64;
    let key = ((triangle as u64) << 32) | (cell(u) << 16) | cell(v);
    let hash = xxhash_rust::xxh3::xxh3_64(&key.to_le_bytes());
    // The top 24 bits: exact in an f32, below 1.
    (hash >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blended coverage's threshold is uniform on [0, 1) over cells (a surface of alpha a
    /// covers a fraction a of them, within 5 standard errors of 2^18 cells, 0.2% of 0.3),
    /// one value per cell of the 2^16 grid, and defined for barycentrics a rounding error
    /// outside [0, 1] or NaN.
    #[test]
    fn coverage_threshold_is_uniform_and_constant_per_cell() {
        let cell = 1.0 / COVERAGE_CELLS;
        let (mut below, mut total) = (0u32, 0u32);
        for triangle in [0, 1, 77_777] {
            for i in 0..296u32 {
                for j in 0..296u32 {
                    let (u, v) = ((i * 221) as f32 * cell, (j * 221) as f32 * cell);
                    let t = coverage_threshold(triangle, u, v);
                    assert!((0.0..1.0).contains(&t));
                    // Anywhere inside the cell gives the same threshold.
                    assert_eq!(
                        t,
                        coverage_threshold(triangle, u + 0.7 * cell, v + 0.3 * cell)
                    );
                    below += (t < 0.3) as u32;
                    total += 1;
                }
            }
        }
        let fraction = below as f64 / total as f64;
        let standard_error = (0.3 * 0.7 / total as f64).sqrt();
        assert!(
            (fraction - 0.3).abs() < 5.0 * standard_error,
            "{fraction} of the cells below 0.3 (± {standard_error})"
        );
        // Neighbouring cells and triangles differ.
        let t = coverage_threshold(5, 0.5, 0.5);
        assert_ne!(t, coverage_threshold(5, 0.5 + cell, 0.5));
        assert_ne!(t, coverage_threshold(5, 0.5, 0.5 + cell));
        assert_ne!(t, coverage_threshold(6, 0.5, 0.5));
        for b in [-1e-7, 1.0 + 1e-7, f32::NAN] {
            assert!((0.0..1.0).contains(&coverage_threshold(3, b, b)));
        }
    }

    /// Ray queries through a scene go through its cut-outs, with either backend: a triangle
    /// whose vertex alphas make alpha = 1 - u - v is solid only where u + v <= 1/2 (the
    /// cutoff), and rays through the rest reach the opaque triangle behind it.
    /// A clear coat's own normal map needs the mesh's tangents as the base's does: a scene
    /// whose only normal map is a coat's gets them.
    #[test]
    fn a_coat_normal_map_alone_gets_tangents() {
        let positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let texcoords = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let coat = |normal_map: bool| Material {
            clearcoat: 1.0,
            clearcoat_normal_texture: normal_map.then(|| TextureRef::new(0)),
            ..Material::metallic_roughness([0.5; 3], 0.0, 0.5)
        };
        for (normal_map, tangents) in [(true, 3), (false, 0)] {
            let materials = [coat(normal_map)];
            let desc = SceneDesc {
                positions: &positions,
                texcoords: &texcoords,
                indices: &[0, 1, 2],
                material_ids: &[0],
                materials: &materials,
                ..Default::default()
            };
            assert_eq!(corner_tangents(&desc).len(), tangents);
        }
    }

    #[test]
    fn rays_pass_through_cut_outs() {
        #[rustfmt::skip]
        let positions = [
            -1.0, -1.0, 1.0, 1.0, -1.0, 1.0, 0.0, 1.0, 1.0,
            -9.0, -9.0, 2.0, 9.0, -9.0, 2.0, 0.0, 9.0, 2.0,
        ];
        let mut colors = vec![1.0; 6 * 4];
        colors[4 + 3] = 0.0;
        colors[8 + 3] = 0.0;
        let cut_out = Material {
            alpha_mode: AlphaMode::Mask,
            alpha_cutoff: 0.5,
            ..Material::diffuse([0.5; 3])
        };
        let materials = [cut_out, Material::diffuse([0.5; 3])];
        for backend in [Backend::Bvh, Backend::Embree] {
            if !backend.is_available() {
                continue;
            }
            let scene = Scene::new(&SceneDesc {
                positions: &positions,
                indices: &[0, 1, 2, 3, 4, 5],
                material_ids: &[0, 1],
                materials: &materials,
                colors: &colors,
                backend,
                ..Default::default()
            })
            .unwrap();
            // Points of the front triangle at (u, v) = (0.1, 0.2) and (0.4, 0.4).
            for (u, v, front) in [(0.1, 0.2, true), (0.4, 0.4, false)] {
                let origin = Vec3A::new(-1.0 + 2.0 * u + v, -1.0 + 2.0 * v, 0.0);
                let ray = Ray::new(origin, Vec3A::Z, 0.0, f32::INFINITY);
                let hit = scene.intersect(&ray).unwrap();
                let what = format!("{backend:?}, u {u}, v {v}: {hit:?}");
                assert_eq!(hit.triangle, if front { 0 } else { 1 }, "{what}");
                assert!(
                    (hit.t - if front { 1.0 } else { 2.0 }).abs() < 1e-5,
                    "{what}"
                );
                let short = Ray::new(origin, Vec3A::Z, 0.0, 1.5);
                assert_eq!(scene.occluded(&short), front, "{what}");
            }
        }
    }

    /// Finite light values whose power overflows a float (found by the capi_scene fuzzer:
    /// the light selection's or the environment map's weights were infinite) are refused,
    /// naming the light; the same lights in a scene of sensible size and strength are
    /// accepted.
    #[test]
    fn lights_whose_power_overflows_are_refused() {
        // Two triangles `size` wide, `apart` from each other along x.
        let geometry = |size: f32, apart: f32| {
            let mut positions = Vec::new();
            for x in [-apart / 2.0, apart / 2.0] {
                positions.extend_from_slice(&[x, 0.0, 0.0, x, size, 0.0, x, 0.0, size]);
            }
            positions
        };
        let scene = |positions: &[f32], emission: f32, lights: LightsDesc| {
            Scene::new(&SceneDesc {
                positions,
                indices: &[0, 1, 2, 3, 4, 5],
                materials: &[Material::diffuse([0.5; 3]).with_emission([emission; 3])],
                lights,
                ..Default::default()
            })
            .map(|_| ())
            .map_err(|e| e.message)
        };
        let huge_point = [PunctualLight::point([0.0; 3], [1e38; 3])];
        let max_point = [PunctualLight::point([0.0; 3], [f32::MAX; 3])];
        let bright_point = [PunctualLight::point([0.0; 3], [1e30; 3])];
        let point = |lights| LightsDesc {
            punctual: lights,
            ..Default::default()
        };
        let sun = LightsDesc {
            sun: Some(SunDesc {
                direction: [0.0, 1.0, 0.0],
                angular_radius_degrees: 0.0,
                irradiance: [1.0; 3],
            }),
            ..Default::default()
        };
        let bright_sky = [1e30f32; 6];
        let sky = |scale| LightsDesc {
            environment: Some(EnvironmentDesc {
                pixels: &bright_sky,
                width: 2,
                height: 1,
                rotation_degrees: 0.0,
                scale,
            }),
            ..Default::default()
        };
        let tiny_sun = LightsDesc {
            sun: Some(SunDesc {
                direction: [0.0, 1.0, 0.0],
                angular_radius_degrees: 1e-30,
                irradiance: [1.0; 3],
            }),
            ..Default::default()
        };
        let cases = [
            (
                scene(&geometry(1e9, 1.0), 1e30, Default::default()),
                "emissive triangle 0",
            ),
            (
                scene(&geometry(1.0, 1.0), 0.0, point(&huge_point)),
                "desc.punctual_lights[0]",
            ),
            (
                scene(&geometry(1.0, 1.0), 0.0, point(&max_point)),
                "desc.punctual_lights[0]",
            ),
            (
                scene(&geometry(1.0, 1e20), 0.0, sun),
                "the sun and environment",
            ),
        ];
        for (result, needle) in cases {
            let message = result.expect_err(needle);
            assert!(message.contains(needle), "{message}");
            assert!(message.contains("overflows a float"), "{message}");
        }
        // Light values beyond what single-precision sums hold are refused when validated.
        let message = scene(&geometry(1.0, 1.0), 0.0, sky(1e10)).unwrap_err();
        assert!(
            message.contains("desc.environment.pixels times its scale"),
            "{message}"
        );
        let message = scene(&geometry(1.0, 1.0), 0.0, tiny_sun).unwrap_err();
        assert!(message.contains("desc.sun.irradiance"), "{message}");
        scene(&geometry(1e3, 1.0), 1e10, point(&bright_point)).unwrap();
        scene(&geometry(1.0, 1e3), 0.0, sun).unwrap();
        scene(&geometry(1.0, 1.0), 0.0, sky(1.0)).unwrap();
    }
}
