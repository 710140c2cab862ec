//! MikkTSpace tangents, which glTF requires for normal-mapped meshes without a TANGENT
//! attribute.

use glam::Vec3A;
use mikktspace::Geometry;

use crate::sampling::OrthonormalBasis;

/// One tangent per triangle corner (xyz unit, w = ±1 bitangent sign), 3 per triangle in the
/// order of `indices`.
///
/// The bitangent is cross(normal, tangent.xyz) · w, as glTF defines it, and points towards
/// decreasing v: up the image, the direction a normal texture's +Y (green) means. Where
/// MikkTSpace finds no tangent (a triangle whose texture coordinates are all equal, with no
/// neighbour to borrow one from), the corner gets an arbitrary unit tangent perpendicular to
/// its normal, with w = +1.
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) fn mikktspace_tangents(
    positions: &[f32],
    normals: &[f32],
    texcoords: &[f32],
    indices: &[u32],
) -> Vec<[f32; 4]> {
    let mut mesh = Mesh {
        positions,
        normals,
        texcoords,
        indices,
        tangents: vec![[0.0; 4]; indices.len() / 3 * 3],
    };
    // On failure (no triangles) every corner keeps its zero tangent and gets the fallback.
    if has_extent(positions, &indices[..indices.len() / 3 * 3]) {
        mikktspace::generate_tangents(&mut mesh);
    }
    let mut tangents = mesh.tangents;
    for (corner, tangent) in tangents.iter_mut().enumerate() {
        let normal = Vec3A::from_slice(&normals[indices[corner] as usize * 3..]);
        *tangent = unit_tangent_perpendicular_to(normal, *tangent);
    }
    tangents
}

/// Whether mikktspace 0.3 can take these triangles: some triangle has three distinct corner
/// positions, and the corners span a box of finite size. With every triangle degenerate it
/// subtracts 1 from their count of 0 (a panic, or without overflow checks reads past its
/// arrays; found by the obj_mtl fuzzer); it hashes the corners into a grid along the box's
/// widest axis and indexes past its table when that extent is 0 or overflows (found by the
/// capi_scene fuzzer). Such meshes get the fallback tangent at every corner.
fn has_extent(positions: &[f32], corners: &[u32]) -> bool {
    let position = |corner: u32| Vec3A::from_slice(&positions[corner as usize * 3..]);
    let (mut min, mut max) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for &corner in corners {
        let p = position(corner);
        (min, max) = (min.min(p), max.max(p));
    }
    let proper = corners.chunks_exact(3).any(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| position(t[k]));
        a != b && a != c && b != c
    });
    proper && (max - min).is_finite()
}

/// `tangent` made unit length and perpendicular to `normal`; any such tangent when it is zero
/// or not finite.
fn unit_tangent_perpendicular_to(normal: Vec3A, tangent: [f32; 4]) -> [f32; 4] {
    let normal = normal.try_normalize().unwrap_or(Vec3A::Z);
    let sign = if tangent[3] < 0.0 { -1.0 } else { 1.0 };
    let xyz = Vec3A::from_slice(&tangent[..3]);
    let xyz = (xyz - normal * normal.dot(xyz))
        .try_normalize()
        .unwrap_or_else(|| OrthonormalBasis::from_normal(normal).tangent);
    [xyz.x, xyz.y, xyz.z, sign]
}

/// The mesh as MikkTSpace reads it, and the tangents it writes.
struct Mesh<'a> {
    positions: &'a [f32],
    normals: &'a [f32],
    texcoords: &'a [f32],
    indices: &'a [u32],
    tangents: Vec<[f32; 4]>,
}

impl Mesh<'_> {
    fn vertex(&self, face: usize, corner: usize) -> usize {
        self.indices[face * 3 + corner] as usize
    }
}

