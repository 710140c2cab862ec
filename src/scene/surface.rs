//! What a surface is at a point inside a triangle: the per-vertex attributes a host may give
//! (shading normals, texture coordinates, tangents, colours), interpolated with the hit's
//! barycentrics, and the material evaluated there as a [`Bsdf`].
//!
//! Attributes are stored per triangle corner in the backend's internal triangle order, so a
//! hit reads one contiguous record per attribute. A scene without an attribute stores none.

use super::material::{Material, SpecularAndSheen, TextureRef};
use crate::bsdf::{Anisotropy, Bsdf, BsdfModel, Clearcoat};
use crate::error::{Error, Result};
use crate::sampling::OrthonormalBasis;
use crate::spectral::{Channels, FittedColour};
use crate::spectrum::Spectrum;
use crate::texture::Texture;
use glam::{Vec3A, Vec4};

/// Per-vertex arrays as the host gives them (empty: absent), before they are validated.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct VertexArrays<'a> {
    pub normals: &'a [f32],
    pub texcoords: &'a [f32],
    pub texcoords1: &'a [f32],
    pub tangents: &'a [f32],
    pub colors: &'a [f32],
}

impl VertexArrays<'_> {
    /// Checks lengths and values against `vertex_count` vertices.
    pub fn validate(&self, vertex_count: usize) -> Result<()> {
        let arrays: [(&str, &[f32], usize, &[&str]); 5] = [
            ("normals", self.normals, 3, &["x", "y", "z"]),
            ("texcoords", self.texcoords, 2, &["u", "v"]),
            ("texcoords1", self.texcoords1, 2, &["u", "v"]),
            ("tangents", self.tangents, 4, &["x", "y", "z", "w"]),
            ("colors", self.colors, 4, &["r", "g", "b", "a"]),
        ];
        for (name, values, width, components) in arrays {
            if values.is_empty() {
                continue;
            }
            if values.len() != vertex_count * width {
                return Err(Error::invalid(format!(
                    "desc.{name} has {} floats; it must be empty or hold {width} per vertex ({} for {vertex_count} vertices)",
                    values.len(),
                    vertex_count * width
                )));
            }
            for (i, &x) in values.iter().enumerate() {
                if !x.is_finite() {
                    return Err(Error::invalid(format!(
                        "desc.{name}[{i}] (vertex {}, {}) is {x}; it must be a finite number",
                        i / width,
                        components[i % width]
                    )));
                }
            }
        }
        for (vertex, n) in self.normals.chunks_exact(3).enumerate() {
            let length2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if !(length2 > 0.0 && length2.is_finite()) {
                return Err(Error::invalid(format!(
                    "desc.normals of vertex {vertex} is ({}, {}, {}); a normal must have a nonzero length",
                    n[0], n[1], n[2]
                )));
            }
        }
        for (vertex, t) in self.tangents.chunks_exact(4).enumerate() {
            let length2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
            if !(length2 > 0.0 && length2.is_finite()) || t[3] == 0.0 {
                return Err(Error::invalid(format!(
                    "desc.tangents of vertex {vertex} is ({}, {}, {}, {}); a tangent must have a nonzero length and w = ±1",
                    t[0], t[1], t[2], t[3]
                )));
            }
        }
        for (i, &c) in self.colors.iter().enumerate() {
            if !(0.0..=1.0).contains(&c) {
                return Err(Error::invalid(format!(
                    "desc.colors[{i}] (vertex {}, {}) is {c}; vertex colours must be in [0, 1]",
                    i / 4,
                    ["r", "g", "b", "a"][i % 4]
                )));
            }
        }
        Ok(())
    }
}

/// The attributes of every triangle's corners, in internal triangle order; an attribute
/// the host did not give is an empty vector.
#[derive(Debug, Default)]
pub(crate) struct SurfaceAttributes {
    normals: Vec<[Vec3A; 3]>,
    /// The texture coordinate sets 0 and 1 (`TextureRef::texcoord`).
    texcoords: [Vec<[[f32; 2]; 3]>; 2],
    /// Per triangle, for each set: √(area in texture coordinates / area in space), the
    /// texture coordinates' growth per unit of length across the triangle (on average over
    /// its two axes): what turns a footprint's width in space into one in texture coordinates.
    texcoord_density: [Vec<f32>; 2],
    colors: Vec<[Vec4; 3]>,
    /// xyz and the bitangent sign w, per corner: the host's, or MikkTSpace's where a
    /// material has a normal map (empty otherwise).
    tangents: Vec<[Vec4; 3]>,
}

