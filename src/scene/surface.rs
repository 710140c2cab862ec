//! What a surface is at a point inside a triangle: the per-vertex attributes a host may give
//! (shading normals, texture coordinates, tangents, colours), interpolated with the hit's
//! barycentrics, and the material evaluated there as a [`Bsdf`].
//!
//! Attributes are stored per triangle corner in the backend's internal triangle order, so a
//! hit reads one contiguous record per attribute. A scene without an attribute stores none.

use super::Material;
use crate::bsdf::{Bsdf, BsdfModel};
use crate::error::{Error, Result};
use crate::spectrum::Spectrum;
use glam::{Vec3A, Vec4};

/// Per-vertex arrays as the host gives them (empty: absent), before they are validated.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct VertexArrays<'a> {
    pub normals: &'a [f32],
    pub texcoords: &'a [f32],
    pub tangents: &'a [f32],
    pub colors: &'a [f32],
}

impl VertexArrays<'_> {
    /// Checks lengths and values against `vertex_count` vertices.
    pub fn validate(&self, vertex_count: usize) -> Result<()> {
        let arrays: [(&str, &[f32], usize, &[&str]); 4] = [
            ("normals", self.normals, 3, &["x", "y", "z"]),
            ("texcoords", self.texcoords, 2, &["u", "v"]),
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
    texcoords: Vec<[[f32; 2]; 3]>,
    colors: Vec<[Vec4; 3]>,
}

impl SurfaceAttributes {
    /// Room for `triangle_count` triangles of each attribute `arrays` has.
    pub fn with_capacity(arrays: &VertexArrays, triangle_count: usize) -> Self {
        let capacity = |values: &[f32]| if values.is_empty() { 0 } else { triangle_count };
        SurfaceAttributes {
            normals: Vec::with_capacity(capacity(arrays.normals)),
            texcoords: Vec::with_capacity(capacity(arrays.texcoords)),
            colors: Vec::with_capacity(capacity(arrays.colors)),
        }
    }

    /// Appends the next internal triangle, whose corners are vertices `corners`.
    pub fn push(&mut self, arrays: &VertexArrays, corners: [u32; 3]) {
        if !arrays.normals.is_empty() {
            self.normals.push(corners.map(|c| {
                let i = c as usize * 3;
                Vec3A::from_slice(&arrays.normals[i..i + 3]).normalize()
            }));
        }
        if !arrays.texcoords.is_empty() {
            self.texcoords.push(corners.map(|c| {
                let i = c as usize * 2;
                [arrays.texcoords[i], arrays.texcoords[i + 1]]
            }));
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
        self.normals.is_empty() && self.colors.is_empty() && !material.has_textures()
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

/// The BSDF of `material` at barycentrics `b` of internal triangle `triangle` with front
/// geometric normal `geometric_normal`.
#[inline]
pub(crate) fn bsdf_at(
    attributes: &SurfaceAttributes,
    material: &Material,
    triangle: u32,
    b: [f32; 2],
    geometric_normal: Vec3A,
) -> Bsdf {
    if attributes.is_flat(material) {
        return Bsdf::new(BsdfModel::of(material), geometric_normal, geometric_normal);
    }
    let vertex_color = attributes.color(triangle, b);
    let color = Spectrum::from(material.color)
        * Spectrum::new(vertex_color.x, vertex_color.y, vertex_color.z);
    let model = BsdfModel::with_color(material, color);
    let normal = attributes.shading_normal(triangle, b, geometric_normal);
    Bsdf::new(model, normal, geometric_normal)
}
