//! Camera sidecar JSON: `eye`, `target`, `up` (3 numbers each), `fov_y_deg` (vertical field of
//! view, degrees), `width`, `height` (pixels), optional `lens_radius` and `focus_distance`
//! (0 by default: a pinhole focused on the target). Unknown keys are rejected, so a typo
//! does not silently fall back to a default.

use super::scene_data::{CameraFile, IoError};
use crate::Camera;
use crate::render::MLT_MAX_IMAGE_SIDE;
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct CameraJson {
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    fov_y_deg: f32,
    width: u32,
    height: u32,
    #[serde(default)]
    lens_radius: f32,
    #[serde(default)]
    focus_distance: f32,
}

/// Reads and validates a camera sidecar file.
pub fn load_camera_json(path: &Path) -> Result<CameraFile, IoError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| IoError::new(format!("cannot read camera file {}: {e}", path.display())))?;
    let json: CameraJson = serde_json::from_str(&text).map_err(|e| {
        IoError::new(format!(
            "camera file {} is not a valid camera description: {e}",
            path.display()
        ))
    })?;
    let camera = Camera {
        eye: json.eye,
        target: json.target,
        up: json.up,
        fov_y_deg: json.fov_y_deg,
        lens_radius: json.lens_radius,
        focus_distance: json.focus_distance,
    };
    camera.validate().map_err(|e| {
        IoError::new(format!(
            "camera file {} is invalid: {}",
            path.display(),
            e.message
        ))
    })?;
    for (name, side) in [("width", json.width), ("height", json.height)] {
        if side == 0 || side > MLT_MAX_IMAGE_SIDE {
            return Err(IoError::new(format!(
                "camera file {} is invalid: {name} is {side}; it must be between 1 and {MLT_MAX_IMAGE_SIDE} pixels",
                path.display()
            )));
        }
    }
    Ok(CameraFile {
        camera,
        width: json.width,
        height: json.height,
    })
}

impl CameraFile {
    /// A camera framing the box `[min, max]` (a scene without a camera of its own): from
    /// the front (+Z, where glTF assets face) and a little above, looking at the box's
    /// centre with a 40° field of view, far enough back that its bounding sphere fits;
    /// 512 × 512.
    pub fn framing(min: [f32; 3], max: [f32; 3]) -> CameraFile {
        let (min, max) = (glam::Vec3::from(min), glam::Vec3::from(max));
        let center = (min + max) * 0.5;
        let radius = ((max - min).length() * 0.5).max(1e-3);
        let fov_y_deg = 40.0f32;
        let distance = radius / (fov_y_deg.to_radians() * 0.5).sin() * 1.05;
        let eye = center + glam::Vec3::new(0.0, 0.3, 1.0).normalize() * distance;
        CameraFile {
            camera: Camera {
                eye: eye.to_array(),
                target: center.to_array(),
                up: [0.0, 1.0, 0.0],
                fov_y_deg,
                ..Camera::default()
            },
            width: 512,
            height: 512,
        }
    }

    /// The camera as a sidecar file's JSON (what `load_camera_json` reads).
    pub fn to_json(&self) -> String {
        let c = &self.camera;
        serde_json::to_string_pretty(&CameraJson {
            eye: c.eye,
            target: c.target,
            up: c.up,
            fov_y_deg: c.fov_y_deg,
            width: self.width,
            height: self.height,
            lens_radius: c.lens_radius,
            focus_distance: c.focus_distance,
        })
        .expect("a camera serializes")
    }
}
