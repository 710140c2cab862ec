//! The traversal bench's scenes, generated deterministically to look like real content:
//! `room` (~70k triangles of furniture, books, spheres, vases, blinds, a plant and a heap of
//! boxes in a closed room) and `terrain` (~1.2M triangles: a finely tessellated displaced
//! heightfield with rocks, trees and houses), each with a camera looking into it.

use crate::generate::{MeshBuilder, uniform_direction};
use glam::{DAffine3, DQuat, DVec3, Vec3A};
use mlt::Camera;
use mlt::sampling::Rng;
use std::ops::Range;

/// The scenes' names, for `MLT_BENCH_SCENES`.
pub const SCENES: &[&str] = &["room", "terrain"];

pub struct BenchScene {
    pub name: &'static str,
    pub triangles: Vec<[Vec3A; 3]>,
    pub camera: Camera,
}

/// The scene called `name`, if there is one.
pub fn by_name(name: &str) -> Option<BenchScene> {
    match name {
        "room" => Some(room()),
        "terrain" => Some(terrain()),
        _ => None,
    }
}

/// A random rotation (uniform axis, any angle).
fn random_rotation(rng: &mut Rng) -> DQuat {
    DQuat::from_axis_angle(
        uniform_direction(rng).as_dvec3().normalize(),
        std::f64::consts::TAU * rng.uniform() as f64,
    )
}

fn uniform(rng: &mut Rng, range: Range<f64>) -> f64 {
    range.start + (range.end - range.start) * rng.uniform() as f64
}

/// Translation · rotation · scale.
fn place(at: DVec3, rotation: DQuat, scale: DVec3) -> DAffine3 {
    DAffine3::from_scale_rotation_translation(scale, rotation, at)
}

/// A box of half extents `half` centred at `at`, turned by `yaw` about the vertical.
fn furniture(mesh: &mut MeshBuilder, at: DVec3, half: DVec3, yaw: f64, cells: u32) {
    mesh.cuboid(place(at, DQuat::from_rotation_y(yaw), half), cells);
}

/// A vertical cylinder (closed) standing on `base`.
fn post(mesh: &mut MeshBuilder, base: DVec3, radius: f64, height: f64, segments: u32) {
    let upright = DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2);
    mesh.cylinder(
        place(base, upright, DVec3::new(radius, radius, height)),
        segments,
        1,
        true,
    );
}