impl SurfaceAttributes {
    /// Room for `triangle_count` triangles of each attribute `arrays` has.
    pub fn with_capacity(arrays: &VertexArrays, triangle_count: usize) -> Self {
        let capacity = |values: &[f32]| if values.is_empty() { 0 } else { triangle_count };
        SurfaceAttributes {
            normals: Vec::with_capacity(capacity(arrays.normals)),
            texcoords: [
                Vec::with_capacity(capacity(arrays.texcoords)),
                Vec::with_capacity(capacity(arrays.texcoords1)),
            ],
            texcoord_density: [
                Vec::with_capacity(capacity(arrays.texcoords)),
                Vec::with_capacity(capacity(arrays.texcoords1)),
            ],
            colors: Vec::with_capacity(capacity(arrays.colors)),
            tangents: Vec::new(),
        }
    }

    /// Appends the next internal triangle, whose corners are vertices `corners` and whose
    /// edges' cross product has length `double_area` (> 0), and its corner tangents if the
    /// scene has any (`tangents`: per corner of the host's triangles; `id` is this one's
    /// host index).
    pub fn push(
        &mut self,
        arrays: &VertexArrays,
        corners: [u32; 3],
        double_area: f32,
        tangents: &[[f32; 4]],
        id: u32,
    ) {
        if !tangents.is_empty() {
            let first = id as usize * 3;
            self.tangents
                .push([0, 1, 2].map(|k| Vec4::from_array(tangents[first + k])));
        }
        if !arrays.normals.is_empty() {
            self.normals.push(corners.map(|c| {
                let i = c as usize * 3;
                Vec3A::from_slice(&arrays.normals[i..i + 3]).normalize()
            }));
        }
        for ((set, density), values) in self
            .texcoords
            .iter_mut()
            .zip(&mut self.texcoord_density)
            .zip([arrays.texcoords, arrays.texcoords1])
        {
            if !values.is_empty() {
                let t = corners.map(|c| {
                    let i = c as usize * 2;
                    [values[i], values[i + 1]]
                });
                let (e1, e2) = (
                    [t[1][0] - t[0][0], t[1][1] - t[0][1]],
                    [t[2][0] - t[0][0], t[2][1] - t[0][1]],
                );
                let double_texcoord_area =
                    (e1[0] as f64 * e2[1] as f64 - e1[1] as f64 * e2[0] as f64).abs();
                density.push((double_texcoord_area / double_area as f64).sqrt() as f32);
                set.push(t);
            }
        }
        if !arrays.colors.is_empty() {
            self.colors.push(corners.map(|c| {
                let i = c as usize * 4;
                Vec4::from_slice(&arrays.colors[i..i + 4])
            }));
        }
    }

    /// Whether a point's BSDF is its material's untextured one on the geometric normal.
    #[inline]
    fn is_flat(&self, material: &Material) -> bool {
        self.normals.is_empty()
            && self.colors.is_empty()
            && !material.has_textures()
            && material.anisotropy == 0.0
    }

    /// The interpolated texture coordinates of set `set` (0 or 1; (0, 0) without any).
    #[inline]
    fn texcoord(&self, set: u32, triangle: u32, b: [f32; 2]) -> [f32; 2] {
        match self.texcoords[(set & 1) as usize].get(triangle as usize) {
            Some(t) => {
                let w = 1.0 - b[0] - b[1];
                [
                    t[0][0] * w + t[1][0] * b[0] + t[2][0] * b[1],
                    t[0][1] * w + t[1][1] * b[0] + t[2][1] * b[1],
                ]
            }
            None => [0.0; 2],
        }
    }