impl Geometry for Mesh<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, corner: usize) -> [f32; 3] {
        let start = self.vertex(face, corner) * 3;
        self.positions[start..start + 3].try_into().unwrap()
    }

    fn normal(&self, face: usize, corner: usize) -> [f32; 3] {
        let start = self.vertex(face, corner) * 3;
        self.normals[start..start + 3].try_into().unwrap()
    }

    fn tex_coord(&self, face: usize, corner: usize) -> [f32; 2] {
        let start = self.vertex(face, corner) * 2;
        // MikkTSpace's bitangent follows increasing v, but glTF's (and a normal texture's
        // +Y) follows decreasing v: glTF images start at the top. Negating v gives the signs
        // glTF tools write, e.g. Blender's exporter, which runs MikkTSpace on 1 - v.
        [self.texcoords[start], -self.texcoords[start + 1]]
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, corner: usize) {
        self.tangents[face * 3 + corner] = tangent;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square in the xy plane facing +z, counter-clockwise seen from +z, with the
    /// texture coordinates `uv` gives each corner position.
    fn quad_tangents(uv: impl Fn(f32, f32) -> [f32; 2]) -> Vec<[f32; 4]> {
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let positions: Vec<f32> = corners.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect();
        let normals = [0.0, 0.0, 1.0].repeat(4);
        let texcoords: Vec<f32> = corners.iter().flat_map(|&[x, y]| uv(x, y)).collect();
        mikktspace_tangents(&positions, &normals, &texcoords, &[0, 1, 2, 0, 2, 3])
    }

    fn assert_all_close(tangents: &[[f32; 4]], expected: [f32; 4]) {
        assert_eq!(tangents.len(), 6);
        for (corner, tangent) in tangents.iter().enumerate() {
            for c in 0..4 {
                assert!(
                    (tangent[c] - expected[c]).abs() < 1e-5,
                    "corner {corner}: {tangent:?} != {expected:?}"
                );
            }
        }
    }

    #[test]
    fn flat_quad_tangent_follows_u_and_bitangent_points_up_the_image() {
        // u = x, so the tangent is +x. glTF images have v growing downwards and a normal
        // texture's +Y (green) pointing up the image, towards decreasing v: -y here. glTF's
        // bitangent is cross(n, t) · w = cross(+z, +x) · w = +y · w, so w = -1.
        assert_all_close(&quad_tangents(|x, y| [x, y]), [1.0, 0.0, 0.0, -1.0]);
    }

    #[test]
    fn mirrored_u_flips_the_sign() {
        // u = 1 - x: the tangent is -x; the bitangent is still -y (towards decreasing v), and
        // cross(+z, -x) = -y, so w = +1.
        assert_all_close(&quad_tangents(|x, y| [1.0 - x, y]), [-1.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn rotated_uv_keeps_the_sign() {
        // The texture turned a quarter: u = y, v = 1 - x. The tangent is +y; decreasing v is
        // +x; cross(+z, +y) = -x, so w = -1, as for the unrotated quad.
        assert_all_close(&quad_tangents(|x, y| [y, 1.0 - x]), [0.0, 1.0, 0.0, -1.0]);
    }

    #[test]
    fn degenerate_uv_gives_a_unit_tangent_perpendicular_to_the_normal() {
        let positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let normal = Vec3A::new(0.0, 0.6, 0.8);
        let normals = normal.to_array().repeat(3);
        let texcoords = [0.5; 6];
        let tangents = mikktspace_tangents(&positions, &normals, &texcoords, &[0, 1, 2]);
        assert_eq!(tangents.len(), 3);
        for tangent in tangents {
            let xyz = Vec3A::from_slice(&tangent);
            assert!(xyz.is_finite() && tangent[3].abs() == 1.0, "{tangent:?}");
            assert!((xyz.length() - 1.0).abs() < 1e-5, "{tangent:?}");
            assert!(xyz.dot(normal).abs() < 1e-5, "{tangent:?}");
        }
    }

    #[test]
    fn smooth_normals_give_unit_tangents_perpendicular_to_each_corner_normal() {
        // A square pyramid's four sides around an apex whose normal is +z, with each base
        // vertex's normal tilted outwards, and a shared texture-space layout (uv = xy).
        let positions = [
            0.0, 0.0, 1.0, // apex
            1.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0,
        ];
        let normals: Vec<f32> = [
            Vec3A::Z,
            Vec3A::new(1.0, 0.0, 1.0).normalize(),
            Vec3A::new(0.0, 1.0, 1.0).normalize(),
            Vec3A::new(-1.0, 0.0, 1.0).normalize(),
            Vec3A::new(0.0, -1.0, 1.0).normalize(),
        ]
        .iter()
        .flat_map(|n| n.to_array())
        .collect();
        let texcoords: Vec<f32> = positions.chunks(3).flat_map(|p| [p[0], p[1]]).collect();
        let indices = [0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1];
        let tangents = mikktspace_tangents(&positions, &normals, &texcoords, &indices);
        assert_eq!(tangents.len(), indices.len());
        for (corner, tangent) in tangents.iter().enumerate() {
            let normal = Vec3A::from_slice(&normals[indices[corner] as usize * 3..]);
            let xyz = Vec3A::from_slice(tangent);
            assert!(
                (xyz.length() - 1.0).abs() < 1e-5,
                "corner {corner}: {tangent:?}"
            );
            assert!(xyz.dot(normal).abs() < 1e-5, "corner {corner}: {tangent:?}");
            // u = x everywhere, so the tangent leans towards +x, and the layout is the flat
            // quad's, so w is -1.
            assert!(
                xyz.x > 0.0 && tangent[3] == -1.0,
                "corner {corner}: {tangent:?}"
            );
        }
    }

    #[test]
    fn no_triangles_give_no_tangents() {
        assert!(mikktspace_tangents(&[], &[], &[], &[]).is_empty());
    }

    /// Corners all at one point, only degenerate triangles, or corners spanning more than a
    /// float holds: mikktspace would overflow or index past its grid (found by the fuzzers);
    /// every corner gets a unit tangent perpendicular to its normal.
    #[test]
    fn meshes_without_a_usable_extent_get_the_fallback() {
        let normals = [0.0, 0.0, 1.0].repeat(3);
        let texcoords = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        for positions in [
            [1.0; 9],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            [-3e38, 0.0, 0.0, 3e38, 0.0, 0.0, 0.0, 1.0, 0.0],
        ] {
            for t in mikktspace_tangents(&positions, &normals, &texcoords, &[0, 1, 2]) {
                let xyz = Vec3A::from_slice(&t[..3]);
                assert!((xyz.length() - 1.0).abs() < 1e-5, "{t:?}");
                assert!(xyz.z.abs() < 1e-5, "{t:?}");
            }
        }
    }
}