/// An 8 × 3 × 6 m room (y up) with a table and chairs, a sofa, shelves of books, spheres of
/// several sizes, vases, a window with blinds, a plant of many thin leaves and a heap of
/// overlapping boxes: ~70k triangles of very different sizes and orientations.
pub fn room() -> BenchScene {
    let mut mesh = MeshBuilder::default();
    let mut rng = Rng::new(1, 1);
    // Floor, walls and ceiling.
    mesh.cuboid(
        place(
            DVec3::new(0.0, 1.5, 0.0),
            DQuat::IDENTITY,
            DVec3::new(4.0, 1.5, 3.0),
        ),
        16,
    );
    // A rug: a thin panel just above the floor.
    furniture(
        &mut mesh,
        DVec3::new(0.5, 0.005, 0.3),
        DVec3::new(1.6, 0.005, 1.1),
        0.1,
        8,
    );
    // The table and six chairs around it.
    let table = DVec3::new(0.5, 0.0, 0.3);
    furniture(
        &mut mesh,
        table + DVec3::new(0.0, 0.75, 0.0),
        DVec3::new(1.0, 0.03, 0.55),
        0.1,
        4,
    );
    for (x, z) in [(-0.9, -0.45), (0.9, -0.45), (-0.9, 0.45), (0.9, 0.45)] {
        post(&mut mesh, table + DVec3::new(x, 0.0, z), 0.04, 0.72, 24);
    }
    for i in 0..6 {
        let side = if i % 2 == 0 { -1.0 } else { 1.0 };
        let seat = table + DVec3::new(-0.6 + 0.6 * (i / 2) as f64, 0.45, side * 0.85);
        let yaw = uniform(&mut rng, -0.3..0.3);
        furniture(&mut mesh, seat, DVec3::new(0.22, 0.025, 0.22), yaw, 2);
        furniture(
            &mut mesh,
            seat + DVec3::new(0.0, 0.3, side * 0.2),
            DVec3::new(0.22, 0.28, 0.015),
            yaw,
            2,
        );
        for (x, z) in [(-0.18, -0.18), (0.18, -0.18), (-0.18, 0.18), (0.18, 0.18)] {
            post(
                &mut mesh,
                DVec3::new(seat.x + x, 0.0, seat.z + z),
                0.02,
                0.43,
                12,
            );
        }
    }
    // A sofa of finely divided cushions.
    let sofa = DVec3::new(-2.6, 0.0, 1.2);
    furniture(
        &mut mesh,
        sofa + DVec3::new(0.0, 0.25, 0.0),
        DVec3::new(0.45, 0.25, 1.1),
        0.0,
        12,
    );
    furniture(
        &mut mesh,
        sofa + DVec3::new(-0.35, 0.65, 0.0),
        DVec3::new(0.1, 0.4, 1.1),
        0.0,
        12,
    );
    for z in [-0.55, 0.0, 0.55] {
        furniture(
            &mut mesh,
            sofa + DVec3::new(0.05, 0.56, z),
            DVec3::new(0.35, 0.06, 0.26),
            0.0,
            10,
        );
    }
    // Shelves on the back wall, full of books leaning a little.
    for shelf in 0..5 {
        let y = 0.35 + 0.45 * shelf as f64;
        furniture(
            &mut mesh,
            DVec3::new(-1.0, y, -2.8),
            DVec3::new(1.5, 0.015, 0.18),
            0.0,
            6,
        );
        let mut x = -2.45;
        while x < 0.45 {
            let (width, height) = (
                uniform(&mut rng, 0.012..0.035),
                uniform(&mut rng, 0.12..0.19),
            );
            let lean = DQuat::from_rotation_z(uniform(&mut rng, -0.12..0.12));
            mesh.cuboid(
                place(
                    DVec3::new(x + width, y + 0.015 + height, -2.8),
                    lean,
                    DVec3::new(width, height, uniform(&mut rng, 0.09..0.14)),
                ),
                1,
            );
            x += 2.0 * width + uniform(&mut rng, 0.0..0.01);
        }
    }
    // A displaced-sphere sculpture on a plinth and smaller spheres on the table and shelves.
    furniture(
        &mut mesh,
        DVec3::new(2.9, 0.45, -2.0),
        DVec3::new(0.3, 0.45, 0.3),
        0.4,
        2,
    );
    mesh.sphere(
        place(
            DVec3::new(2.9, 1.3, -2.0),
            random_rotation(&mut rng),
            DVec3::splat(0.4),
        ),
        64,
        128,
        |theta, phi| 1.0 + 0.15 * (6.0 * theta).sin() * (5.0 * phi).cos(),
    );
    for _ in 0..14 {
        let r = uniform(&mut rng, 0.03..0.12);
        let at = if rng.uniform() < 0.5 {
            table
                + DVec3::new(
                    uniform(&mut rng, -0.9..0.9),
                    0.78 + r,
                    uniform(&mut rng, -0.45..0.45),
                )
        } else {
            let shelf = (rng.next_u32() % 5) as f64;
            DVec3::new(uniform(&mut rng, -2.4..0.4), 0.365 + 0.45 * shelf + r, -2.7)
        };
        mesh.sphere(
            place(at, random_rotation(&mut rng), DVec3::splat(r)),
            16,
            32,
            |_, _| 1.0,
        );
    }
    // Vases and cans: open or closed cylinders, some tipped over.
    for i in 0..30 {
        let r = uniform(&mut rng, 0.03..0.09);
        let h = uniform(&mut rng, 0.1..0.4);
        let at = DVec3::new(
            uniform(&mut rng, -3.5..3.5),
            0.0,
            uniform(&mut rng, -1.0..2.5),
        );
        let rotation = if i % 3 == 0 {
            DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2) * random_rotation(&mut rng)
        } else {
            DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2)
        };
        mesh.cylinder(
            place(at + DVec3::Y * r, rotation, DVec3::new(r, r, h)),
            32,
            4,
            i % 2 == 0,
        );
    }
    // A window with blinds: many thin tilted slats.
    for slat in 0..40 {
        let y = 0.9 + 0.04 * slat as f64;
        mesh.cuboid(
            place(
                DVec3::new(3.95, y, 0.5),
                DQuat::from_rotation_z(0.6),
                DVec3::new(0.015, 0.001, 0.8),
            ),
            1,
        );
    }
    // A plant: a pot and thousands of thin leaves in every orientation.
    let plant = DVec3::new(-3.3, 0.0, -2.3);
    post(&mut mesh, plant, 0.2, 0.4, 48);
    for _ in 0..2500 {
        let at = plant + DVec3::new(0.0, 0.4, 0.0) + uniform_direction(&mut rng).as_dvec3() * 0.45;
        let leaf = place(
            at.max(DVec3::new(f64::MIN, 0.45, f64::MIN)),
            random_rotation(&mut rng),
            DVec3::ONE,
        );
        mesh.grid(1, 1, |s, u| {
            leaf.transform_point3(DVec3::new(0.12 * s, 0.03 * (u - 0.5) * (1.0 - s), 0.0))
        });
    }
    // A heap of overlapping boxes by the table.
    for _ in 0..600 {
        let at = DVec3::new(
            uniform(&mut rng, -1.5..0.5),
            uniform(&mut rng, 0.35..0.9),
            uniform(&mut rng, 1.7..2.6),
        );
        let half = DVec3::new(
            uniform(&mut rng, 0.02..0.2),
            uniform(&mut rng, 0.02..0.2),
            uniform(&mut rng, 0.02..0.2),
        );
        mesh.cuboid(place(at, random_rotation(&mut rng), half), 1);
    }
    BenchScene {
        name: "room",
        triangles: mesh.triangles(),
        camera: Camera {
            eye: [3.6, 1.75, 2.7],
            target: [-1.0, 0.8, -1.2],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 70.0,
            ..Camera::default()
        },
    }
}