    /// Texture coordinate set `set`'s `texcoord_density` on `triangle` (0 without the set).
    #[inline]
    fn texcoord_density(&self, set: u32, triangle: u32) -> f32 {
        self.texcoord_density[(set & 1) as usize]
            .get(triangle as usize)
            .copied()
            .unwrap_or(0.0)
    }

    /// The interpolated tangent (xyz) and bitangent sign (w), if the scene has tangents.
    #[inline]
    fn tangent(&self, triangle: u32, b: [f32; 2]) -> Option<Vec4> {
        let t = self.tangents.get(triangle as usize)?;
        Some(t[0] * (1.0 - b[0] - b[1]) + t[1] * b[0] + t[2] * b[1])
    }

    /// The interpolated shading normal of internal triangle `triangle` at `barycentrics`,
    /// turned to the side of `geometric_normal` (the front side decides inside and outside).
    #[inline]
    fn shading_normal(&self, triangle: u32, b: [f32; 2], geometric_normal: Vec3A) -> Vec3A {
        let Some(n) = self.normals.get(triangle as usize) else {
            return geometric_normal;
        };
        let interpolated = (n[0] * (1.0 - b[0] - b[1]) + n[1] * b[0] + n[2] * b[1]).normalize();
        if !interpolated.is_finite() {
            // Opposite corner normals can cancel: there is no shading direction to use.
            return geometric_normal;
        }
        if interpolated.dot(geometric_normal) < 0.0 {
            -interpolated
        } else {
            interpolated
        }
    }

    /// The interpolated vertex colour (RGBA), white without colours.
    #[inline]
    fn color(&self, triangle: u32, b: [f32; 2]) -> Vec4 {
        match self.colors.get(triangle as usize) {
            Some(c) => c[0] * (1.0 - b[0] - b[1]) + c[1] * b[0] + c[2] * b[1],
            None => Vec4::ONE,
        }
    }
}

/// The value of `texture` at texture coordinates `uv` (its transform applied), for a
/// footprint `footprint` texture coordinates wide before the transform (0: the image itself,
/// no filtering).
#[inline]
fn lookup(textures: &[Texture], texture: &TextureRef, uv: [f32; 2], footprint: f32) -> Vec4 {
    let [row_u, row_v] = texture.matrix();
    let uv = [
        row_u[0] * uv[0] + row_u[1] * uv[1] + row_u[2],
        row_v[0] * uv[0] + row_v[1] * uv[1] + row_v[2],
    ];
    let image = &textures[texture.texture as usize];
    if footprint > 0.0 {
        Vec4::from_array(image.sample_filtered(uv, level_of_detail(image, texture, footprint)))
    } else {
        Vec4::from_array(image.sample(uv))
    }
}

/// The mip level of detail of a footprint `footprint` texture coordinates wide (before the
/// transform): log2 of its width in the image's texels.
#[inline]
fn level_of_detail(image: &Texture, texture: &TextureRef, footprint: f32) -> f32 {
    // The transform scales areas by |scale_u · scale_v| (a rotation keeps them).
    let [scale_u, scale_v] = texture.scale;
    (footprint * (scale_u * scale_v).abs().sqrt() * image.texels_per_unit()).log2()
}

/// A material's constant colour and emission with their spectral fits, made once per scene.
pub(crate) struct MaterialColours {
    color: FittedColour,
    emission: FittedColour,
}

impl MaterialColours {
    pub fn new(material: &Material) -> Self {
        MaterialColours {
            color: FittedColour::reflectance(material.color),
            emission: FittedColour::illuminant(material.emission),
        }
    }
}

/// A surface point's look: what its material's textures and the vertex attributes make of
/// it there.
pub(crate) struct SurfacePoint<'a> {
    pub attributes: &'a SurfaceAttributes,
    pub textures: &'a [Texture],
    pub material: &'a Material,
    pub colours: &'a MaterialColours,
    pub triangle: u32,
    pub barycentrics: [f32; 2],
    /// The width in space of the ray footprint the BSDF's textures are filtered over (a ray
    /// cone's width over the cosine of its incidence); 0: no filtering, every lookup reads
    /// the image itself. Alpha and emission always read the image itself (`alpha`,
    /// `emission`): the other strategies that reach the point do.
    pub footprint: f32,
}

