//! Wavefront OBJ text for the scenes the tests generate (door-ajar, lamp-behind-glass):
//! exact, platform-independent text, so the committed files can be compared with their
//! generators.
// Each test file and bench uses a part of these helpers.
#![allow(dead_code)]

use std::fmt::Write;

pub type Point = [f64; 3];

/// OBJ text under construction: `o` groups of quads (two triangles each) with a material.
#[derive(Default)]
pub struct Obj {
    pub text: String,
    vertices: usize,
}

impl Obj {
    pub fn group(&mut self, name: &str, material: &str) {
        writeln!(self.text, "o {name}\nusemtl {material}").unwrap();
    }

    /// The quad a, b, c, d (a planar, convex loop); its front side is the one the loop
    /// turns counter-clockwise on.
    pub fn quad(&mut self, [a, b, c, d]: [Point; 4]) {
        for p in [a, b, c, d] {
            // Whole hundredths of a millimetre: exact text, the same on every platform.
            writeln!(self.text, "v {} {} {}", fmt(p[0]), fmt(p[1]), fmt(p[2])).unwrap();
        }
        let i = self.vertices + 1;
        writeln!(self.text, "f {} {} {}", i, i + 1, i + 2).unwrap();
        writeln!(self.text, "f {} {} {}", i, i + 2, i + 3).unwrap();
        self.vertices += 4;
    }

    /// The axis-aligned box [lo, hi], faces outward. `skip` names faces left out because
    /// they lie against other geometry: "-x", "+x", "-y", "+y", "-z", "+z".
    pub fn cuboid(&mut self, lo: Point, hi: Point, skip: &[&str]) {
        self.cuboid_faces(lo, hi, skip, false);
    }

    /// The axis-aligned box [lo, hi] seen from inside (a room's shell), faces inward.
    pub fn inward_cuboid(&mut self, lo: Point, hi: Point, skip: &[&str]) {
        self.cuboid_faces(lo, hi, skip, true);
    }

    fn cuboid_faces(&mut self, lo: Point, hi: Point, skip: &[&str], inward: bool) {
        let corner = |x: usize, y: usize, z: usize| {
            [[lo[0], hi[0]][x], [lo[1], hi[1]][y], [lo[2], hi[2]][z]]
        };
        let faces = [
            ("-x", [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)]),
            ("+x", [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)]),
            ("-y", [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)]),
            ("+y", [(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)]),
            ("-z", [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)]),
            ("+z", [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]),
        ];
        for (name, loop_) in faces {
            if !skip.contains(&name) {
                let mut quad = loop_.map(|(x, y, z)| corner(x, y, z));
                if inward {
                    quad.reverse();
                }
                self.quad(quad);
            }
        }
    }
}

fn fmt(v: f64) -> String {
    let rounded = (v * 100.0).round() / 100.0;
    // Never "-0".
    format!("{}", rounded + 0.0)
}

/// A camera sidecar (tests/scenes' NAME.camera.json) for a 256 × 256 view with a 60° vertical
/// field of view and +y up.
pub fn camera_json(eye: Point, target: Point) -> String {
    let vector = |[x, y, z]: Point| format!("[{x:?}, {y:?}, {z:?}]");
    format!(
        "{{\n  \"eye\": {},\n  \"target\": {},\n  \"up\": [0.0, 1.0, 0.0],\n  \
         \"fov_y_deg\": 60.0,\n  \"width\": 256,\n  \"height\": 256\n}}\n",
        vector(eye),
        vector(target)
    )
}