/// The terrain's height at (x, z): a few octaves of waves.
fn terrain_height(x: f64, z: f64) -> f64 {
    40.0 * (0.006 * x).sin() * (0.008 * z).cos()
        + 15.0 * (0.021 * x + 0.013 * z).sin()
        + 4.0 * (0.07 * x).sin() * (0.09 * z).sin()
        + 1.0 * (0.31 * x + 0.23 * z).sin()
        + 0.3 * (1.3 * x - 0.9 * z).sin()
}

/// A 1 km² displaced heightfield of 980k triangles with rocks, trees and houses on it:
/// ~1.2M triangles.
pub fn terrain() -> BenchScene {
    let mut mesh = MeshBuilder::default();
    let mut rng = Rng::new(2, 1);
    mesh.grid(700, 700, |s, u| {
        let (x, z) = (-500.0 + 1000.0 * s, -500.0 + 1000.0 * u);
        DVec3::new(x, terrain_height(x, z), z)
    });
    let ground = |rng: &mut Rng| {
        let (x, z) = (uniform(rng, -480.0..480.0), uniform(rng, -480.0..480.0));
        DVec3::new(x, terrain_height(x, z), z)
    };
    for _ in 0..250 {
        let at = ground(&mut rng);
        let size = uniform(&mut rng, 0.5..6.0);
        let (a, b) = (uniform(&mut rng, 0.0..6.3), uniform(&mut rng, 0.0..6.3));
        let scale = DVec3::new(
            size,
            size * uniform(&mut rng, 0.4..1.0),
            size * uniform(&mut rng, 0.6..1.2),
        );
        mesh.sphere(
            place(at, random_rotation(&mut rng), scale),
            10,
            20,
            |theta, phi| 1.0 + 0.2 * (3.0 * theta + a).sin() * (2.0 * phi + b).cos(),
        );
    }
    for _ in 0..500 {
        let at = ground(&mut rng);
        let height = uniform(&mut rng, 4.0..14.0);
        post(
            &mut mesh,
            at - DVec3::Y,
            0.15 * height / 8.0,
            height * 0.6,
            8,
        );
        let crown = DVec3::new(height * 0.25, height * 0.35, height * 0.25);
        mesh.sphere(
            place(
                at + DVec3::Y * height * 0.7,
                DQuat::from_rotation_y(uniform(&mut rng, 0.0..6.3)),
                crown,
            ),
            8,
            12,
            |_, phi| 1.0 + 0.1 * (5.0 * phi).sin(),
        );
    }
    for _ in 0..60 {
        let at = ground(&mut rng);
        let yaw = uniform(&mut rng, 0.0..6.3);
        let half = DVec3::new(
            uniform(&mut rng, 3.0..8.0),
            3.0,
            uniform(&mut rng, 3.0..6.0),
        );
        furniture(&mut mesh, at + DVec3::Y * 2.0, half, yaw, 2);
        let roof =
            DQuat::from_rotation_y(yaw) * DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4);
        mesh.cuboid(
            place(
                at + DVec3::Y * 5.0,
                roof,
                DVec3::new(half.x * 0.72, half.x * 0.72, half.z * 1.05),
            ),
            1,
        );
    }
    // From 60 m above the ground towards the middle, 24° down: the far hills and a strip of
    // sky at the top of the image.
    let eye = DVec3::new(-420.0, terrain_height(-420.0, -380.0) + 60.0, -380.0);
    let target = eye + DVec3::new(0.74, 0.0, 0.67) * 100.0 - DVec3::Y * 45.0;
    BenchScene {
        name: "terrain",
        triangles: mesh.triangles(),
        camera: Camera {
            eye: eye.as_vec3().to_array(),
            target: target.as_vec3().to_array(),
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 60.0,
            ..Camera::default()
        },
    }
}