impl SurfacePoint<'_> {
    /// Texture `texture` at this point, at the texture coordinate set it names, filtered
    /// over `footprint` (a width in space; 0: the image itself).
    #[inline]
    fn lookup_over(&self, texture: &TextureRef, footprint: f32) -> Vec4 {
        let uv = self
            .attributes
            .texcoord(texture.texcoord, self.triangle, self.barycentrics);
        let footprint = if footprint > 0.0 {
            footprint
                * self
                    .attributes
                    .texcoord_density(texture.texcoord, self.triangle)
        } else {
            0.0
        };
        lookup(self.textures, texture, uv, footprint)
    }

    /// The mip level of detail texture `texture` is read at for the BSDF here (−∞ without a
    /// footprint: the image itself).
    #[cfg(test)]
    pub fn level_of_detail(&self, texture: &TextureRef) -> f32 {
        let footprint = self.footprint
            * self
                .attributes
                .texcoord_density(texture.texcoord, self.triangle);
        level_of_detail(&self.textures[texture.texture as usize], texture, footprint)
    }

    /// Texture `texture` for the BSDF: filtered over the point's footprint.
    #[inline]
    fn lookup(&self, texture: &TextureRef) -> Vec4 {
        self.lookup_over(texture, self.footprint)
    }

    /// Texture `texture` at full resolution, whatever the footprint.
    #[inline]
    fn lookup_image(&self, texture: &TextureRef) -> Vec4 {
        self.lookup_over(texture, 0.0)
    }

    /// The base colour (RGB) and alpha: factors × vertex colour × base colour texture
    /// (filtered over `footprint`).
    #[inline]
    fn base_color(&self, footprint: f32) -> Vec4 {
        let m = self.material;
        let mut color = Vec4::new(m.color[0], m.color[1], m.color[2], m.alpha)
            * self.attributes.color(self.triangle, self.barycentrics);
        if let Some(texture) = &m.base_color_texture {
            color *= self.lookup_over(texture, footprint);
        }
        color
    }

    /// The coverage `AlphaMode::Mask` tests against the cutoff, at full resolution (ray
    /// queries test it, whatever path they belong to).
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.base_color(0.0).w
    }

    /// Emitted radiance: the emission factor × the emission texture.
    #[inline]
    pub fn emission(&self, channels: &Channels) -> Spectrum {
        let m = self.material;
        let Some(texture) = &m.emission_texture else {
            return channels.fitted_illuminant(&self.colours.emission);
        };
        let texel = self.lookup_image(texture);
        channels.illuminant([
            m.emission[0] * texel.x,
            m.emission[1] * texel.y,
            m.emission[2] * texel.z,
        ])
    }

    /// The shading normal: interpolated, then bent by the normal map (tangent space, x and
    /// y scaled by `normal_scale`); on the side of `geometric_normal`.
    #[inline]
    fn shading_normal(&self, geometric_normal: Vec3A) -> Vec3A {
        let normal =
            self.attributes
                .shading_normal(self.triangle, self.barycentrics, geometric_normal);
        let m = self.material;
        self.normal_mapped(normal, &m.normal_texture, m.normal_scale, geometric_normal)
    }

    /// `normal` (the interpolated one) bent by the tangent-space normal map `texture`
    /// (glTF's convention, x and y scaled by `scale`); `normal` itself without a map or
    /// tangents, or where the map would bend it behind the triangle.
    #[inline]
    fn normal_mapped(
        &self,
        normal: Vec3A,
        texture: &Option<TextureRef>,
        scale: f32,
        geometric_normal: Vec3A,
    ) -> Vec3A {
        let (Some(texture), Some(tangent)) = (
            texture,
            self.attributes.tangent(self.triangle, self.barycentrics),
        ) else {
            return normal;
        };
        // At full resolution: shading is not linear in the normal, so a normal map averaged
        // over the footprint (flattened) would change the converged image, not its noise.
        let texel = self.lookup_image(texture);
        let local = Vec3A::new(
            (texel.x * 2.0 - 1.0) * scale,
            (texel.y * 2.0 - 1.0) * scale,
            texel.z * 2.0 - 1.0,
        );
        // Gram-Schmidt: the interpolated tangent is only nearly perpendicular.
        let t = Vec3A::new(tangent.x, tangent.y, tangent.z);
        let t = (t - normal * normal.dot(t)).normalize();
        if !t.is_finite() {
            return normal;
        }
        let bitangent = normal.cross(t) * tangent.w.signum();
        let mapped = (t * local.x + bitangent * local.y + normal * local.z).normalize();
        // A map bending the normal behind the triangle has no sensible shading frame.
        if mapped.is_finite() && mapped.dot(geometric_normal) > 0.0 {
            mapped
        } else {
            normal
        }
    }

    /// The clear coat here: its factor and roughness times their textures, and its own
    /// normal (its normal map over the interpolated normal, never the base's map), `None`
    /// where that is `shading_normal` itself.
    #[inline]
    fn clearcoat(&self, shading_normal: Vec3A, geometric_normal: Vec3A) -> Clearcoat {
        let m = self.material;
        let mut factor = m.clearcoat;
        if let Some(texture) = &m.clearcoat_texture {
            factor *= self.lookup(texture).x;
        }
        if factor <= 0.0 {
            return Clearcoat::NONE;
        }
        let mut roughness = m.clearcoat_roughness;
        if let Some(texture) = &m.clearcoat_roughness_texture {
            roughness *= self.lookup(texture).y;
        }
        let interpolated =
            self.attributes
                .shading_normal(self.triangle, self.barycentrics, geometric_normal);
        let normal = self.normal_mapped(
            interpolated,
            &m.clearcoat_normal_texture,
            m.clearcoat_normal_scale,
            geometric_normal,
        );
        Clearcoat {
            factor,
            roughness,
            normal: (normal != shading_normal).then_some(normal),
        }
    }

    /// The specular, sheen and thin film parameters here, with their textures.
    #[inline]
    fn specular_and_sheen(&self) -> SpecularAndSheen {
        let m = self.material;
        let mut layers = m.untextured_layers();
        let rgb = |t: Vec4| [t.x, t.y, t.z];
        let times = |c: [f32; 3], t: [f32; 3]| [c[0] * t[0], c[1] * t[1], c[2] * t[2]];
        if let Some(texture) = &m.specular_texture {
            layers.specular *= self.lookup(texture).w;
        }
        if let Some(texture) = &m.specular_color_texture {
            layers.specular_color = times(layers.specular_color, rgb(self.lookup(texture)));
        }
        // Without sheen the sheen's textures change nothing: no lookups.
        if layers.sheen_color != [0.0; 3] {
            if let Some(texture) = &m.sheen_color_texture {
                layers.sheen_color = times(layers.sheen_color, rgb(self.lookup(texture)));
            }
            if let Some(texture) = &m.sheen_roughness_texture {
                layers.sheen_roughness *= self.lookup(texture).w;
            }
        }
        // Without a film its textures change nothing either.
        if layers.iridescence > 0.0 {
            if let Some(texture) = &m.iridescence_texture {
                layers.iridescence *= self.lookup(texture).x;
            }
            if let Some(texture) = &m.iridescence_thickness_texture {
                let (low, high) = (
                    m.iridescence_thickness_minimum,
                    m.iridescence_thickness_maximum,
                );
                layers.iridescence_thickness = low + (high - low) * self.lookup(texture).y;
            }
        }
        layers
    }

    /// `KHR_materials_anisotropy` here: its strength (times the texture's blue), and its
    /// direction (the texture's red and green, or the tangent, turned by the rotation) in
    /// the frame of the mesh's tangent and bitangent made perpendicular to `normal`. A
    /// mesh without tangents gets an arbitrary frame about the normal. `None` where the
    /// strength is 0.
    #[inline]
    fn anisotropy(&self, normal: Vec3A) -> Option<Anisotropy> {
        let m = self.material;
        let mut strength = m.anisotropy;
        if strength <= 0.0 {
            return None;
        }
        let (mut x, mut y) = (1.0, 0.0);
        if let Some(texture) = &m.anisotropy_texture {
            // At full resolution, as normal maps: averaged directions would shorten.
            let texel = self.lookup_image(texture);
            (x, y) = (texel.x * 2.0 - 1.0, texel.y * 2.0 - 1.0);
            strength *= texel.z;
            if strength <= 0.0 {
                return None;
            }
        }
        let (sin, cos) = m.anisotropy_rotation.sin_cos();
        let (x, y) = (cos * x - sin * y, sin * x + cos * y);
        let tangent = self
            .attributes
            .tangent(self.triangle, self.barycentrics)
            .and_then(|t| {
                // Gram-Schmidt: the interpolated tangent is only nearly perpendicular.
                let xyz = Vec3A::new(t.x, t.y, t.z);
                let tangent = (xyz - normal * normal.dot(xyz)).try_normalize()?;
                Some((tangent, normal.cross(tangent) * t.w.signum()))
            });
        let (tangent, bitangent) = tangent.unwrap_or_else(|| {
            let basis = OrthonormalBasis::from_normal(normal);
            (basis.tangent, basis.bitangent)
        });
        // A texel at the middle of red and green names no direction: the tangent's.
        let direction = (tangent * x + bitangent * y)
            .try_normalize()
            .unwrap_or(tangent);
        Some(Anisotropy {
            strength: strength.min(1.0),
            direction: direction.into(),
        })
    }

    /// The BSDF here, on a triangle with front geometric normal `geometric_normal`.
    #[inline]
    pub fn bsdf(&self, geometric_normal: Vec3A, channels: &Channels) -> Bsdf {
        let dispersive = self.material.disperses(channels);
        if self.attributes.is_flat(self.material) {
            let m = self.material;
            let model = m.textured_bsdf_model(
                channels.fitted_reflectance(&self.colours.color),
                m.metallic,
                m.roughness,
                m.transmission,
                m.ior_in(channels),
                &m.untextured_layers(),
                channels,
            );
            return Bsdf::new(model, geometric_normal, geometric_normal)
                .with_dispersion(dispersive);
        }
        let base = self.base_color(self.footprint);
        let color = channels.reflectance([base.x, base.y, base.z]);
        let m = self.material;
        let (mut metallic, mut roughness) = (m.metallic, m.roughness);
        if let Some(texture) = &m.metallic_roughness_texture {
            let texel = self.lookup(texture);
            roughness *= texel.y;
            metallic *= texel.z;
        }
        let mut transmission = m.transmission;
        if let Some(texture) = &m.transmission_texture {
            transmission *= self.lookup(texture).x;
        }
        let layers = self.specular_and_sheen();
        let mut model = m.textured_bsdf_model(
            color,
            metallic,
            roughness,
            transmission,
            m.ior_in(channels),
            &layers,
            channels,
        );
        let shading_normal = self.shading_normal(geometric_normal);
        if let BsdfModel::MetallicRoughness(model) = &mut model {
            if model.clearcoat.is_present() {
                model.clearcoat = self.clearcoat(shading_normal, geometric_normal);
            }
            model.anisotropy = self.anisotropy(shading_normal);
        }
        Bsdf::new(model, shading_normal, geometric_normal).with_dispersion(dispersive)
    }
}

/// The mean of a textured emitter's emission over its triangle relative to its factor,
/// from a grid of points: what the light's power is scaled by for picking lights. Never
/// below 10⁻³, so a triangle whose texture the grid happens to see black still gets light
/// samples where it glows (a zero would make those points unreachable by light sampling).
pub(crate) fn mean_emission_scale<'a>(
    point: impl Fn([f32; 2]) -> SurfacePoint<'a>,
    factor: Spectrum,
) -> f32 {
    const STEPS: u32 = 6;
    let (mut sum, mut count) = (0.0f32, 0u32);
    for i in 0..STEPS {
        for j in 0..STEPS - i {
            let b = [
                (i as f32 + 1.0 / 3.0) / STEPS as f32,
                (j as f32 + 1.0 / 3.0) / STEPS as f32,
            ];
            sum += point(b).emission(&Channels::Rgb).luminance();
            count += 1;
        }
    }
    let factor = factor.luminance();
    if factor > 0.0 {
        (sum / count as f32 / factor).max(1e-3)
    } else {
        1.0
    }
}
